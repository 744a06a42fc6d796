// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "calibration_uncertainty.hpp"
#include "noise_terms.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

const char* const kParameterNames[3] = {"alpha", "sigma_d^2", "sigma_r^2"};

/* Least squares from its normal equations A theta = r with every parameter bounded below by 0: the
 * objective theta'A theta - 2 theta'r is convex, so its minimum over the orthant is the unconstrained
 * minimum of one face; with N <= 3 trying all 2^N faces and keeping the best feasible one is exact and
 * cheaper than an iterative solver. */
template <int N> Vec<double, N> nonNegativeLeastSquares(const Matx<double, N, N>& A, const Vec<double, N>& r)
{
    Vec<double, N> best = Vec<double, N>::all(0.0);
    double bestObjective = 0; // at theta = 0
    for (int face = 1; face < (1 << N); ++face) {
        int index[N];
        int m = 0;
        for (int k = 0; k < N; ++k)
            if ((face >> k) & 1)
                index[m++] = k;
        Mat_<double> Af(m, m), rf(m, 1), x;
        for (int i = 0; i < m; ++i) {
            rf(i) = r[index[i]];
            for (int j = 0; j < m; ++j)
                Af(i, j) = A(index[i], index[j]);
        }
        if (!solve(Af, rf, x, DECOMP_LU))
            continue;
        Vec<double, N> theta = Vec<double, N>::all(0.0);
        bool feasible = true;
        for (int i = 0; i < m; ++i) {
            theta[index[i]] = x(i);
            feasible = feasible && x(i) >= 0;
        }
        if (!feasible)
            continue;
        const double objective = theta.dot(A * theta) - 2 * theta.dot(r);
        if (objective < bestObjective) {
            bestObjective = objective;
            best = theta;
        }
    }
    return best;
}

//! The regressors of a sample in the joint model: its variance is x . (alpha, sigma_d^2, sigma_r^2).
Vec3d jointRegressors(const NoiseSample& s)
{
    return Vec3d(s.gain * std::max(s.mean, 0.0), s.gain * s.gain, 1.0);
}

//! pixelFourthCumulant() of a sample under the joint model p: a = g alpha, b = g^2 sigma_d^2 + sigma_r^2.
double jointFourthCumulant(const NoiseSample& s, const Vec3d& p, double readKurtosis)
{
    return pixelFourthCumulant(s.gain * p[0], s.gain * s.gain * p[1] + p[2], s.mean, readKurtosis);
}

//! The largest variance the model predicts over the samples, floored as every weight of the fit is.
double modelVarianceFloor(const std::vector<NoiseSample>& s, const Vec3d& p)
{
    double largest = 0;
    for (const NoiseSample& x : s)
        largest = std::max(largest, jointRegressors(x).dot(p));
    return varianceFloor(largest);
}

/* Huber's psi of a standardized residual and its derivative: what one sample contributes to the
 * estimating equation of the joint fit (a scale of 0: no loss). */
double huberPsi(double z, double scale, bool robust)
{
    return robust && scale > 0 ? std::max(-scale, std::min(scale, z)) : z;
}

double huberPsiSlope(double z, double scale, bool robust)
{
    return !robust || scale <= 0 || std::abs(z) <= scale ? 1.0 : 0.0;
}

//! The rows and columns of the free parameters of a 3x3 matrix, inverted or not; the rest 0.
Matx33d sandwichOfFree(const Matx33d& bread, const Matx33d& meat, const bool free[3], double n)
{
    int index[3];
    int m = 0;
    for (int k = 0; k < 3; ++k)
        if (free[k])
            index[m++] = k;
    Matx33d cov = Matx33d::zeros();
    if (m == 0 || n <= m)
        return cov;
    Mat_<double> A(m, m), B(m, m);
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) {
            A(i, j) = bread(index[i], index[j]);
            B(i, j) = meat(index[i], index[j]);
        }
    Mat_<double> Ainv;
    if (invert(A, Ainv, DECOMP_SVD) == 0)
        return cov;
    const Mat_<double> C = Mat_<double>(Ainv * B * Ainv) * (n / (n - m));
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j)
            cov(index[i], index[j]) = C(i, j);
    return cov;
}

