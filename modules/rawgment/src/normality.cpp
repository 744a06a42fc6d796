// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "opencv2/rawgment/normality.hpp"
#include "precomp.hpp"

#include <opencv2/core/hal/intrin.hpp>

#include <algorithm>
#include <atomic>
#include <limits>

namespace cv {
namespace rawgment {

namespace detail {

/** Standard normal quantile for p in (0, 0.5]: Abramowitz & Stegun 26.2.23 as a start (error below
 * 4.5e-4), then Halley steps on the erfc-based CDF. Each step triples the number of correct digits, so
 * three steps reach the precision of erfc itself (about 1e-16 relative), which is what the AS R94
 * coefficients need to agree with R's qnorm to 1e-15. */
double lowerNormalQuantile(double p)
{
    const double t = std::sqrt(-2.0 * std::log(p));
    double x = -(t - (2.515517 + t * (0.802853 + t * 0.010328)) /
                         (1.0 + t * (1.432788 + t * (0.189269 + t * 0.001308))));
    for (int iter = 0; iter < 4; ++iter) {
        const double cdf = 0.5 * std::erfc(-x / std::sqrt(2.0));
        const double pdf = std::exp(-0.5 * x * x) / std::sqrt(2.0 * CV_PI);
        const double step = (cdf - p) / pdf;
        x -= step / (1.0 + 0.5 * x * step); // Halley's correction
    }
    return x;
}

} // namespace detail

namespace {

using detail::lowerNormalQuantile;

const int kMinSamples = 3;
const int kMaxSamples = 5000;

//! c[0] + c[1] x + ... + c[count-1] x^(count-1), Horner's scheme.
double polynomial(const double* c, int count, double x)
{
    double r = c[count - 1];
    for (int i = count - 2; i >= 0; --i)
        r = r * x + c[i];
    return r;
}

//! Standard normal upper tail P(Z > z), accurate in relative terms far into both tails.
double normalUpperTail(double z)
{
    return 0.5 * std::erfc(z / std::sqrt(2.0));
}

/** The AS R94 coefficients for one sample size, centred, and the test of a sorted sample. */
class ShapiroWilkCoefficients
{
public:
    explicit ShapiroWilkCoefficients(int n) : n_(n), a_(n, 0.0)
    {
        const int half = n / 2;
        std::vector<double> m(half);
        if (n == 3) {
            m[0] = std::sqrt(0.5);
        } else {
            // Royston's approximation: normal scores m_i, then polynomial corrections of the two
            // extreme coefficients in 1/sqrt(n) and a common rescaling of the others.
            static const double c1[6] = {0.0, 0.221157, -0.147981, -2.07119, 4.434685, -2.706056};
            static const double c2[6] = {0.0, 0.042981, -0.293762, -1.752461, 5.682633, -3.582633};
            double sumM2 = 0;
            for (int i = 0; i < half; ++i) {
                m[i] = lowerNormalQuantile((i + 1 - 0.375) / (n + 0.25)); // negative
                sumM2 += m[i] * m[i];
            }
            sumM2 *= 2.0;
            const double rootSumM2 = std::sqrt(sumM2);
            const double u = 1.0 / std::sqrt(static_cast<double>(n));
            const double a1 = polynomial(c1, 6, u) - m[0] / rootSumM2;
            int first = 1;
            double scale;
            if (n > 5) {
                const double a2 = polynomial(c2, 6, u) - m[1] / rootSumM2;
                scale = std::sqrt((sumM2 - 2.0 * m[0] * m[0] - 2.0 * m[1] * m[1]) /
                                  (1.0 - 2.0 * a1 * a1 - 2.0 * a2 * a2));
                m[1] = a2;
                first = 2;
            } else {
                scale = std::sqrt((sumM2 - 2.0 * m[0] * m[0]) / (1.0 - 2.0 * a1 * a1));
            }
            m[0] = a1;
            for (int i = first; i < half; ++i)
                m[i] = -m[i] / scale;
        }
        // Full antisymmetric vector over the sorted sample: -a_i on the low side, +a_i on the high side.
        for (int i = 0; i < half; ++i) {
            a_[i] = -m[i];
            a_[n - 1 - i] = m[i];
        }
        double mean = 0;
        for (double v : a_)
            mean += v;
        mean /= n;
        sumSqA_ = 0;
        for (double& v : a_) {
            v -= mean;
            sumSqA_ += v * v;
        }
    }

