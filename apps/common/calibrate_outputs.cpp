// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What rawgment_calibrate writes beside its model: report.md, the CSV tables and their plots, the
// dark-frame outputs, and the darktable and Android exports.
#include "calibrate_outputs.hpp"

#include "flow_common.hpp"
#include "plots.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace rawgment_apps {

using namespace cv::rawgment;

//! report.md: the verdict first, with its checks, then the model, the per-gain lines, the plots, the notes.
std::string calibrationReportMarkdown(const CalibrateResult& r, const PlotsWritten& plots,
                                      const std::string& outDir)
{
    std::string md = "# Calibration report\n\n";
    md += std::string("**Verdict: ") + (r.verdict.pass ? "PASS" : "FAIL") + "**\n\n";
    if (!r.verdict.pass)
        md +=
            "The model is marked with the failed checks (`failed_calibration` in noise_model.yml): "
            "rawgment_augment, rawgment_validate, rawgment.batch and NoiseModel::load() refuse it unless "
            "asked explicitly (`--accept_failed_calibration`, `acceptFailedCalibration`), and the darktable "
            "and Android exports are not written.\n\n";
    md += "| check | result | measured figure and threshold |\n|---|---|---|\n";
    for (const VerdictCheck& c : r.verdict.checks)
        md += "| " + c.name + " | " + (c.pass ? "pass" : "**FAIL**") + " | " + c.figure + " |\n";
    md +=
        "\nThe thresholds and what to do on each failure: docs/calibrate_your_camera.md in cv::rawgment.\n\n";
    const CalibrationReport& rep = r.report;
    if (r.haveDark) {
        const NoiseModel& m = rep.model;
        md += "## Dark-frame components\n\n";
        md += cv::format(
            "Row noise %.4g g^2 + %.4g DN^2; read noise Tukey lambda %.3f (the residuals' %.3f, PPCC "
            "%.5f against %.5f for a normal plot); dark shading %s.\n\n",
            m.rowSigmaD2, m.rowSigmaR2, m.tukeyLambda, r.dark.lambdaOfResiduals, r.dark.ppccBest,
            r.dark.ppccGaussian,
            m.hasDarkShading() ? "in noise_model.dark_shading_*.tiff (dark_shading.png)" : "not fitted");
        md +=
            "| gain (dB) | frames | row variance | model | pixel variance | excess kurtosis | Shapiro-Wilk p "
            "with rows | without |\n|---|---|---|---|---|---|---|---|\n";
        for (const DarkGainStatistics& g : r.dark.gains)
            md += cv::format("| %.2f | %d | %.4g +- %.2g | %.4g | %.4g | %.3f | %.3g | %.3g |\n",
                             linearGainToDb(g.gain), g.frames, g.rowVariance, g.rowVarianceSE,
                             m.rowVariance(g.gain), g.pixelVariance, g.excessKurtosis, g.before.pValue,
                             g.after.pValue);
        for (const std::string& n : r.dark.notes)
            md += "\nNote: " + n + "\n";
        md += "\n";
    }
    md += "## Model\n\n";
    md += cv::format("Method %s, %d of %d samples used. ",
                     rep.method == NOISE_FIT_JOINT ? "joint" : "two-stage", rep.samplesUsed, rep.samples);
    if (!rep.separable)
        md += "sigma_d^2 and sigma_r^2 are not separable with these gains: alpha alone is known.";
    md += "\n\n| parameter | value | standard error | 95% interval |\n|---|---|---|---|\n";
    const char* names[3] = {"alpha", "sigma_d^2", "sigma_r^2"};
    const double values[3] = {rep.model.alpha, rep.model.sigmaD2, rep.model.sigmaR2};
    for (int k = 0; k < (rep.separable ? 3 : 1); ++k) {
        const cv::Vec2d ci = rep.interval(static_cast<NoiseModelParameter>(k));
        md += cv::format("| %s | %.6g | %.3g (%.2f%%) | [%.6g, %.6g] |\n", names[k], values[k],
                         rep.uncertainty.stdError[k],
                         values[k] > 0 ? 100 * rep.uncertainty.stdError[k] / values[k] : 0.0, ci[0], ci[1]);
    }
    md += cv::format(
        "\nStandard errors from the %s (fit covariance: %.3g, %.3g, %.3g; bootstrap of %d "
        "replicates: %.3g, %.3g, %.3g)",
        rep.uncertainty.source == UNCERTAINTY_BOOTSTRAP ? "bootstrap" : "fit's sandwich covariance",
        rep.uncertainty.fitStdError[0], rep.uncertainty.fitStdError[1], rep.uncertainty.fitStdError[2],
        rep.uncertainty.bootstrapReplicates, rep.uncertainty.bootstrapStdError[0],
        rep.uncertainty.bootstrapStdError[1], rep.uncertainty.bootstrapStdError[2]);
    if (rep.separable)
        md +=
            cv::format("; the errors of sigma_d^2 and sigma_r^2 correlate %+.2f, as both make up each gain's "
                       "offset",
                       rep.uncertainty.correlation(NOISE_PARAM_SIGMA_D2, NOISE_PARAM_SIGMA_R2));
    md += ".\n\n";
    if (r.baseIso > 0)
        md += cv::format("Gain 1 is ISO %g.\n\n", r.baseIso);
    md += "| gain (dB) | slope a | offset b | R^2 | inliers | samples |\n|---|---|---|---|---|---|\n";
    for (const NoiseLineFit& l : rep.perGain)
        md += cv::format("| %.2f | %.6g +- %.2g | %.6g +- %.2g | %.4f | %d | %d |\n", linearGainToDb(l.gain),
                         l.line.a, l.slopeStdError, l.line.b, l.offsetStdError, l.rSquared, l.inliers,
                         l.samples);
    if (!r.projections.empty()) {
        md +=
            "\n## What more data buys\n\n"
            "Relative standard errors if the calibration were shot again with more data (projected from the "
            "Fisher information of these samples under the fitted model, scaled to the errors measured "
            "here). More of the same shrinks every error as 1/sqrt(pixels x (frames - 1)); dark frames and "
            "wider gains change which parameter is pinned.\n\n"
            "| plan | alpha | sigma_d^2 | sigma_r^2 |\n|---|---|---|---|\n";
        for (const auto& plan : r.projections) {
            md += "| " + plan.first;
            for (int k = 0; k < 3; ++k)
                md += values[k] > 0 && plan.second[k] > 0
                          ? cv::format(" | %.3g%%", 100 * plan.second[k] / values[k])
                          : std::string(" | -");
            md += " |\n";
        }
    }
    md += r.shapiroTested > 0
              ? cv::format("\nShapiro-Wilk: %.1f%% of %d tested pixels have p > 0.05.\n",
                           100 * r.gaussianFraction, r.shapiroTested)
              : std::string("\nShapiro-Wilk: no pixel tested (it needs bursts of 3 or more frames).\n");
    if (!plots.pngs.empty()) {
        md += "\n## Plots\n\n";
        for (const std::string& png : plots.pngs) {
            const std::string name = png.rfind(outDir + "/", 0) == 0 ? png.substr(outDir.size() + 1) : png;
            md += "![" + name + "](" + name + ")\n\n";
        }
    }
    if (!rep.notes.empty() || !r.notes.empty() || !plots.notes.empty()) {
        md += "\n## Notes\n\n";
        for (const std::string& n : rep.notes)
            md += "- " + n + "\n";
        for (const std::string& n : r.notes)
            md += "- " + n + "\n";
        for (const std::string& n : plots.notes)
            md += "- " + n + "\n";
    }
    return md;
}

