// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What the augmentation tests share (test_<step>.cpp of each step, test_resample.cpp, test_scene.cpp): the
// input bursts of the reference sensor and their temporal and spatial statistics.
#ifndef OPENCV_RAWGMENT_TEST_AUGMENT_COMMON_HPP
#define OPENCV_RAWGMENT_TEST_AUGMENT_COMMON_HPP

#include "test_common.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <vector>

namespace cv {
namespace rawgment {
namespace augment_test {

const double kGain = 2.0; // the input bursts' gain (6 dB)
const int kFrames = 64;

//! Eight levels in blocks of 8 columns: 10 to 1800 DN at gain 1, 20 to 3600 DN at kGain.
inline Mat levelScene(Size size)
{
    const double levels[8] = {10, 30, 80, 200, 400, 800, 1200, 1800};
    Mat m(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c)
        m.col(c).setTo(levels[(c / 8) % 8]);
    return m;
}

//! A burst as CV_32FC1 raw frames (integer DN with black): float output avoids a second rounding.
inline std::vector<Mat> floatBurst(const SensorSimulator& sensor, const Mat& mean, uint64 seed)
{
    std::vector<Mat> raws;
    sensor.captureBurst(mean, kGain, 1.0, kFrames, seed, raws);
    for (Mat& f : raws)
        f.convertTo(f, CV_32F);
    return raws;
}

//! Per-pixel temporal mean and unbiased variance (black-subtracted) of a float burst.
inline void temporalStats(const std::vector<Mat>& burst, const RawFormat& fmt, Mat& mean, Mat& var)
{
    Mat sum(burst[0].size(), CV_64F, Scalar(0)), sum2 = sum.clone();
    for (const Mat& f : burst) {
        Mat x;
        subtractBlackLevel(f, fmt, x);
        x.convertTo(x, CV_64F);
        sum += x;
        sum2 += x.mul(x);
    }
    const double n = static_cast<double>(burst.size());
    mean = sum / n;
    var = (sum2 - sum.mul(sum) / n) / (n - 1);
}

const NoiseAlignment kAllAlignments[] = {NoiseAlignment::NONE, NoiseAlignment::IGNORE_PRIOR,
                                         NoiseAlignment::ACCOUNT_PRIOR};

//! Temporal statistics (as temporalStats) of a burst after `step(frame, t, out)` on every frame.
template <typename Step>
inline void statsAfterStep(const std::vector<Mat>& burst, const RawFormat& fmt, Step step, Mat& mean,
                           Mat& var)
{
    std::vector<Mat> out(burst.size());
    for (size_t t = 0; t < burst.size(); ++t)
        step(burst[t], static_cast<int>(t), out[t]);
    temporalStats(out, fmt, mean, var);
}

// The sensor with every dark-frame component (test_common.hpp), lambda -0.1, unquantised: the float
// augmentation and the capture then compare in their statistics without 1/12 DN^2 of rounding on one
// side only.
inline SensorParams darkComponentSensor(Size size)
{
    SensorParams p = test::darkComponentSensorParams(size, -0.1, 19);
    p.quantize = false;
    return p;
}

//! Spatial mean and unbiased variance of the black-subtracted pixels of a flat frame.
inline void spatialStats(const Mat& raw, const RawFormat& fmt, double& mean, double& var)
{
    Mat x;
    subtractBlackLevel(raw, fmt, x);
    Scalar m, s;
    meanStdDev(x, m, s);
    mean = m[0];
    var = s[0] * s[0] * static_cast<double>(x.total()) / static_cast<double>(x.total() - 1);
}

// The statistics of a dark-frame component (docs/mathematics.md, "Dark-frame noise") of a float burst of
// a flat scene, black-subtracted: the residual e = x - (the pixel's temporal mean), its row means R and
// the rest f = e - R. Over T frames of H x W: E[sum R^2] = (T - 1) H (rowVar + pixVar / W) and
// E[sum f^2] = (T - 1) H (W - 1) pixVar.
struct DarkStats
{
    Mat pixelMean;     // temporal mean per pixel (the fixed pattern plus the scene)
    double rowMeanVar; // sum R^2 / ((T - 1) H): row variance plus pixVar / W
    double pixelVar;   // per-pixel temporal variance without the rows
    double kurtosis;   // excess kurtosis of f
    double kurtosisSE; // its standard error, from the spread over the frames
    int dof;           // degrees of freedom of rowMeanVar
};

inline DarkStats darkStats(const std::vector<Mat>& burst, double black)
{
    const int T = static_cast<int>(burst.size()), H = burst[0].rows, W = burst[0].cols;
    DarkStats d;
    Mat sum(burst[0].size(), CV_64F, Scalar(0));
    for (const Mat& f : burst) {
        Mat x;
        f.convertTo(x, CV_64F, 1, -black);
        sum += x;
    }
    d.pixelMean = sum / T;
    double sumR2 = 0, sumF2 = 0, sumF4 = 0;
    std::vector<double> frameKurtosis;
    for (const Mat& f : burst) {
        Mat e;
        f.convertTo(e, CV_64F, 1, -black);
        e -= d.pixelMean;
        double m2 = 0, m4 = 0;
        for (int r = 0; r < H; ++r) {
            const double* p = e.ptr<double>(r);
            double rowSum = 0;
            for (int c = 0; c < W; ++c)
                rowSum += p[c];
            const double R = rowSum / W;
            sumR2 += R * R;
            for (int c = 0; c < W; ++c) {
                const double v = (p[c] - R) * (p[c] - R);
                m2 += v;
                m4 += v * v;
            }
        }
        sumF2 += m2;
        sumF4 += m4;
        const double n = static_cast<double>(H) * W;
        frameKurtosis.push_back((m4 / n) / ((m2 / n) * (m2 / n)) - 3);
    }
    const double n = static_cast<double>(T) * H * W;
    d.rowMeanVar = sumR2 / ((T - 1.0) * H);
    d.pixelVar = sumF2 / ((T - 1.0) * H * (W - 1));
    d.kurtosis = (sumF4 / n) / ((sumF2 / n) * (sumF2 / n)) - 3;
    double mk = 0, vk = 0;
    for (double k : frameKurtosis)
        mk += k / T;
    for (double k : frameKurtosis)
        vk += (k - mk) * (k - mk) / (T - 1);
    d.kurtosisSE = std::sqrt(vk / T);
    d.dof = (T - 1) * H;
    return d;
}

// The mean square difference of two bursts' fixed patterns over what their noise alone gives: 0 when
// the patterns agree. A temporal mean of T frames carries (pixVar + rowVar) / T of noise per pixel.
inline double fixedPatternExcess(const DarkStats& a, const DarkStats& b, int T, int W)
{
    Mat d = a.pixelMean - b.pixelMean;
    d -= cv::mean(d)[0]; // the scene's level is not the pattern
    const double noise = (a.pixelVar + b.pixelVar + (a.rowMeanVar + b.rowMeanVar) * (1 - 1.0 / W)) / T;
    return d.dot(d) / d.total() / noise - 1;
}

//! A noiseless CV_32FC1 capture of a flat scene `level` DN above black, carrying the sensor's `pattern`.
inline Mat flatWithPattern(const RawFormat& fmt, const Mat& pattern, double level)
{
    Mat flat(pattern.size(), CV_32FC1);
    for (int r = 0; r < flat.rows; ++r)
        for (int c = 0; c < flat.cols; ++c)
            flat.at<float>(r, c) = static_cast<float>(fmt.blackAt(r, c) + level) + pattern.at<float>(r, c);
    return flat;
}

//! A small 12-bit mosaic (black 256) with a pixel far below black, one saturated and one exactly at black.
inline Mat smallMosaic(int type = CV_16UC1)
{
    Mat m(16, 24, CV_16UC1);
    RNG rng(3);
    rng.fill(m, RNG::UNIFORM, 200, 3000);
    m.at<ushort>(0, 0) = 0;    // far below black
    m.at<ushort>(1, 1) = 4095; // saturated
    m.at<ushort>(2, 2) = 256;  // exactly black
    Mat out;
    m.convertTo(out, type);
    return out;
}

} // namespace augment_test
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_TEST_AUGMENT_COMMON_HPP
