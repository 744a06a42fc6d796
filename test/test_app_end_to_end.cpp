// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The apps in a row (simulate, calibrate, validate, augment) on small inputs, and validate's refusals.
#include "app_runs.hpp"

#include <gtest/gtest.h>
#include <opencv2/rawgment.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

namespace {

using namespace rawgment_app_tests;

//! The rows of rawgment_validate's validation.csv after its header, each its 11 numbers (factor, mean bounds,
//! mean, pixels, the real and the three augmented variances, the bright burst's mean and variance).
std::vector<std::vector<double>> validationRows(const std::string& path)
{
    std::istringstream csv(readText(path));
    std::string line;
    std::getline(csv, line);
    std::vector<std::vector<double>> rows;
    while (std::getline(csv, line)) {
        std::vector<double> v;
        std::stringstream cells(line);
        std::string cell;
        while (std::getline(cells, cell, ','))
            v.push_back(std::stod(cell));
        EXPECT_EQ(11u, v.size()) << line;
        v.resize(11);
        rows.push_back(v);
    }
    return rows;
}

TEST(Apps, validateRefusesFramesOfAnotherSizeNamingTheFiles)
{
    // Target frames smaller than the bright ones were read out of bounds (ASan: heap-buffer-overflow).
    const std::string dir = freshDir("validate_sizes");
    for (const char* run : {"big --patch=40", "small --patch=20"}) {
        const std::string name(run, std::string(run).find(' '));
        const AppRun r =
            runApp("rawgment_simulate", "--out='" + dir + "/" + name + "' --frames=3 --gains=12 " +
                                            "--levels=0.5 --format=png " + (std::strchr(run, ' ') + 1));
        ASSERT_EQ(0, r.status) << r.output;
    }
    std::ofstream(dir + "/mixed.yml")
        << "%YAML:1.0\nvalidation_manifest:\n  gain_db: 12\n"
        << "  bright: [big/validation/bright/frame_000.png, "
           "big/validation/bright/frame_001.png]\n"
        << "  targets:\n    - { factor: 0.5, files: [small/validation/x0.50/frame_000.png, "
           "small/validation/x0.50/frame_001.png] }\n";
    const AppRun r =
        runApp("rawgment_validate", "'" + dir + "/mixed.yml' --model='" + dir +
                                        "/big/truth_noise_model.yml' --out='" + dir + "/val' --plots=false");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("small/validation/x0.50/frame_000.png")) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("one size and type")) << r.output;
}

