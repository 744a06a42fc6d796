// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "precomp.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/isp.hpp>

#include <algorithm>
#include <vector>

namespace cv {
namespace rawgment {

ToneCurve ToneCurve::simpleGamma(double gamma)
{
    return parametric(gamma, 0.0, 0.0);
}

ToneCurve ToneCurve::parametric(double gamma, double breakPoint, double toeSlope)
{
    ToneCurve c;
    c.gamma = gamma;
    c.breakPoint = breakPoint;
    c.toeSlope = toeSlope;
    c.validate();
    return c;
}

ToneCurve ToneCurve::srgb()
{
    return parametric(2.4, 0.0031308, 12.92);
}

double ToneCurve::offset() const
{
    if (breakPoint <= 0)
        return 0.0;
    const double p = std::pow(breakPoint, 1.0 / gamma);
    return (toeSlope * breakPoint - p) / (p - 1.0);
}

double ToneCurve::operator()(double x) const
{
    x = std::min(std::max(x, 0.0), 1.0);
    if (x < breakPoint)
        return toeSlope * x;
    const double a = offset();
    return (1.0 + a) * std::pow(x, 1.0 / gamma) - a;
}

void ToneCurve::validate() const
{
    detail::checkFinitePositive(gamma, "ToneCurve: gamma");
    if (!(breakPoint >= 0 && breakPoint < 1))
        CV_Error(Error::StsBadArg, format("ToneCurve: breakPoint must be in [0, 1) (got %g)", breakPoint));
    detail::checkFiniteNonNegative(toeSlope, "ToneCurve: toeSlope");
    const double a = offset();
    if (!(1.0 + a > 0) || !std::isfinite(a))
        CV_Error(Error::StsBadArg,
                 format("ToneCurve: (gamma %g, breakPoint %g, toeSlope %g) give offset a = %g; the curve "
                        "is increasing only when 1 + a > 0 (lower toeSlope or breakPoint)",
                        gamma, breakPoint, toeSlope, a));
}

void ToneCurve::write(FileStorage& fs, const String& name) const
{
    validate();
    fs << name << "{"
       << "gamma" << gamma << "break_point" << breakPoint << "toe_slope" << toeSlope << "}";
}

ToneCurve ToneCurve::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "tone curve: expected a map with gamma, break_point, toe_slope");
    ToneCurve c;
    try {
        rejectUnknownKeys(node, {"gamma", "break_point", "toe_slope"});
        c.gamma = detail::readRealField(node, "gamma");
        c.breakPoint = detail::readOptionalRealField(node, "break_point", 0.0);
        c.toeSlope = detail::readOptionalRealField(node, "toe_slope", 0.0);
    } catch (const Exception& e) {
        CV_Error(e.code, "tone curve: " + e.err);
    }
    c.validate();
    return c;
}

void IspParams::validate() const
{
    tone.validate();
    for (int c = 0; c < 3; ++c)
        detail::checkFinitePositive(whiteBalance[c], "IspParams: whiteBalance");
    for (int i = 0; i < 9; ++i)
        if (!std::isfinite(colorMatrix.val[i]))
            CV_Error(Error::StsBadArg, "IspParams: colorMatrix has a non-finite entry");
    detail::checkFinitePositive(exposure, "IspParams: exposure");
    if (demosaic != DEMOSAIC_BILINEAR && demosaic != DEMOSAIC_EDGE_AWARE && demosaic != DEMOSAIC_HALF_SIZE)
        CV_Error(Error::StsBadArg, format("IspParams: demosaic %d is not a DemosaicMethod", int(demosaic)));
    if (outputDepth != CV_8U && outputDepth != CV_32F)
        CV_Error(Error::StsBadArg,
                 format("IspParams: outputDepth %d is not supported; expected CV_8U or CV_32F", outputDepth));
}

