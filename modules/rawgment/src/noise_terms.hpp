// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The one home of the noise model's terms (paper Eq. 5) and of the standard error of a sample
// variance. The simulator draws these terms, calibration fits them, augmentation adds what a target
// lacks of them: each uses this header, so a term is written once. Private to the module. The
// equations, with the paper's numbers: docs/mathematics.md.
#ifndef OPENCV_RAWGMENT_SRC_NOISE_TERMS_HPP
#define OPENCV_RAWGMENT_SRC_NOISE_TERMS_HPP

#include <opencv2/rawgment/noise_model.hpp>

#include <algorithm>
#include <cmath>

namespace cv {
namespace rawgment {
namespace detail {

//! The variance of a line \f$ a\max(\mu, 0) + b \f$ at a black-subtracted mean: no shot noise below black.
template <typename T> inline T lineVariance(T a, T b, T mean)
{
    return a * std::max(mean, T(0)) + b;
}

/** The variance of one gain split into the parts that a change of exposure or gain scales differently
 * (paper Eq. 5 and 13). T is double, float or a Ceres Jet. */
template <typename T> struct NoiseTerms
{
    T shot;           //!< \f$ g\alpha \f$: variance per DN of mean, from the photon count
    T readBeforeGain; //!< \f$ g^2\sigma_d^2 \f$: read noise amplified by the gain
    T readAfterGain;  //!< \f$ \sigma_r^2 \f$: noise added after the gain (quantisation included)

    //! The offset b of the per-gain line: all the variance that does not depend on the mean.
    T read() const { return readBeforeGain + readAfterGain; }
    //! The variance at a black-subtracted mean (double: a data value, never a parameter).
    T variance(double mean) const { return shot * std::max(mean, 0.0) + read(); }
};

//! The terms at linear gain g of a model (alpha, sigma_d^2, sigma_r^2).
template <typename T> inline NoiseTerms<T> noiseTermsAt(T gain, T alpha, T sigmaD2, T sigmaR2)
{
    return {gain * alpha, gain * gain * sigmaD2, sigmaR2};
}

/** A NoiseModel that passed NoiseModel::validate(), once: the only way to its terms without a second
 * validation. A noise step builds everything it needs from one (StepNoise, step_noise.hpp), and a scene
 * makes one for all its steps. Holds a reference: it lives no longer than the call that made it. */
class ValidatedNoiseModel
{
public:
    explicit ValidatedNoiseModel(const NoiseModel& model) : model_(model) { model.validate(); }
    const NoiseModel& model() const { return model_; }
    /** The terms at linear gain g: throws StsBadArg when the gain is not finite and positive or a term
     * overflows. With measured lines, measuredTermsAt(); else noiseTermsAt() of Eq. 5's parameters. */
    NoiseTerms<double> termsAt(double gain) const;

private:
    const NoiseModel& model_;
};

/** The terms of a model at linear gain g, after checking both (ValidatedNoiseModel::termsAt() of a model
 * validated for this call). NoiseModel::lineAtGain() is built from it. */
NoiseTerms<double> checkedNoiseTerms(const NoiseModel& model, double gain);

/** The terms of a model with measured lines (NoiseModel::measuredLines, which says how they are
 * interpolated and extrapolated) at linear gain g > 0; the offset split before and after the gain as
 * Eq. 5's at g. The model is taken as valid (noise_lines.cpp). */
NoiseTerms<double> measuredTermsAt(const NoiseModel& model, double gain);

//! Throws StsBadArg naming the entry when measured lines are not by increasing gain or hold a value
//! that is negative or not finite (NoiseModel::validate()).
void checkMeasuredLines(const std::vector<MeasuredNoiseLine>& lines);

//! The measured lines as the list `measured_lines` of a model file (NoiseModel::write()).
void writeMeasuredLines(FileStorage& fs, const std::vector<MeasuredNoiseLine>& lines);

//! The list `measured_lines` of a model file, every entry's keys and values checked.
std::vector<MeasuredNoiseLine> readMeasuredLines(const FileNode& list);

/** @name The Tukey-lambda shape of the read noise (NoiseModel::tukeyRead)
 * X = (U^lambda - (1 - U)^lambda) / lambda for U uniform in (0, 1); lambda = 0 is the logistic
 * log(U / (1 - U)). Moments from the Beta function (docs/mathematics.md, "Dark-frame noise").
 * The tests check them against SciPy (they link the library's objects statically: rawgment_internal). */
//! @{
//! The variance of X (finite for lambda > -1/2).
double tukeyLambdaVariance(double lambda);
//! The excess kurtosis of X (finite for lambda > -1/4): 0 near lambda = 0.1349, 1.2 at 0, -1.2 at 1.
double tukeyLambdaExcessKurtosis(double lambda);
/** The lambda in [kTukeyLambdaMin, 1] whose excess kurtosis is `kurtosis`, clamped to the kurtosis range
 * of that interval (bisection: the kurtosis falls monotonically as lambda grows there). */
double tukeyLambdaOfExcessKurtosis(double kurtosis);
//! The quantile X(u) (expm1 keeps it exact for lambda near 0).
double tukeyLambdaQuantile(double u, double lambda);
//! The smallest lambda the library draws or accounts for: excess kurtosis 95, far past any sensor's.
constexpr double kTukeyLambdaMin = -0.2;

/** Unit-variance Tukey-lambda draws: quantile(u) / sd(lambda). */
struct TukeyUnitSampler
{
    double lambda = 0, invSd = 1;
    TukeyUnitSampler() = default; //!< unused: no moments computed
    explicit TukeyUnitSampler(double lambda_)
        : lambda(lambda_), invSd(1 / std::sqrt(tukeyLambdaVariance(lambda_)))
    {
    }
    double operator()(double u) const { return invSd * tukeyLambdaQuantile(u, lambda); }
};

/** The shape of the read noise an augmentation adds so that, added to the prior's (Tukey, lambda),
 * the result has the target's excess kurtosis: fourth cumulants add for independent parts, so the
 * added part needs kappa (b_t^2 - K_prior) / added^2, where b_t is the target's read variance, K_prior
 * the prior's sum over its weighted copies of w^4 b^2 (a scaled prior: p^4 b_in^2; a blur: sum w^4 b^2)
 * and `added` = b_t - (the prior's read variance). Two shapes summed are not a Tukey-lambda shape:
 * this matches variance and kurtosis only (docs/mathematics.md measures the error). Returns `lambda`
 * itself when nothing is added. */
double addedReadLambda(double lambda, double targetRead, double priorFourthMoment, double added);
//! @}

/** Throws StsBadArg naming the map when a dark-shading map holds NaN or Inf: a pass over both maps, so
 * it runs where a model enters (read(), write(), the simulator), not in validate(), which every step
 * calls; the steps detect a non-finite map in the rows they read (darkRowExtra()). */
void checkDarkShadingFinite(const NoiseModel& model);

/** The smallest variance a sample's expectation is taken to have when it is weighted or standardised:
 * zero to double precision next to the largest variance the line or model predicts over the samples
 * (1e-15 of it, and > 0). It only keeps a prediction of 0 from dividing by 0. A larger floor would be
 * wrong, not safer: samples of exactly zero variance (dead or stuck pixels) would then count as
 * inliers of any line whose offset is near 0 and pull it there (the 5%-outlier calibration test
 * fails with a floor of 1e-9 of the largest prediction). Relative to the prediction, not to the data,
 * so that outliers with huge variances cannot lift it. */
inline double varianceFloor(double largestPredictedVariance)
{
    return std::max(1e-15 * largestPredictedVariance, 1e-300);
}

/** The fourth cumulant (DN^4) of a pixel's value on the noise line (a, b) at `mean`: the read part's
 * \f$ \kappa b^2 \f$ (kappa its excess kurtosis, 0 when Gaussian) plus the Poisson part's
 * \f$ a^3 \mu \f$ (every cumulant of a count equals its mean, and a DN per electron scales the fourth
 * by a^4). Fourth cumulants of independent parts add. */
inline double pixelFourthCumulant(double a, double b, double mean, double readKurtosis)
{
    const double shot = std::max(a, 0.0);
    return readKurtosis * b * b + shot * shot * shot * std::max(mean, 0.0);
}

/** Standard error of an unbiased sample variance of `dof` degrees of freedom whose expectation is
 * `expected`: \f$ \sqrt{2 v^2/dof + \kappa_4/(dof + 1)} \f$, the exact variance of a sample variance of
 * dof + 1 independent values whose fourth cumulant is kappa_4 (pixelFourthCumulant(); 0 gives the scaled
 * chi-square of Gaussian data). The expectation is floored at `floor` (varianceFloor()); dof below 1
 * counts as 1. */
inline double sampleVarianceStdError(double expected, int dof, double floor, double fourthCumulant = 0)
{
    const double v = std::max(expected, floor);
    const int d = std::max(dof, 1);
    return std::sqrt(std::max(2.0 * v * v / d + fourthCumulant / (d + 1.0), 2.0 * v * v / d * 1e-6));
}

/** The degrees of freedom of the scaled chi-square with the same relative spread as such a sample
 * variance, \f$ 2 v^2 / se^2 \f$ (dof itself for Gaussian data, fewer for heavy tails). */
inline double effectiveDof(double expected, int dof, double floor, double fourthCumulant)
{
    const double v = std::max(expected, floor),
                 se = sampleVarianceStdError(expected, dof, floor, fourthCumulant);
    return 2.0 * v * v / (se * se);
}

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_NOISE_TERMS_HPP
