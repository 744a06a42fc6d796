// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The paper's validation on a real sensor (emva1288 topic): bright steps of an EMVA 1288 series darkened
// with colorJitter() and compared with the series' own darker steps, the same sensor at the same gain.
#include "precomp.hpp"

#include <opencv2/rawgment/emva1288.hpp>
#include <opencv2/rawgment/seeds.hpp>

namespace cv {
namespace rawgment {

namespace {

//! The series' entry of a temporal point (matched by exposure and photons, as emva1288Results() made it).
const Emva1288Images& imagesOfPoint(const Emva1288Series& series, const Emva1288Results& results, int point)
{
    for (const Emva1288Images& g : series.temporal)
        if (!g.dark && g.exposureNs == results.exposureNs[point] && g.photons == results.photons[point])
            return g;
    CV_Error(Error::StsBadArg,
             cv::format("emva1288Darkening: point %d (exposure %g, %g photons) is not a bright "
                        "pair of '%s'",
                        point, results.exposureNs[point], results.photons[point], series.path.c_str()));
}

//! The fraction of (A - B) / sqrt(2) in each bin of `edges`.
std::vector<double> differenceHistogram(const Mat& a, const Mat& b, const std::vector<double>& edges)
{
    Mat d;
    subtract(a, b, d, noArray(), CV_64F);
    d /= std::sqrt(2.0);
    const int bins = int(edges.size()) - 1;
    std::vector<double> h(bins, 0.0);
    const double lo = edges.front(), width = (edges.back() - edges.front()) / bins;
    for (int y = 0; y < d.rows; ++y) {
        const double* p = d.ptr<double>(y);
        for (int x = 0; x < d.cols; ++x) {
            const int k = int(std::floor((p[x] - lo) / width));
            if (k >= 0 && k < bins)
                h[k] += 1.0 / double(d.total());
        }
    }
    return h;
}

} // namespace

std::vector<Point> emva1288DarkeningSteps(const Emva1288Results& results, int count)
{
    const int n = int(results.mean.size());
    if (count < 1 || results.saturationIndex < 0 || results.saturationIndex >= n ||
        int(results.darkMean.size()) != n)
        CV_Error(Error::StsBadArg,
                 "emva1288DarkeningSteps: count must be >= 1 and results what emva1288Results() "
                 "gives");
    const double saturated =
        results.mean[results.saturationIndex] - results.darkMean[results.saturationIndex];
    const auto signal = [&](int i) { return results.mean[i] - results.darkMean[i]; };
    std::vector<int> bright;
    for (int i = 0; i < n; ++i)
        if (signal(i) >= 0.1 * saturated && signal(i) <= 0.3 * saturated)
            bright.push_back(i);
    std::vector<Point> steps;
    for (int k = 0; k < count && k < int(bright.size()); ++k) {
        // Spread over the candidates, brightest last.
        const int i =
            bright[bright.size() == 1 ? 0 : size_t(k) * (bright.size() - 1) / std::max(1, count - 1)];
        // The darker step nearest (in ratio) a quarter of the bright one's signal, at most half of it.
        int dark = -1;
        const auto distance = [&](int j) { return std::abs(std::log(signal(j) / (0.25 * signal(i)))); };
        for (int j = 0; j < n; ++j)
            if (signal(j) > 0 && signal(j) <= 0.5 * signal(i) && (dark < 0 || distance(j) < distance(dark)))
                dark = j;
        const Point step(i, dark);
        if (dark >= 0 && std::find(steps.begin(), steps.end(), step) == steps.end())
            steps.push_back(step);
    }
    if (steps.empty())
        CV_Error(Error::StsBadArg,
                 "emva1288DarkeningSteps: no bright step between 10% and 30% of saturation has a "
                 "step at most a quarter as bright");
    return steps;
}

std::vector<Emva1288Darkening> emva1288Darkening(const Emva1288Series& series, const Emva1288Results& results,
                                                 const NoiseModel& model, const std::vector<Point>& steps,
                                                 uint64 seed)
{
    const int n = int(results.mean.size());
    // How much more the pairs' variances scatter than their pixels imply, from the dark pairs.
    double sw = 0, swv = 0;
    std::vector<const Emva1288Pair*> darkPairs;
    for (const Emva1288Pair& p : results.pairs)
        if (p.dark && p.varianceStdError > 0) {
            darkPairs.push_back(&p);
            sw += 1 / (p.varianceStdError * p.varianceStdError);
            swv += p.variance / (p.varianceStdError * p.varianceStdError);
        }
    double scatter = 1;
    if (darkPairs.size() >= 3) {
        double chi2 = 0;
        for (const Emva1288Pair* p : darkPairs)
            chi2 += std::pow((p->variance - swv / sw) / p->varianceStdError, 2);
        scatter = std::max(1.0, chi2 / double(darkPairs.size() - 1));
    }
    std::vector<Emva1288Darkening> out;
    for (size_t k = 0; k < steps.size(); ++k) {
        const int i = steps[k].x, j = steps[k].y;
        if (i < 0 || i >= n || j < 0 || j >= n)
            CV_Error(Error::StsBadArg,
                     cv::format("emva1288Darkening: step pair (%d, %d) lies outside the %d points", i, j, n));
        if (!(results.photons[j] < results.photons[i]) || !(results.photons[j] > 0))
            CV_Error(Error::StsBadArg,
                     cv::format("emva1288Darkening: point %d (%g photons) is not darker than "
                                "point %d (%g photons), or states no photons",
                                j, results.photons[j], i, results.photons[i]));
        const Emva1288Images& bright = imagesOfPoint(series, results, i);
        const Emva1288Images& dark = imagesOfPoint(series, results, j);
        Mat frames[2], real[2];
        for (int f = 0; f < 2; ++f) {
            readEmva1288Image(series, bright.images[f], bright.line).convertTo(frames[f], CV_32F);
            real[f] = readEmva1288Image(series, dark.images[f], dark.line);
        }
        RawFormat format; // the standard's frames are a monochrome sensor's, or one channel's
        format.pattern = CFA_MONO;
        format.blackLevel = Vec4d::all(results.darkMean[i]);
        format.whiteLevel = std::ldexp(1.0, series.bits) - 1;
        const double ratio = results.photons[j] / results.photons[i];
        const Emva1288Pair realPair = measureEmva1288Pair(real[0], real[1], 0, 0, false);
        const double sd = std::sqrt(realPair.variance);
        // Bins of whole steps of the integer difference (1 / sqrt(2) apart after the scaling), centred on
        // them, so that the real pair's lattice does not alias into the bins.
        const double lattice = 1 / std::sqrt(2.0);
        const double steps = std::max(1.0, std::round(12 * sd / 61 / lattice));
        std::vector<double> edges(62);
        for (int e = 0; e <= 61; ++e)
            edges[e] = (steps * (e - 30.5) - 0.5 * std::fmod(steps + 1, 2.0)) * lattice;
        const std::vector<double> realHistogram = differenceHistogram(real[0], real[1], edges);
        for (NoiseAlignment alignment :
             {NoiseAlignment::NONE, NoiseAlignment::IGNORE_PRIOR, NoiseAlignment::ACCOUNT_PRIOR}) {
            Mat augmented[2];
            RawFormat dstFormat;
            for (int f = 0; f < 2; ++f)
                colorJitter(frames[f], format, model, ColorJitter::exposureChange(ratio, 1.0), alignment,
                            deriveSeed(seed, SEED_VALIDATION_CONVERSION, 2 * k + f), augmented[f], dstFormat);
            const Emva1288Pair a = measureEmva1288Pair(augmented[0], augmented[1], 0, 0, false);
            Emva1288Darkening d;
            d.brightPoint = i;
            d.darkPoint = j;
            d.photonRatio = ratio;
            d.alignment = alignment;
            d.augmentedVariance = a.variance;
            d.augmentedStdError = a.varianceStdError;
            d.realVariance = realPair.variance;
            d.realStdError = realPair.varianceStdError;
            d.ratio = a.variance / realPair.variance;
            d.pairScatter = scatter;
            d.ratioStdError =
                d.ratio * std::sqrt(scatter) *
                std::hypot(a.varianceStdError / a.variance, realPair.varianceStdError / realPair.variance);
            d.histogramEdges = edges;
            d.augmentedHistogram = differenceHistogram(augmented[0], augmented[1], edges);
            d.realHistogram = realHistogram;
            out.push_back(d);
        }
    }
    return out;
}

} // namespace rawgment
} // namespace cv
