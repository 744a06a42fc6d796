// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_calibrate: a noise model from the bursts of a manifest, with CSV tables and plots.
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "calibrate_outputs.hpp"
#include "flow_common.hpp"
#include "plots.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

namespace {

//! A manifest made from a folder of burst folders.
CalibrationManifest manifestOfFolder(const std::string& dir)
{
    CalibrationManifest manifest;
    manifest.patches = "none";
    std::vector<std::string> folders;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        if (entry.is_directory())
            folders.push_back(entry.path().string());
    std::sort(folders.begin(), folders.end());
    for (const std::string& folder : folders) {
        CalibrationManifest::Burst burst;
        burst.dark = std::filesystem::path(folder).filename().string().rfind("dark", 0) == 0;
        for (const auto& entry : std::filesystem::directory_iterator(folder)) {
            const std::string name = entry.path().filename().string();
            // Sidecars (<image>.yml) belong to their images; hidden files to nobody.
            const bool sidecar = name.size() > 4 && name.compare(name.size() - 4, 4, ".yml") == 0;
            if (entry.is_regular_file() && !sidecar && name[0] != '.')
                burst.files.push_back(entry.path().string());
        }
        std::sort(burst.files.begin(), burst.files.end());
        if (!burst.files.empty())
            manifest.bursts.push_back(burst);
    }
    if (manifest.bursts.empty())
        throw std::runtime_error("'" + dir + "' has no folder of frames (one folder per burst)");
    return manifest;
}

} // namespace

CalibrationManifest readCalibrationManifest(const std::string& path)
{
    if (std::filesystem::is_directory(path))
        return manifestOfFolder(path);
    cv::FileStorage fs = openFileStorageForReading(path, "calibration manifest");
    const cv::FileNode root = fs["calibration_manifest"];
    if (!root.isMap() || !root["bursts"].isSeq() || root["bursts"].size() == 0)
        throw std::runtime_error("'" + path +
                                 "': expected a map 'calibration_manifest' with a list 'bursts'");
    requireKnownKeys(root, {"patches", "base_iso", "bursts"}, "'" + path + "'");
    const std::string base = directoryOf(path);
    CalibrationManifest manifest;
    const cv::FileNode patches = root["patches"];
    if (!patches.empty() && !patches.isString())
        throw std::runtime_error("'" + path +
                                 "': 'patches' must be \"detect\", \"none\" or the path of a chart patches "
                                 "file");
    const std::string value = patches.empty() ? std::string("detect") : std::string(patches);
    manifest.patches = value == "detect" || value == "none" ? value : resolvePath(base, value);
    const cv::FileNode baseIso = root["base_iso"];
    if (!baseIso.empty()) {
        if (!(baseIso.isReal() || baseIso.isInt()) || !(double(baseIso) >= NoiseModel::MIN_BASE_ISO) ||
            !(double(baseIso) <= NoiseModel::MAX_BASE_ISO))
            throw std::runtime_error(cv::format("'%s': 'base_iso' must be a number in [%g, %g]", path.c_str(),
                                                NoiseModel::MIN_BASE_ISO, NoiseModel::MAX_BASE_ISO));
        manifest.hasBaseIso = true;
        manifest.baseIso = double(baseIso);
    }
    for (const cv::FileNode& b : root["bursts"]) {
        const std::string where = cv::format("'%s' burst %zu", path.c_str(), manifest.bursts.size() + 1);
        if (!b.isMap())
            throw std::runtime_error(where + ": expected a map with 'files'");
        requireKnownKeys(b, {"gain_db", "level", "dark", "files"}, where);
        CalibrationManifest::Burst burst;
        if (!b["gain_db"].empty()) {
            if (!(b["gain_db"].isReal() || b["gain_db"].isInt()))
                throw std::runtime_error(where + ": 'gain_db' is not a number");
            burst.hasGainDb = true;
            burst.gainDb = double(b["gain_db"]);
            if (!std::isfinite(burst.gainDb))
                throw std::runtime_error(where + ": 'gain_db' is not finite");
        }
        if (!b["dark"].empty()) {
            // The module's reader hands YAML's and JSON's booleans over as "true" and "false", which no
            // number reader takes; 1 and 0 are how OpenCV writes a bool.
            const cv::FileNode dark = b["dark"];
            if (dark.isString() && (dark.string() == "true" || dark.string() == "false"))
                burst.dark = dark.string() == "true";
            else if (dark.isInt() && (int(dark) == 0 || int(dark) == 1))
                burst.dark = int(dark) == 1;
            else
                throw std::runtime_error(where + ": 'dark' must be true or false");
        }
        burst.files = readFileList(b["files"], base, where);
        manifest.bursts.push_back(burst);
    }
    return manifest;
}

