// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The files topic (files.hpp): the one atomic writer, bounded reads of regular files, and the guarded
// YAML/JSON reader every other topic uses.
#include "precomp.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sstream>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

namespace cv {
namespace rawgment {
namespace detail {

int fileStorageFormatOf(const String& path)
{
    const auto endsWith = [&](const char* ext) {
        const size_t n = std::strlen(ext);
        return path.size() >= n && path.compare(path.size() - n, n, ext) == 0;
    };
    if (endsWith(".yml") || endsWith(".yaml"))
        return FileStorage::FORMAT_YAML;
    if (endsWith(".json"))
        return FileStorage::FORMAT_JSON;
    CV_Error(Error::StsBadArg, "'" + path + "': unsupported extension; expected .yml, .yaml or .json");
}

bool fileExists(const String& path)
{
    return ::access(path.c_str(), F_OK) == 0;
}

namespace {

bool isBlank(char c)
{
    return c == ' ' || c == '\t' || c == '\r';
}

/** The integer literal that starts at `line[i]` (after blanks, an optional sign and digits) when it is
 * a whole scalar: followed by blanks and then the end of the line, a comma, a closing bracket or a
 * comment. Empty otherwise. */
std::string scalarIntegerAt(const std::string& line, size_t i)
{
    while (i < line.size() && isBlank(line[i]))
        ++i;
    const size_t start = i;
    if (i < line.size() && (line[i] == '-' || line[i] == '+'))
        ++i;
    const size_t digits = i;
    while (i < line.size() && line[i] >= '0' && line[i] <= '9')
        ++i;
    if (i == digits)
        return std::string();
    const size_t stop = i;
    while (i < line.size() && isBlank(line[i]))
        ++i;
    if (i < line.size() && line[i] != ',' && line[i] != ']' && line[i] != '}' && line[i] != '#')
        return std::string();
    return line.substr(start, stop - start);
}

bool fitsInt(const std::string& literal)
{
    // More than ten significant digits never fit; fewer are parsed exactly.
    size_t first = literal.find_first_not_of("+-");
    first = literal.find_first_not_of('0', first);
    if (first == std::string::npos)
        return true;
    if (literal.size() - first > 10)
        return false;
    const long long value = std::strtoll(literal.c_str(), nullptr, 10);
    return value >= INT_MIN && value <= INT_MAX;
}

} // namespace

void rejectWrappingIntegers(const String& path, const std::string& text)
{
    // A plain integer scalar follows the start of a line, a block list's dash, a key's colon, or a flow
    // list's or map's bracket or comma. Quoted text is skipped. A hand-written scan, not std::regex,
    // whose recursion overflows the stack on a long line.
    std::istringstream lines(text);
    std::string line;
    for (int number = 1; std::getline(lines, line); ++number) {
        std::string unquoted;
        char quote = 0;
        for (char c : line) {
            if (quote) {
                quote = c == quote ? 0 : quote;
                continue;
            }
            if (c == '"' || c == '\'') {
                quote = c;
                continue;
            }
            unquoted += c;
        }
        std::vector<size_t> starts = {0};
        const size_t firstNonBlank = unquoted.find_first_not_of(" \t");
        if (firstNonBlank != std::string::npos && unquoted[firstNonBlank] == '-')
            starts.push_back(firstNonBlank + 1);
        for (size_t i = 0; i < unquoted.size(); ++i)
            if (unquoted[i] == ':' || unquoted[i] == '[' || unquoted[i] == ',' || unquoted[i] == '{')
                starts.push_back(i + 1);
        for (size_t start : starts) {
            const std::string literal = scalarIntegerAt(unquoted, start);
            if (!literal.empty() && !fitsInt(literal))
                CV_Error(Error::StsParseError,
                         format("'%s' line %d: the integer %s does not fit 32 bits (OpenCV's reader would "
                                "wrap it); write it as a real (%s.0) if that is the value meant",
                                path.c_str(), number, literal.c_str(), literal.c_str()));
        }
    }
}

void rejectUnsupportedStructure(const String& path, const std::string& text)
{
    const size_t first = text.find_first_not_of(" \t\r\n");
    if (first == std::string::npos)
        CV_Error(Error::StsParseError, "'" + path + "' is empty");
    if (text[first] == '<')
        CV_Error(Error::StsParseError, "'" + path + "' looks like XML; this module reads YAML and JSON");
    if (text[first] == '{')
        return; // JSON
    // OpenCV 4.6's YAML parser never returns when a stream goes on after its first document with a '-'
    // that does not start '---' (test/fuzz found three such files, for example "---[][  -"). The files
    // of this module hold one document whose root is a block collection starting a line of its own at
    // column 0, which ends only at the end of the file: anything else is refused before OpenCV sees it.
    std::istringstream lines(text);
    std::string line;
    bool header = false, content = false;
    for (int number = 1; std::getline(lines, line); ++number) {
        const size_t start = line.find_first_not_of(" \r");
        if (start == std::string::npos || line[start] == '#')
            continue;
        const auto refuse = [&](const char* why) {
            CV_Error(Error::StsParseError, format("'%s' line %d: %s (this module reads single-document YAML "
                                                  "files whose root is a block map or list at column 0)",
                                                  path.c_str(), number, why));
        };
        const bool marker = line.compare(start, 3, "---") == 0 || line.compare(start, 3, "...") == 0;
        if (!content) {
            if (line[start] == '%')
                continue;
            if (line.compare(start, 3, "---") == 0 && !header) {
                const size_t rest = line.find_first_not_of(" \r", start + 3);
                if (start != 0 || (rest != std::string::npos && line[rest] != '#'))
                    refuse("content on the document's '---' line");
                header = true;
                continue;
            }
            if (marker)
                refuse("a second document marker");
            if (start != 0)
                refuse("the root collection does not start at column 0");
            if (line[start] == '[' || line[start] == '{')
                refuse("the root is a flow collection");
            content = true;
        }
        // At column 0 only the root's own keys or items: anything else ends the root early, and OpenCV's
        // reader loops forever when a '-' follows (test/fuzz found "!: -.\n{  -").
        const unsigned char lead = static_cast<unsigned char>(line[start]);
        if (start == 0 && !marker && !std::isalnum(lead) && lead != '_' && lead != '"' && lead != '\'' &&
            !(lead == '-' && (line.size() == 1 || line[1] == ' ' || line[1] == '\r')))
            refuse("a line at column 0 that is neither a key nor an item of the root collection");
        if (marker)
            refuse("a document marker after the first document's content");
    }
}

double parseCpuBound(size_t bytes)
{
    // 44 MB of numbers parse in 0.42 s (0.01 s/MB on a 2-core AMD EPYC Zen 4, Release, 2026-11-24): 2 s
    // plus 0.25 s per MB is 25 times that. Sanitizer builds are slower, and AddressSanitizer's
    // strict_string_checks (the test command sets it) makes OpenCV's parse of a long line quadratic:
    // 300 kB on one line took 4.2 s of CPU time there against 7 ms without it; so 30 times as long.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
    const double factor = 30;
#else
    const double factor = 1;
#endif
    return factor * (2 + static_cast<double>(bytes) / (4 << 20));
}

ChildWait waitForChild(int child, double cpuBound, double wallCap, double stallSeconds)
{
    const auto start = std::chrono::steady_clock::now();
    const auto wallSeconds = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    clockid_t childClock;
    const bool haveChildClock = ::clock_getcpuclockid(child, &childClock) == 0;
    // Without the child's clock nothing tells spinning from blocked: wall time stands in for CPU time
    // (so a blocked child counts as spinning) and the stall rule is off.
    const auto cpuSeconds = [&] {
        timespec t;
        if (!haveChildClock)
            return wallSeconds();
        if (::clock_gettime(childClock, &t) != 0)
            return -1.0; // the child has just ended: the next wait sees it
        return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
    };
    // A pidfd becomes readable the moment the child ends, even where SIGCHLD is ignored and waitpid()
    // cannot see it; without one (kernels before 5.3), waitpid() and short naps.
    const int pidfd = static_cast<int>(::syscall(SYS_pidfd_open, child, 0));
    long sleepNs = 20000;
    // A runnable child gets its share of a core within milliseconds, even behind a few busy processes
    // (the scheduler is fair): one that gains less than a millisecond of CPU time in stallSeconds of
    // wall time is asleep, waiting for something that will not come.
    const double progressStep = 1e-3;
    double lastCpu = 0, lastProgress = 0;
    ChildWait outcome = ChildWait::OVERTIME;
    while (wallSeconds() <= wallCap) {
        bool finished = false;
        if (pidfd >= 0) {
            pollfd ready = {pidfd, POLLIN, 0};
            finished = ::poll(&ready, 1, 50) > 0;
        } else {
            int status = 0;
            const pid_t done = ::waitpid(child, &status, WNOHANG);
            // ECHILD: SIGCHLD is ignored and the child reaped itself, so it has ended.
            finished = done == child || (done < 0 && errno == ECHILD);
            const timespec pause = {0, sleepNs};
            if (!finished)
                ::nanosleep(&pause, nullptr);
            sleepNs = std::min(sleepNs * 2, 10000000L);
        }
        if (finished) {
            outcome = ChildWait::FINISHED;
            break;
        }
        const double cpu = cpuSeconds(), now = wallSeconds();
        if (cpu > cpuBound) {
            outcome = ChildWait::SPINNING;
            break;
        }
        if (cpu >= lastCpu + progressStep) {
            lastCpu = cpu;
            lastProgress = now;
        } else if (haveChildClock && cpu >= 0 && now - lastProgress > stallSeconds) {
            outcome = ChildWait::STALLED;
            break;
        }
    }
    if (outcome != ChildWait::FINISHED)
        ::kill(child, SIGKILL);
    int status = 0;
    while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
    }
    if (pidfd >= 0)
        ::close(pidfd);
    return outcome;
}

void requireParseFinishes(const String& path, const std::string& text, double cpuBound)
{
    // OpenCV 4.6's YAML reader never returns when its root collection ends before the text does and
    // what follows starts with a '-' that is not '---' (its document loop then spins, neither advancing
    // nor failing). rejectUnsupportedStructure() refuses the shapes seen so far, but where the root ends
    // depends on the whole parser; so the text is parsed once in a child process, which is killed when
    // it has spun for longer than an honest file needs (parseCpuBound()). CPU time, not wall time: under
    // `ctest -j2` a sanitizer build's child took more than 2 s of wall time for 300 kB while waiting for
    // a core. The child of a multi-threaded caller can block for good on a lock that another thread
    // held at the fork (an AddressSanitizer build's allocator did, in an app whose workers read sidecars
    // in parallel, and the caller waited out the whole wall-time cap): such a child says nothing about
    // the text, so it is killed as soon as it is seen asleep and the caller parses. The child only
    // parses and leaves with _exit(): it runs no atexit handler and touches no file.
    if (!(cpuBound > 0))
        cpuBound = parseCpuBound(text.size());
    const double wallCap = 30 + 10 * cpuBound;
    const pid_t child = ::fork();
    if (child < 0)
        return; // no process to spare (a limit on processes): the text checks alone must do
    if (child == 0) {
        // The caller's SIGALRM handler (if any) is inherited: the default action ends the child.
        ::signal(SIGALRM, SIG_DFL);
        ::alarm(static_cast<unsigned>(wallCap) + 1);
        try {
            FileStorage fs(text, FileStorage::READ | FileStorage::MEMORY);
        } catch (...) {
        }
        ::_exit(0);
    }
    if (waitForChild(child, cpuBound, wallCap, CHILD_STALL_SECONDS) == ChildWait::SPINNING)
        CV_Error(Error::StsParseError,
                 format("'%s': OpenCV's YAML reader spun for %.3g s of CPU time without finishing; the text "
                        "is not a single YAML document of the shape this module reads (a line that ends the "
                        "root collection early, followed by a '-'?)",
                        path.c_str(), cpuBound));
}

std::string readTextFile(const String& path)
{
    return readFileBounded(path, MAX_TEXT_FILE_BYTES, "file");
}

void checkRegularFile(const String& path, const String& what)
{
    struct stat status;
    if (::stat(path.c_str(), &status) != 0)
        CV_Error(Error::StsError, "cannot open " + what + " '" + path +
                                      "': " + (errno == ENOENT ? "no such file" : std::strerror(errno)));
    if (!S_ISREG(status.st_mode))
        CV_Error(Error::StsError,
                 "cannot open " + what + " '" + path + "': " + notRegularReason(status.st_mode));
}

const char* notRegularReason(unsigned mode)
{
    if (S_ISDIR(mode))
        return "it is a directory";
    if (S_ISFIFO(mode))
        return "it is a FIFO (named pipe), not a regular file; only regular files are read";
    if (S_ISCHR(mode) || S_ISBLK(mode))
        return "it is a device, not a regular file; only regular files are read";
    if (S_ISSOCK(mode))
        return "it is a socket, not a regular file; only regular files are read";
    return "it is not a regular file; only regular files are read";
}

} // namespace detail

std::string readFileBounded(const String& path, long long maxBytes, const String& what)
{
    if (path.empty())
        CV_Error(Error::StsBadArg, "cannot open " + what + ": the path is empty");
    if (maxBytes < 0)
        CV_Error(Error::StsBadArg, format("readFileBounded: maxBytes must be >= 0 (got %lld)", maxBytes));
    // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer that may never come; the
    // type is decided on the opened file itself, so nothing can swap it in between.
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0)
        CV_Error(Error::StsError, "cannot open " + what + " '" + path +
                                      "': " + (errno == ENOENT ? "no such file" : std::strerror(errno)));
    struct Closer
    {
        int fd;
        ~Closer() { ::close(fd); }
    } closer{fd};
    struct stat status;
    if (::fstat(fd, &status) != 0)
        CV_Error(Error::StsError, "cannot open " + what + " '" + path + "': " + std::strerror(errno));
    if (!S_ISREG(status.st_mode))
        CV_Error(Error::StsError,
                 "cannot open " + what + " '" + path + "': " + detail::notRegularReason(status.st_mode));
    const auto tooLarge = [&](long long bytes) {
        CV_Error(Error::StsError,
                 format("cannot open %s '%s': %lld bytes, more than the %lld bytes such a file may have",
                        what.c_str(), path.c_str(), bytes, maxBytes));
    };
    if (status.st_size > maxBytes)
        tooLarge(static_cast<long long>(status.st_size));
    // One byte beyond the limit is asked for, so that a file that grew while being read is noticed.
    std::string data(static_cast<size_t>(std::min<long long>(status.st_size, maxBytes)) + 1, '\0');
    size_t got = 0;
    for (;;) {
        if (got == data.size()) {
            if (static_cast<long long>(got) > maxBytes)
                tooLarge(static_cast<long long>(got));
            data.resize(std::min<size_t>(data.size() * 2, static_cast<size_t>(maxBytes) + 1));
        }
        const ssize_t n = ::read(fd, &data[got], data.size() - got);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            CV_Error(Error::StsError, "cannot read " + what + " '" + path + "': " + std::strerror(errno));
        if (n == 0)
            break;
        got += static_cast<size_t>(n);
    }
    data.resize(got);
    return data;
}

