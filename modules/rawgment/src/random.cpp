// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The float-lane draws of random.hpp: Gaussian normals by Box-Muller and Tukey-lambda values by their
// quantile tables. The double-lane Poisson counts are in random_poisson.cpp.
#include "random.hpp"

#include "cpu_dispatch.hpp"
#include "noise_terms.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace cv {
namespace rawgment {
namespace detail {
/* The nodes of every table (TukeyQuantileTable): ln u and ln(1 - u) at the four Chebyshev nodes of each
 * cell, which do not depend on the shape, computed once. */
struct TukeyTableNodes
{
    std::vector<double> logU, log1mU, x;
    TukeyTableNodes()
    {
        const int cells = TukeyQuantileTable::kCells - 1;
        logU.resize(4 * static_cast<size_t>(cells));
        log1mU.resize(logU.size());
        for (int k = 0; k < 4; ++k)
            x.push_back(-0.5 * std::cos((2 * k + 1) * CV_PI / 8));
        for (int c = 0; c < cells; ++c) {
            const int octave = c / TukeyQuantileTable::kCellsPerOctave,
                      j = c % TukeyQuantileTable::kCellsPerOctave;
            const double scale = std::ldexp(1.0, TukeyQuantileTable::kLowestExponent - 127 + octave);
            const double width = scale / TukeyQuantileTable::kCellsPerOctave;
            for (int k = 0; k < 4; ++k) {
                const double u = scale + width * (j + 0.5 + x[static_cast<size_t>(k)]);
                logU[4 * static_cast<size_t>(c) + k] = std::log(u);
                log1mU[4 * static_cast<size_t>(c) + k] = std::log1p(-u);
            }
        }
    }
};

TukeyQuantileTable::TukeyQuantileTable(float lambda0, float invSd0, float lambda1, float invSd1)
    : lambda{lambda0, lambda1}, invSd{invSd0, invSd1}
{
    for (int s = 0; s < 2; ++s)
        if (!(lambda[s] >= static_cast<float>(kTukeyLambdaMin) && lambda[s] <= 1) ||
            !(invSd[s] > 0 && std::isfinite(invSd[s])))
            CV_Error(Error::StsBadArg,
                     format("a Tukey-lambda table needs lambda in [%g, 1] and a finite positive 1 / sd (got "
                            "lambda %g, 1 / sd %g)",
                            kTukeyLambdaMin, static_cast<double>(lambda[s]), static_cast<double>(invSd[s])));
    static const TukeyTableNodes nodes;
    coefficients_.assign(static_cast<size_t>(8 * kCells), 0.0f); // the cell of u = 1/2 stays 0
    for (int s = 0; s < 2; ++s) {
        float* const site = coefficients_.data() + 4 * static_cast<size_t>(s * kCells);
        if (s == 1 && lambda[1] == lambda[0] && invSd[1] == invSd[0]) {
            std::copy(coefficients_.begin(), coefficients_.begin() + 4 * kCells, site);
            break;
        }
        const double l = lambda[s], scale = invSd[s];
        for (int c = 0; c + 1 < kCells; ++c) {
            // The quantile at the nodes, then Newton's divided differences, then the monomial coefficients.
            double y[4], p[4] = {0, 0, 0, 0};
            for (int k = 0; k < 4; ++k) {
                const double a = nodes.logU[4 * static_cast<size_t>(c) + k],
                             b = nodes.log1mU[4 * static_cast<size_t>(c) + k];
                y[k] = scale * (l == 0 ? a - b : (std::expm1(l * a) - std::expm1(l * b)) / l);
            }
            const double* x = nodes.x.data();
            for (int k = 1; k < 4; ++k)
                for (int m = 3; m >= k; --m)
                    y[m] = (y[m] - y[m - 1]) / (x[m] - x[m - k]);
            p[0] = y[3];
            for (int k = 2; k >= 0; --k) { // p = p (x - x_k) + y_k
                for (int m = 3; m >= 1; --m)
                    p[m] = p[m - 1] - x[k] * p[m];
                p[0] = y[k] - x[k] * p[0];
            }
            for (int m = 0; m < 4; ++m)
                site[4 * c + m] = static_cast<float>(p[m]);
        }
    }
}

namespace {

// The transform of Philox words into normals, W lanes at a time, W the native width of the path
// (cpu_dispatch.hpp: 16 for AVX-512, 8 for AVX2, 4 below): every operation, the logarithm, the square
// root and the sine and cosine polynomials included, is a vector operation at full width, and each
// lane does the same operations on every path, so all give the same bits.

// ln(x) for x in (0, 1]: exponent and mantissa split, then the Cephes polynomial for ln(1 + f) on
// [sqrt(1/2) - 1, sqrt(2) - 1], evaluated by Estrin's scheme (pairs of terms, then pairs of pairs): a
// dependency chain of 4 multiply-adds instead of Horner's 9. On Zen 3 (AVX2) the out-of-order core could
// not hide Horner's chain, and this cut the normals' time by about a tenth.
template <int W> RAWGMENT_KERNEL typename Lanes<W>::F logPositiveLanes(typename Lanes<W>::F x)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    const I bits = (I)x;
    I e = ((bits >> 23) & 0xff) - 126;
    const I mantissaBits = (bits & 0x007fffff) | 0x3f000000; // mantissa in [0.5, 1)
    const F m = (F)mantissaBits;
    const I small = m < 0.70710678f; // -1 where true
    e += small;
    const F f = selectLanes(small, m + m, m) - 1.0f;
    const F z = f * f;
    const F z2 = z * z;
    const F p01 = f * -2.4999993993e-1f + 3.3333331174e-1f;
    const F p23 = f * -1.6668057665e-1f + 2.0000714765e-1f;
    const F p45 = f * -1.2420140846e-1f + 1.4249322787e-1f;
    const F p67 = f * -1.1514610310e-1f + 1.1676998740e-1f;
    const F p8 = z2 * z2 * 7.0376836292e-2f;
    F y = (p01 + z * p23) + z2 * (p45 + z * p67) + p8;
    y = y * f * z - 0.5f * z + f;
    return y + convertLanes<F>(e) * 0.693147180559945f;
}

/* W Box-Muller pairs from W words for the radius (w1) and W for the angle (w2). u1 in (0, 1] from 24
 * bits (never 0: the logarithm is finite), through int32 (x86 before AVX-512 has no vector
 * uint32 -> float). The angle: quadrant from the top 2 bits of w2, phi in [-pi/4, pi/4) from the next
 * 22; any uniform angle serves Box-Muller, and this one needs only the short polynomials of
 * |phi| <= pi/4. */
template <int W>
RAWGMENT_KERNEL void boxMullerLanes(const uint32_t* radiusWords, const uint32_t* angleWords, float* cosOut,
                                    float* sinOut)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    typedef typename Lanes<W>::U U;
    U w1, w2;
    std::memcpy(&w1, radiusWords, sizeof(w1));
    std::memcpy(&w2, angleWords, sizeof(w2));
    const F u1 = (convertLanes<F>((I)(w1 >> 8)) + 1.0f) * (1.0f / 16777216.0f);
    const F radius = sqrtLanes(-2.0f * logPositiveLanes<W>(u1));
    const I q = (I)(w2 >> 30);
    const F phi = (convertLanes<F>((I)((w2 >> 8) & 0x3fffff)) * (1.0f / 4194304.0f) - 0.5f) * 1.5707963268f;
    const F p2 = phi * phi;
    const F s = phi + phi * p2 * (-1.6666654611e-1f + p2 * (8.3321608736e-3f + p2 * -1.9515295891e-4f));
    const F c =
        1.0f - 0.5f * p2 +
        p2 * p2 * (4.166664568298827e-2f + p2 * (-1.388731625493765e-3f + p2 * 2.443315711809948e-5f));
    // Rotate (c, s) by q quarter turns: (c, s), (-s, c), (-c, -s), (s, -c): swap on odd q, then flip
    // the sign bits (q 1 and 2 negate the cosine, q 2 and 3 the sine), exactly as multiplying by -1.
    const I odd = (q & 1) != 0;
    const I signBit = I{} + std::numeric_limits<int32_t>::min();
    const I cosSign = ((q == 1) | (q == 2)) & signBit;
    const I sinSign = (q >= 2) & signBit;
    const F cosRot = (F)((I)selectLanes(odd, s, c) ^ cosSign);
    const F sinRot = (F)((I)selectLanes(odd, c, s) ^ sinSign);
    const F zc = radius * cosRot, zs = radius * sinRot;
    std::memcpy(cosOut, &zc, sizeof(zc));
    std::memcpy(sinOut, &zs, sizeof(zs));
}

template <int W> RAWGMENT_KERNEL void fillGaussianKernel(uint64_t seed, uint64_t stream, float* out, int n)
{
    // 64 values per chunk: 16 Philox blocks (two groups of 8), 32 Box-Muller pairs: the first 32 words
    // give the radii, the last 32 the angles; the cosines fill z[0..32), the sines z[32..64).
    const int kChunk = 64, kPairs = kChunk / 2;
    alignas(64) uint32_t words[kChunk];
    alignas(64) float z[kChunk];
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    for (int base = 0; base < n; base += kChunk) {
        const uint32_t block0 = static_cast<uint32_t>(base / 4);
        philox8BlocksFor<W>(block0, stream, key, words);
        philox8BlocksFor<W>(block0 + 8, stream, key, words + 32);
        // Whole chunks go straight to the output; the last partial one through z.
        float* const dst = n - base >= kChunk ? out + base : z;
        for (int h = 0; h < kPairs; h += W)
            boxMullerLanes<W>(words + h, words + kPairs + h, dst + h, dst + kPairs + h);
        if (dst == z)
            std::memcpy(out + base, z, sizeof(float) * static_cast<size_t>(n - base));
    }
}

/* e^x for x in [-80, 80]: n = x log2(e) rounded to nearest (the 1.5 * 2^23 trick, exact in float), the
 * remainder r = x - n ln 2 in two parts (Cody and Waite), Cephes' polynomial for e^r on |r| <= ln(2) / 2,
 * then 2^n through the exponent bits. About 1 float ulp. */
template <int W> RAWGMENT_KERNEL typename Lanes<W>::F expLanes(typename Lanes<W>::F x)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    const F shifter = F{} + 12582912.0f;
    const F n = (x * 1.44269504088896341f + shifter) - shifter;
    const F r = (x - n * 0.693359375f) - n * -2.12194440e-4f;
    const F r2 = r * r;
    const F p =
        ((((1.9875691500e-4f * r + 1.3981999507e-3f) * r + 8.3334519073e-3f) * r + 4.1665795894e-2f) * r +
         1.6666665459e-1f) *
            r +
        5.0000001201e-1f;
    const F er = p * r2 + r + 1.0f;
    const I scale = (convertLanes<I>(n) + 127) << 23;
    return er * (F)scale;
}