/* darktable's noise-profile file and Android's form of the model, at the ISOs of the bursts (a file's ISO
 * as it says it; a gain_db burst's from its gain, as dB are not exact). */
void writeProfileExports(const std::string& outDir, const std::vector<CalibrationManifest::Burst>& specs,
                         const std::vector<double>& gainsDb, const std::vector<double>& isos,
                         const RawFormat& firstFormat, CalibrateResult& result)
{
    const CalibrationReport& report = result.report;
    std::vector<double> profileIsos;
    for (size_t i = 0; i < specs.size(); ++i) {
        // The file's ISO as it says it; a gain_db burst's from the gain (dB are not exact).
        const double iso = specs[i].hasGainDb ? result.baseIso * dbToLinearGain(gainsDb[i]) : isos[i];
        if (std::none_of(profileIsos.begin(), profileIsos.end(),
                         [&](double v) { return std::abs(v - iso) < 1e-9 * iso; }))
            profileIsos.push_back(iso);
    }
    const std::string maker = result.camera.make.empty() ? "unknown" : result.camera.make,
                      model = result.camera.model.empty() ? "unknown" : result.camera.model;
    writeNewText(
        outDir + "/darktable_noiseprofiles.json",
        darktableNoiseProfiles(report.model, firstFormat, result.baseIso, profileIsos, maker, model));
    const AndroidNoiseProfile android = androidNoiseProfile(report.model, firstFormat, result.baseIso);
    writeNewText(outDir + "/android_noise_profile.yml",
                 fileStorageText("android_noise_profile.yml", [&](cv::FileStorage& fs) {
                     fs << "android_noise_profile"
                        << "{"
                        << "comment"
                        << "S = A s + B, O = C s^2 + D per CFA site (2x2 block row by row), s = ISO"
                        << "base_iso" << result.baseIso;
                     fs << "A" << std::vector<double>(android.A.val, android.A.val + 4);
                     fs << "B" << std::vector<double>(android.B.val, android.B.val + 4);
                     fs << "C" << std::vector<double>(android.C.val, android.C.val + 4);
                     fs << "D" << std::vector<double>(android.D.val, android.D.val + 4) << "}";
                 }));
    result.notes.push_back("darktable_noiseprofiles.json and android_noise_profile.yml carry the model "
                           "to darktable and Android's camera tests");
}

