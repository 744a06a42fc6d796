// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The project's noise model from EMVA 1288 series (emva1288 topic): per gain, a weighted line through the
// pairs' pooled statistics; across gains, Eq. 5. At two frames per step, a per-pixel sample variance has one
// degree of freedom and is 0 whenever the two integer readings tie; fitNoiseLine()'s inlier band dropped
// every tie until its lower edge took a continuity correction (docs/emva1288.md). The pooled pair statistic
// selects nothing, and its standard error is measured from the pixels' own fourth moment (or the rows).
#include "calibration_lines.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"

#include <opencv2/rawgment/emva1288.hpp>

namespace cv {
namespace rawgment {

namespace {

//! A weighted straight-line fit y = a x + b with its covariance (scaled by the reduced chi-square when > 1).
struct WeightedLine
{
    double a = 0, b = 0;
    Matx22d covariance;
    double reducedChiSquare = 0;
    int points = 0;
};

WeightedLine weightedLine(const std::vector<double>& x, const std::vector<double>& y,
                          const std::vector<double>& se)
{
    double S = 0, Sx = 0, Sy = 0, Sxx = 0, Sxy = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double w = 1.0 / (se[i] * se[i]);
        S += w;
        Sx += w * x[i];
        Sy += w * y[i];
        Sxx += w * x[i] * x[i];
        Sxy += w * x[i] * y[i];
    }
    const double det = S * Sxx - Sx * Sx;
    WeightedLine f;
    f.points = int(x.size());
    f.a = (S * Sxy - Sx * Sy) / det;
    f.b = (Sxx * Sy - Sx * Sxy) / det;
    double chi2 = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        const double r = (y[i] - (f.a * x[i] + f.b)) / se[i];
        chi2 += r * r;
    }
    f.reducedChiSquare = x.size() > 2 ? chi2 / double(x.size() - 2) : 0.0;
    // Inverse of the normal matrix [Sxx Sx; Sx S] for (a, b): the errors the stated weights imply.
    const double scale = std::max(1.0, f.reducedChiSquare);
    f.covariance = Matx22d(S / det, -Sx / det, -Sx / det, Sxx / det) * scale;
    return f;
}

//! One gain's points: bright pairs up to the fraction of saturation, and the dark pairs of their exposures.
struct GainPoints
{
    std::vector<double> signal, variance, stdError;
    double maxSignal = 0;
};

GainPoints pointsOf(const Emva1288Results& r, double fraction, int which)
{
    const int n = int(r.mean.size());
    if (n < 2 || r.saturationIndex < 0 || r.saturationIndex >= n || int(r.variance.size()) != n ||
        int(r.darkMean.size()) != n || int(r.darkVariance.size()) != n ||
        int(r.varianceStdError.size()) != n || int(r.darkVarianceStdError.size()) != n)
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateEmva1288: measurement %d is not what emva1288Results() "
                            "gives (its temporal lists differ in length)",
                            which));
    const double limit = fraction * (r.mean[r.saturationIndex] - r.darkMean[r.saturationIndex]);
    GainPoints p;
    std::vector<double> darkExposures;
    for (int i = 0; i < n; ++i) {
        const double signal = r.mean[i] - r.darkMean[i];
        if (signal > limit)
            continue;
        p.signal.push_back(signal);
        p.variance.push_back(r.variance[i]);
        p.stdError.push_back(r.varianceStdError[i]);
        p.maxSignal = std::max(p.maxSignal, signal);
        // Each exposure's dark pair once, at signal 0: it pins the offset where dark scenes live.
        if (std::find(darkExposures.begin(), darkExposures.end(), r.exposureNs[i]) == darkExposures.end()) {
            darkExposures.push_back(r.exposureNs[i]);
            p.signal.push_back(0.0);
            p.variance.push_back(r.darkVariance[i]);
            p.stdError.push_back(r.darkVarianceStdError[i]);
        }
    }
    const int bright = int(p.signal.size() - darkExposures.size());
    if (bright < 2)
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateEmva1288: measurement %d has %d bright step(s) up to %g%% "
                            "of saturation (%g DN); the line needs at least two",
                            which, bright, 100 * fraction, limit));
    for (double se : p.stdError)
        if (!(se > 0) || !std::isfinite(se))
            CV_Error(Error::StsBadArg,
                     cv::format("calibrateEmva1288: measurement %d has a pair whose variance has "
                                "standard error %g; every pair needs one > 0",
                                which, se));
    return p;
}

