// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "random.hpp"

#include "cpu_dispatch.hpp"

#include <algorithm>
#include <cstring>
#include <limits>

namespace cv {
namespace rawgment {
namespace detail {

double logFactorial(int64_t k)
{
    static const std::array<double, 32> table = [] {
        std::array<double, 32> t{};
        double sum = 0;
        for (int i = 1; i < 32; ++i) {
            sum += std::log(static_cast<double>(i));
            t[i] = sum;
        }
        return t;
    }();
    if (k < 32)
        return table[static_cast<size_t>(k)];
    const double x = static_cast<double>(k), inv = 1.0 / x, inv2 = inv * inv;
    return x * std::log(x) - x + 0.5 * std::log(2.0 * CV_PI * x) +
           inv * (1.0 / 12 - inv2 * (1.0 / 360 - inv2 / 1260));
}

int64_t CounterRng::poisson(double lambda)
{
    if (!(lambda > 0))
        return 0;
    CV_Assert(lambda <= kMaxPoissonMean);
    if (lambda < 10) {
        // Inversion by sequential search over the CDF; the tail beyond 200 has mass below 1e-200.
        const double u = uniform();
        double p = std::exp(-lambda), cdf = p;
        int64_t k = 0;
        while (u > cdf && k < 200) {
            ++k;
            p *= lambda / static_cast<double>(k);
            cdf += p;
        }
        return k;
    }
    const double sqrtLambda = std::sqrt(lambda), logLambda = std::log(lambda);
    const double b = 0.931 + 2.53 * sqrtLambda;
    const double a = -0.059 + 0.02483 * b;
    const double invAlpha = 1.1239 + 1.1328 / (b - 3.4);
    const double vr = 0.9277 - 3.6224 / (b - 2);
    for (;;) {
        const double u = uniform() - 0.5;
        const double v = uniform();
        const double us = 0.5 - std::abs(u);
        const double kd = std::floor((2 * a / us + b) * u + lambda + 0.43);
        if (us >= 0.07 && v <= vr)
            return static_cast<int64_t>(kd);
        if (kd < 0 || (us < 0.013 && v > us))
            continue;
        const int64_t k = static_cast<int64_t>(kd);
        if (std::log(v) + std::log(invAlpha) - std::log(a / (us * us) + b) <=
            -lambda + kd * logLambda - logFactorial(k))
            return k;
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
    const F f = (small ? m + m : m) - 1.0f;
    const F z = f * f;
    const F z2 = z * z;
    const F p01 = f * -2.4999993993e-1f + 3.3333331174e-1f;
    const F p23 = f * -1.6668057665e-1f + 2.0000714765e-1f;
    const F p45 = f * -1.2420140846e-1f + 1.4249322787e-1f;
    const F p67 = f * -1.1514610310e-1f + 1.1676998740e-1f;
    const F p8 = z2 * z2 * 7.0376836292e-2f;
    F y = (p01 + z * p23) + z2 * (p45 + z * p67) + p8;
    y = y * f * z - 0.5f * z + f;
    return y + __builtin_convertvector(e, F) * 0.693147180559945f;
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
    const F u1 = (__builtin_convertvector((I)(w1 >> 8), F) + 1.0f) * (1.0f / 16777216.0f);
    const F radius = sqrtLanes(-2.0f * logPositiveLanes<W>(u1));
    const I q = (I)(w2 >> 30);
    const F phi =
        (__builtin_convertvector((I)((w2 >> 8) & 0x3fffff), F) * (1.0f / 4194304.0f) - 0.5f) * 1.5707963268f;
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
    const F cosRot = (F)((I)(odd ? s : c) ^ cosSign);
    const F sinRot = (F)((I)(odd ? c : s) ^ sinSign);
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
    const I scale = (__builtin_convertvector(n, I) + 127) << 23;
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
    const F series =
        l *
        (1.0f + x * (0.5f + x * (1.6666667e-1f +
                                 x * (4.1666667e-2f +
                                      x * (8.3333333e-3f +
                                           x * (1.3888889e-3f + x * (1.9841270e-4f + x * 2.4801587e-5f)))))));
    const I large = detail::maxLanes(x, -x) >= 0.5f;
    int anyLarge = 0;
    for (int i = 0; i < W; ++i)
        anyLarge |= large[i];
    if (!anyLarge)
        return series;
    const F direct = (expLanes<W>(x) - 1.0f) / safeLambda;
    return large ? direct : series;
}

/* n unit-variance Tukey-lambda values from the stream, two Philox words each: the sign from the top bit
 * of the first, u in (0, 1/2) from its other 31 bits and 24 of the second (u down to 2^-57, so the
 * tails reach as far as a double uniform's), then the quantile Q(u) = (u^lambda - (1 - u)^lambda) /
 * lambda with the symmetry Q(1 - u) = -Q(u). Even columns take lambda0, odd columns lambda1 (the two
 * CFA sites of a row). */
template <int W>
RAWGMENT_KERNEL void fillTukeyUnitKernel(uint64_t seed, uint64_t stream, float lambda0, float invSd0,
                                         float lambda1, float invSd1, float* out, int n)
{
    typedef typename Lanes<W>::F F;
    typedef typename Lanes<W>::I I;
    typedef typename Lanes<W>::U U;
    const int kChunk = 16; // values per 8 Philox blocks: 16 first words, then 16 second words
    alignas(64) uint32_t words[32];
    alignas(64) float chunk[kChunk];
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    F lambda, invSd;
    for (int i = 0; i < W; ++i) {
        lambda[i] = (i & 1) ? lambda1 : lambda0;
        invSd[i] = (i & 1) ? invSd1 : invSd0;
    }
    const F safeLambda = lambda == 0.0f ? F{} + 1.0f : lambda;
    for (int base = 0; base < n; base += kChunk) {
        philox8BlocksFor<W>(static_cast<uint32_t>(base / 2), stream, key, words);
        float* const dst = n - base >= kChunk ? out + base : chunk;
        for (int h = 0; h < kChunk; h += W) {
            U w1, w2;
            std::memcpy(&w1, words + h, sizeof(w1));
            std::memcpy(&w2, words + kChunk + h, sizeof(w2));
            const F hi = __builtin_convertvector((I)(w1 & 0x7fffffffu), F);
            const F lo = (__builtin_convertvector((I)(w2 >> 8), F) + 0.5f) * (1.0f / 16777216.0f);
            const F u = (hi + lo) * (1.0f / 4294967296.0f);
            const F q = tukeyTermLanes<W>(logPositiveLanes<W>(u), lambda, safeLambda) -
                        tukeyTermLanes<W>(logPositiveLanes<W>(1.0f - u), lambda, safeLambda);
            const I negative = (I)(w1 >> 31) != 0;
            const F v = invSd * (negative ? -q : q);
            std::memcpy(dst + h, &v, sizeof(v));
        }
        if (dst == chunk)
            std::memcpy(out + base, chunk, sizeof(float) * static_cast<size_t>(n - base));
    }
}

} // namespace

RAWGMENT_DISPATCHED_BY_WIDTH(void, fillGaussian, (uint64_t seed, uint64_t stream, float* out, int n),
                             (seed, stream, out, n))
RAWGMENT_DISPATCHED_BY_WIDTH(void, fillTukeyUnit,
                             (uint64_t seed, uint64_t stream, float lambda0, float invSd0, float lambda1,
                              float invSd1, float* out, int n),
                             (seed, stream, lambda0, invSd0, lambda1, invSd1, out, n))

} // namespace detail
} // namespace rawgment
} // namespace cv
