// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <functional>
#include <map>
#include <random>

#include "../src/random.hpp"
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/simulate.hpp>

namespace cv {
namespace rawgment {
namespace {

const double kGain = 2.0; // the input bursts' gain (6 dB)
const int kFrames = 64;

//! Eight levels in blocks of 8 columns: 10 to 1800 DN at gain 1, 20 to 3600 DN at kGain.
Mat levelScene(Size size)
{
    const double levels[8] = {10, 30, 80, 200, 400, 800, 1200, 1800};
    Mat m(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c)
        m.col(c).setTo(levels[(c / 8) % 8]);
    return m;
}

//! A burst as CV_32FC1 raw frames (integer DN with black): float output avoids a second rounding.
std::vector<Mat> floatBurst(const SensorSimulator& sensor, const Mat& mean, uint64 seed)
{
    std::vector<Mat> raws;
    sensor.captureBurst(mean, kGain, 1.0, kFrames, seed, raws);
    for (Mat& f : raws)
        f.convertTo(f, CV_32F);
    return raws;
}

//! Per-pixel temporal mean and unbiased variance (black-subtracted) of a float burst.
void temporalStats(const std::vector<Mat>& burst, const RawFormat& fmt, Mat& mean, Mat& var)
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
void statsAfterStep(const std::vector<Mat>& burst, const RawFormat& fmt, Step step, Mat& mean, Mat& var)
{
    std::vector<Mat> out(burst.size());
    for (size_t t = 0; t < burst.size(); ++t)
        step(burst[t], static_cast<int>(t), out[t]);
    temporalStats(out, fmt, mean, var);
}

//! Average of a per-pixel map over the 8-column block b, leaving out `margin` columns at its sides.
double blockAverage(const Mat& m, int b, int margin = 0)
{
    return cv::mean(m(Rect(8 * b + margin, 0, 8 - 2 * margin, m.rows)))[0];
}

TEST(Augment, exposureChangeMatchesTheModelOnlyWhenThePriorIsAccounted)
{
    const Size size(64, 32);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const std::vector<Mat> bright = floatBurst(sensor, levelScene(size), 5);
    // A block averages 256 per-pixel variances of 64 frames: relative standard error
    // sqrt(2 / 63) / sqrt(256) = 1.1%; 5 standard errors = 5.6%.
    const double tolerance = 5 * std::sqrt(2.0 / (kFrames - 1)) / std::sqrt(256.0);
    for (double factor : {0.5, 0.1}) {
        double ratio[3][8];
        for (NoiseAlignment mode : kAllAlignments) {
            RawFormat outFmt;
            Mat mean, var;
            statsAfterStep(
                bright, fmt,
                [&](const Mat& frame, int t, Mat& out) {
                    colorJitter(frame, fmt, model, ColorJitter::exposureChange(factor, 1.0), mode, 1000 + t,
                                out, outFmt);
                },
                mean, var);
            EXPECT_EQ(outFmt.gain, kGain);
            EXPECT_EQ(outFmt.blackLevel, fmt.blackLevel);
            for (int b = 0; b < 8; ++b) {
                const double m = blockAverage(mean, b);
                ratio[static_cast<int>(mode)][b] = blockAverage(var, b) / model.variance(m, kGain);
            }
        }
        for (int b = 0; b < 8; ++b) {
            SCOPED_TRACE(testing::Message() << "x" << factor << ", level block " << b);
            EXPECT_NEAR(ratio[2][b], 1.0, tolerance) << "ACCOUNT_PRIOR";
            EXPECT_LT(ratio[0][b], 1.0 - tolerance) << "NONE keeps only the scaled prior noise";
            // The prior noise matters where f^2 v_in is a sizeable part of the target.
            if (factor == 0.5 || b >= 4) {
                EXPECT_GT(ratio[1][b], 1.0 + tolerance) << "IGNORE_PRIOR adds the target on top of the prior";
            }
        }
        std::cout << "x" << factor << " variance / model, brightest block: NONE " << ratio[0][7]
                  << ", IGNORE_PRIOR " << ratio[1][7] << ", ACCOUNT_PRIOR " << ratio[2][7] << "\n";
    }
}

/* A sensor whose measured lines leave Eq. 5 (0.4, 0.5, 2.0) by 15-30% at gains 2 and 4 (a digitally
 * scaled setting does that): the simulator draws the lines, and an exposure change to another gain adds
 * what the target gain's own line lacks, not what Eq. 5 would. */
SensorParams measuredLinesSensor()
{
    SensorParams p = test::referenceSensorParams();
    const double lines[4][3] = {{1, 0.4, 2.6}, {2, 0.68, 4.5}, {4, 2.08, 12.0}, {8, 3.2, 34.0}};
    for (const auto& l : lines) {
        MeasuredNoiseLine m;
        m.gain = l[0];
        m.line.a = l[1];
        m.line.b = l[2];
        p.noise.measuredLines.push_back(m);
    }
    return p;
}

TEST(Augment, measuredLinesAreFollowedAtTheSourceAndTargetGains)
{
    const Size size(64, 32);
    const SensorSimulator sensor(measuredLinesSensor(), size);
    const NoiseModel model = sensor.effectiveModel();
    NoiseModel eq5 = model;
    eq5.measuredLines.clear();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const std::vector<Mat> bright = floatBurst(sensor, levelScene(size), 11);
    // As in exposureChangeMatchesTheModelOnlyWhenThePriorIsAccounted: 5 standard errors of a block's
    // mean variance are 5.6%; the lines leave Eq. 5 by 15% or more at gains 2, 3 and 4, so a step that
    // followed Eq. 5 fails.
    const double tolerance = 5 * std::sqrt(2.0 / (kFrames - 1)) / std::sqrt(256.0);
    Mat brightMean, brightVar;
    temporalStats(bright, fmt, brightMean, brightVar);
    for (int b = 1; b < 8; ++b) {
        const double m = blockAverage(brightMean, b);
        EXPECT_NEAR(blockAverage(brightVar, b) / model.variance(m, kGain), 1.0, tolerance)
            << "the simulator draws the measured line, block " << b;
    }
    struct Case
    {
        double gainRatio;
        NoiseAlignment alignment;
        ShotNoiseSampling sampling;
        double brightness; // not 0: Eq. 13 per pixel instead of the line per site
    };
    const Case cases[] = {{2.0, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::GAUSSIAN, 0.0},
                          {1.5, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::GAUSSIAN, 0.0},
                          {2.0, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::GAUSSIAN, 40.0},
                          {2.0, NoiseAlignment::ACCOUNT_PRIOR, ShotNoiseSampling::POISSON, 0.0},
                          {2.0, NoiseAlignment::IGNORE_PRIOR, ShotNoiseSampling::GAUSSIAN, 0.0}};
    for (const Case& c : cases) {
        const double outGain = kGain * c.gainRatio, factor = 0.5;
        NoiseOptions noise;
        noise.alignment = c.alignment;
        noise.shotSampling = c.sampling;
        Mat mean, var;
        statsAfterStep(
            bright, fmt,
            [&](const Mat& frame, int t, Mat& out) {
                RawFormat outFmt;
                ColorJitter jitter = ColorJitter::exposureChange(factor, c.gainRatio);
                jitter.brightness = c.brightness;
                colorJitter(frame, fmt, model, jitter, noise, 2000 + t, out, outFmt);
            },
            mean, var);
        for (int b = 1; b < 8; ++b) {
            SCOPED_TRACE(testing::Message()
                         << "gain ratio " << c.gainRatio << ", alignment " << static_cast<int>(c.alignment)
                         << ", sampling " << static_cast<int>(c.sampling) << ", brightness " << c.brightness
                         << ", block " << b);
            const double m = blockAverage(mean, b), v = blockAverage(var, b);
            const double contrast = factor * c.gainRatio, in = (m - c.brightness) / contrast;
            const double prior = contrast * contrast * model.variance(in, kGain);
            double expected = model.variance(m, outGain);
            // IGNORE_PRIOR adds the target's line on top of the prior scaled by the contrast squared.
            if (c.alignment == NoiseAlignment::IGNORE_PRIOR)
                expected += prior;
            // Eq. 13 takes a brightness as light (the prior scaled by (p_u p_g)^2 = (m / in)^2), but an
            // offset leaves the prior's noise as it is (contrast^2): the difference stays, as with Eq. 5.
            // Blocks from 800 DN: there the noisy value's spread moves E[(p_u p_g)^2] by under 1%.
            if (c.brightness != 0) {
                if (b < 4)
                    continue;
                expected += prior - (m / in) * (m / in) * model.variance(in, kGain);
            }
            EXPECT_NEAR(v / expected, 1.0, tolerance);
            if (b >= 4 && c.alignment == NoiseAlignment::ACCOUNT_PRIOR) {
                EXPECT_GT(std::abs(v / eq5.variance(m, outGain) - 1), tolerance) << "Eq. 5 would pass too";
            }
        }
    }
}

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

TEST(Augment, scaleKeepsTheModelVarianceAtEveryInterpolationPosition)
{
    const Size size(128, 128);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const NoiseLine line = model.lineAtGain(kGain);
    // A horizontal ramp: the model variance is linear in the mean, so a bilinear mix of truly noisy
    // pixels must have exactly the model variance at the mixed mean (Eq. 15 with interpolation weights).
    Mat scene(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c)
        scene.col(c).setTo(50.0 + 12.0 * c);
    const std::vector<Mat> burst = floatBurst(sensor, scene, 21);
    for (double scale : {1.03, 0.97}) {
        double worstNone = 1;
        for (NoiseAlignment mode : kAllAlignments) {
            Mat mean, var;
            statsAfterStep(
                burst, fmt,
                [&](const Mat& frame, int t, Mat& out) {
                    scaleMosaic(frame, fmt, model, scale, mode, 900 + t, out);
                },
                mean, var);
            const Mat expected = line.a * mean + line.b;
            double total = 0;
            // Columns away from the left/right edges, where replication makes constant patches.
            for (int c = 8; c < size.width - 8; ++c) {
                const double ratio = cv::mean(var.col(c))[0] / cv::mean(expected.col(c))[0];
                total += ratio;
                if (mode == NoiseAlignment::NONE)
                    worstNone = std::min(worstNone, ratio);
                // A column averages 128 variances of 64 frames (relative standard error sqrt(2/63) =
                // 17.8% each); neighbouring rows share source rows, so count 64 independent ones:
                // 2.2%, and 5 of them is 11%.
                if (mode == NoiseAlignment::ACCOUNT_PRIOR) {
                    EXPECT_NEAR(ratio, 1.0, 0.11) << "scale " << scale << ", column " << c;
                }
            }
            const double average = total / (size.width - 16);
            std::cout << "scale " << scale << ", mode " << static_cast<int>(mode)
                      << ": variance / model, average over columns " << average << "\n";
            if (mode == NoiseAlignment::ACCOUNT_PRIOR) { // ~14,000 pixels, half independent: 0.8% s.e.
                EXPECT_NEAR(average, 1.0, 0.04);
            }
            if (mode == NoiseAlignment::IGNORE_PRIOR) { // the prior noise is counted twice
                EXPECT_GT(average, 1.1);
            }
        }
        // Halfway between two pixels in both directions a bilinear mix keeps a quarter of the
        // variance; columns at x fraction 0.5 keep at most half: plain resampling is far too clean.
        EXPECT_LT(worstNone, 0.75) << "scale " << scale;
    }
}

TEST(Augment, boxesAreCheckedAndClippedOnEveryPath)
{
    // A box outside the frame came back unchanged from an identity or jitter-only scene, and with scale
    // 1.1 a box of negative size became a real 21x10 box; scaleBox took a NaN scale to int.
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    const Mat src(32, 48, CV_16UC1, Scalar(500));
    Mat out;
    RawFormat f;
    Scene jitterOnly;
    jitterOnly.jitter.brightness = 1;
    for (const Scene& scene : {Scene(), jitterOnly}) {
        std::vector<Rect> boxes = {Rect(40, 20, 20, 20), Rect(100, 100, 5, 5), Rect(-4, -4, 8, 8)};
        applyScene(src, fmt, model, scene, 1, out, f, nullptr, &boxes);
        EXPECT_EQ(boxes[0], Rect(40, 20, 8, 12));
        EXPECT_EQ(boxes[1].area(), 0);
        EXPECT_EQ(boxes[2], Rect(0, 0, 4, 4));
    }
    Scene scaled;
    scaled.scale = 1.1;
    for (const Scene& scene : {Scene(), scaled}) {
        std::vector<Rect> boxes = {Rect(4, 4, 8, 8), Rect(10, 10, -21, 10)};
        EXPECT_CV_ERROR_CONTAINS(applyScene(src, fmt, model, scene, 1, out, f, nullptr, &boxes),
                                 "applyScene: box 1 (10, 10, -21 x 10) has a negative size");
    }
    for (double scale :
         {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 0.0, -1.0})
        EXPECT_CV_ERROR_CONTAINS(scaleBox(Rect(1, 1, 2, 2), Size(8, 8), scale),
                                 "scale must be finite and > 0");
    EXPECT_CV_ERROR_CONTAINS(scaleBox(Rect(1, 1, -2, 2), Size(8, 8), 1.5), "negative size");
    // Edges far beyond the frame are clipped before they become ints.
    EXPECT_EQ(scaleBox(Rect(0, 0, 8, 8), Size(8, 8), 1e300), Rect(0, 0, 8, 8));
    EXPECT_EQ(scaleBox(Rect(0, 0, 1, 1), Size(8, 8), 1e300).area(), 0);
}

TEST(Augment, scaleMovesBoxesKeepsThePhaseAndSkipsTheIdentity)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat src(64, 64, CV_16UC1);
    for (int r = 0; r < 64; ++r)
        for (int c = 0; c < 64; ++c)
            src.at<ushort>(r, c) = static_cast<ushort>(300 + 800 * cfaSite(r, c));
    Mat out;
    scaleMosaic(src, fmt, model, 1.0, NoiseAlignment::ACCOUNT_PRIOR, 1, out);
    EXPECT_EQ(out.data, src.data);
    // Each site resamples only its own plane: a constant plane stays constant (NONE adds no noise).
    scaleMosaic(src, fmt, model, 1.03, NoiseAlignment::NONE, 1, out);
    EXPECT_EQ(norm(out, src, NORM_INF), 0);
    // Boxes: the centre is fixed, edges scale about it, the result grows to whole pixels.
    EXPECT_EQ(scaleBox(Rect(16, 16, 32, 32), Size(64, 64), 1.5), Rect(8, 8, 48, 48));
    EXPECT_EQ(scaleBox(Rect(0, 0, 10, 10), Size(64, 64), 2.0).area(), 0); // pushed out of the frame
    EXPECT_EQ(scaleBox(Rect(30, 30, 4, 4), Size(64, 64), 0.5), Rect(31, 31, 2, 2));
    Scene scene;
    scene.scale = 2.0;
    std::vector<Rect> boxes = {Rect(16, 16, 32, 32)};
    RawFormat f;
    AugmentReport report;
    applyScene(src, fmt, model, scene, 3, out, f, &report, &boxes);
    EXPECT_EQ(boxes[0], Rect(0, 0, 64, 64));
    ASSERT_EQ(report.steps.size(), 1u);
    EXPECT_EQ(report.steps[0], "scale");
    EXPECT_CV_ERROR_CONTAINS(scaleMosaic(src, fmt, model, 0, NoiseAlignment::NONE, 1, out), "scale");
    EXPECT_CV_ERROR_CONTAINS(
        scaleMosaic(src, fmt, model, std::numeric_limits<double>::quiet_NaN(), NoiseAlignment::NONE, 1, out),
        "scale");
    EXPECT_CV_ERROR_CONTAINS(
        scaleMosaic(src(Rect(0, 0, 63, 64)), fmt, model, 1.1, NoiseAlignment::NONE, 1, out),
        "both sides must be even");
}

TEST(Augment, gainTravelsFromJitterToBlur)
{
    // Fewer photons x4 at four times the gain: same mean, noisier. The blur that follows must use the
    // new gain, or the result would have the variance of the old gain.
    const Size size(64, 64);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const std::vector<Mat> burst = floatBurst(sensor, Mat(size, CV_32FC1, Scalar(300)), 13);
    Scene scene;
    scene.jitter = ColorJitter::exposureChange(0.25, 4.0);
    scene.motionKernel = linearMotionKernel(9, 30);
    std::vector<Mat> out(kFrames);
    RawFormat outFmt;
    for (int t = 0; t < kFrames; ++t)
        applyScene(burst[t], fmt, model, scene, 40 + t, out[t], outFmt);
    EXPECT_DOUBLE_EQ(outFmt.gain, 4 * kGain);
    Mat mean, var;
    temporalStats(out, outFmt, mean, var);
    const double m = cv::mean(mean)[0], v = cv::mean(var)[0];
    EXPECT_NEAR(m, 600, 2);
    // 4096 pixels of 64 frames, but the blur correlates neighbours; 5% is still over 5 standard errors
    // even if only a quarter of the pixels were independent. The old gain would give 0.42 of this.
    EXPECT_NEAR(v / model.variance(m, 4 * kGain), 1.0, 0.05);
}

Mat smallMosaic(int type = CV_16UC1)
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

// The sensor with every dark-frame component (test_common.hpp), lambda -0.1, unquantised: the float
// augmentation and the capture then compare in their statistics without 1/12 DN^2 of rounding on one
// side only.
SensorParams darkComponentSensor(Size size)
{
    SensorParams p = test::darkComponentSensorParams(size, -0.1, 19);
    p.quantize = false;
    return p;
}

//! A noiseless CV_32FC1 capture of a flat scene `level` DN above black, carrying the sensor's `pattern`.
Mat flatWithPattern(const RawFormat& fmt, const Mat& pattern, double level)
{
    Mat flat(pattern.size(), CV_32FC1);
    for (int r = 0; r < flat.rows; ++r)
        for (int c = 0; c < flat.cols; ++c)
            flat.at<float>(r, c) = static_cast<float>(fmt.blackAt(r, c) + level) + pattern.at<float>(r, c);
    return flat;
}

TEST(Augment, aShiftKeepsTheSensorsDarkShadingWhereTheSensorHasIt)
{
    // applyScene shifted the dark-shading pattern together with the content: on a noiseless flat input
    // carrying the pattern, a shift of (8, 6) changed the output by the pattern's own difference
    // S(x - d) - S(x), where 0 is right because the pattern belongs to the sensor.
    const Size size(96, 64);
    const NoiseModel model = darkComponentSensor(size).noise;
    ASSERT_TRUE(model.hasDarkShading());
    const RawFormat fmt = SensorSimulator(darkComponentSensor(size), size).rawFormat(kGain);
    const Mat pattern = model.darkShadingAt(kGain);
    const Mat flat = flatWithPattern(fmt, pattern, 500);
    const Rect inside(8, 6, size.width - 8, size.height - 6);
    const double patternMove =
        norm(pattern(inside - Point(8, 6)), pattern(inside), NORM_L2) / std::sqrt(double(inside.area()));
    ASSERT_GT(patternMove, 1.0) << "the test needs a pattern that a shift visibly moves";
    Scene shifted;
    shifted.shift = Point(8, 6);
    Mat out;
    RawFormat outFmt;
    applyScene(flat, fmt, model, shifted, 3, out, outFmt);
    // Float arithmetic of values below 2^12: a few ulps.
    EXPECT_LT(norm(out, flat, NORM_INF), 1e-3) << "the pattern moved by " << patternMove << " DN RMS";
    // An integer mosaic is rounded once more: within 1 DN, and a pixel differs (by 1) with probability
    // E|rounding error| = 1/4, so the RMS is 0.5 on average; 4 standard errors of that share over 6144
    // pixels (0.0055 each) allow 0.53.
    Mat flat16, out16, diff;
    flat.convertTo(flat16, CV_16U);
    applyScene(flat16, fmt, model, shifted, 3, out16, outFmt);
    absdiff(out16, flat16, diff);
    EXPECT_LE(norm(diff, NORM_INF), 1);
    EXPECT_LE(norm(diff, NORM_L2) / std::sqrt(double(diff.total())), 0.53);
    // Shifted and darkened x0.5: over 24 seeds the mean output is the darker content plus the sensor's
    // pattern in place; its residual is the mean's noise alone, below 1.5 sqrt(target variance / 24) RMS
    // (the target's variance bounds what ACCOUNT_PRIOR adds to a noiseless input; 1.5 leaves room for the
    // RMS over only 6144 pixels).
    shifted.jitter = ColorJitter::exposureChange(0.5, 1);
    const int seeds = 24;
    Mat sum = Mat::zeros(size, CV_64FC1);
    for (int seed = 0; seed < seeds; ++seed) {
        applyScene(flat, fmt, model, shifted, uint64(seed), out, outFmt);
        accumulate(out, sum);
    }
    Mat expected(size, CV_64FC1);
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c)
            expected.at<double>(r, c) = fmt.blackAt(r, c) + 250 + pattern.at<float>(r, c);
    const double residual = norm(sum / seeds, expected, NORM_L2) / std::sqrt(double(size.area()));
    const double noise = std::sqrt((model.variance(250, kGain) + model.rowVariance(kGain)) / seeds);
    EXPECT_LT(residual, 1.5 * noise) << "pattern move " << patternMove;
}

TEST(Augment, aCropReadsTheDarkShadingOfItsOwnPixelsAtItsSensorOrigin)
{
    // A model with maps worked only on whole frames ("the mosaic must be a whole frame"). A crop now carries
    // its offset (RawFormat::sensorOrigin, set by cropped()) and every step reads the maps there.
    const Size size(96, 64);
    const NoiseModel model = darkComponentSensor(size).noise;
    const RawFormat fmt = SensorSimulator(darkComponentSensor(size), size).rawFormat(kGain);
    const Mat pattern = model.darkShadingAt(kGain);
    const Mat flat = flatWithPattern(fmt, pattern, 500);
    const Rect crop(10, 6, 48, 40); // an odd row offset and an even column offset: another CFA phase too
    const RawFormat cropFmt = fmt.cropped(crop.y, crop.x);
    EXPECT_EQ(Point(10, 6), cropFmt.sensorOrigin);
    // A shift of the crop keeps its own pattern in place, exactly as on the whole frame.
    Scene shifted;
    shifted.shift = Point(4, -2);
    Mat out;
    RawFormat outFmt;
    applyScene(flat(crop), cropFmt, model, shifted, 3, out, outFmt);
    EXPECT_LT(norm(out, flat(crop), NORM_INF), 1e-3);
    EXPECT_EQ(cropFmt.sensorOrigin, outFmt.sensorOrigin);
    // Darkened x0.5 over 24 seeds: the crop's mean is the darker content plus its own pixels' pattern
    // (tolerance as in aShiftKeepsTheSensorsDarkShadingWhereTheSensorHasIt); read at the origin (0, 0) the
    // pattern would be off by its own RMS difference.
    const int seeds = 24;
    Mat sum = Mat::zeros(crop.size(), CV_64FC1);
    for (int seed = 0; seed < seeds; ++seed) {
        colorJitter(flat(crop), cropFmt, model, ColorJitter::exposureChange(0.5, 1), NoiseOptions(),
                    uint64(seed), out, outFmt);
        accumulate(out, sum);
    }
    Mat expected(crop.size(), CV_64FC1);
    for (int r = 0; r < crop.height; ++r)
        for (int c = 0; c < crop.width; ++c)
            expected.at<double>(r, c) =
                fmt.blackAt(r + crop.y, c + crop.x) + 250 + pattern.at<float>(r + crop.y, c + crop.x);
    const double residual = norm(sum / seeds, expected, NORM_L2) / std::sqrt(double(crop.area()));
    const double noise = std::sqrt((model.variance(250, kGain) + model.rowVariance(kGain)) / seeds);
    EXPECT_LT(residual, 1.5 * noise);
    // Blur and scale read the maps at the origin too (they refused any crop before), and a crop that does
    // not lie inside the maps is an error naming the sizes and the origin.
    EXPECT_NO_THROW(motionBlur(flat(crop), cropFmt, model, linearMotionKernel(5, 0), NoiseOptions(), 1, out));
    EXPECT_NO_THROW(scaleMosaic(flat(crop), cropFmt, model, 1.05, NoiseOptions(), 1, out));
    RawFormat outside = cropFmt;
    outside.sensorOrigin = Point(60, 30);
    EXPECT_CV_ERROR_CONTAINS(colorJitter(flat(crop), outside, model, ColorJitter::exposureChange(0.5, 1),
                                         NoiseOptions(), 1, out, outFmt),
                             "colorJitter: the model's dark shading is 96x64 but the mosaic 48x40 at sensor "
                             "origin (60, 30) does not "
                             "lie inside it");
    RawFormat negative = cropFmt;
    negative.sensorOrigin = Point(-2, 0);
    EXPECT_CV_ERROR_CONTAINS(negative.validate(), "RawFormat.sensorOrigin must be >= 0 (got (-2, 0))");
}

TEST(Augment, sameSeedSameBitsOnAnyThreadCount)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel plain(0.4, 0.5, 2.0);
    // With every dark-frame component too: the row draws and the Tukey uniforms are per row as well.
    NoiseModel dark = darkComponentSensor(Size(300, 200)).noise;
    dark.alpha = plain.alpha;
    for (const NoiseModel& model : {plain, dark}) {
        Mat src(200, 300, CV_16UC1);
        RNG(1).fill(src, RNG::UNIFORM, 256, 3000);
        Scene scene;
        scene.jitter.contrast = Vec4d(0.3, 0.25, 0.25, 0.35);
        scene.jitter.gainRatio = 2;
        scene.motionKernel = linearMotionKernel(11, 45);
        scene.shift = Point(6, -4);
        scene.scale = 1.02;
        const Mat original = src.clone();
        const int saved = getNumThreads();
        // The paper's knobs and the other settings: Poisson draws and local means are per row too.
        NoiseOptions knobs;
        knobs.shotSampling = ShotNoiseSampling::POISSON;
        knobs.priorMean = PriorMeanEstimate::LOCAL_MEAN;
        knobs.blurNoiseSum = BlurNoiseSum::FROM_BLURRED_MEAN;
        for (const NoiseOptions& noise : {NoiseOptions(), knobs}) {
            scene.noise = noise;
            std::vector<Mat> outs;
            for (int threads : {1, 2, 8}) {
                setNumThreads(threads);
                Mat out;
                RawFormat f;
                applyScene(src, fmt, model, scene, 99, out, f);
                outs.push_back(out);
            }
            setNumThreads(saved);
            EXPECT_EQ(norm(src, original, NORM_INF), 0) << "the input was written to";
            EXPECT_EQ(norm(outs[0], outs[1], NORM_INF), 0);
            EXPECT_EQ(norm(outs[0], outs[2], NORM_INF), 0);
        }
        scene.noise = NoiseOptions();
        Mat first, second;
        RawFormat f;
        applyScene(src, fmt, model, scene, 99, first, f);
        applyScene(src, fmt, model, scene, 100, second, f);
        EXPECT_GT(norm(first, second, NORM_L1), 0) << "another seed, other noise";
    }
}

