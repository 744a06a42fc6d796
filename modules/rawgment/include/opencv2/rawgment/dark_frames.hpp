// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A bank of real dark frames: what they tell apart (the fixed pattern, the temporal noise by row and by
// pixel), kept per gain and exposure beside the frames (src/dark_frames.cpp, src/dark_frame_bank.cpp).
#ifndef OPENCV_RAWGMENT_DARK_FRAMES_HPP
#define OPENCV_RAWGMENT_DARK_FRAMES_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/export.hpp>
#include <opencv2/rawgment/noise_model.hpp>

#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_dark_frames
//! @{

/** @brief The fixed pattern and the temporal noise of M dark frames of one gain and exposure (DN above
 * the black level).
 *
 * A pixel's mean m over M frames is its fixed pattern F plus temporal noise of variance v/M, frozen into
 * the mean: on EMVA 1288 set 001 (a 12-bit CCD) the spatial variance of the mean of 50 dark frames is
 * 0.214 DN^2, of which 0.190 is v/M and 0.024 the pattern. So the fixed pattern's variance per CFA site is
 * Var(m) - mean(v)/M (the EMVA 1288 correction), and `pattern` is the mean's departure from its site's median
 * shrunk by sqrt(w), w = s_F^2 / (s_F^2 + v/M) with s_F^2 from the interquartile spread of the means: its
 * departures then scatter by s_F^2, the pattern's own variance and no more (a plain mean's scatter by
 * s_F^2 + v/M; the best linear estimate of F, shrunk by w, by w s_F^2), and it is still closer to F than the
 * plain mean (the median itself where the frames resolve no pattern). Pixels beyond 6 robust standard
 * deviations of the means (hot pixels) keep their mean: pattern beyond doubt. docs/dark_frame_bank.md gives
 * the estimators and their tests.
 */
struct CV_EXPORTS_W_SIMPLE DarkFrameStatistics
{
    //! No frames.
    CV_WRAP DarkFrameStatistics() : frames(0), degreesOfFreedom(0) {}
    CV_PROP_RW int frames;           //!< M
    CV_PROP_RW int degreesOfFreedom; //!< those the variances scatter with: M - 1, fewer for heavy tails
    CV_PROP_RW Mat pattern;          //!< CV_32FC1, the frames' size: the fixed pattern, shrunk for its v/M
    //! CV_32FC1, the frames' size: their plain temporal mean (DN above black), which a step's draws take out
    CV_PROP_RW Mat mean;
    //! CV_64FC1, rows x 2: row r's temporal variance per pixel at its columns' parities 0 and 1, pooled
    //! over the pixels that are not noisy
    CV_PROP_RW Mat rowVariance;
    CV_PROP_RW std::vector<Point> noisyPixels; //!< pixels whose temporal variance their row's cannot explain
    CV_PROP_RW std::vector<double> noisyVariance; //!< their own temporal variance, one per noisy pixel
    //! each CFA site's level: the median of its pixels' means (hot pixels do not move it), the pattern's
    //! centre
    CV_PROP_RW Vec4d level;
    //! each site's temporal variance per pixel, pooled over its pixels that are not noisy (row noise
    //! included)
    CV_PROP_RW Vec4d temporalVariance;
    //! each site's row noise: the variance of a row's temporal offset, shared by the row's pixels of the site
    CV_PROP_RW Vec4d rowNoiseVariance;
    CV_PROP_RW Vec4d meanVariance;    //!< each site's spatial variance of the means: what a plain mean holds
    CV_PROP_RW Vec4d patternVariance; //!< each site's fixed-pattern variance, Var(m) - mean(v)/M, at least 0

    /** @brief The fixed-pattern RMS over the sites: the square root of the mean of patternVariance (DN). */
    CV_WRAP double fixedPatternRms() const;
};

/** @brief The dark frames of one gain and exposure time (dark current grows with it), and their statistics.
 */
struct CV_EXPORTS_W_SIMPLE DarkFrameGroup
{
    //! No frames.
    CV_WRAP DarkFrameGroup() : gain(1), exposureTime(0) {}
    CV_PROP_RW double gain;               //!< the linear gain the frames were taken at
    CV_PROP_RW double exposureTime;       //!< seconds; 0 when the frames do not state it
    CV_PROP_RW std::vector<String> files; //!< the frames: read on demand, never all held
    //! each file's size when the bank was made: a frame whose size changed since is refused
    CV_PROP_RW std::vector<double> fileBytes;
    //! each file's content when the bank was made, its bytes' FNV-1a 64 as 16 hex digits: a frame replaced
    //! since, whatever its size, is refused where it is read (checked once per process per file identity,
    //! size and modification time). Empty in a bank of format_version 1, which recorded none: its frames
    //! are held to their sizes alone.
    CV_PROP_RW std::vector<String> fingerprints;
    CV_PROP_RW DarkFrameStatistics statistics; //!< what the frames tell apart
};

