// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "plots.hpp"

#include "app_tools.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace rawgment_apps {

using namespace cv::rawgment;

namespace {

const char* const kSeriesColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                      "#ff7f0e", "#8c564b", "#17becf"};

void plotOrNote(const std::string& png, const std::string& script, PlotsWritten& out)
{
    // A plot an interrupted run of the same job already made is kept, never redrawn over.
    if (pathExists(png)) {
        out.pngs.push_back(png);
        return;
    }
    std::string message;
    if (plotWithGnuplot(png, script, message))
        out.pngs.push_back(png);
    else
        out.notes.push_back(message);
}

} // namespace

PlotsWritten plotCalibration(const std::string& outDir, const CalibrationReport& report,
                             const CalibrationPlotFiles& files, size_t histogramSeries,
                             const std::vector<double>& gainsDb, bool haveShapiro)
{
    PlotsWritten out;
    const NoiseModel& model = report.model;
    std::string s;
    s += "set title 'Noise calibration: variance against mean at each gain'\n";
    s += "set xlabel 'mean signal above black (DN)'\nset ylabel 'variance (DN^2)'\n";
    s += "set key left top box opaque\nset grid\n";
    s += "plot ";
    for (size_t i = 0; i < report.perGain.size(); ++i) {
        const NoiseLineFit& l = report.perGain[i];
        const double gDb = linearGainToDb(l.gain);
        const std::string colour = kSeriesColours[i % 7];
        s += cv::format("%s every ::1 using ($3 > %.6f && $3 < %.6f ? $1 : 1/0):2 with points pt 7 ps 0.25 "
                        "lc rgb '%s' title '%.1f dB samples', ",
                        gnuplotString(files.samplesCsv).c_str(), gDb - 0.01, gDb + 0.01, colour.c_str(), gDb);
        s += cv::format(
            "%.10g*x + %.10g with lines lw 2 lc rgb '%s' dt 2 title 'line fit: %.4f {/Symbol m} + %.3f "
            "(R^2 %.4f)', ",
            l.line.a, l.line.b, colour.c_str(), l.line.a, l.line.b, l.rSquared);
    }
    s += report.separable
             ? cv::format("1/0 title 'model: {/Symbol a} %.4f, {/Symbol s}_d^2 %.4f, {/Symbol s}_r^2 %.4f'\n",
                          model.alpha, model.sigmaD2, model.sigmaR2)
             : cv::format("1/0 title 'model: {/Symbol a} %.4f ({/Symbol s}_d^2, {/Symbol s}_r^2 not "
                          "separable)'\n",
                          model.alpha);
    plotOrNote(outDir + "/calib_mean_variance.png", s, out);

    s = "set title 'Sample variance over fitted variance, per gain (ideal: centred on 1)'\n";
    s += "set xlabel 'variance / fitted variance'\nset ylabel 'samples'\nset key right top\nset grid\nplot ";
    for (size_t i = 0; i < histogramSeries; ++i)
        s += cv::format("%s%s every ::1 using 1:%zu with steps lw 2 lc rgb '%s' title columnhead(%zu)",
                        i ? ", " : "", gnuplotString(files.histogramCsv).c_str(), i + 2,
                        kSeriesColours[i % 7], i + 2);
    plotOrNote(outDir + "/calib_histograms.png", s, out);

    // A cross-gain fit needs two gains, a Shapiro-Wilk plot tested pixels (bursts of >= 3 frames).
    if (report.perGain.size() < 2)
        out.notes.push_back("one gain: no cross-gain plot");
    if (!haveShapiro)
        out.notes.push_back("no burst of 3 or more frames: no Shapiro-Wilk plot");
    if (report.perGain.size() >= 2) {
        s = "set multiplot layout 1,2 title 'Cross-gain fit of the per-gain lines'\nset grid\nset key left "
            "top\n";
        s += cv::format("set title 'slope a_g = g {/Symbol a}   (R^2 %.4f)'\nset xlabel 'linear gain g'\n"
                        "set ylabel 'a_g (DN per DN)'\n",
                        report.rSquaredSlope);
        s += cv::format(
            "plot %s every ::1 using 2:3 with points pt 7 ps 1.5 title 'per-gain fits', %.10g*x with lines "
            "lw 2 title 'g {/Symbol a}'\n",
            gnuplotString(files.linesCsv).c_str(), model.alpha);
        s += cv::format("set title 'offset b_g = g^2 {/Symbol s}_d^2 + {/Symbol s}_r^2   (R^2 %.4f)'\n"
                        "set xlabel 'g^2'\nset ylabel 'b_g (DN^2)'\n",
                        report.rSquaredOffset);
        s += cv::format("plot %s every ::1 using ($2*$2):4 with points pt 7 ps 1.5 title 'per-gain fits', "
                        "%.10g*x + %.10g with lines lw 2 title 'g^2 {/Symbol s}_d^2 + {/Symbol "
                        "s}_r^2'\nunset multiplot\n",
                        gnuplotString(files.linesCsv).c_str(), model.sigmaD2, model.sigmaR2);
        plotOrNote(outDir + "/calib_cross_gain.png", s, out);
    }
    if (!haveShapiro)
        return out;

    s = "set title 'Shapiro-Wilk test of each pixel''s temporal series (Gaussian noise: p spread evenly on "
        "[0, 1])'\n";
    s += "set xlabel 'mean signal above black (DN)'\nset ylabel 'p-value'\nset logscale y\nset yrange "
         "[1e-6:1]\n";
    s += "set key right bottom box opaque\nset grid\nplot ";
    for (size_t i = 0; i < gainsDb.size(); ++i)
        s += cv::format(
            "%s every ::1 using ($1 > %.6f && $1 < %.6f ? $2 : 1/0):($3 < 1e-6 ? 1e-6 : $3) with points "
            "pt 7 ps 0.3 lc rgb '%s' title '%.1f dB', ",
            gnuplotString(files.shapiroCsv).c_str(), gainsDb[i] - 0.01, gainsDb[i] + 0.01,
            kSeriesColours[i % 7], gainsDb[i]);
    s += "0.05 with lines lw 2 lc rgb 'black' dt 2 title 'p = 0.05'\n";
    plotOrNote(outDir + "/shapiro_pvalue.png", s, out);
    return out;
}

