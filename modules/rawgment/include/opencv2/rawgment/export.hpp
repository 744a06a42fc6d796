// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_EXPORT_HPP
#define OPENCV_RAWGMENT_EXPORT_HPP

/** @file
 * The one place that says how cv::rawgment exports symbols.
 *
 * OpenCV's own `CV_EXPORTS` expands to nothing in Debian's build unless `CVAPI_EXPORTS` is defined,
 * so this out-of-tree module uses its own macro. The library is built with hidden visibility and every
 * public class and function carries `CV_RAWGMENT_EXPORTS`, so that the shared object exports exactly
 * the documented API.
 */

#if defined(_WIN32)
#if defined(RAWGMENT_BUILDING_LIBRARY)
#define CV_RAWGMENT_EXPORTS __declspec(dllexport)
#else
#define CV_RAWGMENT_EXPORTS __declspec(dllimport)
#endif
#else
//! Marks a public class or function of cv::rawgment: exported from the shared library.
#define CV_RAWGMENT_EXPORTS __attribute__((visibility("default")))
#endif

#endif // OPENCV_RAWGMENT_EXPORT_HPP
