// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The standard normal quantile of the tails (normality.cpp), for the calibration's noise bands. Private.
#ifndef OPENCV_RAWGMENT_SRC_NORMAL_QUANTILE_HPP
#define OPENCV_RAWGMENT_SRC_NORMAL_QUANTILE_HPP

namespace cv {
namespace rawgment {
namespace detail {

/** Standard normal quantile for p in (0, 0.5] (negative), to the precision of erfc (normality.cpp). */
double lowerNormalQuantile(double p);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_NORMAL_QUANTILE_HPP
