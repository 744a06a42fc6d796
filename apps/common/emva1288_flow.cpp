// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_calibrate --emva: EMVA 1288 series in (one descriptor, or a manifest of descriptors with gains),
// the standard's figures, the project's model, the real-frame validation and their plots out.
#include "app_tools.hpp"
#include "flow_common.hpp"
#include "pipeline.hpp"
#include "plots.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

namespace rawgment_apps {

using namespace cv::rawgment;

namespace {

const char* const kColours[] = {"#d62728", "#ff7f0e", "#2ca02c"};

//! A manifest by its extension (.yml, .yaml, .json, any case); anything else is taken for a descriptor.
bool isManifestPath(const std::string& path)
{
    const size_t dot = path.find_last_of('.'), slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
        return false;
    std::string ext = path.substr(dot);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext == ".yml" || ext == ".yaml" || ext == ".json";
}

double readNumber(const cv::FileNode& node, const std::string& where, const char* key)
{
    if (!(node.isReal() || node.isInt()) || !std::isfinite(double(node)))
        throw std::runtime_error(where + ": '" + key + "' is not a finite number");
    return double(node);
}

//! The series of a manifest (`emva1288_manifest: {base_iso:, series: [{descriptor:, gain_db: | iso:}]}`).
std::vector<Emva1288Input> readManifest(const std::string& path)
{
    cv::FileStorage fs = openFileStorageForReading(path, "EMVA 1288 manifest");
    const cv::FileNode root = fs["emva1288_manifest"];
    if (!root.isMap() || !root["series"].isSeq() || root["series"].size() == 0)
        throw std::runtime_error("'" + path + "': expected a map 'emva1288_manifest' with a list 'series'");
    requireKnownKeys(root, {"base_iso", "series"}, "'" + path + "'");
    double baseIso = 0;
    if (!root["base_iso"].empty()) {
        baseIso = readNumber(root["base_iso"], "'" + path + "'", "base_iso");
        if (!(baseIso >= NoiseModel::MIN_BASE_ISO && baseIso <= NoiseModel::MAX_BASE_ISO))
            throw std::runtime_error(cv::format("'%s': 'base_iso' must be a number in [%g, %g]", path.c_str(),
                                                NoiseModel::MIN_BASE_ISO, NoiseModel::MAX_BASE_ISO));
    }
    std::vector<Emva1288Input> inputs;
    for (const cv::FileNode& item : root["series"]) {
        const std::string where = cv::format("'%s' series %zu", path.c_str(), inputs.size() + 1);
        if (!item.isMap() || !item["descriptor"].isString())
            throw std::runtime_error(where +
                                     ": expected a map with 'descriptor' (the path of EMVA1288_Data.txt)");
        requireKnownKeys(item, {"descriptor", "gain_db", "iso"}, where);
        const bool hasDb = !item["gain_db"].empty(), hasIso = !item["iso"].empty();
        if (hasDb == hasIso)
            throw std::runtime_error(where + ": give exactly one of 'gain_db' and 'iso'");
        Emva1288Input in;
        in.descriptor = resolvePath(directoryOf(path), std::string(item["descriptor"]));
        if (hasDb) {
            in.gainDb = readNumber(item["gain_db"], where, "gain_db");
        } else {
            const double iso = readNumber(item["iso"], where, "iso");
            if (!(baseIso > 0) || !(iso > 0))
                throw std::runtime_error(where + ": an 'iso' needs the manifest's 'base_iso', and both > 0");
            in.gainDb = linearGainToDb(iso / baseIso);
        }
        inputs.push_back(in);
    }
    std::vector<cv::String> descriptors;
    for (const Emva1288Input& in : inputs)
        descriptors.push_back(in.descriptor);
    try {
        refuseRepeatedFiles(descriptors, "'" + path + "' series");
    } catch (const cv::Exception& e) {
        throw std::runtime_error(e.err);
    }
    return inputs;
}

std::string emvaFiguresYaml(const std::vector<Emva1288Input>& inputs,
                            const std::vector<Emva1288Results>& results)
{
    return fileStorageText("emva1288.yml", [&](cv::FileStorage& fs) {
        fs << "emva1288"
           << "[";
        for (size_t k = 0; k < results.size(); ++k) {
            const Emva1288Results& r = results[k];
            fs << "{";
            cv::rawgment::writeString(fs, "descriptor", inputs[k].descriptor);
            fs << "gain_db" << inputs[k].gainDb;
            // The reference implementation's names (EMVA1288/emva1288, Results1288), in its units.
            fs << "K" << r.K << "inverse_K" << 1 / r.K << "QE" << r.eta << "sigma_y_dark" << r.sigmaYDark
               << "sigma_d" << r.sigmaD << "u_p_min" << r.muPMin << "u_e_min" << r.eta * r.muPMin / 100
               << "u_p_sat" << r.muPSat << "u_e_sat" << r.muESat << "SNR_max" << r.snrMax << "SNR_max_dB"
               << r.snrMaxDb << "inverse_SNR_max" << 100 / r.snrMax << "DR"
               << std::pow(10.0, r.dynamicRangeDb / 20) << "DR_dB" << r.dynamicRangeDb << "LE_min"
               << r.linearityErrorMin << "LE_max" << r.linearityErrorMax << "DSNU1288" << r.dsnu1288
               << "DSNU1288_DN" << r.dsnu1288 * r.K << "PRNU1288" << r.prnu1288;
            fs << "}";
        }
        fs << "]";
    });
}

PlotsWritten plotSeries(const std::string& outDir, const std::string& pointsCsv,
                        const std::string& validationCsv, const std::string& histogramCsv,
                        const std::vector<Emva1288Results>& results, double gain,
                        const CalibrationReport& report, const Emva1288CalibrationParams& params)
{
    PlotsWritten out;
    const Emva1288Results& r = results.front();
    const NoiseLineFit& line = emva1288LineAtGain(report, gain);
    const double saturated = r.mean[r.saturationIndex] - r.darkMean[r.saturationIndex];
    const double fitEnd = r.mean[r.sensitivityMaxIndex] - r.darkMean[r.sensitivityMaxIndex];
    std::string s =
        "set title 'Photon transfer: temporal variance above dark against signal (first series)'\n";
    s += "set xlabel 'mean signal above dark (DN)'\nset ylabel 'variance above dark (DN^2)'\nset grid\n";
    s += "set key left top box opaque\n";
    s += cv::format(
        "plot %s every ::1 using ($1 == 0 ? $3-$6 : 1/0):($4-$7) with points pt 7 ps 0.8 lc rgb '#1f77b4' "
        "title "
        "'steps', (x <= %.6g ? %.10g*x : 1/0) with lines lw 2 lc rgb '#d62728' title 'standard: K %.5f "
        "(fitted to 70%% of saturation)', (x <= %.6g ? %.10g*x : 1/0) with lines lw 2 dt 2 lc rgb "
        "'#2ca02c' title 'model: %.5f (fitted to %.0f%%)'\n",
        gnuplotString(pointsCsv).c_str(), fitEnd, r.K, r.K, params.maxSignalFraction * saturated, line.line.a,
        line.line.a, 100 * params.maxSignalFraction);
    std::string message;
    const auto plot = [&](const std::string& png, const std::string& script) {
        // A plot an interrupted run of the same job already made is kept, never drawn over.
        if (pathExists(png) || plotWithGnuplot(png, script, message))
            out.pngs.push_back(png);
        else
            out.notes.push_back(message);
    };
    plot(outDir + "/emva_photon_transfer.png", s);
    if (r.photonsGiven) {
        s = "set title 'SNR against photons per pixel (first series)'\nset logscale xy\nset grid\n";
        s += "set xlabel 'photons per pixel'\nset ylabel 'SNR'\nset key left top box opaque\n";
        s += cv::format(
            "plot %s every ::1 using ($1 == 0 ? $2 : 1/0):(($3-$6)/sqrt($4)) with points pt 7 ps 0.8 lc "
            "rgb '#1f77b4' "
            "title 'measured', sqrt(%.10g*x) with lines lw 2 lc rgb '#2ca02c' title 'ideal sensor (eta "
            "%.1f%%)', %.10g*x/sqrt(%.10g*x + %.10g) with lines lw 2 dt 2 lc rgb '#d62728' title "
            "'model'\n",
            gnuplotString(pointsCsv).c_str(), r.eta / 100, r.eta, r.responsivity,
            line.line.a * r.responsivity, line.line.b);
        plot(outDir + "/emva_snr.png", s);
        s = "set title 'Linearity: deviation from the standard''s fit (first series)'\nset grid\n";
        s += "set xlabel 'photons per pixel'\nset ylabel 'deviation (%)'\nset key left top box opaque\n";
        s += cv::format("plot %s every ::1 using ($1 == 0 ? $2 : 1/0):9 with linespoints pt 7 lc rgb "
                        "'#1f77b4' title 'deviation "
                        "(fit range %.0f%% to %.0f%% of saturation: 5%% to 95%%)'\n",
                        gnuplotString(pointsCsv).c_str(), 5.0, 95.0);
        plot(outDir + "/emva_linearity.png", s);
    }
    if (!validationCsv.empty()) {
        s = "set title 'Real darker steps: augmented variance over the real one (1 is right)'\nset grid\n";
        s += "set xlabel 'step pair'\nset ylabel 'variance ratio'\nset key outside right top\nset logscale "
             "y\n";
        s += "set xtics 1\n";
        const char* names[] = {"NONE", "IGNORE\\_PRIOR", "ACCOUNT\\_PRIOR"};
        s += "plot ";
        for (int a = 0; a < 3; ++a)
            s += cv::format(
                "%s every ::1 using ($4 == %d ? $2 + %.2f : 1/0):7:8 with yerrorbars pt 7 lc rgb '%s' "
                "title '%s', ",
                gnuplotString(validationCsv).c_str(), a + 1, 0.12 * (a - 1), kColours[a], names[a]);
        s += "1 with lines lc rgb 'black' title 'the real darker pair'\n";
        plot(outDir + "/emva_validation.png", s);
        s = "set title 'Pixel differences (A - B) / sqrt 2 of the darker pair: real and augmented'\nset "
            "grid\n";
        s += "set xlabel 'DN'\nset ylabel 'fraction of pixels'\nset key left top box opaque\nplot ";
        s += cv::format("%s every ::1 using 1:2 with steps lw 3 lc rgb 'black' title 'real darker pair', ",
                        gnuplotString(histogramCsv).c_str());
        for (int a = 0; a < 3; ++a)
            s += cv::format("%s%s every ::1 using 1:%d with steps lw 2 lc rgb '%s' title '%s'", a ? ", " : "",
                            gnuplotString(histogramCsv).c_str(), a + 3, kColours[a], names[a]);
        plot(outDir + "/emva_validation_histograms.png", s + "\n");
    }
    return out;
}

} // namespace

std::string writeSimulatedEmva1288(const std::string& dir, const SimulatedEmva1288& series)
{
    makeDirectories(dir);
    const SensorSimulator sim(series.sensor, series.size);
    const double white = std::ldexp(1.0, series.sensor.bitDepth) - 1 - series.sensor.blackLevel[0];
    const double alpha = series.sensor.noise.alpha;
    // Light per exposure unit: 1.15 x the white level over the steps; photons = electrons / QE.
    const double perExposure = 1.15 * white / series.steps;
    const cv::Mat light(series.size, CV_32FC1, cv::Scalar(perExposure));
    const cv::Mat dark = cv::Mat::zeros(series.size, CV_32FC1);
    std::string text =
        cv::format("# A simulated sensor in the EMVA 1288 form (cv::rawgment)\nv 4.0\nn %d %d %d\n",
                   series.sensor.bitDepth, series.size.width, series.size.height);
    std::vector<cv::Mat> frames;
    const auto write = [&](const std::string& kind, int step, bool isDark, double exposure, int count) {
        sim.captureBurst(isDark ? dark : light, 1.0, exposure, count,
                         deriveSeed(series.seed, SEED_SIMULATED_BURST, uint64_t(2 * step + (isDark ? 1 : 0))),
                         frames);
        const double photons = perExposure * exposure / alpha / series.quantumEfficiency;
        text += isDark ? cv::format("d %.6g\n", 1000 * exposure)
                       : cv::format("b %.6g %.6g\n", 1000 * exposure, photons);
        for (int f = 0; f < count; ++f) {
            const std::string name = cv::format("%s%03d_%03d.png", kind.c_str(), step, f);
            writeNewImage(dir + "/" + name, frames[f]);
            text += "i " + name + "\n";
        }
    };
    for (int k = 0; k < series.steps; ++k) {
        write("b", k, false, k + 1, 2);
        write("d", k, true, k + 1, 2);
    }
    if (series.spatialFrames > 0) {
        const double half = 0.5 * series.steps / 1.15;
        write("sb", series.steps, false, half, series.spatialFrames);
        write("sd", series.steps, true, half, series.spatialFrames);
    }
    writeNewText(dir + "/EMVA1288_Data.txt", text);
    return dir + "/EMVA1288_Data.txt";
}

Emva1288FlowResult calibrateFromEmva1288(const Emva1288Options& o)
{
    Emva1288FlowResult out;
    std::vector<Emva1288Input> inputs;
    if (isManifestPath(o.input))
        inputs = readManifest(o.input);
    else
        inputs.push_back({o.input, 0.0});
    std::vector<Emva1288Series> series;
    size_t total = 0;
    for (const Emva1288Input& in : inputs) {
        series.push_back(readEmva1288(in.descriptor));
        total += series.back().temporal.size() + series.back().spatial.size();
    }
    prepareOutputDirectory(o.outDir);
    // The run is deterministic: outputs already there must be what this run writes (writeNewText checks,
    // naming any other), so a run that died before its end is completed and an identical rerun succeeds.
    ProgressBar bar("EMVA 1288 steps", total);
    std::vector<Emva1288Results> results;
    std::vector<double> gains;
    for (size_t k = 0; k < series.size(); ++k) {
        results.push_back(emva1288Results(series[k], [&](int, int) { bar.advance(); }));
        gains.push_back(dbToLinearGain(inputs[k].gainDb));
    }
    bar.finish();
    Emva1288CalibrationParams params;
    params.maxSignalFraction = o.maxSignalFraction;
    out.report = calibrateEmva1288(results, gains, params);
    out.verdict = judgeEmva1288(results, gains, out.report, params);
    out.results = results;
    out.inputs = inputs;

    // The paper's validation on each series' own darker steps, with the model's line at its gain.
    // Pairs are numbered through the whole file, each row naming its series (0 for the manifest's first, as
    // in emva1288_points.csv), so that a manifest of several series has no two rows of one number (#79 item
    // 26).
    CsvTable validation({"series", "pair", "bright_point", "alignment", "dark_point", "photon_ratio", "ratio",
                         "ratio_std_error", "augmented_variance", "real_variance"});
    size_t pairsBefore = 0;
    for (size_t k = 0; k < series.size(); ++k) {
        const NoiseLineFit& line = emva1288LineAtGain(out.report, gains[k]);
        const NoiseModel atGain(line.line.a, 0.0, std::max(line.line.b, 0.0));
        std::vector<cv::Point> steps;
        try {
            steps = emva1288DarkeningSteps(results[k]);
        } catch (const cv::Exception& e) {
            out.notes.push_back("no real-frame validation of '" + inputs[k].descriptor + "': " + e.err);
            continue;
        }
        if (!results[k].photonsGiven) {
            out.notes.push_back(
                "no real-frame validation of '" + inputs[k].descriptor +
                "': it states no photon counts, so no step's light is known relative to another's");
            continue;
        }
        const std::vector<Emva1288Darkening> d =
            emva1288Darkening(series[k], results[k], atGain, steps, o.seed);
        // The same steps with the standard's K and sigma_y.dark as the model: the evidence of which slope
        // predicts the sensor's own darker steps when the two differ (a photon transfer curve that bends).
        const NoiseModel standard(results[k].K, 0.0, results[k].sigmaYDark * results[k].sigmaYDark);
        const auto meanAccountRatio = [](const std::vector<Emva1288Darkening>& darkening) {
            double sum = 0;
            int pairs = 0;
            for (const Emva1288Darkening& e : darkening)
                if (e.alignment == NoiseAlignment::ACCOUNT_PRIOR) {
                    sum += e.ratio;
                    ++pairs;
                }
            return sum / pairs;
        };
        const double modelMean = meanAccountRatio(d);
        const double standardMean =
            meanAccountRatio(emva1288Darkening(series[k], results[k], standard, steps, o.seed));
        const bool modelCloser = std::abs(modelMean - 1) <= std::abs(standardMean - 1);
        out.notes.push_back(cv::format("%s: darkened with ACCOUNT_PRIOR, the model's line (slope %.5f, to "
                                       "%.0f%% of saturation) gives %.4f of "
                                       "the real darker steps' variance on average, the standard's K %.5f "
                                       "and sigma_y.dark gives %.4f: %s "
                                       "predicts this sensor's darker steps better",
                                       inputs[k].descriptor.c_str(), line.line.a, 100 * o.maxSignalFraction,
                                       modelMean, results[k].K, standardMean,
                                       modelCloser ? "the model's line" : "the standard's K"));
        for (size_t i = 0; i < d.size(); ++i) {
            out.darkening.push_back(d[i]);
            out.darkeningSeries.push_back(int(k));
            validation.addRow(std::vector<double>{
                double(k), double(pairsBefore + i / 3 + 1), double(d[i].brightPoint),
                double(int(d[i].alignment) + 1), double(d[i].darkPoint), d[i].photonRatio, d[i].ratio,
                d[i].ratioStdError, d[i].augmentedVariance, d[i].realVariance});
        }
        pairsBefore += d.size() / 3;
    }

    // Files: never over an existing one (writeNewText), each atomically.
    NoiseModel model = out.report.model;
    if (!out.verdict.pass) {
        std::string failed;
        for (const VerdictCheck& c : out.verdict.checks)
            if (!c.pass)
                failed += (failed.empty() ? "" : ", ") + c.name;
        model.failedCalibration = failed;
    }
    writeNewText(o.outDir + "/noise_model.yml", fileStorageText("noise_model.yml", [&](cv::FileStorage& fs) {
                     model.write(fs, "noise_model");
                 }));
    writeNewText(o.outDir + "/calibration_report.yml",
                 fileStorageText("calibration_report.yml",
                                 [&](cv::FileStorage& fs) { out.report.write(fs, "calibration_report"); }));
    writeNewText(o.outDir + "/emva1288.yml", emvaFiguresYaml(inputs, results));
    CsvTable points({"series", "photons", "mean", "variance", "variance_std_error", "dark_mean",
                     "dark_variance", "exposure", "linearity_deviation_percent"});
    for (size_t k = 0; k < results.size(); ++k) {
        const Emva1288Results& r = results[k];
        for (size_t i = 0; i < r.mean.size(); ++i)
            points.addRow(std::vector<double>{double(k), r.photons[i], r.mean[i], r.variance[i],
                                              r.varianceStdError[i], r.darkMean[i], r.darkVariance[i],
                                              r.exposureNs[i],
                                              r.linearityDeviation.empty() ? NAN : r.linearityDeviation[i]});
    }
    const std::string pointsCsv = o.outDir + "/emva1288_points.csv";
    points.write(pointsCsv);
    std::string validationCsv, histogramCsv;
    if (validation.rows() > 0) {
        validationCsv = o.outDir + "/emva1288_validation.csv";
        validation.write(validationCsv);
        // The histograms of the step pair of the largest photon ratio: there the three alignments differ
        // most.
        size_t best = 0;
        for (size_t i = 0; i < out.darkening.size(); i += 3)
            if (out.darkening[i].photonRatio > out.darkening[best].photonRatio)
                best = i;
        const Emva1288Darkening* d = &out.darkening[best];
        CsvTable histograms({"difference_over_sqrt2_DN", "real", "NONE", "IGNORE_PRIOR", "ACCOUNT_PRIOR"});
        for (size_t b = 0; b < d[0].realHistogram.size(); ++b)
            histograms.addRow(std::vector<double>{0.5 * (d[0].histogramEdges[b] + d[0].histogramEdges[b + 1]),
                                                  d[0].realHistogram[b], d[0].augmentedHistogram[b],
                                                  d[1].augmentedHistogram[b], d[2].augmentedHistogram[b]});
        histogramCsv = o.outDir + "/emva1288_validation_histograms.csv";
        histograms.write(histogramCsv);
        out.notes.push_back(
            cv::format("the histograms are those of point %d taken to point %d (photon ratio %.3f)",
                       d[0].brightPoint, d[0].darkPoint, d[0].photonRatio));
    }
    if (o.plots) {
        const PlotsWritten plots = plotSeries(o.outDir, pointsCsv, validationCsv, histogramCsv, results,
                                              gains.front(), out.report, params);
        out.pngs = plots.pngs;
        out.notes.insert(out.notes.end(), plots.notes.begin(), plots.notes.end());
    }
    writeNewText(o.outDir + "/report.md", emva1288ReportMarkdown(out, o));
    return out;
}

std::string emva1288ReportMarkdown(const Emva1288FlowResult& r, const Emva1288Options& o)
{
    std::string md = "# EMVA 1288 calibration report\n\n";
    md += std::string("**Verdict: ") + (r.verdict.pass ? "PASS" : "FAIL") + "**\n\n";
    md += "| check | result | measured figure and threshold |\n|---|---|---|\n";
    for (const VerdictCheck& c : r.verdict.checks)
        md += "| " + c.name + " | " + (c.pass ? "pass" : "**FAIL**") + " | " + c.figure + " |\n";
    md += "\nThresholds: docs/calibrate_your_camera.md, \"EMVA 1288 data\".\n\n## The standard's figures\n\n";
    md += "| series | gain (dB) | K (DN/e-) | sigma_y.dark (DN) | sigma_d (e-) | mu_e.sat (e-) | eta (%) | "
          "SNR_max (dB) "
          "| DR (dB) | mu_p.min (p) | DSNU1288 (e-) | PRNU1288 (%) | linearity error (%) |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (size_t k = 0; k < r.results.size(); ++k) {
        const Emva1288Results& e = r.results[k];
        md += cv::format(
            "| %s | %.2f | %.5f | %.4f | %.3f | %.0f | %.2f | %.2f | %.2f | %.2f | %.3f | %.3f | %.3f to "
            "%+.3f |\n",
            r.inputs[k].descriptor.c_str(), r.inputs[k].gainDb, e.K, e.sigmaYDark, e.sigmaD, e.muESat, e.eta,
            e.snrMaxDb, e.dynamicRangeDb, e.muPMin, e.dsnu1288, e.prnu1288, e.linearityErrorMin,
            e.linearityErrorMax);
    }
    md += "\nEach figure as the standard and its reference implementation define it (emva1288.yml holds them "
          "under "
          "the reference implementation's names).\n\n## The noise model\n\n";
    const CalibrationReport& rep = r.report;
    const cv::Vec3d se = rep.uncertainty.stdError;
    md += cv::format("alpha %.6f +- %.2g DN/e- at gain 1; ", rep.model.alpha, se[0]);
    md += rep.separable
              ? cv::format("sigma_d^2 %.5f +- %.2g, sigma_r^2 %.5f +- %.2g DN^2 (one standard error).\n\n",
                           rep.model.sigmaD2, se[1], rep.model.sigmaR2, se[2])
              : cv::format("read noise %.5f +- %.2g DN^2 (sigma_y.dark %.4f DN), stated as sigma_r^2 at "
                           "this gain.\n\n",
                           rep.model.sigmaR2, se[2], std::sqrt(rep.model.sigmaR2));
    md += "| gain (dB) | slope (K) | offset (DN^2) | points | R^2 |\n|---|---|---|---|---|\n";
    for (const NoiseLineFit& l : rep.perGain)
        md += cv::format("| %.2f | %.5f +- %.2g | %.4f +- %.2g | %d | %.5f |\n", linearGainToDb(l.gain),
                         l.line.a, l.slopeStdError, l.line.b, l.offsetStdError, l.inliers, l.rSquared);
    md += cv::format(
        "\nThe model's slope is fitted to the steps up to %.0f%% of saturation, the standard's K to 70%%. "
        "Where "
        "they differ by more than their errors the photon transfer curve bends, and the validation below "
        "shows which one predicts the sensor's own darker steps: the model's range is where augmented dark "
        "scenes live.\n\n",
        100 * o.maxSignalFraction);
    if (!r.darkening.empty()) {
        md += "## The paper's validation on real frames\n\nEach bright step of the series taken to a darker "
              "one with "
              "colorJitter() (photon ratio from the descriptor), against the real darker pair: ratio of "
              "temporal "
              "variances, 1 is right, +- one standard error (pixels and the series' own pair-to-pair "
              "scatter).\n\n";
        md +=
            "| series | bright point | darker point | photon ratio | NONE | IGNORE_PRIOR | ACCOUNT_PRIOR |\n"
            "|---|---|---|---|---|---|---|\n";
        for (size_t i = 0; i + 2 < r.darkening.size(); i += 3) {
            const Emva1288Darkening* d = &r.darkening[i];
            md += cv::format("| %d | %d | %d | %.3f | %.4f +- %.4f | %.4f +- %.4f | %.4f +- %.4f |\n",
                             r.darkeningSeries[i], d[0].brightPoint, d[0].darkPoint, d[0].photonRatio,
                             d[0].ratio, d[0].ratioStdError, d[1].ratio, d[1].ratioStdError, d[2].ratio,
                             d[2].ratioStdError);
        }
        md += "\n";
    }
    if (!r.pngs.empty()) {
        md += "## Plots\n\n";
        for (const std::string& p : r.pngs) {
            const std::string name = p.substr(p.find_last_of('/') + 1);
            md += "![" + name + "](" + name + ")\n\n";
        }
    }
    for (const std::string& n : rep.notes)
        md += "Note: " + n + "\n\n";
    for (const std::string& n : r.notes)
        md += "Note: " + n + "\n\n";
    return md;
}

} // namespace rawgment_apps
