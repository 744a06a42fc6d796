// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A mutation fuzzer for every file reader of the module and the apps: it mutates valid files (made by
// the module's own writers, plus the files of a corpus folder) for a bounded time and fails on anything
// but a clean rejection: a crash or a sanitizer report (the process dies), an exception other than the
// reader's documented one, an accepted file that breaks the reader's promises, or an input that takes
// longer than a stated time. The allocation cap is the sanitizer's (max_allocation_size_mb, set by the
// test). Deterministic: a seed and an iteration number name an input; --replay reads one file.
#include "differential.hpp"
#include "fuzz_target.hpp"

#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>

#include <cxxabi.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <typeinfo>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/common_interface_defs.h>
#endif

namespace rawgment_fuzz {

std::string readBytes(const std::string& path)
{
    std::ifstream f(path, std::ios::binary);
    if (!f)
        throw std::runtime_error("cannot read '" + path + "'");
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

} // namespace rawgment_fuzz

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------------
// Files.

using rawgment_fuzz::readBytes;

void writeBytes(const std::string& path, const std::string& bytes)
{
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(bytes.data(), std::streamsize(bytes.size()));
    f.close();
    if (!f)
        throw std::runtime_error("cannot write '" + path + "'");
}

using rawgment_fuzz::Errors;
using rawgment_fuzz::Target;

//! The YAML and JSON targets (by their input's extension), whose accepted inputs an independent parse must
//! agree with.
bool checkedDifferentially(const Target& t)
{
    const size_t dot = t.inputName.find_last_of('.');
    const std::string ext = dot == std::string::npos ? std::string() : t.inputName.substr(dot);
    return ext == ".yml" || ext == ".yaml" || ext == ".json";
}

// ---------------------------------------------------------------------------------------------------
// Mutations.

const std::vector<std::string>& textDictionary()
{
    static const std::vector<std::string> words = {"0",
                                                   "-0",
                                                   "1",
                                                   "-1",
                                                   "2",
                                                   "3",
                                                   "7",
                                                   "1.5",
                                                   "-2.5",
                                                   "1e308",
                                                   "-1e308",
                                                   "1e-320",
                                                   "4.9e-324",
                                                   "nan",
                                                   ".nan",
                                                   ".NaN",
                                                   "inf",
                                                   ".inf",
                                                   "-.inf",
                                                   "Infinity",
                                                   "4294967297",
                                                   "2147483647",
                                                   "-2147483648",
                                                   "2147483648",
                                                   "65535",
                                                   "65536",
                                                   "1048577",
                                                   "46341",
                                                   "1e9",
                                                   "~",
                                                   "null",
                                                   "true",
                                                   "\"\"",
                                                   "\"x\"",
                                                   "[]",
                                                   "{}",
                                                   "[ 1, 2 ]",
                                                   "[ [ 1 ] ]",
                                                   "{ a: 1 }",
                                                   "!!opencv-matrix",
                                                   "rows",
                                                   "cols",
                                                   "dt",
                                                   "data",
                                                   "d",
                                                   "f",
                                                   "u",
                                                   "i",
                                                   "format_version",
                                                   "version",
                                                   "%YAML:1.0",
                                                   "---",
                                                   ":",
                                                   "- ",
                                                   ",",
                                                   "\n",
                                                   "'"};
    return words;
}

bool isTokenChar(char c)
{
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-' || c == '+';
}

class Mutator
{
public:
    Mutator(uint64_t seed, bool binary) : rng_(seed), binary_(binary) {}

    std::string mutate(std::string data, const std::vector<std::string>& corpus)
    {
        const int count = 1 + int(below(4));
        for (int k = 0; k < count; ++k)
            data = mutateOnce(std::move(data), corpus);
        return data;
    }

private:
    uint64_t below(uint64_t n) { return n == 0 ? 0 : rng_() % n; }

