// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The dark-frame bank against independent captures of a sensor that departs from the parametric components,
// and on a real sensor's frames (dark_bank_study.hpp): what docs/dark_frame_bank.md claims of it.
#include "dark_bank_study.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>

namespace {

using rawgment_studies::DarkBankMethod;

double combined(double a, double b)
{
    return std::sqrt(a * a + b * b);
}

/* 24 campaigns (each a new sensor, bank, 32 inputs and 32 targets); every bound is 3 standard errors of the
 * campaigns' mean difference, or of the difference of two methods' (they share the targets):
 * - the accounted bank matches the targets' row part, pixel part (plus the output's rounding, 1/12 DN^2) and
 *   fixed-pattern RMS, puts hot pixels at their level, and leaves the input's column banding, k^2 of the
 *   simulated 1 DN^2: the bank's parts are rows and pixels, so the columns the input holds are not taken out;
 * - it is at least as close as the calibrated components on the row and pixel parts, and closer where the
 *   sensor departs from them: the column part (the components have no columns), the hot pixels (a shading
 * line per pixel) and the fixed pattern (the components' maps hold their frames' v/M);
 * - its kurtosis is its mixture's (the input's k^4 share and the frames' own population, drawn with
 *   replacement, with the output's rounding): +0.039 +- 0.031 measured. Against the targets it is 0.92 of a
 *   frame's by design (a frame less its group's mean), which docs/dark_frame_bank.md reports; the KS test is
 *   reported too, not held (its bootstrap is off here). 16 s on host H3; the library code it runs is under
 *   the sanitizers in test_dark_frames.cpp, so this runs in the Release build only. */
TEST(DarkBankStudy, theAccountedBankMatchesIndependentCapturesAndBeatsTheComponentsWhereTheSensorDeparts)
{
    rawgment_studies::DarkBankStudySettings settings;
    settings.campaigns = 24;
    settings.bootstrap = 0;
    settings.workDir = (std::filesystem::temp_directory_path() / "rawgment_dark_bank_study_test").string();
    std::filesystem::remove_all(settings.workDir);
    const rawgment_studies::DarkBankStudy study = rawgment_studies::runDarkBankStudy(settings);
    std::cout << rawgment_studies::darkBankStudyMarkdown(study, settings);
    ASSERT_EQ(study.methods.size(), 4u);
    const DarkBankMethod &bank = study.methods[0], &components = study.methods[2];
    EXPECT_LT(std::abs(bank.rowPart), 3 * bank.rowPartSe);
    EXPECT_LT(std::abs(bank.pixelPart - 1.0 / 12), 3 * bank.pixelPartSe);
    EXPECT_LT(std::abs(bank.fpnRms), 3 * bank.fpnRmsSe);
    EXPECT_LT(bank.hotError, 0.01);
    EXPECT_LT(std::abs(bank.expectedKurtosis), 3 * bank.expectedKurtosisSe);
    const double inputColumns = settings.contrast * settings.contrast * 1.0;
    EXPECT_LT(std::abs(bank.columnPart - inputColumns), 3 * bank.columnPartSe);
    EXPECT_LE(std::abs(bank.rowPart),
              std::abs(components.rowPart) + 3 * combined(bank.rowPartSe, components.rowPartSe));
    EXPECT_LE(std::abs(bank.pixelPart),
              std::abs(components.pixelPart) + 3 * combined(bank.pixelPartSe, components.pixelPartSe));
    EXPECT_LT(std::abs(bank.columnPart - inputColumns) +
                  3 * combined(bank.columnPartSe, components.columnPartSe),
              std::abs(components.columnPart));
    EXPECT_LT(bank.hotError + 3 * combined(bank.hotErrorSe, components.hotErrorSe), components.hotError);
    EXPECT_LT(std::abs(bank.fpnRms) + 3 * combined(bank.fpnRmsSe, components.fpnRmsSe),
              std::abs(components.fpnRms));
    std::filesystem::remove_all(settings.workDir);
}

/* Set 001 (one gain): the bank of the spatial set's first 25 dark frames, the components calibrated from them
 * and the Gaussian, against the last 25 frames and against five darker steps' real pairs. Every claim is the
 * study's 3-standard-error rule (emva1288_bank_study.cpp says what each error holds):
 * - the accounted bank is told apart from the real frames by no figure, in either comparison;
 * - the bank that ignores the prior adds k^2 of each bright pair's variance (7 to 20 DN^2 here) too much;
 * - the components' fixed pattern is their frames' plain mean, which holds v/M (0.38 DN^2) over a pattern of
 *   0.02: told apart, above;
 * - the Gaussian has no row noise: the pairs' row means vary less than the real ones, and the halves' row
 *   noise and fixed pattern are missing;
 * - the bank's own fixed-pattern figure equals the study's arithmetic on the same frames. */
TEST(DarkBankStudy, onSet001TheAccountedBankIsToldApartFromRealFramesByNoFigure)
{
    const char* name = "emva1288/EMVA1288_ReferenceSet_001_CCD_12Bit/EMVA1288_Data.txt";
    std::filesystem::path path = std::filesystem::path(RAWGMENT_SHARED_DATA_DIR) / name;
    if (const char* dir = std::getenv("RAWGMENT_TEST_DATA_DIR"))
        if (std::filesystem::exists(std::filesystem::path(dir) / name))
            path = std::filesystem::path(dir) / name;
    if (!std::filesystem::exists(path))
        GTEST_SKIP() << "test data file '" << name
                     << "' not found (set RAWGMENT_TEST_DATA_DIR or put ../shared/data beside the checkout)";
    const std::string work =
        (std::filesystem::temp_directory_path() / "rawgment_emva1288_bank_study_test").string();
    const rawgment_studies::Emva1288BankStudy study =
        rawgment_studies::runEmva1288BankStudy(path.string(), work);
    std::cout << rawgment_studies::emva1288BankStudyMarkdown(study);
    EXPECT_NEAR(study.bankFixedPattern, study.studyFixedPattern, 1e-4 + 1e-3 * study.studyFixedPattern);
    int steps = 0;
    for (const rawgment_studies::RealComparison& r : study.rows) {
        SCOPED_TRACE(r.part + ", " + r.method + ", " + r.measure);
        const double z = (r.value - r.real) / r.se;
        const bool halves = r.part == "half against half";
        steps += !halves && r.method.rfind("bank, accounted", 0) == 0 && r.measure.rfind("temporal", 0) == 0;
        if (r.method.rfind("bank, accounted", 0) == 0) {
            EXPECT_FALSE(r.distinguishable());
        }
        if (r.method.rfind("bank, prior ignored", 0) == 0 && r.measure.rfind("temporal", 0) == 0) {
            EXPECT_GT(z, 3);
        }
        if (r.method == "calibrated components" && r.measure.rfind("fixed pattern", 0) == 0) {
            EXPECT_GT(z, 3);
        }
        if (r.method == "Gaussian read noise" &&
            (r.measure.rfind("row", 0) == 0 || (halves && r.measure.rfind("fixed pattern", 0) == 0))) {
            EXPECT_LT(z, -3);
        }
    }
    EXPECT_GE(steps, 4);
    std::filesystem::remove_all(work);
}

} // namespace
