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

//! The pixel values of two frames of one type (CV_8U, CV_16U or CV_32F), row by row, as doubles.
template <typename Visit> void forEachPixelPair(const Mat& a, const Mat& b, Visit&& visit)
{
    for (int y = 0; y < a.rows; ++y) {
        if (a.depth() == CV_8U) {
            const uchar *pa = a.ptr<uchar>(y), *pb = b.ptr<uchar>(y);
            for (int x = 0; x < a.cols; ++x)
                visit(double(pa[x]), double(pb[x]));
        } else if (a.depth() == CV_16U) {
            const ushort *pa = a.ptr<ushort>(y), *pb = b.ptr<ushort>(y);
            for (int x = 0; x < a.cols; ++x)
                visit(double(pa[x]), double(pb[x]));
        } else {
            const float *pa = a.ptr<float>(y), *pb = b.ptr<float>(y);
            for (int x = 0; x < a.cols; ++x)
                visit(double(pa[x]), double(pb[x]));
        }
    }
}

void checkFrame(const Mat& m, const char* who, const char* what)
{
    if (m.type() != CV_8UC1 && m.type() != CV_16UC1 && m.type() != CV_32FC1)
        CV_Error(Error::StsBadArg,
                 cv::format("%s: %s must be CV_8UC1, CV_16UC1 or CV_32FC1 (got %s)", who, what,
                            m.empty() ? "an empty array" : typeToString(m.type()).c_str()));
    if (m.depth() == CV_32F && !checkRange(m))
        CV_Error(Error::StsBadArg, cv::format("%s: %s holds a value that is not finite", who, what));
}

//! The running sums of a stack, made from the first frame added so that nothing is allocated before.
struct StackAccumulator
{
    Mat sum, squares, frame;
    int frames = 0;

    void add(const Mat& image)
    {
        image.convertTo(frame, CV_64F);
        if (sum.empty()) {
            sum = frame.clone();
            squares = frame.mul(frame);
        } else {
            sum += frame;
            squares += frame.mul(frame);
        }
        ++frames;
    }

    //! The standard's s_y^2: the spatial variance of the mean image less the mean temporal variance over L.
    Emva1288Stack stack(double exposureNs, double photons, bool dark) const
    {
        const double L = frames;
        const Mat mean = sum / L;
        // Each pixel's unbiased temporal variance, (L sum y^2 - (sum y)^2) / (L (L - 1)).
        const Mat temporal = (L * squares - sum.mul(sum)) / (L * (L - 1));
        Scalar m, sd;
        meanStdDev(mean, m, sd);
        const double n = double(mean.total());
        Emva1288Stack s;
        s.exposureNs = exposureNs;
        s.photons = photons;
        s.dark = dark;
        s.frames = frames;
        s.mean = m[0];
        s.variance = sd[0] * sd[0] * n / (n - 1) - cv::mean(temporal)[0] / L;
        return s;
    }
};

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

//! Whether at least half of a frame's pixels hold its largest value: a step clipped but for a few pixels.
bool mostlyClipped(const Mat& frame)
{
    double lo, hi;
    minMaxLoc(frame.reshape(1, 1), &lo, &hi);
    return 2 * countNonZero(frame == hi) >= int(frame.total());
}

} // namespace

