// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// PNG and TIFF headers read before any decode (image_headers.hpp).
#include "image_headers.hpp"

#include "precomp.hpp"

#include <opencv2/imgcodecs.hpp>

#include <cstring>
#include <set>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

uint32_t bigEndian32(const uchar* p)
{
    return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}

bool pngHeader(const std::string& bytes, ImageHeader& h)
{
    static const char kSignature[] = "\x89PNG\r\n\x1a\n";
    if (bytes.size() < 33 || bytes.compare(0, 8, kSignature, 8) != 0)
        return false;
    const uchar* p = reinterpret_cast<const uchar*>(bytes.data());
    if (std::memcmp(p + 12, "IHDR", 4) != 0)
        return false;
    h.kind = "PNG";
    h.width = bigEndian32(p + 16);
    h.height = bigEndian32(p + 20);
    const int colourType = p[25];
    h.bitDepth = colourType == 3 ? 8 : p[24];
    h.channels = colourType == 0   ? 1
                 : colourType == 4 ? 2
                 : colourType == 2 ? 3
                 : colourType == 3 ? 3
                 : colourType == 6 ? 4
                                   : 0;
    return true;
}

/* A classic TIFF's first directory, which is the one libtiff (and so OpenCV) decodes: ImageWidth (256),
 * ImageLength (257), BitsPerSample (258), SamplesPerPixel (277), SampleFormat (339). Every offset is
 * checked against the file's size. */
bool tiffHeader(const std::string& bytes, ImageHeader& h, std::string& why)
{
    if (bytes.size() < 8)
        return false;
    const bool little = bytes.compare(0, 4, "II*\0", 4) == 0;
    const bool big = bytes.compare(0, 4, "MM\0*", 4) == 0;
    if (!little && !big) {
        if (bytes.compare(0, 4, "II+\0", 4) == 0 || bytes.compare(0, 4, "MM\0+", 4) == 0)
            why = "it is a BigTIFF; only classic TIFF and PNG images are read";
        return false;
    }
    h.kind = "TIFF";
    const uchar* p = reinterpret_cast<const uchar*>(bytes.data());
    const auto u16 = [&](size_t at) {
        return little ? uint32_t(p[at] | (p[at + 1] << 8)) : uint32_t((p[at] << 8) | p[at + 1]);
    };
    const auto u32 = [&](size_t at) {
        return little ? (uint32_t(p[at]) | (uint32_t(p[at + 1]) << 8) | (uint32_t(p[at + 2]) << 16) |
                         (uint32_t(p[at + 3]) << 24))
                      : bigEndian32(p + at);
    };
    const size_t ifd = u32(4);
    if (ifd < 8 || ifd + 2 > bytes.size()) {
        why = "its TIFF directory lies outside the file";
        return false;
    }
    const size_t entries = u16(ifd);
    if (ifd + 2 + 12 * entries > bytes.size()) {
        why = "its TIFF directory runs beyond the end of the file";
        return false;
    }
    h.channels = 1;
    h.bitDepth = 1; // TIFF's defaults
    std::set<uint32_t> seen;
    for (size_t e = 0; e < entries; ++e) {
        const size_t at = ifd + 2 + 12 * e;
        const uint32_t tag = u16(at), type = u16(at + 2), count = u32(at + 4);
        if (!seen.insert(tag).second) {
            why = cv::format("its TIFF directory names tag %u twice (a reader and a decoder could each take "
                             "another of the two)",
                             tag);
            return false;
        }
        if (tag != 256 && tag != 257 && tag != 258 && tag != 277 && tag != 339)
            continue;
        // A SHORT value sits in the first two bytes of the value field, a LONG in all four; several SHORTs
        // (BitsPerSample of an RGB image) lie elsewhere unless they fit in four bytes.
        if (type != 3 && type != 4) {
            why = cv::format("its TIFF tag %u has type %u, not SHORT or LONG", tag, type);
            return false;
        }
        const uint32_t value = type == 3 ? u16(at + 8) : u32(at + 8);
        if (tag == 256 || tag == 257 || tag == 277) {
            if (count != 1) {
                why = cv::format("its TIFF tag %u holds %u values, not one", tag, count);
                return false;
            }
            if (tag == 256)
                h.width = value;
            else if (tag == 257)
                h.height = value;
            else
                h.channels = int(value);
        } else if (tag == 258) {
            h.bitDepth = count == 1 || (type == 3 && count == 2 && u16(at + 10) == value) ? int(value) : -1;
        } else if (tag == 339) {
            h.isFloat = count >= 1 && value == 3;
        }
    }
    return true;
}

} // namespace

bool readImageHeader(const std::string& bytes, ImageHeader& header, std::string& why)
{
    why.clear();
    header = ImageHeader();
    return pngHeader(bytes, header) || tiffHeader(bytes, header, why);
}

Mat readImageFileOfSize(const String& path, Size expectedSize, int expectedType, const String& what)
{
    const String where = what + " '" + path + "'";
    const auto fail = [&](const std::string& why) { CV_Error(Error::StsParseError, where + ": " + why); };
    const long long pixelBytes =
        static_cast<long long>(expectedSize.width) * expectedSize.height * CV_ELEM_SIZE(expectedType);
    const std::string bytes = readFileBounded(path, 2 * pixelBytes + (1LL << 20), what);
    ImageHeader h;
    std::string why;
    if (!readImageHeader(bytes, h, why))
        fail(why.empty() ? "it is neither a PNG nor a TIFF image" : why);
    const int depth = CV_MAT_DEPTH(expectedType), channels = CV_MAT_CN(expectedType);
    const int bits = depth == CV_8U ? 8 : depth == CV_16U ? 16 : depth == CV_32F ? 32 : 0;
    if (h.width != expectedSize.width || h.height != expectedSize.height || h.channels != channels ||
        h.bitDepth != bits || h.isFloat != (depth == CV_32F))
        fail(cv::format("its %s header says %lld x %lld, %d channel(s) of %d-bit %s samples; %dx%d %s was "
                        "expected (nothing was decoded)",
                        h.kind, h.width, h.height, h.channels, h.bitDepth, h.isFloat ? "float" : "integer",
                        expectedSize.width, expectedSize.height, typeToString(expectedType).c_str()));
    Mat image;
    try {
        image = imdecode(Mat(1, int(bytes.size()), CV_8U, const_cast<char*>(bytes.data())), IMREAD_UNCHANGED);
    } catch (const Exception& e) {
        fail(std::string("it cannot be decoded: ") + e.what());
    }
    if (image.empty())
        fail("it cannot be decoded");
    if (image.size() != expectedSize || image.type() != expectedType)
        fail(cv::format("it decodes as %dx%d %s, not the %dx%d %s its header says", image.cols, image.rows,
                        typeToString(image.type()).c_str(), expectedSize.width, expectedSize.height,
                        typeToString(expectedType).c_str()));
    return image;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