/* The joint fit's sandwich covariance at p: bread sum psi'(z) x x'/se^2, meat sum psi(z)^2 x x'/se^2,
 * with z the standardized residual (the Huber M-estimator's asymptotic covariance). */
Matx33d jointCovariance(const std::vector<NoiseSample>& s, const Vec3d& p, double floor, double lossScale,
                        bool robust, const bool free[3], double readKurtosis)
{
    Matx33d bread = Matx33d::zeros(), meat = Matx33d::zeros();
    for (const NoiseSample& x : s) {
        const Vec3d r = jointRegressors(x);
        const double se =
            sampleVarianceStdError(r.dot(p), x.dof, floor, jointFourthCumulant(x, p, readKurtosis));
        const double z = (x.variance - r.dot(p)) / se;
        const Matx33d outer = (r * r.t()) * (1.0 / (se * se));
        bread += outer * huberPsiSlope(z, lossScale, robust);
        const double psi = huberPsi(z, lossScale, robust);
        meat += outer * (psi * psi);
    }
    return sandwichOfFree(bread, meat, free, static_cast<double>(s.size()));
}

/* The paper's second stage is linear in the per-gain lines: alpha = sum g a_g / sum g^2 and the free
 * read terms (X'X)^-1 X'b with rows (g^2, 1). The lines of different gains are independent, so the
 * covariance is the sum over gains of J_g C_g J_g' with C_g the covariance of (a_g, b_g). */
Matx33d twoStageCovariance(const std::vector<NoiseLineFit>& lines, const bool free[3])
{
    double sgg = 0;
    for (const NoiseLineFit& f : lines)
        sgg += f.gain * f.gain;
    int index[2];
    int m = 0;
    for (int k = 1; k < 3; ++k)
        if (free[k])
            index[m++] = k;
    Mat_<double> gram(m, m, 0.0), gramInv;
    for (const NoiseLineFit& f : lines) {
        const double x[3] = {0, f.gain * f.gain, 1};
        for (int i = 0; i < m; ++i)
            for (int j = 0; j < m; ++j)
                gram(i, j) += x[index[i]] * x[index[j]];
    }
    if (m > 0 && invert(gram, gramInv, DECOMP_SVD) == 0)
        m = 0;
    Matx33d cov = Matx33d::zeros();
    for (const NoiseLineFit& f : lines) {
        const double ab = f.slopeOffsetCorrelation * f.slopeStdError * f.offsetStdError;
        const Matx22d C(f.slopeStdError * f.slopeStdError, ab, ab, f.offsetStdError * f.offsetStdError);
        Matx<double, 3, 2> J = Matx<double, 3, 2>::zeros();
        if (free[0])
            J(0, 0) = f.gain / sgg;
        const double x[3] = {0, f.gain * f.gain, 1};
        for (int i = 0; i < m; ++i)
            for (int j = 0; j < m; ++j)
                J(index[i], 1) += gramInv(i, j) * x[index[j]];
        cov += J * C * J.t();
    }
    return cov;
}

//! The second stage of the paper's fit from per-gain lines (alpha alone when not separable).
Vec3d twoStageOfLines(const std::vector<NoiseLineFit>& lines, const std::vector<Vec2d>& ab, bool separable)
{
    double sga = 0, sgg = 0;
    Matx22d A = Matx22d::zeros();
    Vec2d r(0, 0);
    for (size_t k = 0; k < lines.size(); ++k) {
        const double g = lines[k].gain;
        sga += g * ab[k][0];
        sgg += g * g;
        const Vec2d x(g * g, 1.0);
        A += x * x.t();
        r += x * ab[k][1];
    }
    const Vec2d read = separable ? nonNegativeLeastSquares<2>(A, r) : Vec2d(0, 0);
    return Vec3d(std::max(0.0, sga / sgg), read[0], read[1]);
}

/* Each replicate draws, for every gain, as many samples as the gain has, uniformly with replacement
 * (a multinomial count per sample: the rounds then read the samples in order), and repeats the final
 * fit from the fitted values: two reweighting rounds move a converged fit by far less than its error. */
