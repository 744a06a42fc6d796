// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// One noise step of an augmentation (a shift, a scale, a colour jitter, a motion blur) and the loop that runs
// a sequence of them: applyScene() compiles a Scene to steps, and colorJitter(), motionBlur() and
// scaleMosaic() are one-step sequences through the same loop. The loop owns the buffers, the state of the
// input's values (checked or not), the errors a step's rows found and the report; a step only validates,
// prepares and runs its rows. Private to the module; docs/architecture.md ("Adding an effect") says why it is
// not public.
#ifndef OPENCV_RAWGMENT_SRC_NOISE_STEP_HPP
#define OPENCV_RAWGMENT_SRC_NOISE_STEP_HPP

#include "noise_terms.hpp"
#include "opencv2/rawgment/augment.hpp"
#include "precomp.hpp"

#include <atomic>
#include <memory>
#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

//! What a step is prepared for: the model, the noise options and the input's format (each validated once for
//! the whole sequence by runNoiseSteps()), the seed and the input it will read (its size, its depth and the
//! format the step before it left).
struct StepContext
{
    const ValidatedNoiseModel& model;
    const NoiseOptions& noise;
    uint64 seed;
    Size size;
    int depth;
    RawFormat format;
};

//! What a step's rows found, gathered over the threads by the loop, which turns it into an error or a count
//! in the report once, for every step.
struct StepTally
{
    std::atomic<bool> nonFiniteInput{false};   //!< a float input row held NaN or Inf
    std::atomic<bool> nonFiniteShading{false}; //!< a dark-shading row held NaN or Inf
    std::atomic<int64> brightening{0};         //!< AugmentReport::brighteningPixels
    std::atomic<int64> readBrightening{0};     //!< AugmentReport::readBrighteningPixels
};

/** One step. The loop calls, in this order: prepare() for every step of the sequence before any pixel is read
 * (so a bad parameter anywhere fails before work is done), then per step that is not the identity begin(),
 * the rows in parallel (runRows() over [0, rowCount())), finish(); every step, identity or not, gets
 * describeInput(). A step is then destroyed, freeing what begin() made (a bank's frames). */
class NoiseStep
{
public:
    virtual ~NoiseStep() = default;

    //! The name errors carry ("colorJitter: ...").
    virtual const char* name() const = 0;
    //! The name AugmentReport::steps records.
    virtual const char* reportName() const { return name(); }

    /** Validates the step's parameters against its input and decides what it does, reading no pixel.
     * Returns the format of its output. Throws cv::Exception naming the step on a bad parameter. */
    virtual RawFormat prepare(const StepContext& context) = 0;
    //! Whether, prepared, the step leaves its input as it is: then it reads no row and takes no buffer.
    virtual bool isIdentity() const = 0;

    /** Makes what the rows read (tables, a bank's frames, a prior from the input's values). `checkValues`:
     * the rows must check a float input's values (no step before read them); they report to `tally`, which
     * outlives the rows. */
    virtual void begin(const Mat& src, bool checkValues, StepTally& tally) = 0;
    //! The units [0, rowCount()) the loop splits among threads (mosaic rows, or CFA plane rows).
    virtual int rowCount() const = 0;
    //! Writes dst's rows of the units `units`; the same bits whatever the split.
    virtual void runRows(const Mat& src, Mat& dst, const Range& units) const = 0;
    //! After every row: checks of what no row read (rows a shift or a magnification left out).
    virtual void finish(const Mat& src, bool checkValues, StepTally& tally) const
    {
        CV_UNUSED(src);
        CV_UNUSED(checkValues);
        CV_UNUSED(tally);
    }
    //! What the step reports of its input, identity or not (a jitter's saturated pixels).
    virtual void describeInput(const Mat& src, AugmentReport* report) const
    {
        CV_UNUSED(src);
        CV_UNUSED(report);
    }
    //! Moves boxes of a frame of `size` as the step moves its content.
    virtual void moveBoxes(std::vector<Rect>& boxes, Size size) const
    {
        CV_UNUSED(boxes);
        CV_UNUSED(size);
    }
};

typedef std::vector<std::unique_ptr<NoiseStep>> NoiseSteps;

/** Runs `steps` on src (a two-dimensional CV_16UC1 or CV_32FC1 mosaic of even sides where a step needs them)
 * into dst, in two buffers in turn, the last step into the caller's dst when it is a Mat of src's size and
 * type that shares no memory with src: a new 48 MB float frame per step costs more in page faults than the
 * step (glibc maps blocks over 32 MB afresh on every allocation). src is never written. The first step that
 * runs checks a float input's values as it reads them; when none runs they are checked here, naming `who`.
 * `valuesChecked`: src's values are known finite (a step's own output). */
void runNoiseSteps(NoiseSteps& steps, const Mat& src, const RawFormat& format,
                   const ValidatedNoiseModel& model, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                   RawFormat& dstFormat, AugmentReport* report, std::vector<Rect>* boxes, const char* who,
                   bool valuesChecked = false);

/** @name The steps
 * Each is defined in its own source; a Scene compiles to them in this order (applyScene()). */
//! @{
//! Moves the content by `shift` mosaic pixels (rounded to the CFA's period), the dark shading staying put.
std::unique_ptr<NoiseStep> makeShiftStep(Point shift);
//! scaleMosaic()
std::unique_ptr<NoiseStep> makeScaleStep(double scale);
//! colorJitter(); `saturatedMask`, when not null, receives the input's saturated pixels.
std::unique_ptr<NoiseStep> makeColorJitterStep(const ColorJitter& jitter, const _OutputArray* saturatedMask);
//! motionBlur()
std::unique_ptr<NoiseStep> makeMotionBlurStep(InputArray kernel);
//! @}

//! runNoiseSteps() of one step.
void runNoiseStep(std::unique_ptr<NoiseStep> step, const Mat& src, const RawFormat& format,
                  const ValidatedNoiseModel& model, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                  RawFormat& dstFormat, AugmentReport* report, bool valuesChecked = false);

/** A public step function (colorJitter(), motionBlur(), scaleMosaic()): src made two-dimensional, the model
 * validated, src's type checked, then its one step; errors name the step. */
void runPublicStep(std::unique_ptr<NoiseStep> step, InputArray src, const RawFormat& format,
                   const NoiseModel& model, const NoiseOptions& noise, uint64 seed, OutputArray dst,
                   RawFormat& dstFormat, AugmentReport* report);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_NOISE_STEP_HPP
