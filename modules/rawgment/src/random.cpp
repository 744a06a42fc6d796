// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "random.hpp"

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

// ln(x) for x in (0, 1], float32: exponent and mantissa split, then the Cephes polynomial for
// ln(1 + f) on [sqrt(1/2) - 1, sqrt(2) - 1].
inline float logPositive(float x)
{
    int32_t bits;
    std::memcpy(&bits, &x, sizeof(bits));
    int32_t e = ((bits >> 23) & 0xff) - 126;
    bits = (bits & 0x007fffff) | 0x3f000000; // mantissa in [0.5, 1)
    float m;
    std::memcpy(&m, &bits, sizeof(m));
    const bool small = m < 0.70710678f;
    e -= small ? 1 : 0;
    const float f = (small ? m + m : m) - 1.0f;
    const float z = f * f;
    float y = 7.0376836292e-2f;
    y = y * f - 1.1514610310e-1f;
    y = y * f + 1.1676998740e-1f;
    y = y * f - 1.2420140846e-1f;
    y = y * f + 1.4249322787e-1f;
    y = y * f - 1.6668057665e-1f;
    y = y * f + 2.0000714765e-1f;
    y = y * f - 2.4999993993e-1f;
    y = y * f + 3.3333331174e-1f;
    y = y * f * z - 0.5f * z + f;
    return y + static_cast<float>(e) * 0.693147180559945f;
}

} // namespace

RAWGMENT_HOT_KERNEL
void fillGaussian(uint64_t seed, uint64_t stream, float* out, int n)
{
    // 64 values per chunk: 16 Philox blocks (two groups of 8), 32 Box-Muller pairs.
    const int kChunk = 64, kPairs = kChunk / 2;
    uint32_t words[kChunk];
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    for (int base = 0; base < n; base += kChunk) {
        const uint32_t block0 = static_cast<uint32_t>(base / 4);
        philox8Blocks(block0, stream, key, words);
        philox8Blocks(block0 + 8, stream, key, words + 32);
        float z[kChunk];
        for (int i = 0; i < kPairs; ++i) {
            // u1 in (0, 1] from 24 bits (never 0: log is finite), through int32 (x86 before AVX-512
            // has no vector uint32->float); the other word picks the angle.
            const float u1 =
                (static_cast<float>(static_cast<int32_t>(words[i] >> 8)) + 1.0f) * (1.0f / 16777216.0f);
            const uint32_t a = words[kPairs + i];
            const float radius = std::sqrt(-2.0f * logPositive(u1));
            // The angle: quadrant from the top 2 bits, phi in [-pi/4, pi/4) from the next 22. Any
            // uniform angle serves Box-Muller; this one needs only the short polynomials of |phi| <= pi/4.
            const uint32_t q = a >> 30;
            const float phi =
                (static_cast<float>(static_cast<int32_t>((a >> 8) & 0x3fffff)) * (1.0f / 4194304.0f) - 0.5f) *
                1.5707963268f;
            const float p2 = phi * phi;
            const float s =
                phi + phi * p2 * (-1.6666654611e-1f + p2 * (8.3321608736e-3f + p2 * -1.9515295891e-4f));
            const float c =
                1.0f - 0.5f * p2 +
                p2 * p2 *
                    (4.166664568298827e-2f + p2 * (-1.388731625493765e-3f + p2 * 2.443315711809948e-5f));
            // Rotate (c, s) by q quarter turns: (c, s), (-s, c), (-c, -s), (s, -c).
            const bool odd = (q & 1) != 0;
            const float cosRot = (odd ? s : c) * ((q == 1 || q == 2) ? -1.0f : 1.0f);
            const float sinRot = (odd ? c : s) * (q >= 2 ? -1.0f : 1.0f);
            z[i] = radius * cosRot;
            z[kPairs + i] = radius * sinRot;
        }
        std::memcpy(out + base, z, sizeof(float) * static_cast<size_t>(std::min(kChunk, n - base)));
    }
}

} // namespace detail
} // namespace rawgment
} // namespace cv
