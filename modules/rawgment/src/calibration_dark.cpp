// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Calibration of the dark-frame components (row noise, dark shading, Tukey-lambda read noise) from
// bursts of dark frames; the equations are in docs/mathematics.md, "Dark-frame noise".
#include "noise_terms.hpp"
#include "opencv2/rawgment/calibration.hpp"
#include "precomp.hpp"

#include <algorithm>
#include <numeric>

namespace cv {
namespace rawgment {

namespace {

//! How many distinct gains there are (gains within 1e-9 of each other count as one).
int distinctGains(std::vector<double> gains)
{
    std::sort(gains.begin(), gains.end());
    int distinct = gains.empty() ? 0 : 1;
    for (size_t k = 1; k < gains.size(); ++k)
        distinct += gains[k] > gains[k - 1] * (1 + 1e-9) ? 1 : 0;
    return distinct;
}

// What one gain's burst gives: its statistics, its temporal mean and its residual samples.
struct GainData
{
    DarkGainStatistics stats;
    Mat mean;                       // CV_64FC1 temporal mean, black-subtracted
    std::vector<double> ppccSample; // residuals without the rows, a spread-out subsample
};

// Per-row sums of one frame's residual: its row mean R, and the sums of R^2, f^2 and f^4 (f = e - R).
struct RowSums
{
    double R = 0, r2 = 0, f2 = 0, f4 = 0;
};

// The black-subtracted values of a burst, read row by row from the caller's frames: a burst of 24 MP
// frames held as doubles would take 6 GB at 32 frames.
class BlackSubtracted
{
public:
    BlackSubtracted(const std::vector<Mat>& frames, const RawFormat& format)
        : frames_(frames), format_(format)
    {
    }
    double at(int t, int r, int c) const
    {
        const Mat& f = frames_[static_cast<size_t>(t)];
        const double v = f.depth() == CV_16U ? f.ptr<ushort>(r)[c] : static_cast<double>(f.ptr<float>(r)[c]);
        return v - format_.blackAt(r, c);
    }
    void row(int t, int r, double* out, int width) const
    {
        const Mat& f = frames_[static_cast<size_t>(t)];
        const double b[2] = {format_.blackAt(r, 0), format_.blackAt(r, 1)};
        if (f.depth() == CV_16U) {
            const ushort* p = f.ptr<ushort>(r);
            for (int c = 0; c < width; ++c)
                out[c] = p[c] - b[c & 1];
        } else {
            const float* p = f.ptr<float>(r);
            for (int c = 0; c < width; ++c)
                out[c] = static_cast<double>(p[c]) - b[c & 1];
        }
    }

private:
    const std::vector<Mat>& frames_;
    const RawFormat& format_;
};

GainData analyseGain(const std::vector<Mat>& frames, double gain, const RawFormat& format, int ppccSamples,
                     Size size, int type)
{
    const int T = static_cast<int>(frames.size()), H = size.height, W = size.width;
    if (T < 3)
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateDarkNoise: the burst at gain %g has %d frames; at least 3 are "
                            "needed (the temporal mean and two residuals)",
                            gain, T));
    for (int t = 0; t < T; ++t) {
        const Mat& f = frames[static_cast<size_t>(t)];
        if (f.size() != size || f.type() != type)
            CV_Error(Error::StsBadArg,
                     cv::format(
                         "calibrateDarkNoise: frame %d at gain %g is %s %dx%d; every frame must be %s %dx%d",
                         t, gain, typeToString(f.type()).c_str(), f.cols, f.rows, typeToString(type).c_str(),
                         size.width, size.height));
        if (type == CV_32FC1 && !checkRange(f, true))
            CV_Error(Error::StsBadArg,
                     cv::format("calibrateDarkNoise: frame %d at gain %g has NaN or Inf", t, gain));
    }
    const BlackSubtracted x(frames, format);
    GainData d;
    d.mean = Mat::zeros(size, CV_64FC1);
    // Per row, then per (frame, row): every sum is made in one order whatever the threads.
    parallel_for_(Range(0, H), [&](const Range& range) {
        std::vector<double> values(static_cast<size_t>(W));
        for (int r = range.start; r < range.end; ++r) {
            double* m = d.mean.ptr<double>(r);
            for (int t = 0; t < T; ++t) {
                x.row(t, r, values.data(), W);
                for (int c = 0; c < W; ++c)
                    m[c] += values[static_cast<size_t>(c)];
            }
            for (int c = 0; c < W; ++c)
                m[c] /= T;
        }
    });
    std::vector<RowSums> sums(static_cast<size_t>(T) * H);
    parallel_for_(Range(0, T * H), [&](const Range& range) {
        std::vector<double> e(static_cast<size_t>(W));
        for (int i = range.start; i < range.end; ++i) {
            const int t = i / H, r = i % H;
            x.row(t, r, e.data(), W);
            const double* m = d.mean.ptr<double>(r);
            double rowSum = 0;
            for (int c = 0; c < W; ++c) {
                e[static_cast<size_t>(c)] -= m[c];
                rowSum += e[static_cast<size_t>(c)];
            }
            RowSums s;
            s.R = rowSum / W;
            s.r2 = s.R * s.R;
            for (int c = 0; c < W; ++c) {
                const double f = e[static_cast<size_t>(c)] - s.R, f2 = f * f;
                s.f2 += f2;
                s.f4 += f2 * f2;
            }
            sums[static_cast<size_t>(i)] = s;
        }
    });
    RowSums total;
    for (const RowSums& s : sums) {
        total.r2 += s.r2;
        total.f2 += s.f2;
        total.f4 += s.f4;
    }
    // Nothing varies: every statistic below would be 0/0 and the fit a NaN far from here.
    if (!(total.f2 > 0) && !(total.r2 > 0))
        CV_Error(
            Error::StsBadArg,
            cv::format("calibrateDarkNoise: the %d frames at gain %g do not vary: every pixel has one value "
                       "in every frame (constant or clipped frames, or copies of one frame); dark frames "
                       "must hold the sensor's read noise",
                       T, gain));
    DarkGainStatistics& st = d.stats;
    st.gain = gain;
    st.frames = T;
    const double dofRows = (T - 1.0) * H, n = static_cast<double>(T) * H * W;
    st.rowMeanVar = total.r2 / dofRows;
    st.pixelVariance = total.f2 / (dofRows * (W - 1));
    st.rowVariance = st.rowMeanVar - st.pixelVariance / W;
    st.rowVarianceSE = std::sqrt(2 / dofRows) * st.rowMeanVar;
    st.excessKurtosis = total.f2 > 0 ? (total.f4 / n) / ((total.f2 / n) * (total.f2 / n)) - 3 : 0;