TEST(Augment, anAbsentComponentChangesNoBitAndBrighteningWithComponentsIsClippedAndCounted)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel plain(0.4, 0.5, 2.0);
    Mat src(64, 96, CV_16UC1);
    RNG(2).fill(src, RNG::UNIFORM, 256, 3000);
    // Components present but zero (no rows: both variances 0) are absent: the same bits as the plain model.
    NoiseModel zeroRows = plain;
    zeroRows.rowSigmaD2 = zeroRows.rowSigmaR2 = 0;
    ASSERT_FALSE(zeroRows.hasDarkComponents());
    const ColorJitter jitter = ColorJitter::exposureChange(0.2, 2);
    Mat a, b;
    RawFormat f;
    colorJitter(src, fmt, plain, jitter, NoiseOptions(), 5, a, f);
    colorJitter(src, fmt, zeroRows, jitter, NoiseOptions(), 5, b, f);
    EXPECT_EQ(0, norm(a, b, NORM_INF));
    // Brightening x4 with every component: no NaN, values in range, the brightening pixels counted.
    NoiseModel dark = darkComponentSensor(src.size()).noise;
    Mat srcFloat, out;
    src.convertTo(srcFloat, CV_32F);
    for (const Mat& input : {src, srcFloat}) {
        AugmentReport report;
        colorJitter(input, fmt, dark, ColorJitter::exposureChange(4, 1), NoiseOptions(), 6, out, f, &report);
        EXPECT_GT(report.brighteningPixels, 0);
        Mat asFloat;
        out.convertTo(asFloat, CV_32F);
        EXPECT_EQ(0, test::countNonFinite(asFloat));
        double lo, hi;
        minMaxLoc(asFloat, &lo, &hi);
        EXPECT_GE(lo, 0);
        EXPECT_LE(hi, fmt.whiteLevel);
        for (const char* step : {"blur", "scale"}) {
            Mat resampled;
            if (std::string(step) == "blur")
                motionBlur(input, fmt, dark, linearMotionKernel(9, 10), NoiseOptions(), 7, resampled);
            else
                scaleMosaic(input, fmt, dark, 1.1, NoiseOptions(), 7, resampled);
            resampled.convertTo(asFloat, CV_32F);
            EXPECT_EQ(0, test::countNonFinite(asFloat)) << step;
        }
    }
    // A model whose maps are of a smaller sensor than the mosaic is an error naming both sizes (a crop
    // inside them is read at its origin: aCropReadsTheDarkShadingOfItsOwnPixelsAtItsSensorOrigin).
    Mat big(128, 96, src.type(), Scalar(300));
    EXPECT_CV_ERROR_CONTAINS(
        colorJitter(big, fmt, dark, jitter, NoiseOptions(), 5, out, f),
        "the model's dark shading is 96x64 but the mosaic 96x128 at sensor origin (0, 0)");
    EXPECT_CV_ERROR_CONTAINS(motionBlur(big, fmt, dark, linearMotionKernel(9, 10), NoiseOptions(), 7, out),
                             "the model's dark shading is 96x64");
    // A map value that is not finite is an error, never a NaN output.
    NoiseModel bad = dark;
    bad.darkShadingPerGain = dark.darkShadingPerGain.clone();
    bad.darkShadingPerGain.at<float>(40, 17) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(colorJitter(src, fmt, bad, jitter, NoiseOptions(), 5, out, f),
                             "colorJitter: the model's dark shading contains NaN or Inf");
    EXPECT_CV_ERROR_CONTAINS(motionBlur(src, fmt, bad, linearMotionKernel(9, 10), NoiseOptions(), 7, out),
                             "motionBlur: the model's dark shading contains NaN or Inf");
    EXPECT_CV_ERROR_CONTAINS(scaleMosaic(src, fmt, bad, 1.1, NoiseAlignment::IGNORE_PRIOR, 7, out),
                             "scaleMosaic: the model's dark shading contains NaN or Inf");
    // Without noise (NONE) the maps are not used, so any size goes.
    EXPECT_NO_THROW(colorJitter(big, fmt, dark, jitter, NoiseAlignment::NONE, 5, out, f));
}

