// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include "../src/precomp.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <fstream>
#include <iterator>
#include <limits>
#include <sys/mount.h>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>
#include <vector>

namespace cv {
namespace rawgment {
namespace {

using test::makeTempDir;

using test::filesIn;
using test::readBytes;
using test::writeBytes;

TEST(RawIo, colorchartDngHasTheLevelsLibRawReports)
{
    RAWGMENT_DATA_FILE_OR_SKIP(path, "colorchart.dng");
    const RawImage img = readRaw(path);
    EXPECT_EQ(Size(1734, 1156), img.mosaic.size());
    EXPECT_EQ(CV_16UC1, img.mosaic.type());
    EXPECT_EQ(CFA_RGGB, img.format.pattern);
    EXPECT_EQ(Vec4d::all(2056), img.format.blackLevel);
    EXPECT_EQ(15000, img.format.whiteLevel);
    EXPECT_EQ(1.0, img.format.gain);
    EXPECT_EQ("Canon", img.make);
    EXPECT_EQ(0, img.iso) << "SOURCES.md: no ISO in the metadata";
    // A camera's as-shot white balance boosts red and blue relative to green under indoor light.
    EXPECT_GT(img.whiteBalance[0], 1.0);
    EXPECT_GT(img.whiteBalance[2], 1.0);
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(1.0, img.cameraToSrgb(i, 0) + img.cameraToSrgb(i, 1) + img.cameraToSrgb(i, 2), 1e-3)
            << "LibRaw normalises each row of rgb_cam to 1";
    double minVal, maxVal;
    minMaxLoc(img.mosaic, &minVal, &maxVal);
    EXPECT_GT(minVal, 1500) << "the data sits on a 2056 black level";
    EXPECT_LE(maxVal, 16383) << "14-bit data";
}

struct CameraFile
{
    const char* name;
    Size visible;
    CfaPattern pattern;
    double black;
    double white;
    double iso;
};

class RawIoCamera : public ::testing::TestWithParam<CameraFile>
{
};

TEST_P(RawIoCamera, readsVisibleAreaPatternAndLevels)
{
    const CameraFile& f = GetParam();
    RAWGMENT_DATA_FILE_OR_SKIP(path, f.name);
    const RawImage img = readRaw(path);
    EXPECT_EQ(f.visible, img.mosaic.size());
    EXPECT_EQ(cfaPatternName(f.pattern), cfaPatternName(img.format.pattern));
    EXPECT_EQ(Vec4d::all(f.black), img.format.blackLevel);
    EXPECT_EQ(f.white, img.format.whiteLevel);
    EXPECT_EQ(f.iso, img.iso);
}

// Values from ../shared/data/SOURCES.md (as LibRaw 0.20 reports them).
INSTANTIATE_TEST_CASE_P(
    SharedData, RawIoCamera,
    ::testing::Values(CameraFile{"RAW_NIKON_D1.NEF", Size(2012, 1324), CFA_BGGR, 0, 4095, 200},
                      CameraFile{"RAW_CANON_D30_SRGB.CRW", Size(2176, 1448), CFA_RGGB, 126, 4095, 100},
                      CameraFile{"RAW_KODAK_DC50.KDC", Size(768, 512), CFA_GRBG, 0, 16383, 84}));

TEST(RawIo, nikonExposureTimeIsRead)
{
    RAWGMENT_DATA_FILE_OR_SKIP(path, "RAW_NIKON_D1.NEF");
    EXPECT_NEAR(1.0 / 250, readRaw(path).exposureTime, 1e-6);
}

class RawIoDngPattern : public ::testing::TestWithParam<CfaPattern>
{
};

TEST_P(RawIoDngPattern, writtenDngReadsBackExactlyThroughLibRaw)
{
    const std::string dir = makeTempDir("raw_io_dng_" + cfaPatternName(GetParam()));
    RawImage img;
    img.mosaic.create(48, 64, CV_16UC1);
    randu(img.mosaic, 0, 4096);
    img.format.pattern = GetParam();
    img.format.blackLevel = Vec4d(100, 101, 102, 103);
    img.format.whiteLevel = 4000;
    img.iso = 400;
    img.exposureTime = 0.01;
    img.make = "Rawgment";
    img.model = "Simulated Sensor";
    img.whiteBalance = Vec3d(2.0, 1.0, 1.5);
    const std::string path = dir + "/" + cfaPatternName(GetParam()) + ".dng";
    writeDng(path, img);
    const RawImage back = readRaw(path);
    EXPECT_EQ(0, norm(img.mosaic, back.mosaic, NORM_INF));
    EXPECT_EQ(cfaPatternName(img.format.pattern), cfaPatternName(back.format.pattern));
    EXPECT_EQ(img.format.blackLevel, back.format.blackLevel) << "per-site blacks must follow the phase";
    EXPECT_EQ(img.format.whiteLevel, back.format.whiteLevel);
    EXPECT_EQ(img.iso, back.iso);
    EXPECT_NEAR(img.exposureTime, back.exposureTime, 1e-6);
    EXPECT_EQ(img.make, back.make);
    EXPECT_EQ(img.model, back.model);
    // AsShotNeutral holds 6 significant digits.
    EXPECT_NEAR(2.0, back.whiteBalance[0], 1e-4);
    EXPECT_NEAR(1.5, back.whiteBalance[2], 1e-4);
    // A file there of exactly these bytes is this write's output (an identical run got there first); any
    // other is never overwritten.
    EXPECT_NO_THROW(writeDng(path, img));
    RawImage other = img;
    other.iso += 1;
    EXPECT_CV_ERROR_CONTAINS(writeDng(path, other), "already exists");
    EXPECT_EQ(img.iso, readRaw(path).iso);
}

INSTANTIATE_TEST_CASE_P(AllPatterns, RawIoDngPattern,
                        ::testing::Values(CFA_RGGB, CFA_BGGR, CFA_GRBG, CFA_GBRG));

TEST(RawIo, writeDngRejectsWhatDngCannotHold)
{
    const std::string dir = makeTempDir("raw_io_dng_bad");
    RawImage img;
    img.mosaic = Mat(4, 4, CV_32FC1, Scalar(1));
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/a.dng", img), "CV_16UC1");
    img.mosaic = Mat(5, 4, CV_16UC1, Scalar(1));
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/a.dng", img), "even");
    img.mosaic = Mat(22, 22, CV_16UC1, Scalar(1));
    img.format.blackLevel = Vec4d(10.5, 10, 10, 10);
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/a.dng", img), "not an integer");
    img.format.blackLevel = Vec4d::all(10);
    // A white level of 4095.5 was written and read back as 4096: another sensor's clipping.
    img.format.whiteLevel = 4095.5;
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/a.dng", img), "white level 4095.5 is not an integer");
    img.format.whiteLevel = 4095;
    // LibRaw reads no RAW file under 22 pixels on a side: such a DNG would be written, then refused by
    // readRaw as "not RAW file".
    for (const Size size : {Size(2, 2), Size(16, 16), Size(20, 64), Size(64, 20)}) {
        img.mosaic = Mat(size, CV_16UC1, Scalar(1));
        EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/a.dng", img), "smaller than 22 pixels on a side");
    }
    // An ISO a DNG cannot state is refused, not clamped to 0 or 65535.
    img.mosaic = Mat(22, 22, CV_16UC1, Scalar(1));
    for (double iso :
         {std::numeric_limits<double>::quiet_NaN(), -1.0, std::numeric_limits<double>::infinity(), 5e9}) {
        img.iso = iso;
        EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/a.dng", img), "is not one a DNG can state");
    }
    EXPECT_TRUE(filesIn(dir).empty()) << "a refused write leaves nothing behind";
}

TEST(RawIo, anIsoBeyond16BitsIsWrittenAndReadExactly)
{
    // Augment multiplies ISO by the gain ratio, so real runs reach ISO 102400 and beyond; ISOSpeedRatings
    // holds 16 bits, EXIF 2.3's ISOSpeed 32. The smallest mosaic LibRaw reads is written and read back.
    const std::string dir = makeTempDir("raw_io_dng_iso");
    RawImage img;
    img.mosaic = Mat(22, 22, CV_16UC1, Scalar(100));
    img.format.whiteLevel = 4095;
    for (double iso : {100.0, 65534.0, 65535.0, 102400.0, 409600.0, 4294967295.0, 141.4}) {
        img.iso = iso;
        const std::string path = dir + format("/iso_%g.dng", iso);
        writeDng(path, img);
        const RawImage back = readRaw(path);
        EXPECT_EQ(std::round(iso), back.iso) << iso;
        EXPECT_EQ(Size(22, 22), back.mosaic.size());
    }
}

TEST(RawIo, dngNoiseProfileRoundTripsAndGivesBackTheModelsLines)
{
    const std::string dir = makeTempDir("raw_io_noise_profile");
    const NoiseModel model(0.3, 1.2, 2.5);
    RawImage img;
    img.mosaic = Mat(48, 64, CV_16UC1, Scalar(500)); // LibRaw refuses very small images
    img.format.pattern = CFA_GBRG;
    img.format.blackLevel = Vec4d(100, 101, 102, 103);
    img.format.whiteLevel = 4000;
    img.format.gain = 4;
    img.noiseProfile = dngNoiseProfile(model, img.format);
    ASSERT_EQ(img.noiseProfile.size(), 3u);
    // GBRG: blue is site 1 (black 101), red site 2 (102), green sites 0 and 3 (mean 101.5).
    EXPECT_DOUBLE_EQ(img.noiseProfile[0][0], 4 * 0.3 / (4000 - 102.0));
    EXPECT_DOUBLE_EQ(img.noiseProfile[1][1], (16 * 1.2 + 2.5) / ((4000 - 101.5) * (4000 - 101.5)));
    EXPECT_DOUBLE_EQ(img.noiseProfile[2][0], 4 * 0.3 / (4000 - 101.0));
    writeDng(dir + "/profiled.dng", img);
    const RawImage back = readRaw(dir + "/profiled.dng");
    ASSERT_EQ(back.noiseProfile.size(), 3u);
    for (int k = 0; k < 3; ++k)
        EXPECT_EQ(back.noiseProfile[k], img.noiseProfile[k]) << "doubles are stored bit for bit";
    // The line of each site at the mosaic's gain is the model's (4 alpha, 16 sigma_d^2 + sigma_r^2),
    // up to the rounding of one division and one multiplication.
    RawFormat atGain = back.format;
    atGain.gain = 4;
    const NoiseLine truth = model.lineAtGain(4);
    for (CfaChannel channel : {CFA_R, CFA_G1, CFA_G2, CFA_B}) {
        const NoiseLine line = noiseLineFromDngProfile(back.noiseProfile, atGain, channel);
        EXPECT_NEAR(line.a, truth.a, 1e-14 * truth.a) << channel;
        EXPECT_NEAR(line.b, truth.b, 1e-13 * truth.b) << channel;
    }
    const std::vector<Vec2d> single = {Vec2d(0.001, 2e-6)};
    EXPECT_DOUBLE_EQ(noiseLineFromDngProfile(single, atGain, CFA_B).a, 0.001 * (4000 - 101));
    // Finite S and O that DNG allows can still give an infinite line.
    EXPECT_CV_ERROR_CONTAINS(noiseLineFromDngProfile({Vec2d(1e308, 0)}, atGain, CFA_B),
                             "a noise profile must give a finite line");
    EXPECT_CV_ERROR_CONTAINS(noiseLineFromDngProfile({Vec2d(1e-3, 1e305)}, atGain, CFA_R), "b = inf");
    img.noiseProfile.clear();
    writeDng(dir + "/plain.dng", img);
    EXPECT_TRUE(readRaw(dir + "/plain.dng").noiseProfile.empty());
}

TEST(RawIo, aFilesOwnNoiseProfileBecomesAMeasuredLineAtItsGain)
{
    const std::string dir = makeTempDir("raw_io_noise_profile_line");
    // The file states the noise of another sensor than the model's (as a converter's database would).
    const NoiseModel stated(0.5, 2.0, 3.0), model = [] {
        NoiseModel m(0.3, 1.2, 2.5);
        m.baseIso = 100;
        return m;
    }();
    RawImage img;
    img.mosaic = Mat(48, 64, CV_16UC1, Scalar(500));
    img.format.pattern = CFA_GBRG;
    img.format.blackLevel = Vec4d(101, 101, 102, 102);
    img.format.whiteLevel = 4000;
    img.format.gain = 4;
    img.iso = 400;
    img.noiseProfile = dngNoiseProfile(stated, img.format);
    writeDng(dir + "/stated.dng", img);
    const RawImage back = readRaw(dir + "/stated.dng");
    const NoiseModel followed = withDngNoiseProfileLine(model, back);
    ASSERT_EQ(1u, followed.measuredLines.size());
    EXPECT_EQ(4.0, followed.measuredLines[0].gain);
    EXPECT_EQ(400.0, followed.measuredLines[0].iso);
    // At the file's gain the file's line (green's range, up to the rounding of S r and O r^2).
    EXPECT_NEAR(stated.lineAtGain(4).a, followed.lineAtGain(4).a, 1e-13 * stated.lineAtGain(4).a);
    EXPECT_NEAR(stated.lineAtGain(4).b, followed.lineAtGain(4).b, 1e-12 * stated.lineAtGain(4).b);
    EXPECT_GT(std::abs(followed.lineAtGain(4).a / model.lineAtGain(4).a - 1), 0.5);
    // A second file at the same ISO replaces the line, one at another ISO joins it in order.
    RawImage other = back;
    other.iso = 200;
    const NoiseModel two = withDngNoiseProfileLine(withDngNoiseProfileLine(followed, back), other);
    ASSERT_EQ(2u, two.measuredLines.size());
    EXPECT_EQ(2.0, two.measuredLines[0].gain);
    EXPECT_EQ(4.0, two.measuredLines[1].gain);
    RawImage noIso = back;
    noIso.iso = 0;
    EXPECT_CV_ERROR_CONTAINS(withDngNoiseProfileLine(model, noIso), "the file states no ISO");
    NoiseModel noBase = model;
    noBase.baseIso = 0;
    EXPECT_CV_ERROR_CONTAINS(withDngNoiseProfileLine(noBase, back), "the model has no base ISO");
    RawImage unprofiled = back;
    unprofiled.noiseProfile.clear();
    EXPECT_CV_ERROR_CONTAINS(withDngNoiseProfileLine(model, unprofiled), "the file has no NoiseProfile");
}

TEST(RawIo, aNoiseProfileDngCannotHoldIsRefusedAndAMalformedTagNamesTheFile)
{
    const std::string dir = makeTempDir("raw_io_noise_profile_bad");
    RawImage img;
    img.mosaic = Mat(48, 64, CV_16UC1, Scalar(500));
    img.format.whiteLevel = 4095;
    img.noiseProfile = {Vec2d(1e-4, 1e-6), Vec2d(1e-4, 1e-6)};
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/two.dng", img), "1 or 3");
    img.noiseProfile = {Vec2d(0, 1e-6)};
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/zero.dng", img), "S > 0 and O >= 0");
    img.noiseProfile = {Vec2d(1e-4, std::numeric_limits<double>::quiet_NaN())};
    EXPECT_CV_ERROR_CONTAINS(writeDng(dir + "/nan.dng", img), "S > 0 and O >= 0");
    EXPECT_TRUE(filesIn(dir).empty());
    EXPECT_CV_ERROR_CONTAINS(dngNoiseProfile(NoiseModel(0, 1, 1), img.format), "S > 0");

    img.noiseProfile = {Vec2d(1e-4, 1e-6)};
    writeDng(dir + "/good.dng", img);
    const std::vector<char> good = readBytes(dir + "/good.dng");
    // The tag's IFD entry: 51041 = 0xC761, little-endian, then type 12 (DOUBLE) and count 2.
    const char entry[] = {'\x61', '\xC7', 12, 0, 2, 0, 0, 0};
    const auto at = std::search(good.begin(), good.end(), entry, entry + sizeof(entry));
    ASSERT_NE(at, good.end());
    const size_t offset = static_cast<size_t>(at - good.begin());
    std::vector<char> bad = good;
    bad[offset + 4] = 5; // five values
    writeBytes(dir + "/count.dng", bad);
    EXPECT_CV_ERROR_CONTAINS(readRaw(dir + "/count.dng"),
                             "count.dng' has a NoiseProfile tag of type 12 with 5");
    bad = good;
    for (int k = 0; k < 4; ++k)
        bad[offset + 8 + k] = '\x7F'; // the values' offset, far beyond the end
    writeBytes(dir + "/beyond.dng", bad);
    EXPECT_CV_ERROR_CONTAINS(readRaw(dir + "/beyond.dng"), "beyond.dng' is truncated");
    bad = good;
    uint32_t valuesAt = 0;
    std::memcpy(&valuesAt, &good[offset + 8], 4);
    const double negative = -1e-4;
    std::memcpy(&bad[valuesAt], &negative, 8);
    writeBytes(dir + "/negative.dng", bad);
    EXPECT_CV_ERROR_CONTAINS(readRaw(dir + "/negative.dng"), "negative.dng' has an invalid NoiseProfile");
}

// A format whose four sites have different black levels, so a per-colour or per-site range that used
// the wrong site would show.
RawFormat unevenBlackFormat()
{
    RawFormat format;
    format.pattern = CFA_GRBG;
    format.blackLevel = Vec4d(510, 512, 514, 516);
    format.whiteLevel = 16383;
    return format;
}

TEST(RawIo, darktableNoiseProfilesAreTheDngProfilesPerIsoAndGiveTheModelBack)
{
    const std::string dir = makeTempDir("darktable_profiles");
    const NoiseModel model(0.42, 1.7, 3.1);
    const RawFormat format = unevenBlackFormat();
    const std::string json =
        darktableNoiseProfiles(model, format, 100, {800, 100, 3200, 400}, "Rawgment", "Test \"Cam\"");
    const std::string path = dir + "/noiseprofiles.json";
    writeFileAtomically(path, json.data(), json.size());

    FileStorage fs(path, FileStorage::READ);
    const FileNode entry = fs["noiseprofiles"][0];
    EXPECT_EQ(std::string(entry["maker"]), "Rawgment");
    EXPECT_EQ(std::string(entry["models"][0]["model"]), "Test \"Cam\"");
    const FileNode profiles = entry["models"][0]["profiles"];
    ASSERT_EQ(profiles.size(), 4u);
    const double isos[] = {100, 400, 800, 3200}; // written in ascending order, as darktable keeps them
    for (int k = 0; k < 4; ++k) {
        EXPECT_EQ(double(profiles[k]["iso"]), isos[k]);
        RawFormat atIso = format;
        atIso.gain = isos[k] / 100;
        const std::vector<Vec2d> dng = dngNoiseProfile(model, atIso);
        for (int c = 0; c < 3; ++c) {
            // 17 significant digits give the double back exactly.
            // darktable's units: c times the per-pixel variance (DarktableImportParams).
            EXPECT_EQ(double(profiles[k]["a"][c]), DARKTABLE_HAAR_VARIANCE_RATIO * dng[size_t(c)][0]);
            EXPECT_EQ(double(profiles[k]["b"][c]), DARKTABLE_HAAR_VARIANCE_RATIO * dng[size_t(c)][1]);
        }
    }

    const NoiseModel back = noiseModelFromDarktableExport(path, format, 100, "Rawgment", "Test \"Cam\"");
    // Exact up to the rounding of a 12-value least-squares line: a few ulps of the largest term.
    EXPECT_NEAR(back.alpha, model.alpha, 1e-13 * model.alpha);
    EXPECT_NEAR(back.sigmaD2, model.sigmaD2, 1e-11 * model.sigmaD2);
    EXPECT_NEAR(back.sigmaR2, model.sigmaR2, 1e-9 * model.sigmaR2);
    EXPECT_EQ(100.0, back.baseIso);
    // Another base ISO scales the gain: the model at base ISO 200 has twice the per-gain terms.
    const NoiseModel at200 = noiseModelFromDarktableExport(path, format, 200, "Rawgment", "Test \"Cam\"");
    EXPECT_NEAR(at200.alpha, 2 * model.alpha, 1e-12);
    EXPECT_NEAR(at200.sigmaD2, 4 * model.sigmaD2, 1e-9);

    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(path, format, 100, "Rawgment", "Other"),
                             "no profile of 'Rawgment / Other' (it has: Rawgment / Test \"Cam\")");
    EXPECT_CV_ERROR_CONTAINS(darktableNoiseProfiles(model, format, 100, {100, 100}, "A", "B"), "given twice");
    EXPECT_CV_ERROR_CONTAINS(darktableNoiseProfiles(model, format, 0, {100}, "A", "B"), "baseIso");
    EXPECT_CV_ERROR_CONTAINS(darktableNoiseProfiles(model, format, 100, {}, "A", "B"), "no ISO");
}

TEST(RawIo, darktableFilesThatNoModelMatchesAreRefusedNamingWhy)
{
    const std::string dir = makeTempDir("darktable_refused");
    const RawFormat format = unevenBlackFormat();
    const auto write = [&](const std::string& name, const std::string& text) {
        writeFileAtomically(dir + "/" + name, text.data(), text.size());
        return dir + "/" + name;
    };
    // The layout of darktable's own file: a skipped profile, another maker, comments. The skipped profile
    // is inconsistent with the others and must not be read.
    const NoiseModel model(0.5, 2, 4);
    RawFormat g1 = format, g2 = format;
    g1.gain = 1;
    g2.gain = 2;
    const std::vector<Vec2d> p1 = dngNoiseProfile(model, g1), p2 = dngNoiseProfile(model, g2);
    const auto list = [](const std::vector<Vec2d>& p, int k) {
        const double c = DARKTABLE_HAAR_VARIANCE_RATIO;
        return cv::format("[%.17g, %.17g, %.17g]", c * p[0][k], c * p[1][k], c * p[2][k]);
    };
    const std::string good = write(
        "good.json",
        "{\"version\": 0, \"noiseprofiles\": [\n"
        " {\"maker\": \"Other\", \"models\": [{\"model\": \"X\", \"profiles\": []}]},\n"
        " {\"maker\": \"Maker\", \"comment\": \"c\", \"models\": [{\"model\": \"M\", \"comment\": \"c\", "
        "\"profiles\": [\n"
        "  {\"name\": \"M iso 100\", \"iso\": 100, \"a\": " +
            list(p1, 0) + ", \"b\": " + list(p1, 1) +
            "},\n"
            "  {\"name\": \"M iso 150\", \"iso\": 150, \"skip\": true, \"a\": [1, 1, 1], \"b\": [1, 1, "
            "1]},\n"
            "  {\"name\": \"M iso 200\", \"iso\": 200, \"a\": " +
            list(p2, 0) + ", \"b\": " + list(p2, 1) + "}]}]}]}\n");
    const NoiseModel back = noiseModelFromDarktableExport(good, format, 100, "Maker", "M");
    EXPECT_NEAR(back.alpha, 0.5, 1e-13);
    EXPECT_NEAR(back.sigmaD2, 2, 1e-11);
    EXPECT_NEAR(back.sigmaR2, 4, 1e-10);

    // A measured profile: the colours' a differ, as they do in darktable's database.
    const std::string measured =
        write("measured.json",
              "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", \"models\": "
              "[{\"model\": \"M\", \"profiles\": [\n"
              "  {\"name\": \"a\", \"iso\": 100, \"a\": [7.6e-06, 1.5e-06, 2.3e-06], \"b\": [2e-09, "
              "3e-09, 4.7e-09]},\n"
              "  {\"name\": \"b\", \"iso\": 200, \"a\": [1.5e-05, 3e-06, 4.6e-06], \"b\": [8e-09, "
              "1.2e-08, 1.9e-08]}]}]}]}\n");
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(measured, format, 100, "Maker", "M"),
                             "measured.json': ISO 100 colour 1 gives alpha");
    const std::string oneIso =
        write("one_iso.json",
              "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", \"models\": [{\"model\": "
              "\"M\", \"profiles\": [{\"name\": \"a\", \"iso\": 100, \"a\": " +
                  list(p1, 0) + ", \"b\": " + list(p1, 1) + "}]}]}]}\n");
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(oneIso, format, 100, "Maker", "M"),
                             "one ISO only");
    const std::string typo = write("typo.json", "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", "
                                                "\"modles\": []}]}\n");
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(typo, format, 100, "Maker", "M"), "modles");
    const std::string shortList =
        write("short.json", "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", "
                            "\"models\": [{\"model\": \"M\", \"profiles\": [{\"iso\": 100, "
                            "\"a\": [1, 2], \"b\": [1, 2, 3]}]}]}]}\n");
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(shortList, format, 100, "Maker", "M"),
                             "short.json': field 'a' must be a list of 3 numbers");
    // a = 0 at one ISO: 0 once meant "alpha not yet seen", so the profile was taken. A zero slope where
    // another ISO has one is no exact model.
    const std::string zeroSlope =
        write("zero_slope.json",
              "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", \"models\": [{\"model\": "
              "\"M\", \"profiles\": [{\"name\": \"a\", \"iso\": 100, \"a\": [0, 0, 0], \"b\": " +
                  list(p1, 1) + "},\n  {\"name\": \"b\", \"iso\": 200, \"a\": " + list(p2, 0) +
                  ", \"b\": " + list(p2, 1) + "}]}]}]}\n");
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(zeroSlope, format, 100, "Maker", "M"),
                             "zero_slope.json': ISO 200 colour 0 gives alpha");
    const std::string negative =
        write("negative.json",
              "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", \"models\": [{\"model\": "
              "\"M\", \"profiles\": [{\"name\": \"a\", \"iso\": 100, \"a\": [-1e-6, 1e-6, 1e-6], \"b\": " +
                  list(p1, 1) + "}]}]}]}\n");
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(negative, format, 100, "Maker", "M"),
                             "ISO 100 colour 0 has a = -1e-06");
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(good, format, 1e300, "Maker", "M"),
                             "baseIso must lie in [1, 1e+07]");
}

