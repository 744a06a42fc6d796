// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The .npy mosaic container (mosaic_files topic): numpy's own format, uncompressed and C-ordered, so that a
// mosaic reads at the speed of a copy from the page cache, and numpy maps it without a copy
// (np.load(path, mmap_mode="r")). Only what writeMosaic() writes is read: a 2-D little-endian uint16 or
// float32 array in C order, its header checked to the byte and the file's size to the array's.
#include "precomp.hpp"

#include <cerrno>
#include <cstring>
#include <unistd.h>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

const char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicBytes = 6;
//! A 2-D array's header is under 128 bytes; numpy writes format 1.0 below 65536.
constexpr size_t kMaxHeaderBytes = 65535;
//! OpenCV's own limit on an image's pixels (CV_IO_MAX_IMAGE_PIXELS), and on a side.
constexpr long long kMaxPixels = 1LL << 30, kMaxSide = 1 << 20;

[[noreturn]] void malformed(const String& path, const std::string& why)
{
    CV_Error(Error::StsParseError, "readMosaic: '" + path + "' is not a mosaic .npy file: " + why);
}

/** The dictionary of a .npy header, read as numpy writes it: {'descr': '<u2', 'fortran_order': False,
 * 'shape': (rows, cols), } in any order, with spaces, each key once. */
struct NpyHeader
{
    std::string descr;
    bool fortranOrder = true;
    std::vector<long long> shape;
};

class HeaderParser
{
public:
    HeaderParser(const String& path, const std::string& text) : path_(path), text_(text) {}

    NpyHeader parse()
    {
        NpyHeader h;
        bool haveDescr = false, haveOrder = false, haveShape = false;
        expect('{');
        while (true) {
            skipSpaces();
            if (peek() == '}')
                break;
            const std::string key = quoted();
            expect(':');
            skipSpaces();
            bool* seen = key == "descr"           ? &haveDescr
                         : key == "fortran_order" ? &haveOrder
                         : key == "shape"         ? &haveShape
                                                  : nullptr;
            if (!seen)
                malformed(path_, "unknown header key '" + key + "'");
            if (*seen)
                malformed(path_, "header key '" + key + "' appears twice");
            *seen = true;
            if (key == "descr")
                h.descr = quoted();
            else if (key == "fortran_order")
                h.fortranOrder = boolean();
            else
                h.shape = tuple();
            skipSpaces();
            if (peek() == ',') {
                ++at_;
                continue;
            }
            skipSpaces();
            if (peek() != '}')
                malformed(path_, "expected ',' or '}' in the header");
        }
        ++at_;
        skipSpaces();
        if (at_ != text_.size())
            malformed(path_, "text after the header's dictionary");
        if (!(haveDescr && haveOrder && haveShape))
            malformed(path_, "the header lacks 'descr', 'fortran_order' or 'shape'");
        return h;
    }

private:
    char peek() const { return at_ < text_.size() ? text_[at_] : '\0'; }
    void skipSpaces()
    {
        while (at_ < text_.size() && (text_[at_] == ' ' || text_[at_] == '\n'))
            ++at_;
    }
    void expect(char c)
    {
        skipSpaces();
        if (peek() != c)
            malformed(path_, std::string("expected '") + c + "' in the header");
        ++at_;
    }
    std::string quoted()
    {
        skipSpaces();
        const char q = peek();
        if (q != '\'' && q != '"')
            malformed(path_, "expected a quoted string in the header");
        const size_t end = text_.find(q, at_ + 1);
        if (end == std::string::npos || end - at_ > 64)
            malformed(path_, "unterminated or overlong string in the header");
        std::string s = text_.substr(at_ + 1, end - at_ - 1);
        at_ = end + 1;
        return s;
    }
    bool boolean()
    {
        for (const char* word : {"False", "True"})
            if (text_.compare(at_, std::strlen(word), word) == 0) {
                at_ += std::strlen(word);
                return word[0] == 'T';
            }
        malformed(path_, "fortran_order must be True or False");
    }
    std::vector<long long> tuple()
    {
        expect('(');
        std::vector<long long> values;
        while (true) {
            skipSpaces();
            if (peek() == ')')
                break;
            long long v = 0;
            int digits = 0;
            while (peek() >= '0' && peek() <= '9') {
                if (++digits > 12)
                    malformed(path_, "a dimension of the shape is too large");
                v = 10 * v + (peek() - '0');
                ++at_;
            }
            if (digits == 0)
                malformed(path_, "the shape must be a tuple of non-negative integers");
            values.push_back(v);
            if (values.size() > 8)
                malformed(path_, "the shape has too many dimensions");
            skipSpaces();
            if (peek() == ',')
                ++at_;
            else if (peek() != ')')
                malformed(path_, "expected ',' or ')' in the shape");
        }
        ++at_;
        return values;
    }

    const String& path_;
    const std::string& text_;
    size_t at_ = 0;
};