TEST(Augment, identityStepsAreSkippedAndReturnTheInputItself)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    const Mat src = smallMosaic();
    Mat out;
    RawFormat outFmt;
    AugmentReport report;
    applyScene(src, fmt, model, Scene(), 1, out, outFmt, &report);
    EXPECT_EQ(out.data, src.data); // no copy
    EXPECT_TRUE(report.steps.empty());
    EXPECT_TRUE(report.stepSeconds.empty());
    EXPECT_EQ(outFmt.gain, fmt.gain);
    // Every step that runs is named and timed, in order.
    Scene all;
    all.shift = Point(2, 4);
    all.scale = 1.02;
    all.jitter = ColorJitter::exposureChange(0.5, 2);
    all.motionKernel = linearMotionKernel(5, 30);
    const Mat big(64, 48, CV_16UC1, Scalar(900));
    AugmentReport timed;
    applyScene(big, fmt, model, all, 1, out, outFmt, &timed);
    EXPECT_EQ(timed.steps, (std::vector<std::string>{"shift", "scale", "colorJitter", "motionBlur"}));
    ASSERT_EQ(timed.stepSeconds.size(), timed.steps.size());
    for (double seconds : timed.stepSeconds)
        EXPECT_TRUE(seconds >= 0 && seconds < 60) << seconds;
    Scene identityKernel;
    identityKernel.motionKernel = linearMotionKernel(1.0, 30); // length 0 or 1: identity
    EXPECT_TRUE(identityKernel.isIdentity());
    EXPECT_TRUE(linearMotionKernel(0, 0).total() == 1);
    motionBlur(src, fmt, model, linearMotionKernel(2, 0), NoiseAlignment::ACCOUNT_PRIOR, 1, out);
    EXPECT_EQ(out.data, src.data);
}

