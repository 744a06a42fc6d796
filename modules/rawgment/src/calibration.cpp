// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/calibration.hpp"
#include "calibration_lines.hpp"
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

using detail::checkSamples;
using detail::inliersOf;
using detail::kMaxExcessKurtosis;
using detail::kMinExcessKurtosis;
using detail::lineVarianceFloor;
using detail::meanRangeOf;

// The cross-gain fit of the noise model (calibrateNoiseModel); the per-gain lines are in
// calibration_lines.cpp and the report file in calibration_report.cpp.

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

void checkCalibrationParams(const std::vector<NoiseSample>& samples, const CalibrationParams& params)
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
    if (!std::isnan(params.readExcessKurtosis) &&
        !(params.readExcessKurtosis >= kMinExcessKurtosis && params.readExcessKurtosis <= kMaxExcessKurtosis))
        CV_Error(
            Error::StsBadArg,
            format("calibrateNoiseModel: readExcessKurtosis must be NaN (estimate it) or lie in [%g, %g] "
                   "(got %g)",
                   kMinExcessKurtosis, kMaxExcessKurtosis, params.readExcessKurtosis));
}

//! The per-gain lines and what the cross-gain fit takes from them: the inlier samples, grouped by gain.
struct PerGainLines
{
    std::map<double, std::vector<NoiseSample>> byGain;
    std::vector<NoiseSample> inlierSamples;
    std::vector<detail::GainGroup> groups;
    std::set<int64> outlierPixels; // pixels outside the band of their gain's line in some burst
    LineFitParams lineParams;

    //! Fits each gain's line anew into report.perGain and collects its inliers and outlier pixels.
    void fit(const CalibrationParams& params, CalibrationReport& report)
    {
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
    }
};

/* Without a given kurtosis, it is estimated from the lines' residuals and the lines are fitted again
 * with bands of that spread (twice: the first lines were cut with Gaussian bands). */
void estimateKurtosisAndRefit(PerGainLines& lines, const CalibrationParams& params, CalibrationReport& report)
{
    std::string why;
    for (int round = 0; round < 2; ++round) {
        double kappa = 0;
        if (!estimateReadKurtosis(lines.byGain, report.perGain, kappa, why))
            break;
        report.readExcessKurtosisEstimated = true;
        if (std::abs(kappa - lines.lineParams.readExcessKurtosis) < 1e-3)
            break;
        lines.lineParams.readExcessKurtosis = kappa;
        lines.outlierPixels.clear();
        lines.fit(params, report);
    }
    if (!report.readExcessKurtosisEstimated)
        report.notes.push_back("the read noise's excess kurtosis could not be estimated, " + why +
                               ": the fit takes it as 0 (Gaussian); give CalibrationParams::"
                               "readExcessKurtosis (for example from dark frames) if the read noise has "
                               "heavier tails");
}

/* A noisy pixel (random telegraph noise) or a stuck one is the same pixel in every burst, but it stands
 * out of the noise band only where the normal noise is small (dark patches, dark frames, low gains);
 * in bright patches its extra variance hides inside the band, and kept there it biases the lines
 * where it hides and not where it was cut (5% such pixels moved alpha by 2-3 standard errors). So a
 * pixel outside the band in any burst is left out of every burst, as a defect map would, unless so
 * many are that the lines themselves must be wrong. Normal pixels leave the band by chance in
 * 2 Phi(-k) of bursts; that only costs samples, since their bursts are independent. */
void leaveOutOutlierPixels(const std::vector<NoiseSample>& samples, PerGainLines& lines,
                           const CalibrationParams& params, CalibrationReport& report)
{
    if (lines.outlierPixels.empty())
        return;
    std::set<int64> pixels;
    for (const NoiseSample& s : samples)
        if (s.pixel >= 0)
            pixels.insert(s.pixel);
    // The count before the refit: the refit's own outliers are not left out again.
    const int leftOut = static_cast<int>(lines.outlierPixels.size());
    if (lines.outlierPixels.size() > pixels.size() / 5) {
        report.notes.push_back(format("%d of %d pixels lay outside the noise band in at least one burst: too "
                                      "many to be defects, so each was left out only where it was outside",
                                      leftOut, static_cast<int>(pixels.size())));
        return;
    }
    for (auto& entry : lines.byGain) {
        std::vector<NoiseSample>& v = entry.second;
        v.erase(std::remove_if(v.begin(), v.end(),
                               [&](const NoiseSample& x) { return lines.outlierPixels.count(x.pixel) > 0; }),
                v.end());
        if (v.size() < 2)
            CV_Error(Error::StsBadArg,
                     format("calibrateNoiseModel: gain %g: fewer than 2 samples are left once the "
                            "pixels outside the noise band in any burst are left out",
                            entry.first));
    }
    lines.fit(params, report);
    report.notes.push_back(format("%d of %d pixels lay outside the noise band in at least one burst "
                                  "(a band as wide as read noise of excess kurtosis %.3g makes it) "
                                  "and were left out of every burst, as noisy, hot or stuck pixels "
                                  "would be; normal pixels leave it by chance in %.2g of their bursts",
                                  leftOut, static_cast<int>(pixels.size()), report.readExcessKurtosis,
                                  std::erfc(params.line.inlierThreshold / std::sqrt(2.0))));
}