// One gain's line from its points: the weighted fit with its errors and its weighted R^2.
NoiseLineFit lineFitOf(const GainPoints& p, const WeightedLine& line, double gain)
{
    NoiseLineFit fit;
    fit.gain = gain;
    fit.line.a = line.a;
    fit.line.b = line.b;
    fit.inliers = fit.samples = line.points;
    fit.slopeStdError = std::sqrt(line.covariance(0, 0));
    fit.offsetStdError = std::sqrt(line.covariance(1, 1));
    fit.slopeOffsetCorrelation = line.covariance(0, 1) / (fit.slopeStdError * fit.offsetStdError);
    // R^2 of the weighted fit, against the weighted mean.
    double sw = 0, swy = 0;
    for (size_t i = 0; i < p.signal.size(); ++i) {
        sw += 1 / (p.stdError[i] * p.stdError[i]);
        swy += p.variance[i] / (p.stdError[i] * p.stdError[i]);
    }
    double ssTot = 0, ssRes = 0;
    for (size_t i = 0; i < p.signal.size(); ++i) {
        const double w = 1 / (p.stdError[i] * p.stdError[i]);
        ssTot += w * (p.variance[i] - swy / sw) * (p.variance[i] - swy / sw);
        const double e = p.variance[i] - (line.a * p.signal[i] + line.b);
        ssRes += w * e * e;
    }
    fit.rSquared = ssTot > 0 ? 1 - ssRes / ssTot : 1;
    return fit;
}

// The lines' slopes and offsets with their errors, by increasing gain.
struct GainLines
{
    std::vector<double> g, a, aSe, b, bSe;
};

// sigma_d^2, sigma_r^2 and their covariance.
struct ReadNoiseFit
{
    double sigmaD2 = 0, sigmaR2 = 0;
    Matx22d covariance;
};

// alpha and its variance: a_g = g alpha through the origin, weighted, the variance scaled by a reduced
// chi-square above 1.
std::pair<double, double> fitAlpha(const GainLines& l)
{
    double swgg = 0, swga = 0;
    for (size_t i = 0; i < l.g.size(); ++i) {
        const double w = 1 / (l.aSe[i] * l.aSe[i]);
        swgg += w * l.g[i] * l.g[i];
        swga += w * l.g[i] * l.a[i];
    }
    const double alpha = swga / swgg;
    double alphaVar = 1 / swgg;
    if (l.g.size() > 1) {
        double chi2 = 0;
        for (size_t i = 0; i < l.g.size(); ++i)
            chi2 += std::pow((l.a[i] - alpha * l.g[i]) / l.aSe[i], 2);
        alphaVar *= std::max(1.0, chi2 / double(l.g.size() - 1));
    }
    return {alpha, alphaVar};
}

/* b_g = g^2 sigma_d^2 + sigma_r^2, weighted (two gains: exact, with the covariance of the two offsets
 * propagated); a negative variance is held at 0 and the other refitted. Sets report.rSquaredOffset and a
 * note when a variance was held. */