TEST(RawIo, androidNoiseProfileIsTheDngProfileOfEverySiteAtEverySensitivity)
{
    const NoiseModel model(0.42, 1.7, 3.1);
    const RawFormat format = unevenBlackFormat();
    const AndroidNoiseProfile p = androidNoiseProfile(model, format, 50);
    for (double sensitivity : {50.0, 100.0, 800.0, 6400.0}) {
        const NoiseLine line = model.lineAtGain(sensitivity / 50);
        for (int site = 0; site < 4; ++site) {
            const double r = format.whiteLevel - format.blackLevel[site];
            EXPECT_NEAR(p.A[site] * sensitivity + p.B[site], line.a / r, 1e-15 * line.a / r);
            EXPECT_NEAR(p.C[site] * sensitivity * sensitivity + p.D[site], line.b / (r * r),
                        1e-14 * line.b / (r * r));
        }
    }
    const NoiseModel back = noiseModelFromAndroid(p, format, 50);
    EXPECT_EQ(50.0, back.baseIso);
    EXPECT_NEAR(back.alpha, model.alpha, 1e-15);
    EXPECT_NEAR(back.sigmaD2, model.sigmaD2, 1e-14);
    EXPECT_NEAR(back.sigmaR2, model.sigmaR2, 1e-14);

    AndroidNoiseProfile offset = p;
    offset.B[2] = 1e-7;
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromAndroid(offset, format, 50), "site 2 has B = 1e-07");
    AndroidNoiseProfile perColour = p;
    perColour.C[3] *= 1.01;
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromAndroid(perColour, format, 50), "site 3 gives sigma_d^2");
    AndroidNoiseProfile nan = p;
    nan.D[1] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromAndroid(nan, format, 50), "site 1 has a non-finite value");
    EXPECT_CV_ERROR_CONTAINS(androidNoiseProfile(model, format, -1), "baseIso");
}

