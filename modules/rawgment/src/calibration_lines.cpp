// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The calibration topic's per-gain lines (fitNoiseLine): RANSAC inside a chi-square band of each sample's
// variance, then weighted least squares; the band and sample helpers the cross-gain fit shares are in
// calibration_lines.hpp.
#include "calibration_lines.hpp"
#include "calibration_uncertainty.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <opencv2/rawgment/calibration.hpp>

#include <algorithm>
#include <map>
#include <mutex>
#include <numeric>
#include <set>

namespace cv {
namespace rawgment {

using detail::checkSamples;
using detail::inliersOf;
using detail::kMaxExcessKurtosis;
using detail::kMinExcessKurtosis;
using detail::lineVarianceFloor;
using detail::MeanRange;
using detail::meanRangeOf;

namespace {

struct LineLS
{
    double a = 0, b = 0, r2 = 0;
};

//! The ordinary R^2 of the line (a, b) over the selected samples.
double ordinaryRSquared(const std::vector<NoiseSample>& s, const std::vector<int>& idx, double a, double b)
{
    double mean = 0;
    for (int i : idx)
        mean += s[i].variance;
    mean /= static_cast<double>(idx.size());
    double ssRes = 0, ssTot = 0;
    for (int i : idx) {
        const double e = s[i].variance - (a * s[i].mean + b);
        ssRes += e * e;
        ssTot += (s[i].variance - mean) * (s[i].variance - mean);
    }
    return ssTot > 0 ? 1.0 - ssRes / ssTot : 1.0;
}

/** Ordinary least squares of v on mu over the selected samples, then iterated weighted least squares
 * from it (refineNoiseLine(): a sample variance of `dof` degrees of freedom has variance 2 v^2 / dof
 * around its expectation v, so each sample is weighted by dof / (2 v^2), Fisher scoring for the Gamma
 * likelihood of sample variances). Unlike ordinary least squares, the many precise dark samples then pin
 * the offset instead of the few noisy bright ones. False when the means do not vary. */
bool weightedNoiseLine(const std::vector<NoiseSample>& s, const std::vector<int>& idx, double readKurtosis,
                       LineLS& out)
{
    if (idx.size() < 2)
        return false;
    double mx = 0, my = 0;
    for (int i : idx) {
        mx += s[i].mean;
        my += s[i].variance;
    }
    const double n = static_cast<double>(idx.size());
    mx /= n;
    my /= n;
    double sxx = 0, sxy = 0;
    for (int i : idx) {
        const double dx = s[i].mean - mx;
        sxx += dx * dx;
        sxy += dx * (s[i].variance - my);
    }
    if (!(sxx > 1e-12 * std::max(1.0, mx * mx) * n))
        return false;
    std::vector<NoiseSample> chosen;
    chosen.reserve(idx.size());
    for (int i : idx)
        chosen.push_back(s[i]);
    const Vec2d ab = detail::refineNoiseLine(chosen.data(), nullptr, static_cast<int>(chosen.size()),
                                             Vec2d(sxy / sxx, my - sxy / sxx * mx), 4, readKurtosis);
    out.a = ab[0];
    out.b = ab[1];
    out.r2 = ordinaryRSquared(s, idx, out.a, out.b);
    return true;
}

const int kRansacScoringSamples = 4096;

/* The regularised lower incomplete gamma function P(a, x): its series below x = a + 1 and Lentz's
 * continued fraction for the upper part above, each to double precision. */
double lowerGammaRegularized(double a, double x)
{
    if (x <= 0)
        return 0.0;
    const double logPrefix = -x + a * std::log(x) - std::lgamma(a);
    if (x < a + 1) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 1000 && term > sum * 1e-17; ++n) {
            term *= x / (a + n);
            sum += term;
        }
        return std::min(1.0, sum * std::exp(logPrefix));
    }
    const double tiny = 1e-300;
    double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
    for (int i = 1; i < 1000; ++i) {
        const double an = -i * (i - a);
        b += 2;
        d = an * d + b;
        d = std::abs(d) < tiny ? tiny : d;
        c = b + an / c;
        c = std::abs(c) < tiny ? tiny : c;
        d = 1 / d;
        const double step = d * c;
        h *= step;
        if (std::abs(step - 1) < 1e-16)
            break;
    }
    return std::max(0.0, 1.0 - std::exp(logPrefix) * h);
}

//! The chi-square quantile of `dof` (> 0, not necessarily whole) degrees of freedom at probability p, by
//! bisection on log q.
double chiSquareQuantile(double dof, double p)
{
    double lo = std::log(1e-40), hi = std::log(100.0 * dof + 1000.0);
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (lowerGammaRegularized(0.5 * dof, 0.5 * std::exp(mid)) < p ? lo : hi) = mid;
    }
    return std::exp(0.5 * (lo + hi));
}