ReadNoiseFit fitSeparableReadNoise(const GainLines& l, CalibrationReport& report)
{
    const std::vector<double>&g = l.g, &b = l.b, &bSe = l.bSe;
    ReadNoiseFit r;
    std::vector<double> g2(g.size());
    for (size_t i = 0; i < g.size(); ++i)
        g2[i] = g[i] * g[i];
    if (g.size() == 2) {
        const double d = g2[1] - g2[0];
        r.sigmaD2 = (b[1] - b[0]) / d;
        r.sigmaR2 = (g2[1] * b[0] - g2[0] * b[1]) / d;
        const double v0 = bSe[0] * bSe[0], v1 = bSe[1] * bSe[1];
        r.covariance = Matx22d((v0 + v1) / (d * d), -(g2[1] * v0 + g2[0] * v1) / (d * d),
                               -(g2[1] * v0 + g2[0] * v1) / (d * d),
                               (g2[1] * g2[1] * v0 + g2[0] * g2[0] * v1) / (d * d));
    } else {
        const WeightedLine read = weightedLine(g2, b, bSe);
        r.sigmaD2 = read.a;
        r.sigmaR2 = read.b;
        r.covariance = read.covariance;
    }
    if (r.sigmaR2 < 0 || r.sigmaD2 < 0) {
        report.notes.push_back(
            cv::format("sigma_d^2 %g and sigma_r^2 %g: the negative one is held at 0 and the "
                       "other refitted alone",
                       r.sigmaD2, r.sigmaR2));
        double s0 = 0, s1 = 0;
        for (size_t i = 0; i < g.size(); ++i) {
            const double w = 1 / (bSe[i] * bSe[i]);
            if (r.sigmaR2 < 0) { // b = g^2 sigma_d^2
                s0 += w * g2[i] * g2[i];
                s1 += w * g2[i] * b[i];
            } else { // b = sigma_r^2
                s0 += w;
                s1 += w * b[i];
            }
        }
        if (r.sigmaR2 < 0) {
            r.sigmaD2 = std::max(s1 / s0, 0.0);
            r.sigmaR2 = 0;
            r.covariance = Matx22d(1 / s0, 0, 0, 0);
        } else {
            r.sigmaR2 = std::max(s1 / s0, 0.0);
            r.sigmaD2 = 0;
            r.covariance = Matx22d(0, 0, 0, 1 / s0);
        }
    }
    double ssTot = 0, ssRes = 0, mean = 0;
    for (double v : b)
        mean += v / double(b.size());
    for (size_t i = 0; i < g.size(); ++i) {
        ssTot += (b[i] - mean) * (b[i] - mean);
        ssRes += std::pow(b[i] - detail::noiseTermsAt(g[i], 0.0, r.sigmaD2, r.sigmaR2).read(), 2);
    }
    report.rSquaredOffset = ssTot > 0 ? 1 - ssRes / ssTot : 1;
    return r;
}

// One gain (or gains too close to tell the two variances apart): the read noise at that gain, after it.
ReadNoiseFit fitReadNoiseAtItsGains(const GainLines& l, double minGainRatio, CalibrationReport& report)
{
    ReadNoiseFit r;
    double sw = 0, swb = 0;
    for (size_t i = 0; i < l.g.size(); ++i) {
        sw += 1 / (l.bSe[i] * l.bSe[i]);
        swb += l.b[i] / (l.bSe[i] * l.bSe[i]);
    }
    r.sigmaR2 = std::max(swb / sw, 0.0);
    r.covariance = Matx22d(0, 0, 0, 1 / sw);
    report.rSquaredOffset = 1;
    report.notes.push_back(
        l.g.size() == 1 ? cv::format("one gain: the read noise %.4f DN^2 is stated as sigma_r^2, which "
                                     "holds at this gain",
                                     r.sigmaR2)
                        : cv::format("gains %g to %g, closer than the ratio %g: the read noise %.4f DN^2 "
                                     "is stated as sigma_r^2, which holds at these gains",
                                     l.g.front(), l.g.back(), minGainRatio, r.sigmaR2));
    return r;
}

void checkCalibrationArguments(const std::vector<Emva1288Results>& measurements,
                               const std::vector<double>& gains, const Emva1288CalibrationParams& params)
{
    if (measurements.empty() || measurements.size() != gains.size())
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateEmva1288: %d measurements and %d gains; give one gain per "
                            "measurement, at least one",
                            int(measurements.size()), int(gains.size())));
    if (!(params.maxSignalFraction > 0 && params.maxSignalFraction <= 1))
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateEmva1288: maxSignalFraction must lie in (0, 1] (got %g)",
                            params.maxSignalFraction));
    if (!(params.minGainRatio >= 1 && std::isfinite(params.minGainRatio)))
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateEmva1288: minGainRatio must be finite and >= 1 (got %g)",
                            params.minGainRatio));
    for (double g : gains)
        detail::checkFinitePositive(g, "calibrateEmva1288: every gain");
}

} // namespace