TEST(RawIo, missingUnreadableAndNonRawFilesNameTheFileAndTheReason)
{
    const std::string dir = makeTempDir("raw_io_errors");
    EXPECT_CV_ERROR_CONTAINS(readRaw(dir + "/nothing.dng"), "nothing.dng': no such file");
    EXPECT_CV_ERROR_CONTAINS(readRaw(""), "empty");
    writeBytes(dir + "/text.dng", std::vector<char>(1000, 'x'));
    EXPECT_CV_ERROR_CONTAINS(readRaw(dir + "/text.dng"), "text.dng': LibRaw cannot open it");
    RAWGMENT_DATA_FILE_OR_SKIP(jpeg, "colorchecker_photo_1.jpg");
    EXPECT_CV_ERROR_CONTAINS(readRaw(jpeg), "LibRaw cannot open it");
}

TEST(RawIo, truncatedFileIsAnError)
{
    const std::string dir = makeTempDir("raw_io_truncated");
    RawImage img;
    img.mosaic.create(200, 300, CV_16UC1);
    randu(img.mosaic, 0, 4096);
    img.format.whiteLevel = 4095;
    writeDng(dir + "/whole.dng", img);
    std::vector<char> bytes = readBytes(dir + "/whole.dng");
    bytes.resize(bytes.size() / 2);
    writeBytes(dir + "/half.dng", bytes);
    // LibRaw reports an I/O error while decoding ("truncated or corrupt?") or calls the data-error handler.
    EXPECT_CV_ERROR_CONTAINS(readRaw(dir + "/half.dng"), "truncated");
}

