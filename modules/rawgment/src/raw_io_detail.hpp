// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Private helpers of the raw_io topic (raw_io.cpp, dng_writer.cpp, noise_profiles.cpp); never installed.
#ifndef OPENCV_RAWGMENT_SRC_RAW_IO_DETAIL_HPP
#define OPENCV_RAWGMENT_SRC_RAW_IO_DETAIL_HPP

#include "precomp.hpp"

#include <opencv2/rawgment/raw_io.hpp>

namespace cv {
namespace rawgment {
namespace detail {

//! The NoiseProfile (tag 51041) pairs of a DNG or other TIFF-based file, empty when it has none or is
//! not TIFF-based; throws StsParseError naming the file when the tag or the IFDs are malformed.
std::vector<Vec2d> readDngNoiseProfile(const String& path);
//! The EXIF ISOSpeed (or RecommendedExposureIndex) of a TIFF-based file, which states an ISO of 65535 or
//! more (EXIF 2.3) where ISOSpeedRatings holds 65535; 0 when it has none or is not TIFF-based.
double readExifIsoSpeed(const String& path);
//! The bytes writeDng() writes to `path` (named in its errors) for `image`, after the same checks.
std::vector<uint8_t> dngFileBytes(const String& path, const RawImage& image);
//! White level minus the mean black level of the CFA sites of DNG colour plane 0 (red), 1 or 2.
double rangeOfColourPlane(const RawFormat& format, int plane);
//! Throws StsBadArg (prefixed by `what`) unless a NoiseProfile has 1 or 3 pairs, each S > 0, O >= 0.
void checkDngNoiseProfile(const std::vector<Vec2d>& profile, const char* what);
//! Whether `tag` is one of the DNG colour tags that DngTag holds.
bool isColorTag(int tag);
//! The colour tags of a DNG's IFD0 (sorted by tag), empty when the file has no ColorMatrix1 or is not
//! TIFF-based; throws StsParseError naming the file when a tag or the IFD is malformed.
std::vector<DngTag> readDngColorTags(const String& path);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_RAW_IO_DETAIL_HPP
