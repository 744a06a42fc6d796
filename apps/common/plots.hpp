// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The apps' plots: gnuplot scripts over the CSV tables the flows write. Private to apps/common.
#ifndef RAWGMENT_APPS_PLOTS_HPP
#define RAWGMENT_APPS_PLOTS_HPP

#include <opencv2/rawgment/calibration.hpp>

#include <string>
#include <vector>

namespace rawgment_apps {

//! The CSV tables that rawgment_calibrate writes and its plots read.
struct CalibrationPlotFiles
{
    std::string samplesCsv, linesCsv, histogramCsv, shapiroCsv;
};

/** calib_mean_variance.png, calib_histograms.png (histogramSeries columns after the first),
 * calib_cross_gain.png (with two gains or more) and shapiro_pvalue.png (when `haveShapiro`; one series
 * per gain in gainsDb) in outDir. Each PNG written goes to `pngs`; a plot that could not be made, or
 * was not, leaves its reason in `notes`. */
void plotCalibration(const std::string& outDir, const cv::rawgment::CalibrationReport& report,
                     const CalibrationPlotFiles& files, size_t histogramSeries,
                     const std::vector<double>& gainsDb, bool haveShapiro, std::vector<std::string>& pngs,
                     std::vector<std::string>& notes);

/** The dark-frame components' plots in outDir: dark_rows.png (row variance against gain with the fitted
 * g^2 sigma_row_d^2 + sigma_row_r^2), dark_ppcc.png (probability-plot correlation against lambda) and
 * dark_shading.png (the two maps in false colour, without gnuplot). */
void plotDarkComponents(const std::string& outDir, const cv::rawgment::DarkCalibrationReport& dark,
                        const std::string& rowsCsv, const std::string& ppccCsv,
                        std::vector<std::string>& pngs, std::vector<std::string>& notes);

//! One panel of the validation plot: an exposure factor and the largest mean of its bins.
struct ValidationPanel
{
    double factor;
    double largestMean;
};

//! validation.png in outDir from the validation CSV, one panel per target (see plotCalibration()).
void plotValidation(const std::string& outDir, const std::string& csvPath,
                    const std::vector<ValidationPanel>& panels, std::vector<std::string>& pngs,
                    std::vector<std::string>& notes);

} // namespace rawgment_apps

#endif // RAWGMENT_APPS_PLOTS_HPP
