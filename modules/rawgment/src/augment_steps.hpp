// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The machinery that the augment topic's noise steps share (color_jitter.cpp, resample.cpp, scene.cpp):
// input checks, the split of an added variance into shot and read parts, its sampling, and the store.
// Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_AUGMENT_STEPS_HPP
#define OPENCV_RAWGMENT_SRC_AUGMENT_STEPS_HPP

#include "noise_terms.hpp"
#include "opencv2/rawgment/augment.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <algorithm>
#include <type_traits>

namespace cv {
namespace rawgment {
namespace detail {

//! Throws StsBadArg naming `who` unless src is a non-empty CV_16UC1 or finite CV_32FC1 mosaic.
void checkMosaicInput(const Mat& src, const char* who);

//! checkMosaicInput() plus the format, model and options, and even sides: blur and scale resample each
//! CFA plane, so they need whole 2x2 blocks.
void checkResampleInput(const Mat& src, const RawFormat& format, const NoiseModel& model,
                        const NoiseOptions& noise, const char* who);

//! Counts or masks saturated input pixels, only when the caller asks: the hot loops do not pay for it.
void reportSaturation(const Mat& src, const RawFormat& format, AugmentReport* report, OutputArray mask);

/** The Mat a noise step writes its result into: the caller's dst when it is a Mat of src's size and type
 * that shares no memory with src, else a new one. A buffer reused call after call costs no page faults:
 * on a virtual machine, first touching a new 48 MB float frame costs more than the step itself. A dst
 * that overlaps src gets a new Mat, so the input is never written. */
Mat stepOutput(const Mat& src, OutputArray dst);

//! Whether a motion kernel leaves the mosaic as it is (empty or a single tap).
bool isIdentityKernel(const Mat& kernel);

// The variance to add to a pixel, split into its shot part and the rest (read noise, and for
// ACCOUNT_PRIOR the correction of the scaled prior), before any clipping.
template <typename V> struct AddedVarianceOf
{
    V shot, rest;
};
//! One pixel's; the vector kernels use AddedVarianceOf their lanes.
typedef AddedVarianceOf<float> AddedVariance;

/* Gaussian noise of variance `rest` plus the shot part as an electron count: q (K - m) with
 * K ~ Poisson(m), m = shot / q^2 (ShotNoiseSampling::POISSON). A negative total (brightening) adds
 * nothing; a negative rest (the gain grew) is taken from the Poisson part, so the variance added is
 * always max(shot + rest, 0), the same as the Gaussian path.
 * A row draws in two passes: poissonMean() of every pixel, one fillPoisson() of the row (vector lanes),
 * then sampledNoise() with each pixel's count. */
inline double poissonMean(AddedVariance v, float q)
{
    const float total = std::max(v.shot + v.rest, 0.0f);
    const float shot = q > 0 ? std::min(std::max(v.shot, 0.0f), total) : 0.0f;
    const double m = shot > 0 ? static_cast<double>(shot) / (static_cast<double>(q) * q) : 0.0;
    // Beyond kMaxPoissonMean electrons the count is Gaussian to double precision: sampledNoise() draws the
    // whole variance as one Gaussian then (with a tiny q, m can be any size), and no count is needed.
    return m <= detail::kMaxPoissonMean ? m : 0.0;
}

//! The noise of one pixel from its Gaussian z and its count K ~ Poisson(poissonMean(v, q)).
inline float sampledNoise(AddedVariance v, float q, float z, double count)
{
    const float total = std::max(v.shot + v.rest, 0.0f);
    const float shot = q > 0 ? std::min(std::max(v.shot, 0.0f), total) : 0.0f;
    const double m = static_cast<double>(shot) / (static_cast<double>(q) * q);
    if (!(m <= detail::kMaxPoissonMean))
        return std::sqrt(total) * z;
    const float centred = shot > 0 ? static_cast<float>(count - m) : 0.0f;
    return q * centred + std::sqrt(total - shot) * z;
}

/* sampledNoise() with the read part from the unit-variance heavy-tailed draw t (NoiseModel::tukeyRead)
 * and the shot part from z, or as an electron count when `poisson` (the mean of that count:
 * poissonMeanWithTails()). The variance added is max(shot + rest, 0) as on every path; the read part is
 * the rest, never more than that total. */
inline double poissonMeanWithTails(AddedVariance v, float q)
{
    const float total = std::max(v.shot + v.rest, 0.0f);
    const float read = std::min(std::max(v.rest, 0.0f), total), shot = total - read;
    if (!(q > 0 && shot > 0))
        return 0.0;
    const double m = static_cast<double>(shot) / (static_cast<double>(q) * q);
    return m <= detail::kMaxPoissonMean ? m : 0.0;
}

inline float sampledNoiseWithTails(AddedVariance v, float q, bool poisson, float z, float t, double count)
{
    const float total = std::max(v.shot + v.rest, 0.0f);
    const float read = std::min(std::max(v.rest, 0.0f), total), shot = total - read;
    float shotNoise = std::sqrt(shot) * z;
    if (poisson && q > 0 && shot > 0) {
        const double m = static_cast<double>(shot) / (static_cast<double>(q) * q);
        if (m <= detail::kMaxPoissonMean)
            shotNoise = q * static_cast<float>(count - m);
    }
    return shotNoise + std::sqrt(read) * t;
}

/** The dark-frame components a noise step adds (NoiseModel's row noise, dark shading and Tukey read),
 * per CFA site: a row offset of amplitude rowSigma drawn once per mosaic row, the deterministic
 * shadingPerGain B_d + shadingOffset B_r, and the lambda of the read part's heavy tails. */
struct DarkTerms
{
    bool row = false, shading = false, tails = false;
    float rowSigma[4] = {0, 0, 0, 0};
    float shadingPerGain[4] = {0, 0, 0, 0}, shadingOffset[4] = {0, 0, 0, 0};
    Point origin; // where the mosaic lies on the sensor (RawFormat::sensorOrigin): the maps are read there
    TukeyUnitSampler tailSampler[4]; // the added read part's heavy-tailed shape per site, when `tails`
    bool any() const { return row || shading; }
};

/** The dark shading g B_d + B_r of a model at one gain, read row by row from its maps: a whole-frame
 * map per call (48 MB at 12 MP) would cost more in first-touch page faults than the step itself. */
struct ShadingRows
{
    const Mat* perGain = nullptr; // null: no shading
    const Mat* offset = nullptr;
    float gain = 0;
    Point origin; // the mosaic's (0, 0) on the sensor: row r, column c of the mosaic read the maps there
    ShadingRows() = default;
    ShadingRows(const NoiseModel& model, double g, Point sensorOrigin)
        : perGain(&model.darkShadingPerGain), offset(&model.darkShadingOffset), gain(static_cast<float>(g)),
          origin(sensorOrigin)
    {
    }
    bool empty() const { return perGain == nullptr; }
    //! g B_d + B_r of mosaic row r, column c (float: the same on every CPU path).
    float at(const float* bd, const float* br, int c) const { return gain * bd[c] + br[c]; }
    const float* perGainRow(int r) const { return perGain->ptr<float>(r + origin.y) + origin.x; }
    const float* offsetRow(int r) const { return offset->ptr<float>(r + origin.y) + origin.x; }
};

/** Row r's additive part of `d` into extra[0..cols): d.rowSigma[site] times the row's one draw from
 * stream (rowKey, r), plus the dark shading. Sites of one row share the draw, as a real row offset does.
 * Returns false when the row's shading holds NaN or Inf (the check costs one subtraction per value). */
bool darkRowExtra(const DarkTerms& d, const NoiseModel& model, uint64_t rowKey, int r, int cols,
                  float* extra);
//! The error of a step whose dark-shading rows held NaN or Inf (darkRowExtra() returned false).
void throwNonFiniteShading(const char* who);
/** Throws StsBadArg naming `who` when the model has dark shading and a mosaic of `size` at the sensor
 * origin `origin` (RawFormat::sensorOrigin) does not lie inside its maps. */
void checkDarkShadingSize(const NoiseModel& model, Size size, Point origin, const char* who);

// Rounds a float or a vector of floats in [0, 2^23] to the nearest integer, ties to even: adding and
// subtracting 2^23 (where the float spacing is 1) leaves the rounding to IEEE's default mode, the same
// on every vector width. Adding 0.5 and truncating would round every tie up, a bias of +1/4 DN wherever
// ties are common: integer mosaics halved with no noise added (NoiseAlignment::NONE, brightening pixels).
template <typename V> inline __attribute__((always_inline)) V roundHalfToEven(V v)
{
    const float spacingOne = 8388608.0f;
    return (v + spacingOne) - spacingOne;
}

// Clipped to [0, white]; 16-bit output is rounded half to even.
template <typename T> inline __attribute__((always_inline)) T storeValue(float out, float white)
{
    out = std::min(std::max(out, 0.0f), white);
    return std::is_same<T, ushort>::value ? static_cast<T>(static_cast<int>(roundHalfToEven(out)))
                                          : static_cast<T>(out);
}

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_AUGMENT_STEPS_HPP