/* (e^(lambda l) - 1) / lambda, the term of a Tukey-lambda quantile, for l = ln(u) <= 0: for |lambda l| < 1/2
 * l (1 + x/2 + ... + x^7/8!) with x = lambda l (truncation below 1e-8 relative, and exactly l when lambda
 * is 0, the logistic limit), else (e^x - 1) / lambda, where no cancellation remains. The exponential is
 * computed only for a vector that has such a lane (a few in a hundred for the tails of sensors); the
 * choice is per lane either way, so the bits do not depend on the width. */
template <int W>
RAWGMENT_KERNEL typename Lanes<W>::F tukeyTermLanes(typename Lanes<W>::F l, typename Lanes<W>::F lambda,
                                                    typename Lanes<W>::F safeLambda)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    const F x = lambda * l;
    // 1 + x/2! + ... + x^7/8! by Estrin's scheme: a dependency chain of 3 multiply-adds, not Horner's 7
    // (the quantile's two series were the latency that bounded the fill).
    const F x2 = x * x, x4 = x2 * x2;
    const F c01 = 1.0f + x * 0.5f, c23 = 1.6666667e-1f + x * 4.1666667e-2f;
    const F c45 = 8.3333333e-3f + x * 1.3888889e-3f, c67 = 1.9841270e-4f + x * 2.4801587e-5f;
    const F series = l * ((c01 + x2 * c23) + x4 * (c45 + x2 * c67));
    const I large = detail::maxLanes(x, -x) >= 0.5f;
    if (!maskBits(large))
        return series;
    const F direct = (expLanes<W>(x) - 1.0f) / safeLambda;
    return selectLanes(large, direct, series);
}

