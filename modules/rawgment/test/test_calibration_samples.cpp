// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The calibration's samples (calibration_samples.hpp): burst statistics, CFA-aligned squares and the
// chart-free sampling of a static scene.
#include "test_calibration_common.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

namespace cv {
namespace rawgment {
namespace {

using namespace calibration_test;

TEST(Calibration, staticSceneSamplingNeedsNoChartAndLeavesOutEdgesThatShakeMoves)
{
    ColorCheckerOptions chart;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    const ColorCheckerScene scene = makeColorCheckerScene(chart);
    const SensorSimulator sensor(test::referenceSensorParams(), scene.meanAtUnitGain.size());
    const NoiseModel truth = truthModel();
    const int frames = 16;
    // Every other frame of the shaken burst sees the scene two pixels (one CFA block) to the right.
    Mat shifted;
    warpAffine(scene.meanAtUnitGain, shifted, Matx23d(1, 0, 2, 0, 1, 0), scene.meanAtUnitGain.size(),
               INTER_NEAREST, BORDER_REPLICATE);
    std::vector<NoiseSample> calibration;
    for (double db : {6.0, 12.0, 24.0})
        for (double level : {0.2, 0.65}) {
            const double g = dbToLinearGain(db);
            BurstStatistics still(sensor.rawFormat(g)), shaken(sensor.rawFormat(g));
            for (int t = 0; t < frames; ++t) {
                Mat raw;
                sensor.capture(scene.meanAtUnitGain, g, level * 3839 / (g * 1000), 91, t, raw);
                still.add(raw);
                sensor.capture(t % 2 ? shifted : scene.meanAtUnitGain, g, level * 3839 / (g * 1000), 92, t,
                               raw);
                shaken.add(raw);
            }
            const std::vector<NoiseSample> s = sampleStaticScene(still, g);
            calibration.insert(calibration.end(), s.begin(), s.end());
            // Under shake, the kept pixels have the model's variance (each ratio has relative spread
            // sqrt(2 / 15) = 37%; over thousands of pixels the mean's is under 1%, so 3% is > 3 standard
            // errors), while the patch edges the shake moved have several times more.
            const std::vector<NoiseSample> kept = sampleStaticScene(shaken, g);
            ASSERT_GT(kept.size(), 5000u);
            double ratio = 0;
            for (const NoiseSample& k : kept)
                ratio += k.variance / truth.variance(k.mean, g) / double(kept.size());
            EXPECT_NEAR(ratio, 1.0, 0.03) << db << " dB, level " << level;
            Mat var;
            shaken.variance(var);
            Mat mean;
            shaken.mean(mean);
            double edgeRatio = 0;
            int edges = 0;
            for (const Rect& patch : scene.patches) {
                const int r = patch.y + patch.height / 2, c = patch.x; // on the patch's left edge
                edgeRatio += var.at<double>(r, c) / truth.variance(mean.at<double>(r, c), g);
                ++edges;
            }
            EXPECT_GT(edgeRatio / edges, 2.0) << "the shake must be visible for the test to mean anything";
        }
    // Without a chart, from the pixels the rule keeps. The spread of this fit at 16 frames, measured over
    // seeds 1-4 of rawgment_simulate's bursts of the same sensor (gains 6, 12, 24 dB, levels 0.2 and 0.65,
    // manifest with patches: none): alpha 0.1%, sigma_d^2 0.2%, sigma_r^2 3.9%. The bounds of 1%, 6% and
    // 15% are 10, 30 and 4 of those; alpha and sigma_d^2 keep room for the sampling's own bias, if any.
    const CalibrationReport r = calibrateNoiseModel(calibration, modelOnly());
    const Errors e = relativeErrors(r.model, truth);
    std::cout << "no chart, 16 frames: " << e << " from " << calibration.size() << " pixels\n";
    EXPECT_LT(std::abs(e.alpha), 0.01);
    EXPECT_LT(std::abs(e.sigmaD2), 0.06);
    EXPECT_LT(std::abs(e.sigmaR2), 0.15);

    BurstStatistics two(sensor.rawFormat(1));
    Mat raw;
    sensor.capture(scene.meanAtUnitGain, 1, 1, 5, 0, raw);
    EXPECT_CV_ERROR_CONTAINS(sampleStaticScene(two, 1), "at least 2 frames");
    two.add(raw);
    sensor.capture(scene.meanAtUnitGain, 1, 1, 5, 1, raw);
    two.add(raw);
    EXPECT_LE(sampleStaticScene(two, 1, 400).size(), 400u);
    EXPECT_GT(sampleStaticScene(two, 1, 400).size(), 200u) << "the grid fills most of its budget";
    EXPECT_CV_ERROR_CONTAINS(sampleStaticScene(two, 1, 3), "maxSamples");
}

TEST(Calibration, burstStatisticsResetGivesTheBitsOfANewObject)
{
    RawFormat fmt;
    fmt.blackLevel = Vec4d(60, 64, 64, 62);
    fmt.whiteLevel = 4095;
    RawFormat other = fmt;
    other.blackLevel = Vec4d::all(200);
    other.gain = 4;
    RNG rng(5);
    const auto burst = [&](Size size, int type, int frames, double level) {
        std::vector<Mat> b;
        for (int t = 0; t < frames; ++t) {
            Mat f(size, type);
            rng.fill(f, RNG::NORMAL, level, 40);
            b.push_back(f);
        }
        return b;
    };
    const std::vector<std::vector<Mat>> bursts = {burst(Size(64, 48), CV_16UC1, 7, 900),
                                                  burst(Size(64, 48), CV_16UC1, 5, 4050),
                                                  burst(Size(30, 20), CV_32FC1, 4, 300)};
    BurstStatistics reused(fmt, 3);
    for (size_t k = 0; k < bursts.size(); ++k) {
        SCOPED_TRACE(cv::format("burst %zu", k));
        const RawFormat& f = k == 1 ? other : fmt;
        if (k > 0)
            reused.reset(f);
        EXPECT_EQ(0, reused.frames());
        EXPECT_EQ(f.blackLevel, reused.format().blackLevel);
        BurstStatistics fresh(f, 3);
        for (const Mat& frame : bursts[k]) {
            reused.add(frame);
            fresh.add(frame);
        }
        EXPECT_EQ(fresh.frames(), reused.frames());
        Mat m1, m2, v1, v2, c1, c2;
        fresh.mean(m1);
        reused.mean(m2);
        fresh.variance(v1);
        reused.variance(v2);
        fresh.clippedMask(c1);
        reused.clippedMask(c2);
        EXPECT_EQ(bursts[k][0].size(), reused.size());
        EXPECT_EQ(0, cv::norm(m1, m2, NORM_INF));
        EXPECT_EQ(0, cv::norm(v1, v2, NORM_INF));
        EXPECT_EQ(0, cv::norm(c1, c2, NORM_INF));
        if (k == 1) {
            EXPECT_GT(countNonZero(c1), 10) << "the second burst reaches white";
        }
    }
    RawFormat bad = fmt;
    bad.whiteLevel = -1;
    EXPECT_CV_ERROR_CONTAINS(reused.reset(bad), "whiteLevel");
}

// The default constructor is the one cv2 wraps (#79 item 30): an object with no format refuses frames,
// naming the factory, and once reset() gives it a format it is the constructed object, bit for bit.
TEST(Calibration, aBurstMadeWithoutAFormatRefusesFramesUntilResetThenMatchesAConstructedOne)
{
    BurstStatistics unformatted;
    const Mat frame(8, 6, CV_16UC1, Scalar(700));
    EXPECT_CV_ERROR_CONTAINS(unformatted.add(frame), "no format: make it with BurstStatistics::create");
    EXPECT_EQ(0, unformatted.frames());
    EXPECT_CV_ERROR_CONTAINS(
        {
            Mat m;
            unformatted.mean(m);
        },
        "no frame was added");
    RawFormat fmt;
    fmt.blackLevel = Vec4d(60, 61, 62, 63);
    fmt.whiteLevel = 4095;
    unformatted.reset(fmt);
    BurstStatistics constructed(fmt);
    RNG rng(7);
    for (int t = 0; t < 11; ++t) {
        Mat f(8, 6, CV_16UC1);
        rng.fill(f, RNG::UNIFORM, 0, 4096);
        unformatted.add(f);
        constructed.add(f);
    }
    Mat v1, v2;
    unformatted.variance(v1);
    constructed.variance(v2);
    EXPECT_EQ(0, cv::norm(v1, v2, NORM_INF));
}

TEST(Calibration, burstStatisticsMarkClippedPixelsAndCheckFrames)
{
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(10);
    fmt.whiteLevel = 1023;
    BurstStatistics stats(fmt);
    Mat a(4, 4, CV_16UC1, Scalar(500)), b = a.clone();
    b.at<ushort>(1, 1) = 1023; // at white
    b.at<ushort>(2, 3) = 0;    // at zero
    stats.add(a);
    EXPECT_CV_ERROR_CONTAINS(
        {
            Mat v;
            stats.variance(v);
        },
        "at least 2 frames (got 1)");
    stats.add(b);
    Mat clipped;
    stats.clippedMask(clipped);
    EXPECT_EQ(countNonZero(clipped), 2);
    EXPECT_EQ(clipped.at<uchar>(1, 1), 255);
    EXPECT_EQ(clipped.at<uchar>(2, 3), 255);
    EXPECT_CV_ERROR_CONTAINS(stats.add(Mat(4, 5, CV_16UC1, Scalar(1))), "frame 2 is 5x4");
    EXPECT_CV_ERROR_CONTAINS(stats.add(Mat(4, 4, CV_32FC1, Scalar(1))), "of type CV_32FC1");
    EXPECT_CV_ERROR_CONTAINS(stats.add(Mat(4, 4, CV_8UC1, Scalar(1))), "expected CV_16UC1 or CV_32FC1");
    BurstStatistics floats(fmt);
    Mat nan(4, 4, CV_32FC1, Scalar(std::numeric_limits<float>::quiet_NaN()));
    EXPECT_CV_ERROR_CONTAINS(floats.add(nan), "NaN or Inf");
    // All pixels saturated: nothing to sample, and calibration says so.
    BurstStatistics saturated(fmt);
    for (int t = 0; t < 3; ++t)
        saturated.add(Mat(4, 4, CV_16UC1, Scalar(1023)));
    const std::vector<NoiseSample> none = sampleBurstPatches(saturated, {Rect(0, 0, 4, 4)}, 1.0);
    EXPECT_TRUE(none.empty());
    EXPECT_CV_ERROR_CONTAINS(calibrateNoiseModel(none), "no samples");
}

TEST(Calibration, squaresAreCfaAlignedAndInside)
{
    const std::vector<Rect> patches = {Rect(3, 5, 31, 29), Rect(10, 10, 24, 24), Rect(0, 0, 25, 25)};
    const std::vector<Rect> sq = cfaAlignedSquares(patches, 24);
    for (size_t i = 0; i < sq.size(); ++i) {
        EXPECT_EQ(sq[i].x % 2, 0);
        EXPECT_EQ(sq[i].y % 2, 0);
        EXPECT_EQ(sq[i].size(), Size(24, 24));
        EXPECT_EQ(sq[i] & patches[i], sq[i]) << i;
    }
    EXPECT_CV_ERROR_CONTAINS(cfaAlignedSquares({Rect(1, 1, 24, 30)}, 24), "cannot hold");
    EXPECT_CV_ERROR_CONTAINS(cfaAlignedSquares(patches, 23), "even");
}

} // namespace
} // namespace rawgment
} // namespace cv
