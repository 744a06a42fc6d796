// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The dark-frame components of the noise model from dark bursts (row noise, dark shading, the read
// noise's shape), alone or with the light samples in one call (src/calibration_dark.cpp).
#ifndef OPENCV_RAWGMENT_CALIBRATION_DARK_HPP
#define OPENCV_RAWGMENT_CALIBRATION_DARK_HPP

#include <opencv2/rawgment/calibration_fit.hpp>

#include <string>
#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_calibration
//! @{

/** @brief Options of calibrateDarkNoise(): which dark-frame components to fit. */
struct CV_RAWGMENT_EXPORTS DarkCalibrationParams
{
    bool rowNoise = true;    //!< fit NoiseModel::rowSigmaD2 and rowSigmaR2 (two or more distinct gains)
    bool darkShading = true; //!< fit the dark-shading maps (two or more distinct gains)
    bool tukeyShape = true;  //!< fit NoiseModel::tukeyLambda (and set tukeyRead)
    double lambdaMin = -0.2; //!< the search range of lambda (>= -0.2)
    double lambdaMax = 0.5;  //!< (<= 1; 0.14 is Gaussian, so the range covers light tails too)
    /** Residuals per gain that enter the probability plot (a fixed spread-out subsample; all when fewer).
     * 100,000 put the PPCC's own noise near 1e-5, below the differences between lambdas 0.01 apart. */
    int ppccSamples = 100000;

    void validate() const; //!< throws cv::Exception naming the invalid field
};

/** @brief What one gain's dark burst shows (calibrateDarkNoise()). */
struct CV_RAWGMENT_EXPORTS DarkGainStatistics
{
    double gain = 0;        //!< linear gain
    int frames = 0;         //!< frames of the burst
    double rowMeanVar = 0;  //!< variance of a row's mean after the fixed pattern is removed
    double rowVariance = 0; //!< the row noise: rowMeanVar less the pixel noise's share, pixelVariance / width
    double rowVarianceSE = 0;  //!< its standard error (Gaussian row means)
    double pixelVariance = 0;  //!< per-pixel temporal variance without the rows
    double excessKurtosis = 0; //!< of the pixel residuals after the rows are removed
    ShapiroWilkResult before;  //!< Shapiro-Wilk of 5000 residuals with the row offsets still in
    ShapiroWilkResult after;   //!< ... and of the same residuals without them
};

/** @brief The statistics of one burst of a flat scene (dark frames, or any burst whose scene is
 * constant over its frames), as calibrateDarkNoise() computes them per gain: with e the residual of
 * each black-subtracted value from its pixel's temporal mean, R its row's mean and f = e - R over T
 * frames of H x W, the row-mean variance sum R^2 / ((T - 1) H), the per-pixel variance without the rows,
 * the excess kurtosis of f, and Shapiro-Wilk of the residuals with and without the rows. The one home of
 * these measures: the trade-off report uses it too.
 * @param frames 3 or more frames of one size, CV_16UC1 or CV_32FC1
 * @param format black levels of the frames (per CFA site)
 * @param gain linear gain of the burst (stored)
 * @param pixelMean optional output: the black-subtracted temporal mean of each pixel, CV_64FC1 (the
 *        fixed pattern plus the scene)
 * @throws cv::Exception for fewer than 3 frames, frames of other sizes or types, NaN or Inf, or frames
 *         that do not vary at all. */
CV_RAWGMENT_EXPORTS DarkGainStatistics darkBurstStatistics(const std::vector<Mat>& frames,
                                                           const RawFormat& format, double gain,
                                                           OutputArray pixelMean = noArray());

/** @brief Everything calibrateDarkNoise() found. */
struct CV_RAWGMENT_EXPORTS DarkCalibrationReport
{
    NoiseModel model;                      //!< the base model with the fitted components
    std::vector<DarkGainStatistics> gains; //!< by increasing gain
    std::vector<Vec2d> ppcc;               //!< (lambda, probability-plot correlation) over the search grid
    /** The lambda whose probability plot fits the residuals best, before the correction for what the
     * temporal mean and rounding mix into them (model.tukeyLambda is after it). */
    double lambdaOfResiduals = 0;
    double ppccBest = 0;            //!< the correlation at lambdaOfResiduals
    double ppccGaussian = 0;        //!< the correlation of a normal probability plot, for comparison
    std::vector<std::string> notes; //!< what the user should know (a component at a bound, few frames, ...)

    /** @brief Writes the report (without the maps, which the model's save() writes) under `name`. */
    void write(FileStorage& fs, const String& name) const;
};

