// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A bank of dark frames (opencv2/rawgment/dark_frames.hpp): made from files by gain and exposure, saved
// beside its frames and loaded with every field checked, its nearest group, its refusals. What the statistics
// estimate is tested against the simulator's truth in test_dark_frames_internals.cpp.
#include "test_common.hpp"

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/cpu.hpp>
#include <opencv2/rawgment/dark_frames.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/raw_io.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
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
    // One frame twice (another spelling of its path) made a group of temporal variance 0.
    const String respelt = dir + "/./dark_00.png";
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::create({files[0], files[1], respelt}, model),
                             "entries 1 ('" + files[0] + "') and 3 ('" + respelt + "') are one file");
    // A frame the statistics refuse (a float frame among integer ones) is named by its file.
    Mat floats;
    sensor.capture(Mat::zeros(size, CV_32FC1), 2.0, 1.0, 99, 0, floats);
    floats.convertTo(floats, CV_32F);
    floats.at<float>(3, 3) = std::numeric_limits<float>::quiet_NaN();
    MosaicMetadata floatMeta;
    floatMeta.format = sensor.rawFormat(2.0);
    writeMosaic(dir + "/nan.npy", floats, floatMeta);
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::create({files[0], files[1], dir + "/nan.npy"}, model),
                             "'" + dir + "/nan.npy'");
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
DarkFrameBank smallBank(const std::string& dir, std::vector<String>* files = nullptr,
                        const char* extension = "png")
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
            const std::string path = dir + format("/g%g_%d.%s", gain, t, extension);
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
        EXPECT_EQ(x.fingerprints, y.fingerprints);
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

std::string textOf(const std::string& path)
{
    std::ifstream in(path);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

//! FNV-1a 64 as its definition gives it, byte by byte (http://www.isthe.com/chongo/tech/comp/fnv/).
std::string fnv1a64Of(const std::string& bytes)
{
    uint64_t h = 14695981039346656037ull;
    for (unsigned char c : bytes)
        h = (h ^ c) * 1099511628211ull;
    return format("%016llx", static_cast<unsigned long long>(h));
}

/* Each frame's content is recorded: a frame replaced after saving by a flat frame of the same size (an .npy,
 * whose size follows from its shape alone) is refused where a step would draw it, naming the file; a bank of
 * format_version 1, which recorded sizes alone, loads and holds its frames to their sizes, as it stated. */
TEST(DarkFrameBank, aFrameReplacedByAnotherOfItsSizeIsRefusedWhereItIsRead)
{
    const std::string dir = test::makeTempDir("dark_bank_fingerprints");
    std::vector<String> files;
    DarkFrameBank bank = smallBank(dir, &files, "npy");
    ASSERT_EQ(bank.groups.size(), 2u);
    for (const DarkFrameGroup& g : bank.groups) {
        ASSERT_EQ(g.fingerprints.size(), g.files.size());
        for (size_t f = 0; f < g.files.size(); ++f)
            EXPECT_EQ(g.fingerprints[f], fnv1a64Of(textOf(g.files[f]))) << g.files[f];
    }
    bank.save(dir + "/bank.yml");
    EXPECT_NE(textOf(dir + "/bank.yml").find("format_version: 2"), std::string::npos);
    const DarkFrameBank loaded = DarkFrameBank::load(dir + "/bank.yml");
    expectSameBank(bank, loaded);

    DarkFrameBank version1 = bank;
    for (DarkFrameGroup& g : version1.groups)
        g.fingerprints.clear();
    version1.save(dir + "/bank_v1.yml");
    const std::string v1Text = textOf(dir + "/bank_v1.yml");
    EXPECT_NE(v1Text.find("format_version: 1"), std::string::npos);
    EXPECT_EQ(v1Text.find("fingerprints"), std::string::npos);
    const DarkFrameBank oldBank = DarkFrameBank::load(dir + "/bank_v1.yml");
    EXPECT_TRUE(oldBank.groups[1].fingerprints.empty());

    // The case: flat 4000 DN frames of the same size, written over a saved bank's frames.
    const String replaced = bank.groups[1].files[1];
    MosaicMetadata meta;
    Mat original;
    meta = readMosaic(replaced, original);
    const double bytes = bank.groups[1].fileBytes[1];
    std::filesystem::remove(std::string(replaced));
    writeMosaic(replaced, Mat(original.size(), CV_16UC1, Scalar(4000)), meta);
    ASSERT_EQ(double(std::filesystem::file_size(std::string(replaced))), bytes) << "the test's premise";
    EXPECT_CV_ERROR_CONTAINS(loaded.readFrame(1, 1), "holds other bytes than when the bank was made");
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::load(dir + "/bank.yml").readFrame(1, 1), replaced);
    EXPECT_EQ(cv::norm(loaded.readFrame(1, 0), Mat(original.size(), CV_16UC1, Scalar(4000)), NORM_INF) > 0,
              true)
        << "the frames not replaced are still drawn";
    EXPECT_EQ(cv::mean(oldBank.readFrame(1, 1))[0], 4000) << "version 1 holds a frame to its size alone";

    // Every group or none has fingerprints: a bank half of version 1 is not one any file could hold.
    DarkFrameBank mixed = bank;
    mixed.groups[0].fingerprints.clear();
    EXPECT_CV_ERROR_CONTAINS(mixed.validate(), "every group or none");
    DarkFrameBank bad = bank;
    bad.groups[0].fingerprints[0] = "not hex";
    EXPECT_CV_ERROR_CONTAINS(bad.validate(), "16 lower-case hex digits");
    std::filesystem::remove_all(dir);
}

