// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The fit across gains (paper Sec. 3.2) and its errors: calibrateNoiseModel() and its report, the
// standard errors and their projection (src/calibration.cpp, calibration_report.cpp,
// calibration_uncertainty.cpp).
#ifndef OPENCV_RAWGMENT_CALIBRATION_FIT_HPP
#define OPENCV_RAWGMENT_CALIBRATION_FIT_HPP

#include <opencv2/rawgment/calibration_lines.hpp>
#include <opencv2/rawgment/normality.hpp>

#include <limits>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_calibration
//! @{

/** @brief How the cross-gain parameters are estimated. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum NoiseFitMethod: int
// clang-format on
{
    /** One fit of \f$ \sigma^2 = g\alpha\mu + g^2\sigma_d^2 + \sigma_r^2 \f$ over all samples of all gains,
     * each weighted by the inverse squared standard error of a sample variance, \f$ dof / (2\sigma^4) \f$
     * (iterated: the weights use the previous fit), corrected for the error of each sample's own mean
     * (see docs/mathematics.md), on the per-gain RANSAC inliers, with every parameter >= 0 (an exact
     * bounded solve). The default: it uses the dark samples that pin \f$ \sigma_r^2 \f$ directly
     * instead of extrapolating each offset. */
    NOISE_FIT_JOINT = 0,
    /** The paper's method (Eq. 7, 8): per-gain lines, then \f$ a_g = g\alpha \f$ and
     * \f$ b_g = g^2\sigma_d^2 + \sigma_r^2 \f$ by least squares with non-negative bounds. */
    NOISE_FIT_TWO_STAGE = 1
};

/** @brief Settings of calibrateNoiseModel(). */
struct CV_EXPORTS_W_SIMPLE CalibrationParams
{
    //! Every field at its default, as initialised here.
    CV_WRAP CalibrationParams()
        : method(NOISE_FIT_JOINT), reweightIterations(8), lossScale(0.0), minGainRatio(1.12),
          bootstrapReplicates(200), readExcessKurtosis(std::numeric_limits<double>::quiet_NaN())
    {
    }
    CV_PROP_RW NoiseFitMethod method;  //!< cross-gain method
    CV_PROP_RW LineFitParams line;     //!< per-gain line fits (also select the joint fit's inliers)
    CV_PROP_RW int reweightIterations; //!< joint fit: re-weighting rounds from the two-stage fit
    /** Joint fit: Huber loss scale in standard errors, 0 for none (the default). The per-gain band
     * (LineFitParams::inlierThreshold) has already removed what cannot be noise, and a loss on a skewed
     * residual (a sample variance is chi-squared) cuts its long tail only and biases the fit low: Cauchy
     * at 3 by ~0.4%, and even Huber at 4 measurably. */
    CV_PROP_RW double lossScale;
    /** Gains closer than this ratio count as one when deciding whether sigma_d^2 and sigma_r^2 are
     * separable (1.12 is 1 dB). */
    CV_PROP_RW double minGainRatio;
    /** Bootstrap replicates of the final fit (0: none), the check of the covariance and its stand-in
     * where the covariance does not hold (see ModelUncertainty). Each replicate draws the samples of
     * each gain anew with replacement and repeats the final weighted fit; 200 give each standard
     * error to about 5% (\f$ 1/\sqrt{2R} \f$). Keyed by `line.seed`: the same seed gives the same
     * errors on any number of threads. */
    CV_PROP_RW int bootstrapReplicates;
    /** Excess kurtosis of the read noise (see LineFitParams::readExcessKurtosis), or NaN (the default) to
     * estimate it from the spread of the sample variances around their lines (CalibrationReport::
     * readExcessKurtosis). Give it when dark frames have measured it: NoiseModel::readExcessKurtosis() of
     * calibrateDarkNoise()'s model (0 for Gaussian read noise). The estimate needs samples where read
     * noise dominates (dark frames or dark patches); without them the fit takes 0 and says so. */
    CV_PROP_RW double readExcessKurtosis;
};