std::vector<Vec3d> bootstrapEstimates(const std::vector<NoiseSample>& s, const std::vector<GainGroup>& groups,
                                      const CalibrationReport& report, const CalibrationParams& params)
{
    const int replicates = params.bootstrapReplicates;
    const Vec3d p(report.model.alpha, report.model.sigmaD2, report.model.sigmaR2);
    const bool joint = params.method == NOISE_FIT_JOINT && report.separable;
    std::vector<Vec3d> estimates(replicates);
    parallel_for_(Range(0, replicates), [&](const Range& range) {
        std::vector<uint32_t> counts(s.size());
        std::vector<Vec2d> lines(groups.size());
        for (int rep = range.start; rep < range.end; ++rep) {
            std::fill(counts.begin(), counts.end(), 0u);
            CounterRng rng(params.line.seed, bootstrapStream(rep));
            for (const GainGroup& g : groups) {
                const uint64_t n = static_cast<uint64_t>(g.end - g.begin);
                for (uint64_t k = 0; k < n; ++k)
                    ++counts[g.begin + static_cast<int>((static_cast<uint64_t>(rng.nextU32()) * n) >> 32)];
            }
            if (joint) {
                estimates[rep] =
                    refineJointFit(s.data(), counts.data(), static_cast<int>(s.size()), p, params.lossScale,
                                   params.line.robust, 2, report.readExcessKurtosis);
            } else {
                for (size_t k = 0; k < groups.size(); ++k)
                    lines[k] = refineNoiseLine(s.data() + groups[k].begin, counts.data() + groups[k].begin,
                                               groups[k].end - groups[k].begin,
                                               Vec2d(report.perGain[k].line.a, report.perGain[k].line.b), 2,
                                               report.readExcessKurtosis);
                estimates[rep] = twoStageOfLines(report.perGain, lines, report.separable);
            }
        }
    });
    return estimates;
}

Matx33d covarianceOf(const std::vector<Vec3d>& x)
{
    Vec3d mean(0, 0, 0);
    for (const Vec3d& v : x)
        mean += v;
    mean *= 1.0 / static_cast<double>(x.size());
    Matx33d cov = Matx33d::zeros();
    for (const Vec3d& v : x)
        cov += (v - mean) * (v - mean).t();
    return cov * (1.0 / static_cast<double>(x.size() - 1));
}

Vec3d stdErrorsOf(const Matx33d& cov)
{
    return Vec3d(std::sqrt(std::max(0.0, cov(0, 0))), std::sqrt(std::max(0.0, cov(1, 1))),
                 std::sqrt(std::max(0.0, cov(2, 2))));
}

/* The mean-error correction of one sample (docs/mathematics.md): a fit's estimating equation gains
 * (c b w / T)(x' - 2 c x / m), with c the slope of the variance in the mean, b = m - c mu the read part,
 * T = dof + 1 frames, x' the regressors' slope in the mean. Returned: the factor c b w / T, and the
 * caller adds it times (x' - 2 c x / m). Only above black, where the model has a slope: dark frames are
 * given their exact mean 0 (rawgment_calibrate does), which has no error to correct. */
double meanErrorFactor(const NoiseSample& s, double slope, double m, double w)
{
    if (!(s.mean > 0))
        return 0.0;
    const double c = std::max(slope, 0.0);
    return c * std::max(m - c * s.mean, 0.0) * w / (s.dof + 1.0);
}

} // namespace

