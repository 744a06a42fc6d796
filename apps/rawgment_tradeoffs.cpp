// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What accuracy costs in time: every knob of the library that trades one for the other, measured in one
// run against the sensor simulator's ground truth, written as a Markdown table, a CSV and a PNG.
#include "app_tools.hpp"
#include "tradeoff_measures.hpp"

#include <opencv2/rawgment/cpu.hpp>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <iostream>
#include <sstream>

using namespace cv;
using cv::rawgment::activeCpuPath;
using cv::rawgment::availableCpuPaths;
using cv::rawgment::CpuPath;
using cv::rawgment::cpuPathName;
using rawgment_apps::formatNumber;

namespace {

std::string markdownCell(const std::string& text)
{
    std::string out;
    for (char c : text)
        out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
}

std::string markdownTable(const std::vector<rawgment_apps::TradeoffRow>& rows)
{
    // The time on every CPU path this machine has, for the knobs whose loops are dispatched.
    const std::vector<CpuPath> paths = availableCpuPaths();
    std::ostringstream md;
    md << "| Knob | Setting | Accuracy measure | Error | Time per MP (" << cpuPathName(activeCpuPath())
       << ") |";
    for (CpuPath p : paths)
        md << " " << cpuPathName(p) << " |";
    md << "\n|---|---|---|---:|---:|";
    for (size_t k = 0; k < paths.size(); ++k)
        md << "---:|";
    md << "\n";
    for (const rawgment_apps::TradeoffRow& r : rows) {
        char error[64], time[32];
        if (r.errorStdError > 0)
            std::snprintf(error, sizeof(error), "%.3g ± %.2g", r.error, r.errorStdError);
        else
            std::snprintf(error, sizeof(error), "%.3g", r.error);
        std::snprintf(time, sizeof(time), "%.3g ms", r.msPerMp);
        md << "| " << r.knob << " | " << r.setting << " | " << markdownCell(r.measure) << " | " << error
           << " | " << time << " |";
        for (size_t k = 0; k < paths.size(); ++k) {
            if (k < r.msPerMpByPath.size()) {
                std::snprintf(time, sizeof(time), "%.3g ms", r.msPerMpByPath[k]);
                md << " " << time << " |";
            } else {
                md << " |";
            }
        }
        md << "\n";
    }
    return md.str();
}

} // namespace

