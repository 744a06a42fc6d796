// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/calibration.hpp"
#include "precomp.hpp"
#include "random.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#include <cstring>
#include <map>
#include <numeric>

namespace cv {
namespace rawgment {

// ---------------------------------------------------------------------------------------------------
// BurstStatistics

namespace {

// Sums of d = v_k - v_0 and d^2 over frames 1..m-1 of a group, and min/max of the raw values, for n
// columns. Multi-versioned (see random.hpp): these loops are the whole cost of burst statistics.
template <typename T>
inline void groupSumsBody(const T* const* rows, int m, int n, double* s1, double* s2, double* lo, double* hi)
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

RAWGMENT_HOT_KERNEL
void groupSums(const ushort* const* rows, int m, int n, double* s1, double* s2, double* lo, double* hi)
{
    groupSumsBody(rows, m, n, s1, s2, lo, hi);
}

RAWGMENT_HOT_KERNEL
void groupSums(const float* const* rows, int m, int n, double* s1, double* s2, double* lo, double* hi)
{
    groupSumsBody(rows, m, n, s1, s2, lo, hi);
}

// Chan et al.'s pairwise merge of a group's (mean, M2) into the running statistics, n columns. The
// state S is float64 (default) or float32 (half the memory and traffic); the merge itself is float64.
template <typename S>
inline void mergeGroupColumnsBody(const double* first, const double* s1, const double* s2,
                                  const double* blackOfColumn, int m, double wGroup, double wCross, S* mu,
                                  S* acc, int n)
{
    for (int c = 0; c < n; ++c) {
        const double groupMean = first[c] - blackOfColumn[c] + s1[c] / m;
        const double groupM2 = (m * s2[c] - s1[c] * s1[c]) / m;
        const double delta = groupMean - static_cast<double>(mu[c]);
        mu[c] = static_cast<S>(static_cast<double>(mu[c]) + delta * wGroup);
        acc[c] = static_cast<S>(static_cast<double>(acc[c]) + groupM2 + delta * delta * wCross);
    }
}

RAWGMENT_HOT_KERNEL
void mergeGroupColumns(const double* first, const double* s1, const double* s2, const double* blackOfColumn,
                       int m, double wGroup, double wCross, double* mu, double* acc, int n)
{
    mergeGroupColumnsBody(first, s1, s2, blackOfColumn, m, wGroup, wCross, mu, acc, n);
}

RAWGMENT_HOT_KERNEL
void mergeGroupColumns(const double* first, const double* s1, const double* s2, const double* blackOfColumn,
                       int m, double wGroup, double wCross, float* mu, float* acc, int n)
{
    mergeGroupColumnsBody(first, s1, s2, blackOfColumn, m, wGroup, wCross, mu, acc, n);
}

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

BurstStatistics::BurstStatistics(const RawFormat& format, int groupFrames, int stateDepth) : impl_(nullptr)
{
    // Arguments first: a constructor that throws never runs its destructor, so nothing may be owned yet.
    format.validate();
    if (groupFrames < 1 || groupFrames > 256)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics: groupFrames must lie in [1, 256] (got %d)", groupFrames));
    if (stateDepth != CV_64F && stateDepth != CV_32F)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics: stateDepth must be CV_64F or CV_32F (got %d)", stateDepth));
    impl_ = new Impl;
    impl_->stateDepth = stateDepth;
    impl_->format = format;
    impl_->groupFrames = groupFrames;
    impl_->buffers.resize(static_cast<size_t>(groupFrames));
}

BurstStatistics::~BurstStatistics()
{
    delete impl_;
}

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
        d.mean = largeBuffer(frame.size(), CV_MAKETYPE(d.stateDepth, 1));
        d.m2 = largeBuffer(frame.size(), CV_MAKETYPE(d.stateDepth, 1));
        d.clipped = largeBuffer(frame.size(), CV_8UC1);
        d.mean.setTo(0);
        d.m2.setTo(0);
        d.clipped.setTo(0);
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
    impl_->mean.convertTo(dst, CV_64F);
}

void BurstStatistics::variance(OutputArray dst) const
{
    if (frames() < 2)
        CV_Error(Error::StsBadArg,
                 cv::format("BurstStatistics::variance: needs at least 2 frames (got %d)", frames()));
    impl_->flush();
    impl_->m2.convertTo(dst, CV_64F, 1.0 / (impl_->merged - 1));
}

void BurstStatistics::clippedMask(OutputArray dst) const
{
    if (frames() < 1)
        CV_Error(Error::StsBadArg, "BurstStatistics::clippedMask: no frame was added");
    impl_->flush();
    impl_->clipped.copyTo(dst);
}

// ---------------------------------------------------------------------------------------------------
// Sampling

std::vector<Rect> cfaAlignedSquares(const std::vector<Rect>& patches, int side)
{
    if (side < 2 || side % 2)
        CV_Error(Error::StsBadArg, format("cfaAlignedSquares: side must be even and >= 2 (got %d)", side));
    std::vector<Rect> out;
    for (size_t i = 0; i < patches.size(); ++i) {
        const Rect& p = patches[i];
        // The largest even corner that keeps the square inside the patch, nearest to centred.
        int x = p.x + (p.width - side) / 2, y = p.y + (p.height - side) / 2;
        x += x & 1;
        y += y & 1;
        if (x + side > p.x + p.width)
            x -= 2;
        if (y + side > p.y + p.height)
            y -= 2;
        if (p.width < side || p.height < side || x < p.x || y < p.y)
            CV_Error(Error::StsBadArg,
                     format("cfaAlignedSquares: patch %d (%dx%d at %d,%d) cannot hold a CFA-aligned "
                            "%dx%d square",
                            static_cast<int>(i), p.width, p.height, p.x, p.y, side, side));
        out.emplace_back(x, y, side, side);
    }
    return out;
}

namespace {

void checkSquares(const std::vector<Rect>& squares, Size size, const char* who)
{
    const Rect frame(Point(0, 0), size);
    for (size_t i = 0; i < squares.size(); ++i)
        if ((squares[i] & frame) != squares[i] || squares[i].area() == 0)
            CV_Error(Error::StsBadArg,
                     format("%s: square %d (%dx%d at %d,%d) is empty or outside the %dx%d frame", who,
                            static_cast<int>(i), squares[i].width, squares[i].height, squares[i].x,
                            squares[i].y, size.width, size.height));
}

} // namespace

std::vector<NoiseSample> sampleBurstPatches(const BurstStatistics& stats, const std::vector<Rect>& squares,
                                            double gain)
{
    detail::checkFinitePositive(gain, "sampleBurstPatches: gain");
    Mat mean, var, clipped;
    stats.mean(mean);
    stats.variance(var);
    stats.clippedMask(clipped);
    checkSquares(squares, stats.size(), "sampleBurstPatches");
    std::vector<NoiseSample> out;
    for (const Rect& sq : squares)
        for (int r = sq.y; r < sq.y + sq.height; ++r)
            for (int c = sq.x; c < sq.x + sq.width; ++c) {
                if (clipped.at<uchar>(r, c))
                    continue;
                NoiseSample s;
                s.mean = mean.at<double>(r, c);
                s.variance = var.at<double>(r, c);
                s.gain = gain;
                s.dof = stats.frames() - 1;
                s.channel = cfaChannelAt(stats.format().pattern, r, c);
                out.push_back(s);
            }
    return out;
}

std::vector<NoiseSample> sampleSingleFramePatches(InputArray _raw, const RawFormat& format,
                                                  const std::vector<Rect>& squares, double gain)
{
    detail::checkFinitePositive(gain, "sampleSingleFramePatches: gain");
    format.validate();
    const Mat raw = _raw.getMat();
    if (raw.type() != CV_16UC1 && raw.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, "sampleSingleFramePatches: raw must be CV_16UC1 or CV_32FC1");
    checkSquares(squares, raw.size(), "sampleSingleFramePatches");
    Mat raw64;
    raw.convertTo(raw64, CV_64F);
    if (!checkRange(raw64, true))
        CV_Error(Error::StsBadArg, "sampleSingleFramePatches: raw contains NaN or Inf");
    std::vector<NoiseSample> out;
    for (const Rect& sq : squares) {
        for (int site = 0; site < 4; ++site) {
            // Least squares of v = p0 + p1 x + p2 y over the site's pixels: 3x3 normal equations.
            Matx33d A = Matx33d::zeros();
            Vec3d rhs(0, 0, 0);
            std::vector<Vec3d> points;
            bool isClipped = false;
            for (int r = sq.y + (site / 2 + sq.y) % 2; r < sq.y + sq.height; r += 2)
                for (int c = sq.x + (site % 2 + sq.x) % 2; c < sq.x + sq.width; c += 2) {
                    const double v = raw64.at<double>(r, c);
                    isClipped = isClipped || v <= 0 || v >= format.whiteLevel;
                    const Vec3d f(1.0, c - sq.x, r - sq.y);
                    points.emplace_back(f[1], f[2], v - format.blackAt(r, c));
                    A += f * f.t();
                    rhs += f * (v - format.blackAt(r, c));
                }
            const int n = static_cast<int>(points.size());
            if (isClipped || n < 4)
                continue;
            Vec3d p;
            if (!solve(A, rhs, p, DECOMP_SVD))
                continue;
            double ss = 0, mean = 0;
            for (const Vec3d& q : points) {
                const double fit = p[0] + p[1] * q[0] + p[2] * q[1];
                ss += (q[2] - fit) * (q[2] - fit);
                mean += fit;
            }
            NoiseSample s;
            s.mean = mean / n;
            s.variance = ss / (n - 3);
            s.gain = gain;
            s.dof = n - 3;
            s.channel = cfaChannelAt(format.pattern, sq.y + site / 2, sq.x + site % 2);
            out.push_back(s);
        }
    }
    return out;
}

// ---------------------------------------------------------------------------------------------------
// Per-gain line

namespace {

struct LineLS
{
    double a = 0, b = 0, r2 = 0;
};

/** Least squares of v on mu over the selected samples, weighted by `weights` (empty: unweighted);
 * R^2 is the ordinary one (unweighted sums). False when the means do not vary. */
bool leastSquaresLine(const std::vector<NoiseSample>& s, const std::vector<int>& idx,
                      const std::vector<double>& weights, LineLS& out)
{
    if (idx.size() < 2)
        return false;
    double sw = 0, mx = 0, my = 0;
    for (int i : idx) {
        const double w = weights.empty() ? 1.0 : weights[i];
        sw += w;
        mx += w * s[i].mean;
        my += w * s[i].variance;
    }
    mx /= sw;
    my /= sw;
    double sxx = 0, sxy = 0;
    for (int i : idx) {
        const double w = weights.empty() ? 1.0 : weights[i];
        const double dx = s[i].mean - mx;
        sxx += w * dx * dx;
        sxy += w * dx * (s[i].variance - my);
    }
    if (!(sxx > 1e-12 * std::max(1.0, mx * mx) * sw))
        return false;
    out.a = sxy / sxx;
    out.b = my - out.a * mx;
    double mean = 0;
    for (int i : idx)
        mean += s[i].variance;
    mean /= static_cast<double>(idx.size());
    double ssRes = 0, ssTot = 0;
    for (int i : idx) {
        const double e = s[i].variance - (out.a * s[i].mean + out.b);
        ssRes += e * e;
        ssTot += (s[i].variance - mean) * (s[i].variance - mean);
    }
    out.r2 = ssTot > 0 ? 1.0 - ssRes / ssTot : 1.0;
    return true;
}

/** Iterated weighted least squares: a sample variance of `dof` degrees of freedom has variance
 * 2 v^2 / dof around its expectation v, so each sample is weighted by dof / (2 v^2) with v from the
 * previous line (Fisher scoring for the Gamma likelihood of sample variances). Unlike ordinary least
 * squares, the many precise dark samples then pin the offset instead of the few noisy bright ones. */
bool weightedNoiseLine(const std::vector<NoiseSample>& s, const std::vector<int>& idx, LineLS& out)
{
    if (!leastSquaresLine(s, idx, {}, out))
        return false;
    std::vector<double> w(s.size(), 0.0);
    for (int round = 0; round < 4; ++round) {
        double largest = 0;
        for (int i : idx)
            largest = std::max(largest, out.a * std::max(s[i].mean, 0.0) + out.b);
        // A floor keeps a line that dips to 0 at the darkest mean from giving one sample all the weight.
        const double floor = std::max(1e-6 * largest, 1e-12);
        for (int i : idx) {
            const double v = std::max(out.a * std::max(s[i].mean, 0.0) + out.b, floor);
            w[i] = s[i].dof / (2.0 * v * v);
        }
        LineLS next;
        if (!leastSquaresLine(s, idx, w, next))
            break;
        out = next;
    }
    return true;
}

//! Residual in standard errors of a sample variance around the line at the sample's mean.
double standardizedResidual(const NoiseSample& s, double a, double b)
{
    const double predicted = a * std::max(s.mean, 0.0) + b;
    const double scale = std::sqrt(2.0 / std::max(s.dof, 1)) * std::max(std::abs(predicted), 1e-12);
    return (s.variance - predicted) / scale;
}

std::vector<int> inliersOf(const std::vector<NoiseSample>& s, double a, double b, double threshold)
{
    std::vector<int> idx;
    for (int i = 0; i < static_cast<int>(s.size()); ++i)
        if (std::abs(standardizedResidual(s[i], a, b)) <= threshold)
            idx.push_back(i);
    return idx;
}

void checkSamples(const std::vector<NoiseSample>& samples, const char* who)
{
    for (size_t i = 0; i < samples.size(); ++i) {
        const NoiseSample& s = samples[i];
        if (!std::isfinite(s.mean) || !std::isfinite(s.variance) || !std::isfinite(s.gain) || !(s.gain > 0) ||
            s.variance < 0 || s.dof < 1)
            CV_Error(Error::StsBadArg,
                     format("%s: sample %d is invalid (mean %g, variance %g, gain %g, dof %d): "
                            "values must be finite, variance >= 0, gain > 0, dof >= 1",
                            who, static_cast<int>(i), s.mean, s.variance, s.gain, s.dof));
    }
}

} // namespace

NoiseLineFit fitNoiseLine(const std::vector<NoiseSample>& samples, const LineFitParams& params)
{
    if (samples.size() < 2)
        CV_Error(Error::StsBadArg,
                 format("fitNoiseLine: needs at least 2 samples (got %d)", static_cast<int>(samples.size())));
    checkSamples(samples, "fitNoiseLine");
    for (const NoiseSample& s : samples)
        if (s.gain != samples[0].gain)
            CV_Error(Error::StsBadArg,
                     format("fitNoiseLine: samples of gains %g and %g; fit one gain at a time",
                            samples[0].gain, s.gain));
    if (params.ransacIterations < 1 || !(params.inlierThreshold > 0))
        CV_Error(Error::StsBadArg, "fitNoiseLine: ransacIterations must be >= 1 and inlierThreshold > 0");
    NoiseLineFit fit;
    fit.gain = samples[0].gain;
    fit.samples = static_cast<int>(samples.size());
    std::vector<int> all(samples.size());
    std::iota(all.begin(), all.end(), 0);
    LineLS ls;
    if (!weightedNoiseLine(samples, all, ls))
        CV_Error(Error::StsBadArg, "fitNoiseLine: all samples share one mean; the slope needs at least two "
                                   "distinct means");
    std::vector<int> chosen = all;
    if (params.robust) {
        const int n = static_cast<int>(samples.size());
        size_t bestCount = 0;
        double bestA = ls.a, bestB = ls.b;
        for (int it = 0; it < params.ransacIterations; ++it) {
            detail::CounterRng rng(params.seed, static_cast<uint64_t>(it));
            const int i = static_cast<int>(rng.nextU32() % static_cast<uint32_t>(n));
            const int j = static_cast<int>(rng.nextU32() % static_cast<uint32_t>(n));
            const double dm = samples[j].mean - samples[i].mean;
            if (std::abs(dm) < 1e-9)
                continue;
            const double a = (samples[j].variance - samples[i].variance) / dm;
            const double b = samples[i].variance - a * samples[i].mean;
            size_t count = 0;
            for (const NoiseSample& s : samples)
                count += std::abs(standardizedResidual(s, a, b)) <= params.inlierThreshold ? 1 : 0;
            if (count > bestCount) {
                bestCount = count;
                bestA = a;
                bestB = b;
            }
        }
        // Refine: least squares on the inliers, then once more on the inliers of the refined line.
        for (int round = 0; round < 2; ++round) {
            std::vector<int> inl = inliersOf(samples, bestA, bestB, params.inlierThreshold);
            LineLS refined;
            if (!weightedNoiseLine(samples, inl, refined))
                break;
            chosen.swap(inl);
            ls = refined;
            bestA = ls.a;
            bestB = ls.b;
        }
    }
    fit.line.a = ls.a;
    fit.line.b = ls.b;
    fit.rSquared = ls.r2;
    fit.inliers = static_cast<int>(chosen.size());
    return fit;
}

// ---------------------------------------------------------------------------------------------------
// Cross-gain fits

namespace {

//! b_g = g^2 sigma_d^2 + sigma_r^2 (paper Eq. 8).
struct OffsetResidual
{
    OffsetResidual(double gain, double offset) : g2(gain * gain), b(offset) {}
    template <typename T> bool operator()(const T* sigmaD2, const T* sigmaR2, T* r) const
    {
        r[0] = T(b) - (T(g2) * sigmaD2[0] + sigmaR2[0]);
        return true;
    }
    static ceres::CostFunction* Create(double gain, double offset)
    {
        return new ceres::AutoDiffCostFunction<OffsetResidual, 1, 1, 1>(new OffsetResidual(gain, offset));
    }
    double g2, b;
};

//! (v - (g alpha mu + g^2 sigma_d^2 + sigma_r^2)) / scale: one sample of the joint fit.
struct JointResidual
{
    JointResidual(double mean, double variance, double gain, double invScale)
        : mu(std::max(mean, 0.0)), v(variance), g(gain), w(invScale)
    {
    }
    template <typename T> bool operator()(const T* p, T* r) const
    {
        r[0] = (T(v) - (T(g * mu) * p[0] + T(g * g) * p[1] + p[2])) * T(w);
        return true;
    }
    static ceres::CostFunction* Create(double mean, double variance, double gain, double invScale)
    {
        return new ceres::AutoDiffCostFunction<JointResidual, 1, 3>(
            new JointResidual(mean, variance, gain, invScale));
    }
    double mu, v, g, w;
};

ceres::Solver::Options solverOptions()
{
    ceres::Solver::Options o;
    o.logging_type = ceres::SILENT;
    o.minimizer_progress_to_stdout = false;
    o.linear_solver_type = ceres::DENSE_QR;
    o.max_num_iterations = 200;
    o.function_tolerance = 1e-14;
    o.gradient_tolerance = 1e-14;
    o.parameter_tolerance = 1e-12;
    o.num_threads = 1; // the problems are tiny; one thread keeps results reproducible
    return o;
}

double rSquared(const std::vector<double>& y, const std::vector<double>& fit)
{
    double mean = 0;
    for (double v : y)
        mean += v;
    mean /= y.size();
    double ssTot = 0, ssRes = 0;
    for (size_t i = 0; i < y.size(); ++i) {
        ssTot += (y[i] - mean) * (y[i] - mean);
        ssRes += (y[i] - fit[i]) * (y[i] - fit[i]);
    }
    return ssTot > 0 ? 1.0 - ssRes / ssTot : (ssRes == 0 ? 1.0 : 0.0);
}

//! Two-stage offsets: sigma_d^2, sigma_r^2 >= 0 from (g, b_g) by bounded least squares.
void fitOffsets(const std::vector<NoiseLineFit>& lines, double& sigmaD2, double& sigmaR2)
{
    // Start from the unbounded solution clipped to the bounds.
    double sxx = 0, sx = 0, sy = 0, sxy = 0;
    for (const NoiseLineFit& f : lines) {
        const double x = f.gain * f.gain;
        sxx += x * x;
        sx += x;
        sy += f.line.b;
        sxy += x * f.line.b;
    }
    const double n = static_cast<double>(lines.size());
    const double det = n * sxx - sx * sx;
    sigmaD2 = std::max(0.0, det > 0 ? (n * sxy - sx * sy) / det : 0.0);
    sigmaR2 = std::max(0.0, (sy - sigmaD2 * sx) / n);
    ceres::Problem problem;
    for (const NoiseLineFit& f : lines)
        problem.AddResidualBlock(OffsetResidual::Create(f.gain, f.line.b), nullptr, &sigmaD2, &sigmaR2);
    problem.SetParameterLowerBound(&sigmaD2, 0, 0.0);
    problem.SetParameterLowerBound(&sigmaR2, 0, 0.0);
    ceres::Solver::Summary summary;
    ceres::Solve(solverOptions(), &problem, &summary);
    if (!summary.IsSolutionUsable())
        CV_Error(Error::StsError, "calibrateNoiseModel: the offset fit failed: " + summary.BriefReport());
}

} // namespace

CalibrationReport calibrateNoiseModel(const std::vector<NoiseSample>& samples,
                                      const CalibrationParams& params)
{
    if (samples.empty())
        CV_Error(Error::StsBadArg, "calibrateNoiseModel: no samples (all pixels clipped, or no patches?)");
    checkSamples(samples, "calibrateNoiseModel");
    if (params.method != NOISE_FIT_JOINT && params.method != NOISE_FIT_TWO_STAGE)
        CV_Error(Error::StsBadArg,
                 format("calibrateNoiseModel: unknown method %d", static_cast<int>(params.method)));
    if (!(params.lossScale > 0) || params.reweightIterations < 1 || !(params.minGainRatio >= 1))
        CV_Error(Error::StsBadArg, "calibrateNoiseModel: lossScale must be > 0, reweightIterations >= 1, "
                                   "minGainRatio >= 1");
    CalibrationReport report;
    report.method = params.method;
    report.samples = static_cast<int>(samples.size());

    std::map<double, std::vector<NoiseSample>> byGain;
    for (const NoiseSample& s : samples)
        byGain[s.gain].push_back(s);
    std::vector<NoiseSample> inlierSamples;
    for (auto& entry : byGain) {
        NoiseLineFit fit;
        try {
            fit = fitNoiseLine(entry.second, params.line);
        } catch (const Exception& e) {
            CV_Error(Error::StsBadArg, format("calibrateNoiseModel: gain %g: ", entry.first) + e.err);
        }
        report.perGain.push_back(fit);
        if (fit.line.a < 0 || fit.line.b < 0)
            report.notes.push_back(
                format("gain %g: the line has a negative %s (a = %g, b = %g); the data do not "
                       "follow the model there",
                       fit.gain, fit.line.a < 0 ? "slope" : "offset", fit.line.a, fit.line.b));
        if (params.line.robust) {
            for (int i : inliersOf(entry.second, fit.line.a, fit.line.b, params.line.inlierThreshold))
                inlierSamples.push_back(entry.second[i]);
        } else {
            inlierSamples.insert(inlierSamples.end(), entry.second.begin(), entry.second.end());
        }
    }

    // alpha from a_g = g alpha (least squares through the origin, non-negative).
    double sga = 0, sgg = 0;
    for (const NoiseLineFit& f : report.perGain) {
        sga += f.gain * f.line.a;
        sgg += f.gain * f.gain;
    }
    double alpha = std::max(0.0, sga / sgg);
    const double gainRatio = report.perGain.back().gain / report.perGain.front().gain;
    report.separable = report.perGain.size() >= 2 && gainRatio >= params.minGainRatio;
    if (!report.separable) {
        report.notes.push_back(format("sigma_d^2 and sigma_r^2 are not separable: %s; only alpha is reported "
                                      "(the offset of each gain is in its line)",
                                      report.perGain.size() < 2
                                          ? "a single gain was calibrated"
                                          : "the gains differ by less than minGainRatio"));
        report.model = NoiseModel(alpha, 0.0, 0.0);
        report.samplesUsed = static_cast<int>(inlierSamples.size());
        return report;
    }
    double sigmaD2 = 0, sigmaR2 = 0;
    fitOffsets(report.perGain, sigmaD2, sigmaR2);

    if (params.method == NOISE_FIT_JOINT) {
        double p[3] = {alpha, sigmaD2, sigmaR2};
        for (int round = 0; round < params.reweightIterations; ++round) {
            // Weights from the previous fit: the standard deviation of a sample variance is
            // sqrt(2 / dof) times its expectation.
            double prev[3] = {p[0], p[1], p[2]};
            ceres::Problem problem;
            for (const NoiseSample& s : inlierSamples) {
                const double predicted =
                    s.gain * prev[0] * std::max(s.mean, 0.0) + s.gain * s.gain * prev[1] + prev[2];
                const double scale = std::sqrt(2.0 / s.dof) * std::max(predicted, 1e-9);
                ceres::LossFunction* loss =
                    params.line.robust ? new ceres::HuberLoss(params.lossScale) : nullptr;
                problem.AddResidualBlock(JointResidual::Create(s.mean, s.variance, s.gain, 1.0 / scale), loss,
                                         p);
            }
            for (int k = 0; k < 3; ++k)
                problem.SetParameterLowerBound(p, k, 0.0);
            ceres::Solver::Summary summary;
            ceres::Solve(solverOptions(), &problem, &summary);
            if (!summary.IsSolutionUsable())
                CV_Error(Error::StsError,
                         "calibrateNoiseModel: the joint fit failed: " + summary.BriefReport());
        }
        alpha = p[0];
        sigmaD2 = p[1];
        sigmaR2 = p[2];
    }
    report.model = NoiseModel(alpha, sigmaD2, sigmaR2);
    report.samplesUsed = static_cast<int>(inlierSamples.size());
    const char* names[3] = {"alpha", "sigma_d^2", "sigma_r^2"};
    const double values[3] = {alpha, sigmaD2, sigmaR2};
    for (int k = 0; k < 3; ++k)
        if (values[k] == 0)
            report.notes.push_back(std::string(names[k]) +
                                   " is at its lower bound 0: the data cannot tell it from 0");

    std::vector<double> a, aFit, b, bFit;
    for (const NoiseLineFit& f : report.perGain) {
        a.push_back(f.line.a);
        aFit.push_back(f.gain * alpha);
        b.push_back(f.line.b);
        bFit.push_back(f.gain * f.gain * sigmaD2 + sigmaR2);
    }
    report.rSquaredSlope = rSquared(a, aFit);
    report.rSquaredOffset = rSquared(b, bFit);
    return report;
}

// ---------------------------------------------------------------------------------------------------
// Report I/O

void CalibrationReport::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    fs << "format_version" << FORMAT_VERSION;
    fs << "method" << (method == NOISE_FIT_JOINT ? "joint" : "two_stage");
    fs << "separable" << static_cast<int>(separable);
    model.write(fs, "noise_model");
    fs << "r_squared_slope" << rSquaredSlope;
    fs << "r_squared_offset" << rSquaredOffset;
    fs << "samples" << samples;
    fs << "samples_used" << samplesUsed;
    fs << "per_gain"
       << "[";
    for (const NoiseLineFit& f : perGain) {
        fs << "{";
        fs << "gain" << f.gain << "gain_db" << linearGainToDb(f.gain) << "a" << f.line.a << "b" << f.line.b;
        fs << "r_squared" << f.rSquared << "inliers" << f.inliers << "samples" << f.samples;
        fs << "}";
    }
    fs << "]";
    fs << "notes"
       << "[";
    for (const std::string& n : notes)
        fs << n;
    fs << "]";
    fs << "}";
}

CalibrationReport CalibrationReport::read(const FileNode& node)
{
    if (node.empty() || !node.isMap())
        CV_Error(Error::StsParseError, "calibration report: expected a map");
    const FileNode version = node["format_version"];
    if (!version.isInt() || static_cast<int>(version) < 1 || static_cast<int>(version) > FORMAT_VERSION)
        CV_Error(Error::StsParseError,
                 format("calibration report: format_version is missing or newer than %d", FORMAT_VERSION));
    CalibrationReport r;
    const FileNode method = node["method"];
    if (!method.isString() || (method.string() != "joint" && method.string() != "two_stage"))
        CV_Error(Error::StsParseError, "calibration report: field 'method' must be 'joint' or 'two_stage'");
    r.method = method.string() == "joint" ? NOISE_FIT_JOINT : NOISE_FIT_TWO_STAGE;
    r.separable = detail::readRealField(node, "separable") != 0;
    r.model = NoiseModel::read(node["noise_model"]);
    r.rSquaredSlope = detail::readRealField(node, "r_squared_slope");
    r.rSquaredOffset = detail::readRealField(node, "r_squared_offset");
    r.samples = static_cast<int>(detail::readRealField(node, "samples"));
    r.samplesUsed = static_cast<int>(detail::readRealField(node, "samples_used"));
    const FileNode perGain = node["per_gain"];
    if (!perGain.isSeq())
        CV_Error(Error::StsParseError, "calibration report: field 'per_gain' is missing or not a list");
    for (const FileNode& g : perGain) {
        NoiseLineFit f;
        f.gain = detail::readRealField(g, "gain");
        f.line.a = detail::readRealField(g, "a");
        f.line.b = detail::readRealField(g, "b");
        f.rSquared = detail::readRealField(g, "r_squared");
        f.inliers = static_cast<int>(detail::readRealField(g, "inliers"));
        f.samples = static_cast<int>(detail::readRealField(g, "samples"));
        r.perGain.push_back(f);
    }
    for (const FileNode& n : node["notes"])
        r.notes.push_back(n.string());
    return r;
}

void CalibrationReport::save(const String& path) const
{
    detail::writeFileStorageAtomically(path, [&](FileStorage& fs) { write(fs, "calibration_report"); });
}

CalibrationReport CalibrationReport::load(const String& path)
{
    return detail::loadFileStorage(path, "calibration_report", "calibration report",
                                   [](const FileNode& n) { return read(n); });
}

} // namespace rawgment
} // namespace cv