/* Each edit of a saved bank's file that save() would not write is refused on load, naming what is wrong; the
 * file as saved loads. */
TEST(DarkFrameBank, loadRefusesWhatSaveDoesNotWrite)
{
    const std::string dir = test::makeTempDir("dark_bank_refusals");
    DarkFrameBank bank = smallBank(dir);
    bank.save(dir + "/bank.yml");
    const std::string text = textOf(dir + "/bank.yml");
    const struct
    {
        std::string from, to, error;
    } edits[] = {
        {"format_version: 2", "format_version: 3", "format_version 3 is not supported"},
        {"format_version: 2", "format_version: 0", "format_version 0 is not supported"},
        {"format_version: 2", "format_version: 1", "'fingerprints'"},
        {"fingerprints:\n            - \"", "fingerprints:\n            - \"0", "16 lower-case hex digits"},
        {"   width: 32", "   widht: 32", "'widht'"},
        {"   width: 32", "   width: -32", "width and height must be > 0"},
        {"-\n         gain: 1.", "-\n         gain: -1.", "gain must be finite and > 0"},
        {"exposure_time: 0.", "exposure_time: .nan", "exposure time"},
        {"         degrees_of_freedom:", "         frames_per_gain: 1\n         degrees_of_freedom:",
         "'frames_per_gain'"},
        {"g1_1.png", "/dev/zero", ""},
        {"temporal_variance: [ ", "temporal_variance: [ -", "a variance finite and >= 0"},
        {"level: [ ", "level: [ .inf, ", "'level' must be a list of 4"},
        {".dark_frame_pattern_0.", ".dark_frame_pattern_1.", "groups[0].pattern"},
        {"fnv1a64: \"", "fnv1a64: \"0", "does not match the file naming it"},
        {"row_variance: [ ", "row_variance: [ 1., ", "'row_variance' has 49 values, more than 48"},
        {"noisy_pixels: [", "noisy_pixels: [ 40., 1., 3.,", "(40, 1) is not a pixel of the 32x24 frames"},
        {"noisy_pixels: [", "noisy_pixels: [ 1., 1.,", "x, y and variance per pixel"},
    };
    for (const auto& e : edits) {
        SCOPED_TRACE(e.from + " -> " + e.to);
        std::string edited = text;
        const size_t at = edited.find(e.from);
        ASSERT_NE(at, std::string::npos) << text.substr(0, 600);
        edited.replace(at, e.from.size(), e.to);
        std::ofstream(dir + "/edited.yml", std::ios::trunc) << edited;
        if (e.error.empty()) {
            // A frame path is not read on load: where a step reads it, a device is refused by name.
            const DarkFrameBank loaded = DarkFrameBank::load(dir + "/edited.yml");
            EXPECT_CV_ERROR_CONTAINS(loaded.readFrame(0, 1), "/dev/zero");
            continue;
        }
        EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::load(dir + "/edited.yml"), e.error);
    }
    // A group of one frame, though its statistics are consistent otherwise.
    DarkFrameBank one = bank;
    one.groups[0].files.resize(1);
    one.groups[0].fileBytes.resize(1);
    one.groups[0].fingerprints.resize(1);
    one.groups[0].statistics.frames = 1;
    EXPECT_CV_ERROR_CONTAINS(one.save(dir + "/one.yml"), "a group needs at least two frames");
    EXPECT_FALSE(std::filesystem::exists(dir + "/one.yml"));
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank().save(dir + "/empty.yml"), "an empty bank");
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::createFromFolder(dir + "/none", NoiseModel()), "is not a folder");
    const std::string empty = test::makeTempDir("dark_bank_refusals_empty");
    EXPECT_CV_ERROR_CONTAINS(DarkFrameBank::createFromFolder(empty, NoiseModel()), "holds no dark frames");
    EXPECT_NO_THROW(DarkFrameBank::load(dir + "/bank.yml"));
}

