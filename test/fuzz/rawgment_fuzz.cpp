// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A mutation fuzzer for every file reader of the module and the apps: it mutates valid files (made by
// the module's own writers, plus the files of a corpus folder) for a bounded time and fails on anything
// but a clean rejection: a crash or a sanitizer report (the process dies), an exception other than the
// reader's documented one, an accepted file that breaks the reader's promises, or an input that takes
// longer than a stated time. The allocation cap is the sanitizer's (max_allocation_size_mb, set by the
// test). Deterministic: a seed and an iteration number name an input; --replay reads one file.
#include "chart_patches.hpp"
#include "differential.hpp"
#include "flow_common.hpp"
#include "fuzz_target.hpp"
#include "pipeline.hpp"

#include <opencv2/core/utils/logger.hpp>
#include <opencv2/rawgment.hpp>

#include <cxxabi.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
#endif

namespace rawgment_fuzz {

std::string readBytes(const std::string& path)
{
    std::ifstream f(path, std::ios::binary);
    if (!f)
        throw std::runtime_error("cannot read '" + path + "'");
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

} // namespace rawgment_fuzz

namespace {

using namespace cv::rawgment;
namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------------
// Files.

using rawgment_fuzz::readBytes;

void writeBytes(const std::string& path, const std::string& bytes)
{
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    f.close();
    if (!f)
        throw std::runtime_error("cannot write '" + path + "'");
}

using rawgment_fuzz::Errors;
using rawgment_fuzz::Target;

//! The YAML and JSON targets (by their input's extension), whose accepted inputs an independent parse must
//! agree with.
bool checkedDifferentially(const Target& t)
{
    const size_t dot = t.inputName.find_last_of('.');
    const std::string ext = dot == std::string::npos ? std::string() : t.inputName.substr(dot);
    return ext == ".yml" || ext == ".yaml" || ext == ".json";
}

std::string checkModel(const NoiseModel& m)
{
    if (!(std::isfinite(m.alpha) && m.alpha >= 0 && std::isfinite(m.sigmaD2) && m.sigmaD2 >= 0 &&
          std::isfinite(m.sigmaR2) && m.sigmaR2 >= 0))
        return cv::format("accepted a model with alpha %g, sigma_d^2 %g, sigma_r^2 %g", m.alpha, m.sigmaD2,
                          m.sigmaR2);
    if (!(std::isfinite(m.rowSigmaD2) && m.rowSigmaD2 >= 0 && std::isfinite(m.rowSigmaR2) &&
          m.rowSigmaR2 >= 0))
        return cv::format("accepted row noise %g, %g", m.rowSigmaD2, m.rowSigmaR2);
    if (m.tukeyRead && !(m.tukeyLambda >= -0.2 && m.tukeyLambda <= 1))
        return cv::format("accepted a Tukey lambda of %g", m.tukeyLambda);
    if (m.hasDarkShading() && (m.darkShadingPerGain.type() != CV_32FC1 ||
                               m.darkShadingOffset.size() != m.darkShadingPerGain.size() ||
                               !cv::checkRange(m.darkShadingPerGain) || !cv::checkRange(m.darkShadingOffset)))
        return "accepted dark-shading maps that are not finite CV_32FC1 maps of one size";
    return std::string();
}

std::string checkFormat(const RawFormat& f)
{
    try {
        f.validate();
    } catch (const cv::Exception& e) {
        return "accepted a format that does not validate: " + e.err;
    }
    return std::string();
}

std::string checkScene(const Scene& s)
{
    if (!std::isfinite(s.scale) || s.scale <= 0)
        return cv::format("accepted a scene with scale %g", s.scale);
    if (!s.motionKernel.empty() &&
        (s.motionKernel.rows > MAX_MOTION_LENGTH || s.motionKernel.cols > MAX_MOTION_LENGTH ||
         !cv::checkRange(s.motionKernel)))
        return cv::format("accepted a %dx%d or non-finite motion kernel", s.motionKernel.cols,
                          s.motionKernel.rows);
    return std::string();
}

cv::Mat seedMosaic(cv::Size size, double white, uint64_t seed)
{
    cv::Mat m(size, CV_16UC1);
    cv::RNG rng(seed);
    rng.fill(m, cv::RNG::UNIFORM, 64, white);
    return m;
}

std::vector<std::string> textSeeds(const std::string& work, const std::string& stem,
                                   const std::function<void(const std::string&)>& save)
{
    std::vector<std::string> seeds;
    for (const char* ext : {".yml", ".json"}) {
        const std::string path = work + "/seed_" + stem + ext;
        fs::remove(path);
        save(path);
        seeds.push_back(readBytes(path));
    }
    return seeds;
}

NoiseModel seedModel()
{
    return NoiseModel(1.7, 2.5, 0.8);
}

//! seedModel() with every dark-frame component; its maps are saved beside the seeds (and so beside the
//! mutated input, which names them).
NoiseModel seedDarkModel()
{
    NoiseModel m = seedModel();
    m.rowSigmaD2 = 0.2;
    m.rowSigmaR2 = 0.4;
    m.tukeyRead = true;
    m.tukeyLambda = -0.05;
    m.darkShadingPerGain = cv::Mat(6, 8, CV_32FC1, cv::Scalar(0.5));
    m.darkShadingOffset = cv::Mat(6, 8, CV_32FC1, cv::Scalar(-1.25));
    return m;
}

std::vector<NoiseSample> seedSamples()
{
    // Three gains, means spread over the range, variances on the model's lines with a deterministic
    // scatter: a report with every field filled.
    const NoiseModel model = seedModel();
    std::vector<NoiseSample> samples;
    cv::RNG rng(5);
    for (double gain : {1.0, 2.0, 4.0})
        for (int k = 0; k < 120; ++k) {
            NoiseSample s;
            s.gain = gain;
            s.mean = 20.0 + 30.0 * k;
            s.variance = model.variance(s.mean, gain) * (1.0 + 0.05 * rng.gaussian(1.0));
            s.dof = 99;
            s.channel = k % 4;
            samples.push_back(s);
        }
    return samples;
}

Scene seedScene()
{
    Scene scene;
    scene.shift = cv::Point(4, -2);
    scene.scale = 1.02;
    scene.jitter.contrast = cv::Vec4d(0.3, 0.31, 0.29, 0.3);
    scene.jitter.brightness = 2.5;
    scene.jitter.gainRatio = 2.0;
    scene.motionKernel = linearMotionKernel(5, 30);
    return scene;
}

std::vector<Target> targets(const std::string& dataDir)
{
    std::vector<Target> t;
    t.push_back({"model", "input.yml", false, Errors::LIBRARY,
                 [](const std::string& work) {
                     return textSeeds(work, "model", [](const std::string& p) { seedModel().save(p); });
                 },
                 [](const std::string& in) { return checkModel(NoiseModel::load(in)); }});
    t.push_back({"dark_model", "input.yml", false, Errors::LIBRARY,
                 [](const std::string& work) {
                     return textSeeds(work, "dark_model",
                                      [](const std::string& p) { seedDarkModel().save(p); });
                 },
                 [](const std::string& in) { return checkModel(NoiseModel::load(in)); }});
    t.push_back(
        {"camera_profiles", "input.json", false, Errors::LIBRARY,
         [](const std::string&) {
             // darktable's layout: two makers, a skipped profile, negative offsets, comments.
             RawFormat format;
             format.blackLevel = cv::Vec4d(64, 64, 64, 64);
             format.whiteLevel = 4095;
             const std::string own =
                 darktableNoiseProfiles(seedModel(), format, 100, {100, 400, 1600}, "Maker", "Own");
             const std::string measured =
                 "{\"version\": 0, \"noiseprofiles\": [\n"
                 " {\"maker\": \"A\", \"models\": [{\"comment\": \"c\", \"model\": \"M 1\", \"profiles\": [\n"
                 "  {\"name\": \"M 1 iso 100\", \"iso\": 100, \"a\": [4.6e-06, 2.5e-06, 3.3e-06], \"b\": "
                 "[2.0e-07, -1.2e-07, -1.0e-07]},\n"
                 "  {\"name\": \"M 1 iso 200\", \"iso\": 200, \"skip\": true, \"a\": [1, 1, 1], \"b\": [0, "
                 "0, "
                 "0]},\n"
                 "  {\"name\": \"M 1 iso 800\", \"iso\": 800, \"a\": [2.3e-05, 1.3e-05, 1.8e-05], \"b\": "
                 "[1.4e-06, 3.9e-07, 1.1e-07]}]}]},\n"
                 " {\"maker\": \"B\", \"models\": [{\"model\": \"N\", \"profiles\": []}]}]}\n";
             return std::vector<std::string>{own, measured};
         },
         [](const std::string& in) {
             RawFormat format;
             format.whiteLevel = 16383;
             for (const CameraNoiseProfile& cam : readCameraProfiles(in)) {
                 if (!cam.usable()) {
                     if (cam.reason.empty())
                         return "refused camera '" + cam.name() + "' without a reason";
                     continue;
                 }
                 const std::string bad = checkModel(cam.modelFor(format));
                 if (!bad.empty())
                     return cam.name() + ": " + bad;
             }
             return std::string();
         }});
    t.push_back({"report", "input.yml", false, Errors::LIBRARY,
                 [](const std::string& work) {
                     const CalibrationReport report = calibrateNoiseModel(seedSamples());
                     return textSeeds(work, "report", [&](const std::string& p) { report.save(p); });
                 },
                 [](const std::string& in) { return checkModel(CalibrationReport::load(in).model); }});
    t.push_back({"policy", "input.yml", false, Errors::LIBRARY,
                 [](const std::string& work) {
                     RandomScenePolicy policy;
                     policy.blurProbability = 1;
                     return textSeeds(work, "policy", [&](const std::string& p) { policy.save(p); });
                 },
                 [](const std::string& in) {
                     const RandomScenePolicy policy = RandomScenePolicy::load(in);
                     // A loaded policy must draw a valid scene, quickly, for a small mosaic.
                     const RawFormat format;
                     const Scene scene = policy.draw(seedMosaic(cv::Size(16, 16), 4000, 1), format, 3);
                     return checkScene(scene);
                 }});
    t.push_back({"scene", "input.yml", false, Errors::APP,
                 [](const std::string&) {
                     std::vector<std::string> seeds;
                     for (int format : {cv::FileStorage::FORMAT_YAML, cv::FileStorage::FORMAT_JSON}) {
                         cv::FileStorage out(format == cv::FileStorage::FORMAT_JSON ? ".json" : ".yml",
                                             cv::FileStorage::WRITE | cv::FileStorage::MEMORY | format);
                         seedScene().write(out, "scene");
                         seeds.push_back(out.releaseAndGetString());
                     }
                     return seeds;
                 },
                 [](const std::string& in) { return checkScene(rawgment_apps::readSceneFile(in)); }});
    t.push_back({"sidecar", "mosaic.png.yml", false, Errors::LIBRARY,
                 [](const std::string& work) {
                     // The mosaic stays; its sidecar is the input.
                     const std::string seedDir = work + "/sidecar_seed";
                     fs::remove_all(seedDir);
                     fs::create_directories(seedDir);
                     MosaicMetadata meta;
                     meta.format.whiteLevel = 4095;
                     meta.format.blackLevel = cv::Vec4d(64, 64, 64, 64);
                     meta.hasScene = true;
                     meta.scene = seedScene();
                     meta.seed = 77;
                     meta.hasCamera = true;
                     meta.camera.make = "Fuzz";
                     meta.camera.iso = 400;
                     meta.camera.exposureTime = 0.01;
                     meta.camera.noiseProfile = {cv::Vec2d(1e-4, 1e-7)};
                     meta.source = "frame_000.dng";
                     const cv::Mat mosaic = seedMosaic(cv::Size(16, 12), 4095, 2);
                     writeMosaic(seedDir + "/mosaic.png", mosaic, meta);
                     fs::copy_file(seedDir + "/mosaic.png", work + "/mosaic.png",
                                   fs::copy_options::overwrite_existing);
                     return std::vector<std::string>{readBytes(seedDir + "/mosaic.png.yml")};
                 },
                 [](const std::string& in) {
                     cv::Mat mosaic;
                     const MosaicMetadata meta = readMosaic(in.substr(0, in.size() - 4), mosaic);
                     std::string why = checkFormat(meta.format);
                     if (why.empty() && meta.hasScene)
                         why = checkScene(meta.scene);
                     return why;
                 }});
    t.push_back({"chart_patches", "input.yml", false, Errors::LIBRARY,
                 [](const std::string& work) {
                     rawgment_helpers::ChartPatches patches;
                     patches.gridCorners = {{0, 0}, {100, 0}, {100, 60}, {0, 60}};
                     patches.squares = {{2, 2, 8, 8}, {20, 2, 8, 8}, {2, 20, 24, 24}};
                     const std::string path = work + "/seed_patches.yml";
                     fs::remove(path);
                     rawgment_helpers::writeChartPatches(path, patches);
                     return std::vector<std::string>{readBytes(path)};
                 },
                 [](const std::string& in) {
                     const rawgment_helpers::ChartPatches p = rawgment_helpers::readChartPatches(in);
                     for (const cv::Rect& r : p.squares)
                         if (r.width <= 0 || r.height <= 0 || r.x < 0 || r.y < 0)
                             return std::string("accepted a square outside the first quadrant");
                     return std::string();
                 }});
    t.push_back({"manifest", "input.yml", false, Errors::APP,
                 [](const std::string& work) {
                     rawgment_helpers::ChartPatches patches;
                     patches.squares = {{2, 2, 8, 8}, {20, 2, 8, 8}};
                     const std::string path = work + "/patches.yml";
                     fs::remove(path);
                     rawgment_helpers::writeChartPatches(path, patches);
                     const std::string yaml =
                         "%YAML:1.0\n---\ncalibration_manifest:\n"
                         "   patches: patches.yml\n"
                         "   bursts:\n"
                         "      - { gain_db: 6., level: 0.3, files: [ a/f0.dng, a/f1.dng, "
                         "a/f2.dng ] }\n"
                         "      - gain_db: 12\n"
                         "        files:\n"
                         "           - b/f0.dng\n"
                         "           - b/f1.dng\n"
                         "           - b/f2.dng\n";
                     const std::string json =
                         "{\n  \"calibration_manifest\": {\n    \"patches\": \"detect\",\n"
                         "    \"bursts\": [ { \"gain_db\": 24.0, \"files\": [ \"c/f0.png\", "
                         "\"c/f1.png\", \"c/f2.png\" ] } ]\n  }\n}\n";
                     const std::string fromIso = "%YAML:1.0\n---\ncalibration_manifest:\n"
                                                 "   patches: none\n   base_iso: 100\n   bursts:\n"
                                                 "      - { files: [ a/f0.dng, a/f1.dng ] }\n"
                                                 "      - { dark: true, files: [ d/f0.dng, d/f1.dng ] }\n";
                     return std::vector<std::string>{yaml, json, fromIso};
                 },
                 [](const std::string& in) {
                     const rawgment_apps::CalibrationManifest m = rawgment_apps::readCalibrationManifest(in);
                     if (m.bursts.empty())
                         return std::string("accepted a manifest without bursts");
                     for (const auto& b : m.bursts)
                         if (b.files.empty() || !std::isfinite(b.gainDb))
                             return std::string("accepted a burst without files or with a non-finite gain");
                     if (m.hasBaseIso && !(m.baseIso > 0 && std::isfinite(m.baseIso)))
                         return std::string("accepted a base ISO that is not finite and positive");
                     if (m.patches != "detect" && m.patches != "none") {
                         std::vector<std::string> notes;
                         rawgment_apps::manifestSquares(m.patches, m.bursts.front().files.front(), 24, notes);
                     }
                     return std::string();
                 }});
    t.push_back(
        {"validation_manifest", "input.yml", false, Errors::APP,
         [](const std::string& work) {
             rawgment_helpers::ChartPatches patches;
             patches.squares = {{2, 2, 8, 8}};
             const std::string path = work + "/patches.yml";
             fs::remove(path);
             rawgment_helpers::writeChartPatches(path, patches);
             const std::string yaml = "%YAML:1.0\n---\nvalidation_manifest:\n"
                                      "   patches: patches.yml\n"
                                      "   gain_db: 12.\n"
                                      "   bright: [ bright/f0.dng, bright/f1.dng, bright/f2.dng ]\n"
                                      "   targets:\n"
                                      "      - { factor: 0.5, files: [ h/f0.dng, h/f1.dng, h/f2.dng ] }\n"
                                      "      - factor: 1.0000000000000001e-01\n"
                                      "        files:\n"
                                      "           - t/f0.dng\n"
                                      "           - t/f1.dng\n";
             const std::string json = "{\n  \"validation_manifest\": {\n    \"bright\": [ \"b/0.png\", "
                                      "\"b/1.png\" ],\n    \"targets\": [ { \"factor\": 0.2, \"files\": "
                                      "[ \"t/0.png\", \"t/1.png\" ] } ]\n  }\n}\n";
             return std::vector<std::string>{yaml, json};
         },
         [](const std::string& in) {
             const rawgment_apps::ValidationManifest m = rawgment_apps::readValidationManifest(in);
             if (m.bright.empty() || m.targets.empty())
                 return std::string("accepted a manifest without a bright burst or targets");
             for (const auto& t : m.targets)
                 if (t.files.empty() || !(t.factor > 0 && t.factor <= 1))
                     return std::string("accepted a target without files or with a factor outside (0, 1]");
             if (m.hasGainDb && !std::isfinite(m.gainDb))
                 return std::string("accepted a non-finite gain");
             if (!m.patches.empty())
                 rawgment_helpers::readChartPatches(m.patches);
             return std::string();
         }});
    t.push_back({"npy", "input.npy", true, Errors::LIBRARY,
                 [](const std::string& work) {
                     // The .npy is the input and its seed's sidecar stays beside it (a seed must be
                     // accepted, so there is one: mutations reach the other dtype through the header).
                     const std::string seedDir = work + "/npy_seed";
                     fs::remove_all(seedDir);
                     fs::create_directories(seedDir);
                     MosaicMetadata meta;
                     meta.format.whiteLevel = 4095;
                     meta.format.blackLevel = cv::Vec4d::all(64);
                     writeMosaic(seedDir + "/u16.npy", seedMosaic(cv::Size(16, 12), 4095, 3), meta);
                     fs::copy_file(seedDir + "/u16.npy.yml", work + "/input.npy.yml",
                                   fs::copy_options::overwrite_existing);
                     return std::vector<std::string>{readBytes(seedDir + "/u16.npy")};
                 },
                 [](const std::string& in) {
                     cv::Mat mosaic;
                     const MosaicMetadata meta = readMosaic(in, mosaic);
                     if (mosaic.size() != meta.size || mosaic.type() != meta.type)
                         return std::string("accepted a .npy whose array is not the one its sidecar states");
                     return checkFormat(meta.format);
                 }});
    for (Target& e : rawgment_fuzz::emva1288Targets())
        t.push_back(std::move(e));
    t.push_back({"raw", "input.dng", true, Errors::LIBRARY,
                 [dataDir](const std::string& work) {
                     std::vector<std::string> seeds;
                     const CfaPattern patterns[] = {CFA_RGGB, CFA_GBRG};
                     for (int k = 0; k < 2; ++k) {
                         RawImage image;
                         image.format.pattern = patterns[k];
                         image.format.whiteLevel = k == 0 ? 65535 : 4095;
                         image.format.blackLevel = cv::Vec4d::all(k == 0 ? 512 : 64);
                         image.mosaic = seedMosaic(k == 0 ? cv::Size(32, 32) : cv::Size(40, 24),
                                                   image.format.whiteLevel, 10 + k);
                         image.iso = 400;
                         image.exposureTime = 0.01;
                         image.make = "Rawgment";
                         image.model = "Fuzz seed";
                         // A NoiseProfile in both layouts, so mutations reach the tag reader.
                         if (k == 0)
                             image.noiseProfile = {cv::Vec2d(2e-5, 1e-8)};
                         else
                             image.noiseProfile = {cv::Vec2d(1e-4, 1e-7), cv::Vec2d(2e-4, 2e-7),
                                                   cv::Vec2d(3e-4, 3e-7)};
                         const std::string path = work + cv::format("/seed_%d.dng", k);
                         fs::remove(path);
                         writeDng(path, image);
                         seeds.push_back(readBytes(path));
                     }
                     // Camera files, when the shared data is there: other containers, other decoders.
                     if (!dataDir.empty() && fs::is_directory(dataDir))
                         for (const char* name : {"RAW_KODAK_DC50.KDC", "RAW_CANON_D30_SRGB.CRW",
                                                  "RAW_NIKON_D1.NEF", "colorchart.dng"})
                             if (fs::exists(dataDir + "/" + name))
                                 seeds.push_back(readBytes(dataDir + "/" + name));
                     return seeds;
                 },
                 [](const std::string& in) {
                     const RawImage image = readRaw(in);
                     if (image.mosaic.empty() || image.mosaic.type() != CV_16UC1 || image.mosaic.rows % 2 ||
                         image.mosaic.cols % 2)
                         return std::string("accepted a file whose mosaic is empty, odd or not 16-bit");
                     for (const cv::Vec2d& so : image.noiseProfile)
                         if (!(so[0] > 0 && so[1] >= 0 && std::isfinite(so[0]) && std::isfinite(so[1])))
                             return std::string("accepted a NoiseProfile DNG forbids");
                     if (!image.noiseProfile.empty() && image.noiseProfile.size() != 1 &&
                         image.noiseProfile.size() != 3)
                         return std::string("accepted a NoiseProfile of neither 1 nor 3 pairs");
                     return checkFormat(image.format);
                 }});
    // A reader with a planted bug, so that a test proves the fuzzer reports what it must: it throws a
    // std::out_of_range (not a cv::Exception) for any file shorter than its seed.
    t.push_back({"canary", "input.txt", false, Errors::LIBRARY,
                 [](const std::string&) {
                     return std::vector<std::string>{"a canary: any shorter file is a planted bug\n"};
                 },
                 [](const std::string& in) {
                     if (readBytes(in).size() < 44)
                         throw std::out_of_range("the planted bug");
                     return std::string();
                 }});
    return t;
}

// ---------------------------------------------------------------------------------------------------
// Mutations.

const std::vector<std::string>& textDictionary()
{
    static const std::vector<std::string> words = {"0",
                                                   "-0",
                                                   "1",
                                                   "-1",
                                                   "2",
                                                   "3",
                                                   "7",
                                                   "1.5",
                                                   "-2.5",
                                                   "1e308",
                                                   "-1e308",
                                                   "1e-320",
                                                   "4.9e-324",
                                                   "nan",
                                                   ".nan",
                                                   ".NaN",
                                                   "inf",
                                                   ".inf",
                                                   "-.inf",
                                                   "Infinity",
                                                   "4294967297",
                                                   "2147483647",
                                                   "-2147483648",
                                                   "2147483648",
                                                   "65535",
                                                   "65536",
                                                   "1048577",
                                                   "46341",
                                                   "1e9",
                                                   "~",
                                                   "null",
                                                   "true",
                                                   "\"\"",
                                                   "\"x\"",
                                                   "[]",
                                                   "{}",
                                                   "[ 1, 2 ]",
                                                   "[ [ 1 ] ]",
                                                   "{ a: 1 }",
                                                   "!!opencv-matrix",
                                                   "rows",
                                                   "cols",
                                                   "dt",
                                                   "data",
                                                   "d",
                                                   "f",
                                                   "u",
                                                   "i",
                                                   "format_version",
                                                   "version",
                                                   "%YAML:1.0",
                                                   "---",
                                                   ":",
                                                   "- ",
                                                   ",",
                                                   "\n",
                                                   "'"};
    return words;
}

bool isTokenChar(char c)
{
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-' || c == '+';
}

class Mutator
{
public:
    Mutator(uint64_t seed, bool binary) : rng_(seed), binary_(binary) {}

