// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The simulator's and the noise steps' private samplers (src/random.hpp), against their references: exact
// Poisson counts in vector lanes and the Tukey-lambda quantiles, the same on every CPU path. They call
// functions the shared library does not export: the standalone build links rawgment_internal, and the
// OpenCV build leaves this file out of opencv_test_rawgment (docs/architecture.md).
#include "test_common.hpp"

#include "../src/random.hpp"
#include <opencv2/rawgment/cpu.hpp>

#include <cmath>
#include <cstring>
#include <map>

namespace cv {
namespace rawgment {
namespace {

/* The words of fillPoisson()'s value i in the stream (seed, stream), as random.hpp documents (word j of
 * block b of a chunk's 8 at 8 j + b): value h of its chunk of 16 owns word 16 + h; its Box-Muller pair
 * h % 8 takes the radius from word h % 8 and the angle from word 8 + h % 8. */
struct PoissonWords
{
    uint32_t own, radius, angle;
};

PoissonWords poissonWords(uint64_t seed, uint64_t stream, int i)
{
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    auto word = [&](int chunk, int w) {
        const std::array<uint32_t, 4> counter = {static_cast<uint32_t>(8 * chunk + w % 8), 0,
                                                 static_cast<uint32_t>(stream),
                                                 static_cast<uint32_t>(stream >> 32)};
        return detail::philox4x32(counter, key)[static_cast<size_t>(w / 8)];
    };
    const int chunk = i / 16, h = i % 16;
    return {word(chunk, 16 + h), word(chunk, h % 8), word(chunk, 8 + h % 8)};
}

/* Steps P, Q and E of Ahrens and Dieter's PD (ACM TOMS 8, 1982), written out from the paper with the C
 * library's lgamma for the Poisson probabilities (the library's own takes Stirling's formula with its
 * remainder), for a value whose steps N, I and S left it: g = mu + sqrt(mu) T, u its uniform. */
double referencePdRest(double mu, double g, double u, detail::CounterRng& rng)
{
    const double s = std::sqrt(mu), omega = 1 / std::sqrt(2 * CV_PI) / s;
    const double b1 = 1 / (24 * mu), b2 = 0.3 * b1 * b1, c3 = b1 * b2 / 7, c2 = b2 - 15 * c3;
    const double c1 = b1 - 6 * b2 + 45 * c3, c0 = 1 - b1 + 3 * b2 - 15 * c3, c = 0.1069 / mu;
    const auto logP = [mu](double k) { return k * std::log(mu) - mu - std::lgamma(k + 1); };
    const auto fxy = [&](double k, double& fx, double& fy) {
        const double x2 = std::pow((0.5 - (mu - k)) / s, 2);
        fx = -0.5 * x2;
        fy = omega * (((c3 * x2 + c2) * x2 + c1) * x2 + c0);
    };
    double fx, fy;
    if (g >= 0) {
        const double k = std::floor(g);
        fxy(k, fx, fy);
        if (fy * (1 - u) <= std::exp(logP(k) - fx))
            return k;
    }
    for (;;) {
        const double e = -std::log(rng.uniform()), signedU = 2 * rng.uniform() - 1;
        const double t = 1.8 + (signedU < 0 ? -e : e);
        if (t <= -0.6744)
            continue;
        const double k = std::floor(mu + s * t);
        fxy(k, fx, fy);
        if (c * std::abs(signedU) <= std::exp(logP(k) + e) - fy * std::exp(fx + e))
            return k;
    }
}

/* fillPoisson()'s value i written out with the C library's exp, log, sqrt, sin and cos: below a mean of 25,
 * inversion from the uniform of its own word; up to 2^40, PD's steps N, I and S on its normal (Box-Muller of
 * its pair's words) and its uniform, and referencePdRest() on its retry stream for the rest (`rest` tells);
 * beyond 2^40, the scalar sampler on that stream. */
double referencePoisson(uint64_t seed, uint64_t stream, int i, double lambda, bool* rest = nullptr)
{
    if (rest)
        *rest = false;
    if (!(lambda > 0))
        return 0;
    const PoissonWords w = poissonWords(seed, stream, i);
    const double u = (w.own + 0.5) / 4294967296.0;
    if (lambda < 25) { // fillPoisson's switch (CounterRng::poisson()'s is at 10)
        double p = std::exp(-lambda), cdf = p;
        int k = 0;
        while (u > cdf && k < 200) {
            ++k;
            p *= lambda * (1.0 / k); // as fillPoisson(): 1 / k from a table
            cdf += p;
        }
        return k;
    }
    detail::CounterRng retry(detail::poissonRetryKey(seed, stream), static_cast<uint64_t>(i));
    if (lambda > 1099511627776.0) // beyond 2^40: the scalar sampler alone
        return static_cast<double>(retry.poisson(lambda));
    // The angle: quadrant q from the top 2 bits, phi in (-pi/4, pi/4) from the other 30.
    const double radius = std::sqrt(-2 * std::log((w.radius + 0.5) / 4294967296.0));
    const double phi = (((w.angle & 0x3fffffffu) + 0.5) / 1073741824.0 - 0.5) * (CV_PI / 2);
    const int q = static_cast<int>(w.angle >> 30);
    const double angle = q * (CV_PI / 2) + phi;
    const double t = radius * ((i % 16) < 8 ? std::cos(angle) : std::sin(angle));
    const double g = lambda + std::sqrt(lambda) * t;
    const double k = std::floor(std::max(g, 0.0)), dif = lambda - k;
    if (g >= 0 && (k >= std::floor(lambda - 1.1484) || 6 * lambda * lambda * u >= dif * dif * dif))
        return k;
    if (rest)
        *rest = true;
    return referencePdRest(lambda, g, u, retry);
}

/* The share of values that PD's steps N, I and S leave to steps Q and E at mean mu: K = floor(mu + sqrt(mu)
 * T) below floor(mu - 1.1484) and not squeezed (u < (mu - K)^3 / (6 mu^2)), or mu + sqrt(mu) T < 0. */
double pdRestShare(double mu)
{
    const double s = std::sqrt(mu), l = std::floor(mu - 1.1484);
    const auto below = [&](double x) { return 0.5 * std::erfc(-(x - mu) / (s * std::sqrt(2.0))); };
    double share = below(0);
    for (double k = 0; k < l; ++k)
        share += (below(k + 1) - below(k)) * std::min(1.0, std::pow(mu - k, 3) / (6 * mu * mu));
    return share;
}

TEST(Simulate, fillPoissonIsExactAndTheSameOnEveryPath)
{
    const uint64_t seed = 0x1234abcd5678ef01ull, stream = 7;
    // Means on both sides of the switch from inversion to PD at 25, PD's range up to 2^40 and the scalar
    // sampler beyond, and 0, interleaved, so that the small means are gathered from mixed chunks and the
    // pairs of Box-Muller mix both kinds.
    const std::vector<double> lambdas = {0.05, 0.7,    3.0, 12.0, 24.99, 25.0, 30.0,
                                         37.5, 1000.0, 2e6, 0.0,  3e12,  5e9};
    const int perMean = 40000;
    const int n = static_cast<int>(lambdas.size()) * perMean + 5; // a partial last chunk too
    std::vector<double> means(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i)
        means[static_cast<size_t>(i)] = lambdas[static_cast<size_t>(i) % lambdas.size()];
    std::vector<double> first;
    for (CpuPath path : availableCpuPaths()) {
        setCpuPath(path);
        std::vector<double> counts(static_cast<size_t>(n));
        detail::fillPoisson(seed, stream, means.data(), counts.data(), n);
        if (first.empty())
            first = counts;
        else
            ASSERT_EQ(0, std::memcmp(first.data(), counts.data(), sizeof(double) * first.size()))
                << cpuPathName(path);
    }
    setCpuPath(CpuPath::AUTO);
    // Value by value against the reference: the polynomial exp, log, sin and cos differ from the C library's
    // by an ulp or two, and the library's Poisson probabilities from lgamma's by about 1e-13, which moves a
    // count only when a uniform or g falls within about 1e-13 of a boundary of the CDF or of a test (chance
    // below 1e-12 per value): none of these 520,005 may differ.
    std::map<double, int> rests;
    for (int i = 0; i < n; ++i) {
        const double lambda = means[static_cast<size_t>(i)];
        bool rest = false;
        ASSERT_EQ(first[static_cast<size_t>(i)], referencePoisson(seed, stream, i, lambda, &rest))
            << "value " << i << ", mean " << lambda;
        rests[lambda] += rest;
    }
    // The share that steps N, I and S leave (1-2%) against its value from the normal CDF, 5 binomial standard
    // errors: a share far from it would mean the lanes take or leave values they should not.
    for (double lambda : {25.0, 30.0, 37.5, 1000.0, 2e6}) {
        const double expected = pdRestShare(lambda), share = rests[lambda] / static_cast<double>(perMean);
        std::cout << "fillPoisson at mean " << lambda << ": steps Q and E for " << share << " (expected "
                  << expected << ")\n";
        EXPECT_NEAR(share, expected, 5 * std::sqrt(expected * (1 - expected) / perMean)) << lambda;
    }
    // A chunk of small means only is inverted in place, not gathered: the same values as the reference.
    std::vector<double> dark(4096 + 7), darkCounts(dark.size());
    for (size_t i = 0; i < dark.size(); ++i)
        dark[i] = 0.05 + 24.9 * static_cast<double>((i * 37) % 101) / 100.0; // 0.05 to 24.95
    detail::fillPoisson(seed, stream, dark.data(), darkCounts.data(), static_cast<int>(dark.size()));
    for (size_t i = 0; i < dark.size(); ++i)
        ASSERT_EQ(darkCounts[i], referencePoisson(seed, stream, static_cast<int>(i), dark[i]))
            << "value " << i;
    // A value depends on its own mean only: the same means in another order give each value its count.
    std::vector<double> reversed(means.rbegin(), means.rend()), again(static_cast<size_t>(n));
    detail::fillPoisson(seed, stream, reversed.data(), again.data(), n);
    for (int i = 0; i < n; i += 997)
        ASSERT_EQ(again[static_cast<size_t>(i)],
                  referencePoisson(seed, stream, i, reversed[static_cast<size_t>(i)]))
            << "value " << i;
    // The distribution against the Poisson probabilities, at every mean that is not too large to bin:
    // cells grown from the left until their expected count reaches 20, as poissonHistogramPassesChiSquare.
    for (size_t m = 0; m < lambdas.size(); ++m) {
        const double lambda = lambdas[m];
        double sum = 0, sum2 = 0;
        std::map<int64_t, int> hist;
        for (size_t i = m; i < static_cast<size_t>(perMean) * lambdas.size(); i += lambdas.size()) {
            const double k = first[i];
            ASSERT_EQ(k, std::floor(k));
            sum += k;
            sum2 += k * k;
            if (lambda <= 1e4)
                ++hist[static_cast<int64_t>(k)];
        }
        const double mean = sum / perMean, var = sum2 / perMean - mean * mean;
        if (lambda == 0) {
            EXPECT_EQ(sum, 0);
            continue;
        }
        // Mean and variance are lambda; their standard errors sqrt(lambda / N) and
        // sqrt((2 lambda^2 + lambda) / N): 5 of them.
        EXPECT_NEAR(mean, lambda, 5 * std::sqrt(lambda / perMean)) << lambda;
        EXPECT_NEAR(var, lambda, 5 * std::sqrt((2 * lambda * lambda + lambda) / perMean)) << lambda;
        if (lambda > 1e4)
            continue;
        int dof = 0;
        const double chi2 = test::poissonChiSquare(hist, lambda, perMean, dof);
        // chi^2 with dof degrees of freedom: mean dof, sd sqrt(2 dof); 6 sd, as
        // poissonHistogramPassesChiSquare.
        EXPECT_LT(chi2, dof + 6 * std::sqrt(2.0 * dof)) << "lambda " << lambda << " dof " << dof;
    }
}

TEST(Simulate, poissonProbabilitiesOfTheLanesAreExact)
{
    // PD's quotient test and hat compare against the Poisson probabilities. The reference, k ln mu - mu -
    // lgamma(k + 1) in long double, errs by a few long-double ulps (4e-19) of its largest term, k ln mu + mu
    // (2e10 at a mean of 1e9). The lanes round v = (mu - k) / k (2e-16 |mu - k| after the factor k), the
    // sum (2e-15 of |ln P|, four double ulps) and the rest (1e-13). Checked on every path: near k = mu (the
    // series of ln(1 + v) - v), far from it (the logarithm), at k = 0, below and above the remainder's table
    // (32) and at means up to 1e9.
    std::vector<double> ks, mus;
    for (double mu : {25.0, 30.5, 1000.0, 123456.7, 1e9})
        for (double f : {0.0, 0.3, 0.7, 0.9, 0.99, 1.0, 1.01, 1.1, 1.3, 2.0, 4.0})
            for (double shift : {0.0, 1.0, 7.0}) {
                ks.push_back(std::floor(f * mu) + shift);
                mus.push_back(mu);
            }
    for (double k : {1.0, 2.0, 9.0, 10.0, 31.0, 32.0, 33.0}) {
        ks.push_back(k);
        mus.push_back(27.25);
    }
    const int n = static_cast<int>(ks.size());
    for (CpuPath path : availableCpuPaths()) {
        setCpuPath(path);
        std::vector<double> lp(static_cast<size_t>(n));
        detail::logPoissonProbabilities(ks.data(), mus.data(), lp.data(), n);
        for (int i = 0; i < n; ++i) {
            const long double k = ks[static_cast<size_t>(i)], mu = mus[static_cast<size_t>(i)];
            const long double reference = k * std::log(mu) - mu - std::lgamma(k + 1);
            const double referenceError = 4e-19 * static_cast<double>(k * std::log(mu) + mu);
            EXPECT_NEAR(lp[static_cast<size_t>(i)], static_cast<double>(reference),
                        1e-13 + 2e-16 * static_cast<double>(std::abs(mu - k)) +
                            2e-15 * std::abs(static_cast<double>(reference)) + referenceError)
                << cpuPathName(path) << ": k " << ks[static_cast<size_t>(i)] << ", mu "
                << mus[static_cast<size_t>(i)];
        }
    }
    setCpuPath(CpuPath::AUTO);
}

TEST(Simulate, fillTukeyUnitIsTheQuantileOfItsWordsOnEveryPath)
{
    // Each value against the Tukey-lambda quantile in double precision of the uniform its words give, in the
    // layout random.hpp documents (value h of a chunk of 32: word h of the chunk's 8 blocks, word j of
    // block b at 8 j + b; below u = 2^-8, 24 more bits from the first word of the value's own stream), at
    // both lambdas of a row (even and odd columns), for the lightest, the logistic and the heaviest shapes
    // a model takes.
    const uint64_t seed = 0x0fedcba987654321ull, stream = 3;
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    const uint64_t refineKey = detail::tukeyRefineKey(seed, stream);
    const std::array<uint32_t, 2> refineWordKey = {static_cast<uint32_t>(refineKey),
                                                   static_cast<uint32_t>(refineKey >> 32)};
    // The uniform of value i, and the one it would have without its refinement (the fraction 1/2).
    auto uniforms = [&](int i, double& u, double& unrefined) {
        const int chunk = i / 32, h = i % 32;
        const std::array<uint32_t, 4> counter = {static_cast<uint32_t>(8 * chunk + h % 8), 0,
                                                 static_cast<uint32_t>(stream),
                                                 static_cast<uint32_t>(stream >> 32)};
        const uint32_t w1 = detail::philox4x32(counter, key)[static_cast<size_t>(h / 8)];
        const uint32_t m = w1 & 0x7fffffffu;
        const uint32_t w2 = m < (1u << 24)
                                ? detail::philox4x32({0, 0, static_cast<uint32_t>(i), 0}, refineWordKey)[0]
                                : 0x80000000u;
        u = (m + (static_cast<double>(w2 >> 8) + 0.5) / 16777216.0) / 4294967296.0;
        unrefined = (m + 0.5) / 4294967296.0;
        return (w1 >> 31) != 0;
    };
    const auto quantile = [](double u, double lambda) {
        return lambda == 0 ? std::log(u / (1 - u)) : (std::pow(u, lambda) - std::pow(1 - u, lambda)) / lambda;
    };
    const int n = 32 * 4096 + 11; // a partial last chunk too
    for (const Vec2f& lambdas : {Vec2f(1.0f, 0.14f), Vec2f(0.0f, -0.05f), Vec2f(-0.2f, 0.5f)}) {
        const float invSd[2] = {0.7f, 1.3f};
        const detail::TukeyQuantileTable table(lambdas[0], invSd[0], lambdas[1], invSd[1]);
        std::vector<double> reference(static_cast<size_t>(n));
        for (int i = 0; i < n; ++i) {
            double u, unrefined;
            const bool negative = uniforms(i, u, unrefined);
            const double q = quantile(u, lambdas[i & 1]) * invSd[i & 1];
            reference[static_cast<size_t>(i)] = negative ? -q : q;
        }
        // From u = 2^-8 up the table's cubics round in their float coefficients and four multiply-adds (their
        // truncation is below 2e-9, random.hpp), and u rounds to float's 24 bits: a few ulps, 2.5e-7 of
        // max(1, |value|) seen. The refined values below round in the two logarithms (each a few ulps of
        // |ln u| <= 40), the exponential and the difference. 2e-6 bounds both; a wrong word, cell, sign or
        // branch of the series errs by order one.
        std::vector<float> first;
        for (CpuPath path : availableCpuPaths()) {
            setCpuPath(path);
            std::vector<float> t(static_cast<size_t>(n));
            detail::fillTukeyUnit(seed, stream, table, t.data(), n);
            double worst = 0;
            for (int i = 0; i < n; ++i) {
                const double ref = reference[static_cast<size_t>(i)];
                const double error = std::abs(t[static_cast<size_t>(i)] - ref) / std::max(1.0, std::abs(ref));
                worst = std::max(worst, error);
                ASSERT_LE(error, 2e-6) << cpuPathName(path) << ", lambdas " << lambdas << ", value " << i;
            }
            std::cout << cpuPathName(path) << ", lambdas " << lambdas << ": largest error " << worst << "\n";
            if (first.empty())
                first = t;
            else
                ASSERT_EQ(0, std::memcmp(first.data(), t.data(), sizeof(float) * first.size()))
                    << cpuPathName(path);
        }
        setCpuPath(CpuPath::AUTO);
    }
    // The refinement is there: the refined share is 2^-7, and where it moves u by more than 1e-4 (31 bits of
    // u below 2^13, a few in 2^22 values), the logistic's output gives back the refined u, not the unrefined
    // one (|v| = ln((1 - u) / u) within 4e-5 here, so u within 5e-5 relative).
    const int many = 1 << 22;
    std::vector<float> t(static_cast<size_t>(many));
    detail::fillTukeyUnit(seed, stream, detail::TukeyQuantileTable(0.0f, 1.0f), t.data(), many);
    int refined = 0, telling = 0;
    for (int i = 0; i < many; ++i) {
        double u, unrefined;
        uniforms(i, u, unrefined);
        if (u >= 1.0 / 256)
            continue;
        ++refined;
        if (std::abs(u - unrefined) <= 1e-4 * u)
            continue;
        ++telling;
        const double fromValue = 1 / (1 + std::exp(std::abs(static_cast<double>(t[static_cast<size_t>(i)]))));
        EXPECT_NEAR(fromValue, u, 5e-5 * u) << "value " << i << " (unrefined u " << unrefined << ")";
    }
    // Binomial(2^22, 2^-7): mean 32768, sd 180.
    EXPECT_NEAR(refined, many / 128, 5 * 181);
    EXPECT_GT(telling, 0);
    std::cout << "refined " << refined << " of " << many << ", " << telling
              << " where it moves u by over 1e-4\n";
}

} // namespace
} // namespace rawgment
} // namespace cv