TEST(Apps, simulateCalibrateValidateAugmentEndToEnd)
{
    const std::string dir = freshDir("pipeline");
    // 1. Simulate. 32 frames keep the test short and still pin the model (tolerances below).
    const std::string simulate =
        cv::format("--out='%s/sim' --frames=%d --seed=5", dir.c_str(), framesOfThisBuild(32));
    AppRun r = runApp("rawgment_simulate", simulate);
    ASSERT_EQ(0, r.status) << r.output;
    ASSERT_TRUE(exists(dir + "/sim/manifest.yml"));
    ASSERT_TRUE(exists(dir + "/sim/validation_manifest.yml"));
    r = runApp("rawgment_simulate", simulate);
    EXPECT_EQ(1, r.status) << "a second run must not overwrite the first";
    EXPECT_NE(std::string::npos, r.output.find("already exists")) << r.output;

    // 2. Calibrate.
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    ASSERT_EQ(0, r.status) << r.output;
    const cv::rawgment::NoiseModel truth = cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
    const cv::rawgment::NoiseModel fitted = cv::rawgment::NoiseModel::load(dir + "/cal/noise_model.yml");
    // The joint fit's spread over seeds at 100 frames is 0.08% / 0.45% / 1.7% (docs/performance.md,
    // study_calibration); a variance of 32 frames is sqrt(99/31) = 1.8x noisier. The bounds are about 5 of
    // those spreads.
    if (kAccuracyChecked) {
        EXPECT_NEAR(truth.alpha, fitted.alpha, 0.01 * truth.alpha);
        EXPECT_NEAR(truth.sigmaD2, fitted.sigmaD2, 0.04 * truth.sigmaD2);
        EXPECT_NEAR(truth.sigmaR2, fitted.sigmaR2, 0.15 * truth.sigmaR2);
    }
    for (const char* f : {"calibration_report.yml", "samples.csv", "lines.csv", "shapiro.csv"})
        EXPECT_TRUE(exists(dir + "/cal/" + f)) << f;
    EXPECT_EQ(kAccuracyChecked ? 200 : kSanitizedBootstrapReplicates,
              cv::rawgment::CalibrationReport::load(dir + "/cal/calibration_report.yml")
                  .uncertainty.bootstrapReplicates)
        << "--bootstrap reaches the calibration";
    for (const char* png :
         {"calib_mean_variance.png", "calib_histograms.png", "calib_cross_gain.png", "shapiro_pvalue.png"})
        expectPngDecodes(dir + "/cal/" + png);
    const std::string modelBefore = readText(dir + "/cal/noise_model.yml");
    // An identical rerun finds its own outputs and succeeds; an output changed since is never overwritten.
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_EQ(modelBefore, readText(dir + "/cal/noise_model.yml"));
    const std::string linesBefore = readText(dir + "/cal/lines.csv");
    std::ofstream(dir + "/cal/lines.csv", std::ios::app) << "edited\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status);
    EXPECT_NE(r.output.find("lines.csv' already exists"), std::string::npos) << r.output;
    EXPECT_EQ(linesBefore + "edited\n", readText(dir + "/cal/lines.csv"))
        << "an existing output is never overwritten";
    std::ofstream(dir + "/cal/lines.csv", std::ios::trunc) << linesBefore;
    // A run that died before its plots and its last table is completed by the same command.
    std::remove((dir + "/cal/shapiro_pvalue.png").c_str());
    std::remove((dir + "/cal/variance_ratio_histogram.csv").c_str());
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(0, r.status) << r.output;
    expectPngDecodes(dir + "/cal/shapiro_pvalue.png");
    EXPECT_TRUE(exists(dir + "/cal/variance_ratio_histogram.csv"));
    EXPECT_EQ(modelBefore, readText(dir + "/cal/noise_model.yml"));
    // ...but never over an output that is not what it computes.
    std::remove((dir + "/cal/shapiro_pvalue.png").c_str());
    std::ofstream(dir + "/cal/lines.csv") << "not these lines\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_EQ("not these lines\n", readText(dir + "/cal/lines.csv"));

    // 2b. The same bursts with the patches detected by cv::mcc (the sample's method) instead of given.
    std::string manifest = readText(dir + "/sim/manifest.yml");
    const size_t at = manifest.find("patches.yml");
    ASSERT_NE(std::string::npos, at);
    manifest.replace(at - 1, std::string("\"patches.yml\"").size(), "detect");
    {
        std::ofstream f(dir + "/sim/manifest_detect.yml");
        f << manifest;
    }
    r = runApp("rawgment_calibrate",
               "'" + dir + "/sim/manifest_detect.yml' --side=12 --plots=false --out='" + dir + "/cal_detect'",
               AllocationStacks::FULL);
    ASSERT_EQ(0, r.status) << r.output << manifest;
    EXPECT_NE(std::string::npos, r.output.find("patches detected with cv::mcc")) << r.output;
    // A quarter of the pixels of the given squares: alpha still within 2% (about 5 of its spreads).
    if (kAccuracyChecked)
        EXPECT_NEAR(truth.alpha, cv::rawgment::NoiseModel::load(dir + "/cal_detect/noise_model.yml").alpha,
                    0.02 * truth.alpha);

    // 3. Validate: ACCOUNT_PRIOR matches the real darker bursts, IGNORE_PRIOR overshoots, NONE undershoots.
    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/cal/noise_model.yml' --out='" + dir + "/val'");
    ASSERT_EQ(0, r.status) << r.output;
    expectPngDecodes(dir + "/val/validation.png");
    double real = 0, none = 0, ignore = 0, account = 0;
    int rows = 0;
    for (const std::vector<double>& v : validationRows(dir + "/val/validation.csv")) {
        if (v[0] != 0.5)
            continue;
        real += v[5];
        none += v[6];
        ignore += v[7];
        account += v[8];
        ++rows;
    }
    ASSERT_GT(rows, 3);
    // Pooled over ~10k pixels x 31 degrees of freedom the ratio's noise is far below 1%; 3% allows for the
    // model error of a 32-frame calibration. The prior noise of the x0.5 conversion is half the target's
    // signal noise, so IGNORE_PRIOR lands ~1.5x high and NONE ~0.5x low.
    if (kAccuracyChecked)
        EXPECT_NEAR(1.0, account / real, 0.03);
    EXPECT_GT(ignore / real, 1.3);
    EXPECT_LT(none / real, 0.7);

    // 4. Augment two inputs twice each with a fixed scene; a second run resumes (skips everything).
    writeExposureScene(dir + "/scene.yml", 0.25, 2.0);
    const std::string in0 = dir + "/sim/g06dB_level0.90/frame_000.dng",
                      in1 = dir + "/sim/g06dB_level0.90/frame_001.dng";
    const std::string inputBytes = readText(in0);
    const std::string args = "--model='" + dir + "/cal/noise_model.yml' --scene='" + dir +
                             "/scene.yml' --out='" + dir + "/aug' --variants=2 --preview=true '" + in0 +
                             "' '" + in1 + "'";
    r = runApp("rawgment_augment", args);
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 4 outputs")) << r.output;
    cv::Mat out;
    const cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(dir + "/aug/frame_000_v01.dng", out);
    EXPECT_NEAR(2.0 * cv::rawgment::dbToLinearGain(6), meta.format.gain, 1e-9)
        << "the new gain is in the sidecar";
    EXPECT_TRUE(meta.hasScene);
    expectPngDecodes(dir + "/aug/frame_001_v00_preview.png");
    r = runApp("rawgment_augment", args);
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("skipped 4")) << r.output;
    EXPECT_EQ(inputBytes, readText(in0)) << "inputs are never modified";
}

