// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "precomp.hpp"

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <unistd.h>

namespace cv {
namespace rawgment {
namespace detail {

void checkFinitePositive(double value, const char* what)
{
    if (!std::isfinite(value) || value <= 0)
        CV_Error(Error::StsBadArg, format("%s must be finite and > 0 (got %g)", what, value));
}

void checkFiniteNonNegative(double value, const char* what)
{
    if (!std::isfinite(value) || value < 0)
        CV_Error(Error::StsBadArg, format("%s must be finite and >= 0 (got %g)", what, value));
}

Mat normalisedKernel(InputArray _kernel, const char* who)
{
    Mat kernel;
    _kernel.getMat().convertTo(kernel, CV_64F);
    if (kernel.empty() || !checkRange(kernel, true))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-empty and finite", who));
    double lo = 0;
    minMaxLoc(kernel, &lo);
    const double total = sum(kernel)[0];
    if (lo < 0 || !(total > 0))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-negative with a positive sum", who));
    return kernel / total;
}

double readRealField(const FileNode& node, const char* field)
{
    const FileNode f = node[field];
    if (f.empty() || f.isNone())
        CV_Error(Error::StsParseError, format("field '%s' is missing", field));
    if (!f.isReal() && !f.isInt())
        CV_Error(Error::StsParseError, format("field '%s' is not a number", field));
    return static_cast<double>(f);
}

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

String temporaryPathFor(const String& path)
{
    // Unique per process and call, so concurrent writers never share a temporary file.
    static std::atomic<unsigned> counter{0};
    return format("%s.tmp-%d-%u", path.c_str(), static_cast<int>(::getpid()), counter++);
}

void commitTemporaryFile(const String& tmpPath, const String& path)
{
    if (std::rename(tmpPath.c_str(), path.c_str()) != 0) {
        const int err = errno;
        std::remove(tmpPath.c_str());
        CV_Error(Error::StsError, "cannot rename '" + tmpPath + "' to '" + path + "': " + std::strerror(err));
    }
}

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

void writeBytesAtomically(const String& path, const void* data, size_t size, bool replace)
{
    const String tmp = temporaryPathFor(path);
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f)
        CV_Error(Error::StsError, "cannot open '" + tmp + "' for writing: " + std::strerror(errno));
    const bool written =
        std::fwrite(data, 1, size, f) == size && std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
    const int err = errno;
    if (std::fclose(f) != 0 || !written) {
        std::remove(tmp.c_str());
        CV_Error(Error::StsError, "cannot write '" + tmp + "': " + std::strerror(written ? errno : err));
    }
    if (replace)
        commitTemporaryFile(tmp, path);
    else
        commitTemporaryFileNoReplace(tmp, path);
}

bool fileExists(const String& path)
{
    return ::access(path.c_str(), F_OK) == 0;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