/** @brief Real dark frames of one sensor as the read noise of augmentation (NoiseOptions::darkBank), grouped
 * by gain and exposure time, with what their statistics tell apart.
 *
 * The frames stay in their files: the bank holds their paths and, per group, its statistics (a pattern the
 * size of a frame, the rest small). create() reads each file once, one at a time; readFrame() reads one again
 * when a step draws it. save() writes the bank as a versioned YAML or JSON file, its patterns beside it as
 * TIFF images, and the frames' paths relative to its folder when they lie inside it: a bank is passed to
 * other processes (Dask workers, DataLoader workers) by its path.
 */
struct CV_EXPORTS_W_SIMPLE DarkFrameBank
{
    //! The version of the bank's file that save() writes (2: with each frame's fingerprint; a bank loaded
    //! from version 1, which has none, is saved as version 1); load() reads versions up to it.
    static constexpr int FORMAT_VERSION = 2;

    //! An empty bank: no noise step uses it.
    CV_WRAP DarkFrameBank() {}
    CV_PROP_RW String path;      //!< the file it was loaded from or saved to, absolute ("" before either)
    CV_PROP_RW RawFormat format; //!< the frames' format, at gain 1
    CV_PROP_RW Size size;        //!< the frames' size
    CV_PROP_RW std::vector<DarkFrameGroup> groups; //!< by gain, then exposure time

    //! Whether the bank has no groups.
    CV_WRAP bool empty() const { return groups.empty(); }

    /** @brief A bank of dark-frame files: mosaics with sidecars (readMosaic(): the sidecar's gain, or its
     * camera's ISO through `model`) or DNG and camera RAW files (readRaw(): their ISO through formatAtIso()
     * with `model`, the library's one ISO-to-gain rule), grouped by gain and exposure time. A single gain is
     * a valid bank.
     * @param files the frames, in any order
     * @param model what turns an ISO into a gain (NoiseModel::baseIso); only that is used
     * @param falseAlarm the rate per pixel at which an ordinary pixel is flagged as noisy, in (0, 0.5)
     * @throws cv::Exception naming the file for: no files; a frame of another size, CFA pattern, black or
     * white level than the first (both named); a gain and exposure with fewer than two frames; an unreadable
     * file. */
    CV_WRAP static DarkFrameBank create(const std::vector<String>& files, const NoiseModel& model,
                                        double falseAlarm = 1e-6);
    /** @brief create() of every file in `folder` but sidecars (.yml, .yaml, .json), hidden files and a bank's
     * own TIFF images, by name. */
    CV_WRAP static DarkFrameBank createFromFolder(const String& folder, const NoiseModel& model,
                                                  double falseAlarm = 1e-6);
    /** @brief Loads a bank saved by save(): its file (top-level map `dark_frame_bank`) and its pattern
     * images. Only the statistics are read; the frames are read when a step draws them.
     * @throws cv::Exception naming the file and the key for anything save() does not write: an unknown or
     * missing key, a version newer than FORMAT_VERSION, a group with fewer than two frames, an image of
     * another size or checksum, a value that is negative or not finite. */
    CV_WRAP static DarkFrameBank load(const String& path);
    /** @brief Writes the bank to `path` (.yml, .yaml or .json) and its patterns beside it, atomically, and
     * sets `path`. The earlier patterns of that file are removed once it names the new ones. */
    CV_WRAP void save(const String& path);
    /** @brief True when the bank is its file's, as load() or save() left it: the text save() would write at
     * `path` is the file's, and the maps' checksums in that text are the maps'. A bank goes to other
     * processes by its path, so one edited in memory, or whose file was replaced, would arrive there as
     * another bank: the Python binding refuses to pickle it. Costs a read of the file and a checksum of each
     * map. */
    bool matchesItsFile() const;
    /** @brief Throws cv::Exception naming the group and field when the bank is not one create() or load()
     * could make: groups not by increasing gain, fewer than two frames, maps of another size or type,
     * statistics that are negative or not finite. */
    CV_WRAP void validate() const;
    /** @brief The group whose gain is nearest `gain` (on a log scale) and, of that gain, whose exposure time
     * matches `exposureTime` (seconds): the nearest within a third of a stop (a factor 2^(1/3), the step of
     * shutter settings), else a group whose frames state no exposure. With `exposureTime` 0 (not stated), the
     * gain's one group.
     * @throws cv::Exception for an empty bank, a gain beyond the bank's range (more than 0.1% outside its
     * lowest and highest gains): the bank says nothing of gains it has not seen; an exposure no group of that
     * gain matches, or 0 where the gain has groups of several exposures, naming the exposures it has (dark
     * current grows with the exposure). */
    CV_WRAP int nearestGroup(double gain, double exposureTime = 0) const;
    /** @brief Reads frame `index` of group `group` again (raw DN, black level included).
     * @throws cv::Exception for an index out of range, a file that is missing, unreadable, of another size or
     * format, or of another byte size or content (DarkFrameGroup::fingerprints) than when the bank was
     * made. */
    CV_WRAP Mat readFrame(int group, int index) const;
};

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_DARK_FRAMES_HPP
