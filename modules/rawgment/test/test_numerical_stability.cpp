// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The hard cases of every topic in one place: values below black and at zero, saturation, vanishing
// and huge exposure and gain ratios, 16-bit extremes, large means with tiny variances, the smallest and
// largest Shapiro-Wilk samples, degenerate line and cross-gain fits. Each case asserts a correct value
// or a clear cv::Exception; none may give NaN or Inf silently.
#include "test_common.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/cpu.hpp>
#include <opencv2/rawgment/isp.hpp>
#include <opencv2/rawgment/normality.hpp>
#include <opencv2/rawgment/raw_io.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <limits>

namespace cv {
namespace rawgment {
namespace {

// ---------------------------------------------------------------------------------------------------
// Augmentation

const double kGain = 2.0;

//! 16x24 12-bit mosaic (black 256) holding the hard values: 0 (far below black), 255 (just below),
//! exactly black, and white, among uniform values.
Mat hardMosaic(int type)
{
    Mat m(16, 24, CV_16UC1);
    RNG(17).fill(m, RNG::UNIFORM, 100, 3500);
    m.at<ushort>(0, 0) = 0;
    m.at<ushort>(0, 1) = 255;
    m.at<ushort>(2, 2) = 256;
    m.at<ushort>(1, 1) = 4095;
    Mat out;
    m.convertTo(out, type);
    return out;
}

const NoiseAlignment kAlignments[] = {NoiseAlignment::NONE, NoiseAlignment::IGNORE_PRIOR,
                                      NoiseAlignment::ACCOUNT_PRIOR};

//! Every combination of the noise knobs with ACCOUNT_PRIOR: hard cases must hold for each.
std::vector<NoiseOptions> everyKnob()
{
    std::vector<NoiseOptions> all;
    for (ShotNoiseSampling s : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON})
        for (PriorMeanEstimate p : {PriorMeanEstimate::PIXEL_VALUE, PriorMeanEstimate::LOCAL_MEAN})
            for (BlurNoiseSum b : {BlurNoiseSum::EXACT, BlurNoiseSum::FROM_BLURRED_MEAN}) {
                NoiseOptions o;
                o.shotSampling = s;
                o.priorMean = p;
                o.blurNoiseSum = b;
                all.push_back(o);
            }
    return all;
}

TEST(NumericalStability, augmentationHardCasesGiveFiniteCorrectOutput)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    const Mat src = hardMosaic(CV_32FC1);
    Mat x;
    subtractBlackLevel(src, fmt, x);
    RawFormat outFmt;
    // Brightening x10: the target is less noisy than the input; nothing can be added, so the output is
    // exactly ten times the input (clipped to [0, white]), and every pixel is reported.
    Mat out;
    for (const NoiseOptions& noise : everyKnob()) {
        AugmentReport report;
        Mat mask;
        colorJitter(src, fmt, model, ColorJitter::exposureChange(10, 1), noise, 1, out, outFmt, &report,
                    mask);
        EXPECT_EQ(report.brighteningPixels, static_cast<int64>(src.total()));
        EXPECT_EQ(report.saturatedPixels, 1);
        EXPECT_EQ(mask.at<uchar>(1, 1), 255);
        EXPECT_EQ(countNonZero(mask), 1);
        for (int r = 0; r < src.rows; ++r)
            for (int c = 0; c < src.cols; ++c) {
                const float expected = std::min(std::max(10 * x.at<float>(r, c) + 256.f, 0.f), 4095.f);
                ASSERT_NEAR(out.at<float>(r, c), expected, 1e-2f) << "at " << r << "," << c;
            }
    }
    // p_u = 1: at the same gain the step is the identity (skipped, the input itself); at four times
    // the gain the target's read noise after the gain is smaller than the amplified input's, which is
    // brightening too (reported), and the output is exactly four times the input.
    colorJitter(src, fmt, model, ColorJitter::exposureChange(1, 1), NoiseAlignment::ACCOUNT_PRIOR, 1, out,
                outFmt);
    EXPECT_EQ(out.data, src.data);
    AugmentReport gained;
    colorJitter(src, fmt, model, ColorJitter::exposureChange(1, 4), NoiseAlignment::ACCOUNT_PRIOR, 1, out,
                outFmt, &gained);
    EXPECT_EQ(gained.brighteningPixels, static_cast<int64>(src.total()));
    EXPECT_EQ(outFmt.gain, 4 * kGain);
    EXPECT_NEAR(out.at<float>(3, 3), std::min(4 * x.at<float>(3, 3) + 256.f, 4095.f), 1e-2f);
    // Knobs at p_u -> 0 and 60 dB: finite everywhere, in range.
    for (const NoiseOptions& noise : everyKnob()) {
        for (double pu : {1e-6, 1e-9}) {
            colorJitter(src, fmt, model, ColorJitter::exposureChange(pu, 1), noise, 2, out, outFmt);
            EXPECT_EQ(test::countNonFinite(out), 0);
        }
        RawFormat loud = fmt;
        loud.gain = 1000;
        colorJitter(src, loud, model, ColorJitter::exposureChange(0.01, 1), noise, 3, out, outFmt);
        EXPECT_EQ(test::countNonFinite(out), 0);
        motionBlur(src, loud, model, linearMotionKernel(9, 10), noise, 3, out);
        EXPECT_EQ(test::countNonFinite(out), 0);
        scaleMosaic(src, loud, model, 0.9, noise, 3, out);
        EXPECT_EQ(test::countNonFinite(out), 0);
        double lo = 0, hi = 0;
        minMaxLoc(out, &lo, &hi);
        EXPECT_GE(lo, 0);
        EXPECT_LE(hi, 4095);
    }
    // p_u -> 0 (1e-6, 1e-9): only read noise remains, around black; finite everywhere.
    for (double pu : {1e-6, 1e-9}) {
        colorJitter(src, fmt, model, ColorJitter::exposureChange(pu, 1), NoiseAlignment::ACCOUNT_PRIOR, 2,
                    out, outFmt);
        EXPECT_EQ(test::countNonFinite(out), 0);
        EXPECT_NEAR(cv::mean(out)[0], 256, 3 * std::sqrt(model.variance(0, kGain)));
    }
    // 0 dB and 60 dB inputs; 60 dB target gain.
    for (double gain : {1.0, 1000.0}) {
        RawFormat g = fmt;
        g.gain = gain;
        for (NoiseAlignment mode : kAlignments) {
            colorJitter(src, g, model, ColorJitter::exposureChange(0.01, 10), mode, 3, out, outFmt);
            EXPECT_EQ(test::countNonFinite(out), 0);
            motionBlur(src, g, model, linearMotionKernel(9, 10), mode, 3, out);
            EXPECT_EQ(test::countNonFinite(out), 0);
        }
    }
    // A kernel larger than the image.
    Mat tiny = src(Rect(0, 0, 4, 4)).clone();
    motionBlur(tiny, fmt, model, Mat::ones(41, 41, CV_32F), NoiseAlignment::ACCOUNT_PRIOR, 4, out);
    EXPECT_EQ(out.size(), tiny.size());
    EXPECT_EQ(test::countNonFinite(out), 0);
    // 16-bit extremes stay in range.
    Mat extremes(4, 4, CV_16UC1, Scalar(0));
    extremes.row(1).setTo(65535);
    RawFormat wide = fmt;
    wide.whiteLevel = 65535;
    colorJitter(extremes, wide, model, ColorJitter::exposureChange(0.5, 3), NoiseAlignment::ACCOUNT_PRIOR, 5,
                out, outFmt);
    EXPECT_EQ(out.type(), CV_16UC1);
    // x1.5 of 65535 clips at white instead of wrapping around; 0 (far below black) stays at 0 or near it.
    double lo = 0, hi = 0;
    minMaxLoc(out.row(1), &lo, &hi);
    EXPECT_EQ(lo, 65535);
    minMaxLoc(out.row(0), &lo, &hi);
    EXPECT_LT(hi, 256 + 6 * std::sqrt(model.variance(0, 3 * wide.gain)));
    // Brightening 16-bit extremes by 10x: white stays white, no wrap-around anywhere.
    colorJitter(extremes, wide, model, ColorJitter::exposureChange(10, 1), NoiseAlignment::ACCOUNT_PRIOR, 5,
                out, outFmt);
    minMaxLoc(out.row(1), &lo, &hi);
    EXPECT_EQ(lo, 65535);
    // A white level far above what 16 bits hold (a format that claims never to saturate): every 16-bit
    // step clips at 65535. With a white level of 70000 the jitter once wrapped 1.2 x 60000 round to 4464.
    // 34 columns: whole vectors and the scalar tail of every store.
    RawFormat beyond = wide;
    beyond.whiteLevel = 1e12;
    const Mat high(8, 34, CV_16UC1, Scalar(60000)), higher(high.size(), CV_16UC1, Scalar(65535));
    for (NoiseAlignment mode : kAlignments) {
        SCOPED_TRACE(static_cast<int>(mode));
        colorJitter(high, beyond, model, ColorJitter::exposureChange(1.2, 1), mode, 6, out, outFmt);
        minMaxLoc(out, &lo, &hi);
        EXPECT_EQ(lo, 65535) << "colorJitter";
        motionBlur(higher, beyond, model, linearMotionKernel(9, 10), mode, 6, out);
        minMaxLoc(out, &lo, &hi);
        EXPECT_GT(lo, 65535 - 6 * std::sqrt(model.variance(65535, beyond.gain))) << "motionBlur";
        EXPECT_EQ(hi, 65535) << "motionBlur";
        scaleMosaic(higher, beyond, model, 1.1, mode, 6, out);
        minMaxLoc(out, &lo, &hi);
        EXPECT_GT(lo, 65535 - 6 * std::sqrt(model.variance(65535, beyond.gain))) << "scaleMosaic";
        EXPECT_EQ(hi, 65535) << "scaleMosaic";
    }
}

// ---------------------------------------------------------------------------------------------------
// Burst statistics

//! Largest errors of BurstStatistics' mean and variance against a long-double two-pass reference, for
//! a burst of 6x10 float frames with mean 60000 (59900 above black) and variance 1.
Vec2d burstStatisticsErrorsAtLargeMean(const RawFormat& fmt, int depth, int group, int frames)
{
    BurstStatistics stats(fmt, group, depth);
    RNG rng(frames);
    std::vector<Mat> burst;
    for (int t = 0; t < frames; ++t) {
        Mat f(6, 10, CV_32FC1);
        rng.fill(f, RNG::NORMAL, 60000, 1);
        stats.add(f);
        burst.push_back(f);
    }
    EXPECT_EQ(stats.frames(), frames);
    Mat mean, var;
    stats.mean(mean);
    stats.variance(var);
    Vec2d worst(0, 0);
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 10; ++c) {
            long double m = 0, v = 0;
            for (const Mat& f : burst)
                m += f.at<float>(r, c);
            m /= frames;
            for (const Mat& f : burst)
                v += (f.at<float>(r, c) - m) * (f.at<float>(r, c) - m);
            v /= frames - 1;
            worst[0] = std::max(worst[0], std::abs(mean.at<double>(r, c) - (static_cast<double>(m) - 100)));
            worst[1] = std::max(worst[1], std::abs(var.at<double>(r, c) - static_cast<double>(v)));
        }
    return worst;
}

