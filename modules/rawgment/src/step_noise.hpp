// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A noise step's model, prepared once per call: what colorJitter(), motionBlur(), scaleMosaic() and
// applyScene() take from a NoiseModel, validated once, before any row runs. Row code sees the prepared
// terms and the dark terms (which own the reader of the dark shading), never the NoiseModel. Private to
// the module.
#ifndef OPENCV_RAWGMENT_SRC_STEP_NOISE_HPP
#define OPENCV_RAWGMENT_SRC_STEP_NOISE_HPP

#include "dark_shading.hpp"
#include "noise_terms.hpp"
#include "opencv2/rawgment/augment.hpp"
#include "random.hpp"

#include <opencv2/rawgment/dark_frames.hpp>

#include <memory>

namespace cv {
namespace rawgment {
namespace detail {

/** The noise of one step from gain g to p_g g on a mosaic of `size` (paper Eq. 5 and 13, and the
 * dark-frame components of docs/mathematics.md): the model's terms at both gains (each gain's own
 * measured line when the model has them), its dark-frame components and its dark shading at g where the
 * mosaic lies on the sensor. Built inside a step from a ValidatedNoiseModel and the options runNoiseSteps()
 * validated, so a call validates its model and its options once; the shading is checked to cover the mosaic
 * only when the step adds noise (NoiseAlignment::NONE reads no map). */
struct StepNoise
{
    /** `exposureOut`: the target's exposure time (0: the input's, format.exposureTime); only a bank's
     * groups depend on it. */
    StepNoise(const ValidatedNoiseModel& model, const RawFormat& format, const NoiseOptions& options,
              double gainRatio, Size size, const char* who, double exposureOut = 0);

    NoiseOptions options;
    double gainIn, gainOut;         //!< g and p_g g
    double exposureIn, exposureOut; //!< seconds, 0 when not stated
    NoiseTerms<double> in, out;     //!< the model's terms at gainIn and gainOut
    bool measured;                  //!< the terms are measured lines' (NoiseModel::measuredLines)
    bool rowNoise;                  //!< NoiseModel::hasRowNoise()
    double rowSigmaD2, rowSigmaR2;
    bool tails;          //!< NoiseModel::tukeyRead
    double tukeyLambda;  //!< the read noise's Tukey-lambda shape, when `tails`
    DarkShading shading; //!< at gainIn; empty when the model has none, the step adds no noise or uses a bank
    /** NoiseOptions::darkBank's bank, when set and the step adds noise: it then stands in for the model's
     * read terms, which `in` and `out` no longer hold (nor rowNoise, tails or shading). */
    std::shared_ptr<const DarkFrameBank> bank;
    //! the bank's groups at gainIn (nearest) and gainOut (in range), each of its side's exposure
    int bankGroupIn = -1, bankGroupOut = -1;
    //! sqrt of the model's read variance at gainIn (gainOut) over that at its group's gain: the frames' scale
    double bankScaleIn = 1, bankScaleOut = 1;

    bool addsNoise() const { return options.alignment != NoiseAlignment::NONE; }
    bool hasDarkComponents() const { return rowNoise || !shading.empty() || tails; }
    //! The row noise's variance at a gain: g^2 sigma_row_d^2 + sigma_row_r^2 (NoiseModel::rowVariance()).
    double rowVariance(double gain) const { return gain * gain * rowSigmaD2 + rowSigmaR2; }
};

/** The dark-frame components a noise step adds, per CFA site: a row offset of amplitude rowSigma drawn
 * once per mosaic row, the deterministic shadingPerGain B_d + shadingOffset B_r read through `shading`,
 * and the lambda of the read part's heavy tails. */
struct DarkTerms
{
    bool row = false, tails = false;
    float rowSigma[4] = {0, 0, 0, 0};
    float shadingPerGain[4] = {0, 0, 0, 0}, shadingOffset[4] = {0, 0, 0, 0};
    DarkShading shading; // the maps where the mosaic lies (empty: no shading), at the step's input gain
    // The quantiles of the added read part's heavy-tailed shapes, when `tails`, for fillTukeyUnit(): a mosaic
    // row of parity p reads tailTable[p] (sites 2p and 2p + 1); a resampling step, whose sites share one
    // shape, tailTable[0].
    TukeyQuantileTable tailTable[2];
    bool any() const { return row || !shading.empty(); }
};

/** Row r's additive part of `d` into extra[0..cols): d.rowSigma[site] times the row's one draw from
 * stream (rowKey, r), plus the dark shading. Sites of one row share the draw, as a real row offset does.
 * Returns false when the row's shading holds NaN or Inf (the check costs one subtraction per value). */
bool darkRowExtra(const DarkTerms& d, uint64_t rowKey, int r, int cols, float* extra);
//! The error of a step whose dark-shading rows held NaN or Inf (darkRowExtra() returned false).
void throwNonFiniteShading(const char* who);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_STEP_NOISE_HPP
