// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/bayer.hpp"
#include "precomp.hpp"

#include <algorithm>
#include <array>
#include <cctype>

namespace cv {
namespace rawgment {

namespace {

// Channels of the four sites, per pattern (row-major 2x2 block).
constexpr std::array<std::array<CfaChannel, 4>, 5> kChannelsOfPattern = {{
    {{CFA_R, CFA_G1, CFA_G2, CFA_B}}, // RGGB
    {{CFA_B, CFA_G2, CFA_G1, CFA_R}}, // BGGR
    {{CFA_G1, CFA_R, CFA_B, CFA_G2}}, // GRBG
    {{CFA_G2, CFA_B, CFA_R, CFA_G1}}, // GBRG
    {{CFA_W, CFA_W, CFA_W, CFA_W}},   // MONO
}};
constexpr std::array<const char*, 5> kPatternNames = {{"RGGB", "BGGR", "GRBG", "GBRG", "MONO"}};

void checkPattern(CfaPattern pattern)
{
    if (pattern < CFA_RGGB || pattern > CFA_MONO)
        CV_Error(Error::StsBadArg,
                 format("CFA pattern %d is not one of CFA_RGGB, CFA_BGGR, CFA_GRBG, CFA_GBRG, CFA_MONO",
                        static_cast<int>(pattern)));
}

inline int mod2(int v)
{
    return v & 1;
} // two's complement: also right for negative values

void checkMosaic(const Mat& m, const char* what)
{
    if (m.empty())
        CV_Error(Error::StsBadArg, format("%s is empty; expected a single-channel Bayer mosaic", what));
    if (m.channels() != 1)
        CV_Error(Error::StsBadArg,
                 format("%s has %d channels; expected a single-channel Bayer mosaic", what, m.channels()));
}

// dst(r, c) = (src(r, c) - offset[site]) * scale[site], with float arithmetic per row.
template <typename Src> void affinePerSite(const Mat& src, Mat& dst, const Vec4d& offset, const Vec4d& scale)
{
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const Src* s = src.ptr<Src>(r);
            float* d = dst.ptr<float>(r);
            const int site0 = 2 * mod2(r);
            const float o0 = static_cast<float>(offset[site0]), o1 = static_cast<float>(offset[site0 + 1]);
            const float k0 = static_cast<float>(scale[site0]), k1 = static_cast<float>(scale[site0 + 1]);
            int c = 0;
            for (; c + 1 < src.cols; c += 2) {
                d[c] = (static_cast<float>(s[c]) - o0) * k0;
                d[c + 1] = (static_cast<float>(s[c + 1]) - o1) * k1;
            }
            if (c < src.cols)
                d[c] = (static_cast<float>(s[c]) - o0) * k0;
        }
    });
}

// dst = clip(src * scale[site] + offset[site], 0, white), rounded when Dst is integral.
template <typename Dst>
void inverseAffinePerSite(const Mat& src, Mat& dst, const Vec4d& offset, const Vec4d& scale, double white)
{
    const float hi = static_cast<float>(white);
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const float* s = src.ptr<float>(r);
            Dst* d = dst.ptr<Dst>(r);
            const int site0 = 2 * mod2(r);
            for (int c = 0; c < src.cols; ++c) {
                const int site = site0 + mod2(c);
                float v = s[c] * static_cast<float>(scale[site]) + static_cast<float>(offset[site]);
                // NaN fails both comparisons; map it to 0 rather than let it through as garbage.
                v = v >= 0.f ? (v <= hi ? v : hi) : 0.f;
                d[c] = saturate_cast<Dst>(v);
            }
        }
    });
}

} // namespace

int cfaSite(int row, int col)
{
    return 2 * mod2(row) + mod2(col);
}

CfaChannel cfaChannelAt(CfaPattern pattern, int row, int col)
{
    checkPattern(pattern);
    return kChannelsOfPattern[pattern][cfaSite(row, col)];
}

