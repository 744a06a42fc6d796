// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// BurstStatistics: streaming per-pixel mean and variance of a burst (calibration topic).
#include "cpu_dispatch.hpp"
#include "opencv2/rawgment/calibration.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <algorithm>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#include <cstring>

namespace cv {
namespace rawgment {

namespace {

// Sums of d = v_k - v_0 and d^2 over frames 1..m-1 of a group, and min/max of the raw values, for n
// columns. Multi-versioned (see random.hpp): these loops are the whole cost of burst statistics.
template <typename T>
RAWGMENT_KERNEL void groupSumsBody(const T* const* rows, int m, int n, double* s1, double* s2, double* lo,
                                   double* hi)
{
    const T* first = rows[0];
    for (int c = 0; c < n; ++c) {
        s1[c] = s2[c] = 0;
        lo[c] = hi[c] = static_cast<double>(first[c]);
    }
    for (int k = 1; k < m; ++k) {
        const T* v = rows[k];
        for (int c = 0; c < n; ++c) {
            const double x = static_cast<double>(v[c]);
            const double d = x - static_cast<double>(first[c]);
            s1[c] += d;
            s2[c] += d * d;
            lo[c] = std::min(lo[c], x);
            hi[c] = std::max(hi[c], x);
        }
    }
}

RAWGMENT_KERNEL void groupSumsKernel(const ushort* const* rows, int m, int n, double* s1, double* s2,
                                     double* lo, double* hi)
{
    groupSumsBody(rows, m, n, s1, s2, lo, hi);
}
RAWGMENT_DISPATCHED(void, groupSums,
                    (const ushort* const* rows, int m, int n, double* s1, double* s2, double* lo, double* hi),
                    (rows, m, n, s1, s2, lo, hi))

RAWGMENT_KERNEL void groupSumsKernel(const float* const* rows, int m, int n, double* s1, double* s2,
                                     double* lo, double* hi)
{
    groupSumsBody(rows, m, n, s1, s2, lo, hi);
}
RAWGMENT_DISPATCHED(void, groupSums,
                    (const float* const* rows, int m, int n, double* s1, double* s2, double* lo, double* hi),
                    (rows, m, n, s1, s2, lo, hi))

// Chan et al.'s pairwise merge of a group's (mean, M2) into the running statistics, n columns. The
// state S is float64 (default) or float32 (half the memory and traffic); the merge itself is float64.
template <typename S>
RAWGMENT_KERNEL void mergeGroupColumnsBody(const double* first, const double* s1, const double* s2,
                                           const double* blackOfColumn, int m, double wGroup, double wCross,
                                           S* mu, S* acc, int n)
{
    for (int c = 0; c < n; ++c) {
        const double groupMean = first[c] - blackOfColumn[c] + s1[c] / m;
        const double groupM2 = (m * s2[c] - s1[c] * s1[c]) / m;
        const double delta = groupMean - static_cast<double>(mu[c]);
        mu[c] = static_cast<S>(static_cast<double>(mu[c]) + delta * wGroup);
        acc[c] = static_cast<S>(static_cast<double>(acc[c]) + groupM2 + delta * delta * wCross);
    }
}

RAWGMENT_KERNEL void mergeGroupColumnsKernel(const double* first, const double* s1, const double* s2,
                                             const double* blackOfColumn, int m, double wGroup, double wCross,
                                             double* mu, double* acc, int n)
{
    mergeGroupColumnsBody(first, s1, s2, blackOfColumn, m, wGroup, wCross, mu, acc, n);
}
RAWGMENT_DISPATCHED(void, mergeGroupColumns,
                    (const double* first, const double* s1, const double* s2, const double* blackOfColumn,
                     int m, double wGroup, double wCross, double* mu, double* acc, int n),
                    (first, s1, s2, blackOfColumn, m, wGroup, wCross, mu, acc, n))

RAWGMENT_KERNEL void mergeGroupColumnsKernel(const double* first, const double* s1, const double* s2,
                                             const double* blackOfColumn, int m, double wGroup, double wCross,
                                             float* mu, float* acc, int n)
{
    mergeGroupColumnsBody(first, s1, s2, blackOfColumn, m, wGroup, wCross, mu, acc, n);
}
RAWGMENT_DISPATCHED(void, mergeGroupColumns,
                    (const double* first, const double* s1, const double* s2, const double* blackOfColumn,
                     int m, double wGroup, double wCross, float* mu, float* acc, int n),
                    (first, s1, s2, blackOfColumn, m, wGroup, wCross, mu, acc, n))

/** Folds a group of frames into the running mean and M2 of each pixel of rows [r0, r1).
 *
 * Row by row, in column blocks whose sums stay in L1 while the group's rows stream past: sums of
 * d = v_k - v_0 (differences from the group's first frame) and of d^2, then Chan et al.'s pairwise
 * merge with the running statistics. For 16-bit input every d, sum and m * sum(d^2) - sum(d)^2 is an
 * integer below 2^53, so the group's mean and M2 are exact; float input keeps full float64 precision
 * because the differences are small next to a large mean. */
template <typename T, typename S>
void mergeGroupRows(const std::vector<Mat>& group, int merged, const Vec4d& black, double white, Mat& mean,
                    Mat& m2, Mat& clipped, int r0, int r1)
{
    const int kBlock = 256;
    const int m = static_cast<int>(group.size()), cols = mean.cols;
    double s1[kBlock], s2[kBlock], lo[kBlock], hi[kBlock], first[kBlock], blackOfColumn[kBlock];
    std::vector<const T*> rows(static_cast<size_t>(m));
    const double total = static_cast<double>(merged + m);
    const double wGroup = m / total, wCross = static_cast<double>(merged) * m / total;
    for (int r = r0; r < r1; ++r) {
        const double b0 = black[2 * (r & 1)], b1 = black[2 * (r & 1) + 1];
        for (int c = 0; c < kBlock; ++c)
            blackOfColumn[c] = (c & 1) ? b1 : b0; // kBlock is even: the phase holds in every block
        S* mu = mean.ptr<S>(r);
        S* acc = m2.ptr<S>(r);
        uchar* clip = clipped.ptr<uchar>(r);
        if (merged == 0) {
            // The state's first touch, here on every thread rather than in one serial setTo(0): on a
            // virtual machine a page fault costs microseconds, hundreds of milliseconds for a 12 MP state.
            std::memset(mu, 0, sizeof(S) * static_cast<size_t>(cols));
            std::memset(acc, 0, sizeof(S) * static_cast<size_t>(cols));
            std::memset(clip, 0, static_cast<size_t>(cols));
        }
        for (int c0 = 0; c0 < cols; c0 += kBlock) {
            const int n = std::min(kBlock, cols - c0);
            for (int k = 0; k < m; ++k)
                rows[static_cast<size_t>(k)] = group[static_cast<size_t>(k)].ptr<T>(r) + c0;
            groupSums(rows.data(), m, n, s1, s2, lo, hi);
            for (int c = 0; c < n; ++c)
                first[c] = static_cast<double>(rows[0][c]);
            mergeGroupColumns(first, s1, s2, blackOfColumn, m, wGroup, wCross, mu + c0, acc + c0, n);
            for (int c = 0; c < n; ++c)
                if (lo[c] <= 0 || hi[c] >= white)
                    clip[c0 + c] = 255;
        }
    }
}

// A Mat for hundreds of megabytes that is written once in full: on Linux, asks for transparent huge
// pages, which cut the page faults of first touch (a third of the time of a 12 MP burst) by 512x.
Mat largeBuffer(Size size, int type)
{
    Mat m(size, type);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t kHuge = size_t(2) << 20;
    const uintptr_t begin = (reinterpret_cast<uintptr_t>(m.data) + kHuge - 1) & ~(kHuge - 1);
    const uintptr_t end = (reinterpret_cast<uintptr_t>(m.data) + m.total() * m.elemSize()) & ~(kHuge - 1);
    if (end > begin) // advice only: a kernel without THP refuses it and nothing changes
        (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
    return m;
}

/* src converted to `type` and scaled, rows split among threads: the output is as large as the state
 * (96 MB for 12 MP in float64) and new, so its page faults are most of the cost, and one thread would
 * take them all. */
void convertInParallel(const Mat& src, OutputArray _dst, int type, double scale)
{
    _dst.create(src.size(), type);
    Mat dst = _dst.getMat();
    parallel_for_(Range(0, src.rows),
                  [&](const Range& rows) { src.rowRange(rows).convertTo(dst.rowRange(rows), type, scale); });
}

} // namespace

struct BurstStatistics::Impl
{
    //! Frames buffered before a merge: the float64 state is read once per group instead of per frame.
    int groupFrames = 8;
    int stateDepth = CV_64F;
    RawFormat format;
    int type = -1;
    int merged = 0; // frames folded into mean/m2
    Mat mean, m2, clipped;
    //! Reused group buffers: a fresh allocation per frame would page-fault 24 MB each time.
    std::vector<Mat> buffers;
    int pending = 0;