TEST(Augment, stepsWriteIntoTheCallersBufferButNeverIntoTheirInput)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    const Mat kernel = linearMotionKernel(5, 30);
    typedef std::function<void(const Mat&, Mat&)> Step;
    const std::vector<std::pair<const char*, Step>> steps = {
        {"colorJitter",
         [&](const Mat& in, Mat& out) {
             RawFormat f;
             colorJitter(in, fmt, model, ColorJitter::exposureChange(0.5, 2), NoiseOptions(), 3, out, f);
         }},
        {"motionBlur",
         [&](const Mat& in, Mat& out) { motionBlur(in, fmt, model, kernel, NoiseOptions(), 3, out); }},
        {"scaleMosaic",
         [&](const Mat& in, Mat& out) { scaleMosaic(in, fmt, model, 1.1, NoiseOptions(), 3, out); }}};
    for (const auto& step : steps) {
        Mat big(40, 48, CV_16UC1);
        randu(big, 300, 3000);
        const Mat original = big.clone();
        const Mat src = big(Rect(8, 4, 32, 24));
        Mat expected;
        step.second(src, expected);
        // A buffer of the right size and type is written in place, with the same result.
        Mat reused(src.size(), src.type(), Scalar(7));
        const uchar* buffer = reused.data;
        step.second(src, reused);
        EXPECT_EQ(reused.data, buffer) << step.first;
        EXPECT_EQ(0, norm(reused, expected, NORM_INF)) << step.first;
        // The input as output, or a view that overlaps it: a new Mat, the input untouched.
        Mat same = src;
        step.second(src, same);
        EXPECT_NE(same.data, src.data) << step.first;
        EXPECT_EQ(0, norm(same, expected, NORM_INF)) << step.first;
        Mat overlapping = big(Rect(10, 6, 32, 24));
        step.second(src, overlapping);
        EXPECT_EQ(0, norm(overlapping, expected, NORM_INF)) << step.first;
        EXPECT_EQ(0, norm(big, original, NORM_INF)) << step.first << " wrote into its input";
        // A buffer of another size or type is replaced.
        Mat wrongType(src.size(), CV_32FC1);
        step.second(src, wrongType);
        EXPECT_EQ(wrongType.type(), CV_16UC1) << step.first;
    }
}

//! colorJitter's exposure change by photonRatio (the gain unchanged) with the shot noise drawn by `sampling`
//! and the other noise options at their defaults (ACCOUNT_PRIOR, PIXEL_VALUE).
Mat exposureChangeSampledBy(ShotNoiseSampling sampling, const Mat& src, const RawFormat& fmt,
                            const NoiseModel& model, double photonRatio, uint64 seed)
{
    NoiseOptions noise;
    noise.shotSampling = sampling;
    Mat out;
    RawFormat outFmt;
    colorJitter(src, fmt, model, ColorJitter::exposureChange(photonRatio, 1.0), noise, seed, out, outFmt);
    return out;
}

TEST(Augment, exposureChangeThirdCumulantIsWhatTheMathematicsDerives)
{
    // docs/mathematics.md: with pure shot noise (q = 1 DN per electron) an input of Poisson(lambda / p_u)
    // electrons darkened by p_u with PIXEL_VALUE has third cumulant (3 p_u - 2 p_u^2) lambda with Gaussian
    // added noise and (1 + 2 p_u (1 - p_u)) lambda with POISSON counts; the capture has lambda. These pin
    // the documented departure from the capture (POISSON overshoots a mild darkening's skewness by half),
    // so that a change of either sampling shows here. 2 M pixels: the standard error of k3 / lambda is
    // sqrt(6 lambda / n) (a near-normal sample of variance lambda), 0.017 at lambda = 100; the bound is 4
    // of them, and the two samplings differ by 0.5 lambda at p_u = 1/2.
    const double lambda = 100;
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(100);
    fmt.whiteLevel = 1e6;
    fmt.gain = 1;
    const NoiseModel model(1.0, 0.0, 1e-6);
    std::mt19937_64 engine(7);
    for (double pu : {0.5, 0.2, 0.05}) {
        Mat bright(1000, 2000, CV_32FC1);
        std::poisson_distribution<int> electrons(lambda / pu);
        for (int r = 0; r < bright.rows; ++r)
            for (int c = 0; c < bright.cols; ++c)
                bright.at<float>(r, c) = static_cast<float>(100 + electrons(engine));
        for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON}) {
            const Mat out = exposureChangeSampledBy(sampling, bright, fmt, model, pu, 3);
            double s1 = 0, s2 = 0, s3 = 0;
            for (int r = 0; r < out.rows; ++r)
                for (int c = 0; c < out.cols; ++c) {
                    const double v = out.at<float>(r, c) - 100 - lambda;
                    s1 += v;
                    s2 += v * v;
                    s3 += v * v * v;
                }
            const double n = static_cast<double>(out.total()), m = s1 / n;
            const double k3 = s3 / n - 3 * m * s2 / n + 2 * m * m * m;
            const double predicted =
                sampling == ShotNoiseSampling::GAUSSIAN ? 3 * pu - 2 * pu * pu : 1 + 2 * pu * (1 - pu);
            EXPECT_NEAR(k3 / lambda, predicted, 4 * std::sqrt(6 * lambda / n))
                << "p_u " << pu << (sampling == ShotNoiseSampling::GAUSSIAN ? " GAUSSIAN" : " POISSON");
            EXPECT_NEAR((s2 / n - m * m) / lambda, 1.0, 4 * std::sqrt(2.0 / n)) << "p_u " << pu;
        }
    }
}

TEST(Augment, jitterAddsRowROfItsOwnStreamValueForValue)
{
    // The noise the jitter adds must be row r of its stream, value for value: a row that reused another
    // row's numbers, or restarted its stream part-way, would pass statistical tests. IGNORE_PRIOR on
    // float input with no clipping lets the test read the normal back: z = (out - black - c x) /
    // sqrt(v), v the model's variance at the new mean.
    const int rows = 5, cols = 1000; // rows of both CFA parities; 1000 is not a whole number of blocks
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(100);
    fmt.whiteLevel = 1e6;
    fmt.gain = 1;
    const NoiseModel model(0.5, 1.5, 3.0);
    Mat src(rows, cols, CV_32FC1);
    randu(src, 1000, 3000);
    ColorJitter jitter;
    jitter.contrast = Vec4d::all(0.5);
    const uint64 seed = 99;
    Mat out;
    RawFormat outFmt;
    colorJitter(src, fmt, model, jitter, NoiseAlignment::IGNORE_PRIOR, seed, out, outFmt);
    Mat z;
    fillStandardNormal(z, Size(cols, rows), detail::stepKey(seed, detail::RandomStream::JITTER_GAUSSIAN));
    const NoiseLine line = model.lineAtGain(1.0);
    double worst = 0;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            const double mean = 0.5 * (src.at<float>(r, c) - 100);
            const double added = out.at<float>(r, c) - 100 - mean;
            worst = std::max(worst, std::abs(added / std::sqrt(line.a * mean + line.b) - z.at<float>(r, c)));
        }
    // Float arithmetic of values near 1000 (ulp 6e-5) divided by a standard deviation near 25.
    EXPECT_LT(worst, 1e-4);
}

TEST(Augment, sixteenBitOutputRoundsTiesToEvenSoNoiselessStepsAreUnbiased)
{
    RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    fmt.blackLevel = Scalar::all(64);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat out, outFloat;
    RawFormat outFmt;
    // The steps that average neighbours (blur, scale), with no noise added, against the unrounded float
    // output of the same call: each pixel within half a DN and the mean not shifted. On random integers
    // a 2-tap blur makes a tie at half the pixels and this 2x scale at 1.7% of them, so rounding ties up
    // would add 0.12 and 0.008 DN. Unbiased rounding errors are uniform on [-1/2, 1/2] (s.d. 0.29): over
    // 65536 pixels their mean has s.d. 0.0011, and 0.004 is 3.5 of those.
    Mat src(256, 256, CV_16UC1), srcFloat;
    RNG(7).fill(src, RNG::UNIFORM, 64, 4000);
    src.convertTo(srcFloat, CV_32F);
    const auto checkUnbiased = [&](const Mat& rounded, const Mat& exact, const char* step) {
        Mat roundedFloat, difference;
        rounded.convertTo(roundedFloat, CV_32F);
        cv::subtract(roundedFloat, exact, difference);
        double lo = 0, hi = 0;
        cv::minMaxLoc(difference, &lo, &hi);
        EXPECT_LE(std::max(-lo, hi), 0.5) << step;
        EXPECT_NEAR(cv::mean(difference)[0], 0.0, 0.004) << step;
    };
    const Mat kernel = (Mat_<float>(1, 2) << 0.5f, 0.5f);
    motionBlur(src, fmt, model, kernel, NoiseAlignment::NONE, 1, out);
    motionBlur(srcFloat, fmt, model, kernel, NoiseAlignment::NONE, 1, outFloat);
    checkUnbiased(out, outFloat, "motionBlur");
    scaleMosaic(src, fmt, model, 2.0, NoiseAlignment::NONE, 1, out);
    scaleMosaic(srcFloat, fmt, model, 2.0, NoiseAlignment::NONE, 1, outFloat);
    checkUnbiased(out, outFloat, "scaleMosaic");

    // Every integer from 0 to 2047 above black, halved: half the pixels are ties, and each goes to the
    // even neighbour (1 -> 0, 3 -> 2, 5 -> 2, 7 -> 4, ...). Rounding them up would add exactly 1/4 DN.
    Mat ramp(32, 64, CV_16UC1);
    for (int i = 0; i < ramp.rows; ++i)
        for (int j = 0; j < ramp.cols; ++j)
            ramp.at<ushort>(i, j) = static_cast<ushort>(64 + i * ramp.cols + j);
    colorJitter(ramp, fmt, model, ColorJitter::exposureChange(0.5, 1.0), NoiseAlignment::NONE, 1, out,
                outFmt);
    for (int i = 0; i < ramp.rows; ++i)
        for (int j = 0; j < ramp.cols; ++j) {
            const int above = i * ramp.cols + j;
            const int half = above / 2;
            const int expected = above % 2 == 0 || half % 2 == 0 ? half : half + 1;
            ASSERT_EQ(out.at<ushort>(i, j), 64 + expected) << "at " << above << " DN above black";
        }
}

