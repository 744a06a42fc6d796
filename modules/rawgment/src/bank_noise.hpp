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

/** What the input's values already hold of the read noise a step's output needs, per CFA site of the
 * output: the factor of the input's pixel part (a jitter's k^2, a blur's sum of w^2), of its row part (a
 * jitter's k^2; a blur's sum over kernel rows of the squared row sums) and the factor of its fixed pattern
 * (a jitter's k; none for a resampling step, which the bank does not support tied). */
struct BankPrior
{
    Vec4d pixel = Vec4d::all(1), row = Vec4d::all(1), pattern = Vec4d::all(1);
};

/** A step's read part from a bank, prepared once per call: the target group's two frames (IGNORE_PRIOR: one),
 * their scale to the output gain, and per pixel the share c of each part with k^2 v_s + c^2 v_t = v_t. */
struct BankRead
{
    bool ignore = false; //!< IGNORE_PRIOR: a whole dark frame
    Mat frameA, frameB;  //!< CV_32FC1 whole frames of the target group (raw DN)
    Point origin;        //!< where the mosaic lies on them
    float scale = 1;     //!< the frames' temporal noise to the output gain's (the model's read lines)
    float black[4] = {0, 0, 0, 0};    //!< the bank's black level per sensor site
    float rowShare[4] = {0, 0, 0, 0}; //!< c of the row part, per mosaic site
    Mat pixelShare;                   //!< CV_32FC1, the mosaic's size: c of the pixel part
    Mat patternAdd;                   //!< CV_32FC1, the mosaic's size, or empty: the pattern added
    int64 readBrightening = 0;        //!< pixels whose row or pixel part the prior already exceeds
    bool empty() const { return frameA.empty(); }
};

/** The read part of a step from gain step.gainIn to step.gainOut on a mosaic of `size` at
 * format.sensorOrigin, drawn with `seed` from stream family `stream`.
 * @throws cv::Exception naming `who` for a mosaic outside the bank's frames, another CFA phase, a tied bank
 * without frames at the input's gain, a target gain beyond the bank's range. */
BankRead prepareBankRead(const StepNoise& step, const RawFormat& format, Size size, const BankPrior& prior,
                         uint64 seed, RandomStream stream, const char* who);

//! Row r of the bank's read part into extra[0..cols) (the same bits on every path and thread count).
void bankRowExtra(const BankRead& b, int r, int cols, float* extra);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_BANK_NOISE_HPP
