// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The read part of a noise step drawn from a dark-frame bank (NoiseOptions::darkBank): which frames, how much
// of their row part and pixel part each pixel takes, and the pattern to add; docs/mathematics.md ("A bank of
// dark frames"). Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_BANK_NOISE_HPP
#define OPENCV_RAWGMENT_SRC_BANK_NOISE_HPP

#include "random.hpp"
#include "step_noise.hpp"

#include <opencv2/rawgment/dark_frames.hpp>

#include <memory>

namespace cv {
namespace rawgment {
namespace detail {

//! The bank saved at `path`, read once per process while the file keeps its size and modification time.
std::shared_ptr<const DarkFrameBank> cachedDarkFrameBank(const String& path);

/** How a step scales the input's fixed pattern, per CFA site of the output: `amplitude` times it (a jitter's
 * k; a resampling step's sqrt(sum w^2), its pattern's typical spread when the pattern is not correlated), and
 * for a tied bank the input's pattern as the step leaves it (`held`, CV_32FC1 of the mosaic's size: a
 * resampling step's own output of bankInputPattern(); empty: amplitude times that pattern in place). */
struct BankPattern
{
    Vec4d amplitude = Vec4d::all(1);
    Mat held;
};

/** The pixel part's variance of a group where a mosaic lies: per mosaic row and column parity, and each noisy
 * pixel's own, by mosaic row. */
struct PixelPartVariance
{
    Mat byRow;                   //!< CV_32FC1, the mosaic's rows x 2 (column parity)
    std::vector<int> rowStart;   //!< the noisy pixels of mosaic row r are [rowStart[r], rowStart[r + 1])
    std::vector<int> column;     //!< each noisy pixel's mosaic column
    std::vector<float> variance; //!< and its variance
    bool empty() const { return byRow.empty(); }
};

/** A step's read part from a bank, prepared once per call: the target group's two frames (IGNORE_PRIOR: one)
 * as read, their scale to the output gain, the variances of the row part and the pixel part at the target and
 * in the input, and how the pattern is added. No map of the mosaic's size is made: the rows read the frames
 * and the groups' statistics where the mosaic lies (bankRowExtra()). */
struct BankRead
{
    enum Pattern
    {
        NO_PATTERN,
        ADD_LACKING, //!< untied: patternShare (F_t - level_t)
        SWAP,        //!< tied: F_t - patternAmplitude F_s
        SWAP_MOVED   //!< tied, resampled: F_t - movedPattern
    };
    bool ignore = false; //!< IGNORE_PRIOR: a whole dark frame
    Mat frame;           //!< a whole frame of the target group as read (CV_16UC1 or CV_32FC1)
    //! ACCOUNT_PRIOR: the group's plain mean, which the draw takes out (CV_32FC1, shared, not copied)
    Mat groupMean;
    Point origin; //!< where the mosaic lies on them
    /** The draw's scale: the frames' temporal noise to the output gain's (the model's read lines), and for
     * ACCOUNT_PRIOR sqrt(M / (M - 1)) of a frame less its group's mean. */
    float drawScale = 1;
    float black[4] = {0, 0, 0, 0};     //!< the bank's black level per sensor site
    float rowTarget[4] = {0, 0, 0, 0}; //!< the target's row-part variance per mosaic site
    float rowHeld[4] = {0, 0, 0, 0};   //!< the input's, before the step's factor
    PixelPartVariance pixelTarget;     //!< the target's pixel part
    PixelPartVariance pixelHeld;       //!< the input's for a tied bank; empty: pooled per site
    float pixelHeldBySite[4] = {0, 0, 0, 0};
    Pattern pattern = NO_PATTERN;
    Mat patternTarget, patternInput; //!< the groups' whole patterns (shared, not copied)
    Mat movedPattern; //!< SWAP_MOVED: the input's pattern as the step left it, the mosaic's size
    float patternShare[4] = {0, 0, 0, 0}, patternAmplitude[4] = {0, 0, 0, 0}, levelTarget[4] = {0, 0, 0, 0};
    bool empty() const { return frame.empty(); }
};

/** The input's fixed pattern where the mosaic lies (the bank's group nearest the input's gain; DN above
 * black): what a resampling step moves and mixes, for BankPattern::held. */
Mat bankInputPattern(const StepNoise& step, const RawFormat& format, Size size);

/** The read part of a step from gain step.gainIn to step.gainOut on a mosaic of `size` at
 * format.sensorOrigin, drawn with `seed` from stream family `stream`.
 * @throws cv::Exception naming `who` for a mosaic outside the bank's frames, another CFA phase, a tied bank
 * without frames at the input's gain, a target gain beyond the bank's range. */
BankRead prepareBankRead(const StepNoise& step, const RawFormat& format, Size size,
                         const BankPattern& pattern, uint64 seed, RandomStream stream, const char* who);

/** The bank's read part at columns first + step j (j < n) of mosaic row r into extra[0..n): the row part (the
 * frames' difference averaged over the sensor's row at the column's parity) with the share left by
 * rowFactor[p] (the input's row-part variance the step keeps, for mosaic column parity p), the pixel part
 * with the share left by pixelFactor[j], and the pattern. The same bits on every path and thread count.
 * Returns the pixels whose row or pixel part the input already held more of than the target has. */
int64 bankRowExtra(const BankRead& b, int r, int first, int step, int n, const float rowFactor[2],
                   const float* pixelFactor, float* extra);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_BANK_NOISE_HPP