    void flush()
    {
        if (pending == 0)
            return;
        const std::vector<Mat> group(buffers.begin(), buffers.begin() + pending);
        parallel_for_(Range(0, mean.rows), [&](const Range& rows) {
            const auto merge = [&](auto pixel, auto state) {
                mergeGroupRows<decltype(pixel), decltype(state)>(group, merged, format.blackLevel,
                                                                 format.whiteLevel, mean, m2, clipped,
                                                                 rows.start, rows.end);
            };
            if (type == CV_16UC1 && stateDepth == CV_64F)
                merge(ushort(), double());
            else if (type == CV_16UC1)
                merge(ushort(), float());
            else if (stateDepth == CV_64F)
                merge(float(), double());
            else
                merge(float(), float());
        });
        merged += pending;
        pending = 0;
    }
};

BurstStatistics::BurstStatistics(const RawFormat& format, int groupFrames, int stateDepth)
{
    format.validate();
    if (groupFrames < 1 || groupFrames > 256)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics: groupFrames must lie in [1, 256] (got %d)", groupFrames));
    if (stateDepth != CV_64F && stateDepth != CV_32F)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics: stateDepth must be CV_64F or CV_32F (got %d)", stateDepth));
    impl_ = std::make_unique<Impl>();
    impl_->stateDepth = stateDepth;
    impl_->format = format;
    impl_->groupFrames = groupFrames;
    impl_->buffers.resize(static_cast<size_t>(groupFrames));
}

// Defined here, where Impl is complete, for the unique_ptr.
BurstStatistics::~BurstStatistics() = default;

void BurstStatistics::add(InputArray _frame)
{
    const Mat frame = _frame.getMat();
    if (frame.empty())
        CV_Error(Error::StsBadArg, "BurstStatistics::add: frame is empty");
    if (frame.type() != CV_16UC1 && frame.type() != CV_32FC1)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics::add: frame type %s is not supported; expected CV_16UC1 "
                            "or CV_32FC1",
                            typeToString(frame.type()).c_str()));
    Impl& d = *impl_;
    if (d.type < 0) {
        d.type = frame.type();
        // Zeroed by the first merge (mergeGroupRows()), in parallel.
        d.mean = largeBuffer(frame.size(), CV_MAKETYPE(d.stateDepth, 1));
        d.m2 = largeBuffer(frame.size(), CV_MAKETYPE(d.stateDepth, 1));
        d.clipped = largeBuffer(frame.size(), CV_8UC1);
    } else if (frame.type() != d.type || frame.size() != d.mean.size()) {
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics::add: frame %d is %dx%d of type %s; the burst is %dx%d "
                            "of type %s",
                            frames(), frame.cols, frame.rows, typeToString(frame.type()).c_str(), d.mean.cols,
                            d.mean.rows, typeToString(d.type).c_str()));
    }
    if (frame.type() == CV_32FC1 && !checkRange(frame, true))
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics::add: frame %d contains NaN or Inf", frames()));
    // A parallel copy: one thread cannot saturate the memory bus, and the copy is a third of the cost.
    Mat& buffer = d.buffers[d.pending++];
    if (buffer.empty()) // allocated on first use: a short burst never holds a whole group
        buffer = largeBuffer(frame.size(), frame.type());
    parallel_for_(Range(0, frame.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r)
            std::memcpy(buffer.ptr(r), frame.ptr(r), frame.cols * frame.elemSize());
    });
    if (d.pending == d.groupFrames)
        d.flush();
}

int BurstStatistics::frames() const
{
    return impl_->merged + impl_->pending;
}
Size BurstStatistics::size() const
{
    return impl_->mean.size();
}
const RawFormat& BurstStatistics::format() const
{
    return impl_->format;
}

void BurstStatistics::mean(OutputArray dst) const
{
    if (frames() < 1)
        CV_Error(Error::StsBadArg, "BurstStatistics::mean: no frame was added");
    impl_->flush();
    convertInParallel(impl_->mean, dst, CV_64F, 1.0);
}

void BurstStatistics::variance(OutputArray dst) const
{
    if (frames() < 2)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics::variance: needs at least 2 frames (got %d)", frames()));
    impl_->flush();
    convertInParallel(impl_->m2, dst, CV_64F, 1.0 / (impl_->merged - 1));
}

void BurstStatistics::clippedMask(OutputArray dst) const
{
    if (frames() < 1)
        CV_Error(Error::StsBadArg, "BurstStatistics::clippedMask: no frame was added");
    impl_->flush();
    convertInParallel(impl_->clipped, dst, CV_8U, 1.0);
}

} // namespace rawgment
} // namespace cv
