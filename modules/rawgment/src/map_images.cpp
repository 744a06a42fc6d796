// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Float maps saved beside a file as checksummed TIFF images (map_images.hpp).
#include "map_images.hpp"

#include "file_access.hpp"
#include "image_headers.hpp"
#include "precomp.hpp"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <cinttypes>
#include <cstdio>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

// Whether the file at `image` holds exactly `map`: read with the bound and header check of any map image,
// so a damaged or hostile file there is simply not this map.
bool isOwnMapImage(const String& image, const Mat& map)
{
    try {
        return mapChecksum(readImageFileOfSize(image, map.size(), map.type(), "map image")) ==
               mapChecksum(map);
    } catch (const Exception&) {
        return false;
    }
}

} // namespace

std::string mapChecksum(const Mat& map)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (int r = 0; r < map.rows; ++r) {
        const uchar* p = map.ptr<uchar>(r);
        for (size_t i = 0; i < map.cols * map.elemSize(); ++i) {
            h ^= p[i];
            h *= 0x100000001b3ull;
        }
    }
    return format("%016" PRIx64, h);
}

String baseNameOf(const String& path)
{
    const size_t slash = path.find_last_of('/');
    return slash == String::npos ? path : path.substr(slash + 1);
}

String mapImageName(const String& ownerPath, const String& tag, const Mat& map)
{
    return baseNameOf(ownerPath) + "." + tag + "." + mapChecksum(map) + ".tiff";
}

bool isMapImageOf(const String& ownerPath, const std::string& name, const std::vector<String>& tags)
{
    for (const String& tag : tags) {
        const std::string prefix = baseNameOf(ownerPath) + "." + tag + ".";
        if (name.size() != prefix.size() + 16 + 5 || name.compare(0, prefix.size(), prefix) != 0 ||
            name.compare(name.size() - 5, 5, ".tiff") != 0)
            continue;
        if (std::all_of(name.begin() + long(prefix.size()), name.end() - 5,
                        [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) != 0; }))
            return true;
    }
    return false;
}

void saveWithMapImages(const String& ownerPath, const std::string& text, const std::vector<const Mat*>& maps,
                       const std::vector<String>& names, const std::function<bool(const String&)>& isOwnImage,
                       const char* who)
{
    CV_Assert(maps.size() == names.size());
    const String folder = folderOf(ownerPath);
    std::vector<String> created;
    try {
        for (size_t i = 0; i < maps.size(); ++i) {
            const String image = folder + names[i];
            // Same name, same checksum: a map an earlier save left is this one already (when its pixels
            // say so; a damaged one is replaced, as nothing can load it).
            const bool present = pathExists(image);
            if (present && isOwnMapImage(image, *maps[i]))
                continue;
            std::vector<uchar> bytes;
            if (!imencode(".tiff", *maps[i], bytes, {IMWRITE_TIFF_COMPRESSION, 1}) || bytes.empty())
                CV_Error(Error::StsError, format("%s: cannot encode the image %s", who, image.c_str()));
            writeFileAtomically(image, bytes.data(), bytes.size(), present);
            if (!present)
                created.push_back(image);
        }
        writeFileAtomically(ownerPath, text.data(), text.size(), true);
    } catch (...) {
        for (const String& image : created)
            removeFileIfPresent(image);
        throw;
    }
    // The owner file now names only the new maps: its earlier ones go.
    std::vector<String> entries;
    try {
        entries = folderEntryNames(folder, who);
    } catch (const Exception&) {
        return; // the owner file is written: an earlier map left behind costs room, not correctness
    }
    for (const String& name : entries)
        if (isOwnImage(name) && std::find(names.begin(), names.end(), name) == names.end())
            removeFileIfPresent(folder + name);
}

Mat readMapImage(const FileNode& entry, const String& what, const String& folder, Size size)
{
    if (entry.empty() || !entry.isMap())
        CV_Error(Error::StsParseError, what + " must be a map with image and fnv1a64");
    rejectUnknownKeys(entry, {"image", "fnv1a64"});
    if (!entry["image"].isString() || !entry["fnv1a64"].isString())
        CV_Error(Error::StsParseError, what + ".image and .fnv1a64 must be strings");
    const String name = entry["image"].string(), checksum = entry["fnv1a64"].string();
    // A file name in the owner's folder, nothing else: a hostile file could otherwise name a device or a
    // pipe that blocks the reader, or a file anywhere on the machine.
    if (name.empty() || name == "." || name == ".." || name.find('/') != String::npos)
        CV_Error(Error::StsParseError,
                 format("%s.image '%s' must be a file name in the same folder as the file naming it (no '/')",
                        what.c_str(), name.c_str()));
    const String path = folder + name;
    FileStamp stamp;
    if (!fileStampOf(path, stamp))
        CV_Error(Error::StsError, format("%s: image '%s' is missing", what.c_str(), path.c_str()));
    if (!stamp.regular())
        CV_Error(Error::StsParseError,
                 format("%s: image '%s' is not a regular file", what.c_str(), path.c_str()));
    // Its header is checked against the size before anything is decoded: a header claiming 30000x30000
    // floats was decoded (3.6 GB) before the size was compared (round 5 item 20).
    const Mat map = readImageFileOfSize(path, size, CV_32FC1, what + ": image");
    if (mapChecksum(map) != checksum)
        CV_Error(
            Error::StsParseError,
            format("%s: image '%s' does not match the file naming it (checksum %s, the file says %s): the "
                   "image and the file come from different saves",
                   what.c_str(), path.c_str(), mapChecksum(map).c_str(), checksum.c_str()));
    return map;
}

void writeMapImageEntry(FileStorage& fs, const String& name, const Mat& map)
{
    fs << "{";
    writeString(fs, "image", name);
    fs << "fnv1a64" << mapChecksum(map) << "}";
}

} // namespace detail
} // namespace rawgment
} // namespace cv
