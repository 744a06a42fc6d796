// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The dark-frame bank against independent captures (dark_bank_study.hpp).
#include "dark_bank_study.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>

namespace rawgment_studies {

double residualKurtosisFactor(int n)
{
    const double a = 1 - 1.0 / n;
    return (std::pow(a, 4) + (n - 1) / std::pow(static_cast<double>(n), 4)) / (a * a);
}

double ksStatistic(std::vector<float> a, std::vector<float> b)
{
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    size_t i = 0, j = 0;
    double d = 0;
    while (i < a.size() && j < b.size()) {
        const float t = std::min(a[i], b[j]);
        while (i < a.size() && a[i] == t)
            ++i;
        while (j < b.size() && b[j] == t)
            ++j;
        d = std::max(d, std::abs(static_cast<double>(i) / a.size() - static_cast<double>(j) / b.size()));
    }
    return d;
}

namespace {

using namespace cv;
using namespace cv::rawgment;

/* The parametric components (row noise, dark shading with a column ramp, Tukey lambda -0.1 tails) and what
 * they do not describe: 0.2% hot pixels, 1% noisy pixels (100 DN^2 more), column banding of 1 DN^2. */
SensorParams departingSensor(Size size, uint64 seed)
{
    SensorParams p;
    p.noise.rowSigmaD2 = 0.3;
    p.noise.rowSigmaR2 = 0.5;
    p.noise.tukeyRead = true;
    p.noise.tukeyLambda = -0.1;
    Mat bd(size, CV_32FC1), br(size, CV_32FC1);
    RNG rng(seed);
    rng.fill(bd, RNG::NORMAL, 0, 0.8);
    rng.fill(br, RNG::NORMAL, 0, 2.0);
    for (int c = 0; c < size.width; ++c)
        bd.col(c) += 2.0 * c / size.width;
    p.noise.darkShadingPerGain = bd;
    p.noise.darkShadingOffset = br;
    p.dsnu = 0.3;
    p.hotPixelFraction = 0.002;
    p.noisyPixelFraction = 0.01;
    p.noisyPixelVariance = 100;
    p.columnNoiseVariance = 1;
    p.fixedPatternSeed = seed;
    return p;
}

double excessKurtosis(const std::vector<double>& values)
{
    double mean = 0;
    for (double v : values)
        mean += v / values.size();
    double m2 = 0, m4 = 0;
    for (double v : values) {
        const double d = (v - mean) * (v - mean);
        m2 += d / values.size();
        m4 += d * d / values.size();
    }
    return m4 / (m2 * m2) - 3;
}

struct StackFigures
{
    double rowPart = 0, columnPart = 0, pixelPart = 0, fpnVariance = 0, kurtosis = 0;
    double ordinaryPixelPart = 0;              // the pixel part of the pixels the kurtosis pools
    std::vector<double> hotMeans;              // the hot pixels' means over the frames, in raster order
    std::vector<std::vector<float>> residuals; // per frame: the pixel part of every 7th kept pixel, for KS
};

double varianceOf(const std::vector<double>& v)
{
    double s = 0, s2 = 0;
    for (double x : v) {
        s += x;
        s2 += x * x;
    }
    return (s2 - s * s / v.size()) / (v.size() - 1);
}

/* What the study measures of N frames over the pixels `keep` marks (not hot, not dead: they have no temporal
 * noise), and the means of the `hot` ones. The kurtosis is the `ordinary` pixels' (not noisy either): pooled
 * over pixels of one variance, it is the mixture of its parts' cumulants. */
StackFigures figuresOf(const std::vector<Mat>& frames, const Mat& keep, const Mat& hot, const Mat& ordinary)
{
    const int n = static_cast<int>(frames.size()), rows = frames[0].rows, cols = frames[0].cols;
    std::vector<Mat> x(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i)
        frames[static_cast<size_t>(i)].convertTo(x[static_cast<size_t>(i)], CV_64F);
    std::vector<std::vector<double>> rowMeans(static_cast<size_t>(rows)), colMeans(static_cast<size_t>(cols));
    for (const Mat& f : x) {
        std::vector<double> colSum(static_cast<size_t>(cols), 0), colCount(static_cast<size_t>(cols), 0);
        for (int r = 0; r < rows; ++r) {
            double sum = 0, count = 0;
            for (int c = 0; c < cols; ++c)
                if (keep.at<uchar>(r, c)) {
                    sum += f.at<double>(r, c);
                    count += 1;
                    colSum[static_cast<size_t>(c)] += f.at<double>(r, c);
                    colCount[static_cast<size_t>(c)] += 1;
                }
            rowMeans[static_cast<size_t>(r)].push_back(sum / count);
        }
        for (int c = 0; c < cols; ++c)
            colMeans[static_cast<size_t>(c)].push_back(colSum[static_cast<size_t>(c)] /
                                                       colCount[static_cast<size_t>(c)]);
    }
    StackFigures s;
    for (const auto& m : rowMeans)
        s.rowPart += varianceOf(m) / rows;
    for (const auto& m : colMeans)
        s.columnPart += varianceOf(m) / cols;
    s.residuals.resize(static_cast<size_t>(n));
    std::vector<double> pooled;
    double pixelSum = 0, pixelCount = 0, ordinarySum = 0, ordinaryCount = 0, ordinarySquares = 0;
    double siteSum[4] = {0, 0, 0, 0}, siteSum2[4] = {0, 0, 0, 0}, siteOwn[4] = {0, 0, 0, 0},
           siteN[4] = {0, 0, 0, 0};
    int kept = 0;
    std::vector<double> y(static_cast<size_t>(n)), v(static_cast<size_t>(n));
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            for (int i = 0; i < n; ++i)
                v[static_cast<size_t>(i)] = x[static_cast<size_t>(i)].at<double>(r, c);
            double mean = 0;
            for (double value : v)
                mean += value / n;
            if (hot.at<uchar>(r, c))
                s.hotMeans.push_back(mean);
            if (!keep.at<uchar>(r, c))
                continue;
            const int site = cfaSite(r, c);
            siteSum[site] += mean;
            siteSum2[site] += mean * mean;
            siteOwn[site] += varianceOf(v);
            siteN[site] += 1;
            double yMean = 0;
            for (int i = 0; i < n; ++i) {
                y[static_cast<size_t>(i)] =
                    v[static_cast<size_t>(i)] - rowMeans[static_cast<size_t>(r)][static_cast<size_t>(i)];
                yMean += y[static_cast<size_t>(i)] / n;
            }
            double ss = 0;
            const bool sampled = kept++ % 7 == 0;
            for (int i = 0; i < n; ++i) {
                const double e = y[static_cast<size_t>(i)] - yMean;
                ss += e * e;
                if (ordinary.at<uchar>(r, c))
                    pooled.push_back(e);
                if (sampled)
                    s.residuals[static_cast<size_t>(i)].push_back(static_cast<float>(e));
            }
            pixelSum += ss / (n - 1);
            pixelCount += 1;
            if (ordinary.at<uchar>(r, c)) {
                ordinarySum += ss / (n - 1);
                ordinarySquares += (ss / (n - 1)) * (ss / (n - 1));
                ordinaryCount += 1;
            }
        }
    s.pixelPart = pixelSum / pixelCount;
    s.ordinaryPixelPart = ordinarySum / ordinaryCount;
    /* Residuals about each pixel's own mean of n frames mix in 1/n of the others, which scales the fourth
     * cumulants by residualKurtosisFactor(n), but not the part of a pooled kurtosis that comes from pixels of
     * different variances, 3 (E[sigma^4] / E[sigma^2]^2 - 1): a bank's draws carry it (each pixel's M frames
     * have their own spread). Dividing it by the factor too put the bank's kurtosis 0.04 high. Each pixel's
     * sample variance over n frames scatters by kappa / n + 2 / (n - 1) of its square, which comes out of
     * E[sigma^4]. */
    const double factor = residualKurtosisFactor(n), raw = excessKurtosis(pooled);
    const double meanVariance = ordinarySum / ordinaryCount,
                 meanSquare = ordinarySquares / ordinaryCount / (1 + raw / factor / n + 2.0 / (n - 1));
    const double spread = std::max(0.0, 3 * (meanSquare / (meanVariance * meanVariance) - 1));
    s.kurtosis = raw / factor - spread * (1 / factor - 1);
    for (int site = 0; site < 4; ++site) {
        const double m = siteN[site];
        s.fpnVariance +=
            ((siteSum2[site] - siteSum[site] * siteSum[site] / m) / (m - 1) - siteOwn[site] / m / n) / 4;
    }
    return s;
}

std::vector<float> concatenated(const std::vector<const std::vector<float>*>& frames)
{
    std::vector<float> all;
    for (const std::vector<float>* f : frames)
        all.insert(all.end(), f->begin(), f->end());
    return all;
}

/* The two-sample KS statistic of a method's pixel parts against the target's, and whether it rejects at 5%
 * against a null from a bootstrap over frames: two sets of N frames drawn with replacement from both stacks
 * together (pixels of one frame share its row and column offsets, so a plain KS test over them rejects
 * everything). */
std::pair<double, bool> ksAgainstTarget(const StackFigures& method, const StackFigures& target, int bootstrap,
                                        uint64 seed)
{
    std::vector<const std::vector<float>*> m, t, pool;
    for (const auto& f : method.residuals)
        m.push_back(&f);
    for (const auto& f : target.residuals)
        t.push_back(&f);
    pool = m;
    pool.insert(pool.end(), t.begin(), t.end());
    const double observed = ksStatistic(concatenated(m), concatenated(t));
    RNG rng(seed);
    int atLeast = 0;
    for (int b = 0; b < bootstrap; ++b) {
        std::vector<const std::vector<float>*> x, y;
        for (size_t i = 0; i < m.size(); ++i) {
            x.push_back(pool[static_cast<size_t>(rng.uniform(0, static_cast<int>(pool.size())))]);
            y.push_back(pool[static_cast<size_t>(rng.uniform(0, static_cast<int>(pool.size())))]);
        }
        atLeast += ksStatistic(concatenated(x), concatenated(y)) >= observed;
    }
    return {observed, (atLeast + 1.0) / (bootstrap + 1.0) < 0.05};
}

//! The bank's draws' pixel part, each frame less the frames' mean (their scale does not change the shape)
//! less its row mean, over the `ordinary` pixels: its excess kurtosis.
double drawKurtosis(const std::vector<Mat>& frames, const Mat& ordinary)
{
    Mat mean = Mat::zeros(frames[0].size(), CV_64F);
    for (const Mat& f : frames)
        accumulate(f, mean);
    mean /= static_cast<double>(frames.size());
    std::vector<double> values;
    for (const Mat& f : frames) {
        Mat d;
        f.convertTo(d, CV_64F);
        d -= mean;
        for (int r = 0; r < d.rows; ++r) {
            double sum = 0, count = 0;
            for (int c = 0; c < d.cols; ++c)
                if (ordinary.at<uchar>(r, c)) {
                    sum += d.at<double>(r, c);
                    count += 1;
                }
            for (int c = 0; c < d.cols; ++c)
                if (ordinary.at<uchar>(r, c))
                    values.push_back(d.at<double>(r, c) - sum / count);
        }
    }
    return excessKurtosis(values);
}

struct Differences
{
    std::vector<double> row, column, pixel, fpn, hot, kurtosis, expected, ks;
    int rejected = 0;
};

void summarise(const Differences& d, DarkBankMethod& m)
{
    const auto meanAndSe = [](const std::vector<double>& v, double& mean, double& se) {
        mean = 0;
        for (double x : v)
            mean += x / v.size();
        se = v.size() > 1 ? std::sqrt(std::max(0.0, varianceOf(v)) / v.size()) : 0.0;
    };
    meanAndSe(d.row, m.rowPart, m.rowPartSe);
    meanAndSe(d.column, m.columnPart, m.columnPartSe);
    meanAndSe(d.pixel, m.pixelPart, m.pixelPartSe);
    meanAndSe(d.fpn, m.fpnRms, m.fpnRmsSe);
    meanAndSe(d.hot, m.hotError, m.hotErrorSe);
    meanAndSe(d.kurtosis, m.kurtosis, m.kurtosisSe);
    if (d.expected.empty()) {
        m.expectedKurtosis = m.expectedKurtosisSe = std::numeric_limits<double>::quiet_NaN();
    } else {
        meanAndSe(d.expected, m.expectedKurtosis, m.expectedKurtosisSe);
    }
    double ksSe = 0;
    meanAndSe(d.ks, m.ks, ksSe);
    m.ksRejected = d.rejected;
}

} // namespace