    std::string mutateOnce(std::string d, const std::vector<std::string>& corpus)
    {
        if (d.empty())
            return binary_ ? std::string(1, char(below(256)))
                           : textDictionary()[below(textDictionary().size())];
        // Binary files: most mutations go to the first 4 KiB, where RAW containers keep their headers and
        // directories; pixel data past them only changes pixel values.
        const size_t pos =
            binary_ && below(4) != 0 ? below(std::min<size_t>(d.size(), 4096)) : below(d.size());
        switch (below(binary_ ? 8 : 10)) {
        case 0: // flip a bit
            d[pos] = char(d[pos] ^ (1 << below(8)));
            break;
        case 1: // a random or boundary byte
        {
            static const unsigned char edge[] = {0, 1, 0x7f, 0x80, 0xff, ' ', '\n', '"', '[', '{'};
            d[pos] = below(2) ? char(below(256)) : char(edge[below(sizeof edge)]);
            break;
        }
        case 2: // delete a range
            d.erase(pos, 1 + below(std::min<uint64_t>(64, d.size() - pos)));
            break;
        case 3: // duplicate a range elsewhere
        {
            const std::string piece = d.substr(pos, 1 + below(64));
            d.insert(below(d.size() + 1), piece);
            break;
        }
        case 4: // truncate
            d.resize(pos);
            break;
        case 5: // splice with another corpus entry
        {
            const std::string& other = corpus[below(corpus.size())];
            if (!other.empty())
                d = d.substr(0, pos) + other.substr(below(other.size()));
            break;
        }
        case 6: // binary: a boundary integer of 1, 2 or 4 bytes at any offset (sizes, offsets, counts)
        case 7: {
            if (!binary_) {
                d.insert(pos, textDictionary()[below(textDictionary().size())]);
                break;
            }
            static const uint32_t values[] = {
                0,           1,           2,           0x7f,       0x80,    0xff,
                0x100,       0x7fff,      0x8000,      0xffff,     0x10000, 0x7fffffff,
                0x80000000u, 0xffffffffu, 0xfffffffeu, 0x40000000, 0x1000,  3};
            const uint32_t v = values[below(sizeof values / sizeof values[0])];
            const int width = 1 << below(3);
            const bool bigEndian = below(2) == 1;
            for (int b = 0; b < width && pos + size_t(b) < d.size(); ++b) {
                const int shift = 8 * (bigEndian ? width - 1 - b : b);
                d[pos + size_t(b)] = char((v >> shift) & 0xff);
            }
            break;
        }
        case 8: // text: replace a token by a dictionary word or a token of the same file
        {
            size_t start = pos;
            while (start > 0 && isTokenChar(d[start - 1]))
                --start;
            size_t end = pos;
            while (end < d.size() && isTokenChar(d[end]))
                ++end;
            std::string word;
            if (below(3) == 0) {
                const size_t at = below(d.size());
                size_t a = at, b = at;
                while (a > 0 && isTokenChar(d[a - 1]))
                    --a;
                while (b < d.size() && isTokenChar(d[b]))
                    ++b;
                word = d.substr(a, b - a);
            } else {
                word = textDictionary()[below(textDictionary().size())];
            }
            d.replace(start, end - start, word);
            break;
        }
        default: // text: duplicate, drop or move a whole line
        {
            const size_t before = d.rfind('\n', pos);
            const size_t lineStart = before == std::string::npos ? 0 : before + 1;
            const size_t after = d.find('\n', pos);
            const size_t lineEnd = after == std::string::npos ? d.size() : after + 1;
            const std::string line = d.substr(lineStart, lineEnd - lineStart);
            const int what = int(below(3)); // 0: duplicate, 1: drop, 2: move
            if (what != 0)
                d.erase(lineStart, lineEnd - lineStart);
            if (what != 1) {
                const size_t next = d.find('\n', below(d.size() + 1));
                d.insert(next == std::string::npos ? d.size() : next + 1, line);
            }
            break;
        }
        }
        return d;
    }

