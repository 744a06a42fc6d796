// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "raw_io_detail.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <libraw/libraw.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <unistd.h>
#include <vector>

namespace cv {
namespace rawgment {

namespace {

/* LibRaw keeps ISO and exposure time as float: ISO 200 of a file can come back as 200.000002 once
 * widened. The shortest decimal that gives the same float is the value the file held, and is what
 * gain ratios and the exported profiles should see. */
double shortestDecimal(float value)
{
    for (int digits = 1; digits < 9; ++digits) {
        const double candidate = std::strtod(cv::format("%.*g", digits, double(value)).c_str(), nullptr);
        if (float(candidate) == value)
            return candidate;
    }
    return double(value);
}

[[noreturn]] void failOn(const String& path, const String& reason)
{
    CV_Error(Error::StsError, "readRaw: '" + path + "': " + reason);
}

String libRawError(int code)
{
    // LibRaw returns negative codes of its own and positive errno values.
    return code > 0 ? String(std::strerror(code)) : String(libraw_strerror(code));
}

struct DataErrors
{
    int count = 0;
    int offset = 0;
};

void recordDataError(void* context, const char*, const int offset)
{
    auto* errors = static_cast<DataErrors*>(context);
    if (errors->count++ == 0)
        errors->offset = offset;
}

//! Colour index LibRaw gives a pixel (0 R, 1 G, 2 B, 3 second G) to our channel names.
CfaChannel channelOfLibRawColour(int colour, int row)
{
    switch (colour) {
    case 0:
        return CFA_R;
    case 2:
        return CFA_B;
    default:
        return (row & 1) == 0 ? CFA_G1 : CFA_G2;
    }
}

CfaPattern patternOf(LibRaw& raw, const String& path)
{
    // FC() covers 8 rows x 2 columns; a 2x2 Bayer layout repeats every 2 rows.
    for (int r = 2; r < 8; ++r)
        for (int c = 0; c < 2; ++c)
            if (raw.COLOR(r, c) != raw.COLOR(r % 2, c))
                failOn(path, "the colour filter array repeats over more than 2 rows; not a 2x2 Bayer mosaic");
    int colourAtSite[4];
    int count[4] = {0, 0, 0, 0};
    for (int s = 0; s < 4; ++s) {
        colourAtSite[s] = raw.COLOR(s / 2, s % 2);
        if (colourAtSite[s] < 0 || colourAtSite[s] > 3)
            failOn(path, format("LibRaw reports colour %d in the CFA; not a Bayer mosaic", colourAtSite[s]));
        ++count[colourAtSite[s] == 3 ? 1 : colourAtSite[s]];
    }
    if (count[0] != 1 || count[1] != 2 || count[2] != 1)
        failOn(path, "the 2x2 CFA block is not one red, two greens and one blue");
    // The red site decides the layout; the greens and blue follow for a Bayer block.
    for (int p = CFA_RGGB; p <= CFA_GBRG; ++p) {
        const CfaPattern pattern = static_cast<CfaPattern>(p);
        bool match = true;
        for (int s = 0; s < 4; ++s) {
            const CfaChannel want = cfaChannelAt(pattern, s / 2, s % 2);
            const CfaChannel got = channelOfLibRawColour(colourAtSite[s], s / 2);
            const bool bothGreen = (want == CFA_G1 || want == CFA_G2) && (got == CFA_G1 || got == CFA_G2);
            match = match && (want == got || bothGreen);
        }
        if (match)
            return pattern;
    }
    failOn(path, "the 2x2 CFA block is not a Bayer layout (the two greens are not diagonal)");
}

/* The layout LibRaw found, refused unless it is a 2x2 Bayer mosaic of red, green and blue or a monochrome
 * frame (one colour, no filter array) stored as integers. */
CfaPattern mosaicLayoutOf(LibRaw& raw, const String& path)
{
    const libraw_data_t& d = raw.imgdata;
    // One colour and no filter array: a monochrome sensor (a LinearRaw DNG with one sample per pixel).
    const bool mono = d.idata.filters == 0 && d.idata.colors == 1;
    if (d.idata.filters == 0 && !mono)
        failOn(path, format("LibRaw reports no colour filter array and %d colours: a linear or demosaiced "
                            "DNG or a Foveon, neither a Bayer mosaic nor a monochrome frame",
                            d.idata.colors));
    if (d.idata.filters == 9)
        failOn(path, "the sensor has a 6x6 X-Trans colour filter array, not a 2x2 Bayer mosaic");
    if (!mono && d.idata.filters < 1000)
        failOn(path, "the colour filter array is not a 2x2 Bayer layout");
    if (!mono && d.idata.colors != 3)
        failOn(path, format("the sensor has %d colours (for example CMYG), not red, green and blue",
                            d.idata.colors));
    if (raw.is_floating_point())
        failOn(path, "the mosaic is stored as floating point, which readRaw does not support");
    return mono ? CFA_MONO : patternOf(raw, path);
}

// The visible area's even part, copied out of LibRaw's decoded data.
Mat visibleMosaicOf(const LibRaw& raw, const String& path)
{
    const libraw_data_t& d = raw.imgdata;
    const libraw_image_sizes_t& s = d.sizes;
    // Our mosaic functions need even sides; an odd visible size loses its last row or column.
    const int rows = s.height & ~1, cols = s.width & ~1;
    if (rows < 2 || cols < 2)
        failOn(path, format("the visible area %dx%d is too small", int(s.width), int(s.height)));
    if (s.top_margin + rows > s.raw_height || s.left_margin + cols > s.raw_width)
        failOn(path, "the visible area lies outside the decoded data");
    Mat mosaic;
    const Mat full(s.raw_height, s.raw_width, CV_16UC1, d.rawdata.raw_image, s.raw_pitch);
    full(Rect(s.left_margin, s.top_margin, cols, rows)).copyTo(mosaic);
    return mosaic;
}

// The black level of each site of the 2x2 block: LibRaw's common black, its per-colour one and its pattern.
void readBlackLevels(LibRaw& raw, bool mono, RawFormat& format)
{
    const libraw_colordata_t& c = raw.imgdata.color;
    for (int site = 0; site < 4; ++site) {
        const int r = site / 2, col = site % 2;
        // LibRaw's COLOR() has no colour index for a frame without a filter; its one colour is index 0.
        double black = double(c.black) + double(c.cblack[mono ? 0 : raw.COLOR(r, col)]);
        if (c.cblack[4] > 0 && c.cblack[5] > 0) {
            const unsigned idx = 6 + (r % c.cblack[4]) * c.cblack[5] + (col % c.cblack[5]);
            if (idx < LIBRAW_CBLACK_SIZE)
                black += double(c.cblack[idx]);
        }
        format.blackLevel[site] = black;
    }
}

/* The camera's colour: white balance, the camera-to-sRGB matrix, the DNG's NoiseProfile and colour tags; for
 * another RAW format LibRaw's XYZ-to-camera matrix, which is Adobe's coefficients for the camera (integers
 * over 10000, given for D65): the DNG's ColorMatrix with CalibrationIlluminant D65 (21). A monochrome frame
 * has no colour to balance or convert: the identity balance and matrix. */
void readCameraColour(const LibRaw& raw, bool mono, const String& path, RawImage& out)
{
    const libraw_colordata_t& c = raw.imgdata.color;
    if (!mono && c.cam_mul[0] > 0 && c.cam_mul[1] > 0 && c.cam_mul[2] > 0)
        out.whiteBalance = Vec3d(c.cam_mul[0] / c.cam_mul[1], 1.0, c.cam_mul[2] / c.cam_mul[1]);
    bool haveMatrix = false;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            out.cameraToSrgb(i, j) = c.rgb_cam[i][j];
            haveMatrix = haveMatrix || (!mono && i != j && c.rgb_cam[i][j] != 0);
        }
    if (!haveMatrix)
        out.cameraToSrgb = Matx33d::eye();
    out.noiseProfile = detail::readDngNoiseProfile(path);
    if (mono && out.noiseProfile.size() > 1)
        failOn(path, format("its NoiseProfile has %d (S, O) pairs for its one colour plane; DNG allows one",
                            static_cast<int>(out.noiseProfile.size())));
    out.colorTags = detail::readDngColorTags(path);
    bool haveXyz = false;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            haveXyz = haveXyz || (!mono && c.cam_xyz[i][j] != 0);
    if (!out.colorTags.empty() || !haveXyz)
        return;
    DngTag colorMatrix;
    colorMatrix.tag = 50721;
    colorMatrix.type = 10;
    colorMatrix.count = 9;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            colorMatrix.values.insert(
                colorMatrix.values.end(),
                {static_cast<double>(std::llround(c.cam_xyz[i][j] * 10000.0)), 10000.0});
    DngTag illuminant;
    illuminant.tag = 50778;
    illuminant.type = 3;
    illuminant.count = 1;
    illuminant.values = {21};
    out.colorTags = {colorMatrix, illuminant};
}

} // namespace

RawImage readRaw(const String& path)
{
    if (path.empty())
        CV_Error(Error::StsBadArg, "readRaw: the path is empty");
    if (!pathExists(path))
        failOn(path, "no such file");
    // LibRaw would block on a FIFO's open and read a device until its own allocation limit.
    detail::FileStamp stamp;
    if (detail::fileStampOf(path, stamp) && !stamp.regular())
        failOn(path, detail::notRegularReason(stamp.mode));
    // LibRaw's state is a few hundred kilobytes: keep it off the stack.
    std::unique_ptr<LibRaw> raw(new LibRaw(0));
    DataErrors errors;
    raw->set_dataerror_handler(&recordDataError, &errors);
    int rc = raw->open_file(path.c_str());
    if (rc != LIBRAW_SUCCESS)
        failOn(path, "LibRaw cannot open it: " + libRawError(rc));
    const libraw_data_t& d = raw->imgdata;
    const CfaPattern pattern = mosaicLayoutOf(*raw, path);
    const bool mono = pattern == CFA_MONO;
    rc = raw->unpack();
    if (rc != LIBRAW_SUCCESS)
        failOn(path, "LibRaw cannot decode the image data (truncated or corrupt?): " + libRawError(rc));
    if (errors.count > 0)
        failOn(path, errors.offset < 0 ? String("the file is truncated (LibRaw reached its end early)")
                                       : format("the image data is corrupt (LibRaw reports a data error at "
                                                "offset %d)",
                                                errors.offset));
    if (!d.rawdata.raw_image)
        failOn(path, "LibRaw decoded no single-channel data for it");

    RawImage out;
    out.mosaic = visibleMosaicOf(*raw, path);
    out.format.pattern = pattern;
    readBlackLevels(*raw, mono, out.format);
    out.format.whiteLevel = double(d.color.maximum);
    out.format.gain = 1.0;
    try {
        out.format.validate();
    } catch (const Exception& e) {
        failOn(path, "LibRaw's levels do not make a valid format: " + e.err);
    }
    out.iso = d.other.iso_speed > 0 ? shortestDecimal(d.other.iso_speed) : 0.0;
    // LibRaw 0.20 reads ISOSpeedRatings only, which stops at 65535 (EXIF 2.3 states more in ISOSpeed).
    if (out.iso >= 65535) {
        const double exifIso = detail::readExifIsoSpeed(path);
        if (exifIso > 0)
            out.iso = exifIso;
    }
    out.exposureTime = d.other.shutter > 0 ? shortestDecimal(d.other.shutter) : 0.0;
    out.format.exposureTime = out.exposureTime;
    out.make = d.idata.make;
    out.model = d.idata.model;
    readCameraColour(*raw, mono, path, out);
    return out;
}

// ---------------------------------------------------------------------------------------------------
// Mosaics with sidecars.

CameraTags CameraTags::of(const RawImage& image)
{
    CameraTags tags;
    tags.make = image.make;
    tags.model = image.model;
    tags.iso = image.iso;
    tags.exposureTime = image.exposureTime;
    tags.whiteBalance = image.whiteBalance;
    tags.cameraToSrgb = image.cameraToSrgb;
    tags.noiseProfile = image.noiseProfile;
    tags.colorTags = image.colorTags;
    return tags;
}

void CameraTags::applyTo(RawImage& image) const
{
    image.make = make;
    image.model = model;
    image.iso = iso;
    image.exposureTime = exposureTime;
    image.whiteBalance = whiteBalance;
    image.cameraToSrgb = cameraToSrgb;
    image.noiseProfile = noiseProfile;
    image.colorTags = colorTags;
}

void CameraTags::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    writeString(fs, "make", make);
    writeString(fs, "model", model);
    fs << "iso" << iso << "exposure_time" << exposureTime;
    fs << "white_balance" << std::vector<double>(whiteBalance.val, whiteBalance.val + 3);
    fs << "camera_to_srgb" << std::vector<double>(cameraToSrgb.val, cameraToSrgb.val + 9);
    std::vector<double> pairs;
    for (const Vec2d& so : noiseProfile) {
        pairs.push_back(so[0]);
        pairs.push_back(so[1]);
    }
    fs << "noise_profile" << pairs;
    if (!colorTags.empty()) {
        fs << "color_tags"
           << "[";
        for (const DngTag& t : colorTags)
            fs << "{"
               << "tag" << t.tag << "type" << t.type << "count" << t.count << "values" << t.values << "}";
        fs << "]";
    }
    fs << "}";
}

