// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/calibration.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <deque>
#include <map>
#include <numeric>

namespace cv {
namespace rawgment {

// Per-gain line fits, the cross-gain fit of the noise model, and the calibration report.

// ---------------------------------------------------------------------------------------------------
// Per-gain line

namespace {

struct LineLS
{
    double a = 0, b = 0, r2 = 0;
};

/** Least squares of v on mu over the selected samples, weighted by `weights` (empty: unweighted);
 * R^2 is the ordinary one (unweighted sums). False when the means do not vary. */
bool leastSquaresLine(const std::vector<NoiseSample>& s, const std::vector<int>& idx,
                      const std::vector<double>& weights, LineLS& out)
{
    if (idx.size() < 2)
        return false;
    double sw = 0, mx = 0, my = 0;
    for (int i : idx) {
        const double w = weights.empty() ? 1.0 : weights[i];
        sw += w;
        mx += w * s[i].mean;
        my += w * s[i].variance;
    }
    mx /= sw;
    my /= sw;
    double sxx = 0, sxy = 0;
    for (int i : idx) {
        const double w = weights.empty() ? 1.0 : weights[i];
        const double dx = s[i].mean - mx;
        sxx += w * dx * dx;
        sxy += w * dx * (s[i].variance - my);
    }
    if (!(sxx > 1e-12 * std::max(1.0, mx * mx) * sw))
        return false;
    out.a = sxy / sxx;
    out.b = my - out.a * mx;
    double mean = 0;
    for (int i : idx)
        mean += s[i].variance;
    mean /= static_cast<double>(idx.size());
    double ssRes = 0, ssTot = 0;
    for (int i : idx) {
        const double e = s[i].variance - (out.a * s[i].mean + out.b);
        ssRes += e * e;
        ssTot += (s[i].variance - mean) * (s[i].variance - mean);
    }
    out.r2 = ssTot > 0 ? 1.0 - ssRes / ssTot : 1.0;
    return true;
}

/** Iterated weighted least squares: a sample variance of `dof` degrees of freedom has variance
 * 2 v^2 / dof around its expectation v, so each sample is weighted by dof / (2 v^2) with v from the
 * previous line (Fisher scoring for the Gamma likelihood of sample variances). Unlike ordinary least
 * squares, the many precise dark samples then pin the offset instead of the few noisy bright ones. */
bool weightedNoiseLine(const std::vector<NoiseSample>& s, const std::vector<int>& idx, LineLS& out)
{
    if (!leastSquaresLine(s, idx, {}, out))
        return false;
    std::vector<double> w(s.size(), 0.0);
    for (int round = 0; round < 4; ++round) {
        double largest = 0;
        for (int i : idx)
            largest = std::max(largest, detail::lineVariance(out.a, out.b, s[i].mean));
        const double floor = detail::varianceFloor(largest);
        for (int i : idx) {
            const double se = detail::sampleVarianceStdError(detail::lineVariance(out.a, out.b, s[i].mean),
                                                             s[i].dof, floor);
            w[i] = 1.0 / (se * se);
        }
        LineLS next;
        if (!leastSquaresLine(s, idx, w, next))
            break;
        out = next;
    }
    return true;
}

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

//! Residual in standard errors of a sample variance around the line at the sample's mean.
double standardizedResidual(const NoiseSample& s, double a, double b, double floor)
{
    const double predicted = detail::lineVariance(a, b, s.mean);
    return (s.variance - predicted) / detail::sampleVarianceStdError(predicted, s.dof, floor);
}

std::vector<int> inliersOf(const std::vector<NoiseSample>& s, double a, double b, double threshold)
{
    const double floor = lineVarianceFloor(a, b, meanRangeOf(s));
    std::vector<int> idx;
    for (int i = 0; i < static_cast<int>(s.size()); ++i)
        if (std::abs(standardizedResidual(s[i], a, b, floor)) <= threshold)
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
    NoiseLineFit fit;
    fit.gain = samples[0].gain;
    fit.samples = static_cast<int>(samples.size());
    std::vector<int> all(samples.size());
    std::iota(all.begin(), all.end(), 0);
    LineLS ls;
    if (!weightedNoiseLine(samples, all, ls))
        CV_Error(Error::StsBadArg, "fitNoiseLine: all samples share one mean; the slope needs at least two "
                                   "distinct means");
    std::vector<int> chosen = all;
    if (params.robust) {
        const int n = static_cast<int>(samples.size());
        const MeanRange range = meanRangeOf(samples);
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
            for (const NoiseSample& s : samples)
                count += std::abs(standardizedResidual(s, a, b, floor)) <= params.inlierThreshold ? 1 : 0;
            if (count > bestCount) {
                bestCount = count;
                bestA = a;
                bestB = b;
            }
        }
        // Refine: least squares on the inliers, then once more on the inliers of the refined line.
        for (int round = 0; round < 2; ++round) {
            std::vector<int> inl = inliersOf(samples, bestA, bestB, params.inlierThreshold);
            LineLS refined;
            if (!weightedNoiseLine(samples, inl, refined))
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

/* (v - (g alpha mu + g^2 sigma_d^2 + sigma_r^2)) / scale: one sample of the joint fit. The model is
 * linear in its parameters, so the Jacobian is the constant (-g max(mu, 0), -g^2, -1) / scale; written
 * out rather than differentiated automatically, and held in one array that the problem does not own,
 * because a calibration without a chart has hundreds of thousands of samples and a heap object and a
 * dual-number evaluation per sample were most of its time. */
class JointResidual final : public ceres::SizedCostFunction<1, 3>
{
public:
    JointResidual(double mean, double variance, double gain, double invScale)
        : mu(mean), v(variance), g(gain), w(invScale)
    {
    }
    bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override
    {
        const double* p = parameters[0];
        residuals[0] = (v - detail::noiseTermsAt(g, p[0], p[1], p[2]).variance(mu)) * w;
        if (jacobians != nullptr && jacobians[0] != nullptr) {
            jacobians[0][0] = -g * std::max(mu, 0.0) * w;
            jacobians[0][1] = -g * g * w;
            jacobians[0][2] = -w;
        }
        return true;
    }

private:
    double mu, v, g, w;
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
    if (!(params.lossScale > 0) || params.reweightIterations < 1 || !(params.minGainRatio >= 1))
        CV_Error(Error::StsBadArg, "calibrateNoiseModel: lossScale must be > 0, reweightIterations >= 1, "
                                   "minGainRatio >= 1");
    CalibrationReport report;
    report.method = params.method;
    report.samples = static_cast<int>(samples.size());

    std::map<double, std::vector<NoiseSample>> byGain;
    for (const NoiseSample& s : samples)
        byGain[s.gain].push_back(s);
    std::vector<NoiseSample> inlierSamples;
    for (auto& entry : byGain) {
        NoiseLineFit fit;
        try {
            fit = fitNoiseLine(entry.second, params.line);
        } catch (const Exception& e) {
            CV_Error(Error::StsBadArg, format("calibrateNoiseModel: gain %g: ", entry.first) + e.err);
        }
        report.perGain.push_back(fit);
        if (fit.line.a < 0 || fit.line.b < 0)
            report.notes.push_back(
                format("gain %g: the line has a negative %s (a = %g, b = %g); the data do not "
                       "follow the model there",
                       fit.gain, fit.line.a < 0 ? "slope" : "offset", fit.line.a, fit.line.b));
        if (params.line.robust) {
            for (int i : inliersOf(entry.second, fit.line.a, fit.line.b, params.line.inlierThreshold))
                inlierSamples.push_back(entry.second[i]);
        } else {
            inlierSamples.insert(inlierSamples.end(), entry.second.begin(), entry.second.end());
        }
    }

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
        return report;
    }
    double sigmaD2 = 0, sigmaR2 = 0;
    fitOffsets(report.perGain, sigmaD2, sigmaR2);

    if (params.method == NOISE_FIT_JOINT) {
        double p[3] = {alpha, sigmaD2, sigmaR2};
        for (int round = 0; round < params.reweightIterations; ++round) {
            // Weights from the previous fit: the standard error of each sample variance.
            std::vector<double> predicted;
            for (const NoiseSample& s : inlierSamples)
                predicted.push_back(detail::noiseTermsAt(s.gain, p[0], p[1], p[2]).variance(s.mean));
            const double floor = detail::varianceFloor(*std::max_element(predicted.begin(), predicted.end()));
            // The residuals and the one loss outlive the problem, which only points at them (a deque:
            // its elements never move, and a cost function cannot).
            std::deque<JointResidual> residuals;
            ceres::HuberLoss huber(params.lossScale);
            ceres::Problem::Options problemOptions;
            problemOptions.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
            problemOptions.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
            ceres::Problem problem(problemOptions);
            for (size_t i = 0; i < inlierSamples.size(); ++i) {
                const NoiseSample& s = inlierSamples[i];
                const double scale = detail::sampleVarianceStdError(predicted[i], s.dof, floor);
                residuals.emplace_back(s.mean, s.variance, s.gain, 1.0 / scale);
                problem.AddResidualBlock(&residuals.back(), params.line.robust ? &huber : nullptr, p);
            }
            for (int k = 0; k < 3; ++k)
                problem.SetParameterLowerBound(p, k, 0.0);
            ceres::Solver::Summary summary;
            ceres::Solve(solverOptions(), &problem, &summary);
            if (!summary.IsSolutionUsable())
                CV_Error(Error::StsError,
                         "calibrateNoiseModel: the joint fit failed: " + summary.BriefReport());
        }
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
    return report;
}

// ---------------------------------------------------------------------------------------------------
// Report I/O

void CalibrationReport::write(FileStorage& fs, const String& name) const
{
    // Any other value would be written as one of the two and read back as a method that never ran.
    if (method != NOISE_FIT_JOINT && method != NOISE_FIT_TWO_STAGE)
        CV_Error(Error::StsBadArg,
                 format("CalibrationReport::write: method %d is not a NoiseFitMethod", int(method)));
    fs << name << "{";
    fs << "format_version" << FORMAT_VERSION;
    fs << "method" << (method == NOISE_FIT_JOINT ? "joint" : "two_stage");
    fs << "separable" << static_cast<int>(separable);
    model.write(fs, "noise_model");
    fs << "r_squared_slope" << rSquaredSlope;
    fs << "r_squared_offset" << rSquaredOffset;
    fs << "samples" << samples;
    fs << "samples_used" << samplesUsed;
    fs << "per_gain"
       << "[";
    for (const NoiseLineFit& f : perGain) {
        fs << "{";
        fs << "gain" << f.gain << "gain_db" << linearGainToDb(f.gain) << "a" << f.line.a << "b" << f.line.b;
        fs << "r_squared" << f.rSquared << "inliers" << f.inliers << "samples" << f.samples;
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
    const FileNode version = node["format_version"];
    if (!version.isInt() || static_cast<int>(version) < 1 || static_cast<int>(version) > FORMAT_VERSION)
        CV_Error(Error::StsParseError,
                 format("calibration report: format_version is missing or newer than %d", FORMAT_VERSION));
    CalibrationReport r;
    try {
        rejectUnknownKeys(node, {"format_version", "method", "separable", "noise_model", "r_squared_slope",
                                 "r_squared_offset", "samples", "samples_used", "per_gain", "notes"});
        for (const FileNode& g : node["per_gain"])
            rejectUnknownKeys(g, {"gain", "gain_db", "a", "b", "r_squared", "inliers", "samples"});
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