// A float mosaic's values are checked where the steps read them (augment_steps.hpp): one NaN or Inf anywhere
// must still be an error on every path, at the corners and in the rows a magnification or a shift reads
// no longer, on Bayer and monochrome frames alike.
TEST(NumericalStability, oneNonFiniteValueAnywhereIsAnErrorOfEveryStep)
{
    const NoiseModel model(0.4, 0.5, 2.0);
    NoiseOptions poisson;
    poisson.shotSampling = ShotNoiseSampling::POISSON;
    const Size size(40, 32);
    const Point places[] = {Point(0, 0), Point(39, 31), Point(17, 0), Point(3, 31), Point(21, 15)};
    for (CfaPattern pattern : {CFA_RGGB, CFA_MONO}) {
        RawFormat fmt;
        fmt.pattern = pattern;
        fmt.blackLevel = Vec4d::all(64);
        fmt.whiteLevel = 4095;
        for (float bad : {std::numeric_limits<float>::quiet_NaN(), -std::numeric_limits<float>::infinity()})
            for (const Point at : places) {
                Mat src(size, CV_32FC1, Scalar(900));
                src.at<float>(at) = bad;
                SCOPED_TRACE(
                    cv::format("%s, %g at (%d, %d)", cfaPatternName(pattern).c_str(), bad, at.x, at.y));
                Mat out;
                RawFormat f;
                const ColorJitter darker = ColorJitter::exposureChange(0.5, 2);
                EXPECT_CV_ERROR_CONTAINS(colorJitter(src, fmt, model, darker, NoiseOptions(), 1, out, f),
                                         "NaN or Inf");
                EXPECT_CV_ERROR_CONTAINS(colorJitter(src, fmt, model, darker, poisson, 1, out, f),
                                         "NaN or Inf");
                EXPECT_CV_ERROR_CONTAINS(
                    colorJitter(src, fmt, model, ColorJitter(), NoiseOptions(), 1, out, f), "NaN or Inf");
                EXPECT_CV_ERROR_CONTAINS(
                    motionBlur(src, fmt, model, linearMotionKernel(9, 30, pattern), NoiseOptions(), 1, out),
                    "NaN or Inf");
                EXPECT_CV_ERROR_CONTAINS(
                    motionBlur(src, fmt, model, Mat::ones(1, 1, CV_32F), NoiseOptions(), 1, out),
                    "NaN or Inf");
                for (double scale : {1.3, 0.8, 1.0}) {
                    SCOPED_TRACE(cv::format("scale %g", scale));
                    EXPECT_CV_ERROR_CONTAINS(scaleMosaic(src, fmt, model, scale, NoiseOptions(), 1, out),
                                             "NaN or Inf");
                }
                Scene moved;
                moved.shift = Point(12, -10);
                Scene blurred;
                blurred.motionKernel = linearMotionKernel(9, 0, pattern);
                // Each scene's first step that reads the input checks it: the jitter here, the blur after it
                // unchecked.
                Scene darkBlurred = blurred;
                darkBlurred.jitter = ColorJitter::exposureChange(0.5, 2);
                for (const Scene& scene : {Scene(), moved, blurred, darkBlurred})
                    EXPECT_CV_ERROR_CONTAINS(applyScene(src, fmt, model, scene, 1, out, f), "NaN or Inf");
                EXPECT_CV_ERROR_CONTAINS(RandomScenePolicy().draw(src, fmt, 1), "NaN or Inf");
            }
    }
}

