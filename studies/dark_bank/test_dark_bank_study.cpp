// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The dark-frame bank against independent captures of a sensor that departs from the parametric components
// (dark_bank_study.hpp): what docs/dark_frame_bank.md claims of it.
#include "dark_bank_study.hpp"

#include <gtest/gtest.h>

#include <cmath>
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
 * line per pixel) and the fixed pattern (the components' maps hold their frames' v/M). The kurtosis and the
 * KS test are reported, not held (docs/dark_frame_bank.md: the draws' differences halve a frame's excess
 * kurtosis). 28 s on host H3; the library code it runs is under the sanitizers in test_dark_frames.cpp, so
 * this runs in the Release build only. */
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

} // namespace
