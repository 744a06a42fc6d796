// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The mosaic_files topic: mosaics with their sidecars in every container, camera tags that travel with
// them, sidecars never replaced or left without their image, and sidecars checked against the image.
#include "test_common.hpp"

#include "../src/precomp.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/emva1288.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sys/stat.h>
#include <unistd.h>
#include <vector>

namespace cv {
namespace rawgment {
namespace {

using test::filesIn;
using test::makeTempDir;
using test::readBytes;
using test::writeBytes;

std::string sidecarText(const std::string& mosaic)
{
    const std::vector<char> bytes = readBytes(mosaic + ".yml");
    return std::string(bytes.begin(), bytes.end());
}

/* A mosaic's exposure time travels in its sidecar (#79 item 10): in the camera tags when it has them (one
 * capture has one exposure: a format that says another is refused), else in the format, and only then at
 * version 5, so that every other sidecar keeps its version and bytes. A DNG carries it as its ExposureTime.
 */
TEST(MosaicFiles, theExposureTimeTravelsInTheCameraTagsOrTheFormat)
{
    const std::string dir = makeTempDir("mosaic_exposure");
    const Mat m16(24, 32, CV_16UC1, Scalar(100));
    MosaicMetadata meta;
    meta.format.whiteLevel = 4095;
    writeMosaic(dir + "/plain.npy", m16, meta);
    EXPECT_NE(sidecarText(dir + "/plain.npy").find("format_version: 3"), std::string::npos);
    meta.format.exposureTime = 0.25;
    for (const char* name : {"/format.npy", "/format.dng"}) {
        writeMosaic(dir + name, m16, meta);
        Mat back;
        EXPECT_NEAR(readMosaic(dir + name, back).format.exposureTime, 0.25, 1e-12) << name;
    }
    EXPECT_NE(sidecarText(dir + "/format.npy").find("format_version: 5"), std::string::npos);
    EXPECT_NEAR(readRaw(dir + "/format.dng").format.exposureTime, 0.25, 1e-7);
    meta.hasCamera = true;
    meta.camera.exposureTime = 0.25;
    writeMosaic(dir + "/tagged.npy", m16, meta);
    const std::string tagged = sidecarText(dir + "/tagged.npy");
    EXPECT_NE(tagged.find("format_version: 3"), std::string::npos) << tagged;
    Mat back;
    EXPECT_EQ(readMosaic(dir + "/tagged.npy", back).format.exposureTime, 0.25) << "the tags' exposure";
    meta.camera.exposureTime = 0.5;
    EXPECT_CV_ERROR_CONTAINS(writeMosaic(dir + "/two.npy", m16, meta),
                             "the format's exposure time 0.25 s differs from the camera tags' 0.5 s");
}

TEST(MosaicFiles, cameraTagsTravelInTheSidecarAndTheDngAndFirstVersionSidecarsStillLoad)
{
    const std::string dir = makeTempDir("raw_io_camera_tags");
    Mat m16(48, 64, CV_16UC1, Scalar(900));
    MosaicMetadata meta;
    meta.format.whiteLevel = 4095;
    meta.format.blackLevel = Vec4d::all(64);
    meta.hasCamera = true;
    meta.camera.make = "Maker";
    meta.camera.model = "Model";
    meta.camera.iso = 1234.4;
    meta.camera.exposureTime = 1.0 / 32000 * 0.3;
    meta.camera.whiteBalance = Vec3d(2.1, 1, 1.6);
    meta.camera.cameraToSrgb = Matx33d(1.6, -0.4, -0.2, -0.2, 1.5, -0.3, 0.1, -0.5, 1.4);
    meta.camera.noiseProfile = {Vec2d(1e-4, 2e-7)};
    writeMosaic(dir + "/tagged.dng", m16, meta);
    Mat back;
    const CameraTags side = readMosaic(dir + "/tagged.dng", back).camera;
    EXPECT_EQ(side.make, "Maker");
    EXPECT_EQ(side.iso, 1234.4) << "the sidecar keeps what the DNG rounds";
    EXPECT_EQ(side.exposureTime, meta.camera.exposureTime);
    EXPECT_EQ(side.whiteBalance, meta.camera.whiteBalance);
    EXPECT_EQ(side.cameraToSrgb, meta.camera.cameraToSrgb);
    EXPECT_EQ(side.noiseProfile, meta.camera.noiseProfile);
    const RawImage dng = readRaw(dir + "/tagged.dng");
    EXPECT_EQ(dng.make, "Maker");
    EXPECT_EQ(dng.model, "Model");
    EXPECT_EQ(dng.iso, 1234) << "ISOSpeedRatings is an integer";
    // Nine decimals of the DNG rational, then LibRaw's float: 1e-7 relative.
    EXPECT_NEAR(dng.exposureTime, meta.camera.exposureTime, 1e-6 * meta.camera.exposureTime);
    EXPECT_NEAR(norm(Vec3d(dng.whiteBalance) - meta.camera.whiteBalance), 0, 1e-5);
    EXPECT_EQ(dng.noiseProfile, meta.camera.noiseProfile);

    // Colour tags travel verbatim through the sidecar and the DNG: a big-endian source's numerators,
    // an unsigned rational beyond int32, a CalibrationIlluminant2 that writeDng would never make.
    DngTag colorMatrix, neutral, illuminant2;
    colorMatrix.tag = 50721;
    colorMatrix.type = 10;
    colorMatrix.count = 9;
    colorMatrix.values = {6461,  10000, -1164, 10000, -857,  10000, -3825, 10000, 11597,
                          10000, 2534,  10000, -416,  10000, 1540,  10000, 6039,  10000};
    neutral.tag = 50728;
    neutral.type = 5;
    neutral.count = 3;
    neutral.values = {3000000000.0, 3000000000.0, 2477, 1000, 1462, 1000};
    illuminant2.tag = 50779;
    illuminant2.type = 3;
    illuminant2.count = 1;
    illuminant2.values = {17};
    meta.camera.colorTags = {colorMatrix, neutral, illuminant2};
    writeMosaic(dir + "/colour.dng", m16, meta);
    const CameraTags colourSide = readMosaic(dir + "/colour.dng", back).camera;
    const RawImage colourDng = readRaw(dir + "/colour.dng");
    for (const std::vector<DngTag>* tags : {&colourSide.colorTags, &colourDng.colorTags}) {
        ASSERT_EQ(3u, tags->size());
        for (size_t k = 0; k < 3; ++k) {
            EXPECT_EQ((*tags)[k].tag, meta.camera.colorTags[k].tag);
            EXPECT_EQ((*tags)[k].type, meta.camera.colorTags[k].type);
            EXPECT_EQ((*tags)[k].values, meta.camera.colorTags[k].values);
        }
    }
    // What no TIFF value holds is refused, naming the tag.
    DngTag bad = neutral;
    bad.values[1] = 0;
    EXPECT_CV_ERROR_CONTAINS(bad.validate("x"),
                             "x 50728: value 1 (0) does not fit TIFF type 5 (a denominator");
    bad = colorMatrix;
    bad.tag = 271;
    EXPECT_CV_ERROR_CONTAINS(bad.validate("x"), "tag 271 is not one of the DNG colour tags");
    meta.camera.colorTags.clear();

    // The same sidecar as format version 1 wrote it (no camera key) still loads.
    meta.hasCamera = false;
    writeMosaic(dir + "/plain.png", m16, meta);
    std::string text;
    {
        const std::vector<char> bytes = readBytes(dir + "/plain.png.yml");
        text.assign(bytes.begin(), bytes.end());
    }
    const size_t at = text.find("format_version: 3");
    ASSERT_NE(at, std::string::npos) << text;
    text.replace(at, 17, "format_version: 1");
    std::remove((dir + "/plain.png.yml").c_str());
    writeBytes(dir + "/plain.png.yml", std::vector<char>(text.begin(), text.end()));
    EXPECT_FALSE(readMosaic(dir + "/plain.png", back).hasCamera);
    // A misspelled camera key is named.
    text.replace(at, 17, "format_version: 2");
    text +=
        "   camera: { make: x, iso: 1, white_balance: [1, 1, 1], camera_to_srgb: [1, 0, 0, 0, 1, 0, 0, 0, 1],"
        " exposure: 1 }\n";
    std::remove((dir + "/plain.png.yml").c_str());
    writeBytes(dir + "/plain.png.yml", std::vector<char>(text.begin(), text.end()));
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/plain.png", back), "exposure");

    // The real camera whose noise a scene simulated travels in the sidecar (format version 3).
    meta.noiseCamera = "Nikon D3";
    writeMosaic(dir + "/camera.png", m16, meta);
    EXPECT_EQ(readMosaic(dir + "/camera.png", back).noiseCamera, "Nikon D3");
}

TEST(MosaicFiles, mosaicRoundTripsWithItsSidecarInEveryContainer)
{
    const std::string dir = makeTempDir("raw_io_mosaic");
    Mat m16(32, 48, CV_16UC1);
    randu(m16, 0, 65536);
    MosaicMetadata meta;
    meta.format.pattern = CFA_GBRG;
    meta.format.blackLevel = Vec4d(64, 64, 64, 64);
    meta.format.whiteLevel = 65535;
    meta.format.gain = 3.98;
    meta.hasScene = true;
    meta.scene.jitter.brightness = -2.5;
    meta.scene.jitter.gainRatio = 2.0;
    meta.seed = 18446744073709551557ull; // the largest 64-bit prime: the seed needs all 64 bits
    meta.source = "input.dng";
    // Every container of the table that writes, under each of its extensions: a new entry is tested here.
    std::vector<std::string> expected, writtenExtensions;
    for (const MosaicContainer& c : mosaicContainers())
        if (c.writes)
            for (const String& e : c.extensions)
                writtenExtensions.push_back(e);
    ASSERT_EQ(writtenExtensions, std::vector<std::string>({".dng", ".npy", ".png", ".tif", ".tiff"}));
    for (const std::string& ext : writtenExtensions) {
        const std::string path = dir + "/out" + ext;
        expected.insert(expected.end(), {"out" + ext, "out" + ext + ".yml"});
        writeMosaic(path, m16, meta);
        Mat back;
        const MosaicMetadata r = readMosaic(path, back);
        SCOPED_TRACE(ext);
        EXPECT_EQ(0, norm(m16, back, NORM_INF));
        EXPECT_EQ(cfaPatternName(CFA_GBRG), cfaPatternName(r.format.pattern));
        EXPECT_EQ(3.98, r.format.gain) << "the new gain travels in the sidecar";
        EXPECT_TRUE(r.hasScene);
        EXPECT_EQ(-2.5, r.scene.jitter.brightness);
        EXPECT_EQ(2.0, r.scene.jitter.gainRatio);
        EXPECT_EQ(meta.seed, r.seed);
        EXPECT_EQ("input.dng", r.source);
        // The same job's files again (another writer of it) are its output; anything else is never written.
        const std::vector<char> before = test::readBytes(path);
        EXPECT_NO_THROW(writeMosaic(path, m16, meta));
        EXPECT_EQ(before, test::readBytes(path));
        MosaicMetadata other = meta;
        other.seed += 1;
        EXPECT_CV_ERROR_CONTAINS(writeMosaic(path, m16, other), "never overwritten");
        EXPECT_CV_ERROR_CONTAINS(writeMosaic(path, Mat(m16 + 1), meta), "never overwritten");
        EXPECT_EQ(before, test::readBytes(path));
    }
    // Float mosaics losslessly where the table says the container holds them, refused elsewhere.
    Mat f32(32, 48, CV_32FC1);
    randu(f32, -5.0, 1000.0);
    for (const MosaicContainer& c : mosaicContainers()) {
        if (!c.writes)
            continue;
        const std::string path = dir + "/float" + c.extensions.back();
        SCOPED_TRACE(path);
        if (!c.float32) {
            EXPECT_CV_ERROR_CONTAINS(writeMosaic(path, f32, meta),
                                     "cannot be stored as " + c.extensions.back());
            continue;
        }
        writeMosaic(path, f32, meta);
        expected.insert(expected.end(),
                        {"float" + c.extensions.back(), "float" + c.extensions.back() + ".yml"});
        Mat back;
        readMosaic(path, back);
        EXPECT_EQ(CV_32FC1, back.type());
        EXPECT_EQ(0, norm(f32, back, NORM_INF)) << "float is lossless";
    }
    EXPECT_CV_ERROR_CONTAINS(writeMosaic(dir + "/x.jpg", m16, meta),
                             "unsupported extension; expected .dng, .npy, .png, .tif or .tiff");
    EXPECT_CV_ERROR_CONTAINS(writeMosaic(dir + "/x.nef", m16, meta), "unsupported extension");
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(expected, filesIn(dir)) << "no temporary files are left behind";
}

// One table of containers: every extension lower case with its dot and in one container only, a path found
// by its extension in any case, the camera formats read by readRaw() and never written.
TEST(MosaicFiles, theContainerTableNamesEachExtensionOnceAndFindsAPathsContainer)
{
    std::vector<String> all;
    for (const MosaicContainer& c : mosaicContainers()) {
        SCOPED_TRACE(c.name);
        EXPECT_FALSE(c.name.empty());
        ASSERT_FALSE(c.extensions.empty());
        EXPECT_TRUE(c.writes || c.readsMosaic || c.cameraRaw);
        EXPECT_FALSE(c.writes && !c.readsMosaic) << "what is written is read back";
        for (const String& e : c.extensions) {
            EXPECT_TRUE(e.size() > 1 && e[0] == '.') << e;
            EXPECT_EQ(e, toLowerCase(e));
            all.push_back(e);
        }
    }
    std::vector<String> unique = all;
    std::sort(unique.begin(), unique.end());
    EXPECT_EQ(std::unique(unique.begin(), unique.end()), unique.end());
    ASSERT_NE(mosaicContainerOf("/a/b/IMG_0001.NEF"), nullptr);
    EXPECT_TRUE(mosaicContainerOf("/a/b/IMG_0001.NEF")->cameraRaw);
    EXPECT_FALSE(mosaicContainerOf("x.nef")->writes);
    EXPECT_EQ(mosaicContainerOf("x.TIFF")->name, "tif");
    EXPECT_TRUE(mosaicContainerOf("x.dng")->cameraRaw && mosaicContainerOf("x.dng")->writes);
    EXPECT_EQ(mosaicContainerOf("x.jpg"), nullptr);
    EXPECT_EQ(mosaicContainerOf("noextension"), nullptr);
    EXPECT_CV_ERROR_CONTAINS(readMosaic("/no/such/x.jpg", noArray()), "no such file");
}

TEST(MosaicFiles, aMonochromeFrameRoundTripsWithItsSidecarInEveryContainer)
{
    const std::string dir = makeTempDir("mosaic_files_mono");
    Mat frame(40, 60, CV_16UC1);
    randu(frame, 0, 4096);
    MosaicMetadata meta;
    meta.format.pattern = CFA_MONO;
    meta.format.blackLevel = Vec4d::all(100);
    meta.format.whiteLevel = 4095;
    meta.format.gain = 2.5;
    meta.seed = 7;
    for (const char* ext : {".png", ".tif", ".dng", ".npy"}) {
        SCOPED_TRACE(ext);
        const std::string path = dir + "/mono" + ext;
        writeMosaic(path, frame, meta);
        Mat back;
        const MosaicMetadata r = readMosaic(path, back);
        EXPECT_EQ(0, norm(frame, back, NORM_INF));
        EXPECT_EQ(r.format.pattern, CFA_MONO);
        EXPECT_EQ(r.format.blackLevel, meta.format.blackLevel);
        EXPECT_EQ(r.format.gain, 2.5);
        EXPECT_NE(std::string(test::readBytes(path + ".yml").data(), test::readBytes(path + ".yml").size())
                      .find("pattern: MONO"),
                  std::string::npos);
    }
    // The DNG states the same format as the sidecar, so readMosaic() compares them: a Bayer sidecar beside
    // a monochrome DNG contradicts it.
    const std::string dng = dir + "/mono.dng";
    std::vector<char> sidecar = test::readBytes(dng + ".yml");
    std::string text(sidecar.begin(), sidecar.end());
    text.replace(text.find("pattern: MONO"), 13, "pattern: RGGB");
    test::writeBytes(dng + ".yml", std::vector<char>(text.begin(), text.end()));
    Mat back;
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dng, back), "MONO");
}

/* The .npy container as numpy writes it: a 64-byte-aligned header, and the data right after; and every
 * malformed file an error naming it, decided before the array is allocated. */
TEST(MosaicFiles, npyMosaicsAreNumpysFormatAndMalformedOnesAreErrors)
{
    const std::string dir = makeTempDir("mosaic_npy");
    Mat m(6, 10, CV_16UC1);
    randu(m, 0, 65536);
    MosaicMetadata meta;
    meta.format.whiteLevel = 65535;
    const std::string good = dir + "/good.npy";
    writeMosaic(good, m, meta);
    const std::vector<char> bytes = readBytes(good);
    const std::string expectedHeader = "{'descr': '<u2', 'fortran_order': False, 'shape': (6, 10), }";
    ASSERT_EQ(bytes.size(), 128u + 120u) << "a 128-byte header (aligned to 64), then 6 x 10 x 2 bytes";
    EXPECT_EQ(std::string(bytes.begin(), bytes.begin() + 6), "\x93NUMPY");
    EXPECT_EQ(std::string(bytes.begin() + 10, bytes.begin() + 10 + long(expectedHeader.size())),
              expectedHeader);
    EXPECT_EQ(bytes[127], '\n');
    EXPECT_EQ(0, std::memcmp(bytes.data() + 128, m.data, 120));

    const std::string header(bytes.begin() + 10, bytes.begin() + 128);
    // Each case: a file with the good one's sidecar (so that only the .npy is wrong) and the error.
    const auto variant = [&](const std::string& name, std::vector<char> content) {
        const std::string path = dir + "/" + name + ".npy";
        writeBytes(path, content);
        writeBytes(sidecarPathOf(path), readBytes(sidecarPathOf(good)));
        return path;
    };
    const auto withHeader = [&](std::string h, size_t dataBytes = 120) {
        h.resize(118, ' ');
        h.back() = '\n';
        std::vector<char> c(bytes.begin(), bytes.begin() + 10);
        c.insert(c.end(), h.begin(), h.end());
        c.insert(c.end(), bytes.begin() + 128, bytes.begin() + 128 + long(std::min<size_t>(dataBytes, 120)));
        c.resize(128 + dataBytes, 0);
        return c;
    };
    const std::vector<std::pair<std::vector<char>, std::string>> cases = {
        {{}, "numpy's magic string"},
        {std::vector<char>(bytes.begin(), bytes.begin() + 9), "numpy's magic string"},
        {std::vector<char>(bytes.begin(), bytes.begin() + 60), "ends inside its header"},
        {std::vector<char>(bytes.begin(), bytes.end() - 1), "247 bytes, but its header describes 248"},
        {withHeader(header, 121), "249 bytes, but its header describes 248"},
        {withHeader("{'descr': '>u2', 'fortran_order': False, 'shape': (6, 10), }"), "dtype '>u2'"},
        {withHeader("{'descr': '<u2', 'fortran_order': True, 'shape': (6, 10), }"), "Fortran order"},
        {withHeader("{'descr': '<u2', 'fortran_order': False, 'shape': (6, 10, 1), }"), "3 dimensions"},
        {withHeader("{'descr': '<u2', 'fortran_order': False, 'shape': (60000, 60000), }"),
         "pixels be at most"},
        {withHeader("{'descr': '<u2', 'fortran_order': False, 'shape': (600, 1000), }"),
         "but its header describes"},
        {withHeader("{'descr': '<u2', 'fortran_order': False, 'shape': (6, 10), 'x': 1}"),
         "unknown header key 'x'"},
        {withHeader("{'descr': '<u2', 'descr': '<u2', 'shape': (6, 10), }"), "'descr' appears twice"},
        {withHeader("{'descr': '<u2', 'shape': (6, 10), }"), "lacks"},
        {withHeader("{'descr': '<u2', 'fortran_order': False, 'shape': (6, -10), }"),
         "non-negative integers"},
        {withHeader("{'descr': '<u2', 'fortran_order': False, 'shape': (6, 10), } x"), "text after"},
    };
    int k = 0;
    for (const auto& c : cases) {
        SCOPED_TRACE(c.second);
        const std::string path = variant(cv::format("bad%d", k++), c.first);
        Mat back;
        EXPECT_CV_ERROR_CONTAINS(readMosaic(path, back), c.second);
        EXPECT_CV_ERROR_CONTAINS(readMosaic(path, back), path);
    }
    std::vector<char> version = bytes;
    version[6] = 4;
    Mat back;
    EXPECT_CV_ERROR_CONTAINS(readMosaic(variant("version", version), back), "format version 4.0");
}

TEST(MosaicFiles, writeMosaicNeverReplacesASidecarAndLeavesNoneWithoutItsImage)
{
    const std::string dir = makeTempDir("raw_io_sidecar_safety");
    Mat m16(32, 48, CV_16UC1, Scalar(500));
    MosaicMetadata meta;
    meta.format.whiteLevel = 65535;
    meta.source = "a/frame_000.dng";
    // Another mosaic's sidecar whose image is missing: kept as it is, and the write refused.
    const std::string other = dir + "/other.png";
    writeBytes(sidecarPathOf(other), {'x', '\n'});
    EXPECT_CV_ERROR_CONTAINS(writeMosaic(other, m16, meta), "describes another mosaic");
    EXPECT_EQ(readBytes(sidecarPathOf(other)), (std::vector<char>{'x', '\n'}));
    EXPECT_FALSE(std::ifstream(other).good());
    // The sidecar an interrupted run of the same job left: the write completes.
    const std::string same = dir + "/same.png";
    writeMosaic(same, m16, meta);
    std::remove(same.c_str());
    writeMosaic(same, m16, meta);
    Mat back;
    EXPECT_EQ(readMosaic(same, back).source, "a/frame_000.dng");
    // An image that cannot be written takes its new sidecar with it (odd sides do not fit a DNG).
    const std::string odd = dir + "/odd.dng";
    EXPECT_CV_ERROR_CONTAINS(writeMosaic(odd, Mat(31, 48, CV_16UC1, Scalar(1)), meta), "even");
    EXPECT_FALSE(std::ifstream(sidecarPathOf(odd)).good()) << "no sidecar without its image";
}

TEST(MosaicFiles, readMosaicChecksTheSidecar)
{
    const std::string dir = makeTempDir("raw_io_sidecar");
    Mat m(8, 8, CV_16UC1, Scalar(7));
    MosaicMetadata meta;
    writeMosaic(dir + "/a.png", m, meta);
    Mat back;
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/b.png", back), "no such file");
    ASSERT_EQ(0, std::remove((dir + "/a.png.yml").c_str()));
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/a.png", back), "cannot open mosaic sidecar");
    // A sidecar that describes another image.
    Mat other(4, 4, CV_16UC1, Scalar(1));
    writeMosaic(dir + "/c.png", other, meta);
    ASSERT_EQ(0, std::rename((dir + "/c.png.yml").c_str(), (dir + "/a.png.yml").c_str()));
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/a.png", back), "its sidecar says 4x4");
}

// A little-endian classic TIFF of 8x8 uint16 zeros whose directory holds `entries` (tag, type, value) as
// given, in that order: hostile headers are written exactly as the test says.
std::vector<char> tiffWithDirectory(const std::vector<std::array<uint32_t, 3>>& entries)
{
    std::vector<char> b = {'I', 'I', 42, 0, 0, 0, 0, 0};
    b.resize(8 + 128, 0); // the pixels
    const auto put16 = [&](uint32_t v) {
        b.push_back(char(v & 0xff));
        b.push_back(char(v >> 8));
    };
    const auto put32 = [&](uint32_t v) {
        put16(v & 0xffff);
        put16(v >> 16);
    };
    const uint32_t ifd = uint32_t(b.size());
    std::memcpy(&b[4], &ifd, 4);
    put16(uint32_t(entries.size()));
    for (const auto& e : entries) {
        put16(e[0]);
        put16(e[1]);
        put32(1);
        if (e[1] == 3) {
            put16(e[2]);
            put16(0);
        } else {
            put32(e[2]);
        }
    }
    put32(0);
    return b;
}

TEST(MosaicFiles, imageHeadersAreReadAsTheDecoderReadsThemAndCheckedBeforeAnyDecode)
{
    // Round 5 item 20: a TIFF whose first width/height tags said 30000x30000 and whose last said 8x8 passed
    // a check that read the last tags, and libtiff, which reads the first, allocated 1.8 GB; readMosaic
    // decoded a PNG before holding its header to the sidecar.
    const std::string dir = makeTempDir("image_headers");
    const std::vector<std::array<uint32_t, 3>> duplicated = {
        {256, 4, 30000}, {257, 4, 30000}, {256, 3, 8}, {257, 3, 8}, {258, 3, 16}, {259, 3, 1},
        {262, 3, 1},     {273, 4, 8},     {277, 3, 1}, {278, 3, 8}, {279, 4, 128}};
    const std::vector<std::array<uint32_t, 3>> huge = {{256, 4, 30000}, {257, 4, 30000}, {258, 3, 16},
                                                       {259, 3, 1},     {262, 3, 1},     {273, 4, 8},
                                                       {277, 3, 1},     {278, 3, 8},     {279, 4, 128}};
    const Mat m(8, 8, CV_16UC1, Scalar(0));
    MosaicMetadata meta;
    writeMosaic(dir + "/a.tif", m, meta);
    Mat back;
    ASSERT_NO_THROW(readMosaic(dir + "/a.tif", back));
    writeBytes(dir + "/a.tif", tiffWithDirectory(duplicated));
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/a.tif", back), "names tag 256 twice");
    writeBytes(dir + "/a.tif", tiffWithDirectory(huge));
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/a.tif", back), "header says 30000 x 30000");
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/a.tif", back), "nothing was decoded");

    // A PNG whose IHDR claims 30000x30000 beside a sidecar of 8x8: refused before libpng is asked.
    writeMosaic(dir + "/b.png", m, meta);
    std::vector<char> png = readBytes(dir + "/b.png");
    ASSERT_GE(png.size(), size_t(24));
    const char side[4] = {0, 0, 0x75, 0x30}; // 30000, big-endian
    std::memcpy(&png[16], side, 4);
    std::memcpy(&png[20], side, 4);
    writeBytes(dir + "/b.png", png);
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/b.png", back), "PNG header says 30000 x 30000");
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/b.png", back), "its sidecar says 8x8");

    // The EMVA 1288 reader reads its images' headers with the same reader.
    Emva1288Series series;
    series.path = dir + "/set.txt";
    series.width = 8;
    series.height = 8;
    series.bits = 12;
    writeBytes(dir + "/e.tif", tiffWithDirectory(duplicated));
    EXPECT_CV_ERROR_CONTAINS(readEmva1288Image(series, dir + "/e.tif", 3), "names tag 256 twice");
    writeBytes(dir + "/e.tif", tiffWithDirectory(huge));
    EXPECT_CV_ERROR_CONTAINS(readEmva1288Image(series, dir + "/e.tif", 3), "it is 30000 x 30000");
}

TEST(MosaicFiles, readMosaicRefusesASidecarThatContradictsItsDng)
{
    const std::string dir = makeTempDir("raw_io_sidecar_dng");
    MosaicMetadata meta;
    meta.format.blackLevel = Vec4d::all(64);
    meta.format.whiteLevel = 4095;
    writeMosaic(dir + "/m.dng", Mat(64, 64, CV_16UC1, Scalar(500)), meta);
    std::vector<char> text = readBytes(dir + "/m.dng.yml");
    std::string s(text.begin(), text.end());
    const size_t at = s.find("white_level: 4095.");
    ASSERT_NE(at, std::string::npos) << s;
    s.replace(at, 18, "white_level: 1023.");
    writeBytes(dir + "/m.dng.yml", std::vector<char>(s.begin(), s.end()));
    Mat back;
    EXPECT_CV_ERROR_CONTAINS(readMosaic(dir + "/m.dng", back),
                             "but its sidecar says RGGB with black 64 64 64 64 and white 1023");
}

} // namespace
} // namespace rawgment
} // namespace cv