TEST(NumericalStability, burstStatisticsAreExactForLargeMeansAndAnyFrameCount)
{
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(100);
    fmt.whiteLevel = 65535;
    for (int group : {1, 3, 8, 16})
        for (int frames : {2, 7, 8, 13, 100}) {
            SCOPED_TRACE(testing::Message() << "group " << group << ", frames " << frames);
            // Float64 state: errors of order 1e-16 x 60000 on the mean, far below 1e-9.
            const Vec2d exact = burstStatisticsErrorsAtLargeMean(fmt, CV_64F, group, frames);
            EXPECT_LT(exact[0], 1e-9);
            EXPECT_LT(exact[1], 1e-9);
            // The float32 state (a documented knob) rounds the stored mean at every merge: an error
            // uniform in half an ulp of 59900 (2^-8), standard deviation 2^-8 / sqrt(12) = 0.0011, adding
            // up over K merges (the update (1 - w) old + w new hardly damps it): 5 x 0.0011 sqrt(K). That
            // error enters each merge's delta^2 n_a m / n as 2 delta eps m with delta ~ 1 / sqrt(m) (a
            // group mean's spread), of random sign: over K = frames / m merges about 2 sqrt(m) K 0.0011
            // in M2, i.e. 5 x 2 x 0.0011 frames / sqrt(m) / (frames - 1) in the variance (~1% at worst).
            const double rounding = 0.00390625 / std::sqrt(12.0);
            const double merges = std::ceil(static_cast<double>(frames) / group);
            const double m = std::min(group, frames);
            const Vec2d single = burstStatisticsErrorsAtLargeMean(fmt, CV_32F, group, frames);
            EXPECT_LT(single[0], 5 * rounding * std::sqrt(merges));
            EXPECT_LT(single[1], 5 * 2 * rounding * frames / std::sqrt(m) / (frames - 1));
        }
    EXPECT_CV_ERROR_CONTAINS(BurstStatistics(fmt, 0), "groupFrames");
    EXPECT_CV_ERROR_CONTAINS(BurstStatistics(fmt, 257), "groupFrames");
    EXPECT_CV_ERROR_CONTAINS(BurstStatistics stats(fmt, 8, CV_16U), "stateDepth");
    RawFormat badWhite = fmt;
    badWhite.whiteLevel = std::numeric_limits<double>::infinity();
    EXPECT_CV_ERROR_CONTAINS(BurstStatistics stats(badWhite), "whiteLevel"); // and leaks nothing (ASan build)
}