    std::mt19937_64 rng_;
    bool binary_;
};

// ---------------------------------------------------------------------------------------------------
// Running.

char g_inputPath[4096];
unsigned g_inputSeconds = 20;

void reportHang(int)
{
    static const char a[] = "\nrawgment_fuzz: FAIL: one input took longer than the per-input limit; it is "
                            "kept at ";
    ssize_t ignored = ::write(2, a, sizeof a - 1);
    ignored = ::write(2, g_inputPath, std::strlen(g_inputPath));
    ignored = ::write(2, "\n", 1);
    (void)ignored;
    _exit(3);
}

#if defined(__SANITIZE_ADDRESS__)
void reportDeath()
{
    std::fprintf(stderr, "\nrawgment_fuzz: FAIL: the process died reading the input kept at %s\n",
                 g_inputPath);
}
#endif

std::string typeName(const std::type_info& type)
{
    int status = 0;
    char* name = abi::__cxa_demangle(type.name(), nullptr, nullptr, &status);
    const std::string out = status == 0 && name ? name : type.name();
    std::free(name);
    return out;
}

//! The message of a rejection with the digits and paths blurred: distinct messages stand for distinct
//! checks reached, which is what makes an input worth keeping as a new seed.
std::string errorClass(const std::string& message)
{
    std::string out;
    bool inQuote = false;
    for (char c : message) {
        if (c == '\'') {
            inQuote = !inQuote;
            out += c;
            continue;
        }
        if (inQuote)
            continue;
        out += (c >= '0' && c <= '9') ? '#' : c;
    }
    return out.substr(0, 160);
}

enum class Outcome
{
    ACCEPTED,
    REJECTED,
    FAILED
};

Outcome runOne(const Target& target, const std::string& input, std::string& detail)
{
    try {
        detail = target.read(input);
        return detail.empty() ? Outcome::ACCEPTED : Outcome::FAILED;
    } catch (const cv::Exception& e) {
        // OpenCV's persistence code says what went wrong in its own terms ("parseSeq", "skipSpaces"): its
        // exception must never reach a caller unwrapped.
        if (e.file.find("persistence") != std::string::npos) {
            detail = "a cv::Exception of OpenCV's persistence code (" + e.func + ", " + e.file +
                     ") reached the caller unwrapped: " + e.err;
            return Outcome::FAILED;
        }
        detail = e.err;
        return Outcome::REJECTED;
    } catch (const std::exception& e) {
        if (target.errors == Errors::APP && typeid(e) == typeid(std::runtime_error)) {
            detail = e.what();
            return Outcome::REJECTED;
        }
        detail = "threw " + typeName(typeid(e)) + " (" + e.what() + "), not " +
                 (target.errors == Errors::APP ? "cv::Exception or std::runtime_error" : "cv::Exception");
        return Outcome::FAILED;
    } catch (...) {
        detail = "threw something that is not a std::exception";
        return Outcome::FAILED;
    }
}

struct Options
{
    std::string target, work, corpus, dataDir, replay;
    bool verbose = false;
    double seconds = 20;
    long long iterations = -1;
    uint64_t seed = 1;
};

void usage()
{
    std::cout
        << "rawgment_fuzz: mutates valid files and feeds them to one reader of cv::rawgment.\n"
           "  --target=NAME      model, report, policy, scene, sidecar, chart_patches, manifest, emva1288,\n"
           "                     emva1288_image,\n"
           "                     validation_manifest, raw (canary: a planted bug)\n"
           "  --work=DIR         scratch folder (created; the input being read is kept there)\n"
           "  --seconds=S        time budget (default 20)\n"
           "  --iterations=N     stop after N inputs instead (for replaying a seed's sequence)\n"
           "  --seed=N           mutation seed (default 1): seed and iteration name an input\n"
           "  --corpus=DIR       more seeds: every file of DIR (regression inputs)\n"
           "  --data=DIR         camera RAW files for the raw target's seeds, when present\n"
           "  --input-seconds=S  longest time one input may take (default 20)\n"
           "  --verbose=1        print each new kind of outcome (what the reader said)\n"
           "  --replay=FILE      read FILE once with the target's reader and report (a sidecar\n"
           "                     must sit beside its mosaic, as in the work folder)\n"
           "Exit 0: every input was rejected with the documented exception or accepted intact.\n";
}

bool parse(int argc, char** argv, Options& o)
{
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const size_t eq = a.find('=');
        const std::string key = a.substr(0, eq), value = eq == std::string::npos ? "" : a.substr(eq + 1);
        if (key == "--help" || key == "-h") {
            usage();
            std::exit(0);
        }
        if (eq == std::string::npos) {
            std::cerr << "rawgment_fuzz: '" << a << "' is not --key=value (see --help)\n";
            return false;
        }
        try {
            if (key == "--target")
                o.target = value;
            else if (key == "--work")
                o.work = value;
            else if (key == "--seconds")
                o.seconds = std::stod(value);
            else if (key == "--iterations")
                o.iterations = std::stoll(value);
            else if (key == "--seed")
                o.seed = std::stoull(value);
            else if (key == "--corpus")
                o.corpus = value;
            else if (key == "--data")
                o.dataDir = value;
            else if (key == "--input-seconds")
                g_inputSeconds = unsigned(std::stoul(value));
            else if (key == "--verbose")
                o.verbose = value != "0";
            else if (key == "--replay")
                o.replay = value;
            else {
                std::cerr << "rawgment_fuzz: unknown option '" << key << "' (see --help)\n";
                return false;
            }
        } catch (const std::exception&) {
            std::cerr << "rawgment_fuzz: '" << value << "' is not a valid value for " << key << "\n";
            return false;
        }
    }
    if (o.target.empty() || (o.work.empty() && o.replay.empty())) {
        std::cerr << "rawgment_fuzz: --target and --work (or --replay) are required (see --help)\n";
        return false;
    }
    return true;
}

