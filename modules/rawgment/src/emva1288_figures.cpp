// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The EMVA 1288 figures (emva1288 topic), defined as release 3.1/4.0 of the standard and its reference
// implementation define them, including the reference's choices where the standard leaves one (the scan
// for saturation, the weighted linearity fit); docs/emva1288.md states each formula. Pairs are reduced with
// exact integer sums, the spatial stacks accumulated one frame at a time in float64 (exact: at most 2^53).
#include "precomp.hpp"

#include <opencv2/rawgment/emva1288.hpp>

#include <algorithm>
#include <map>
#include <numeric>

namespace cv {
namespace rawgment {

namespace {

//! Mean and temporal variance of a pair, as the standard defines them: half the variance of A - B.
struct PairStatistics
{
    double mean = 0, variance = 0;
};

PairStatistics pairStatistics(const Mat& a, const Mat& b)
{
    long long sumA = 0, sumB = 0, sumD = 0;
    unsigned long long sumD2 = 0;
    for (int y = 0; y < a.rows; ++y) {
        const auto row = [&](const Mat& m, int x) {
            return m.depth() == CV_8U ? int(m.ptr<uchar>(y)[x]) : int(m.ptr<ushort>(y)[x]);
        };
        for (int x = 0; x < a.cols; ++x) {
            const int va = row(a, x), vb = row(b, x), d = va - vb;
            sumA += va;
            sumB += vb;
            sumD += d;
            sumD2 += (unsigned long long)((long long)d * d);
        }
    }
    const double n = double(a.total());
    PairStatistics s;
    s.mean = double(sumA + sumB) / (2 * n);
    const double meanD = double(sumD) / n;
    s.variance = 0.5 * (double(sumD2) / n - meanD * meanD);
    return s;
}

//! The spatial figures of one stack (bright or dark): its mean and s_y^2 with the temporal part removed.
struct StackStatistics
{
    double mean = 0, variance = 0;
};

StackStatistics stackStatistics(const Emva1288Series& series, const Emva1288Images& stack)
{
    // The accumulators are made from the first image read, so that a descriptor's 'n' alone allocates
    // nothing.
    Mat sum, squares, frame;
    for (const String& image : stack.images) {
        readEmva1288Image(series, image, stack.line).convertTo(frame, CV_64F);
        if (sum.empty()) {
            sum = frame.clone();
            squares = frame.mul(frame);
        } else {
            sum += frame;
            squares += frame.mul(frame);
        }
    }
    const double L = double(stack.images.size());
    const Mat mean = sum / L;
    // Each pixel's unbiased temporal variance, (L sum y^2 - (sum y)^2) / (L (L - 1)).
    const Mat temporal = (L * squares - sum.mul(sum)) / (L * (L - 1));
    const double temporalMean = cv::mean(temporal)[0];
    Scalar m, sd;
    meanStdDev(mean, m, sd);
    const double n = double(mean.total());
    const double spatial = sd[0] * sd[0] * n / (n - 1);
    StackStatistics s;
    s.mean = m[0];
    s.variance = spatial - temporalMean / L;
    return s;
}

//! The slope of y = m x by least squares (the reference's LinearB0).
double slopeThroughOrigin(const std::vector<double>& x, const std::vector<double>& y, int first, int last)
{
    double xy = 0, xx = 0;
    for (int i = first; i <= last; ++i) {
        xy += x[i] * y[i];
        xx += x[i] * x[i];
    }
    return xy / xx;
}

//! The intercept of y = m x + b by least squares (the reference's LinearB).
double interceptOfLine(const std::vector<double>& x, const std::vector<double>& y)
{
    const double n = double(x.size());
    const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
    const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
    double sxy = 0, sxx = 0;
    for (size_t i = 0; i < x.size(); ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
    }
    return my - (sxy / sxx) * mx;
}

/** The reference's saturation point: scanning from the brightest step down, the last step whose variance,
 * or its darker neighbour's, is at least the running maximum. */
int saturationIndexOf(const std::vector<double>& variance)
{
    const int n = int(variance.size());
    double maxValue = 0;
    int maxIndex = 0;
    for (int i = n - 1; i >= 0; --i) {
        const int darker = std::abs(i - 1);
        if (variance[i] >= maxValue || variance[darker] >= maxValue) {
            maxValue = variance[i];
            maxIndex = i;
        } else {
            break;
        }
    }
    return maxIndex;
}

} // namespace

Emva1288Results::Emva1288Results()
    : K(NAN), sigmaYDark(NAN), sigmaD(NAN), responsivity(NAN), eta(NAN), muPSat(NAN), muESat(NAN),
      snrMax(NAN), snrMaxDb(NAN), muPMin(NAN), dynamicRangeDb(NAN), dsnu1288(NAN), prnu1288(NAN),
      linearityErrorMin(NAN), linearityErrorMax(NAN), photonsGiven(false), saturationIndex(-1),
      sensitivityMaxIndex(-1), linearityMinIndex(-1), linearityMaxIndex(-1), linearityFitSlope(NAN),
      linearityFitOffset(NAN), spatialMeanBright(NAN), spatialMeanDark(NAN), spatialVarianceBright(NAN),
      spatialVarianceDark(NAN)
{
}

Emva1288Results emva1288Results(const Emva1288Series& series)
{
    return emva1288Results(series, std::function<void(int, int)>());
}

Emva1288Results emva1288Results(const Emva1288Series& series, const std::function<void(int, int)>& progress)
{
    std::vector<const Emva1288Images*> bright;
    for (const Emva1288Images& g : series.temporal)
        if (!g.dark)
            bright.push_back(&g);
    if (bright.size() < 3)
        CV_Error(Error::StsBadArg,
                 cv::format("emva1288Results: '%s' has %d bright temporal step(s); the figures "
                            "need at least three",
                            series.path.c_str(), int(bright.size())));
    std::stable_sort(bright.begin(), bright.end(), [](const Emva1288Images* a, const Emva1288Images* b) {
        return a->exposureNs != b->exposureNs ? a->exposureNs < b->exposureNs : a->photons < b->photons;
    });
    const int total = int(series.temporal.size() + series.spatial.size());
    int done = 0;
    const auto stepDone = [&] {
        if (progress)
            progress(++done, total);
    };
    const auto statisticsOf = [&](const Emva1288Images& g) {
        const Mat a = readEmva1288Image(series, g.images[0], g.line);
        const Mat b = readEmva1288Image(series, g.images[1], g.line);
        const PairStatistics s = pairStatistics(a, b);
        stepDone();
        return s;
    };
    // One dark pair per exposure time, read once, in ascending exposure.
    std::map<double, PairStatistics> darkByExposure;
    for (const Emva1288Images& g : series.temporal)
        if (g.dark)
            darkByExposure[g.exposureNs] = statisticsOf(g);
    Emva1288Results r;
    for (const Emva1288Images* g : bright) {
        const auto dark = darkByExposure.find(g->exposureNs);
        if (dark == darkByExposure.end())
            CV_Error(Error::StsBadArg,
                     cv::format("emva1288Results: '%s', line %d: exposure %g has no dark pair",
                                series.path.c_str(), g->line, g->exposureNs));
        const PairStatistics s = statisticsOf(*g);
        r.exposureNs.push_back(g->exposureNs);
        r.photons.push_back(g->photons);
        r.mean.push_back(s.mean);
        r.variance.push_back(s.variance);
        r.darkMean.push_back(dark->second.mean);
        r.darkVariance.push_back(dark->second.variance);
        r.photonsGiven = r.photonsGiven || g->photons > 0;
    }
    const int n = int(r.mean.size());
    std::vector<double> signal(n), excess(n);
    for (int i = 0; i < n; ++i) {
        signal[i] = r.mean[i] - r.darkMean[i];
        excess[i] = r.variance[i] - r.darkVariance[i];
    }
    r.saturationIndex = saturationIndexOf(r.variance);
    const double saturated = signal[r.saturationIndex];
    const auto lastAtMost = [&](double limit) {
        int last = -1;
        for (int i = 0; i < n; ++i)
            if (signal[i] <= limit)
                last = i;
        return last;
    };
    r.sensitivityMaxIndex = lastAtMost(0.7 * saturated);
    if (!(saturated > 0) || r.sensitivityMaxIndex < 1)
        CV_Error(Error::StsBadArg,
                 cv::format(
                     "emva1288Results: '%s': the signal at saturation is %g DN above dark and %d step(s) lie "
                     "below 70%% of it; K needs a signal that rises over at least two steps",
                     series.path.c_str(), saturated, r.sensitivityMaxIndex + 1));
    r.K = slopeThroughOrigin(signal, excess, 0, r.sensitivityMaxIndex);
    if (!(std::isfinite(r.K) && r.K > 0))
        CV_Error(Error::StsBadArg,
                 cv::format("emva1288Results: '%s': the fitted K is %g; the temporal variance "
                            "does not rise with the signal up to 70%% of saturation",
                            series.path.c_str(), r.K));

    // The dark noise: the intercept of the dark variance against exposure time (dark current adds the slope).
    std::vector<double> times, darkVariances;
    for (const auto& d : darkByExposure) {
        times.push_back(d.first);
        darkVariances.push_back(d.second.variance);
    }
    double darkVariance = times.size() <= 2 ? r.darkVariance[0] : interceptOfLine(times, darkVariances);
    darkVariance = std::max(darkVariance, 0.24); // the standard's floor: quantisation noise resolves no less
    r.sigmaYDark = std::sqrt(darkVariance);
    r.sigmaD = std::sqrt(darkVariance - 1.0 / 12.0) / r.K;

    if (r.photonsGiven) {
        r.responsivity = slopeThroughOrigin(r.photons, signal, 0, r.sensitivityMaxIndex);
        if (!(std::isfinite(r.responsivity) && r.responsivity > 0))
            CV_Error(
                Error::StsBadArg,
                cv::format("emva1288Results: '%s': the responsivity is %g DN per photon; the signal does not "
                           "rise with the descriptor's photon counts",
                           series.path.c_str(), r.responsivity));
        r.eta = 100.0 * r.responsivity / r.K;
        r.muPSat = r.photons[r.saturationIndex];
        r.muESat = r.eta * r.muPSat / 100.0;
        r.muPMin = (100.0 / r.eta) * (r.sigmaYDark / r.K + 0.5);
        r.dynamicRangeDb = 20.0 * std::log10(r.muPSat / r.muPMin);
    } else {
        r.muESat = saturated / r.K;
    }
    r.snrMax = std::sqrt(r.muESat);
    r.snrMaxDb = 20.0 * std::log10(r.snrMax);

    // Linearity: the weighted fit of the reference over 5%..95% of the saturation signal, against photons
    // (exposure time when no photon count is given).
    const std::vector<double>& light = r.photonsGiven ? r.photons : r.exposureNs;
    r.linearityMinIndex = -1;
    for (int i = 0; i < n && r.linearityMinIndex < 0; ++i)
        if (signal[i] >= 0.05 * saturated)
            r.linearityMinIndex = i;
    r.linearityMaxIndex = lastAtMost(0.95 * saturated);
    if (r.linearityMinIndex >= 0 && r.linearityMaxIndex > r.linearityMinIndex) {
        double xy = 0, xy2 = 0, x2y2 = 0, y1 = 0, y2 = 0;
        for (int i = r.linearityMinIndex; i <= r.linearityMaxIndex; ++i) {
            const double X = light[i], Y = signal[i];
            xy += X / Y;
            xy2 += X / (Y * Y);
            x2y2 += (X / Y) * (X / Y);
            y1 += 1.0 / Y;
            y2 += 1.0 / (Y * Y);
        }
        // The determinant vanishes when every X/Y is equal (a response exactly through the origin): b is 0.
        const double det = xy2 * xy2 - x2y2 * y2;
        const double b = std::abs(det) > 1e-12 * x2y2 * y2 ? (xy * xy2 - x2y2 * y1) / det : 0.0;
        const double a = (xy - b * xy2) / x2y2;
        r.linearityFitSlope = a;
        r.linearityFitOffset = b;
        r.linearityDeviation.resize(n);
        for (int i = 0; i < n; ++i)
            r.linearityDeviation[i] = 100.0 * (signal[i] - (a * light[i] + b)) / (a * light[i] + b);
        const auto range = std::minmax_element(r.linearityDeviation.begin() + r.linearityMinIndex,
                                               r.linearityDeviation.begin() + r.linearityMaxIndex + 1);
        r.linearityErrorMin = *range.first;
        r.linearityErrorMax = *range.second;
    }

    if (series.spatial.size() == 2) {
        const Emva1288Images& brightStack = series.spatial[0].dark ? series.spatial[1] : series.spatial[0];
        const Emva1288Images& darkStack = series.spatial[0].dark ? series.spatial[0] : series.spatial[1];
        const StackStatistics b = stackStatistics(series, brightStack);
        stepDone();
        const StackStatistics d = stackStatistics(series, darkStack);
        stepDone();
        r.spatialMeanBright = b.mean;
        r.spatialMeanDark = d.mean;
        r.spatialVarianceBright = b.variance;
        r.spatialVarianceDark = d.variance;
        // A negative estimate means a pattern below what the stack resolves: stated as NaN, as the reference.
        if (d.variance >= 0)
            r.dsnu1288 = std::sqrt(d.variance) / r.K;
        if (b.variance - d.variance >= 0)
            r.prnu1288 = 100.0 * std::sqrt(b.variance - d.variance) / (b.mean - d.mean);
    }
    return r;
}

} // namespace rawgment
} // namespace cv
