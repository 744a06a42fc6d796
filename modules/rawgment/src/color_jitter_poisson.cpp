// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The colour jitter's rows with ShotNoiseSampling::POISSON: exact Poisson shot counts (paper Eq. 13's
// shot part as electrons at the output gain) beside Gaussian or Tukey-lambda read noise.
#include "color_jitter_rows.hpp"

#include <algorithm>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

/* The rows of ShotNoiseSampling::POISSON, with Tukey-lambda read noise (NoiseModel::tukeyRead: t holds
 * the row's unit-variance heavy-tailed draws) or without, and the dark terms' `extra` when present, in
 * three passes: every pixel's split (splitNoise(), here in vector lanes: the same operations),
 * the row's counts (fillPoisson()), every pixel's noise and output. Like jitterRowBody(), the
 * last partial block runs through the vector code on padded copies. */
template <int W, typename T, NoiseAlignment A, bool kLocalMean>
RAWGMENT_KERNEL void poissonSplitBlock(const T* s, const float* prior, const JitterColumns& col, int c,
                                       const JitterConstants& k, const PoissonScale& scale, bool tails,
                                       double* means, float* zVar, float* tVar, typename Lanes<W>::I& bright)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    typedef PixelLanes<W, T> P;
    F pcv, blackv;
    std::memcpy(&pcv, col.pc + c, sizeof(pcv));
    std::memcpy(&blackv, col.black + c, sizeof(blackv));
    const F x = P::load(s + c) - blackv;
    F xm = x;
    if (kLocalMean)
        std::memcpy(&xm, prior + c, sizeof(xm));
    const AddedVarianceOf<F> v = jitterVariance<A>(xm, pcv, k);
    const F sum = v.shot + v.rest;
    bright -= sum < 0;
    const F zero = F{}, total = maxLanes(sum, zero);
    const F read = tails ? minLanes(maxLanes(v.rest, zero), total) : zero;
    const F shot = tails ? total - read : (scale.q > 0 ? minLanes(maxLanes(v.shot, zero), total) : zero);
    const I drawn = (shot > 0.0f) & (shot <= scale.maxShot);
    const F shotDrawn = selectLanes(drawn, shot, zero);
    const F z = (total - read) - shotDrawn;
    storeScaledAsDoubles(shotDrawn, scale.invQ2, means + c);
    std::memcpy(zVar + c, &z, sizeof(z));
    std::memcpy(tVar + c, &read, sizeof(read));
}

template <int W, typename T>
RAWGMENT_KERNEL void poissonNoiseBlock(const T* s, T* d, const float* z, const float* t, const float* extra,
                                       const JitterColumns& col, int c, const JitterConstants& k, float q,
                                       const double* means, const double* counts, const float* zVar,
                                       const float* tVar)
{
    typedef typename Lanes<W>::F F;
    typedef PixelLanes<W, T> P;
    F pcv, blackv, zv, tv = {}, zVarv, tVarv;
    std::memcpy(&pcv, col.pc + c, sizeof(pcv));
    std::memcpy(&blackv, col.black + c, sizeof(blackv));
    std::memcpy(&zv, z + c, sizeof(zv));
    if (t)
        std::memcpy(&tv, t + c, sizeof(tv));
    std::memcpy(&zVarv, zVar + c, sizeof(zVarv));
    std::memcpy(&tVarv, tVar + c, sizeof(tVarv));
    const F noise =
        q * differenceAsFloats<F>(counts + c, means + c) + sqrtLanes(zVarv) * zv + sqrtLanes(tVarv) * tv;
    const F x = P::load(s + c) - blackv;
    F out = pcv * x + k.pb + noise;
    if (extra) {
        F e;
        std::memcpy(&e, extra + c, sizeof(e));
        out += e;
    }
    P::store(d + c, out + blackv, F{} + k.white);
}