namespace {

// A gnuplot string in double quotes, so that the "\\n" of wrapped() breaks the line.
std::string quoted(const std::string& text)
{
    std::string out = "\"";
    for (char c : text)
        out += c == '"' ? std::string("\\\"") : std::string(1, c);
    return out + "\"";
}

// A data-block cell: the blocks are comma-separated.
std::string cellText(std::string text)
{
    std::replace(text.begin(), text.end(), ',', ';');
    return text;
}

// Breaks text into lines of at most `width` characters at spaces (gnuplot's "\n" in a title).
std::string wrapped(const std::string& text, size_t width)
{
    std::string out, line;
    std::istringstream words(text);
    for (std::string word; words >> word;) {
        if (!line.empty() && line.size() + 1 + word.size() > width) {
            out += (out.empty() ? "" : "\\n") + line;
            line.clear();
        }
        line += (line.empty() ? "" : " ") + word;
    }
    return out + (out.empty() ? "" : "\\n") + line;
}

// The setting a knob is measured against: the paper's or the library's default, else the model without
// the component, else the first.
size_t referenceOf(const std::vector<const rawgment_apps::TradeoffRow*>& settings)
{
    for (const char* mark : {"(paper)", "(default)", "absent"})
        for (size_t k = 0; k < settings.size(); ++k)
            if (settings[k]->setting.find(mark) != std::string::npos)
                return k;
    return 0;
}

/* The trade-off figure. On top, one view of every knob: each setting's error and time relative to its
 * knob's reference setting (so that knobs with different measures and units share the axes), the
 * reference at (1, 1): down is more accurate, left is faster. Below, one panel per knob in its own
 * measure and unit, its settings told apart by the key instead of labels that overlap. */
std::string tradeoffPlotScript(const std::vector<rawgment_apps::TradeoffRow>& rows)
{
    std::vector<std::string> knobs;
    for (const rawgment_apps::TradeoffRow& r : rows)
        if (std::find(knobs.begin(), knobs.end(), r.knob) == knobs.end())
            knobs.push_back(r.knob);
    const auto settingsOf = [&](const std::string& knob) {
        std::vector<const rawgment_apps::TradeoffRow*> out;
        for (const rawgment_apps::TradeoffRow& r : rows)
            if (r.knob == knob)
                out.push_back(&r);
        return out;
    };
    // A log axis cannot show 0: an exact match is drawn at 1e-17.
    const auto shown = [](double error) { return formatNumber(std::max(error, 1e-17)); };
    const int columns = 4, panelRows = (static_cast<int>(knobs.size()) + columns - 1) / columns;
    const double overviewHeight = 0.36, panelHeight = (1 - overviewHeight) / panelRows;
    std::string script = "set multiplot\nset termoption noenhanced\nset logscale xy\nset grid\n";

    // The overview.
    script += cv::format("set origin 0,%g\nset size 1,%g\n", 1 - overviewHeight, overviewHeight);
    script += "set title " +
              quoted("Which knob buys the most accuracy per millisecond?\\nEvery setting against its knob's "
                     "reference setting at (1, 1): the paper's or the library's default, for a dark-frame "
                     "component the model without it.\\nDown is more accurate, left is faster. Knobs whose "
                     "reference is exact (error 0) are in their own panels only.") +
              " font ',12'\n";
    script += "set xlabel " + quoted("time per MP / the reference setting's") + "\nset ylabel " +
              quoted("error / the reference setting's error (each knob's own measure)") + "\n";
    script += "set key outside right top vertical font ',9' spacing 1.1\nset offsets graph 0.03, graph 0.03, "
              "graph 0.08, "
              "graph 0.03\n";
    script += "set arrow 1 from graph 0, first 1 to graph 1, first 1 nohead dt 2 lc rgb '#888888'\n"
              "set arrow 2 from first 1, graph 0 to first 1, graph 1 nohead dt 2 lc rgb '#888888'\n";
    std::string plots;
    int style = 0;
    for (size_t k = 0; k < knobs.size(); ++k) {
        const std::vector<const rawgment_apps::TradeoffRow*> settings = settingsOf(knobs[k]);
        const rawgment_apps::TradeoffRow& reference = *settings[referenceOf(settings)];
        if (!(reference.error > 0) || !(reference.msPerMp > 0))
            continue;
        const std::string block = "$overview" + std::to_string(k);
        script += block + " << EOD\n";
        for (const rawgment_apps::TradeoffRow* r : settings)
            if (r != &reference)
                script += cellText(r->setting) + "," + shown(r->error / reference.error) + "," +
                          formatNumber(r->msPerMp / reference.msPerMp) + "\n";
        script += "EOD\n";
        ++style;
        plots += (plots.empty() ? "plot " : ", ") + block + " using 3:2 with points pt " +
                 std::to_string(4 + style % 10) + " ps 1.8 lc " + std::to_string(style) + " title " +
                 quoted(knobs[k]);
    }
    script += plots + ", '+' using (1):(1) every ::0::0 with points pt 7 ps 2 lc rgb 'black' title "
                      "'every reference setting'\n";
    script += "unset arrow 1\nunset arrow 2\n";

    // One panel per knob, in its own measure.
    // Room around the points, so that none sits on a panel's edge.
    script += "set key below font ',8' spacing 0.9\nset xlabel 'ms per MP' font ',9'\n"
              "set offsets graph 0.15, graph 0.15, graph 0.15, graph 0.15\n";
    for (size_t k = 0; k < knobs.size(); ++k) {
        const std::vector<const rawgment_apps::TradeoffRow*> settings = settingsOf(knobs[k]);
        const int row = static_cast<int>(k) / columns, column = static_cast<int>(k) % columns;
        script += cv::format("set origin %g,%g\nset size %g,%g\n", column * (1.0 / columns),
                             (1 - overviewHeight) - (row + 1) * panelHeight, 1.0 / columns, panelHeight);
        script += "set title " + quoted(wrapped(knobs[k], 44)) + " font ',10'\n";
        script += "set ylabel " + quoted(wrapped(settings.front()->measure, 34)) + " font ',8'\n";
        const std::string block = "$knob" + std::to_string(k);
        script += block + " << EOD\n";
        for (const rawgment_apps::TradeoffRow* r : settings)
            script += cellText(r->setting) + "," + shown(r->error) + "," + formatNumber(r->msPerMp) + "\n";
        script += "EOD\nplot ";
        for (size_t i = 0; i < settings.size(); ++i)
            script += std::string(i ? ", " : "") + block + " every ::" + std::to_string(i) +
                      "::" + std::to_string(i) + " using 3:2 with points pt " +
                      std::to_string(5 + static_cast<int>(i)) + " ps 1.6 lc " +
                      std::to_string(static_cast<int>(i) + 1) + " title " + quoted(settings[i]->setting);
        script += "\n";
    }
    return script + "unset multiplot\n";
}

//! The table's rows as CSV cells, one time column per CPU path.
rawgment_apps::CsvTable tradeoffTable(const std::vector<rawgment_apps::TradeoffRow>& rows)
{
    std::vector<std::string> header = {"knob",     "setting",         "measure",           "error",
                                       "error_se", "frames_to_shoot", "s_per_calibration", "ms_per_mp"};
    for (CpuPath p : availableCpuPaths())
        header.push_back("ms_per_mp_" + cpuPathName(p));
    rawgment_apps::CsvTable table(header);
    // CsvTable does not quote: text cells keep their commas out of the way as semicolons.
    const auto cell = [](std::string text) {
        std::replace(text.begin(), text.end(), ',', ';');
        return text;
    };
    for (const rawgment_apps::TradeoffRow& r : rows) {
        // The calibration knobs' own columns stay empty for the other knobs.
        const bool calibration = r.framesToShoot > 0;
        std::vector<std::string> cells = {cell(r.knob),
                                          cell(r.setting),
                                          cell(r.measure),
                                          formatNumber(r.error),
                                          calibration ? formatNumber(r.errorStdError) : std::string(),
                                          calibration ? std::to_string(r.framesToShoot) : std::string(),
                                          calibration ? formatNumber(r.secondsPerCalibration) : std::string(),
                                          formatNumber(r.msPerMp)};
        // Knobs whose loops are not dispatched have one time: the other cells stay empty.
        for (size_t k = 0; k < availableCpuPaths().size(); ++k)
            cells.push_back(k < r.msPerMpByPath.size() ? formatNumber(r.msPerMpByPath[k]) : std::string());
        table.addRow(cells);
    }
    return table;
}

/** The calibration knobs as a user meets them: the frames to shoot and the time of one calibration, beside
 * the error and how far it falls from the setting before, in standard errors of that fall. */
std::string calibrationMarkdown(const std::vector<rawgment_apps::TradeoffRow>& rows,
                                const rawgment_apps::TradeoffSettings& set)
{
    std::ostringstream md;
    md << "## A calibration: the frames to shoot, its time, its error\n\n"
       << "One calibration of a " << set.timingSize.width << "x" << set.timingSize.height
       << " camera (3 gains x 2 light levels of a chart): the burst statistics of every frame, the "
          "sampling of the squares and the fit with its bootstrap, on "
       << getNumThreads()
       << " threads; reading the files is not included. The dark-frame bank's rows: one gain's dark frames, "
          "the time to make its group from them (reading them from the page cache included), the RMS error "
          "of "
          "its pattern against the sensor's. The fall is that of the mean squared error from "
          "the row above, over the same "
       << set.seeds
       << " campaigns, in standard errors of the per-campaign differences (the settings share their "
          "frames).\n\n"
       << "| Knob | Setting | Frames to shoot | Time per calibration | Error (RMS ± SE) | Fall from the row "
          "above |\n|---|---|---:|---:|---:|---:|\n";
    const rawgment_apps::TradeoffRow* previous = nullptr;
    for (const rawgment_apps::TradeoffRow& r : rows) {
        if (r.framesToShoot == 0)
            continue;
        std::string fall = "-";
        if (previous && previous->knob == r.knob && r.knob != "Calibration RANSAC iterations") {
            const rawgment_apps::ErrorFall f =
                rawgment_apps::pairedFall(previous->campaignErrors, r.campaignErrors);
            fall = f.stdError > 0 ? cv::format("%.1f SE", f.meanSquareFall / f.stdError) : std::string("-");
        }
        md << "| " << r.knob << " | " << r.setting << " | " << r.framesToShoot << " | "
           << cv::format("%.2f s", r.secondsPerCalibration) << " | "
           << cv::format("%.3g ± %.2g", r.error, r.errorStdError) << " | " << fall << " |\n";
        previous = &r;
    }
    return md.str();
}

//! tradeoffs.md: the table, what each setting means, and what more calibration data buys.
std::string tradeoffMarkdown(const std::vector<rawgment_apps::TradeoffRow>& rows,
                             const std::vector<rawgment_apps::PrecisionRow>& precision,
                             const rawgment_apps::TradeoffSettings& set, bool quick)
{
    std::ostringstream text;
    text << "# What accuracy costs in time\n\n"
         << "Measured by `rawgment_tradeoffs" << (quick ? " --quick" : "") << "` on " << getNumThreads()
         << " threads; times per megapixel of a " << set.timingSize.width << "x" << set.timingSize.height
         << " CV_16UC1 mosaic (fastest of " << set.repeats
         << "), per MP of burst input for calibration, per million values for Shapiro-Wilk; the "
            "augmentation and burst-statistics knobs are timed on every CPU path this machine has "
            "(the same bits on each). Errors "
            "against "
            "the sensor simulator's truth; calibration errors are RMS over "
         << set.seeds << " simulated campaigns, ± their standard error.\n\n"
         << markdownTable(rows) << "\n"
         << calibrationMarkdown(rows, set) << "\n## What each setting means\n\n";
    for (const rawgment_apps::TradeoffRow& r : rows)
        text << "- " << r.knob << ", " << r.setting << ": " << r.meaning << ".\n";
    text << "\n## Calibration precision: what more data buys\n\n"
            "Relative standard errors the calibration states (mean over "
         << set.seeds
         << " campaigns), the relative errors it makes (RMS over the same campaigns, against the "
            "simulator's truth: with few campaigns a noisy figure of the same size), and for more of the "
            "same data the formula se0 sqrt((T0 - 1) N0 / ((T - 1) N)) from the reference row (T frames, "
            "N "
            "pixels). Fewer gains and dark frames change the design; their rows are measured only "
            "(`projectedStdError` and the calibrate app's report project them for a user's own data).\n\n"
            "| set-up | alpha stated | made | formula | sigma_d^2 stated | made | formula | sigma_r^2 "
            "stated | "
            "made | formula |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    const auto percent = [](double v) { return v > 0 ? cv::format("%.3g%%", 100 * v) : std::string("-"); };
    for (const rawgment_apps::PrecisionRow& p : precision) {
        text << "| " << p.setting;
        for (int k = 0; k < 3; ++k)
            text << " | " << percent(p.stated[k]) << " | " << percent(p.made[k]) << " | "
                 << percent(p.formula[k]);
        text << " |\n";
    }
    return text.str();
}

} // namespace