Vec2d refineNoiseLine(const NoiseSample* s, const uint32_t* counts, int n, Vec2d ab, int rounds,
                      double readKurtosis)
{
    for (int round = 0; round < rounds; ++round) {
        double largest = 0;
        for (int i = 0; i < n; ++i)
            largest = std::max(largest, lineVariance(ab[0], ab[1], s[i].mean));
        const double floor = varianceFloor(largest);
        Matx22d A = Matx22d::zeros();
        Vec2d r(0, 0);
        for (int i = 0; i < n; ++i) {
            const double count = counts != nullptr ? counts[i] : 1.0;
            if (count == 0)
                continue;
            const double m = std::max(lineVariance(ab[0], ab[1], s[i].mean), floor);
            const double se = sampleVarianceStdError(
                m, s[i].dof, floor, pixelFourthCumulant(ab[0], ab[1], s[i].mean, readKurtosis));
            const double w = count / (se * se);
            const Vec2d x(s[i].mean, 1.0);
            A += (x * x.t()) * w;
            r += x * (w * s[i].variance);
            const double a = std::max(ab[0], 0.0);
            r += (Vec2d(1, 0) - x * (2 * a / m)) * meanErrorFactor(s[i], a, m, w);
        }
        const double det = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
        if (!(det > 0))
            break;
        ab = A.inv() * r;
    }
    return ab;
}

Vec3d refineJointFit(const NoiseSample* s, const uint32_t* counts, int n, Vec3d p, double lossScale,
                     bool robust, int rounds, double readKurtosis)
{
    for (int round = 0; round < rounds; ++round) {
        double largest = 0;
        for (int i = 0; i < n; ++i)
            largest = std::max(largest, jointRegressors(s[i]).dot(p));
        const double floor = varianceFloor(largest);
        Matx33d A = Matx33d::zeros();
        Vec3d r(0, 0, 0);
        for (int i = 0; i < n; ++i) {
            const double count = counts != nullptr ? counts[i] : 1.0;
            if (count == 0)
                continue;
            const Vec3d x = jointRegressors(s[i]);
            const double m = std::max(x.dot(p), floor);
            const double se =
                sampleVarianceStdError(m, s[i].dof, floor, jointFourthCumulant(s[i], p, readKurtosis));
            double w = count / (se * se);
            const double z = std::abs(s[i].variance - m) / se;
            if (robust && lossScale > 0 && z > lossScale)
                w *= lossScale / z; // Huber's loss as a reweighting
            A += (x * x.t()) * w;
            r += x * (w * s[i].variance);
            const double c = std::max(s[i].gain * p[0], 0.0);
            r += (Vec3d(s[i].gain, 0, 0) - x * (2 * c / m)) * meanErrorFactor(s[i], c, m, w);
        }
        p = nonNegativeLeastSquares<3>(A, r);
    }
    return p;
}

bool lineCovariance(const std::vector<NoiseSample>& s, const std::vector<int>& idx, double a, double b,
                    double readKurtosis, Matx22d& covariance)
{
    const double n = static_cast<double>(idx.size());
    if (idx.size() < 3)
        return false;
    double largest = 0;
    for (int i : idx)
        largest = std::max(largest, lineVariance(a, b, s[i].mean));
    const double floor = varianceFloor(largest);
    Matx22d bread = Matx22d::zeros(), meat = Matx22d::zeros();
    for (int i : idx) {
        const double predicted = lineVariance(a, b, s[i].mean);
        const double se = sampleVarianceStdError(predicted, s[i].dof, floor,
                                                 pixelFourthCumulant(a, b, s[i].mean, readKurtosis));
        const Vec2d x(s[i].mean, 1.0);
        const double w = 1.0 / (se * se);
        const double e = s[i].variance - predicted;
        bread += (x * x.t()) * w;
        meat += (x * x.t()) * (w * w * e * e);
    }
    const double det = bread(0, 0) * bread(1, 1) - bread(0, 1) * bread(1, 0);
    if (!(det > 0))
        return false;
    const Matx22d inv = bread.inv();
    covariance = (inv * meat * inv) * (n / (n - 2));
    return true;
}