    // Samples at odd strides through (frame, row, column), so that both sites of a row take part: the
    // residual e with the row's offset still in, or without it.
    auto residualAt = [&](size_t index, bool withRow) {
        const int t = static_cast<int>(index / (static_cast<size_t>(H) * W));
        const int r = static_cast<int>((index / W) % H), c = static_cast<int>(index % W);
        const double e = x.at(t, r, c) - d.mean.ptr<double>(r)[c];
        return withRow ? e : e - sums[static_cast<size_t>(t) * H + r].R;
    };
    const size_t count = static_cast<size_t>(n);
    const size_t swStride = std::max<size_t>(1, count / 5000) | 1;
    std::vector<double> before, after;
    for (size_t i = 0; i < count && before.size() < 5000; i += swStride) {
        before.push_back(residualAt(i, true));
        after.push_back(residualAt(i, false));
    }
    if (before.size() >= 3) {
        st.before = shapiroWilk(before);
        st.after = shapiroWilk(after);
    }
    const size_t ppccStride = std::max<size_t>(1, count / static_cast<size_t>(ppccSamples)) | 1;
    for (size_t i = 0; i < count; i += ppccStride)
        d.ppccSample.push_back(residualAt(i, false));
    return d;
}

// Weighted least squares of y = g^2 u + v over the gains with both parts >= 0 (the bound taken when the
// free fit crosses it).
Vec2d fitRowNoise(const std::vector<GainData>& data, std::vector<std::string>& notes)
{
    double s00 = 0, s01 = 0, s11 = 0, t0 = 0, t1 = 0;
    for (const GainData& d : data) {
        const double w = 1 / std::max(d.stats.rowVarianceSE * d.stats.rowVarianceSE, 1e-300);
        const double g2 = d.stats.gain * d.stats.gain, y = d.stats.rowVariance;
        s00 += w * g2 * g2;
        s01 += w * g2;
        s11 += w;
        t0 += w * g2 * y;
        t1 += w * y;
    }
    const double det = s00 * s11 - s01 * s01;
    Vec2d uv((s11 * t0 - s01 * t1) / det, (s00 * t1 - s01 * t0) / det);
    if (uv[0] < 0) {
        uv = Vec2d(0, std::max(t1 / s11, 0.0));
        notes.push_back("row noise before the gain came out negative and is set to 0 (bound)");
    } else if (uv[1] < 0) {
        uv = Vec2d(std::max(t0 / s00, 0.0), 0);
        notes.push_back("row noise after the gain came out negative and is set to 0 (bound)");
    }
    return uv;
}

// Per pixel, the weighted line g B_d + B_r through the temporal means of the gains.
void fitDarkShading(const std::vector<GainData>& data, Mat& perGain, Mat& offset)
{
    double sw = 0, sg = 0, sgg = 0;
    std::vector<double> w;
    for (const GainData& d : data) {
        // A temporal mean carries (pixel + row variance) / T of noise.
        w.push_back(d.stats.frames /
                    std::max(d.stats.pixelVariance + std::max(d.stats.rowVariance, 0.0), 1e-12));
        sw += w.back();
        sg += w.back() * d.stats.gain;
        sgg += w.back() * d.stats.gain * d.stats.gain;
    }
    const double det = sw * sgg - sg * sg;
    const Size size = data[0].mean.size();
    // New buffers: the base model's maps may be shared with the caller's (Mat copies share data).
    perGain = Mat(size, CV_32FC1);
    offset = Mat(size, CV_32FC1);
    parallel_for_(Range(0, size.height), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r) {
            float* bd = perGain.ptr<float>(r);
            float* br = offset.ptr<float>(r);
            for (int c = 0; c < size.width; ++c) {
                double sm = 0, sgm = 0;
                for (size_t k = 0; k < data.size(); ++k) {
                    const double m = data[k].mean.ptr<double>(r)[c];
                    sm += w[k] * m;
                    sgm += w[k] * data[k].stats.gain * m;
                }
                const double slope = (sw * sgm - sg * sm) / det;
                bd[c] = static_cast<float>(slope);
                br[c] = static_cast<float>((sm - slope * sg) / sw);
            }
        }
    });
}