TEST(NumericalStability, burstStatisticsOf16BitFramesAreExactAndTheSameOnEveryPath)
{
    // 16-bit frames take integer lanes (exact sums) and a merge in double lanes; float frames of the same
    // values take the double loops. Both must give the same bits on every path, for both state depths and
    // for groups of 256 frames (the largest: the split sums of d^2 are at their limit) and of 8, on values
    // at the extremes: columns that alternate 0 and 65535 (|d| = 65535 in every frame), stay at 65535, are
    // uniform over the whole range, or are near the white level (4000.5: 4001 is clipped, 4000 is not).
    // Width 45 leaves a partial vector on every path, and 4 rows cover both CFA phases.
    RawFormat fmt;
    fmt.blackLevel = Vec4d(100, 90, 80, 70);
    fmt.whiteLevel = 4000.5;
    const int frames = 300, rows = 4, cols = 45;
    RNG rng(20261126);
    std::vector<Mat> burst16, burst32;
    for (int t = 0; t < frames; ++t) {
        Mat f(rows, cols, CV_16UC1);
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < cols; ++c) {
                int v;
                switch (c % 5) {
                case 0:
                    v = (t + r) % 2 ? 65535 : 0;
                    break;
                case 1:
                    v = 65535;
                    break;
                case 2:
                    v = rng.uniform(0, 65536);
                    break;
                case 3:
                    v = 3995 + rng.uniform(0, 6) * (c > 20 ? 1 : 0);
                    break; // reaches 4000 at most
                default:
                    v = 3996 + rng.uniform(0, 6);
                    break; // reaches 4001
                }
                f.at<ushort>(r, c) = static_cast<ushort>(v);
            }
        burst16.push_back(f);
        Mat g;
        f.convertTo(g, CV_32F);
        burst32.push_back(g);
    }
    for (int depth : {CV_64F, CV_32F})
        for (int group : {256, 8}) {
            SCOPED_TRACE(testing::Message() << "depth " << depth << ", group " << group);
            Mat firstMean, firstVar, firstMask;
            for (CpuPath path : availableCpuPaths()) {
                setCpuPath(path);
                for (const std::vector<Mat>* burst : {&burst16, &burst32}) {
                    BurstStatistics stats(fmt, group, depth);
                    for (const Mat& f : *burst)
                        stats.add(f);
                    Mat mean, var, mask;
                    stats.mean(mean);
                    stats.variance(var);
                    stats.clippedMask(mask);
                    if (firstMean.empty()) {
                        firstMean = mean;
                        firstVar = var;
                        firstMask = mask;
                        continue;
                    }
                    const std::string what =
                        std::string(cpuPathName(path)) + (burst == &burst16 ? ", 16-bit" : ", float");
                    EXPECT_EQ(0, cv::norm(mean, firstMean, NORM_INF)) << what;
                    EXPECT_EQ(0, cv::norm(var, firstVar, NORM_INF)) << what;
                    EXPECT_EQ(0, cv::norm(mask, firstMask, NORM_INF)) << what;
                }
            }
            setCpuPath(CpuPath::AUTO);
            // Against exact integer sums: N S2 - S1^2 is exact in 128 bits, so with the float64 state the
            // variance is exact up to the two merges' double rounding (1e-16 relative, 1e-13 allowed). The
            // float32 state's rounding (burstStatisticsAreExactForLargeMeansAndAnyFrameCount) is the float
            // input's too, which it matched bit for bit above.
            if (depth != CV_64F)
                continue;
            const double tolerance = 1e-13;
            for (int r = 0; r < rows; ++r)
                for (int c = 0; c < cols; ++c) {
                    int64_t s1 = 0;
                    __int128 s2 = 0;
                    int lowest = 65535, highest = 0;
                    for (const Mat& f : burst16) {
                        const int v = f.at<ushort>(r, c);
                        s1 += v;
                        s2 += static_cast<__int128>(v) * v;
                        lowest = std::min(lowest, v);
                        highest = std::max(highest, v);
                    }
                    const double black = fmt.blackLevel[2 * (r & 1) + (c & 1)];
                    const double mean = static_cast<double>(s1) / frames - black;
                    const double variance = static_cast<double>(static_cast<__int128>(frames) * s2 -
                                                                static_cast<__int128>(s1) * s1) /
                                            (static_cast<double>(frames) * (frames - 1));
                    EXPECT_NEAR(firstMean.at<double>(r, c), mean, tolerance * std::max(1.0, std::abs(mean)))
                        << r << ", " << c;
                    EXPECT_NEAR(firstVar.at<double>(r, c), variance, tolerance * std::max(1.0, variance))
                        << r << ", " << c;
                    EXPECT_EQ(firstMask.at<uchar>(r, c), lowest <= 0 || highest >= 4001 ? 255 : 0)
                        << r << ", " << c;
                }
        }
}