/* W unit-variance Tukey-lambda values from W pairs of words: the sign from the top bit of the first, u in
 * (0, 1/2) from its other 31 bits m plus 24 bits of the second as a fraction of m's last place, in float,
 * then the quantile Q(u) = (u^lambda - (1 - u)^lambda) / lambda with the symmetry Q(1 - u) = -Q(u). */
template <int W>
RAWGMENT_KERNEL typename Lanes<W>::F tukeyValuesLanes(typename Lanes<W>::U w1, typename Lanes<W>::U w2,
                                                      typename Lanes<W>::F lambda, typename Lanes<W>::F invSd,
                                                      typename Lanes<W>::F safeLambda)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    const F hi = convertLanes<F>((I)(w1 & 0x7fffffffu));
    const F lo = (convertLanes<F>((I)(w2 >> 8)) + 0.5f) * (1.0f / 16777216.0f);
    const F u = (hi + lo) * (1.0f / 4294967296.0f);
    const F q = tukeyTermLanes<W>(logPositiveLanes<W>(u), lambda, safeLambda) -
                tukeyTermLanes<W>(logPositiveLanes<W>(1.0f - u), lambda, safeLambda);
    const I negative = (I)(w1 >> 31) != 0;
    return invSd * selectLanes(negative, -q, q);
}