/** @brief The parameters of a NoiseModel, as indices into the vectors and matrices of
 * ModelUncertainty. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum NoiseModelParameter: int
// clang-format on
{
    NOISE_PARAM_ALPHA = 0,    //!< \f$ \alpha \f$
    NOISE_PARAM_SIGMA_D2 = 1, //!< \f$ \sigma_d^2 \f$
    NOISE_PARAM_SIGMA_R2 = 2  //!< \f$ \sigma_r^2 \f$
};

/** @brief Where the standard errors of a calibration come from. */
// OpenCV 4.6's binding parser reads an enum's base only with no space before ':'.
// clang-format off
enum UncertaintySource: int
// clang-format on
{
    UNCERTAINTY_NONE = 0, //!< none were computed (a report of format 1)
    /** The sandwich covariance of the final fit (see NoiseLineFit::slopeStdError), confirmed by the
     * bootstrap where one ran. */
    UNCERTAINTY_COVARIANCE = 1,
    /** The bootstrap: a parameter sits at its bound 0, where a covariance from derivatives does not
     * hold, or the bootstrap found an error over 25% larger than the covariance's (its own spread at
     * 200 replicates is 5%, so this is no chance). */
    UNCERTAINTY_BOOTSTRAP = 2
};

/** @brief How exact a calibrated model is: the standard errors of alpha, sigma_d^2 and sigma_r^2 and
 * their covariance.
 *
 * The errors are those of the final fit given its inliers (the RANSAC choice is not redone); they
 * describe scatter, not bias, and the coverage study (study_calibration_coverage) measures how often
 * the 95% interval holds the simulator's truth. When sigma_d^2 and sigma_r^2 are not separable only
 * alpha has an error. */
struct CV_EXPORTS_W_SIMPLE ModelUncertainty
{
    //! Every field at its default, as initialised here.
    CV_WRAP ModelUncertainty() : source(UNCERTAINTY_NONE), bootstrapReplicates(0) {}
    CV_PROP_RW UncertaintySource source; //!< which of the two estimates below is used
    CV_PROP_RW Vec3d stdError;           //!< standard errors used, indexed by NoiseModelParameter
    CV_PROP_RW Matx33d covariance;       //!< their covariance (DN units squared of each pair)
    CV_PROP_RW Vec3d
        fitStdError; //!< from the sandwich covariance of the fit (0 for a parameter at its bound)
    CV_PROP_RW Vec3d bootstrapStdError; //!< from the bootstrap (0 when none ran)
    CV_PROP_RW int bootstrapReplicates; //!< replicates of the bootstrap that ran

    /** @brief The correlation of the errors of two parameters (0 when either has no error). The one
     * of sigma_d^2 and sigma_r^2 is usually strongly negative: both make up each gain's offset. */
    CV_WRAP double correlation(NoiseModelParameter first, NoiseModelParameter second) const;
};

/** @brief Everything a calibration found, readable and writable as YAML or JSON. */
struct CV_EXPORTS_W_SIMPLE CalibrationReport
{
    //! Every field at its default, as initialised here.
    CV_WRAP CalibrationReport()
        : method(NOISE_FIT_JOINT), separable(false), rSquaredSlope(0), rSquaredOffset(0), samples(0),
          samplesUsed(0), readExcessKurtosis(0), readExcessKurtosisEstimated(false)
    {
    }
    /** Newest version of the file format. Version 2 adds the uncertainty and the per-gain standard
     * errors, version 3 the read noise's excess kurtosis; a report without an uncertainty (source
     * UNCERTAINTY_NONE) is written as version 1, and files of versions 1 and 2 still load (kurtosis 0). */
    static constexpr int FORMAT_VERSION = 3;

    CV_PROP_RW NoiseFitMethod method; //!< the method that ran
    /** The fitted model. Valid only when `separable`; with a single gain (or gains closer than
     * CalibrationParams::minGainRatio) only alpha is known, and sigma_d^2, sigma_r^2 are left at 0. */
    CV_PROP_RW NoiseModel model;
    CV_PROP_RW bool separable;                    //!< sigma_d^2 and sigma_r^2 could be told apart
    CV_PROP_RW std::vector<NoiseLineFit> perGain; //!< the per-gain lines, by increasing gain
    CV_PROP_RW double rSquaredSlope;              //!< R^2 of a_g = g alpha over the gains (paper: 1.0000)
    CV_PROP_RW double rSquaredOffset;             //!< R^2 of b_g = g^2 sigma_d^2 + sigma_r^2 (paper: 0.9984)
    CV_PROP_RW int samples;                       //!< samples offered
    CV_PROP_RW int samplesUsed;                   //!< samples in the final fit
    CV_PROP_RW std::vector<std::string> notes; //!< what the user should know (bounds hit, not separable, ...)
    CV_PROP_RW ModelUncertainty uncertainty;   //!< standard errors of the model's parameters
    /** The read noise's excess kurtosis the bands, weights and errors used: the given one, or the
     * estimate (see CalibrationParams::readExcessKurtosis). */
    CV_PROP_RW double readExcessKurtosis;
    CV_PROP_RW bool
        readExcessKurtosisEstimated; //!< whether readExcessKurtosis was estimated from the samples