TEST(Augment, badArgumentsGiveClearErrors)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    const Mat src = smallMosaic();
    Mat out;
    RawFormat f;
    EXPECT_CV_ERROR_CONTAINS(colorJitter(Mat(), fmt, model, ColorJitter(), NoiseAlignment::NONE, 0, out, f),
                             "src is empty");
    EXPECT_CV_ERROR_CONTAINS(
        colorJitter(Mat(4, 4, CV_8UC1), fmt, model, ColorJitter(), NoiseAlignment::NONE, 0, out, f),
        "expected CV_16UC1 or CV_32FC1");
    ColorJitter bad;
    bad.contrast[2] = -1;
    EXPECT_CV_ERROR_CONTAINS(colorJitter(src, fmt, model, bad, NoiseAlignment::NONE, 0, out, f), "contrast");
    bad = ColorJitter();
    bad.gainRatio = std::numeric_limits<double>::infinity();
    EXPECT_CV_ERROR_CONTAINS(colorJitter(src, fmt, model, bad, NoiseAlignment::NONE, 0, out, f), "gainRatio");
    bad = ColorJitter();
    bad.brightness = std::numeric_limits<double>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(colorJitter(src, fmt, model, bad, NoiseAlignment::NONE, 0, out, f),
                             "brightness");
    EXPECT_CV_ERROR_CONTAINS(ColorJitter::exposureChange(0, 1), "photonRatio");
    EXPECT_CV_ERROR_CONTAINS(
        motionBlur(src, fmt, model, Mat::zeros(3, 3, CV_32F), NoiseAlignment::NONE, 0, out), "positive sum");
    EXPECT_CV_ERROR_CONTAINS(
        motionBlur(src(Rect(0, 0, 5, 4)), fmt, model, Mat::ones(3, 3, CV_32F), NoiseAlignment::NONE, 0, out),
        "both sides must be even");
    EXPECT_CV_ERROR_CONTAINS(linearMotionKernel(-1, 0), "length");
    Mat nan(4, 4, CV_32FC1, Scalar(std::numeric_limits<float>::quiet_NaN()));
    EXPECT_CV_ERROR_CONTAINS(colorJitter(nan, fmt, model, ColorJitter(), NoiseAlignment::NONE, 0, out, f),
                             "NaN");
    EXPECT_CV_ERROR_CONTAINS(
        colorJitter(src, fmt, model, ColorJitter(), static_cast<NoiseAlignment>(7), 0, out, f),
        "unknown alignment 7");
    NoiseOptions badSampling;
    badSampling.shotSampling = static_cast<ShotNoiseSampling>(3);
    EXPECT_CV_ERROR_CONTAINS(motionBlur(src, fmt, model, Mat::ones(3, 3, CV_32F), badSampling, 0, out),
                             "unknown shotSampling 3");
    NoiseOptions badPrior;
    badPrior.priorMean = static_cast<PriorMeanEstimate>(-1);
    EXPECT_CV_ERROR_CONTAINS(scaleMosaic(src, fmt, model, 1.5, badPrior, 0, out), "unknown priorMean -1");
    FileStorage fs("%YAML:1.0\nscene_policy: {blur_noise_sum: 0.5}\n",
                   FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(RandomScenePolicy::read(fs["scene_policy"]),
                             "'blur_noise_sum' must be an integer");
}

TEST(Augment, shiftKeepsTheCfaPhaseAndMovesBoxes)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat src(16, 16, CV_16UC1);
    for (int r = 0; r < 16; ++r)
        for (int c = 0; c < 16; ++c)
            src.at<ushort>(r, c) = static_cast<ushort>(1000 * cfaSite(r, c) + 10 * r + c);
    Scene scene;
    scene.shift = Point(3, 2); // x rounds to an even 4
    std::vector<Rect> boxes = {Rect(2, 2, 4, 4), Rect(14, 0, 2, 2)};
    Mat out;
    RawFormat f;
    applyScene(src, fmt, model, scene, 0, out, f, nullptr, &boxes);
    for (int r = 2; r < 16; ++r)
        for (int c = 4; c < 16; ++c)
            ASSERT_EQ(out.at<ushort>(r, c), src.at<ushort>(r - 2, c - 4));
    for (int r = 0; r < 16; ++r)
        for (int c = 0; c < 16; ++c)
            ASSERT_EQ(out.at<ushort>(r, c) / 1000, cfaSite(r, c)); // every pixel keeps its site's colour
    EXPECT_EQ(boxes[0], Rect(6, 4, 4, 4));
    EXPECT_EQ(boxes[1].area(), 0); // moved out of the frame
}

TEST(Augment, shiftMatchesThePlaneWiseComposition)
{
    // The one-pass shift against what it replaced: each CFA plane moved by half the shift with
    // warpAffine (nearest, edge replicated), for shifts inside, at and beyond the middle, up to the
    // whole frame, on both depths and on a view that is not continuous.
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat big(22, 40, CV_16UC1);
    randu(big, 0, 4096);
    for (const Mat& src : {big(Rect(4, 2, 30, 18)), Mat(big(Rect(4, 2, 30, 18)).clone())})
        for (int depth : {CV_16U, CV_32F})
            for (const Point shift : {Point(2, 0), Point(0, -4), Point(6, 8), Point(-12, 10), Point(-30, -18),
                                      Point(30, 18), Point(28, -16)}) {
                Mat typed;
                src.convertTo(typed, depth);
                std::vector<Mat> planes;
                splitCfaPlanes(typed, planes);
                for (Mat& plane : planes) {
                    Mat moved;
                    warpAffine(plane, moved, Matx23d(1, 0, shift.x / 2, 0, 1, shift.y / 2), plane.size(),
                               INTER_NEAREST, BORDER_REPLICATE);
                    plane = moved;
                }
                Mat expected, out;
                mergeCfaPlanes(planes, expected);
                Scene scene;
                scene.shift = shift;
                RawFormat f;
                applyScene(typed, fmt, model, scene, 0, out, f);
                ASSERT_EQ(out.type(), typed.type());
                EXPECT_EQ(0, norm(out, expected, NORM_INF)) << "shift " << shift << ", depth " << depth;
            }
}

TEST(Augment, randomPolicyDrawsInItsRangesAndRoundTrips)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const Mat src = smallMosaic();
    RandomScenePolicy policy;
    policy.gainDbMin = 3;
    policy.gainDbMax = 9;
    policy.noise.shotSampling = ShotNoiseSampling::POISSON;
    int blurred = 0, hue = 0, geometry = 0;
    for (uint64 seed = 0; seed < 400; ++seed) {
        const Scene s = policy.draw(src, fmt, seed);
        const double base = std::min(
            {s.jitter.contrast[0], s.jitter.contrast[1], s.jitter.contrast[2], s.jitter.contrast[3]});
        EXPECT_GE(base, 0.01 * 0.8);
        EXPECT_LE(s.jitter.contrast[0], 1.0 * 1.2);
        EXPECT_GE(linearGainToDb(s.jitter.gainRatio), 3 - 1e-9);
        EXPECT_LE(linearGainToDb(s.jitter.gainRatio), 9 + 1e-9);
        EXPECT_LE(std::abs(s.shift.x), 0.1 * src.cols + 1);
        EXPECT_GE(s.scale, 0.97);
        EXPECT_LE(s.scale, 1.03);
        geometry += s.scale != 1 ? 1 : 0;
        blurred += s.motionKernel.empty() ? 0 : 1;
        hue += s.jitter.contrast[0] != s.jitter.contrast[3] ? 1 : 0;
    }
    // Probabilities 0.5: binomial(400, 0.5) has standard deviation 10; 5 of them around 200.
    EXPECT_NEAR(blurred, 200, 50);
    EXPECT_NEAR(hue, 200, 50);
    EXPECT_NEAR(geometry, 320, 40); // probability 0.8: standard deviation 8
    const Scene a = policy.draw(src, fmt, 7), b = policy.draw(src, fmt, 7);
    EXPECT_EQ(a.jitter.contrast, b.jitter.contrast);
    EXPECT_EQ(a.shift, b.shift);
    const std::string dir = test::makeTempDir("random_policy");
    for (const char* name : {"/policy.yml", "/policy.json"}) {
        policy.save(dir + name);
        const RandomScenePolicy back = RandomScenePolicy::load(dir + name);
        EXPECT_EQ(back.gainDbMax, 9);
        EXPECT_EQ(back.contrastMin, 0.01);
        EXPECT_EQ(back.noise.alignment, NoiseAlignment::ACCOUNT_PRIOR);
        EXPECT_EQ(back.noise.shotSampling, ShotNoiseSampling::POISSON);
    }
    // p_b = u min(x), with min(x) over black-subtracted pixels of every site.
    RandomScenePolicy fixedBrightness;
    fixedBrightness.brightnessMin = fixedBrightness.brightnessMax = 0.1;
    RawFormat perSite = fmt;
    perSite.blackLevel = Vec4d(250, 256, 260, 270);
    for (int type : {CV_16UC1, CV_32FC1}) {
        const Mat mosaic = smallMosaic(type);
        Mat x;
        subtractBlackLevel(mosaic, perSite, x);
        double minX = 0;
        minMaxLoc(x, &minX);
        EXPECT_DOUBLE_EQ(fixedBrightness.draw(mosaic, perSite, 3).jitter.brightness, 0.1 * minX);
    }
    RandomScenePolicy bad;
    bad.contrastMin = 2;
    EXPECT_CV_ERROR_CONTAINS(bad.validate(), "contrast range");
    FileStorage fs("%YAML:1.0\nscene_policy: {hue_probability: 2}\n",
                   FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(RandomScenePolicy::read(fs["scene_policy"]), "hueProbability");
}