void rejectUnknownKeys(const FileNode& map, const std::vector<String>& valid)
{
    if (!map.isMap())
        return;
    std::vector<std::string> seen;
    for (const FileNode& entry : map) {
        const std::string key = entry.name();
        // OpenCV keeps both entries of a repeated key and a lookup finds one: which value counts would be
        // a guess.
        if (std::find(seen.begin(), seen.end(), key) != seen.end())
            CV_Error(Error::StsParseError, format("key '%s' appears twice", key.c_str()));
        seen.push_back(key);
        if (std::none_of(valid.begin(), valid.end(), [&](const String& v) { return key == v; })) {
            std::string list;
            for (const String& v : valid)
                list += (list.empty() ? "" : ", ") + v;
            CV_Error(Error::StsParseError,
                     format("unknown key '%s' (valid keys: %s)", key.c_str(), list.c_str()));
        }
    }
}

FileStorage openFileStorageForReading(const String& path, const String& what)
{
    if (path.empty())
        CV_Error(Error::StsBadArg, "cannot open " + what + ": the path is empty");
    // Read once and parsed from memory: the integer check and OpenCV's parser see the same bytes.
    std::string text = readFileBounded(path, MAX_TEXT_FILE_BYTES, what);
    // A UTF-8 byte-order mark (some Windows editors write one) is not part of the YAML or JSON.
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0)
        text.erase(0, 3);
    detail::rejectUnsupportedStructure(path, text);
    detail::rejectWrappingIntegers(path, text);
    // OpenCV tells YAML from JSON by the first bytes only: JSON must start with its brace, and YAML
    // with a %YAML line, which hand-written files often lack.
    const size_t first = text.find_first_not_of(" \t\r\n");
    const std::string parsed = text[first] == '{'                 ? text.substr(first)
                               : text.compare(0, 5, "%YAML") == 0 ? text
                                                                  : "%YAML:1.0\n" + text;
    detail::requireParseFinishes(path, parsed);
    FileStorage fs;
    try {
        fs.open(parsed, FileStorage::READ | FileStorage::MEMORY);
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError, "'" + path + "' is not a valid YAML or JSON file: " + e.err);
    } catch (const std::exception& e) {
        CV_Error(Error::StsParseError, "'" + path + "' is not a valid YAML or JSON file: " + e.what());
    }
    if (!fs.isOpened())
        CV_Error(Error::StsError, "cannot open " + what + " '" + path + "'");
    return fs;
}

