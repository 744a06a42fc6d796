// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "random.hpp"

#include "cpu_dispatch.hpp"

#if RAWGMENT_HAVE_CPU_PATHS
#include <immintrin.h>
#endif

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
// [sqrt(1/2) - 1, sqrt(2) - 1].
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
    F y = f * 7.0376836292e-2f - 1.1514610310e-1f;
    y = y * f + 1.1676998740e-1f;
    y = y * f - 1.2420140846e-1f;
    y = y * f + 1.4249322787e-1f;
    y = y * f - 1.6668057665e-1f;
    y = y * f + 2.0000714765e-1f;
    y = y * f - 2.4999993993e-1f;
    y = y * f + 3.3333331174e-1f;
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

#if RAWGMENT_HAVE_CPU_PATHS
/* philox8Blocks() with x86 intrinsics: GCC multiplies generic 64-bit lanes with three 32-bit
 * multiplies and shifts below AVX-512, and with the slow vpmullq on it, although both factors fit 32
 * bits, which one (v)pmuludq multiplies exactly. The same integers as philox8Blocks(), so the
 * same bits. Plain calls, not inlined, so that the AVX2 version keeps its target. */
void philox8BlocksSse2(uint32_t firstBlock, uint64_t stream, const std::array<uint32_t, 2>& key,
                       uint32_t* words)
{
    // Eight blocks in four registers of two 64-bit lanes, each 32-bit word in a lane's low half.
    const __m128i low = _mm_set1_epi64x(0xffffffffLL), m0 = _mm_set1_epi64x(kPhiloxM0),
                  m1 = _mm_set1_epi64x(kPhiloxM1);
    __m128i c0[4], c1[4], c2[4], c3[4];
    for (int p = 0; p < 4; ++p) {
        c0[p] = _mm_set_epi64x(static_cast<uint32_t>(firstBlock + 2 * p + 1),
                               static_cast<uint32_t>(firstBlock + 2 * p));
        c1[p] = _mm_setzero_si128();
        c2[p] = _mm_set1_epi64x(static_cast<uint32_t>(stream));
        c3[p] = _mm_set1_epi64x(static_cast<uint32_t>(stream >> 32));
    }
    uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const __m128i kv0 = _mm_set1_epi64x(k0), kv1 = _mm_set1_epi64x(k1);
        for (int p = 0; p < 4; ++p) {
            const __m128i p0 = _mm_mul_epu32(c0[p], m0), p1 = _mm_mul_epu32(c2[p], m1);
            c0[p] = _mm_xor_si128(_mm_xor_si128(_mm_srli_epi64(p1, 32), c1[p]), kv0);
            c2[p] = _mm_xor_si128(_mm_xor_si128(_mm_srli_epi64(p0, 32), c3[p]), kv1);
            c1[p] = _mm_and_si128(p1, low);
            c3[p] = _mm_and_si128(p0, low);
        }
        k0 += kPhiloxW0;
        k1 += kPhiloxW1;
    }
    const __m128i* const state[4] = {c0, c1, c2, c3};
    for (int j = 0; j < 4; ++j)
        for (int p = 0; p < 4; ++p) {
            // The low halves of the two lanes, side by side.
            const __m128i packed = _mm_shuffle_epi32(state[j][p], _MM_SHUFFLE(3, 1, 2, 0));
            _mm_storel_epi64(reinterpret_cast<__m128i*>(words + 8 * j + 2 * p), packed);
        }
}