TEST(Augment, policyBrightnessIsAFractionOfTheSmallestValueAboveBlack)
{
    // brightness = uniform(min, max) * min over pixels of (value - black of its site): with min = max = 1
    // it is that minimum itself. Each site has its own black level; the minimum sits at each site in
    // turn, inside the 16-value blocks or in a row's tail (37 columns: 32 + 5), on both depths.
    RawFormat fmt;
    fmt.blackLevel = Vec4d(60, 64, 70, 50);
    fmt.whiteLevel = 4095;
    RandomScenePolicy policy;
    policy.brightnessMin = policy.brightnessMax = 1;
    for (int depth : {CV_16U, CV_32F})
        for (const Point where : {Point(3, 0), Point(34, 0), Point(0, 7), Point(35, 9), Point(10, 12)}) {
            Mat src(14, 37, CV_16UC1, Scalar(2000));
            src.at<ushort>(where) = 300;
            const double expected = 300 - fmt.blackAt(where.y, where.x);
            Mat typed;
            src.convertTo(typed, depth);
            EXPECT_EQ(policy.draw(typed, fmt, 1).jitter.brightness, expected) << where << ", depth " << depth;
        }
}

TEST(Augment, sceneRoundTripsThroughFileStorage)
{
    Scene s;
    s.shift = Point(4, -2);
    s.scale = 1.02;
    s.jitter.contrast = Vec4d(0.1, 0.2, 0.3, 0.4);
    s.jitter.brightness = -3;
    s.jitter.gainRatio = 8;
    s.motionKernel = linearMotionKernel(7, 20);
    s.noise.alignment = NoiseAlignment::IGNORE_PRIOR;
    s.noise.priorMean = PriorMeanEstimate::LOCAL_MEAN;
    s.noise.blurNoiseSum = BlurNoiseSum::FROM_BLURRED_MEAN;
    FileStorage out("", FileStorage::WRITE | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
    s.write(out, "scene");
    FileStorage in(out.releaseAndGetString(), FileStorage::READ | FileStorage::MEMORY);
    const Scene r = Scene::read(in["scene"]);
    EXPECT_EQ(r.shift, s.shift);
    EXPECT_EQ(r.scale, 1.02);
    EXPECT_EQ(r.jitter.contrast, s.jitter.contrast);
    EXPECT_EQ(r.jitter.gainRatio, 8);
    EXPECT_EQ(r.noise.alignment, NoiseAlignment::IGNORE_PRIOR);
    EXPECT_EQ(r.noise.shotSampling, ShotNoiseSampling::GAUSSIAN);
    EXPECT_EQ(r.noise.priorMean, PriorMeanEstimate::LOCAL_MEAN);
    EXPECT_EQ(r.noise.blurNoiseSum, BlurNoiseSum::FROM_BLURRED_MEAN);
    EXPECT_EQ(norm(r.motionKernel, s.motionKernel, NORM_INF), 0);
}

TEST(Augment, sceneAndPolicyFilesRejectWhatIsNotANumber)
{
    // Every numeric field goes through one reader: a word where a number belongs is an error naming
    // the field, never a default or a wrapped value.
    const auto readScene = [](const std::string& fields) {
        FileStorage fs("%YAML:1.0\nscene: {contrast: [1, 1, 1, 1], brightness: 0, gain_ratio: 1" + fields +
                           "}\n",
                       FileStorage::READ | FileStorage::MEMORY);
        return Scene::read(fs["scene"]);
    };
    EXPECT_EQ(readScene("").jitter.contrast, Vec4d::all(1));
    FileStorage badContrast("%YAML:1.0\nscene: {contrast: [1, abc, 1, 1], brightness: 0, gain_ratio: 1}\n",
                            FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(Scene::read(badContrast["scene"]), "scene: field 'contrast[1]' is not a number");
    EXPECT_CV_ERROR_CONTAINS(readScene(", scale: big"), "scene: field 'scale' is not a number");
    EXPECT_CV_ERROR_CONTAINS(readScene(", alignment: 1e10"), "'alignment' must be an integer");
    EXPECT_CV_ERROR_CONTAINS(readScene(", shift: here"), "field 'shift' must be a list of two integers");
    EXPECT_CV_ERROR_CONTAINS(readScene(", shift: [ 1.5, 2 ]"),
                             "field 'shift' must be a list of two integers");
    // max_shift is a fraction of each side: 4 (pixels meant?) loaded and failed only after 1-2 outputs.
    FileStorage pixels("%YAML:1.0\nrandom_scene_policy: {max_shift: 4}\n",
                       FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(RandomScenePolicy::read(pixels["random_scene_policy"]),
                             "maxShift must lie in [0, 1), a fraction of each side (got 4)");
    // A kernel weight the reader cannot use (found by test/fuzz: -1e308 stored as a float is -inf).
    const auto kernel = [](const char* dt, const char* data) {
        return cv::format(", motion_kernel: !!opencv-matrix { rows: 1, cols: 3, dt: %s, data: [ %s ] }", dt,
                          data);
    };
    EXPECT_EQ(readScene(kernel("f", "0.5, 1, 0.5")).motionKernel.cols, 3);
    EXPECT_CV_ERROR_CONTAINS(readScene(kernel("f", "0.5, -1e308, 0.5")), "one channel of finite numbers");
    EXPECT_CV_ERROR_CONTAINS(readScene(kernel("d", "0.5, -1, 0.5")), "non-negative with a positive sum");
    EXPECT_CV_ERROR_CONTAINS(readScene(kernel("d", "0, 0, 0")), "non-negative with a positive sum");
    EXPECT_CV_ERROR_CONTAINS(readScene(kernel("u", "1, 1, 1")), "must have dt 'f' or 'd'");
    FileStorage policy("%YAML:1.0\nscene_policy: {gain_db_max: loud}\n",
                       FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(RandomScenePolicy::read(policy["scene_policy"]),
                             "random scene policy: field 'gain_db_max' is not a number");
}

//! Counts of the integer values v - black in [lo, hi] of a CV_16UC1 frame.
std::vector<double> valueHistogram(const Mat& raw, double black, int lo, int hi)
{
    std::vector<double> counts(static_cast<size_t>(hi - lo + 1), 0.0);
    for (int r = 0; r < raw.rows; ++r)
        for (int c = 0; c < raw.cols; ++c) {
            const int v = static_cast<int>(raw.at<ushort>(r, c)) - static_cast<int>(black);
            if (v >= lo && v <= hi)
                counts[static_cast<size_t>(v - lo)] += 1;
        }
    return counts;
}

//! KL(p || q) in nats of two histograms; half a count is added to every bin of q (an empty bin of the
//! model where the truth has mass would make the divergence infinite, which says nothing useful).
double klDivergence(const std::vector<double>& p, const std::vector<double>& q)
{
    double np = 0, nq = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        np += p[i];
        nq += q[i] + 0.5;
    }
    double kl = 0;
    for (size_t i = 0; i < p.size(); ++i)
        if (p[i] > 0)
            kl += p[i] / np * std::log((p[i] / np) / ((q[i] + 0.5) / nq));
    return kl;
}

//! Spatial mean and unbiased variance of the black-subtracted pixels of a flat frame.
void spatialStats(const Mat& raw, const RawFormat& fmt, double& mean, double& var)
{
    Mat x;
    subtractBlackLevel(raw, fmt, x);
    Scalar m, s;
    meanStdDev(x, m, s);
    mean = m[0];
    var = s[0] * s[0] * static_cast<double>(x.total()) / static_cast<double>(x.total() - 1);
}

TEST(Augment, poissonShotNoiseGivesTheElectronLatticeOfARealDarkCapture)
{
    // A sensor whose read noise (0.5 DN) is small next to its 4 DN per electron at gain 4: a capture of
    // two electrons per pixel puts its values on a lattice of 4 DN, the shape that matters at very low
    // light and that a Gaussian does not have.
    SensorParams params = test::referenceSensorParams();
    params.noise = NoiseModel(1.0, 0.01, 0.05);
    const Size size(256, 256);
    const SensorSimulator sensor(params, size);
    const NoiseModel model = sensor.effectiveModel();
    const double gain = 4, photonRatio = 0.01;
    const RawFormat fmt = sensor.rawFormat(gain);
    const Mat scene(size, CV_32FC1, Scalar(200)); // 200 electrons; x 0.01 = 2 electrons
    Mat bright, truth, truthAgain;
    sensor.capture(scene, gain, 1.0, 1, 0, bright);
    sensor.capture(scene, gain, photonRatio, 2, 0, truth);
    sensor.capture(scene, gain, photonRatio, 3, 0, truthAgain);
    const int lo = -24, hi = 64; // 2 electrons + 8 sigma of Poisson(2), in DN
    const std::vector<double> truthCounts = valueHistogram(truth, fmt.blackLevel[0], lo, hi);
    // The floor: two independent true captures differ by this much through sampling alone.
    const double klFloor = klDivergence(truthCounts, valueHistogram(truthAgain, fmt.blackLevel[0], lo, hi));
    double truthMean = 0, truthVar = 0;
    spatialStats(truth, fmt, truthMean, truthVar);
    double kl[2] = {0, 0};
    for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON}) {
        const Mat out = exposureChangeSampledBy(sampling, bright, fmt, model, photonRatio, 7);
        const int i = static_cast<int>(sampling);
        kl[i] = klDivergence(truthCounts, valueHistogram(out, fmt.blackLevel[0], lo, hi));
        double mean = 0, var = 0;
        spatialStats(out, fmt, mean, var);
        // Both samplings add the same variance. A sample variance of N = 65536 values of a Poisson-like
        // variable (excess kurtosis 1/2 at 2 electrons) has relative spread sqrt((2 + 0.5) / N) = 0.6%;
        // the difference of two has sqrt(2) times that; 5 of those: 4.4%.
        const double tolerance = 5 * std::sqrt(2.0) * std::sqrt(2.5 / static_cast<double>(size.area()));
        EXPECT_NEAR(var / truthVar, 1.0, tolerance) << "sampling " << i;
        EXPECT_NEAR(mean, truthMean, 5 * std::sqrt(2 * truthVar / static_cast<double>(size.area())));
    }
    std::cout << "KL(true capture || augmented) at 2 electrons: GAUSSIAN " << kl[0] << ", POISSON " << kl[1]
              << ", between two true captures " << klFloor << "\n";
    // The Gaussian misses the lattice entirely (KL of order log 4: the truth's mass sits on one value in
    // four); the Poisson sampling reproduces it up to the scaled prior's 0.57 DN smear, comparable to
    // the truth's own 0.5 DN read noise. An order of magnitude between them is the claim.
    EXPECT_GT(kl[0], 0.3);
    EXPECT_LT(kl[1], kl[0] / 10);
}

//! The 3x3 same-site mean of each pixel of a float mosaic (offsets -2, 0, 2), mirrored at the edges.
Mat sameSiteLocalMean(const Mat& x)
{
    const auto mirror = [](int i, int n) { return i < 0 ? -i : (i >= n ? 2 * (n - 1) - i : i); };
    Mat mean(x.size(), CV_32FC1);
    for (int r = 0; r < x.rows; ++r)
        for (int c = 0; c < x.cols; ++c) {
            double sum = 0;
            for (int dy = -2; dy <= 2; dy += 2)
                for (int dx = -2; dx <= 2; dx += 2)
                    sum += x.at<float>(mirror(r + dy, x.rows), mirror(c + dx, x.cols));
            mean.at<float>(r, c) = static_cast<float>(sum / 9);
        }
    return mean;
}

TEST(Augment, localPriorMeanRemovesTheClipBiasAtBlack)
{
    // A black frame at 18 dB: the true mean is 0, so the target of a x0.5 exposure has no shot noise.
    // mu_x = max(x, 0) of a noisy pixel is E[max(x, 0)] = sigma / sqrt(2 pi) on average, adding shot
    // variance that is not there; the mean of nine same-site pixels has a third of the spread.
    const Size size(512, 512);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const double gain = 8, photonRatio = 0.5;
    const RawFormat fmt = sensor.rawFormat(gain);
    Mat raw;
    sensor.capture(Mat::zeros(size, CV_32FC1), gain, 1.0, 11, 0, raw);
    raw.convertTo(raw, CV_32F); // float output: no second rounding in the variance
    double inMean = 0, inVar = 0;
    spatialStats(raw, fmt, inMean, inVar);
    Mat x;
    subtractBlackLevel(raw, fmt, x);
    const NoiseLine line = model.lineAtGain(gain);
    double excess[2] = {0, 0};
    for (PriorMeanEstimate prior : {PriorMeanEstimate::PIXEL_VALUE, PriorMeanEstimate::LOCAL_MEAN}) {
        NoiseOptions noise;
        noise.priorMean = prior;
        Mat out;
        RawFormat outFmt;
        colorJitter(raw, fmt, model, ColorJitter::exposureChange(photonRatio, 1.0), noise, 12, out, outFmt);
        double mean = 0, var = 0;
        spatialStats(out, fmt, mean, var);
        // Eq. 11 with this estimate, averaged over the frame: p^2 v_in + E[v], where
        // v = p_u (1 - p_u) g alpha mu + (1 - p_u^2) b (p_g = 1, so p_u = p and v > 0 everywhere).
        const Mat mu = max(prior == PriorMeanEstimate::LOCAL_MEAN ? sameSiteLocalMean(x) : x, 0.0);
        const double shotTerm = photonRatio * (1 - photonRatio) * line.a * cv::mean(mu)[0];
        const double predicted =
            photonRatio * photonRatio * inVar + shotTerm + (1 - photonRatio * photonRatio) * line.b;
        // Sample variance of 262144 near-Gaussian values: relative spread sqrt(2 / N) = 0.28%; 5 of it.
        EXPECT_NEAR(var / predicted, 1.0, 5 * std::sqrt(2.0 / static_cast<double>(size.area())))
            << "prior " << static_cast<int>(prior);
        excess[static_cast<int>(prior)] = shotTerm / line.b;
    }
    std::cout << "Shot variance added at black (relative to the read noise): PIXEL_VALUE " << excess[0]
              << ", LOCAL_MEAN " << excess[1] << "\n";
    // sigma / sqrt(2 pi) against (sigma / 3) / sqrt(2 pi): a third, give or take the mirrored borders.
    EXPECT_GT(excess[0], 0.03);
    EXPECT_LT(excess[1], 0.4 * excess[0]);
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

TEST(Augment, poissonJitterAddsExactPoissonCountsAtEveryMean)
{
    // End to end through the POISSON rows of colorJitter (split, vector draws, noise pass): a sensor
    // without read noise at 1 DN per electron, a noiseless float input, exposure x0.2. ACCOUNT_PRIOR adds
    // shot variance p_u (1 - p_u) x = 0.16 x, drawn as K - m with m = 0.16 x electrons, so each output is
    // 0.2 x + K - 0.16 x = 0.04 x + K: an integer K above 0.04 x that must be Poisson(0.16 x). Means on
    // both sides of the inversion/rejection switch at 10 and far above it.
    const std::vector<double> means = {2.0, 8.0, 10.0, 40.0, 1000.0};
    const int blockCols = 100, rows = 400;
    Mat src(rows, blockCols * static_cast<int>(means.size()), CV_32FC1);
    for (int c = 0; c < src.cols; ++c)
        src.col(c).setTo(means[static_cast<size_t>(c / blockCols)] / 0.16);
    const NoiseModel model(1.0, 0.0, 0.0);
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(0);
    fmt.whiteLevel = 1e9;
    fmt.gain = 1;
    const Mat out = exposureChangeSampledBy(ShotNoiseSampling::POISSON, src, fmt, model, 0.2, 11);
    for (size_t m = 0; m < means.size(); ++m) {
        const double lambda = means[m];
        std::map<int64_t, int> hist;
        double worst = 0;
        for (int r = 0; r < rows; ++r)
            for (int c = static_cast<int>(m) * blockCols; c < static_cast<int>(m + 1) * blockCols; ++c) {
                const double k = out.at<float>(r, c) - 0.04 * src.at<float>(r, c);
                const double rounded = std::round(k);
                worst = std::max(worst, std::abs(k - rounded));
                ++hist[static_cast<int64_t>(rounded)];
            }
        // The float output holds 0.04 x + K to a few float ulps of values below 1100 (1e-4).
        EXPECT_LT(worst, 1e-3) << "mean " << lambda;
        int dof = 0;
        const double chi2 = test::poissonChiSquare(hist, lambda, static_cast<double>(rows * blockCols), dof);
        // chi^2 with dof degrees of freedom: mean dof, sd sqrt(2 dof); 6 sd, as the samplers' own tests.
        EXPECT_LT(chi2, dof + 6 * std::sqrt(2.0 * dof)) << "mean " << lambda << ", dof " << dof;
    }
}

TEST(Augment, poissonSamplingKeepsTheVarianceOfBlurAndScale)
{
    // A noiseless flat frame of 20 DN above black: the added variance is all there is to measure.
    const Size size(256, 256);
    const NoiseModel model(0.4, 0.5, 2.0);
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(64);
    fmt.whiteLevel = 65535;
    fmt.gain = 4;
    const Mat src(size, CV_32FC1, Scalar(64 + 20));
    const Mat kernel = linearMotionKernel(9, 30);
    for (int step = 0; step < 2; ++step) {
        double var[2] = {0, 0};
        for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON}) {
            NoiseOptions noise;
            noise.shotSampling = sampling;
            Mat out;
            if (step == 0)
                motionBlur(src, fmt, model, kernel, noise, 5, out);
            else
                scaleMosaic(src, fmt, model, 1.01, noise, 5, out);
            double mean = 0;
            spatialStats(out, fmt, mean, var[static_cast<int>(sampling)]);
            EXPECT_NEAR(mean, 20, 0.1);
        }
        // Neighbouring outputs are independent draws; the variance differs between pixels (scale)
        // but the frame averages are comparable: 5 x sqrt(2) x sqrt(3 / N) (kurtosis of a few-electron
        // Poisson below 1) = 4.8%.
        EXPECT_NEAR(var[1] / var[0], 1.0,
                    5 * std::sqrt(2.0) * std::sqrt(3.0 / static_cast<double>(size.area())))
            << (step == 0 ? "blur" : "scale");
    }
}

