// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The Poisson counts of random.hpp: CounterRng::poisson() in scalar code and fillPoisson() in double
// lanes (inversion for small means, Ahrens and Dieter's PD above). The float-lane normals are in
// random.cpp.
#include "random.hpp"

#include "cpu_dispatch.hpp"

#include <algorithm>
#include <cstring>
#include <memory>

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

/* The double lanes of a kernel of width W floats: W / 2 doubles, one register on every path (wider
 * vectors would compare and select lane by lane in scalar code, cpu_dispatch.hpp). */
template <int W> struct DoubleLanes
{
    typedef RAWGMENT_VECTOR(double, 4 * W) D;
    typedef RAWGMENT_VECTOR(int64_t, 4 * W) L;
    typedef RAWGMENT_VECTOR(uint64_t, 4 * W) UL;
    typedef RAWGMENT_VECTOR(uint32_t, 2 * W) U32; // a 32-bit word per double lane
    static constexpr int kCount = W / 2;
};

// 2^52 and 2^52 + 2^51: adding one to a double in range leaves an integer in the low mantissa bits.
constexpr double kTwo52 = 4503599627370496.0, kTwo52And51 = 6755399441055744.0;
// ln 2 in two parts (Cody and Waite): the high part has 32 trailing zero bits, so n ln2Hi is exact for
// any exponent n of a double.
constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10;

//! An int64 lane in [-2^51, 2^51) as a double, with integer operations only (x86 before AVX-512 has no
//! vector int64 -> double).
template <int W> RAWGMENT_KERNEL typename DoubleLanes<W>::D int64ToDoubleLanes(typename DoubleLanes<W>::L v)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::UL UL;
    const UL bits = (UL)(v + (int64_t(1) << 51)) | 0x4330000000000000ull;
    return (D)bits - kTwo52And51;
}

/* ln(x) for finite normal x > 0, to about 2 double ulps: x = 2^e m with m in [sqrt(1/2), sqrt(2)), then
 * ln m = 2 atanh(s), s = (m - 1) / (m + 1), |s| <= 0.1716, by its series to s^19 (the next term is below
 * 2^-56 relative); m - 1 is exact, so the result stays accurate relative to ln m near 1. */
template <int W> RAWGMENT_KERNEL typename DoubleLanes<W>::D logLanesD(typename DoubleLanes<W>::D x)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::L L;
    typedef typename DoubleLanes<W>::UL UL;
    const UL bits = (UL)x;
    L e = (L)(bits >> 52) - 1023;
    D m = (D)((bits & 0x000fffffffffffffull) | 0x3ff0000000000000ull); // in [1, 2)
    const L big = m > 1.4142135623730951;
    m = selectLanes(big, m * 0.5, m);
    e -= big;
    const D s = (m - 1.0) / (m + 1.0), s2 = s * s, s4 = s2 * s2, s8 = s4 * s4;
    // 1 + s2/3 + ... + s2^9/19 by Estrin's scheme (a short dependency chain, as logPositiveLanes()).
    const D p01 = 1.0 + s2 * (1.0 / 3), p23 = 1.0 / 5 + s2 * (1.0 / 7), p45 = 1.0 / 9 + s2 * (1.0 / 11),
            p67 = 1.0 / 13 + s2 * (1.0 / 15), p89 = 1.0 / 17 + s2 * (1.0 / 19);
    const D poly = (p01 + s4 * p23) + s8 * ((p45 + s4 * p67) + s8 * p89);
    const D ed = int64ToDoubleLanes<W>(e);
    return ed * kLn2Hi + (2.0 * s * poly + ed * kLn2Lo);
}

/* e^x for x in [-700, 0], to about 2 double ulps: n = x / ln 2 rounded to nearest, r = x - n ln 2 (two
 * parts), |r| <= ln(2) / 2, e^r by its Taylor series to r^13 (the remainder is below 2^-55), then 2^n
 * through the exponent bits. */
template <int W> RAWGMENT_KERNEL typename DoubleLanes<W>::D expLanesD(typename DoubleLanes<W>::D x)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::UL UL;
    const D n = (x * 1.4426950408889634 + kTwo52And51) - kTwo52And51;
    const D r = (x - n * kLn2Hi) - n * kLn2Lo;
    const D r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
    const D q01 = 1.0 + r, q23 = 1.0 / 2 + r * (1.0 / 6), q45 = 1.0 / 24 + r * (1.0 / 120),
            q67 = 1.0 / 720 + r * (1.0 / 5040), q89 = 1.0 / 40320 + r * (1.0 / 362880),
            q1011 = 1.0 / 3628800 + r * (1.0 / 39916800), q1213 = 1.0 / 479001600 + r * (1.0 / 6227020800.0);
    const D er = ((q01 + r2 * q23) + r4 * (q45 + r2 * q67)) + r8 * ((q89 + r2 * q1011) + r4 * q1213);
    const UL scale = (UL)(n + (kTwo52 + 1023.0)) << 52;
    return er * (D)scale;
}

