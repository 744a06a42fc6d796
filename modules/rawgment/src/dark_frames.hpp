// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What M dark frames of one gain tell apart: the fixed pattern and the temporal noise (issue #64, the
// statistics of a dark-frame bank). Private until the bank itself is public.
#ifndef OPENCV_RAWGMENT_SRC_DARK_FRAMES_HPP
#define OPENCV_RAWGMENT_SRC_DARK_FRAMES_HPP

#include <opencv2/rawgment/calibration_samples.hpp>
#include <opencv2/rawgment/noise_model.hpp>

#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

/** The fixed pattern and the temporal noise of M dark frames of one gain (DN above the black level).
 *
 * A pixel's mean m over M frames is its fixed pattern F plus temporal noise of variance v/M, frozen into
 * the mean: on EMVA 1288 set 001 (a 12-bit CCD) the spatial variance of the mean of 50 dark frames is
 * 0.214 DN^2, of which 0.190 is v/M and 0.024 the pattern. So the fixed pattern's variance per CFA site is
 * Var(m) - mean(v)/M (the EMVA 1288 correction), and the pattern is
 * the mean shrunk towards the site's level by w = s_F^2 / (s_F^2 + v/M): the best linear estimate of F given
 * m when the pattern's values scatter by s_F^2 around the site's level (zero when the frames resolve no
 * pattern at all). */
struct DarkFrameEstimate
{
    int frames = 0;           //!< M
    int degreesOfFreedom = 0; //!< those the variances scatter with: M - 1, fewer for heavy-tailed noise
    Mat pattern;              //!< CV_32FC1: the fixed pattern, shrunk for its v/M
    Mat rowVariance;          //!< CV_64FC1, rows x 2: row r's temporal variance at its columns' parities 0, 1
    std::vector<Point> noisyPixels;    //!< pixels whose temporal variance the row's cannot explain
    std::vector<double> noisyVariance; //!< their own temporal variance
    Vec4d level;                       //!< each CFA site's mean level
    Vec4d temporalVariance; //!< each site's temporal variance, pooled over its pixels that are not noisy
    Vec4d meanVariance;     //!< each site's spatial variance of the means: what a plain mean holds
    Vec4d patternVariance;  //!< each site's fixed-pattern variance, Var(m) - mean(v)/M, at least 0

    /** The fixed-pattern RMS over the sites: sqrt of the mean of patternVariance (DN). */
    double fixedPatternRms() const;
};

/** Estimates the dark frames' pattern and temporal noise from their burst statistics (every frame of one
 * gain and exposure, M >= 2), black-subtracted with `stats`' format. A pixel is noisy when its variance
 * exceeds its row's (at least 1/12 DN^2, what whole DN resolve) by more than a chi-square allows at a
 * false-alarm rate of `falseAlarm` per pixel, with
 * the degrees of freedom the variances scatter with (their interquartile range: M - 1 for Gaussian noise,
 * fewer for heavy tails); its own variance then stands in the pattern's shrinkage, and it is left out of
 * the pooled variances. Hot pixels (a high mean) belong to the pattern and count in its variance.
 * @throws cv::Exception for fewer than two frames, frames of fewer than 16 pixels or a false-alarm rate
 * outside (0, 0.5). */
DarkFrameEstimate estimateDarkFrames(const BurstStatistics& stats, double falseAlarm = 1e-6);

/** Dark frames of one gain and exposure time (dark current grows with it), and what they tell apart. */
struct DarkFrameGroup
{
    double gain = 1;           //!< the linear gain the frames were taken at
    double exposureTime = 0;   //!< seconds; 0 when the frames do not state it
    std::vector<String> files; //!< the frames, in the order given: read on demand, never all held
    DarkFrameEstimate estimate;
};

/** Dark frames of one sensor (one size, CFA pattern, black and white level), grouped by gain and exposure. */
struct DarkFrameCollection
{
    RawFormat format; //!< the frames' format, at gain 1
    Size size;
    std::vector<DarkFrameGroup> groups; //!< by gain, then exposure time
};

/** Reads each file once, one at a time, and groups the frames by gain and exposure time: a mosaic with a
 * sidecar (readMosaic(): the sidecar's gain, or its camera's ISO through `model` when it says gainFromIso)
 * or a DNG or camera RAW file without one (readRaw(): its ISO through formatAtIso() with `model`, the
 * library's one ISO-to-gain rule). A single gain is a valid collection.
 * @throws cv::Exception naming the file for: no files; a frame of another size, CFA pattern, black or white
 * level than the first (both named); a gain and exposure with fewer than two frames; an unreadable file. */
DarkFrameCollection collectDarkFrames(const std::vector<String>& files, const NoiseModel& model);

/** The upper chi-square quantile over its degrees of freedom, chi2_{1-p}(k) / k, to Wilson and Hilferty's
 * approximation, which overstates it: against SciPy's chi2.isf by at most 3.4% for k >= 7 and p >= 1e-6, but
 * 15% at k = 1 (a threshold that then flags fewer pixels). */
double chiSquareUpperQuantileOverDof(int k, double p);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_DARK_FRAMES_HPP