    /** @brief The two-sided confidence interval of a parameter, value \f$ \pm z_{(1+level)/2} \f$
     * standard errors (normal: each estimate is a weighted sum over thousands of samples). Not cut at
     * 0, so that an interval that spans 0 shows the data cannot tell the parameter from 0.
     * @throws cv::Exception when level is not in (0, 1) or the report has no uncertainty. */
    CV_WRAP Vec2d interval(NoiseModelParameter parameter, double level = 0.95) const;

    /** @brief Writes the report as a map under `name`; its model without the dark-shading maps, which
     * NoiseModel::save() writes beside the model file. */
    void write(FileStorage& fs, const String& name) const;
    /** @brief Reads a report written by write(). @throws cv::Exception naming a missing field. */
    static CalibrationReport read(const FileNode& node);
    /** @brief Saves to .yml/.yaml/.json atomically (top-level map `calibration_report`). */
    void save(const String& path) const;
    /** @brief Loads a report saved by save(). */
    CV_WRAP static CalibrationReport load(const String& path);
};

/** @brief A change to the data of a calibration, for projectedStdError(): what a user could shoot more of. */
struct CV_RAWGMENT_EXPORTS CalibrationPlan
{
    double frameFactor = 1; //!< frames per burst times this (> 0): each sample's dof + 1 scales
    double pixelFactor = 1; //!< pixels per burst times this (> 0): more or larger patches
    bool addDarkFrames =
        false; //!< one burst of dark frames (mean 0) per gain, as many pixels as its light samples
    /** > 0: one more gain (linear), shot like the highest gain: the same means, pixels and frames. */
    double addGain = 0;
};

/** @brief The standard errors a calibration would have if its data changed by `plan`.
 *
 * From the Fisher information of the samples under the fitted model, \f$ I = \sum_i x_i x_i^T\, dof_i /
 * (2 m_i^2) \f$ with \f$ x_i = (g\mu_i, g^2, 1) \f$ and \f$ m_i \f$ the model's variance, the errors of the
 * changed data are the report's errors times \f$ \sqrt{[I'^{-1}]_{kk} / [I^{-1}]_{kk}} \f$: the ratio
 * carries over whatever the report measured beyond Gaussian scatter (shot noise's kurtosis, quantisation).
 * More of the same data has the formula \f$ \sigma' = \sigma / \sqrt{p} \f$ for p times the pixels and about
 * \f$ \sigma\sqrt{(T - 1)/(fT - 1)} \f$ for f times T frames; new gains and dark frames change the design,
 * and only the information says what they buy. Where the report has no error for a parameter (not
 * separable), the information's own error is returned.
 * @param samples the samples the report was calibrated from
 * @param report its report (with an uncertainty)
 * @param plan the change
 * @return standard errors of alpha, sigma_d^2 and sigma_r^2 (0 where the changed data still cannot
 *         determine a parameter)
 * @throws cv::Exception on an invalid plan, no samples, or a report without an uncertainty
 */
CV_RAWGMENT_EXPORTS Vec3d projectedStdError(const std::vector<NoiseSample>& samples,
                                            const CalibrationReport& report, const CalibrationPlan& plan);

/** @brief Calibrates the noise model from samples of one or more gains (paper Sec. 3.2).
 * @param samples noise samples of all gains (their `gain` field groups them)
 * @param params method and settings
 * @throws cv::Exception when there are no samples, a value is not finite, or a gain has fewer than
 *         2 distinct means.
 */
CV_EXPORTS_W CalibrationReport calibrateNoiseModel(const std::vector<NoiseSample>& samples,
                                                   const CalibrationParams& params = CalibrationParams());

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_CALIBRATION_FIT_HPP