template <int W, typename T, NoiseAlignment A, bool kLocalMean>
RAWGMENT_KERNEL int poissonSplitRowBody(const T* s, const float* prior, const JitterColumns& col,
                                        const JitterConstants& k, const PoissonScale& scale, bool tails,
                                        double* means, float* zVar, float* tVar, int cols)
{
    typename Lanes<W>::I bright = {};
    int c = 0;
    for (; c + W <= cols; c += W)
        poissonSplitBlock<W, T, A, kLocalMean>(s, prior, col, c, k, scale, tails, means, zVar, tVar, bright);
    int total = 0;
    for (int i = 0; i < W; ++i)
        total += bright[i];
    const int rest = cols - c;
    if (rest > 0) {
        // Padded copies: the extra lanes compute on zeros and are neither kept nor counted.
        T sPad[W] = {};
        float priorPad[W] = {}, pcPad[W] = {}, blackPad[W] = {}, zPad[W], tPad[W];
        double meanPad[W];
        for (int i = 0; i < rest; ++i) {
            sPad[i] = s[c + i];
            priorPad[i] = kLocalMean ? prior[c + i] : 0.0f;
            pcPad[i] = col.pc[c + i];
            blackPad[i] = col.black[c + i];
        }
        const JitterColumns padded = {pcPad, blackPad, nullptr, nullptr};
        typename Lanes<W>::I tail = {};
        poissonSplitBlock<W, T, A, kLocalMean>(sPad, priorPad, padded, 0, k, scale, tails, meanPad, zPad,
                                               tPad, tail);
        for (int i = 0; i < rest; ++i) {
            means[c + i] = meanPad[i];
            zVar[c + i] = zPad[i];
            tVar[c + i] = tPad[i];
            total += tail[i];
        }
    }
    return total;
}

template <int W, typename T>
RAWGMENT_KERNEL int poissonSplitRowKernel(const T* s, const float* prior, const JitterColumns& col,
                                          const JitterConstants& k, const PoissonScale& scale, bool tails,
                                          double* means, float* zVar, float* tVar, int cols)
{
    if (k.alignment == NoiseAlignment::ACCOUNT_PRIOR)
        return prior ? poissonSplitRowBody<W, T, NoiseAlignment::ACCOUNT_PRIOR, true>(
                           s, prior, col, k, scale, tails, means, zVar, tVar, cols)
                     : poissonSplitRowBody<W, T, NoiseAlignment::ACCOUNT_PRIOR, false>(
                           s, prior, col, k, scale, tails, means, zVar, tVar, cols);
    return prior ? poissonSplitRowBody<W, T, NoiseAlignment::IGNORE_PRIOR, true>(
                       s, prior, col, k, scale, tails, means, zVar, tVar, cols)
                 : poissonSplitRowBody<W, T, NoiseAlignment::IGNORE_PRIOR, false>(
                       s, prior, col, k, scale, tails, means, zVar, tVar, cols);
}

template <int W, typename T>
RAWGMENT_KERNEL void
poissonNoiseRowKernel(const T* s, T* d, const float* z, const float* t, const float* extra,
                      const JitterColumns& col, const JitterConstants& k, float q, const double* means,
                      const double* counts, const float* zVar, const float* tVar, int cols)
{
    int c = 0;
    for (; c + W <= cols; c += W)
        poissonNoiseBlock<W, T>(s, d, z, t, extra, col, c, k, q, means, counts, zVar, tVar);
    const int rest = cols - c;
    if (rest <= 0)
        return;
    T sPad[W] = {}, dPad[W];
    float zPad[W] = {}, tPad[W] = {}, extraPad[W] = {}, pcPad[W] = {}, blackPad[W] = {}, zVarPad[W] = {},
          tVarPad[W] = {};
    double meanPad[W] = {}, countPad[W] = {};
    for (int i = 0; i < rest; ++i) {
        sPad[i] = s[c + i];
        zPad[i] = z[c + i];
        tPad[i] = t ? t[c + i] : 0.0f;
        extraPad[i] = extra ? extra[c + i] : 0.0f;
        pcPad[i] = col.pc[c + i];
        blackPad[i] = col.black[c + i];
        zVarPad[i] = zVar[c + i];
        tVarPad[i] = tVar[c + i];
        meanPad[i] = means[c + i];
        countPad[i] = counts[c + i];
    }
    const JitterColumns padded = {pcPad, blackPad, nullptr, nullptr};
    poissonNoiseBlock<W, T>(sPad, dPad, zPad, t ? tPad : nullptr, extra ? extraPad : nullptr, padded, 0, k, q,
                            meanPad, countPad, zVarPad, tVarPad);
    for (int i = 0; i < rest; ++i)
        d[c + i] = dPad[i];
}