    std::string mutate(std::string data, const std::vector<std::string>& corpus)
    {
        const int count = 1 + int(below(4));
        for (int k = 0; k < count; ++k)
            data = mutateOnce(std::move(data), corpus);
        return data;
    }

private:
    uint64_t below(uint64_t n) { return n == 0 ? 0 : rng_() % n; }

    std::string mutateOnce(std::string d, const std::vector<std::string>& corpus)
    {
        if (d.empty())
            return binary_ ? std::string(1, char(below(256)))
                           : textDictionary()[below(textDictionary().size())];
        // Binary files: most mutations go to the first 4 KiB, where RAW containers keep their headers and
        // directories; pixel data past them only changes pixel values.
        const size_t pos =
            binary_ && below(4) != 0 ? below(std::min<size_t>(d.size(), 4096)) : below(d.size());
        switch (below(binary_ ? 8 : 10)) {
        case 0: // flip a bit
            d[pos] = char(d[pos] ^ (1 << below(8)));
            break;
        case 1: // a random or boundary byte
        {
            static const unsigned char edge[] = {0, 1, 0x7f, 0x80, 0xff, ' ', '\n', '"', '[', '{'};
            d[pos] = below(2) ? char(below(256)) : char(edge[below(sizeof edge)]);
            break;
        }
        case 2: // delete a range
            d.erase(pos, 1 + below(std::min<uint64_t>(64, d.size() - pos)));
            break;
        case 3: // duplicate a range elsewhere
        {
            const std::string piece = d.substr(pos, 1 + below(64));
            d.insert(below(d.size() + 1), piece);
            break;
        }
        case 4: // truncate
            d.resize(pos);
            break;
        case 5: // splice with another corpus entry
        {
            const std::string& other = corpus[below(corpus.size())];
            if (!other.empty())
                d = d.substr(0, pos) + other.substr(below(other.size()));
            break;
        }
        case 6: // binary: a boundary integer of 1, 2 or 4 bytes at any offset (sizes, offsets, counts)
        case 7: {
            if (!binary_) {
                d.insert(pos, textDictionary()[below(textDictionary().size())]);
                break;
            }
            static const uint32_t values[] = {
                0,           1,           2,           0x7f,       0x80,    0xff,
                0x100,       0x7fff,      0x8000,      0xffff,     0x10000, 0x7fffffff,
                0x80000000u, 0xffffffffu, 0xfffffffeu, 0x40000000, 0x1000,  3};
            const uint32_t v = values[below(sizeof values / sizeof values[0])];
            const int width = 1 << below(3);
            const bool bigEndian = below(2) == 1;
            for (int b = 0; b < width && pos + size_t(b) < d.size(); ++b) {
                const int shift = 8 * (bigEndian ? width - 1 - b : b);
                d[pos + size_t(b)] = char((v >> shift) & 0xff);
            }
            break;
        }
        case 8: // text: replace a token by a dictionary word or a token of the same file
        {
            size_t start = pos;
            while (start > 0 && isTokenChar(d[start - 1]))
                --start;
            size_t end = pos;
            while (end < d.size() && isTokenChar(d[end]))
                ++end;
            std::string word;
            if (below(3) == 0) {
                const size_t at = below(d.size());
                size_t a = at, b = at;
                while (a > 0 && isTokenChar(d[a - 1]))
                    --a;
                while (b < d.size() && isTokenChar(d[b]))
                    ++b;
                word = d.substr(a, b - a);
            } else {
                word = textDictionary()[below(textDictionary().size())];
            }
            d.replace(start, end - start, word);
            break;
        }
        default: // text: duplicate, drop or move a whole line
        {
            const size_t before = d.rfind('\n', pos);
            const size_t lineStart = before == std::string::npos ? 0 : before + 1;
            const size_t after = d.find('\n', pos);
            const size_t lineEnd = after == std::string::npos ? d.size() : after + 1;
            const std::string line = d.substr(lineStart, lineEnd - lineStart);
            const int what = int(below(3)); // 0: duplicate, 1: drop, 2: move
            if (what != 0)
                d.erase(lineStart, lineEnd - lineStart);
            if (what != 1) {
                const size_t next = d.find('\n', below(d.size() + 1));
                d.insert(next == std::string::npos ? d.size() : next + 1, line);
            }
            break;
        }
        }
        return d;
    }