int main(int argc, char** argv)
{
    const char* keys =
        "{help h usage ? |       | print this message }"
        "{out o          |       | output directory, created; existing outputs are never replaced }"
        "{quick          | false | a small timing frame and short bursts (a smoke run, seconds) }"
        "{seeds          | 32    | simulated calibration campaigns averaged per setting }"
        "{repeats        | 3     | timings keep the fastest of this many runs }"
        "{seed           | 1     | seed of every simulated capture and noise draw }"
        "{plots          | true  | write tradeoffs.png with gnuplot }";
    if (!rawgment_apps::checkCommandLine(argc, argv, keys, "rawgment_tradeoffs"))
        return 2;
    rawgment_apps::installInterruptCleanup();
    CommandLineParser parser(argc, argv, keys);
    parser.about(
        "rawgment_tradeoffs: measures what each accuracy knob of cv::rawgment costs in time.\n"
        "For every setting, an error against the sensor simulator's ground truth and the wall time\n"
        "per megapixel on a 4000x3000 CV_16UC1 mosaic, in one run, on every CPU path this machine has\n"
        "for the augmentation and statistics knobs. Writes tradeoffs.md (the table),\n"
        "tradeoffs.csv and tradeoffs.png (error against time, one panel per knob).");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    const std::string outDir = parser.get<std::string>("out");
    rawgment_apps::TradeoffSettings set;
    set.seeds = parser.get<int>("seeds");
    set.repeats = parser.get<int>("repeats");
    set.seed = rawgment_apps::seedOption(parser, "rawgment_tradeoffs");
    const bool plots = parser.get<bool>("plots");
    if (parser.get<bool>("quick")) {
        set.timingSize = Size(800, 600);
        set.burstLengths = {8, 16};
        set.bankFrames = {4, 8};
        set.seeds = std::min(set.seeds, 2); // two, so that every error has a standard error
        set.repeats = 1;
        set.shapiroSeries = 5000;
    }
    if (!parser.check() || outDir.empty() || set.seeds < 1 || set.repeats < 1) {
        parser.printErrors();
        std::cerr << "usage: rawgment_tradeoffs --out=<dir> [--quick] [--seeds=32] [--repeats=3]\n";
        return 2;
    }
    try {
        rawgment_apps::OutputDirectory outputDirectory(outDir);
        rawgment_apps::prepareOutputDirectory(outDir);
        const std::string md = outDir + "/tradeoffs.md", csv = outDir + "/tradeoffs.csv",
                          png = outDir + "/tradeoffs.png";
        for (const std::string& p : {md, csv, png, png + ".gp"})
            if (rawgment_apps::pathExists(p))
                throw std::runtime_error("'" + p + "' already exists; outputs are never overwritten");

        rawgment_apps::ProgressBar progress("tradeoffs", 7 + 9 * static_cast<size_t>(set.seeds));
        std::vector<rawgment_apps::TradeoffRow> rows;
        std::vector<rawgment_apps::PrecisionRow> precision;
        rawgment_apps::measureTradeoffs(set, progress, rows, precision);
        progress.finish();

        const rawgment_apps::CsvTable table = tradeoffTable(rows);
        const std::string text = tradeoffMarkdown(rows, precision, set, parser.get<bool>("quick"));
        rawgment_apps::writeTextAtomically(md, text);
        table.write(csv);
        const std::string script = tradeoffPlotScript(rows);
        std::cout << text;
        if (plots) {
            std::string message;
            if (rawgment_apps::plotWithGnuplot(png, script, message, 1800, 1700))
                std::cout << "plot: " << png << "\n";
            else
                std::cout << "note: " << message << "\n";
        }
        std::cout << "table: " << md << "\n";
        outputDirectory.keep();
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_tradeoffs: " << e.what() << "\n";
        return 1;
    }
}