// The probability-plot correlation of a sorted sample against Tukey-lambda quantiles at Filliben's
// medians, whose logs are precomputed (logM = log m_i, log1mM = log(1 - m_i)).
double ppccAt(const std::vector<double>& sorted, const std::vector<double>& logM,
              const std::vector<double>& log1mM, double lambda)
{
    const size_t n = sorted.size();
    double sq = 0, sqq = 0, sy = 0, syy = 0, syq = 0;
    for (size_t i = 0; i < n; ++i) {
        const double q = lambda == 0
                             ? logM[i] - log1mM[i]
                             : (std::expm1(lambda * logM[i]) - std::expm1(lambda * log1mM[i])) / lambda;
        const double y = sorted[i];
        sq += q;
        sqq += q * q;
        sy += y;
        syy += y * y;
        syq += y * q;
    }
    const double cov = syq - sy * sq / n, vq = sqq - sq * sq / n, vy = syy - sy * sy / n;
    return vq > 0 && vy > 0 ? cov / std::sqrt(vq * vy) : 0;
}

/* The residuals the read noise's shape is judged from, scaled to unit variance and sorted, and what
 * their excess kurtosis is made of: residualKurtosis = kurtosisScale x (the read noise's own) +
 * kurtosisOffset. A residual is (1 - 1/T) of its frame's noise less 1/T of each of the T - 1 others:
 * its excess kurtosis is c(T) = ((1 - 1/T)^4 + (T - 1) / T^4) / (1 - 1/T)^2 of the noise's. Rounding (for
 * 16-bit frames) adds a uniform part, share q = (1/12) / variance, of excess kurtosis -1.2. Gains whose
 * pixel noise is 2 DN or more take part (quantisation flattens the tails below); without any, the
 * highest gain alone. */
