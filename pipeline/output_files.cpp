// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer's files (output_files.hpp): paths, output folders, and writes through the library's
// atomic writer.
#include "output_files.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment/files.hpp>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace rawgment_pipeline {

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

// Never replaces: an existing file with exactly these bytes (an interrupted run of the same job) is
// kept, any other is an error.
void writeNewBytes(const std::string& path, const std::vector<uchar>& bytes)
{
    if (pathExists(path)) {
        // Read no more than the new bytes: a larger file, a FIFO or a device differs anyway.
        bool same = false;
        try {
            const std::string existing =
                cv::rawgment::readFileBounded(path, static_cast<long long>(bytes.size()), "existing output");
            same =
                existing.size() == bytes.size() && std::equal(bytes.begin(), bytes.end(), existing.begin(),
                                                              [](uchar a, char b) { return a == uchar(b); });
        } catch (const cv::Exception&) {
        }
        if (same)
            return;
        throw std::runtime_error("'" + path + "' already exists; it is never overwritten");
    }
    try {
        cv::rawgment::writeFileAtomically(path, bytes.data(), bytes.size(), false);
    } catch (const cv::Exception& e) {
        throw std::runtime_error(e.err);
    }
}

/* The process that wrote a temporary file: "<file>.tmp-<pid>-<n>" (writeFileAtomically) or
 * "<plot>.gp.<pid>.run" (a gnuplot script); 0 for any other name. */
pid_t temporaryOwner(const std::string& name)
{
    // Digits only, at most 9 of them (pids are far below), so that the number always fits.
    const auto number = [&](size_t from, size_t to) -> long {
        if (to <= from || to - from > 9)
            return 0;
        for (size_t i = from; i < to; ++i)
            if (name[i] < '0' || name[i] > '9')
                return 0;
        return std::stol(name.substr(from, to - from));
    };
    const size_t tmp = name.rfind(".tmp-");
    if (tmp != std::string::npos) {
        const size_t dash = name.find('-', tmp + 5);
        if (dash != std::string::npos && dash + 1 < name.size() &&
            name.find_first_not_of("0123456789", dash + 1) == std::string::npos)
            return static_cast<pid_t>(number(tmp + 5, dash));
    }
    const size_t gp = name.rfind(".gp.");
    if (gp != std::string::npos && name.size() >= gp + 8 && name.compare(name.size() - 4, 4, ".run") == 0)
        return static_cast<pid_t>(number(gp + 4, name.size() - 4));
    return 0;
}

} // namespace

void prepareOutputDirectory(const std::string& dir)
{
    makeDirectories(dir);
    int removed = 0;
    std::error_code error;
    for (auto it = std::filesystem::recursive_directory_iterator(dir, error);
         !error && it != std::filesystem::recursive_directory_iterator(); it.increment(error)) {
        const pid_t pid = temporaryOwner(it->path().filename().string());
        if (pid <= 0 || !it->is_regular_file(error))
            continue;
        if (pid != ::getpid() && ::kill(pid, 0) != 0 && errno == ESRCH &&
            std::remove(it->path().c_str()) == 0)
            ++removed;
    }
    if (removed > 0)
        std::cerr << "removed " << removed << " temporary file(s) that interrupted runs left in " << dir
                  << "\n";
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