    int size() const { return n_; }

    //! x: n finite values sorted ascending.
    ShapiroWilkResult testSorted(const double* x) const
    {
        ShapiroWilkResult r;
        r.n = n_;
        // W does not depend on the scale. A power of two is an exact scale: it changes no bit of an
        // ordinary sample's W and brings both ends of a huge (+-1.7e308) or denormal sample to about 1,
        // where their range and squares exist.
        const double big = std::max(std::abs(x[0]), std::abs(x[n_ - 1]));
        // (in two factors: 2^1029 for a denormal sample is itself beyond a double).
        const int shift = big > 0 ? -std::ilogb(big) : 0;
        const double s1 = std::ldexp(1.0, shift / 2), s2 = std::ldexp(1.0, shift - shift / 2);
        const double lo = x[0] * s1 * s2, range = x[n_ - 1] * s1 * s2 - lo;
        if (!(range > 0)) {
            r.constant = true;
            return r;
        }
        const double inv = 1.0 / range;
        // Four partial sums: independent of the thread count, and short dependency chains.
        double s[4] = {0, 0, 0, 0};
        int i = 0;
        for (; i + 3 < n_; i += 4)
            for (int k = 0; k < 4; ++k)
                s[k] += (x[i + k] * s1 * s2 - lo) * inv;
        for (; i < n_; ++i)
            s[0] += (x[i] * s1 * s2 - lo) * inv;
        const double mean = ((s[0] + s[1]) + (s[2] + s[3])) / n_;
        double sxx[4] = {0, 0, 0, 0}, sax[4] = {0, 0, 0, 0};
        i = 0;
        for (; i + 3 < n_; i += 4)
            for (int k = 0; k < 4; ++k) {
                const double d = (x[i + k] * s1 * s2 - lo) * inv - mean;
                sxx[k] += d * d;
                sax[k] += a_[i + k] * d;
            }
        for (; i < n_; ++i) {
            const double d = (x[i] * s1 * s2 - lo) * inv - mean;
            sxx[0] += d * d;
            sax[0] += a_[i] * d;
        }
        const double ssx = (sxx[0] + sxx[1]) + (sxx[2] + sxx[3]);
        const double sa = (sax[0] + sax[1]) + (sax[2] + sax[3]);
        // 1 - W = 1 - sax^2 / (ssa ssx), as a product of two differences: exact near W = 1.
        const double root = std::sqrt(sumSqA_ * ssx);
        const double w1 = std::max(0.0, (root - sa) * (root + sa) / (sumSqA_ * ssx));
        r.W = std::min(1.0, std::max(0.0, 1.0 - w1));
        r.pValue = pValue(r.W, w1);
        return r;
    }

private:
    double pValue(double w, double w1) const
    {
        if (n_ == 3) {
            // Exact: W of three normal values is distributed as sin^2 of a uniform angle on [pi/3, pi/2].
            const double p = 6.0 / CV_PI * (std::asin(std::sqrt(w)) - CV_PI / 3.0);
            return std::min(1.0, std::max(0.0, p));
        }
        double y = std::log(w1); // -inf for W = 1: the upper tail below is then exactly 1
        const double logN = std::log(static_cast<double>(n_));
        double mu, sigma;
        if (n_ <= 11) {
            static const double g[2] = {-2.273, 0.459};
            static const double c3[4] = {0.544, -0.39978, 0.025054, -6.714e-4};
            static const double c4[4] = {1.3822, -0.77857, 0.062767, -0.0020322};
            const double gamma = polynomial(g, 2, n_);
            if (y >= gamma)
                return 1e-99; // beyond the range of the approximation: as R, an "obviously" tiny value
            y = -std::log(gamma - y);
            mu = polynomial(c3, 4, n_);
            sigma = std::exp(polynomial(c4, 4, n_));
        } else {
            static const double c5[4] = {-1.5861, -0.31082, -0.083751, 0.0038915};
            static const double c6[3] = {-0.4803, -0.082676, 0.0030302};
            mu = polynomial(c5, 4, logN);
            sigma = std::exp(polynomial(c6, 3, logN));
        }
        return normalUpperTail((y - mu) / sigma);
    }

