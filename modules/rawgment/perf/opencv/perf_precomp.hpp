// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// OpenCV-style performance tests (opencv_perf_rawgment), built only inside OpenCV's build.
#ifndef OPENCV_RAWGMENT_PERF_PRECOMP_HPP
#define OPENCV_RAWGMENT_PERF_PRECOMP_HPP

#include <opencv2/rawgment.hpp>
#include <opencv2/ts.hpp>

namespace opencv_test {
using namespace cv::rawgment;

//! A 12-bit RGGB format, black 256: the sensor of the module's unit tests.
inline RawFormat perfFormat()
{
    RawFormat format;
    format.blackLevel = Vec4d::all(256);
    format.whiteLevel = 4095;
    return format;
}

//! A mosaic of the given size and type with values from black to near white, from a fixed seed.
inline Mat perfMosaic(Size size, int type)
{
    Mat mosaic(size, type);
    RNG rng(20231126);
    rng.fill(mosaic, RNG::UNIFORM, 256, 3800);
    return mosaic;
}

} // namespace opencv_test

#endif // OPENCV_RAWGMENT_PERF_PRECOMP_HPP