TEST(RawIo, aThreeSampleLinearDngIsNeitherBayerNorMonochrome)
{
    const std::string dir = makeTempDir("raw_io_linear");
    RawImage img;
    // LibRaw ignores images narrower than 22 pixels, so the linear image is 22 wide.
    img.mosaic = Mat(64, 66, CV_16UC1, Scalar(500));
    img.format.whiteLevel = 4095;
    writeDng(dir + "/cfa.dng", img);
    std::vector<char> bytes = readBytes(dir + "/cfa.dng");
    // Make it a 3-sample LinearRaw image (demosaiced data): PhotometricInterpretation 32803 -> 34892,
    // SamplesPerPixel 1 -> 3, ImageWidth 66 -> 22 so that the strip still holds every sample.
    const auto patchEntry = [&](uint16_t tag, uint16_t value) {
        for (size_t i = 10; i + 12 <= bytes.size(); i += 12)
            if (uint8_t(bytes[i]) == (tag & 0xff) && uint8_t(bytes[i + 1]) == (tag >> 8)) {
                bytes[i + 8] = char(value & 0xff);
                bytes[i + 9] = char(value >> 8);
                return true;
            }
        return false;
    };
    const bool patched = patchEntry(262, 34892) && patchEntry(277, 3) && patchEntry(256, 22);
    ASSERT_TRUE(patched);
    writeBytes(dir + "/linear.dng", bytes);
    EXPECT_CV_ERROR_CONTAINS(readRaw(dir + "/linear.dng"), "neither a Bayer mosaic nor a monochrome frame");
}