PlotsWritten plotDarkComponents(const std::string& outDir, const DarkCalibrationReport& dark,
                                const std::string& rowsCsv, const std::string& ppccCsv)
{
    PlotsWritten out;
    const NoiseModel& m = dark.model;
    std::string rows = "set title 'Row noise: variance of a row offset against gain'\n";
    rows += "set xlabel 'linear gain'\nset ylabel 'row variance (DN^2)'\nset logscale xy\nset grid\n";
    rows += "set key left top box opaque\nset datafile separator ','\n";
    rows += cv::format(
        "plot %s every ::1 using 2:3:4 with yerrorbars pt 7 lc rgb '%s' title 'measured (+- 1 "
        "standard error)', x*x*%.10g + %.10g with lines lw 2 lc rgb '%s' title 'fit: g^2 %.4g + %.4g'\n",
        gnuplotString(rowsCsv).c_str(), kSeriesColours[0], m.rowSigmaD2, m.rowSigmaR2, kSeriesColours[1],
        m.rowSigmaD2, m.rowSigmaR2);
    plotOrNote(outDir + "/dark_rows.png", rows, out);
    std::string ppcc = "set title 'Read-noise shape: probability-plot correlation against Tukey lambda'\n";
    ppcc += "set xlabel 'lambda (0.14: Gaussian, smaller: heavier tails)'\nset ylabel 'PPCC'\nset grid\n";
    ppcc += "set datafile separator ','\nset key left bottom box opaque\n";
    ppcc += cv::format("set arrow from %.6g, graph 0 to %.6g, graph 1 nohead dt 2 lc rgb '%s'\n",
                       dark.lambdaOfResiduals, dark.lambdaOfResiduals, kSeriesColours[1]);
    ppcc +=
        cv::format("plot %s every ::1 using 1:2 with linespoints pt 7 ps 0.5 lc rgb '%s' title "
                   "'residuals (best %.3f; Gaussian plot %.5f); model lambda %.3f after the correction'\n",
                   gnuplotString(ppccCsv).c_str(), kSeriesColours[0], dark.lambdaOfResiduals,
                   dark.ppccGaussian, m.tukeyLambda);
    plotOrNote(outDir + "/dark_ppcc.png", ppcc, out);
    if (!m.hasDarkShading())
        return out;
    const std::string shading = outDir + "/dark_shading.png";
    if (pathExists(shading)) {
        out.pngs.push_back(shading);
        return out;
    }
    // Each map in false colour over its 1st to 99th percentile, side by side, with its range as text.
    std::vector<cv::Mat> panels;
    for (int i = 0; i < 2; ++i) {
        const cv::Mat& map = i == 0 ? m.darkShadingPerGain : m.darkShadingOffset;
        std::vector<float> v(map.begin<float>(), map.end<float>());
        std::sort(v.begin(), v.end());
        const float lo = v[v.size() / 100], hi = v[v.size() - 1 - v.size() / 100];
        cv::Mat scaled, colour;
        map.convertTo(scaled, CV_8U, 255.0 / std::max(hi - lo, 1e-6f),
                      -lo * 255.0 / std::max(hi - lo, 1e-6f));
        // About 600 pixels wide, whatever the sensor: small maps are enlarged pixel for pixel.
        const double fit = 600.0 / map.cols;
        cv::resize(scaled, scaled, cv::Size(), fit, fit, fit < 1 ? cv::INTER_AREA : cv::INTER_NEAREST);
        cv::applyColorMap(scaled, colour, cv::COLORMAP_VIRIDIS);
        cv::Mat panel(colour.rows + 40, colour.cols + 20, CV_8UC3, cv::Scalar::all(255));
        colour.copyTo(panel(cv::Rect(10, 40, colour.cols, colour.rows)));
        cv::putText(
            panel, cv::format("%s: %.3g to %.3g DN", i == 0 ? "B_d (per unit gain)" : "B_r (offset)", lo, hi),
            cv::Point(10, 28), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar::all(0), 1, cv::LINE_AA);
        panels.push_back(panel);
    }
    cv::Mat both;
    cv::hconcat(panels, both);
    writeNewImage(shading, both);
    out.pngs.push_back(shading);
    return out;
}

