// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer's files (output_files.hpp): paths, output folders, and writes through the library's
// atomic writer.
#include "output_files.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment/files.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

namespace rawgment_pipeline {

void reportRemovedTemporaries()
{
    const std::vector<std::string> removed = cv::rawgment::takeRemovedStaleTemporaries();
    if (removed.empty())
        return;
    std::cerr << "removed " << removed.size() << " temporary file(s) that interrupted runs left:";
    for (const std::string& path : removed)
        std::cerr << " '" << path << "'";
    std::cerr << "\n";
}

FolderLock::FolderLock(const std::string& folder)
{
    cv::rawgment::checkPathHasNoNul(folder);
    fd_ = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ < 0)
        throw std::runtime_error("cannot open the folder '" + folder +
                                 "' to lock it: " + std::strerror(errno));
    while (::flock(fd_, LOCK_EX) != 0) {
        if (errno == EINTR)
            continue;
        const int err = errno;
        ::close(fd_);
        throw std::runtime_error("cannot lock the folder '" + folder + "': " + std::strerror(err));
    }
}

FolderLock::~FolderLock()
{
    ::close(fd_); // releases the lock
}

void writeBytesAtomically(const std::string& path, const void* data, size_t size)
{
    try {
        cv::rawgment::writeFileAtomically(path, data, size, true);
    } catch (const cv::Exception& e) {
        throw std::runtime_error(e.err);
    }
}

namespace {

//! The image encoded by the extension of `path`.
std::vector<uchar> encodeByExtension(const std::string& path, const cv::Mat& image)
{
    const size_t dot = path.find_last_of('.');
    if (dot == std::string::npos)
        throw std::runtime_error("'" + path + "': no image extension");
    std::vector<uchar> bytes;
    if (!cv::imencode(path.substr(dot), image, bytes))
        throw std::runtime_error("cannot encode '" + path + "'");
    return bytes;
}

// Never replaces: an existing file with exactly these bytes (an interrupted or identical run of the same
// job) is kept, any other is an error; the library's writer decides both, atomically.
void writeNewBytes(const std::string& path, const std::vector<uchar>& bytes)
{
    try {
        cv::rawgment::writeFileAtomically(path, bytes.data(), bytes.size(), false);
    } catch (const cv::Exception& e) {
        throw std::runtime_error(e.err);
    }
}

} // namespace

void prepareOutputDirectory(const std::string& dir)
{
    makeDirectories(dir);
    const std::string probe = dir + "/.rawgment-write-test-" + std::to_string(::getpid());
    try {
        cv::rawgment::writeFileAtomically(probe, "ok", 2, true);
    } catch (const cv::Exception& e) {
        throw std::runtime_error("the output folder '" + dir + "' cannot be written: " + e.err);
    }
    std::remove(probe.c_str());
}

std::string canonicalPath(const std::string& path)
{
    std::error_code error;
    const std::filesystem::path resolved = std::filesystem::weakly_canonical(path, error);
    return error ? path : resolved.string();
}

void makeDirectories(const std::string& path)
{
    if (path.empty())
        return;
    std::string partial;
    std::stringstream parts(path);
    std::string part;
    if (path[0] == '/')
        partial = "/";
    while (std::getline(parts, part, '/')) {
        if (part.empty())
            continue;
        partial += part + "/";
        if (::mkdir(partial.c_str(), 0777) != 0 && errno != EEXIST)
            throw std::runtime_error("cannot create directory '" + partial + "': " + std::strerror(errno));
    }
    struct stat st;
    if (::stat(path.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
        throw std::runtime_error("'" + path + "' is not a directory");
}

std::string directoryOf(const std::string& path)
{
    const size_t slash = path.find_last_of('/');
    if (slash == std::string::npos)
        return ".";
    return slash == 0 ? "/" : path.substr(0, slash);
}

std::string stemOf(const std::string& path)
{
    const size_t slash = path.find_last_of('/');
    std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
    const size_t dot = name.find_last_of('.');
    return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

std::string resolvePath(const std::string& base, const std::string& path)
{
    if (path.empty() || path[0] == '/' || base.empty())
        return path;
    return base + "/" + path;
}

void writeTextAtomically(const std::string& path, const std::string& text)
{
    writeBytesAtomically(path, text.data(), text.size());
}

void writeImageAtomically(const std::string& path, const cv::Mat& image)
{
    const std::vector<uchar> bytes = encodeByExtension(path, image);
    writeBytesAtomically(path, bytes.data(), bytes.size());
}

void writeNewText(const std::string& path, const std::string& text)
{
    writeNewBytes(path, std::vector<uchar>(text.begin(), text.end()));
}

void writeNewImage(const std::string& path, const cv::Mat& image)
{
    writeNewBytes(path, encodeByExtension(path, image));
}

} // namespace rawgment_pipeline