ModelUncertainty modelUncertainty(const std::vector<NoiseSample>& inliers,
                                  const std::vector<GainGroup>& groups, const CalibrationReport& report,
                                  const CalibrationParams& params, std::vector<std::string>& notes)
{
    CV_Assert(groups.size() == report.perGain.size());
    ModelUncertainty u;
    const Vec3d p(report.model.alpha, report.model.sigmaD2, report.model.sigmaR2);
    const bool free[3] = {p[0] > 0, report.separable && p[1] > 0, report.separable && p[2] > 0};
    const double floor = modelVarianceFloor(inliers, p);
    const Matx33d fitCov = params.method == NOISE_FIT_JOINT && report.separable
                               ? jointCovariance(inliers, p, floor, params.lossScale, params.line.robust,
                                                 free, report.readExcessKurtosis)
                               : twoStageCovariance(report.perGain, free);
    u.fitStdError = stdErrorsOf(fitCov);
    u.covariance = fitCov;
    u.source = UNCERTAINTY_COVARIANCE;
    const int parameters = report.separable ? 3 : 1;
    const bool boundActive = !free[0] || (report.separable && (!free[1] || !free[2]));
    if (params.bootstrapReplicates >= 2) {
        const Matx33d bootCov = covarianceOf(bootstrapEstimates(inliers, groups, report, params));
        u.bootstrapStdError = stdErrorsOf(bootCov);
        u.bootstrapReplicates = params.bootstrapReplicates;
        int widest = -1;
        for (int k = 0; k < parameters; ++k)
            if (free[k] && u.bootstrapStdError[k] > 1.25 * u.fitStdError[k] &&
                (widest < 0 || u.bootstrapStdError[k] / u.fitStdError[k] >
                                   u.bootstrapStdError[widest] / u.fitStdError[widest]))
                widest = k;
        if (boundActive || widest >= 0) {
            u.covariance = bootCov;
            u.source = UNCERTAINTY_BOOTSTRAP;
        }
        if (widest >= 0)
            notes.push_back(format("the bootstrap's standard error of %s is %.0f%% larger than the fit "
                                   "covariance's: the samples scatter more than the fit assumes, so the "
                                   "bootstrap's errors are reported",
                                   kParameterNames[widest],
                                   100.0 * (u.bootstrapStdError[widest] / u.fitStdError[widest] - 1.0)));
    } else if (boundActive) {
        for (int k = 0; k < parameters; ++k)
            if (!free[k])
                notes.push_back(format("%s sits at its bound 0, where the fit's covariance does not hold: it "
                                       "has no standard error without the bootstrap",
                                       kParameterNames[k]));
    }
    u.stdError = stdErrorsOf(u.covariance);
    return u;
}

} // namespace detail

namespace {

//! Adds the Fisher information of one sample (dof, at the model's variance m of regressors x), times n.
void addInformation(Matx33d& info, const Vec3d& x, double m, int dof, double n)
{
    info += (x * x.t()) * (n * dof / (2.0 * m * m));
}

/* sqrt of the diagonal of the (pseudo-)inverse of an information matrix, equilibrated first (its entries
 * span ten orders of magnitude). With one gain the read terms are not identifiable, but alpha is, and
 * the pseudo-inverse gives its variance exactly; the read terms' entries are then meaningless and set to 0.
 */
Vec3d informationStdErrors(const Matx33d& info, bool readTermsIdentifiable)
{
    Matx33d scaled;
    double d[3];
    for (int k = 0; k < 3; ++k)
        d[k] = info(k, k) > 0 ? 1.0 / std::sqrt(info(k, k)) : 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            scaled(i, j) = info(i, j) * d[i] * d[j];
    Matx33d inv;
    cv::invert(scaled, inv, DECOMP_SVD);
    Vec3d se;
    for (int k = 0; k < 3; ++k)
        se[k] = std::sqrt(std::max(0.0, inv(k, k))) * d[k];
    if (!readTermsIdentifiable)
        se[1] = se[2] = 0;
    return se;
}

} // namespace

