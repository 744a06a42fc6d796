// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The files topic (files.hpp): the one atomic writer, bounded reads of regular files, and the YAML/JSON
// reader every other topic uses (its text checks are in text_checks.cpp).
#include "precomp.hpp"

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#include <map>
#include <mutex>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <tuple>
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

std::string readTextFile(const String& path)
{
    return readFileBounded(path, MAX_TEXT_FILE_BYTES, "file");
}

String folderOf(const String& path)
{
    const size_t slash = path.find_last_of('/');
    return slash == String::npos ? String() : path.substr(0, slash + 1);
}

void checkRegularFile(const String& path, const String& what)
{
    checkPathHasNoNul(path);
    struct stat status;
    if (::stat(path.c_str(), &status) != 0)
        CV_Error(Error::StsError, "cannot open " + what + " '" + path +
                                      "': " + (errno == ENOENT ? "no such file" : std::strerror(errno)));
    if (!S_ISREG(status.st_mode))
        CV_Error(Error::StsError,
                 "cannot open " + what + " '" + path + "': " + notRegularReason(status.st_mode));
}

RegularFileForReading::RegularFileForReading(const String& path, const String& what)
{
    checkPathHasNoNul(path);
    // O_NONBLOCK: opening a FIFO for reading would otherwise wait for a writer that may never come.
    fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd_ < 0)
        CV_Error(Error::StsError, "cannot open " + what + " '" + path +
                                      "': " + (errno == ENOENT ? "no such file" : std::strerror(errno)));
    struct stat status;
    const bool statted = ::fstat(fd_, &status) == 0;
    const int statError = errno;
    if (!statted || !S_ISREG(status.st_mode)) {
        ::close(fd_);
        CV_Error(Error::StsError,
                 "cannot open " + what + " '" + path +
                     "': " + (statted ? notRegularReason(status.st_mode) : std::strerror(statError)));
    }
    size_ = static_cast<long long>(status.st_size);
}