struct PooledResiduals
{
    std::vector<double> sorted;
    double kurtosisScale = 0, kurtosisOffset = 0;
};

PooledResiduals poolResiduals(const std::vector<GainData>& data, int type, std::vector<std::string>& notes)
{
    const double minPixelVariance = 4;
    const bool anyAboveQuantisation = std::any_of(data.begin(), data.end(), [&](const GainData& d) {
        return d.stats.pixelVariance >= minPixelVariance;
    });
    PooledResiduals pooled;
    for (size_t k = 0; k < data.size(); ++k) {
        const GainData& d = data[k];
        if (anyAboveQuantisation ? d.stats.pixelVariance < minPixelVariance : k + 1 != data.size())
            continue;
        const double sd = std::sqrt(std::max(d.stats.pixelVariance, 1e-300));
        for (double v : d.ppccSample)
            pooled.sorted.push_back(v / sd);
        const double frames = d.stats.frames, keep = 1 - 1 / frames;
        const double meanRemoval = (std::pow(keep, 4) + (frames - 1) / std::pow(frames, 4)) / (keep * keep);
        const double roundingShare =
            type == CV_16UC1 ? std::min(1.0 / 12 / std::max(d.stats.pixelVariance, 1e-300), 1.0) : 0;
        const double weight = static_cast<double>(d.ppccSample.size());
        pooled.kurtosisScale += weight * meanRemoval * (1 - roundingShare) * (1 - roundingShare);
        pooled.kurtosisOffset += weight * meanRemoval * -1.2 * roundingShare * roundingShare;
    }
    pooled.kurtosisScale /= static_cast<double>(pooled.sorted.size());
    pooled.kurtosisOffset /= static_cast<double>(pooled.sorted.size());
    if (!anyAboveQuantisation)
        notes.push_back("no gain has a pixel noise of 2 DN or more: lambda comes from the highest gain, "
                        "where quantisation may still flatten the tails");
    std::sort(pooled.sorted.begin(), pooled.sorted.end());
    return pooled;
}

/* Filliben's medians of the uniform order statistics of n values, as the logs ppccAt() takes, and the
 * probability-plot correlation of the sorted sample against a normal distribution. */
struct ProbabilityPlot
{
    std::vector<double> logMedian, log1mMedian;
    double ppccGaussian = 0;
};

