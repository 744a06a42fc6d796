// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "precomp.hpp"

#include <opencv2/rawgment/augment.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <iterator>
#include <poll.h>
#include <sstream>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

namespace cv {
namespace rawgment {
namespace detail {

void adviseHugePages(const Mat& m)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t huge = size_t(2) << 20;
    if (!m.isContinuous() || m.total() * m.elemSize() < 2 * huge)
        return;
    const uintptr_t begin = (reinterpret_cast<uintptr_t>(m.data) + huge - 1) & ~(huge - 1);
    const uintptr_t end = (reinterpret_cast<uintptr_t>(m.data) + m.total() * m.elemSize()) & ~(huge - 1);
    if (end > begin) // advice only: a kernel without THP refuses it and nothing changes
        (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
    (void)m;
#endif
}

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

Mat twoDimensional(InputArray array, const char* what)
{
    const Mat m = array.getMat();
    if (m.dims > 2) {
        std::string shape;
        for (int d = 0; d < m.dims; ++d)
            shape += (d ? " x " : "") + std::to_string(m.size[d]);
        CV_Error(Error::StsBadArg,
                 format("%s has %d dimensions (%s); expected a 2-D matrix (a (rows, cols) array)", what,
                        m.dims, shape.c_str()));
    }
    return m;
}

Mat normalisedKernel(InputArray _kernel, const char* who, CfaPattern pattern)
{
    const int maxSide = pattern == CFA_MONO ? 2 * MAX_MOTION_KERNEL_SIDE - 1 : MAX_MOTION_KERNEL_SIDE;
    const Mat given = twoDimensional(_kernel, format("%s: kernel", who).c_str());
    if (given.rows > maxSide || given.cols > maxSide)
        CV_Error(Error::StsBadArg,
                 format("%s: the kernel is %dx%d; a blur kernel is at most %d plane pixels on a "
                        "side (a motion of MAX_MOTION_LENGTH), and its cost grows with its area",
                        who, given.cols, given.rows, maxSide));
    // A kernel of several channels would be read interleaved, its channels taken for taps.
    if (given.channels() != 1)
        CV_Error(Error::StsBadArg, format("%s: kernel has %d channels; expected a single-channel 2-D kernel",
                                          who, given.channels()));
    Mat kernel;
    given.convertTo(kernel, CV_64F);
    if (kernel.empty() || !checkRange(kernel, true))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-empty and finite", who));
    double lo = 0;
    minMaxLoc(kernel, &lo);
    const double total = sum(kernel)[0];
    if (lo < 0 || !(total > 0))
        CV_Error(Error::StsBadArg, format("%s: kernel must be non-negative with a positive sum", who));
    return kernel / total;
}

namespace {

bool isAbsent(const FileNode& f)
{
    return f.empty() || f.isNone();
}

double numberOf(const FileNode& f, const String& name)
{
    if (!f.isReal() && !f.isInt())
        CV_Error(Error::StsParseError, format("field '%s' is not a number", name.c_str()));
    return static_cast<double>(f);
}

} // namespace

double readRealField(const FileNode& node, const char* field)
{
    const FileNode f = node[field];
    if (isAbsent(f))
        CV_Error(Error::StsParseError, format("field '%s' is missing", field));
    return numberOf(f, field);
}

double readOptionalRealField(const FileNode& node, const char* field, double fallback)
{
    const FileNode f = node[field];
    return isAbsent(f) ? fallback : numberOf(f, field);
}

bool readOptionalFlagField(const FileNode& node, const char* field, bool fallback)
{
    const FileNode f = node[field];
    if (isAbsent(f))
        return fallback;
    if (f.isString() && (f.string() == "true" || f.string() == "false"))
        return f.string() == "true";
    if (f.isInt() && (int(f) == 0 || int(f) == 1))
        return int(f) == 1;
    CV_Error(Error::StsParseError, format("field '%s' must be true or false (or 1 or 0)", field));
}

int readOptionalIntField(const FileNode& node, const char* field, int fallback)
{
    const FileNode f = node[field];
    if (isAbsent(f))
        return fallback;
    const double value = f.isInt() || f.isReal() ? static_cast<double>(f) : 0.5;
    if (value != std::floor(value) || value < INT_MIN || value > INT_MAX)
        CV_Error(Error::StsParseError, format("field '%s' must be an integer", field));
    return static_cast<int>(value);
}

std::vector<double> readRealList(const FileNode& node, const char* field, int n)
{
    const FileNode list = node[field];
    if (!list.isSeq() || static_cast<int>(list.size()) != n)
        CV_Error(Error::StsParseError, format("field '%s' must be a list of %d numbers", field, n));
    std::vector<double> values;
    for (int i = 0; i < n; ++i)
        values.push_back(numberOf(list[i], format("%s[%d]", field, i)));
    return values;
}

} // namespace detail

} // namespace rawgment
} // namespace cv