TEST(Augment, augmentedOutputSeedDependsOnlyOnSeedNameAndVariant)
{
    const uint64 s = augmentedOutputSeed(7, "frame_000", 2);
    EXPECT_EQ(s, augmentedOutputSeed(7, "frame_000", 2));
    EXPECT_NE(s, augmentedOutputSeed(7, "frame_000", 3));
    EXPECT_NE(s, augmentedOutputSeed(7, "frame_001", 2));
    EXPECT_NE(s, augmentedOutputSeed(8, "frame_000", 2));
    EXPECT_CV_ERROR_CONTAINS(augmentedOutputSeed(7, "frame_000", -1), "variant must be >= 0");
}

TEST(Augment, misspelledKeysInSceneAndPolicyFilesAreErrorsNamingThem)
{
    FileStorage policy("%YAML:1.0\nscene_policy: {contrst_min: 0.1}\n",
                       FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(RandomScenePolicy::read(policy["scene_policy"]),
                             "random scene policy: unknown key 'contrst_min' (valid keys: contrast_min,");
    FileStorage scene("%YAML:1.0\nscene: {contrast: [1, 1, 1, 1], brightness: 0, gain_ratio: 1, sclae: 2}\n",
                      FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(Scene::read(scene["scene"]), "scene: unknown key 'sclae'");
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

DarkStats darkStats(const std::vector<Mat>& burst, double black)
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
double fixedPatternExcess(const DarkStats& a, const DarkStats& b, int T, int W)
{
    Mat d = a.pixelMean - b.pixelMean;
    d -= cv::mean(d)[0]; // the scene's level is not the pattern
    const double noise = (a.pixelVar + b.pixelVar + (a.rowMeanVar + b.rowMeanVar) * (1 - 1.0 / W)) / T;
    return d.dot(d) / d.total() / noise - 1;
}

TEST(Augment, darkeningAddsTheDarkFrameComponentsATargetCaptureHas)
{
    const Size size(256, 256);
    const int T = 32;
    const SensorParams params = darkComponentSensor(size);
    const SensorSimulator sensor(params, size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(1.0);
    const double black = fmt.blackLevel[0];
    const Mat scene(size, CV_32FC1, Scalar(400));
    std::vector<Mat> bright;
    sensor.captureBurst(scene, 1.0, 1.0, T, 7, bright);
    NoiseModel gaussianRead = model;
    gaussianRead.tukeyRead = false;
    struct Case
    {
        double photonRatio, gainRatio;
        bool priorMatters; // whether the scaled prior is a sizeable part of the target (IGNORE_PRIOR shows)
    };
    for (const Case& c : {Case{1.0 / 200, 8, false}, Case{0.5, 2, true}}) {
        SCOPED_TRACE(testing::Message() << "photons x" << c.photonRatio << ", gain x" << c.gainRatio);
        std::vector<Mat> target;
        sensor.captureBurst(scene, c.gainRatio, c.photonRatio, T, 8, target);
        const DarkStats truth = darkStats(target, black);
        const ColorJitter jitter = ColorJitter::exposureChange(c.photonRatio, c.gainRatio);
        auto augmented = [&](const NoiseModel& m, const NoiseOptions& options) {
            std::vector<Mat> out(T);
            RawFormat outFmt;
            for (int t = 0; t < T; ++t)
                colorJitter(bright[t], fmt, m, jitter, options, 100 + t, out[t], outFmt);
            return darkStats(out, black);
        };
        // Row-mean variances of (T - 1) H Gaussian row means: relative standard error sqrt(2 / dof) each;
        // pixel variances: sqrt((2 + kurtosis) / n) each with n = (T - 1) H (W - 1) (a sample variance of
        // heavy-tailed data). Five standard errors of the difference of two such estimates.
        const double rowTol = 5 * std::sqrt(2.0) * std::sqrt(2.0 / truth.dof);
        const double pixTol =
            5 * std::sqrt(2.0) *
            std::sqrt((2 + std::max(truth.kurtosis, 0.0)) / (truth.dof * (size.width - 1.0)));
        // The fixed-pattern excess is a mean of H W squared normal differences: standard error
        // sqrt(2 / (H W)) (0.55%); 5 of them.
        const double patternTol = 5 * std::sqrt(2.0 / size.area());
        const DarkStats account = augmented(model, NoiseAlignment::ACCOUNT_PRIOR);
        EXPECT_NEAR(account.rowMeanVar / truth.rowMeanVar, 1, rowTol) << "row-mean variance";
        EXPECT_NEAR(account.pixelVar / truth.pixelVar, 1, pixTol) << "per-pixel variance";
        EXPECT_NEAR(fixedPatternExcess(account, truth, T, size.width), 0, patternTol) << "fixed pattern";
        // The capture's shot noise is a Poisson count (excess kurtosis 1 / electrons: 0.2 at 5 electrons,
        // 0.07 of the total's kurtosis here), which Gaussian shot draws lack: the kurtosis is compared
        // with Poisson shot draws, so that only the read part's tails are under test.
        NoiseOptions poisson;
        poisson.shotSampling = ShotNoiseSampling::POISSON;
        const DarkStats accountPoisson = augmented(model, poisson);
        const double kurtosisTol = 5 * std::hypot(accountPoisson.kurtosisSE, truth.kurtosisSE);
        EXPECT_NEAR(accountPoisson.kurtosis, truth.kurtosis, kurtosisTol) << "excess kurtosis";
        EXPECT_NEAR(accountPoisson.pixelVar / truth.pixelVar, 1, pixTol) << "per-pixel variance (Poisson)";
        const DarkStats none = augmented(model, NoiseAlignment::NONE);
        EXPECT_LT(none.rowMeanVar / truth.rowMeanVar, 1 - rowTol) << "NONE keeps only the scaled rows";
        EXPECT_LT(none.pixelVar / truth.pixelVar, 1 - pixTol) << "NONE keeps only the scaled prior";
        EXPECT_GT(fixedPatternExcess(none, truth, T, size.width), patternTol)
            << "NONE keeps the scaled pattern";
        const DarkStats ignore = augmented(model, NoiseAlignment::IGNORE_PRIOR);
        if (c.priorMatters) {
            EXPECT_GT(ignore.rowMeanVar / truth.rowMeanVar, 1 + rowTol) << "IGNORE_PRIOR doubles the rows";
            EXPECT_GT(ignore.pixelVar / truth.pixelVar, 1 + pixTol) << "IGNORE_PRIOR doubles the noise";
            EXPECT_GT(fixedPatternExcess(ignore, truth, T, size.width), patternTol)
                << "IGNORE_PRIOR adds the pattern on top of the scaled one";
        } else {
            // Where the target's read noise dominates, the tails must come from the added part: Gaussian
            // draws of the same variance leave the result less heavy-tailed than the capture.
            const DarkStats gaussian = augmented(gaussianRead, poisson);
            EXPECT_LT(gaussian.kurtosis,
                      truth.kurtosis - 5 * std::hypot(gaussian.kurtosisSE, truth.kurtosisSE))
                << "Gaussian read noise";
            EXPECT_NEAR(gaussian.pixelVar / truth.pixelVar, 1, pixTol) << "its variance is still right";
        }
        std::cout << "photons x" << c.photonRatio << " gain x" << c.gainRatio << ": row-mean var (capture "
                  << truth.rowMeanVar << ") NONE " << none.rowMeanVar << ", IGNORE " << ignore.rowMeanVar
                  << ", ACCOUNT " << account.rowMeanVar << "; kurtosis (capture " << truth.kurtosis << " +- "
                  << truth.kurtosisSE << ") NONE " << none.kurtosis << ", IGNORE " << ignore.kurtosis
                  << ", ACCOUNT " << account.kurtosis << " (Poisson shot " << accountPoisson.kurtosis
                  << "); pattern excess NONE " << fixedPatternExcess(none, truth, T, size.width)
                  << ", IGNORE " << fixedPatternExcess(ignore, truth, T, size.width) << ", ACCOUNT "
                  << fixedPatternExcess(account, truth, T, size.width) << "\n";
    }
}

TEST(Augment, blurAndScaleRestoreTheDarkFrameComponentsTheyAverageAway)
{
    // A dark flat scene at a high gain, where the components are a large part of the noise: the target
    // of a blur or a scale of a flat scene is a plain capture (captureBlurred of a flat scene is one).
    const Size size(256, 256);
    const int T = 32;
    const double gain = 8;
    const SensorSimulator sensor(darkComponentSensor(size), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(gain);
    const double black = fmt.blackLevel[0];
    const Mat scene(size, CV_32FC1, Scalar(2)); // 16 DN at gain 8: 5 electrons
    std::vector<Mat> input, target;
    sensor.captureBurst(scene, gain, 1.0, T, 9, input);
    sensor.captureBurst(scene, gain, 1.0, T, 10, target);
    const DarkStats truth = darkStats(target, black);
    const Mat kernel = linearMotionKernel(9, 30);
    typedef std::function<void(const Mat&, const NoiseOptions&, uint64, Mat&)> Step;
    const std::pair<const char*, Step> steps[] = {
        {"motionBlur", [&](const Mat& in, const NoiseOptions& o, uint64 seed,
                           Mat& out) { motionBlur(in, fmt, model, kernel, o, seed, out); }},
        {"scale 1.3", [&](const Mat& in, const NoiseOptions& o, uint64 seed, Mat& out) {
             scaleMosaic(in, fmt, model, 1.3, o, seed, out);
         }}};
    // Tolerances as in darkeningAddsTheDarkFrameComponentsATargetCaptureHas.
    const double rowTol = 5 * std::sqrt(2.0) * std::sqrt(2.0 / truth.dof);
    const double pixTol = 5 * std::sqrt(2.0) *
                          std::sqrt((2 + std::max(truth.kurtosis, 0.0)) / (truth.dof * (size.width - 1.0)));
    const double patternTol = 5 * std::sqrt(2.0 / size.area());
    for (const auto& step : steps) {
        SCOPED_TRACE(step.first);
        auto stats = [&](const NoiseOptions& o) {
            std::vector<Mat> out(T);
            for (int t = 0; t < T; ++t)
                step.second(input[t], o, 300 + t, out[t]);
            return darkStats(out, black);
        };
        NoiseOptions poisson;
        poisson.shotSampling = ShotNoiseSampling::POISSON;
        const DarkStats account = stats(poisson), none = stats(NoiseAlignment::NONE),
                        ignore = stats(NoiseAlignment::IGNORE_PRIOR);
        EXPECT_NEAR(account.rowMeanVar / truth.rowMeanVar, 1, rowTol) << "row-mean variance";
        EXPECT_NEAR(account.pixelVar / truth.pixelVar, 1, pixTol) << "per-pixel variance";
        EXPECT_NEAR(fixedPatternExcess(account, truth, T, size.width), 0, patternTol) << "fixed pattern";
        // The added read part's shape matches the kurtosis of the step's typical weights: exact inside a
        // blur, on average along a scaled row; the tolerance is statistical only, which the measured
        // error (printed) stays within.
        EXPECT_NEAR(account.kurtosis, truth.kurtosis, 5 * std::hypot(account.kurtosisSE, truth.kurtosisSE))
            << "excess kurtosis";
        EXPECT_LT(none.rowMeanVar / truth.rowMeanVar, 1 - rowTol) << "NONE averages the rows away";
        EXPECT_LT(none.pixelVar / truth.pixelVar, 1 - pixTol) << "NONE averages the noise away";
        EXPECT_GT(fixedPatternExcess(none, truth, T, size.width), patternTol) << "NONE blurs the pattern";
        EXPECT_GT(ignore.rowMeanVar / truth.rowMeanVar, 1 + rowTol) << "IGNORE_PRIOR adds rows on top";
        EXPECT_GT(ignore.pixelVar / truth.pixelVar, 1 + pixTol) << "IGNORE_PRIOR adds noise on top";
        EXPECT_GT(fixedPatternExcess(ignore, truth, T, size.width), patternTol) << "IGNORE_PRIOR doubles it";
        std::cout << step.first << ": row-mean var (capture " << truth.rowMeanVar << ") NONE "
                  << none.rowMeanVar << ", IGNORE " << ignore.rowMeanVar << ", ACCOUNT " << account.rowMeanVar
                  << "; pixel var (" << truth.pixelVar << ") " << none.pixelVar << ", " << ignore.pixelVar
                  << ", " << account.pixelVar << "; kurtosis (" << truth.kurtosis << " +- "
                  << truth.kurtosisSE << ") ACCOUNT " << account.kurtosis << "; pattern excess "
                  << fixedPatternExcess(none, truth, T, size.width) << ", "
                  << fixedPatternExcess(ignore, truth, T, size.width) << ", "
                  << fixedPatternExcess(account, truth, T, size.width) << "\n";
    }
}

} // namespace
} // namespace rawgment
} // namespace cv