Vec3d projectedStdError(const std::vector<NoiseSample>& samples, const CalibrationReport& report,
                        const CalibrationPlan& plan)
{
    if (samples.empty())
        CV_Error(Error::StsBadArg, "projectedStdError: no samples");
    if (!(plan.frameFactor > 0) || !(plan.pixelFactor > 0) || !(plan.addGain >= 0) ||
        !std::isfinite(plan.frameFactor) || !std::isfinite(plan.pixelFactor) || !std::isfinite(plan.addGain))
        CV_Error(Error::StsBadArg, "projectedStdError: frameFactor and pixelFactor must be finite and > 0, "
                                   "addGain finite and >= 0");
    if (report.uncertainty.source == UNCERTAINTY_NONE)
        CV_Error(Error::StsBadArg, "projectedStdError: the report has no uncertainty");
    const NoiseModel& model = report.model;
    const Vec3d p(model.alpha, model.sigmaD2, model.sigmaR2);
    double largest = 0;
    for (const NoiseSample& s : samples)
        largest = std::max(largest, detail::noiseTermsAt(s.gain, p[0], p[1], p[2]).variance(s.mean));
    const double floor = detail::varianceFloor(largest);
    const auto variance = [&](double gain, double mean) {
        return std::max(detail::noiseTermsAt(gain, p[0], p[1], p[2]).variance(mean), floor);
    };
    Matx33d now = Matx33d::zeros(), changed = Matx33d::zeros();
    double highest = 0;
    std::map<double, double> pixelsOfGain;
    for (const NoiseSample& s : samples) {
        highest = std::max(highest, s.gain);
        pixelsOfGain[s.gain] += 1;
    }
    for (const NoiseSample& s : samples) {
        const Vec3d x = detail::jointRegressors(s);
        const double m = variance(s.gain, s.mean);
        const int dof = std::max(1, static_cast<int>(std::lround((s.dof + 1) * plan.frameFactor)) - 1);
        addInformation(now, x, m, s.dof, 1.0);
        addInformation(changed, x, m, dof, plan.pixelFactor);
        if (plan.addGain > 0 && s.gain == highest) {
            NoiseSample t = s;
            t.gain = plan.addGain;
            addInformation(changed, detail::jointRegressors(t), variance(t.gain, t.mean), dof,
                           plan.pixelFactor);
        }
    }
    if (plan.addDarkFrames) {
        const int dof =
            std::max(1, static_cast<int>(std::lround((samples[0].dof + 1) * plan.frameFactor)) - 1);
        for (const auto& g : pixelsOfGain) {
            NoiseSample d;
            d.gain = g.first;
            addInformation(changed, detail::jointRegressors(d), variance(g.first, 0.0), dof,
                           g.second * plan.pixelFactor);
        }
        if (plan.addGain > 0) {
            NoiseSample d;
            d.gain = plan.addGain;
            addInformation(changed, detail::jointRegressors(d), variance(plan.addGain, 0.0), dof,
                           pixelsOfGain[highest] * plan.pixelFactor);
        }
    }
    const bool separableAfter = pixelsOfGain.size() >= 2 || (plan.addGain > 0 && plan.addGain != highest);
    const Vec3d before = informationStdErrors(now, pixelsOfGain.size() >= 2),
                after = informationStdErrors(changed, separableAfter);
    Vec3d out;
    for (int k = 0; k < 3; ++k) {
        const double measured = report.uncertainty.stdError[k];
        out[k] = measured > 0 && before[k] > 0 ? measured * after[k] / before[k] : after[k];
    }
    return out;
}

double ModelUncertainty::correlation(NoiseModelParameter first, NoiseModelParameter second) const
{
    CV_Assert(first >= 0 && first < 3 && second >= 0 && second < 3);
    const double d = std::sqrt(covariance(first, first) * covariance(second, second));
    return d > 0 ? covariance(first, second) / d : 0.0;
}

Vec2d CalibrationReport::interval(NoiseModelParameter parameter, double level) const
{
    if (!(level > 0 && level < 1))
        CV_Error(Error::StsBadArg, format("CalibrationReport::interval: level %g is not in (0, 1)", level));
    if (parameter < 0 || parameter > 2)
        CV_Error(
            Error::StsBadArg,
            format("CalibrationReport::interval: parameter %d is not a NoiseModelParameter", int(parameter)));
    if (uncertainty.source == UNCERTAINTY_NONE)
        CV_Error(Error::StsBadArg, "CalibrationReport::interval: the report has no uncertainty (a report of "
                                   "format 1, or one made by hand)");
    const double value[3] = {model.alpha, model.sigmaD2, model.sigmaR2};
    const double half = -detail::lowerNormalQuantile(0.5 * (1 - level)) * uncertainty.stdError[parameter];
    return Vec2d(value[parameter] - half, value[parameter] + half);
}

} // namespace rawgment
} // namespace cv
