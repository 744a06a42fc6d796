// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/calibration.hpp"
#include "calibration_uncertainty.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <map>
#include <mutex>
#include <numeric>
#include <set>

namespace cv {
namespace rawgment {

// Per-gain line fits, the cross-gain fit of the noise model, and the calibration report.

// ---------------------------------------------------------------------------------------------------
// Per-gain line

namespace {

// Every distribution has excess kurtosis >= -2; above 1000 no sensor's read noise lies (Tukey lambda -0.2,
// the heaviest NoiseModel takes, has 19).
const double kMinExcessKurtosis = -2, kMaxExcessKurtosis = 1000;

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

//! The lowest and highest mean of a set of samples: where a line's largest prediction lies.
struct MeanRange
{
    double lo = 0, hi = 0;
};

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

//! Whether a sample's variance lies inside its band around the line at its mean.
bool insideBand(const NoiseSample& s, const ChiSquareBand& band, double a, double b, double floor)
{
    const double predicted = std::max(detail::lineVariance(a, b, s.mean), floor);
    return s.variance >= band.lo * predicted && s.variance <= band.hi * predicted;
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

} // namespace

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

// ---------------------------------------------------------------------------------------------------
// Cross-gain fits

namespace {

//! b_g = g^2 sigma_d^2 + sigma_r^2 (paper Eq. 8).
struct OffsetResidual
{
    OffsetResidual(double gain, double offset) : g(gain), b(offset) {}
    template <typename T> bool operator()(const T* sigmaD2, const T* sigmaR2, T* r) const
    {
        r[0] = T(b) - detail::noiseTermsAt(T(g), T(0), sigmaD2[0], sigmaR2[0]).read();
        return true;
    }
    static ceres::CostFunction* Create(double gain, double offset)
    {
        return new ceres::AutoDiffCostFunction<OffsetResidual, 1, 1, 1>(new OffsetResidual(gain, offset));
    }
    double g, b;
};

ceres::Solver::Options solverOptions()
{
    ceres::Solver::Options o;
    o.logging_type = ceres::SILENT;
    o.minimizer_progress_to_stdout = false;
    o.linear_solver_type = ceres::DENSE_QR;
    o.max_num_iterations = 200;
    o.function_tolerance = 1e-14;
    o.gradient_tolerance = 1e-14;
    o.parameter_tolerance = 1e-12;
    o.num_threads = 1; // the problems are tiny; one thread keeps results reproducible
    return o;
}

double rSquared(const std::vector<double>& y, const std::vector<double>& fit)
{
    double mean = 0;
    for (double v : y)
        mean += v;
    mean /= y.size();
    double ssTot = 0, ssRes = 0;
    for (size_t i = 0; i < y.size(); ++i) {
        ssTot += (y[i] - mean) * (y[i] - mean);
        ssRes += (y[i] - fit[i]) * (y[i] - fit[i]);
    }
    return ssTot > 0 ? 1.0 - ssRes / ssTot : (ssRes == 0 ? 1.0 : 0.0);
}

//! Two-stage offsets: sigma_d^2, sigma_r^2 >= 0 from (g, b_g) by bounded least squares.
void fitOffsets(const std::vector<NoiseLineFit>& lines, double& sigmaD2, double& sigmaR2)
{
    // Start from the unbounded solution clipped to the bounds.
    double sxx = 0, sx = 0, sy = 0, sxy = 0;
    for (const NoiseLineFit& f : lines) {
        const double x = f.gain * f.gain;
        sxx += x * x;
        sx += x;
        sy += f.line.b;
        sxy += x * f.line.b;
    }
    const double n = static_cast<double>(lines.size());
    const double det = n * sxx - sx * sx;
    sigmaD2 = std::max(0.0, det > 0 ? (n * sxy - sx * sy) / det : 0.0);
    sigmaR2 = std::max(0.0, (sy - sigmaD2 * sx) / n);
    ceres::Problem problem;
    for (const NoiseLineFit& f : lines)
        problem.AddResidualBlock(OffsetResidual::Create(f.gain, f.line.b), nullptr, &sigmaD2, &sigmaR2);
    problem.SetParameterLowerBound(&sigmaD2, 0, 0.0);
    problem.SetParameterLowerBound(&sigmaR2, 0, 0.0);
    ceres::Solver::Summary summary;
    ceres::Solve(solverOptions(), &problem, &summary);
    if (!summary.IsSolutionUsable())
        CV_Error(Error::StsError, "calibrateNoiseModel: the offset fit failed: " + summary.BriefReport());
}

/* The read noise's excess kurtosis kappa from the spread of the sample variances around their gain's
 * line, by the method of moments: for a sample of ratio u = s^2 / v to its line and n = dof + 1 frames,
 * E[(u - 1)^2] = 2 / dof + (kappa w + c) / n with w = b^2 / v^2 (the read part's share of the variance,
 * squared) and c = a^3 mu / v^2 (the Poisson part), so y = n ((u - 1)^2 - 2 / dof) - c has mean kappa w
 * and kappa is the least-squares slope of y on w. A fourth moment is fragile to defects, so: a pixel whose
 * median ratio over its bursts lies outside [0.5, 2] (a noisy, hot, dead or stuck pixel: a normal one's
 * median over 3 or more bursts of 16 frames lies there but once in 10^5) and a pixel with two or more
 * read-dominated samples above 3 (a noisy pixel) are left out, and ratios more than 20 of their own
 * standard errors (at the current kappa, held at most 19) above 1 are cut (a hot or noisy pixel in a dark
 * burst), which leaves 0.6% of kappa out at lambda -0.05 and 3% at -0.1 (8 left 7% and 18%). Returns
 * false, with the reason, when the read part is too small a share of too few samples (sum of w^2 below 50) to
 * tell. */
bool estimateReadKurtosis(const std::map<double, std::vector<NoiseSample>>& byGain,
                          const std::vector<NoiseLineFit>& lines, double& kappa, std::string& why)
{
    struct Ratio
    {
        double u, w, c, n;
        int dof;
        int64 pixel;
    };
    std::vector<Ratio> ratios;
    size_t g = 0;
    for (const auto& entry : byGain) {
        const NoiseLine& line = lines[g++].line;
        const double a = std::max(line.a, 0.0), b = std::max(line.b, 0.0);
        const double floor = lineVarianceFloor(a, b, meanRangeOf(entry.second));
        for (const NoiseSample& x : entry.second) {
            const double v = std::max(detail::lineVariance(a, b, x.mean), floor);
            const int dof = std::max(x.dof, 1);
            ratios.push_back({x.variance / v, b * b / (v * v), a * a * a * std::max(x.mean, 0.0) / (v * v),
                              dof + 1.0, dof, x.pixel});
        }
    }
    std::map<int64, std::vector<double>> byPixel;
    std::map<int64, int> highReadRatios; // read-dominated samples more than 3 times their line
    for (const Ratio& r : ratios)
        if (r.pixel >= 0) {
            byPixel[r.pixel].push_back(r.u);
            if (r.w >= 0.25 && r.u > 3)
                ++highReadRatios[r.pixel];
        }
    std::set<int64> defects;
    for (auto& entry : byPixel) {
        std::vector<double>& u = entry.second;
        if (u.size() < 3)
            continue;
        std::nth_element(u.begin(), u.begin() + long(u.size() / 2), u.end());
        const double median = u[u.size() / 2];
        if (median < 0.5 || median > 2)
            defects.insert(entry.first);
    }
    /* A noisy pixel (extra variance of its own) stands out only where the read noise dominates, so the
     * median over every burst misses it, and its few dark samples would each look like a heavy tail.
     * What tells it from a tail is that it stands out in more than one such burst: a pixel with two or
     * more read-dominated samples above 3 times their line is a defect here. A normal pixel with three such
     * samples does that with probability 3 P(u > 3)^2: 1e-8 for Gaussian noise, 3e-4 at lambda -0.1. */
    for (const auto& entry : highReadRatios)
        if (entry.second >= 2)
            defects.insert(entry.first);
    kappa = 0;
    for (int iteration = 0; iteration < 20; ++iteration) {
        double sww = 0, swy = 0;
        for (const Ratio& r : ratios) {
            if (r.pixel >= 0 && defects.count(r.pixel))
                continue;
            // The cut's kappa is held at 19 (Tukey lambda -0.2, the heaviest tail a NoiseModel takes), so
            // that defects the rules above miss cannot widen the cut that lets them in.
            const double se =
                std::sqrt(std::max(2.0 / r.dof + (std::min(kappa, 19.0) * r.w + r.c) / r.n, 1e-12));
            if (r.u - 1 > 20 * se)
                continue;
            const double y = r.n * ((r.u - 1) * (r.u - 1) - 2.0 / r.dof) - r.c;
            sww += r.w * r.w;
            swy += r.w * y;
        }
        if (sww < 50) {
            why = format("too few samples where read noise dominates (sum of its squared share %.3g, 50 "
                         "needed: dark frames or dark patches give them)",
                         sww);
            kappa = 0;
            return false;
        }
        if (!std::isfinite(swy / sww)) {
            why = "the spread of the sample variances is not finite";
            kappa = 0;
            return false;
        }
        const double next = std::min(std::max(swy / sww, kMinExcessKurtosis), kMaxExcessKurtosis);
        const bool converged = std::abs(next - kappa) < 1e-4;
        kappa = next;
        if (converged)
            break;
    }
    return true;
}

} // namespace

CalibrationReport calibrateNoiseModel(const std::vector<NoiseSample>& samples,
                                      const CalibrationParams& params)
{
    if (samples.empty())
        CV_Error(Error::StsBadArg, "calibrateNoiseModel: no samples (all pixels clipped, or no patches?)");
    checkSamples(samples, "calibrateNoiseModel");
    if (params.method != NOISE_FIT_JOINT && params.method != NOISE_FIT_TWO_STAGE)
        CV_Error(Error::StsBadArg,
                 format("calibrateNoiseModel: unknown method %d", static_cast<int>(params.method)));
    if (!(params.lossScale >= 0) || params.reweightIterations < 1 || !(params.minGainRatio >= 1) ||
        params.bootstrapReplicates < 0 || params.bootstrapReplicates == 1)
        CV_Error(Error::StsBadArg, "calibrateNoiseModel: lossScale must be >= 0, reweightIterations >= 1, "
                                   "minGainRatio >= 1, bootstrapReplicates 0 or >= 2");
    const bool kurtosisGiven = !std::isnan(params.readExcessKurtosis);
    if (kurtosisGiven &&
        !(params.readExcessKurtosis >= kMinExcessKurtosis && params.readExcessKurtosis <= kMaxExcessKurtosis))
        CV_Error(
            Error::StsBadArg,
            format("calibrateNoiseModel: readExcessKurtosis must be NaN (estimate it) or lie in [%g, %g] "
                   "(got %g)",
                   kMinExcessKurtosis, kMaxExcessKurtosis, params.readExcessKurtosis));
    CalibrationReport report;
    report.method = params.method;
    report.samples = static_cast<int>(samples.size());

    std::map<double, std::vector<NoiseSample>> byGain;
    for (const NoiseSample& s : samples)
        byGain[s.gain].push_back(s);
    std::vector<NoiseSample> inlierSamples;
    std::vector<detail::GainGroup> groups;
    std::set<int64> outlierPixels; // pixels outside the band of their gain's line in some burst
    LineFitParams lineParams = params.line;
    lineParams.readExcessKurtosis = kurtosisGiven ? params.readExcessKurtosis : 0.0;
    const auto fitEachGain = [&]() {
        report.perGain.clear();
        inlierSamples.clear();
        groups.clear();
        for (auto& entry : byGain) {
            NoiseLineFit fit;
            try {
                fit = fitNoiseLine(entry.second, lineParams);
            } catch (const Exception& e) {
                CV_Error(Error::StsBadArg, format("calibrateNoiseModel: gain %g: ", entry.first) + e.err);
            }
            report.perGain.push_back(fit);
            detail::GainGroup group;
            group.begin = static_cast<int>(inlierSamples.size());
            if (params.line.robust) {
                const std::vector<int> in =
                    inliersOf(entry.second, fit.line.a, fit.line.b, params.line.inlierThreshold,
                              lineParams.readExcessKurtosis);
                std::vector<bool> kept(entry.second.size(), false);
                for (int i : in) {
                    inlierSamples.push_back(entry.second[i]);
                    kept[i] = true;
                }
                for (size_t i = 0; i < kept.size(); ++i)
                    if (!kept[i] && entry.second[i].pixel >= 0)
                        outlierPixels.insert(entry.second[i].pixel);
            } else {
                inlierSamples.insert(inlierSamples.end(), entry.second.begin(), entry.second.end());
            }
            group.end = static_cast<int>(inlierSamples.size());
            groups.push_back(group);
        }
    };
    fitEachGain();
    /* Without a given kurtosis, it is estimated from the lines' residuals and the lines are fitted again
     * with bands of that spread (twice: the first lines were cut with Gaussian bands). */
    if (!kurtosisGiven) {
        std::string why;
        for (int round = 0; round < 2; ++round) {
            double kappa = 0;
            if (!estimateReadKurtosis(byGain, report.perGain, kappa, why))
                break;
            report.readExcessKurtosisEstimated = true;
            if (std::abs(kappa - lineParams.readExcessKurtosis) < 1e-3)
                break;
            lineParams.readExcessKurtosis = kappa;
            outlierPixels.clear();
            fitEachGain();
        }
        if (!report.readExcessKurtosisEstimated)
            report.notes.push_back("the read noise's excess kurtosis could not be estimated, " + why +
                                   ": the fit takes it as 0 (Gaussian); give CalibrationParams::"
                                   "readExcessKurtosis (for example from dark frames) if the read noise has "
                                   "heavier tails");
    }
    report.readExcessKurtosis = lineParams.readExcessKurtosis;
    /* A noisy pixel (random telegraph noise) or a stuck one is the same pixel in every burst, but it stands
     * out of the noise band only where the normal noise is small (dark patches, dark frames, low gains);
     * in bright patches its extra variance hides inside the band, and kept there it biases the lines
     * where it hides and not where it was cut (5% such pixels moved alpha by 2-3 standard errors). So a
     * pixel outside the band in any burst is left out of every burst, as a defect map would, unless so
     * many are that the lines themselves must be wrong. Normal pixels leave the band by chance in
     * 2 Phi(-k) of bursts; that only costs samples, since their bursts are independent. */
    if (!outlierPixels.empty()) {
        std::set<int64> pixels;
        for (const NoiseSample& s : samples)
            if (s.pixel >= 0)
                pixels.insert(s.pixel);
        // The count before the refit: the refit's own outliers are not left out again.
        const int leftOut = static_cast<int>(outlierPixels.size());
        if (outlierPixels.size() <= pixels.size() / 5) {
            for (auto& entry : byGain) {
                std::vector<NoiseSample>& v = entry.second;
                v.erase(
                    std::remove_if(v.begin(), v.end(),
                                   [&](const NoiseSample& x) { return outlierPixels.count(x.pixel) > 0; }),
                    v.end());
                if (v.size() < 2)
                    CV_Error(Error::StsBadArg,
                             format("calibrateNoiseModel: gain %g: fewer than 2 samples are left once the "
                                    "pixels outside the noise band in any burst are left out",
                                    entry.first));
            }
            fitEachGain();
            report.notes.push_back(
                format("%d of %d pixels lay outside the noise band in at least one burst "
                       "(a band as wide as read noise of excess kurtosis %.3g makes it) "
                       "and were left out of every burst, as noisy, hot or stuck pixels "
                       "would be; normal pixels leave it by chance in %.2g of their bursts",
                       leftOut, static_cast<int>(pixels.size()), report.readExcessKurtosis,
                       std::erfc(params.line.inlierThreshold / std::sqrt(2.0))));
        } else {
            report.notes.push_back(
                format("%d of %d pixels lay outside the noise band in at least one burst: too "
                       "many to be defects, so each was left out only where it was outside",
                       leftOut, static_cast<int>(pixels.size())));
        }
    }
    for (const NoiseLineFit& fit : report.perGain)
        if (fit.line.a < 0 || fit.line.b < 0)
            report.notes.push_back(
                format("gain %g: the line has a negative %s (a = %g, b = %g); the data do not "
                       "follow the model there",
                       fit.gain, fit.line.a < 0 ? "slope" : "offset", fit.line.a, fit.line.b));

    // alpha from a_g = g alpha (least squares through the origin, non-negative).
    double sga = 0, sgg = 0;
    for (const NoiseLineFit& f : report.perGain) {
        sga += f.gain * f.line.a;
        sgg += f.gain * f.gain;
    }
    double alpha = std::max(0.0, sga / sgg);
    const double gainRatio = report.perGain.back().gain / report.perGain.front().gain;
    report.separable = report.perGain.size() >= 2 && gainRatio >= params.minGainRatio;
    if (!report.separable) {
        report.notes.push_back(format("sigma_d^2 and sigma_r^2 are not separable: %s; only alpha is reported "
                                      "(the offset of each gain is in its line)",
                                      report.perGain.size() < 2
                                          ? "a single gain was calibrated"
                                          : "the gains differ by less than minGainRatio"));
        report.model = NoiseModel(alpha, 0.0, 0.0);
        report.samplesUsed = static_cast<int>(inlierSamples.size());
        report.uncertainty = detail::modelUncertainty(inlierSamples, groups, report, params, report.notes);
        return report;
    }
    double sigmaD2 = 0, sigmaR2 = 0;
    fitOffsets(report.perGain, sigmaD2, sigmaR2);

    if (params.method == NOISE_FIT_JOINT) {
        const Vec3d p =
            detail::refineJointFit(inlierSamples.data(), nullptr, static_cast<int>(inlierSamples.size()),
                                   Vec3d(alpha, sigmaD2, sigmaR2), params.lossScale, params.line.robust,
                                   params.reweightIterations, report.readExcessKurtosis);
        alpha = p[0];
        sigmaD2 = p[1];
        sigmaR2 = p[2];
    }
    report.model = NoiseModel(alpha, sigmaD2, sigmaR2);
    report.samplesUsed = static_cast<int>(inlierSamples.size());
    const char* names[3] = {"alpha", "sigma_d^2", "sigma_r^2"};
    const double values[3] = {alpha, sigmaD2, sigmaR2};
    for (int k = 0; k < 3; ++k)
        if (values[k] == 0)
            report.notes.push_back(std::string(names[k]) +
                                   " is at its lower bound 0: the data cannot tell it from 0");

    std::vector<double> a, aFit, b, bFit;
    for (const NoiseLineFit& f : report.perGain) {
        a.push_back(f.line.a);
        const detail::NoiseTerms<double> t = detail::noiseTermsAt(f.gain, alpha, sigmaD2, sigmaR2);
        aFit.push_back(t.shot);
        b.push_back(f.line.b);
        bFit.push_back(t.read());
    }
    report.rSquaredSlope = rSquared(a, aFit);
    report.rSquaredOffset = rSquared(b, bFit);
    report.uncertainty = detail::modelUncertainty(inlierSamples, groups, report, params, report.notes);
    return report;
}

// ---------------------------------------------------------------------------------------------------
// Report I/O

namespace {

const char* uncertaintySourceName(UncertaintySource source)
{
    return source == UNCERTAINTY_BOOTSTRAP ? "bootstrap" : "covariance";
}

void writeReals(FileStorage& fs, const char* name, const double* values, int count)
{
    fs << name << "[:";
    for (int i = 0; i < count; ++i)
        fs << values[i];
    fs << "]";
}

//! A list of exactly `count` numbers, or an error naming the field.
void readReals(const FileNode& node, const char* field, double* values, int count)
{
    const FileNode list = node[field];
    if (!list.isSeq() || static_cast<int>(list.size()) != count)
        CV_Error(Error::StsParseError,
                 format("calibration report: field '%s' must be a list of %d numbers", field, count));
    for (int i = 0; i < count; ++i) {
        if (!list[i].isReal() && !list[i].isInt())
            CV_Error(Error::StsParseError,
                     format("calibration report: field '%s' holds something other than a number", field));
        values[i] = static_cast<double>(list[i]);
    }
}

ModelUncertainty readUncertainty(const FileNode& node)
{
    if (!node.isMap())
        CV_Error(Error::StsParseError, "calibration report: field 'uncertainty' is missing or not a map");
    try {
        rejectUnknownKeys(node, {"source", "std_error", "covariance", "fit_std_error", "bootstrap_std_error",
                                 "bootstrap_replicates"});
    } catch (const Exception& e) {
        CV_Error(e.code, "calibration report: uncertainty: " + e.err);
    }
    ModelUncertainty u;
    const FileNode source = node["source"];
    if (!source.isString() || (source.string() != "covariance" && source.string() != "bootstrap"))
        CV_Error(Error::StsParseError,
                 "calibration report: uncertainty: field 'source' must be 'covariance' or 'bootstrap'");
    u.source = source.string() == "bootstrap" ? UNCERTAINTY_BOOTSTRAP : UNCERTAINTY_COVARIANCE;
    readReals(node, "std_error", u.stdError.val, 3);
    readReals(node, "covariance", u.covariance.val, 9);
    readReals(node, "fit_std_error", u.fitStdError.val, 3);
    readReals(node, "bootstrap_std_error", u.bootstrapStdError.val, 3);
    u.bootstrapReplicates = static_cast<int>(detail::readRealField(node, "bootstrap_replicates"));
    for (int k = 0; k < 3; ++k)
        if (!(u.stdError[k] >= 0) || !(u.fitStdError[k] >= 0) || !(u.bootstrapStdError[k] >= 0))
            CV_Error(Error::StsParseError, "calibration report: uncertainty: standard errors must be >= 0");
    return u;
}

} // namespace

void CalibrationReport::write(FileStorage& fs, const String& name) const
{
    // Any other value would be written as one of the two and read back as a method that never ran.
    if (method != NOISE_FIT_JOINT && method != NOISE_FIT_TWO_STAGE)
        CV_Error(Error::StsBadArg,
                 format("CalibrationReport::write: method %d is not a NoiseFitMethod", int(method)));
    // The lowest version that holds what the report has: one without errors stays readable by builds
    // that know only version 1.
    const bool withErrors = uncertainty.source != UNCERTAINTY_NONE;
    fs << name << "{";
    fs << "format_version" << (withErrors ? FORMAT_VERSION : 1);
    fs << "method" << (method == NOISE_FIT_JOINT ? "joint" : "two_stage");
    fs << "separable" << static_cast<int>(separable);
    {
        // The dark-shading maps live beside the model file (NoiseModel::save()), not in the report.
        NoiseModel withoutMaps = model;
        withoutMaps.darkShadingPerGain = Mat();
        withoutMaps.darkShadingOffset = Mat();
        withoutMaps.write(fs, "noise_model");
    }
    fs << "r_squared_slope" << rSquaredSlope;
    fs << "r_squared_offset" << rSquaredOffset;
    fs << "samples" << samples;
    fs << "samples_used" << samplesUsed;
    if (withErrors) {
        fs << "uncertainty"
           << "{";
        fs << "source" << uncertaintySourceName(uncertainty.source);
        writeReals(fs, "std_error", uncertainty.stdError.val, 3);
        writeReals(fs, "covariance", uncertainty.covariance.val, 9);
        writeReals(fs, "fit_std_error", uncertainty.fitStdError.val, 3);
        writeReals(fs, "bootstrap_std_error", uncertainty.bootstrapStdError.val, 3);
        fs << "bootstrap_replicates" << uncertainty.bootstrapReplicates;
        fs << "}";
        fs << "read_excess_kurtosis" << readExcessKurtosis;
        fs << "read_excess_kurtosis_estimated" << static_cast<int>(readExcessKurtosisEstimated);
    }
    fs << "per_gain"
       << "[";
    for (const NoiseLineFit& f : perGain) {
        fs << "{";
        fs << "gain" << f.gain << "gain_db" << linearGainToDb(f.gain) << "a" << f.line.a << "b" << f.line.b;
        fs << "r_squared" << f.rSquared << "inliers" << f.inliers << "samples" << f.samples;
        if (withErrors)
            fs << "a_std_error" << f.slopeStdError << "b_std_error" << f.offsetStdError << "ab_correlation"
               << f.slopeOffsetCorrelation;
        fs << "}";
    }
    fs << "]";
    fs << "notes"
       << "[";
    for (const std::string& n : notes)
        fs << n;
    fs << "]";
    fs << "}";
}

CalibrationReport CalibrationReport::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "calibration report: expected a map");
    const FileNode versionNode = node["format_version"];
    if (!versionNode.isInt())
        CV_Error(Error::StsParseError,
                 "calibration report: field 'format_version' is missing or not an integer");
    if (static_cast<int>(versionNode) < 1 || static_cast<int>(versionNode) > FORMAT_VERSION)
        CV_Error(
            Error::StsParseError,
            format("calibration report: format_version %d is not supported; this build reads versions 1 to "
                   "%d%s",
                   static_cast<int>(versionNode), FORMAT_VERSION,
                   static_cast<int>(versionNode) > FORMAT_VERSION ? " (a newer cv::rawgment wrote the file)"
                                                                  : ""));
    const int version = static_cast<int>(versionNode);
    CalibrationReport r;
    try {
        std::vector<String> keys = {
            "format_version",   "method",  "separable",    "noise_model", "r_squared_slope",
            "r_squared_offset", "samples", "samples_used", "per_gain",    "notes"};
        std::vector<String> gainKeys = {"gain", "gain_db", "a", "b", "r_squared", "inliers", "samples"};
        if (version >= 3)
            keys.insert(keys.end(), {"read_excess_kurtosis", "read_excess_kurtosis_estimated"});
        if (version >= 2) {
            keys.push_back("uncertainty");
            gainKeys.insert(gainKeys.end(), {"a_std_error", "b_std_error", "ab_correlation"});
        }
        rejectUnknownKeys(node, keys);
        for (const FileNode& g : node["per_gain"])
            rejectUnknownKeys(g, gainKeys);
    } catch (const Exception& e) {
        CV_Error(e.code, "calibration report: " + e.err);
    }
    const FileNode method = node["method"];
    if (!method.isString() || (method.string() != "joint" && method.string() != "two_stage"))
        CV_Error(Error::StsParseError, "calibration report: field 'method' must be 'joint' or 'two_stage'");
    r.method = method.string() == "joint" ? NOISE_FIT_JOINT : NOISE_FIT_TWO_STAGE;
    r.separable = detail::readRealField(node, "separable") != 0;
    r.model = NoiseModel::read(node["noise_model"]);
    r.rSquaredSlope = detail::readRealField(node, "r_squared_slope");
    r.rSquaredOffset = detail::readRealField(node, "r_squared_offset");
    r.samples = static_cast<int>(detail::readRealField(node, "samples"));
    r.samplesUsed = static_cast<int>(detail::readRealField(node, "samples_used"));
    if (version >= 2)
        r.uncertainty = readUncertainty(node["uncertainty"]);
    if (version >= 3) {
        r.readExcessKurtosis = detail::readRealField(node, "read_excess_kurtosis");
        if (!(r.readExcessKurtosis >= kMinExcessKurtosis && r.readExcessKurtosis <= kMaxExcessKurtosis))
            CV_Error(Error::StsParseError,
                     format("calibration report: field 'read_excess_kurtosis' must lie in "
                            "[%g, %g] (got %g)",
                            kMinExcessKurtosis, kMaxExcessKurtosis, r.readExcessKurtosis));
        r.readExcessKurtosisEstimated = detail::readRealField(node, "read_excess_kurtosis_estimated") != 0;
    }
    const FileNode perGain = node["per_gain"];
    if (!perGain.isSeq())
        CV_Error(Error::StsParseError, "calibration report: field 'per_gain' is missing or not a list");
    for (const FileNode& g : perGain) {
        NoiseLineFit f;
        f.gain = detail::readRealField(g, "gain");
        f.line.a = detail::readRealField(g, "a");
        f.line.b = detail::readRealField(g, "b");
        f.rSquared = detail::readRealField(g, "r_squared");
        f.inliers = static_cast<int>(detail::readRealField(g, "inliers"));
        f.samples = static_cast<int>(detail::readRealField(g, "samples"));
        if (version >= 2) {
            f.slopeStdError = detail::readRealField(g, "a_std_error");
            f.offsetStdError = detail::readRealField(g, "b_std_error");
            f.slopeOffsetCorrelation = detail::readRealField(g, "ab_correlation");
        }
        r.perGain.push_back(f);
    }
    for (const FileNode& n : node["notes"])
        r.notes.push_back(n.string());
    return r;
}

void CalibrationReport::save(const String& path) const
{
    detail::writeFileStorageAtomically(path, [&](FileStorage& fs) { write(fs, "calibration_report"); });
}

CalibrationReport CalibrationReport::load(const String& path)
{
    return detail::loadFileStorage(path, "calibration_report", "calibration report",
                                   [](const FileNode& n) { return read(n); });
}

} // namespace rawgment
} // namespace cv