const NoiseLineFit& emva1288LineAtGain(const CalibrationReport& report, double gain)
{
    for (const NoiseLineFit& l : report.perGain)
        if (l.gain == gain)
            return l;
    CV_Error(Error::StsBadArg, cv::format("emva1288LineAtGain: the report has no line at gain %g", gain));
}

CalibrationReport calibrateEmva1288(const std::vector<Emva1288Results>& measurements,
                                    const std::vector<double>& gains, const Emva1288CalibrationParams& params)
{
    checkCalibrationArguments(measurements, gains, params);
    std::vector<int> order(gains.size());
    for (size_t i = 0; i < order.size(); ++i)
        order[i] = int(i);
    std::stable_sort(order.begin(), order.end(), [&](int i, int j) { return gains[i] < gains[j]; });

    CalibrationReport report;
    report.method = NOISE_FIT_TWO_STAGE;
    GainLines lines;
    for (int k : order) {
        const GainPoints p = pointsOf(measurements[k], params.maxSignalFraction, k);
        const WeightedLine line = weightedLine(p.signal, p.variance, p.stdError);
        const NoiseLineFit fit = lineFitOf(p, line, gains[k]);
        report.perGain.push_back(fit);
        report.samples += line.points;
        report.samplesUsed += line.points;
        report.notes.push_back(cv::format(
            "gain %g: the line holds for signals 0 to %.1f DN above dark (steps up to %g%% of saturation), "
            "%d "
            "points, reduced chi-square %.2f%s",
            gains[k], p.maxSignal, 100 * params.maxSignalFraction, line.points, line.reducedChiSquare,
            line.reducedChiSquare > 1 ? " (errors scaled by its square root)" : ""));
        lines.g.push_back(gains[k]);
        lines.a.push_back(line.a);
        lines.aSe.push_back(fit.slopeStdError);
        lines.b.push_back(line.b);
        lines.bSe.push_back(fit.offsetStdError);
    }
    const std::pair<double, double> alpha = fitAlpha(lines);
    report.rSquaredSlope = 1;
    report.separable = lines.g.back() / lines.g.front() >= params.minGainRatio;
    const ReadNoiseFit read = report.separable ? fitSeparableReadNoise(lines, report)
                                               : fitReadNoiseAtItsGains(lines, params.minGainRatio, report);
    report.model = NoiseModel(alpha.first, read.sigmaD2, read.sigmaR2);
    ModelUncertainty& u = report.uncertainty;
    u.source = UNCERTAINTY_COVARIANCE;
    u.covariance = Matx33d::zeros();
    u.covariance(NOISE_PARAM_ALPHA, NOISE_PARAM_ALPHA) = alpha.second;
    u.covariance(NOISE_PARAM_SIGMA_D2, NOISE_PARAM_SIGMA_D2) = read.covariance(0, 0);
    u.covariance(NOISE_PARAM_SIGMA_D2, NOISE_PARAM_SIGMA_R2) = read.covariance(0, 1);
    u.covariance(NOISE_PARAM_SIGMA_R2, NOISE_PARAM_SIGMA_D2) = read.covariance(1, 0);
    u.covariance(NOISE_PARAM_SIGMA_R2, NOISE_PARAM_SIGMA_R2) = read.covariance(1, 1);
    for (int i = 0; i < 3; ++i)
        u.stdError[i] = u.fitStdError[i] = std::sqrt(std::max(u.covariance(i, i), 0.0));
    return report;
}

/* The verdict of a calibration from two-frame steps: what such series can show, each a figure against a
 * threshold (docs/calibrate_your_camera.md, "EMVA 1288 data"). */
