// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What every source of the module includes first: OpenCV's core and the module's private headers that
// most sources share (one per topic). Includes only: a declaration belongs to its topic's header.
#ifndef OPENCV_RAWGMENT_SRC_PRECOMP_HPP
#define OPENCV_RAWGMENT_SRC_PRECOMP_HPP

#include "argument_checks.hpp"
#include "file_access.hpp"
#include "huge_pages.hpp"
#include "normal_quantile.hpp"
#include "npy_format.hpp"

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/files.hpp>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#endif // OPENCV_RAWGMENT_SRC_PRECOMP_HPP