namespace {

constexpr int kCodes = 65536;

//! The tone curve sampled at the 16-bit codes x = i / 65535, scaled to the output range.
template <typename T> std::vector<T> toneTable(const ToneCurve& curve, double scale)
{
    std::vector<T> table(kCodes);
    for (int i = 0; i < kCodes; ++i) {
        const double y = curve(i / double(kCodes - 1)) * scale;
        table[i] = std::is_integral<T>::value ? saturate_cast<T>(y) : static_cast<T>(y);
    }
    return table;
}

template <typename T> inline float toUnit(T v, float black, float scale)
{
    return (static_cast<float>(v) - black) * scale;
}

inline ushort toCode(float x)
{
    // NaN fails both comparisons and becomes 0, like a pixel below black.
    const float c = x > 0.f ? (x < 1.f ? x : 1.f) : 0.f;
    return static_cast<ushort>(c * 65535.f + 0.5f);
}

//! Black-normalised, white-balanced, clipped 16-bit codes of the mosaic.
template <typename T>
void normaliseMosaic(const Mat& src, const RawFormat& format, const Vec4f& siteGain, Mat& codes)
{
    Vec4f black, scale;
    for (int s = 0; s < 4; ++s) {
        black[s] = static_cast<float>(format.blackLevel[s]);
        scale[s] = siteGain[s] / static_cast<float>(format.whiteLevel - format.blackLevel[s]);
    }
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const T* in = src.ptr<T>(r);
            ushort* out = codes.ptr<ushort>(r);
            const int s0 = 2 * (r & 1);
            const float b0 = black[s0], b1 = black[s0 + 1], k0 = scale[s0], k1 = scale[s0 + 1];
            for (int c = 0; c + 1 < src.cols; c += 2) {
                out[c] = toCode(toUnit(in[c], b0, k0));
                out[c + 1] = toCode(toUnit(in[c + 1], b1, k1));
            }
        }
    });
}

int bayerToBgrCode(CfaPattern pattern, bool edgeAware)
{
    // OpenCV names a Bayer layout by the second and third pixels of its second row, so an RGGB mosaic
    // (second row G B G B) is "BayerBG".
    switch (pattern) {
    case CFA_RGGB:
        return edgeAware ? COLOR_BayerBG2BGR_EA : COLOR_BayerBG2BGR;
    case CFA_BGGR:
        return edgeAware ? COLOR_BayerRG2BGR_EA : COLOR_BayerRG2BGR;
    case CFA_GRBG:
        return edgeAware ? COLOR_BayerGB2BGR_EA : COLOR_BayerGB2BGR;
    case CFA_GBRG:
        return edgeAware ? COLOR_BayerGR2BGR_EA : COLOR_BayerGR2BGR;
    case CFA_MONO:
        break;
    }
    CV_Error(Error::StsBadArg, "renderSimpleIsp: invalid CFA pattern");
}

void halfSizeBgr(const Mat& codes, CfaPattern pattern, Mat& bgr)
{
    const int sr = cfaSiteOfChannel(pattern, CFA_R), sg1 = cfaSiteOfChannel(pattern, CFA_G1),
              sg2 = cfaSiteOfChannel(pattern, CFA_G2), sb = cfaSiteOfChannel(pattern, CFA_B);
    bgr.create(codes.rows / 2, codes.cols / 2, CV_16UC3);
    parallel_for_(Range(0, bgr.rows), [&](const Range& rows) {
        for (int i = rows.start; i < rows.end; ++i) {
            const ushort* rowPair[2] = {codes.ptr<ushort>(2 * i), codes.ptr<ushort>(2 * i + 1)};
            ushort* out = bgr.ptr<ushort>(i);
            for (int j = 0; j < bgr.cols; ++j) {
                const auto at = [&](int s) { return rowPair[s >> 1][2 * j + (s & 1)]; };
                out[3 * j + 0] = at(sb);
                out[3 * j + 1] = static_cast<ushort>((at(sg1) + at(sg2) + 1) >> 1);
                out[3 * j + 2] = at(sr);
            }
        }
    });
}

template <typename T>
void toneMapBgr(const Mat& bgr16, const Matx33d& rgbMatrix, const std::vector<T>& table, Mat& dst)
{
    const bool identity = rgbMatrix == Matx33d::eye();
    // The matrix acts on RGB; the pixels are BGR, so reverse both its rows and columns.
    Matx33f m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            m(2 - i, 2 - j) = static_cast<float>(rgbMatrix(i, j));
    parallel_for_(Range(0, bgr16.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const ushort* in = bgr16.ptr<ushort>(r);
            T* out = dst.ptr<T>(r);
            const int n = 3 * bgr16.cols;
            if (identity) {
                for (int k = 0; k < n; ++k)
                    out[k] = table[in[k]];
                continue;
            }
            for (int k = 0; k < n; k += 3) {
                const float b = in[k], g = in[k + 1], rr = in[k + 2];
                for (int c = 0; c < 3; ++c) {
                    const float v = (m(c, 0) * b + m(c, 1) * g + m(c, 2) * rr) * (1.f / 65535.f);
                    out[k + c] = table[toCode(v)];
                }
            }
        }
    });
}

} // namespace