namespace {

//! "make model" of a frame's camera, or "no camera tags".
std::string cameraName(const LoadedMosaic& m)
{
    if (m.camera.make.empty() && m.camera.model.empty())
        return "no camera tags";
    return "camera '" + m.camera.make + " " + m.camera.model + "'";
}

/** A model describes one sensor: frames of two cameras (make or model tags that differ) are refused,
 * naming both, instead of being calibrated into one model named after the first. */
void requireSameCamera(const LoadedMosaic& first, const std::string& firstPath, const LoadedMosaic& m,
                       const std::string& path)
{
    if (m.camera.make == first.camera.make && m.camera.model == first.camera.model)
        return;
    throw std::runtime_error("'" + path + "' comes from " + cameraName(m) + " and '" + firstPath + "' from " +
                             cameraName(first) +
                             ": a noise model describes one sensor, so calibrate each camera on its own");
}

//! What must be the same in every frame of a burst; the first frame's, compared with each other frame's.
void requireSameCapture(const LoadedMosaic& first, const std::string& firstPath, const LoadedMosaic& m,
                        const std::string& path)
{
    requireSameCamera(first, firstPath, m, path);
    std::string what;
    if (m.mosaic.size() != first.mosaic.size())
        what = cv::format("is %dx%d where '%s' is %dx%d", m.mosaic.cols, m.mosaic.rows, firstPath.c_str(),
                          first.mosaic.cols, first.mosaic.rows);
    else if (m.format.pattern != first.format.pattern || m.format.blackLevel != first.format.blackLevel ||
             m.format.whiteLevel != first.format.whiteLevel)
        what = "has other levels or another CFA pattern than '" + firstPath + "'";
    else if (m.camera.iso != first.camera.iso)
        what = cv::format("says ISO %g where '%s' says ISO %g", m.camera.iso, firstPath.c_str(),
                          first.camera.iso);
    else if (m.camera.exposureTime != first.camera.exposureTime)
        what = cv::format("has exposure time %g s where '%s' has %g s", m.camera.exposureTime,
                          firstPath.c_str(), first.camera.exposureTime);
    if (!what.empty())
        throw std::runtime_error("'" + path + "' " + what +
                                 ": the frames of a burst must share ISO, exposure, size and levels");
}

std::string formatDescription(const RawFormat& f)
{
    return cv::format("%s, black %g/%g/%g/%g, white %g", cfaPatternName(f.pattern).c_str(), f.blackLevel[0],
                      f.blackLevel[1], f.blackLevel[2], f.blackLevel[3], f.whiteLevel);
}

/* --dark_components fits the dark frames' rows, tails and shading with the first burst's format: dark
 * frames of another camera mode (another pattern or levels) would be fitted as if they were this one's. */
void requireOneFormatForDarkComponents(const RawFormat& first, const std::string& firstPath,
                                       const RawFormat& f, const std::string& path)
{
    if (f.pattern == first.pattern && f.blackLevel == first.blackLevel && f.whiteLevel == first.whiteLevel)
        return;
    throw std::runtime_error("'" + path + "' (" + formatDescription(f) + ") has another format than '" +
                             firstPath + "' (" + formatDescription(first) +
                             "): --dark_components fits every burst with one format, so dark frames must "
                             "come from the same camera and mode as the light bursts");
}

//! Positions spread over the frame, away from its border, for the Shapiro-Wilk test without squares.
std::vector<cv::Rect> frameGridSquares(cv::Size size)
{
    const int border = 8;
    if (size.width <= 2 * border || size.height <= 2 * border)
        return {cv::Rect(0, 0, size.width & ~1, size.height & ~1)};
    return {cv::Rect(border, border, (size.width - 2 * border) & ~1, (size.height - 2 * border) & ~1)};
}

/* The gain of each burst: the manifest's gain_db, or the ISO of its first frame relative to the base ISO
 * (the manifest's, or the lowest that a burst without gain_db has); with it the files' ISOs, the first
 * frame's size and camera (into `result`), the base ISO and a note per burst. */
struct BurstGains
{
    std::vector<double> isos, gainsDb;
    cv::Size frameSize;
};

BurstGains burstGains(const CalibrationManifest& manifest, CalibrateResult& result)
{
    const std::vector<CalibrationManifest::Burst>& specs = manifest.bursts;
    BurstGains gains;
    std::vector<double>& isos = gains.isos;
    isos.assign(specs.size(), 0.0);
    LoadedMosaic firstOfAll;
    for (size_t i = 0; i < specs.size(); ++i) {
        const LoadedMosaic first = loadMosaicFile(specs[i].files.front());
        if (i == 0) {
            gains.frameSize = first.mosaic.size();
            result.camera = first.camera;
            firstOfAll = first;
        }
        requireSameCamera(firstOfAll, specs.front().files.front(), first, specs[i].files.front());
        isos[i] = first.camera.iso;
    }
    // Files that say no ISO and a manifest that gives no gain: one gain, whose value is unknown. The
    // calibration then finds the noise line of that capture, and says what it cannot determine.
    const bool noGainAnywhere =
        std::none_of(specs.begin(), specs.end(),
                     [](const CalibrationManifest::Burst& b) { return b.hasGainDb; }) &&
        std::none_of(isos.begin(), isos.end(), [](double iso) { return iso > 0; });
    for (size_t i = 0; i < specs.size() && !noGainAnywhere; ++i)
        if (!specs[i].hasGainDb && !(isos[i] > 0))
            throw std::runtime_error("'" + specs[i].files.front() +
                                     "' does not say its ISO: give this burst a gain_db in a manifest");
    if (noGainAnywhere)
        result.notes.push_back(
            "the files do not say their ISO and the manifest gives no gain_db: every burst is "
            "taken at gain 1 (0 dB), so alpha is the slope at this unknown gain, and neither "
            "the gain nor the split of the read noise into sigma_d^2 and sigma_r^2 can be "
            "determined");
    result.baseIso = manifest.hasBaseIso ? manifest.baseIso : 0.0;
    for (size_t i = 0; i < specs.size(); ++i)
        if (!manifest.hasBaseIso && !specs[i].hasGainDb && (result.baseIso == 0 || isos[i] < result.baseIso))
            result.baseIso = isos[i];
    std::vector<double>& gainsDb = gains.gainsDb;
    gainsDb.assign(specs.size(), 0.0);
    for (size_t i = 0; i < specs.size() && !noGainAnywhere; ++i) {
        gainsDb[i] = specs[i].hasGainDb ? specs[i].gainDb : linearGainToDb(isos[i] / result.baseIso);
        result.notes.push_back(
            specs[i].hasGainDb
                ? cv::format("burst %zu (%s%s): gain %.2f dB from the manifest", i + 1,
                             specs[i].files.front().c_str(), specs[i].dark ? ", dark" : "", gainsDb[i])
                : cv::format("burst %zu (%s%s): gain %.2f dB from ISO %g relative to base ISO %g%s", i + 1,
                             specs[i].files.front().c_str(), specs[i].dark ? ", dark" : "", gainsDb[i],
                             isos[i], result.baseIso,
                             manifest.hasBaseIso ? " (manifest)" : " (the lowest in the files)"));
    }

    return gains;
}

/* --dark_components: calibrateWithDarkFrames() on the light and dark samples and the dark bursts (their
 * frames are released after): the base fit, the components, the light samples' shading correction and
 * refit, and the rows out of the read terms; `samples` become the final fit's. */
void addDarkComponents(std::vector<std::vector<cv::Mat>>& darkFrames, const std::vector<double>& darkGains,
                       const RawFormat& firstFormat, const CalibrationParams& params,
                       std::vector<NoiseSample>& samples, const std::vector<bool>& lightSample,
                       const std::vector<cv::Size>& sampleFrame, CalibrateResult& result)
{
    if (darkFrames.empty())
        throw std::runtime_error(
            "--dark_components needs dark bursts (dark: true in the manifest, or folders "
            "named dark*) of 3 or more frames");
    std::vector<NoiseSample> light, dark;
    std::vector<cv::Size> lightFrames;
    for (size_t i = 0; i < samples.size(); ++i) {
        (lightSample[i] ? light : dark).push_back(samples[i]);
        if (lightSample[i])
            lightFrames.push_back(sampleFrame[i]);
    }
    const DarkFrameCalibration fit = calibrateWithDarkFrames(light, dark, darkFrames, darkGains, firstFormat,
                                                             params, DarkCalibrationParams(), lightFrames);
    darkFrames.clear();
    // The samples as the final fit used them (light means without the shading), in the bursts' order.
    size_t nextLight = 0, nextDark = light.size();
    for (size_t i = 0; i < samples.size(); ++i)
        samples[i] = fit.samples[lightSample[i] ? nextLight++ : nextDark++];
    result.report = fit.report;
    result.report.model.baseIso = result.baseIso;
    result.dark = fit.dark;
    result.dark.model.baseIso = result.baseIso;
    result.notes.insert(result.notes.end(), fit.notes.begin(), fit.notes.end());
    result.haveDark = true;
}

/* What the bursts give the calibration, read frame by frame: the noise samples (and per sample whether
 * its burst had light and the size of its frame), the Shapiro-Wilk rows, the facts the verdict judges,
 * the first burst's format, and the dark bursts' frames for the dark-frame components. */
struct BurstInputs
{
    std::vector<NoiseSample> samples;
    std::vector<bool> lightSample; // per sample: from a burst with light (its mean holds the dark shading)
    std::vector<cv::Size> sampleFrame; // per sample: the size of the frame whose pixel it numbers
    CsvTable shapiro{{"gain_db", "mean", "p_value", "W"}};
    std::vector<CalibrationBurstFacts> facts;
    RawFormat firstFormat;
    // The dark bursts' frames, kept for the dark-frame components (their statistics need every frame).
    std::vector<std::vector<cv::Mat>> darkFrames;
    std::vector<double> darkGains;
};

/* Shapiro-Wilk positions: every k-th pixel of the squares (of each burst's own frame without a chart), at
 * most shapiroPixels of them. Bursts may differ in size (dark frames of a crop, say): each is read only
 * inside its own frame. */
std::vector<cv::Point> testedPositions(const std::vector<cv::Rect>& rects, int shapiroPixels)
{
    std::vector<cv::Point> positions;
    for (const cv::Rect& s : rects)
        for (int y = s.y; y < s.br().y; ++y)
            for (int x = s.x; x < s.br().x; ++x)
                positions.emplace_back(x, y);
    const size_t step = std::max<size_t>(1, positions.size() / size_t(std::max(1, shapiroPixels)));
    std::vector<cv::Point> tested;
    for (size_t k = 0; k < positions.size(); k += step)
        tested.push_back(positions[k]);
    return tested;
}

/* A burst's facts for the verdict (its clipped share of the sampled area) and its Shapiro-Wilk rows (the
 * unclipped, non-constant tested pixels); returns how many of them look Gaussian at 5%. */
int addBurstFactsAndShapiro(const BurstStatistics& stats, const std::string& name, double gainDb, bool dark,
                            const std::vector<cv::Rect>& sampledRects, const cv::Mat& series,
                            const std::vector<cv::Point>& tested, BurstInputs& in, CalibrateResult& result)
{
    // Shapiro-Wilk needs 3 values per pixel.
    std::vector<ShapiroWilkResult> sw;
    if (series.rows >= 3)
        shapiroWilkBatch(series, sw, SW_SERIES_IN_COLUMNS);
    cv::Mat mean, clipped;
    stats.mean(mean);
    stats.clippedMask(clipped);
    CalibrationBurstFacts burstFacts{name, gainDb, stats.frames(), 0.0, dark};
    double area = 0, clippedArea = 0;
    for (const cv::Rect& r : sampledRects) {
        area += r.area();
        clippedArea += cv::countNonZero(clipped(r));
    }
    burstFacts.clippedFraction = area > 0 ? clippedArea / area : 0.0;
    in.facts.push_back(burstFacts);
    int gaussian = 0;
    for (size_t k = 0; k < sw.size(); ++k) {
        if (clipped.at<uchar>(tested[k]) || sw[k].constant)
            continue;
        in.shapiro.addRow(std::vector<double>{gainDb, mean.at<double>(tested[k]), sw[k].pValue, sw[k].W});
        ++result.shapiroTested;
        gaussian += sw[k].pValue > 0.05;
    }
    return gaussian;
}

BurstInputs readBursts(const CalibrateOptions& o, const std::vector<CalibrationManifest::Burst>& specs,
                       const std::vector<double>& gainsDb, const std::vector<cv::Rect>& squares,
                       bool chartless, cv::Size frameSize, size_t totalFrames, CalibrateResult& result)
{
    BurstInputs in;
    int gaussian = 0;
    ProgressBar progress("calibrate", totalFrames);
    // One object for every burst, reset between them: its 12 MP state's pages are touched once.
    std::unique_ptr<BurstStatistics> stats;
    for (size_t i = 0; i < specs.size(); ++i) {
        const CalibrationManifest::Burst& spec = specs[i];
        const double gain = dbToLinearGain(gainsDb[i]);
        LoadedMosaic first;
        std::vector<cv::Point> tested;
        cv::Mat series;
        for (size_t t = 0; t < spec.files.size(); ++t) {
            const LoadedMosaic m = loadMosaicFile(spec.files[t]);
            if (t == 0) {
                RawFormat f = m.format;
                f.gain = gain;
                if (stats)
                    stats->reset(f);
                else
                    stats.reset(new BurstStatistics(f));
                if (i == 0)
                    in.firstFormat = m.format;
                first = m;
            } else {
                requireSameCapture(first, spec.files.front(), m, spec.files[t]);
            }
            if (o.darkComponents && t == 0 && i > 0)
                requireOneFormatForDarkComponents(in.firstFormat, specs.front().files.front(), m.format,
                                                  spec.files.front());
            stats->add(m.mosaic);
            if (spec.dark && o.darkComponents) {
                if (t == 0) {
                    in.darkFrames.emplace_back();
                    in.darkGains.push_back(gain);
                }
                in.darkFrames.back().push_back(m.mosaic);
            }
            if (t == 0) {
                for (const cv::Rect& s : squares)
                    if ((s & cv::Rect(cv::Point(), stats->size())) != s)
                        throw std::runtime_error(cv::format(
                            "square at (%d, %d) of %dx%d lies outside the %dx%d frames of '%s' (the squares "
                            "are found on '%s', %dx%d)",
                            s.x, s.y, s.width, s.height, stats->size().width, stats->size().height,
                            spec.files.front().c_str(), specs.front().files.front().c_str(), frameSize.width,
                            frameSize.height));
                tested =
                    testedPositions(chartless ? frameGridSquares(stats->size()) : squares, o.shapiroPixels);
                series.create(int(spec.files.size()), int(tested.size()), CV_64F);
            }
            // stats->add() has checked the size and the type (CV_16UC1 or CV_32FC1).
            const bool integer = m.mosaic.depth() == CV_16U;
            for (size_t k = 0; k < tested.size(); ++k)
                series.at<double>(int(t), int(k)) =
                    integer ? m.mosaic.at<ushort>(tested[k]) : double(m.mosaic.at<float>(tested[k]));
            progress.advance();
        }
        // One frame: single-frame mode, the spatial statistics of each patch (less exact, see
        // sampleSingleFramePatches()); it needs patches.
        const bool singleFrame = spec.files.size() == 1;
        if (singleFrame && (chartless || spec.dark))
            throw std::runtime_error(
                "'" + spec.files.front() +
                "' is a burst of one frame: single-frame mode needs the patches of a chart "
                "(patches: detect or a patches file), and dark frames need a burst");
        if (singleFrame)
            result.notes.push_back("'" + spec.files.front() +
                                   "': single-frame mode, the spatial variance of each patch (it includes "
                                   "fixed-pattern noise and any texture: less exact than a burst)");
        RawFormat burstFormat = first.format;
        burstFormat.gain = gain;
        // Dark frames: every unclipped pixel away from the border. A dark frame has no scene, so the static
        // sampler's flatness test would only reject the pixels of a dark-shading pattern (with 4 DN of
        // shading it kept a third of them, and the offsets were then extrapolated from the light samples:
        // +2.3%).
        const std::vector<NoiseSample> burstSamples =
            singleFrame ? sampleSingleFramePatches(first.mosaic, burstFormat, squares, gain)
            : spec.dark ? sampleDarkBurst(*stats, frameGridSquares(stats->size()), gain)
            : chartless ? sampleStaticScene(*stats, gain)
                        : sampleBurstPatches(*stats, squares, gain);
        in.samples.insert(in.samples.end(), burstSamples.begin(), burstSamples.end());
        in.lightSample.insert(in.lightSample.end(), burstSamples.size(), !spec.dark);
        in.sampleFrame.insert(in.sampleFrame.end(), burstSamples.size(), stats->size());
        gaussian += addBurstFactsAndShapiro(
            *stats, spec.files.front(), gainsDb[i], spec.dark,
            chartless || spec.dark ? frameGridSquares(stats->size()) : squares, series, tested, in, result);
    }
    progress.finish();
    result.gaussianFraction = result.shapiroTested ? double(gaussian) / result.shapiroTested : 0.0;
    return in;
}

//! How the standard errors would shrink with more frames, pixels, dark frames or one more gain.
void addProjections(const std::vector<NoiseSample>& samples, const std::vector<CalibrationBurstFacts>& facts,
                    CalibrateResult& result)
{
    const CalibrationReport& report = result.report;
    const double highest = report.perGain.back().gain;
    const auto plan = [&](const std::string& name, double frames, double pixels, bool dark, double gain) {
        CalibrationPlan p;
        p.frameFactor = frames;
        p.pixelFactor = pixels;
        p.addDarkFrames = dark;
        p.addGain = gain;
        result.projections.emplace_back(name, projectedStdError(samples, report, p));
    };
    plan("as shot", 1, 1, false, 0);
    plan("2x the frames per burst", 2, 1, false, 0);
    plan("4x the frames per burst", 4, 1, false, 0);
    plan("2x the pixels (patches)", 1, 2, false, 0);
    if (std::none_of(facts.begin(), facts.end(), [](const CalibrationBurstFacts& b) { return b.dark; }))
        plan("dark frames at each gain", 1, 1, true, 0);
    plan(cv::format("one more gain, %.1f dB", linearGainToDb(2 * highest)), 1, 1, false, 2 * highest);
}

/* The model with its dark-shading images (when the gains separate its terms), and the darktable and
 * Android exports when the gains come from ISO and the verdict passed. */
void writeModelAndExports(const CalibrateOptions& o, const std::vector<CalibrationManifest::Burst>& specs,
                          const BurstGains& gains, const RawFormat& firstFormat, CalibrateResult& result)
{
    const CalibrationReport& report = result.report;
    if (!report.separable) {
        result.notes.push_back(
            "sigma_d^2 and sigma_r^2 are not separable with these gains: no noise_model.yml "
            "written (see the report's notes)");
        return;
    }
    // Dark shading goes into two float TIFFs next to the model, which names them with their checksums.
    std::vector<std::string> shadingImages;
    if (report.model.hasDarkShading()) {
        shadingImages = {"noise_model.dark_shading_per_gain.tiff", "noise_model.dark_shading_offset.tiff"};
        writeNewImage(o.outDir + "/" + shadingImages[0], report.model.darkShadingPerGain);
        writeNewImage(o.outDir + "/" + shadingImages[1], report.model.darkShadingOffset);
    }
    writeNewText(o.outDir + "/noise_model.yml", fileStorageText("noise_model.yml", [&](cv::FileStorage& fs) {
                     report.model.write(fs, "noise_model",
                                        std::vector<cv::String>(shadingImages.begin(), shadingImages.end()));
                 }));
    // With gains from ISO the model carries over to the tools that index noise by ISO.
    if (result.baseIso > 0 && report.model.alpha > 0 && result.verdict.pass)
        writeProfileExports(o.outDir, specs, gains.gainsDb, gains.isos, firstFormat, result);
    else if (result.baseIso > 0 && report.model.alpha > 0)
        result.notes.push_back("the verdict is FAIL: darktable_noiseprofiles.json and "
                               "android_noise_profile.yml are not written, and noise_model.yml is marked "
                               "failed_calibration, so the apps and NoiseModel::load() refuse it unless "
                               "asked (--accept_failed_calibration)");
}

/* The per-gain lines of the gains that had light (a gain of dark frames alone has no slope to measure),
 * with their standard errors and the ISO their bursts say; a negative slope or offset (a fit's value, never
 * a variance) is taken as 0. */
std::vector<MeasuredNoiseLine> measuredLinesOf(const std::vector<NoiseLineFit>& perGain,
                                               const std::vector<CalibrationManifest::Burst>& specs,
                                               const BurstGains& gains)
{
    std::vector<MeasuredNoiseLine> lines;
    for (const NoiseLineFit& f : perGain) {
        MeasuredNoiseLine l;
        bool light = false;
        for (size_t i = 0; i < specs.size(); ++i)
            if (std::abs(gains.gainsDb[i] - linearGainToDb(f.gain)) < 1e-9 && !specs[i].dark) {
                light = true;
                l.iso = gains.isos[i];
            }
        if (!light)
            continue;
        l.gain = f.gain;
        l.line.a = std::max(f.line.a, 0.0);
        l.line.b = std::max(f.line.b, 0.0);
        // A standard error the fit could not state (too few samples) is written as 0, "not stated".
        l.slopeStdError = std::isfinite(f.slopeStdError) ? f.slopeStdError : 0.0;
        l.offsetStdError = std::isfinite(f.offsetStdError) ? f.offsetStdError : 0.0;
        lines.push_back(l);
    }
    return lines;
}

} // namespace