/* Lane i of c0..c3 from the four floats at table + offset[i]: 16-byte loads transposed in registers (a
 * gather would load each float on its own). Target v3, so that the AVX2 and AVX-512 paths inline it; not
 * always_inline, which GCC would also try in loadCells<8>'s baseline instance. */
#if RAWGMENT_HAVE_CPU_PATHS
__attribute__((target("arch=x86-64-v3"))) inline void
loadCells8(const float* table, const int32_t* offset, __m256& c0, __m256& c1, __m256& c2, __m256& c3)
{
    // Cells i and i + 4 in the low and high halves, so that the transpose leaves lane i in place.
    const __m256 a0 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(table + offset[0])),
                                           _mm_loadu_ps(table + offset[4]), 1);
    const __m256 a1 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(table + offset[1])),
                                           _mm_loadu_ps(table + offset[5]), 1);
    const __m256 a2 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(table + offset[2])),
                                           _mm_loadu_ps(table + offset[6]), 1);
    const __m256 a3 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(table + offset[3])),
                                           _mm_loadu_ps(table + offset[7]), 1);
    const __m256 lo01 = _mm256_unpacklo_ps(a0, a1), lo23 = _mm256_unpacklo_ps(a2, a3);
    const __m256 hi01 = _mm256_unpackhi_ps(a0, a1), hi23 = _mm256_unpackhi_ps(a2, a3);
    c0 = _mm256_shuffle_ps(lo01, lo23, 0x44);
    c1 = _mm256_shuffle_ps(lo01, lo23, 0xee);
    c2 = _mm256_shuffle_ps(hi01, hi23, 0x44);
    c3 = _mm256_shuffle_ps(hi01, hi23, 0xee);
}
#endif

