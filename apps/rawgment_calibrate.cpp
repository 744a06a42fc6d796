// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Calibrates the noise model from bursts listed in a manifest, with plots.
#include "app_tools.hpp"
#include "pipeline.hpp"

#include <opencv2/core/utility.hpp>

#include <cstdio>
#include <iostream>

namespace {

//! The verdict's line (scripts read it) and each check.
void printVerdict(const cv::rawgment::CalibrationVerdict& verdict)
{
    std::printf("verdict: %s\n", verdict.pass ? "PASS" : "FAIL");
    for (const cv::rawgment::VerdictCheck& c : verdict.checks)
        std::printf("  %s %s: %s\n", c.pass ? "pass" : "FAIL", c.name.c_str(), c.figure.c_str());
}

//! The report's notes, the run's notes and the plots written.
void printNotesAndPlots(const std::vector<std::string>& reportNotes, const std::vector<std::string>& notes,
                        const std::vector<std::string>& pngs)
{
    for (const std::string& n : reportNotes)
        std::printf("note: %s\n", n.c_str());
    for (const std::string& n : notes)
        std::printf("note: %s\n", n.c_str());
    for (const std::string& p : pngs)
        std::printf("plot: %s\n", p.c_str());
}

//! The verdict, the lines, the model with its errors, Shapiro-Wilk, the dark frames' findings and the notes.
void printCalibration(const rawgment_apps::CalibrateResult& r, const std::string& method)
{
    const cv::rawgment::CalibrationReport& rep = r.report;
    printVerdict(r.verdict);
    std::printf("method %s, %d of %d samples used\n", method.c_str(), rep.samplesUsed, rep.samples);
    if (!r.bank.empty()) {
        std::printf("dark-frame bank %s: %zu groups in %.1f s\n", r.bank.path.c_str(), r.bank.groups.size(),
                    r.bankSeconds);
        for (const cv::rawgment::DarkFrameGroup& g : r.bank.groups)
            std::printf(
                "  gain %g%s: %zu frames, temporal variance %.4g DN^2 (row part %.4g), fixed-pattern RMS "
                "%.4g DN, %zu noisy pixels\n",
                g.gain, g.exposureTime > 0 ? cv::format(", exposure %g s", g.exposureTime).c_str() : "",
                g.files.size(), cv::mean(g.statistics.temporalVariance)[0],
                cv::mean(g.statistics.rowNoiseVariance)[0], g.statistics.fixedPatternRms(),
                g.statistics.noisyPixels.size());
    }
    for (const cv::rawgment::NoiseLineFit& l : rep.perGain)
        std::printf(
            "  gain %6.2f dB: variance = (%.5f +- %.2g) mean + (%.4f +- %.2g)  (R^2 %.4f, %d inliers)\n",
            cv::rawgment::linearGainToDb(l.gain), l.line.a, l.slopeStdError, l.line.b, l.offsetStdError,
            l.rSquared, l.inliers);
    // Standard errors, and 95% intervals for the read terms, whose relative errors are the larger.
    const cv::Vec2d d = rep.interval(cv::rawgment::NOISE_PARAM_SIGMA_D2),
                    r2 = rep.interval(cv::rawgment::NOISE_PARAM_SIGMA_R2);
    if (rep.separable)
        std::printf("model: alpha %.6f +- %.2g  sigma_d^2 %.5f +- %.2g [%.5g, %.5g]  sigma_r^2 %.5f +- %.2g "
                    "[%.5g, %.5g]  (+- one standard error, [95%% interval]; R^2 slope %.4f, offset %.4f)\n",
                    rep.model.alpha, rep.uncertainty.stdError[0], rep.model.sigmaD2,
                    rep.uncertainty.stdError[1], d[0], d[1], rep.model.sigmaR2, rep.uncertainty.stdError[2],
                    r2[0], r2[1], rep.rSquaredSlope, rep.rSquaredOffset);
    else
        std::printf("model: alpha %.6f +- %.2g (sigma_d^2 and sigma_r^2 not separable)\n", rep.model.alpha,
                    rep.uncertainty.stdError[0]);
    const std::string correlation =
        rep.separable ? cv::format("; sigma_d^2 and sigma_r^2 correlate %+.2f",
                                   rep.uncertainty.correlation(cv::rawgment::NOISE_PARAM_SIGMA_D2,
                                                               cv::rawgment::NOISE_PARAM_SIGMA_R2))
                      : std::string();
    std::printf("errors: from the %s%s\n",
                rep.uncertainty.source == cv::rawgment::UNCERTAINTY_BOOTSTRAP ? "bootstrap"
                                                                              : "fit's covariance",
                correlation.c_str());
    if (r.shapiroTested > 0)
        std::printf("Shapiro-Wilk: %.1f%% of %d pixels have p > 0.05\n", 100 * r.gaussianFraction,
                    r.shapiroTested);
    else
        std::printf("Shapiro-Wilk: no pixel tested (it needs bursts of 3 or more frames)\n");
    if (r.haveDark) {
        const cv::rawgment::NoiseModel& m = rep.model;
        std::printf(
            "dark frames: row noise %.4g g^2 + %.4g DN^2, read-noise lambda %.3f (PPCC %.5f, Gaussian "
            "%.5f)%s\n",
            m.rowSigmaD2, m.rowSigmaR2, m.tukeyLambda, r.dark.ppccBest, r.dark.ppccGaussian,
            m.hasDarkShading() ? ", dark shading maps beside noise_model.yml" : "");
        for (const cv::rawgment::DarkGainStatistics& g : r.dark.gains)
            std::printf("  gain %6.2f dB: row variance %.4g +- %.2g, pixel variance %.4g, excess kurtosis "
                        "%.3f, Shapiro-Wilk p %.3g with the rows, %.3g without\n",
                        cv::rawgment::linearGainToDb(g.gain), g.rowVariance, g.rowVarianceSE, g.pixelVariance,
                        g.excessKurtosis, g.before.pValue, g.after.pValue);
        for (const std::string& n : r.dark.notes)
            std::printf("note: %s\n", n.c_str());
    }
    printNotesAndPlots(rep.notes, r.notes, r.pngs);
}

//! The verdict, the standard's figures of each series, the model and the real-frame validation.
void printEmva1288(const rawgment_apps::Emva1288FlowResult& r)
{
    printVerdict(r.verdict);
    for (size_t k = 0; k < r.results.size(); ++k) {
        const cv::rawgment::Emva1288Results& e = r.results[k];
        std::printf(
            "EMVA 1288 %s (%.2f dB): K %.5f DN/e-, sigma_y.dark %.4f DN, sigma_d %.3f e-, mu_e.sat %.0f "
            "e-, eta %.2f%%, SNR_max %.2f dB, DR %.2f dB, mu_p.min %.2f p, DSNU1288 %.3f e-, PRNU1288 "
            "%.3f%%, linearity %.3f%% to %+.3f%%\n",
            r.inputs[k].descriptor.c_str(), r.inputs[k].gainDb, e.K, e.sigmaYDark, e.sigmaD, e.muESat, e.eta,
            e.snrMaxDb, e.dynamicRangeDb, e.muPMin, e.dsnu1288, e.prnu1288, e.linearityErrorMin,
            e.linearityErrorMax);
    }
    const cv::rawgment::CalibrationReport& rep = r.report;
    std::printf("model: alpha %.6f +- %.2g, sigma_d^2 %.5f +- %.2g, sigma_r^2 %.5f +- %.2g%s\n",
                rep.model.alpha, rep.uncertainty.stdError[0], rep.model.sigmaD2, rep.uncertainty.stdError[1],
                rep.model.sigmaR2, rep.uncertainty.stdError[2],
                rep.separable ? "" : " (one gain: the read noise is sigma_r^2)");
    for (size_t i = 0; i + 2 < r.darkening.size(); i += 3)
        std::printf("validation: point %d to %d (photon ratio %.3f): variance ratio NONE %.4f, IGNORE_PRIOR "
                    "%.4f, ACCOUNT_PRIOR %.4f +- %.4f\n",
                    r.darkening[i].brightPoint, r.darkening[i].darkPoint, r.darkening[i].photonRatio,
                    r.darkening[i].ratio, r.darkening[i + 1].ratio, r.darkening[i + 2].ratio,
                    r.darkening[i + 2].ratioStdError);
    printNotesAndPlots(rep.notes, r.notes, r.pngs);
}

} // namespace

