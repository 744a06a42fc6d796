// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "tradeoff_measures.hpp"

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

// What each seed of the study drives: deriveSeed(seed, SEED_STUDY, draw << 32 | sub-index).
enum StudyDraw : uint64
{
    DRAW_TIMING_FRAME,
    DRAW_TIMED_STEP,
    DRAW_LATTICE_BRIGHT,
    DRAW_LATTICE_TRUTH,
    DRAW_LATTICE_JITTER,
    DRAW_BLACK_FRAME,
    DRAW_BLACK_TRUTH,
    DRAW_BLACK_JITTER,
    DRAW_BLUR_BURST,
    DRAW_BLUR_STEP,
    DRAW_STATE_BURST,
    DRAW_SHAPIRO_DATA,
    DRAW_CAMPAIGN_BURST,
    DRAW_DARK_INPUT,
    DRAW_DARK_TARGET,
    DRAW_DARK_STEP
};

uint64 studySeed(const TradeoffSettings& set, StudyDraw draw, uint64 sub = 0)
{
    return deriveSeed(set.seed, SEED_STUDY, (static_cast<uint64>(draw) << 32) | sub);
}

//! Fastest wall time of `repeats` runs of `work`, in milliseconds.
double fastestMs(int repeats, const std::function<void()>& work)
{
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i < repeats; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        work();
        best = std::min(
            best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    return best;
}

/** fastestMs() on every CPU path this machine has, in the order of availableCpuPaths(), and in `active`
 * the time on the path that was active, which is restored. */
std::vector<double> fastestMsOnEveryPath(int repeats, const std::function<void()>& work, double& active)
{
    const CpuPath before = activeCpuPath();
    std::vector<double> ms;
    for (CpuPath path : availableCpuPaths()) {
        setCpuPath(path);
        ms.push_back(fastestMs(repeats, work));
        if (path == before)
            active = ms.back();
    }
    setCpuPath(before);
    return ms;
}

std::vector<double> perMegapixel(std::vector<double> ms, Size s)
{
    for (double& m : ms)
        m /= s.area() / 1e6;
    return ms;
}

double megapixels(Size s)
{
    return s.area() / 1e6;
}

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
                        wide ? "exact to float64 rounding" : "half the state memory; ~1e-4 at extreme means",
                        byPath});
    }
}

// Calibration: burst length, patch size and RANSAC iterations on the paper's protocol.

//! One setting of a calibration knob: the frames, square side and RANSAC iterations it uses.
struct CalibrationKnobSetting
{
    std::string knob, name;
    int frames, side, ransac;
};

std::vector<CalibrationKnobSetting> calibrationKnobSettings(const TradeoffSettings& set)
{
    const int maxFrames = set.burstLengths.back();
    std::vector<CalibrationKnobSetting> settings;
    for (int f : set.burstLengths)
        settings.push_back({"Calibration burst length", std::to_string(f) + " frames", f, 24, 500});
    for (int side : {8, 16})
        settings.push_back({"Calibration patch size", std::to_string(side) + "x" + std::to_string(side),
                            maxFrames, side, 500});
    settings.push_back({"Calibration patch size", "24x24 (paper)", maxFrames, 24, 500});
    for (int it : {20, 100, 2000})
        settings.push_back({"Calibration RANSAC iterations", std::to_string(it), maxFrames, 24, it});
    return settings;
}

//! A set-up whose stated errors are compared with the errors made over the campaigns.
struct PrecisionSetup
{
    std::string name;
    int frames, side;
    bool twoGains, dark;
};

/** Every burst length and side as the knobs have them, then two gains and dark frames at the longest
 * bursts and 24x24 squares (the reference, whose errors the formula scales). */
std::vector<PrecisionSetup> precisionSetups(const TradeoffSettings& set)
{
    const int maxFrames = set.burstLengths.back();
    std::vector<PrecisionSetup> setups;
    for (int f : set.burstLengths)
        setups.push_back({std::to_string(f) + " frames, 24x24, 3 gains", f, 24, false, false});
    for (int side : {8, 16})
        setups.push_back({std::to_string(maxFrames) + " frames, " + std::to_string(side) + "x" +
                              std::to_string(side) + ", 3 gains",
                          maxFrames, side, false, false});
    setups.push_back(
        {std::to_string(maxFrames) + " frames, 24x24, 2 gains (6 and 24 dB)", maxFrames, 24, true, false});
    setups.push_back(
        {std::to_string(maxFrames) + " frames, 24x24, 3 gains + dark frames", maxFrames, 24, false, true});
    return setups;
}

//! The simulated chart and sensor of the calibration campaigns.
struct CalibrationBench
{
    ColorCheckerOptions chart;
    ColorCheckerScene scene;
    SensorSimulator sensor;
    NoiseModel truth;

    CalibrationBench(const ColorCheckerOptions& chartOptions, const SensorParams& params)
        : chart(chartOptions), scene(makeColorCheckerScene(chartOptions)),
          sensor(params, scene.meanAtUnitGain.size()), truth(sensor.effectiveModel())
    {
    }