RegularFileForReading::~RegularFileForReading()
{
    ::close(fd_);
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

void checkPathHasNoNul(const String& path)
{
    const size_t nul = path.find('\0');
    if (nul != String::npos)
        CV_Error(Error::StsBadArg,
                 format("a path holds a NUL character (after '%s'); no file can be named so", path.c_str()));
}

namespace {

/* The code point of the UTF-8 sequence at value[i] (advancing i), or -1 when it is not one: a byte that no
 * sequence starts with, a sequence cut short, an overlong form, a surrogate or a value beyond U+10FFFF. */
long decodeUtf8(const String& value, size_t& i)
{
    const auto byte = [&](size_t k) { return static_cast<unsigned char>(value[k]); };
    const unsigned char lead = byte(i);
    const int length = lead < 0x80                   ? 1
                       : lead >= 0xc2 && lead < 0xe0 ? 2
                       : lead >= 0xe0 && lead < 0xf0 ? 3
                       : lead >= 0xf0 && lead < 0xf5 ? 4
                                                     : 0;
    if (length == 0 || i + length > value.size())
        return -1;
    long code = length == 1 ? lead : lead & (0x7f >> length);
    for (int k = 1; k < length; ++k) {
        if ((byte(i + k) & 0xc0) != 0x80)
            return -1;
        code = (code << 6) | (byte(i + k) & 0x3f);
    }
    static const long smallest[] = {0, 0, 0x80, 0x800, 0x10000};
    if (code < smallest[length] || (code >= 0xd800 && code < 0xe000) || code > 0x10ffff)
        return -1;
    i += static_cast<size_t>(length);
    return code;
}

//! YAML's printable characters (YAML 1.1, 5.1), which libyaml, the check of every file read, demands;
//! but U+0085, a line break to libyaml, which a quoted string gives back as a space.
bool yamlPrintable(long c)
{
    return c == 0x9 || c == 0xa || c == 0xd || (c >= 0x20 && c <= 0x7e) || (c >= 0xa0 && c <= 0xd7ff) ||
           (c >= 0xe000 && c <= 0xfffd) || (c >= 0x10000 && c <= 0x10ffff);
}

} // namespace

void writeString(FileStorage& fs, const String& key, const String& value)
{
    // OpenCV's emitter writes a string that starts and ends with '"' as it is: the escaped form given here
    // is that, and its readers undo exactly these escapes.
    std::string quoted = "\"";
    for (size_t i = 0; i < value.size();) {
        const size_t at = i;
        const long code = decodeUtf8(value, i);
        if (code < 0 || !yamlPrintable(code))
            CV_Error(Error::StsBadArg,
                     format("'%s': the text holds %s at byte %zu, which the module's readers refuse (text is "
                            "UTF-8 without control characters but tab, line feed and carriage return)",
                            key.c_str(), code < 0 ? "a byte that is not UTF-8" : "a control character", at));
        const char c = value[at];
        if (c == '\\' || c == '"')
            quoted += {'\\', c};
        else if (c == '\n')
            quoted += "\\n";
        else if (c == '\t')
            quoted += "\\t";
        else if (c == '\r')
            quoted += "\\r";
        else
            quoted.append(value, at, i - at);
    }
    fs.write(key, quoted + "\"");
}

void writeStringList(FileStorage& fs, const String& key, const std::vector<String>& values)
{
    fs << key << "[";
    for (const String& v : values)
        writeString(fs, String(), v);
    fs << "]";
}

bool pathExists(const String& path)
{
    checkPathHasNoNul(path);
    return ::access(path.c_str(), F_OK) == 0;
}

namespace detail {

bool fileIdentityOf(const String& path, FileIdentity& id)
{
    FileStamp stamp;
    if (!fileStampOf(path, stamp))
        return false;
    id = FileIdentity{stamp.device, stamp.inode};
    return true;
}

namespace {

struct FingerprintKey
{
    unsigned long long device, inode;
    long long size, mtimeNs;
    bool operator<(const FingerprintKey& o) const
    {
        return std::tie(device, inode, size, mtimeNs) < std::tie(o.device, o.inode, o.size, o.mtimeNs);
    }
};

FingerprintKey fingerprintKeyOf(const FileStamp& s)
{
    return FingerprintKey{s.device, s.inode, s.bytes, s.modifiedNs};
}

} // namespace

std::string contentFingerprintOf(const String& path, const String& what)
{
    static std::mutex mutex;
    static std::map<FingerprintKey, std::string> known;
    RegularFileForReading file(path, what);
    FileStamp before;
    if (!fileStampOf(file.fd(), before))
        CV_Error(Error::StsError, "cannot read " + what + " '" + path + "': " + std::strerror(errno));
    const FingerprintKey key = fingerprintKeyOf(before);
    {
        std::lock_guard<std::mutex> lock(mutex);
        const auto hit = known.find(key);
        if (hit != known.end())
            return hit->second;
    }
    uint64_t h = 0xcbf29ce484222325ull;
    std::vector<unsigned char> chunk(1 << 20);
    long long offset = 0;
    for (;;) {
        const ssize_t got = ::pread(file.fd(), chunk.data(), chunk.size(), static_cast<off_t>(offset));
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0)
            CV_Error(Error::StsError, "cannot read " + what + " '" + path + "': " + std::strerror(errno));
        if (got == 0)
            break;
        for (ssize_t i = 0; i < got; ++i) {
            h ^= chunk[static_cast<size_t>(i)];
            h *= 0x100000001b3ull;
        }
        offset += got;
    }
    FileStamp after;
    if (!fileStampOf(file.fd(), after) || offset != key.size || after.modifiedNs != key.mtimeNs)
        CV_Error(Error::StsError, "cannot read " + what + " '" + path + "': it changed while it was read");
    const std::string hex = format("%016llx", static_cast<unsigned long long>(h));
    std::lock_guard<std::mutex> lock(mutex);
    known.emplace(key, hex);
    return hex;
}

} // namespace detail

std::string fileFingerprint(const String& path)
{
    return detail::contentFingerprintOf(path, "file");
}

void refuseRepeatedFiles(const std::vector<String>& paths, const String& what)
{
    std::map<detail::FileIdentity, size_t> seen;
    for (size_t k = 0; k < paths.size(); ++k) {
        detail::FileIdentity id;
        if (!detail::fileIdentityOf(paths[k], id))
            continue;
        const auto first = seen.emplace(id, k);
        if (!first.second)
            CV_Error(Error::StsBadArg,
                     format("%s: entries %zu ('%s') and %zu ('%s') are one file; every entry must be a "
                            "capture of its own",
                            what.c_str(), first.first->second + 1, paths[first.first->second].c_str(), k + 1,
                            paths[k].c_str()));
    }
}

bool isRegularFile(const String& path)
{
    detail::FileStamp stamp;
    return detail::fileStampOf(path, stamp) && stamp.regular();
}

std::string fileStorageText(const String& path, const std::function<void(FileStorage&)>& writeBody)
{
    const int format = detail::fileStorageFormatOf(path);
    FileStorage fs(format == FileStorage::FORMAT_JSON ? ".json" : ".yml",
                   FileStorage::WRITE | FileStorage::MEMORY | format);
    writeBody(fs);
    return fs.releaseAndGetString();
}

