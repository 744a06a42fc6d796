// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <opencv2/rawgment/bayer.hpp>

namespace cv {
namespace rawgment {
namespace {

const CfaPattern kAllPatterns[] = {CFA_RGGB, CFA_BGGR, CFA_GRBG, CFA_GBRG};

TEST(Bayer, siteIndexFollowsRowAndColumnParity)
{
    EXPECT_EQ(cfaSite(0, 0), 0);
    EXPECT_EQ(cfaSite(0, 1), 1);
    EXPECT_EQ(cfaSite(1, 0), 2);
    EXPECT_EQ(cfaSite(1, 1), 3);
    EXPECT_EQ(cfaSite(1000, 2001), 1);
    EXPECT_EQ(cfaSite(-1, -1), 3);
    EXPECT_EQ(cfaSite(-2, -3), 1);
}

TEST(Bayer, channelAtMatchesThePatternName)
{
    // Each pattern's name spells its top-left block; greens are G1 on the red row, G2 on the blue row.
    EXPECT_EQ(cfaChannelAt(CFA_RGGB, 0, 0), CFA_R);
    EXPECT_EQ(cfaChannelAt(CFA_RGGB, 0, 1), CFA_G1);
    EXPECT_EQ(cfaChannelAt(CFA_RGGB, 1, 0), CFA_G2);
    EXPECT_EQ(cfaChannelAt(CFA_RGGB, 1, 1), CFA_B);
    EXPECT_EQ(cfaChannelAt(CFA_BGGR, 0, 0), CFA_B);
    EXPECT_EQ(cfaChannelAt(CFA_BGGR, 0, 1), CFA_G2);
    EXPECT_EQ(cfaChannelAt(CFA_BGGR, 1, 1), CFA_R);
    EXPECT_EQ(cfaChannelAt(CFA_GRBG, 0, 0), CFA_G1);
    EXPECT_EQ(cfaChannelAt(CFA_GRBG, 0, 1), CFA_R);
    EXPECT_EQ(cfaChannelAt(CFA_GRBG, 1, 0), CFA_B);
    EXPECT_EQ(cfaChannelAt(CFA_GBRG, 0, 0), CFA_G2);
    EXPECT_EQ(cfaChannelAt(CFA_GBRG, 1, 0), CFA_R);
    EXPECT_EQ(cfaChannelAt(CFA_GBRG, 1, 1), CFA_G1);
    // Far from the origin the layout repeats with period 2.
    for (CfaPattern p : kAllPatterns)
        for (int r = 0; r < 2; ++r)
            for (int c = 0; c < 2; ++c)
                EXPECT_EQ(cfaChannelAt(p, r + 4000, c + 3002), cfaChannelAt(p, r, c));
}

TEST(Bayer, greenOfRedRowSharesTheRowWithRed)
{
    for (CfaPattern p : kAllPatterns) {
        const int sR = cfaSiteOfChannel(p, CFA_R), sG1 = cfaSiteOfChannel(p, CFA_G1);
        const int sG2 = cfaSiteOfChannel(p, CFA_G2), sB = cfaSiteOfChannel(p, CFA_B);
        EXPECT_EQ(sR / 2, sG1 / 2) << cfaPatternName(p);
        EXPECT_EQ(sB / 2, sG2 / 2) << cfaPatternName(p);
        EXPECT_NE(sR / 2, sB / 2) << cfaPatternName(p);
        EXPECT_NE(sR % 2, sB % 2) << cfaPatternName(p); // R and B lie on a diagonal
    }
}

TEST(Bayer, siteOfChannelInvertsChannelAt)
{
    for (CfaPattern p : kAllPatterns)
        for (int s = 0; s < 4; ++s)
            EXPECT_EQ(cfaSiteOfChannel(p, cfaChannelAt(p, s / 2, s % 2)), s);
}

TEST(Bayer, cropOffsetChangesPhase)
{
    EXPECT_EQ(cfaPatternOfCrop(CFA_RGGB, 0, 0), CFA_RGGB);
    EXPECT_EQ(cfaPatternOfCrop(CFA_RGGB, 0, 1), CFA_GRBG);
    EXPECT_EQ(cfaPatternOfCrop(CFA_RGGB, 1, 0), CFA_GBRG);
    EXPECT_EQ(cfaPatternOfCrop(CFA_RGGB, 1, 1), CFA_BGGR);
    EXPECT_EQ(cfaPatternOfCrop(CFA_BGGR, 1, 1), CFA_RGGB);
    EXPECT_EQ(cfaPatternOfCrop(CFA_GRBG, 0, 1), CFA_RGGB);
    // The defining property: the crop's (r, c) is the original's (r + dy, c + dx), for any offset.
    for (CfaPattern p : kAllPatterns)
        for (int dy = -3; dy <= 6; ++dy)
            for (int dx = -3; dx <= 6; ++dx) {
                const CfaPattern q = cfaPatternOfCrop(p, dy, dx);
                for (int r = 0; r < 2; ++r)
                    for (int c = 0; c < 2; ++c)
                        EXPECT_EQ(cfaChannelAt(q, r, c), cfaChannelAt(p, r + dy, c + dx));
            }
}

TEST(Bayer, patternNamesRoundTrip)
{
    for (CfaPattern p : kAllPatterns)
        EXPECT_EQ(cfaPatternFromName(cfaPatternName(p)), p);
    EXPECT_EQ(cfaPatternFromName("gbrg"), CFA_GBRG);
    EXPECT_CV_ERROR_CONTAINS(cfaPatternFromName("RGBG"), "expected one of RGGB, BGGR, GRBG, GBRG, MONO");
    EXPECT_CV_ERROR_CONTAINS(cfaPatternName(static_cast<CfaPattern>(7)), "CFA pattern 7");
    EXPECT_CV_ERROR_CONTAINS(cfaChannelAt(static_cast<CfaPattern>(-1), 0, 0), "CFA pattern -1");
    EXPECT_CV_ERROR_CONTAINS(cfaSiteOfChannel(CFA_RGGB, static_cast<CfaChannel>(5)), "CFA channel 5");
}

TEST(Bayer, monochromeIsAPatternWithOneChannelOnEverySite)
{
    EXPECT_EQ(cfaPatternFromName("mono"), CFA_MONO);
    EXPECT_EQ(cfaPatternName(CFA_MONO), "MONO");
    for (int r = -2; r < 3; ++r)
        for (int c = -2; c < 3; ++c) {
            EXPECT_EQ(cfaChannelAt(CFA_MONO, r, c), CFA_W);
            EXPECT_EQ(cfaPatternOfCrop(CFA_MONO, r, c), CFA_MONO);
        }
    EXPECT_EQ(cfaSiteOfChannel(CFA_MONO, CFA_W), 0);
    EXPECT_CV_ERROR_CONTAINS(cfaSiteOfChannel(CFA_MONO, CFA_R), "a monochrome frame has only CFA_W");
    EXPECT_CV_ERROR_CONTAINS(cfaSiteOfChannel(CFA_RGGB, CFA_W), "CFA_W is the channel of a monochrome frame");

    RawFormat f;
    f.pattern = CFA_MONO;
    f.blackLevel = Vec4d::all(100);
    f.whiteLevel = 4095;
    EXPECT_TRUE(f.isMonochrome());
    EXPECT_FALSE(RawFormat().isMonochrome());
    EXPECT_NO_THROW(f.validate());
    const RawFormat crop = f.cropped(1, 3);
    EXPECT_EQ(crop.pattern, CFA_MONO);
    EXPECT_EQ(crop.blackLevel, f.blackLevel);
    EXPECT_EQ(crop.sensorOrigin, Point(3, 1));
    FileStorage out("", FileStorage::WRITE | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
    f.write(out, "raw_format");
    const std::string text = out.releaseAndGetString();
    EXPECT_NE(text.find("MONO"), std::string::npos) << text;
    FileStorage in(text, FileStorage::READ | FileStorage::MEMORY);
    const RawFormat g = RawFormat::read(in["raw_format"]);
    EXPECT_EQ(g.pattern, CFA_MONO);
    EXPECT_EQ(g.blackLevel, f.blackLevel);
    // A sensor without a colour filter has no 2x2 structure to give four black levels.
    f.blackLevel[3] = 101;
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "one value on all four sites for a CFA_MONO format");
}

TEST(Bayer, packCfaPlanesOfAMonochromeFrameIsSpaceToDepthInSiteOrder)
{
    RawFormat format;
    format.pattern = CFA_MONO;
    format.blackLevel = Vec4d::all(64);
    format.whiteLevel = 1023;
    for (int type : {CV_16UC1, CV_32FC1}) {
        Mat frame(20, 30, type);
        randu(frame, 0, 1024);
        Mat signal, packed;
        std::vector<Mat> planes;
        subtractBlackLevel(frame, format, signal, true);
        splitCfaPlanes(signal, planes);
        packCfaPlanes(frame, format, packed, true);
        ASSERT_EQ(Size(15, 40), packed.size());
        for (int site = 0; site < 4; ++site)
            EXPECT_EQ(0, norm(packed.rowRange(10 * site, 10 * (site + 1)), planes[site], NORM_INF)) << site;
    }
}

RawFormat makeFormat(CfaPattern pattern = CFA_RGGB)
{
    RawFormat f;
    f.pattern = pattern;
    f.blackLevel = Vec4d(64, 65, 66, 67);
    f.whiteLevel = 1023;
    f.gain = 2.0;
    return f;
}

TEST(Bayer, rawFormatValidation)
{
    EXPECT_NO_THROW(makeFormat().validate());
    RawFormat f = makeFormat();
    f.gain = 0;
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "RawFormat.gain must be finite and > 0");
    f.gain = std::numeric_limits<double>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "RawFormat.gain");
    f = makeFormat();
    f.blackLevel[2] = -1;
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "RawFormat.blackLevel[2]");
    f = makeFormat();
    f.whiteLevel = 66;
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "above the black level");
    f.whiteLevel = std::numeric_limits<double>::infinity();
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "RawFormat.whiteLevel must be finite");
    f = makeFormat();
    f.pattern = static_cast<CfaPattern>(9);
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "CFA pattern 9");
}