    /** The exposure of a burst at light `level`: a perfect white reflector at that fraction of the DN
     * range above black (4095 - 256 = 3839 DN), level x range / (gain x the chart's illumination). */
    double exposureFor(double level, double gain) const
    {
        const RawFormat unitFormat = sensor.rawFormat(1);
        return level * (unitFormat.whiteLevel - unitFormat.blackLevel[0]) / (gain * chart.illumination);
    }
};

//! One campaign's samples after each burst length, for every square side.
struct CampaignSamples
{
    std::map<std::pair<int, int>, std::vector<NoiseSample>> light; //!< (frames, side)
    std::map<int, std::vector<NoiseSample>> dark;                  //!< (frames), 24x24
    std::map<std::pair<int, int>, double> samplingMs;              //!< (frames, side)
};

/** Simulates one campaign (3 gains x (2 light levels + 1 dark)) and samples each burst's statistics after
 * every burst length of the study; `statsMs` gains the time of every BurstStatistics::add. */
CampaignSamples sampleCampaign(const TradeoffSettings& set, const CalibrationBench& bench, int campaign,
                               double& statsMs, rawgment_apps::ProgressBar& progress)
{
    const int maxFrames = set.burstLengths.back();
    const auto isBurstLength = [&](int frames) {
        return std::find(set.burstLengths.begin(), set.burstLengths.end(), frames) != set.burstLengths.end();
    };
    // Every burst of a campaign has a seed of its own: campaign c's bursts are numbered from 100 c (9 of
    // them).
    uint64 burstIndex = 0;
    const auto nextBurstSeed = [&] {
        return studySeed(set, DRAW_CAMPAIGN_BURST, 100 * static_cast<uint64>(campaign) + burstIndex);
    };
    CampaignSamples out;
    for (double db : {6.0, 12.0, 24.0}) {
        const double g = dbToLinearGain(db);
        const RawFormat fmt = bench.sensor.rawFormat(g);
        for (double level : {0.2, 0.65}) {
            BurstStatistics stats(fmt);
            for (int t = 0; t < maxFrames; ++t) {
                Mat raw;
                bench.sensor.capture(bench.scene.meanAtUnitGain, g, bench.exposureFor(level, g),
                                     nextBurstSeed(), t, raw);
                statsMs += fastestMs(1, [&] { stats.add(raw); });
                if (!isBurstLength(t + 1))
                    continue;
                for (int side : {8, 16, 24}) {
                    std::vector<NoiseSample>& samples = out.light[{t + 1, side}];
                    out.samplingMs[{t + 1, side}] += fastestMs(1, [&] {
                        const std::vector<NoiseSample> s =
                            sampleBurstPatches(stats, cfaAlignedSquares(bench.scene.patches, side), g);
                        samples.insert(samples.end(), s.begin(), s.end());
                    });
                }
            }
            ++burstIndex;
            progress.advance();
        }
        // A burst of dark frames (sampleDarkBurst(), as rawgment_calibrate samples them).
        BurstStatistics dark(fmt);
        const Mat black = Mat::zeros(bench.scene.meanAtUnitGain.size(), CV_32FC1);
        for (int t = 0; t < maxFrames; ++t) {
            Mat raw;
            bench.sensor.capture(black, g, 1.0, nextBurstSeed(), t, raw);
            dark.add(raw);
            if (isBurstLength(t + 1))
                for (const NoiseSample& x :
                     sampleDarkBurst(dark, cfaAlignedSquares(bench.scene.patches, 24), g))
                    out.dark[t + 1].push_back(x);
        }
        ++burstIndex;
        progress.advance();
    }
    return out;
}

//! Per set-up and parameter, the mean stated relative error and the mean squared relative error made.
struct PrecisionSums
{
    std::vector<std::array<double, 3>> stated, made;
};

void addCampaignPrecision(const std::vector<PrecisionSetup>& setups, CampaignSamples& campaign,
                          const NoiseModel& truth, int seeds, PrecisionSums& sums)
{
    for (size_t i = 0; i < setups.size(); ++i) {
        const PrecisionSetup& u = setups[i];
        std::vector<NoiseSample> use;
        for (const NoiseSample& x : campaign.light[{u.frames, u.side}])
            if (!u.twoGains || std::abs(linearGainToDb(x.gain) - 12) > 1)
                use.push_back(x);
        if (u.dark)
            use.insert(use.end(), campaign.dark[u.frames].begin(), campaign.dark[u.frames].end());
        const CalibrationReport r = calibrateNoiseModel(use);
        const double est[3] = {r.model.alpha, r.model.sigmaD2, r.model.sigmaR2};
        const double tru[3] = {truth.alpha, truth.sigmaD2, truth.sigmaR2};
        for (int k = 0; k < 3; ++k) {
            sums.stated[i][size_t(k)] += r.uncertainty.stdError[k] / tru[k] / seeds;
            sums.made[i][size_t(k)] += (est[k] / tru[k] - 1) * (est[k] / tru[k] - 1) / seeds;
        }
    }
}

