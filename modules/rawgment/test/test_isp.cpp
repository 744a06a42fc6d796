// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <opencv2/rawgment/isp.hpp>

namespace cv {
namespace rawgment {
namespace {

using test::makeTempDir;

TEST(Isp, simpleGammaIsThePapersPowerCurve)
{
    const ToneCurve c = ToneCurve::simpleGamma();
    EXPECT_EQ(5.0, c.gamma);
    EXPECT_EQ(0.0, c.offset());
    for (double x : {0.0, 1e-6, 0.01, 0.5, 1.0})
        EXPECT_NEAR(std::pow(x, 0.2), c(x), 1e-15) << x;
    EXPECT_EQ(0.0, c(-0.5)) << "values below black are clipped";
    EXPECT_EQ(1.0, c(3.0)) << "values above white are clipped";
}

TEST(Isp, srgbParametersGiveTheStandardOffsetAndAContinuousCurve)
{
    const ToneCurve c = ToneCurve::srgb();
    // The standard's 0.055 is itself rounded; the derived offset agrees to the standard's precision.
    EXPECT_NEAR(0.055, c.offset(), 1e-4);
    const double x0 = c.breakPoint;
    const double below = c.toeSlope * x0;
    const double above = (1 + c.offset()) * std::pow(x0, 1 / c.gamma) - c.offset();
    EXPECT_NEAR(below, above, 1e-12) << "the pieces meet at the break point by construction";
    EXPECT_NEAR(1.0, c(1.0), 1e-12);
    double previous = -1;
    for (int i = 0; i <= 10000; ++i) {
        const double y = c(i / 10000.0);
        EXPECT_GE(y, previous) << "increasing at x = " << i / 10000.0;
        previous = y;
    }
}

TEST(Isp, toneCurveRejectsParametersThatDoNotMakeAnIncreasingCurve)
{
    EXPECT_CV_ERROR_CONTAINS(ToneCurve::simpleGamma(0), "gamma");
    EXPECT_CV_ERROR_CONTAINS(ToneCurve::simpleGamma(std::nan("")), "gamma");
    EXPECT_CV_ERROR_CONTAINS(ToneCurve::parametric(2.2, 1.0, 1.0), "breakPoint");
    EXPECT_CV_ERROR_CONTAINS(ToneCurve::parametric(2.2, 0.1, -1.0), "toeSlope");
    // A toe steep enough that the power part would have to start below -1.
    EXPECT_CV_ERROR_CONTAINS(ToneCurve::parametric(2.2, 0.5, 100.0), "1 + a > 0");
}

TEST(Isp, toneCurveRoundTripsThroughYaml)
{
    const std::string dir = makeTempDir("isp_tone");
    const ToneCurve c = ToneCurve::parametric(2.2, 0.018, 4.5);
    {
        cv::FileStorage fs(dir + "/t.yml", cv::FileStorage::WRITE);
        c.write(fs, "tone");
    }
    cv::FileStorage fs(dir + "/t.yml", cv::FileStorage::READ);
    const ToneCurve r = ToneCurve::read(fs["tone"]);
    EXPECT_EQ(c.gamma, r.gamma);
    EXPECT_EQ(c.breakPoint, r.breakPoint);
    EXPECT_EQ(c.toeSlope, r.toeSlope);
}

TEST(Isp, applyToneCurveMatchesTheScalarCurveForEveryDepth)
{
    const ToneCurve c = ToneCurve::srgb();
    cv::Mat x(1, 7, CV_32FC1);
    const float values[] = {-1.f, 0.f, 0.001f, 0.0031308f, 0.2f, 0.9f, 2.f};
    for (int i = 0; i < 7; ++i)
        x.at<float>(i) = values[i];
    cv::Mat y32, y8, y64;
    applyToneCurve(x, y32, c);
    applyToneCurve(x, y8, c, CV_8U);
    cv::Mat x64;
    x.convertTo(x64, CV_64F);
    applyToneCurve(x64, y64, c);
    ASSERT_EQ(CV_32FC1, y32.type());
    ASSERT_EQ(CV_8UC1, y8.type());
    ASSERT_EQ(CV_64FC1, y64.type());
    for (int i = 0; i < 7; ++i) {
        const double expected = c(double(values[i]));
        EXPECT_NEAR(expected, y32.at<float>(i), 1e-6);
        EXPECT_NEAR(expected, y64.at<double>(i), 1e-6) << "float input is the limit of precision";
        EXPECT_EQ(cvRound(expected * 255), y8.at<uchar>(i));
    }
    EXPECT_CV_ERROR_CONTAINS(applyToneCurve(cv::Mat(2, 2, CV_16UC1), y32, c), "not supported");
    EXPECT_CV_ERROR_CONTAINS(applyToneCurve(cv::Mat(), y32, c), "empty");
}

//! A mosaic in which every R pixel reads r, every green g and every blue b (signal above black).
cv::Mat uniformColourMosaic(const RawFormat& f, cv::Size size, double r, double g, double b, int type)
{
    cv::Mat m(size, type);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const CfaChannel ch = cfaChannelAt(f.pattern, y, x);
            const double v = (ch == CFA_R ? r : ch == CFA_B ? b : g) + f.blackAt(y, x);
            if (type == CV_16UC1)
                m.at<ushort>(y, x) = cv::saturate_cast<ushort>(v);
            else
                m.at<float>(y, x) = static_cast<float>(v);
        }
    return m;
}

class IspPattern : public ::testing::TestWithParam<CfaPattern>
{
};

TEST_P(IspPattern, everyDemosaicMethodPutsEachColourInItsBgrChannel)
{
    RawFormat f;
    f.pattern = GetParam();
    f.blackLevel = cv::Vec4d(64, 60, 62, 66);
    f.whiteLevel = 4095;
    const double r = 3000, g = 1200, b = 300;
    for (int type : {CV_16UC1, CV_32FC1})
        for (DemosaicMethod method : {DEMOSAIC_BILINEAR, DEMOSAIC_EDGE_AWARE, DEMOSAIC_HALF_SIZE}) {
            IspParams p;
            p.demosaic = method;
            p.tone = ToneCurve::simpleGamma(2.0);
            cv::Mat bgr;
            renderSimpleIsp(uniformColourMosaic(f, cv::Size(16, 12), r, g, b, type), f, bgr, p);
            ASSERT_EQ(CV_8UC3, bgr.type());
            const cv::Size expectedSize = method == DEMOSAIC_HALF_SIZE ? cv::Size(8, 6) : cv::Size(16, 12);
            ASSERT_EQ(expectedSize, bgr.size());
            // Away from the border every interpolation of a uniform plane is that plane's value; the
            // black level differs per site, so this also checks that each site's own black is used.
            const cv::Vec3b px = bgr.at<cv::Vec3b>(bgr.rows / 2, bgr.cols / 2);
            const double range = f.whiteLevel;
            const auto expected = [&](double signal, int site) {
                return cvRound(255 * std::sqrt(signal / (range - f.blackLevel[site])));
            };
            const int sr = cfaSiteOfChannel(f.pattern, CFA_R), sb = cfaSiteOfChannel(f.pattern, CFA_B);
            const int sg = cfaSiteOfChannel(f.pattern, CFA_G1);
            SCOPED_TRACE(cv::format("%s type %d method %d", cfaPatternName(f.pattern).c_str(), type, method));
            EXPECT_NEAR(expected(r, sr), px[2], 1);
            EXPECT_NEAR(expected(g, sg), px[1], 1);
            EXPECT_NEAR(expected(b, sb), px[0], 1);
        }
}

INSTANTIATE_TEST_CASE_P(AllPatterns, IspPattern, ::testing::Values(CFA_RGGB, CFA_BGGR, CFA_GRBG, CFA_GBRG));

TEST(Isp, whiteBalanceExposureAndColourMatrixActOnTheLinearSignal)
{
    RawFormat f;
    f.whiteLevel = 65535;
    const cv::Mat m = uniformColourMosaic(f, cv::Size(8, 8), 8000, 4000, 2000, CV_16UC1);
    IspParams p;
    p.outputDepth = CV_32F;
    p.tone = ToneCurve::simpleGamma(1.0);
    p.demosaic = DEMOSAIC_HALF_SIZE;
    cv::Mat base, balanced, swapped;
    renderSimpleIsp(m, f, base, p);
    ASSERT_EQ(CV_32FC3, base.type());
    p.whiteBalance = cv::Vec3d(0.5, 1.0, 2.0);
    p.exposure = 2.0;
    renderSimpleIsp(m, f, balanced, p);
    p.whiteBalance = cv::Vec3d(1, 1, 1);
    p.exposure = 1.0;
    p.colorMatrix = cv::Matx33d(0, 0, 1, 0, 1, 0, 1, 0, 0);
    renderSimpleIsp(m, f, swapped, p);
    const cv::Vec3f b0 = base.at<cv::Vec3f>(1, 1), b1 = balanced.at<cv::Vec3f>(1, 1),
                    sw = swapped.at<cv::Vec3f>(1, 1);
    // 16-bit quantisation of the linear signal: half a step, 1/131070.
    const double q = 1.0 / 65535;
    EXPECT_NEAR(8000.0 / 65535, b0[2], q);
    EXPECT_NEAR(b0[2] * 1.0, b1[2], 2 * q) << "R: 0.5 white balance x 2 exposure";
    EXPECT_NEAR(b0[1] * 2.0, b1[1], 2 * q);
    EXPECT_NEAR(b0[0] * 4.0, b1[0], 2 * q);
    EXPECT_NEAR(b0[0], sw[2], q) << "the matrix swapping R and B in RGB space";
    EXPECT_NEAR(b0[2], sw[0], q);
}

// A monochrome frame has no colour to balance, interpolate or mix: its grey fills the three channels.
TEST(Isp, aMonochromeFrameIsGreyWhateverTheColourSettings)
{
    RawFormat f;
    f.pattern = CFA_MONO;
    f.blackLevel = cv::Vec4d::all(100);
    f.whiteLevel = 4095;
    cv::Mat m(8, 12, CV_16UC1);
    for (int r = 0; r < m.rows; ++r)
        for (int c = 0; c < m.cols; ++c)
            m.at<ushort>(r, c) = static_cast<ushort>(500 + 100 * r + 10 * c);
    IspParams p;
    p.outputDepth = CV_32F;
    p.tone = ToneCurve::simpleGamma(1.0);
    p.whiteBalance = cv::Vec3d(2.0, 1.0, 0.5);
    p.colorMatrix = cv::Matx33d(0, 0, 1, 0, 1, 0, 1, 0, 0);
    p.exposure = 1.5;
    // The linear signal is quantised to 16-bit codes (half a step), and at half size their 2x2 average is
    // rounded again (half a step): one step, and a little for float32 output.
    const double q = 1.001 / 65535;
    for (DemosaicMethod method : {DEMOSAIC_BILINEAR, DEMOSAIC_EDGE_AWARE, DEMOSAIC_HALF_SIZE}) {
        p.demosaic = method;
        cv::Mat bgr;
        renderSimpleIsp(m, f, bgr, p);
        const int k = method == DEMOSAIC_HALF_SIZE ? 2 : 1;
        ASSERT_EQ(bgr.size(), cv::Size(m.cols / k, m.rows / k));
        for (int r = 0; r < bgr.rows; ++r)
            for (int c = 0; c < bgr.cols; ++c) {
                double raw = 0;
                for (int dy = 0; dy < k; ++dy)
                    for (int dx = 0; dx < k; ++dx)
                        raw += m.at<ushort>(k * r + dy, k * c + dx) / double(k * k);
                const double want = 1.5 * (raw - 100) / (4095 - 100);
                const cv::Vec3f v = bgr.at<cv::Vec3f>(r, c);
                EXPECT_NEAR(v[0], want, q) << method << " at " << r << ", " << c;
                EXPECT_EQ(v[0], v[1]);
                EXPECT_EQ(v[1], v[2]);
            }
    }
}

TEST(Isp, clippingBelowBlackAboveWhiteAndNan)
{
    RawFormat f;
    f.blackLevel = cv::Vec4d::all(100);
    f.whiteLevel = 1000;
    cv::Mat m(4, 4, CV_32FC1, cv::Scalar(50));
    m.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
    m.at<float>(1, 1) = 5000;
    IspParams p;
    p.demosaic = DEMOSAIC_HALF_SIZE;
    cv::Mat bgr;
    renderSimpleIsp(m, f, bgr, p);
    // Block (0, 0): R is NaN (no signal), the greens are below black, B (site 3) is above white.
    EXPECT_EQ(cv::Vec3b(255, 0, 0), bgr.at<cv::Vec3b>(0, 0));
    EXPECT_EQ(cv::Vec3b(0, 0, 0), bgr.at<cv::Vec3b>(1, 1)) << "below black is clipped to 0";
}

TEST(Isp, badInputGivesClearErrors)
{
    RawFormat f;
    cv::Mat bgr;
    EXPECT_CV_ERROR_CONTAINS(renderSimpleIsp(cv::Mat(), f, bgr), "empty");
    EXPECT_CV_ERROR_CONTAINS(renderSimpleIsp(cv::Mat(4, 4, CV_8UC1), f, bgr), "not supported");
    EXPECT_CV_ERROR_CONTAINS(renderSimpleIsp(cv::Mat(5, 4, CV_16UC1), f, bgr), "even");
    IspParams p;
    p.whiteBalance = cv::Vec3d(1, 0, 1);
    EXPECT_CV_ERROR_CONTAINS(renderSimpleIsp(cv::Mat(4, 4, CV_16UC1), f, bgr, p), "whiteBalance");
    p = IspParams();
    p.outputDepth = CV_16U;
    EXPECT_CV_ERROR_CONTAINS(renderSimpleIsp(cv::Mat(4, 4, CV_16UC1), f, bgr, p), "outputDepth");
    p = IspParams();
    p.demosaic = static_cast<DemosaicMethod>(7);
    EXPECT_CV_ERROR_CONTAINS(renderSimpleIsp(cv::Mat(4, 4, CV_16UC1), f, bgr, p), "DemosaicMethod");
}

} // namespace
} // namespace rawgment
} // namespace cv