PlotsWritten plotValidation(const std::string& outDir, const std::string& csvPath,
                            const std::vector<ValidationPanel>& panels)
{
    PlotsWritten out;
    std::string s =
        cv::format("set multiplot layout 1,%zu title 'Bright burst converted to darker exposures against "
                   "real darker bursts (per-pixel temporal variance, averaged per mean bin)'\n",
                   panels.size());
    s += "set grid\nset key left top box opaque\nset xlabel 'mean signal above black (DN)'\n"
         "set ylabel 'temporal variance (DN^2)'\n";
    for (size_t i = 0; i < panels.size(); ++i) {
        const double f = panels[i].factor;
        const std::string sel = cv::format("($1 > %.6f && $1 < %.6f ? $4 : 1/0)", f - 1e-6, f + 1e-6);
        s += cv::format("set title 'x%.2f exposure'\nset xrange [0:%.6g]\nset yrange [0:*]\n", f,
                        panels[i].largestMean * 1.05);
        s += cv::format(
            "plot %s every ::1 using %s:6 with points pt 7 ps 1.6 lc rgb 'black' title 'real darker "
            "burst', ",
            gnuplotString(csvPath).c_str(), sel.c_str());
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
    plotOrNote(outDir + "/validation.png", s, out);
    return out;
}

} // namespace rawgment_apps
