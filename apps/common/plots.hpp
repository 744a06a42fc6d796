// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The apps' plots: gnuplot scripts over the CSV tables the flows write. Private to apps/common.
#ifndef RAWGMENT_APPS_PLOTS_HPP
#define RAWGMENT_APPS_PLOTS_HPP

#include <opencv2/rawgment/calibration.hpp>

#include <string>
#include <vector>

namespace rawgment_apps {

/** What a plotting call wrote: each PNG made (or kept from an interrupted run of the same job), and for each
 * plot that could not be made, or was not, its reason. A report lists what it is given of these, so the
 * plots it shows are those returned, never those some earlier call left in a shared list. */
struct PlotsWritten
{
    std::vector<std::string> pngs, notes;
    PlotsWritten& operator+=(const PlotsWritten& other)
    {
        pngs.insert(pngs.end(), other.pngs.begin(), other.pngs.end());
        notes.insert(notes.end(), other.notes.begin(), other.notes.end());
        return *this;
    }
};

//! The CSV tables that rawgment_calibrate writes and its plots read.
struct CalibrationPlotFiles
{
    std::string samplesCsv, linesCsv, histogramCsv, shapiroCsv;
};

/** calib_mean_variance.png, calib_histograms.png (histogramSeries columns after the first),
 * calib_cross_gain.png (with two gains or more) and shapiro_pvalue.png (when `haveShapiro`; one series
 * per gain in gainsDb) in outDir. */
PlotsWritten plotCalibration(const std::string& outDir, const cv::rawgment::CalibrationReport& report,
                             const CalibrationPlotFiles& files, size_t histogramSeries,
                             const std::vector<double>& gainsDb, bool haveShapiro);

/** The dark-frame components' plots in outDir: dark_rows.png (row variance against gain with the fitted
 * g^2 sigma_row_d^2 + sigma_row_r^2), dark_ppcc.png (probability-plot correlation against lambda) and
 * dark_shading.png (the two maps in false colour, without gnuplot). */
PlotsWritten plotDarkComponents(const std::string& outDir, const cv::rawgment::DarkCalibrationReport& dark,
                                const std::string& rowsCsv, const std::string& ppccCsv);

//! One panel of the validation plot: an exposure factor and the largest mean of its bins.
struct ValidationPanel
{
    double factor;
    double largestMean;
};

//! validation.png in outDir from the validation CSV, one panel per target.
PlotsWritten plotValidation(const std::string& outDir, const std::string& csvPath,
                            const std::vector<ValidationPanel>& panels);

} // namespace rawgment_apps

#endif // RAWGMENT_APPS_PLOTS_HPP
