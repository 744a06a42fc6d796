// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "tradeoff_measures.hpp"
#include "tradeoff_study.hpp"

#include "flow_common.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/cpu.hpp>
#include <opencv2/rawgment/normality.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <functional>
#include <limits>
#include <map>
#include <sstream>

namespace rawgment_apps {

using namespace cv;
using namespace cv::rawgment;

namespace {

using namespace tradeoff_study;

//! A scene of bars and a ramp: edges for the blur, every level from near black to bright.
Mat timingScene(Size size)
{
    Mat scene(size, CV_32FC1);
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c)
            scene.at<float>(r, c) =
                static_cast<float>(((c / 64) % 2 ? 1500.0 : 60.0) * (0.2 + 0.8 * r / size.height));
    return scene;
}

//! Histogram of the integer DN above black of a CV_16UC1 frame in [lo, hi], as probabilities
//! (half a count in every bin, so that an empty bin of a model is not an infinite divergence).
std::vector<double> valueDistribution(const Mat& raw, int black, int lo, int hi)
{
    std::vector<double> p(static_cast<size_t>(hi - lo + 1), 0.5);
    double total = 0.5 * static_cast<double>(p.size());
    for (int r = 0; r < raw.rows; ++r)
        for (const ushort* v = raw.ptr<ushort>(r); v != raw.ptr<ushort>(r) + raw.cols; ++v) {
            const int k = static_cast<int>(*v) - black;
            if (k >= lo && k <= hi) {
                p[static_cast<size_t>(k - lo)] += 1;
                total += 1;
            }
        }
    for (double& x : p)
        x /= total;
    return p;
}

double kullbackLeibler(const std::vector<double>& truth, const std::vector<double>& model)
{
    double kl = 0;
    for (size_t i = 0; i < truth.size(); ++i)
        kl += truth[i] * std::log(truth[i] / model[i]);
    return kl;
}

double spatialVariance(const Mat& raw, const RawFormat& fmt)
{
    Mat x;
    subtractBlackLevel(raw, fmt, x);
    Scalar m, s;
    meanStdDev(x, m, s);
    return s[0] * s[0];
}

// Shot-noise sampling and prior-mean estimate: colour jitter's accuracy at very low light and at black.
void measureColorJitterKnobs(const TradeoffSettings& set, const Mat& timingRaw, const RawFormat& timingFmt,
                             const NoiseModel& timingModel, std::vector<TradeoffRow>& rows)
{
    // Two electrons per pixel on a sensor with 4 DN per electron and 0.5 DN of read noise: the value
    // distribution of a true capture is a lattice; KL(true || augmented) measures how well a sampling
    // reproduces it.
    SensorParams lattice;
    lattice.noise = NoiseModel(1.0, 0.01, 0.05);
    const Size flat(512, 512);
    const SensorSimulator latticeSensor(lattice, flat);
    const RawFormat latticeFmt = latticeSensor.rawFormat(4);
    Mat bright, truth;
    latticeSensor.capture(Mat(flat, CV_32FC1, Scalar(200)), 4, 1.0, studySeed(set, DRAW_LATTICE_BRIGHT), 0,
                          bright);
    latticeSensor.capture(Mat(flat, CV_32FC1, Scalar(200)), 4, 0.01, studySeed(set, DRAW_LATTICE_TRUTH), 0,
                          truth);
    const int black = static_cast<int>(latticeFmt.blackLevel[0]);
    const std::vector<double> truthDistribution = valueDistribution(truth, black, -24, 64);

    // A black frame at 18 dB darkened to x0.5: the truth has no shot noise, only read noise.
    const SensorSimulator dark(SensorParams(), flat);
    const RawFormat darkFmt = dark.rawFormat(8);
    Mat darkRaw, darkTruth;
    dark.capture(Mat::zeros(flat, CV_32FC1), 8, 1.0, studySeed(set, DRAW_BLACK_FRAME), 0, darkRaw);
    dark.capture(Mat::zeros(flat, CV_32FC1), 8, 0.5, studySeed(set, DRAW_BLACK_TRUTH), 0, darkTruth);
    const double darkTruthVar = spatialVariance(darkTruth, darkFmt);

    // The time per MP on the active path; every path's in `byPath`.
    const auto time = [&](const NoiseOptions& noise, std::vector<double>& byPath) {
        Mat out;
        RawFormat f;
        double active = 0;
        byPath = perMegapixel(fastestMsOnEveryPath(
                                  set.repeats,
                                  [&] {
                                      colorJitter(timingRaw, timingFmt, timingModel,
                                                  ColorJitter::exposureChange(0.1, 1.0), noise,
                                                  studySeed(set, DRAW_TIMED_STEP), out, f);
                                  },
                                  active),
                              timingRaw.size());
        return active / megapixels(timingRaw.size());
    };
    for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON}) {
        NoiseOptions noise;
        noise.shotSampling = sampling;
        Mat out;
        RawFormat f;
        colorJitter(bright, latticeFmt, latticeSensor.effectiveModel(),
                    ColorJitter::exposureChange(0.01, 1.0), noise, studySeed(set, DRAW_LATTICE_JITTER), out,
                    f);
        const bool poisson = sampling == ShotNoiseSampling::POISSON;
        std::vector<double> byPath;
        const double msPerMp = time(noise, byPath);
        rows.push_back(
            {"Shot-noise sampling (colour jitter)", poisson ? "POISSON" : "GAUSSIAN (paper)",
             "KL(true || augmented) of the values at 2 e-",
             kullbackLeibler(truthDistribution, valueDistribution(out, black, -24, 64)), msPerMp,
             poisson
                 ? "the electron lattice of a real dark capture; an exact count per pixel, in vector lanes"
                 : "right variance, wrong shape below ~10 e-",
             byPath});
    }
    for (PriorMeanEstimate prior : {PriorMeanEstimate::PIXEL_VALUE, PriorMeanEstimate::LOCAL_MEAN}) {
        NoiseOptions noise;
        noise.priorMean = prior;
        Mat out;
        RawFormat f;
        colorJitter(darkRaw, darkFmt, dark.effectiveModel(), ColorJitter::exposureChange(0.5, 1.0), noise,
                    studySeed(set, DRAW_BLACK_JITTER), out, f);
        const bool local = prior == PriorMeanEstimate::LOCAL_MEAN;
        std::vector<double> byPath;
        const double msPerMp = time(noise, byPath);
        rows.push_back({"Prior mean mu_x (colour jitter)", local ? "LOCAL_MEAN" : "PIXEL_VALUE (paper)",
                        "|variance / true variance - 1| at black, x0.5",
                        std::abs(spatialVariance(out, darkFmt) / darkTruthVar - 1), msPerMp,
                        local ? "a third of the clip bias at black; smooths across edges"
                              : "max(x, 0) of a noisy pixel adds shot noise at black",
                        byPath});
    }
}

