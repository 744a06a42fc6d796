// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The fuzz targets of the module's and the apps' file readers (models, reports, scenes, policies, sidecars,
// manifests, camera profiles, .npy, RAW files), their seeds and the promises an accepted file must keep;
// test/fuzz/rawgment_fuzz.cpp runs them.
#include "chart_patches.hpp"
#include "flow_common.hpp"
#include "fuzz_target.hpp"
#include "pipeline.hpp"

#include <opencv2/rawgment.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace rawgment_fuzz {

namespace {

using namespace cv::rawgment;
namespace fs = std::filesystem;

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

/* A dark-frame bank of two gains, two 12x8 frames each, written in `work` with their sidecars: the seeds name
 * these frames and their saved patterns, which lie beside the mutated input. */
DarkFrameBank seedDarkBank(const std::string& work)
{
    std::vector<cv::String> files;
    for (double gain : {1.0, 4.0})
        for (int t = 0; t < 2; ++t) {
            MosaicMetadata meta;
            meta.format.blackLevel = cv::Vec4d::all(64);
            meta.format.whiteLevel = 4095;
            meta.format.gain = gain;
            const std::string path = work + cv::format("/dark_g%g_%d.png", gain, t);
            writeMosaic(
                path, seedMosaic(cv::Size(12, 8), 80 + 10 * gain, 11 + 2 * t + static_cast<int>(gain)), meta);
            files.push_back(path);
        }
    return DarkFrameBank::create(files, NoiseModel());
}

std::string checkDarkBank(const DarkFrameBank& b)
{
    if (b.groups.empty() || b.size.area() <= 0)
        return "accepted an empty bank";
    for (size_t i = 0; i < b.groups.size(); ++i) {
        const DarkFrameGroup& g = b.groups[i];
        const DarkFrameStatistics& s = g.statistics;
        if (!(g.gain > 0 && std::isfinite(g.gain)) || g.files.size() < 2 || s.frames != int(g.files.size()))
            return cv::format("accepted group %zu with gain %g and %zu frames", i, g.gain, g.files.size());
        if (s.pattern.type() != CV_32FC1 || s.pattern.size() != b.size || !cv::checkRange(s.pattern))
            return cv::format("accepted group %zu's pattern that is not a finite map of the frames' size", i);
        if (s.rowVariance.rows != b.size.height || s.noisyPixels.size() != s.noisyVariance.size())
            return cv::format("accepted group %zu's row variances or noisy pixels of another size", i);
        for (const cv::Point& p : s.noisyPixels)
            if (!cv::Rect(cv::Point(), b.size).contains(p))
                return cv::format("accepted a noisy pixel (%d, %d) outside the frames", p.x, p.y);
    }
    // A frame the file names is read as the readers read any file: a clear error or the bank's size.
    const cv::Mat frame = b.readFrame(0, 0);
    if (frame.size() != b.size)
        return "read a frame of another size than the bank's";
    return std::string();
}

} // namespace

std::vector<Target> readerTargets(const std::string& dataDir)
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
    t.push_back({"dark_bank", "input.yml", false, Errors::LIBRARY,
                 [](const std::string& work) {
                     const DarkFrameBank bank = seedDarkBank(work);
                     return textSeeds(work, "dark_bank",
                                      [&](const std::string& p) { DarkFrameBank(bank).save(p); });
                 },
                 [](const std::string& in) { return checkDarkBank(DarkFrameBank::load(in)); }});
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
    for (Target& e : emva1288Targets())
        t.push_back(std::move(e));
    t.push_back({"raw", "input.dng", true, Errors::LIBRARY,
                 [dataDir](const std::string& work) {
                     std::vector<std::string> seeds;
                     // Two Bayer layouts and a monochrome LinearRaw file, whose reading takes LibRaw's other
                     // path.
                     const CfaPattern patterns[] = {CFA_RGGB, CFA_GBRG, CFA_MONO};
                     for (int k = 0; k < 3; ++k) {
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
                         if (k != 1)
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
                     if (image.format.isMonochrome() && image.noiseProfile.size() > 1)
                         return std::string("accepted a NoiseProfile of 3 pairs for one colour plane");
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

} // namespace rawgment_fuzz