namespace {

// The temporaries of writes in progress, for removeTemporaryFilesInProgress() in a signal handler: a
// fixed table of lock-free slots (0 free, 1 being filled, 2 holds a path), no allocation, no lock.
struct TemporarySlot
{
    std::atomic<int> state{0};
    char path[4096];
};
TemporarySlot temporarySlots[64];

// Registers a temporary for the lifetime of the guard (a path too long or a full table: not registered,
// the write goes on; only a signal's cleanup misses it).
class TemporaryRegistration
{
public:
    explicit TemporaryRegistration(const String& tmp)
    {
        if (tmp.size() >= sizeof(temporarySlots[0].path))
            return;
        for (int i = 0; i < 64; ++i) {
            int expected = 0;
            if (temporarySlots[i].state.compare_exchange_strong(expected, 1)) {
                std::memcpy(temporarySlots[i].path, tmp.c_str(), tmp.size() + 1);
                temporarySlots[i].state.store(2);
                slot_ = i;
                return;
            }
        }
    }
    ~TemporaryRegistration()
    {
        if (slot_ >= 0)
            temporarySlots[slot_].state.store(0);
    }
    TemporaryRegistration(const TemporaryRegistration&) = delete;
    TemporaryRegistration& operator=(const TemporaryRegistration&) = delete;

private:
    int slot_ = -1;
};

String temporaryPathFor(const String& path)
{
    // Unique per process and call, so concurrent writers never share a temporary file.
    static std::atomic<unsigned> counter{0};
    return format("%s.tmp-%d-%u", path.c_str(), static_cast<int>(::getpid()), counter++);
}

// Syncs the directory that holds `path`, so that a rename or link in it survives a power cut. Some
// file systems cannot sync a directory (EINVAL): the file itself is synced already, so that is no error.
void syncDirectoryOf(const String& path)
{
    const size_t slash = path.find_last_of('/');
    const String dir = slash == String::npos ? String(".") : slash == 0 ? String("/") : path.substr(0, slash);
    const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
    if (fd < 0)
        CV_Error(Error::StsError, "cannot open the directory of '" + path + "': " + std::strerror(errno));
    const bool synced = ::fsync(fd) == 0 || errno == EINVAL;
    const int err = errno;
    ::close(fd);
    if (!synced)
        CV_Error(Error::StsError, "cannot sync the directory of '" + path + "': " + std::strerror(err));
}

void commitTemporaryFile(const String& tmpPath, const String& path)
{
    if (std::rename(tmpPath.c_str(), path.c_str()) != 0) {
        const int err = errno;
        std::remove(tmpPath.c_str());
        CV_Error(Error::StsError, "cannot rename '" + tmpPath + "' to '" + path + "': " + std::strerror(err));
    }
}

// Like commitTemporaryFile(), but fails (removing the temporary) when `path` already exists.
void commitTemporaryFileNoReplace(const String& tmpPath, const String& path)
{
    // link() fails with EEXIST instead of replacing, which makes "never overwrite" atomic too.
    if (::link(tmpPath.c_str(), path.c_str()) == 0) {
        std::remove(tmpPath.c_str());
        return;
    }
    const int err = errno;
    if (err == EEXIST) {
        std::remove(tmpPath.c_str());
        CV_Error(Error::StsError, "'" + path + "' already exists; it is never overwritten");
    }
    // Some file systems (FAT, some network mounts) have no hard links: fall back to check-then-rename.
    if (err == EPERM || err == ENOTSUP || err == EXDEV || err == ENOSYS) {
        if (::access(path.c_str(), F_OK) == 0) {
            std::remove(tmpPath.c_str());
            CV_Error(Error::StsError, "'" + path + "' already exists; it is never overwritten");
        }
        commitTemporaryFile(tmpPath, path);
        return;
    }
    std::remove(tmpPath.c_str());
    CV_Error(Error::StsError, "cannot create '" + path + "': " + std::strerror(err));
}

} // namespace

