// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The checks every entry point makes on its arguments (numbers, arrays, blur kernels, base ISOs), with
// errors that name the argument. Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_ARGUMENT_CHECKS_HPP
#define OPENCV_RAWGMENT_SRC_ARGUMENT_CHECKS_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>

namespace cv {
namespace rawgment {
namespace detail {

//! Throws StsBadArg "<what> must be finite and > 0 (got <value>)" unless value is finite and positive.
void checkFinitePositive(double value, const char* what);
//! Throws StsBadArg "<what> must be finite and >= 0 (got <value>)" unless value is finite and >= 0.
void checkFiniteNonNegative(double value, const char* what);

/** A blur kernel as float64 normalised to sum 1: the one check of motion blur and the simulator's
 * blurred captures. Throws StsBadArg naming `who` unless it is non-empty, finite, non-negative, of positive
 * sum and at most MAX_MOTION_KERNEL_SIDE on a side on the CFA planes; on a monochrome frame's pixel grid
 * (`pattern` CFA_MONO), where a motion spans twice the pixels, 2 MAX_MOTION_KERNEL_SIDE - 1. */
Mat normalisedKernel(InputArray kernel, const char* who, CfaPattern pattern);
/** The Mat of an array argument, refused with StsBadArg naming `what` ("colorJitter: src") unless it has at
 * most two dimensions: an N-D array (numpy's (1, 1, H, W) through cv2) would otherwise be read as 1x1. The
 * check every entry point makes, so that every binding gets it. */
Mat twoDimensional(InputArray array, const char* what);

/** The border rule of every blur: BORDER_REPLICATE, the nearest visible pixel stands for the light just
 * outside the frame. A motion blur at the edge integrates light the sensor never saw; the nearest
 * recorded value is the estimate of it that assumes least (a reflection would invent structure that
 * moves the wrong way), and it is the rule the augmentation's noise accounting implements exactly
 * (taps that replicate one pixel are merged, motion_blur.cpp). The simulator uses it too, so a blurred
 * capture and a blurred augmentation agree up to the frame's edge. */
constexpr int kBlurBorder = BORDER_REPLICATE;

//! Throws StsBadArg naming `what` unless baseIso lies in [NoiseModel::MIN_BASE_ISO, MAX_BASE_ISO] (or is 0,
//! for unknown, when zeroIsUnknown).
void checkBaseIso(double baseIso, const char* what, bool zeroIsUnknown);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_ARGUMENT_CHECKS_HPP
