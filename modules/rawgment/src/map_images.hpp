// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Float maps saved beside a YAML or JSON file as TIFF images named by their checksum: the noise model's
// dark shading and the dark-frame bank's patterns. One way to write them (a save never touches the images
// the current file names until that file is switched) and one way to read them back (a file name in the
// same folder, a regular file, its type, size and checksum checked). Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_MAP_IMAGES_HPP
#define OPENCV_RAWGMENT_SRC_MAP_IMAGES_HPP

#include <opencv2/core.hpp>

#include <functional>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

//! FNV-1a (64 bits, hex) over a map's rows: the check that a file and its images belong together.
std::string mapChecksum(const Mat& map);

//! The file name of a path (what follows its last '/').
String baseNameOf(const String& path);

/** `<file name of owner>.<tag>.<checksum>.tiff`: the owner's whole name keeps cam.yml and cam.json apart,
 * the checksum gives every new map a new name. */
String mapImageName(const String& ownerPath, const String& tag, const Mat& map);

/** Writes `text` to `ownerPath` and each map beside it as a TIFF named `names[i]` (mapImageName()),
 * atomically: the images first (one already there with the same checksum is kept), the owner file last;
 * on an error the images this call created are removed and the owner file is left as it was. Then the
 * owner's earlier images, those `isOwnImage` recognises and `names` does not list, are removed. */
void saveWithMapImages(const String& ownerPath, const std::string& text, const std::vector<const Mat*>& maps,
                       const std::vector<String>& names, const std::function<bool(const String&)>& isOwnImage,
                       const char* who);

/** Whether `name` is `<file name of owner>.<tag>.<16 hex digits>.tiff` for one of `tags`. */
bool isMapImageOf(const String& ownerPath, const std::string& name, const std::vector<String>& tags);

/** Reads the map named by `entry` (a map with keys `image`, a file name in `folder`, and `fnv1a64`): a
 * CV_32FC1 TIFF of `size` whose checksum is the one stated. Errors start with `what` ("noise model:
 * dark_shading.per_gain"). */
Mat readMapImage(const FileNode& entry, const String& what, const String& folder, Size size);

//! Writes `{image: name, fnv1a64: checksum}` as the value of the key last written to `fs`.
void writeMapImageEntry(FileStorage& fs, const String& name, const Mat& map);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_MAP_IMAGES_HPP
