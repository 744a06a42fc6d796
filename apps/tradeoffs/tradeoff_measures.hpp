// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_tradeoffs' measurements: every knob of the library that trades accuracy for time, measured
// against the sensor simulator's ground truth. The trade-off study (apps/tradeoffs), which the app
// rawgment_tradeoffs runs.
#ifndef RAWGMENT_APPS_TRADEOFF_MEASURES_HPP
#define RAWGMENT_APPS_TRADEOFF_MEASURES_HPP

#include "app_tools.hpp"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace rawgment_apps {

/** What rawgment_tradeoffs measures and how long it may take (--quick shrinks it). */
struct TradeoffSettings
{
    cv::Size timingSize{4000, 3000}; // the frame every augmentation and statistics time is measured on
    int repeats = 3;                 // timings keep the fastest of this many runs
    /* Calibration errors are RMS over this many simulated campaigns. 32 give each RMS a standard error of
     * about 12% of itself, which tells apart neighbouring burst lengths and patch sizes (their errors differ
     * by 1.4-3x); 3 could not (16x16 patches came out worse than 8x8). */
    int seeds = 32;
    std::vector<int> burstLengths{8, 16, 32, 100};
    std::vector<int> ransacIterations{20, 100, 2000}; // the RANSAC knob's settings (500 is the library's)
    std::vector<int> bankFrames{4, 8, 16, 25, 50};    // dark frames per gain in a dark-frame bank
    // Also the stated against the made errors (PrecisionRow), each fit with its bootstrap, and dark bursts.
    bool precision = true;
    int shapiroSeries = 100000; // series of 64 values in the Shapiro-Wilk timing
    uint64_t seed = 1;          // every simulated capture and noise draw derives from it
};

/** One setting of one knob: its error against the simulator's truth and its time. */
struct TradeoffRow
{
    std::string knob, setting, measure;
    double error = 0;   // of the measure, against the simulator's truth (smaller is better)
    double msPerMp = 0; // wall time per megapixel of input (per million values for Shapiro-Wilk)
    std::string meaning;
    /** The time on each CPU path this machine has, in the order of availableCpuPaths(), for the knobs
     * whose loops are dispatched (cpu.hpp); empty for the others. msPerMp is the active path's. */
    std::vector<double> msPerMpByPath;
    // Calibration knobs only (empty or 0 elsewhere):
    std::vector<double> campaignErrors{}; // each campaign's error; `error` is their RMS
    double errorStdError = 0;             // the standard error of that RMS
    int framesToShoot = 0;                // every burst's frames, as a user shoots them
    double secondsPerCalibration = 0;     // compute time of one calibration of a timingSize camera
};

/** rmsOf(errors) and its standard error over the campaigns (the delta method on the mean square); 0 for
 * fewer than two campaigns. */
double rmsOf(const std::vector<double>& errors);
double rmsStandardError(const std::vector<double>& errors);

/** How much the mean squared error falls from one setting to another over the same campaigns, and the
 * standard error of that fall from the per-campaign differences (paired: the settings share each campaign's
 * frames, which a comparison of two independent standard errors would ignore). */
struct ErrorFall
{
    double meanSquareFall = 0, stdError = 0;
};
ErrorFall pairedFall(const std::vector<double>& before, const std::vector<double>& after);

/** How exact one calibration set-up is: the relative standard errors the calibration states (mean over
 * campaigns), the relative errors it makes (RMS over campaigns, against the simulator's truth), and
 * the errors the formula se0 sqrt((T0 - 1) N0 / ((T - 1) N)) gives from the reference set-up for more of
 * the same (frames T, pixels N; 0 where no formula applies). Parameters: alpha, sigma_d^2, sigma_r^2. */
struct PrecisionRow
{
    std::string setting;
    double stated[3] = {0, 0, 0};
    double made[3] = {0, 0, 0};
    double formula[3] = {0, 0, 0};
};

/** Measures every knob in one run (colour jitter, blur, burst statistics, calibration, Shapiro-Wilk)
 * and appends one row per setting, and the calibration's precision per set-up; `progress` advances by
 * 7 + 9 * settings.seeds. */
void measureTradeoffs(const TradeoffSettings& settings, ProgressBar& progress, std::vector<TradeoffRow>& rows,
                      std::vector<PrecisionRow>& precision);

} // namespace rawgment_apps

#endif // RAWGMENT_APPS_TRADEOFF_MEASURES_HPP
