// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A bank of dark frames (opencv2/rawgment/dark_frames.hpp): made from files by gain and exposure, saved
// beside its frames and loaded with every field checked, its nearest group, its refusals. What the statistics
// estimate is tested against the simulator's truth in test_dark_frames_internals.cpp.
#include "test_common.hpp"

#include <opencv2/rawgment/dark_frames.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/raw_io.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

namespace cv {
namespace rawgment {
namespace {

// Dark frames from files: mosaics with sidecars at two gains (one of them at two exposure times) and DNGs
// whose ISO gives their gain, each group estimated as its frames in memory are; and the refusals a bank
// needs.
TEST(DarkFrameBank, filesGroupByGainAndExposureAndRefuseAnotherSensor)
{
    const std::string dir = test::makeTempDir("dark_frames_files");
    const Size size(32, 24);
    SensorParams params = test::darkComponentSensorParams(size, 0.14, 3);
    const SensorSimulator sensor(params, size);
    NoiseModel model = sensor.effectiveModel();
    model.baseIso = 100;
    std::vector<String> files;
    std::map<std::pair<double, double>, std::vector<Mat>> frames;
    int n = 0;
    for (const auto& setting :
         {std::make_pair(2.0, 0.01), std::make_pair(8.0, 0.01), std::make_pair(8.0, 0.5)})
        for (int t = 0; t < 3; ++t) {
            Mat raw;
            sensor.capture(Mat::zeros(size, CV_32FC1), setting.first, 1.0, 40 + n, t, raw);
            MosaicMetadata meta;
            meta.format = sensor.rawFormat(setting.first);
            meta.hasCamera = true;
            meta.camera.exposureTime = setting.second;
            const std::string path = dir + format("/dark_%02d.png", n++);
            writeMosaic(path, raw, meta);
            files.push_back(path);
            frames[setting].push_back(raw);
        }
    // Camera files: ISO 400 over the model's base ISO 100 is gain 4; no exposure time stated.
    for (int t = 0; t < 2; ++t) {
        RawImage image;
        sensor.capture(Mat::zeros(size, CV_32FC1), 4.0, 1.0, 77, t, image.mosaic);
        image.format = sensor.rawFormat(1.0);
        image.iso = 400;
        const std::string path = dir + format("/camera_%d.dng", t);
        writeDng(path, image);
        files.push_back(path);
        frames[{4.0, 0.0}].push_back(image.mosaic);
    }
    const DarkFrameBank c = DarkFrameBank::create(files, model);
    ASSERT_EQ(c.groups.size(), 4u);
    EXPECT_EQ(c.size, size);
    EXPECT_EQ(c.format.gain, 1);
    for (const DarkFrameGroup& g : c.groups) {
        const std::vector<Mat>& burst = frames.at({g.gain, g.exposureTime});
        ASSERT_EQ(g.files.size(), burst.size()) << g.gain;
        EXPECT_EQ(g.statistics.frames, static_cast<int>(burst.size()));
        const int group = static_cast<int>(&g - c.groups.data());
        for (size_t i = 0; i < burst.size(); ++i)
            EXPECT_EQ(cv::norm(c.readFrame(group, static_cast<int>(i)), burst[i], NORM_INF), 0)
                << "the files hold the frames' bits";
    }
    EXPECT_EQ(c.groups[0].gain, 2);
    EXPECT_EQ(c.groups[1].gain, 4);
    EXPECT_EQ(c.groups[2].exposureTime, 0.01);
    EXPECT_EQ(c.groups[3].exposureTime, 0.5);
    // One gain is a bank; none is not.
    EXPECT_EQ(DarkFrameBank::create({files[0], files[1]}, model).groups.size(), 1u);
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::create({}, model), "an empty bank");
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::create({files[0], files[1], files[3]}, model),
                             "gain 8, exposure 0.01 s has one frame");
    // Another sensor: another black level, then another size.
    const auto writeOther = [&](const std::string& name, Size otherSize, double black) {
        SensorParams p = params;
        p.blackLevel = Vec4d::all(black);
        p.noise = NoiseModel(p.noise.alpha, p.noise.sigmaD2, p.noise.sigmaR2);
        const SensorSimulator other(p, otherSize);
        Mat raw;
        other.capture(Mat::zeros(otherSize, CV_32FC1), 2.0, 1.0, 5, 0, raw);
        MosaicMetadata meta;
        meta.format = other.rawFormat(2.0);
        writeMosaic(dir + name, raw, meta);
        return String(dir + name);
    };
    EXPECT_CV_ERROR_CONTAINS(
        DarkFrameBank::create({files[0], files[1], writeOther("/black.png", size, 64)}, model),
        "black 64/64/64/64");
    EXPECT_CV_ERROR_CONTAINS(
        DarkFrameBank::create(
            {files[0], files[1], writeOther("/size.png", Size(16, 24), params.blackLevel[0])}, model),
        "16x24");
}

//! A small bank in `dir`: two gains of three mosaic files each, with sidecars.
DarkFrameBank smallBank(const std::string& dir, std::vector<String>* files = nullptr)
{
    const Size size(32, 24);
    const SensorSimulator sensor(test::darkComponentSensorParams(size, 0.14, 3), size);
    std::vector<String> written;
    for (double gain : {1.0, 4.0})
        for (int t = 0; t < 3; ++t) {
            Mat raw;
            sensor.capture(Mat::zeros(size, CV_32FC1), gain, 1.0, 7, t + 10 * static_cast<int>(gain), raw);
            MosaicMetadata meta;
            meta.format = sensor.rawFormat(gain);
            const std::string path = dir + format("/g%g_%d.png", gain, t);
            writeMosaic(path, raw, meta);
            written.push_back(path);
        }
    if (files)
        *files = written;
    return DarkFrameBank::createFromFolder(dir, NoiseModel());
}

void expectSameBank(const DarkFrameBank& a, const DarkFrameBank& b)
{
    ASSERT_EQ(a.groups.size(), b.groups.size());
    EXPECT_EQ(a.size, b.size);
    EXPECT_EQ(a.format.blackLevel, b.format.blackLevel);
    for (size_t i = 0; i < a.groups.size(); ++i) {
        const DarkFrameGroup &x = a.groups[i], &y = b.groups[i];
        EXPECT_EQ(x.gain, y.gain);
        EXPECT_EQ(x.exposureTime, y.exposureTime);
        ASSERT_EQ(x.files.size(), y.files.size());
        for (size_t f = 0; f < x.files.size(); ++f)
            EXPECT_TRUE(std::filesystem::equivalent(std::string(x.files[f]), std::string(y.files[f])));
        EXPECT_EQ(x.fileBytes, y.fileBytes);
        const DarkFrameStatistics &s = x.statistics, &t = y.statistics;
        EXPECT_EQ(s.frames, t.frames);
        EXPECT_EQ(s.degreesOfFreedom, t.degreesOfFreedom);
        EXPECT_EQ(s.level, t.level);
        EXPECT_EQ(s.temporalVariance, t.temporalVariance);
        EXPECT_EQ(s.rowNoiseVariance, t.rowNoiseVariance);
        EXPECT_EQ(s.meanVariance, t.meanVariance);
        EXPECT_EQ(s.patternVariance, t.patternVariance);
        EXPECT_EQ(cv::norm(s.pattern, t.pattern, NORM_INF), 0);
        EXPECT_EQ(cv::norm(s.rowVariance, t.rowVariance, NORM_INF), 0);
        EXPECT_EQ(s.noisyPixels, t.noisyPixels);
        EXPECT_EQ(s.noisyVariance, t.noisyVariance);
    }
}

std::set<std::string> filesOf(const std::string& dir)
{
    std::set<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir))
        names.insert(e.path().filename().string());
    return names;
}

