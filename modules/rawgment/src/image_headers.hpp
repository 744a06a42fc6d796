// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// PNG and TIFF headers read as the decoders read them, before anything is decoded: a file's header decides
// what OpenCV allocates, so it is checked against the size the reader expects first.
#ifndef RAWGMENT_IMAGE_HEADERS_HPP
#define RAWGMENT_IMAGE_HEADERS_HPP

#include <opencv2/core.hpp>

#include <string>

namespace cv {
namespace rawgment {
namespace detail {

//! What an image file's header states.
struct ImageHeader
{
    long long width = 0, height = 0;
    int bitDepth = 0;      //!< bits per sample; -1 when samples differ in depth
    int channels = 0;      //!< samples per pixel (a PNG palette counts 3: OpenCV decodes it to BGR)
    bool isFloat = false;  //!< TIFF SampleFormat 3
    const char* kind = ""; //!< "PNG" or "TIFF"
};

/** Reads the header of a PNG (its IHDR) or of a classic TIFF (the first directory, which libtiff decodes).
 * A TIFF directory that names one tag twice is malformed (TIFF 6.0 asks for unique, ascending tags) and
 * refused: a reader that takes the last and a decoder that takes the first saw two images in one file.
 * @return false when the bytes are neither; `why` then says why when they look like one but are broken. */
bool readImageHeader(const std::string& bytes, ImageHeader& header, std::string& why);

/** Reads and decodes a PNG or TIFF file that must hold `expectedSize` pixels of `expectedType`: the file is
 * read with a bound that such an image cannot exceed (twice its pixels' bytes and 1 MiB, as LZW can
 * expand noise by half), its header is checked against the size and type, and only then is it decoded.
 * @throws cv::Exception starting with `what` and the path: too large, not a PNG or TIFF, another size or
 * type than expected, or not decodable. */
Mat readImageFileOfSize(const String& path, Size expectedSize, int expectedType, const String& what);

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // RAWGMENT_IMAGE_HEADERS_HPP