DarkBankStudy runDarkBankStudy(const DarkBankStudySettings& st)
{
    const char* names[4] = {"bank, accounted (tied)", "bank, prior ignored (the peer's)",
                            "calibrated components", "Gaussian read noise"};
    Differences diffs[4], target;
    const double k = st.contrast, ratio = st.gainOut / st.gainIn;
    for (int campaign = 0; campaign < st.campaigns; ++campaign) {
        const uint64 seed = 1000 + static_cast<uint64>(campaign);
        const SensorSimulator sensor(departingSensor(st.size, seed), st.size);
        Mat prnu, dsnu, defects;
        sensor.fixedPattern(prnu, dsnu, defects);
        const Mat keep = (defects != 1) & (defects != 2), hot = defects == 1, ordinary = defects == 0;
        const auto capture = [&](double gain, int frame) {
            Mat raw;
            sensor.capture(Mat::zeros(st.size, CV_32F), gain, 1.0, seed, frame, raw);
            return raw;
        };
        // The bank: frames other than the targets, beside its file.
        const std::string dir = st.workDir + cv::format("/campaign_%02d", campaign);
        std::filesystem::create_directories(dir);
        std::vector<String> files;
        std::vector<std::vector<Mat>> bursts(2);
        for (int g = 0; g < 2; ++g)
            for (int t = 0; t < st.bankFrames; ++t) {
                const double gain = g == 0 ? st.gainIn : st.gainOut;
                bursts[static_cast<size_t>(g)].push_back(capture(gain, 100 * (g + 1) + t));
                MosaicMetadata meta;
                meta.format = sensor.rawFormat(gain);
                files.push_back(dir + cv::format("/dark_%d_%02d.png", g, t));
                writeMosaic(files.back(), bursts[static_cast<size_t>(g)].back(), meta);
            }
        DarkFrameBank bank = DarkFrameBank::create(files, NoiseModel());
        bank.save(dir + "/bank.yml");
        // The models: no shot noise (dark frames hold no photons); the Gaussian's read variance is what a
        // pixel's temporal variance measures (rows and columns in it), the components calibrated from the
        // bank's own frames on top of that.
        NoiseModel gaussian = sensor.effectiveModel();
        gaussian.alpha = 0;
        gaussian.rowSigmaD2 = gaussian.rowSigmaR2 = 0;
        gaussian.tukeyRead = false;
        gaussian.darkShadingPerGain.release();
        gaussian.darkShadingOffset.release();
        gaussian.sigmaD2 += sensor.params().noise.rowSigmaD2;
        gaussian.sigmaR2 += sensor.params().noise.rowSigmaR2 + sensor.params().columnNoiseVariance;
        const NoiseModel components =
            calibrateDarkNoise(bursts, {st.gainIn, st.gainOut}, sensor.rawFormat(1.0), gaussian).model;
        std::vector<Mat> inputs, targets, outputs[4];
        for (int i = 0; i < st.outputs; ++i) {
            inputs.push_back(capture(st.gainIn, 2000 + i));
            targets.push_back(capture(st.gainOut, 3000 + i));
            ColorJitter jitter;
            jitter.contrast = Vec4d::all(k);
            jitter.gainRatio = ratio;
            for (int m = 0; m < 4; ++m) {
                NoiseOptions options(m == 1 ? NoiseAlignment::IGNORE_PRIOR : NoiseAlignment::ACCOUNT_PRIOR);
                if (m < 2) {
                    options.darkBank = dir + "/bank.yml";
                    options.darkBankTied = true;
                }
                Mat out;
                RawFormat outFormat;
                colorJitter(inputs.back(), sensor.rawFormat(st.gainIn), m == 2 ? components : gaussian,
                            jitter, options, seed * 100 + static_cast<uint64>(i), out, outFormat);
                outputs[m].push_back(out);
            }
        }
        const StackFigures in = figuresOf(inputs, keep, hot, ordinary),
                           t = figuresOf(targets, keep, hot, ordinary);
        double hotLevel = 0;
        for (double h : t.hotMeans)
            hotLevel += h / t.hotMeans.size();
        target.hot.push_back(hotLevel);
        target.row.push_back(t.rowPart);
        target.column.push_back(t.columnPart);
        target.pixel.push_back(t.pixelPart);
        target.fpn.push_back(std::sqrt(std::max(0.0, t.fpnVariance)));
        target.kurtosis.push_back(t.kurtosis);
        const double kappaDraws = drawKurtosis(bursts[1], ordinary);
        for (int m = 0; m < 4; ++m) {
            const StackFigures f = figuresOf(outputs[m], keep, hot, ordinary);
            double hotError = 0;
            for (size_t h = 0; h < f.hotMeans.size(); ++h)
                hotError += std::pow(f.hotMeans[h] - t.hotMeans[h], 2) / f.hotMeans.size();
            Differences& d = diffs[m];
            d.row.push_back(f.rowPart - t.rowPart);
            d.column.push_back(f.columnPart - t.columnPart);
            d.pixel.push_back(f.pixelPart - t.pixelPart);
            d.fpn.push_back(std::sqrt(std::max(0.0, f.fpnVariance)) -
                            std::sqrt(std::max(0.0, t.fpnVariance)));
            d.hot.push_back(std::sqrt(hotError));
            d.kurtosis.push_back(f.kurtosis - t.kurtosis);
            // The mixture's kurtosis over the pixels it pools: fourth cumulants add, k^4 of the input's, the
            // added part's, less the output's rounding (a uniform 1/12 DN^2, excess kurtosis -1.2). The added
            // part of a pixel, accounted or whole frames, is drawn with replacement from its M frames (less
            // their mean, which a pixel's own mean over the outputs takes out): its shape is that finite
            // population's, measured on the frames themselves, not the sensor's.
            if (m < 2) {
                const double vin = k * k * in.ordinaryPixelPart, added = f.ordinaryPixelPart - vin - 1.0 / 12;
                const double expected = (vin * vin * in.kurtosis + added * added * kappaDraws - 1.2 / 144) /
                                        (f.ordinaryPixelPart * f.ordinaryPixelPart);
                d.expected.push_back(f.kurtosis - expected);
            }
            const auto ks = ksAgainstTarget(f, t, st.bootstrap, seed * 10 + static_cast<uint64>(m));
            d.ks.push_back(ks.first);
            d.rejected += ks.second;
        }
    }
    DarkBankStudy study;
    study.campaigns = st.campaigns;
    summarise(target, study.target);
    study.target.name = "target captures (their values)";
    for (int m = 0; m < 4; ++m) {
        DarkBankMethod method;
        summarise(diffs[m], method);
        method.name = names[m];
        study.methods.push_back(method);
    }
    return study;
}