namespace {

/* --dark_bank: a bank of the dark bursts' files, each file's gain from its own ISO (through the calibrated
 * model's base ISO) or sidecar, as augmentation reads an input's gain; a burst whose manifest gain disagrees
 * with its files' is refused, as the bank would file its frames under another gain. */
std::vector<cv::String> darkBankFiles(const CalibrateOptions& o,
                                      const std::vector<CalibrationManifest::Burst>& specs)
{
    // What save() would refuse at the end is refused here, before the calibration's work (#79 item 23).
    const std::string ext = std::filesystem::path(o.darkBank).extension().string();
    if (ext != ".yml" && ext != ".yaml" && ext != ".json")
        throw std::runtime_error("--dark_bank '" + o.darkBank +
                                 "': a bank file is .yml, .yaml or .json (the extension picks the format)");
    const std::filesystem::path folder = std::filesystem::path(o.darkBank).parent_path();
    std::error_code error;
    if (!folder.empty() && !std::filesystem::is_directory(folder, error))
        throw std::runtime_error("--dark_bank '" + o.darkBank + "': its folder '" + folder.string() +
                                 "' does not exist (or is not a folder)");
    std::vector<cv::String> files;
    for (const CalibrationManifest::Burst& spec : specs)
        if (spec.dark)
            files.insert(files.end(), spec.files.begin(), spec.files.end());
    if (files.empty())
        throw std::runtime_error(
            "--dark_bank needs dark bursts (dark: true in the manifest, or folders named dark*)");
    return files;
}

/* An existing bank is refused before the work unless it is one this run may have made: a bank of these very
 * files (a rerun, or an identical run at the same time). Its content is compared when the bank is saved
 * (saveNewDarkFrameBank). */
void refuseAnotherExistingBank(const CalibrateOptions& o, const std::vector<cv::String>& files)
{
    if (pathExists(o.darkBank)) {
        std::set<std::string> ours, its;
        for (const cv::String& f : files)
            ours.insert(canonicalPath(f));
        try {
            for (const DarkFrameGroup& g : DarkFrameBank::load(o.darkBank).groups)
                for (const cv::String& f : g.files)
                    its.insert(canonicalPath(f));
        } catch (const cv::Exception& e) {
            throw std::runtime_error("'" + o.darkBank + "' exists and is not a bank this run makes (" +
                                     e.err + "); the dark-frame bank is never written over");
        }
        if (ours != its)
            throw std::runtime_error("'" + o.darkBank +
                                     "' exists and holds other dark frames than this run's; the dark-frame "
                                     "bank is never written over");
    }
}

/* Saves `bank` at `path` unless a bank is there, under a lock of its folder so that two runs take turns. An
 * existing bank is this run's output when it loads (maps checked) and is, text for text, the bank this run
 * made: the same frames with the same fingerprints, the same statistics and maps. Any other is refused. */
void saveNewDarkFrameBank(DarkFrameBank& bank, const std::string& path)
{
    const FolderLock lock(directoryOf(path));
    if (!pathExists(path)) {
        bank.save(path);
        return;
    }
    DarkFrameBank existing;
    try {
        existing = DarkFrameBank::load(path);
    } catch (const cv::Exception& e) {
        throw std::runtime_error("'" + path + "' exists and is not a bank (" + e.err +
                                 "); the dark-frame bank is never written over");
    }
    bank.path = existing.path;
    if (!bank.matchesItsFile())
        throw std::runtime_error("'" + path +
                                 "' exists and is another bank than this run's (other frames, frame content "
                                 "or statistics); the dark-frame bank is never written over");
}

void writeDarkFrameBank(const CalibrateOptions& o, const std::vector<CalibrationManifest::Burst>& specs,
                        const BurstGains& gains, CalibrateResult& result)
{
    const std::vector<cv::String> files = darkBankFiles(o, specs);
    const auto start = std::chrono::steady_clock::now();
    result.bank = DarkFrameBank::create(files, result.report.model);
    for (size_t i = 0; i < specs.size(); ++i) {
        if (!specs[i].dark)
            continue;
        const double gain = std::pow(10.0, gains.gainsDb[i] / 20);
        const auto holds = [&](const DarkFrameGroup& g) {
            return std::find(g.files.begin(), g.files.end(), specs[i].files.front()) != g.files.end();
        };
        const auto group = std::find_if(result.bank.groups.begin(), result.bank.groups.end(), holds);
        if (group != result.bank.groups.end() && std::abs(std::log(group->gain / gain)) > 1e-3)
            throw std::runtime_error(cv::format("--dark_bank: '%s' is at gain %g by its own ISO or sidecar, "
                                                "but the manifest puts its burst at %g "
                                                "(%.2f dB): a bank files frames by the gain they state",
                                                specs[i].files.front().c_str(), group->gain, gain,
                                                gains.gainsDb[i]));
    }
    saveNewDarkFrameBank(result.bank, o.darkBank);
    result.bankSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace

CalibrateResult calibrateFromManifest(const CalibrateOptions& o)
{
    const CalibrationManifest manifest = readCalibrationManifest(o.manifest);
    // A bank that cannot be written is refused before the calibration, not after it.
    if (!o.darkBank.empty())
        refuseAnotherExistingBank(o, darkBankFiles(o, manifest.bursts));
    prepareOutputDirectory(o.outDir);
    const std::string reportPath = o.outDir + "/calibration_report.yml",
                      samplesCsv = o.outDir + "/samples.csv", linesCsv = o.outDir + "/lines.csv",
                      shapiroCsv = o.outDir + "/shapiro.csv",
                      histCsv = o.outDir + "/variance_ratio_histogram.csv";
    // The calibration is deterministic, so every output already there must be what this run writes
    // (writeNewText refuses anything else, naming it): a run that died before its end is completed, and a
    // rerun of a finished one, or an identical run at the same time, finds its own outputs and succeeds.

    CalibrateResult result;
    const std::vector<CalibrationManifest::Burst>& specs = manifest.bursts;
    size_t totalFrames = 0;
    for (const CalibrationManifest::Burst& spec : specs)
        totalFrames += spec.files.size();

    const BurstGains gains = burstGains(manifest, result);
    const std::vector<double>& gainsDb = gains.gainsDb;
    const cv::Size frameSize = gains.frameSize;

    const bool chartless = manifest.patches == "none";
    const std::vector<cv::Rect> squares =
        chartless ? std::vector<cv::Rect>()
                  : manifestSquares(manifest.patches, specs.front().files.front(), o.side, result.notes);
    if (chartless)
        result.notes.push_back(
            "no chart: every unclipped pixel away from edges is a sample (sampleStaticScene)");

    BurstInputs in = readBursts(o, specs, gainsDb, squares, chartless, frameSize, totalFrames, result);
    std::vector<NoiseSample>& samples = in.samples;
    const RawFormat& firstFormat = in.firstFormat;

    CalibrationParams params;
    params.method = o.method;
    params.line.seed = o.seed;
    params.bootstrapReplicates = o.bootstrapReplicates;
    if (o.darkComponents)
        addDarkComponents(in.darkFrames, in.darkGains, firstFormat, params, samples, in.lightSample,
                          in.sampleFrame, result);
    else
        result.report = calibrateNoiseModel(samples, params);
    // The ISO of gain 1 travels with the model, so a camera file's ISO gives its gain when augmenting.
    result.report.model.baseIso = result.baseIso;
    const CalibrationReport& report = result.report;
    addProjections(samples, in.facts, result);
    result.verdict =
        judgeCalibration(samples, report, in.facts,
                         firstFormat.whiteLevel - (firstFormat.blackLevel[0] + firstFormat.blackLevel[1] +
                                                   firstFormat.blackLevel[2] + firstFormat.blackLevel[3]) /
                                                      4);
    // A failed verdict travels in the model, so no file of this calibration works silently:
    // NoiseModel::load() refuses it unless asked, and the exports, which other programs would read without
    // asking, are not written.
    if (!result.verdict.pass) {
        std::string failed;
        for (const VerdictCheck& c : result.verdict.checks)
            if (!c.pass)
                failed += (failed.empty() ? "" : ", ") + c.name;
        result.report.model.failedCalibration = failed;
    }
    // The per-gain fits travel with the model as its measured lines, which the augmentation follows; the
    // verdict above judged Eq. 5, which stays the model's summary and its trend beyond the gains.
    result.report.model.measuredLines = measuredLinesOf(report.perGain, specs, gains);
    writeNewText(reportPath, fileStorageText(reportPath, [&](cv::FileStorage& fs) {
                     report.write(fs, "calibration_report");
                 }));
    writeModelAndExports(o, specs, gains, firstFormat, result);
    if (!o.darkBank.empty())
        writeDarkFrameBank(o, specs, gains, result);

    const size_t histogramGains =
        writeSampleTables(samples, report, in.shapiro, samplesCsv, linesCsv, shapiroCsv, histCsv);
    PlotsWritten plots;
    if (result.haveDark)
        plots += writeDarkOutputs(o, result);
    if (o.plots) {
        std::vector<double> distinctGainsDb;
        for (double g : gainsDb)
            if (std::none_of(distinctGainsDb.begin(), distinctGainsDb.end(),
                             [&](double d) { return std::abs(g - d) < 1e-9; }))
                distinctGainsDb.push_back(g);
        CalibrationPlotFiles files{samplesCsv, linesCsv, histCsv, shapiroCsv};
        plots += plotCalibration(o.outDir, report, files, histogramGains, distinctGainsDb,
                                 result.shapiroTested > 0);
    }
    writeNewText(o.outDir + "/report.md", calibrationReportMarkdown(result, plots, o.outDir));
    result.pngs = plots.pngs;
    result.notes.insert(result.notes.end(), plots.notes.begin(), plots.notes.end());
    return result;
}

} // namespace rawgment_apps
