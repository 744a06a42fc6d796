// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// writeDng(): one little-endian TIFF IFD with an uncompressed 16-bit CFA strip (raw_io topic).
#include "raw_io_detail.hpp"

#include <opencv2/rawgment/raw_io.hpp>

#include <cstring>
#include <vector>

namespace cv {
namespace rawgment {

namespace {

enum TiffType : uint16_t
{
    TIFF_BYTE = 1,
    TIFF_ASCII = 2,
    TIFF_SHORT = 3,
    TIFF_LONG = 4,
    TIFF_RATIONAL = 5,
    TIFF_SRATIONAL = 10,
    TIFF_DOUBLE = 12
};

void put16le(std::vector<uint8_t>& b, uint16_t v)
{
    b.push_back(uint8_t(v));
    b.push_back(uint8_t(v >> 8));
}

void put32le(std::vector<uint8_t>& b, uint32_t v)
{
    for (int k = 0; k < 4; ++k)
        b.push_back(uint8_t(v >> (8 * k)));
}

struct TiffEntry
{
    uint16_t tag;
    uint16_t type;
    uint32_t count;
    std::vector<uint8_t> bytes; // the value, little-endian
};

class TiffBuilder
{
public:
    void add(uint16_t tag, uint16_t type, uint32_t count, std::vector<uint8_t> bytes)
    {
        entries_.push_back({tag, type, count, std::move(bytes)});
    }
    void shorts(uint16_t tag, std::initializer_list<uint16_t> v)
    {
        std::vector<uint8_t> b;
        for (uint16_t x : v)
            put16(b, x);
        add(tag, TIFF_SHORT, uint32_t(v.size()), b);
    }
    void longs(uint16_t tag, std::initializer_list<uint32_t> v)
    {
        std::vector<uint8_t> b;
        for (uint32_t x : v)
            put32(b, x);
        add(tag, TIFF_LONG, uint32_t(v.size()), b);
    }
    void bytes(uint16_t tag, std::initializer_list<uint8_t> v) { add(tag, TIFF_BYTE, uint32_t(v.size()), v); }
    void ascii(uint16_t tag, const String& s)
    {
        std::vector<uint8_t> b(s.begin(), s.end());
        b.push_back(0);
        add(tag, TIFF_ASCII, uint32_t(b.size()), b);
    }
    void rationals(uint16_t tag, const std::vector<double>& v, bool isSigned)
    {
        std::vector<uint8_t> b;
        for (double x : v) {
            // The largest power-of-ten denominator up to 10^9 whose numerator still fits 32 bits: nine
            // decimals for values below 2 (an exposure time of 1/32000 s, scaled by an augmentation's
            // photon ratio, keeps its digits), fewer for large ones, an error for what no rational holds.
            const double limit = isSigned ? 2147483647.0 : 4294967295.0;
            if (!std::isfinite(x) || std::abs(x) > limit || (!isSigned && x < 0))
                CV_Error(Error::StsBadArg, format("writeDng: tag %d: %g does not fit a TIFF %s", int(tag), x,
                                                  isSigned ? "SRATIONAL" : "RATIONAL"));
            uint32_t den = 1000000000;
            while (den > 1 && std::abs(x) * den > limit)
                den /= 10;
            const int64_t num = static_cast<int64_t>(std::llround(x * den));
            put32(b,
                  isSigned ? static_cast<uint32_t>(static_cast<int32_t>(num)) : static_cast<uint32_t>(num));
            put32(b, den);
        }
        add(tag, isSigned ? TIFF_SRATIONAL : TIFF_RATIONAL, uint32_t(v.size()), b);
    }

    void doubles(uint16_t tag, const std::vector<double>& v)
    {
        std::vector<uint8_t> b;
        for (double x : v) {
            uint64_t bits;
            std::memcpy(&bits, &x, sizeof(bits));
            put32(b, uint32_t(bits));
            put32(b, uint32_t(bits >> 32));
        }
        add(tag, TIFF_DOUBLE, uint32_t(v.size()), b);
    }

    //! Moves the entries with these tags into the EXIF sub-IFD (where LibRaw looks for the ISO).
    void moveToExif(std::initializer_list<uint16_t> tags)
    {
        for (uint16_t tag : tags)
            for (size_t i = 0; i < entries_.size(); ++i)
                if (entries_[i].tag == tag) {
                    exif_.push_back(entries_[i]);
                    entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(i));
                    break;
                }
    }

