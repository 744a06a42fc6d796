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

} // namespace detail
} // namespace rawgment
} // namespace cv