CameraTags CameraTags::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "camera tags: expected a map");
    rejectUnknownKeys(node, {"make", "model", "iso", "exposure_time", "white_balance", "camera_to_srgb",
                             "noise_profile", "color_tags"});
    CameraTags tags;
    const auto text = [&](const char* field) {
        const FileNode f = node[field];
        if (!f.empty() && !f.isString())
            CV_Error(Error::StsParseError, cv::format("camera tags: field '%s' must be a string", field));
        return f.empty() ? String() : String(f);
    };
    tags.make = text("make");
    tags.model = text("model");
    tags.iso = detail::readOptionalRealField(node, "iso", 0);
    tags.exposureTime = detail::readOptionalRealField(node, "exposure_time", 0);
    if (!(tags.iso >= 0 && std::isfinite(tags.iso) && tags.exposureTime >= 0 &&
          std::isfinite(tags.exposureTime)))
        CV_Error(Error::StsParseError, "camera tags: iso and exposure_time must be finite and >= 0");
    const std::vector<double> wb = detail::readRealList(node, "white_balance", 3);
    const std::vector<double> m = detail::readRealList(node, "camera_to_srgb", 9);
    for (int k = 0; k < 3; ++k)
        tags.whiteBalance[k] = wb[size_t(k)];
    for (int k = 0; k < 9; ++k)
        tags.cameraToSrgb.val[k] = m[size_t(k)];
    const FileNode profile = node["noise_profile"];
    if (!profile.empty()) {
        if (!profile.isSeq() || (profile.size() != 0 && profile.size() != 2 && profile.size() != 6))
            CV_Error(Error::StsParseError,
                     "camera tags: field 'noise_profile' must be a list of 0, 2 or 6 numbers");
        const std::vector<double> v = detail::readRealList(node, "noise_profile", int(profile.size()));
        for (size_t k = 0; k + 1 < v.size(); k += 2)
            tags.noiseProfile.emplace_back(v[k], v[k + 1]);
        if (!tags.noiseProfile.empty())
            detail::checkDngNoiseProfile(tags.noiseProfile, "camera tags: noise_profile");
    }
    const FileNode colour = node["color_tags"];
    if (!colour.empty()) {
        if (!colour.isSeq() || colour.size() > 16)
            CV_Error(Error::StsParseError,
                     "camera tags: field 'color_tags' must be a list of at most 16 tags");
        for (const FileNode& entry : colour) {
            rejectUnknownKeys(entry, {"tag", "type", "count", "values"});
            DngTag t;
            t.tag = detail::readOptionalIntField(entry, "tag", 0);
            t.type = detail::readOptionalIntField(entry, "type", 0);
            t.count = detail::readOptionalIntField(entry, "count", 0);
            const bool rational = t.type == 5 || t.type == 10;
            if (t.count < 1 || t.count > 64)
                CV_Error(Error::StsParseError,
                         format("camera tags: colour tag %d: count %d is not in [1, 64]", t.tag, t.count));
            t.values = detail::readRealList(entry, "values", t.count * (rational ? 2 : 1));
            try {
                t.validate("camera tags: colour tag");
            } catch (const Exception& e) {
                CV_Error(Error::StsParseError, e.err);
            }
            if (std::any_of(tags.colorTags.begin(), tags.colorTags.end(),
                            [&](const DngTag& d) { return d.tag >= t.tag; }))
                CV_Error(Error::StsParseError,
                         format("camera tags: colour tag %d is repeated or out of order", t.tag));
            tags.colorTags.push_back(t);
        }
    }
    return tags;
}

