// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What the trade-off studies share (tradeoff_measures.cpp, tradeoff_calibration.cpp): their seeds and
// timers. Private to the trade-off study (apps/tradeoffs).
#ifndef RAWGMENT_APPS_TRADEOFF_STUDY_HPP
#define RAWGMENT_APPS_TRADEOFF_STUDY_HPP

#include "app_tools.hpp"
#include "tradeoff_measures.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace rawgment_apps {
namespace tradeoff_study {

// What each seed of the study drives: deriveSeed(seed, SEED_STUDY, draw << 32 | sub-index).
enum StudyDraw : uint64_t
{
    DRAW_TIMING_FRAME,
    DRAW_TIMED_STEP,
    DRAW_LATTICE_BRIGHT,
    DRAW_LATTICE_TRUTH,
    DRAW_LATTICE_JITTER,
    DRAW_BLACK_FRAME,
    DRAW_BLACK_TRUTH,
    DRAW_BLACK_JITTER,
    DRAW_BLUR_BURST,
    DRAW_BLUR_STEP,
    DRAW_STATE_BURST,
    DRAW_SHAPIRO_DATA,
    DRAW_CAMPAIGN_BURST,
    DRAW_DARK_INPUT,
    DRAW_DARK_TARGET,
    DRAW_DARK_STEP,
    DRAW_BANK_CAMPAIGN
};

//! The seed of one draw of the study.
uint64_t studySeed(const TradeoffSettings& set, StudyDraw draw, uint64_t sub = 0);
//! Fastest wall time of `repeats` runs of `work`, in milliseconds.
double fastestMs(int repeats, const std::function<void()>& work);
/** fastestMs() on every CPU path this machine has, in the order of availableCpuPaths(), and in `active`
 * the time on the path that was active, which is restored. */
std::vector<double> fastestMsOnEveryPath(int repeats, const std::function<void()>& work, double& active);
//! Milliseconds per megapixel of a frame of size `s`.
std::vector<double> perMegapixel(std::vector<double> ms, cv::Size s);
//! The megapixels of a frame of size `s`.
double megapixels(cv::Size s);
/** The calibration knobs' time and accuracy over simulated campaigns, and the stated against the made
 * errors (tradeoff_calibration.cpp). */
void measureCalibrationKnobs(const TradeoffSettings& set, std::vector<TradeoffRow>& rows,
                             std::vector<PrecisionRow>& precision, ProgressBar& progress);
/** The dark-frame bank's frames per gain (settings.bankFrames) against the RMS error of its fixed pattern
 * over simulated campaigns, and the time to make one gain's group (tradeoff_dark_bank.cpp). */
void measureDarkBankFrames(const TradeoffSettings& set, std::vector<TradeoffRow>& rows);

} // namespace tradeoff_study
} // namespace rawgment_apps

#endif // RAWGMENT_APPS_TRADEOFF_STUDY_HPP