/* Where a sample variance of `dof` degrees of freedom lies, relative to its expectation, with the
 * probability that a normal variable has within +-k: [chi2(p), chi2(1 - p)] / dof with p = Phi(-k).
 * A band of +-k standard errors would be lopsided, because a sample variance is skewed: at 15 degrees of
 * freedom it never reaches -k = -4 (a variance of 0 is -2.7 standard errors) but exceeds +4 once in
 * 750 samples, so it kept every dead or stuck pixel and cut only the high tail, which biased alpha
 * low by 2-3 of its standard errors. Equal probability in both tails removes 2 Phi(-k) of the samples
 * and shifts the mean of the rest by a few parts in 10^5.
 * Heavy tails (read noise of excess kurtosis kappa, and the Poisson part at low counts) spread a sample
 * variance further: each sample's band is that of the scaled chi-square with its effectiveDof(), so that
 * the band does not trim the tails it should keep (a Gaussian band left sigma_d^2 4-8 standard errors low
 * and called 1.6% of the pixels defects at lambda -0.05). Bands are cached by (effective dof to 0.5%, k). */
struct ChiSquareBand
{
    double lo = 0, hi = 0;
};

//! The cache key of a band: its effective dof to 0.5%.
int64 bandKey(double dof)
{
    return static_cast<int64>(std::llround(std::log(std::max(dof, 0.5)) * 200));
}

ChiSquareBand chiSquareBandOfKey(int64 key, double k)
{
    static std::mutex mutex;
    static std::map<std::pair<int64, double>, ChiSquareBand> cache;
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(std::make_pair(key, k));
    if (it != cache.end())
        return it->second;
    const double d = std::exp(static_cast<double>(key) / 200);
    const double p = 0.5 * std::erfc(k / std::sqrt(2.0));
    ChiSquareBand band;
    band.lo = chiSquareQuantile(d, p) / d;
    band.hi = chiSquareQuantile(d, 1 - p) / d;
    cache.emplace(std::make_pair(key, k), band);
    return band;
}

/* The high edge that one extreme read value alone reaches with the band's probability: a sample variance
 * of heavy-tailed data has a far longer right tail than the scaled chi-square of the same spread, because one
 * value can carry it (at lambda -0.05 and 16 frames, 20 times the nominal share lay above that chi-square's
 * edge, and cutting them took 0.29% from the mean variance). With the read noise's shape taken as the
 * Tukey-lambda of its kurtosis, the standardised value exceeded by one of n frames with probability p is
 * y = Q(1 - p / (2n)) / sd; in a sample of read share r = b / v it makes the sample variance about
 * (r y^2 + (1 - r) + n - 2) / (n - 1) times its expectation. Each band's high edge is the larger of the two
 * (the chi-square's for Gaussian or lighter tails, where one value cannot carry it). Returns y (0 when the
 * read noise is not heavy-tailed). */
double extremeReadValue(double readKurtosis, int frames, double k)
{
    if (!(readKurtosis > 0))
        return 0.0;
    const double lambda = detail::tukeyLambdaOfExcessKurtosis(readKurtosis);
    const double p = 0.5 * std::erfc(k / std::sqrt(2.0));
    return detail::tukeyLambdaQuantile(1 - p / (2.0 * frames), lambda) /
           std::sqrt(detail::tukeyLambdaVariance(lambda));
}

