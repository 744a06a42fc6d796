// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "chart_patches.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

namespace {

std::string yamlToString(const std::function<void(cv::FileStorage&)>& body)
{
    cv::FileStorage fs(".yml",
                       cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    body(fs);
    return fs.releaseAndGetString();
}

cv::FileStorage openYaml(const std::string& path, const char* what)
{
    if (!pathExists(path))
        throw std::runtime_error(std::string("cannot open ") + what + " '" + path + "': no such file");
    cv::FileStorage fs(path, cv::FileStorage::READ);
    if (!fs.isOpened())
        throw std::runtime_error(std::string("cannot open ") + what + " '" + path + "'");
    return fs;
}

std::vector<std::string> readFileList(const cv::FileNode& node, const std::string& base,
                                      const std::string& where)
{
    if (!node.isSeq() || node.size() == 0)
        throw std::runtime_error(where + ": 'files' must be a non-empty list");
    std::vector<std::string> files;
    for (const cv::FileNode& f : node)
        files.push_back(resolvePath(base, std::string(f)));
    return files;
}

void refuseExisting(const std::vector<std::string>& outputs)
{
    for (const std::string& p : outputs)
        if (pathExists(p))
            throw std::runtime_error(
                "'" + p + "' already exists; outputs are never overwritten (choose another --out)");
}

//! Squares from a manifest's `patches` entry: a file written by writeChartPatches(), or "detect".
std::vector<cv::Rect> manifestSquares(const cv::FileNode& node, const std::string& base,
                                      const std::string& firstFrame, int side,
                                      std::vector<std::string>& notes)
{
    const std::string value = node.empty() ? std::string("detect") : std::string(node);
    if (value != "detect")
        return rawgment_helpers::readChartPatches(resolvePath(base, value)).squares;
    const LoadedMosaic m = loadMosaicFile(firstFrame);
    RawImage image;
    image.mosaic = m.mosaic;
    image.format = m.format;
    // Detection needs a visible chart: expose the preview so that the brightest 1% reaches 90%.
    cv::Mat signal;
    subtractBlackLevel(m.mosaic, m.format, signal, true);
    cv::Mat sorted = signal.reshape(1, 1).clone();
    cv::sort(sorted, sorted, cv::SORT_ASCENDING);
    const float p99 = sorted.at<float>(static_cast<int>(sorted.total() * 0.99));
    const double exposure = p99 > 0 ? std::min(64.0, std::max(1.0, 0.9 / p99)) : 1.0;
    rawgment_helpers::ChartPatches patches;
    std::string why;
    if (!rawgment_helpers::findChartPatches(rawgment_helpers::renderDetectionPreview(image, exposure), side,
                                            patches, why))
        throw std::runtime_error("'" + firstFrame + "': " + why);
    notes.push_back(
        cv::format("patches detected with cv::mcc on %s (exposure x%.2f)", firstFrame.c_str(), exposure));
    return patches.squares;
}

const char* kSeriesColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf"};

void plotOrNote(const std::string& png, const std::string& script, std::vector<std::string>& pngs,
                std::vector<std::string>& notes)
{
    std::string message;
    if (plotWithGnuplot(png, script, message))
        pngs.push_back(png);
    else
        notes.push_back(message);
}

uint64_t fnv1a(const std::string& text, uint64_t seed)
{
    uint64_t h = 1469598103934665603ull ^ seed;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return h;
}

} // namespace

LoadedMosaic loadMosaicFile(const std::string& path)
{
    LoadedMosaic out;
    if (pathExists(sidecarPathOf(path))) {
        const MosaicMetadata meta = readMosaic(path, out.mosaic);
        out.format = meta.format;
    } else {
        RawImage image = readRaw(path);
        out.mosaic = image.mosaic;
        out.format = image.format;
    }
    return out;
}

cv::Mat previewOf(const cv::Mat& mosaic, const RawFormat& format, double exposure)
{
    IspParams isp;
    isp.tone = ToneCurve::srgb();
    isp.exposure = exposure;
    cv::Mat bgr;
    renderSimpleIsp(mosaic, format, bgr, isp);
    return bgr;
}

// ---------------------------------------------------------------------------------------------------

SimulateResult simulateBursts(const SimulateOptions& o)
{
    if (o.outDir.empty())
        throw std::runtime_error("no output directory");
    if (o.frames < 2 || o.gainsDb.empty() || o.levels.empty())
        throw std::runtime_error("need at least 2 frames, one gain and one level");
    for (double level : o.levels)
        if (!(level > 0 && level <= 1))
            throw std::runtime_error(cv::format("level %g is outside (0, 1]", level));
    makeDirectories(o.outDir);
    SimulateResult result;
    result.manifest = o.outDir + "/manifest.yml";
    result.truthModel = o.outDir + "/truth_noise_model.yml";
    const std::string patchesPath = o.outDir + "/patches.yml";
    refuseExisting({result.manifest, result.truthModel, patchesPath});

    ColorCheckerOptions co;
    co.pattern = o.sensor.pattern;
    co.patchSize = o.patchSize;
    const ColorCheckerScene scene = makeColorCheckerScene(co);
    const SensorSimulator sensor(o.sensor, scene.meanAtUnitGain.size());
    double sceneMax = 0;
    cv::minMaxLoc(scene.meanAtUnitGain, nullptr, &sceneMax);
    const RawFormat unit = sensor.rawFormat(1.0);
    const double range = unit.whiteLevel - *std::max_element(unit.blackLevel.val, unit.blackLevel.val + 4);

    rawgment_helpers::ChartPatches patches;
    const int side = std::max(2, std::min(24, (o.patchSize - 8) & ~1));
    patches.squares = cfaAlignedSquares(scene.patches, side);
    const cv::Rect& first = scene.patches.front();
    const cv::Rect& last = scene.patches.back();
    patches.gridCorners = {
        cv::Point2f(float(first.x), float(first.y)), cv::Point2f(float(last.br().x), float(first.y)),
        cv::Point2f(float(last.br().x), float(last.br().y)), cv::Point2f(float(first.x), float(last.br().y))};

    struct Burst
    {
        std::string dir;
        double gainDb, exposure, level;
        int frames;
        uint64_t seed;
    };
    std::vector<Burst> bursts;
    uint64_t burstSeed = o.seed;
    for (double gDb : o.gainsDb)
        for (double level : o.levels) {
            const double g = dbToLinearGain(gDb);
            bursts.push_back({cv::format("g%02.0fdB_level%.2f", gDb, level), gDb,
                              level * range / (g * sceneMax), level, o.frames, ++burstSeed * 1000003ull});
        }
    const size_t calibrationBursts = bursts.size();
    if (o.validation) {
        const double g = dbToLinearGain(o.validationGainDb);
        const double bright = 0.9 * range / (g * sceneMax);
        bursts.push_back({"validation/bright", o.validationGainDb, bright, 0.9, o.validationFrames, 17});
        bursts.push_back(
            {"validation/x0.50", o.validationGainDb, 0.5 * bright, 0.45, o.validationFrames, 18});
        bursts.push_back(
            {"validation/x0.10", o.validationGainDb, 0.1 * bright, 0.09, o.validationFrames, 19});
    }
    size_t totalFrames = 0;
    for (const Burst& b : bursts)
        totalFrames += size_t(b.frames);
    ProgressBar progress("simulate", totalFrames);
    std::vector<std::vector<std::string>> files(bursts.size());
    for (size_t i = 0; i < bursts.size(); ++i) {
        const Burst& b = bursts[i];
        makeDirectories(o.outDir + "/" + b.dir);
        const double g = dbToLinearGain(b.gainDb);
        MosaicMetadata meta;
        meta.format = sensor.rawFormat(g);
        meta.source =
            cv::format("simulated colour checker, gain %.2f dB, exposure %.6g", b.gainDb, b.exposure);
        for (int t = 0; t < b.frames; ++t) {
            const std::string name = b.dir + cv::format("/frame_%03d", t) + o.extension;
            files[i].push_back(name);
            const std::string path = o.outDir + "/" + name;
            // Frames are deterministic: a frame left by an interrupted run is already right.
            if (!pathExists(path)) {
                cv::Mat raw;
                sensor.capture(scene.meanAtUnitGain, g, b.exposure, b.seed, t, raw);
                writeMosaic(path, raw, meta);
            }
            ++result.files;
            progress.advance();
        }
    }
    progress.finish();

    rawgment_helpers::writeChartPatches(patchesPath, patches);
    sensor.effectiveModel().save(result.truthModel);
    if (o.validation) {
        result.validationManifest = o.outDir + "/validation_manifest.yml";
        writeTextAtomically(result.validationManifest, yamlToString([&](cv::FileStorage& fs) {
                                fs << "validation_manifest"
                                   << "{";
                                fs << "patches"
                                   << "patches.yml";
                                fs << "gain_db" << o.validationGainDb;
                                fs << "bright" << files[calibrationBursts];
                                fs << "targets"
                                   << "[";
                                for (size_t k = 1; k <= 2; ++k) {
                                    fs << "{"
                                       << "factor" << (k == 1 ? 0.5 : 0.1);
                                    fs << "files" << files[calibrationBursts + k] << "}";
                                }
                                fs << "]"
                                   << "}";
                            }));
    }
    // The manifest last: its presence marks a complete simulation.
    writeTextAtomically(result.manifest, yamlToString([&](cv::FileStorage& fs) {
                            fs << "calibration_manifest"
                               << "{";
                            fs << "patches"
                               << "patches.yml";
                            fs << "bursts"
                               << "[";
                            for (size_t i = 0; i < calibrationBursts; ++i)
                                fs << "{"
                                   << "gain_db" << bursts[i].gainDb << "level" << bursts[i].level << "files"
                                   << files[i] << "}";
                            fs << "]"
                               << "}";
                        }));
    return result;
}

// ---------------------------------------------------------------------------------------------------

CalibrateResult calibrateFromManifest(const CalibrateOptions& o)
{
    cv::FileStorage fs = openYaml(o.manifest, "calibration manifest");
    const cv::FileNode root = fs["calibration_manifest"];
    if (!root.isMap() || !root["bursts"].isSeq() || root["bursts"].size() == 0)
        throw std::runtime_error("'" + o.manifest +
                                 "': expected a map 'calibration_manifest' with a list 'bursts'");
    const std::string base = directoryOf(o.manifest);
    makeDirectories(o.outDir);
    const std::string modelPath = o.outDir + "/noise_model.yml",
                      reportPath = o.outDir + "/calibration_report.yml",
                      samplesCsv = o.outDir + "/samples.csv", linesCsv = o.outDir + "/lines.csv",
                      shapiroCsv = o.outDir + "/shapiro.csv",
                      histCsv = o.outDir + "/variance_ratio_histogram.csv";
    refuseExisting({modelPath, reportPath, samplesCsv, linesCsv, shapiroCsv, histCsv});

    CalibrateResult result;
    struct BurstSpec
    {
        double gainDb;
        std::vector<std::string> files;
    };
    std::vector<BurstSpec> specs;
    size_t totalFrames = 0;
    for (const cv::FileNode& b : root["bursts"]) {
        const std::string where = cv::format("'%s' burst %zu", o.manifest.c_str(), specs.size() + 1);
        if (b["gain_db"].empty() || !(b["gain_db"].isReal() || b["gain_db"].isInt()))
            throw std::runtime_error(where + ": 'gain_db' is missing or not a number");
        specs.push_back({double(b["gain_db"]), readFileList(b["files"], base, where)});
        totalFrames += specs.back().files.size();
    }
    const std::vector<cv::Rect> squares =
        manifestSquares(root["patches"], base, specs.front().files.front(), o.side, result.notes);

    // Shapiro-Wilk positions, the same in every burst: every k-th pixel of the squares, at most
    // shapiroPixels of them.
    std::vector<cv::Point> positions;
    for (const cv::Rect& s : squares)
        for (int y = s.y; y < s.br().y; ++y)
            for (int x = s.x; x < s.br().x; ++x)
                positions.emplace_back(x, y);
    const size_t step = std::max<size_t>(1, positions.size() / size_t(std::max(1, o.shapiroPixels)));
    std::vector<cv::Point> tested;
    for (size_t k = 0; k < positions.size(); k += step)
        tested.push_back(positions[k]);

    std::vector<NoiseSample> samples;
    CsvTable shapiro({"gain_db", "mean", "p_value", "W"});
    int gaussian = 0;
    ProgressBar progress("calibrate", totalFrames);
    for (const BurstSpec& spec : specs) {
        const double gain = dbToLinearGain(spec.gainDb);
        std::unique_ptr<BurstStatistics> stats;
        cv::Mat series(int(spec.files.size()), int(tested.size()), CV_64F);
        for (size_t t = 0; t < spec.files.size(); ++t) {
            const LoadedMosaic m = loadMosaicFile(spec.files[t]);
            if (!stats) {
                RawFormat f = m.format;
                f.gain = gain;
                stats.reset(new BurstStatistics(f));
            }
            stats->add(m.mosaic);
            if (t == 0)
                for (const cv::Rect& s : squares)
                    if ((s & cv::Rect(cv::Point(), stats->size())) != s)
                        throw std::runtime_error(
                            cv::format("square at (%d, %d) lies outside the %dx%d frames", s.x, s.y,
                                       stats->size().width, stats->size().height));
            // stats->add() has checked the size and the type (CV_16UC1 or CV_32FC1).
            const bool integer = m.mosaic.depth() == CV_16U;
            for (size_t k = 0; k < tested.size(); ++k)
                series.at<double>(int(t), int(k)) =
                    integer ? m.mosaic.at<ushort>(tested[k]) : double(m.mosaic.at<float>(tested[k]));
            progress.advance();
        }
        const std::vector<NoiseSample> burstSamples = sampleBurstPatches(*stats, squares, gain);
        samples.insert(samples.end(), burstSamples.begin(), burstSamples.end());
        std::vector<ShapiroWilkResult> sw;
        shapiroWilkBatch(series, sw, SW_SERIES_IN_COLUMNS);
        cv::Mat mean, clipped;
        stats->mean(mean);
        stats->clippedMask(clipped);
        for (size_t k = 0; k < tested.size(); ++k) {
            if (clipped.at<uchar>(tested[k]) || sw[k].constant)
                continue;
            shapiro.addRow(
                std::vector<double>{spec.gainDb, mean.at<double>(tested[k]), sw[k].pValue, sw[k].W});
            ++result.shapiroTested;
            gaussian += sw[k].pValue > 0.05;
        }
    }
    progress.finish();
    result.gaussianFraction = result.shapiroTested ? double(gaussian) / result.shapiroTested : 0.0;

    CalibrationParams params;
    params.method = o.method;
    result.report = calibrateNoiseModel(samples, params);
    const CalibrationReport& report = result.report;
    report.save(reportPath);
    if (report.separable)
        report.model.save(modelPath);
    else
        result.notes.push_back(
            "sigma_d^2 and sigma_r^2 are not separable with these gains: no noise_model.yml "
            "written (see the report's notes)");

    CsvTable samplesTable({"mean", "variance", "gain_db", "channel", "dof"});
    for (const NoiseSample& s : samples)
        samplesTable.addRow(std::vector<double>{s.mean, s.variance, linearGainToDb(s.gain), double(s.channel),
                                                double(s.dof)});
    samplesTable.write(samplesCsv);
    CsvTable lines({"gain_db", "gain", "a", "b", "r_squared", "inliers", "samples", "model_a", "model_b"});
    for (const NoiseLineFit& l : report.perGain) {
        const NoiseLine m = report.model.lineAtGain(l.gain);
        lines.addRow(std::vector<double>{linearGainToDb(l.gain), l.gain, l.line.a, l.line.b, l.rSquared,
                                         double(l.inliers), double(l.samples), m.a, m.b});
    }
    lines.write(linesCsv);
    shapiro.write(shapiroCsv);

    // Histogram of variance / model variance per gain: a sample variance of T frames has mean 1 and
    // relative spread sqrt(2 / (T - 1)) around the model when the model is right.
    const int bins = 60;
    const double hiRatio = 3.0;
    std::map<double, std::vector<double>> counts;
    for (const NoiseSample& s : samples) {
        const double predicted = report.model.variance(s.mean, s.gain);
        if (!(predicted > 0))
            continue;
        const int b = static_cast<int>(s.variance / predicted / hiRatio * bins);
        std::vector<double>& c = counts[linearGainToDb(s.gain)];
        c.resize(bins, 0.0);
        if (b >= 0 && b < bins)
            c[size_t(b)] += 1;
    }
    std::vector<std::string> histHeader = {"ratio"};
    for (const auto& kv : counts)
        histHeader.push_back(cv::format("gain_%.1fdB", kv.first));
    CsvTable hist(histHeader);
    for (int b = 0; b < bins; ++b) {
        std::vector<double> row = {(b + 0.5) * hiRatio / bins};
        for (const auto& kv : counts)
            row.push_back(kv.second[size_t(b)]);
        hist.addRow(row);
    }
    hist.write(histCsv);

    if (!o.plots)
        return result;
    const NoiseModel& model = report.model;
    std::string s;
    s += "set title 'Noise calibration: temporal variance against mean at each gain'\n";
    s += "set xlabel 'mean signal above black (DN)'\nset ylabel 'temporal variance (DN^2)'\n";
    s += "set key left top box opaque\nset grid\n";
    s += "plot ";
    for (size_t i = 0; i < report.perGain.size(); ++i) {
        const NoiseLineFit& l = report.perGain[i];
        const double gDb = linearGainToDb(l.gain);
        const std::string colour = kSeriesColours[i % 7];
        s += cv::format("'%s' every ::1 using ($3 > %.6f && $3 < %.6f ? $1 : 1/0):2 with points pt 7 ps 0.25 "
                        "lc rgb '%s' title '%.1f dB samples', ",
                        samplesCsv.c_str(), gDb - 0.01, gDb + 0.01, colour.c_str(), gDb);
        s += cv::format(
            "%.10g*x + %.10g with lines lw 2 lc rgb '%s' dt 2 title 'line fit: %.4f {/Symbol m} + %.3f "
            "(R^2 %.4f)', ",
            l.line.a, l.line.b, colour.c_str(), l.line.a, l.line.b, l.rSquared);
    }
    s += cv::format("1/0 title 'model: {/Symbol a} %.4f, {/Symbol s}_d^2 %.4f, {/Symbol s}_r^2 %.4f'\n",
                    model.alpha, model.sigmaD2, model.sigmaR2);
    plotOrNote(o.outDir + "/calib_mean_variance.png", s, result.pngs, result.notes);

    s = "set title 'Sample variance over model variance, per gain (ideal: centred on 1)'\n";
    s += "set xlabel 'variance / model variance'\nset ylabel 'samples'\nset key right top\nset grid\nplot ";
    for (size_t i = 0; i < counts.size(); ++i)
        s += cv::format("%s'%s' every ::1 using 1:%zu with steps lw 2 lc rgb '%s' title columnhead(%zu)",
                        i ? ", " : "", histCsv.c_str(), i + 2, kSeriesColours[i % 7], i + 2);
    plotOrNote(o.outDir + "/calib_histograms.png", s, result.pngs, result.notes);

    s = "set multiplot layout 1,2 title 'Cross-gain fit of the per-gain lines'\nset grid\nset key left top\n";
    s += cv::format("set title 'slope a_g = g {/Symbol a}   (R^2 %.4f)'\nset xlabel 'linear gain g'\n"
                    "set ylabel 'a_g (DN per DN)'\n",
                    report.rSquaredSlope);
    s += cv::format(
        "plot '%s' every ::1 using 2:3 with points pt 7 ps 1.5 title 'per-gain fits', %.10g*x with lines "
        "lw 2 title 'g {/Symbol a}'\n",
        linesCsv.c_str(), model.alpha);
    s += cv::format("set title 'offset b_g = g^2 {/Symbol s}_d^2 + {/Symbol s}_r^2   (R^2 %.4f)'\n"
                    "set xlabel 'g^2'\nset ylabel 'b_g (DN^2)'\n",
                    report.rSquaredOffset);
    s += cv::format(
        "plot '%s' every ::1 using ($2*$2):4 with points pt 7 ps 1.5 title 'per-gain fits', "
        "%.10g*x + %.10g with lines lw 2 title 'g^2 {/Symbol s}_d^2 + {/Symbol s}_r^2'\nunset multiplot\n",
        linesCsv.c_str(), model.sigmaD2, model.sigmaR2);
    plotOrNote(o.outDir + "/calib_cross_gain.png", s, result.pngs, result.notes);

    s = "set title 'Shapiro-Wilk test of each pixel''s temporal series (Gaussian noise: p spread evenly on "
        "[0, 1])'\n";
    s += "set xlabel 'mean signal above black (DN)'\nset ylabel 'p-value'\nset logscale y\nset yrange "
         "[1e-6:1]\n";
    s += "set key right bottom box opaque\nset grid\nplot ";
    size_t series = 0;
    for (size_t i = 0; i < specs.size(); ++i) {
        bool seen = false;
        for (size_t j = 0; j < i; ++j)
            seen = seen || std::abs(specs[j].gainDb - specs[i].gainDb) < 1e-9;
        if (seen)
            continue;
        s += cv::format(
            "'%s' every ::1 using ($1 > %.6f && $1 < %.6f ? $2 : 1/0):($3 < 1e-6 ? 1e-6 : $3) with points "
            "pt 7 ps 0.3 lc rgb '%s' title '%.1f dB', ",
            shapiroCsv.c_str(), specs[i].gainDb - 0.01, specs[i].gainDb + 0.01, kSeriesColours[series++ % 7],
            specs[i].gainDb);
    }
    s += "0.05 with lines lw 2 lc rgb 'black' dt 2 title 'p = 0.05'\n";
    plotOrNote(o.outDir + "/shapiro_pvalue.png", s, result.pngs, result.notes);
    return result;
}

// ---------------------------------------------------------------------------------------------------

ValidateResult validateConversion(const ValidateOptions& o)
{
    cv::FileStorage fs = openYaml(o.manifest, "validation manifest");
    const cv::FileNode root = fs["validation_manifest"];
    if (!root.isMap() || !root["targets"].isSeq())
        throw std::runtime_error("'" + o.manifest +
                                 "': expected a map 'validation_manifest' with 'bright' and "
                                 "'targets'");
    const std::string base = directoryOf(o.manifest);
    const NoiseModel model = NoiseModel::load(o.model);
    makeDirectories(o.outDir);
    const std::string csvPath = o.outDir + "/validation.csv", mdPath = o.outDir + "/validation.md";
    refuseExisting({csvPath, mdPath});

    const std::vector<std::string> brightFiles =
        readFileList(root["bright"], base, "'" + o.manifest + "' bright");
    std::vector<LoadedMosaic> bright;
    for (const std::string& f : brightFiles)
        bright.push_back(loadMosaicFile(f));
    RawFormat format = bright.front().format;
    if (!root["gain_db"].empty())
        format.gain = dbToLinearGain(double(root["gain_db"]));
    cv::Mat mask(bright.front().mosaic.size(), CV_8U, cv::Scalar(root["patches"].empty() ? 255 : 0));
    if (!root["patches"].empty())
        for (const cv::Rect& s :
             rawgment_helpers::readChartPatches(resolvePath(base, root["patches"])).squares)
            mask(s & cv::Rect(cv::Point(), mask.size())).setTo(255);

    const auto statsOf = [&](const std::function<cv::Mat(size_t)>& frameAt, size_t frames, cv::Mat& mean,
                             cv::Mat& variance, cv::Mat& clipped) {
        BurstStatistics stats(format);
        for (size_t t = 0; t < frames; ++t)
            stats.add(frameAt(t));
        stats.mean(mean);
        stats.variance(variance);
        stats.clippedMask(clipped);
    };
    cv::Mat brightMean, brightVar, brightClip;
    statsOf([&](size_t t) { return bright[t].mosaic; }, bright.size(), brightMean, brightVar, brightClip);

    ValidateResult result;
    struct Target
    {
        double factor;
        std::vector<ValidationRow> rows;
    };
    std::vector<Target> targets;
    const NoiseAlignment alignments[3] = {NoiseAlignment::NONE, NoiseAlignment::IGNORE_PRIOR,
                                          NoiseAlignment::ACCOUNT_PRIOR};
    ProgressBar progress("validate", root["targets"].size() * (3 + 1) * bright.size());
    CsvTable csv({"factor", "mean_low", "mean_high", "mean", "pixels", "real_variance", "none_variance",
                  "ignore_prior_variance", "account_prior_variance", "bright_mean", "bright_variance"});
    for (const cv::FileNode& t : root["targets"]) {
        const double factor = double(t["factor"]);
        if (!(factor > 0 && factor <= 1))
            throw std::runtime_error(
                cv::format("'%s': target factor %g is outside (0, 1]", o.manifest.c_str(), factor));
        const std::vector<std::string> files = readFileList(t["files"], base, "'" + o.manifest + "' target");
        cv::Mat realMean, realVar, realClip;
        statsOf(
            [&](size_t k) {
                progress.advance();
                return loadMosaicFile(files[k]).mosaic;
            },
            files.size(), realMean, realVar, realClip);
        cv::Mat convVar[3];
        for (int a = 0; a < 3; ++a) {
            cv::Mat m, c;
            statsOf(
                [&](size_t k) {
                    cv::Mat out;
                    RawFormat outFormat;
                    colorJitter(bright[k].mosaic, format, model, ColorJitter::exposureChange(factor, 1.0),
                                alignments[a], o.seed * 1000003ull + k, out, outFormat);
                    progress.advance();
                    return out;
                },
                bright.size(), m, convVar[a], c);
        }
        // Bins of the real burst's mean (BurstStatistics subtracts the black) over the unclipped masked
        // pixels.
        double lo = 1e300, hi = -1e300;
        for (int y = 0; y < mask.rows; ++y)
            for (int x = 0; x < mask.cols; ++x)
                if (mask.at<uchar>(y, x) && !realClip.at<uchar>(y, x) && !brightClip.at<uchar>(y, x)) {
                    lo = std::min(lo, realMean.at<double>(y, x));
                    hi = std::max(hi, realMean.at<double>(y, x));
                }
        if (!(hi > lo))
            throw std::runtime_error("the target burst has no unclipped pixels with distinct means");
        std::vector<ValidationRow> rows(size_t(o.bins));
        std::vector<double> meanSum(size_t(o.bins), 0), brightMeanSum(size_t(o.bins), 0),
            brightVarSum(size_t(o.bins), 0);
        for (int b = 0; b < o.bins; ++b) {
            rows[size_t(b)].factor = factor;
            rows[size_t(b)].meanLow = lo + (hi - lo) * b / o.bins;
            rows[size_t(b)].meanHigh = lo + (hi - lo) * (b + 1) / o.bins;
        }
        for (int y = 0; y < mask.rows; ++y)
            for (int x = 0; x < mask.cols; ++x) {
                if (!mask.at<uchar>(y, x) || realClip.at<uchar>(y, x) || brightClip.at<uchar>(y, x))
                    continue;
                const double mu = realMean.at<double>(y, x);
                const int b = std::min(o.bins - 1, static_cast<int>((mu - lo) / (hi - lo) * o.bins));
                ValidationRow& r = rows[size_t(b)];
                ++r.pixels;
                meanSum[size_t(b)] += mu;
                r.realVariance += realVar.at<double>(y, x);
                r.noneVariance += convVar[0].at<double>(y, x);
                r.ignoreVariance += convVar[1].at<double>(y, x);
                r.accountVariance += convVar[2].at<double>(y, x);
                brightMeanSum[size_t(b)] += brightMean.at<double>(y, x);
                brightVarSum[size_t(b)] += brightVar.at<double>(y, x);
            }
        Target target{factor, {}};
        for (int b = 0; b < o.bins; ++b) {
            ValidationRow r = rows[size_t(b)];
            if (r.pixels == 0)
                continue;
            const double n = r.pixels;
            r.realVariance /= n;
            r.noneVariance /= n;
            r.ignoreVariance /= n;
            r.accountVariance /= n;
            csv.addRow(std::vector<double>{factor, r.meanLow, r.meanHigh, meanSum[size_t(b)] / n, n,
                                           r.realVariance, r.noneVariance, r.ignoreVariance,
                                           r.accountVariance, brightMeanSum[size_t(b)] / n,
                                           brightVarSum[size_t(b)] / n});
            target.rows.push_back(r);
            result.rows.push_back(r);
        }
        targets.push_back(target);
    }
    progress.finish();
    csv.write(csvPath);

    std::string md =
        "| factor | mean bin (DN) | pixels | real variance | NONE | IGNORE_PRIOR | ACCOUNT_PRIOR | "
        "ACCOUNT_PRIOR / real |\n|---|---|---|---|---|---|---|---|\n";
    for (const ValidationRow& r : result.rows)
        md += cv::format("| x%.2f | %.1f-%.1f | %d | %.3f | %.3f | %.3f | %.3f | %.3f |\n", r.factor,
                         r.meanLow, r.meanHigh, r.pixels, r.realVariance, r.noneVariance, r.ignoreVariance,
                         r.accountVariance, r.accountVariance / r.realVariance);
    result.table = md;
    writeTextAtomically(mdPath, md);

    if (!o.plots)
        return result;
    std::string s =
        cv::format("set multiplot layout 1,%zu title 'Bright burst converted to darker exposures against "
                   "real darker bursts (per-pixel temporal variance, averaged per mean bin)'\n",
                   targets.size());
    s += "set grid\nset key left top box opaque\nset xlabel 'mean signal above black (DN)'\n"
         "set ylabel 'temporal variance (DN^2)'\n";
    for (size_t i = 0; i < targets.size(); ++i) {
        const double f = targets[i].factor;
        const std::string sel = cv::format("($1 > %.6f && $1 < %.6f ? $4 : 1/0)", f - 1e-6, f + 1e-6);
        s += cv::format("set title 'x%.2f exposure'\nset xrange [0:%.6g]\nset yrange [0:*]\n", f,
                        targets[i].rows.empty() ? 1.0 : targets[i].rows.back().meanHigh * 1.05);
        s += cv::format(
            "plot '%s' every ::1 using %s:6 with points pt 7 ps 1.6 lc rgb 'black' title 'real darker "
            "burst', ",
            csvPath.c_str(), sel.c_str());
        s += cv::format(
            "'' every ::1 using %s:9 with linespoints lw 2 pt 5 lc rgb '#2ca02c' title 'ACCOUNT\\_PRIOR "
            "(ours)', ",
            sel.c_str());
        s += cv::format(
            "'' every ::1 using %s:8 with linespoints lw 2 pt 9 lc rgb '#ff7f0e' title 'IGNORE\\_PRIOR', ",
            sel.c_str());
        s += cv::format("'' every ::1 using %s:7 with linespoints lw 2 pt 11 lc rgb '#d62728' title 'NONE', ",
                        sel.c_str());
        s += cv::format(
            "'' every ::1 using ($1 > %.6f && $1 < %.6f ? $10 : 1/0):11 with points pt 6 ps 1.2 lc rgb "
            "'#7f7f7f' title 'bright burst (before)'\n",
            f - 1e-6, f + 1e-6);
    }
    s += "unset multiplot\n";
    plotOrNote(o.outDir + "/validation.png", s, result.pngs, result.notes);
    return result;
}

// ---------------------------------------------------------------------------------------------------

AugmentResult augmentFiles(const AugmentOptions& o)
{
    if (o.inputs.empty())
        throw std::runtime_error("no input files");
    if (o.scene.empty() == o.policy.empty())
        throw std::runtime_error("give exactly one of a scene file and a policy file");
    if (o.variants < 1)
        throw std::runtime_error("variants must be >= 1");
    const NoiseModel model = NoiseModel::load(o.model);
    Scene fixedScene;
    RandomScenePolicy policy;
    if (!o.scene.empty()) {
        cv::FileStorage fs = openYaml(o.scene, "scene");
        try {
            fixedScene = Scene::read(fs["scene"]);
        } catch (const cv::Exception& e) {
            throw std::runtime_error("'" + o.scene + "': " + e.err);
        }
    } else {
        policy = RandomScenePolicy::load(o.policy);
    }
    for (const std::string& in : o.inputs)
        if (!pathExists(in))
            throw std::runtime_error("input '" + in + "': no such file");
    makeDirectories(o.outDir);

    struct Job
    {
        size_t input;
        int variant;
        std::string out, preview;
    };
    std::vector<Job> jobs;
    AugmentResult result;
    for (size_t i = 0; i < o.inputs.size(); ++i) {
        const std::string inExt = o.inputs[i].substr(o.inputs[i].find_last_of('.'));
        const bool ours = pathExists(sidecarPathOf(o.inputs[i]));
        const std::string ext = !o.extension.empty() ? o.extension : (ours ? inExt : std::string(".dng"));
        for (int v = 0; v < o.variants; ++v) {
            const std::string stem = o.outDir + "/" + stemOf(o.inputs[i]) + cv::format("_v%02d", v);
            Job job{i, v, stem + ext, o.previews ? stem + "_preview.png" : std::string()};
            for (const std::string& in : o.inputs)
                if (in == job.out)
                    throw std::runtime_error("output '" + job.out +
                                             "' would replace an input; choose another --out");
            result.outputs.push_back(job.out);
            if (pathExists(job.out)) {
                ++result.skipped; // resumable: a finished output stays
                continue;
            }
            jobs.push_back(job);
        }
    }
    ProgressBar progress("augment", jobs.size());
    std::mutex errorMutex;
    std::string firstError;
    std::atomic<int> written{0};
    cv::parallel_for_(cv::Range(0, int(jobs.size())), [&](const cv::Range& range) {
        for (int j = range.start; j < range.end; ++j) {
            const Job& job = jobs[size_t(j)];
            try {
                const LoadedMosaic m = loadMosaicFile(o.inputs[job.input]);
                // The seed depends on the file name and the variant, not on the order of the inputs.
                const uint64_t seed = fnv1a(stemOf(o.inputs[job.input]), o.seed) +
                                      uint64_t(job.variant) * 0x9E3779B97F4A7C15ull;
                const Scene scene = o.scene.empty() ? policy.draw(m.mosaic, m.format, seed) : fixedScene;
                cv::Mat out;
                RawFormat outFormat;
                AugmentReport report;
                applyScene(m.mosaic, m.format, model, scene, seed ^ 0xA5A5A5A5A5A5A5A5ull, out, outFormat,
                           &report);
                MosaicMetadata meta;
                meta.format = outFormat;
                meta.hasScene = true;
                meta.scene = scene;
                meta.seed = seed ^ 0xA5A5A5A5A5A5A5A5ull;
                meta.source = o.inputs[job.input];
                if (!job.preview.empty())
                    writeImageAtomically(job.preview, previewOf(out, outFormat));
                writeMosaic(job.out, out, meta);
                ++written;
            } catch (const std::exception& e) {
                std::lock_guard<std::mutex> lock(errorMutex);
                if (firstError.empty())
                    firstError = "'" + o.inputs[job.input] + "' variant " + std::to_string(job.variant) +
                                 ": " + e.what();
            }
            progress.advance();
        }
    });
    progress.finish();
    result.written = written;
    if (!firstError.empty())
        throw std::runtime_error(firstError);
    return result;
}

} // namespace rawgment_apps
