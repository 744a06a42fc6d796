// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_simulate: simulated colour-checker bursts, their manifests, the truth model.
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "chart_patches.hpp"
#include "flow_common.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

namespace {

//! A burst's folder: whole gains keep the short name (g06dB), others carry two decimals (g12.40dB).
std::string burstFolder(double gainDb, double level)
{
    const std::string gain =
        gainDb == std::round(gainDb) ? cv::format("g%02.0fdB", gainDb) : cv::format("g%.2fdB", gainDb);
    return gain + cv::format("_level%.2f", level);
}

/** Everything that decides the frames of a run, as YAML: a run that finds another job's description in
 * its folder refuses, so an interrupted run is only ever resumed by the same job. */
std::string jobDescription(const SimulateOptions& o)
{
    return fileStorageText("simulation_job.yml", [&](cv::FileStorage& fs) {
        fs << "simulation_job"
           << "{";
        fs << "gains_db" << o.gainsDb << "levels" << o.levels << "frames" << o.frames << "patch_size"
           << o.patchSize;
        o.sensor.noise.write(fs, "noise_model");
        fs << "bit_depth" << o.sensor.bitDepth << "pattern" << cfaPatternName(o.sensor.pattern);
        fs << "black_level" << std::vector<double>(o.sensor.blackLevel.val, o.sensor.blackLevel.val + 4);
        fs << "hot" << o.sensor.hotPixelFraction << "dead" << o.sensor.deadPixelFraction << "noisy"
           << o.sensor.noisyPixelFraction << "noisy_variance" << o.sensor.noisyPixelVariance;
        fs << "prnu" << o.sensor.prnu << "dsnu" << o.sensor.dsnu;
        fs << "fixed_pattern_seed"
           << cv::format("%llu", static_cast<unsigned long long>(o.sensor.fixedPatternSeed));
        fs << "quantize" << int(o.sensor.quantize);
        fs << "seed" << cv::format("%llu", static_cast<unsigned long long>(o.seed)) << "extension"
           << o.extension;
        fs << "dark" << int(o.dark) << "dark_shading" << o.darkShading;
        fs << "validation" << int(o.validation) << "validation_gain_db" << o.validationGainDb
           << "validation_frames" << o.validationFrames;
        fs << "}";
    });
}

//! One burst to write: its folder under the output, gain, exposure and seed.
struct PlannedBurst
{
    std::string dir;
    double gainDb, exposure, level;
    int frames;
    uint64_t seed;
    bool dark = false;
};

void checkSimulateOptions(const SimulateOptions& o)
{
    if (o.outDir.empty())
        throw std::runtime_error("no output directory");
    // Three frames at least: rawgment_calibrate tests each pixel's series with Shapiro-Wilk (n >= 3).
    if (o.frames < 3 || o.validationFrames < 3 || o.gainsDb.empty() || o.levels.empty())
        throw std::runtime_error("need at least 3 frames per burst, one gain and one level");
    for (double level : o.levels)
        if (!(level > 0 && level <= 1))
            throw std::runtime_error(cv::format("level %g is outside (0, 1]", level));
}

//! The ground-truth squares and grid corners of the chart, as rawgment_calibrate reads them.
rawgment_helpers::ChartPatches chartPatchesOf(const ColorCheckerScene& scene, int patchSize)
{
    rawgment_helpers::ChartPatches patches;
    const int side = std::max(2, std::min(24, (patchSize - 8) & ~1));
    patches.squares = cfaAlignedSquares(scene.patches, side);
    const cv::Rect& first = scene.patches.front();
    const cv::Rect& last = scene.patches.back();
    patches.gridCorners = {
        cv::Point2f(float(first.x), float(first.y)), cv::Point2f(float(last.br().x), float(first.y)),
        cv::Point2f(float(last.br().x), float(last.br().y)), cv::Point2f(float(first.x), float(last.br().y))};
    return patches;
}

/** The calibration bursts (every gain and level, then the dark ones), followed by the validation bursts
 * when asked; `calibrationBursts` is the count of the former.
 * @param range white level minus the highest black level
 * @param sceneMax the chart's largest mean at unit gain and exposure */
std::vector<PlannedBurst> planBursts(const SimulateOptions& o, double range, double sceneMax,
                                     size_t& calibrationBursts)
{
    std::vector<PlannedBurst> bursts;
    for (double gDb : o.gainsDb)
        for (double level : o.levels) {
            const double g = dbToLinearGain(gDb);
            bursts.push_back({burstFolder(gDb, level), gDb, level * range / (g * sceneMax), level, o.frames,
                              deriveSeed(o.seed, SEED_SIMULATED_BURST, bursts.size())});
        }
    // Dark frames (no light: the lens cap) after the lit bursts, so that their seeds leave those alone.
    if (o.dark)
        for (double gDb : o.gainsDb) {
            const std::string folder = burstFolder(gDb, 0);
            bursts.push_back({"dark_" + folder.substr(0, folder.find('_')), gDb, 0.0, 0.0, o.frames,
                              deriveSeed(o.seed, SEED_SIMULATED_BURST, bursts.size()), true});
        }
    for (size_t i = 0; i < bursts.size(); ++i)
        for (size_t j = 0; j < i; ++j)
            if (bursts[i].dir == bursts[j].dir)
                throw std::runtime_error(
                    cv::format("gains %g and %g dB at levels %g and %g share the folder '%s': "
                               "give gains and levels that differ by at least 0.01",
                               bursts[j].gainDb, bursts[i].gainDb, bursts[j].level, bursts[i].level,
                               bursts[i].dir.c_str()));
    calibrationBursts = bursts.size();
    if (o.validation) {
        const double g = dbToLinearGain(o.validationGainDb);
        const double bright = 0.9 * range / (g * sceneMax);
        const uint64_t seeds[3] = {deriveSeed(o.seed, SEED_SIMULATED_VALIDATION_BURST, 0),
                                   deriveSeed(o.seed, SEED_SIMULATED_VALIDATION_BURST, 1),
                                   deriveSeed(o.seed, SEED_SIMULATED_VALIDATION_BURST, 2)};
        bursts.push_back(
            {"validation/bright", o.validationGainDb, bright, 0.9, o.validationFrames, seeds[0]});
        bursts.push_back(
            {"validation/x0.50", o.validationGainDb, 0.5 * bright, 0.45, o.validationFrames, seeds[1]});
        bursts.push_back(
            {"validation/x0.10", o.validationGainDb, 0.1 * bright, 0.09, o.validationFrames, seeds[2]});
    }
    return bursts;
}

//! The job before any frame: a folder holds the frames of one job, and a rerun continues only that job.
void claimJob(const SimulateOptions& o)
{
    const std::string jobPath = o.outDir + "/simulation_job.yml", job = jobDescription(o);
    if (pathExists(jobPath)) {
        const std::string existing =
            cv::rawgment::readFileBounded(jobPath, cv::rawgment::MAX_TEXT_FILE_BYTES, "simulation job file");
        if (existing != job)
            throw std::runtime_error("'" + jobPath +
                                     "' describes another simulation (other gains, levels, frames, "
                                     "sensor or seed): its frames are not this job's; choose another --out");
    } else {
        writeTextAtomically(jobPath, job);
    }
}

/** Writes every burst's frames that are not there yet and returns each burst's file names relative to
 * the output folder. */
std::vector<std::vector<std::string>> writeFrames(const SimulateOptions& o, const SensorSimulator& sensor,
                                                  const cv::Mat& meanAtUnitGain,
                                                  const std::vector<PlannedBurst>& bursts, int& written)
{
    const cv::Mat darkScene = cv::Mat::zeros(meanAtUnitGain.size(), meanAtUnitGain.type());
    size_t totalFrames = 0;
    for (const PlannedBurst& b : bursts)
        totalFrames += size_t(b.frames);
    ProgressBar progress("simulate", totalFrames);
    std::vector<std::vector<std::string>> files(bursts.size());
    for (size_t i = 0; i < bursts.size(); ++i) {
        const PlannedBurst& b = bursts[i];
        makeDirectories(o.outDir + "/" + b.dir);
        const double g = dbToLinearGain(b.gainDb);
        MosaicMetadata meta;
        meta.format = sensor.rawFormat(g);
        meta.source =
            cv::format("simulated colour checker, gain %.2f dB, exposure %.6g", b.gainDb, b.exposure);
        // Tags as a camera writes them, so that calibration can take the gain from the files: ISO 100 at
        // unit gain, 1/100 s per unit of exposure (the DNG rounds the ISO to an integer; the sidecar keeps
        // the exact gain).
        meta.hasCamera = true;
        meta.camera.make = "cv::rawgment";
        meta.camera.model = "simulated sensor";
        meta.camera.iso = kSimulatedBaseIso * g;
        meta.camera.exposureTime = 0.01 * b.exposure;
        for (int t = 0; t < b.frames; ++t) {
            const std::string name = b.dir + cv::format("/frame_%03d", t) + o.extension;
            files[i].push_back(name);
            const std::string path = o.outDir + "/" + name;
            // Frames are deterministic: a frame left by an interrupted run is already right.
            if (!pathExists(path)) {
                cv::Mat raw;
                // Dark frames see no light at all; the simulator's exposure must stay positive.
                if (b.dark)
                    sensor.capture(darkScene, g, 1.0, b.seed, t, raw);
                else
                    sensor.capture(meanAtUnitGain, g, b.exposure, b.seed, t, raw);
                writeMosaic(path, raw, meta);
            }
            ++written;
            progress.advance();
        }
    }
    progress.finish();
    return files;
}

std::string validationManifestText(const SimulateOptions& o,
                                   const std::vector<std::vector<std::string>>& files,
                                   size_t calibrationBursts)
{
    return fileStorageText("validation_manifest.yml", [&](cv::FileStorage& fs) {
        fs << "validation_manifest"
           << "{";
        fs << "patches"
           << "patches.yml";
        fs << "gain_db" << o.validationGainDb;
        writeStringList(fs, "bright", files[calibrationBursts]);
        fs << "targets"
           << "[";
        for (size_t k = 1; k <= 2; ++k) {
            fs << "{"
               << "factor" << (k == 1 ? 0.5 : 0.1);
            writeStringList(fs, "files", files[calibrationBursts + k]);
            fs << "}";
        }
        fs << "]"
           << "}";
    });
}

std::string calibrationManifestText(const std::vector<PlannedBurst>& bursts,
                                    const std::vector<std::vector<std::string>>& files,
                                    size_t calibrationBursts)
{
    return fileStorageText("calibration_manifest.yml", [&](cv::FileStorage& fs) {
        fs << "calibration_manifest"
           << "{";
        fs << "patches"
           << "patches.yml";
        fs << "bursts"
           << "[";
        for (size_t i = 0; i < calibrationBursts; ++i) {
            fs << "{"
               << "gain_db" << bursts[i].gainDb << "level" << bursts[i].level;
            if (bursts[i].dark)
                fs << "dark" << 1;
            writeStringList(fs, "files", files[i]);
            fs << "}";
        }
        fs << "]"
           << "}";
    });
}

} // namespace

