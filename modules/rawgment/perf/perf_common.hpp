// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The frame every benchmark works on: a 4000x3000 CV_16UC1 mosaic, 12-bit with black 256.
#ifndef OPENCV_RAWGMENT_PERF_COMMON_HPP
#define OPENCV_RAWGMENT_PERF_COMMON_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>

namespace cv {
namespace rawgment {
namespace perf {

//! The format of perfFrame() at a linear gain.
inline RawFormat perfFrameFormat(double gain = 1.0)
{
    RawFormat f;
    f.blackLevel = Vec4d::all(256);
    f.whiteLevel = 4095;
    f.gain = gain;
    return f;
}

//! A 12-megapixel mosaic of uniform random values between black and white, made once.
inline const Mat& perfFrame()
{
    static const Mat m = [] {
        Mat f(3000, 4000, CV_16UC1);
        RNG(5).fill(f, RNG::UNIFORM, 256, 4000);
        return f;
    }();
    return m;
}

} // namespace perf
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_PERF_COMMON_HPP