//! The band of each sample around the line (a, b) (see ChiSquareBand and extremeReadValue()).
std::vector<ChiSquareBand> bandsOf(const std::vector<NoiseSample>& s, double k, double a, double b,
                                   double floor, double readKurtosis)
{
    std::vector<ChiSquareBand> bands(s.size());
    std::map<int, double> extreme; // by dof
    std::map<int64, ChiSquareBand>
        known; // by bandKey(): the shared cache's lock once per key, not per sample
    for (size_t i = 0; i < s.size(); ++i) {
        const double v = std::max(detail::lineVariance(a, b, s[i].mean), floor);
        const int dof = std::max(s[i].dof, 1);
        const int64 key = bandKey(
            detail::effectiveDof(v, dof, floor, detail::pixelFourthCumulant(a, b, s[i].mean, readKurtosis)));
        auto band = known.find(key);
        if (band == known.end())
            band = known.emplace(key, chiSquareBandOfKey(key, k)).first;
        bands[i] = band->second;
        auto it = extreme.find(dof);
        if (it == extreme.end())
            it = extreme.emplace(dof, extremeReadValue(readKurtosis, dof + 1, k)).first;
        if (it->second > 0) {
            const double share = std::min(std::max(b / v, 0.0), 1.0), y = it->second;
            bands[i].hi = std::max(bands[i].hi, (share * y * y + (1 - share) + dof - 1) / dof);
        }
    }
    return bands;
}

/** Whether a sample's variance lies inside its band around the line at its mean. A sample of two frames
 * (dof 1) is the half square of an integer difference d, and 0 whenever the two readings tie: at 3 DN of
 * noise that is 9% of all pixels, far more than the chi-square's lower tail (the band's edge) allows for a
 * continuous variable. Dropping the ties biased the fit of two-frame steps up (set 001: the read variance
 * 10%, K 2.6%). Its lower edge is therefore taken with a continuity correction, (|d| + 1/2)^2 / 2: a tie
 * counts as the cell [0, 1/2) of the lattice it lives on. */
bool insideBand(const NoiseSample& s, const ChiSquareBand& band, double a, double b, double floor)
{
    const double predicted = std::max(detail::lineVariance(a, b, s.mean), floor);
    const double lowSide = s.dof == 1 ? 0.5 * std::pow(std::sqrt(2 * s.variance) + 0.5, 2) : s.variance;
    return lowSide >= band.lo * predicted && s.variance <= band.hi * predicted;
}

} // namespace

namespace detail {

MeanRange meanRangeOf(const std::vector<NoiseSample>& s)
{
    MeanRange r{s.front().mean, s.front().mean};
    for (const NoiseSample& x : s) {
        r.lo = std::min(r.lo, x.mean);
        r.hi = std::max(r.hi, x.mean);
    }
    return r;
}

//! varianceFloor() of a line over samples whose means span `range` (a line peaks at an end).
double lineVarianceFloor(double a, double b, const MeanRange& range)
{
    return detail::varianceFloor(
        std::max(detail::lineVariance(a, b, range.lo), detail::lineVariance(a, b, range.hi)));
}

std::vector<int> inliersOf(const std::vector<NoiseSample>& s, double a, double b, double threshold,
                           double readKurtosis)
{
    const double floor = lineVarianceFloor(a, b, meanRangeOf(s));
    const std::vector<ChiSquareBand> bands = bandsOf(s, threshold, a, b, floor, readKurtosis);
    std::vector<int> idx;
    for (int i = 0; i < static_cast<int>(s.size()); ++i)
        if (insideBand(s[i], bands[i], a, b, floor))
            idx.push_back(i);
    return idx;
}

void checkSamples(const std::vector<NoiseSample>& samples, const char* who)
{
    for (size_t i = 0; i < samples.size(); ++i) {
        const NoiseSample& s = samples[i];
        if (!std::isfinite(s.mean) || !std::isfinite(s.variance) || !std::isfinite(s.gain) || !(s.gain > 0) ||
            s.variance < 0 || s.dof < 1)
            CV_Error(Error::StsBadArg,
                     format("%s: sample %d is invalid (mean %g, variance %g, gain %g, dof %d): "
                            "values must be finite, variance >= 0, gain > 0, dof >= 1",
                            who, static_cast<int>(i), s.mean, s.variance, s.gain, s.dof));
    }
}

} // namespace detail