void applyToneCurve(InputArray _linear, OutputArray _dst, const ToneCurve& curve, int ddepth)
{
    curve.validate();
    const Mat linear = detail::twoDimensional(_linear, "applyToneCurve: linear");
    if (linear.empty())
        CV_Error(Error::StsBadArg, "applyToneCurve: linear is empty");
    if (linear.depth() != CV_32F && linear.depth() != CV_64F)
        CV_Error(Error::StsBadArg,
                 format("applyToneCurve: linear type %s is not supported; expected CV_32F or "
                        "CV_64F with any channels",
                        typeToString(linear.type()).c_str()));
    if (ddepth < 0)
        ddepth = linear.depth();
    if (ddepth != CV_8U && ddepth != CV_32F && ddepth != CV_64F)
        CV_Error(
            Error::StsBadArg,
            format("applyToneCurve: ddepth %d is not supported; expected CV_8U, CV_32F or CV_64F", ddepth));
    Mat src64;
    linear.convertTo(src64, CV_64F);
    Mat dst64(src64.size(), src64.type());
    const double a = curve.offset(), invGamma = 1.0 / curve.gamma;
    parallel_for_(Range(0, src64.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            const double* in = src64.ptr<double>(r);
            double* out = dst64.ptr<double>(r);
            for (int k = 0; k < src64.cols * src64.channels(); ++k) {
                const double x = in[k] > 0 ? (in[k] < 1 ? in[k] : 1.0) : 0.0;
                out[k] = x < curve.breakPoint ? curve.toeSlope * x : (1 + a) * std::pow(x, invGamma) - a;
            }
        }
    });
    dst64.convertTo(_dst, CV_MAKETYPE(ddepth, linear.channels()), ddepth == CV_8U ? 255.0 : 1.0);
}

void renderSimpleIsp(InputArray _mosaic, const RawFormat& format, OutputArray _bgr, const IspParams& params)
{
    format.validate();
    params.validate();
    const Mat mosaic = detail::twoDimensional(_mosaic, "renderSimpleIsp: mosaic");
    if (mosaic.empty())
        CV_Error(Error::StsBadArg, "renderSimpleIsp: mosaic is empty");
    if (mosaic.type() != CV_16UC1 && mosaic.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, cv::format("renderSimpleIsp: mosaic type %s is not supported; expected "
                                              "CV_16UC1 or CV_32FC1",
                                              typeToString(mosaic.type()).c_str()));
    if (mosaic.rows % 2 || mosaic.cols % 2 || mosaic.rows < 2 || mosaic.cols < 2)
        CV_Error(Error::StsBadArg, cv::format("renderSimpleIsp: mosaic is %dx%d; both sides must be even and "
                                              "at least 2 (crop it by one row or column)",
                                              mosaic.cols, mosaic.rows));
    const bool mono = format.isMonochrome();
    Vec4f siteGain;
    for (int s = 0; s < 4; ++s) {
        const CfaChannel ch = cfaChannelAt(format.pattern, s / 2, s % 2);
        const int rgb = ch == CFA_R ? 0 : (ch == CFA_B ? 2 : 1);
        siteGain[s] = static_cast<float>((mono ? 1.0 : params.whiteBalance[rgb]) * params.exposure);
    }
    Mat codes(mosaic.size(), CV_16UC1);
    if (mosaic.depth() == CV_16U)
        normaliseMosaic<ushort>(mosaic, format, siteGain, codes);
    else
        normaliseMosaic<float>(mosaic, format, siteGain, codes);

    Mat bgr16;
    if (mono) {
        Mat grey;
        if (params.demosaic == DEMOSAIC_HALF_SIZE)
            resize(codes, grey, Size(codes.cols / 2, codes.rows / 2), 0, 0, INTER_AREA);
        else
            grey = codes;
        cvtColor(grey, bgr16, COLOR_GRAY2BGR);
    } else if (params.demosaic == DEMOSAIC_HALF_SIZE) {
        halfSizeBgr(codes, format.pattern, bgr16);
    } else if (codes.rows < 4 || codes.cols < 4) {
        // OpenCV's Bayer conversions return black below 3 pixels on a side: each 2x2 block then gets its
        // own colour, at full size.
        Mat half;
        halfSizeBgr(codes, format.pattern, half);
        resize(half, bgr16, codes.size(), 0, 0, INTER_NEAREST);
    } else {
        cvtColor(codes, bgr16, bayerToBgrCode(format.pattern, params.demosaic == DEMOSAIC_EDGE_AWARE));
    }
    codes.release();

    Mat dst(bgr16.size(), CV_MAKETYPE(params.outputDepth, 3));
    const Matx33d colorMatrix = mono ? Matx33d::eye() : params.colorMatrix;
    if (params.outputDepth == CV_8U)
        toneMapBgr(bgr16, colorMatrix, toneTable<uchar>(params.tone, 255.0), dst);
    else
        toneMapBgr(bgr16, colorMatrix, toneTable<float>(params.tone, 1.0), dst);
    _bgr.assign(dst);
}

} // namespace rawgment
} // namespace cv
