// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What the per-gain line fits (calibration_lines.cpp) share with the cross-gain fit (calibration.cpp):
// the range of a read excess kurtosis, the checks of samples and the chi-square band that tells inliers;
// and the check of slopes against stated gains that both verdicts (calibration_verdict.cpp,
// emva1288_calibration.cpp) make.
// Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_CALIBRATION_LINES_HPP
#define OPENCV_RAWGMENT_SRC_CALIBRATION_LINES_HPP

#include <opencv2/rawgment/calibration.hpp>

#include <functional>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

// Every distribution has excess kurtosis >= -2; above 1000 no sensor's read noise lies (Tukey lambda -0.2,
// the heaviest NoiseModel takes, has 19).
constexpr double kMinExcessKurtosis = -2, kMaxExcessKurtosis = 1000;

//! The lowest and highest mean of a set of samples: where a line's largest prediction lies.
struct MeanRange
{
    double lo = 0, hi = 0;
};
//! The range of the samples' means (at least one sample).
MeanRange meanRangeOf(const std::vector<NoiseSample>& s);
//! varianceFloor() of a line over samples whose means span `range` (a line peaks at an end).
double lineVarianceFloor(double a, double b, const MeanRange& range);
/** The samples whose variance lies inside their chi-square band around the line (a, b) at `threshold`,
 * for read noise of excess kurtosis `readKurtosis`. */
std::vector<int> inliersOf(const std::vector<NoiseSample>& s, double a, double b, double threshold,
                           double readKurtosis);
//! Throws StsBadArg naming `who` and the first sample that is not finite, has a variance below 0, a gain
//! not above 0 or fewer than 1 degree of freedom.
void checkSamples(const std::vector<NoiseSample>& samples, const char* who);

/** Whether each gain's fitted slope agrees with its stated gain (5% beyond 4 standard errors, alpha the
 * median of a_g / g): a verdict check naming, through `namesAt`, the bursts or series (`unit`) at a gain
 * that disagrees. The camera flow's and the EMVA 1288 flow's verdicts share it. */
VerdictCheck slopesAgreeWithGains(const CalibrationReport& report,
                                  const std::function<std::string(double gain)>& namesAt, const char* unit);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_CALIBRATION_LINES_HPP
