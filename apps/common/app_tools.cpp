// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "app_tools.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <spawn.h>
#include <sstream>
#include <stdexcept>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>
#include <utility>

namespace rawgment_apps {

namespace {

void removeTemporariesAndStop(int signal)
{
    cv::rawgment::removeTemporaryFilesInProgress();
    ::signal(signal, SIG_DFL);
    ::raise(signal);
}

} // namespace

void installInterruptCleanup()
{
    struct sigaction action;
    std::memset(&action, 0, sizeof action);
    action.sa_handler = removeTemporariesAndStop;
    sigemptyset(&action.sa_mask);
    for (int signal : {SIGINT, SIGTERM, SIGHUP})
        if (::sigaction(signal, &action, nullptr) != 0)
            std::cerr << "warning: cannot install the cleanup on signal " << signal << "\n";
    // A file-size limit (ulimit -f) killed the run with SIGXFSZ, no message and a temporary left; ignored,
    // write() fails with EFBIG instead, which the atomic writer reports naming the file, as a full disk.
    if (::signal(SIGXFSZ, SIG_IGN) == SIG_ERR)
        std::cerr << "warning: cannot ignore SIGXFSZ\n";
    std::atexit(reportRemovedTemporaries);
}

uint64_t seedOption(const cv::CommandLineParser& parser, const char* app)
{
    try {
        return parseSeed(parser.get<std::string>("seed"));
    } catch (const std::invalid_argument& e) {
        std::cerr << app << ": " << e.what() << "\n";
        std::exit(2);
    }
}

OutputDirectory::OutputDirectory(std::string path) : path_(std::move(path)), existed_(pathExists(path_)) {}

OutputDirectory::~OutputDirectory()
{
    if (!kept_ && !existed_ && !path_.empty())
        ::rmdir(path_.c_str()); // fails, as it should, when the run left anything inside
}

bool checkCommandLine(int argc, char** argv, const char* keys, const char* app)
{
    struct Option
    {
        std::vector<std::string> names;
        std::string value;
        bool flag; // takes no value (help, or a true/false default)
    };
    const auto trim = [](std::string s) {
        const size_t b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
        return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
    };
    std::vector<Option> options;
    const std::string text(keys);
    for (size_t open = text.find('{'); open != std::string::npos; open = text.find('{', open + 1)) {
        const size_t bar1 = text.find('|', open), bar2 = text.find('|', bar1 + 1);
        if (bar1 == std::string::npos || bar2 == std::string::npos)
            break;
        Option o;
        std::stringstream names(text.substr(open + 1, bar1 - open - 1));
        for (std::string n; names >> n;)
            o.names.push_back(n);
        o.value = trim(text.substr(bar1 + 1, bar2 - bar1 - 1));
        const bool help = std::find(o.names.begin(), o.names.end(), "help") != o.names.end();
        o.flag = help || o.value == "true" || o.value == "false";
        if (!o.names.empty() && o.names.front()[0] != '@')
            options.push_back(o);
    }
    const auto fail = [&](const std::string& why) {
        std::string valid;
        for (const Option& o : options)
            valid += (valid.empty() ? "--" : ", --") + o.names.front();
        std::cerr << app << ": " << why << " (valid options: " << valid << "; see --help)\n";
        return false;
    };
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg.size() < 2 || arg[0] != '-')
            continue;
        const std::string body = arg.substr(arg[1] == '-' ? 2 : 1);
        const size_t eq = body.find('=');
        const std::string name = body.substr(0, eq);
        const auto it = std::find_if(options.begin(), options.end(), [&](const Option& o) {
            return std::find(o.names.begin(), o.names.end(), name) != o.names.end();
        });
        if (it == options.end())
            return fail("unknown option '" + arg + "'");
        if (eq == std::string::npos) {
            if (!it->flag)
                return fail("option '--" + name + "' needs a value: --" + name + "=<value>");
            continue;
        }
        const std::string value = body.substr(eq + 1);
        if (it->flag && !it->names.empty() && it->names.front() == "help")
            return fail("option '--help' takes no value");
        if (it->flag && value != "true" && value != "false")
            return fail("option '--" + name + "' is true or false (got '" + value + "')");
        char* end = nullptr;
        const bool numericDefault =
            !it->value.empty() && (std::strtod(it->value.c_str(), &end), *end == '\0');
        if (numericDefault) {
            std::strtod(value.c_str(), &end);
            if (value.empty() || *end != '\0')
                return fail("option '--" + name + "': '" + value + "' is not a number");
        }
    }
    return true;
}

std::vector<double> parseNumberList(const std::string& text)
{
    std::vector<double> values;
    std::stringstream items(text);
    std::string item;
    while (std::getline(items, item, ',')) {
        char* end = nullptr;
        const double v = std::strtod(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !std::isfinite(v))
            throw std::invalid_argument("'" + item + "' in '" + text + "' is not a number");
        values.push_back(v);
    }
    if (values.empty())
        throw std::invalid_argument("the list '" + text + "' is empty");
    return values;
}

ProgressBar::ProgressBar(std::string label, size_t total)
    : label_(std::move(label)), total_(total), interactive_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()), lastDraw_(start_)
{
}

void ProgressBar::advance(size_t steps)
{
    std::lock_guard<std::mutex> lock(mutex_);
    done_ += steps;
    const auto now = std::chrono::steady_clock::now();
    if (interactive_ && (now - lastDraw_ > std::chrono::milliseconds(100) || done_ == total_)) {
        lastDraw_ = now;
        draw(false);
    }
}

void ProgressBar::finish()
{
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_)
        return;
    finished_ = true;
    draw(true);
}

void ProgressBar::draw(bool final)
{
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double fraction = total_ ? double(done_) / double(total_) : 1.0;
    const int width = 30, filled = static_cast<int>(fraction * width + 0.5);
    std::string bar(size_t(filled), '#');
    bar.resize(width, '.');
    const double eta = fraction > 0 ? seconds * (1 - fraction) / fraction : 0;
    std::fprintf(stderr, "%s%s [%s] %zu/%zu  %.1f s%s", interactive_ ? "\r" : "", label_.c_str(), bar.c_str(),
                 done_, total_, final ? seconds : eta, final ? " total\n" : " left ");
    std::fflush(stderr);
}

CsvTable::CsvTable(std::vector<std::string> header) : header_(std::move(header)) {}

void CsvTable::addRow(const std::vector<std::string>& cells)
{
    if (cells.size() != header_.size())
        throw std::logic_error("CSV row has " + std::to_string(cells.size()) + " cells for " +
                               std::to_string(header_.size()) + " columns");
    std::string line;
    for (size_t i = 0; i < cells.size(); ++i)
        line += (i ? "," : "") + cells[i];
    rows_.push_back(line);
}

void CsvTable::addRow(const std::vector<double>& values)
{
    std::vector<std::string> cells;
    for (double v : values)
        cells.push_back(formatNumber(v));
    addRow(cells);
}

void CsvTable::write(const std::string& path) const
{
    std::string text;
    for (size_t i = 0; i < header_.size(); ++i)
        text += (i ? "," : "") + header_[i];
    text += "\n";
    for (const std::string& row : rows_)
        text += row + "\n";
    writeNewText(path, text);
}

std::string formatNumber(double value)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.10g", value);
    return buf;
}

bool gnuplotAvailable()
{
    return std::system("gnuplot --version > /dev/null 2>&1") == 0;
}

namespace {

/** gnuplot on one script, its standard output collected: started without a shell (posix_spawnp with
 * the script as its one argument), so no byte of a path is ever read as a command. Returns gnuplot's
 * exit status, or -1 when it could not be started. */
int runGnuplot(const std::string& script, std::vector<char>& out)
{
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0)
        return -1;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    std::string program = "gnuplot", argument = script;
    char* argv[] = {program.data(), argument.data(), nullptr};
    pid_t pid = -1;
    const int spawned = ::posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    if (spawned != 0) {
        ::close(fds[0]);
        return -1;
    }
    char buf[65536];
    for (;;) {
        const ssize_t n = ::read(fds[0], buf, sizeof buf);
        if (n > 0)
            out.insert(out.end(), buf, buf + n);
        else if (n == 0 || errno != EINTR)
            break;
    }
    ::close(fds[0]);
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

} // namespace

std::string gnuplotString(const std::string& text)
{
    std::string literal = "\"";
    for (const unsigned char c : text) {
        if (std::isalnum(c) || c == '.' || c == '_' || c == '/' || c == '-')
            literal += static_cast<char>(c);
        else
            literal += cv::format("\\%03o", c);
    }
    return literal + "\"";
}

bool plotWithGnuplot(const std::string& pngPath, const std::string& scriptBody, std::string& message,
                     int width, int height)
{
    const std::string scriptPath = pngPath + ".gp";
    const std::string preamble = "set terminal pngcairo size " + std::to_string(width) + "," +
                                 std::to_string(height) +
                                 " enhanced font 'DejaVu Sans,11'\n"
                                 "set datafile separator ','\n";
    // The saved script writes the PNG itself, so that a user can re-run it as it is; the run writes
    // to standard output, and the PNG reaches its name through the one atomic writer.
    writeTextAtomically(scriptPath, preamble + "set output " + gnuplotString(pngPath) + "\n" + scriptBody +
                                        "\nunset output\n");
    if (!gnuplotAvailable()) {
        message =
            "gnuplot is not installed (apt-get install gnuplot-nox); plot with: gnuplot '" + scriptPath + "'";
        return false;
    }
    // The script gnuplot runs lives in memory (a memfd, which gnuplot opens as /dev/fd/N): a run stopped
    // by a signal or killed leaves nothing of it behind. Without memfd (kernels before 3.17), a file
    // "<plot>.gp.<pid>.run" that the next run in the folder removes once this process is gone.
    const std::string runBody = preamble + scriptBody + "\n";
    std::string runScript;
    const int memfd = static_cast<int>(::syscall(SYS_memfd_create, "rawgment-plot", 0));
    if (memfd >= 0 &&
        ::write(memfd, runBody.data(), runBody.size()) == static_cast<ssize_t>(runBody.size())) {
        runScript = "/dev/fd/" + std::to_string(memfd);
    } else {
        runScript = scriptPath + "." + std::to_string(::getpid()) + ".run";
        writeTextAtomically(runScript, runBody);
    }
    std::vector<char> png;
    const int status = runGnuplot(runScript, png);
    if (memfd >= 0)
        ::close(memfd);
    if (runScript.compare(0, 8, "/dev/fd/") != 0)
        std::remove(runScript.c_str());
    if (status != 0 || png.empty()) {
        message = "gnuplot failed on '" + scriptPath + "' (its messages are above)";
        return false;
    }
    writeBytesAtomically(pngPath, png.data(), png.size());
    message.clear();
    return true;
}

} // namespace rawgment_apps