    std::mt19937_64 rng_;
    bool binary_;
};

// ---------------------------------------------------------------------------------------------------
// Running.

char g_inputPath[4096];
unsigned g_inputSeconds = 20;

void reportHang(int)
{
    static const char a[] = "\nrawgment_fuzz: FAIL: one input took longer than the per-input limit; it is "
                            "kept at ";
    ssize_t ignored = ::write(2, a, sizeof a - 1);
    ignored = ::write(2, g_inputPath, std::strlen(g_inputPath));
    ignored = ::write(2, "\n", 1);
    (void)ignored;
    _exit(3);
}

#if defined(__SANITIZE_ADDRESS__)
void reportDeath()
{
    std::fprintf(stderr, "\nrawgment_fuzz: FAIL: the process died reading the input kept at %s\n",
                 g_inputPath);
}
#endif

std::string typeName(const std::type_info& type)
{
    int status = 0;
    char* name = abi::__cxa_demangle(type.name(), nullptr, nullptr, &status);
    const std::string out = status == 0 && name ? name : type.name();
    std::free(name);
    return out;
}

//! The message of a rejection with the digits and paths blurred: distinct messages stand for distinct
//! checks reached, which is what makes an input worth keeping as a new seed.
std::string errorClass(const std::string& message)
{
    std::string out;
    bool inQuote = false;
    for (char c : message) {
        if (c == '\'') {
            inQuote = !inQuote;
            out += c;
            continue;
        }
        if (inQuote)
            continue;
        out += (c >= '0' && c <= '9') ? '#' : c;
    }
    return out.substr(0, 160);
}

enum class Outcome
{
    ACCEPTED,
    REJECTED,
    FAILED
};

Outcome runOne(const Target& target, const std::string& input, std::string& detail)
{
    try {
        detail = target.read(input);
        return detail.empty() ? Outcome::ACCEPTED : Outcome::FAILED;
    } catch (const cv::Exception& e) {
        // OpenCV's persistence code says what went wrong in its own terms ("parseSeq", "skipSpaces"): its
        // exception must never reach a caller unwrapped.
        if (e.file.find("persistence") != std::string::npos) {
            detail = "a cv::Exception of OpenCV's persistence code (" + e.func + ", " + e.file +
                     ") reached the caller unwrapped: " + e.err;
            return Outcome::FAILED;
        }
        detail = e.err;
        return Outcome::REJECTED;
    } catch (const std::exception& e) {
        if (target.errors == Errors::APP && typeid(e) == typeid(std::runtime_error)) {
            detail = e.what();
            return Outcome::REJECTED;
        }
        detail = "threw " + typeName(typeid(e)) + " (" + e.what() + "), not " +
                 (target.errors == Errors::APP ? "cv::Exception or std::runtime_error" : "cv::Exception");
        return Outcome::FAILED;
    } catch (...) {
        detail = "threw something that is not a std::exception";
        return Outcome::FAILED;
    }
}

struct Options
{
    std::string target, work, corpus, dataDir, replay;
    bool verbose = false;
    double seconds = 20;
    long long iterations = -1;
    uint64_t seed = 1;
};

void usage()
{
    std::cout
        << "rawgment_fuzz: mutates valid files and feeds them to one reader of cv::rawgment.\n"
           "  --target=NAME      model, report, policy, scene, sidecar, chart_patches, manifest, emva1288,\n"
           "                     emva1288_image,\n"
           "                     validation_manifest, raw (canary: a planted bug)\n"
           "  --work=DIR         scratch folder (created; the input being read is kept there)\n"
           "  --seconds=S        time budget (default 20)\n"
           "  --iterations=N     stop after N inputs instead (for replaying a seed's sequence)\n"
           "  --seed=N           mutation seed (default 1): seed and iteration name an input\n"
           "  --corpus=DIR       more seeds: every file of DIR (regression inputs)\n"
           "  --data=DIR         camera RAW files for the raw target's seeds, when present\n"
           "  --input-seconds=S  longest time one input may take (default 20)\n"
           "  --verbose=1        print each new kind of outcome (what the reader said)\n"
           "  --replay=FILE      read FILE once with the target's reader and report (a sidecar\n"
           "                     must sit beside its mosaic, as in the work folder)\n"
           "Exit 0: every input was rejected with the documented exception or accepted intact.\n";
}

bool parse(int argc, char** argv, Options& o)
{
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const size_t eq = a.find('=');
        const std::string key = a.substr(0, eq), value = eq == std::string::npos ? "" : a.substr(eq + 1);
        if (key == "--help" || key == "-h") {
            usage();
            std::exit(0);
        }
        if (eq == std::string::npos) {
            std::cerr << "rawgment_fuzz: '" << a << "' is not --key=value (see --help)\n";
            return false;
        }
        try {
            if (key == "--target")
                o.target = value;
            else if (key == "--work")
                o.work = value;
            else if (key == "--seconds")
                o.seconds = std::stod(value);
            else if (key == "--iterations")
                o.iterations = std::stoll(value);
            else if (key == "--seed")
                o.seed = std::stoull(value);
            else if (key == "--corpus")
                o.corpus = value;
            else if (key == "--data")
                o.dataDir = value;
            else if (key == "--input-seconds")
                g_inputSeconds = unsigned(std::stoul(value));
            else if (key == "--verbose")
                o.verbose = value != "0";
            else if (key == "--replay")
                o.replay = value;
            else {
                std::cerr << "rawgment_fuzz: unknown option '" << key << "' (see --help)\n";
                return false;
            }
        } catch (const std::exception&) {
            std::cerr << "rawgment_fuzz: '" << value << "' is not a valid value for " << key << "\n";
            return false;
        }
    }
    if (o.target.empty() || (o.work.empty() && o.replay.empty())) {
        std::cerr << "rawgment_fuzz: --target and --work (or --replay) are required (see --help)\n";
        return false;
    }
    return true;
}

int fuzz(const Target& target, const Options& o)
{
    const std::string work = o.work + "/" + target.name;
    fs::remove_all(work);
    fs::create_directories(work);
    std::vector<std::string> corpus = target.seeds(work);
    const size_t generated = corpus.size();
    std::vector<std::string> accepted = corpus;
    if (!o.corpus.empty() && fs::is_directory(o.corpus))
        for (const auto& entry : fs::directory_iterator(o.corpus))
            if (entry.is_regular_file())
                corpus.push_back(readBytes(entry.path().string()));
    const std::string input = work + "/" + target.inputName;
    std::snprintf(g_inputPath, sizeof g_inputPath, "%s", input.c_str());

    // Every seed must be accepted: a reader that rejects its own writer's files tests nothing.
    std::set<std::string> seen;
    for (size_t k = 0; k < generated; ++k) {
        writeBytes(input, corpus[k]);
        std::string detail;
        if (runOne(target, input, detail) != Outcome::ACCEPTED) {
            std::cerr << "rawgment_fuzz: FAIL: " << target.name << " seed " << k
                      << " is not accepted: " << detail << "\n";
            return 1;
        }
    }
    // Every seed and corpus file as it is, before any mutation, passes the differential check too.
    if (checkedDifferentially(target))
        for (size_t k = 0; k < corpus.size(); ++k) {
            writeBytes(input, corpus[k]);
            const std::string why = rawgment_fuzz::differentialCheck(input);
            if (!why.empty()) {
                std::cerr << "rawgment_fuzz: FAIL: " << target.name << " corpus entry " << k
                          << ", differential check: " << why << "\n";
                return 1;
            }
        }
    std::cout << "rawgment_fuzz: " << target.name << ": " << corpus.size() << " seeds (" << generated
              << " made by the writers), budget " << o.seconds << " s, seed " << o.seed
              << "; the input being "
              << "read is always " << input << "\n"
              << std::flush;

    Mutator mutator(o.seed, target.binary);
    const auto start = std::chrono::steady_clock::now();
    long long iteration = 0, acceptedCount = 0, rejectedCount = 0;
    const size_t maxCorpus = 400;
    for (;; ++iteration) {
        if (o.iterations >= 0
                ? iteration >= o.iterations
                : std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
                      o.seconds)
            break;
        // Half the inputs start from a file the reader accepts (a seed or an accepted mutant), so that
        // mutations reach the checks behind the parser; the rest from any kept input.
        const std::vector<std::string>& pool = iteration % 2 == 0 ? accepted : corpus;
        const std::string data = mutator.mutate(pool[size_t(iteration / 2) % pool.size()], corpus);
        writeBytes(input, data);
        std::string detail;
        ::alarm(g_inputSeconds);
        Outcome outcome = runOne(target, input, detail);
        if (outcome != Outcome::FAILED && checkedDifferentially(target)) {
            const std::string why = rawgment_fuzz::differentialCheck(input);
            if (!why.empty()) {
                detail = "differential check: " + why;
                outcome = Outcome::FAILED;
            }
        }
        ::alarm(0);
        if (outcome == Outcome::FAILED) {
            const std::string kept = work + "/failure_" + target.inputName;
            writeBytes(kept, data);
            std::cerr << "rawgment_fuzz: FAIL: " << target.name << ", seed " << o.seed << ", iteration "
                      << iteration << ": " << detail << "\n  the input is kept at " << kept << "\n";
            return 1;
        }
        (outcome == Outcome::ACCEPTED ? acceptedCount : rejectedCount) += 1;
        const std::string key = outcome == Outcome::ACCEPTED ? std::string("accepted") : errorClass(detail);
        const bool novel = seen.insert(key).second;
        if (novel && o.verbose)
            std::cout << "  new outcome at iteration " << iteration << ": " << key << "\n";
        if ((novel || outcome == Outcome::ACCEPTED) && corpus.size() < maxCorpus)
            corpus.push_back(data);
        if (outcome == Outcome::ACCEPTED && accepted.size() < maxCorpus)
            accepted.push_back(data);
    }
    std::cout << "rawgment_fuzz: " << target.name << ": PASS, " << iteration << " inputs (" << acceptedCount
              << " accepted, " << rejectedCount << " rejected with " << seen.size()
              << " distinct outcomes), corpus grew to " << corpus.size() << "\n";
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    Options o;
    if (!parse(argc, argv, o))
        return 2;
    // The readers' own diagnostics would drown the summary.
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    const std::vector<Target> all = targets(o.dataDir);
    const auto it = std::find_if(all.begin(), all.end(), [&](const Target& t) { return t.name == o.target; });
    if (it == all.end()) {
        std::cerr << "rawgment_fuzz: unknown target '" << o.target << "' (see --help)\n";
        return 2;
    }
    ::signal(SIGALRM, reportHang);
#if defined(__SANITIZE_ADDRESS__)
    __sanitizer_set_death_callback(reportDeath);
#endif
    if (!o.replay.empty()) {
        std::snprintf(g_inputPath, sizeof g_inputPath, "%s", o.replay.c_str());
        std::string detail;
        const Outcome outcome = runOne(*it, o.replay, detail);
        std::cout << (outcome == Outcome::ACCEPTED   ? "accepted"
                      : outcome == Outcome::REJECTED ? "rejected: "
                                                     : "FAIL: ")
                  << detail << "\n";
        return outcome == Outcome::FAILED ? 1 : 0;
    }
    try {
        return fuzz(*it, o);
    } catch (const std::exception& e) {
        std::cerr << "rawgment_fuzz: cannot set up the target: " << e.what() << "\n";
        return 1;
    }
}