namespace detail {

String lowerExtensionOf(const String& path)
{
    const size_t dot = path.find_last_of('.');
    const size_t slash = path.find_last_of('/');
    if (dot == String::npos || (slash != String::npos && dot < slash))
        return String();
    String ext = path.substr(dot);
    for (char& ch : ext)
        ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    return ext;
}

} // namespace detail

RawFormat formatAtIso(const RawFormat& format, double iso, const NoiseModel& model)
{
    format.validate();
    model.validate();
    if (!(std::isfinite(iso) && iso >= 0))
        CV_Error(Error::StsBadArg,
                 cv::format("formatAtIso: the ISO must be finite and >= 0 (0: unknown), not %g", iso));
    if (iso == 0)
        return format;
    if (!(model.baseIso > 0))
        CV_Error(Error::StsBadArg,
                 cv::format(
                     "formatAtIso: the capture is at ISO %g, but the noise model has no base ISO (the ISO of "
                     "its gain 1), so its gain is unknown; set the model's base_iso (a calibration from "
                     "files that state their ISO records it), or set the format's gain yourself",
                     iso));
    RawFormat out = format;
    out.gain = iso / model.baseIso;
    out.validate();
    return out;
}

RawFormat RawImage::formatFor(const NoiseModel& model) const
{
    return formatAtIso(format, iso, model);
}

} // namespace rawgment
} // namespace cv
