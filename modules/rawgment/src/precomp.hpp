// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Private helpers shared by the module's sources; never installed.
#ifndef OPENCV_RAWGMENT_SRC_PRECOMP_HPP
#define OPENCV_RAWGMENT_SRC_PRECOMP_HPP

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <cmath>
#include <string>

namespace cv {
namespace rawgment {
namespace detail {

//! Throws StsBadArg "<what> must be finite and > 0 (got <value>)" unless value is finite and positive.
void checkFinitePositive(double value, const char* what);
//! Throws StsBadArg "<what> must be finite and >= 0 (got <value>)" unless value is finite and >= 0.
void checkFiniteNonNegative(double value, const char* what);

//! Reads a required real field of a FileStorage map, naming it when it is missing or not a number.
double readRealField(const FileNode& node, const char* field);

//! Writes `path` atomically with a FileStorage: a temporary file beside it, then rename().
//! The format follows the extension of `path` (.yml/.yaml or .json); other extensions are rejected.
template <typename Writer> void writeFileStorageAtomically(const String& path, Writer&& writeBody);
int fileStorageFormatOf(const String& path);
void commitTemporaryFile(const String& tmpPath, const String& path);
String temporaryPathFor(const String& path);
//! Like commitTemporaryFile(), but fails (removing the temporary) when `path` already exists.
void commitTemporaryFileNoReplace(const String& tmpPath, const String& path);
//! Writes bytes to a temporary file beside `path`, syncs it, then commits it (replacing or not).
//! Every I/O call is checked; errors name the file and the reason.
void writeBytesAtomically(const String& path, const void* data, size_t size, bool replace);
//! Whether anything exists at `path`.
bool fileExists(const String& path);

template <typename Writer> void writeFileStorageAtomically(const String& path, Writer&& writeBody)
{
    const int format = fileStorageFormatOf(path);
    const String tmp = temporaryPathFor(path);
    {
        FileStorage fs(tmp, FileStorage::WRITE | format);
        if (!fs.isOpened())
            CV_Error(Error::StsError, "cannot open '" + tmp + "' for writing (next to '" + path + "')");
        writeBody(fs);
        fs.release();
    }
    commitTemporaryFile(tmp, path);
}

/** Reads the map `topLevel` of a YAML/JSON file with `read(node)`. Errors name the file: a missing or
 * unreadable file ("cannot open <what> '<path>'"), text that is not YAML/JSON, or whatever `read`
 * rejects. */
template <typename Reader>
auto loadFileStorage(const String& path, const char* topLevel, const char* what, Reader&& read)
    -> decltype(read(FileNode()))
{
    // Checked first so that OpenCV does not log its own error for a missing file.
    if (!fileExists(path))
        CV_Error(Error::StsError, String("cannot open ") + what + " '" + path + "': no such file");
    FileStorage fs;
    try {
        fs.open(path, FileStorage::READ);
    } catch (const Exception& e) {
        CV_Error(Error::StsParseError, "'" + path + "' is not a valid YAML or JSON file: " + e.err);
    }
    if (!fs.isOpened())
        CV_Error(Error::StsError, String("cannot open ") + what + " '" + path + "'");
    try {
        return read(fs[topLevel]);
    } catch (const Exception& e) {
        CV_Error(e.code, "'" + path + "': " + e.err);
    }
}

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_PRECOMP_HPP