/** @brief Calibrates the dark-frame components of a noise model from bursts of dark frames (lens cap)
 * at several gains (docs/mathematics.md, "Dark-frame noise").
 *
 * Per gain g with T frames of H x W: the residual of a frame is its pixels less their temporal mean,
 * which removes the fixed pattern. Its row means R have variance \f$ (1 - 1/T)(\sigma_{row}^2 +
 * \sigma_{pix}^2 / W) \f$, and the rest of the residual \f$ (1 - 1/T)(1 - 1/W)\sigma_{pix}^2 \f$, which
 * gives each gain's row variance corrected for the pixel noise's part of a row mean.
 * - row noise: \f$ \sigma_{row}^2(g) = g^2\sigma_{row,d}^2 + \sigma_{row,r}^2 \f$ by weighted least squares
 *   over the gains (each weighted by its standard error), both parts >= 0;
 * - dark shading: each pixel's temporal means over the gains fitted by the line \f$ g B_d + B_r \f$
 *   (weights: frames over variance per gain);
 * - Tukey lambda: the lambda that maximises the probability-plot correlation (Filliben's medians) of the
 *   pooled, standardised residuals without the rows, over the gains whose pixel noise is at least 2 DN
 *   (quantisation flattens the tails below; the highest gain when none is). Removing the temporal mean
 *   mixes 1/T of the other frames into each residual, and rounding a uniform part, both of which pull
 *   the shape towards the Gaussian; their effect on the excess kurtosis is known (c(T) and the share
 *   1/12 over the variance), so the lambda of the residuals is carried back to the read noise's through
 *   its kurtosis. The accuracy reached per number of frames is in docs/calibrate_your_camera.md.
 *
 * @param bursts bursts[k] are the dark frames at gains[k]: CV_16UC1 or CV_32FC1 mosaics of one size,
 *        at least 3 frames each
 * @param gains the linear gains, finite and > 0
 * @param format the CFA format (its black level is subtracted; its gain is not used)
 * @param base the model to extend, as calibrateNoiseModel() gives it: alpha and the base ISO are kept;
 *        its sigma_d^2 and sigma_r^2, measured from per-pixel temporal variances, hold the row noise too,
 *        so the fitted row parts are moved out of them (at least 0, with a note when they do not fit)
 * @param params what to fit
 * @throws cv::Exception naming the problem: no bursts, sizes or types that differ, fewer than 3 frames,
 *         fewer than 2 distinct gains for row noise or dark shading, non-finite values.
 */
CV_RAWGMENT_EXPORTS DarkCalibrationReport calibrateDarkNoise(
    const std::vector<std::vector<Mat>>& bursts, const std::vector<double>& gains, const RawFormat& format,
    const NoiseModel& base, const DarkCalibrationParams& params = DarkCalibrationParams());

/** @brief What calibrateWithDarkFrames() found: the final fit and the dark-frame components. */
struct CV_RAWGMENT_EXPORTS DarkFrameCalibration
{
    /** The final fit of the light and dark samples; its model carries the dark-frame components, with the
     * row parts moved out of sigma_d^2 and sigma_r^2 (the pixel's own read noise, as the simulator's). */
    CalibrationReport report;
    DarkCalibrationReport dark;     //!< the components' report (its model is report.model)
    std::vector<std::string> notes; //!< what was done to the light samples and the fit, for the user
    /** The samples of the final fit: the light samples (their means without the dark shading when it was
     * fitted), then the dark samples, in the order given. */
    std::vector<NoiseSample> samples;
};

/** @brief The whole model of a sensor from its light samples and its dark bursts, in one call: what
 * calibrateNoiseModel() alone cannot know about dark frames.
 *
 * 1. calibrateNoiseModel() of the light and dark samples gives the base model;
 * 2. calibrateDarkNoise() of the dark bursts gives row noise, dark shading and the read noise's shape;
 * 3. with dark shading, each light sample's mean loses its pixel's \f$ g B_d + B_r \f$: the shading is
 *    no signal, and left in the means it takes \f$ g\alpha s \f$ from each line's offset (with 4 DN of
 *    shading sigma_r^2 came out 59% low, and a plain calibrateNoiseModel() of a shaded sensor's light and
 *    dark samples gives sigma_d^2 about 2% low); with a heavy-tailed read noise, its excess kurtosis
 *    (NoiseModel::readExcessKurtosis() of the dark fit) replaces the light samples' estimate unless
 *    params gives one; the model is then fitted again;
 * 4. the row noise, which every pixel's temporal variance holds, moves out of the read terms.
 *
 * @param lightSamples samples of bursts with light (sampleBurstPatches(), sampleStaticScene())
 * @param darkSamples samples of the dark bursts (sampleDarkBurst(): means 0), or empty
 * @param darkBursts darkBursts[k]: the dark frames at darkGains[k] (see calibrateDarkNoise())
 * @param darkGains their linear gains
 * @param format the CFA format of the frames (black levels)
 * @param params the fit of the noise model
 * @param darkParams what to fit of the dark-frame components (row noise and dark shading need 2 or more
 *        distinct gains: with one, only the read noise's shape is fitted, with a note)
 * @param lightFrames per light sample, the size of the frame whose pixel NoiseSample::pixel numbers;
 *        empty: every light sample numbers a pixel of the dark frames. A sample of a frame of another size
 *        (or of no single pixel) loses the maps' mean shading instead.
 * @throws cv::Exception as calibrateNoiseModel() and calibrateDarkNoise() do, and when lightFrames is
 *         neither empty nor one size per light sample.
 */
CV_RAWGMENT_EXPORTS DarkFrameCalibration calibrateWithDarkFrames(
    const std::vector<NoiseSample>& lightSamples, const std::vector<NoiseSample>& darkSamples,
    const std::vector<std::vector<Mat>>& darkBursts, const std::vector<double>& darkGains,
    const RawFormat& format, const CalibrationParams& params = CalibrationParams(),
    const DarkCalibrationParams& darkParams = DarkCalibrationParams(),
    const std::vector<Size>& lightFrames = std::vector<Size>());

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_CALIBRATION_DARK_HPP
