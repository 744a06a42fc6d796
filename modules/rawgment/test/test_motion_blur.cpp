// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The motion blur step (motion_blur.cpp, paper Eq. 15 with the kernel's weights): against a capture blurred
// before the noise, its taps at the edge, and the noise sum from the blurred mean.
#include "test_augment_common.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <functional>

namespace cv {
namespace rawgment {
namespace {

using namespace augment_test;

TEST(Augment, motionBlurMatchesACaptureBlurredBeforeTheNoise)
{
    const Size size(128, 128);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    Mat scene(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c) // bars of 16 columns: the blur mixes dark and bright photons
        scene.col(c).setTo((c / 16) % 2 ? 1500.0 : 60.0);
    const Mat kernel = linearMotionKernel(13, 0); // horizontal, the paper's largest length
    std::vector<Mat> truth(kFrames), sharp = floatBurst(sensor, scene, 9);
    for (int t = 0; t < kFrames; ++t) {
        sensor.captureBlurred(scene, kernel, kGain, 1.0, 77, t, truth[t]);
        truth[t].convertTo(truth[t], CV_32F);
    }
    Mat truthMean, truthVar;
    temporalStats(truth, fmt, truthMean, truthVar);
    // The simulator and the augmentation share one border rule (replicate), so every column counts.
    const Rect inner(Point(0, 0), size);
    double ratio[3];
    for (NoiseAlignment mode : kAllAlignments) {
        Mat mean, var;
        statsAfterStep(
            sharp, fmt,
            [&](const Mat& frame, int t, Mat& out) {
                motionBlur(frame, fmt, model, kernel, mode, 500 + t, out);
            },
            mean, var);
        ratio[static_cast<int>(mode)] = cv::mean(var(inner))[0] / cv::mean(truthVar(inner))[0];
        // The mean is the blurred mean whatever the mode. Column means over 128 rows x 64 frames, for
        // both bursts: the difference has standard error sqrt(2 v / (64 * 128)); 5 of them.
        for (int c = inner.x; c < inner.x + inner.width; ++c) {
            const double v = cv::mean(truthVar.col(c))[0];
            EXPECT_NEAR(cv::mean(mean.col(c))[0], cv::mean(truthMean.col(c))[0],
                        5 * std::sqrt(2 * v / (64.0 * 128)))
                << "column " << c;
        }
        if (mode == NoiseAlignment::ACCOUNT_PRIOR) {
            // Column by column (edges included, where Eq. 15's per-pixel sum matters most): each column
            // averages 128 variances of 64 frames, twice (truth and augmentation): the relative standard
            // error of the ratio is sqrt(2) * sqrt(2 / 63) / sqrt(128) = 2.2%; 5 of them = 11%.
            for (int c = inner.x; c < inner.x + inner.width; ++c) {
                const double rc = cv::mean(var.col(c))[0] / cv::mean(truthVar.col(c))[0];
                EXPECT_NEAR(rc, 1.0, 0.11) << "column " << c;
            }
        }
    }
    std::cout << "blur variance / true blurred capture: NONE " << ratio[0] << ", IGNORE_PRIOR " << ratio[1]
              << ", ACCOUNT_PRIOR " << ratio[2] << "\n";
    // Over the 16,384 pixels the standard error is 0.55%: 3% is more than 5 of them.
    EXPECT_NEAR(ratio[2], 1.0, 0.03);
    EXPECT_LT(ratio[0], 0.5); // a plain blur smooths the read noise too: far too clean
    EXPECT_GT(ratio[1], 1.03);
}

TEST(Augment, motionBlurMergesTapsThatReplicateOneEdgePixel)
{
    // A flat burst blurred with a peaked 5x5 kernel: at the frame's edges several taps replicate one
    // pixel, whose prior noise the blur keeps with the square of their summed weight. Eq. 15 over the
    // distinct pixels gives back exactly the input's variance everywhere; over the taps it would leave
    // 20-50% too much at the edges and corners.
    const Size size(128, 128);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const std::vector<Mat> burst = floatBurst(sensor, Mat(size, CV_32FC1, Scalar(800)), 31);
    const Mat taps = (Mat_<float>(1, 5) << 1, 4, 6, 4, 1);
    const Mat kernel = taps.t() * taps;
    Mat mean, var;
    statsAfterStep(
        burst, fmt,
        [&](const Mat& frame, int t, Mat& out) {
            motionBlur(frame, fmt, model, kernel, NoiseAlignment::ACCOUNT_PRIOR, 40 + t, out);
        },
        mean, var);
    const double truth = model.variance(800 * kGain, kGain);
    // Averages of 128 pixels (a row or column) or 16 (a 4x4 corner) of 64-frame variances: relative
    // standard errors sqrt(2 / 63) / sqrt(n) = 1.6% and 4.5%; 5 of them.
    const double lineTolerance = 5 * std::sqrt(2.0 / 63) / std::sqrt(128.0);
    const double cornerTolerance = 5 * std::sqrt(2.0 / 63) / 4;
    for (int k : {0, 1, 2, 3, size.width - 4, size.width - 3, size.width - 2, size.width - 1}) {
        EXPECT_NEAR(cv::mean(var.col(k))[0] / truth, 1.0, lineTolerance) << "column " << k;
        EXPECT_NEAR(cv::mean(var.row(k))[0] / truth, 1.0, lineTolerance) << "row " << k;
    }
    for (Point corner : {Point(0, 0), Point(size.width - 4, 0), Point(0, size.height - 4),
                         Point(size.width - 4, size.height - 4)})
        EXPECT_NEAR(cv::mean(var(Rect(corner, Size(4, 4))))[0] / truth, 1.0, cornerTolerance)
            << "corner " << corner;
}

TEST(Augment, blurNoiseFromTheBlurredMeanIsExactWhereTheTapsAgree)
{
    // A noiseless float mosaic with a vertical edge: the added noise of the same seed differs between
    // the two sums only through sqrt(v), so (out - plain blur) compares the variances pixel by pixel.
    const Size size(64, 16);
    const NoiseModel model(0.4, 0.5, 2.0);
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(64);
    fmt.whiteLevel = 65535;
    fmt.gain = 2;
    Mat src(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c)
        src.col(c).setTo(c < size.width / 2 ? 64 + 50 : 64 + 2000);
    const auto noiseOf = [&](const Mat& kernel, BlurNoiseSum sum) {
        NoiseOptions noise;
        noise.blurNoiseSum = sum;
        Mat plain, noisy;
        motionBlur(src, fmt, model, kernel, NoiseAlignment::NONE, 3, plain);
        motionBlur(src, fmt, model, kernel, noise, 3, noisy);
        return Mat(noisy - plain);
    };
    const Mat uniform = Mat::ones(1, 5, CV_32F);
    Mat exact = noiseOf(uniform, BlurNoiseSum::EXACT),
        approx = noiseOf(uniform, BlurNoiseSum::FROM_BLURRED_MEAN);
    // Equal weights: sum w (1 - w) x = (1 - sum w^2) mean, the approximation is exact (to float rounding).
    EXPECT_LT(norm(exact, approx, NORM_INF), 1e-3);
    const Mat skewed = (Mat_<float>(1, 3) << 0.7f, 0.2f, 0.1f);
    exact = noiseOf(skewed, BlurNoiseSum::EXACT);
    approx = noiseOf(skewed, BlurNoiseSum::FROM_BLURRED_MEAN);
    // Flat away from the edge: the same. At the edge (plane column 15 sees both levels): the ratio of
    // standard deviations the two formulas give there.
    EXPECT_LT(norm(exact.colRange(0, 24), approx.colRange(0, 24), NORM_INF), 1e-3);
    EXPECT_LT(norm(exact.colRange(40, 64), approx.colRange(40, 64), NORM_INF), 1e-3);
    const NoiseLine line = model.lineAtGain(fmt.gain);
    const double w[3] = {0.7, 0.2, 0.1}, level[3] = {50, 2000, 2000}; // plane columns 15, 16, 17
    double exactShot = 0, blurred = 0, sumW2 = 0;
    for (int t = 0; t < 3; ++t) {
        exactShot += w[t] * (1 - w[t]) * level[t];
        blurred += w[t] * level[t];
        sumW2 += w[t] * w[t];
    }
    const double vExact = line.a * exactShot + (1 - sumW2) * line.b;
    const double vApprox = line.a * (1 - sumW2) * blurred + (1 - sumW2) * line.b;
    for (int r = 0; r < size.height; ++r) {
        const int c = 2 * 15 + r % 2; // both sites of the row
        const float e = exact.at<float>(r, c), a = approx.at<float>(r, c);
        if (std::abs(e) > 1) { // far from zero, so the ratio is well conditioned
            EXPECT_NEAR(a / e, std::sqrt(vApprox / vExact), 1e-3);
        }
    }
}

} // namespace
} // namespace rawgment
} // namespace cv
