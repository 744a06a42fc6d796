// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What the colour jitter's rows share (color_jitter.cpp, and the ShotNoiseSampling::POISSON rows in
// color_jitter_poisson.cpp): the jitter's constants, the variance Eq. 13 adds, and pixels in lanes.
#ifndef OPENCV_RAWGMENT_SRC_COLOR_JITTER_ROWS_HPP
#define OPENCV_RAWGMENT_SRC_COLOR_JITTER_ROWS_HPP

#include "augment_steps.hpp"
#include "cpu_dispatch.hpp"
#include "noise_terms.hpp"

#include <cstring>

namespace cv {
namespace rawgment {
namespace detail {

struct JitterConstants
{
    float pc[4], black[4];
    float slope[4], offset[4]; // lineBySite: the added variance per site (perSiteLine())
    float pb, pg, white;
    NoiseTerms<float> in; // the model's terms at the input gain
    // The output gain's shot slope (DN per electron there) and read variance: with measured lines the
    // model's own line there, else Eq. 5's scaling of `in` (p_g in.shot, p_g^2 in.readBeforeGain +
    // in.readAfterGain) in float, as the Eq. 5 formulas below had it, so no bit changes.
    float shotOut, readOut;
    // Measured lines: Eq. 13 with each gain's own line (jitterVariance()), from p_g shotOut and p_g^2
    // times the input's terms.
    bool measured;
    float pgShotOut, pg2ShotIn, pg2ReadIn;
    NoiseAlignment alignment;
    ShotNoiseSampling sampling;
    // ACCOUNT_PRIOR without brightness: the prior's share p_u = p_c / p_g is one number per CFA site, so
    // Eq. 13 is a line in the mean per site, its slope and offset computed once (perSiteLine()).
    bool lineBySite;
    DarkTerms dark; // the model's dark-frame components this jitter adds
};

// The column arrays of one row (the CFA site alternates along it): contrast, black level and, for
// lineBySite, the slope and offset of the added variance.
struct JitterColumns
{
    const float *pc, *black, *slope, *offset;
};

// The variance to add to a pixel, split into its shot part and the rest (read noise, and for
// ACCOUNT_PRIOR the correction of the scaled prior), before any clipping. xm is the prior-mean estimate
// (black-subtracted), pc the pixel's contrast. Eq. 13 for ACCOUNT_PRIOR; the model at the new mean and
// gain for IGNORE_PRIOR.
// V is float (one pixel) or a vector of lanes (cpu_dispatch.hpp): the same operations in the same order.
template <NoiseAlignment A, typename V>
RAWGMENT_KERNEL AddedVarianceOf<V> jitterVariance(V xm, V pc, const JitterConstants& k)
{
    const V zero = V{} + 0.0f, one = zero + 1.0f;
    const float pg2 = k.pg * k.pg;
    if (A == NoiseAlignment::ACCOUNT_PRIOR) {
        const V xf = maxLanes(xm, one);
        const V pu = maxLanes((pc * xf + k.pb) / (xf * k.pg), zero);
        const V mu = maxLanes(xm, zero);
        // The target's line at the output mean p_u p_g mu less the prior scaled by (p_u p_g)^2; with
        // Eq. 5 (shotOut = p_g in.shot) the same as the expressions below.
        if (k.measured)
            return {pu * (k.pgShotOut - pu * k.pg2ShotIn) * mu, k.readOut - pu * pu * k.pg2ReadIn};
        return {pu * (1 - pu) * (pg2 * k.in.shot) * mu,
                (1 - pu * pu) * (pg2 * k.in.readBeforeGain) + (1 - pu * pu * pg2) * k.in.readAfterGain};
    }
    if (A == NoiseAlignment::IGNORE_PRIOR)
        return {k.shotOut * maxLanes(pc * xm + k.pb, zero), zero + k.readOut};
    return {zero, zero};
}

// W pixels of type T as float lanes: loaded, and stored clipped to [0, white] (16-bit: rounded half to
// even, roundHalfToEven).
template <int W, typename T> struct PixelLanes;
template <int W> struct PixelLanes<W, ushort>
{
    typedef typename Lanes<W>::F F;
    RAWGMENT_KERNEL F load(const ushort* p)
    {
        typename Lanes<W>::U16 v;
        std::memcpy(&v, p, sizeof(v));
        return convertLanes<F>(v);
    }
    RAWGMENT_KERNEL void store(ushort* p, F out, F white)
    {
        out = roundHalfToEven(minLanes(maxLanes(out, F{}), white));
        const typename Lanes<W>::U16 v =
            convertLanes<typename Lanes<W>::U16>(convertLanes<typename Lanes<W>::I>(out));
        std::memcpy(p, &v, sizeof(v));
    }
};
template <int W> struct PixelLanes<W, float>
{
    typedef typename Lanes<W>::F F;
    RAWGMENT_KERNEL F load(const float* p)
    {
        F v;
        std::memcpy(&v, p, sizeof(v));
        return v;
    }
    RAWGMENT_KERNEL void store(float* p, F out, F white)
    {
        out = minLanes(maxLanes(out, F{}), white);
        std::memcpy(p, &out, sizeof(out));
    }
};

// The passes' arrays of one thread, reused row after row.
struct PoissonRowBuffers
{
    std::vector<double> means, counts;
    std::vector<float> zVar, tVar;
};

/* One row of ShotNoiseSampling::POISSON (color_jitter_poisson.cpp): z and t the row's Gaussian and
 * Tukey-lambda draws (t null without tails), prior the local-mean row or null, extra the dark terms or
 * null; key and stream name the row's Poisson counts. Returns the number of brightening pixels. */
template <typename T>
int jitterRowPoisson(const T* s, T* d, const float* z, const float* t, const float* prior, const float* extra,
                     const JitterColumns& col, const JitterConstants& k, uint64_t key, uint64_t stream,
                     PoissonRowBuffers& rows, int cols);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif
