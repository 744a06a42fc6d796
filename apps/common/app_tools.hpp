// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What the apps share and the library must not hold (docs/architecture.md): progress, command-line
// lists, CSV and plots; files go through the pipeline layer (output_files.hpp) and so through the
// library's writeFileAtomically().
#ifndef RAWGMENT_APPS_APP_TOOLS_HPP
#define RAWGMENT_APPS_APP_TOOLS_HPP

#include "augment_command_line.hpp"
#include "output_files.hpp"

#include <opencv2/core.hpp>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

namespace rawgment_apps {

// The pipeline layer's files (paths, output folders, writes that never replace) are the apps' too, and so is
// its command-line rules: parseSeed() (one --seed rule for every app and rawgment.batch; a negative seed used
// to wrap to 2^64 - 1 here and raise in Python) and the written containers' names.
using namespace rawgment_pipeline;

//! parseSeed() of a command line's --seed; prints "<app>: <why>" and exits with status 2 when it is bad.
uint64_t seedOption(const cv::CommandLineParser& parser, const char* app);

/** The output directory of one run: removed at the end of a run that created it and failed before
 * writing anything into it (an empty folder is no result). Call keep() when the run succeeded. */
class OutputDirectory
{
public:
    explicit OutputDirectory(std::string path);
    ~OutputDirectory();
    OutputDirectory(const OutputDirectory&) = delete;
    OutputDirectory& operator=(const OutputDirectory&) = delete;
    void keep() { kept_ = true; }

private:
    std::string path_;
    bool existed_, kept_ = false;
};

/** On SIGINT, SIGTERM or SIGHUP, removes the temporaries of the writes in progress, then ends the
 * process as the signal would have. */
void installInterruptCleanup();

/** What cv::CommandLineParser lets through: an option that `keys` does not name, a valued option
 * without `=<value>` (`--model m.yml` would read "true"), a number option whose value is not a number.
 * Prints the first problem, naming the option and the valid ones, to stderr and returns false. */
bool checkCommandLine(int argc, char** argv, const char* keys, const char* app);

//! Comma-separated numbers ("0,6,12"); throws std::invalid_argument naming the bad item.
std::vector<double> parseNumberList(const std::string& text);

/** A one-line progress bar on stderr, safe to advance from several threads. Prints nothing when
 * stderr is not a terminal, except a final summary line. */
class ProgressBar
{
public:
    ProgressBar(std::string label, size_t total);
    void advance(size_t steps = 1);
    void finish();

private:
    void draw(bool final);
    std::string label_;
    size_t total_, done_ = 0;
    bool interactive_, finished_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, lastDraw_;
};

/** A CSV table written atomically and never over another file (see writeNewText()): a header, then
 * rows of numbers or text. */
class CsvTable
{
public:
    explicit CsvTable(std::vector<std::string> header);
    void addRow(const std::vector<std::string>& cells);
    void addRow(const std::vector<double>& values);
    void write(const std::string& path) const;
    size_t rows() const { return rows_.size(); }

private:
    std::vector<std::string> header_;
    std::vector<std::string> rows_;
};

//! Formats a number for CSV and reports with enough digits to round-trip a double.
std::string formatNumber(double value);

/** Runs gnuplot on a script (written beside the PNG as `<png>.gp`) that must set its output to the
 * PNG's path. Returns false and explains how to plot by hand when gnuplot is missing or fails; the
 * data files stay either way. The PNG appears atomically (gnuplot writes a temporary, then rename).
 * The canvas is `width` x `height` pixels. */
bool plotWithGnuplot(const std::string& pngPath, const std::string& scriptBody, std::string& message,
                     int width = 1100, int height = 750);

//! Whether gnuplot can be run.
bool gnuplotAvailable();

/** A gnuplot string literal holding `text` exactly, for every path or name a script mentions. Scripts
 * never splice a user's string between quotes: gnuplot runs backquoted commands inside double quotes and
 * a quote in a path would end a single-quoted string, so every byte but letters, digits and `._/-` is
 * written as an octal escape, and the literal holds no character gnuplot could act on. */
std::string gnuplotString(const std::string& text);

} // namespace rawgment_apps

#endif // RAWGMENT_APPS_APP_TOOLS_HPP