// A monochrome sensor through the same apps: its frames are LinearRaw DNGs, its calibration finds the sensor,
// its validation matches the darker captures with ACCOUNT_PRIOR only, and its augmented frames stay
// monochrome. The library's tests hold the accuracy
// (Calibration.aMonochromeSensorCalibratesOnTheSameProtocol); 16 frames keep this one short.
TEST(Apps, aMonochromeSensorGoesFromSimulationToAugmentation)
{
    const std::string dir = freshDir("mono_pipeline");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir + "/sim' --pattern=MONO --frames=16 --seed=3");
    ASSERT_EQ(0, r.status) << r.output;
    const cv::rawgment::RawImage frame = cv::rawgment::readRaw(dir + "/sim/g06dB_level0.90/frame_000.dng");
    EXPECT_EQ(cv::rawgment::CFA_MONO, frame.format.pattern);
    r = runApp("rawgment_simulate", "--out='" + dir + "/bad' --pattern=RGBW");
    EXPECT_EQ(2, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("expected one of RGGB, BGGR, GRBG, GBRG, MONO")) << r.output;

    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --plots=false --out='" + dir + "/cal'");
    ASSERT_EQ(0, r.status) << r.output;
    const cv::rawgment::NoiseModel truth = cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
    const cv::rawgment::NoiseModel fitted = cv::rawgment::NoiseModel::load(dir + "/cal/noise_model.yml");
    // At 100 frames the joint fit's alpha spreads by 0.08% over seeds; 16 frames are sqrt(99 / 15) = 2.6x
    // noisier: 2% is more than 9 of those spreads.
    EXPECT_NEAR(truth.alpha, fitted.alpha, 0.02 * truth.alpha);

    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/cal/noise_model.yml' --plots=false --out='" + dir + "/val'");
    ASSERT_EQ(0, r.status) << r.output;
    double real = 0, none = 0, ignore = 0, account = 0;
    for (const std::vector<double>& v : validationRows(dir + "/val/validation.csv")) {
        real += v[5];
        none += v[6];
        ignore += v[7];
        account += v[8];
    }
    // As in simulateCalibrateValidateAugmentEndToEnd, with half the frames: 5% for the ratio pooled over the
    // validation bins (both factors), while IGNORE_PRIOR and NONE miss by far more.
    EXPECT_NEAR(1.0, account / real, 0.05);
    EXPECT_GT(ignore / real, 1.2);
    EXPECT_LT(none / real, 0.8);

    cv::rawgment::RandomScenePolicy policy;
    policy.hueProbability = 1;
    policy.blurProbability = 1;
    policy.geometryProbability = 1;
    policy.save(dir + "/policy.yml");
    r = runApp("rawgment_augment", "--model='" + dir + "/cal/noise_model.yml' --policy='" + dir +
                                       "/policy.yml' --out='" + dir + "/aug' --variants=2 --preview=true '" +
                                       dir + "/sim/g06dB_level0.90/frame_000.dng'");
    ASSERT_EQ(0, r.status) << r.output;
    for (int v = 0; v < 2; ++v) {
        const std::string out = dir + cv::format("/aug/frame_000_v%02d.dng", v);
        EXPECT_EQ(cv::rawgment::CFA_MONO, cv::rawgment::readRaw(out).format.pattern);
        cv::Mat mosaic;
        const cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(out, mosaic);
        EXPECT_EQ(cv::rawgment::CFA_MONO, meta.format.pattern);
        EXPECT_EQ(cv::Vec4d::all(meta.scene.jitter.contrast[0]), meta.scene.jitter.contrast);
        expectPngDecodes(dir + cv::format("/aug/frame_000_v%02d_preview.png", v));
    }
}

} // namespace