TEST(Bayer, rawFormatCropMovesBlackLevelsWithThePhase)
{
    const RawFormat f = makeFormat(CFA_GBRG);
    for (int dy = 0; dy < 3; ++dy)
        for (int dx = 0; dx < 3; ++dx) {
            const RawFormat c = f.cropped(dy, dx);
            EXPECT_EQ(c.pattern, cfaPatternOfCrop(f.pattern, dy, dx));
            EXPECT_EQ(c.gain, f.gain);
            EXPECT_EQ(c.whiteLevel, f.whiteLevel);
            for (int r = 0; r < 2; ++r)
                for (int col = 0; col < 2; ++col)
                    EXPECT_EQ(c.blackAt(r, col), f.blackAt(r + dy, col + dx));
        }
}

TEST(Bayer, rawFormatFileStorageRoundTrip)
{
    for (const int format : {FileStorage::FORMAT_YAML, FileStorage::FORMAT_JSON}) {
        const char* ext = format == FileStorage::FORMAT_YAML ? "YAML" : "JSON";
        const RawFormat f = makeFormat(CFA_GRBG);
        FileStorage out("", FileStorage::WRITE | FileStorage::MEMORY | format);
        f.write(out, "raw_format");
        const std::string text = out.releaseAndGetString();
        FileStorage in(text, FileStorage::READ | FileStorage::MEMORY);
        const RawFormat g = RawFormat::read(in["raw_format"]);
        EXPECT_EQ(g.pattern, f.pattern) << ext;
        EXPECT_EQ(g.blackLevel, f.blackLevel) << ext;
        EXPECT_EQ(g.whiteLevel, f.whiteLevel) << ext;
        EXPECT_EQ(g.gain, f.gain) << ext;
    }
    FileStorage bad(
        "%YAML:1.0\nraw_format: {pattern: RGGB, black_level: [1, 2, 3], white_level: 10, gain: 1}",
        FileStorage::READ | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
    EXPECT_CV_ERROR_CONTAINS(RawFormat::read(bad["raw_format"]), "black_level");
    FileStorage noGain("%YAML:1.0\nraw_format: {pattern: RGGB, black_level: [1, 2, 3, 4], white_level: 10}",
                       FileStorage::READ | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
    EXPECT_CV_ERROR_CONTAINS(RawFormat::read(noGain["raw_format"]), "'gain' is missing");
}

/* The exposure time (#79 item 10): written only when stated, so a format without one keeps its bytes; kept by
 * a crop; a negative, NaN or boolean one is refused. */
TEST(Bayer, anExposureTimeIsWrittenOnlyWhenStatedAndRoundTrips)
{
    const auto text = [](const RawFormat& f) {
        FileStorage out("", FileStorage::WRITE | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
        f.write(out, "raw_format");
        return std::string(out.releaseAndGetString());
    };
    RawFormat f = makeFormat(CFA_GRBG);
    EXPECT_EQ(text(f).find("exposure_time"), std::string::npos);
    f.exposureTime = 1.0 / 60;
    const std::string stated = text(f);
    FileStorage in(stated, FileStorage::READ | FileStorage::MEMORY);
    EXPECT_EQ(RawFormat::read(in["raw_format"]).exposureTime, 1.0 / 60);
    EXPECT_EQ(f.cropped(1, 1).exposureTime, 1.0 / 60);
    f.exposureTime = -1;
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "RawFormat.exposureTime must be finite and >= 0");
    f.exposureTime = std::nan("");
    EXPECT_CV_ERROR_CONTAINS(f.validate(), "RawFormat.exposureTime");
    FileStorage boolean("%YAML:1.0\nraw_format: {pattern: RGGB, black_level: [1, 2, 3, 4], white_level: 10, "
                        "gain: 1, exposure_time: true}",
                        FileStorage::READ | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
    EXPECT_CV_ERROR_CONTAINS(RawFormat::read(boolean["raw_format"]), "exposure_time");
}

TEST(Bayer, aCropsSensorOriginAccumulatesAndRoundTrips)
{
    const RawFormat whole = makeFormat(CFA_GRBG);
    EXPECT_EQ(Point(0, 0), whole.sensorOrigin);
    const RawFormat crop = whole.cropped(3, 10).cropped(2, 4);
    EXPECT_EQ(Point(14, 5), crop.sensorOrigin);
    EXPECT_EQ(whole.cropped(5, 14).pattern, crop.pattern);
    for (const int format : {FileStorage::FORMAT_YAML, FileStorage::FORMAT_JSON}) {
        FileStorage out("", FileStorage::WRITE | FileStorage::MEMORY | format);
        crop.write(out, "raw_format");
        whole.write(out, "whole");
        const std::string text = out.releaseAndGetString();
        FileStorage in(text, FileStorage::READ | FileStorage::MEMORY);
        EXPECT_EQ(Point(14, 5), RawFormat::read(in["raw_format"]).sensorOrigin);
        // A whole frame's format is written as before, so older readers keep reading it.
        EXPECT_TRUE(in["whole"]["sensor_origin"].empty());
    }
    for (const char* origin : {"[-2, 0]", "[1.5, 0]", "[3]"}) {
        FileStorage bad(std::string("%YAML:1.0\nraw_format: {pattern: RGGB, black_level: [1, 2, 3, 4], "
                                    "white_level: 10, gain: 1, sensor_origin: ") +
                            origin + "}",
                        FileStorage::READ | FileStorage::MEMORY | FileStorage::FORMAT_YAML);
        EXPECT_CV_ERROR_CONTAINS(RawFormat::read(bad["raw_format"]), "sensor_origin");
    }
}

class BayerPlanes : public ::testing::TestWithParam<int>
{
};

TEST_P(BayerPlanes, splitPlacesEverySiteInItsPlaneAndMergeInvertsIt)
{
    const int type = GetParam();
    for (const Size size : {Size(2, 2), Size(4, 6), Size(130, 66)}) {
        Mat mosaic(size, type);
        randu(mosaic, 0, 250);
        std::vector<Mat> planes;
        splitCfaPlanes(mosaic, planes);
        ASSERT_EQ(planes.size(), 4u);
        for (int s = 0; s < 4; ++s) {
            ASSERT_EQ(planes[s].size(), Size(size.width / 2, size.height / 2));
            ASSERT_EQ(planes[s].type(), type);
        }
        for (int r = 0; r < size.height; ++r)
            for (int c = 0; c < size.width; ++c) {
                const Mat& p = planes[cfaSite(r, c)];
                ASSERT_EQ(0, std::memcmp(p.ptr(r / 2, c / 2), mosaic.ptr(r, c), mosaic.elemSize()));
            }
        Mat back;
        mergeCfaPlanes(planes, back);
        ASSERT_EQ(back.type(), type);
        EXPECT_EQ(0, norm(back, mosaic, NORM_INF));
    }
}

INSTANTIATE_TEST_CASE_P(AllDepths, BayerPlanes, ::testing::Values(CV_8UC1, CV_16UC1, CV_32FC1, CV_64FC1));

/* packCfaPlanes is subtractBlackLevel then splitCfaPlanes in R, G1, G2, B order, to the bit, for every
 * pattern, both input types and both scales; into a Mat over the caller's memory it writes in place. */
TEST(Bayer, packCfaPlanesIsBlackSubtractionAndSplitInOnePass)
{
    const CfaPattern patterns[] = {CFA_RGGB, CFA_GRBG, CFA_GBRG, CFA_BGGR};
    RawFormat format;
    format.blackLevel = Vec4d(60, 64.5, 63, 61);
    format.whiteLevel = 4095;
    for (int type : {CV_16UC1, CV_32FC1})
        for (CfaPattern pattern : patterns)
            for (bool normalize : {false, true}) {
                SCOPED_TRACE(cv::format("type %d, pattern %s, normalize %d", type,
                                        cfaPatternName(pattern).c_str(), int(normalize)));
                format.pattern = pattern;
                Mat mosaic(34, 50, type);
                randu(mosaic, 0, 4096);
                Mat signal, packed;
                std::vector<Mat> planes;
                subtractBlackLevel(mosaic, format, signal, normalize);
                splitCfaPlanes(signal, planes);
                packCfaPlanes(mosaic, format, packed, normalize);
                ASSERT_EQ(Size(25, 68), packed.size());
                ASSERT_EQ(CV_32FC1, packed.type());
                const CfaChannel order[4] = {CFA_R, CFA_G1, CFA_G2, CFA_B};
                for (int k = 0; k < 4; ++k)
                    EXPECT_EQ(0, norm(packed.rowRange(17 * k, 17 * (k + 1)),
                                      planes[cfaSiteOfChannel(pattern, order[k])], NORM_INF))
                        << "plane " << k;
                std::vector<float> memory(68 * 25, -1.f);
                Mat inPlace(68, 25, CV_32FC1, memory.data());
                packCfaPlanes(mosaic, format, inPlace, normalize);
                EXPECT_EQ(static_cast<void*>(memory.data()), static_cast<void*>(inPlace.data));
                EXPECT_EQ(0, norm(inPlace, packed, NORM_INF));
            }
    Mat out;
    EXPECT_CV_ERROR_CONTAINS(packCfaPlanes(Mat(5, 4, CV_16UC1, Scalar(1)), format, out), "must be even");
    EXPECT_CV_ERROR_CONTAINS(packCfaPlanes(Mat(4, 4, CV_8UC1, Scalar(1)), format, out), "not supported");
}

TEST(Bayer, splitRejectsBadMosaics)
{
    std::vector<Mat> planes;
    EXPECT_CV_ERROR_CONTAINS(splitCfaPlanes(Mat(), planes), "mosaic is empty");
    EXPECT_CV_ERROR_CONTAINS(splitCfaPlanes(Mat(4, 4, CV_16UC3), planes), "has 3 channels");
    EXPECT_CV_ERROR_CONTAINS(splitCfaPlanes(Mat(5, 4, CV_16UC1), planes), "both sides must be even");
    EXPECT_CV_ERROR_CONTAINS(splitCfaPlanes(Mat(4, 3, CV_16UC1), planes), "both sides must be even");
    EXPECT_CV_ERROR_CONTAINS(splitCfaPlanes(Mat(1, 1, CV_16UC1), planes), "both sides must be even");
    Mat out;
    EXPECT_CV_ERROR_CONTAINS(mergeCfaPlanes(std::vector<Mat>(3, Mat(2, 2, CV_16UC1)), out), "got 3 planes");
    std::vector<Mat> mixed(4, Mat(2, 2, CV_16UC1));
    mixed[3] = Mat(2, 2, CV_32FC1);
    EXPECT_CV_ERROR_CONTAINS(mergeCfaPlanes(mixed, out), "plane 3");
    mixed[3] = Mat(2, 3, CV_16UC1);
    EXPECT_CV_ERROR_CONTAINS(mergeCfaPlanes(mixed, out), "plane 3");
}

TEST(Bayer, subtractBlackLevelPerSiteAndBackIsExact)
{
    for (CfaPattern p : kAllPatterns) {
        const RawFormat f = makeFormat(p);
        Mat raw(6, 8, CV_16UC1);
        randu(raw, 0, 1024);
        raw.at<ushort>(0, 0) = 0;    // below black: must stay negative, not clip
        raw.at<ushort>(1, 1) = 1023; // at white
        Mat x;
        subtractBlackLevel(raw, f, x);
        ASSERT_EQ(x.type(), CV_32FC1);
        for (int r = 0; r < raw.rows; ++r)
            for (int c = 0; c < raw.cols; ++c)
                ASSERT_EQ(x.at<float>(r, c), raw.at<ushort>(r, c) - f.blackAt(r, c));
        EXPECT_EQ(x.at<float>(0, 0), -64.f);
        Mat back;
        addBlackLevel(x, f, back, CV_16U);
        EXPECT_EQ(0, norm(back, raw, NORM_INF)) << cfaPatternName(p);

        Mat n;
        subtractBlackLevel(raw, f, n, true);
        // The white level maps to 1 at every site (float rounding: a few ulps).
        EXPECT_NEAR(n.at<float>(1, 1), 1.f, 1e-6f);
        addBlackLevel(n, f, back, CV_16U, true);
        EXPECT_EQ(0, norm(back, raw, NORM_INF)) << cfaPatternName(p);
    }
}

TEST(Bayer, addBlackLevelRoundsAndClipsToTheValidRange)
{
    RawFormat f = makeFormat();
    Mat x = (Mat_<float>(2, 4) << -1000.f, 0.4f, 0.6f, 5000.f, std::numeric_limits<float>::quiet_NaN(), -0.5f,
             1e30f, 958.f);
    Mat out;
    addBlackLevel(x, f, out, CV_16U);
    EXPECT_EQ(out.at<ushort>(0, 0), 0);    // far below black clips at 0, not wraps
    EXPECT_EQ(out.at<ushort>(0, 1), 65);   // 65 + 0.4 rounds down (site 1 black 65)
    EXPECT_EQ(out.at<ushort>(0, 2), 65);   // 64 + 0.6 rounds up (site 0 black 64)
    EXPECT_EQ(out.at<ushort>(0, 3), 1023); // clipped at white
    EXPECT_EQ(out.at<ushort>(1, 0), 0);    // NaN never leaks into a mosaic
    EXPECT_EQ(out.at<ushort>(1, 1), 66);   // 67 - 0.5: ties round to even, like cvRound
    EXPECT_EQ(out.at<ushort>(1, 2), 1023);
    EXPECT_EQ(out.at<ushort>(1, 3), 1023); // 67 + 958 = 1025 > white
    Mat fl;
    addBlackLevel(x, f, fl, CV_32F);
    EXPECT_EQ(fl.at<float>(0, 1), 65.4f);
    EXPECT_EQ(fl.at<float>(1, 0), 0.f);
    EXPECT_EQ(test::countNonFinite(fl), 0);
}

TEST(Bayer, blackLevelRejectsBadInput)
{
    const RawFormat f = makeFormat();
    Mat out;
    EXPECT_CV_ERROR_CONTAINS(subtractBlackLevel(Mat(), f, out), "src is empty");
    EXPECT_CV_ERROR_CONTAINS(subtractBlackLevel(Mat(2, 2, CV_8UC1), f, out), "expected CV_16UC1 or CV_32FC1");
    EXPECT_CV_ERROR_CONTAINS(subtractBlackLevel(Mat(2, 2, CV_16UC2), f, out), "has 2 channels");
    EXPECT_CV_ERROR_CONTAINS(addBlackLevel(Mat(2, 2, CV_16UC1), f, out), "expected CV_32FC1");
    EXPECT_CV_ERROR_CONTAINS(addBlackLevel(Mat(2, 2, CV_32FC1), f, out, CV_8U), "expected CV_16U or CV_32F");
    RawFormat bad = f;
    bad.gain = -1;
    EXPECT_CV_ERROR_CONTAINS(subtractBlackLevel(Mat(2, 2, CV_16UC1), bad, out), "RawFormat.gain");
}

TEST(Bayer, blackLevelOnOddAndTinyMosaicsFollowsTheSite)
{
    const RawFormat f = makeFormat(CFA_BGGR);
    for (const Size size : {Size(1, 1), Size(2, 2), Size(3, 5)}) {
        Mat raw(size, CV_16UC1, Scalar(500));
        Mat x;
        subtractBlackLevel(raw, f, x);
        for (int r = 0; r < size.height; ++r)
            for (int c = 0; c < size.width; ++c)
                EXPECT_EQ(x.at<float>(r, c), 500 - f.blackAt(r, c));
    }
}

TEST(Bayer, subtractBlackLevelInPlaceKeepsSourceSemantics)
{
    const RawFormat f = makeFormat();
    Mat a(4, 4, CV_32FC1, Scalar(100.f));
    subtractBlackLevel(a, f, a);
    EXPECT_EQ(a.at<float>(0, 0), 36.f);
    EXPECT_EQ(a.at<float>(1, 1), 33.f);
}

TEST(Bayer, rawFormatRejectsAMisspelledKey)
{
    FileStorage fs("%YAML:1.0\nf: {pattern: RGGB, black_level: [0, 0, 0, 0], white_level: 1023, gain: 1, "
                   "white: 4095}\n",
                   FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(RawFormat::read(fs["f"]), "raw format: unknown key 'white'");
}

} // namespace
} // namespace rawgment
} // namespace cv
