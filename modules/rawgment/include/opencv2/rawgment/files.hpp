// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_FILES_HPP
#define OPENCV_RAWGMENT_FILES_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/export.hpp>

#include <functional>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_files
//! @{

/** @brief Writes bytes to a file so that a reader, a crash or a full disk never leaves a partial file
 * under `path`: the one writer of the library and its apps.
 *
 * The bytes go to a temporary file beside `path` (same directory, so the move is atomic); every write,
 * the flush and an fsync are checked (a full disk is an error, not a short file); then the temporary
 * is moved into place and the directory is synced, so the new name survives a power cut. With
 * `replace` false the move fails when `path` exists, atomically too (a hard link), so an existing file
 * is never overwritten, unless it holds exactly these bytes: then it is this write's output (a rerun of
 * the same job, or an identical run at the same time that got there first) and the call succeeds
 * leaving it as it is. With `replace` true it replaces `path`. On any error the temporary is removed
 * and `path` is left as it was.
 * @param path destination file
 * @param data the bytes (may be null when size is 0)
 * @param size number of bytes
 * @param replace whether an existing `path` may be replaced
 * @throws cv::Exception naming the file and the system's reason.
 */
CV_RAWGMENT_EXPORTS void writeFileAtomically(const String& path, const void* data, size_t size,
                                             bool replace = false);

/** @brief Removes the temporary files of writeFileAtomically() calls still in progress in this process.
 *
 * Async-signal-safe: meant for a SIGINT or SIGTERM handler of a program that must leave no partial
 * file behind when it is stopped (the apps install one). The target files are untouched: a write in
 * progress simply never happened. Temporaries are named `<target>.tmp-<pid>-<n>`; a process killed
 * with SIGKILL leaves its own, which the next writeFileAtomically() of that same target removes once
 * that pid is gone (see takeRemovedStaleTemporaries()).
 */
CV_RAWGMENT_EXPORTS void removeTemporaryFilesInProgress();

/** @brief The temporaries of killed writers that writeFileAtomically() removed in this process since the
 * last call, and forgets them: what an app reports when it ends.
 *
 * Before it writes `path`, writeFileAtomically() removes `<path>.tmp-<pid>-<n>` (and `<path>.<pid>.run`,
 * a plot script's, for a `path` ending in `.gp`) when no process `<pid>` is alive: only the leftovers of
 * an earlier write of that same file. A file of any other name, one whose writer still runs, and anything
 * that is not a regular file are never removed, and folders are never walked. Each folder is listed once
 * per process, at the first write into it.
 */
CV_RAWGMENT_EXPORTS std::vector<String> takeRemovedStaleTemporaries();

/** @brief Refuses a path that holds a NUL character, as Python's open() does: the operating system reads
 * such a path only up to the NUL, so `bank.save("other.yml\0.json")` wrote its maps and its bank over one
 * another into `other.yml`. Every reader and writer of the module checks its paths with this.
 * @throws cv::Exception StsBadArg whose message starts with "a path holds a NUL character" (the Python
 * module raises ValueError for it). */
CV_RAWGMENT_EXPORTS void checkPathHasNoNul(const String& path);

/** @brief Writes `value` into `fs` as a string, whatever it holds: the one way every writer of the module
 * and its apps puts a path, a name or a note into a YAML or JSON file. OpenCV's `fs << value` opens a list
 * or a map when the string starts with '[' or '{' (a path `[0] dark.png` broke the file), and its writer
 * drops the quotes of `"q"` and the spaces that end `a `; here the value is quoted and escaped, so that
 * OpenCV's reader gives back exactly `value`.
 * @param fs an open FileStorage for writing, where a value is expected
 * @param key the entry's name, or "" for an element of the list being written
 * @param value UTF-8 text without a control character other than tab, line feed and carriage return
 * @throws cv::Exception naming the key and the byte for a NUL, another control character or bytes that are
 * not UTF-8: the module's readers (libyaml's check, then OpenCV's parser) refuse or cannot give back those,
 * so a file holding them is never written. */
CV_RAWGMENT_EXPORTS void writeString(FileStorage& fs, const String& key, const String& value);
//! @brief writeString() of a list: `key: [values...]`, each element a string.
CV_RAWGMENT_EXPORTS void writeStringList(FileStorage& fs, const String& key,
                                         const std::vector<String>& values);

/** @brief Whether anything (a file, a folder, or a link to one) exists at `path`: the one existence check of
 * the library, its pipeline and its apps. */
CV_RAWGMENT_EXPORTS bool pathExists(const String& path);

/** @brief Refuses a list of input files in which two entries are one file.
 *
 * Two entries are one file when they share a device and an inode: the same path spelt otherwise
 * (`d/f`, `d/./f`, a link to it) or a hard link. A series, a burst or a bank that holds one capture twice
 * has a temporal variance of 0 between those entries, which every figure drawn from it would carry
 * silently. Entries that do not exist are left to the reader that opens them.
 * @param paths the entries, in the order they were given
 * @param what what the list is, for the message ("EMVA 1288 manifest 'm.yml'")
 * @throws cv::Exception StsBadArg naming both entries and their places (1-based) in the list.
 */