//! alpha, sigma_d^2 and sigma_r^2 across the gains' lines, with their notes, R^2 and uncertainty.
void fitAcrossGains(const PerGainLines& lines, const CalibrationParams& params, CalibrationReport& report)
{
    // alpha from a_g = g alpha (least squares through the origin, non-negative).
    double sga = 0, sgg = 0;
    for (const NoiseLineFit& f : report.perGain) {
        sga += f.gain * f.line.a;
        sgg += f.gain * f.gain;
    }
    double alpha = std::max(0.0, sga / sgg);
    const double gainRatio = report.perGain.back().gain / report.perGain.front().gain;
    report.separable = report.perGain.size() >= 2 && gainRatio >= params.minGainRatio;
    report.samplesUsed = static_cast<int>(lines.inlierSamples.size());
    if (!report.separable) {
        report.notes.push_back(format("sigma_d^2 and sigma_r^2 are not separable: %s; only alpha is reported "
                                      "(the offset of each gain is in its line)",
                                      report.perGain.size() < 2
                                          ? "a single gain was calibrated"
                                          : "the gains differ by less than minGainRatio"));
        report.model = NoiseModel(alpha, 0.0, 0.0);
        report.uncertainty =
            detail::modelUncertainty(lines.inlierSamples, lines.groups, report, params, report.notes);
        return;
    }
    double sigmaD2 = 0, sigmaR2 = 0;
    fitOffsets(report.perGain, sigmaD2, sigmaR2);

    if (params.method == NOISE_FIT_JOINT) {
        const Vec3d p = detail::refineJointFit(
            lines.inlierSamples.data(), nullptr, static_cast<int>(lines.inlierSamples.size()),
            Vec3d(alpha, sigmaD2, sigmaR2), params.lossScale, params.line.robust, params.reweightIterations,
            report.readExcessKurtosis);
        alpha = p[0];
        sigmaD2 = p[1];
        sigmaR2 = p[2];
    }
    report.model = NoiseModel(alpha, sigmaD2, sigmaR2);
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
    report.uncertainty =
        detail::modelUncertainty(lines.inlierSamples, lines.groups, report, params, report.notes);
}

} // namespace

CalibrationReport calibrateNoiseModel(const std::vector<NoiseSample>& samples,
                                      const CalibrationParams& params)
{
    checkCalibrationParams(samples, params);
    const bool kurtosisGiven = !std::isnan(params.readExcessKurtosis);
    CalibrationReport report;
    report.method = params.method;
    report.samples = static_cast<int>(samples.size());

    PerGainLines lines;
    for (const NoiseSample& s : samples)
        lines.byGain[s.gain].push_back(s);
    lines.lineParams = params.line;
    lines.lineParams.readExcessKurtosis = kurtosisGiven ? params.readExcessKurtosis : 0.0;
    lines.fit(params, report);
    if (!kurtosisGiven)
        estimateKurtosisAndRefit(lines, params, report);
    report.readExcessKurtosis = lines.lineParams.readExcessKurtosis;
    leaveOutOutlierPixels(samples, lines, params, report);
    for (const NoiseLineFit& fit : report.perGain)
        if (fit.line.a < 0 || fit.line.b < 0)
            report.notes.push_back(
                format("gain %g: the line has a negative %s (a = %g, b = %g); the data do not "
                       "follow the model there",
                       fit.gain, fit.line.a < 0 ? "slope" : "offset", fit.line.a, fit.line.b));
    fitAcrossGains(lines, params, report);
    return report;
}

} // namespace rawgment
} // namespace cv