//! floor(x) for x in [0, 2^52): rounded to nearest by the 2^52 trick, then one down where that went up.
template <int W>
RAWGMENT_KERNEL typename DoubleLanes<W>::D floorNonNegativeLanesD(typename DoubleLanes<W>::D x)
{
    typedef typename DoubleLanes<W>::D D;
    const D r = (x + kTwo52) - kTwo52;
    return selectLanes(r > x, r - 1.0, r);
}

//! Uniforms of 32 bits in (0, 1): (w + 1/2) 2^-32, exact, through 64-bit lanes (no vector uint32 -> double
//! before AVX-512).
template <int W> RAWGMENT_KERNEL typename DoubleLanes<W>::D uniform32LanesD(typename DoubleLanes<W>::UL w)
{
    typedef typename DoubleLanes<W>::D D;
    return (((D)(w | 0x4330000000000000ull) - kTwo52) + 0.5) * (1.0 / 4294967296.0);
}

// The largest mean fillPoisson() draws in lanes, 2^40: mu + sqrt(mu) T and its floor then stay far below
// 2^52. Larger means go to CounterRng::poisson() (which takes up to kMaxPoissonMean).
constexpr double kMaxLaneMean = 1099511627776.0;

/* The mean from which fillPoisson() takes Ahrens and Dieter's PD (which needs 10 or more); below, it inverts
 * the CDF. On host H2 (AVX2), per value on one core, inversion took 9.1 ns at a mean of 10 and 13.3 at 24.9,
 * PD 16.5 at 10 (where 5% of values need its scalar steps Q and E), 13.5 at 25 and 12.9 at 30.
 * CounterRng::poisson() switches from inversion to PTRS at 10. */
constexpr double kInversionBelow = 25.0;

/* log k! - (k ln k - k + ln(2 pi k) / 2), the remainder of Stirling's formula, for k >= 1: exact below 32
 * (from the table of logFactorial()), its series 1/(12k) - 1/(360k^3) + 1/(1260k^5) above, as
 * logFactorial() (error below 1e-13 relative to log k!). */
double stirlingRemainder(double k)
{
    static const std::array<double, 32> table = [] {
        std::array<double, 32> t{};
        for (int i = 1; i < 32; ++i) {
            const double x = i;
            t[static_cast<size_t>(i)] =
                logFactorial(i) - (x * std::log(x) - x + 0.5 * std::log(2.0 * CV_PI * x));
        }
        return t;
    }();
    if (k < 32)
        return table[static_cast<size_t>(k)];
    const double inv = 1.0 / k, inv2 = inv * inv;
    return inv * (1.0 / 12 - inv2 * (1.0 / 360 - inv2 * (1.0 / 1260)));
}

/* Box-Muller in double lanes: the normals of kCount pairs from their 32-bit words, the radius from
 * u = (w + 1/2) 2^-32 (so |T| <= 6.7: a true normal lies beyond with probability 3e-11), the angle's
 * quadrant from the top 2 bits of the angle word and phi in (-pi/4, pi/4) from the other 30 (plus 1/2).
 * sin and cos of phi by their Taylor series to phi^17 and phi^16 (next terms below 2^-55 relative), the
 * quadrant by swapping and negating, so the normals are Box-Muller's to about 2 ulps on every path. */
