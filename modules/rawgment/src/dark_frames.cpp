// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The fixed pattern and the temporal noise of dark frames (dark_frames.hpp).
#include "dark_frames.hpp"

#include "normal_quantile.hpp"

#include <algorithm>
#include <cmath>

namespace cv {
namespace rawgment {

double DarkFrameStatistics::fixedPatternRms() const
{
    return std::sqrt((patternVariance[0] + patternVariance[1] + patternVariance[2] + patternVariance[3]) / 4);
}

namespace detail {

double chiSquareUpperQuantileOverDof(int k, double p)
{
    CV_Assert(k >= 1 && p > 0 && p < 0.5);
    const double z = -lowerNormalQuantile(p), a = 2.0 / (9.0 * k);
    const double root = 1.0 - a + z * std::sqrt(a);
    return root * root * root;
}

namespace {

// The median of chi2(k) / k (Wilson and Hilferty): a row's median variance over it is the row's variance,
// whatever few noisy pixels the row holds.
double chiSquareMedianOverDof(int k)
{
    const double root = 1.0 - 2.0 / (9.0 * k);
    return root * root * root;
}

double medianOf(std::vector<double>& v)
{
    CV_Assert(!v.empty());
    const size_t half = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<long>(half), v.end());
    const double upper = v[half];
    if (v.size() % 2)
        return upper;
    return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<long>(half)));
}

// The quartiles of chi2(k) / k (Wilson and Hilferty).
double chiSquareInterquartileOverDof(int k)
{
    const double a = 2.0 / (9.0 * k), z = 0.6744897501960817;
    return std::pow(1.0 - a + z * std::sqrt(a), 3) - std::pow(1.0 - a - z * std::sqrt(a), 3);
}

/* The degrees of freedom k <= most whose chi2(k) / k has the interquartile range of `ratios` (each variance
 * over its row's typical one): most when they scatter no more than that. */
int effectiveDegreesOfFreedom(std::vector<double>& ratios, int most)
{
    const size_t q1 = ratios.size() / 4, q3 = (3 * ratios.size()) / 4;
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<long>(q1), ratios.end());
    const double lower = ratios[q1];
    std::nth_element(ratios.begin(), ratios.begin() + static_cast<long>(q3), ratios.end());
    const double iqr = ratios[q3] - lower;
    int k = most;
    while (k > 1 && chiSquareInterquartileOverDof(k) < iqr)
        --k;
    return k;
}

/* The noisy pixels of a burst's variances: beyond the chi-square threshold of `falseAlarm` over their row's
 * typical variance at their column parity, with the degrees of freedom the variances do scatter with. Fills
 * e.degreesOfFreedom, e.noisyPixels, e.noisyVariance and e.rowVariance (each row's pooled variance without
 * them); returns the mask of noisy pixels (1). */
Mat flagNoisyPixels(const Mat& variance, int M, double falseAlarm, DarkFrameStatistics& e)
{
    const int rows = variance.rows, cols = variance.cols;
    e.rowVariance.create(rows, 2, CV_64FC1);
    // A row's typical variance at one column parity: its median over the median of chi2(k) / k, and at least
    // 1/12 DN^2, the variance of rounding to whole DN. Below it integer frames do not resolve noise: with 0.2
    // DN of it most pixels never change, the median is 0, and a pixel that flickers once in eight frames
    // (variance 1/8) would be called noisy.
    const auto typicalVariance = [&](int r, int parity, int k, std::vector<double>& values) {
        const double* v = variance.ptr<double>(r);
        values.clear();
        for (int c = parity; c < cols; c += 2)
            values.push_back(v[c]);
        return std::max(medianOf(values) / chiSquareMedianOverDof(k), 1.0 / 12);
    };
    // Heavy-tailed read noise scatters the sample variances more than M - 1 degrees of freedom say (with
    // Tukey lambda -0.1 and 25 frames, the chi-square threshold flagged 0.2% of ordinary pixels as noisy).
    // The degrees of freedom they do scatter with come from the interquartile range of each variance over
    // its row's, which the few noisy pixels leave alone.
    std::vector<double> values, ratios;
    ratios.reserve(variance.total());
    for (int r = 0; r < rows; ++r)
        for (int parity = 0; parity < 2; ++parity) {
            const double typical = typicalVariance(r, parity, M - 1, values);
            const double* v = variance.ptr<double>(r);
            for (int c = parity; c < cols; c += 2)
                ratios.push_back(typical > 0 ? v[c] / typical : 1.0);
        }
    const int dof = effectiveDegreesOfFreedom(ratios, M - 1);
    e.degreesOfFreedom = dof;
    const double threshold = detail::chiSquareUpperQuantileOverDof(dof, falseAlarm);
    Mat noisy(rows, cols, CV_8UC1, Scalar(0));
    for (int r = 0; r < rows; ++r) {
        const double* v = variance.ptr<double>(r);
        for (int parity = 0; parity < 2; ++parity) {
            const double typical = typicalVariance(r, parity, dof, values);
            double sum = 0;
            int n = 0;
            for (int c = parity; c < cols; c += 2) {
                if (v[c] > threshold * typical) {
                    noisy.at<uchar>(r, c) = 1;
                    e.noisyPixels.emplace_back(c, r);
                    e.noisyVariance.push_back(v[c]);
                } else {
                    sum += v[c];
                    ++n;
                }
            }
            // A row whose every pixel is noisy keeps the typical figure: there is nothing else to pool.
            e.rowVariance.at<double>(r, parity) = n > 0 ? sum / n : typical;
        }
    }
    return noisy;
}