template <int W>
RAWGMENT_KERNEL void loadCells(const float* table, typename Lanes<W>::I offsets, typename Lanes<W>::F& c0,
                               typename Lanes<W>::F& c1, typename Lanes<W>::F& c2, typename Lanes<W>::F& c3)
{
    typedef typename Lanes<W>::F F;
    alignas(64) int32_t offset[W];
    std::memcpy(offset, &offsets, sizeof(offsets));
#if RAWGMENT_HAVE_CPU_PATHS
    if constexpr (W == 4) {
        __m128 r0 = _mm_loadu_ps(table + offset[0]), r1 = _mm_loadu_ps(table + offset[1]),
               r2 = _mm_loadu_ps(table + offset[2]), r3 = _mm_loadu_ps(table + offset[3]);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        c0 = (F)r0;
        c1 = (F)r1;
        c2 = (F)r2;
        c3 = (F)r3;
        return;
    }
    if constexpr (W == 8) {
        __m256 r0, r1, r2, r3;
        loadCells8(table, offset, r0, r1, r2, r3);
        c0 = (F)r0;
        c1 = (F)r1;
        c2 = (F)r2;
        c3 = (F)r3;
        return;
    }
#endif
    for (int i = 0; i < W; ++i) {
        c0[i] = table[offset[i]];
        c1[i] = table[offset[i] + 1];
        c2[i] = table[offset[i] + 2];
        c3[i] = table[offset[i] + 3];
    }
}

/* W unit-variance Tukey-lambda values from W words by the table's cubics (TukeyQuantileTable): u = m 2^-32
 * from the word's 31 bits m, exact in float from m = 2^24 up (the float rounds m, as tukeyValuesLanes()
 * does); float's exponent and top 5 mantissa bits of m pick the cell, its other 18 bits the position in
 * it. A value below (m < 2^24) gets the lowest cell here, and its refinement later. */
template <int W>
RAWGMENT_KERNEL typename Lanes<W>::F tukeyTableLanes(typename Lanes<W>::U w, const float* table,
                                                     typename Lanes<W>::I siteOffset)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    constexpr int kPositionBits = 23 - 5; // TukeyQuantileTable::kCellsPerOctave = 2^5
    static_assert(TukeyQuantileTable::kCellsPerOctave == 1 << (23 - kPositionBits), "cells per octave");
    // m 2^-32 has the exponent of m less 32: the cell of u from the bits of m as a float.
    constexpr int kFirstCell = (TukeyQuantileTable::kLowestExponent + 32) << (23 - kPositionBits);
    const F m = convertLanes<F>((I)(w & 0x7fffffffu));
    const I bits = (I)m;
    const I cell = detail::maxLanes((bits >> kPositionBits) - kFirstCell, I{});
    const F x = convertLanes<F>(bits & ((1 << kPositionBits) - 1)) * (1.0f / (1 << kPositionBits)) - 0.5f;
    F c0, c1, c2, c3;
    loadCells<W>(table, cell * 4 + siteOffset, c0, c1, c2, c3);
    const F q = c0 + x * (c1 + x * (c2 + x * c3));
    const I negative = (I)(w >> 31) != 0;
    return selectLanes(negative, -q, q);
}

/* n unit-variance Tukey-lambda values from the stream, one Philox word each (value h of a chunk of 32 takes
 * word h of its 8 blocks), by the table's cubics (tukeyTableLanes()). Where m, the word's 31 bits of u, is
 * below 2^24 (u < 2^-8, a share 2^-7), the second word is the first of the value's own stream
 * (tukeyRefineKey(seed, stream), index), so u reaches 2^-57 and the tails are drawn as far as a double
 * uniform's would be; such a value is the quantile computed by tukeyValuesLanes(). Even columns take the
 * table's first shape, odd columns its second (the two CFA sites of a row). */