std::string darkBankStudyMarkdown(const DarkBankStudy& s, const DarkBankStudySettings& st)
{
    std::ostringstream md;
    md << cv::format(
        "%d campaigns of a %dx%d simulated sensor, each with its own fixed pattern; a tied bank of %d dark "
        "frames at gains %g and %g (not the targets); %d dark inputs at gain %g taken to gain %g at k = "
        "%g, against %d independent target captures. Each figure is the method's less the "
        "target's, mean +- standard error over the campaigns (the target's row: its values).\n\n",
        s.campaigns, st.size.width, st.size.height, st.bankFrames, st.gainIn, st.gainOut, st.outputs,
        st.gainIn, st.gainOut, st.contrast, st.outputs);
    md << "| method | row part (DN^2) | column part (DN^2) | pixel part (DN^2) | fixed-pattern RMS (DN) | "
          "hot "
          "pixels' level (DN) | excess kurtosis | kurtosis less its mixture's | KS D | KS rejects (5%) |\n";
    md << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    const auto cell = [](double v, double se) { return cv::format("%+.3f +- %.3f", v, se); };
    const DarkBankMethod& t = s.target;
    md << "| " << t.name << " | " << cv::format("%.3f", t.rowPart) << " | "
       << cv::format("%.3f", t.columnPart) << " | " << cv::format("%.3f", t.pixelPart) << " | "
       << cv::format("%.3f", t.fpnRms) << " | " << cv::format("%.1f", t.hotError) << " | "
       << cv::format("%.3f", t.kurtosis) << " | - | - | - |\n";
    for (const DarkBankMethod& m : s.methods)
        md << "| " << m.name << " | " << cell(m.rowPart, m.rowPartSe) << " | "
           << cell(m.columnPart, m.columnPartSe) << " | " << cell(m.pixelPart, m.pixelPartSe) << " | "
           << cell(m.fpnRms, m.fpnRmsSe) << " | "
           << cv::format("%.2f +- %.2f (RMS error)", m.hotError, m.hotErrorSe) << " | "
           << cell(m.kurtosis, m.kurtosisSe) << " | "
           << (std::isnan(m.expectedKurtosis) ? std::string("-")
                                              : cell(m.expectedKurtosis, m.expectedKurtosisSe))
           << " | " << cv::format("%.4f", m.ks) << " | " << m.ksRejected << " of " << s.campaigns << " |\n";
    return md.str();
}

} // namespace rawgment_studies