// ---------------------------------------------------------------------------------------------------
// Shapiro-Wilk

TEST(NumericalStability, shapiroWilkThreeValuesHaveTheExactPValue)
{
    // Equally spaced values are perfectly normal-looking: W = 1, p = 1.
    ShapiroWilkResult r = shapiroWilk(std::vector<double>{0, 1, 2});
    EXPECT_NEAR(r.W, 1.0, 1e-15);
    EXPECT_NEAR(r.pValue, 1.0, 1e-12);
    // Two equal values and one other: the smallest possible W for n = 3, 3/4, and p = 0.
    r = shapiroWilk(std::vector<double>{5, 5, 9});
    EXPECT_NEAR(r.W, 0.75, 1e-15);
    EXPECT_NEAR(r.pValue, 0.0, 1e-12);
    // In between, p = 6/pi (asin(sqrt(W)) - pi/3) by hand: W of {1, 2, 4} is 27/28.
    r = shapiroWilk(std::vector<double>{4, 1, 2});
    EXPECT_NEAR(r.W, 27.0 / 28.0, 1e-15);
    EXPECT_NEAR(r.pValue, 6 / CV_PI * (std::asin(std::sqrt(27.0 / 28.0)) - CV_PI / 3), 1e-14);
}

TEST(NumericalStability, shapiroWilkNearlyConstantDataWithLargeOffsetKeepsItsDigits)
{
    // A bright pixel: mean 60000, one DN of spread. Centring on the minimum before the sums keeps W
    // equal to that of the spread alone.
    std::vector<double> spread = {0, 1, 1, 2, 0, 1, 3, 1, 2, 1, 0, 2, 1, 1, 2, 1, 0, 1, 2, 1};
    std::vector<double> bright(spread.size());
    for (size_t i = 0; i < spread.size(); ++i)
        bright[i] = 60000 + spread[i];
    EXPECT_EQ(shapiroWilk(bright).W, shapiroWilk(spread).W);
    std::vector<double> tiny(spread.size());
    for (size_t i = 0; i < spread.size(); ++i)
        tiny[i] = 1.0 + spread[i] * 1e-13;
    // 1 + k 1e-13 is exact to ~1e-16 / 1e-13 = 1e-3 of a step: W moves at that scale, not more.
    EXPECT_NEAR(shapiroWilk(tiny).W, shapiroWilk(spread).W, 1e-2);
    EXPECT_FALSE(shapiroWilk(tiny).constant);
}

TEST(NumericalStability, shapiroWilkConstantSampleIsFlaggedAndRejected)
{
    for (int n : {3, 100, 5000}) {
        const ShapiroWilkResult r = shapiroWilk(std::vector<double>(n, 42.0));
        EXPECT_TRUE(r.constant) << n;
        EXPECT_EQ(r.W, 0.0) << n;
        EXPECT_EQ(r.pValue, 0.0) << n;
        EXPECT_EQ(r.n, n);
    }
}

TEST(NumericalStability, shapiroWilkLargestSampleSize)
{
    Mat data(5000, 2, CV_64FC1);
    RNG(3).fill(data, RNG::NORMAL, 200, 15);
    std::vector<ShapiroWilkResult> r;
    shapiroWilkBatch(data, r);
    for (const ShapiroWilkResult& x : r) {
        EXPECT_GT(x.W, 0.99); // normal data of this size: W is within a few 1e-4 of 1
        EXPECT_TRUE(std::isfinite(x.pValue));
        EXPECT_GE(x.pValue, 0.0);
        EXPECT_LE(x.pValue, 1.0);
    }
}

// ---------------------------------------------------------------------------------------------------
// Line and cross-gain fits

std::vector<NoiseSample> linePoints(const std::vector<Point2d>& pts, double gain = 1.0, int dof = 99)
{
    std::vector<NoiseSample> s;
    for (const Point2d& p : pts) {
        NoiseSample n;
        n.mean = p.x;
        n.variance = p.y;
        n.gain = gain;
        n.dof = dof;
        s.push_back(n);
    }
    return s;
}