template <int W>
RAWGMENT_KERNEL void normalPairsLanesD(const uint32_t* radiusWords, const uint32_t* angleWords,
                                       typename DoubleLanes<W>::D& cosNormal,
                                       typename DoubleLanes<W>::D& sinNormal)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::L L;
    typedef typename DoubleLanes<W>::UL UL;
    typename DoubleLanes<W>::U32 a, b;
    std::memcpy(&a, radiusWords, sizeof(a));
    std::memcpy(&b, angleWords, sizeof(b));
    const UL w1 = convertLanes<UL>(a), w2 = convertLanes<UL>(b);
    const D radius = sqrtLanes(-2.0 * logLanesD<W>(uniform32LanesD<W>(w1)));
    const D fraction =
        (((D)((w2 & 0x3fffffffull) | 0x4330000000000000ull) - kTwo52) + 0.5) * (1.0 / 1073741824.0);
    const D phi = (fraction - 0.5) * 1.5707963267948966;
    const D p2 = phi * phi, p4 = p2 * p2, p8 = p4 * p4;
    const D sinPhi = phi * (((1.0 - p2 * (1.0 / 6)) + p4 * (1.0 / 120 - p2 * (1.0 / 5040))) +
                            p8 * ((1.0 / 362880 - p2 * (1.0 / 39916800)) +
                                  p4 * (1.0 / 6227020800.0 - p2 * (1.0 / 1307674368000.0)) +
                                  p8 * (1.0 / 355687428096000.0)));
    const D cosPhi =
        ((1.0 - p2 * 0.5) + p4 * (1.0 / 24 - p2 * (1.0 / 720))) +
        p8 * ((1.0 / 40320 - p2 * (1.0 / 3628800)) + p4 * (1.0 / 479001600 - p2 * (1.0 / 87178291200.0)) +
              p8 * (1.0 / 20922789888000.0));
    // Rotate (cos, sin) by q quarter turns, as boxMullerLanes() does in float.
    const L q = (L)(w2 >> 30);
    const L odd = (q & 1) != 0;
    D c = selectLanes(odd, sinPhi, cosPhi), s = selectLanes(odd, cosPhi, sinPhi);
    c = selectLanes((q == 1) | (q == 2), -c, c);
    s = selectLanes(q >= 2, -s, s);
    cosNormal = radius * c;
    sinNormal = radius * s;
}

//! 1 / k for k = 1..200 (index 0 unused): the steps of the inversion's search.
const std::array<double, 201>& inverseIntegers()
{
    static const std::array<double, 201> table = [] {
        std::array<double, 201> t{};
        for (size_t k = 1; k < t.size(); ++k)
            t[k] = 1.0 / static_cast<double>(k);
        return t;
    }();
    return table;
}

/* Inversion by sequential search for the means below kInversionBelow among a chunk's G groups of lanes,
 * the groups' chains interleaved (one multiply-add chain each, so together they hide each other's
 * latency): u = (w + 1/2) 2^-32 from the value's own word, and p_k = p_(k-1) lambda (1 / k). e^-25 and the
 * sums of up to 200 terms stay far inside double's range and precision. Lanes of larger means run with
 * mean 0 and give 0. */
template <int W, int G>
RAWGMENT_KERNEL void poissonInversionLanes(const double* chunkMeans, const uint32_t* ownWords,
                                           double* chunkCounts)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::L L;
    typedef typename DoubleLanes<W>::UL UL;
    typedef typename DoubleLanes<W>::U32 U32;
    const int kLanes = DoubleLanes<W>::kCount;
    D u[G], lambda[G], p[G], cdf[G], k[G];
    L small[G];
    for (int g = 0; g < G; ++g) {
        D m;
        U32 a;
        std::memcpy(&m, chunkMeans + g * kLanes, sizeof(m));
        std::memcpy(&a, ownWords + g * kLanes, sizeof(a));
        small[g] = m < kInversionBelow;
        lambda[g] = selectLanes(small[g], m, D{});
        u[g] = uniform32LanesD<W>(convertLanes<UL>(a));
        p[g] = expLanesD<W>(-lambda[g]);
        cdf[g] = p[g];
        k[g] = D{};
    }
    // An active lane has taken every step so far, so its count is the step number. An inactive one stays
    // so: its cdf, which already reached u, only grows (it adds p >= 0), so its p and cdf need no select.
    // lambda / k as lambda (1 / k), 1 / k from a table: a division per group and step cost more than the
    // rest of the search.
    const std::array<double, 201>& inverse = inverseIntegers();
    for (int step = 1; step <= 200; ++step) {
        L any = {};
        const double next = step, invNext = inverse[static_cast<size_t>(step)];
        for (int g = 0; g < G; ++g) {
            const L active = u[g] > cdf[g];
            any |= active;
            p[g] = p[g] * (lambda[g] * invNext);
            cdf[g] = cdf[g] + p[g];
            k[g] = selectLanes(active, D{} + next, k[g]);
        }
        if (!maskBits(any))
            break;
    }
    for (int g = 0; g < G; ++g) {
        D counts;
        std::memcpy(&counts, chunkCounts + g * kLanes, sizeof(counts));
        counts = selectLanes(small[g], k[g], counts);
        std::memcpy(chunkCounts + g * kLanes, &counts, sizeof(counts));
    }
}

//! Appends base + i to list[size..] for every bit i of `bits` (of `lanes`), without branches: each lane is
//! written, and the size advances past the set ones (list has room for `lanes` more).
inline void appendBits(int bits, int lanes, int base, int* list, int& size)
{
    for (int i = 0; i < lanes; ++i) {
        list[size] = base + i;
        size += (bits >> i) & 1;
    }
}

