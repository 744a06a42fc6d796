// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_validate: a bright burst converted to darker exposures against real darker bursts.
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "chart_patches.hpp"
#include "flow_common.hpp"
#include "plots.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

ValidationManifest readValidationManifest(const std::string& path)
{
    cv::FileStorage fs = openFileStorageForReading(path, "validation manifest");
    const cv::FileNode root = fs["validation_manifest"];
    if (!root.isMap() || !root["targets"].isSeq() || root["targets"].size() == 0)
        throw std::runtime_error("'" + path +
                                 "': expected a map 'validation_manifest' with 'bright' and a non-empty list "
                                 "'targets'");
    requireKnownKeys(root, {"patches", "gain_db", "bright", "targets"}, "'" + path + "'");
    const std::string base = directoryOf(path);
    ValidationManifest m;
    const cv::FileNode gain = root["gain_db"];
    if (!gain.empty()) {
        if (!(gain.isReal() || gain.isInt()) || !std::isfinite(double(gain)))
            throw std::runtime_error("'" + path + "': 'gain_db' must be a finite number");
        m.hasGainDb = true;
        m.gainDb = double(gain);
    }
    const cv::FileNode patches = root["patches"];
    if (!patches.empty()) {
        if (!patches.isString())
            throw std::runtime_error("'" + path + "': 'patches' must be the path of a chart patches file");
        m.patches = resolvePath(base, std::string(patches));
    }
    m.bright = readFileList(root["bright"], base, "'" + path + "' bright");
    for (const cv::FileNode& t : root["targets"]) {
        const std::string where = cv::format("'%s' target %zu", path.c_str(), m.targets.size() + 1);
        if (!t.isMap())
            throw std::runtime_error(where + ": expected a map with 'factor' and 'files'");
        requireKnownKeys(t, {"factor", "files"}, where);
        const cv::FileNode factor = t["factor"];
        if (!(factor.isReal() || factor.isInt()) || !(double(factor) > 0 && double(factor) <= 1))
            throw std::runtime_error(where + ": 'factor' must be a number in (0, 1]");
        m.targets.push_back({double(factor), readFileList(t["files"], base, where)});
    }
    return m;
}

namespace {

struct BurstMoments
{
    cv::Mat mean, variance, clipped;
};

BurstMoments momentsOf(const RawFormat& format, const std::function<cv::Mat(size_t)>& frameAt, size_t frames)
{
    BurstStatistics stats(format);
    for (size_t t = 0; t < frames; ++t)
        stats.add(frameAt(t));
    BurstMoments m;
    stats.mean(m.mean);
    stats.variance(m.variance);
    stats.clippedMask(m.clipped);
    return m;
}

/** One target's rows: bins of the real burst's mean (BurstStatistics subtracts the black) over the masked
 * pixels unclipped in both bursts, each holding the mean variance of the real burst and of the three
 * conversions; empty bins are left out. */
std::vector<ValidationRow> binByRealMean(double factor, int bins, const cv::Mat& mask,
                                         const BurstMoments& bright, const BurstMoments& real,
                                         const cv::Mat (&convVar)[3], CsvTable& csv)
{
    const auto counted = [&](int y, int x) {
        return mask.at<uchar>(y, x) && !real.clipped.at<uchar>(y, x) && !bright.clipped.at<uchar>(y, x);
    };
    double lo = 1e300, hi = -1e300;
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x)
            if (counted(y, x)) {
                lo = std::min(lo, real.mean.at<double>(y, x));
                hi = std::max(hi, real.mean.at<double>(y, x));
            }
    if (!(hi > lo))
        throw std::runtime_error("the target burst has no unclipped pixels with distinct means");
    std::vector<ValidationRow> rows(static_cast<size_t>(bins));
    std::vector<double> meanSum(size_t(bins), 0), brightMeanSum(size_t(bins), 0),
        brightVarSum(size_t(bins), 0);
    for (int b = 0; b < bins; ++b) {
        rows[size_t(b)].factor = factor;
        rows[size_t(b)].meanLow = lo + (hi - lo) * b / bins;
        rows[size_t(b)].meanHigh = lo + (hi - lo) * (b + 1) / bins;
    }
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x) {
            if (!counted(y, x))
                continue;
            const double mu = real.mean.at<double>(y, x);
            const int b = std::min(bins - 1, static_cast<int>((mu - lo) / (hi - lo) * bins));
            ValidationRow& r = rows[size_t(b)];
            ++r.pixels;
            meanSum[size_t(b)] += mu;
            r.realVariance += real.variance.at<double>(y, x);
            r.noneVariance += convVar[0].at<double>(y, x);
            r.ignoreVariance += convVar[1].at<double>(y, x);
            r.accountVariance += convVar[2].at<double>(y, x);
            brightMeanSum[size_t(b)] += bright.mean.at<double>(y, x);
            brightVarSum[size_t(b)] += bright.variance.at<double>(y, x);
        }
    std::vector<ValidationRow> kept;
    for (int b = 0; b < bins; ++b) {
        ValidationRow r = rows[size_t(b)];
        if (r.pixels == 0)
            continue;
        const double n = r.pixels;
        r.realVariance /= n;
        r.noneVariance /= n;
        r.ignoreVariance /= n;
        r.accountVariance /= n;
        csv.addRow(std::vector<double>{factor, r.meanLow, r.meanHigh, meanSum[size_t(b)] / n, n,
                                       r.realVariance, r.noneVariance, r.ignoreVariance, r.accountVariance,
                                       brightMeanSum[size_t(b)] / n, brightVarSum[size_t(b)] / n});
        kept.push_back(r);
    }
    return kept;
}

