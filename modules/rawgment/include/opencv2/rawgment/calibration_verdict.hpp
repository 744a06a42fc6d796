// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The verdict of a calibration: its checks against stated thresholds, and the variance it predicts
// (src/calibration_verdict.cpp).
#ifndef OPENCV_RAWGMENT_CALIBRATION_VERDICT_HPP
#define OPENCV_RAWGMENT_CALIBRATION_VERDICT_HPP

#include <opencv2/rawgment/calibration_fit.hpp>

#include <string>
#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_calibration
//! @{

/** @brief What the verdict of a calibration needs to know about one burst besides its samples. */
struct CV_RAWGMENT_EXPORTS CalibrationBurstFacts
{
    String name;                //!< how the report names the burst (its first file)
    double gainDb = 0;          //!< its gain as the calibration took it (dB)
    int frames = 0;             //!< its frames
    double clippedFraction = 0; //!< of the pixels it could sample (squares, or the frame without a chart)
    bool dark = false;          //!< dark frames (no light)
};

/** @brief One check of a calibration's verdict: a measured figure against a stated threshold. */
struct CV_RAWGMENT_EXPORTS VerdictCheck
{
    String name;      //!< what is checked
    bool pass = true; //!< whether the figure meets the threshold
    String figure;    //!< the measured figure, the threshold and, on a failure, what to do
};

/** @brief PASS when every check passes; the checks and their thresholds are in
 * docs/calibrate_your_camera.md. */
struct CV_RAWGMENT_EXPORTS CalibrationVerdict
{
    bool pass = true;                 //!< every check passed
    std::vector<VerdictCheck> checks; //!< in the order of the report
};

/** @brief The variance a calibration predicts at `mean` and linear `gain`: the model when sigma_d^2 and
 * sigma_r^2 were separable; otherwise the line fitted at the nearest calibrated gain, since the model then
 * holds alpha alone and would leave out the read noise. */
CV_EXPORTS_W double fittedVariance(const CalibrationReport& report, double mean, double gain);

/** @brief Judges a calibration from its samples, its report and its bursts, each check a measured figure
 * against a stated threshold (docs/calibrate_your_camera.md says where each comes from): frames per burst,
 * clipped fraction, separability of sigma_d^2 and sigma_r^2 (gain ratio and both 95% intervals above 0),
 * each gain's slope against its tagged gain (naming the burst that disagrees and the gain it implies),
 * residuals of the variance against the model per gain and mean bin, distinct means per gain, and the
 * curvature of variance against mean (a non-linear raw file).
 * @param samples the samples the report was fitted to
 * @param report what calibrateNoiseModel() (or calibrateWithDarkFrames()) gave
 * @param bursts one entry per burst, light and dark
 * @param signalRange white level minus black level of the frames
 */
CV_RAWGMENT_EXPORTS CalibrationVerdict judgeCalibration(const std::vector<NoiseSample>& samples,
                                                        const CalibrationReport& report,
                                                        const std::vector<CalibrationBurstFacts>& bursts,
                                                        double signalRange);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_CALIBRATION_VERDICT_HPP