void removeTemporaryFilesInProgress()
{
    for (TemporarySlot& slot : temporarySlots)
        if (slot.state.load() == 2)
            ::unlink(slot.path);
}

void writeFileAtomically(const String& path, const void* data, size_t size, bool replace)
{
    if (path.empty())
        CV_Error(Error::StsBadArg, "writeFileAtomically: the path is empty");
    if (!data && size > 0)
        CV_Error(Error::StsBadArg, "writeFileAtomically: no data for " + std::to_string(size) + " bytes");
    const String tmp = temporaryPathFor(path);
    const TemporaryRegistration registration(tmp);
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f)
        CV_Error(Error::StsError, "cannot open '" + tmp + "' for writing: " + std::strerror(errno));
    const bool written = (size == 0 || std::fwrite(data, 1, size, f) == size) && std::fflush(f) == 0 &&
                         ::fsync(::fileno(f)) == 0;
    const int err = errno;
    if (std::fclose(f) != 0 || !written) {
        const int closeErr = errno;
        std::remove(tmp.c_str());
        CV_Error(Error::StsError, "cannot write '" + path + "': " + std::strerror(written ? closeErr : err) +
                                      " (nothing was replaced)");
    }
    if (replace)
        commitTemporaryFile(tmp, path);
    else
        commitTemporaryFileNoReplace(tmp, path);
    syncDirectoryOf(path);
}

} // namespace rawgment
} // namespace cv