TEST(RawIo, aMonochromeFrameRoundTripsThroughALinearRawDng)
{
    const std::string dir = makeTempDir("raw_io_mono");
    RawImage img;
    img.mosaic.create(48, 70, CV_16UC1);
    randu(img.mosaic, 0, 4096);
    img.format.pattern = CFA_MONO;
    img.format.blackLevel = Vec4d::all(200);
    img.format.whiteLevel = 4095;
    img.iso = 400;
    img.exposureTime = 0.02;
    img.make = "Basler";
    img.model = "mono test";
    img.noiseProfile = {Vec2d(1e-4, 2e-6)};
    writeDng(dir + "/mono.dng", img);
    const std::vector<char> bytes = readBytes(dir + "/mono.dng");
    // PhotometricInterpretation LinearRaw (34892), SamplesPerPixel 1, and no CFA tags.
    const auto entry = [&](uint16_t tag) -> int {
        for (size_t i = 10; i + 12 <= bytes.size(); i += 12)
            if (uint8_t(bytes[i]) == (tag & 0xff) && uint8_t(bytes[i + 1]) == (tag >> 8))
                return uint8_t(bytes[i + 8]) | (uint8_t(bytes[i + 9]) << 8);
        return -1;
    };
    EXPECT_EQ(entry(262), 34892);
    EXPECT_EQ(entry(277), 1);
    EXPECT_EQ(entry(33421), -1);
    EXPECT_EQ(entry(33422), -1);
    const RawImage back = readRaw(dir + "/mono.dng");
    EXPECT_EQ(back.format.pattern, CFA_MONO);
    EXPECT_EQ(back.format.blackLevel, img.format.blackLevel);
    EXPECT_EQ(back.format.whiteLevel, img.format.whiteLevel);
    EXPECT_EQ(0, norm(back.mosaic, img.mosaic, NORM_INF));
    EXPECT_EQ(back.iso, 400);
    EXPECT_EQ(back.exposureTime, 0.02);
    EXPECT_EQ(back.make, "Basler");
    ASSERT_EQ(back.noiseProfile.size(), 1u);
    EXPECT_EQ(back.noiseProfile[0], img.noiseProfile[0]);
    // No colour: the identity balance and matrix, and no colour tags.
    EXPECT_EQ(back.whiteBalance, Vec3d(1, 1, 1));
    EXPECT_EQ(back.cameraToSrgb, Matx33d::eye());
    EXPECT_TRUE(back.colorTags.empty());
}

} // namespace
} // namespace rawgment
} // namespace cv