/* log(1 + v) - v for v > -1, to about 2 ulps of v^2 / 2 and without cancellation: below |v| = 1/4 as
 * -s v + 2 s^3 (1/3 + s^2/5 + ... + s^18/21) with s = v / (2 + v) (log(1 + v) = 2 atanh(s), and v - 2 s =
 * s v exactly in real numbers; |s| <= 1/7, so the series' next term is below 2^-56 of the sum), else from
 * the logarithm, where v is large enough. */
template <int W> RAWGMENT_KERNEL typename DoubleLanes<W>::D log1pMinusLanesD(typename DoubleLanes<W>::D v)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::L L;
    const L small = (v < 0.25) & (v > -0.25);
    const D vs = selectLanes(small, v, D{});
    const D s = vs / (2.0 + vs), s2 = s * s, s4 = s2 * s2, s8 = s4 * s4;
    const D p01 = 1.0 / 3 + s2 * (1.0 / 5), p23 = 1.0 / 7 + s2 * (1.0 / 9), p45 = 1.0 / 11 + s2 * (1.0 / 13),
            p67 = 1.0 / 15 + s2 * (1.0 / 17), p89 = 1.0 / 19 + s2 * (1.0 / 21);
    const D series = -s * vs + 2.0 * s * s2 * (((p01 + s4 * p23) + s8 * (p45 + s4 * p67)) + s8 * s8 * p89);
    if (maskBits(~small) == 0)
        return series;
    const D direct = logLanesD<W>(selectLanes(small, D{} + 1.0, 1.0 + v)) - v;
    return selectLanes(small, series, direct);
}

/* The log of the Poisson probability of k >= 0 at mean mu in lanes, to about 1e-13 + 1e-16 |mu - k| absolute
 * (the rounding of ln(1 + v), times k): -mu at k = 0, else k (log(1 + v) - v) - ln(2 pi k) / 2 -
 * Stirling's remainder (the table below 32, its series above) with v = (mu - k) / k. */
template <int W>
RAWGMENT_KERNEL typename DoubleLanes<W>::D logPoissonProbabilityLanesD(typename DoubleLanes<W>::D k,
                                                                       typename DoubleLanes<W>::D mu)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::L L;
    const L zero = k < 1.0;
    const D kk = selectLanes(zero, D{} + 1.0, k);
    const D inv = 1.0 / kk, inv2 = inv * inv;
    D remainder = inv * (1.0 / 12 - inv2 * (1.0 / 360 - inv2 * (1.0 / 1260)));
    if (maskBits(kk < 32.0))
        for (int i = 0; i < DoubleLanes<W>::kCount; ++i)
            if (kk[i] < 32)
                remainder[i] = stirlingRemainder(kk[i]);
    const D v = (mu - kk) * inv;
    const D lp = kk * log1pMinusLanesD<W>(v) - 0.5 * logLanesD<W>(2.0 * CV_PI * kk) - remainder;
    return selectLanes(zero, -mu, lp);
}

//! e^x for x <= 40 in lanes, with x below -700 taken as -700 (e^-700 is 1e-304: every comparison PD makes
//! with it has the same outcome as with 0).
template <int W> RAWGMENT_KERNEL typename DoubleLanes<W>::D expClampedLanesD(typename DoubleLanes<W>::D x)
{
    return expLanesD<W>(selectLanes(x < -700.0, typename DoubleLanes<W>::D{} - 700.0, x));
}

//! CounterRng::uniform() from its two words in lanes: (first << 21) ^ (second >> 11), 53 bits, plus 1/2,
//! times 2^-53, exact as a double sum.
template <int W>
RAWGMENT_KERNEL typename DoubleLanes<W>::D uniform53LanesD(typename DoubleLanes<W>::UL first,
                                                           typename DoubleLanes<W>::UL second)
{
    typedef typename DoubleLanes<W>::D D;
    return ((((D)(first | 0x4330000000000000ull) - kTwo52) * 2097152.0 +
             ((D)((second >> 11) | 0x4330000000000000ull) - kTwo52)) +
            0.5) *
           (1.0 / 9007199254740992.0);
}

//! The constants of PD's hat and of its discrete normal for means mu, in lanes: sqrt(mu), 1 / sqrt(mu),
//! omega = 1 / sqrt(2 pi mu), the Hermite corrections c0..c3 and the hat's constant c (A & D's names).
template <int W> struct PdHatLanes
{
    typename DoubleLanes<W>::D mu, s, invS, omega, c0, c1, c2, c3, c;
};

