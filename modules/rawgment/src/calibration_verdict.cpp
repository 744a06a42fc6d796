// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The verdict of a calibration (judgeCalibration()): each check a measured figure against a stated
// threshold. Where each threshold comes from is in docs/calibrate_your_camera.md.
#include "calibration_lines.hpp"
#include "opencv2/rawgment/calibration.hpp"
#include "precomp.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <map>

namespace cv {
namespace rawgment {

namespace {

// Thresholds (docs/calibrate_your_camera.md says why each has its value).
const int kMinFrames = 16;
const double kMaxClippedFraction = 0.5;
const int kMeanBins = 8;
const int kMinBinSamples = 30;
const int kMinDistinctMeans = 3;
const double kMinMeanSpread = 0.1;
const double kMaxBinDeviation = 0.05;
const double kMaxCurvatureShare = 0.05;
const double kMinGainRatio = 2.0;
const double kMaxGainDeviation = 0.05;

//! Median of chi-square(k) / k: the median of a sample variance over its expectation (Wilson-Hilferty).
double medianVarianceRatio(double dof)
{
    const double t = 1 - 2 / (9 * dof);
    return t * t * t;
}

double median(std::vector<double> v)
{
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
}

VerdictCheck check(const std::string& name, bool pass, const std::string& figure)
{
    return {name, pass, figure};
}

VerdictCheck gainsAgreeWithSlopes(const CalibrationReport& report,
                                  const std::vector<CalibrationBurstFacts>& bursts)
{
    return detail::slopesAgreeWithGains(
        report,
        [&](double gain) {
            std::string names;
            for (const CalibrationBurstFacts& b : bursts)
                if (!b.dark && std::abs(b.gainDb - linearGainToDb(gain)) < 0.01)
                    names += (names.empty() ? "" : ", ") + b.name;
            return names.empty() ? std::string("no burst") : names;
        },
        "burst");
}

} // namespace

double fittedVariance(const CalibrationReport& report, double mean, double gain)
{
    // A pixel's temporal variance holds its row's noise too: the model's pixel variance (which a calibration
    // with dark components gives less the row noise) plus the row variance it stated beside it.
    if (report.separable || report.perGain.empty())
        return report.model.variance(mean, gain) + report.model.rowVariance(gain);
    const NoiseLineFit* nearest = &report.perGain.front();
    for (const NoiseLineFit& f : report.perGain)
        if (std::abs(std::log(f.gain / gain)) < std::abs(std::log(nearest->gain / gain)))
            nearest = &f;
    return nearest->line.a * std::max(0.0, mean) + nearest->line.b;
}

namespace {

//! What the per-gain checks found worst so far, over the gains.
struct PerGainFindings
{
    std::string fewMeans, badBin, curved;
    double worstBin = 0, worstCurvature = 0;
    int worstDistinct = INT_MAX;
};

std::vector<VerdictCheck> burstChecks(const std::vector<CalibrationBurstFacts>& bursts)
{
    int fewest = INT_MAX;
    std::string fewestName;
    double mostClipped = 0;
    std::string mostClippedName;
    for (const CalibrationBurstFacts& b : bursts) {
        if (b.frames < fewest) {
            fewest = b.frames;
            fewestName = b.name;
        }
        if (!b.dark && b.clippedFraction > mostClipped) {
            mostClipped = b.clippedFraction;
            mostClippedName = b.name;
        }
    }
    return {
        check("frames per burst", fewest >= kMinFrames,
              format("fewest %d (%s); threshold %d%s", fewest, fewestName.c_str(), kMinFrames,
                     fewest >= kMinFrames ? "" : ": shoot more frames per burst")),
        check("clipped fraction", mostClipped <= kMaxClippedFraction,
              format("largest %.1f%% (%s); threshold %.0f%%%s", 100 * mostClipped,
                     mostClippedName.empty() ? "none" : mostClippedName.c_str(), 100 * kMaxClippedFraction,
                     mostClipped <= kMaxClippedFraction ? "" : ": lower the exposure of that burst"))};
}

//! Separability: the spread of the gains and whether the read terms' intervals stay clear of 0.
VerdictCheck separabilityCheck(const CalibrationReport& report)
{
    double gMin = INFINITY, gMax = 0;
    for (const NoiseLineFit& f : report.perGain) {
        gMin = std::min(gMin, f.gain);
        gMax = std::max(gMax, f.gain);
    }
    const double ratio = report.perGain.empty() ? 1.0 : gMax / gMin;
    // A read term whose 95% interval reaches 0 is not told apart from 0 by the data.
    bool intervalsClear = report.separable && report.uncertainty.source != UNCERTAINTY_NONE;
    std::string intervals;
    if (intervalsClear) {
        const Vec2d d = report.interval(NOISE_PARAM_SIGMA_D2), r = report.interval(NOISE_PARAM_SIGMA_R2);
        intervalsClear = d[0] > 0 && r[0] > 0;
        intervals =
            format("; 95%% intervals sigma_d^2 [%.4g, %.4g], sigma_r^2 [%.4g, %.4g]", d[0], d[1], r[0], r[1]);
    }
    const bool separated = report.separable && ratio >= kMinGainRatio && intervalsClear;
    return check(
        "separability of sigma_d^2 and sigma_r^2", separated,
        format("gain ratio %.2f (%.1f dB) over %zu gains%s; threshold %.1f (%.1f dB) and both intervals "
               "above 0%s",
               ratio, linearGainToDb(ratio), report.perGain.size(), intervals.c_str(), kMinGainRatio,
               linearGainToDb(kMinGainRatio),
               separated ? ""
                         : ": add a burst at an ISO at least twice the lowest, and dark frames at "
                           "each ISO"));
}

//! One gain's residuals per mean bin and the spread of its means, from lo to hi.
void judgeMeanBins(double g, const std::vector<const NoiseSample*>& gs, const CalibrationReport& report,
                   double lo, double hi, double signalRange, PerGainFindings& found)
{
    const double width = std::max(hi - lo, 1e-9) / kMeanBins;
    std::vector<std::vector<double>> ratios(kMeanBins);
    std::vector<double> dofs(kMeanBins, 0), binMeans(kMeanBins, 0);
    // Heavy-tailed read noise (the model's Tukey-lambda shape) spreads and skews a sample variance beyond
    // chi-square's: its variance is sigma^4 (2 / dof + k / n) for excess kurtosis k of the pixel's noise, the
    // read noise's k weighted by its share of the variance squared (rows and shot noise add none to speak
    // of). Each sample counts with the chi-square's dof of that spread, whose median the check expects.
    const double readKurtosis = report.model.readExcessKurtosis();
    const double readVariance = fittedVariance(report, 0, g) - report.model.rowVariance(g);
    for (const NoiseSample* s : gs) {
        const int bin = std::min(kMeanBins - 1, std::max(0, int((std::max(0.0, s->mean) - lo) / width)));
        const double predicted = fittedVariance(report, s->mean, g);
        if (predicted > 0) {
            const double share = std::max(0.0, readVariance) / predicted;
            const double spread = 2.0 / s->dof + readKurtosis * share * share / (s->dof + 1.0);
            ratios[size_t(bin)].push_back(s->variance / predicted);
            dofs[size_t(bin)] += spread > 0 ? 2 / spread : s->dof;
            binMeans[size_t(bin)] += s->mean;
        }
    }
    int distinct = 0;
    double lowest = INFINITY, highest = -INFINITY;
    for (int b = 0; b < kMeanBins; ++b) {
        const std::vector<double>& r = ratios[size_t(b)];
        if (int(r.size()) < kMinBinSamples)
            continue;
        ++distinct;
        const double meanOfBin = binMeans[size_t(b)] / double(r.size());
        lowest = std::min(lowest, meanOfBin);
        highest = std::max(highest, meanOfBin);
        // The median ratio over the median a correct model gives; its standard error is about
        // 1.25 sqrt(2 / dof) / sqrt(n) (the median's efficiency against the mean is 2 / pi).
        const double dof = dofs[size_t(b)] / double(r.size());
        const double deviation = median(r) / medianVarianceRatio(dof) - 1;
        const double standardError = 1.2533 * std::sqrt(2 / dof) / std::sqrt(double(r.size()));
        const double excess = std::abs(deviation) - 4 * standardError;
        if (excess > kMaxBinDeviation && std::abs(deviation) > std::abs(found.worstBin)) {
            found.worstBin = deviation;
            found.badBin =
                format("%.2f dB, mean %.0f DN: %+.1f%%", linearGainToDb(g), meanOfBin, 100 * deviation);
        }
    }
    const bool spread = distinct >= kMinDistinctMeans && highest - lowest >= kMinMeanSpread * signalRange;
    if (!spread && distinct < found.worstDistinct) {
        found.worstDistinct = distinct;
        found.fewMeans =
            format("%.2f dB: %d mean bins of %d samples, spanning %.1f%% of the range", linearGainToDb(g),
                   distinct, kMinBinSamples, distinct ? 100 * (highest - lowest) / signalRange : 0.0);
    }
}

//! Curvature: weighted least squares of v = b + a mu + c mu^2 with weights dof / (2 model^2).
void judgeCurvature(double g, const std::vector<const NoiseSample*>& gs, const CalibrationReport& report,
                    double hi, PerGainFindings& found)
{
    Matx33d A = Matx33d::zeros();
    Vec3d rhs(0, 0, 0);
    for (const NoiseSample* s : gs) {
        const double m = std::max(0.0, s->mean), predicted = fittedVariance(report, s->mean, g);
        if (!(predicted > 0))
            continue;
        const double w = s->dof / (2 * predicted * predicted);
        const Vec3d x(1, m, m * m);
        A += w * x * x.t();
        rhs += w * s->variance * x;
    }
    Matx33d cov;
    if (invert(A, cov, DECOMP_SVD) == 0 || !(hi > 0))
        return;
    const Vec3d p = cov * rhs;
    const double top = fittedVariance(report, hi, g);
    const double share = p[2] * hi * hi / top, shareSe = std::sqrt(cov(2, 2)) * hi * hi / top;
    if (std::abs(share) - 4 * shareSe > kMaxCurvatureShare &&
        std::abs(share) > std::abs(found.worstCurvature)) {
        found.worstCurvature = share;
        found.curved = format("%.2f dB: %+.1f%% of the variance at the highest mean (%.0f DN) is curvature",
                              linearGainToDb(g), 100 * share, hi);
    }
}

std::vector<VerdictCheck> perGainChecks(const std::vector<NoiseSample>& samples,
                                        const CalibrationReport& report, double signalRange)
{
    std::map<double, std::vector<const NoiseSample*>> byGain;
    for (const NoiseSample& s : samples)
        byGain[s.gain].push_back(&s);
    PerGainFindings found;
    for (const auto& kv : byGain) {
        double lo = INFINITY, hi = -INFINITY;
        for (const NoiseSample* s : kv.second) {
            lo = std::min(lo, std::max(0.0, s->mean));
            hi = std::max(hi, s->mean);
        }
        judgeMeanBins(kv.first, kv.second, report, lo, hi, signalRange, found);
        judgeCurvature(kv.first, kv.second, report, hi, found);
    }
    return {
        check("residuals per gain and mean bin", found.badBin.empty(),
              found.badBin.empty()
                  ? format("every bin of >= %d samples within %.0f%% (+4 standard errors) of the "
                           "model",
                           kMinBinSamples, 100 * kMaxBinDeviation)
                  : "worst " + found.badBin +
                        format("; threshold %.0f%% beyond 4 standard errors: the model does not "
                               "describe these data (see the mean-variance plot)%s",
                               100 * kMaxBinDeviation,
                               found.worstBin > 0 && !report.model.hasDarkComponents()
                                   ? "; variance beyond the model at low means is often row noise or other "
                                     "dark-frame noise: add dark bursts and calibrate with --dark_components"
                                   : "")),
        check("distinct means per gain", found.fewMeans.empty(),
              found.fewMeans.empty()
                  ? format("every gain has >= %d mean bins spanning >= %.0f%% of the range",
                           kMinDistinctMeans, 100 * kMinMeanSpread)
                  : found.fewMeans + format("; threshold %d bins spanning %.0f%%: use a chart or scene with "
                                            "darker and brighter parts, or a second exposure",
                                            kMinDistinctMeans, 100 * kMinMeanSpread)),
        check(
            "linearity (curvature of variance against mean)", found.curved.empty(),
            found.curved.empty()
                ? format("no gain has curvature beyond %.0f%% (+4 standard errors)", 100 * kMaxCurvatureShare)
                : "worst " + found.curved +
                      format("; threshold %.0f%%: the raw values are not linear in light (a tone curve, "
                             "compression or a processed file?)",
                             100 * kMaxCurvatureShare))};
}

} // namespace

namespace detail {

/* Whether each gain's fitted slope a_g = g alpha agrees with the gain its files' ISO (or the manifest's
 * gain_db) gives: a burst shot at another gain than its tag says (a camera that switches its analog gain at
 * other ISOs than it reports) moves its whole line, and the residual check then blames whichever bin of
 * whichever gain deviates most. alpha is taken as the median of a_g / g over the gains, so that one wrong
 * gain of three or more does not move it; a gain disagrees when a_g / (g alpha) is off by more than 5%
 * beyond 4 of its standard errors. With two gains the two can only disagree with each other. */
VerdictCheck slopesAgreeWithGains(const CalibrationReport& report,
                                  const std::function<std::string(double gain)>& namesAt, const char* unit)
{
    const std::string name = format("gain of each %s against its slope", unit);
    std::vector<double> perGainAlpha;
    for (const NoiseLineFit& f : report.perGain)
        if (f.line.a > 0)
            perGainAlpha.push_back(f.line.a / f.gain);
    if (perGainAlpha.size() < 2)
        return VerdictCheck{name, true, "one gain with a positive slope: nothing to compare"};
    const double alpha = median(perGainAlpha);
    std::string wrong;
    double worst = 1; // the ratio furthest from 1 so far
    for (const NoiseLineFit& f : report.perGain) {
        if (!(f.line.a > 0))
            continue;
        const double ratio = f.line.a / (f.gain * alpha), se = f.slopeStdError / (f.gain * alpha);
        if (std::abs(ratio - 1) - 4 * se > kMaxGainDeviation && std::abs(ratio - 1) > std::abs(worst - 1)) {
            worst = ratio;
            wrong = format("%.2f dB (%s): its slope says gain %.3g (%.2f dB), %.3f times the gain its ISO "
                           "or gain_db gives",
                           linearGainToDb(f.gain), namesAt(f.gain).c_str(), f.gain * ratio,
                           linearGainToDb(f.gain * ratio), ratio);
        }
    }
    if (wrong.empty())
        return VerdictCheck{
            name, true,
            format("every gain's slope within %.0f%% (+4 standard errors) of g alpha, alpha the "
                   "median over %zu gains",
                   100 * kMaxGainDeviation, perGainAlpha.size())};
    return VerdictCheck{name, false,
                        wrong +
                            format("; threshold %.0f%% beyond 4 standard errors%s", 100 * kMaxGainDeviation,
                                   perGainAlpha.size() == 2
                                       ? ": with two gains either may be the wrong one; check both ISOs, or "
                                         "add a third gain"
                                       : format(": that %s was not shot at the gain its ISO says; give it "
                                                "a gain_db or leave it out",
                                                unit)
                                             .c_str())};
}

} // namespace detail

CalibrationVerdict judgeCalibration(const std::vector<NoiseSample>& samples, const CalibrationReport& report,
                                    const std::vector<CalibrationBurstFacts>& bursts, double signalRange)
{
    CalibrationVerdict verdict;
    std::vector<VerdictCheck> checks = burstChecks(bursts);
    checks.push_back(separabilityCheck(report));
    checks.push_back(gainsAgreeWithSlopes(report, bursts));
    for (const VerdictCheck& c : perGainChecks(samples, report, signalRange))
        checks.push_back(c);
    for (const VerdictCheck& c : checks) {
        verdict.checks.push_back(c);
        verdict.pass = verdict.pass && c.pass;
    }
    return verdict;
}

} // namespace rawgment
} // namespace cv