/* samples.csv, lines.csv, shapiro.csv and the histogram of variance / model variance per gain (a sample
 * variance of T frames has mean 1 and relative spread sqrt(2 / (T - 1)) around a right model). Returns
 * the number of gains in the histogram. */
size_t writeSampleTables(const std::vector<NoiseSample>& samples, const CalibrationReport& report,
                         const CsvTable& shapiro, const std::string& samplesCsv, const std::string& linesCsv,
                         const std::string& shapiroCsv, const std::string& histCsv)
{
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

    const int bins = 60;
    const double hiRatio = 3.0;
    std::map<double, std::vector<double>> counts;
    for (const NoiseSample& s : samples) {
        const double predicted = fittedVariance(report, s.mean, s.gain);
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
        histHeader.push_back(cv::format("%.1f dB", kv.first));
    CsvTable hist(histHeader);
    for (int b = 0; b < bins; ++b) {
        std::vector<double> row = {(b + 0.5) * hiRatio / bins};
        for (const auto& kv : counts)
            row.push_back(kv.second[size_t(b)]);
        hist.addRow(row);
    }
    hist.write(histCsv);

    return counts.size();
}

PlotsWritten writeDarkOutputs(const CalibrateOptions& o, const CalibrateResult& result)
{
    const CalibrationReport& report = result.report;
    writeNewText(o.outDir + "/dark_calibration.yml",
                 fileStorageText("dark_calibration.yml",
                                 [&](cv::FileStorage& fs) { result.dark.write(fs, "dark_calibration"); }));
    CsvTable rows({"gain_db", "gain", "row_variance", "row_variance_se", "model_row_variance",
                   "pixel_variance", "excess_kurtosis", "sw_p_with_rows", "sw_p_without_rows"});
    for (const DarkGainStatistics& g : result.dark.gains)
        rows.addRow(std::vector<double>{linearGainToDb(g.gain), g.gain, g.rowVariance, g.rowVarianceSE,
                                        report.model.rowVariance(g.gain), g.pixelVariance, g.excessKurtosis,
                                        g.before.pValue, g.after.pValue});
    rows.write(o.outDir + "/dark_rows.csv");
    CsvTable ppcc({"lambda", "ppcc"});
    for (const cv::Vec2d& p : result.dark.ppcc)
        ppcc.addRow(std::vector<double>{p[0], p[1]});
    ppcc.write(o.outDir + "/dark_ppcc.csv");
    if (!o.plots)
        return PlotsWritten();
    return plotDarkComponents(o.outDir, result.dark, o.outDir + "/dark_rows.csv",
                              o.outDir + "/dark_ppcc.csv");
}

} // namespace rawgment_apps