int cfaSiteOfChannel(CfaPattern pattern, CfaChannel channel)
{
    checkPattern(pattern);
    if (channel < CFA_R || channel > CFA_W)
        CV_Error(Error::StsBadArg, format("CFA channel %d is not one of CFA_R, CFA_G1, CFA_G2, CFA_B, CFA_W",
                                          static_cast<int>(channel)));
    const auto& sites = kChannelsOfPattern[pattern];
    const auto site = std::find(sites.begin(), sites.end(), channel);
    if (site == sites.end())
        CV_Error(Error::StsBadArg,
                 format("a %s frame has no CFA channel %d (%s)", kPatternNames[pattern],
                        static_cast<int>(channel),
                        pattern == CFA_MONO ? "a monochrome frame has only CFA_W"
                                            : "CFA_W is the channel of a monochrome frame"));
    return static_cast<int>(site - sites.begin());
}

CfaPattern cfaPatternOfCrop(CfaPattern pattern, int rowOffset, int colOffset)
{
    checkPattern(pattern);
    if (pattern == CFA_MONO)
        return CFA_MONO;
    // The crop's site s lies at the original's site s XOR the offset's phase.
    const int shift = cfaSite(rowOffset, colOffset);
    const auto& original = kChannelsOfPattern[pattern];
    for (int p = 0; p < 4; ++p) {
        bool same = true;
        for (int s = 0; s < 4; ++s)
            same = same && kChannelsOfPattern[p][s] == original[s ^ shift];
        if (same)
            return static_cast<CfaPattern>(p);
    }
    CV_Error(Error::StsInternal, "no Bayer pattern matches the cropped layout");
}

String cfaPatternName(CfaPattern pattern)
{
    checkPattern(pattern);
    return kPatternNames[pattern];
}

CfaPattern cfaPatternFromName(const String& name)
{
    String upper = name;
    std::transform(upper.begin(), upper.end(), upper.begin(),
                   [](unsigned char ch) { return static_cast<char>(std::toupper(ch)); });
    for (size_t p = 0; p < kPatternNames.size(); ++p)
        if (upper == kPatternNames[p])
            return static_cast<CfaPattern>(p);
    CV_Error(Error::StsBadArg,
             "unknown CFA pattern '" + name + "'; expected one of RGGB, BGGR, GRBG, GBRG, MONO");
}

void RawFormat::validate() const
{
    checkPattern(pattern);
    if (!std::isfinite(whiteLevel))
        CV_Error(Error::StsBadArg, format("RawFormat.whiteLevel must be finite (got %g)", whiteLevel));
    for (int s = 0; s < 4; ++s) {
        if (!std::isfinite(blackLevel[s]) || blackLevel[s] < 0)
            CV_Error(Error::StsBadArg,
                     format("RawFormat.blackLevel[%d] must be finite and >= 0 (got %g)", s, blackLevel[s]));
        if (!(whiteLevel > blackLevel[s]))
            CV_Error(Error::StsBadArg,
                     format("RawFormat.whiteLevel (%g) must be above the black level of every site "
                            "(blackLevel[%d] = %g)",
                            whiteLevel, s, blackLevel[s]));
    }
    if (pattern == CFA_MONO && blackLevel != Vec4d::all(blackLevel[0]))
        CV_Error(Error::StsBadArg,
                 format("RawFormat.blackLevel must be one value on all four sites for a CFA_MONO format (got "
                        "%g, %g, %g, %g): a sensor without a colour filter has no 2x2 structure",
                        blackLevel[0], blackLevel[1], blackLevel[2], blackLevel[3]));
    detail::checkFinitePositive(gain, "RawFormat.gain");
    if (sensorOrigin.x < 0 || sensorOrigin.y < 0)
        CV_Error(Error::StsBadArg, format("RawFormat.sensorOrigin must be >= 0 (got (%d, %d))",
                                          sensorOrigin.x, sensorOrigin.y));
    if (!(std::isfinite(exposureTime) && exposureTime >= 0))
        CV_Error(Error::StsBadArg,
                 format("RawFormat.exposureTime must be finite and >= 0 seconds (got %g)", exposureTime));
}