/* A simulated sensor whose dark frames hold what the parametric components do (row noise, dark shading,
 * Tukey tails) and what they do not (hot pixels, 1% noisy pixels), its bank of 16 frames per gain at gains 1
 * and 4 saved in `dir`, and captures of any other frames. */
constexpr int kBankFrames = 16;

struct BankedSensor
{
    Size size{96, 64};
    SensorParams params;
    std::unique_ptr<SensorSimulator> sensor;
    String bankPath;
    Mat defects;
    explicit BankedSensor(const std::string& dir)
    {
        params = test::darkComponentSensorParams(size, -0.1, 5);
        params.dsnu = 0.3;
        params.hotPixelFraction = 0.002;
        params.noisyPixelFraction = 0.01;
        params.noisyPixelVariance = 100;
        sensor.reset(new SensorSimulator(params, size));
        Mat prnu, dsnu;
        sensor->fixedPattern(prnu, dsnu, defects);
        std::vector<String> files;
        for (double gain : {1.0, 4.0})
            for (int t = 0; t < kBankFrames; ++t) {
                MosaicMetadata meta;
                meta.format = sensor->rawFormat(gain);
                const std::string path = dir + format("/dark_g%g_%02d.png", gain, t);
                writeMosaic(path, capture(0.0, gain, 1000 + t), meta);
                files.push_back(path);
            }
        DarkFrameBank bank = DarkFrameBank::create(files, NoiseModel());
        bankPath = dir + "/bank.yml";
        bank.save(bankPath);
    }
    Mat capture(double meanAtUnitGain, double gain, int frame) const
    {
        Mat raw;
        sensor->capture(Mat(size, CV_32FC1, Scalar(meanAtUnitGain)), gain, 1.0, 77, frame, raw);
        return raw;
    }
};

/* Over a stack of frames, per row: the variance of the row's mean over the pixels `keep` marks (the row part,
 * with 1/n of the pixel part) and the mean over those pixels of their variance about the row's mean (the
 * pixel part). One value per row for each, so that the rows' shared offsets do not pass for independent
 * samples. */
void rowAndPixelParts(const std::vector<Mat>& frames, const Mat& keep, std::vector<double>& rowPart,
                      std::vector<double>& pixelPart)
{
    const int n = static_cast<int>(frames.size());
    rowPart.clear();
    pixelPart.clear();
    for (int r = 0; r < frames[0].rows; ++r) {
        std::vector<double> means;
        for (const Mat& f : frames) {
            double sum = 0, count = 0;
            for (int c = 0; c < f.cols; ++c)
                if (keep.at<uchar>(r, c)) {
                    sum += f.at<ushort>(r, c);
                    count += 1;
                }
            means.push_back(sum / count);
        }
        double s = 0, s2 = 0;
        for (double m : means) {
            s += m;
            s2 += m * m;
        }
        rowPart.push_back((s2 - s * s / n) / (n - 1));
        double sum = 0, count = 0;
        for (int c = 0; c < frames[0].cols; ++c) {
            if (!keep.at<uchar>(r, c))
                continue;
            double p = 0, p2 = 0;
            for (int i = 0; i < n; ++i) {
                const double v =
                    frames[static_cast<size_t>(i)].at<ushort>(r, c) - means[static_cast<size_t>(i)];
                p += v;
                p2 += v * v;
            }
            sum += (p2 - p * p / n) / (n - 1);
            count += 1;
        }
        pixelPart.push_back(sum / count);
    }
}