TEST(NumericalStability, lineFitHardCases)
{
    // Collinear: exact, R^2 = 1, every point an inlier. The fit corrects for the error of each sample's
    // mean, which it takes to have the variance v / (dof + 1); noise-free points have none, and the
    // correction moves their line by about 1/(dof + 1) relative (5e-4 at 99), so they are given 1e9
    // degrees of freedom, where it is below 1e-9.
    const NoiseLineFit exact =
        fitNoiseLine(linePoints({{0, 2}, {10, 7}, {100, 52}, {1000, 502}}, 1.0, 1000000000));
    EXPECT_NEAR(exact.line.a, 0.5, 1e-9);
    EXPECT_NEAR(exact.line.b, 2, 1e-9);
    EXPECT_NEAR(exact.rSquared, 1, 1e-12);
    EXPECT_EQ(exact.inliers, 4);
    // Vertical: one mean only.
    EXPECT_CV_ERROR_CONTAINS(fitNoiseLine(linePoints({{5, 1}, {5, 2}, {5, 3}})), "share one mean");
    // All outliers: no three points on a line; the fit stays finite and says how few agree.
    const NoiseLineFit scattered =
        fitNoiseLine(linePoints({{1, 100}, {2, 1}, {3, 5000}, {4, 3}, {5, 900}, {6, 0.01}, {7, 40000}}));
    EXPECT_TRUE(std::isfinite(scattered.line.a) && std::isfinite(scattered.line.b));
    EXPECT_LT(scattered.inliers, 7);
    // Zero variance everywhere: a flat line at 0, and a calibration that reports its bounds.
    std::vector<NoiseSample> zero = linePoints({{1, 0}, {50, 0}, {900, 0}}, 2.0);
    const std::vector<NoiseSample> zero4 = linePoints({{1, 0}, {50, 0}, {900, 0}}, 4.0);
    zero.insert(zero.end(), zero4.begin(), zero4.end());
    const CalibrationReport flat = calibrateNoiseModel(zero);
    EXPECT_EQ(flat.model.alpha, 0);
    EXPECT_EQ(flat.model.sigmaR2, 0);
    EXPECT_FALSE(flat.notes.empty());
    // Negative slope data: reported as is, with a note.
    std::vector<NoiseSample> falling = linePoints({{0, 100}, {100, 50}, {200, 0.5}}, 2.0);
    const std::vector<NoiseSample> rising = linePoints({{0, 10}, {100, 60}, {200, 110}}, 8.0);
    falling.insert(falling.end(), rising.begin(), rising.end());
    const CalibrationReport neg = calibrateNoiseModel(falling);
    EXPECT_LT(neg.perGain[0].line.a, 0);
    EXPECT_TRUE(std::any_of(neg.notes.begin(), neg.notes.end(), [](const std::string& n) {
        return n.find("negative slope") != std::string::npos;
    }));
    // Bad samples.
    std::vector<NoiseSample> bad = linePoints({{1, 1}, {2, std::numeric_limits<double>::quiet_NaN()}});
    EXPECT_CV_ERROR_CONTAINS(fitNoiseLine(bad), "sample 1 is invalid");
    EXPECT_CV_ERROR_CONTAINS(fitNoiseLine(linePoints({{1, 1}})), "at least 2 samples");
    std::vector<NoiseSample> mixed = linePoints({{1, 1}, {2, 2}});
    mixed[1].gain = 2;
    EXPECT_CV_ERROR_CONTAINS(fitNoiseLine(mixed), "fit one gain at a time");
}

//! Samples of one gain drawn from a model: means uniform in [5, 2500], sample variances of 100 frames
//! (relative spread sqrt(2 / 99)).
std::vector<NoiseSample> samplesOfOneGain(const NoiseModel& model, double gain, int count, uint64 seed)
{
    RNG rng(seed);
    std::vector<NoiseSample> out;
    for (int i = 0; i < count; ++i) {
        NoiseSample s;
        s.gain = gain;
        s.dof = 99;
        s.mean = rng.uniform(5.0, 2500.0);
        s.variance = model.variance(s.mean, gain) * (1 + std::sqrt(2.0 / 99) * rng.gaussian(1.0));
        out.push_back(s);
    }
    return out;
}

TEST(NumericalStability, oneGainReportsAlphaButDoesNotInventReadNoise)
{
    const NoiseModel truth(0.4, 0.5, 2.0 + 1.0 / 12);
    const double g = dbToLinearGain(12);
    const std::vector<NoiseSample> oneGain = samplesOfOneGain(truth, g, 10000, 4);
    const CalibrationReport r = calibrateNoiseModel(oneGain);
    EXPECT_FALSE(r.separable);
    // 10000 samples of 14% relative spread over means 5..2500: the slope's standard error is ~0.2%.
    EXPECT_NEAR(r.model.alpha, truth.alpha, 0.01 * truth.alpha);
    EXPECT_EQ(r.model.sigmaD2, 0.0);
    EXPECT_EQ(r.model.sigmaR2, 0.0);
    ASSERT_EQ(r.perGain.size(), 1u);
    EXPECT_NEAR(r.perGain[0].line.b, truth.lineAtGain(g).b, 0.05 * truth.lineAtGain(g).b);
    ASSERT_FALSE(r.notes.empty());
    EXPECT_NE(r.notes.back().find("not separable"), std::string::npos);

    // Two gains 0.01 dB apart cannot separate the two read noises either.
    std::vector<NoiseSample> close = oneGain;
    const std::vector<NoiseSample> other = samplesOfOneGain(truth, dbToLinearGain(12.01), 10000, 5);
    close.insert(close.end(), other.begin(), other.end());
    const CalibrationReport c = calibrateNoiseModel(close);
    EXPECT_FALSE(c.separable);
    EXPECT_TRUE(std::isfinite(c.model.alpha));
    EXPECT_EQ(c.model.sigmaD2, 0.0);
}