RawFormat RawFormat::cropped(int rowOffset, int colOffset) const
{
    RawFormat out = *this;
    out.pattern = cfaPatternOfCrop(pattern, rowOffset, colOffset);
    const int shift = cfaSite(rowOffset, colOffset);
    for (int s = 0; s < 4; ++s)
        out.blackLevel[s] = blackLevel[s ^ shift];
    out.sensorOrigin += Point(colOffset, rowOffset);
    return out;
}

void RawFormat::write(FileStorage& fs, const String& name) const
{
    validate();
    fs << name << "{";
    fs << "pattern" << cfaPatternName(pattern);
    fs << "black_level"
       << "[" << blackLevel[0] << blackLevel[1] << blackLevel[2] << blackLevel[3] << "]";
    fs << "white_level" << whiteLevel;
    fs << "gain" << gain;
    if (sensorOrigin != Point(0, 0))
        fs << "sensor_origin"
           << "[:" << sensorOrigin.x << sensorOrigin.y << "]";
    // Only when stated, so that a format without one keeps the bytes it had before the field existed.
    if (exposureTime > 0)
        fs << "exposure_time" << exposureTime;
    fs << "}";
}

RawFormat RawFormat::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError,
                 "raw format: expected a map with pattern, black_level, white_level, gain");
    RawFormat f;
    const FileNode patternNode = node["pattern"];
    if (!patternNode.isString())
        CV_Error(Error::StsParseError, "raw format: field 'pattern' is missing or not a string");
    f.pattern = cfaPatternFromName(patternNode.string());
    try {
        rejectUnknownKeys(
            node, {"pattern", "black_level", "white_level", "gain", "sensor_origin", "exposure_time"});
        const std::vector<double> black = detail::readRealList(node, "black_level", 4);
        for (int s = 0; s < 4; ++s)
            f.blackLevel[s] = black[static_cast<size_t>(s)];
        f.whiteLevel = detail::readRealField(node, "white_level");
        f.gain = detail::readRealField(node, "gain");
        if (!node["sensor_origin"].empty()) {
            const std::vector<double> origin = detail::readRealList(node, "sensor_origin", 2);
            for (double v : origin)
                if (!(v >= 0 && v <= 1e9 && v == std::floor(v)))
                    CV_Error(Error::StsParseError, "field 'sensor_origin' must be two whole numbers >= 0");
            f.sensorOrigin = Point(static_cast<int>(origin[0]), static_cast<int>(origin[1]));
        }
        f.exposureTime = detail::readOptionalRealField(node, "exposure_time", 0);
    } catch (const Exception& e) {
        CV_Error(e.code, "raw format: " + e.err);
    }
    f.validate();
    return f;
}

void splitCfaPlanes(InputArray _mosaic, OutputArrayOfArrays _planes)
{
    const Mat mosaic = detail::twoDimensional(_mosaic, "splitCfaPlanes: mosaic");
    checkMosaic(mosaic, "splitCfaPlanes: mosaic");
    if (mosaic.rows % 2 != 0 || mosaic.cols % 2 != 0)
        CV_Error(Error::StsBadArg,
                 format("splitCfaPlanes: mosaic is %dx%d (cols x rows); both sides must be even so that "
                        "the four CFA planes have one size (crop the mosaic first)",
                        mosaic.cols, mosaic.rows));
    const Size half(mosaic.cols / 2, mosaic.rows / 2);
    _planes.create(4, 1, mosaic.type());
    std::array<Mat, 4> planes;
    for (int s = 0; s < 4; ++s) {
        _planes.create(half, mosaic.type(), s);
        planes[s] = _planes.getMat(s);
    }
    const size_t elem = mosaic.elemSize();
    parallel_for_(Range(0, half.height), [&](const Range& rows) {
        for (int i = rows.start; i < rows.end; ++i) {
            for (int s = 0; s < 4; ++s) {
                const uchar* src = mosaic.ptr(2 * i + s / 2) + (s % 2) * elem;
                uchar* dst = planes[s].ptr(i);
                for (int j = 0; j < half.width; ++j, src += 2 * elem, dst += elem)
                    std::copy(src, src + elem, dst);
            }
        }
    });
}