using test::meanAndStandardError;

/* A noise step with a bank, as the statistics below see it: its input gain, and the share of the input's row
 * part and pixel part its output keeps (0 where the test does not know it exactly). */
struct BankedStep
{
    const char* name;
    double inputGain;
    double rowKeep, pixelKeep;
    std::function<Mat(const Mat& in, const RawFormat& format, const NoiseOptions& options, uint64 seed,
                      AugmentReport& report)>
        run;
};

std::vector<BankedStep> bankedSteps(const NoiseModel& model)
{
    std::vector<BankedStep> steps;
    const ColorJitter jitter = ColorJitter::exposureChange(1.0 / 8, 4.0);
    const double k = jitter.contrast[0];
    steps.push_back(
        {"colour jitter to gain 4 at k = 1/2", 1.0, k * k, k * k,
         [=](const Mat& in, const RawFormat& f, const NoiseOptions& o, uint64 seed, AugmentReport& r) {
             Mat out;
             RawFormat outFormat;
             colorJitter(in, f, model, jitter, o, seed, out, outFormat, r);
             return out;
         }});
    // Along the rows: every tap in its row, so the row part is kept whole and the pixel part sum w^2 of it.
    const Mat kernel = linearMotionKernel(5, 0);
    Mat w;
    kernel.convertTo(w, CV_64F, 1 / sum(kernel)[0]);
    steps.push_back(
        {"motion blur of 5 pixels along the rows", 4.0, 1.0, w.dot(w),
         [=](const Mat& in, const RawFormat& f, const NoiseOptions& o, uint64 seed, AugmentReport& r) {
             Mat out;
             motionBlur(in, f, model, kernel, o, seed, out, &r);
             return out;
         }});
    // Bilinear weights differ from pixel to pixel: only ACCOUNT_PRIOR's match is checked.
    steps.push_back(
        {"scaling by 1.25", 4.0, 0, 0,
         [=](const Mat& in, const RawFormat& f, const NoiseOptions& o, uint64 seed, AugmentReport& r) {
             Mat out;
             scaleMosaic(in, f, model, 1.25, o, seed, out, &r);
             return out;
         }});
    return steps;
}

/* Every noise step with a bank of the same sensor (tied), on dark frames: the input's read noise, as the step
 * scales it, is already part of the target's. ACCOUNT_PRIOR adds only what the target lacks, so its outputs'
 * row part and pixel part are the independent target captures'; IGNORE_PRIOR adds whole dark frames on top,
 * too much by what the step kept of the input's (a jitter's k^2 v_s). A whole frame drawn from M frames
 * varies as their population, (M - 1)/M of the target's variance (1 - 1/16 here: 0.7 DN^2 of the pixel part),
 * which its expectation includes; a frame less their mean, times sqrt(M / (M - 1)), varies as their unbiased
 * sample variance. Differences are taken per row (32 outputs each, the 84 columns away from the edges, where
 * clamped taps weigh otherwise), and each claim holds within 3 standard errors of the 64 rows' mean. The
 * output's rounding adds 1/12 DN^2 to both methods' pixel part: the target's own rounding is in the frames'
 * variance, the input's in what the step kept. */
