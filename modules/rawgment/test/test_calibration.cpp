// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <numeric>

namespace cv {
namespace rawgment {
namespace {

struct ProtocolOptions
{
    std::vector<double> gainsDb{6, 12, 24};
    std::vector<double> levels{0.2, 0.65}; // brightest patch at this fraction of the range
    int frames = 100;
    int square = 24;
    bool darkFrames = false; // a burst with the lens cap on per gain, counted at mean 0
    SensorParams sensor = test::referenceSensorParams();
    uint64 seed = 42;
};

/** The paper's protocol (Sec. 4.3) on the simulator: per gain and illumination, a burst of a chart,
 * temporal statistics, then the pixels of a 24x24 square in each of the 24 patches. */
std::vector<NoiseSample> protocolSamples(const ProtocolOptions& o)
{
    ColorCheckerOptions chart;
    chart.pattern = o.sensor.pattern;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    const ColorCheckerScene scene = makeColorCheckerScene(chart);
    const SensorSimulator sensor(o.sensor, scene.meanAtUnitGain.size());
    const std::vector<Rect> squares = cfaAlignedSquares(scene.patches, o.square);
    std::vector<NoiseSample> all;
    uint64 seed = o.seed;
    for (double db : o.gainsDb) {
        const double g = dbToLinearGain(db);
        const RawFormat fmt = sensor.rawFormat(g);
        const double range = fmt.whiteLevel - fmt.blackLevel[0];
        for (double level : o.levels) {
            const double exposure = level * range / (g * chart.illumination);
            BurstStatistics stats(fmt);
            for (int t = 0; t < o.frames; ++t) {
                Mat raw;
                sensor.capture(scene.meanAtUnitGain, g, exposure, seed, t, raw);
                stats.add(raw);
            }
            ++seed;
            const std::vector<NoiseSample> s = sampleBurstPatches(stats, squares, g);
            all.insert(all.end(), s.begin(), s.end());
        }
        if (o.darkFrames) {
            BurstStatistics dark(fmt);
            for (int t = 0; t < o.frames; ++t) {
                Mat raw;
                sensor.capture(Mat::zeros(scene.meanAtUnitGain.size(), CV_32FC1), g, 1.0, seed, t, raw);
                dark.add(raw);
            }
            ++seed;
            const std::vector<NoiseSample> d = sampleDarkBurst(dark, squares, g);
            all.insert(all.end(), d.begin(), d.end());
        }
    }
    return all;
}

const std::vector<NoiseSample>& cleanProtocol()
{
    static const std::vector<NoiseSample> samples = protocolSamples(ProtocolOptions());
    return samples;
}

const std::vector<NoiseSample>& outlierProtocol()
{
    static const std::vector<NoiseSample> samples = [] {
        ProtocolOptions o;
        o.sensor.hotPixelFraction = 0.02;
        o.sensor.deadPixelFraction = 0.01;
        o.sensor.noisyPixelFraction = 0.02; // 5% outliers in all
        o.sensor.noisyPixelVariance = 400;
        o.seed = 4242;
        return protocolSamples(o);
    }();
    return samples;
}

struct Errors
{
    double alpha, sigmaD2, sigmaR2;
};

Errors relativeErrors(const NoiseModel& fit, const NoiseModel& truth)
{
    return {fit.alpha / truth.alpha - 1, fit.sigmaD2 / truth.sigmaD2 - 1, fit.sigmaR2 / truth.sigmaR2 - 1};
}

std::ostream& operator<<(std::ostream& os, const Errors& e)
{
    return os << "alpha " << 100 * e.alpha << "%, sigma_d^2 " << 100 * e.sigmaD2 << "%, sigma_r^2 "
              << 100 * e.sigmaR2 << "%";
}

NoiseModel truthModel()
{
    return SensorSimulator(test::referenceSensorParams(), Size(2, 2)).effectiveModel();
}

TEST(Calibration, jointFitRecoversTheSensorOnThePaperProtocol)
{
    const std::vector<NoiseSample>& samples = cleanProtocol();
    ASSERT_EQ(samples.size(), 3u * 2u * 24u * 24u * 24u); // no pixel clipped
    const CalibrationReport joint = calibrateNoiseModel(samples);
    ASSERT_TRUE(joint.separable);
    EXPECT_EQ(joint.method, NOISE_FIT_JOINT);
    const Errors e = relativeErrors(joint.model, truthModel());
    std::cout << "joint fit: " << e << "\n";
    // Over 8 other seeds of this protocol the joint fit's errors had standard deviations of 0.08%
    // (alpha), 0.45% (sigma_d^2) and 1.7% (sigma_r^2) around means of -0.04%, +0.5% and -0.2%: the
    // issue's bounds of 0.5%, 3% and 5% are 6, 6 and 3 standard deviations. This seed lands at about
    // -4% on sigma_r^2, a 2.4-sigma draw, kept as it came rather than re-seeded.
    EXPECT_LT(std::abs(e.alpha), 0.005);
    EXPECT_LT(std::abs(e.sigmaD2), 0.03);
    EXPECT_LT(std::abs(e.sigmaR2), 0.05);

    CalibrationParams paper;
    paper.method = NOISE_FIT_TWO_STAGE;
    const CalibrationReport twoStage = calibrateNoiseModel(samples, paper);
    std::cout << "paper's two-stage fit on the same data: " << relativeErrors(twoStage.model, truthModel())
              << " (R^2 of a_g: " << twoStage.rSquaredSlope << ", of b_g: " << twoStage.rSquaredOffset
              << ")\n";
    EXPECT_EQ(twoStage.method, NOISE_FIT_TWO_STAGE);
    EXPECT_LT(std::abs(relativeErrors(twoStage.model, truthModel()).alpha), 0.01);
    // The cross-gain relations hold nearly exactly on model data, as in the paper (1.0000, 0.9984).
    EXPECT_GT(twoStage.rSquaredSlope, 0.999);
    EXPECT_GT(twoStage.rSquaredOffset, 0.99);
}

TEST(Calibration, perGainRSquaredIsWhatTheBurstLengthAllows)
{
    const std::vector<NoiseSample>& samples = cleanProtocol();
    const CalibrationReport report = calibrateNoiseModel(samples);
    ASSERT_EQ(report.perGain.size(), 3u);
    const NoiseModel truth = truthModel();
    for (const NoiseLineFit& f : report.perGain) {
        // A sample variance of T frames scatters around its expectation v with a relative standard
        // deviation sqrt(2 / (T - 1)). So E[SS_res] = sum 2 v^2 / (T - 1) and E[SS_tot] adds that to the
        // spread of the expectations: R^2 = 1 - E[SS_res] / E[SS_tot].
        double ssNoise = 0, sum = 0, sum2 = 0;
        int n = 0;
        for (const NoiseSample& s : samples) {
            if (s.gain != f.gain)
                continue;
            const double v = truth.variance(s.mean, s.gain);
            ssNoise += 2.0 * v * v / s.dof;
            sum += v;
            sum2 += v * v;
            ++n;
        }
        const double ssSpread = sum2 - sum * sum / n;
        const double expected = 1.0 - ssNoise / (ssSpread + ssNoise);
        std::cout << "gain " << linearGainToDb(f.gain) << " dB: R^2 " << f.rSquared
                  << ", expected from T = 100: " << expected << ", inliers " << f.inliers << "/" << f.samples
                  << "\n";
        // SS_res is a sum of ~27,000 terms dominated by the brightest few thousand; its relative
        // standard error is about 3%, so 1 - R^2 must match within 15% (5 standard errors).
        EXPECT_NEAR(1.0 - f.rSquared, 1.0 - expected, 0.15 * (1.0 - expected));
        EXPECT_GT(f.inliers, 0.995 * f.samples); // clean data: RANSAC keeps nearly everything
    }
}

TEST(Calibration, robustFitsSurviveFivePercentOutliersAndPlainLeastSquaresDoesNot)
{
    const std::vector<NoiseSample>& samples = outlierProtocol();
    const CalibrationReport robust = calibrateNoiseModel(samples);
    const Errors e = relativeErrors(robust.model, truthModel());
    std::cout << "robust joint fit with 5% outliers: " << e << "\n";
    EXPECT_LT(std::abs(e.alpha), 0.005);
    EXPECT_LT(std::abs(e.sigmaD2), 0.03);
    EXPECT_LT(std::abs(e.sigmaR2), 0.05);
    EXPECT_LT(robust.samplesUsed, 0.97 * robust.samples); // the outliers were set aside

    CalibrationParams plain;
    plain.line.robust = false;
    const CalibrationReport naive = calibrateNoiseModel(samples, plain);
    const Errors n = relativeErrors(naive.model, truthModel());
    std::cout << "plain least squares with 5% outliers: " << n << "\n";
    EXPECT_TRUE(std::abs(n.alpha) > 0.005 || std::abs(n.sigmaD2) > 0.03 || std::abs(n.sigmaR2) > 0.05);
}

TEST(Calibration, singleFrameModeIsLessExactButRight)
{
    ColorCheckerOptions chart;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    chart.vignetting = 0.3; // shading inside each patch, which the plane fit removes
    const ColorCheckerScene scene = makeColorCheckerScene(chart);
    const SensorSimulator sensor(test::referenceSensorParams(), scene.meanAtUnitGain.size());
    const std::vector<Rect> squares = cfaAlignedSquares(scene.patches, 24);
    std::vector<NoiseSample> samples;
    for (double db : {6.0, 12.0, 24.0})
        for (double level : {0.2, 0.65})
            for (int shot = 0; shot < 4; ++shot) {
                const double g = dbToLinearGain(db);
                const RawFormat fmt = sensor.rawFormat(g);
                Mat raw;
                sensor.capture(scene.meanAtUnitGain, g, level * 3839 / (g * 1000), 77, shot, raw);
                const std::vector<NoiseSample> s = sampleSingleFramePatches(raw, fmt, squares, g);
                samples.insert(samples.end(), s.begin(), s.end());
            }
    ASSERT_EQ(samples.size(), 3u * 2u * 4u * 24u * 4u);
    EXPECT_EQ(samples[0].dof, 144 - 3);
    const CalibrationReport r = calibrateNoiseModel(samples);
    const Errors e = relativeErrors(r.model, truthModel());
    std::cout << "single-frame mode (4 shots per setting): " << e << "\n";
    // 192 samples per gain with a relative spread of sqrt(2 / 141) = 12% each: the slope is known to
    // about 1.5%, so 7.5% is 5 standard errors.
    EXPECT_LT(std::abs(e.alpha), 0.075);
}

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
    const CalibrationReport r = calibrateNoiseModel(calibration);
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

/* A reset burst statistics object gives the bits of a new one: bursts of one size and type in the same
 * memory (the group of 3 leaves a partial group pending at each reset), then one of another size and type. */
TEST(Calibration, twoFrameBurstsAreNotBiasedByTheirTies)
{
    // Flat steps of two frames each (an EMVA 1288 series): a pixel's variance is d^2 / 2 of an integer
    // difference d, and 0 for the ~9% of pixels whose readings tie at 3 DN of noise. The inlier band used to
    // drop every tie, which put the read variance 10% and the slope 2% high (set 001 and this sensor alike).
    SensorParams p;
    p.noise = NoiseModel(0.1, 0.0, 9.0);
    p.blackLevel = Vec4d::all(64);
    const Size size(256, 192);
    const SensorSimulator sensor(p, size);
    const double truthRead = 9.0 + 1.0 / 12;
    std::vector<double> slopes, offsets;
    for (int seed = 1; seed <= 6; ++seed) {
        std::vector<NoiseSample> samples;
        for (int k = 0; k < 4; ++k) {
            std::vector<Mat> frames;
            // Signals 0 (dark) and 100, 400, 900 DN: the tied pixels are most of the bias at the bottom.
            sensor.captureBurst(Mat(size, CV_32FC1, Scalar(100.0 * k * k)), 1.0, 1.0, 2,
                                uint64(100 * seed + k), frames);
            BurstStatistics stats(sensor.rawFormat(1.0));
            for (const Mat& f : frames)
                stats.add(f);
            const std::vector<NoiseSample> s = sampleStaticScene(stats, 1.0);
            samples.insert(samples.end(), s.begin(), s.end());
        }
        const NoiseLineFit fit = fitNoiseLine(samples);
        slopes.push_back(fit.line.a);
        offsets.push_back(fit.line.b);
    }
    // Six seeds of 4 x 49,152 pixels: the offset's mean is known to about 0.3%, the slope's to 0.2%; the
    // bounds are five times that, and a fifth of the bias the ties made.
    const double slope = std::accumulate(slopes.begin(), slopes.end(), 0.0) / 6;
    const double offset = std::accumulate(offsets.begin(), offsets.end(), 0.0) / 6;
    EXPECT_NEAR(offset / truthRead, 1.0, 0.015);
    EXPECT_NEAR(slope / 0.1, 1.0, 0.01);
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

TEST(Calibration, reportRoundTripsThroughYamlAndJson)
{
    const CalibrationReport r = calibrateNoiseModel(cleanProtocol());
    const std::string dir = test::makeTempDir("calibration_report");
    for (const char* name : {"/report.yml", "/report.json"}) {
        r.save(dir + name);
        const CalibrationReport back = CalibrationReport::load(dir + name);
        EXPECT_EQ(back.method, r.method);
        EXPECT_EQ(back.separable, r.separable);
        EXPECT_EQ(back.model.alpha, r.model.alpha);
        EXPECT_EQ(back.model.sigmaR2, r.model.sigmaR2);
        ASSERT_EQ(back.perGain.size(), r.perGain.size());
        EXPECT_EQ(back.perGain[2].line.b, r.perGain[2].line.b);
        EXPECT_EQ(back.perGain[1].inliers, r.perGain[1].inliers);
        EXPECT_EQ(back.samplesUsed, r.samplesUsed);
        EXPECT_EQ(back.notes, r.notes);
    }
    EXPECT_CV_ERROR_CONTAINS(CalibrationReport::load(dir + "/missing.yml"), "cannot open");
    // A method outside the enumeration is neither written as one of the two nor read back as one.
    CalibrationReport invalid = r;
    invalid.method = static_cast<NoiseFitMethod>(7);
    EXPECT_CV_ERROR_CONTAINS(invalid.save(dir + "/invalid.yml"), "method 7 is not a NoiseFitMethod");
    CalibrationParams params;
    params.method = static_cast<NoiseFitMethod>(7); // defined: the enum's underlying type is int
    EXPECT_CV_ERROR_CONTAINS(calibrateNoiseModel(cleanProtocol(), params), "method");
    std::string text;
    {
        std::ifstream f(dir + "/report.yml");
        text.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    }
    const size_t at = text.find("method: joint");
    ASSERT_NE(at, std::string::npos);
    for (const char* value : {"method: 2", "method: JOINT", "method: [ joint ]"}) {
        std::ofstream(dir + "/method.yml", std::ios::trunc)
            << text.substr(0, at) << value << text.substr(at + std::strlen("method: joint"));
        EXPECT_CV_ERROR_CONTAINS(CalibrationReport::load(dir + "/method.yml"),
                                 "field 'method' must be 'joint'");
    }
}

/* The errors a calibration states are the errors it makes: over campaigns that differ only in their seed
 * (16 frames, levels that clip the brightest patches, dark frames, 12x12 squares; clean and with 5%
 * outlier pixels), (estimate - truth) / standard error must average 0 and have a mean square of 1 for
 * every parameter and both methods. Over 12 campaigns a mean square is chi2(12)/12 when the errors are
 * right, inside [0.25, 2.75] with 99.9% probability, and the mean is N(0, 1/12), inside +-1.15 (4 sd);
 * errors off by a factor 1.7 or a bias of one standard error fail. Before the mean-error correction and
 * the chi-square band the mean was -2.8 for alpha, and with noisy pixels +34 (study_calibration_coverage
 * measures the coverage over 40 campaigns). */
TEST(Calibration, intervalsHoldTheTruthAsOftenAsTheyClaim)
{
#ifdef RAWGMENT_SANITIZED_BUILD
    // 24 simulated campaigns take 40-60 s in Release and several minutes under ASan on 2 cores; the
    // library code they run (both fits, the sandwich, the band, the defect pixels) runs under the
    // sanitizers in the other calibration tests.
    GTEST_SKIP() << "the coverage campaigns run in the Release build only";
#endif
    const int campaigns = 12;
    const char* names[3] = {"alpha", "sigma_d^2", "sigma_r^2"};
    for (int outliers = 0; outliers < 2; ++outliers) {
        double z[2][3] = {}, zz[2][3] = {};
        for (int c = 0; c < campaigns; ++c) {
            ProtocolOptions o;
            o.frames = 16;
            o.square = 12;
            o.levels = {0.2, 0.65, 1.05};
            o.darkFrames = true;
            o.seed = 7000 + 100 * c + 50 * outliers;
            if (outliers) {
                o.sensor.hotPixelFraction = 0.02;
                o.sensor.deadPixelFraction = 0.01;
                o.sensor.noisyPixelFraction = 0.02;
            }
            const NoiseModel truth = SensorSimulator(o.sensor, Size(2, 2)).effectiveModel();
            const std::vector<NoiseSample> samples = protocolSamples(o);
            for (int m = 0; m < 2; ++m) {
                CalibrationParams params;
                params.method = m == 0 ? NOISE_FIT_JOINT : NOISE_FIT_TWO_STAGE;
                params.line.seed = static_cast<uint64>(c);
                params.line.ransacIterations =
                    100;                        // 5% outliers: 100 pairs miss a clean one 1e-100 of the time
                params.bootstrapReplicates = 0; // the covariance alone; the bootstrap has its own test
                const CalibrationReport r = calibrateNoiseModel(samples, params);
                ASSERT_TRUE(r.separable);
                const double est[3] = {r.model.alpha, r.model.sigmaD2, r.model.sigmaR2};
                const double tru[3] = {truth.alpha, truth.sigmaD2, truth.sigmaR2};
                for (int k = 0; k < 3; ++k) {
                    ASSERT_GT(r.uncertainty.stdError[k], 0) << names[k];
                    const double e = (est[k] - tru[k]) / r.uncertainty.stdError[k];
                    z[m][k] += e;
                    zz[m][k] += e * e;
                }
            }
        }
        for (int m = 0; m < 2; ++m)
            for (int k = 0; k < 3; ++k) {
                SCOPED_TRACE(std::string(m == 0 ? "joint " : "two-stage ") + names[k] +
                             (outliers ? ", 5% outliers" : ", clean"));
                EXPECT_LT(std::abs(z[m][k] / campaigns), 1.15);
                EXPECT_GT(zz[m][k] / campaigns, 0.25);
                EXPECT_LT(zz[m][k] / campaigns, 2.75);
            }
    }
}

TEST(Calibration, bootstrapConfirmsTheCovarianceAndStandsInAtABound)
{
    ProtocolOptions o;
    o.frames = 16;
    o.square = 12;
    o.darkFrames = true;
    const CalibrationReport r = calibrateNoiseModel(protocolSamples(o));
    EXPECT_EQ(r.uncertainty.source, UNCERTAINTY_COVARIANCE);
    EXPECT_EQ(r.uncertainty.bootstrapReplicates, 200);
    for (int k = 0; k < 3; ++k) {
        // 200 replicates give a standard error to 5% (1/sqrt(2R)); the two agree within 4 of those.
        EXPECT_NEAR(r.uncertainty.bootstrapStdError[k] / r.uncertainty.fitStdError[k], 1.0, 0.2) << k;
        EXPECT_EQ(r.uncertainty.stdError[k], r.uncertainty.fitStdError[k]);
    }
    EXPECT_LT(r.uncertainty.correlation(NOISE_PARAM_SIGMA_D2, NOISE_PARAM_SIGMA_R2), 0);
    const Vec2d ci = r.interval(NOISE_PARAM_ALPHA);
    EXPECT_NEAR(0.5 * (ci[0] + ci[1]), r.model.alpha, 1e-12);
    EXPECT_NEAR(0.5 * (ci[1] - ci[0]), 1.959963984540054 * r.uncertainty.stdError[0], 1e-12);
    const Vec2d wide = r.interval(NOISE_PARAM_ALPHA, 0.99);
    EXPECT_NEAR(0.5 * (wide[1] - wide[0]), 2.5758293035489 * r.uncertainty.stdError[0], 1e-12);
    EXPECT_CV_ERROR_CONTAINS(r.interval(NOISE_PARAM_ALPHA, 1.0), "level");
    // The same seed gives the same errors on one thread as on all.
    const int threads = getNumThreads();
    setNumThreads(1);
    const CalibrationReport one = calibrateNoiseModel(protocolSamples(o));
    setNumThreads(threads);
    EXPECT_EQ(one.uncertainty.bootstrapStdError, r.uncertainty.bootstrapStdError);

    // A sensor without read noise before the gain: sigma_d^2 lands on its bound, where derivatives say
    // nothing of its error, and the bootstrap's errors are the ones reported.
    o.sensor.noise = NoiseModel(o.sensor.noise.alpha, 0.0, o.sensor.noise.sigmaR2);
    const std::vector<NoiseSample> noPreGain = protocolSamples(o);
    const CalibrationReport atBound = calibrateNoiseModel(noPreGain);
    if (atBound.model.sigmaD2 == 0) {
        EXPECT_EQ(atBound.uncertainty.source, UNCERTAINTY_BOOTSTRAP);
        EXPECT_GT(atBound.uncertainty.stdError[1], 0);
        EXPECT_LT(atBound.interval(NOISE_PARAM_SIGMA_D2)[0], 0); // the data cannot tell it from 0
        CalibrationParams none;
        none.bootstrapReplicates = 0;
        const CalibrationReport noBootstrap = calibrateNoiseModel(noPreGain, none);
        EXPECT_EQ(noBootstrap.uncertainty.stdError[1], 0);
        EXPECT_TRUE(std::any_of(noBootstrap.notes.begin(), noBootstrap.notes.end(), [](const std::string& n) {
            return n.find("no standard error without the bootstrap") != std::string::npos;
        }));
    } else {
        // Just above the bound: its interval must still reach 0.
        EXPECT_LT(atBound.interval(NOISE_PARAM_SIGMA_D2)[0], 0);
    }
    CalibrationParams bad;
    bad.bootstrapReplicates = 1;
    EXPECT_CV_ERROR_CONTAINS(calibrateNoiseModel(noPreGain, bad), "bootstrapReplicates");
}

/* What more data buys, against what it bought: the errors projected for 4x the frames of an 8-frame
 * calibration against the errors the 32-frame calibration states. The projection is asymptotic and each
 * stated error is itself known to ~5% (the sandwich of ~10^4 samples), so they agree within 20%. More pixels
 * follow 1/sqrt(p) exactly, and a second gain makes the read terms of a one-gain calibration known. */
TEST(Calibration, projectedErrorsMatchTheErrorsOfTheLargerCalibration)
{
    ProtocolOptions o;
    o.frames = 8;
    o.square = 12;
    o.darkFrames = true;
    const std::vector<NoiseSample> eight = protocolSamples(o);
    o.frames = 32;
    const CalibrationReport r8 = calibrateNoiseModel(eight), r32 = calibrateNoiseModel(protocolSamples(o));
    CalibrationPlan more;
    more.frameFactor = 4;
    const Vec3d projected = projectedStdError(eight, r8, more);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(projected[k] / r32.uncertainty.stdError[k], 1.0, 0.2) << k;
    CalibrationPlan pixels;
    pixels.pixelFactor = 4;
    const Vec3d quarter = projectedStdError(eight, r8, pixels);
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(quarter[k], 0.5 * r8.uncertainty.stdError[k], 1e-9 * r8.uncertainty.stdError[k]) << k;

    std::vector<NoiseSample> oneGain;
    for (const NoiseSample& s : eight)
        if (s.gain == eight.front().gain)
            oneGain.push_back(s);
    const CalibrationReport single = calibrateNoiseModel(oneGain);
    ASSERT_FALSE(single.separable);
    EXPECT_GT(single.uncertainty.stdError[0], 0);
    EXPECT_EQ(single.uncertainty.stdError[1], 0);
    CalibrationPlan gain;
    gain.addGain = 8 * oneGain.front().gain;
    const Vec3d withGain = projectedStdError(oneGain, single, gain);
    EXPECT_GT(withGain[1], 0);
    EXPECT_GT(withGain[2], 0);
    EXPECT_LT(withGain[0], single.uncertainty.stdError[0]);
    CalibrationPlan invalid;
    invalid.frameFactor = 0;
    EXPECT_CV_ERROR_CONTAINS(projectedStdError(eight, r8, invalid), "frameFactor");
}

TEST(Calibration, reportErrorsRoundTripAndFirstVersionReportsStillLoad)
{
    ProtocolOptions o;
    o.frames = 16;
    o.square = 12;
    const CalibrationReport r = calibrateNoiseModel(protocolSamples(o));
    const std::string dir = test::makeTempDir("calibration_errors");
    r.save(dir + "/report.yml");
    const CalibrationReport back = CalibrationReport::load(dir + "/report.yml");
    EXPECT_EQ(back.uncertainty.source, r.uncertainty.source);
    EXPECT_EQ(back.uncertainty.stdError, r.uncertainty.stdError);
    EXPECT_EQ(back.uncertainty.bootstrapStdError, r.uncertainty.bootstrapStdError);
    EXPECT_EQ(back.uncertainty.bootstrapReplicates, r.uncertainty.bootstrapReplicates);
    for (int i = 0; i < 9; ++i)
        EXPECT_EQ(back.uncertainty.covariance.val[i], r.uncertainty.covariance.val[i]);
    EXPECT_EQ(back.perGain[1].offsetStdError, r.perGain[1].offsetStdError);
    EXPECT_EQ(back.perGain[1].slopeOffsetCorrelation, r.perGain[1].slopeOffsetCorrelation);
    std::string text;
    {
        std::ifstream f(dir + "/report.yml");
        text.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
    }
    EXPECT_NE(text.find("format_version: 3"), std::string::npos);
    EXPECT_EQ(back.readExcessKurtosis, r.readExcessKurtosis);
    EXPECT_EQ(back.readExcessKurtosisEstimated, r.readExcessKurtosisEstimated);
    // Version 3 added the read noise's kurtosis: a version 2 file without it loads with 0, and one with it
    // names the key.
    {
        const size_t v = text.find("format_version: 3"), k = text.find("read_excess_kurtosis:"),
                     end = text.find("per_gain:");
        ASSERT_TRUE(v != std::string::npos && k != std::string::npos && end != std::string::npos && k < end);
        const std::string v2 = text.substr(0, v) + "format_version: 2" + text.substr(v + 17);
        std::ofstream(dir + "/v2_with_kurtosis.yml") << v2;
        EXPECT_CV_ERROR_CONTAINS(CalibrationReport::load(dir + "/v2_with_kurtosis.yml"),
                                 "unknown key 'read_excess_kurtosis'");
        const size_t k2 = v2.find("read_excess_kurtosis:"), end2 = v2.find("per_gain:");
        std::ofstream(dir + "/v2.yml") << v2.substr(0, k2) << v2.substr(end2);
        const CalibrationReport v2back = CalibrationReport::load(dir + "/v2.yml");
        EXPECT_EQ(0.0, v2back.readExcessKurtosis);
        EXPECT_FALSE(v2back.readExcessKurtosisEstimated);
        EXPECT_EQ(v2back.model.alpha, r.model.alpha);
    }
    // A report without errors is written as version 1, which loads with none.
    CalibrationReport old = r;
    old.uncertainty = ModelUncertainty();
    old.save(dir + "/old.yml");
    const CalibrationReport oldBack = CalibrationReport::load(dir + "/old.yml");
    EXPECT_EQ(oldBack.uncertainty.source, UNCERTAINTY_NONE);
    EXPECT_EQ(oldBack.model.alpha, r.model.alpha);
    EXPECT_CV_ERROR_CONTAINS(oldBack.interval(NOISE_PARAM_ALPHA), "no uncertainty");
    // Version 2's keys are unknown to version 1, and a misspelt key of the uncertainty is named.
    const size_t at = text.find("format_version: 3");
    std::ofstream(dir + "/mixed.yml")
        << text.substr(0, at) << "format_version: 1" << text.substr(at + std::strlen("format_version: 3"));
    EXPECT_CV_ERROR_CONTAINS(CalibrationReport::load(dir + "/mixed.yml"), "uncertainty");
    const size_t source = text.find("source:");
    ASSERT_NE(source, std::string::npos);
    std::ofstream(dir + "/typo.yml") << text.substr(0, source) << "sauce:" << text.substr(source + 7);
    EXPECT_CV_ERROR_CONTAINS(CalibrationReport::load(dir + "/typo.yml"), "sauce");
    // Version 0 was never written: not called newer; 9 is.
    for (const char* version : {"0", "9"}) {
        std::ofstream(dir + "/version.yml") << text.substr(0, at) << "format_version: " << version
                                            << text.substr(at + std::strlen("format_version: 3"));
        EXPECT_CV_ERROR_CONTAINS(CalibrationReport::load(dir + "/version.yml"),
                                 std::string("format_version ") + version +
                                     " is not supported; this build reads "
                                     "versions 1 to 3" +
                                     (version[0] == '9' ? " (a newer" : ""));
    }
}

// A sensor with every dark-frame component (the same kind as the augmentation tests'), quantised.
SensorParams darkSensor(Size size, double lambda)
{
    return test::darkComponentSensorParams(size, lambda, 23);
}

struct DarkRun
{
    DarkCalibrationReport report;
    SensorParams truth;
    std::vector<double> gains;
};

DarkRun calibrateSimulatedDark(int frames, double lambda, uint64 seed)
{
    const Size size(128, 128);
    DarkRun run;
    run.truth = darkSensor(size, lambda);
    const SensorSimulator sensor(run.truth, size);
    run.gains = {1, 4, 16};
    std::vector<std::vector<Mat>> bursts(run.gains.size());
    const Mat dark = Mat::zeros(size, CV_32FC1);
    for (size_t k = 0; k < run.gains.size(); ++k)
        sensor.captureBurst(dark, run.gains[k], 1.0, frames, seed + k, bursts[k]);
    // The base a calibration from light bursts gives: per-pixel temporal variances hold the rows too.
    NoiseModel base = sensor.effectiveModel();
    base.sigmaD2 += run.truth.noise.rowSigmaD2;
    base.sigmaR2 += run.truth.noise.rowSigmaR2;
    run.report = calibrateDarkNoise(bursts, run.gains, sensor.rawFormat(1.0), base);
    return run;
}

TEST(Calibration, darkFramesRecoverRowNoiseDarkShadingAndTheReadNoiseShape)
{
    const int T = 32;
    const DarkRun run = calibrateSimulatedDark(T, -0.1, 40);
    const DarkCalibrationReport& r = run.report;
    const NoiseModel& truth = run.truth.noise;
    ASSERT_EQ(3u, r.gains.size());
    // Row noise: weighted least squares over the gains; its covariance (X^T W X)^-1 from the per-gain
    // standard errors gives each part's standard error. Five of them.
    double s00 = 0, s01 = 0, s11 = 0;
    for (const DarkGainStatistics& g : r.gains) {
        const double w = 1 / (g.rowVarianceSE * g.rowVarianceSE), g2 = g.gain * g.gain;
        s00 += w * g2 * g2;
        s01 += w * g2;
        s11 += w;
        EXPECT_NEAR(g.rowVariance, truth.rowVariance(g.gain), 5 * g.rowVarianceSE) << "gain " << g.gain;
    }
    const double det = s00 * s11 - s01 * s01;
    EXPECT_NEAR(r.model.rowSigmaD2, truth.rowSigmaD2, 5 * std::sqrt(s11 / det));
    EXPECT_NEAR(r.model.rowSigmaR2, truth.rowSigmaR2, 5 * std::sqrt(s00 / det));
    // The rows move out of the base's read terms, which are then the pixel's own, to the rows' error.
    const NoiseModel pixelOnly = SensorSimulator(run.truth, Size(2, 2)).effectiveModel();
    EXPECT_NEAR(r.model.sigmaD2, pixelOnly.sigmaD2, 5 * std::sqrt(s11 / det));
    EXPECT_NEAR(r.model.sigmaR2, pixelOnly.sigmaR2, 5 * std::sqrt(s00 / det));
    // Dark shading: each pixel's weighted line through its T-frame means M_k, slope = sum h_k M_k and
    // offset = sum o_k M_k. A mean carries pixel noise (independent per pixel) and the row offsets'
    // mean (shared by a row), so the mean square error over the map is P + R, with the standard error
    // sqrt(2 P^2 / pixels + 2 R^2 / rows) (a row's part counts once per row). Five of them.
    double sw = 0, sg = 0, sgg = 0;
    std::vector<double> w;
    for (const DarkGainStatistics& g : r.gains) {
        w.push_back(T / (g.pixelVariance + g.rowVariance));
        sw += w.back();
        sg += w.back() * g.gain;
        sgg += w.back() * g.gain * g.gain;
    }
    const double shadingDet = sw * sgg - sg * sg;
    double slopeP = 0, slopeR = 0, offsetP = 0, offsetR = 0;
    for (size_t k = 0; k < r.gains.size(); ++k) {
        const DarkGainStatistics& g = r.gains[k];
        const double h = w[k] * (sw * g.gain - sg) / shadingDet, o = w[k] * (sgg - sg * g.gain) / shadingDet;
        slopeP += h * h * g.pixelVariance / T;
        slopeR += h * h * g.rowVariance / T;
        offsetP += o * o * g.pixelVariance / T;
        offsetR += o * o * g.rowVariance / T;
    }
    ASSERT_TRUE(r.model.hasDarkShading());
    const double pixels = static_cast<double>(truth.darkShadingPerGain.total()),
                 rows = truth.darkShadingPerGain.rows;
    const double mseSlope =
        std::pow(norm(r.model.darkShadingPerGain, truth.darkShadingPerGain, NORM_L2), 2) / pixels;
    const double mseOffset =
        std::pow(norm(r.model.darkShadingOffset, truth.darkShadingOffset, NORM_L2), 2) / pixels;
    EXPECT_NEAR(mseSlope, slopeP + slopeR,
                5 * std::sqrt(2 * slopeP * slopeP / pixels + 2 * slopeR * slopeR / rows))
        << "B_d";
    EXPECT_NEAR(mseOffset, offsetP + offsetR,
                5 * std::sqrt(2 * offsetP * offsetP / pixels + 2 * offsetR * offsetR / rows))
        << "B_r";
    // Lambda: darkFrameLambdaAccuracyPerNumberOfFrames bounds the bias by 0.015 and the spread over
    // seeds by 0.005 (measured: 0.005 and 0.004 at 32 frames); bias + 3 spreads.
    ASSERT_TRUE(r.model.tukeyRead);
    EXPECT_NEAR(r.model.tukeyLambda, -0.1, 0.015 + 3 * 0.005);
    EXPECT_GT(r.ppccBest, r.ppccGaussian);
    // Shapiro-Wilk rejects the heavy-tailed residuals with or without the rows.
    EXPECT_LT(r.gains[2].after.pValue, 1e-3);
    std::cout << "row d2 " << r.model.rowSigmaD2 << " (truth " << truth.rowSigmaD2 << "), r2 "
              << r.model.rowSigmaR2 << " (" << truth.rowSigmaR2 << "); shading mse B_d " << mseSlope
              << " (expected " << slopeP + slopeR << "), B_r " << mseOffset << " (" << offsetP + offsetR
              << "); lambda " << r.model.tukeyLambda << ", PPCC " << r.ppccBest << " (Gaussian "
              << r.ppccGaussian << "); SW p with rows " << r.gains[2].before.pValue << ", without "
              << r.gains[2].after.pValue << "\n";
}

// The accuracy of lambda that docs/calibrate_your_camera.md states, per number of frames (128 x 128
// dark frames at gains 1, 4 and 16, quantised): the correction for the temporal mean and rounding leaves
// a bias below 0.015 (measured +0.009 at 8 frames, +0.005 at 32, 0.002 at lambda 0.14), and three seeds
// spread by less than 0.005 (measured 0.001 to 0.004). A Gaussian (0.14) and a heavy tail (-0.1).
TEST(Calibration, darkFrameLambdaAccuracyPerNumberOfFrames)
{
    for (int T : {8, 32}) {
        for (double lambda : {-0.1, 0.14}) {
            std::vector<double> fitted;
            for (int i = 0; i < 3; ++i)
                fitted.push_back(calibrateSimulatedDark(T, lambda, 1000 + 10 * i).report.model.tukeyLambda);
            double mean = 0, var = 0;
            for (double l : fitted)
                mean += l / fitted.size();
            for (double l : fitted)
                var += (l - mean) * (l - mean) / (fitted.size() - 1);
            EXPECT_NEAR(mean, lambda, 0.015) << T << " frames";
            EXPECT_LT(std::sqrt(var), 0.005) << T << " frames";
            std::cout << T << " frames, lambda " << lambda << ": mean " << mean << ", sd " << std::sqrt(var)
                      << "\n";
        }
    }
}

TEST(Calibration, darkBurstsHaveOneHomeForTheirSamplesAndStatistics)
{
    // sampleDarkBurst(): sampleBurstPatches() at mean 0, nothing else changed.
    const Size size(48, 32);
    const SensorSimulator sensor(test::darkComponentSensorParams(size, -0.05, 3), size);
    const double gain = 4;
    std::vector<Mat> burst;
    sensor.captureBurst(Mat::zeros(size, CV_32FC1), gain, 1.0, 8, 5, burst);
    BurstStatistics stats(sensor.rawFormat(gain));
    for (const Mat& f : burst)
        stats.add(f);
    const std::vector<Rect> region = {Rect(8, 8, 32, 16)};
    const std::vector<NoiseSample> plain = sampleBurstPatches(stats, region, gain),
                                   dark = sampleDarkBurst(stats, region, gain);
    ASSERT_EQ(plain.size(), dark.size());
    for (size_t k = 0; k < dark.size(); ++k) {
        EXPECT_EQ(0.0, dark[k].mean);
        EXPECT_EQ(plain[k].variance, dark[k].variance);
        EXPECT_EQ(plain[k].pixel, dark[k].pixel);
    }
    // darkBurstStatistics(): the numbers calibrateDarkNoise() reports for that gain, bit for bit.
    Mat pixelMean;
    const DarkGainStatistics one = darkBurstStatistics(burst, sensor.rawFormat(gain), gain, pixelMean);
    DarkCalibrationParams shapeOnly;
    shapeOnly.rowNoise = shapeOnly.darkShading = false;
    const DarkCalibrationReport report =
        calibrateDarkNoise({burst}, {gain}, sensor.rawFormat(gain), sensor.effectiveModel(), shapeOnly);
    ASSERT_EQ(1u, report.gains.size());
    EXPECT_EQ(report.gains[0].rowMeanVar, one.rowMeanVar);
    EXPECT_EQ(report.gains[0].pixelVariance, one.pixelVariance);
    EXPECT_EQ(report.gains[0].excessKurtosis, one.excessKurtosis);
    EXPECT_EQ(size, pixelMean.size());
    EXPECT_EQ(CV_64FC1, pixelMean.type());
    EXPECT_CV_ERROR_CONTAINS(darkBurstStatistics({burst[0], burst[1]}, sensor.rawFormat(gain), gain),
                             "at least 3 are needed");
}

TEST(Calibration, darkFrameCalibrationRejectsWhatItCannotFit)
{
    const Size size(8, 8);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    std::vector<std::vector<Mat>> bursts(1);
    sensor.captureBurst(Mat::zeros(size, CV_32FC1), 2.0, 1.0, 4, 1, bursts[0]);
    const RawFormat fmt = sensor.rawFormat(2.0);
    const NoiseModel base = sensor.effectiveModel();
    EXPECT_CV_ERROR_CONTAINS(calibrateDarkNoise(bursts, {2.0}, fmt, base), "2 or more distinct gains");
    DarkCalibrationParams shapeOnly;
    shapeOnly.rowNoise = shapeOnly.darkShading = false;
    EXPECT_NO_THROW(calibrateDarkNoise(bursts, {2.0}, fmt, base, shapeOnly));
    EXPECT_CV_ERROR_CONTAINS(calibrateDarkNoise(bursts, {2.0, 4.0}, fmt, base), "1 bursts but 2 gains");
    std::vector<std::vector<Mat>> short_ = {{bursts[0][0], bursts[0][1]}};
    EXPECT_CV_ERROR_CONTAINS(calibrateDarkNoise(short_, {2.0}, fmt, base, shapeOnly),
                             "at least 3 are needed");
    std::vector<std::vector<Mat>> mixed = bursts;
    mixed[0][2] = Mat::zeros(4, 4, CV_16UC1);
    EXPECT_CV_ERROR_CONTAINS(calibrateDarkNoise(mixed, {2.0}, fmt, base, shapeOnly), "every frame must be");
    DarkCalibrationParams badRange;
    badRange.lambdaMin = -0.5;
    EXPECT_CV_ERROR_CONTAINS(calibrateDarkNoise(bursts, {2.0}, fmt, base, badRange), "lambdaMin");
    // Constant or all-clipped frames: an error that says so, not "sigmaD2 ... (got -nan)".
    for (double level : {fmt.blackLevel[0], fmt.whiteLevel}) {
        SCOPED_TRACE(level);
        std::vector<std::vector<Mat>> flat(2, std::vector<Mat>(4, Mat(size, CV_16UC1, Scalar(level))));
        EXPECT_CV_ERROR_CONTAINS(calibrateDarkNoise(flat, {2.0, 8.0}, fmt, base),
                                 "the 4 frames at gain 2 do not vary");
    }
}

} // namespace
} // namespace rawgment
} // namespace cv