template <int W> RAWGMENT_KERNEL PdHatLanes<W> pdHatLanes(typename DoubleLanes<W>::D mu)
{
    PdHatLanes<W> h;
    h.mu = mu;
    h.s = sqrtLanes(mu);
    h.invS = 1.0 / h.s;
    h.omega = 0.3989422804014327 * h.invS;
    const typename DoubleLanes<W>::D b1 = 1.0 / (24.0 * mu), b2 = 0.3 * b1 * b1;
    h.c3 = b1 * b2 * (1.0 / 7);
    h.c2 = b2 - 15.0 * h.c3;
    h.c1 = b1 - 6.0 * b2 + 45.0 * h.c3;
    h.c0 = 1.0 - b1 + 3.0 * b2 - 15.0 * h.c3;
    h.c = 0.1069 / mu;
    return h;
}

//! A & D's procedure F less its Poisson part, at counts k: fx = -x^2 / 2 and fy = omega (c3 x^6 + c2 x^4 + c1
//! x^2 + c0) with x = (k + 1/2 - mu) / sqrt(mu).
template <int W>
RAWGMENT_KERNEL void pdModifiedNormalLanes(const PdHatLanes<W>& h, typename DoubleLanes<W>::D k,
                                           typename DoubleLanes<W>::D& fx, typename DoubleLanes<W>::D& fy)
{
    const typename DoubleLanes<W>::D x = (0.5 - (h.mu - k)) * h.invS, xx = x * x;
    fx = -0.5 * xx;
    fy = h.omega * (((h.c3 * xx + h.c2) * xx + h.c1) * xx + h.c0);
}

/* Steps P, Q and E of Ahrens and Dieter's PD ("Computer generation of Poisson deviates from modified normal
 * distributions", ACM TOMS 8, 1982) in lanes, for the `count` values that fillPoissonKernel()'s steps N, I
 * and S left, eight at a time: step Q on their g = mu + sqrt(mu) T and u, then step E's tries until each is
 * accepted (0.64 of tries are at means 10 and 100, measured), try j of value i on block j of its stream (key,
 * i): its first two words the 53-bit uniform of the exponential, its last two the signed uniform, as two
 * calls of CounterRng::uniform() take them. The Poisson probabilities are exact
 * (logPoissonProbabilityLanesD()); the algorithm's own approximations of them (Stirling's series to two
 * terms, a polynomial of 7 digits for ln(1 + v)) would leave errors of 1e-8 relative. Log and exp are the
 * double polynomials, the same bits on every path. */
template <int W>
RAWGMENT_KERNEL void poissonPdRestLanes(uint64_t key, const double* means, const int* list, const double* gs,
                                        const double* us, int count, double* counts)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::L L;
    typedef typename DoubleLanes<W>::UL UL;
    typedef typename DoubleLanes<W>::U32 U32;
    const int kLanes = DoubleLanes<W>::kCount, kGroups = 8 / kLanes;
    const std::array<uint32_t, 2> streamKey = {static_cast<uint32_t>(key), static_cast<uint32_t>(key >> 32)};
    for (int start = 0; start < count; start += 8) {
        const int live = std::min(8, count - start);
        alignas(64) uint64_t streams[8];
        alignas(64) double mus[8], g8[8], u8[8], k8[8] = {};
        for (int i = 0; i < 8; ++i) {
            const int index = i < live ? list[start + i] : 0;
            streams[i] = static_cast<uint64_t>(index);
            mus[i] = i < live ? means[index] : kInversionBelow; // padding lanes: a valid mean, unused
            g8[i] = i < live ? gs[start + i] : 0.0;
            u8[i] = i < live ? us[start + i] : 0.5;
        }
        int pending = (1 << live) - 1;
        // Each value's hat, and its step Q.
        PdHatLanes<W> hat[kGroups];
        for (int gr = 0; gr < kGroups; ++gr) {
            D mu, g, u, fx, fy;
            std::memcpy(&mu, mus + gr * kLanes, sizeof(D));
            hat[gr] = pdHatLanes<W>(mu);
            std::memcpy(&g, g8 + gr * kLanes, sizeof(D));
            std::memcpy(&u, u8 + gr * kLanes, sizeof(D));
            const L quotient = g >= 0.0;
            const D k = floorNonNegativeLanesD<W>(selectLanes(quotient, g, D{}));
            pdModifiedNormalLanes<W>(hat[gr], k, fx, fy);
            const L accept =
                quotient & (fy - u * fy <= expClampedLanesD<W>(logPoissonProbabilityLanesD<W>(k, mu) - fx));
            std::memcpy(k8 + gr * kLanes, &k, sizeof(D));
            pending &= ~(maskBits(accept) << (gr * kLanes));
        }
        for (uint32_t j = 0; pending; ++j) {
            alignas(64) uint32_t words[32];
            philox8StreamsFor<W>(j, streams, streamKey, words);
            for (int gr = 0; gr < kGroups; ++gr) {
                const int groupBits = (pending >> (gr * kLanes)) & ((1 << kLanes) - 1);
                if (!groupBits)
                    continue;
                U32 a0, a1, a2, a3;
                std::memcpy(&a0, words + gr * kLanes, sizeof(U32));
                std::memcpy(&a1, words + 8 + gr * kLanes, sizeof(U32));
                std::memcpy(&a2, words + 16 + gr * kLanes, sizeof(U32));
                std::memcpy(&a3, words + 24 + gr * kLanes, sizeof(U32));
                const PdHatLanes<W>& h = hat[gr];
                const D e = -logLanesD<W>(uniform53LanesD<W>(convertLanes<UL>(a0), convertLanes<UL>(a1)));
                const D signedUniform =
                    2.0 * uniform53LanesD<W>(convertLanes<UL>(a2), convertLanes<UL>(a3)) - 1.0;
                const D t = 1.8 + selectLanes(signedUniform < 0.0, -e, e);
                const L valid = t > -0.6744;
                const D k = floorNonNegativeLanesD<W>(selectLanes(valid, h.mu + h.s * t, D{}));
                D fx, fy;
                pdModifiedNormalLanes<W>(h, k, fx, fy);
                const D lp = logPoissonProbabilityLanesD<W>(k, h.mu);
                const D absU = selectLanes(signedUniform < 0.0, -signedUniform, signedUniform);
                const L accept =
                    valid & (h.c * absU <= expClampedLanesD<W>(lp + e) - fy * expClampedLanesD<W>(fx + e));
                const int taken = maskBits(accept) & groupBits;
                for (int bits = taken; bits; bits &= bits - 1) {
                    const int i = lowestSetBit(static_cast<unsigned>(bits));
                    k8[gr * kLanes + i] = k[i];
                }
                pending &= ~(taken << (gr * kLanes));
            }
        }
        for (int i = 0; i < live; ++i)
            counts[list[start + i]] = k8[i];
    }
}

