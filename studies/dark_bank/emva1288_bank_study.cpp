// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The dark-frame bank on a real sensor, EMVA 1288 reference set 001 (dark_bank_study.hpp): one gain, so a
// held-out frame at the bank's own gain and exposure proves nothing (k = 1, c = 0). Instead, bright steps are
// darkened to darker steps' photon counts and compared with their real pairs, and each method's read-noise
// figures from half of the spatial set's dark frames are compared with the other half's.
#include "dark_bank_study.hpp"

#include <opencv2/rawgment.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <sstream>

namespace rawgment_studies {

bool RealComparison::distinguishable() const
{
    return std::abs(value - real) > 3 * se;
}

namespace {

using namespace cv;
using namespace cv::rawgment;

/* A stack's read-noise figures by the study's own arithmetic (not the bank's code, which they check), per
 * site of the row and column parities (a CCD's even and odd columns differ in level and in row offsets; a
 * bank keeps both per site, as a mosaic's CFA sites) and averaged over the four: the temporal variance v; the
 * variance of the stack's mean image, and that less v/n (the fixed pattern); the row noise, from the variance
 * over the frames of each row's mean at a column parity less the pixels' share; the residuals' excess
 * kurtosis (each value less its pixel's mean and its row's offset at its parity), as measured (the shape of a
 * bank's draws, a frame less its group's mean) and carried back to a frame's own. */
struct StackFigures
{
    double temporal = 0, meanVariance = 0, fixedPattern = 0, rowNoise = 0, residualKurtosis = 0, kurtosis = 0;
};

//! Each frame's row means per column parity: frames x (2 rows), entry (t, 2y + p).
Mat parityRowMeans(const std::vector<Mat>& frames)
{
    const int rows = frames[0].rows, cols = frames[0].cols;
    Mat means(static_cast<int>(frames.size()), 2 * rows, CV_64F, Scalar(0));
    for (size_t t = 0; t < frames.size(); ++t)
        for (int y = 0; y < rows; ++y) {
            const double* f = frames[t].ptr<double>(y);
            for (int x = 0; x < cols; ++x)
                means.at<double>(static_cast<int>(t), 2 * y + (x & 1)) += f[x] / ((cols + 1 - (x & 1)) / 2);
        }
    return means;
}

StackFigures figuresOfStack(const std::vector<Mat>& frames, const Mat& rowMeans, const std::vector<int>& use)
{
    const int n = static_cast<int>(use.size()), rows = frames[0].rows, cols = frames[0].cols;
    Mat sum = Mat::zeros(frames[0].size(), CV_64F), sum2 = sum.clone();
    for (int t : use) {
        sum += frames[static_cast<size_t>(t)];
        sum2 += frames[static_cast<size_t>(t)].mul(frames[static_cast<size_t>(t)]);
    }
    const Mat mean = sum / n;
    const Mat variance = (sum2 - n * mean.mul(mean)) / (n - 1);
    double v[4] = {0, 0, 0, 0}, m1[4] = {0, 0, 0, 0}, m2[4] = {0, 0, 0, 0}, count[4] = {0, 0, 0, 0};
    for (int y = 0; y < rows; ++y)
        for (int x = 0; x < cols; ++x) {
            const int site = 2 * (y & 1) + (x & 1);
            const double mu = mean.at<double>(y, x);
            v[site] += variance.at<double>(y, x);
            m1[site] += mu;
            m2[site] += mu * mu;
            count[site] += 1;
        }
    std::vector<double> offsetMean(static_cast<size_t>(2 * rows), 0.0);
    double rowMeanVariance[4] = {0, 0, 0, 0}, rowCount[4] = {0, 0, 0, 0};
    for (int j = 0; j < 2 * rows; ++j) {
        double a = 0, a2 = 0;
        for (int t : use) {
            const double r = rowMeans.at<double>(t, j);
            a += r;
            a2 += r * r;
        }
        offsetMean[static_cast<size_t>(j)] = a / n;
        const int site = 2 * ((j / 2) & 1) + (j & 1);
        rowMeanVariance[site] += (a2 - a * a / n) / (n - 1);
        rowCount[site] += 1;
    }
    StackFigures s;
    for (int site = 0; site < 4; ++site) {
        const double temporal = v[site] / count[site],
                     meanVariance = (m2[site] - m1[site] * m1[site] / count[site]) / (count[site] - 1),
                     perRow = count[site] / rowCount[site];
        s.temporal += temporal / 4;
        s.meanVariance += meanVariance / 4;
        s.fixedPattern += (meanVariance - temporal / n) / 4;
        s.rowNoise += (rowMeanVariance[site] / rowCount[site] - temporal / perRow) / (1 - 1 / perRow) / 4;
    }
    double e2sum = 0, e4sum = 0;
    for (int t : use)
        for (int y = 0; y < rows; ++y) {
            const double* f = frames[static_cast<size_t>(t)].ptr<double>(y);
            const double* mu = mean.ptr<double>(y);
            const double offset[2] = {rowMeans.at<double>(t, 2 * y) - offsetMean[static_cast<size_t>(2 * y)],
                                      rowMeans.at<double>(t, 2 * y + 1) -
                                          offsetMean[static_cast<size_t>(2 * y + 1)]};
            for (int x = 0; x < cols; ++x) {
                const double e = f[x] - mu[x] - offset[x & 1], e2 = e * e;
                e2sum += e2;
                e4sum += e2 * e2;
            }
        }
    const double all = static_cast<double>(n) * rows * cols;
    s.residualKurtosis = (e4sum / all) / ((e2sum / all) * (e2sum / all)) - 3;
    s.kurtosis = s.residualKurtosis / residualKurtosisFactor(n);
    return s;
}

//! The figures of frames[use] and their jackknife standard errors over frames (drift and frame-level noise
//! count, which an error from the pixels alone would miss).
std::pair<StackFigures, StackFigures> figuresWithErrors(const std::vector<Mat>& frames, const Mat& rowMeans,
                                                        const std::vector<int>& use)
{
    const StackFigures all = figuresOfStack(frames, rowMeans, use);
    const int n = static_cast<int>(use.size());
    std::vector<StackFigures> loo;
    for (int i = 0; i < n; ++i) {
        std::vector<int> less = use;
        less.erase(less.begin() + i);
        loo.push_back(figuresOfStack(frames, rowMeans, less));
    }
    const auto se = [&](double StackFigures::*field) {
        double mean = 0, ss = 0;
        for (const StackFigures& f : loo)
            mean += f.*field / n;
        for (const StackFigures& f : loo)
            ss += (f.*field - mean) * (f.*field - mean);
        return std::sqrt((n - 1.0) / n * ss);
    };
    StackFigures errors;
    for (double StackFigures::*field :
         {&StackFigures::temporal, &StackFigures::meanVariance, &StackFigures::fixedPattern,
          &StackFigures::rowNoise, &StackFigures::residualKurtosis, &StackFigures::kurtosis})
        errors.*field = se(field);
    return {all, errors};
}

double siteAverage(const Vec4d& perSite)
{
    return (perSite[0] + perSite[1] + perSite[2] + perSite[3]) / 4;
}

//! The variance of `map` over each site of the row and column parities, averaged over the four (the sites'
//! levels differ, which a bank keeps as each site's level and a pattern does not add).
double siteSpatialVariance(const Mat& map)
{
    Mat m;
    map.convertTo(m, CV_64F);
    double total = 0;
    for (int site = 0; site < 4; ++site) {
        double s = 0, s2 = 0, n = 0;
        for (int y = site / 2; y < m.rows; y += 2)
            for (int x = site % 2; x < m.cols; x += 2) {
                const double v = m.at<double>(y, x);
                s += v;
                s2 += v * v;
                n += 1;
            }
        total += (s2 - s * s / n) / (n - 1) / 4;
    }
    return total;
}

double spatialVariance(const Mat& map)
{
    Scalar m, sd;
    meanStdDev(map, m, sd);
    return sd[0] * sd[0];
}

/* What a darkened (or real) pair shows: its temporal variance and error (the standard's), the variance of the
 * row means of (A - B) / sqrt(2), the difference's excess kurtosis, and its values for the two-sample KS
 * statistic against a real pair: each frame rounded as a sensor's output is (a no-op for the real frames),
 * both then dithered by the same uniform +-0.5 DN (a real pair's values lie on the integers' lattice, which
 * alone makes a KS statistic large against continuous values), and centred (frame-level offsets, which the
 * standard's variance removes too). */
struct PairFigures
{
    double variance = 0, varianceSe = 0, rowMeanVariance = 0, kurtosis = 0;
    std::vector<float> values;
};

PairFigures figuresOfPair(const Mat& a, const Mat& b, uint64 ditherSeed)
{
    PairFigures p;
    const Emva1288Pair pair = measureEmva1288Pair(a, b, 0, 0, false);
    p.variance = pair.variance;
    p.varianceSe = pair.varianceStdError;
    Mat fa, fb;
    a.convertTo(fa, CV_64F);
    b.convertTo(fb, CV_64F);
    const Mat d = (fa - fb) / std::sqrt(2.0);
    Mat rowMeans;
    reduce(d, rowMeans, 1, REDUCE_AVG, CV_64F);
    p.rowMeanVariance = spatialVariance(rowMeans) * d.rows / (d.rows - 1.0);
    const double mu = cv::mean(d)[0];
    double m2 = 0, m4 = 0, dithered = 0;
    RNG rng(ditherSeed);
    p.values.reserve(d.total());
    for (int y = 0; y < d.rows; ++y)
        for (int x = 0; x < d.cols; ++x) {
            const double e = d.at<double>(y, x) - mu, e2 = e * e;
            m2 += e2;
            m4 += e2 * e2;
            const double ra = std::round(fa.at<double>(y, x)) + rng.uniform(-0.5, 0.5),
                         rb = std::round(fb.at<double>(y, x)) + rng.uniform(-0.5, 0.5);
            p.values.push_back(static_cast<float>((ra - rb) / std::sqrt(2.0)));
            dithered += p.values.back();
        }
    const double count = static_cast<double>(d.total());
    p.kurtosis = (m4 / count) / ((m2 / count) * (m2 / count)) - 3;
    for (float& v : p.values)
        v -= static_cast<float>(dithered / count);
    return p;
}

// The spatial set's dark stack, each frame as read (CV_16UC1) and as doubles.
struct DarkStack
{
    std::vector<Mat> raw, values;
    Mat rowMeans; // parityRowMeans()
    double level = 0;
};

DarkStack readDarkStack(const Emva1288Series& series)
{
    const auto dark = std::find_if(series.spatial.begin(), series.spatial.end(),
                                   [](const Emva1288Images& g) { return g.dark; });
    if (dark == series.spatial.end() || dark->images.size() < 6)
        CV_Error(Error::StsBadArg,
                 "the EMVA 1288 bank study needs a spatial set of at least 6 dark frames in '" + series.path +
                     "'");
    DarkStack s;
    for (const String& image : dark->images) {
        s.raw.push_back(readEmva1288Image(series, image, dark->line));
        Mat v;
        s.raw.back().convertTo(v, CV_64F);
        s.level += cv::mean(v)[0] / static_cast<double>(dark->images.size());
        s.values.push_back(v);
    }
    s.rowMeans = parityRowMeans(s.values);
    return s;
}

const Emva1288Images& imagesOfPoint(const Emva1288Series& series, const Emva1288Results& results, int point)
{
    for (const Emva1288Images& g : series.temporal)
        if (!g.dark && g.exposureNs == results.exposureNs[static_cast<size_t>(point)] &&
            g.photons == results.photons[static_cast<size_t>(point)])
            return g;
    CV_Error(Error::StsBadArg, cv::format("no bright pair of point %d in '%s'", point, series.path.c_str()));
}

} // namespace

Emva1288BankStudy runEmva1288BankStudy(const std::string& descriptor, const std::string& workDir, int draws)
{
    CV_Assert(draws >= 1);
    Emva1288BankStudy study;
    const Emva1288Series series = readEmva1288(descriptor);
    const Emva1288Results results = emva1288Results(series);
    const NoiseModel model = calibrateEmva1288({results}, {1.0}).model;
    const DarkStack stack = readDarkStack(series);
    const int frames = static_cast<int>(stack.raw.size()), half = frames / 2;
    std::vector<int> first(static_cast<size_t>(half)), second(static_cast<size_t>(frames - half));
    std::iota(first.begin(), first.end(), 0);
    std::iota(second.begin(), second.end(), half);

    // The bank of the first half, as PNG mosaics with sidecars: gain 1, the stack's mean as its black level.
    RawFormat format;
    format.pattern = CFA_MONO;
    format.blackLevel = Vec4d::all(stack.level);
    format.whiteLevel = std::ldexp(1.0, series.bits) - 1;
    std::filesystem::remove_all(workDir);
    std::filesystem::create_directories(workDir);
    std::vector<String> files;
    std::vector<Mat> firstRaw;
    for (int t : first) {
        MosaicMetadata meta;
        meta.format = format;
        files.push_back(workDir + cv::format("/dark_%02d.png", t));
        writeMosaic(files.back(), stack.raw[static_cast<size_t>(t)], meta);
        firstRaw.push_back(stack.raw[static_cast<size_t>(t)]);
    }
    DarkFrameBank bank = DarkFrameBank::create(files, model);
    bank.save(workDir + "/bank.yml");
    const DarkFrameStatistics& bs = bank.groups.front().statistics;

    // The components, calibrated from the same frames: the Tukey shape by calibrateDarkNoise(); row noise and
    // shading, which it fits across gains only, from the burst's own statistics (the row variance moved out
    // of the read terms, the shading the burst's plain mean).
    DarkCalibrationParams dp;
    dp.rowNoise = false;
    dp.darkShading = false;
    NoiseModel components = calibrateDarkNoise({firstRaw}, {1.0}, format, model, dp).model;
    Mat pixelMean;
    const DarkGainStatistics ds = darkBurstStatistics(firstRaw, format, 1.0, pixelMean);
    components.rowSigmaR2 = ds.rowVariance;
    components.sigmaR2 = std::max(0.0, model.sigmaR2 - ds.rowVariance);
    Mat offset;
    pixelMean.convertTo(offset, CV_32F, 1, -cv::mean(pixelMean)[0]);
    components.darkShadingOffset = offset;
    components.darkShadingPerGain = Mat::zeros(offset.size(), CV_32F);

    // Half against half: each method's figures from the first half against the second half's own.
    const auto a = figuresWithErrors(stack.values, stack.rowMeans, first);
    const auto b = figuresWithErrors(stack.values, stack.rowMeans, second);
    const std::string halves = "half against half";
    const auto add = [&](const std::string& part, const std::string& method, const std::string& measure,
                         double value, double real, double se) {
        study.rows.push_back({part, method, measure, value, real, se});
    };
    const char* bankName = "bank, accounted (untied)";
    const char* temporal = "temporal variance (DN^2)";
    const char* pattern = "fixed pattern it adds, variance (DN^2)";
    const char* rows = "row noise (DN^2)";
    const char* kurtosis = "excess kurtosis of a frame";
    add(halves, bankName, temporal, siteAverage(bs.temporalVariance), b.first.temporal,
        std::hypot(a.second.temporal, b.second.temporal));
    add(halves, bankName, pattern, siteSpatialVariance(bs.pattern), b.first.fixedPattern,
        std::hypot(a.second.fixedPattern, b.second.fixedPattern));
    add(halves, bankName, rows, siteAverage(bs.rowNoiseVariance), b.first.rowNoise,
        std::hypot(a.second.rowNoise, b.second.rowNoise));
    // The draws (a frame less its group's mean) keep residualKurtosis of a frame's shape.
    add(halves, bankName, kurtosis, a.first.residualKurtosis, b.first.kurtosis,
        std::hypot(a.second.residualKurtosis, b.second.kurtosis));
    const char* componentsName = "calibrated components";
    add(halves, componentsName, temporal, ds.pixelVariance + ds.rowVariance, b.first.temporal,
        std::hypot(a.second.temporal, b.second.temporal));
    add(halves, componentsName, pattern, siteSpatialVariance(offset), b.first.fixedPattern,
        std::hypot(a.second.meanVariance, b.second.fixedPattern));
    add(halves, componentsName, rows, ds.rowVariance, b.first.rowNoise,
        std::hypot(a.second.rowNoise, b.second.rowNoise));
    add(halves, componentsName, kurtosis, components.readExcessKurtosis(), b.first.kurtosis,
        std::hypot(a.second.kurtosis, b.second.kurtosis));
    const char* gaussianName = "Gaussian read noise";
    add(halves, gaussianName, temporal, a.first.temporal, b.first.temporal,
        std::hypot(a.second.temporal, b.second.temporal));
    add(halves, gaussianName, pattern, 0, b.first.fixedPattern, b.second.fixedPattern);
    add(halves, gaussianName, rows, 0, b.first.rowNoise, b.second.rowNoise);
    add(halves, gaussianName, kurtosis, 0, b.first.kurtosis, b.second.kurtosis);
    study.bankFixedPattern = siteAverage(bs.patternVariance);
    study.studyFixedPattern = a.first.fixedPattern;
    study.notes.push_back(cv::format(
        "Halves: the spatial set's dark frames %d-%d (the bank's) against %d-%d, %dx%d, at %.1f DN. The "
        "first "
        "half's plain mean has spatial variance %.4f DN^2, of which v/N is %.4f; the bank's own figure "
        "(Var(mean) - v/M) is %.4f, the study's arithmetic on the same frames %.4f.",
        first.front(), first.back(), second.front(), second.back(), series.width, series.height, stack.level,
        a.first.meanVariance, a.first.temporal / half, siteAverage(bs.patternVariance),
        a.first.fixedPattern));

    // Darkened steps: every method with its own seeds, each pair drawn `draws` times.
    const std::vector<Point> steps = emva1288DarkeningSteps(results);
    const double scatter = emva1288Darkening(series, results, model, {steps.front()}, 1).front().pairScatter;
    study.notes.push_back(cv::format(
        "Darkened steps: bright steps to darker ones (emva1288DarkeningSteps()), each augmented pair drawn "
        "%d "
        "times; the variance's error holds the series' pair-to-pair scatter (%.2f, emva1288Darkening()); the "
        "KS statistic's 'error' is a third of its critical value at p = 0.0027 (3 standard errors), its "
        "pixels "
        "taken as independent, each frame rounded as a sensor's output is, dithered and centred.",
        draws, scatter));
    struct Method
    {
        const char* name;
        NoiseAlignment alignment;
        bool bank;
        const NoiseModel* model;
    };
    const Method methods[4] = {
        {bankName, NoiseAlignment::ACCOUNT_PRIOR, true, &model},
        {"bank, prior ignored (the peer's)", NoiseAlignment::IGNORE_PRIOR, true, &model},
        {componentsName, NoiseAlignment::ACCOUNT_PRIOR, false, &components},
        {gaussianName, NoiseAlignment::ACCOUNT_PRIOR, false, &model}};
    for (size_t k = 0; k < steps.size(); ++k) {
        const int i = steps[k].x, j = steps[k].y;
        const Emva1288Images &bright = imagesOfPoint(series, results, i),
                             &dark = imagesOfPoint(series, results, j);
        Mat in[2], real[2];
        for (int f = 0; f < 2; ++f) {
            readEmva1288Image(series, bright.images[static_cast<size_t>(f)], bright.line)
                .convertTo(in[f], CV_32F);
            real[f] = readEmva1288Image(series, dark.images[static_cast<size_t>(f)], dark.line);
        }
        const double ratio =
            results.photons[static_cast<size_t>(j)] / results.photons[static_cast<size_t>(i)];
        const std::string part = cv::format("step %d to %d (photon ratio %.3f)", i, j, ratio);
        const PairFigures r = figuresOfPair(real[0], real[1], 7 * k);
        RawFormat stepFormat = format;
        stepFormat.blackLevel = Vec4d::all(results.darkMean[static_cast<size_t>(i)]);
        for (int m = 0; m < 4; ++m) {
            NoiseOptions options(methods[m].alignment);
            if (methods[m].bank)
                options.darkBank = bank.path;
            std::vector<PairFigures> drawn;
            std::vector<float> pooled;
            for (int d = 0; d < draws; ++d) {
                Mat out[2];
                for (int f = 0; f < 2; ++f) {
                    RawFormat outFormat;
                    colorJitter(in[f], stepFormat, *methods[m].model, ColorJitter::exposureChange(ratio, 1.0),
                                options, 1000 * k + 10 * static_cast<uint64>(d) + static_cast<uint64>(f),
                                out[f], outFormat);
                }
                drawn.push_back(figuresOfPair(out[0], out[1], 7 * k + 1 + static_cast<uint64>(d)));
                pooled.insert(pooled.end(), drawn.back().values.begin(), drawn.back().values.end());
            }
            /* Each figure is the mean over the draws. Its error: the input pair is one and the same in every
             * draw, so its share of the pixels' error does not average out (taken whole), and the draws' own
             * spread counts what varies between them (a bank's draws repeat a frame: two outputs share one
             * with probability 1/M, and their difference then lacks it). */
            const auto meanAndSpread = [&](double PairFigures::*field) {
                double mean = 0, ss = 0;
                for (const PairFigures& p : drawn)
                    mean += p.*field / draws;
                for (const PairFigures& p : drawn)
                    ss += (p.*field - mean) * (p.*field - mean);
                return std::make_pair(mean, draws > 1 ? ss / (draws - 1) / draws : 0.0);
            };
            const auto variance = meanAndSpread(&PairFigures::variance);
            const auto pixelSe = meanAndSpread(&PairFigures::varianceSe);
            const auto rowMean = meanAndSpread(&PairFigures::rowMeanVariance);
            const auto kurt = meanAndSpread(&PairFigures::kurtosis);
            const double rows_ = in[0].rows, pixels = static_cast<double>(in[0].total());
            add(part, methods[m].name, temporal, variance.first, r.variance,
                std::sqrt(scatter * (r.varianceSe * r.varianceSe + pixelSe.first * pixelSe.first) +
                          variance.second));
            add(part, methods[m].name, "row-mean variance of (A - B)/sqrt(2) (DN^2)", rowMean.first,
                r.rowMeanVariance,
                std::sqrt(2 / (rows_ - 1) *
                              (r.rowMeanVariance * r.rowMeanVariance + rowMean.first * rowMean.first) +
                          rowMean.second));
            add(part, methods[m].name, "excess kurtosis of (A - B)/sqrt(2)", kurt.first, r.kurtosis,
                std::sqrt(2 * 24 / pixels + kurt.second));
            const double n1 = static_cast<double>(pooled.size()), n2 = static_cast<double>(r.values.size());
            add(part, methods[m].name, "KS statistic of (A - B)/sqrt(2) against the real pair's",
                ksStatistic(pooled, r.values), 0,
                std::sqrt(-0.5 * std::log(0.0027 / 2)) * std::sqrt((n1 + n2) / (n1 * n2)) / 3);
        }
    }
    return study;
}

std::string emva1288BankStudyMarkdown(const Emva1288BankStudy& study)
{
    std::ostringstream md;
    for (const std::string& note : study.notes)
        md << note << "\n\n";
    md << "| part | method | measure | method's | real | difference / SE | told apart (> 3 SE) |\n";
    md << "|---|---|---|---:|---:|---:|---|\n";
    for (const RealComparison& r : study.rows)
        md << "| " << r.part << " | " << r.method << " | " << r.measure << " | "
           << cv::format("%.4f", r.value) << " | " << cv::format("%.4f", r.real) << " | "
           << cv::format("%+.1f", (r.value - r.real) / r.se) << " | " << (r.distinguishable() ? "yes" : "no")
           << " |\n";
    return md.str();
}

} // namespace rawgment_studies
