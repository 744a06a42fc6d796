// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The file system for the rest of the module (file_access.hpp): stamps, removal, folders, paths and
// positioned reads.
#include "file_access.hpp"

#include "precomp.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sys/stat.h>
#include <unistd.h>

namespace cv {
namespace rawgment {
namespace detail {

bool FileStamp::regular() const
{
    return S_ISREG(mode);
}

namespace {

FileStamp stampOf(const struct stat& info)
{
    FileStamp stamp;
    stamp.device = static_cast<unsigned long long>(info.st_dev);
    stamp.inode = static_cast<unsigned long long>(info.st_ino);
    stamp.bytes = static_cast<long long>(info.st_size);
    stamp.modifiedNs = static_cast<long long>(info.st_mtim.tv_sec) * 1000000000LL + info.st_mtim.tv_nsec;
    stamp.mode = static_cast<unsigned>(info.st_mode);
    return stamp;
}

} // namespace

bool fileStampOf(const String& path, FileStamp& stamp)
{
    checkPathHasNoNul(path);
    struct stat info;
    if (::stat(path.c_str(), &info) != 0)
        return false;
    stamp = stampOf(info);
    return true;
}

bool fileStampOf(int fd, FileStamp& stamp)
{
    struct stat info;
    if (::fstat(fd, &info) != 0)
        return false;
    stamp = stampOf(info);
    return true;
}

void removeFileIfPresent(const String& path)
{
    std::remove(path.c_str());
}

bool isFolder(const String& path)
{
    std::error_code error;
    return std::filesystem::is_directory(std::filesystem::path(path), error);
}

std::vector<String> folderEntryNames(const String& folder, const char* who)
{
    std::vector<String> names;
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator(folder.empty() ? "." : folder, error))
        names.push_back(entry.path().filename().string());
    if (error)
        CV_Error(Error::StsError,
                 format("%s: cannot list '%s': %s", who, folder.c_str(), error.message().c_str()));
    return names;
}

String absolutePathOf(const String& path)
{
    std::error_code error;
    const std::filesystem::path absolute = std::filesystem::absolute(path, error);
    return error ? path : absolute.string();
}

String pathAsNamedBy(const String& path, const String& ownerPath)
{
    namespace fs = std::filesystem;
    const fs::path absolute = fs::absolute(fs::path(path)).lexically_normal();
    const fs::path base = fs::absolute(fs::path(ownerPath)).parent_path().lexically_normal();
    const fs::path relative = absolute.lexically_relative(base);
    if (!relative.empty() && *relative.begin() != "..")
        return relative.string();
    return absolute.string();
}

bool readFullyAt(int fd, void* data, size_t size, long long offset, const String& path, const char* who)
{
    uchar* out = static_cast<uchar*>(data);
    size_t got = 0;
    while (got < size) {
        const ssize_t n =
            ::pread(fd, out + got, size - got, static_cast<off_t>(offset) + static_cast<off_t>(got));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            CV_Error(Error::StsError,
                     format("%s: cannot read '%s': %s", who, path.c_str(), std::strerror(errno)));
        if (n == 0)
            return false;
        got += static_cast<size_t>(n);
    }
    return true;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
