// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// End-to-end tests of rawgment_calibrate --emva: EMVA 1288 series in, as a user runs it.
#include "app_runs.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace {

using namespace rawgment_app_tests;

TEST(Apps, calibrateEmvaOnSet001WritesTheStandardsFiguresTheModelPlotsAndTheValidation)
{
    const std::string descriptor = std::string(RAWGMENT_SHARED_DATA_DIR) +
                                   "/emva1288/EMVA1288_ReferenceSet_001_CCD_12Bit/EMVA1288_Data.txt";
    if (!exists(descriptor))
        GTEST_SKIP() << descriptor << " is missing (see ../shared/data/SOURCES.md)";
    const std::string dir = freshDir("calibrate_emva_set001");
    const std::string args = "--emva='" + descriptor + "' --out='" + dir + "/cal'";
    const AppRun r = runApp("rawgment_calibrate", args);
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(r.output.find("verdict: PASS"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("K 0.28006 DN/e-"), std::string::npos) << r.output;
    for (const char* name :
         {"noise_model.yml", "calibration_report.yml", "emva1288.yml", "emva1288_points.csv",
          "emva1288_validation.csv", "emva1288_validation_histograms.csv", "report.md"})
        EXPECT_TRUE(exists(dir + "/cal/" + name)) << name;
    for (const char* png : {"emva_photon_transfer.png", "emva_snr.png", "emva_linearity.png",
                            "emva_validation.png", "emva_validation_histograms.png"})
        expectPngDecodes(dir + "/cal/" + png);
    // The figures under the reference implementation's names, and a model the other apps load.
    cv::FileStorage figures(dir + "/cal/emva1288.yml", cv::FileStorage::READ);
    const cv::FileNode first = figures["emva1288"][0];
    EXPECT_NEAR(double(first["K"]), 0.28006, 0.005 * 0.28006);
    EXPECT_NEAR(double(first["sigma_y_dark"]), 3.0731, 0.005 * 3.0731);
    EXPECT_NEAR(double(first["QE"]), 45.25, 0.005 * 45.25);
    EXPECT_NEAR(double(first["DR_dB"]), 61.73, 0.04);
    const cv::rawgment::NoiseModel model = cv::rawgment::NoiseModel::load(dir + "/cal/noise_model.yml");
    EXPECT_NEAR(model.alpha, 0.2877, 0.002);
    const std::string report = readText(dir + "/cal/report.md");
    EXPECT_NE(report.find("ACCOUNT_PRIOR"), std::string::npos);
    EXPECT_NE(report.find("holds for signals 0 to"), std::string::npos);
    // Which slope is right on a curve that bends: the sensor's own darker steps decide (docs/emva1288.md).
    EXPECT_NE(report.find("the model's line predicts this sensor's darker steps better"), std::string::npos)
        << report;
    // An identical rerun finds its own outputs, byte for byte, and succeeds (round 5, item 21); an output
    // changed since is never written over, and the run names it.
    const AppRun again = runApp("rawgment_calibrate", args);
    EXPECT_EQ(0, again.status) << again.output;
    EXPECT_EQ(report, readText(dir + "/cal/report.md"));
    std::ofstream(dir + "/cal/report.md", std::ios::app) << "the user's note\n";
    const AppRun edited = runApp("rawgment_calibrate", args);
    EXPECT_NE(0, edited.status);
    EXPECT_NE(edited.output.find("report.md' already exists"), std::string::npos) << edited.output;
    EXPECT_EQ(report + "the user's note\n", readText(dir + "/cal/report.md"));
}

TEST(Apps, calibrateEmvaSeparatesTheReadNoiseOfAManifestOfGainsAndRefusesBadInputWithStatus2)
{
    const std::string dir = freshDir("calibrate_emva_gains");
    // Two small series of the simulator at 0 and 12 dB, 12 steps each, written as the standard's PNGs.
    cv::rawgment::SensorParams params;
    params.noise = cv::rawgment::NoiseModel(0.1, 2.0, 4.0);
    params.blackLevel = cv::Vec4d::all(64);
    const cv::rawgment::SensorSimulator sim(params, cv::Size(128, 96));
    std::string manifest = "%YAML:1.0\nemva1288_manifest:\n  base_iso: 100\n  series:\n";
    for (int g = 0; g < 2; ++g) {
        const std::string series = dir + cv::format("/g%d", g);
        ASSERT_EQ(0, std::system(("mkdir -p '" + series + "'").c_str()));
        const double gain = g == 0 ? 1.0 : 4.0;
        std::ofstream d(series + "/EMVA1288_Data.txt");
        d << "v 4.0\nn 12 128 96\n";
        std::vector<cv::Mat> frames;
        // Exposures 1 to 12, and 0.4: a step at most a quarter as bright as one between 10% and 30% of
        // saturation, which the real-frame validation needs.
        for (int k = 0; k < 13; ++k) {
            const double exposure = k < 12 ? k + 1 : 0.4;
            const cv::Mat light(96, 128, CV_32FC1, cv::Scalar(1.15 * 4031 / gain / 12));
            for (int dark = 0; dark < 2; ++dark) {
                sim.captureBurst(dark ? cv::Mat::zeros(96, 128, CV_32FC1) : light, gain, exposure, 2,
                                 uint64_t(100 * g + 2 * k + dark), frames);
                d << (dark ? cv::format("d %g\n", exposure)
                           : cv::format("b %g %g\n", exposure, 1000 * exposure));
                for (int f = 0; f < 2; ++f) {
                    const std::string name = cv::format("%s%d_%d.png", dark ? "d" : "b", k, f);
                    ASSERT_TRUE(cv::imwrite(series + "/" + name, frames[f]));
                    d << "i " << name << "\n";
                }
            }
        }
        manifest += g == 0 ? "    - { descriptor: g0/EMVA1288_Data.txt, gain_db: 0 }\n"
                           : "    - { descriptor: g1/EMVA1288_Data.txt, iso: 400 }\n";
    }
    std::ofstream(dir + "/m.yml") << manifest;
    const AppRun r =
        runApp("rawgment_calibrate", "--emva='" + dir + "/m.yml' --out='" + dir + "/cal' --plots=false");
    ASSERT_EQ(0, r.status) << r.output;
    const cv::rawgment::CalibrationReport rep =
        cv::rawgment::CalibrationReport::load(dir + "/cal/calibration_report.yml");
    ASSERT_TRUE(rep.separable);
    ASSERT_EQ(rep.perGain.size(), 2u);
    // 128x96 series: both read variances to within 5 of their stated standard errors of the truth.
    EXPECT_NEAR(rep.model.sigmaD2, 2.0, 5 * rep.uncertainty.stdError[1]);
    EXPECT_NEAR(rep.model.sigmaR2, 4.0 + 1.0 / 12, 5 * rep.uncertainty.stdError[2]);
    // The validation of both series in one file: each row names its series, and no pair number is given
    // twice (the second series' restarted at 1, #79 item 26).
    std::istringstream csv(readText(dir + "/cal/emva1288_validation.csv"));
    std::string row;
    ASSERT_TRUE(std::getline(csv, row));
    EXPECT_EQ(0u, row.find("series,pair,bright_point,")) << row;
    std::map<int, std::set<int>> pairsOfSeries;
    while (std::getline(csv, row)) {
        int seriesNumber = 0, pair = 0;
        ASSERT_EQ(2, std::sscanf(row.c_str(), "%d,%d,", &seriesNumber, &pair)) << row;
        pairsOfSeries[seriesNumber].insert(pair);
    }
    ASSERT_EQ(2u, pairsOfSeries.size());
    ASSERT_FALSE(pairsOfSeries[0].empty());
    ASSERT_FALSE(pairsOfSeries[1].empty());
    EXPECT_LT(*pairsOfSeries[0].rbegin(), *pairsOfSeries[1].begin());

    // Bad input is a usage error (status 2) naming what is wrong and where.
    std::ofstream(dir + "/huge.txt") << "v 4.0\nn 16 100000 100000\n";
    AppRun bad = runApp("rawgment_calibrate", "--emva='" + dir + "/huge.txt' --out='" + dir + "/bad1'");
    EXPECT_EQ(2, bad.status) << bad.output;
    EXPECT_NE(bad.output.find("line 2: 100000 x 100000 pixels"), std::string::npos) << bad.output;
    std::ofstream(dir + "/missing.txt") << "n 12 128 96\nb 1 10\ni nowhere.png\ni g0/b0_0.png\n";
    bad = runApp("rawgment_calibrate", "--emva='" + dir + "/missing.txt' --out='" + dir + "/bad2'");
    EXPECT_EQ(2, bad.status) << bad.output;
    EXPECT_NE(bad.output.find("line 3: image '" + dir + "/nowhere.png' does not exist"), std::string::npos)
        << bad.output;
    std::ofstream(dir + "/typo.yml")
        << "emva1288_manifest:\n  series:\n    - { descriptor: g0/EMVA1288_Data.txt, "
           "gain_bd: 0 }\n";
    bad = runApp("rawgment_calibrate", "--emva='" + dir + "/typo.yml' --out='" + dir + "/bad3'");
    EXPECT_EQ(2, bad.status) << bad.output;
    EXPECT_NE(bad.output.find("gain_bd"), std::string::npos) << bad.output;
    // A boolean is not a number (gain_db: true calibrated at 1 dB), in YAML or JSON.
    std::ofstream(dir + "/boolean.json") << "{\"emva1288_manifest\": {\"series\": [{\"descriptor\": "
                                            "\"g0/EMVA1288_Data.txt\", \"gain_db\": true}]}}";
    bad = runApp("rawgment_calibrate", "--emva='" + dir + "/boolean.json' --out='" + dir + "/bad4'");
    EXPECT_EQ(2, bad.status) << bad.output;
    EXPECT_NE(bad.output.find("'gain_db' is not a finite number"), std::string::npos) << bad.output;
    std::ofstream(dir + "/boolean_iso.yml") << "emva1288_manifest:\n  base_iso: true\n  series:\n    - { "
                                               "descriptor: g0/EMVA1288_Data.txt, iso: 100 }\n";
    bad = runApp("rawgment_calibrate", "--emva='" + dir + "/boolean_iso.yml' --out='" + dir + "/bad5'");
    EXPECT_EQ(2, bad.status) << bad.output;
    EXPECT_NE(bad.output.find("'base_iso' is not a finite number"), std::string::npos) << bad.output;
    // One descriptor twice under two spellings shrank alpha's stated error (0.0011 to 0.0008).
    std::ofstream(dir + "/twice.yml") << "emva1288_manifest:\n  series:\n"
                                         "    - { descriptor: g0/EMVA1288_Data.txt, gain_db: 0 }\n"
                                         "    - { descriptor: g0/./EMVA1288_Data.txt, gain_db: 6 }\n";
    bad = runApp("rawgment_calibrate", "--emva='" + dir + "/twice.yml' --out='" + dir + "/bad6'");
    EXPECT_EQ(2, bad.status) << bad.output;
    EXPECT_NE(bad.output.find("series: entries 1 ('" + dir + "/g0/EMVA1288_Data.txt') and 2"),
              std::string::npos)
        << bad.output;
    EXPECT_NE(bad.output.find("are one file"), std::string::npos) << bad.output;
    EXPECT_FALSE(exists(dir + "/bad1")) << "a failed run leaves no empty folder";
}

} // namespace
