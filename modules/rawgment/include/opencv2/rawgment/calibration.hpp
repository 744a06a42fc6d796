// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The calibration topic: one header per seam of its sources, all included here, so that a user's include
// of calibration.hpp keeps working.
#ifndef OPENCV_RAWGMENT_CALIBRATION_HPP
#define OPENCV_RAWGMENT_CALIBRATION_HPP

#include <opencv2/rawgment/calibration_dark.hpp>
#include <opencv2/rawgment/calibration_fit.hpp>
#include <opencv2/rawgment/calibration_lines.hpp>
#include <opencv2/rawgment/calibration_samples.hpp>
#include <opencv2/rawgment/calibration_verdict.hpp>

#endif // OPENCV_RAWGMENT_CALIBRATION_HPP
