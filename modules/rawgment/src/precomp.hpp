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

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_PRECOMP_HPP