// Per site: the level, the spatial variance of the means and the temporal variance each mean holds.
void siteFigures(const Mat& mean, const Mat& variance, const Mat& noisy, int M, DarkFrameStatistics& e)
{
    double sum[4] = {0, 0, 0, 0}, sum2[4] = {0, 0, 0, 0}, own[4] = {0, 0, 0, 0}, pooled[4] = {0, 0, 0, 0};
    double count[4] = {0, 0, 0, 0}, pooledCount[4] = {0, 0, 0, 0};
    for (int r = 0; r < mean.rows; ++r) {
        const double* m = mean.ptr<double>(r);
        const double* v = variance.ptr<double>(r);
        const uchar* flagged = noisy.ptr<uchar>(r);
        for (int c = 0; c < mean.cols; ++c) {
            const int s = cfaSite(r, c);
            sum[s] += m[c];
            sum2[s] += m[c] * m[c];
            own[s] += v[c];
            count[s] += 1;
            if (!flagged[c]) {
                pooled[s] += v[c];
                pooledCount[s] += 1;
            }
        }
    }
    for (int s = 0; s < 4; ++s) {
        const double n = count[s];
        if (n == 0) // a frame of one row or one column has two sites only
            continue;
        e.level[s] = sum[s] / n;
        e.meanVariance[s] = n > 1 ? (sum2[s] - sum[s] * sum[s] / n) / (n - 1) : 0.0;
        // E[Var(m)] = s_F^2 + mean(v) / M, each pixel's own variance unbiased for its own noise.
        e.patternVariance[s] = std::max(0.0, e.meanVariance[s] - own[s] / n / M);
        e.temporalVariance[s] = pooledCount[s] > 0 ? pooled[s] / pooledCount[s] : own[s] / n;
    }
}

/* The shrinkage is the bulk's: a site's centre and spread from the median and interquartile range of its
 * means, which its hot pixels (a few far out, thousands of DN) leave alone. Those, beyond 6 robust standard
 * deviations of the means (`outlier`), are pattern beyond doubt and kept as measured. With the plain variance
 * 0.2% of hot pixels made every w 1 on a simulated sensor: no shrinkage at all, the mean's whole v/M kept. */
struct RobustSites
{
    double centre[4], spread[4], outlier[4];
};

RobustSites robustSites(const Mat& mean, int M, DarkFrameStatistics& e)
{
    RobustSites robust;
    std::vector<double> site[4];
    for (int r = 0; r < mean.rows; ++r) {
        const double* m = mean.ptr<double>(r);
        for (int c = 0; c < mean.cols; ++c)
            site[cfaSite(r, c)].push_back(m[c]);
    }
    for (int s = 0; s < 4; ++s) {
        std::vector<double>& x = site[s];
        if (x.empty()) {
            robust.centre[s] = robust.spread[s] = robust.outlier[s] = 0;
            continue;
        }
        const size_t q1 = x.size() / 4, q3 = (3 * x.size()) / 4;
        std::nth_element(x.begin(), x.begin() + long(q1), x.end());
        const double low = x[q1];
        std::nth_element(x.begin(), x.begin() + long(q3), x.end());
        const double high = x[q3];
        robust.centre[s] = medianOf(x);
        // One centre for the pattern and its users (an untied step adds F - level): the mean of a site's
        // means moved 7 DN with 0.2% of hot pixels at 3430 DN.
        e.level[s] = robust.centre[s];
        const double robustVariance = std::pow((high - low) / 1.349, 2);
        robust.spread[s] = std::max(0.0, robustVariance - e.temporalVariance[s] / M);
        robust.outlier[s] = 6 * std::sqrt(robustVariance);
    }
    return robust;
}

// The pattern: each mean's departure from its site's centre shrunk by the share of it that is pattern, not
// the temporal noise the mean of M frames still holds.
void shrunkPattern(const Mat& mean, const Mat& variance, const Mat& noisy, int M, const RobustSites& robust,
                   DarkFrameStatistics& e)
{
    e.pattern.create(mean.rows, mean.cols, CV_32FC1);
    for (int r = 0; r < mean.rows; ++r) {
        const double* m = mean.ptr<double>(r);
        const double* v = variance.ptr<double>(r);
        const uchar* flagged = noisy.ptr<uchar>(r);
        float* out = e.pattern.ptr<float>(r);
        for (int c = 0; c < mean.cols; ++c) {
            const int s = cfaSite(r, c);
            const double departure = m[c] - robust.centre[s];
            if (std::abs(departure) > robust.outlier[s] && robust.outlier[s] > 0) {
                out[c] = static_cast<float>(m[c]);
                continue;
            }
            const double frozen = (flagged[c] ? v[c] : e.rowVariance.at<double>(r, c & 1)) / M;
            // sqrt(w), not w: the departures then scatter by s_F^2, the pattern's own variance, which is what
            // an augmentation adds (w, the best linear estimate, scatters by w s_F^2: less pattern than the
            // sensor).
            const double w = robust.spread[s] > 0 ? robust.spread[s] / (robust.spread[s] + frozen) : 0.0;
            out[c] = static_cast<float>(robust.centre[s] + std::sqrt(w) * departure);
        }
    }
}

} // namespace