RAWGMENT_DISPATCHED_BY_WIDTH(int, poissonSplitRow,
                             (const ushort* s, const float* prior, const JitterColumns& col,
                              const JitterConstants& k, const PoissonScale& scale, bool tails, double* means,
                              float* zVar, float* tVar, int cols),
                             (s, prior, col, k, scale, tails, means, zVar, tVar, cols))
RAWGMENT_DISPATCHED_BY_WIDTH(int, poissonSplitRow,
                             (const float* s, const float* prior, const JitterColumns& col,
                              const JitterConstants& k, const PoissonScale& scale, bool tails, double* means,
                              float* zVar, float* tVar, int cols),
                             (s, prior, col, k, scale, tails, means, zVar, tVar, cols))
RAWGMENT_DISPATCHED_BY_WIDTH(void, poissonNoiseRow,
                             (const ushort* s, ushort* d, const float* z, const float* t, const float* extra,
                              const JitterColumns& col, const JitterConstants& k, float q,
                              const double* means, const double* counts, const float* zVar, const float* tVar,
                              int cols),
                             (s, d, z, t, extra, col, k, q, means, counts, zVar, tVar, cols))
RAWGMENT_DISPATCHED_BY_WIDTH(void, poissonNoiseRow,
                             (const float* s, float* d, const float* z, const float* t, const float* extra,
                              const JitterColumns& col, const JitterConstants& k, float q,
                              const double* means, const double* counts, const float* zVar, const float* tVar,
                              int cols),
                             (s, d, z, t, extra, col, k, q, means, counts, zVar, tVar, cols))

} // namespace

template <typename T>
int jitterRowPoisson(const T* s, T* d, const float* z, const float* t, const float* prior, const float* extra,
                     const JitterColumns& col, const JitterConstants& k, uint64_t key, uint64_t stream,
                     PoissonRowBuffers& rows, int cols)
{
    const PoissonScale scale(k.shotOut); // DN per electron at the output gain
    const size_t n = static_cast<size_t>(cols);
    rows.means.resize(n);
    rows.counts.resize(n);
    rows.zVar.resize(n);
    rows.tVar.resize(n);
    const int bright = poissonSplitRow(s, prior, col, k, scale, t != nullptr, rows.means.data(),
                                       rows.zVar.data(), rows.tVar.data(), cols);
    fillPoisson(key, stream, rows.means.data(), rows.counts.data(), cols);
    poissonNoiseRow(s, d, z, t, extra, col, k, scale.q, rows.means.data(), rows.counts.data(),
                    rows.zVar.data(), rows.tVar.data(), cols);
    return bright;
}

template int jitterRowPoisson<ushort>(const ushort*, ushort*, const float*, const float*, const float*,
                                      const float*, const JitterColumns&, const JitterConstants&, uint64_t,
                                      uint64_t, PoissonRowBuffers&, int);
template int jitterRowPoisson<float>(const float*, float*, const float*, const float*, const float*,
                                     const float*, const JitterColumns&, const JitterConstants&, uint64_t,
                                     uint64_t, PoissonRowBuffers&, int);

} // namespace detail
} // namespace rawgment
} // namespace cv
