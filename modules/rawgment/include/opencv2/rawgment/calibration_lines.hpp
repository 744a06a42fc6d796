// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The per-gain line fit of the calibration, sigma^2 = a mu + b (paper Eq. 6; src/calibration_lines.cpp).
#ifndef OPENCV_RAWGMENT_CALIBRATION_LINES_HPP
#define OPENCV_RAWGMENT_CALIBRATION_LINES_HPP

#include <opencv2/rawgment/calibration_samples.hpp>
#include <opencv2/rawgment/noise_model.hpp>

#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_calibration
//! @{

/** @brief Settings of the per-gain line fit. */
struct CV_EXPORTS_W_SIMPLE LineFitParams
{
    //! Every field at its default, as initialised here.
    CV_WRAP LineFitParams()
        : robust(true), ransacIterations(500), inlierThreshold(4.0), seed(0), readExcessKurtosis(0)
    {
    }
    CV_PROP_RW bool robust; //!< RANSAC, then least squares on the inliers; false: least squares on all
    CV_PROP_RW int ransacIterations; //!< line hypotheses drawn from random pairs of samples
    /** Inlier band: a sample is kept when its variance lies where a sample variance of `dof` degrees of
     * freedom lies with the probability that a normal variable lies within +-k,
     * \f$ \chi^2_{dof}(\Phi(-k))/dof \le v / line(\mu) \le \chi^2_{dof}(\Phi(k))/dof \f$ (about
     * +-k standard errors for large dof; equal in probability on both sides, because a sample variance is
     * skewed and a band of equal width keeps every zero variance and cuts only the high tail). */
    CV_PROP_RW double inlierThreshold;
    CV_PROP_RW uint64 seed; //!< seed of the RANSAC draws (deterministic)
    /** Excess kurtosis of the read noise (\f$ g n_d + n_r \f$ together; 0: Gaussian, in [-2, 1000]).
     * With the Poisson part it sets how far a sample variance spreads, \f$ Var(s^2) = 2v^2/dof +
     * \kappa_4/(dof + 1) \f$ with fourth cumulant \f$ \kappa_4 = \kappa b^2 + a^3\mu \f$: the inlier
     * band is that of the scaled chi-square with the same spread, and the weights are its inverse, so
     * heavy tails are neither trimmed nor down-weighted as if they were defects.
     * calibrateNoiseModel() sets it from CalibrationParams::readExcessKurtosis or its estimate. */
    CV_PROP_RW double readExcessKurtosis;
};

/** @brief The line \f$ \sigma^2 = a\mu + b \f$ fitted to the samples of one gain.
 *
 * The final fit is iterated weighted least squares with weights \f$ dof / (2 v^2) \f$, the inverse
 * variance of a sample variance, which makes the offset b far more precise than ordinary least squares
 * (paper) does on the same inliers. */
struct CV_EXPORTS_W_SIMPLE NoiseLineFit
{
    //! Every field at its default, as initialised here.
    CV_WRAP NoiseLineFit()
        : gain(1), rSquared(0), inliers(0), samples(0), slopeStdError(0), offsetStdError(0),
          slopeOffsetCorrelation(0)
    {
    }
    CV_PROP_RW double gain;     //!< linear gain
    CV_PROP_RW NoiseLine line;  //!< slope a and offset b (unconstrained: a negative value is reported as is)
    CV_PROP_RW double rSquared; //!< coefficient of determination on the inliers
    CV_PROP_RW int inliers;     //!< samples used by the final least squares
    CV_PROP_RW int samples;     //!< samples offered
    /** Standard errors of a and b and their correlation: the sandwich (Huber-White) covariance of the
     * final weighted least squares, \f$ A^{-1} B A^{-1} \f$ with \f$ A = \sum w_i x_i x_i^T \f$ and
     * \f$ B = \sum w_i^2 e_i^2 x_i x_i^T \f$, \f$ x_i = (\mu_i, 1) \f$: it takes the scatter the data
     * show rather than the \f$ 2v^2/dof \f$ of Gaussian noise, so excess kurtosis (Poisson at low
     * counts, quantisation, noisy pixels inside the inlier band) widens it as it should. Conditional on
     * the inliers chosen. 0 when there are fewer than 3 inliers. */
    CV_PROP_RW double slopeStdError;
    CV_PROP_RW double offsetStdError;         //!< standard error of b (see slopeStdError)
    CV_PROP_RW double slopeOffsetCorrelation; //!< correlation of the errors of a and b (see slopeStdError)
};

/** @brief Fits \f$ \sigma^2 = a\mu + b \f$ to samples of one gain (paper Eq. 6), robustly by default.
 * @throws cv::Exception with fewer than 2 samples, samples of different gains, non-finite values, or
 *         when all samples share one mean (the slope is then undefined).
 */
CV_EXPORTS_W NoiseLineFit fitNoiseLine(const std::vector<NoiseSample>& samples,
                                       const LineFitParams& params = LineFitParams());

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_CALIBRATION_LINES_HPP