DarkFrameStatistics estimateDarkFrames(const BurstStatistics& stats, double falseAlarm)
{
    const int M = stats.frames();
    if (M < 2)
        CV_Error(Error::StsBadArg,
                 format("estimateDarkFrames: %d frame(s); temporal noise needs at least two", M));
    if (!(falseAlarm > 0 && falseAlarm < 0.5))
        CV_Error(Error::StsOutOfRange,
                 format("estimateDarkFrames: falseAlarm %g must lie in (0, 0.5)", falseAlarm));
    Mat mean, variance;
    stats.mean(mean);
    stats.variance(variance);
    if (mean.rows * mean.cols < 16)
        CV_Error(Error::StsBadArg, format("estimateDarkFrames: %dx%d frames are too small to tell a pattern "
                                          "from noise (at least 16 pixels)",
                                          mean.cols, mean.rows));
    DarkFrameStatistics e;
    e.frames = M;
    const Mat noisy = flagNoisyPixels(variance, M, falseAlarm, e);
    siteFigures(mean, variance, noisy, M, e);
    const RobustSites robust = robustSites(mean, M, e);
    mean.convertTo(e.mean, CV_32F);
    shrunkPattern(mean, variance, noisy, M, robust, e);
    return e;
}

DarkFrameAccumulator::DarkFrameAccumulator(const RawFormat& format) : format_(format), stats_(format) {}

void DarkFrameAccumulator::add(const Mat& frame)
{
    stats_.add(frame);
    const int rows = frame.rows, cols = frame.cols;
    if (rowSum_.empty()) {
        rowSum_.assign(2 * static_cast<size_t>(rows), 0.0);
        rowSum2_.assign(2 * static_cast<size_t>(rows), 0.0);
    }
    Mat values;
    frame.convertTo(values, CV_64F);
    const double counts[2] = {static_cast<double>((cols + 1) / 2), static_cast<double>(cols / 2)};
    for (int r = 0; r < rows; ++r) {
        const double* v = values.ptr<double>(r);
        double sums[2] = {0, 0};
        for (int c = 0; c < cols; ++c)
            sums[c & 1] += v[c];
        for (int parity = 0; parity < 2; ++parity) {
            if (counts[parity] == 0)
                continue;
            const double mean = sums[parity] / counts[parity];
            rowSum_[2 * static_cast<size_t>(r) + parity] += mean;
            rowSum2_[2 * static_cast<size_t>(r) + parity] += mean * mean;
        }
    }
}

/* A row's mean at one column parity over its n pixels is the row's offset plus the mean of the pixels' own
 * noise: its variance over the M frames is s_row^2 + sum(u_c) / n^2, u_c a pixel's temporal variance less the
 * row's (noisy pixels included, as they are in the mean). A pixel's measured variance is v_c = u_c + s_row^2,
 * so s_row^2 = (Var(row mean) - sum(v_c) / n^2) / (1 - 1/n), averaged over the rows of the site's parity. */
DarkFrameStatistics DarkFrameAccumulator::estimate(double falseAlarm) const
{
    DarkFrameStatistics e = estimateDarkFrames(stats_, falseAlarm);
    const int M = stats_.frames();
    Mat variance;
    stats_.variance(variance);
    const int rows = variance.rows, cols = variance.cols;
    double sum[4] = {0, 0, 0, 0}, count[4] = {0, 0, 0, 0};
    for (int r = 0; r < rows; ++r) {
        const double* v = variance.ptr<double>(r);
        double own[2] = {0, 0}, n[2] = {0, 0};
        for (int c = 0; c < cols; ++c) {
            own[c & 1] += v[c];
            n[c & 1] += 1;
        }
        for (int parity = 0; parity < 2; ++parity) {
            if (n[parity] == 0)
                continue;
            const size_t i = 2 * static_cast<size_t>(r) + parity;
            const double ofMeans = (rowSum2_[i] - rowSum_[i] * rowSum_[i] / M) / (M - 1);
            const int site = cfaSite(r, parity);
            // Each pixel's own variance holds the row's s_row^2 too: sum(v_c) / n^2 = s_row^2 / n + the rest.
            sum[site] += (ofMeans - own[parity] / (n[parity] * n[parity])) / (1 - 1 / n[parity]);
            count[site] += 1;
        }
    }
    for (int s = 0; s < 4; ++s)
        e.rowNoiseVariance[s] = count[s] > 0 ? std::max(0.0, sum[s] / count[s]) : 0.0;
    return e;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