/* A bank saved beside its frames loads as it was saved, in YAML and JSON, to the bit (the doubles are written
 * with 17 digits, the pattern as a TIFF); moved with its frames it still finds them; saved again it keeps one
 * pattern image per group; a frame replaced since is refused when it is read. */
TEST(DarkFrameBank, savesBesideItsFramesAndLoadsToTheBit)
{
    const std::string dir = test::makeTempDir("dark_bank_save");
    std::vector<String> files;
    DarkFrameBank bank = smallBank(dir, &files);
    ASSERT_EQ(bank.groups.size(), 2u);
    EXPECT_EQ(bank.groups[0].files.size(), 3u) << "the sidecars are not frames";
    for (const char* name : {"/bank.yml", "/bank.json"}) {
        bank.save(dir + name);
        EXPECT_EQ(bank.path, dir + name);
        const DarkFrameBank loaded = DarkFrameBank::load(dir + name);
        EXPECT_EQ(loaded.path, dir + name);
        expectSameBank(bank, loaded);
    }
    // The file names its frames relative to its folder: the folder moves as a whole.
    std::ifstream in(dir + "/bank.yml");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text.find(dir), std::string::npos) << text.substr(0, 400);
    const std::string moved = dir + "_moved";
    std::filesystem::remove_all(moved);
    std::filesystem::rename(dir, moved);
    const DarkFrameBank there = DarkFrameBank::load(moved + "/bank.yml");
    Mat direct;
    readMosaic(moved + "/g4_2.png", direct);
    EXPECT_EQ(cv::norm(there.readFrame(1, 2), direct, NORM_INF), 0);
    EXPECT_CV_ERROR_CONTAINS(bank.readFrame(1, 2), "is missing");
    // Saved again with another pattern: the file names the new image and the old one goes.
    DarkFrameBank changed = there;
    changed.groups[0].statistics.pattern += 1;
    const size_t before = filesOf(moved).size();
    changed.save(moved + "/bank.yml");
    EXPECT_EQ(filesOf(moved).size(), before);
    expectSameBank(changed, DarkFrameBank::load(moved + "/bank.yml"));
    // A frame whose file changed since is refused where it is read, by name.
    std::ofstream(moved + "/g1_1.png", std::ios::app) << "appended";
    EXPECT_CV_ERROR_CONTAINS(there.readFrame(0, 1), "g1_1.png' is");
    std::filesystem::remove_all(moved);
}

} // namespace
} // namespace rawgment
} // namespace cv