CV_RAWGMENT_EXPORTS void refuseRepeatedFiles(const std::vector<String>& paths, const String& what);

/** @brief Whether `path` is a regular file, or a link to one: what every reader of this module opens (a FIFO,
 * a device or a folder never is). */
CV_RAWGMENT_EXPORTS bool isRegularFile(const String& path);

/** @brief The text of the YAML or JSON file that `writeBody` writes into a cv::FileStorage, built in memory:
 * what the library's own writers give writeFileAtomically().
 * @param path the file the text is for: its extension decides the format (.yml or .yaml: YAML; .json: JSON)
 * @param writeBody writes the file's content into the storage it is given
 * @throws cv::Exception StsBadArg for another extension, and whatever `writeBody` throws.
 */
CV_RAWGMENT_EXPORTS std::string fileStorageText(const String& path,
                                                const std::function<void(FileStorage&)>& writeBody);

//! The largest YAML or JSON file openFileStorageForReading() (and so every reader of this module) opens.
static constexpr long long MAX_TEXT_FILE_BYTES = 64LL << 20;

/** @brief Reads a whole regular file of at most `maxBytes` bytes, the way every reader of this module
 * reads its text files.
 *
 * A FIFO, a device (`/dev/zero`), a socket or a directory is refused before anything is read, without
 * waiting for a FIFO's writer; a file larger than `maxBytes`, or one that grows beyond it while being
 * read, is refused without reading more than `maxBytes + 1` bytes.
 * @param path the file
 * @param maxBytes the largest size accepted
 * @param what what the file is, for the messages ("noise model file", "calibration manifest")
 * @return the file's bytes
 * @throws cv::Exception StsError naming `what` and `path`: missing, unreadable, not a regular file (and
 * which kind it is), or larger than `maxBytes`; StsBadArg for an empty path or a negative limit.
 */
CV_RAWGMENT_EXPORTS std::string readFileBounded(const String& path, long long maxBytes, const String& what);

/** @brief Opens a YAML or JSON file for reading the way every reader of this module does.
 *
 * What it adds to cv::FileStorage, which readers of your own files (manifests, job files) can use too:
 * the file is a regular file of at most MAX_TEXT_FILE_BYTES; libyaml (YAML) or nlohmann-json (JSON: text
 * that starts with a brace) parses it in the calling thread, iteratively, its scalars are typed by YAML
 * 1.2's core schema, and OpenCV's own writer writes the values anew into memory: the storage returned reads
 * that text, so OpenCV's parser never sees what it would read otherwise than YAML (wrapped integers, keys
 * inside plain values, escapes and exponents it lacks, streams it loops on). The text must be one document
 * whose root is a map, nested at most 64 levels, without anchors or aliases, a repeated key in any map, a
 * key outside OpenCV's alphabet (a letter or '_', then letters, digits, '_', '-' or spaces), an integer
 * beyond 32 bits, or a plain value OpenCV 4.6's reader would read as another type or value (017, 0o17,
 * 1_000, 1:20, a value holding ':', an empty value). Booleans read as 1 and 0, a JSON null in a map as a
 * missing key; JSON's \\uXXXX and OpenCV's own \\' escapes are read. No child process or thread is
 * started and no time limit applies: a malformed file is refused by the parse itself. Every error names the
 * file (and the line where there is one).
 *
 * @param path the file (.yml, .yaml or .json; the content decides how it is parsed)
 * @param what what the file is, for the messages ("scene", "calibration manifest")
 * @return an opened storage
 * @throws cv::Exception StsError for a missing, unreadable or oversized file, or anything but a regular
 * file (a directory, a FIFO, a device: see readFileBounded());
 * StsParseError for an empty, XML or UTF-16/32 file, text that is not valid YAML or JSON, or any of the
 * refusals above, each with the line where it is known.
 */
CV_RAWGMENT_EXPORTS FileStorage openFileStorageForReading(const String& path, const String& what);

/** @brief The FNV-1a 64 of a regular file's bytes, as 16 lower-case hex digits: what a dark-frame bank
 * records of each frame and an augmentation run of its recipe files and inputs. Hashed once per process per
 * (device, inode, size, modification time in ns): about 30 ms for 24 MB, paid once.
 * @throws cv::Exception naming the file when it is not a regular file, cannot be read, or changed while it
 * was read. */
CV_RAWGMENT_EXPORTS std::string fileFingerprint(const String& path);

/** @brief Refuses a map with a key outside `valid` or a key that appears twice: a misspelled key
 * (`contrst_min`) must not fall back to a default, and of a repeated key OpenCV keeps both entries and a
 * lookup finds one. Every reader of this module checks its maps so; use it for your own files too.
 * @param map a map of a file opened with openFileStorageForReading() (anything else is not checked)
 * @param valid the keys the map may have
 * @throws cv::Exception StsParseError naming the key (and the valid ones).
 */
CV_RAWGMENT_EXPORTS void rejectUnknownKeys(const FileNode& map, const std::vector<String>& valid);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_FILES_HPP