template <int W>
RAWGMENT_KERNEL void fillTukeyUnitKernel(uint64_t seed, uint64_t stream, const TukeyQuantileTable& table,
                                         float* out, int n)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    typedef typename Lanes<W>::U U;
    CV_Assert(!table.empty());
    const int kChunk = 32; // values per 8 Philox blocks
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    I siteOffset;
    for (int i = 0; i < W; ++i)
        siteOffset[i] = (i & 1) * 4 * TukeyQuantileTable::kCells;
    const float* const coefficients = table.coefficients();
    const U fine = U{} + (1u << 24);
    // Two chunks per step: their words first, then their values. The values to refine, and their words,
    // are kept for the end.
    const int kStep = 2 * kChunk;
    alignas(64) uint32_t stepWords[kStep];
    alignas(64) float stepValues[kStep];
    std::vector<int> refine;
    std::vector<uint32_t> refineWords;
    refine.reserve(static_cast<size_t>(n / 64 + 16)); // a share 2^-7, and its spread
    refineWords.reserve(static_cast<size_t>(n / 64 + 16));
    for (int base = 0; base < n; base += kStep) {
        philox8BlocksFor<W>(static_cast<uint32_t>(base / 4), stream, key, stepWords);
        philox8BlocksFor<W>(static_cast<uint32_t>(base / 4 + 8), stream, key, stepWords + kChunk);
        float* const dst = n - base >= kStep ? out + base : stepValues;
        for (int h = 0; h < kStep; h += W) {
            U w1;
            std::memcpy(&w1, stepWords + h, sizeof(w1));
            const F v = tukeyTableLanes<W>(w1, coefficients, siteOffset);
            std::memcpy(dst + h, &v, sizeof(v));
            if (int coarse = maskBits((w1 & 0x7fffffffu) < fine))
                for (; coarse; coarse &= coarse - 1) {
                    const int lane = lowestSetBit(static_cast<unsigned>(coarse));
                    if (base + h + lane < n) {
                        refine.push_back(base + h + lane);
                        refineWords.push_back(stepWords[h + lane]);
                    }
                }
        }
        if (dst == stepValues)
            std::memcpy(out + base, stepValues, sizeof(float) * static_cast<size_t>(n - base));
    }
    if (refine.empty())
        return;
    // The refined values, eight streams' first words at a time, in lanes.
    const uint64_t refineKey = tukeyRefineKey(seed, stream);
    const std::array<uint32_t, 2> refineWordsKey = {static_cast<uint32_t>(refineKey),
                                                    static_cast<uint32_t>(refineKey >> 32)};
    const int count = static_cast<int>(refine.size());
    for (int start = 0; start < count; start += 8) {
        const int live = std::min(8, count - start);
        alignas(64) uint64_t streams[8];
        alignas(64) uint32_t blockWords[32];
        alignas(64) uint32_t firsts[16] = {}, seconds[16] = {};
        alignas(64) float lambdas[16], invSds[16], values[16];
        for (int i = 0; i < 16; ++i) {
            const int index = i < live ? refine[static_cast<size_t>(start + i)] : 0;
            if (i < 8)
                streams[i] = static_cast<uint64_t>(index);
            lambdas[i] = table.lambda[index & 1];
            invSds[i] = table.invSd[index & 1];
            if (i < live)
                firsts[i] = refineWords[static_cast<size_t>(start + i)];
        }
        philox8StreamsFor<W>(0, streams, refineWordsKey, blockWords);
        for (int i = 0; i < live; ++i)
            seconds[i] = blockWords[i];
        for (int h = 0; h < 8; h += W) {
            U w1, w2;
            F l, sd;
            std::memcpy(&w1, firsts + h, sizeof(w1));
            std::memcpy(&w2, seconds + h, sizeof(w2));
            std::memcpy(&l, lambdas + h, sizeof(l));
            std::memcpy(&sd, invSds + h, sizeof(sd));
            const F v = tukeyValuesLanes<W>(w1, w2, l, sd, selectLanes(l == 0.0f, F{} + 1.0f, l));
            std::memcpy(values + h, &v, sizeof(v));
        }
        for (int i = 0; i < live; ++i)
            out[refine[static_cast<size_t>(start + i)]] = values[i];
    }
}

} // namespace

RAWGMENT_DISPATCHED_BY_WIDTH(void, fillGaussian, (uint64_t seed, uint64_t stream, float* out, int n),
                             (seed, stream, out, n))
RAWGMENT_DISPATCHED_BY_WIDTH(void, fillTukeyUnit,
                             (uint64_t seed, uint64_t stream, const TukeyQuantileTable& table, float* out,
                              int n),
                             (seed, stream, table, out, n))

} // namespace detail
} // namespace rawgment
} // namespace cv