/* Steps N, I and S of PD for the values of a chunk whose bit is set in pdBits: g = mu + sqrt(mu) T,
 * K = floor(g), taken at once when K >= floor(mu - 1.1484) (there the Poisson probabilities exceed the
 * discrete normal's) or when 6 mu^2 u >= (mu - K)^3 (the squeeze); the rest (3% at a mean of 25, 0.4% at
 * 1000) are appended, with their g and u, for poissonPdRestLanes(). Counts of the other values are 0. */
template <int W>
RAWGMENT_KERNEL void pdFastStepsLanes(const uint32_t* words, const double* chunkMeans, int pdBits, int base,
                                      double* chunkCounts, int* rest, double* restG, double* restU,
                                      int& rests)
{
    typedef typename DoubleLanes<W>::D D;
    typedef typename DoubleLanes<W>::L L;
    typedef typename DoubleLanes<W>::UL UL;
    const int kLanes = DoubleLanes<W>::kCount, kChunk = 16;
    const int kGroups = kChunk / kLanes;
    alignas(64) double normals[kChunk];
    // Steps N, I and S of PD: g = mu + sqrt(mu) T, K = floor(g), taken at once when K >= floor(mu -
    // 1.1484) (there the Poisson probabilities exceed the discrete normal's) or when 6 mu^2 u >= (mu
    // - K)^3 (the squeeze); the rest (3% at a mean of 25, 0.4% at 1000) go to poissonPdRestLanes().
    for (int g = 0; g < kGroups / 2; ++g) {
        D c, s;
        normalPairsLanesD<W>(words + g * kLanes, words + 8 + g * kLanes, c, s);
        std::memcpy(normals + g * kLanes, &c, sizeof(c));
        std::memcpy(normals + 8 + g * kLanes, &s, sizeof(s));
    }
    for (int g = 0; g < kGroups; ++g) {
        const int bits = (pdBits >> (g * kLanes)) & ((1 << kLanes) - 1);
        if (!bits) {
            const D zero = {};
            std::memcpy(chunkCounts + g * kLanes, &zero, sizeof(zero));
            continue;
        }
        D m, t;
        typename DoubleLanes<W>::U32 w;
        std::memcpy(&m, chunkMeans + g * kLanes, sizeof(m));
        std::memcpy(&t, normals + g * kLanes, sizeof(t));
        std::memcpy(&w, words + kChunk + g * kLanes, sizeof(w));
        const L pd = (m >= kInversionBelow) & (m <= kMaxLaneMean);
        const D mu = selectLanes(pd, m, D{} + kInversionBelow); // other lanes compute on a valid mean, unused
        const D gv = mu + sqrtLanes(mu) * t;
        const D k = floorNonNegativeLanesD<W>(selectLanes(gv > 0.0, gv, D{}));
        const D u = uniform32LanesD<W>(convertLanes<UL>(w));
        const D dif = mu - k;
        const L taken = (gv >= 0.0) & ((k >= floorNonNegativeLanesD<W>(mu - 1.1484)) |
                                       (6.0 * mu * mu * u >= dif * dif * dif));
        const D kept = selectLanes(pd, k, D{}); // other lanes: 0, or their inversion's count later
        std::memcpy(chunkCounts + g * kLanes, &kept, sizeof(kept));
        // The rest (1-5%) rarely appear, so a branch costs less than appending every lane.
        for (int open = maskBits(~taken) & bits; open; open &= open - 1) {
            const int i = lowestSetBit(static_cast<unsigned>(open));
            rest[rests] = base + g * kLanes + i;
            restG[rests] = gv[i];
            restU[rests] = u[i];
            ++rests;
        }
    }
}