ProbabilityPlot probabilityPlot(const std::vector<double>& sorted)
{
    const size_t n = sorted.size();
    ProbabilityPlot plot;
    plot.logMedian.resize(n);
    plot.log1mMedian.resize(n);
    double sz = 0, szz = 0, sy = 0, syy = 0, syz = 0;
    const double last = std::pow(0.5, 1.0 / n);
    for (size_t i = 0; i < n; ++i) {
        const double median = i == 0 ? 1 - last : i + 1 == n ? last : (i + 1 - 0.3175) / (n + 0.365);
        plot.logMedian[i] = std::log(median);
        plot.log1mMedian[i] = std::log1p(-median);
        const double z =
            median <= 0.5 ? detail::lowerNormalQuantile(median) : -detail::lowerNormalQuantile(1 - median);
        sz += z;
        szz += z * z;
        sy += sorted[i];
        syy += sorted[i] * sorted[i];
        syz += sorted[i] * z;
    }
    plot.ppccGaussian =
        (syz - sy * sz / n) / std::sqrt(std::max((szz - sz * sz / n) * (syy - sy * sy / n), 1e-300));
    return plot;
}

/* The lambda of the largest probability-plot correlation in [lambdaMin, lambdaMax]: a grid of step 0.01
 * (kept in `grid` as (lambda, r) for the report's plot), then a golden-section search within one step of
 * the grid's best. */
double maximumPpccLambda(const std::vector<double>& sorted, const ProbabilityPlot& plot, double lambdaMin,
                         double lambdaMax, std::vector<Vec2d>& grid)
{
    const auto ppcc = [&](double lambda) { return ppccAt(sorted, plot.logMedian, plot.log1mMedian, lambda); };
    const double gridStep = 0.01;
    double best = lambdaMin, bestR = -2;
    const int steps = static_cast<int>(std::round((lambdaMax - lambdaMin) / gridStep));
    for (int i = 0; i <= steps; ++i) {
        const double lambda = lambdaMin + (lambdaMax - lambdaMin) * i / steps;
        const double r = ppcc(lambda);
        grid.push_back(Vec2d(lambda, r));
        if (r > bestR) {
            bestR = r;
            best = lambda;
        }
    }
    double lo = std::max(lambdaMin, best - gridStep), hi = std::min(lambdaMax, best + gridStep);
    const double goldenRatio = (std::sqrt(5.0) - 1) / 2;
    double left = hi - goldenRatio * (hi - lo), right = lo + goldenRatio * (hi - lo);
    double rLeft = ppcc(left), rRight = ppcc(right);
    // 40 steps shrink the bracket by 0.618^40, 4e-9 of a grid step.
    for (int iteration = 0; iteration < 40; ++iteration) {
        if (rLeft > rRight) {
            hi = right;
            right = left;
            rRight = rLeft;
            left = hi - goldenRatio * (hi - lo);
            rLeft = ppcc(left);
        } else {
            lo = left;
            left = right;
            rLeft = rRight;
            right = lo + goldenRatio * (hi - lo);
            rRight = ppcc(right);
        }
    }
    return 0.5 * (lo + hi);
}

} // namespace

void DarkCalibrationParams::validate() const
{
    if (!(lambdaMin >= detail::kTukeyLambdaMin && lambdaMin < lambdaMax && lambdaMax <= 1))
        CV_Error(Error::StsBadArg, cv::format("DarkCalibrationParams: lambdaMin %g and lambdaMax %g must "
                                              "satisfy %g <= lambdaMin < lambdaMax "
                                              "<= 1",
                                              lambdaMin, lambdaMax, detail::kTukeyLambdaMin));
    if (ppccSamples < 100)
        CV_Error(Error::StsBadArg,
                 cv::format("DarkCalibrationParams.ppccSamples must be >= 100 (got %d)", ppccSamples));
}

