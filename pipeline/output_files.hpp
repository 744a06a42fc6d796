// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer's file policy: output folders, and writes that never replace a file (through the
// library's atomic writer), shared by the apps and the Python module. Errors are std::runtime_error naming
// the path.
#ifndef RAWGMENT_PIPELINE_OUTPUT_FILES_HPP
#define RAWGMENT_PIPELINE_OUTPUT_FILES_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/files.hpp>

#include <string>

namespace rawgment_pipeline {

// The checks are the library's (files.hpp); this layer keeps only the policy: outputs that are never
// replaced, output folders.
using cv::rawgment::isRegularFile;
using cv::rawgment::pathExists;
//! `path` with '.', '..' and links resolved (as far as it exists): two names of one file compare equal.
std::string canonicalPath(const std::string& path);
/** Makes `dir` (and its parents) and checks that a file can be written there: before any computation,
 * not after it. The temporaries that killed runs left are removed by the writer, one output at a time
 * (cv::rawgment::takeRemovedStaleTemporaries()), never by walking the folder. Throws std::runtime_error. */
void prepareOutputDirectory(const std::string& dir);
//! Says on stderr which temporaries of killed runs the writes of this process removed (the apps, at exit).
void reportRemovedTemporaries();

/** An exclusive lock on a folder (flock() of the folder itself, so no file is left in it), held while the
 * object lives: two runs that decide, each, whether a shared file (a job record, a bank) is theirs to write,
 * and then write it, take turns. Blocks until the lock is free; the lock goes with the process, even when
 * it is killed. Throws std::runtime_error naming the folder when it cannot be opened or locked. */
class FolderLock
{
public:
    explicit FolderLock(const std::string& folder);
    ~FolderLock();
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

private:
    int fd_;
};

//! Creates a directory and its parents (like mkdir -p); throws std::runtime_error naming the path.
void makeDirectories(const std::string& path);
//! The directory part of a path ("." when there is none).
std::string directoryOf(const std::string& path);
//! The file name without directory and without its last extension.
std::string stemOf(const std::string& path);
//! `path` resolved against `base` when it is relative.
std::string resolvePath(const std::string& base, const std::string& path);

/** Writes bytes to `path` through the library's writer (checked, synced, atomic), replacing a file there;
 * its errors become std::runtime_error with the library's message. */
void writeBytesAtomically(const std::string& path, const void* data, size_t size);
/** Writes `text` to `path` atomically: a temporary file beside it, checked writes, then rename.
 * Throws std::runtime_error naming the file and the reason. */
void writeTextAtomically(const std::string& path, const std::string& text);
/** Encodes an image by the extension of `path` and writes it atomically (see writeTextAtomically). */
void writeImageAtomically(const std::string& path, const cv::Mat& image);
/** Like writeImageAtomically(), but never replaces a file: an existing file with exactly these bytes
 * (an interrupted run of the same job) is kept, any other is an error. */
void writeNewImage(const std::string& path, const cv::Mat& image);
//! writeNewImage() for text.
void writeNewText(const std::string& path, const std::string& text);

} // namespace rawgment_pipeline

#endif // RAWGMENT_PIPELINE_OUTPUT_FILES_HPP
