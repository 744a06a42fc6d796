// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The machinery that the augment topic's noise steps share (noise_step.hpp and the steps' sources):
// input checks, the split of an added variance into shot and read parts, its sampling, and the store.
// Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_AUGMENT_STEPS_HPP
#define OPENCV_RAWGMENT_SRC_AUGMENT_STEPS_HPP

#include "noise_step.hpp"
#include "opencv2/rawgment/augment.hpp"
#include "precomp.hpp"
#include "step_noise.hpp"

#include <algorithm>
#include <chrono>
#include <type_traits>

namespace cv {
namespace rawgment {
namespace detail {

/* A float mosaic's values are checked where a step reads them anyway, row by row while the row is in cache
 * (checkMosaicType() up front, rowIsFinite() in the rows, throwNonFiniteInput() after them): a separate pass
 * over a 48 MB frame cost a float step more than its extra memory traffic. A sequence of steps none of which
 * runs (runNoiseSteps(), noise_step.hpp) checks with checkMosaicInput(). */

//! Throws StsBadArg naming `who` unless src is a non-empty CV_16UC1 or CV_32FC1 mosaic; its values unread.
void checkMosaicType(const Mat& src, const char* who);

//! checkMosaicType(), then every value of a CV_32FC1 mosaic finite (rows in parallel).
void checkMosaicInput(const Mat& src, const char* who);

//! Whether n floats are all finite: one pass without an early exit, vectorised for the active CpuPath.
bool rowIsFinite(const float* p, int n);

//! The error of a step whose float input held NaN or Inf (found by rowIsFinite()).
[[noreturn]] void throwNonFiniteInput(const char* who);

//! Both sides even: blur and scale resample each CFA plane, so they need whole 2x2 blocks.
void checkResampleShape(Size size, const char* who);

//! Counts or masks saturated input pixels, only when the caller asks: the hot loops do not pay for it.
void reportSaturation(const Mat& src, const RawFormat& format, AugmentReport* report, OutputArray mask);
//! Adds a step that ran to `report` (when given): its name and its wall time since `start`.
void recordStep(AugmentReport* report, const char* name, std::chrono::steady_clock::time_point start);

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

/* How a pixel's added variance is drawn: a Poisson count of mean `mean` electrons
 * (ShotNoiseSampling::POISSON), Gaussian noise of variance zVar from the step's normals, and, with
 * heavy-tailed read noise (NoiseModel::tukeyRead), variance tVar from its unit-variance Tukey-lambda draws.
 * The noise is then q (K - mean) + sqrt(zVar) z + sqrt(tVar) t, K ~ Poisson(mean), q the DN per electron
 * (poissonNoise()). The variance added is always max(shot + rest, 0), as on the Gaussian path:
 * - a negative total (brightening) adds nothing;
 * - with POISSON the shot part is the count: mean = shot / q^2; a negative rest (the gain grew) is taken
 *   from it;
 * - with tails the read part (the rest, never more than the total) takes t, the shot part z or the count;
 * - a mean beyond kMaxPoissonMean electrons (a tiny q) is Gaussian to double precision: z takes it all.
 * A row is drawn in passes: the split of every pixel, one fillPoisson() of the row's means (vector lanes),
 * then the noise of every pixel. */
struct NoiseSplit
{
    double mean;
    float zVar, tVar;
};

//! A row's constants for splitNoise(): q, 1 / q^2 in double, and the largest shot variance drawn as a
//! count (kMaxPoissonMean electrons; 0 when q is not positive, so that nothing is).
struct PoissonScale
{
    float q = 0, maxShot = 0;
    double invQ2 = 0;
    explicit PoissonScale(float dnPerElectron)
        : q(dnPerElectron), maxShot(dnPerElectron > 0 ? static_cast<float>(kMaxPoissonMean * dnPerElectron *
                                                                           static_cast<double>(dnPerElectron))
                                                      : 0.0f),
          invQ2(dnPerElectron > 0 ? 1.0 / (static_cast<double>(dnPerElectron) * dnPerElectron) : 0.0)
    {
    }
};

// The vector kernels (color_jitter.cpp) do the same operations in the same order, lane by lane.
inline NoiseSplit splitNoise(AddedVariance v, const PoissonScale& scale, bool poisson, bool tails)
{
    const float total = std::max(v.shot + v.rest, 0.0f);
    const float read = tails ? std::min(std::max(v.rest, 0.0f), total) : 0.0f;
    const float shot = tails ? total - read : (scale.q > 0 ? std::min(std::max(v.shot, 0.0f), total) : 0.0f);
    const bool drawn = poisson && shot > 0 && shot <= scale.maxShot;
    const float shotDrawn = drawn ? shot : 0.0f;
    return {static_cast<double>(shotDrawn) * scale.invQ2, (total - read) - shotDrawn, read};
}

//! The noise of a split pixel from its normal z, its Tukey-lambda draw t and its count K ~ Poisson(mean).
inline float poissonNoise(const NoiseSplit& s, float q, double count, float z, float t)
{
    return q * static_cast<float>(count - s.mean) + std::sqrt(s.zVar) * z + std::sqrt(s.tVar) * t;
}

// Rounds a float or a vector of floats in [0, 2^23] to the nearest integer, ties to even: adding and
// subtracting 2^23 (where the float spacing is 1) leaves the rounding to IEEE's default mode, the same
// on every vector width. Adding 0.5 and truncating would round every tie up, a bias of +1/4 DN wherever
// ties are common: integer mosaics halved with no noise added (NoiseAlignment::NONE, brightening pixels).
template <typename V> RAWGMENT_ALWAYS_INLINE V roundHalfToEven(V v)
{
    const float spacingOne = 8388608.0f;
    return (v + spacingOne) - spacingOne;
}

//! The level a step clips its output at: the format's white level, and for 16-bit output no more than
//! 65535, whatever white level the format claims (clipped there, never wrapped round).
inline float outputWhite(const RawFormat& format, int depth)
{
    return static_cast<float>(depth == CV_16U ? std::min(format.whiteLevel, 65535.0) : format.whiteLevel);
}

// Clipped to [0, white]; 16-bit output is rounded half to even.
template <typename T> RAWGMENT_ALWAYS_INLINE T storeValue(float out, float white)
{
    out = std::min(std::max(out, 0.0f), white);
    return std::is_same<T, ushort>::value ? static_cast<T>(static_cast<int>(roundHalfToEven(out)))
                                          : static_cast<T>(out);
}

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_AUGMENT_STEPS_HPP