//! Adds each knob setting's fit and sampling time and its squared worst relative parameter error.
void addCampaignKnobErrors(const std::vector<CalibrationKnobSetting>& settings, CampaignSamples& campaign,
                           const NoiseModel& truth, std::vector<double>& ms,
                           std::vector<double>& squaredError)
{
    for (size_t i = 0; i < settings.size(); ++i) {
        const CalibrationKnobSetting& s = settings[i];
        CalibrationParams p;
        p.line.ransacIterations = s.ransac;
        CalibrationReport r;
        const double fitMs = fastestMs(1, [&] {
            r = calibrateNoiseModel(campaign.light[{s.frames, s.side}], p);
        });
        ms[i] += fitMs + campaign.samplingMs[{s.frames, s.side}];
        const double e = std::max({std::abs(r.model.alpha / truth.alpha - 1),
                                   std::abs(r.model.sigmaD2 / truth.sigmaD2 - 1),
                                   std::abs(r.model.sigmaR2 / truth.sigmaR2 - 1)});
        squaredError[i] += e * e;
    }
}

/** The stated and made errors per set-up, and for more of the same data (no gain left out, no dark
 * frames) the reference's stated errors scaled by the formula. */
std::vector<PrecisionRow> precisionRows(const std::vector<PrecisionSetup>& setups, const PrecisionSums& sums,
                                        int maxFrames)
{
    // The reference: the longest bursts, 24x24, 3 gains, no dark frames (the row of the paper's protocol).
    size_t reference = 0;
    for (size_t i = 0; i < setups.size(); ++i)
        if (setups[i].frames == maxFrames && setups[i].side == 24 && !setups[i].twoGains && !setups[i].dark)
            reference = i;
    std::vector<PrecisionRow> rows;
    for (size_t i = 0; i < setups.size(); ++i) {
        PrecisionRow row;
        row.setting = setups[i].name;
        const PrecisionSetup& u = setups[i];
        const bool moreOfTheSame = !u.twoGains && !u.dark;
        // Pixels per square scale with side^2; frames enter as T - 1 degrees of freedom.
        const double scale = std::sqrt((maxFrames - 1.0) * 24 * 24 / ((u.frames - 1.0) * u.side * u.side));
        for (int k = 0; k < 3; ++k) {
            row.stated[k] = sums.stated[i][size_t(k)];
            row.made[k] = std::sqrt(sums.made[i][size_t(k)]);
            row.formula[k] = moreOfTheSame ? sums.stated[reference][size_t(k)] * scale : 0.0;
        }
        rows.push_back(row);
    }
    return rows;
}

void measureCalibrationKnobs(const TradeoffSettings& set, std::vector<TradeoffRow>& rows,
                             std::vector<PrecisionRow>& precision, rawgment_apps::ProgressBar& progress)
{
    ColorCheckerOptions chart;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    SensorParams params;
    params.noise = NoiseModel(0.4, 0.5, 2.0);
    const CalibrationBench bench(chart, params);
    const int maxFrames = set.burstLengths.back();
    const double frameMp = megapixels(bench.scene.meanAtUnitGain.size());
    const std::vector<CalibrationKnobSetting> settings = calibrationKnobSettings(set);
    const std::vector<PrecisionSetup> setups = precisionSetups(set);
    std::vector<double> squaredError(settings.size(), 0), ms(settings.size(), 0);
    PrecisionSums sums{std::vector<std::array<double, 3>>(setups.size(), {0, 0, 0}),
                       std::vector<std::array<double, 3>>(setups.size(), {0, 0, 0})};
    double statsMsPerFrame = 0;
    for (int campaign = 0; campaign < set.seeds; ++campaign) {
        CampaignSamples samples = sampleCampaign(set, bench, campaign, statsMsPerFrame, progress);
        addCampaignPrecision(setups, samples, bench.truth, set.seeds, sums);
        addCampaignKnobErrors(settings, samples, bench.truth, ms, squaredError);
    }
    const std::vector<PrecisionRow> made = precisionRows(setups, sums, maxFrames);
    precision.insert(precision.end(), made.begin(), made.end());
    statsMsPerFrame /= set.seeds * 6.0 * maxFrames;
    for (size_t i = 0; i < settings.size(); ++i) {
        const CalibrationKnobSetting& s = settings[i];
        // Time of the whole calibration (statistics of every frame, sampling, fit) per MP of burst input.
        const double totalMs = 6 * s.frames * statsMsPerFrame + ms[i] / set.seeds;
        rows.push_back({s.knob,
                        s.name,
                        "RMS over campaigns of the worst relative error of alpha, sigma_d^2, sigma_r^2",
                        std::sqrt(squaredError[i] / set.seeds),
                        totalMs / (6 * s.frames * frameMp),
                        s.knob == "Calibration RANSAC iterations" ? "the fit is a small part of the time"
                                                                  : "more data, smaller error, linear cost",
                        {}});
    }
}

// Shapiro-Wilk, batched against one call per series: the same numbers, a different price.
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
}

} // namespace rawgment_apps