std::string validationTable(const std::vector<ValidationRow>& rows)
{
    std::string md =
        "| factor | mean bin (DN) | pixels | real variance | NONE | IGNORE_PRIOR | ACCOUNT_PRIOR | "
        "ACCOUNT_PRIOR / real |\n|---|---|---|---|---|---|---|---|\n";
    for (const ValidationRow& r : rows)
        md += cv::format("| x%.2f | %.1f-%.1f | %d | %.3f | %.3f | %.3f | %.3f | %.3f |\n", r.factor,
                         r.meanLow, r.meanHigh, r.pixels, r.realVariance, r.noneVariance, r.ignoreVariance,
                         r.accountVariance, r.accountVariance / r.realVariance);
    return md;
}

} // namespace

ValidateResult validateConversion(const ValidateOptions& o)
{
    const ValidationManifest manifest = readValidationManifest(o.manifest);
    // A NoiseModel file is read (and refused) before any frame; a darktable camera's or an Android
    // profile's model is made at the bright frames' levels once they are read.
    const bool modelFromLevels = !o.camera.empty() || noiseModelFileKind(o.model) != NOISE_MODEL_FILE;
    NoiseModel model = modelFromLevels ? NoiseModel() : NoiseModel::load(o.model, o.acceptFailedCalibration);
    prepareOutputDirectory(o.outDir);
    const std::string csvPath = o.outDir + "/validation.csv", mdPath = o.outDir + "/validation.md";
    refuseExisting({csvPath, mdPath});

    const std::vector<std::string>& brightFiles = manifest.bright;
    std::vector<LoadedMosaic> bright;
    // Every frame of every burst must have the bright burst's size and type: the comparison reads them
    // pixel by pixel.
    const auto loadMatching = [&](const std::string& file) {
        LoadedMosaic m = loadMosaicFile(file);
        if (!bright.empty() && (m.mosaic.size() != bright.front().mosaic.size() ||
                                m.mosaic.type() != bright.front().mosaic.type()))
            throw std::runtime_error(cv::format(
                "'%s' is %dx%d %s, but '%s' is %dx%d %s: all frames of a "
                "validation must have one size and type",
                file.c_str(), m.mosaic.cols, m.mosaic.rows, cv::typeToString(m.mosaic.type()).c_str(),
                brightFiles.front().c_str(), bright.front().mosaic.cols, bright.front().mosaic.rows,
                cv::typeToString(bright.front().mosaic.type()).c_str()));
        return m;
    };
    for (const std::string& f : brightFiles)
        bright.push_back(loadMatching(f));
    RawFormat format = bright.front().format;
    if (modelFromLevels)
        model = loadAnyNoiseModel(o.model, o.camera, format, o.acceptFailedCalibration);
    if (manifest.hasGainDb)
        format.gain = dbToLinearGain(manifest.gainDb);
    cv::Mat mask(bright.front().mosaic.size(), CV_8U, cv::Scalar(manifest.patches.empty() ? 255 : 0));
    if (!manifest.patches.empty())
        for (const cv::Rect& s : rawgment_helpers::readChartPatches(manifest.patches).squares)
            mask(s & cv::Rect(cv::Point(), mask.size())).setTo(255);

    const BurstMoments brightMoments = momentsOf(
        format, [&](size_t t) { return bright[t].mosaic; }, bright.size());

    ValidateResult result;
    std::vector<ValidationPanel> panels;
    const NoiseAlignment alignments[3] = {NoiseAlignment::NONE, NoiseAlignment::IGNORE_PRIOR,
                                          NoiseAlignment::ACCOUNT_PRIOR};
    ProgressBar progress("validate", manifest.targets.size() * (3 + 1) * bright.size());
    CsvTable csv({"factor", "mean_low", "mean_high", "mean", "pixels", "real_variance", "none_variance",
                  "ignore_prior_variance", "account_prior_variance", "bright_mean", "bright_variance"});
    for (const ValidationManifest::Target& t : manifest.targets) {
        const double factor = t.factor;
        const BurstMoments real = momentsOf(
            format,
            [&](size_t k) {
                progress.advance();
                return loadMatching(t.files[k]).mosaic;
            },
            t.files.size());
        cv::Mat convVar[3];
        for (int a = 0; a < 3; ++a)
            convVar[a] =
                momentsOf(
                    format,
                    [&](size_t k) {
                        cv::Mat out;
                        RawFormat outFormat;
                        colorJitter(bright[k].mosaic, format, model, ColorJitter::exposureChange(factor, 1.0),
                                    alignments[a], deriveSeed(o.seed, SEED_VALIDATION_CONVERSION, k), out,
                                    outFormat);
                        progress.advance();
                        return out;
                    },
                    bright.size())
                    .variance;
        const std::vector<ValidationRow> rows =
            binByRealMean(factor, o.bins, mask, brightMoments, real, convVar, csv);
        result.rows.insert(result.rows.end(), rows.begin(), rows.end());
        panels.push_back({factor, rows.empty() ? 1.0 : rows.back().meanHigh});
    }
    progress.finish();
    csv.write(csvPath);
    result.table = validationTable(result.rows);
    writeTextAtomically(mdPath, result.table);
    if (o.plots) {
        const PlotsWritten plots = plotValidation(o.outDir, csvPath, panels);
        result.pngs = plots.pngs;
        result.notes.insert(result.notes.end(), plots.notes.begin(), plots.notes.end());
    }
    return result;
}

} // namespace rawgment_apps
