// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The random scene policy's draws, the seed of each output, and scene and policy files.
#include "test_augment_common.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/simulate.hpp>

namespace cv {
namespace rawgment {
namespace {

using namespace augment_test;

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
    EXPECT_EQ(r.jitter.exposureTime, 0);
    // The target's exposure is written only when stated (#79 item 10), so every other scene keeps its bytes.
    FileStorage plain("", FileStorage::WRITE | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
    s.write(plain, "scene");
    EXPECT_EQ(std::string(plain.releaseAndGetString()).find("exposure_time"), std::string::npos);
    s.jitter.exposureTime = 2.5;
    FileStorage stated("", FileStorage::WRITE | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
    s.write(stated, "scene");
    FileStorage back(stated.releaseAndGetString(), FileStorage::READ | FileStorage::MEMORY);
    EXPECT_EQ(Scene::read(back["scene"]).jitter.exposureTime, 2.5);
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
    EXPECT_CV_ERROR_CONTAINS(readScene(", exposure_time: -1"), "'exposure_time' must be a finite number");
    EXPECT_CV_ERROR_CONTAINS(readScene(", exposure_time: true"), "exposure_time");
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

} // namespace
} // namespace rawgment
} // namespace cv
