// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What rawgment_calibrate writes beside its model (calibrate_outputs.cpp): report.md, the CSV tables and
// their plots, the dark-frame outputs, and the darktable and Android exports. Private to the apps.
#ifndef RAWGMENT_APPS_CALIBRATE_OUTPUTS_HPP
#define RAWGMENT_APPS_CALIBRATE_OUTPUTS_HPP

#include "app_tools.hpp"
#include "pipeline.hpp"
#include "plots.hpp"

#include <string>
#include <vector>

namespace rawgment_apps {

//! report.md: the verdict first, with its checks, then the model, the per-gain lines, the plots that were
//! written (`plots`), the notes (the run's, then the plots').
std::string calibrationReportMarkdown(const CalibrateResult& r, const PlotsWritten& plots,
                                      const std::string& outDir);
/* darktable's noise-profile file and Android's form of the model, at the ISOs of the bursts (a file's ISO
 * as it says it; a gain_db burst's from its gain, as dB are not exact). */
void writeProfileExports(const std::string& outDir, const std::vector<CalibrationManifest::Burst>& specs,
                         const std::vector<double>& gainsDb, const std::vector<double>& isos,
                         const cv::rawgment::RawFormat& firstFormat, CalibrateResult& result);
/* samples.csv, lines.csv, shapiro.csv and the histogram of variance / model variance per gain (a sample
 * variance of T frames has mean 1 and relative spread sqrt(2 / (T - 1)) around a right model). Returns
 * the number of gains in the histogram. */
size_t writeSampleTables(const std::vector<cv::rawgment::NoiseSample>& samples,
                         const cv::rawgment::CalibrationReport& report, const CsvTable& shapiro,
                         const std::string& samplesCsv, const std::string& linesCsv,
                         const std::string& shapiroCsv, const std::string& histCsv);
//! dark_calibration.yml, dark_rows.csv, dark_ppcc.csv and their plots (returned).
PlotsWritten writeDarkOutputs(const CalibrateOptions& o, const CalibrateResult& result);

} // namespace rawgment_apps

#endif // RAWGMENT_APPS_CALIBRATE_OUTPUTS_HPP