    //! The file: header, main IFD and its values, EXIF IFD and its values, then the image strip.
    std::vector<uint8_t> build(const Mat& mosaic)
    {
        const size_t stripBytes = mosaic.total() * 2;
        if (stripBytes > 0xF0000000u)
            CV_Error(Error::StsBadArg, "writeDng: the mosaic is too large for a baseline TIFF (4 GB)");
        longs(273, {0}); // StripOffsets, patched below
        longs(279, {uint32_t(stripBytes)});
        if (!exif_.empty())
            longs(34665, {0}); // ExifIFD, patched below
        std::vector<uint8_t> out = {'I', 'I', 42, 0};
        put32(out, 8);
        std::vector<std::pair<uint16_t, size_t>> fields = appendIfd(out, entries_);
        if (!exif_.empty()) {
            patch32(out, fieldOf(fields, 34665), uint32_t(out.size()));
            appendIfd(out, exif_);
        }
        patch32(out, fieldOf(fields, 273), uint32_t(out.size()));
        out.reserve(out.size() + stripBytes);
        for (int r = 0; r < mosaic.rows; ++r) {
            const ushort* p = mosaic.ptr<ushort>(r);
            for (int c = 0; c < mosaic.cols; ++c)
                put16(out, p[c]);
        }
        return out;
    }

private:
    static void put16(std::vector<uint8_t>& b, uint16_t v)
    {
        b.push_back(uint8_t(v));
        b.push_back(uint8_t(v >> 8));
    }
    static void put32(std::vector<uint8_t>& b, uint32_t v)
    {
        for (int k = 0; k < 4; ++k)
            b.push_back(uint8_t(v >> (8 * k)));
    }
    //! Appends an IFD at the end of `out` (absolute offsets) with its out-of-line values after it;
    //! returns where each tag's value field is.
    static std::vector<std::pair<uint16_t, size_t>> appendIfd(std::vector<uint8_t>& out,
                                                              std::vector<TiffEntry> entries)
    {
        std::sort(entries.begin(), entries.end(),
                  [](const TiffEntry& a, const TiffEntry& b) { return a.tag < b.tag; });
        const size_t ifdSize = 2 + 12 * entries.size() + 4;
        const size_t dataOffset = out.size() + ifdSize;
        std::vector<uint8_t> data;
        std::vector<std::pair<uint16_t, size_t>> fields;
        put16(out, uint16_t(entries.size()));
        for (const TiffEntry& e : entries) {
            put16(out, e.tag);
            put16(out, e.type);
            put32(out, e.count);
            fields.emplace_back(e.tag, out.size());
            if (e.bytes.size() <= 4) {
                std::vector<uint8_t> v = e.bytes;
                v.resize(4, 0);
                out.insert(out.end(), v.begin(), v.end());
            } else {
                put32(out, uint32_t(dataOffset + data.size()));
                data.insert(data.end(), e.bytes.begin(), e.bytes.end());
                if (data.size() % 2)
                    data.push_back(0); // TIFF values start on word boundaries
            }
        }
        put32(out, 0); // no next IFD
        out.insert(out.end(), data.begin(), data.end());
        return fields;
    }
    static size_t fieldOf(const std::vector<std::pair<uint16_t, size_t>>& fields, uint16_t tag)
    {
        for (const auto& f : fields)
            if (f.first == tag)
                return f.second;
        CV_Error(Error::StsInternal, "writeDng: missing TIFF tag");
    }
    static void patch32(std::vector<uint8_t>& b, size_t at, uint32_t v)
    {
        for (int k = 0; k < 4; ++k)
            b[at + k] = uint8_t(v >> (8 * k));
    }
    std::vector<TiffEntry> entries_;
    std::vector<TiffEntry> exif_;
};

uint8_t dngColourOf(CfaChannel ch)
{
    return ch == CFA_R ? 0 : (ch == CFA_B ? 2 : 1);
}

//! The one ExposureTime tag: the image's, or its format's when the image states none.
double dngExposureTime(const RawImage& image)
{
    return image.exposureTime > 0 ? image.exposureTime : image.format.exposureTime;
}

/** Every field writeDng stores, checked against what its tag can hold; returns the black levels as the
 * integers DNG stores for 16-bit data. */
std::vector<uint32_t> checkDngImage(const String& path, const RawImage& image)
{
    image.format.validate();
    const Mat& m = image.mosaic;
    if (m.empty() || m.type() != CV_16UC1)
        CV_Error(Error::StsBadArg, format("writeDng: '%s': the mosaic must be a non-empty CV_16UC1 (got %s)",
                                          path.c_str(), typeToString(m.type()).c_str()));
    if (m.rows % 2 || m.cols % 2)
        CV_Error(Error::StsBadArg, format("writeDng: '%s': the mosaic is %dx%d; both sides must be even",
                                          path.c_str(), m.cols, m.rows));
    std::vector<uint32_t> blacks(4);
    for (int s = 0; s < 4; ++s) {
        const double b = image.format.blackLevel[s];
        if (std::abs(b - std::round(b)) > 1e-9)
            CV_Error(Error::StsBadArg, format("writeDng: '%s': black level %g of site %d is not an integer; "
                                              "DNG stores integer levels for 16-bit data",
                                              path.c_str(), b, s));
        blacks[s] = static_cast<uint32_t>(std::llround(b));
    }
    if (image.format.whiteLevel > 65535)
        CV_Error(Error::StsBadArg,
                 format("writeDng: '%s': white level %g does not fit 16-bit data (<= 65535)", path.c_str(),
                        image.format.whiteLevel));
    // WhiteLevel is an integer tag: 4095.5 was written as 4096 and read back so, another sensor.
    if (image.format.whiteLevel != std::round(image.format.whiteLevel))
        CV_Error(Error::StsBadArg, format("writeDng: '%s': white level %.17g is not an integer; DNG stores "
                                          "integer levels for 16-bit data",
                                          path.c_str(), image.format.whiteLevel));
    const double exposureTime = dngExposureTime(image);
    if (image.exposureTime > 0 && image.format.exposureTime > 0 &&
        std::abs(image.exposureTime - image.format.exposureTime) > 1e-9 * image.exposureTime)
        CV_Error(
            Error::StsBadArg,
            format("writeDng: '%s': exposure time %g s but format.exposureTime %g s: one capture has one",
                   path.c_str(), image.exposureTime, image.format.exposureTime));
    if (!(exposureTime >= 0 && exposureTime <= 4294967295.0))
        CV_Error(Error::StsBadArg, format("writeDng: '%s': exposure time %g s does not fit its DNG tag "
                                          "(a rational of at most 4294967295 s)",
                                          path.c_str(), exposureTime));
    if (!(image.iso >= 0 && image.iso < 4294967295.5))
        CV_Error(Error::StsBadArg,
                 format("writeDng: '%s': ISO %g is not one a DNG can state (0 for unknown, or "
                        "up to 4294967295, rounded to an integer)",
                        path.c_str(), image.iso));
    // LibRaw, and so readRaw(), reads no mosaic smaller than this on a side.
    const int smallest = 22;
    if (m.rows < smallest || m.cols < smallest)
        CV_Error(Error::StsBadArg,
                 format("writeDng: '%s': the mosaic is %dx%d; LibRaw (readRaw) reads no RAW file "
                        "smaller than %d pixels on a side",
                        path.c_str(), m.cols, m.rows, smallest));
    if (!image.noiseProfile.empty())
        detail::checkDngNoiseProfile(image.noiseProfile, ("writeDng: '" + path + "': noiseProfile").c_str());
    if (image.format.isMonochrome() && image.noiseProfile.size() > 1)
        CV_Error(
            Error::StsBadArg,
            format("writeDng: '%s': %d noise profile pairs for a monochrome frame; its one colour plane has "
                   "one (S, O) pair",
                   path.c_str(), static_cast<int>(image.noiseProfile.size())));

    return blacks;
}

void addColourTags(TiffBuilder& t, const RawImage& image)
{
    // The colour tags as the source stated them (RawImage::colorTags): rebuilt from LibRaw's normalised
    // matrix, ColorMatrix1's rows came out rescaled and a reader derived another white point.
    const auto has = [&](int tag) {
        return std::any_of(image.colorTags.begin(), image.colorTags.end(),
                           [&](const DngTag& d) { return d.tag == tag; });
    };
    for (const DngTag& tag : image.colorTags) {
        tag.validate("writeDng: colour tag");
        if (std::count_if(image.colorTags.begin(), image.colorTags.end(),
                          [&](const DngTag& d) { return d.tag == tag.tag; }) > 1)
            CV_Error(Error::StsBadArg, format("writeDng: colour tag %d is given twice", tag.tag));
        std::vector<uint8_t> b;
        for (double v : tag.values) {
            if (tag.type == 3)
                put16le(b, static_cast<uint16_t>(v));
            else if (tag.type == 11) {
                const float f = static_cast<float>(v);
                uint32_t bits;
                std::memcpy(&bits, &f, sizeof(bits));
                put32le(b, bits);
            } else if (tag.type == 12) {
                uint64_t bits;
                std::memcpy(&bits, &v, sizeof(bits));
                put32le(b, uint32_t(bits));
                put32le(b, uint32_t(bits >> 32));
            } else
                put32le(b, static_cast<uint32_t>(static_cast<int64_t>(v)));
        }
        t.add(uint16_t(tag.tag), uint16_t(tag.type), uint32_t(tag.count), b);
    }
    if (!has(50721)) {
        // No stated colour: ColorMatrix1 maps XYZ to camera RGB, camera = inverse(cameraToSrgb) * (XYZ to
        // linear sRGB, D65), for D65.
        const Matx33d xyzToSrgb(3.2404542, -1.5371385, -0.4985314, -0.9692660, 1.8760108, 0.0415560,
                                0.0556434, -0.2040259, 1.0572252);
        Matx33d inv;
        if (cv::invert(image.cameraToSrgb, inv, DECOMP_SVD) == 0)
            CV_Error(Error::StsBadArg, "writeDng: cameraToSrgb is singular");
        const Matx33d colorMatrix = inv * xyzToSrgb;
        t.rationals(50721, std::vector<double>(colorMatrix.val, colorMatrix.val + 9), true);
        if (!has(50778))
            t.shorts(50778, {21}); // CalibrationIlluminant1: D65
    }
    if (!has(50728) && !has(50729)) {
        std::vector<double> neutral(3);
        for (int c = 0; c < 3; ++c) {
            detail::checkFinitePositive(image.whiteBalance[c], "writeDng: whiteBalance");
            neutral[c] = image.whiteBalance[1] / image.whiteBalance[c];
        }
        t.rationals(50728, neutral, false);
    }
}

} // namespace

namespace detail {

std::vector<uint8_t> dngFileBytes(const String& path, const RawImage& image)
{
    const std::vector<uint32_t> blacks = checkDngImage(path, image);
    const Mat& m = image.mosaic;

    TiffBuilder t;
    t.longs(254, {0});
    t.longs(256, {uint32_t(m.cols)});
    t.longs(257, {uint32_t(m.rows)});
    t.shorts(258, {16});
    t.shorts(259, {1});
    const bool mono = image.format.isMonochrome();
    t.shorts(262, {static_cast<uint16_t>(mono ? 34892 : 32803)}); // LinearRaw or CFA
    if (!image.make.empty())
        t.ascii(271, image.make);
    if (!image.model.empty())
        t.ascii(272, image.model);
    t.shorts(274, {1});
    t.shorts(277, {1});
    t.longs(278, {uint32_t(m.rows)});
    t.shorts(284, {1});
    t.ascii(305, "cv::rawgment");
    if (!mono) {
        t.shorts(33421, {2, 2});
        const CfaPattern p = image.format.pattern;
        t.bytes(33422, {dngColourOf(cfaChannelAt(p, 0, 0)), dngColourOf(cfaChannelAt(p, 0, 1)),
                        dngColourOf(cfaChannelAt(p, 1, 0)), dngColourOf(cfaChannelAt(p, 1, 1))});
    }
    if (dngExposureTime(image) > 0)
        t.rationals(33434, {dngExposureTime(image)}, false);
    if (image.iso > 0) {
        // EXIF 2.3: ISOSpeedRatings holds 16 bits, and 65535 there says that ISOSpeed (32 bits) holds the
        // value; SensitivityType 3 says that ISOSpeed is the one stated. ISO tags hold integers.
        const double iso = std::round(image.iso);
        t.shorts(34855, {static_cast<uint16_t>(std::min(65535.0, iso))});
        if (iso >= 65535) {
            t.shorts(34864, {3});
            t.longs(34867, {static_cast<uint32_t>(iso)});
        }
    }
    t.bytes(50706, {1, 4, 0, 0});
    t.bytes(50707, {1, 1, 0, 0});
    t.ascii(50708, image.make.empty() && image.model.empty() ? String("cv::rawgment")
                                                             : image.make + " " + image.model);
    if (mono) {
        // A monochrome DNG has one sample per pixel and one black level (RawFormat::validate() makes
        // the four sites' equal); DNG requires colour tags only of files with colour.
        t.shorts(50713, {1, 1});
        t.longs(50714, {blacks[0]});
    } else {
        t.bytes(50710, {0, 1, 2}); // CFAPlaneColor
        t.shorts(50711, {1});      // CFALayout: rectangular
        t.shorts(50713, {2, 2});
        t.longs(50714, {blacks[0], blacks[1], blacks[2], blacks[3]});
    }
    t.longs(50717, {static_cast<uint32_t>(std::llround(image.format.whiteLevel))});
    if (!mono)
        addColourTags(t, image);
    if (!image.noiseProfile.empty()) {
        std::vector<double> pairs;
        for (const Vec2d& so : image.noiseProfile) {
            pairs.push_back(so[0]);
            pairs.push_back(so[1]);
        }
        t.doubles(51041, pairs);
    }
    t.moveToExif({33434, 34855, 34864, 34867});
    return t.build(m);
}

} // namespace detail

void writeDng(const String& path, const RawImage& image)
{
    const std::vector<uint8_t> bytes = detail::dngFileBytes(path, image);
    // Never replaces: an existing file of these very bytes is this call's output, any other an error.
    writeFileAtomically(path, bytes.data(), bytes.size(), false);
}

} // namespace rawgment
} // namespace cv
