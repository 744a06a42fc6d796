// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_augment and rawgment_convert: inputs with one stem, two runs into one folder, previews and
// capture tags, gains from ISO, real cameras' profiles, .npy conversions.
#include "app_runs.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment.hpp>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>
#include <unistd.h>

namespace {

using namespace rawgment_app_tests;

TEST(Apps, augmentKeepsInputsWithOneStemApartAndNeverTakesAnotherInputsOutput)
{
    // a/frame_000 and b/frame_000 used to race for one output name, so that one input's image could end
    // up with the other's sidecar and a rerun "skipped" an input that was never augmented.
    const std::string dir = freshDir("augment_stems");
    AppRun r =
        runApp("rawgment_simulate", "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    writeExposureScene(dir + "/scene.yml", 0.5, 1.0);
    const std::string a = dir + "/sim/g06dB_level0.50/frame_000.png",
                      b = dir + "/sim/validation/bright/frame_000.png";
    const std::string common =
        "--model='" + dir + "/sim/truth_noise_model.yml' --scene='" + dir + "/scene.yml' ";
    // The first input of a stem takes the stem, a later one the stem and a hash of its path.
    const auto hashed = [](const std::string& f) {
        return "frame_000-" + cv::format("%08llx", static_cast<unsigned long long>(
                                                       cv::rawgment::augmentedOutputSeed(0, f, 0) >> 32));
    };
    r = runApp("rawgment_augment",
               common + "--out='" + dir + "/both' --preview=true '" + a + "' '" + b + "'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 2 outputs")) << r.output;
    for (const auto& [f, name] :
         {std::make_pair(a, std::string("frame_000")), std::make_pair(b, hashed(b))}) {
        cv::Mat out;
        EXPECT_EQ(f, cv::rawgment::readMosaic(dir + "/both/" + name + "_v00.png", out).source)
            << "each output carries its own input's sidecar";
        expectPngDecodes(dir + "/both/" + name + "_v00_preview.png");
    }
    r = runApp("rawgment_augment",
               common + "--out='" + dir + "/both' --preview=true '" + b + "' '" + a + "'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("skipped 2")) << r.output << " (in another order too)";

    // One stem at a time into one folder: b is neither "skipped" on a's output nor renames it.
    r = runApp("rawgment_augment", common + "--out='" + dir + "/single' '" + a + "'");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_augment", common + "--out='" + dir + "/single' '" + b + "'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_TRUE(exists(dir + "/single/frame_000_v00.png") &&
                exists(dir + "/single/" + hashed(b) + "_v00.png"));
    r = runApp("rawgment_augment", common + "--out='" + dir + "/single' '" + a + "' '" + b + "'");
    EXPECT_NE(std::string::npos, r.output.find("skipped 2")) << r.output;
    // Outputs named as versions before 0.2 named every input of a shared stem (hashed, with the seeds of
    // those names) are recognised and skipped: a third input's output held the stem while a and b were
    // augmented, then went.
    const std::string c = dir + "/c/frame_000.png";
    ASSERT_EQ(
        0,
        std::system(("mkdir -p '" + dir + "/c' && cp '" + a + "' '" + a + ".yml' '" + dir + "/c/'").c_str()));
    ASSERT_EQ(0, runApp("rawgment_augment", common + "--out='" + dir + "/old' '" + c + "'").status);
    r = runApp("rawgment_augment", common + "--out='" + dir + "/old' '" + a + "' '" + b + "'");
    ASSERT_TRUE(exists(dir + "/old/" + hashed(a) + "_v00.png") &&
                exists(dir + "/old/" + hashed(b) + "_v00.png"))
        << r.output;
    ASSERT_EQ(
        0, std::system(
               ("rm '" + dir + "/old/frame_000_v00.png' '" + dir + "/old/frame_000_v00.png.yml'").c_str()));
    r = runApp("rawgment_augment", common + "--out='" + dir + "/old' '" + a + "' '" + b + "'");
    EXPECT_NE(std::string::npos, r.output.find("skipped 2")) << r.output;
    EXPECT_FALSE(exists(dir + "/old/frame_000_v00.png"));
    EXPECT_EQ(1, runApp("rawgment_augment", common + "--out='" + dir + "/x' '" + a + "' '" + a + "'").status)
        << "the same input twice";

    // A preview that is not this job's is never replaced.
    std::ofstream(dir + "/single/frame_000_v01_preview.png") << "not a preview";
    r = runApp("rawgment_augment",
               common + "--out='" + dir + "/single' --variants=2 --preview=true '" + a + "'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_EQ("not a preview", readText(dir + "/single/frame_000_v01_preview.png"));
}

/* Round 5 item 12: a rerun into the same --out with another scene, another seed or a bank said "wrote 0,
 * skipped 2" and exited 0 with the first job's outputs. The folder records its job (augment_job.yml: the
 * version, the content of the model, scene or policy and bank, the options, each input's content); a rerun
 * resumes only that job and adds inputs to it. */
TEST(Apps, aRerunResumesOnlyTheSameJob)
{
    const std::string dir = freshDir("augment_job_identity");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir +
                                               "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false "
                                               "--dark=true --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    writeExposureScene(dir + "/scene.yml", 0.5, 1.0);
    writeExposureScene(dir + "/other.yml", 0.25, 1.0);
    std::vector<cv::String> darkFiles;
    for (int f = 0; f < 3; ++f)
        darkFiles.push_back(dir + cv::format("/sim/dark_g06dB/frame_%03d.png", f));
    cv::rawgment::DarkFrameBank::create(darkFiles, cv::rawgment::NoiseModel()).save(dir + "/bank.yml");
    const std::string a = dir + "/sim/g06dB_level0.50/frame_000.png",
                      b = dir + "/sim/g06dB_level0.50/frame_001.png";
    const auto augment = [&](const std::string& scene, const std::string& extra, const std::string& inputs) {
        return runApp("rawgment_augment", "--model='" + dir + "/sim/truth_noise_model.yml' --scene='" + dir +
                                              "/" + scene + "' --out='" + dir + "/out' " + extra + " " +
                                              inputs);
    };
    r = augment("scene.yml", "", "'" + a + "'");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string record = readText(dir + "/out/augment_job.yml");
    EXPECT_NE(std::string::npos, record.find("recipe_fnv1a64")) << record;
    const std::string first = readText(dir + "/out/frame_000_v00.png");
    using Rerun = std::tuple<std::string, std::string, std::string>;
    for (const auto& [scene, extra, field] :
         {Rerun("other.yml", "", "recipe_fnv1a64"), Rerun("scene.yml", "--seed=2", "seed"),
          Rerun("scene.yml", "--dark_bank='" + dir + "/bank.yml'", "dark_bank_fnv1a64")}) {
        r = augment(scene, extra, "'" + a + "'");
        EXPECT_EQ(1, r.status) << extra << r.output;
        EXPECT_NE(
            std::string::npos,
            r.output.find("augment_job.yml': it records another augmentation job: its " + std::string(field)))
            << r.output;
    }
    EXPECT_EQ(first, readText(dir + "/out/frame_000_v00.png"));
    EXPECT_EQ(record, readText(dir + "/out/augment_job.yml")) << "a refused run leaves the record as it was";
    // The same job resumes, and takes a new input; a moved scene file of the same content is the same job.
    ASSERT_EQ(0, std::system(("cp '" + dir + "/scene.yml' '" + dir + "/moved.yml'").c_str()));
    r = augment("moved.yml", "", "'" + a + "' '" + b + "'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("skipped 1")) << r.output;
    // An input whose content changed since its outputs were made is not their input.
    cv::Mat changed = cv::imread(b, cv::IMREAD_UNCHANGED);
    changed.at<uint16_t>(0, 0) += 1;
    ASSERT_TRUE(cv::imwrite(b, changed));
    r = augment("scene.yml", "", "'" + b + "'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("is not the file it was when")) << r.output;
}

TEST(Apps, twoIdenticalRunsIntoOneFolderBothFinishWithCompletePairs)
{
    // Both runs exited 1 in 13 of 15 tries and left an image without its sidecar: the process whose image
    // write lost the race removed the sidecar it had made, on which the winner's image depended, and every
    // rerun then refused the folder. The same job's files are now each run's output.
    const std::string dir = freshDir("augment_race");
    AppRun r =
        runApp("rawgment_simulate",
               "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    std::string inputs;
    for (int f = 0; f < 3; ++f)
        inputs += cv::format(" '%s/sim/g06dB_level0.50/frame_%03d.png'", dir.c_str(), f);
    for (int attempt = 0; attempt < 15; ++attempt) {
        const std::string out = dir + "/out" + std::to_string(attempt);
        const std::string run = std::string(RAWGMENT_APP_DIR) + "/rawgment_augment --model='" + dir +
                                "/sim/truth_noise_model.yml' --scene='" + dir +
                                "/scene.yml' --variants=4 --preview=true --out='" + out + "'" + inputs;
        const auto [first, second] = runTwiceAtOnce(run, dir);
        EXPECT_EQ(0, first.status) << first.output;
        EXPECT_EQ(0, second.status) << second.output;
        int images = 0, previews = 0;
        for (const auto& entry : std::filesystem::directory_iterator(out)) {
            const std::string path = entry.path().string();
            const bool sidecar = path.size() > 4 && path.compare(path.size() - 4, 4, ".yml") == 0;
            if (entry.path().filename() == "augment_job.yml")
                continue; // the run's record, not an output
            const bool preview = path.find("_preview.png") != std::string::npos;
            previews += preview;
            if (sidecar)
                EXPECT_TRUE(exists(path.substr(0, path.size() - 4))) << path << " has no image";
            else if (!preview && path.find(".tmp-") == std::string::npos) {
                EXPECT_TRUE(exists(path + ".yml")) << path << " has no sidecar";
                ++images;
            }
        }
        EXPECT_EQ(12, images) << out;
        EXPECT_EQ(12, previews) << out << ": two identical runs with previews both finish (round 5, item 21)";
    }
}

TEST(Apps, augmentPreviewsAreBrightenedBackAndOutputsKeepTheCaptureTags)
{
    // A darkening scene's preview shows its noise at the input's brightness (as the demo's gallery does),
    // not a dark frame; the output's sidecar and DNG state the capture it simulates.
    const std::string dir = freshDir("augment_preview");
    AppRun r = runApp("rawgment_simulate",
                      "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string input = dir + "/sim/g06dB_level0.50/frame_000.dng";
    const std::string model = "--model='" + dir + "/sim/truth_noise_model.yml' ";
    std::map<double, double> previewMean;
    for (double photons : {1.0, 0.125}) {
        const std::string tag = cv::format("x%g", photons);
        {
            cv::rawgment::Scene scene;
            scene.jitter = cv::rawgment::ColorJitter::exposureChange(photons, 2.0);
            cv::FileStorage fs(dir + "/" + tag + ".yml", cv::FileStorage::WRITE);
            scene.write(fs, "scene");
        }
        r = runApp("rawgment_augment", model + "--scene='" + dir + "/" + tag + ".yml' --out='" + dir + "/" +
                                           tag + "' --preview=true '" + input + "'");
        ASSERT_EQ(0, r.status) << r.output;
        const cv::Mat preview = cv::imread(dir + "/" + tag + "/frame_000_v00_preview.png");
        ASSERT_FALSE(preview.empty());
        previewMean[photons] = cv::mean(preview)[1];

        cv::Mat out;
        const cv::rawgment::MosaicMetadata meta =
            cv::rawgment::readMosaic(dir + "/" + tag + "/frame_000_v00.dng", out);
        ASSERT_TRUE(meta.hasCamera);
        // The input's sidecar has the exact tags; its DNG the ISO rounded to an integer and the exposure
        // time as a rational (LibRaw gives it back as a float: 1e-7 relative).
        cv::Mat inMosaic;
        const cv::rawgment::CameraTags in = cv::rawgment::readMosaic(input, inMosaic).camera;
        const cv::rawgment::RawImage inDng = cv::rawgment::readRaw(input),
                                     dng = cv::rawgment::readRaw(dir + "/" + tag + "/frame_000_v00.dng");
        EXPECT_EQ(inDng.iso, 200) << "rawgment_simulate writes ISO 100 g (g = 6 dB, rounded)";
        EXPECT_NEAR(in.iso, 100 * cv::rawgment::dbToLinearGain(6), 1e-9);
        EXPECT_NEAR(meta.camera.iso, in.iso * 2, 1e-9);
        EXPECT_EQ(dng.iso, std::round(in.iso * 2));
        // The darkening is the scene's light: a scene that states no exposure keeps the input's.
        EXPECT_EQ(meta.camera.exposureTime, in.exposureTime);
        EXPECT_EQ(meta.format.exposureTime, in.exposureTime);
        EXPECT_NEAR(dng.exposureTime, in.exposureTime, 1e-6 * in.exposureTime);
        EXPECT_EQ(dng.make, "cv::rawgment");
        EXPECT_EQ(dng.model, "simulated sensor");
        EXPECT_EQ(dng.noiseProfile,
                  cv::rawgment::dngNoiseProfile(
                      cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml"), meta.format));
    }
    // Unbrightened, x0.125 would be about 0.125^(1/2.2) = 39% of the x1 preview's mean; brightened back it
    // is the same scene with more noise, whose mean the tone curve's curvature moves by a few percent.
    EXPECT_NEAR(previewMean[0.125], previewMean[1.0], 0.1 * previewMean[1.0]);
}

TEST(Apps, augmentTakesACameraFilesGainFromItsIsoAndTheModelsBaseIso)
{
    // A user's camera file (no sidecar) at ISO 200, and models of that camera whose gain 1 is ISO 100 (as
    // rawgment_simulate's truth says, and rawgment_calibrate writes from ISO-tagged files) or unknown.
    const std::string dir = freshDir("augment_iso");
    AppRun r = runApp("rawgment_simulate",
                      "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false");
    ASSERT_EQ(0, r.status) << r.output;
    ASSERT_EQ(0, ::mkdir((dir + "/camera").c_str(), 0755));
    {
        std::ifstream in(dir + "/sim/g06dB_level0.50/frame_000.dng", std::ios::binary);
        std::ofstream out(dir + "/camera/shot.dng", std::ios::binary);
        out << in.rdbuf();
        ASSERT_TRUE(out.good());
    }
    const cv::rawgment::NoiseModel withBase =
        cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
    EXPECT_EQ(100.0, withBase.baseIso);
    cv::rawgment::NoiseModel withoutBase = withBase;
    withoutBase.baseIso = 0;
    withoutBase.save(dir + "/no_base.yml");
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    // ISO 200 over base ISO 100: the input is at gain 2 and the output at 4; the ISO tag is the input's
    // times the gain ratio. Without a base ISO the input's gain is unknown: refused, not taken at gain 1.
    r = runApp("rawgment_augment", "--model='" + dir + "/no_base.yml' --scene='" + dir +
                                       "/scene.yml' --out='" + dir + "/out_no_base' '" + dir +
                                       "/camera/shot.dng'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("the noise model has no base ISO")) << r.output;
    for (const auto& c : {std::make_pair(std::string("/sim/truth_noise_model.yml"), 4.0)}) {
        const std::string out = dir + "/out" + std::to_string(int(c.second));
        r = runApp("rawgment_augment", "--model='" + dir + c.first + "' --scene='" + dir +
                                           "/scene.yml' --out='" + out + "' '" + dir + "/camera/shot.dng'");
        ASSERT_EQ(0, r.status) << r.output;
        cv::Mat mosaic;
        const cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(out + "/shot_v00.dng", mosaic);
        EXPECT_DOUBLE_EQ(c.second, meta.format.gain) << c.first;
        EXPECT_DOUBLE_EQ(400.0, meta.camera.iso) << c.first;
        EXPECT_EQ(cv::rawgment::readRaw(out + "/shot_v00.dng").noiseProfile,
                  cv::rawgment::dngNoiseProfile(withBase, meta.format))
            << c.first;
    }
}

/* rawgment_convert: a camera file and a mosaic with its sidecar into .npy, the same pixels, format and tags;
 * the camera file's conversion augments to the same bytes as the camera file (its gain from its ISO); a
 * second run skips; an output holding another input is never overwritten. */
TEST(Apps, convertWritesNpyThatAugmentsAsItsSource)
{
    const std::string dir = freshDir("convert");
    AppRun r =
        runApp("rawgment_simulate",
               "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_simulate",
               "--out='" + dir + "/dng' --frames=3 --gains=6 --levels=0.5 --validation=false");
    ASSERT_EQ(0, r.status) << r.output;
    ASSERT_EQ(0, ::mkdir((dir + "/camera").c_str(), 0755));
    {
        std::ifstream in(dir + "/dng/g06dB_level0.50/frame_000.dng", std::ios::binary);
        std::ofstream out(dir + "/camera/shot.dng", std::ios::binary);
        out << in.rdbuf();
        ASSERT_TRUE(out.good());
    }
    const std::string png = dir + "/sim/g06dB_level0.50/frame_001.png", camera = dir + "/camera/shot.dng";
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + png + "' '" + camera + "'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 2 files, skipped 0")) << r.output;
    cv::Mat fromPng, pngMosaic, fromCamera;
    const cv::rawgment::MosaicMetadata pngMeta =
        cv::rawgment::readMosaic(dir + "/npy/frame_001.npy", fromPng);
    const cv::rawgment::MosaicMetadata original = cv::rawgment::readMosaic(png, pngMosaic);
    EXPECT_EQ(0, cv::norm(fromPng, pngMosaic, cv::NORM_INF));
    EXPECT_EQ(original.format.gain, pngMeta.format.gain);
    EXPECT_FALSE(pngMeta.gainFromIso) << "a mosaic with a sidecar keeps its gain";
    EXPECT_EQ(png, pngMeta.source);
    const cv::rawgment::MosaicMetadata cameraMeta =
        cv::rawgment::readMosaic(dir + "/npy/shot.npy", fromCamera);
    const cv::rawgment::RawImage raw = cv::rawgment::readRaw(camera);
    EXPECT_EQ(0, cv::norm(fromCamera, raw.mosaic, cv::NORM_INF));
    EXPECT_TRUE(cameraMeta.gainFromIso && cameraMeta.hasCamera);
    EXPECT_EQ(raw.iso, cameraMeta.camera.iso);
    // The same augmentation of the camera file and of its conversion: the same pixels and gain.
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    const std::string model = dir + "/dng/truth_noise_model.yml";
    for (const char* input : {"/camera/shot.dng", "/npy/shot.npy"}) {
        r = runApp("rawgment_augment", "--model='" + model + "' --scene='" + dir +
                                           "/scene.yml' --format=npy --out='" + dir + "/aug" +
                                           std::string(input).substr(1, 3) + "' '" + dir + input + "'");
        ASSERT_EQ(0, r.status) << r.output;
    }
    cv::Mat a, b;
    const cv::rawgment::MosaicMetadata ma = cv::rawgment::readMosaic(dir + "/augcam/shot_v00.npy", a);
    const cv::rawgment::MosaicMetadata mb = cv::rawgment::readMosaic(dir + "/augnpy/shot_v00.npy", b);
    EXPECT_EQ(0, cv::norm(a, b, cv::NORM_INF));
    EXPECT_DOUBLE_EQ(ma.format.gain, mb.format.gain);
    EXPECT_DOUBLE_EQ(4.0, mb.format.gain) << "ISO 200 over the model's base ISO 100, times 2";
    // Again: nothing to do. Another input with the same output name: an error, the output untouched.
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + png + "' '" + camera + "'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 0 files, skipped 2")) << r.output;
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + dir + "/sim/g06dB_level0.50/frame_000.png'");
    EXPECT_EQ(0, r.status) << r.output;
    // Another input of an existing output's name takes the name and a hash; the existing one is untouched.
    const std::string other = dir + "/dng/g06dB_level0.50/frame_001.dng";
    const std::string before = readText(dir + "/npy/frame_001.npy.yml");
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + other + "'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_EQ(before, readText(dir + "/npy/frame_001.npy.yml"));
    EXPECT_TRUE(exists(dir + "/npy/frame_001-" +
                       cv::format("%08llx", static_cast<unsigned long long>(
                                                cv::rawgment::augmentedOutputSeed(0, other, 0) >> 32)) +
                       ".npy"));
    // Every app's --format is the library's table of written containers (mosaicContainers()), so a container
    // one app writes, the others write too: rawgment_simulate refused npy.
    AppRun refused = runApp("rawgment_convert", "--out='" + dir + "/x' --format=jpg '" + png + "'");
    EXPECT_EQ(2, refused.status);
    EXPECT_NE(std::string::npos, refused.output.find("--format must be dng, npy, png or tif"))
        << refused.output;
    refused = runApp("rawgment_simulate", "--out='" + dir + "/y' --format=jpg");
    EXPECT_EQ(2, refused.status);
    EXPECT_NE(std::string::npos, refused.output.find("--format must be dng, npy, png or tif"))
        << refused.output;
    r = runApp("rawgment_simulate",
               "--out='" + dir +
                   "/simnpy' --frames=3 --gains=6 --levels=0.5 --validation=false --format=npy");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_TRUE(exists(dir + "/simnpy/g06dB_level0.50/frame_002.npy"));
    // A folder: its files (not its sidecars), each converted.
    r = runApp("rawgment_convert", "--out='" + dir + "/folder' '" + dir + "/sim/g06dB_level0.50'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 3 files, skipped 0")) << r.output;
    EXPECT_TRUE(exists(dir + "/folder/frame_002.npy") && exists(dir + "/folder/frame_002.npy.yml"));
    r = runApp("rawgment_convert", "--out='" + dir + "/folder' '" + dir + "/sim/g06dB_level0.50'");
    EXPECT_NE(std::string::npos, r.output.find("wrote 0 files, skipped 3")) << r.output;
    // Into the input folder itself: a rerun over it would take the outputs for inputs (it converted them
    // again, growing on every run), so it is refused before anything is written.
    r = runApp("rawgment_convert", "--out='" + dir + "/camera' '" + dir + "/camera'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("lies in the output folder")) << r.output;
    EXPECT_FALSE(exists(dir + "/camera/shot.npy"));
    r = runApp("rawgment_augment", "--model='" + model + "' --scene='" + dir + "/scene.yml' --out='" + dir +
                                       "/camera' '" + camera + "'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("lies in the output folder")) << r.output;
}

TEST(Apps, augmentAsRealCamerasDrawsOnePerOutputAndRecordsIt)
{
    // A darktable file of two cameras (the project's own exports, joined), an Android profile, and the
    // catalogue app over the file.
    const std::string dir = freshDir("augment_cameras");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5");
    ASSERT_EQ(0, r.status) << r.output;
    cv::rawgment::RawFormat format;
    format.blackLevel = cv::Vec4d(64, 64, 64, 64);
    format.whiteLevel = 4095;
    const auto modelsOf = [&](const cv::rawgment::NoiseModel& m, const std::string& name) {
        const std::string text =
            cv::rawgment::darktableNoiseProfiles(m, format, 100, {100, 400, 1600}, "Maker", name);
        const size_t from = text.find("{\n          \"model\"");
        const size_t to = text.rfind("      ]\n    }\n  ]");
        return text.substr(from, to - from);
    };
    {
        std::ofstream out(dir + "/noiseprofiles.json");
        out << "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", \"models\": [\n"
            << modelsOf(cv::rawgment::NoiseModel(0.3, 0.05, 0.2), "Quiet") << ",\n"
            << modelsOf(cv::rawgment::NoiseModel(0.3, 2.0, 30.0), "Loud") << "]}]}\n";
        ASSERT_TRUE(out.good());
    }
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    const std::string input = "'" + dir + "/sim/g06dB_level0.50/frame_000.dng'";
    const std::string common = " --scene='" + dir + "/scene.yml' " + input;
    r = runApp("rawgment_augment", "--model='" + dir +
                                       "/noiseprofiles.json' --camera=usable --variants=8 --out='" + dir +
                                       "/out'" + common);
    ASSERT_EQ(0, r.status) << r.output;
    std::set<std::string> cameras;
    for (int v = 0; v < 8; ++v) {
        cv::Mat mosaic;
        const cv::rawgment::MosaicMetadata meta =
            cv::rawgment::readMosaic(dir + cv::format("/out/frame_000_v%02d.dng", v), mosaic);
        cameras.insert(meta.noiseCamera);
    }
    EXPECT_EQ(cameras, (std::set<std::string>{"Maker Loud", "Maker Quiet"}));
    // The same run again gives the same cameras and bytes (a second folder, compared file by file).
    r = runApp("rawgment_augment", "--model='" + dir +
                                       "/noiseprofiles.json' --camera=usable --variants=8 --out='" + dir +
                                       "/again'" + common);
    ASSERT_EQ(0, r.status) << r.output;
    for (int v = 0; v < 8; ++v)
        EXPECT_EQ(readText(dir + cv::format("/out/frame_000_v%02d.dng", v)),
                  readText(dir + cv::format("/again/frame_000_v%02d.dng", v)));

    r = runApp("rawgment_augment", "--model='" + dir + "/noiseprofiles.json' --out='" + dir + "/x'" + common);
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("choose with --camera")) << r.output;
    r = runApp("rawgment_augment", "--model='" + dir + "/noiseprofiles.json' --camera='Maker Lod' --out='" +
                                       dir + "/x'" + common);
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos,
              r.output.find("no camera named 'Maker Lod' among 2 cameras; the closest are 'Maker "
                            "Loud'"))
        << r.output;
    r = runApp("rawgment_augment", "--model='" + dir +
                                       "/sim/truth_noise_model.yml' --camera='Maker Loud' --out='" + dir +
                                       "/x'" + common);
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("is not one")) << r.output;

    // The validation takes a camera too, made at the bright burst's levels.
    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/noiseprofiles.json' --camera='Maker Quiet' --plots=false --out='" +
                                        dir + "/val'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, readText(dir + "/val/validation.md").find("ACCOUNT_PRIOR"));
    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/noiseprofiles.json' --plots=false --out='" + dir + "/val2'");
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("darktable noise-profile file of many cameras")) << r.output;

    // The catalogue and one camera's table.
    r = runApp("rawgment_cameras", "--profiles='" + dir + "/noiseprofiles.json'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("Maker Quiet")) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("2 of 2 cameras listed")) << r.output;
    r = runApp("rawgment_cameras", "--profiles='" + dir + "/noiseprofiles.json' --camera='maker loud'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("Maker Loud (noiseprofiles[0].models[1]): GOOD")) << r.output;
    r = runApp("rawgment_cameras", "--profiles='" + dir + "/noiseprofiles.json' --verdict=best");
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("--verdict must be")) << r.output;
    r = runApp("rawgment_cameras",
               "--profiles='" + dir + "/noiseprofiles.json' --report='" + dir + "/report'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, readText(dir + "/report/report.md").find("2 GOOD, 0 ROUGH, 0 REFUSED"));
    expectPngDecodes(dir + "/report/real_cameras_slope.png");
}

} // namespace