Emva1288Pair measureEmva1288Pair(InputArray _a, InputArray _b, double exposureNs, double photons, bool dark)
{
    const Mat a = detail::twoDimensional(_a, "measureEmva1288Pair: a");
    const Mat b = detail::twoDimensional(_b, "measureEmva1288Pair: b");
    checkFrame(a, "measureEmva1288Pair", "a");
    checkFrame(b, "measureEmva1288Pair", "b");
    if (a.size() != b.size() || a.type() != b.type() || a.total() < 2)
        CV_Error(Error::StsBadArg,
                 cv::format("measureEmva1288Pair: the frames must share one size and type and "
                            "hold at least 2 pixels (got %dx%d %s and %dx%d %s)",
                            a.cols, a.rows, typeToString(a.type()).c_str(), b.cols, b.rows,
                            typeToString(b.type()).c_str()));
    detail::checkFiniteNonNegative(exposureNs, "measureEmva1288Pair: exposureNs");
    detail::checkFiniteNonNegative(photons, "measureEmva1288Pair: photons");
    // Sums of integer frames are exact in float64 (at most 2^28 x 2^17 < 2^53); the difference's central
    // moments in a second pass.
    double sumAB = 0, sumD = 0;
    forEachPixelPair(a, b, [&](double va, double vb) {
        sumAB += va + vb;
        sumD += va - vb;
    });
    const double n = double(a.total());
    const double meanD = sumD / n;
    double m2 = 0, m4 = 0;
    std::vector<double> rowSums(a.rows, 0.0);
    for (int y = 0; y < a.rows; ++y) {
        double row = 0;
        forEachPixelPair(a.row(y), b.row(y), [&](double va, double vb) {
            const double e = (va - vb) - meanD, e2 = e * e;
            row += e2;
            m4 += e2 * e2;
        });
        rowSums[y] = row;
        m2 += row;
    }
    m2 /= n;
    m4 /= n;
    // Rows as units as well: noise shared along a row (row noise, in most sensors; set 001 has 0.25 DN^2 of
    // it) makes pixels of a row dependent, and the spread of the rows' own estimates then exceeds what the
    // pixels' fourth moment implies. The larger of the two errors is stated.
    double rowError = 0;
    if (a.rows >= 8) {
        double mean = 0, spread = 0;
        for (double r : rowSums)
            mean += r / a.cols / a.rows;
        for (double r : rowSums)
            spread += (r / a.cols - mean) * (r / a.cols - mean);
        rowError = 0.5 * std::sqrt(spread / (a.rows - 1) / a.rows);
    }
    // Two captures never differ by a constant where they are not clipped: such a pair is one capture twice
    // (copied or listed again), whose variance of 0 every figure would carry. A step clipped in most
    // pixels (its defective pixels aside) may well be the same twice.
    if (m2 == 0 && !mostlyClipped(a))
        CV_Error(Error::StsBadArg,
                 "measureEmva1288Pair: the two frames differ by a constant, so they are one "
                 "capture twice; a pair is two captures of its own");
    Emva1288Pair p;
    p.exposureNs = exposureNs;
    p.photons = photons;
    p.dark = dark;
    p.mean = sumAB / (2 * n);
    p.variance = 0.5 * m2;
    p.varianceStdError = std::max(0.5 * std::sqrt(std::max(m4 - m2 * m2, 0.0) / n), rowError);
    return p;
}

Emva1288Stack measureEmva1288Stack(InputArrayOfArrays _frames, double exposureNs, double photons, bool dark)
{
    std::vector<Mat> frames;
    _frames.getMatVector(frames);
    if (frames.size() < 2)
        CV_Error(
            Error::StsBadArg,
            cv::format("measureEmva1288Stack: a stack needs at least 2 frames (got %d)", int(frames.size())));
    detail::checkFiniteNonNegative(exposureNs, "measureEmva1288Stack: exposureNs");
    detail::checkFiniteNonNegative(photons, "measureEmva1288Stack: photons");
    StackAccumulator acc;
    std::vector<Vec2d> sums; // each frame's sum and sum of squares: frames compared only where these agree
    for (size_t k = 0; k < frames.size(); ++k) {
        const Mat& f = frames[k];
        checkFrame(f, "measureEmva1288Stack", "every frame");
        if (f.size() != frames[0].size() || f.type() != frames[0].type() || f.total() < 2)
            CV_Error(Error::StsBadArg,
                     cv::format("measureEmva1288Stack: the frames must share one size and type and hold at "
                                "least 2 pixels (frame 0 is %dx%d %s, this one %dx%d %s)",
                                frames[0].cols, frames[0].rows, typeToString(frames[0].type()).c_str(),
                                f.cols, f.rows, typeToString(f.type()).c_str()));
        // As for a pair: a frame not clipped that equals another is one capture listed twice.
        Mat f64;
        f.convertTo(f64, CV_64F);
        sums.push_back(Vec2d(sum(f64)[0], f64.dot(f64)));
        for (size_t j = 0; j < k; ++j)
            if (sums[j] == sums[k] && norm(f, frames[j], NORM_INF) == 0 && !mostlyClipped(f))
                CV_Error(Error::StsBadArg,
                         cv::format("measureEmva1288Stack: frames %zu and %zu are equal, so they are one "
                                    "capture twice; a stack is captures of their own",
                                    j, k));
        acc.add(f);
    }
    return acc.stack(exposureNs, photons, dark);
}

Emva1288Results::Emva1288Results()
    : K(NAN), sigmaYDark(NAN), sigmaD(NAN), responsivity(NAN), eta(NAN), muPSat(NAN), muESat(NAN),
      snrMax(NAN), snrMaxDb(NAN), muPMin(NAN), dynamicRangeDb(NAN), dsnu1288(NAN), prnu1288(NAN),
      linearityErrorMin(NAN), linearityErrorMax(NAN), photonsGiven(false), saturationIndex(-1),
      sensitivityMaxIndex(-1), linearityMinIndex(-1), linearityMaxIndex(-1), linearityFitSlope(NAN),
      linearityFitOffset(NAN)
{
}