TEST(DarkFrameBank, ignoringThePriorAddsWhatTheStepKeptOfTheInputsReadNoiseAndAccountingDoesNot)
{
    const std::string dir = test::makeTempDir("dark_bank_excess");
    const BankedSensor s(dir);
    // No shot noise: these dark frames hold no photons, which Eq. 13 would read into their positive values.
    NoiseModel model = s.sensor->effectiveModel();
    model.alpha = 0;
    const int n = 32;
    // Hot pixels hold a fixed value near white: Eq. 13 reads them as bright pixels, whose shot noise is
    // another test's.
    Mat keep = s.defects != 1;
    keep.colRange(0, 6).setTo(0);
    keep.colRange(keep.cols - 6, keep.cols).setTo(0);
    for (const BankedStep& step : bankedSteps(model)) {
        SCOPED_TRACE(step.name);
        std::vector<Mat> inputs, targets, account, ignore;
        int64 readBrightening = 0;
        for (int i = 0; i < n; ++i) {
            inputs.push_back(s.capture(0.0, step.inputGain, 2000 + i));
            targets.push_back(s.capture(0.0, 4.0, 3000 + i));
            for (NoiseAlignment a : {NoiseAlignment::ACCOUNT_PRIOR, NoiseAlignment::IGNORE_PRIOR}) {
                NoiseOptions options(a);
                options.darkBank = s.bankPath;
                options.darkBankTied =
                    true; // the inputs are the bank's sensor's: its noisy pixels are theirs
                AugmentReport report;
                const Mat out =
                    step.run(inputs.back(), s.sensor->rawFormat(step.inputGain), options, 500 + i, report);
                (a == NoiseAlignment::ACCOUNT_PRIOR ? account : ignore).push_back(out);
                if (a == NoiseAlignment::ACCOUNT_PRIOR)
                    readBrightening += report.readBrighteningPixels;
            }
        }
        std::vector<double> parts[4][2]; // input, target, ACCOUNT, IGNORE: row part, pixel part
        const std::vector<Mat>* stacks[4] = {&inputs, &targets, &account, &ignore};
        for (int i = 0; i < 4; ++i)
            rowAndPixelParts(*stacks[i], keep, parts[i][0], parts[i][1]);
        std::cout << step.name << "\n";
        for (int part = 0; part < 2; ++part) {
            const char* name = part == 0 ? "row part" : "pixel part";
            const double kept = part == 0 ? step.rowKeep : step.pixelKeep;
            // The output's rounding to whole DN adds 1/12 DN^2 to each pixel (1/12n to a row's mean:
            // nothing).
            const double rounding = part == 0 ? 0.0 : 1.0 / 12;
            std::vector<double> accountLess, ignoreLess, ignoreExcess;
            for (size_t r = 0; r < parts[0][part].size(); ++r) {
                accountLess.push_back(parts[2][part][r] - parts[1][part][r] - rounding);
                ignoreLess.push_back(parts[3][part][r] - parts[1][part][r]);
                ignoreExcess.push_back(parts[3][part][r] - parts[1][part][r] * (1 - 1.0 / kBankFrames) -
                                       kept * parts[0][part][r] - rounding);
            }
            double m, se;
            meanAndStandardError(parts[1][part], m, se);
            std::cout << "  " << name << ": target " << m << " +- " << se;
            meanAndStandardError(parts[0][part], m, se);
            std::cout << ", input " << m << " (kept: " << kept * m << ")\n";
            meanAndStandardError(accountLess, m, se);
            std::cout << "    ACCOUNT_PRIOR - target - rounding: " << m << " +- " << se << "\n";
            EXPECT_LT(std::abs(m), 3 * se) << name;
            meanAndStandardError(ignoreLess, m, se);
            std::cout << "    IGNORE_PRIOR - target: " << m << " +- " << se << "\n";
            if (kept == 0)
                continue;
            meanAndStandardError(ignoreExcess, m, se);
            std::cout << "    IGNORE_PRIOR - target (M - 1) / M - kept - rounding: " << m << " +- " << se
                      << "\n";
            EXPECT_LT(std::abs(m), 3 * se) << name;
        }
        std::cout << "  read-brightening pixels per output: " << readBrightening / n << "\n";
    }
}

/* The same seed gives the same bits with a bank on every instruction-set path and thread count, for 16-bit
 * and float inputs, tied, untied and ignoring the prior, on a crop at an odd sensor origin; another seed
 * draws other frames. A mosaic outside the frames, or at another CFA phase, is refused. */