std::string readFileBounded(const String& path, long long maxBytes, const String& what)
{
    if (path.empty())
        CV_Error(Error::StsBadArg, "cannot open " + what + ": the path is empty");
    if (maxBytes < 0)
        CV_Error(Error::StsBadArg, format("readFileBounded: maxBytes must be >= 0 (got %lld)", maxBytes));
    const detail::RegularFileForReading file(path, what);
    const int fd = file.fd();
    const auto tooLarge = [&](long long bytes) {
        CV_Error(Error::StsError,
                 format("cannot open %s '%s': %lld bytes, more than the %lld bytes such a file may have",
                        what.c_str(), path.c_str(), bytes, maxBytes));
    };
    if (file.size() > maxBytes)
        tooLarge(file.size());
    // One byte beyond the limit is asked for, so that a file that grew while being read is noticed.
    std::string data(static_cast<size_t>(std::min<long long>(file.size(), maxBytes)) + 1, '\0');
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
    // libyaml or nlohmann-json parses the text, iteratively and with a depth limit, and OpenCV's own writer
    // writes its values anew: OpenCV's recursive parser, which loops forever on some malformed YAML and
    // reads numbers and keys otherwise than YAML does, only ever reads text its writer made.
    const std::string parsed = detail::textForOpenCv(path, readFileBounded(path, MAX_TEXT_FILE_BYTES, what));
    FileStorage fs;
    try {
        fs.open(parsed, FileStorage::READ | FileStorage::MEMORY);
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError,
                 "'" + path + "': OpenCV could not read back the text its own writer made of it: " + e.err);
    } catch (const std::exception& e) {
        CV_Error(Error::StsParseError,
                 "'" + path +
                     "': OpenCV could not read back the text its own writer made of it: " + e.what());
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

// Whether the regular file `path` holds exactly `size` bytes equal to `data`; false when it cannot be read.
bool fileHoldsExactly(const String& path, const void* data, size_t size)
{
    try {
        const std::string existing = readFileBounded(path, static_cast<long long>(size), "file");
        return existing.size() == size && (size == 0 || std::memcmp(existing.data(), data, size) == 0);
    } catch (const Exception&) {
        return false; // larger, unreadable, not a regular file: not these bytes
    }
}

/* Like commitTemporaryFile(), but never replaces `path`: an existing file with the temporary's bytes
 * (`data`, `size`) is kept as this write's output, any other fails the call (removing the temporary). */
void commitTemporaryFileNoReplace(const String& tmpPath, const String& path, const void* data, size_t size)
{
    const auto refuse = [&] {
        std::remove(tmpPath.c_str());
        if (fileHoldsExactly(path, data, size))
            return;
        CV_Error(Error::StsError, "'" + path + "' already exists; it is never overwritten");
    };
    // link() fails with EEXIST instead of replacing, which makes "never overwrite" atomic too.
    if (::link(tmpPath.c_str(), path.c_str()) == 0) {
        std::remove(tmpPath.c_str());
        return;
    }
    const int err = errno;
    if (err == EEXIST)
        return refuse();
    // Some file systems (FAT, some network mounts) have no hard links: fall back to check-then-rename.
    if (err == EPERM || err == ENOTSUP || err == EXDEV || err == ENOSYS) {
        if (::access(path.c_str(), F_OK) == 0)
            return refuse();
        commitTemporaryFile(tmpPath, path);
        return;
    }
    std::remove(tmpPath.c_str());
    CV_Error(Error::StsError, "cannot create '" + path + "': " + std::strerror(err));
}

/* The process that left `entry` as a temporary of a file named `target` in the same folder: the pid of
 * "<target>.tmp-<pid>-<n>" (this writer's) or "<target>.<pid>.run" with a target "<plot>.gp" (a plot's
 * script when the kernel has no memfd); 0 for any other name. */
long temporaryOwnerOf(const String& entry, String& target)
{
    const auto digitsBetween = [&](size_t from, size_t to) {
        return to > from && to - from <= 9 &&
               std::all_of(entry.begin() + from, entry.begin() + to,
                           [](char c) { return c >= '0' && c <= '9'; });
    };
    const size_t tmp = entry.rfind(".tmp-");
    if (tmp != String::npos && tmp > 0) {
        const size_t dash = entry.find('-', tmp + 5);
        if (dash != String::npos && digitsBetween(tmp + 5, dash) && digitsBetween(dash + 1, entry.size())) {
            target = entry.substr(0, tmp);
            return std::stol(entry.substr(tmp + 5, dash - tmp - 5));
        }
    }
    if (entry.size() > 4 && entry.compare(entry.size() - 4, 4, ".run") == 0) {
        const size_t dot = entry.rfind('.', entry.size() - 5);
        if (dot != String::npos && dot >= 3 && entry.compare(dot - 3, 3, ".gp") == 0 &&
            digitsBetween(dot + 1, entry.size() - 4)) {
            target = entry.substr(0, dot);
            return std::stol(entry.substr(dot + 1, entry.size() - 5 - dot));
        }
    }
    return 0;
}

/* The temporaries that killed writers left, by folder. A folder is listed again only when its mtime is not
 * the one this process's own last write left: a folder of 100 000 outputs costs one listing, not one per
 * output, and a temporary another process leaves later (a killed run beside a long-lived Python process)
 * is still seen. */
struct FolderListing
{
    timespec mtime{};
    std::multimap<String, std::pair<String, long>> temporaries; // target -> (entry, pid)
};
struct StaleTemporaries
{
    std::mutex mutex;
    std::map<String, FolderListing> byFolder;
    std::vector<String> removed;
};
StaleTemporaries& staleTemporaries()
{
    static StaleTemporaries* stale = new StaleTemporaries; // never destroyed: writes may run at exit
    return *stale;
}

String folderOf(const String& path)
{
    const size_t slash = path.find_last_of('/');
    return slash == String::npos ? String(".") : slash == 0 ? String("/") : path.substr(0, slash);
}

bool sameTime(const timespec& a, const timespec& b)
{
    return a.tv_sec == b.tv_sec && a.tv_nsec == b.tv_nsec;
}

/* Removes "<path>.tmp-<pid>-<n>" (and a plot script's "<path>.<pid>.run") whose process is gone: what a
 * SIGKILL left of an earlier write of this very file. Temporaries of other names are never touched, nor
 * those of a live process, nor anything that is not a regular file. */
void removeStaleTemporariesOf(const String& path)
{
    const String folder = folderOf(path);
    const size_t slash = path.find_last_of('/');
    const String name = slash == String::npos ? path : path.substr(slash + 1);
    struct stat folderStat;
    if (::stat(folder.c_str(), &folderStat) != 0)
        return; // the write itself reports a missing folder
    StaleTemporaries& stale = staleTemporaries();
    const std::lock_guard<std::mutex> lock(stale.mutex);
    FolderListing& listing = stale.byFolder[folder];
    if (!sameTime(listing.mtime, folderStat.st_mtim)) {
        listing.mtime = folderStat.st_mtim;
        listing.temporaries.clear();
        if (DIR* dir = ::opendir(folder.c_str())) {
            while (const dirent* entry = ::readdir(dir)) {
                String target;
                const long pid = temporaryOwnerOf(entry->d_name, target);
                if (pid > 0)
                    listing.temporaries.emplace(target, std::make_pair(String(entry->d_name), pid));
            }
            ::closedir(dir);
        }
    }
    const auto range = listing.temporaries.equal_range(name);
    for (auto it = range.first; it != range.second; ++it) {
        const long pid = it->second.second;
        const String entryPath =
            (slash == String::npos ? String() : path.substr(0, slash + 1)) + it->second.first;
        struct stat st;
        if (pid == static_cast<long>(::getpid()) || ::kill(static_cast<pid_t>(pid), 0) == 0 ||
            errno != ESRCH || ::lstat(entryPath.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
            continue;
        if (::unlink(entryPath.c_str()) == 0)
            stale.removed.push_back(entryPath);
    }
    listing.temporaries.erase(range.first, range.second);
}

// After this process wrote into the folder of `path`: its own change needs no new listing.
void noteOwnWriteInFolderOf(const String& path)
{
    const String folder = folderOf(path);
    struct stat folderStat;
    if (::stat(folder.c_str(), &folderStat) != 0)
        return;
    StaleTemporaries& stale = staleTemporaries();
    const std::lock_guard<std::mutex> lock(stale.mutex);
    const auto listing = stale.byFolder.find(folder);
    if (listing != stale.byFolder.end())
        listing->second.mtime = folderStat.st_mtim;
}

} // namespace

std::vector<String> takeRemovedStaleTemporaries()
{
    StaleTemporaries& stale = staleTemporaries();
    const std::lock_guard<std::mutex> lock(stale.mutex);
    std::vector<String> removed;
    removed.swap(stale.removed);
    return removed;
}

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
    checkPathHasNoNul(path);
    if (!data && size > 0)
        CV_Error(Error::StsBadArg, "writeFileAtomically: no data for " + std::to_string(size) + " bytes");
    removeStaleTemporariesOf(path);
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
        commitTemporaryFileNoReplace(tmp, path, data, size);
    syncDirectoryOf(path);
    noteOwnWriteInFolderOf(path);
}

} // namespace rawgment
} // namespace cv