int main(int argc, char** argv)
{
    const char* keys =
        "{help h usage ? |       | print this message }"
        "{@manifest      |       | calibration manifest (YAML/JSON), or a folder of burst folders }"
        "{emva           |       | an EMVA 1288 descriptor (EMVA1288_Data.txt), or a manifest of them }"
        "{fit_fraction   | 0.3   | with --emva: the steps fitted, up to this fraction of saturation }"
        "{out o          |       | output directory (required) }"
        "{method         | joint | joint (default, beyond the paper) or two-stage (the paper) }"
        "{side           | 24    | square side when the manifest says patches: detect }"
        "{shapiro        | 2000  | pixels per burst tested with Shapiro-Wilk }"
        "{seed           | 0     | seed of the robust line fits (RANSAC); with --emva, of the validation }"
        "{bootstrap      | 200   | bootstrap replicates that confirm the standard errors (0: the fit's "
        "covariance alone; at a bound the bootstrap gives them) }"
        "{plots          | true  | write PNG plots with gnuplot }"
        "{dark_components| false | also row noise, dark shading and the read noise's shape from the dark "
        "bursts }"
        "{dark_bank      |       | also write a dark-frame bank of the dark bursts' files to this file "
        "(bank.yml): rawgment_augment --dark_bank takes it }";
    if (!rawgment_apps::checkCommandLine(argc, argv, keys, "rawgment_calibrate"))
        return 2;
    rawgment_apps::installInterruptCleanup();
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about(
        "rawgment_calibrate: alpha, sigma_d^2, sigma_r^2 from bursts of a static scene\n\n"
        "Manifest:\n"
        "  calibration_manifest:\n"
        "    patches: detect    # cv::mcc finds the chart; or none: any static scene; or patches.yml\n"
        "    base_iso: 100      # optional: the ISO of gain 1 (default: the lowest ISO of the files)\n"
        "    bursts:\n"
        "      - { files: [ iso100/a.dng, iso100/b.dng, ... ] }           # gain from the files' ISO\n"
        "      - { gain_db: 12, files: [ ... ] }                          # or as given\n"
        "      - { dark: true, files: [ dark400/a.dng, ... ] }            # lens cap: pins read noise\n"
        "Or a folder with one folder of frames per burst (names starting with 'dark': dark\n"
        "frames), every gain from the ISO, no chart. The frames of a burst must share ISO,\n"
        "exposure, size and levels (16 frames or more for a PASS); a burst of one file is\n"
        "single-frame mode (spatial variance of chart patches). Paths are relative to the\n"
        "manifest. Writes report.md (a PASS/FAIL verdict, each check against its threshold),\n"
        "noise_model.yml, calibration_report.yml, samples.csv, lines.csv, shapiro.csv, PNG plots\n"
        "(with --dark_components also dark_calibration.yml, dark_rows.csv, dark_ppcc.csv, their\n"
        "plots, dark_shading.png and the dark-shading TIFFs beside noise_model.yml)\n"
        "and, with gains from ISO, darktable_noiseprofiles.json and android_noise_profile.yml into\n"
        "--out; never overwrites them. Step by step: docs/calibrate_your_camera.md.\n\n"
        "EMVA 1288 data (--emva instead of the manifest): a descriptor of the standard, whose series\n"
        "is at gain 0 dB, or a manifest of several gains:\n"
        "  emva1288_manifest:\n"
        "    base_iso: 100                       # optional, for series given by ISO\n"
        "    series:\n"
        "      - { descriptor: g0/EMVA1288_Data.txt, gain_db: 0 }\n"
        "      - { descriptor: g12/EMVA1288_Data.txt, iso: 400 }\n"
        "Writes report.md (verdict, the standard's figures, the model, the real-frame validation),\n"
        "noise_model.yml, calibration_report.yml, emva1288.yml (the reference implementation's\n"
        "names), emva1288_points.csv, emva1288_validation.csv and PNG plots.");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    const std::string emva = parser.get<std::string>("emva");
    if (!emva.empty()) {
        rawgment_apps::Emva1288Options e;
        e.input = emva;
        e.outDir = parser.get<std::string>("out");
        e.maxSignalFraction = parser.get<double>("fit_fraction");
        e.plots = parser.get<bool>("plots");
        e.seed = rawgment_apps::seedOption(parser, "rawgment_calibrate");
        if (!parser.check() || e.outDir.empty() || !parser.get<std::string>("@manifest").empty() ||
            !(e.maxSignalFraction > 0 && e.maxSignalFraction <= 1)) {
            parser.printErrors();
            std::cerr << "usage: rawgment_calibrate --emva=<EMVA1288_Data.txt or manifest.yml> --out=<dir> "
                         "[--fit_fraction=(0, 1]] (no calibration manifest with --emva)\n";
            return 2;
        }
        try {
            rawgment_apps::OutputDirectory outputDirectory(e.outDir);
            const rawgment_apps::Emva1288FlowResult r = rawgment_apps::calibrateFromEmva1288(e);
            printEmva1288(r);
            outputDirectory.keep();
            return 0;
        } catch (const cv::Exception& ex) {
            // A descriptor, an image or a manifest that is not what it should be: bad input, as a usage
            // error.
            std::cerr << "rawgment_calibrate: " << ex.err << "\n";
            return 2;
        } catch (const std::exception& ex) {
            std::cerr << "rawgment_calibrate: " << ex.what() << "\n";
            return 2;
        }
    }
    rawgment_apps::CalibrateOptions o;
    o.manifest = parser.get<std::string>("@manifest");
    o.outDir = parser.get<std::string>("out");
    const std::string method = parser.get<std::string>("method");
    o.side = parser.get<int>("side");
    o.shapiroPixels = parser.get<int>("shapiro");
    o.bootstrapReplicates = parser.get<int>("bootstrap");
    o.plots = parser.get<bool>("plots");
    o.seed = rawgment_apps::seedOption(parser, "rawgment_calibrate");
    o.darkComponents = parser.get<bool>("dark_components");
    o.darkBank = parser.get<std::string>("dark_bank");
    if (!parser.check() || o.manifest.empty() || o.outDir.empty() ||
        (method != "joint" && method != "two-stage") || o.shapiroPixels < 1 || o.shapiroPixels > 1000000 ||
        o.side < 2 || o.side % 2 || o.bootstrapReplicates < 0 || o.bootstrapReplicates == 1 ||
        o.bootstrapReplicates > 100000) {
        parser.printErrors();
        std::cerr << "usage: rawgment_calibrate <manifest.yml> --out=<dir> [--method=joint|two-stage] "
                     "[--shapiro=1..1000000] [--side=even >= 2] [--bootstrap=0 or 2..100000]\n";
        return 2;
    }
    o.method = method == "joint" ? cv::rawgment::NOISE_FIT_JOINT : cv::rawgment::NOISE_FIT_TWO_STAGE;
    try {
        rawgment_apps::OutputDirectory outputDirectory(o.outDir);
        const rawgment_apps::CalibrateResult r = rawgment_apps::calibrateFromManifest(o);
        printCalibration(r, method);
        outputDirectory.keep();
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_calibrate: " << e.what() << "\n";
        return 1;
    }
}