TEST(DarkFrameBank, theSameSeedGivesTheSameBitsOnEveryPathAndThreadCount)
{
    const std::string dir = test::makeTempDir("dark_bank_bits");
    const BankedSensor s(dir);
    const NoiseModel model = s.sensor->effectiveModel();
    const ColorJitter jitter = ColorJitter::exposureChange(0.3, 2.0);
    const Rect crop(3, 2, 61, 40);
    const RawFormat format = s.sensor->rawFormat(1.0).cropped(crop.y, crop.x);
    const Mat whole = s.capture(400.0, 1.0, 9);
    Mat input16 = whole(crop).clone(), input32;
    input16.convertTo(input32, CV_32F);
    const int threads = getNumThreads();
    for (const Mat& input : {input16, input32})
        for (NoiseAlignment a : {NoiseAlignment::ACCOUNT_PRIOR, NoiseAlignment::IGNORE_PRIOR})
            for (bool tied : {false, true}) {
                SCOPED_TRACE(cv::format("depth %d, alignment %d, tied %d", input.depth(), int(a), int(tied)));
                NoiseOptions options(a);
                options.darkBank = s.bankPath;
                options.darkBankTied = tied;
                Mat first;
                for (CpuPath path : availableCpuPaths())
                    for (int t : {1, 2}) {
                        setCpuPath(path);
                        setNumThreads(t);
                        Mat out;
                        RawFormat outFormat;
                        AugmentReport report;
                        colorJitter(input, format, model, jitter, options, 21, out, outFormat, report);
                        if (first.empty())
                            first = out;
                        EXPECT_EQ(cv::norm(out, first, NORM_INF), 0)
                            << cpuPathName(path) << ", " << t << " threads";
                    }
                setCpuPath(CpuPath::AUTO);
                setNumThreads(threads);
                Mat other;
                RawFormat outFormat;
                AugmentReport report;
                colorJitter(input, format, model, jitter, options, 22, other, outFormat, report);
                EXPECT_GT(cv::norm(other, first, NORM_INF), 0);
            }
    NoiseOptions options;
    options.darkBank = s.bankPath;
    Mat out;
    RawFormat outFormat;
    AugmentReport report;
    EXPECT_CV_ERROR_CONTAINS(colorJitter(input16, s.sensor->rawFormat(1.0).cropped(crop.y, 60), model, jitter,
                                         options, 1, out, outFormat, report),
                             "lies outside the dark-frame bank's 96x64 frames");
    RawFormat shifted = format;
    shifted.sensorOrigin.x += 1;
    EXPECT_CV_ERROR_CONTAINS(colorJitter(input16, shifted, model, jitter, options, 1, out, outFormat, report),
                             "another sensor, or a crop without its offset");
    EXPECT_CV_ERROR_CONTAINS(colorJitter(input16, format, model, ColorJitter::exposureChange(0.3, 8.0),
                                         options, 1, out, outFormat, report),
                             "outside the bank's gains [1, 4]");
    options.darkBankTied = true;
    EXPECT_CV_ERROR_CONTAINS(colorJitter(input16, s.sensor->rawFormat(2.0).cropped(crop.y, crop.x), model,
                                         ColorJitter::exposureChange(0.3, 2.0), options, 1, out, outFormat,
                                         report),
                             "no frames at the input's gain 2");
    // Tied to another sensor's levels: black 512 and white 16383 against the frames' own (#79 item 8).
    RawFormat otherSensor = format;
    otherSensor.blackLevel = Vec4d::all(512);
    otherSensor.whiteLevel = 16383;
    EXPECT_CV_ERROR_CONTAINS(
        colorJitter(input16, otherSensor, model, jitter, options, 1, out, outFormat, report),
        "holds its own sensor's frames");
    options.darkBankTied = false;
    EXPECT_NO_THROW(colorJitter(input16, otherSensor, model, jitter, options, 1, out, outFormat, report));
    options.darkBankTied = true;
    options.darkBank = dir + "/missing.yml";
    EXPECT_CV_ERROR_CONTAINS(colorJitter(input16, format, model, jitter, options, 1, out, outFormat, report),
                             "missing.yml' is missing");
    // NONE reads no bank, even a missing one; an identity step neither.
    options.alignment = NoiseAlignment::NONE;
    EXPECT_NO_THROW(colorJitter(input16, format, model, jitter, options, 1, out, outFormat, report));
}

} // namespace
} // namespace rawgment
} // namespace cv
