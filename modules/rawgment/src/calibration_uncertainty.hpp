// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The final weighted fits of a calibration and their standard errors: the sandwich covariance of each
// weighted fit, its propagation through the paper's two-stage fit, and the bootstrap that checks it. Private
// to the module; the equations are in docs/mathematics.md ("How exact a calibration is").
#ifndef OPENCV_RAWGMENT_SRC_CALIBRATION_UNCERTAINTY_HPP
#define OPENCV_RAWGMENT_SRC_CALIBRATION_UNCERTAINTY_HPP

#include <opencv2/rawgment/calibration.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

/* The final weighted fits, shared by the calibration and its bootstrap. Each round weights every sample
 * by the inverse squared standard error of a sample variance at the previous fit (Fisher scoring for
 * sample variances) and corrects the estimating equation for the error of the sample's own mean: the
 * weights and the regressor are taken at a mean that is itself noisy and, through the shot noise's
 * skew, correlated with the variance; uncorrected this biased the read terms of a 16-frame calibration
 * by one to two standard errors (docs/mathematics.md). counts: each sample's multiplicity (a bootstrap
 * draw), or nullptr for one each. */

/* readKurtosis: the read noise's excess kurtosis, which with the Poisson part sets each sample
 * variance's spread (pixelFourthCumulant()); 0 for Gaussian read noise. */

//! The line (a, b) of one gain, `rounds` rounds from `ab`.
Vec2d refineNoiseLine(const NoiseSample* s, const uint32_t* counts, int n, Vec2d ab, int rounds,
                      double readKurtosis);

/** The joint model (alpha, sigma_d^2, sigma_r^2) >= 0, `rounds` rounds from `p`, exactly bounded (see
 * nonNegativeLeastSquares in the source); lossScale > 0 with `robust` adds Huber's loss by reweighting. */
Vec3d refineJointFit(const NoiseSample* s, const uint32_t* counts, int n, Vec3d p, double lossScale,
                     bool robust, int rounds, double readKurtosis);

/** The sandwich covariance of the weighted line (a, b) fitted to s[idx], with the weights of its final
 * round (the inverse squared standard error of each sample variance around the line), scaled by
 * n / (n - 2) for the two fitted parameters. False with fewer than 3 samples or means that do not vary. */
bool lineCovariance(const std::vector<NoiseSample>& s, const std::vector<int>& idx, double a, double b,
                    double readKurtosis, Matx22d& covariance);

//! The samples of one gain in a list grouped by gain: [begin, end).
struct GainGroup
{
    int begin = 0, end = 0;
};

/** The uncertainty of a calibrated model.
 * @param inliers the samples of the final fit, grouped by gain in the order of report.perGain
 * @param groups where each gain's samples lie in `inliers`
 * @param report the finished fit: method, model, separable and the per-gain lines with their errors
 * @param params the settings of the fit (loss, robustness, bootstrap replicates and seed)
 * @param notes receives what the user should know about the errors (a bound, the bootstrap's verdict)
 */
ModelUncertainty modelUncertainty(const std::vector<NoiseSample>& inliers,
                                  const std::vector<GainGroup>& groups, const CalibrationReport& report,
                                  const CalibrationParams& params, std::vector<std::string>& notes);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_CALIBRATION_UNCERTAINTY_HPP