TEST(NumericalStability, sizesLengthsAndShiftsFromArgumentsOrFilesHaveBounds)
{
    // Each used to overflow an int, allocate gigabytes or take many seconds.
    EXPECT_CV_ERROR_CONTAINS(linearMotionKernel(1e300, 0), "must lie in [0, 1024]");
    EXPECT_CV_ERROR_CONTAINS(linearMotionKernel(1e5, 0), "must lie in [0, 1024]");
    EXPECT_EQ(linearMotionKernel(MAX_MOTION_LENGTH, 0).cols, 513);
    RandomScenePolicy policy;
    policy.blurLengthMax = 30000;
    EXPECT_CV_ERROR_CONTAINS(policy.validate(), "blurLengthMax must be <= 1024");

    const Mat mosaic(16, 16, CV_16UC1, Scalar(500));
    RawFormat fmt;
    fmt.whiteLevel = 4095;
    Scene far;
    far.shift = Point(std::numeric_limits<int>::max(), 0);
    Mat out;
    RawFormat outFmt;
    EXPECT_CV_ERROR_CONTAINS(applyScene(mosaic, fmt, NoiseModel(1, 1, 1), far, 1, out, outFmt),
                             "larger than the 16x16 mosaic");

    for (const char* kernel :
         {"{rows: 3, cols: ~, dt: f, data: [1, 1, 1]}", "{rows: 100000, cols: 100000, dt: f, data: [1]}",
          "{rows: 1, cols: 3, dt: f, data: [1]}"}) {
        SCOPED_TRACE(kernel);
        FileStorage fs(std::string("%YAML:1.0\nscene: {contrast: [1, 1, 1, 1], brightness: 0, gain_ratio: 1, "
                                   "motion_kernel: !!opencv-matrix ") +
                           kernel + "}\n",
                       FileStorage::READ | FileStorage::MEMORY);
        EXPECT_CV_ERROR_CONTAINS(Scene::read(fs["scene"]), "'motion_kernel' must be a matrix");
    }

    // 1e-16 DN per electron: 1e19 electrons per pixel do not fit the simulator's exact integers.
    SensorParams tiny;
    tiny.noise = NoiseModel(1e-16, 1, 1);
    const SensorSimulator sensor(tiny, Size(4, 4));
    EXPECT_CV_ERROR_CONTAINS(sensor.capture(Mat(4, 4, CV_32FC1, Scalar(1000)), 1, 1, 1, 0, out),
                             "alpha is too small");
    // In the augmentation such a count is drawn as the Gaussian it is to double precision.
    NoiseOptions poisson;
    poisson.shotSampling = ShotNoiseSampling::POISSON;
    colorJitter(Mat(16, 16, CV_16UC1, Scalar(3000)), fmt, NoiseModel(1e-16, 0.5, 0.5),
                ColorJitter::exposureChange(0.5, 1), poisson, 1, out, outFmt);
    EXPECT_EQ(countNonZero(out == 0), 0);
}

TEST(NumericalStability, extremeValuesAreErrorsOrRightNeverSilentlyWrong)
{
    EXPECT_CV_ERROR_CONTAINS(dbToLinearGain(7000), "outside what a double holds");
    EXPECT_NEAR(dbToLinearGain(-6000), 1e-300, 1e-310);

    RawFormat fmt;
    fmt.whiteLevel = 65535;
    Mat out;
    RawFormat outFmt;
    const Mat flat(8, 8, CV_32FC1, Scalar(1000));
    ColorJitter huge = ColorJitter::exposureChange(1.0, 1e150);
    EXPECT_CV_ERROR_CONTAINS(
        colorJitter(flat, fmt, NoiseModel(1, 1, 1), huge, NoiseAlignment::ACCOUNT_PRIOR, 1, out, outFmt),
        "beyond float range");

    // OpenCV's Bayer conversions return black below 3 pixels a side; the ISP renders every size.
    for (Size size : {Size(2, 2), Size(6, 2), Size(2, 6)}) {
        Mat bgr;
        renderSimpleIsp(Mat(size, CV_16UC1, Scalar(30000)), fmt, bgr, IspParams());
        EXPECT_EQ(bgr.size(), size);
        EXPECT_GT(cv::mean(bgr)[1], 100) << size;
    }

    // DNG holds 16-bit levels and 32-bit rationals: what does not fit is an error, not a wrapped value.
    const std::string dir = test::makeTempDir("stability_dng");
    RawImage image;
    image.mosaic = Mat(64, 64, CV_16UC1, Scalar(100)); // LibRaw reads no smaller DNG
    image.format.whiteLevel = 1e12;
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/white.dng", image), "does not fit 16-bit data");
    image.format.whiteLevel = 65535;
    image.exposureTime = 1e12;
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/exposure.dng", image), "does not fit its DNG tag");
    image.exposureTime = 3000; // beyond the 4294 s that a denominator of 10^6 allows: fewer decimals
    writeDng(dir + "/long.dng", image);
    EXPECT_NEAR(readRaw(dir + "/long.dng").exposureTime, 3000, 1e-3);
}

TEST(NumericalStability, shapiroWilkIsScaleFreeFromDenormalsToTheLargestDoubles)
{
    // W and p do not depend on the scale: the same sample times 2^-1070 (denormal) or 1e300 must give
    // the same numbers (W = 1 and p = 1 before, from an underflowed or overflowed range).
    const std::vector<double> base = {0, 0, 0, 1, 2};
    const ShapiroWilkResult ref = shapiroWilk(base);
    // R 4.2.2: shapiro.test(c(0, 0, 0, 1, 2)) gives W = 0.7709079, p = 0.04595432.
    EXPECT_NEAR(ref.W, 0.7709079, 1e-7);
    EXPECT_NEAR(ref.pValue, 0.04595432, 1e-8);
    for (double scale : {std::ldexp(1.0, -1070), 1e-300, 1e300}) {
        std::vector<double> scaled;
        for (double v : base)
            scaled.push_back(v * scale);
        const ShapiroWilkResult r = shapiroWilk(scaled);
        EXPECT_NEAR(r.W, ref.W, 1e-12) << scale;
        EXPECT_NEAR(r.pValue, ref.pValue, 1e-12) << scale;
    }
    // Both ends at the largest doubles. R 4.2.2 returns NaN for this sample; for the same sample divided
    // by 1e308, shapiro.test(c(-1.7, 0, 1e-308, 1.7)), it gives W = 0.9446643974, p = 0.6829615316.
    const ShapiroWilkResult huge = shapiroWilk(std::vector<double>{-1.7e308, 0, 1, 1.7e308});
    EXPECT_NEAR(huge.W, 0.9446643974, 1e-9);
    EXPECT_NEAR(huge.pValue, 0.6829615316, 1e-9);
}

