// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Transparent huge pages for the large buffers the steps write first (files.cpp). Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_HUGE_PAGES_HPP
#define OPENCV_RAWGMENT_SRC_HUGE_PAGES_HPP

#include <opencv2/core.hpp>

namespace cv {
namespace rawgment {
namespace detail {

/** Asks for transparent huge pages over a large buffer (4 MiB or more) that is about to be written for the
 * first time: on a virtual machine each 4 KiB page fault costs microseconds, so a new 12 MP float mosaic
 * (48 MB) spends more time faulting than being written. Advice only: nothing changes without THP, on
 * memory already touched, or off Linux. */
void adviseHugePages(const Mat& m);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_HUGE_PAGES_HPP