//! Reads exactly `size` bytes at `offset`; false when the file ends first.
bool readFully(int fd, void* data, size_t size, off_t offset, const String& path)
{
    return detail::readFullyAt(fd, data, size, static_cast<long long>(offset), path, "readMosaic");
}

} // namespace

std::vector<uchar> npyFileBytes(const Mat& mosaic)
{
    CV_Assert(mosaic.dims == 2 && (mosaic.type() == CV_16UC1 || mosaic.type() == CV_32FC1));
    std::string header = format("{'descr': '%s', 'fortran_order': False, 'shape': (%d, %d), }",
                                mosaic.type() == CV_16UC1 ? "<u2" : "<f4", mosaic.rows, mosaic.cols);
    // numpy pads the header with spaces and a newline so that the data starts at a multiple of 64 bytes.
    const size_t preamble = kMagicBytes + 4;
    header.append((64 - (preamble + header.size() + 1) % 64) % 64, ' ');
    header += '\n';
    std::vector<uchar> bytes(preamble + header.size() + mosaic.total() * mosaic.elemSize());
    std::memcpy(bytes.data(), kMagic, kMagicBytes);
    bytes[6] = 1; // format 1.0
    bytes[7] = 0;
    bytes[8] = static_cast<uchar>(header.size() & 0xff);
    bytes[9] = static_cast<uchar>(header.size() >> 8);
    std::memcpy(bytes.data() + preamble, header.data(), header.size());
    uchar* data = bytes.data() + preamble + header.size();
    const size_t rowBytes = mosaic.cols * mosaic.elemSize();
    for (int r = 0; r < mosaic.rows; ++r)
        std::memcpy(data + r * rowBytes, mosaic.ptr(r), rowBytes);
    return bytes;
}

Mat readNpyMosaic(const String& path)
{
    const RegularFileForReading file(path, "mosaic");
    const int fd = file.fd();
    const long long fileBytes = file.size();
    uchar preamble[12];
    if (fileBytes < 10 || !readFully(fd, preamble, 10, 0, path) ||
        std::memcmp(preamble, kMagic, kMagicBytes) != 0)
        malformed(path, "it does not start with numpy's magic string");
    const int major = preamble[6];
    if ((major != 1 && major != 2 && major != 3) || preamble[7] != 0)
        malformed(path, format("format version %d.%d (1.0, 2.0 and 3.0 are read)", major, preamble[7]));
    size_t headerBytes = preamble[8] | (size_t(preamble[9]) << 8), preambleBytes = 10;
    if (major > 1) {
        if (!readFully(fd, preamble + 10, 2, 10, path))
            malformed(path, "the file ends inside its preamble");
        headerBytes |= (size_t(preamble[10]) << 16) | (size_t(preamble[11]) << 24);
        preambleBytes = 12;
    }
    if (headerBytes > kMaxHeaderBytes)
        malformed(path, format("a header of %zu bytes (at most %zu)", headerBytes, kMaxHeaderBytes));
    std::string text(headerBytes, '\0');
    if (!readFully(fd, &text[0], headerBytes, static_cast<off_t>(preambleBytes), path))
        malformed(path, "the file ends inside its header");
    for (char c : text)
        if (c < ' ' && c != '\n')
            malformed(path, "a control character in the header");
    const NpyHeader h = HeaderParser(path, text).parse();
    int type = -1;
    if (h.descr == "<u2")
        type = CV_16UC1;
    else if (h.descr == "<f4")
        type = CV_32FC1;
    else
        malformed(path,
                  "dtype '" + h.descr + "'; a mosaic is little-endian uint16 ('<u2') or float32 ('<f4')");
    if (h.fortranOrder)
        malformed(path, "Fortran order; a mosaic is stored in C order");
    if (h.shape.size() != 2)
        malformed(path, format("%zu dimensions; a mosaic has 2", h.shape.size()));
    const long long rows = h.shape[0], cols = h.shape[1];
    if (rows < 1 || cols < 1 || rows > kMaxSide || cols > kMaxSide || rows * cols > kMaxPixels)
        malformed(path,
                  format("shape (%lld, %lld); each side must lie in [1, %lld] and the pixels be at most %lld",
                         rows, cols, kMaxSide, kMaxPixels));
    const long long dataBytes = rows * cols * static_cast<long long>(CV_ELEM_SIZE(type));
    const long long dataOffset = static_cast<long long>(preambleBytes + headerBytes);
    // Checked before anything is allocated: a header cannot make the reader allocate more than the file.
    if (fileBytes != dataOffset + dataBytes)
        malformed(path,
                  format("%lld bytes, but its header describes %lld (%lld x %lld values after %lld bytes)",
                         fileBytes, dataOffset + dataBytes, rows, cols, dataOffset));
    Mat mosaic(static_cast<int>(rows), static_cast<int>(cols), type);
    adviseHugePages(mosaic);
    if (!readFully(fd, mosaic.data, static_cast<size_t>(dataBytes), static_cast<off_t>(dataOffset), path))
        CV_Error(Error::StsError, "readMosaic: '" + path + "' became shorter while it was read");
    return mosaic;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
