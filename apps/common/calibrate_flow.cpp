// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_calibrate: a noise model from the bursts of a manifest, with CSV tables and plots.
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "flow_common.hpp"
#include "plots.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

CalibrationManifest readCalibrationManifest(const std::string& path)
{
    cv::FileStorage fs = openFileStorageForReading(path, "calibration manifest");
    const cv::FileNode root = fs["calibration_manifest"];
    if (!root.isMap() || !root["bursts"].isSeq() || root["bursts"].size() == 0)
        throw std::runtime_error("'" + path +
                                 "': expected a map 'calibration_manifest' with a list 'bursts'");
    requireKnownKeys(root, {"patches", "bursts"}, "'" + path + "'");
    const std::string base = directoryOf(path);
    CalibrationManifest manifest;
    const cv::FileNode patches = root["patches"];
    if (!patches.empty() && !patches.isString())
        throw std::runtime_error("'" + path +
                                 "': 'patches' must be \"detect\" or the path of a chart patches "
                                 "file");
    const std::string value = patches.empty() ? std::string("detect") : std::string(patches);
    manifest.patches = value == "detect" ? value : resolvePath(base, value);
    for (const cv::FileNode& b : root["bursts"]) {
        const std::string where = cv::format("'%s' burst %zu", path.c_str(), manifest.bursts.size() + 1);
        requireKnownKeys(b, {"gain_db", "level", "files"}, where);
        if (b["gain_db"].empty() || !(b["gain_db"].isReal() || b["gain_db"].isInt()))
            throw std::runtime_error(where + ": 'gain_db' is missing or not a number");
        const double gainDb = double(b["gain_db"]);
        if (!std::isfinite(gainDb))
            throw std::runtime_error(where + ": 'gain_db' is not finite");
        manifest.bursts.push_back({gainDb, readFileList(b["files"], base, where)});
    }
    return manifest;
}

CalibrateResult calibrateFromManifest(const CalibrateOptions& o)
{
    const CalibrationManifest manifest = readCalibrationManifest(o.manifest);
    prepareOutputDirectory(o.outDir);
    const std::string modelPath = o.outDir + "/noise_model.yml",
                      reportPath = o.outDir + "/calibration_report.yml",
                      samplesCsv = o.outDir + "/samples.csv", linesCsv = o.outDir + "/lines.csv",
                      shapiroCsv = o.outDir + "/shapiro.csv",
                      histCsv = o.outDir + "/variance_ratio_histogram.csv";
    // A finished calibration is never redone into its folder. A run that died before its end is
    // completed: the calibration is deterministic, outputs already there must be what this run writes
    // (writeNewText refuses anything else) and the missing ones are added.
    std::vector<std::string> finished = {reportPath, samplesCsv, linesCsv, shapiroCsv, histCsv};
    if (o.plots)
        for (const char* png : {"calib_mean_variance.png", "calib_histograms.png", "calib_cross_gain.png",
                                "shapiro_pvalue.png"})
            finished.push_back(o.outDir + "/" + png);
    if (std::all_of(finished.begin(), finished.end(), [](const std::string& p) { return pathExists(p); }))
        refuseExisting(finished);

    CalibrateResult result;
    const std::vector<CalibrationManifest::Burst>& specs = manifest.bursts;
    size_t totalFrames = 0;
    for (const CalibrationManifest::Burst& spec : specs)
        totalFrames += spec.files.size();
    const std::vector<cv::Rect> squares =
        manifestSquares(manifest.patches, specs.front().files.front(), o.side, result.notes);

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
    for (const CalibrationManifest::Burst& spec : specs) {
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
    params.line.seed = o.seed;
    result.report = calibrateNoiseModel(samples, params);
    const CalibrationReport& report = result.report;
    writeNewText(reportPath,
                 yamlToString([&](cv::FileStorage& fs) { report.write(fs, "calibration_report"); }));
    if (report.separable)
        writeNewText(modelPath,
                     yamlToString([&](cv::FileStorage& fs) { report.model.write(fs, "noise_model"); }));
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
    std::vector<double> gainsDb;
    for (const CalibrationManifest::Burst& spec : specs)
        if (std::none_of(gainsDb.begin(), gainsDb.end(),
                         [&](double g) { return std::abs(g - spec.gainDb) < 1e-9; }))
            gainsDb.push_back(spec.gainDb);
    CalibrationPlotFiles files{samplesCsv, linesCsv, histCsv, shapiroCsv};
    plotCalibration(o.outDir, report, files, counts.size(), gainsDb, result.pngs, result.notes);
    return result;
}

} // namespace rawgment_apps
