// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_demo's report and gallery, and rawgment_tradeoffs' report of every knob.
#include "app_runs.hpp"

#include <gtest/gtest.h>
#include <opencv2/rawgment.hpp>

#include <cerrno>
#include <cstring>
#include <map>
#include <sstream>

namespace {

using namespace rawgment_app_tests;

TEST(Apps, demoWritesAReportAndAGallery)
{
    const std::string dir = freshDir("demo");
    AppRun r = runApp("rawgment_demo", "--out='" + dir + "/demo' --frames=8");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string report = readText(dir + "/demo/report.md");
    EXPECT_NE(std::string::npos, report.find("| alpha |")) << report;
    EXPECT_NE(std::string::npos, report.find("gallery.png"));
    expectPngDecodes(dir + "/demo/gallery.png");
    // The dark-frame components, calibrated and side by side with and without them.
    EXPECT_NE(std::string::npos, report.find("## Dark-frame noise beyond the paper")) << report;
    EXPECT_NE(std::string::npos, report.find("| read-noise Tukey lambda | -0.080 |")) << report;
    expectPngDecodes(dir + "/demo/dark_components.png");
    // The same dark scene as two real cameras, when darktable's profiles are on the machine (CI: always).
    EXPECT_NE(std::string::npos, report.find("## Real cameras")) << report;
    if (!cv::rawgment::darktableProfilesPath().empty()) {
        EXPECT_NE(std::string::npos, report.find("| camera | verdict | full well (e-) |")) << report;
        EXPECT_NE(std::string::npos,
                  report.find("| shot slope at 8x, measured | Eq. 5's | profiles' demosaic (c) |"))
            << report;
        expectPngDecodes(dir + "/demo/real_cameras.png");
        cv::Mat mosaic;
        EXPECT_FALSE(
            cv::rawgment::readMosaic(dir + "/demo/gallery/camera_0.dng", mosaic).noiseCamera.empty());
    }
    r = runApp("rawgment_demo", "--out='" + dir + "/demo' --frames=8");
    EXPECT_EQ(1, r.status) << "an existing report is never overwritten";
}

TEST(Apps, tradeoffReportMeasuresEveryKnob)
{
#ifdef RAWGMENT_SANITIZED_BUILD
    // Its simulated calibration campaigns take over 7 minutes under ASan on 2 cores (20 s in Release);
    // the library code it runs is covered by the unit tests under the sanitizers.
    GTEST_SKIP() << "the trade-off report runs in the Release build only";
#endif
    const std::string dir = freshDir("tradeoffs");
    AppRun r = runApp("rawgment_tradeoffs", "--quick --out='" + dir + "/t'");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string md = readText(dir + "/t/tradeoffs.md");
    for (const char* knob :
         {"Shot-noise sampling", "Prior mean", "Motion-blur noise sum", "Arithmetic",
          "Calibration burst length", "Calibration patch size", "Calibration RANSAC iterations",
          "Shapiro-Wilk", "Row noise (dark-frame component)", "Dark shading (dark-frame component)",
          "Read-noise tails (dark-frame component)", "Dark-frame bank frames per gain"})
        EXPECT_NE(std::string::npos, md.find(knob)) << knob;
    // What more data buys: a row per burst length, per square side, for two gains and for dark frames,
    // each with the stated and the made error of every parameter.
    const size_t precision = md.find("## Calibration precision: what more data buys");
    ASSERT_NE(std::string::npos, precision);
    for (const char* setup :
         {"24x24, 3 gains |", "8x8, 3 gains |", "2 gains (6 and 24 dB) |", "+ dark frames |"})
        EXPECT_NE(std::string::npos, md.find(setup, precision)) << setup;
    const size_t perCalibration = md.find("## A calibration: the frames to shoot, its time, its error");
    ASSERT_NE(std::string::npos, perCalibration);
    EXPECT_NE(std::string::npos, md.find("| Calibration burst length | 16 frames | 96 |", perCalibration));
    EXPECT_NE(std::string::npos,
              md.find("| Dark-frame bank frames per gain | 8 frames | 8 |", perCalibration));
    expectPngDecodes(dir + "/t/tradeoffs.png");
    // The figure: one view of every knob relative to its reference setting, then a panel per knob whose
    // y axis names the knob's own measure (the axes once said only "error").
    const std::string script = readText(dir + "/t/tradeoffs.png.gp");
    EXPECT_NE(std::string::npos, script.find("Which knob buys the most accuracy per millisecond?"));
    EXPECT_NE(std::string::npos, script.find("set ylabel \"KL(true || augmented)"));
    EXPECT_NE(std::string::npos, script.find("set ylabel \"RMS fixed-pattern difference (DN)"));
    EXPECT_EQ(std::string::npos, script.find("set ylabel 'error'"));
    // error and time of each (knob, setting) from the CSV: finite, and the orderings the knobs promise.
    std::map<std::string, double> error, errorOfKnob;
    std::istringstream csv(readText(dir + "/t/tradeoffs.csv"));
    const auto split = [](const std::string& line) {
        std::vector<std::string> cells;
        std::stringstream cellStream(line);
        for (std::string cell; std::getline(cellStream, cell, ',');)
            cells.push_back(cell);
        return cells;
    };
    std::string line;
    std::getline(csv, line);
    // Eight columns (three of them the calibration knobs' own), then the time on each CPU path.
    const size_t paths = cv::rawgment::availableCpuPaths().size(), fixed = 8;
    ASSERT_EQ(split(line).size(), fixed + paths) << line;
    EXPECT_EQ(split(line)[4], "error_se");
    EXPECT_EQ(split(line)[6], "s_per_calibration");
    EXPECT_EQ(split(line).back(),
              "ms_per_mp_" + cv::rawgment::cpuPathName(cv::rawgment::availableCpuPaths().back()));
    int rows = 0;
    while (std::getline(csv, line)) {
        std::vector<std::string> cells = split(line);
        ASSERT_LE(cells.size(), fixed + paths) << line;
        cells.resize(fixed + paths);
        const double e = std::stod(cells[3]), t = std::stod(cells[7]);
        EXPECT_TRUE(std::isfinite(e) && e >= 0) << line;
        EXPECT_TRUE(std::isfinite(t) && t > 0) << line;
        const bool calibration = cells[0].rfind("Calibration", 0) == 0,
                   bank = cells[0] == "Dark-frame bank frames per gain";
        if (calibration || bank) {
            // --quick runs two campaigns: each error has a standard error, each calibration its frames (6
            // bursts; a bank's group its frames per gain) and time.
            EXPECT_GT(std::stod(cells[4]), 0) << line;
            EXPECT_EQ(0, std::stoi(cells[5]) % (bank ? 4 : 6)) << line;
            EXPECT_GT(std::stod(cells[6]), 0) << line;
        } else {
            EXPECT_TRUE(cells[4].empty() && cells[5].empty() && cells[6].empty()) << line;
        }
        // The augmentation and burst-statistics knobs run dispatched loops: timed on every path.
        const bool dispatched = !calibration && !bank && cells[0] != "Shapiro-Wilk";
        for (size_t k = fixed; k < cells.size(); ++k)
            if (dispatched)
                EXPECT_GT(std::stod(cells[k]), 0) << line;
            else
                EXPECT_TRUE(cells[k].empty()) << line;
        error[cells[1]] = e;
        errorOfKnob[cells[0] + " | " + cells[1]] = e;
        ++rows;
    }
    // 2 settings of 2 knobs, 4 blur rows, 2 burst lengths (--quick), 3 + 3, 2, 2 for each of the 3 dark-frame
    // components, and 2 bank sizes (--quick).
    EXPECT_EQ(rows, 28);
    for (const char* component : {"Row noise", "Dark shading", "Read-noise tails"}) {
        const std::string knob = std::string(component) + " (dark-frame component) | ";
        EXPECT_LT(errorOfKnob[knob + "in the model"], errorOfKnob[knob + "absent from the model"] / 1.5)
            << knob;
    }
    // Text cells hold semicolons where the report has commas.
    EXPECT_LT(error["POISSON"], error["GAUSSIAN (paper)"] / 10) << "the lattice of a dark capture";
    EXPECT_LT(error["EXACT (Eq. 15); peaked 1x5 (1 4 6 4 1)"],
              error["FROM_BLURRED_MEAN; peaked 1x5 (1 4 6 4 1)"]);
    EXPECT_LT(error["LOCAL_MEAN"], error["PIXEL_VALUE (paper)"]) << "less clip bias at black";
    EXPECT_LT(error["float64 (default)"], error["float32"]);
    EXPECT_EQ(error["batched"], 0) << "batched Shapiro-Wilk gives the single form's numbers";
    r = runApp("rawgment_tradeoffs", "--quick --out='" + dir + "/t'");
    EXPECT_EQ(1, r.status) << "an existing report is never overwritten";
}

} // namespace