/* The small means of mixed chunks (their indices in invert), gathered into whole chunks and inverted with
 * each value's own word (in a row of means spread from 0 to 750, half the chunks have one). */
template <int W, int kGroups>
RAWGMENT_KERNEL void invertGatheredLanes(const double* means, const uint32_t* ownWords, const int* invert,
                                         int inverts, double* counts)
{
    const int kChunk = 16;
    alignas(64) double chunkMeans[kChunk], chunkCounts[kChunk];
    for (int start = 0; start < inverts; start += kChunk) {
        const int live = std::min(kChunk, inverts - start);
        alignas(64) uint32_t gatheredWords[kChunk];
        for (int i = 0; i < kChunk; ++i) {
            const int index = i < live ? invert[start + i] : -1; // padding lanes: mean 0, no count
            chunkMeans[i] = index >= 0 ? means[index] : 0.0;
            gatheredWords[i] = index >= 0 ? ownWords[static_cast<size_t>(index)] : 0u;
        }
        poissonInversionLanes<W, kGroups>(chunkMeans, gatheredWords, chunkCounts);
        for (int i = 0; i < live; ++i)
            counts[invert[start + i]] = chunkCounts[i];
    }
}

/* The words of a chunk of 16 values (8 Philox blocks, word j of block b at 8 j + b): pair p < 8 of
 * Box-Muller takes its radius from word p and its angle from word 8 + p, its cosine going to value p and its
 * sine to value 8 + p; value i's own uniform is word 16 + i. A value of mean 25 or more (PD) uses its normal
 * and its uniform; a smaller one (inversion) only its uniform. So each value's count depends on its own
 * words and mean alone, whatever its pair's mean, and the two normals of a pair are independent. */
