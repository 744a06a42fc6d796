// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The steps together: scenes (shift, scale, jitter, blur), boxes, the dark shading under a crop, identity
// steps, output buffers, monochrome frames, seeds and clear errors (each step alone: test_shift_mosaic.cpp,
// test_scale_mosaic.cpp, test_color_jitter.cpp, test_motion_blur.cpp; the loop that runs them:
// test_noise_step_internals.cpp; the random policy and the files of scenes and policies:
// test_random_scene_policy.cpp).
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
         [&](const Mat& in, Mat& out) { scaleMosaic(in, fmt, model, 1.1, NoiseOptions(), 3, out); }},
        // Four steps through two buffers in turn, the last the caller's.
        {"applyScene", [&](const Mat& in, Mat& out) {
             Scene all;
             all.shift = Point(2, -2);
             all.scale = 1.1;
             all.jitter = ColorJitter::exposureChange(0.5, 2);
             all.motionKernel = kernel;
             RawFormat f;
             applyScene(in, fmt, model, all, 3, out, f);
         }}};
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

// A monochrome frame through every step: each at identity returns the input itself, a shift moves it by any
// whole number of pixels (it has no CFA phase to keep), a random scene gives it one contrast and a kernel on
// its pixel grid, and per-site contrasts are an error.
TEST(Augment, aMonochromeFrameGoesThroughEveryStepOnItsPixelGrid)
{
    SensorParams params = test::referenceSensorParams();
    params.pattern = CFA_MONO;
    const RawFormat fmt = SensorSimulator(params, Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat src(22, 40, CV_16UC1);
    randu(src, 300, 4000);
    for (int depth : {CV_16U, CV_32F}) {
        Mat typed, out;
        src.convertTo(typed, depth);
        RawFormat f;
        AugmentReport report;
        applyScene(typed, fmt, model, Scene(), 1, out, f, &report);
        EXPECT_EQ(out.data, typed.data);
        EXPECT_TRUE(report.steps.empty());
        colorJitter(typed, fmt, model, ColorJitter(), NoiseOptions(), 1, out, f);
        EXPECT_EQ(out.data, typed.data);
        motionBlur(typed, fmt, model, linearMotionKernel(1, 0, CFA_MONO), NoiseOptions(), 1, out);
        EXPECT_EQ(out.data, typed.data);
        scaleMosaic(typed, fmt, model, 1.0, NoiseOptions(), 1, out);
        EXPECT_EQ(out.data, typed.data);
        for (const Point shift : {Point(1, 0), Point(0, -3), Point(5, 7), Point(-13, 9), Point(40, -22)}) {
            Mat expected;
            warpAffine(typed, expected, Matx23d(1, 0, shift.x, 0, 1, shift.y), typed.size(), INTER_NEAREST,
                       BORDER_REPLICATE);
            Scene scene;
            scene.shift = shift;
            std::vector<Rect> boxes = {Rect(2, 2, 4, 4)};
            applyScene(typed, fmt, model, scene, 0, out, f, nullptr, &boxes);
            EXPECT_EQ(0, norm(out, expected, NORM_INF)) << "shift " << shift << ", depth " << depth;
            EXPECT_EQ(boxes[0], (Rect(2, 2, 4, 4) + shift) & Rect(0, 0, 40, 22)) << "shift " << shift;
        }
    }
    RandomScenePolicy policy;
    policy.hueProbability = 1;
    policy.blurProbability = 1;
    for (uint64 seed = 0; seed < 50; ++seed) {
        const Scene s = policy.draw(src, fmt, seed);
        EXPECT_EQ(s.jitter.contrast, Vec4d::all(s.jitter.contrast[0])) << "seed " << seed;
        // A kernel on the pixel grid is as wide as the motion in pixels (one more for the centre tap).
        const Mat plane = linearMotionKernel(policy.blurLengthMax, 0),
                  pixel = linearMotionKernel(policy.blurLengthMax, 0, CFA_MONO);
        EXPECT_GT(pixel.cols, plane.cols);
        Mat out;
        RawFormat f;
        applyScene(src, fmt, model, s, seed, out, f);
        EXPECT_EQ(out.size(), src.size());
    }
    ColorJitter hue;
    hue.contrast = Vec4d(0.5, 0.5, 0.5, 0.6);
    Mat out;
    RawFormat f;
    EXPECT_CV_ERROR_CONTAINS(colorJitter(src, fmt, model, hue, NoiseOptions(), 1, out, f),
                             "a CFA_MONO frame has one contrast for all four sites");
}

} // namespace
} // namespace rawgment
} // namespace cv