void DarkCalibrationReport::write(FileStorage& fs, const String& name) const
{
    fs << name << "{";
    fs << "row_sigma_d2" << model.rowSigmaD2 << "row_sigma_r2" << model.rowSigmaR2;
    fs << "tukey_read" << static_cast<int>(model.tukeyRead) << "tukey_lambda" << model.tukeyLambda;
    fs << "dark_shading" << static_cast<int>(model.hasDarkShading());
    fs << "lambda_of_residuals" << lambdaOfResiduals << "ppcc_best" << ppccBest << "ppcc_gaussian"
       << ppccGaussian;
    fs << "gains"
       << "[";
    for (const DarkGainStatistics& g : gains) {
        fs << "{";
        fs << "gain" << g.gain << "frames" << g.frames << "row_mean_var" << g.rowMeanVar << "row_variance"
           << g.rowVariance << "row_variance_se" << g.rowVarianceSE << "pixel_variance" << g.pixelVariance
           << "excess_kurtosis" << g.excessKurtosis;
        fs << "shapiro_wilk_with_rows"
           << "{"
           << "W" << g.before.W << "p" << g.before.pValue << "n" << g.before.n << "}";
        fs << "shapiro_wilk_without_rows"
           << "{"
           << "W" << g.after.W << "p" << g.after.pValue << "n" << g.after.n << "}";
        fs << "}";
    }
    fs << "]";
    fs << "ppcc"
       << "[";
    for (const Vec2d& p : ppcc)
        fs << "[:" << p[0] << p[1] << "]";
    fs << "]";
    writeStringList(fs, "notes", std::vector<String>(notes.begin(), notes.end()));
    fs << "}";
}

DarkGainStatistics darkBurstStatistics(const std::vector<Mat>& frames, const RawFormat& format, double gain,
                                       OutputArray pixelMean)
{
    format.validate();
    detail::checkFinitePositive(gain, "darkBurstStatistics: gain");
    if (frames.empty())
        CV_Error(Error::StsBadArg, "darkBurstStatistics: no frames");
    const int type = frames[0].type();
    if (type != CV_16UC1 && type != CV_32FC1)
        CV_Error(Error::StsBadArg,
                 cv::format("darkBurstStatistics: frames must be CV_16UC1 or CV_32FC1 (got %s)",
                            typeToString(type).c_str()));
    GainData d =
        analyseGain(frames, gain, format, DarkCalibrationParams().ppccSamples, frames[0].size(), type);
    if (pixelMean.needed())
        pixelMean.assign(d.mean);
    return d.stats;
}