// Motion blur: the exact Eq. 15 sum against the one from the blurred mean, on bars blurred by a motion
// (nearly equal taps) and by a peaked kernel (very unequal taps), against the variance of a true
// capture blurred before the noise (the simulator's model at the blurred photon mean).
void measureBlurKnob(const TradeoffSettings& set, const Mat& timingRaw, const RawFormat& timingFmt,
                     const NoiseModel& timingModel, std::vector<TradeoffRow>& rows)
{
    const Size size(256, 128);
    const SensorSimulator sensor(SensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const double gain = 2;
    const RawFormat fmt = sensor.rawFormat(gain);
    Mat scene(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c)
        scene.col(c).setTo((c / 16) % 2 ? 1500.0 : 40.0); // 3000 DN at gain 2: below white
    const int frames = 48;
    std::vector<Mat> burst(static_cast<size_t>(frames));
    for (int t = 0; t < frames; ++t) {
        sensor.capture(scene, gain, 1.0, studySeed(set, DRAW_BLUR_BURST), t, burst[static_cast<size_t>(t)]);
        burst[static_cast<size_t>(t)].convertTo(burst[static_cast<size_t>(t)], CV_32F);
    }
    const Mat peaked = (Mat_<float>(1, 5) << 1, 4, 6, 4, 1) / 16.0f;
    const std::pair<std::string, Mat> kernels[2] = {{"motion 13 px at 30 deg", linearMotionKernel(13, 30)},
                                                    {"peaked 1x5 (1 4 6 4 1)", peaked}};
    for (const auto& named : kernels) {
        // The truth: the photon image blurred on each CFA plane, then the simulator's noise model.
        Mat truthMean;
        {
            Mat x = scene * gain;
            std::vector<Mat> planes;
            splitCfaPlanes(x, planes);
            for (Mat& p : planes)
                filter2D(p, p, -1, named.second / sum(named.second)[0], Point(-1, -1), 0, BORDER_REPLICATE);
            mergeCfaPlanes(planes, truthMean);
        }
        for (BlurNoiseSum method : {BlurNoiseSum::EXACT, BlurNoiseSum::FROM_BLURRED_MEAN}) {
            NoiseOptions noise;
            noise.blurNoiseSum = method;
            Mat sum1(size, CV_64FC1, Scalar(0)), sum2 = sum1.clone();
            for (int t = 0; t < frames; ++t) {
                Mat out, x;
                motionBlur(burst[static_cast<size_t>(t)], fmt, model, named.second, noise,
                           studySeed(set, DRAW_BLUR_STEP, static_cast<uint64>(t)), out);
                subtractBlackLevel(out, fmt, x);
                x.convertTo(x, CV_64F);
                sum1 += x;
                sum2 += x.mul(x);
            }
            const Mat var = (sum2 - sum1.mul(sum1) / frames) / (frames - 1);
            // Per column, the average over rows of measured / true variance; the error is the RMS of its
            // deviation from 1 over the columns (sampling floor: sqrt(2 / 47) / sqrt(128) = 1.8%).
            double squares = 0;
            for (int c = 0; c < size.width; ++c) {
                double ratio = 0;
                for (int r = 0; r < size.height; ++r)
                    ratio += var.at<double>(r, c) / model.variance(truthMean.at<float>(r, c), gain);
                ratio /= size.height;
                squares += (ratio - 1) * (ratio - 1);
            }
            Mat out;
            double ms = 0;
            const std::vector<double> byPath =
                perMegapixel(fastestMsOnEveryPath(
                                 set.repeats,
                                 [&] {
                                     motionBlur(timingRaw, timingFmt, timingModel, linearMotionKernel(13, 30),
                                                noise, studySeed(set, DRAW_TIMED_STEP), out);
                                 },
                                 ms),
                             timingRaw.size());
            const bool exact = method == BlurNoiseSum::EXACT;
            rows.push_back({"Motion-blur noise sum",
                            std::string(exact ? "EXACT (Eq. 15)" : "FROM_BLURRED_MEAN") + ", " + named.first,
                            "RMS over columns of variance / true variance - 1 (floor 1.8%)",
                            std::sqrt(squares / size.width), ms / megapixels(timingRaw.size()),
                            exact
                                ? "exact at every edge"
                                : "exact when the taps are equal (a motion); off at edges of a peaked kernel",
                            byPath});
        }
    }
}

// Burst statistics: float64 against float32 state.
void measureStatisticsPrecision(const TradeoffSettings& set, const Mat& timingRaw, const RawFormat& timingFmt,
                                std::vector<TradeoffRow>& rows)
{
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(100);
    fmt.whiteLevel = 65535;
    const int frames = 100;
    std::vector<Mat> burst(static_cast<size_t>(frames));
    RNG rng(studySeed(set, DRAW_STATE_BURST));
    for (Mat& f : burst) {
        f.create(64, 64, CV_32FC1);
        rng.fill(f, RNG::NORMAL, 60000, 1);
    }
    for (int depth : {CV_64F, CV_32F}) {
        BurstStatistics stats(fmt, 8, depth);
        for (const Mat& f : burst)
            stats.add(f);
        Mat var;
        stats.variance(var);
        double worst = 0;
        for (int r = 0; r < 64; ++r)
            for (int c = 0; c < 64; ++c) {
                long double m = 0, v = 0;
                for (const Mat& f : burst)
                    m += f.at<float>(r, c);
                m /= frames;
                for (const Mat& f : burst)
                    v += (f.at<float>(r, c) - m) * (f.at<float>(r, c) - m);
                v /= frames - 1;
                worst = std::max(worst, std::abs(var.at<double>(r, c) / static_cast<double>(v) - 1));
            }
        const int timedFrames = 24;
        double ms = 0;
        std::vector<double> byPath = fastestMsOnEveryPath(
            set.repeats,
            [&] {
                BurstStatistics timed(timingFmt, 8, depth);
                for (int t = 0; t < timedFrames; ++t)
                    timed.add(timingRaw);
                Mat v;
                timed.variance(v);
            },
            ms);
        for (double& m : byPath)
            m /= timedFrames * megapixels(timingRaw.size());
        const bool wide = depth == CV_64F;
        rows.push_back({"Arithmetic (burst statistics state)", wide ? "float64 (default)" : "float32",
                        "max |variance / long-double reference - 1|, mean 60000, variance 1", worst,
                        ms / (timedFrames * megapixels(timingRaw.size())),
                        wide ? "exact to float64 rounding"
                             : "half the state memory; the measure's error at an extreme mean",
                        byPath});
    }
}

// Calibration: burst length, patch size and RANSAC iterations on the paper's protocol.

void measureShapiroWilk(const TradeoffSettings& set, std::vector<TradeoffRow>& rows)
{
    const int n = 64, series = set.shapiroSeries;
    Mat data(n, series, CV_32FC1);
    RNG(studySeed(set, DRAW_SHAPIRO_DATA)).fill(data, RNG::NORMAL, 0, 1);
    std::vector<ShapiroWilkResult> batch;
    const double batchMs = fastestMs(set.repeats, [&] { shapiroWilkBatch(data, batch); });
    std::vector<ShapiroWilkResult> single(static_cast<size_t>(series));
    const Mat byRow = data.t();
    const double singleMs = fastestMs(set.repeats, [&] {
        for (int i = 0; i < series; ++i)
            single[static_cast<size_t>(i)] = shapiroWilk(byRow.row(i));
    });
    double worst = 0;
    for (int i = 0; i < series; ++i)
        worst = std::max(
            worst, std::abs(batch[static_cast<size_t>(i)].pValue - single[static_cast<size_t>(i)].pValue));
    const double mValues = static_cast<double>(n) * series / 1e6;
    rows.push_back({"Shapiro-Wilk",
                    "batched",
                    "max |p batched - p single|",
                    worst,
                    batchMs / mValues,
                    "coefficients once, series in parallel",
                    {}});
    rows.push_back({"Shapiro-Wilk",
                    "one call per series",
                    "max |p batched - p single|",
                    worst,
                    singleMs / mValues,
                    "the same numbers, slower",
                    {}});
}

// The dark-frame measures of a burst (darkBurstStatistics(), the library's) with its fixed pattern.
struct DarkBurstStats
{
    Mat pixelMean;
    DarkGainStatistics stats;
};

DarkBurstStats darkBurstStats(const std::vector<Mat>& burst, const RawFormat& format)
{
    DarkBurstStats d;
    d.stats = darkBurstStatistics(burst, format, format.gain, d.pixelMean);
    return d;
}

/* The dark-frame components (NoiseModel): for each, the accuracy of a very dark augmentation (a bright
 * burst darkened x1/200 at x8 gain, 5 electrons per pixel, against a burst simulated at that target by
 * a sensor that has every component) when the model lacks it and when it has it, and the time of a
 * colour jitter on the timing frame without and with it. */
void measureDarkComponents(const TradeoffSettings& set, const Mat& timingRaw, const RawFormat& timingFmt,
                           const NoiseModel& timingModel, std::vector<TradeoffRow>& rows)
{
    const Size size(256, 256);
    const int T = 8;
    SensorParams params;
    params.quantize = false;
    params.noise.rowSigmaD2 = 0.3;
    params.noise.rowSigmaR2 = 0.5;
    params.noise.tukeyRead = true;
    params.noise.tukeyLambda = -0.1;
    addDarkShadingPattern(size, 4, set.seed, params.noise);
    const SensorSimulator sensor(params, size);
    const NoiseModel full = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(1);
    const Mat scene(size, CV_32FC1, Scalar(400));
    std::vector<Mat> bright, target;
    sensor.captureBurst(scene, 1, 1, T, studySeed(set, DRAW_DARK_INPUT), bright);
    sensor.captureBurst(scene, 8, 1.0 / 200, T, studySeed(set, DRAW_DARK_TARGET), target);
    const DarkBurstStats truth = darkBurstStats(target, fmt);
    NoiseOptions options;
    options.shotSampling = ShotNoiseSampling::POISSON; // the capture's shot noise is a count
    const auto augmented = [&](const NoiseModel& m) {
        std::vector<Mat> out(T);
        RawFormat f;
        for (int t = 0; t < T; ++t)
            colorJitter(bright[t], fmt, m, ColorJitter::exposureChange(1.0 / 200, 8), options,
                        studySeed(set, DRAW_DARK_STEP, uint64(t)), out[t], f);
        return darkBurstStats(out, fmt);
    };
    // The time model: the timing frame's, with the component; the dark shading a map of its size.
    NoiseModel timingShading = timingModel;
    addDarkShadingPattern(timingRaw.size(), 4, set.seed, timingShading);
    enum Component
    {
        ROWS,
        SHADING,
        TAILS
    };
    for (Component c : {ROWS, SHADING, TAILS}) {
        for (bool present : {false, true}) {
            NoiseModel m = full, timed = c == SHADING ? timingShading : timingModel;
            if (!present) {
                if (c == ROWS)
                    m.rowSigmaD2 = m.rowSigmaR2 = 0;
                if (c == SHADING)
                    m.darkShadingPerGain = m.darkShadingOffset = Mat();
                if (c == TAILS)
                    m.tukeyRead = false;
                timed = timingModel;
            } else {
                if (c == ROWS) {
                    timed.rowSigmaD2 = full.rowSigmaD2;
                    timed.rowSigmaR2 = full.rowSigmaR2;
                }
                if (c == TAILS) {
                    timed.tukeyRead = true;
                    timed.tukeyLambda = full.tukeyLambda;
                }
            }
            const DarkBurstStats a = augmented(m);
            double error = 0;
            if (c == ROWS)
                error = std::abs(a.stats.rowMeanVar / truth.stats.rowMeanVar - 1);
            if (c == SHADING) {
                // RMS difference of the fixed patterns (the scene's level taken out), in DN: with equal
                // patterns, what remains is the noise of the two 8-frame means (about 5-6 DN here).
                Mat d = a.pixelMean - truth.pixelMean;
                d -= cv::mean(d)[0];
                error = std::sqrt(d.dot(d) / static_cast<double>(d.total()));
            }
            if (c == TAILS)
                error = std::abs(a.stats.excessKurtosis - truth.stats.excessKurtosis);
            double active = 0;
            Mat out;
            RawFormat f;
            const std::vector<double> byPath = perMegapixel(
                fastestMsOnEveryPath(
                    set.repeats,
                    [&] {
                        colorJitter(timingRaw, timingFmt, timed, ColorJitter::exposureChange(0.1, 4),
                                    NoiseAlignment::ACCOUNT_PRIOR, studySeed(set, DRAW_TIMED_STEP), out, f);
                    },
                    active),
                timingRaw.size());
            const char* knob = c == ROWS      ? "Row noise (dark-frame component)"
                               : c == SHADING ? "Dark shading (dark-frame component)"
                                              : "Read-noise tails (dark-frame component)";
            const char* measure = c == ROWS ? "|row-mean variance / capture's - 1| at 5 e-, x8 gain"
                                  : c == SHADING
                                      ? "RMS fixed-pattern difference (DN) of 8-frame means at 5 e-, x8 gain"
                                      : "|excess kurtosis - capture's| at 5 e-, x8 gain";
            const char* meaning =
                c == ROWS ? (present ? "banding of a dark high-gain capture"
                                     : "no banding: the rows of the capture are missing")
                : c == SHADING
                    ? (present ? "the target gain's dark offset pattern; costs a map read per pixel"
                               : "the input's pattern, scaled down by the darkening")
                    : (present ? "heavy-tailed added read noise; Tukey-lambda draws in vector lanes"
                               : "Gaussian added read noise: too few outliers in the dark");
            rows.push_back({knob, present ? "in the model" : "absent from the model", measure, error,
                            active / megapixels(timingRaw.size()), meaning, byPath});
        }
    }
}

//! A pipe inside a table cell would end the cell.

} // namespace

void measureTradeoffs(const TradeoffSettings& set, ProgressBar& progress, std::vector<TradeoffRow>& rows,
                      std::vector<PrecisionRow>& precision)
{
    const SensorSimulator timingSensor(SensorParams(), set.timingSize);
    const RawFormat timingFmt = timingSensor.rawFormat(2);
    Mat timingRaw;
    timingSensor.capture(timingScene(set.timingSize), 2, 1.0, studySeed(set, DRAW_TIMING_FRAME), 0,
                         timingRaw);
    const NoiseModel timingModel = timingSensor.effectiveModel();
    progress.advance();
    measureColorJitterKnobs(set, timingRaw, timingFmt, timingModel, rows);
    progress.advance();
    measureBlurKnob(set, timingRaw, timingFmt, timingModel, rows);
    progress.advance();
    measureStatisticsPrecision(set, timingRaw, timingFmt, rows);
    progress.advance();
    measureCalibrationKnobs(set, rows, precision, progress);
    measureShapiroWilk(set, rows);
    progress.advance();
    measureDarkComponents(set, timingRaw, timingFmt, timingModel, rows);
    progress.advance();
    tradeoff_study::measureDarkBankFrames(set, rows);
    progress.advance();
}

} // namespace rawgment_apps