namespace {

typedef std::map<double, const Emva1288Pair*> DarkPairs;

// The bright steps in the order of their light, each with the dark pair of its exposure, into r; the dark
// pairs by exposure.
DarkPairs takeTemporalSteps(const std::vector<Emva1288Pair>& pairs, Emva1288Results& r)
{
    std::vector<const Emva1288Pair*> bright;
    DarkPairs darkByExposure;
    for (const Emva1288Pair& p : pairs) {
        if (!(std::isfinite(p.mean) && std::isfinite(p.variance) && std::isfinite(p.varianceStdError) &&
              std::isfinite(p.exposureNs) && std::isfinite(p.photons)))
            CV_Error(Error::StsBadArg, "emva1288Results: a pair holds a value that is not finite");
        if (!p.dark)
            bright.push_back(&p);
        else if (!darkByExposure.emplace(p.exposureNs, &p).second)
            CV_Error(Error::StsBadArg,
                     cv::format("emva1288Results: two dark pairs at exposure %g; one per exposure time",
                                p.exposureNs));
    }
    if (bright.size() < 3)
        CV_Error(Error::StsBadArg,
                 cv::format("emva1288Results: %d bright temporal step(s); the figures need at "
                            "least three",
                            int(bright.size())));
    std::stable_sort(bright.begin(), bright.end(), [](const Emva1288Pair* a, const Emva1288Pair* b) {
        return a->exposureNs != b->exposureNs ? a->exposureNs < b->exposureNs : a->photons < b->photons;
    });
    for (const Emva1288Pair* g : bright) {
        const auto dark = darkByExposure.find(g->exposureNs);
        if (dark == darkByExposure.end())
            CV_Error(Error::StsBadArg,
                     cv::format("emva1288Results: the bright pair at exposure %g has no dark pair",
                                g->exposureNs));
        r.exposureNs.push_back(g->exposureNs);
        r.photons.push_back(g->photons);
        r.mean.push_back(g->mean);
        r.variance.push_back(g->variance);
        r.varianceStdError.push_back(g->varianceStdError);
        r.darkMean.push_back(dark->second->mean);
        r.darkVariance.push_back(dark->second->variance);
        r.darkVarianceStdError.push_back(dark->second->varianceStdError);
        r.photonsGiven = r.photonsGiven || g->photons > 0;
    }
    return darkByExposure;
}

// The index of the last step whose signal is at most `limit`; -1 when none is.
int lastStepAtMost(const std::vector<double>& signal, double limit)
{
    int last = -1;
    for (int i = 0; i < int(signal.size()); ++i)
        if (signal[i] <= limit)
            last = i;
    return last;
}

// The dark noise: the intercept of the dark variance against exposure time (dark current adds the slope).
void darkNoiseFigures(const DarkPairs& darkByExposure, Emva1288Results& r)
{
    std::vector<double> times, darkVariances;
    for (const auto& d : darkByExposure) {
        times.push_back(d.first);
        darkVariances.push_back(d.second->variance);
    }
    double darkVariance = times.size() <= 2 ? r.darkVariance[0] : interceptOfLine(times, darkVariances);
    darkVariance = std::max(darkVariance, 0.24); // the standard's floor: quantisation noise resolves no less
    r.sigmaYDark = std::sqrt(darkVariance);
    r.sigmaD = std::sqrt(darkVariance - 1.0 / 12.0) / r.K;
}

// Responsivity, quantum efficiency, saturation capacity, SNR and dynamic range (photon counts given), or the
// saturation capacity in electrons alone.
void photonFigures(const std::vector<double>& signal, double saturated, Emva1288Results& r)
{
    if (r.photonsGiven) {
        r.responsivity = slopeThroughOrigin(r.photons, signal, 0, r.sensitivityMaxIndex);
        if (!(std::isfinite(r.responsivity) && r.responsivity > 0))
            CV_Error(Error::StsBadArg,
                     cv::format("emva1288Results: the responsivity is %g DN per photon; the "
                                "signal does not rise with the photon counts given",
                                r.responsivity));
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
}

// Linearity: the weighted fit of the reference over 5%..95% of the saturation signal, against photons
// (exposure time when no photon count is given).
void linearityFigures(const std::vector<double>& signal, double saturated, Emva1288Results& r)
{
    const int n = int(signal.size());
    const std::vector<double>& light = r.photonsGiven ? r.photons : r.exposureNs;
    for (int i = 0; i < n && r.linearityMinIndex < 0; ++i)
        if (signal[i] >= 0.05 * saturated)
            r.linearityMinIndex = i;
    r.linearityMaxIndex = lastStepAtMost(signal, 0.95 * saturated);
    if (r.linearityMinIndex < 0 || r.linearityMaxIndex <= r.linearityMinIndex)
        return;
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

// DSNU and PRNU from the spatial set, one bright and one dark stack.
void spatialFigures(const std::vector<Emva1288Stack>& stacks, Emva1288Results& r)
{
    if (stacks.empty())
        return;
    if (stacks.size() != 2 || stacks[0].dark == stacks[1].dark)
        CV_Error(Error::StsBadArg, "emva1288Results: the spatial set must be one bright and one dark stack");
    const Emva1288Stack& b = stacks[0].dark ? stacks[1] : stacks[0];
    const Emva1288Stack& d = stacks[0].dark ? stacks[0] : stacks[1];
    // A negative estimate means a pattern below what the stack resolves: stated as NaN, as the reference.
    if (d.variance >= 0)
        r.dsnu1288 = std::sqrt(d.variance) / r.K;
    if (b.variance - d.variance >= 0 && b.mean > d.mean)
        r.prnu1288 = 100.0 * std::sqrt(b.variance - d.variance) / (b.mean - d.mean);
}

} // namespace

Emva1288Results emva1288Results(const std::vector<Emva1288Pair>& pairs,
                                const std::vector<Emva1288Stack>& stacks)
{
    Emva1288Results r;
    r.pairs = pairs;
    r.stacks = stacks;
    const DarkPairs darkByExposure = takeTemporalSteps(pairs, r);
    const int n = int(r.mean.size());
    std::vector<double> signal(n), excess(n);
    for (int i = 0; i < n; ++i) {
        signal[i] = r.mean[i] - r.darkMean[i];
        excess[i] = r.variance[i] - r.darkVariance[i];
    }
    r.saturationIndex = saturationIndexOf(r.variance);
    const double saturated = signal[r.saturationIndex];
    r.sensitivityMaxIndex = lastStepAtMost(signal, 0.7 * saturated);
    if (!(saturated > 0) || r.sensitivityMaxIndex < 1)
        CV_Error(Error::StsBadArg,
                 cv::format(
                     "emva1288Results: the signal at saturation is %g DN above dark and %d step(s) lie below "
                     "70%% of it; K needs a signal that rises over at least two steps",
                     saturated, r.sensitivityMaxIndex + 1));
    r.K = slopeThroughOrigin(signal, excess, 0, r.sensitivityMaxIndex);
    if (!(std::isfinite(r.K) && r.K > 0))
        CV_Error(Error::StsBadArg,
                 cv::format("emva1288Results: the fitted K is %g; the temporal variance does not "
                            "rise with the signal up to 70%% of saturation",
                            r.K));
    darkNoiseFigures(darkByExposure, r);
    photonFigures(signal, saturated, r);
    linearityFigures(signal, saturated, r);
    spatialFigures(stacks, r);
    return r;
}

Emva1288Results emva1288Results(const Emva1288Series& series)
{
    return emva1288Results(series, std::function<void(int, int)>());
}

Emva1288Results emva1288Results(const Emva1288Series& series, const std::function<void(int, int)>& progress)
{
    const int total = int(series.temporal.size() + series.spatial.size());
    int done = 0;
    const auto stepDone = [&] {
        if (progress)
            progress(++done, total);
    };
    std::vector<Emva1288Pair> pairs;
    for (const Emva1288Images& g : series.temporal) {
        if (g.images.size() != 2)
            CV_Error(Error::StsBadArg,
                     cv::format("emva1288Results: '%s', line %d: a temporal step has %d images",
                                series.path.c_str(), g.line, int(g.images.size())));
        const Mat a = readEmva1288Image(series, g.images[0], g.line);
        const Mat b = readEmva1288Image(series, g.images[1], g.line);
        // A refused pair names its descriptor, line and images: the frames alone say nothing of where
        // they came from (#79 item 24).
        try {
            pairs.push_back(measureEmva1288Pair(a, b, g.exposureNs, g.photons, g.dark));
        } catch (const Exception& e) {
            CV_Error(e.code, cv::format("emva1288Results: '%s', line %d, images '%s' and '%s': %s",
                                        series.path.c_str(), g.line, g.images[0].c_str(), g.images[1].c_str(),
                                        e.err.c_str()));
        }
        stepDone();
    }
    std::vector<Emva1288Stack> stacks;
    for (const Emva1288Images& g : series.spatial) {
        StackAccumulator acc;
        for (const String& image : g.images) {
            const Mat frame = readEmva1288Image(series, image, g.line);
            try {
                acc.add(frame);
            } catch (const Exception& e) {
                CV_Error(e.code, cv::format("emva1288Results: '%s', line %d, image '%s': %s",
                                            series.path.c_str(), g.line, image.c_str(), e.err.c_str()));
            }
        }
        try {
            stacks.push_back(acc.stack(g.exposureNs, g.photons, g.dark));
        } catch (const Exception& e) {
            CV_Error(e.code, cv::format("emva1288Results: '%s', line %d: %s", series.path.c_str(), g.line,
                                        e.err.c_str()));
        }
        stepDone();
    }
    try {
        return emva1288Results(pairs, stacks);
    } catch (const Exception& e) {
        CV_Error(e.code, "'" + series.path + "': " + e.err);
    }
}

} // namespace rawgment
} // namespace cv