DarkCalibrationReport calibrateDarkNoise(const std::vector<std::vector<Mat>>& bursts,
                                         const std::vector<double>& gains, const RawFormat& format,
                                         const NoiseModel& base, const DarkCalibrationParams& params)
{
    params.validate();
    format.validate();
    base.validate();
    if (bursts.empty())
        CV_Error(Error::StsBadArg, "calibrateDarkNoise: no bursts");
    if (bursts.size() != gains.size())
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateDarkNoise: %zu bursts but %zu gains", bursts.size(), gains.size()));
    for (double g : gains)
        detail::checkFinitePositive(g, "calibrateDarkNoise: gain");
    if (bursts[0].empty())
        CV_Error(Error::StsBadArg, "calibrateDarkNoise: the first burst has no frames");
    const Size size = bursts[0][0].size();
    const int type = bursts[0][0].type();
    if (type != CV_16UC1 && type != CV_32FC1)
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateDarkNoise: frames must be CV_16UC1 or CV_32FC1 (got %s)",
                            typeToString(type).c_str()));
    if (size.width < 2 || size.height < 2 || size.width % 2 || size.height % 2)
        CV_Error(Error::StsBadArg,
                 cv::format("calibrateDarkNoise: frames must have even sides >= 2 (got %dx%d)", size.width,
                            size.height));
    // Before any burst is read: the check needs only the gains.
    if ((params.rowNoise || params.darkShading) && distinctGains(gains) < 2)
        CV_Error(Error::StsBadArg,
                 "calibrateDarkNoise: row noise and dark shading are split by how they change "
                 "with the gain: give bursts at 2 or more distinct gains (or turn both off)");
    std::vector<size_t> order(gains.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return gains[a] < gains[b]; });
    std::vector<GainData> data;
    for (size_t k : order)
        data.push_back(analyseGain(bursts[k], gains[k], format, params.ppccSamples, size, type));

    DarkCalibrationReport report;
    report.model = base;
    for (const GainData& d : data) {
        report.gains.push_back(d.stats);
        if (d.stats.frames < 16)
            report.notes.push_back(
                cv::format("the burst at gain %g has %d frames: with fewer than 16 the fixed pattern "
                           "and lambda are noticeably less accurate (docs/calibrate_your_camera.md)",
                           d.stats.gain, d.stats.frames));
    }
    if (params.rowNoise) {
        const Vec2d uv = fitRowNoise(data, report.notes);
        report.model.rowSigmaD2 = uv[0];
        report.model.rowSigmaR2 = uv[1];
        // A pixel's temporal variance holds its row's offset too, so the base model's read terms (from
        // calibrateNoiseModel()) include the rows: they move out of them, or the augmentation would add
        // them twice.
        report.model.sigmaD2 = std::max(base.sigmaD2 - uv[0], 0.0);
        report.model.sigmaR2 = std::max(base.sigmaR2 - uv[1], 0.0);
        if (base.sigmaD2 < uv[0] || base.sigmaR2 < uv[1])
            report.notes.push_back(
                cv::format("the base model's read noise (%g, %g) is below the row noise (%g, %g): "
                           "its read terms are set to what is left, at least 0; was it "
                           "calibrated from the same camera?",
                           base.sigmaD2, base.sigmaR2, uv[0], uv[1]));
    }
    if (params.darkShading)
        fitDarkShading(data, report.model.darkShadingPerGain, report.model.darkShadingOffset);
    if (params.tukeyShape) {
        const PooledResiduals pooled = poolResiduals(data, type, report.notes);
        const ProbabilityPlot plot = probabilityPlot(pooled.sorted);
        report.ppccGaussian = plot.ppccGaussian;
        const double shown =
            maximumPpccLambda(pooled.sorted, plot, params.lambdaMin, params.lambdaMax, report.ppcc);
        report.ppccBest = ppccAt(pooled.sorted, plot.logMedian, plot.log1mMedian, shown);
        report.lambdaOfResiduals = shown;
        // The shape the residuals show, carried back to the read noise's own through its kurtosis.
        const double lambda =
            std::min(std::max(detail::tukeyLambdaOfExcessKurtosis(
                                  (detail::tukeyLambdaExcessKurtosis(shown) - pooled.kurtosisOffset) /
                                  pooled.kurtosisScale),
                              params.lambdaMin),
                     params.lambdaMax);
        report.model.tukeyRead = true;
        report.model.tukeyLambda = lambda;
        if (lambda <= params.lambdaMin + 0.005 || lambda >= params.lambdaMax - 0.005)
            report.notes.push_back(cv::format("lambda %.3f is at the edge of the search range [%g, %g]",
                                              lambda, params.lambdaMin, params.lambdaMax));
    }
    report.model.validate();
    return report;
}

namespace {

//! A light sample's mean without its pixel's dark shading (the maps' mean where it numbers no pixel of them).
void removeDarkShading(NoiseSample& sample, Size frame, const Mat& bd, const Mat& br, double meanPerGain,
                       double meanOffset)
{
    if (frame == bd.size() && sample.pixel >= 0 && sample.pixel < static_cast<int64>(bd.total())) {
        const int r = static_cast<int>(sample.pixel / bd.cols), c = static_cast<int>(sample.pixel % bd.cols);
        sample.mean -= sample.gain * bd.at<float>(r, c) + br.at<float>(r, c);
    } else {
        sample.mean -= sample.gain * meanPerGain + meanOffset;
    }
}

} // namespace