int fuzz(const Target& target, const Options& o)
{
    const std::string work = o.work + "/" + target.name;
    fs::remove_all(work);
    fs::create_directories(work);
    std::vector<std::string> corpus = target.seeds(work);
    const size_t generated = corpus.size();
    std::vector<std::string> accepted = corpus;
    if (!o.corpus.empty() && fs::is_directory(o.corpus))
        for (const auto& entry : fs::directory_iterator(o.corpus))
            if (entry.is_regular_file())
                corpus.push_back(readBytes(entry.path().string()));
    const std::string input = work + "/" + target.inputName;
    std::snprintf(g_inputPath, sizeof g_inputPath, "%s", input.c_str());

    // Every seed must be accepted: a reader that rejects its own writer's files tests nothing.
    std::set<std::string> seen;
    for (size_t k = 0; k < generated; ++k) {
        writeBytes(input, corpus[k]);
        std::string detail;
        if (runOne(target, input, detail) != Outcome::ACCEPTED) {
            std::cerr << "rawgment_fuzz: FAIL: " << target.name << " seed " << k
                      << " is not accepted: " << detail << "\n";
            return 1;
        }
    }
    // Every seed and corpus file as it is, before any mutation, passes the differential check too.
    if (checkedDifferentially(target))
        for (size_t k = 0; k < corpus.size(); ++k) {
            writeBytes(input, corpus[k]);
            const std::string why = rawgment_fuzz::differentialCheck(input);
            if (!why.empty()) {
                std::cerr << "rawgment_fuzz: FAIL: " << target.name << " corpus entry " << k
                          << ", differential check: " << why << "\n";
                return 1;
            }
        }
    std::cout << "rawgment_fuzz: " << target.name << ": " << corpus.size() << " seeds (" << generated
              << " made by the writers), budget " << o.seconds << " s, seed " << o.seed
              << "; the input being "
              << "read is always " << input << "\n"
              << std::flush;

    Mutator mutator(o.seed, target.binary);
    const auto start = std::chrono::steady_clock::now();
    long long iteration = 0, acceptedCount = 0, rejectedCount = 0;
    const size_t maxCorpus = 400;
    for (;; ++iteration) {
        if (o.iterations >= 0
                ? iteration >= o.iterations
                : std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >=
                      o.seconds)
            break;
        // Half the inputs start from a file the reader accepts (a seed or an accepted mutant), so that
        // mutations reach the checks behind the parser; the rest from any kept input.
        const std::vector<std::string>& pool = iteration % 2 == 0 ? accepted : corpus;
        const std::string data = mutator.mutate(pool[size_t(iteration / 2) % pool.size()], corpus);
        writeBytes(input, data);
        std::string detail;
        ::alarm(g_inputSeconds);
        Outcome outcome = runOne(target, input, detail);
        if (outcome != Outcome::FAILED && checkedDifferentially(target)) {
            const std::string why = rawgment_fuzz::differentialCheck(input);
            if (!why.empty()) {
                detail = "differential check: " + why;
                outcome = Outcome::FAILED;
            }
        }
        ::alarm(0);
        if (outcome == Outcome::FAILED) {
            const std::string kept = work + "/failure_" + target.inputName;
            writeBytes(kept, data);
            std::cerr << "rawgment_fuzz: FAIL: " << target.name << ", seed " << o.seed << ", iteration "
                      << iteration << ": " << detail << "\n  the input is kept at " << kept << "\n";
            return 1;
        }
        (outcome == Outcome::ACCEPTED ? acceptedCount : rejectedCount) += 1;
        const std::string key = outcome == Outcome::ACCEPTED ? std::string("accepted") : errorClass(detail);
        const bool novel = seen.insert(key).second;
        if (novel && o.verbose)
            std::cout << "  new outcome at iteration " << iteration << ": " << key << "\n";
        if ((novel || outcome == Outcome::ACCEPTED) && corpus.size() < maxCorpus)
            corpus.push_back(data);
        if (outcome == Outcome::ACCEPTED && accepted.size() < maxCorpus)
            accepted.push_back(data);
    }
    std::cout << "rawgment_fuzz: " << target.name << ": PASS, " << iteration << " inputs (" << acceptedCount
              << " accepted, " << rejectedCount << " rejected with " << seen.size()
              << " distinct outcomes), corpus grew to " << corpus.size() << "\n";
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    Options o;
    if (!parse(argc, argv, o))
        return 2;
    // The readers' own diagnostics would drown the summary.
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
    const std::vector<Target> all = rawgment_fuzz::readerTargets(o.dataDir);
    const auto it = std::find_if(all.begin(), all.end(), [&](const Target& t) { return t.name == o.target; });
    if (it == all.end()) {
        std::cerr << "rawgment_fuzz: unknown target '" << o.target << "' (see --help)\n";
        return 2;
    }
    ::signal(SIGALRM, reportHang);
#if defined(__SANITIZE_ADDRESS__)
    __sanitizer_set_death_callback(reportDeath);
#endif
    if (!o.replay.empty()) {
        std::snprintf(g_inputPath, sizeof g_inputPath, "%s", o.replay.c_str());
        std::string detail;
        const Outcome outcome = runOne(*it, o.replay, detail);
        std::cout << (outcome == Outcome::ACCEPTED   ? "accepted"
                      : outcome == Outcome::REJECTED ? "rejected: "
                                                     : "FAIL: ")
                  << detail << "\n";
        return outcome == Outcome::FAILED ? 1 : 0;
    }
    try {
        return fuzz(*it, o);
    } catch (const std::exception& e) {
        std::cerr << "rawgment_fuzz: cannot set up the target: " << e.what() << "\n";
        return 1;
    }
}