SimulateResult simulateBursts(const SimulateOptions& o)
{
    checkSimulateOptions(o);
    prepareOutputDirectory(o.outDir);
    SimulateResult result;
    result.manifest = o.outDir + "/manifest.yml";
    result.truthModel = o.outDir + "/truth_noise_model.yml";
    const std::string patchesPath = o.outDir + "/patches.yml";
    refuseExisting({result.manifest, result.truthModel, patchesPath});

    ColorCheckerOptions co;
    co.pattern = o.sensor.pattern;
    co.patchSize = o.patchSize;
    const ColorCheckerScene scene = makeColorCheckerScene(co);
    SensorParams params = o.sensor;
    if (o.darkShading > 0)
        addDarkShadingPattern(scene.meanAtUnitGain.size(), o.darkShading, o.seed, params.noise);
    const SensorSimulator sensor(params, scene.meanAtUnitGain.size());
    double sceneMax = 0;
    cv::minMaxLoc(scene.meanAtUnitGain, nullptr, &sceneMax);
    const RawFormat unit = sensor.rawFormat(1.0);
    const double range = unit.whiteLevel - *std::max_element(unit.blackLevel.val, unit.blackLevel.val + 4);

    size_t calibrationBursts = 0;
    const std::vector<PlannedBurst> bursts = planBursts(o, range, sceneMax, calibrationBursts);
    claimJob(o);
    const std::vector<std::vector<std::string>> files =
        writeFrames(o, sensor, scene.meanAtUnitGain, bursts, result.files);

    rawgment_helpers::writeChartPatches(patchesPath, chartPatchesOf(scene, o.patchSize));
    // The frames say ISO kSimulatedBaseIso g, so the truth's gain 1 is that ISO.
    NoiseModel truth = sensor.effectiveModel();
    truth.baseIso = kSimulatedBaseIso;
    truth.save(result.truthModel);
    if (o.validation) {
        result.validationManifest = o.outDir + "/validation_manifest.yml";
        writeTextAtomically(result.validationManifest, validationManifestText(o, files, calibrationBursts));
    }
    // The manifest last: its presence marks a complete simulation.
    writeTextAtomically(result.manifest, calibrationManifestText(bursts, files, calibrationBursts));
    return result;
}

} // namespace rawgment_apps
