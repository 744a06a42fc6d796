// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The .npy container of a mosaic (npy_files.cpp): its bytes and its reader. Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_NPY_FORMAT_HPP
#define OPENCV_RAWGMENT_SRC_NPY_FORMAT_HPP

#include <opencv2/core.hpp>

#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

//! The bytes of a .npy file (format 1.0, little-endian, C order) holding `mosaic`, CV_16UC1 or CV_32FC1.
std::vector<uchar> npyFileBytes(const Mat& mosaic);
/** The mosaic of a .npy file as npyFileBytes() writes it (format 1.0 to 3.0, a 2-D '<u2' or '<f4' array
 * in C order, the file exactly that long); throws naming the file otherwise, before allocating. */
Mat readNpyMosaic(const String& path);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_NPY_FORMAT_HPP