void mergeCfaPlanes(InputArrayOfArrays _planes, OutputArray _mosaic)
{
    std::vector<Mat> planes;
    _planes.getMatVector(planes);
    if (planes.size() != 4)
        CV_Error(Error::StsBadArg, format("mergeCfaPlanes: got %d planes; expected 4 (one per CFA site)",
                                          static_cast<int>(planes.size())));
    for (int s = 0; s < 4; ++s) {
        detail::twoDimensional(planes[s], "mergeCfaPlanes: plane");
        checkMosaic(planes[s], "mergeCfaPlanes: plane");
        if (planes[s].size() != planes[0].size() || planes[s].type() != planes[0].type())
            CV_Error(Error::StsBadArg,
                     format("mergeCfaPlanes: plane %d is %dx%d of type %d; every plane must match plane 0 "
                            "(%dx%d of type %d)",
                            s, planes[s].cols, planes[s].rows, planes[s].type(), planes[0].cols,
                            planes[0].rows, planes[0].type()));
    }
    const Size half = planes[0].size();
    _mosaic.create(2 * half.height, 2 * half.width, planes[0].type());
    Mat mosaic = _mosaic.getMat();
    const size_t elem = mosaic.elemSize();
    parallel_for_(Range(0, half.height), [&](const Range& rows) {
        for (int i = rows.start; i < rows.end; ++i) {
            for (int s = 0; s < 4; ++s) {
                const uchar* src = planes[s].ptr(i);
                uchar* dst = mosaic.ptr(2 * i + s / 2) + (s % 2) * elem;
                for (int j = 0; j < half.width; ++j, src += elem, dst += 2 * elem)
                    std::copy(src, src + elem, dst);
            }
        }
    });
}

void subtractBlackLevel(InputArray _src, const RawFormat& format, OutputArray _dst, bool normalize)
{
    format.validate();
    const Mat src = detail::twoDimensional(_src, "subtractBlackLevel: src");
    checkMosaic(src, "subtractBlackLevel: src");
    if (src.type() != CV_16UC1 && src.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, cv::format("subtractBlackLevel: src type %s is not supported; expected "
                                              "CV_16UC1 or CV_32FC1",
                                              typeToString(src.type()).c_str()));
    Vec4d scale = Vec4d::all(1);
    if (normalize)
        for (int s = 0; s < 4; ++s)
            scale[s] = 1.0 / (format.whiteLevel - format.blackLevel[s]);
    // A fresh Mat keeps src intact when the caller passes the same Mat as src and dst.
    Mat dst(src.size(), CV_32FC1);
    detail::adviseHugePages(dst);
    if (src.depth() == CV_16U)
        affinePerSite<ushort>(src, dst, format.blackLevel, scale);
    else
        affinePerSite<float>(src, dst, format.blackLevel, scale);
    _dst.assign(dst);
}

namespace {

/* Each pair of mosaic rows read once and written to the four plane rows it feeds; `plane[site]` is where
 * that site's plane starts in the output, its row `i` from mosaic rows 2i and 2i + 1. */
template <typename Src>
void packPerSite(const Mat& src, Mat& dst, const int planeOfSite[4], const Vec4d& offset, const Vec4d& scale)
{
    const int half = src.rows / 2, width = src.cols / 2;
    parallel_for_(Range(0, half), [&](const Range& rows) {
        for (int i = rows.start; i < rows.end; ++i)
            for (int dy = 0; dy < 2; ++dy) {
                const Src* s = src.ptr<Src>(2 * i + dy);
                const int even = 2 * dy, odd = 2 * dy + 1;
                float* de = dst.ptr<float>(planeOfSite[even] * half + i);
                float* dodd = dst.ptr<float>(planeOfSite[odd] * half + i);
                const float oe = static_cast<float>(offset[even]), oo = static_cast<float>(offset[odd]);
                const float ke = static_cast<float>(scale[even]), ko = static_cast<float>(scale[odd]);
                for (int j = 0; j < width; ++j) {
                    de[j] = (static_cast<float>(s[2 * j]) - oe) * ke;
                    dodd[j] = (static_cast<float>(s[2 * j + 1]) - oo) * ko;
                }
            }
    });
}

} // namespace