DarkFrameCalibration calibrateWithDarkFrames(const std::vector<NoiseSample>& lightSamples,
                                             const std::vector<NoiseSample>& darkSamples,
                                             const std::vector<std::vector<Mat>>& darkBursts,
                                             const std::vector<double>& darkGains,
                                             const RawFormat& frameFormat, const CalibrationParams& params,
                                             const DarkCalibrationParams& darkParams,
                                             const std::vector<Size>& lightFrames)
{
    if (!lightFrames.empty() && lightFrames.size() != lightSamples.size())
        CV_Error(Error::StsBadArg,
                 format("calibrateWithDarkFrames: lightFrames has %d sizes for %d light "
                        "samples (give one per sample, or none)",
                        static_cast<int>(lightFrames.size()), static_cast<int>(lightSamples.size())));
    if (darkBursts.empty())
        CV_Error(Error::StsBadArg, "calibrateWithDarkFrames: no dark bursts");
    DarkFrameCalibration out;
    std::vector<NoiseSample> samples = lightSamples;
    samples.insert(samples.end(), darkSamples.begin(), darkSamples.end());
    const CalibrationReport base = calibrateNoiseModel(samples, params);
    DarkCalibrationParams dp = darkParams;
    if (distinctGains(darkGains) < 2 && (dp.rowNoise || dp.darkShading)) {
        dp.rowNoise = dp.darkShading = false;
        out.notes.push_back(
            "dark bursts at one gain only: row noise and dark shading change with the gain and "
            "need dark bursts at 2 or more gains; only the read noise's shape is calibrated");
    }
    out.dark = calibrateDarkNoise(darkBursts, darkGains, frameFormat, base.model, dp);
    out.report = base;
    const bool shading = out.dark.model.hasDarkShading();
    const bool tails = out.dark.model.tukeyRead && std::isnan(params.readExcessKurtosis);
    if (shading || tails) {
        if (shading) {
            const Mat &bd = out.dark.model.darkShadingPerGain, &br = out.dark.model.darkShadingOffset;
            const double meanPerGain = mean(bd)[0], meanOffset = mean(br)[0];
            for (size_t i = 0; i < lightSamples.size(); ++i)
                removeDarkShading(samples[i], lightFrames.empty() ? bd.size() : lightFrames[i], bd, br,
                                  meanPerGain, meanOffset);
            out.notes.push_back("the light samples' means were corrected by their pixels' dark shading");
        }
        CalibrationParams refit = params;
        if (tails) {
            refit.readExcessKurtosis = out.dark.model.readExcessKurtosis();
            out.notes.push_back(
                format("the fit takes the read noise's excess kurtosis %.3g from the dark frames "
                       "(Tukey lambda %.3f)",
                       refit.readExcessKurtosis, out.dark.model.tukeyLambda));
        }
        out.report = calibrateNoiseModel(samples, refit);
        out.report.model.baseIso = base.model.baseIso;
        out.notes.push_back("the model was fitted again");
    }
    // The components with the (refitted) light model; the rows move out of its read terms, as
    // calibrateDarkNoise() does (a pixel's temporal variance holds its row's offset).
    NoiseModel withComponents = out.dark.model;
    const NoiseModel& light = out.report.model;
    withComponents.alpha = light.alpha;
    withComponents.baseIso = light.baseIso;
    withComponents.failedCalibration = light.failedCalibration;
    withComponents.sigmaD2 = std::max(light.sigmaD2 - withComponents.rowSigmaD2, 0.0);
    withComponents.sigmaR2 = std::max(light.sigmaR2 - withComponents.rowSigmaR2, 0.0);
    if (withComponents.hasRowNoise())
        out.notes.push_back(
            format("sigma_d^2 and sigma_r^2 are the pixel's own read noise: the calibrated %.4g and "
                   "%.4g less the row noise %.4g and %.4g",
                   light.sigmaD2, light.sigmaR2, withComponents.rowSigmaD2, withComponents.rowSigmaR2));
    out.dark.model = withComponents;
    out.report.model = withComponents;
    out.samples = std::move(samples);
    return out;
}

} // namespace rawgment
} // namespace cv
