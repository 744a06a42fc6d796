// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The fit across gains and its errors (calibration_fit.hpp): the paper's protocol, single frames, the
// report's files, intervals that hold the truth, the bootstrap and the projected errors.
#include "test_calibration_common.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>

namespace cv {
namespace rawgment {
namespace {

using namespace calibration_test;

TEST(Calibration, jointFitRecoversTheSensorOnThePaperProtocol)
{
#ifdef RAWGMENT_SANITIZED_BUILD
    // 600 simulated frames for an accuracy figure; both fits run under the sanitizers in
    // reportRoundTripsThroughYamlAndJson.
    GTEST_SKIP() << "the paper protocol's accuracy is measured in the Release build only";
#endif
    const std::vector<NoiseSample>& samples = cleanProtocol();
    ASSERT_EQ(samples.size(), 3u * 2u * 24u * 24u * 24u); // no pixel clipped
    const CalibrationReport joint = calibrateNoiseModel(samples, modelOnly());
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

    CalibrationParams paper = modelOnly();
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

// A monochrome sensor's bursts of the same protocol (a chart of luminances, every pixel channel CFA_W)
// calibrate as a Bayer sensor's do: its four sites are four sub-lattices of one noise line.
TEST(Calibration, aMonochromeSensorCalibratesOnTheSameProtocol)
{
#ifdef RAWGMENT_SANITIZED_BUILD
    // A monochrome calibration runs under the sanitizers in
    // Apps.aMonochromeSensorGoesFromSimulationToAugmentation.
    GTEST_SKIP() << "the monochrome protocol's accuracy is measured in the Release build only";
#endif
    ProtocolOptions o;
    o.sensor.pattern = CFA_MONO;
    o.frames = 32;
    o.darkFrames = true; // the offset is pinned at mean 0, where Eq. 5's read terms are all the variance
    const std::vector<NoiseSample> samples = protocolSamples(o);
    ASSERT_FALSE(samples.empty());
    for (const NoiseSample& s : samples)
        ASSERT_EQ(s.channel, CFA_W);
    const CalibrationReport joint = calibrateNoiseModel(samples, modelOnly());
    const Errors e = relativeErrors(joint.model, truthModel());
    std::cout << "monochrome joint fit, 32 frames: " << e << "\n";
    // Over 12 other seeds (100-111) of this protocol the errors had standard deviations of 0.08% (alpha),
    // 0.19% (sigma_d^2) and 0.33% (sigma_r^2) around means of -0.05%, -0.05% and -0.17%: the bounds are 6,
    // 8 and 7 standard deviations.
    EXPECT_LT(std::abs(e.alpha), 0.005);
    EXPECT_LT(std::abs(e.sigmaD2), 0.015);
    EXPECT_LT(std::abs(e.sigmaR2), 0.025);
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
    const CalibrationReport r = calibrateNoiseModel(samples, modelOnly());
    const Errors e = relativeErrors(r.model, truthModel());
    std::cout << "single-frame mode (4 shots per setting): " << e << "\n";
    // 192 samples per gain with a relative spread of sqrt(2 / 141) = 12% each: the slope is known to
    // about 1.5%, so 7.5% is 5 standard errors.
    EXPECT_LT(std::abs(e.alpha), 0.075);
}

TEST(Calibration, reportRoundTripsThroughYamlAndJson)
{
    // Any calibration's report will do: a short protocol (the paper's 100 frames took 14 s under the
    // sanitizers, where this test is also what runs both fits, robust with outliers to set aside and not).
    ProtocolOptions o;
    o.frames = 8;
    o.square = 12;
    o.sensor.hotPixelFraction = 0.02;
    const std::vector<NoiseSample> samples = protocolSamples(o);
    const CalibrationReport r = calibrateNoiseModel(samples);
    ASSERT_LT(r.samplesUsed, r.samples);
    CalibrationParams paper;
    paper.method = NOISE_FIT_TWO_STAGE;
    paper.line.robust = false;
    const CalibrationReport twoStage = calibrateNoiseModel(samples, paper);
    ASSERT_EQ(twoStage.method, NOISE_FIT_TWO_STAGE);
    ASSERT_EQ(twoStage.samplesUsed, twoStage.samples); // nothing set aside without the robust fit
    const std::string dir = test::makeTempDir("calibration_report");
    for (const CalibrationReport& report : {r, twoStage})
        for (const char* name : {"/report.yml", "/report.json"}) {
            report.save(dir + name);
            const CalibrationReport back = CalibrationReport::load(dir + name);
            EXPECT_EQ(back.method, report.method);
            EXPECT_EQ(back.separable, report.separable);
            EXPECT_EQ(back.model.alpha, report.model.alpha);
            EXPECT_EQ(back.model.sigmaR2, report.model.sigmaR2);
            ASSERT_EQ(back.perGain.size(), report.perGain.size());
            EXPECT_EQ(back.perGain[2].line.b, report.perGain[2].line.b);
            EXPECT_EQ(back.perGain[1].inliers, report.perGain[1].inliers);
            EXPECT_EQ(back.samplesUsed, report.samplesUsed);
            EXPECT_EQ(back.notes, report.notes);
        }
    r.save(dir + "/report.yml");
    EXPECT_CV_ERROR_CONTAINS(CalibrationReport::load(dir + "/missing.yml"), "cannot open");
    // A method outside the enumeration is neither written as one of the two nor read back as one.
    CalibrationReport invalid = r;
    invalid.method = static_cast<NoiseFitMethod>(7);
    EXPECT_CV_ERROR_CONTAINS(invalid.save(dir + "/invalid.yml"), "method 7 is not a NoiseFitMethod");
    CalibrationParams params;
    params.method = static_cast<NoiseFitMethod>(7); // defined: the enum's underlying type is int
    EXPECT_CV_ERROR_CONTAINS(calibrateNoiseModel(samples, params), "method");
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
    const std::vector<NoiseSample> samples = protocolSamples(o);
    CalibrationParams params;
    EXPECT_EQ(params.bootstrapReplicates, 200);
#ifdef RAWGMENT_SANITIZED_BUILD
    // 200 instrumented replicates are most of 30 s; 20 run the same code, and the ratio below needs 200.
    params.bootstrapReplicates = 20;
#endif
    const CalibrationReport r = calibrateNoiseModel(samples, params);
    EXPECT_EQ(r.uncertainty.source, UNCERTAINTY_COVARIANCE);
    EXPECT_EQ(r.uncertainty.bootstrapReplicates, params.bootstrapReplicates);
    for (int k = 0; k < 3; ++k) {
        // 200 replicates give a standard error to 5% (1/sqrt(2R)); the two agree within 4 of those.
        if (params.bootstrapReplicates == 200)
            EXPECT_NEAR(r.uncertainty.bootstrapStdError[k] / r.uncertainty.fitStdError[k], 1.0, 0.2) << k;
        EXPECT_GT(r.uncertainty.bootstrapStdError[k], 0) << k;
        EXPECT_EQ(r.uncertainty.stdError[k], r.uncertainty.fitStdError[k]);
    }
    EXPECT_LT(r.uncertainty.correlation(NOISE_PARAM_SIGMA_D2, NOISE_PARAM_SIGMA_R2), 0);
    const Vec2d ci = r.interval(NOISE_PARAM_ALPHA);
    EXPECT_NEAR(0.5 * (ci[0] + ci[1]), r.model.alpha, 1e-12);
    EXPECT_NEAR(0.5 * (ci[1] - ci[0]), 1.959963984540054 * r.uncertainty.stdError[0], 1e-12);
    const Vec2d wide = r.interval(NOISE_PARAM_ALPHA, 0.99);
    EXPECT_NEAR(0.5 * (wide[1] - wide[0]), 2.5758293035489 * r.uncertainty.stdError[0], 1e-12);
    EXPECT_CV_ERROR_CONTAINS(r.interval(NOISE_PARAM_ALPHA, 1.0), "level");
    // The same seed gives the same errors on one thread as on all: 20 replicates are shared out between
    // threads as 200 are, at a tenth of the single-threaded time (the samples' own thread-invariance is the
    // simulator's, Simulate.*).
    CalibrationParams few;
    few.bootstrapReplicates = 20;
    const CalibrationReport all = calibrateNoiseModel(samples, few);
    const int threads = getNumThreads();
    setNumThreads(1);
    const CalibrationReport one = calibrateNoiseModel(samples, few);
    setNumThreads(threads);
    EXPECT_EQ(one.uncertainty.bootstrapStdError, all.uncertainty.bootstrapStdError);

    // A sensor without read noise before the gain: sigma_d^2 lands on its bound, where derivatives say
    // nothing of its error, and the bootstrap's errors are the ones reported.
    o.sensor.noise = NoiseModel(o.sensor.noise.alpha, 0.0, o.sensor.noise.sigmaR2);
    const std::vector<NoiseSample> noPreGain = protocolSamples(o);
    const CalibrationReport atBound = calibrateNoiseModel(noPreGain, params);
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
    const CalibrationReport r8 = calibrateNoiseModel(eight);
    CalibrationPlan more;
    more.frameFactor = 4;
    const Vec3d projected = projectedStdError(eight, r8, more);
#ifndef RAWGMENT_SANITIZED_BUILD
    // The 32-frame calibration is four times this test's instrumented time and runs no other code.
    o.frames = 32;
    const CalibrationReport r32 = calibrateNoiseModel(protocolSamples(o));
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(projected[k] / r32.uncertainty.stdError[k], 1.0, 0.2) << k;
#endif
    for (int k = 0; k < 3; ++k)
        EXPECT_GT(projected[k], 0) << k;
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

} // namespace
} // namespace rawgment
} // namespace cv