TEST(NumericalStability, anNdArrayOrAMultichannelKernelIsRefusedByEveryEntryPoint)
{
    // Through cv2, numpy's (1, 1, H, W) arrives as a 4-D Mat, whose rows and cols are -1 and size() 1x1:
    // BurstStatistics read it as 1x1 (undefined data), variance gave one value for four means. A (3, 3, 3)
    // kernel arrives as 3 channels, read interleaved as taps. Each entry point refuses both.
    const int sizes[] = {1, 1, 4, 6};
    const Mat nd16(4, sizes, CV_16UC1, Scalar(100)), nd32(4, sizes, CV_32FC1, Scalar(100));
    const Mat nd64(4, sizes, CV_64FC1, Scalar(100));
    RawFormat format;
    format.whiteLevel = 4095;
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat out;
    RawFormat outFormat;
    const char* const fragment = "has 4 dimensions (1 x 1 x 4 x 6); expected a 2-D matrix";
    BurstStatistics stats(format);
    EXPECT_CV_ERROR_CONTAINS(stats.add(nd16), fragment);
    EXPECT_EQ(0, stats.frames());
    EXPECT_CV_ERROR_CONTAINS(model.variance(nd64, 1.0, out), fragment);
    EXPECT_CV_ERROR_CONTAINS(
        colorJitter(nd16, format, model, ColorJitter(), NoiseOptions(), 1, out, outFormat), fragment);
    EXPECT_CV_ERROR_CONTAINS(
        motionBlur(nd16, format, model, linearMotionKernel(3, 0), NoiseOptions(), 1, out), fragment);
    EXPECT_CV_ERROR_CONTAINS(scaleMosaic(nd16, format, model, 1.1, NoiseOptions(), 1, out), fragment);
    EXPECT_CV_ERROR_CONTAINS(applyScene(nd16, format, model, Scene(), 1, out, outFormat), fragment);
    EXPECT_CV_ERROR_CONTAINS(RandomScenePolicy().draw(nd16, format, 1), fragment);
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(nd64), fragment);
    std::vector<ShapiroWilkResult> results;
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBatch(nd64, results), fragment);
    EXPECT_CV_ERROR_CONTAINS(shapiroWilkBurst(std::vector<Mat>{nd64, nd64, nd64}), fragment);
    std::vector<Mat> planes;
    EXPECT_CV_ERROR_CONTAINS(splitCfaPlanes(nd16, planes), fragment);
    EXPECT_CV_ERROR_CONTAINS(mergeCfaPlanes(std::vector<Mat>(4, nd16), out), fragment);
    EXPECT_CV_ERROR_CONTAINS(subtractBlackLevel(nd16, format, out), fragment);
    EXPECT_CV_ERROR_CONTAINS(packCfaPlanes(nd16, format, out), fragment);
    EXPECT_CV_ERROR_CONTAINS(addBlackLevel(nd32, format, out), fragment);
    EXPECT_CV_ERROR_CONTAINS(applyToneCurve(nd32, out, ToneCurve()), fragment);
    EXPECT_CV_ERROR_CONTAINS(renderSimpleIsp(nd16, format, out), fragment);
    const Mat mosaic(8, 8, CV_16UC1, Scalar(500));
    Mat kernel3(3, 3, CV_64FC3, Scalar::all(1));
    EXPECT_CV_ERROR_CONTAINS(motionBlur(mosaic, format, model, kernel3, NoiseOptions(), 1, out),
                             "motionBlur: kernel has 3 channels; expected a single-channel 2-D kernel");
    const int kernelSizes[] = {1, 3, 3};
    EXPECT_CV_ERROR_CONTAINS(
        motionBlur(mosaic, format, model, Mat(3, kernelSizes, CV_64FC1, Scalar(1)), NoiseOptions(), 1, out),
        "motionBlur: kernel has 3 dimensions");
    EXPECT_CV_ERROR_CONTAINS(shapiroWilk(Mat(5, 1, CV_64FC3, Scalar::all(1))), "3 channels");
    // A hand-made kernel has the bound of a drawn one (2001 x 2001 ran past 30 s on a 64 x 96 mosaic).
    EXPECT_CV_ERROR_CONTAINS(motionBlur(mosaic, format, model,
                                        Mat(1, MAX_MOTION_KERNEL_SIDE + 1, CV_32FC1, Scalar(1)),
                                        NoiseOptions(), 1, out),
                             "a blur kernel is at most 513 plane pixels on a side");
    EXPECT_NO_THROW(motionBlur(mosaic, format, model, Mat(1, MAX_MOTION_KERNEL_SIDE, CV_32FC1, Scalar(1)),
                               NoiseOptions(), 1, out));
}

} // namespace
} // namespace rawgment
} // namespace cv