template <int W>
RAWGMENT_KERNEL void fillPoissonKernel(uint64_t seed, uint64_t stream, const double* means, double* counts,
                                       int n)
{
    typedef typename DoubleLanes<W>::D D;
    const int kLanes = DoubleLanes<W>::kCount, kChunk = 16; // 16 values per 8 Philox blocks
    const int kGroups = kChunk / kLanes;
    alignas(64) uint32_t words[32];
    alignas(64) double chunkMeans[kChunk], chunkCounts[kChunk];
    const std::array<uint32_t, 2> key = {static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32)};
    // Every value's own word, kept for the gathered inversion; the values to invert, those PD's fast steps
    // left (with their g and u), and those beyond the lanes' range. Left uninitialised: only written
    // entries are read.
    const size_t room = static_cast<size_t>(n) + kChunk;
    const std::unique_ptr<uint32_t[]> ownWords(new uint32_t[room]);
    const std::unique_ptr<int[]> rest(new int[room]), invert(new int[room]), beyond(new int[room]);
    const std::unique_ptr<double[]> restG(new double[room]), restU(new double[room]);
    int rests = 0, inverts = 0, beyonds = 0;
    for (int base = 0; base < n; base += kChunk) {
        philox8BlocksFor<W>(static_cast<uint32_t>(base / 2), stream, key, words);
        std::memcpy(ownWords.get() + base, words + kChunk, sizeof(uint32_t) * kChunk);
        const int count = std::min(kChunk, n - base);
        if (count == kChunk) {
            for (int g = 0; g < kGroups; ++g) { // as the loop below, in lanes (NaN and negatives give 0)
                D m;
                std::memcpy(&m, means + base + g * kLanes, sizeof(m));
                m = selectLanes(m > 0.0, m, D{});
                std::memcpy(chunkMeans + g * kLanes, &m, sizeof(m));
            }
        } else {
            for (int i = 0; i < kChunk; ++i) {
                const double m = i < count ? means[base + i] : 0.0;
                chunkMeans[i] = m > 0 ? m : 0.0;
            }
        }
        // Bit i: value i's kind, from three masks per group and the live lanes once (with each group's live
        // lanes and four masks, this bookkeeping had cost 0.8 ns per value at a constant mean of 1e5).
        int smallBits = 0, positiveBits = 0, farBits = 0;
        for (int g = 0; g < kGroups; ++g) {
            D lambda;
            std::memcpy(&lambda, chunkMeans + g * kLanes, sizeof(lambda));
            smallBits |= maskBits(lambda < kInversionBelow) << (g * kLanes);
            positiveBits |= maskBits(lambda > 0.0) << (g * kLanes);
            farBits |= maskBits(lambda > kMaxLaneMean) << (g * kLanes);
        }
        const int liveBits = (1 << count) - 1;
        smallBits &= liveBits;
        const int invertBits = smallBits & positiveBits, pdBits = ~smallBits & ~farBits & liveBits,
                  beyondBits = farBits & liveBits;
        if (!pdBits) // a mean of 0 (or below, or NaN) gives 0
            for (int g = 0; g < kGroups; ++g) {
                const D zero = {};
                std::memcpy(chunkCounts + g * kLanes, &zero, sizeof(zero));
            }
        if (pdBits)
            pdFastStepsLanes<W>(words, chunkMeans, pdBits, base, chunkCounts, rest.get(), restG.get(),
                                restU.get(), rests);
        if (beyondBits)
            appendBits(beyondBits, kChunk, base, beyond.get(), beyonds);
        // A chunk of small means only (a dark region) is inverted in place; the small means of a mixed chunk
        // are gathered, so that one value's search does not hold up fifteen others of large means.
        if (smallBits == (1 << count) - 1)
            poissonInversionLanes<W, kGroups>(chunkMeans, words + kChunk, chunkCounts);
        else if (invertBits) // appendBits() writes every lane: skipped for the chunks without one
            appendBits(invertBits, kChunk, base, invert.get(), inverts);
        if (count == kChunk)
            std::memcpy(counts + base, chunkCounts, sizeof(chunkCounts));
        else
            std::memcpy(counts + base, chunkCounts, sizeof(double) * static_cast<size_t>(count));
    }
    invertGatheredLanes<W, kGroups>(means, ownWords.get(), invert.get(), inverts, counts);
    // PD's steps Q and E, and the means beyond the lanes' range, from each value's own stream
    // (poissonRetryKey(seed, stream), index).
    const uint64_t restKey = poissonRetryKey(seed, stream);
    poissonPdRestLanes<W>(restKey, means, rest.get(), restG.get(), restU.get(), rests, counts);
    for (int r = 0; r < beyonds; ++r) {
        const int index = beyond[r];
        CounterRng rng(restKey, static_cast<uint64_t>(index));
        counts[index] = static_cast<double>(rng.poisson(means[index]));
    }
}

/* logPoissonProbabilityLanesD() over arrays, for the test of its accuracy; the last partial vector on
 * padded copies. */
template <int W>
RAWGMENT_KERNEL void logPoissonProbabilitiesKernel(const double* ks, const double* mus, double* out, int n)
{
    typedef typename DoubleLanes<W>::D D;
    const int kLanes = DoubleLanes<W>::kCount;
    for (int i = 0; i < n; i += kLanes) {
        alignas(64) double k[kLanes], mu[kLanes], lp[kLanes];
        for (int j = 0; j < kLanes; ++j) {
            k[j] = i + j < n ? ks[i + j] : 1.0;
            mu[j] = i + j < n ? mus[i + j] : kInversionBelow;
        }
        D kv, muv;
        std::memcpy(&kv, k, sizeof(kv));
        std::memcpy(&muv, mu, sizeof(muv));
        const D r = logPoissonProbabilityLanesD<W>(kv, muv);
        std::memcpy(lp, &r, sizeof(r));
        for (int j = 0; j < kLanes && i + j < n; ++j)
            out[i + j] = lp[j];
    }
}

} // namespace

RAWGMENT_DISPATCHED_BY_WIDTH(void, logPoissonProbabilities,
                             (const double* ks, const double* mus, double* out, int n), (ks, mus, out, n))
RAWGMENT_DISPATCHED_BY_WIDTH(void, fillPoisson,
                             (uint64_t seed, uint64_t stream, const double* means, double* counts, int n),
                             (seed, stream, means, counts, n))

} // namespace detail
} // namespace rawgment
} // namespace cv