__attribute__((target("arch=x86-64-v3"))) void
philox8BlocksAvx2(uint32_t firstBlock, uint64_t stream, const std::array<uint32_t, 2>& key, uint32_t* words)
{
    // Eight blocks in two registers of four 64-bit lanes, each 32-bit word in a lane's low half.
    const __m256i low = _mm256_set1_epi64x(0xffffffffLL), m0 = _mm256_set1_epi64x(kPhiloxM0),
                  m1 = _mm256_set1_epi64x(kPhiloxM1);
    __m256i c0[2], c1[2], c2[2], c3[2];
    for (int p = 0; p < 2; ++p) {
        const uint32_t b = firstBlock + 4 * p;
        c0[p] = _mm256_set_epi64x(static_cast<uint32_t>(b + 3), static_cast<uint32_t>(b + 2),
                                  static_cast<uint32_t>(b + 1), static_cast<uint32_t>(b));
        c1[p] = _mm256_setzero_si256();
        c2[p] = _mm256_set1_epi64x(static_cast<uint32_t>(stream));
        c3[p] = _mm256_set1_epi64x(static_cast<uint32_t>(stream >> 32));
    }
    uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const __m256i kv0 = _mm256_set1_epi64x(k0), kv1 = _mm256_set1_epi64x(k1);
        for (int p = 0; p < 2; ++p) {
            const __m256i p0 = _mm256_mul_epu32(c0[p], m0), p1 = _mm256_mul_epu32(c2[p], m1);
            c0[p] = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(p1, 32), c1[p]), kv0);
            c2[p] = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(p0, 32), c3[p]), kv1);
            c1[p] = _mm256_and_si256(p1, low);
            c3[p] = _mm256_and_si256(p0, low);
        }
        k0 += kPhiloxW0;
        k1 += kPhiloxW1;
    }
    // The low halves of the eight lanes of a word, in block order.
    const __m256i gather = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    const __m256i* const state[4] = {c0, c1, c2, c3};
    for (int j = 0; j < 4; ++j) {
        const __m128i lo = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(state[j][0], gather));
        const __m128i hi = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(state[j][1], gather));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(words + 8 * j), lo);
        _mm_storeu_si128(reinterpret_cast<__m128i*>(words + 8 * j + 4), hi);
    }
}

// GCC 12's avx512fintrin.h warns that _mm512_mul_epu32's masked builtin reads an uninitialised
// pass-through operand, which the full mask never uses.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
__attribute__((target("arch=x86-64-v4"))) void
philox8BlocksAvx512(uint32_t firstBlock, uint64_t stream, const std::array<uint32_t, 2>& key, uint32_t* words)
{
    // Eight blocks in one register of eight 64-bit lanes; vpmuludq, not AVX-512's slower vpmullq.
    const __m512i low = _mm512_set1_epi64(0xffffffffLL), m0 = _mm512_set1_epi64(kPhiloxM0),
                  m1 = _mm512_set1_epi64(kPhiloxM1);
    __m512i c0 = _mm512_and_si512(
                _mm512_add_epi64(_mm512_set1_epi64(firstBlock), _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7)),
                low),
            c1 = _mm512_setzero_si512(), c2 = _mm512_set1_epi64(static_cast<uint32_t>(stream)),
            c3 = _mm512_set1_epi64(static_cast<uint32_t>(stream >> 32));
    uint32_t k0 = key[0], k1 = key[1];
    for (int round = 0; round < kPhiloxRounds; ++round) {
        const __m512i p0 = _mm512_mul_epu32(c0, m0), p1 = _mm512_mul_epu32(c2, m1);
        c0 = _mm512_xor_si512(_mm512_xor_si512(_mm512_srli_epi64(p1, 32), c1), _mm512_set1_epi64(k0));
        c2 = _mm512_xor_si512(_mm512_xor_si512(_mm512_srli_epi64(p0, 32), c3), _mm512_set1_epi64(k1));
        c1 = _mm512_and_si512(p1, low);
        c3 = _mm512_and_si512(p0, low);
        k0 += kPhiloxW0;
        k1 += kPhiloxW1;
    }
    const __m512i state[4] = {c0, c1, c2, c3};
    for (int j = 0; j < 4; ++j)
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(words + 8 * j), _mm512_cvtepi64_epi32(state[j]));
}
#pragma GCC diagnostic pop
#endif

//! Eight Philox blocks by the fastest exact means of a path of width W.
template <int W>
RAWGMENT_KERNEL void philox8BlocksFor(uint32_t firstBlock, uint64_t stream,
                                      const std::array<uint32_t, 2>& key, uint32_t* words)
{
#if RAWGMENT_HAVE_CPU_PATHS
    if (W == 4)
        return philox8BlocksSse2(firstBlock, stream, key, words);
    if (W == 8)
        return philox8BlocksAvx2(firstBlock, stream, key, words);
    if (W == 16)
        return philox8BlocksAvx512(firstBlock, stream, key, words);
#endif
    philox8Blocks(firstBlock, stream, key, words);
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

} // namespace

RAWGMENT_DISPATCHED_BY_WIDTH(void, fillGaussian, (uint64_t seed, uint64_t stream, float* out, int n),
                             (seed, stream, out, n))

} // namespace detail
} // namespace rawgment
} // namespace cv
