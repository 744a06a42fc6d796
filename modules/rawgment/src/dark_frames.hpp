// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What M dark frames of one gain tell apart (DarkFrameStatistics, opencv2/rawgment/dark_frames.hpp), and
// how a bank's frames are read. Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_DARK_FRAMES_HPP
#define OPENCV_RAWGMENT_SRC_DARK_FRAMES_HPP

#include <opencv2/rawgment/calibration_samples.hpp>
#include <opencv2/rawgment/dark_frames.hpp>
#include <opencv2/rawgment/noise_model.hpp>

#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

/** Estimates the dark frames' pattern and temporal noise from their burst statistics (every frame of one
 * gain and exposure, M >= 2), black-subtracted with `stats`' format. A pixel is noisy when its variance
 * exceeds its row's (at least 1/12 DN^2, what whole DN resolve) by more than a chi-square allows at a
 * false-alarm rate of `falseAlarm` per pixel, with
 * the degrees of freedom the variances scatter with (their interquartile range: M - 1 for Gaussian noise,
 * fewer for heavy tails); its own variance then stands in the pattern's shrinkage, and it is left out of
 * the pooled variances. Hot pixels (a high mean) belong to the pattern and count in its variance.
 * @throws cv::Exception for fewer than two frames, frames of fewer than 16 pixels or a false-alarm rate
 * outside (0, 0.5). */
DarkFrameStatistics estimateDarkFrames(const BurstStatistics& stats, double falseAlarm = 1e-6);

/** Dark frames of one gain and exposure added one at a time: their burst statistics and each frame's row
 * means per column parity, from which estimate() tells the row noise (a row's offset, shared by its pixels)
 * from the pixels' own. */
class DarkFrameAccumulator
{
public:
    explicit DarkFrameAccumulator(const RawFormat& format);
    //! Adds a frame (CV_16UC1 or CV_32FC1, black level included); the first fixes the size.
    void add(const Mat& frame);
    int frames() const { return stats_.frames(); }
    //! estimateDarkFrames() with rowNoiseVariance from the row means.
    DarkFrameStatistics estimate(double falseAlarm = 1e-6) const;

private:
    RawFormat format_;
    BurstStatistics stats_;
    std::vector<double> rowSum_, rowSum2_; // per row and column parity, over frames
};

/** Two exposure times are the same capture's when within a third of a stop (a factor 2^(1/3)), the step of
 * cameras' shutter settings: a nominal 1/60 s and a stated 0.0166 s match, 1/60 s and 1/30 s do not. */
constexpr double kExposureMatchFactor = 1.2599210498948732;

/** The group of `groups` (by increasing gain, then exposure) whose gain is nearest `gain` on a log scale, at
 * any gain (DarkFrameBank::nearestGroup() adds the bank's range to it, a step's input side takes it as it
 * is), and of that gain the group of exposure `exposureTime`: the nearest stated one within
 * kExposureMatchFactor, else a group that states none (its frames say nothing of their exposure). Refused,
 * naming the exposures the bank has at that gain (and `bankPath` when not empty), when no group matches, or
 * when `exposureTime` is 0 (not stated) and the gain has groups of more than one exposure. */
int nearestGainGroup(const std::vector<DarkFrameGroup>& groups, double gain, double exposureTime,
                     const String& bankPath = String());

//! One dark frame as read: its pixels, its format at its gain, and its exposure time (0: not stated).
struct DarkFrame
{
    Mat mosaic;
    RawFormat format;
    double exposureTime = 0;
};

/** Reads a dark frame: a mosaic with a sidecar (readMosaic(): the sidecar's gain, or its camera's ISO through
 * `model`) or a DNG or camera RAW file (readRaw(): its ISO through formatAtIso() with `model`). */
DarkFrame readDarkFrame(const String& path, const NoiseModel& model);

/** The upper chi-square quantile over its degrees of freedom, chi2_{1-p}(k) / k, to Wilson and Hilferty's
 * approximation, which overstates it: against SciPy's chi2.isf by at most 3.4% for k >= 7 and p >= 1e-6, but
 * 15% at k = 1 (a threshold that then flags fewer pixels). */
double chiSquareUpperQuantileOverDof(int k, double p);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_DARK_FRAMES_HPP