    int n_;
    std::vector<double> a_;
    double sumSqA_ = 0;
};

/** Batcher's odd-even merge sorting network for n values, run on `kLanes` series at once.
 *
 * std::sort of 100 random doubles spends most of its time on mispredicted branches. A sorting network
 * has no data-dependent branches: every comparator is a min and a max, which the compiler vectorises
 * across the lanes (series) of a block. The network is built for the next power of two and every
 * comparator that touches an index >= n is dropped, which is the same as padding with +infinity. */
class LaneSortingNetwork
{
public:
    static constexpr int kLanes = 8;
    //! Networks grow as n log^2 n; above this size std::sort per series is as fast.
    static constexpr int kMaxSize = 512;

    explicit LaneSortingNetwork(int n)
    {
        int size = 1;
        while (size < n)
            size <<= 1;
        for (int p = 1; p < size; p <<= 1)
            for (int k = p; k >= 1; k >>= 1)
                for (int j = k % p; j + k < size; j += 2 * k)
                    for (int i = 0; i < std::min(k, size - j - k); ++i)
                        if ((i + j) / (2 * p) == (i + j + k) / (2 * p) && i + j + k < n)
                            pairs_.emplace_back(i + j, i + j + k);
    }

    //! x holds n rows of kLanes values (x[i * kLanes + lane]); sorts each lane ascending.
    void sort(double* x) const
    {
        for (const auto& pair : pairs_) {
            double* lo = x + pair.first * kLanes;
            double* hi = x + pair.second * kLanes;
#if CV_SIMD128_64F
            constexpr int step = v_float64x2::nlanes;
            for (int l = 0; l < kLanes; l += step) {
                const v_float64x2 a = v_load(lo + l), b = v_load(hi + l);
                v_store(lo + l, v_min(a, b));
                v_store(hi + l, v_max(a, b));
            }
#else
            for (int l = 0; l < kLanes; ++l) {
                const double a = lo[l], b = hi[l];
                lo[l] = b < a ? b : a;
                hi[l] = b < a ? a : b;
            }
#endif
        }
    }

private:
    std::vector<std::pair<int, int>> pairs_;
};

void checkSampleSize(int n)
{
    if (n < kMinSamples || n > kMaxSamples)
        CV_Error(Error::StsBadArg, format("Shapiro-Wilk needs between %d and %d values per sample (got %d)",
                                          kMinSamples, kMaxSamples, n));
}

void checkNumeric(const Mat& m, const char* what)
{
    if (m.channels() != 1)
        CV_Error(Error::StsBadArg,
                 format("%s has %d channels; expected a single-channel numeric Mat", what, m.channels()));
    if (m.depth() > CV_64F)
        CV_Error(Error::StsBadArg, format("%s has depth %d; expected CV_8U to CV_64F", what, m.depth()));
}

//! Copies `count` values starting at `p` with a stride of `step` bytes into out; false on NaN or Inf.
template <typename T> bool gatherStrided(const uchar* p, size_t step, int count, double* out)
{
    bool finite = true;
    for (int i = 0; i < count; ++i, p += step) {
        out[i] = static_cast<double>(*reinterpret_cast<const T*>(p));
        finite = finite && std::isfinite(out[i]);
    }
    return finite;
}

bool gather(int depth, const uchar* p, size_t step, int count, double* out)
{
    switch (depth) {
    case CV_8U:
        return gatherStrided<uchar>(p, step, count, out);
    case CV_8S:
        return gatherStrided<schar>(p, step, count, out);
    case CV_16U:
        return gatherStrided<ushort>(p, step, count, out);
    case CV_16S:
        return gatherStrided<short>(p, step, count, out);
    case CV_32S:
        return gatherStrided<int>(p, step, count, out);
    case CV_32F:
        return gatherStrided<float>(p, step, count, out);
    default:
        return gatherStrided<double>(p, step, count, out);
    }
}

//! Records the smallest index passed to it, from any thread.
class FirstIndex
{
public:
    void offer(int index)
    {
        int current = value_.load();
        while (index < current && !value_.compare_exchange_weak(current, index)) {
        }
    }
    bool any() const { return value_.load() != std::numeric_limits<int>::max(); }
    int get() const { return value_.load(); }

private:
    std::atomic<int> value_{std::numeric_limits<int>::max()};
};

/** Sorts `count` series of length n in parallel and hands each sorted series to `emit(s, sorted)`.
 * `load(s, out)` writes series s into out and returns false when it holds NaN or Inf; the smallest
 * such s is recorded in firstBad and its block is skipped. Each series is processed by exactly one
 * task and written only to its own slot, so results do not depend on the number of threads. */
template <typename Load, typename Emit>
void forEachSortedSeries(int count, int n, const Load& load, const Emit& emit, FirstIndex& firstBad)
{
    if (n > LaneSortingNetwork::kMaxSize) {
        parallel_for_(Range(0, count), [&](const Range& range) {
            std::vector<double> x(n);
            for (int s = range.start; s < range.end; ++s) {
                if (!load(s, x.data())) {
                    firstBad.offer(s);
                    continue;
                }
                std::sort(x.begin(), x.end());
                emit(s, x.data());
            }
        });
        return;
    }
    // Blocks of kLanes series sorted together; the last block pads with copies of its last series.
    const int lanes = LaneSortingNetwork::kLanes;
    const LaneSortingNetwork network(n);
    const int blocks = (count + lanes - 1) / lanes;
    parallel_for_(Range(0, blocks), [&](const Range& range) {
        std::vector<double> block(static_cast<size_t>(n) * lanes), x(n);
        for (int b = range.start; b < range.end; ++b) {
            bool finite = true;
            for (int l = 0; l < lanes; ++l) {
                const int s = std::min(b * lanes + l, count - 1);
                if (!load(s, x.data())) {
                    firstBad.offer(s);
                    finite = false;
                }
                for (int i = 0; i < n; ++i)
                    block[static_cast<size_t>(i) * lanes + l] = x[i];
            }
            if (!finite)
                continue;
            network.sort(block.data());
            for (int l = 0; l < lanes && b * lanes + l < count; ++l) {
                for (int i = 0; i < n; ++i)
                    x[i] = block[static_cast<size_t>(i) * lanes + l];
                emit(b * lanes + l, x.data());
            }
        }
    });
}

} // namespace

ShapiroWilkResult shapiroWilk(InputArray _samples)
{
    const Mat samples = detail::twoDimensional(_samples, "shapiroWilk: samples");
    checkNumeric(samples, "shapiroWilk: samples");
    const int n = static_cast<int>(samples.total());
    checkSampleSize(n);
    std::vector<double> x(n);
    // Any shape: walk the rows so that non-continuous views (a column of a larger Mat) work.
    const Mat rows = samples.isContinuous() ? samples.reshape(1, 1) : samples;
    bool finite = true;
    for (int r = 0, k = 0; r < rows.rows; ++r, k += rows.cols)
        finite = gather(rows.depth(), rows.ptr(r), rows.elemSize(), rows.cols, x.data() + k) && finite;
    if (!finite)
        CV_Error(Error::StsBadArg, "shapiroWilk: samples contain NaN or Inf");
    std::sort(x.begin(), x.end());
    return ShapiroWilkCoefficients(n).testSorted(x.data());
}

void shapiroWilkBatch(InputArray _series, std::vector<ShapiroWilkResult>& results, ShapiroWilkLayout layout)
{
    const Mat series = detail::twoDimensional(_series, "shapiroWilkBatch: series");
    if (series.empty())
        CV_Error(Error::StsBadArg, "shapiroWilkBatch: series is empty");
    checkNumeric(series, "shapiroWilkBatch: series");
    if (series.dims != 2)
        CV_Error(Error::StsBadArg, "shapiroWilkBatch: series must be a 2-D Mat");
    if (layout != SW_SERIES_IN_COLUMNS && layout != SW_SERIES_IN_ROWS)
        CV_Error(Error::StsBadArg, format("shapiroWilkBatch: layout %d is not SW_SERIES_IN_COLUMNS or "
                                          "SW_SERIES_IN_ROWS",
                                          static_cast<int>(layout)));
    const bool inColumns = layout == SW_SERIES_IN_COLUMNS;
    const int n = inColumns ? series.rows : series.cols;
    const int count = inColumns ? series.cols : series.rows;
    checkSampleSize(n);
    const ShapiroWilkCoefficients coefficients(n);
    const size_t valueStep = inColumns ? series.step[0] : series.elemSize();
    std::vector<ShapiroWilkResult> out(count);
    FirstIndex firstBad;
    const int depth = series.depth();
    forEachSortedSeries(
        count, n,
        [&](int s, double* x) {
            const uchar* start = inColumns ? series.ptr(0) + s * series.elemSize() : series.ptr(s);
            return gather(depth, start, valueStep, n, x);
        },
        [&](int s, const double* sorted) { out[s] = coefficients.testSorted(sorted); }, firstBad);
    if (firstBad.any())
        CV_Error(Error::StsBadArg, format("shapiroWilkBatch: series %d contains NaN or Inf", firstBad.get()));
    results.swap(out);
}

BurstNormality shapiroWilkBurst(InputArrayOfArrays _frames, const std::vector<Point>& positions)
{
    std::vector<Mat> frames;
    _frames.getMatVector(frames);
    const int n = static_cast<int>(frames.size());
    checkSampleSize(n);
    for (int t = 0; t < n; ++t) {
        if (frames[t].empty())
            CV_Error(Error::StsBadArg, format("shapiroWilkBurst: frame %d is empty", t));
        detail::twoDimensional(frames[t], "shapiroWilkBurst: frame");
        checkNumeric(frames[t], "shapiroWilkBurst: frame");
        if (frames[t].size() != frames[0].size() || frames[t].type() != frames[0].type())
            CV_Error(Error::StsBadArg,
                     format("shapiroWilkBurst: frame %d is %dx%d of type %s; every frame must "
                            "match frame 0 (%dx%d of type %s)",
                            t, frames[t].cols, frames[t].rows, typeToString(frames[t].type()).c_str(),
                            frames[0].cols, frames[0].rows, typeToString(frames[0].type()).c_str()));
    }
    BurstNormality burst;
    if (positions.empty()) {
        burst.positions.reserve(frames[0].total());
        for (int r = 0; r < frames[0].rows; ++r)
            for (int c = 0; c < frames[0].cols; ++c)
                burst.positions.emplace_back(c, r);
    } else {
        const Rect frameRect(Point(0, 0), frames[0].size());
        for (size_t i = 0; i < positions.size(); ++i)
            if (!frameRect.contains(positions[i]))
                CV_Error(Error::StsBadArg,
                         format("shapiroWilkBurst: position %d (%d, %d) lies outside the %dx%d frame",
                                static_cast<int>(i), positions[i].x, positions[i].y, frameRect.width,
                                frameRect.height));
        burst.positions = positions;
    }
    const int count = static_cast<int>(burst.positions.size());
    burst.mean.resize(count);
    burst.distinctValues.resize(count);
    burst.results.resize(count);
    const ShapiroWilkCoefficients coefficients(n);
    const int depth = frames[0].depth();
    const size_t elem = frames[0].elemSize();
    FirstIndex firstBad;
    forEachSortedSeries(
        count, n,
        [&](int i, double* x) {
            const Point p = burst.positions[i];
            bool finite = true;
            for (int t = 0; t < n; ++t)
                finite = gather(depth, frames[t].ptr(p.y) + p.x * elem, 0, 1, x + t) && finite;
            return finite;
        },
        [&](int i, const double* sorted) {
            double sum = 0;
            int distinct = 1;
            for (int t = 0; t < n; ++t) {
                sum += sorted[t];
                distinct += (t > 0 && sorted[t] != sorted[t - 1]) ? 1 : 0;
            }
            burst.mean[i] = sum / n;
            burst.distinctValues[i] = distinct;
            burst.results[i] = coefficients.testSorted(sorted);
        },
        firstBad);
    if (firstBad.any()) {
        const Point p = burst.positions[firstBad.get()];
        CV_Error(Error::StsBadArg,
                 format("shapiroWilkBurst: the series at (%d, %d) contains NaN or Inf", p.x, p.y));
    }
    return burst;
}

std::vector<NormalityBin> summarizeNormality(const BurstNormality& burst, int bins, double alpha)
{
    if (bins < 1)
        CV_Error(Error::StsBadArg, format("summarizeNormality: bins must be >= 1 (got %d)", bins));
    if (!(alpha > 0 && alpha < 1))
        CV_Error(Error::StsBadArg, format("summarizeNormality: alpha must lie in (0, 1) (got %g)", alpha));
    const size_t count = burst.results.size();
    if (burst.mean.size() != count || burst.distinctValues.size() != count)
        CV_Error(Error::StsBadArg,
                 "summarizeNormality: the burst's mean, distinctValues and results differ in length");
    std::vector<NormalityBin> out(bins);
    if (count == 0)
        return out;
    const auto range = std::minmax_element(burst.mean.begin(), burst.mean.end());
    const double lo = *range.first, hi = *range.second;
    const double width = (hi - lo) / bins;
    for (int b = 0; b < bins; ++b) {
        out[b].meanLow = lo + b * width;
        out[b].meanHigh = b + 1 == bins ? hi : lo + (b + 1) * width;
    }
    std::vector<std::vector<double>> pValues(bins);
    std::vector<double> distinctSum(bins, 0.0);
    std::vector<int> above(bins, 0);
    for (size_t i = 0; i < count; ++i) {
        const int b = width > 0 ? std::min(bins - 1, static_cast<int>((burst.mean[i] - lo) / width)) : 0;
        pValues[b].push_back(burst.results[i].pValue);
        distinctSum[b] += burst.distinctValues[i];
        above[b] += burst.results[i].pValue > alpha ? 1 : 0;
    }
    for (int b = 0; b < bins; ++b) {
        std::vector<double>& p = pValues[b];
        out[b].count = static_cast<int>(p.size());
        if (p.empty())
            continue;
        out[b].fractionAboveAlpha = static_cast<double>(above[b]) / p.size();
        out[b].meanDistinctValues = distinctSum[b] / p.size();
        std::sort(p.begin(), p.end());
        const size_t mid = p.size() / 2;
        out[b].medianPValue = p.size() % 2 ? p[mid] : 0.5 * (p[mid - 1] + p[mid]);
    }
    return out;
}

} // namespace rawgment
} // namespace cv
