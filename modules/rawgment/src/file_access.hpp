// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// How the module reaches files (files.cpp, text_checks.cpp): regular files only, bounded text, the YAML/JSON
// text and fields every reader takes, and atomic FileStorage writes. The rules: docs/conventions.md.
// Private to the module.
#ifndef OPENCV_RAWGMENT_SRC_FILE_ACCESS_HPP
#define OPENCV_RAWGMENT_SRC_FILE_ACCESS_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/files.hpp>

#include <string>
#include <utility>
#include <vector>

namespace cv {
namespace rawgment {
namespace detail {

/* The one reader of numeric fields in YAML/JSON files: a field is a number or an error naming it. */
//! A required real field of a FileStorage map, named in the error when it is missing or not a number.
double readRealField(const FileNode& node, const char* field);
//! An optional real field: `fallback` when absent (or null), an error naming it when not a number.
double readOptionalRealField(const FileNode& node, const char* field, double fallback);
//! An optional integer field: as readOptionalRealField(), and an error when it has a fraction or does
//! not fit an int.
int readOptionalIntField(const FileNode& node, const char* field, int fallback);
/** An optional flag: true or false (YAML's and JSON's booleans) or 1 or 0 (how this module's writers
 * write a bool); `fallback` when absent, an error naming it otherwise. The text checks hand OpenCV a
 * boolean as the string "true" or "false", so that no number reader takes it for 1 or 0. */
bool readOptionalFlagField(const FileNode& node, const char* field, bool fallback);
//! A required list of exactly `n` numbers, named (and the element) in the error.
std::vector<double> readRealList(const FileNode& node, const char* field, int n);

//! The extension of a path's file name, with its dot, in lower case ("" when it has none).
String lowerExtensionOf(const String& path);
//! The folder of a path with its trailing '/' ("" for a bare file name): what relative names inside a file
//! are resolved against.
String folderOf(const String& path);

/** Writes `path` with a FileStorage, replacing it: the text is built in memory, then written by
 * writeFileAtomically() (checked, synced, atomic). The format follows the extension of `path`
 * (.yml/.yaml or .json); other extensions are rejected. */
template <typename Writer> void writeFileStorageAtomically(const String& path, Writer&& writeBody);
int fileStorageFormatOf(const String& path);
//! The whole content of a regular file of at most MAX_TEXT_FILE_BYTES; throws StsError naming it.
std::string readTextFile(const String& path);
//! Throws StsError naming `path` (as `what`) unless it exists and is a regular file: a reader handed a
//! FIFO or a device would block or read forever.
void checkRegularFile(const String& path, const String& what);
//! Why a file of this st_mode is not read ("it is a FIFO ...").
const char* notRegularReason(unsigned mode);
/** A regular file opened for reading, closed with the object. A FIFO (opened without waiting for a
 * writer), a device, a socket or a directory is refused with StsError naming `what` and `path`, decided on
 * the opened file itself, so nothing can be swapped in between. */
class RegularFileForReading
{
public:
    RegularFileForReading(const String& path, const String& what);
    ~RegularFileForReading();
    RegularFileForReading(const RegularFileForReading&) = delete;
    RegularFileForReading& operator=(const RegularFileForReading&) = delete;
    int fd() const { return fd_; }
    long long size() const { return size_; } //!< at the time it was opened

private:
    int fd_;
    long long size_ = 0;
};
/** @name The file system, for the rest of the module (file_system.cpp)
 * Every stat, listing, removal and path resolution of the library is here, so that a rule about files (a
 * FIFO never opened, a name resolved one way) is made once; scripts/check-sources.sh refuses them elsewhere.
 */
//! @{
/** What stat() says of a file, links followed: where it is (device, inode), its size, its last modification
 * in ns and its kind. The one reading of a stat in the module: identities, fingerprint keys and the checks of
 * other topics all take it. */
struct FileStamp
{
    unsigned long long device = 0, inode = 0;
    long long bytes = 0, modifiedNs = 0;
    unsigned mode = 0;
    bool regular() const;
};
//! The stamp of the file at `path` (a NUL in it refused); false when nothing is there or it cannot be
//! stat'ed.
bool fileStampOf(const String& path, FileStamp& stamp);
//! The stamp of an open file; false when it cannot be stat'ed.
bool fileStampOf(int fd, FileStamp& stamp);
//! Removes the file at `path` if one is there, silently: the undoing of a write that failed halfway.
void removeFileIfPresent(const String& path);
//! Whether `path` is a folder, links followed.
bool isFolder(const String& path);
/** The names in a folder ("" is the working folder), without "." and "..", in no order; throws StsError
 * naming `who` and the folder when it cannot be listed. */
std::vector<String> folderEntryNames(const String& folder, const char* who);
//! `path` made absolute against the working folder; `path` itself when that fails.
String absolutePathOf(const String& path);
/** `path` as a file at `ownerPath` names it: relative to the owner's folder when it lies inside it (both made
 * absolute and normalised lexically first), so that the owner moves with it; absolute otherwise. */
String pathAsNamedBy(const String& path, const String& ownerPath);
/** Reads exactly `size` bytes at `offset` of an open file (retrying an interrupted read); false when the
 * file ends first; throws StsError naming `who` and `path` on a read error. */
bool readFullyAt(int fd, void* data, size_t size, long long offset, const String& path, const char* who);
//! @}
//! A file's device and inode: what two spellings of one path, or two hard links, share.
struct FileIdentity
{
    unsigned long long device = 0, inode = 0;
    bool operator<(const FileIdentity& o) const
    {
        return device != o.device ? device < o.device : inode < o.inode;
    }
};
//! The identity of the file at `path` (links followed); false when it cannot be stat'ed.
bool fileIdentityOf(const String& path, FileIdentity& id);
/** The FNV-1a 64 of a regular file's bytes, as 16 lower-case hex digits: what a dark-frame bank records of
 * each frame, so that a frame replaced by another of the same size is seen. Hashed once per process per
 * (device, inode, size, modification time in ns), since a 24 MB frame costs about 30 ms, more than a step's
 * draw: a frame rewritten in place within one process with all four kept is not hashed again. Throws
 * StsError naming `what` and `path` for a file that cannot be read or changed while it was hashed. */
std::string contentFingerprintOf(const String& path, const String& what);
//! The deepest nesting of maps and lists openFileStorageForReading() accepts; this module's files nest
//! at most five levels, and OpenCV's readers recurse once per level.
constexpr int MAX_NESTING_DEPTH = 64;
/** The text OpenCV's reader is given for a file's whole content `text` (YAML, OpenCV's "%YAML:1.0" line
 * allowed, or JSON when it starts with a brace): parsed by libyaml or nlohmann-json, iteratively, scalars
 * typed by YAML 1.2's core schema, and the values written anew by OpenCV's own JSON writer. Throws
 * StsParseError naming the file (`path`), the line where it is known and what is wrong for text that is not
 * one YAML document or JSON value whose root is a map, nesting deeper than MAX_NESTING_DEPTH, anchors or
 * aliases, a repeated key in any map, a key OpenCV's files cannot hold, an integer beyond 32 bits, a plain
 * value OpenCV's own reader would read as another type or value, and UTF-16 or UTF-32 text. */
std::string textForOpenCv(const String& path, std::string text);

template <typename Writer> void writeFileStorageAtomically(const String& path, Writer&& writeBody)
{
    const std::string text = fileStorageText(path, std::forward<Writer>(writeBody));
    writeFileAtomically(path, text.data(), text.size(), true);
}

/** Reads the map `topLevel` of a YAML/JSON file with `read(node)`. Errors name the file: a missing or
 * unreadable file ("cannot open <what> '<path>'"), text that is not YAML/JSON, or whatever `read`
 * rejects. */
template <typename Reader>
auto loadFileStorage(const String& path, const char* topLevel, const char* what, Reader&& read)
    -> decltype(read(FileNode()))
{
    FileStorage fs = openFileStorageForReading(path, what);
    try {
        return read(fs[topLevel]);
    } catch (const Exception& e) {
        CV_Error(e.code, "'" + path + "': " + e.err);
    } catch (const std::exception& e) {
        // OpenCV's reader throws std::length_error and friends on some malformed files.
        CV_Error(Error::StsParseError, "'" + path + "' is not a valid YAML or JSON file: " + e.what());
    }
}

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_FILE_ACCESS_HPP