NoiseLineFit fitNoiseLine(const std::vector<NoiseSample>& samples, const LineFitParams& params)
{
    if (samples.size() < 2)
        CV_Error(Error::StsBadArg,
                 format("fitNoiseLine: needs at least 2 samples (got %d)", static_cast<int>(samples.size())));
    checkSamples(samples, "fitNoiseLine");
    for (const NoiseSample& s : samples)
        if (s.gain != samples[0].gain)
            CV_Error(Error::StsBadArg,
                     format("fitNoiseLine: samples of gains %g and %g; fit one gain at a time",
                            samples[0].gain, s.gain));
    if (params.ransacIterations < 1 || !(params.inlierThreshold > 0))
        CV_Error(Error::StsBadArg, "fitNoiseLine: ransacIterations must be >= 1 and inlierThreshold > 0");
    if (!(params.readExcessKurtosis >= kMinExcessKurtosis && params.readExcessKurtosis <= kMaxExcessKurtosis))
        CV_Error(Error::StsBadArg, format("fitNoiseLine: readExcessKurtosis must lie in [%g, %g] (got %g)",
                                          kMinExcessKurtosis, kMaxExcessKurtosis, params.readExcessKurtosis));
    const double kurtosis = params.readExcessKurtosis;
    NoiseLineFit fit;
    fit.gain = samples[0].gain;
    fit.samples = static_cast<int>(samples.size());
    std::vector<int> all(samples.size());
    std::iota(all.begin(), all.end(), 0);
    LineLS ls;
    if (!weightedNoiseLine(samples, all, kurtosis, ls))
        CV_Error(Error::StsBadArg, "fitNoiseLine: all samples share one mean; the slope needs at least two "
                                   "distinct means");
    std::vector<int> chosen = all;
    if (params.robust) {
        const int n = static_cast<int>(samples.size());
        const MeanRange range = meanRangeOf(samples);
        // Each sample's band from the least-squares line: the hypotheses are only scored with it.
        const std::vector<ChiSquareBand> bands = bandsOf(samples, params.inlierThreshold, ls.a, ls.b,
                                                         lineVarianceFloor(ls.a, ls.b, range), kurtosis);
        /* Each hypothesis is scored on at most kRansacScoringSamples samples spread evenly over the list
         * (which follows the patches and the frame): its inlier share is then known to 0.8% at worst,
         * enough to pick a line whose inliers the refinement below then takes from every sample, and a
         * chartless burst of 10^5 samples per gain no longer costs 500 x 10^5 band tests. */
        const int scored = std::min(n, kRansacScoringSamples);
        std::vector<int> scoring(static_cast<size_t>(scored));
        for (int m = 0; m < scored; ++m)
            scoring[static_cast<size_t>(m)] = static_cast<int>(static_cast<int64>(m) * n / scored);
        size_t bestCount = 0;
        double bestA = ls.a, bestB = ls.b;
        for (int it = 0; it < params.ransacIterations; ++it) {
            detail::CounterRng rng(params.seed, detail::ransacStream(it));
            const int i = static_cast<int>(rng.nextU32() % static_cast<uint32_t>(n));
            const int j = static_cast<int>(rng.nextU32() % static_cast<uint32_t>(n));
            const double dm = samples[j].mean - samples[i].mean;
            if (std::abs(dm) < 1e-9)
                continue;
            const double a = (samples[j].variance - samples[i].variance) / dm;
            const double b = samples[i].variance - a * samples[i].mean;
            const double floor = lineVarianceFloor(a, b, range);
            size_t count = 0;
            for (int k : scoring)
                count += insideBand(samples[k], bands[k], a, b, floor) ? 1 : 0;
            if (count > bestCount) {
                bestCount = count;
                bestA = a;
                bestB = b;
            }
        }
        // Refine: least squares on the inliers, then once more on the inliers of the refined line.
        for (int round = 0; round < 2; ++round) {
            std::vector<int> inl = inliersOf(samples, bestA, bestB, params.inlierThreshold, kurtosis);
            LineLS refined;
            if (!weightedNoiseLine(samples, inl, kurtosis, refined))
                break;
            chosen.swap(inl);
            ls = refined;
            bestA = ls.a;
            bestB = ls.b;
        }
    }
    fit.line.a = ls.a;
    fit.line.b = ls.b;
    fit.rSquared = ls.r2;
    fit.inliers = static_cast<int>(chosen.size());
    Matx22d cov;
    if (detail::lineCovariance(samples, chosen, ls.a, ls.b, kurtosis, cov)) {
        fit.slopeStdError = std::sqrt(cov(0, 0));
        fit.offsetStdError = std::sqrt(cov(1, 1));
        const double d = fit.slopeStdError * fit.offsetStdError;
        fit.slopeOffsetCorrelation = d > 0 ? cov(0, 1) / d : 0.0;
    }
    return fit;
}

} // namespace rawgment
} // namespace cv