void packCfaPlanes(InputArray _mosaic, const RawFormat& format, OutputArray _planes, bool normalize)
{
    format.validate();
    const Mat src = detail::twoDimensional(_mosaic, "packCfaPlanes: mosaic");
    checkMosaic(src, "packCfaPlanes: mosaic");
    if (src.type() != CV_16UC1 && src.type() != CV_32FC1)
        CV_Error(Error::StsBadArg,
                 cv::format("packCfaPlanes: mosaic type %s is not supported; expected CV_16UC1 "
                            "or CV_32FC1",
                            typeToString(src.type()).c_str()));
    if (src.rows % 2 || src.cols % 2)
        CV_Error(Error::StsBadArg, cv::format("packCfaPlanes: the mosaic is %dx%d; its sides must be even",
                                              src.cols, src.rows));
    Vec4d scale = Vec4d::all(1);
    if (normalize)
        for (int s = 0; s < 4; ++s)
            scale[s] = 1.0 / (format.whiteLevel - format.blackLevel[s]);
    int planeOfSite[4] = {0, 1, 2, 3};
    const CfaChannel order[4] = {CFA_R, CFA_G1, CFA_G2, CFA_B};
    if (!format.isMonochrome())
        for (int k = 0; k < 4; ++k)
            planeOfSite[cfaSiteOfChannel(format.pattern, order[k])] = k;
    _planes.create(2 * src.rows, src.cols / 2, CV_32FC1);
    Mat dst = _planes.getMat();
    // Often a tensor's new memory, first touched here.
    detail::adviseHugePages(dst);
    // The output may be the caller's memory; it must not be the input's.
    if (dst.data == src.data)
        CV_Error(Error::StsBadArg, "packCfaPlanes: planes must not share the mosaic's memory");
    if (src.depth() == CV_16U)
        packPerSite<ushort>(src, dst, planeOfSite, format.blackLevel, scale);
    else
        packPerSite<float>(src, dst, planeOfSite, format.blackLevel, scale);
}

void addBlackLevel(InputArray _src, const RawFormat& format, OutputArray _dst, int ddepth, bool normalized)
{
    format.validate();
    const Mat src = detail::twoDimensional(_src, "addBlackLevel: src");
    checkMosaic(src, "addBlackLevel: src");
    if (src.type() != CV_32FC1)
        CV_Error(Error::StsBadArg,
                 cv::format("addBlackLevel: src type %s is not supported; expected CV_32FC1",
                            typeToString(src.type()).c_str()));
    if (ddepth != CV_16U && ddepth != CV_32F)
        CV_Error(Error::StsBadArg,
                 cv::format("addBlackLevel: ddepth %d is not supported; expected CV_16U or CV_32F", ddepth));
    Vec4d scale = Vec4d::all(1);
    if (normalized)
        for (int s = 0; s < 4; ++s)
            scale[s] = format.whiteLevel - format.blackLevel[s];
    Mat dst(src.size(), CV_MAKETYPE(ddepth, 1));
    if (ddepth == CV_16U)
        inverseAffinePerSite<ushort>(src, dst, format.blackLevel, scale, format.whiteLevel);
    else
        inverseAffinePerSite<float>(src, dst, format.blackLevel, scale, format.whiteLevel);
    _dst.assign(dst);
}

} // namespace rawgment
} // namespace cv