CalibrationVerdict judgeEmva1288(const std::vector<Emva1288Results>& results,
                                 const std::vector<double>& gains, const CalibrationReport& report,
                                 const Emva1288CalibrationParams& params)
{
    if (results.size() != gains.size() || results.size() != report.perGain.size())
        CV_Error(Error::StsBadArg,
                 cv::format("judgeEmva1288: %d measurements, %d gains and %d per-gain lines; give "
                            "what calibrateEmva1288() was given and its report",
                            int(results.size()), int(gains.size()), int(report.perGain.size())));
    CalibrationVerdict v;
    const auto add = [&](const std::string& name, bool pass, const std::string& figure) {
        v.checks.push_back({name, pass, figure});
        v.pass = v.pass && pass;
    };
    for (size_t k = 0; k < results.size(); ++k) {
        const Emva1288Results& r = results[k];
        const NoiseLineFit& line = emva1288LineAtGain(report, gains[k]);
        const double gainDb = linearGainToDb(line.gain);
        const double limit =
            params.maxSignalFraction * (r.mean[r.saturationIndex] - r.darkMean[r.saturationIndex]);
        int steps = 0;
        double worstRelativeError = 0, worstResidual = 0;
        for (size_t i = 0; i < r.mean.size(); ++i) {
            const double signal = r.mean[i] - r.darkMean[i];
            if (signal > limit)
                continue;
            ++steps;
            worstRelativeError = std::max(worstRelativeError, r.varianceStdError[i] / r.variance[i]);
            const double fitted = detail::lineVariance(line.line.a, line.line.b, signal);
            worstResidual = std::max(worstResidual, std::abs(r.variance[i] / fitted - 1));
        }
        // Effective degrees of freedom: each step's variance to 2% (a Gaussian pair of P pixels gives
        // sqrt(2 / P); 2% needs 5,000 pixels), and at least 3 bright steps for a line with a check.
        add(cv::format("steps in the fit (%.1f dB)", gainDb), steps >= 3,
            cv::format("%d bright steps up to %.0f%% of saturation (threshold: 3)", steps,
                       100 * params.maxSignalFraction));
        add(cv::format("effective degrees of freedom (%.1f dB)", gainDb), worstRelativeError <= 0.02,
            cv::format(
                "each step's variance to %.2f%% or better, %.0f effective dof (threshold: 2%%, 5,000 dof)",
                100 * worstRelativeError, 2 / (worstRelativeError * worstRelativeError)));
        // Residuals: real pairs scatter by about 1% from frame to frame (set 001: 0.8%); 3% is a misfit.
        add(cv::format("residuals (%.1f dB)", gainDb), worstResidual <= 0.03,
            cv::format("largest |variance / line - 1| %.2f%% over the fitted steps (threshold: 3%%)",
                       100 * worstResidual));
        // Linearity: the standard's error; beyond 3% one slope cannot hold over the range.
        const bool linear = std::isfinite(r.linearityErrorMin) && std::abs(r.linearityErrorMin) <= 3 &&
                            std::abs(r.linearityErrorMax) <= 3;
        add(cv::format("linearity (%.1f dB)", gainDb), linear,
            cv::format("the standard's linearity error %.3f%% to %.3f%% (threshold: +-3%%)",
                       r.linearityErrorMin, r.linearityErrorMax));
    }
    // Two series labelled with other gains than their slopes show (both K 0.30, one said to be 12 dB)
    // passed with an alpha of 0.089 +- 0.054: the cross-gain fit had nothing to contradict it.
    if (gains.size() < 2)
        return v;
    const VerdictCheck slopes = detail::slopesAgreeWithGains(
        report,
        [&](double gain) {
            std::string names;
            for (size_t k = 0; k < gains.size(); ++k)
                if (std::abs(linearGainToDb(gains[k]) - linearGainToDb(gain)) < 0.01)
                    names += (names.empty() ? "series " : ", ") + std::to_string(k + 1);
            return names.empty() ? std::string("no series") : names;
        },
        "series");
    add(slopes.name, slopes.pass, slopes.figure);
    return v;
}

} // namespace rawgment
} // namespace cv
