// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_EXPORT_HPP
#define OPENCV_RAWGMENT_EXPORT_HPP

#include <opencv2/core/cvdef.h>

/** @file
 * The one place that says how cv::rawgment exports symbols.
 *
 * The library is compiled as OpenCV compiles its own modules: hidden visibility, with `CVAPI_EXPORTS`
 * defined, so that OpenCV's `CV_EXPORTS` (and `CV_EXPORTS_W`, which is `CV_EXPORTS`) marks a symbol as
 * exported. This holds in both builds, the standalone one (`modules/rawgment/CMakeLists.txt` defines it)
 * and the one inside OpenCV (`ocv_create_module` defines it). What OpenCV's binding generator wraps
 * carries `CV_EXPORTS_W`, `CV_EXPORTS_W_SIMPLE` and `CV_WRAP`; the rest of the public API carries
 * `CV_RAWGMENT_EXPORTS`, which is `CV_EXPORTS` under a name the generator does not read.
 */

#if defined(RAWGMENT_BUILDING_LIBRARY) && !defined(CVAPI_EXPORTS)
#error "cv::rawgment is built with CVAPI_EXPORTS defined, or CV_EXPORTS would export nothing"
#endif

//! Marks a public class or function of cv::rawgment that the binding generator does not wrap.
#define CV_RAWGMENT_EXPORTS CV_EXPORTS

#endif // OPENCV_RAWGMENT_EXPORT_HPP
