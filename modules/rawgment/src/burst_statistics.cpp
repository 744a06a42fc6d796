// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// BurstStatistics: streaming per-pixel mean and variance of a burst (calibration topic).
#include "cpu_dispatch.hpp"
#include "opencv2/rawgment/calibration.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <algorithm>
#if defined(__linux__)
#endif
#include <cstring>
#include <type_traits>

namespace cv {
namespace rawgment {

namespace {

// Sums of d = v_k - v_0 and d^2 over frames 1..m-1 of a group, and min/max of the raw values, for n
// columns from `offset` on. Multi-versioned (cpu_dispatch.hpp): these loops are the whole cost of burst
// statistics.
template <typename T>
RAWGMENT_KERNEL void groupSumsBody(const T* const* rows, int m, int n, double* s1, double* s2, double* lo,
                                   double* hi, int offset = 0)
{
    const T* first = rows[0] + offset;
    for (int c = 0; c < n; ++c) {
        s1[c] = s2[c] = 0;
        lo[c] = hi[c] = static_cast<double>(first[c]);
    }
    for (int k = 1; k < m; ++k) {
        const T* v = rows[k] + offset;
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

// Half the lanes of a kernel of width W: int32, double and float.
template <int W> struct HalfLanes
{
    typedef RAWGMENT_VECTOR(int32_t, 2 * W) I;
    typedef RAWGMENT_VECTOR(double, 4 * W) D;
    typedef RAWGMENT_VECTOR(float, 2 * W) F;
};

//! Half h of a vector of W lanes.
template <typename Half, typename V> RAWGMENT_KERNEL Half halfOf(const V& v, int h)
{
    Half part;
    std::memcpy(&part, reinterpret_cast<const char*>(&v) + h * sizeof(Half), sizeof(Half));
    return part;
}

//! W / 2 lanes of a float64 or float32 state, in double lanes, and back.
template <int W> RAWGMENT_KERNEL typename HalfLanes<W>::D loadState(const double* p)
{
    typename HalfLanes<W>::D d;
    std::memcpy(&d, p, sizeof(d));
    return d;
}
template <int W> RAWGMENT_KERNEL typename HalfLanes<W>::D loadState(const float* p)
{
    typename HalfLanes<W>::F f;
    std::memcpy(&f, p, sizeof(f));
    return convertLanes<typename HalfLanes<W>::D>(f);
}
template <int W> RAWGMENT_KERNEL void storeState(double* p, typename HalfLanes<W>::D d)
{
    std::memcpy(p, &d, sizeof(d));
}
template <int W> RAWGMENT_KERNEL void storeState(float* p, typename HalfLanes<W>::D d)
{
    const typename HalfLanes<W>::F f = convertLanes<typename HalfLanes<W>::F>(d);
    std::memcpy(p, &f, sizeof(f));
}

/* A group of 16-bit frames folded into one row's running statistics, W columns at a time: the sums of
 * groupSumsBody() in integer lanes with the frames as the inner loop, so that they stay in registers
 * (d = v_k - v_0 in int32; d^2 < 2^32 in uint32, split into its low and high 16 bits, whose sums over at most
 * 256 frames stay below 2^31), then mergeGroupColumnsBody()'s operations in double lanes, in its order, and
 * the clipped flags (a value of 0 or at least `whiteFloor`, the smallest integer >= the white level). The
 * sums are the exact integers the double loop gives and the merge rounds as it does, so the results are
 * the same bits. Before, the double loop cost about four operations per value and frame and loaded and
 * stored its sums for each frame, and the merge read them back from arrays. */
template <int W, typename S>
RAWGMENT_KERNEL void mergeGroup16Body(const ushort* const* rows, int m, int n, double black0, double black1,
                                      double wGroup, double wCross, int whiteFloor, S* mu, S* acc,
                                      uchar* clip)
{
    typedef typename detail::Lanes<W>::I I;
    typedef typename detail::Lanes<W>::U U;
    typedef typename detail::Lanes<W>::U16 U16;
    typedef typename HalfLanes<W>::I HalfI;
    typedef typename HalfLanes<W>::D D;
    D black; // columns start even in each half, so the CFA phase is the lane's
    for (int i = 0; i < W / 2; ++i)
        black[i] = (i & 1) ? black1 : black0;
    const D md = D{} + static_cast<double>(m);
    int c = 0;
    for (; c + W <= n; c += W) {
        U16 raw;
        std::memcpy(&raw, rows[0] + c, sizeof(raw));
        const I first = convertLanes<I>(raw);
        I sum = {}, low = first, high = first;
        U squareLow = {}, squareHigh = {};
        for (int k = 1; k < m; ++k) {
            std::memcpy(&raw, rows[k] + c, sizeof(raw));
            const I v = convertLanes<I>(raw);
            const I d = v - first;
            sum += d;
            const U square = (U)d * (U)d; // |d| <= 65535: exact modulo 2^32, so exact
            squareLow += square & 0xffffu;
            squareHigh += square >> 16;
            low = detail::minLanes(low, v);
            high = detail::maxLanes(high, v);
        }
        for (int h = 0; h < 2; ++h) {
            const D s1 = convertLanes<D>(halfOf<HalfI>(sum, h));
            const D s2 = convertLanes<D>(halfOf<HalfI>((I)squareHigh, h)) * 65536.0 +
                         convertLanes<D>(halfOf<HalfI>((I)squareLow, h));
            const D groupMean = convertLanes<D>(halfOf<HalfI>(first, h)) - black + s1 / md;
            const D groupM2 = (md * s2 - s1 * s1) / md;
            S* const muAt = mu + c + h * W / 2;
            S* const accAt = acc + c + h * W / 2;
            const D oldMean = loadState<W>(muAt);
            const D delta = groupMean - oldMean;
            storeState<W>(muAt, oldMean + delta * wGroup);
            storeState<W>(accAt, loadState<W>(accAt) + groupM2 + delta * delta * wCross);
        }
        for (int bits = detail::maskBits((low <= 0) | (high >= whiteFloor)); bits; bits &= bits - 1)
            clip[c + lowestSetBit(static_cast<unsigned>(bits))] = 255;
    }
    if (c == n)
        return;
    // The last columns (fewer than W) by the scalar loops, which give the same bits.
    double s1[W], s2[W], lo[W], hi[W], first[W], blackOfColumn[W];
    groupSumsBody(rows, m, n - c, s1, s2, lo, hi, c);
    for (int i = 0; i < n - c; ++i) {
        first[i] = rows[0][c + i];
        blackOfColumn[i] = ((c + i) & 1) ? black1 : black0;
    }
    mergeGroupColumnsBody(first, s1, s2, blackOfColumn, m, wGroup, wCross, mu + c, acc + c, n - c);
    for (int i = 0; i < n - c; ++i)
        if (lo[i] <= 0 || hi[i] >= whiteFloor)
            clip[c + i] = 255;
}

template <int W>
RAWGMENT_KERNEL void mergeGroup16Kernel(const ushort* const* rows, int m, int n, double black0, double black1,
                                        double wGroup, double wCross, int whiteFloor, double* mu, double* acc,
                                        uchar* clip)
{
    mergeGroup16Body<W>(rows, m, n, black0, black1, wGroup, wCross, whiteFloor, mu, acc, clip);
}
template <int W>
RAWGMENT_KERNEL void mergeGroup16Kernel(const ushort* const* rows, int m, int n, double black0, double black1,
                                        double wGroup, double wCross, int whiteFloor, float* mu, float* acc,
                                        uchar* clip)
{
    mergeGroup16Body<W>(rows, m, n, black0, black1, wGroup, wCross, whiteFloor, mu, acc, clip);
}
RAWGMENT_DISPATCHED_BY_WIDTH(void, mergeGroup16,
                             (const ushort* const* rows, int m, int n, double black0, double black1,
                              double wGroup, double wCross, int whiteFloor, double* mu, double* acc,
                              uchar* clip),
                             (rows, m, n, black0, black1, wGroup, wCross, whiteFloor, mu, acc, clip))
RAWGMENT_DISPATCHED_BY_WIDTH(void, mergeGroup16,
                             (const ushort* const* rows, int m, int n, double black0, double black1,
                              double wGroup, double wCross, int whiteFloor, float* mu, float* acc,
                              uchar* clip),
                             (rows, m, n, black0, black1, wGroup, wCross, whiteFloor, mu, acc, clip))

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
    // For 16-bit values, hi >= white is hi >= ceil(white) (0 and 65536 bound every value).
    const int whiteFloor = static_cast<int>(std::min(std::max(std::ceil(white), 0.0), 65536.0));
    for (int r = r0; r < r1; ++r) {
        const double b0 = black[2 * (r & 1)], b1 = black[2 * (r & 1) + 1];
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
        if constexpr (std::is_same<T, ushort>::value) {
            for (int k = 0; k < m; ++k)
                rows[static_cast<size_t>(k)] = group[static_cast<size_t>(k)].ptr<T>(r);
            mergeGroup16(rows.data(), m, cols, b0, b1, wGroup, wCross, whiteFloor, mu, acc, clip);
        } else {
            for (int c = 0; c < kBlock; ++c)
                blackOfColumn[c] = (c & 1) ? b1 : b0; // kBlock is even: the phase holds in every block
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
}

// A Mat for hundreds of megabytes that is written once in full: on Linux, asks for transparent huge
// pages, which cut the page faults of first touch (a third of the time of a 12 MP burst) by 512x.
Mat largeBuffer(Size size, int type)
{
    Mat m(size, type);
    detail::adviseHugePages(m);
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
    bool formatted = false; // false only after the default constructor, until reset()
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
    impl_->formatted = true;
    impl_->buffers.resize(static_cast<size_t>(groupFrames));
}

BurstStatistics::BurstStatistics() : impl_(std::make_unique<Impl>())
{
    impl_->buffers.resize(static_cast<size_t>(impl_->groupFrames));
}

// Defined here, where Impl is complete, for the unique_ptr.
BurstStatistics::~BurstStatistics() = default;

void BurstStatistics::add(InputArray _frame)
{
    const Mat frame = detail::twoDimensional(_frame, "BurstStatistics::add: frame");
    if (frame.empty())
        CV_Error(Error::StsBadArg, "BurstStatistics::add: frame is empty");
    if (frame.type() != CV_16UC1 && frame.type() != CV_32FC1)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics::add: frame type %s is not supported; expected CV_16UC1 "
                            "or CV_32FC1",
                            typeToString(frame.type()).c_str()));
    Impl& d = *impl_;
    if (!d.formatted)
        CV_Error(Error::StsBadArg, "BurstStatistics::add: this object has no format: make it with "
                                   "BurstStatistics::create(format) (cv2: BurstStatistics_create), or call "
                                   "reset(format) first");
    if (d.type < 0 || (frames() == 0 && (frame.type() != d.type || frame.size() != d.mean.size()))) {
        // The first frame of the first burst, or of a burst after reset() of another size or type. The
        // state is written, not accumulated, by the first merge (mergeGroupRows()), so a reused state
        // needs no clearing.
        const bool resized = frame.size() != d.mean.size();
        if (resized) {
            d.mean = largeBuffer(frame.size(), CV_MAKETYPE(d.stateDepth, 1));
            d.m2 = largeBuffer(frame.size(), CV_MAKETYPE(d.stateDepth, 1));
            d.clipped = largeBuffer(frame.size(), CV_8UC1);
        }
        if (resized || frame.type() != d.type)
            for (Mat& buffer : d.buffers)
                buffer.release();
        d.type = frame.type();
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

void BurstStatistics::reset(const RawFormat& format)
{
    format.validate();
    Impl& d = *impl_;
    d.format = format;
    d.formatted = true;
    d.merged = 0;
    d.pending = 0;
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
