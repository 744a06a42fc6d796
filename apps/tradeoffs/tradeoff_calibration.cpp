// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The trade-off studies of calibration (rawgment_tradeoffs): each knob's time and accuracy over simulated
// campaigns (the chart, sensor and light bursts of calibration_bench.hpp), and the errors
// a calibration states against those it makes; and the studies' shared seeds and timers (tradeoff_study.hpp).
#include "tradeoff_study.hpp"

#include "calibration_bench.hpp"

#include "flow_common.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/cpu.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <map>

namespace rawgment_apps {
namespace tradeoff_study {

using namespace cv;
using namespace cv::rawgment;

uint64_t studySeed(const TradeoffSettings& set, StudyDraw draw, uint64_t sub)
{
    return deriveSeed(set.seed, SEED_STUDY, (static_cast<uint64>(draw) << 32) | sub);
}

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

namespace {

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
    for (int it : set.ransacIterations)
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

//! One campaign's samples after each burst length, for every square side.
struct CampaignSamples
{
    std::map<std::pair<int, int>, std::vector<NoiseSample>> light; //!< (frames, side)
    std::map<int, std::vector<NoiseSample>> dark;                  //!< (frames), 24x24
    std::map<std::pair<int, int>, double> samplingMs;              //!< (frames, side)
};

/** Simulates one campaign (3 gains x (2 light levels + 1 dark)) and samples each burst's statistics after
 * every burst length of the study; `statsMs` gains the time of every BurstStatistics::add. */
CampaignSamples sampleCampaign(const TradeoffSettings& set, const rawgment_studies::CalibrationBench& bench,
                               int campaign, double& statsMs, rawgment_apps::ProgressBar& progress)
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
            statsMs += rawgment_studies::simulateLightBurst(
                bench, g, level, nextBurstSeed(), maxFrames, set.burstLengths,
                [&](int frames, const BurstStatistics& stats) {
                    for (int side : {8, 16, 24}) {
                        std::vector<NoiseSample>& samples = out.light[{frames, side}];
                        out.samplingMs[{frames, side}] += fastestMs(1, [&] {
                            const std::vector<NoiseSample> s =
                                sampleBurstPatches(stats, cfaAlignedSquares(bench.scene.patches, side), g);
                            samples.insert(samples.end(), s.begin(), s.end());
                        });
                    }
                });
            ++burstIndex;
            progress.advance();
        }
        progress.advance();   // counted whether or not the dark burst below is simulated
        if (!set.precision) { // only the precision set-up "+ dark frames" uses it; its seed stays taken
            ++burstIndex;
            continue;
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
    }
    return out;
}

//! Per set-up and parameter, the mean stated relative error and the mean squared relative error made.
struct PrecisionSums
{
    std::vector<std::array<double, 3>> stated, made;
};

//! What one campaign gives: its precision terms and its knob settings' errors and times.
struct CampaignResult
{
    PrecisionSums precision;
    std::vector<double> knobErrors, knobMs;
    double statsMs = 0;
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

/** Each knob setting's worst relative parameter error in this campaign, and its fit and sampling time. A
 * timed campaign fits as a user's calibration does, its bootstrap included; the others fit without the
 * bootstrap, which changes the errors a report states but not the model. Settings that are the same
 * calibration (the longest bursts at 24x24 and 500 iterations) are fitted once. */
void campaignKnobErrors(const std::vector<CalibrationKnobSetting>& settings, CampaignSamples& campaign,
                        const NoiseModel& truth, bool timed, CampaignResult& out)
{
    std::map<std::array<int, 3>, std::pair<double, double>> fitted; // (frames, side, ransac) -> error, ms
    for (const CalibrationKnobSetting& s : settings) {
        const std::array<int, 3> key = {s.frames, s.side, s.ransac};
        if (!fitted.count(key)) {
            CalibrationParams p;
            p.line.ransacIterations = s.ransac;
            if (!timed)
                p.bootstrapReplicates = 0;
            CalibrationReport r;
            const double fitMs = fastestMs(1, [&] {
                r = calibrateNoiseModel(campaign.light[{s.frames, s.side}], p);
            });
            fitted[key] = {std::max({std::abs(r.model.alpha / truth.alpha - 1),
                                     std::abs(r.model.sigmaD2 / truth.sigmaD2 - 1),
                                     std::abs(r.model.sigmaR2 / truth.sigmaR2 - 1)}),
                           fitMs + campaign.samplingMs[{s.frames, s.side}]};
        }
        out.knobErrors.push_back(fitted[key].first);
        out.knobMs.push_back(fitted[key].second);
    }
}

/** Fastest time of BurstStatistics::add() per frame of `size` (CV_16UC1), from bursts of 8 frames (one
 * group of the default, so the group's flush is in it). */
double statisticsMsPerFrame(const TradeoffSettings& set, const rawgment_studies::CalibrationBench& bench,
                            Size size)
{
    Mat frame(size, CV_16UC1);
    randu(frame, Scalar(256), Scalar(4095));
    const RawFormat fmt = bench.sensor.rawFormat(1);
    const int frames = 8;
    return fastestMs(set.repeats,
                     [&] {
                         BurstStatistics stats(fmt);
                         for (int t = 0; t < frames; ++t)
                             stats.add(frame);
                     }) /
           frames;
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

} // namespace

void measureCalibrationKnobs(const TradeoffSettings& set, std::vector<TradeoffRow>& rows,
                             std::vector<PrecisionRow>& precision, rawgment_apps::ProgressBar& progress)
{
    ColorCheckerOptions chart;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    SensorParams params;
    params.noise = NoiseModel(0.4, 0.5, 2.0);
    const rawgment_studies::CalibrationBench bench(chart, params);
    const int maxFrames = set.burstLengths.back();
    const double frameMp = megapixels(bench.scene.meanAtUnitGain.size());
    const std::vector<CalibrationKnobSetting> settings = calibrationKnobSettings(set);
    const std::vector<PrecisionSetup> setups = precisionSetups(set);
    // Times are the mean of the first campaigns' (as many as the timings' repeats), run one after another
    // on a quiet machine; the other campaigns run side by side, one per thread. Every campaign counts in
    // the errors, summed in campaign order whatever the threads.
    const int timedCampaigns = std::min(set.seeds, set.repeats);
    std::vector<CampaignResult> results(static_cast<size_t>(set.seeds));
    const auto runCampaign = [&](int campaign) {
        CampaignResult& out = results[static_cast<size_t>(campaign)];
        out.precision = {std::vector<std::array<double, 3>>(setups.size(), {0, 0, 0}),
                         std::vector<std::array<double, 3>>(setups.size(), {0, 0, 0})};
        CampaignSamples samples = sampleCampaign(set, bench, campaign, out.statsMs, progress);
        if (set.precision)
            addCampaignPrecision(setups, samples, bench.truth, set.seeds, out.precision);
        campaignKnobErrors(settings, samples, bench.truth, campaign < timedCampaigns, out);
    };
    for (int campaign = 0; campaign < timedCampaigns; ++campaign)
        runCampaign(campaign);
    parallel_for_(Range(timedCampaigns, set.seeds), [&](const Range& range) {
        for (int campaign = range.start; campaign < range.end; ++campaign)
            runCampaign(campaign);
    });
    std::vector<std::vector<double>> errors(settings.size());
    std::vector<double> ms(settings.size(), 0);
    PrecisionSums sums{std::vector<std::array<double, 3>>(setups.size(), {0, 0, 0}),
                       std::vector<std::array<double, 3>>(setups.size(), {0, 0, 0})};
    double statsMsPerFrame = 0;
    for (int campaign = 0; campaign < set.seeds; ++campaign) {
        const CampaignResult& r = results[static_cast<size_t>(campaign)];
        for (size_t i = 0; i < settings.size(); ++i) {
            errors[i].push_back(r.knobErrors[i]);
            if (campaign < timedCampaigns)
                ms[i] += r.knobMs[i];
        }
        for (size_t i = 0; i < setups.size(); ++i)
            for (size_t k = 0; k < 3; ++k) {
                sums.stated[i][k] += r.precision.stated[i][k];
                sums.made[i][k] += r.precision.made[i][k];
            }
        if (campaign < timedCampaigns)
            statsMsPerFrame += r.statsMs / (timedCampaigns * 6.0 * maxFrames);
    }
    if (set.precision) {
        const std::vector<PrecisionRow> made = precisionRows(setups, sums, maxFrames);
        precision.insert(precision.end(), made.begin(), made.end());
    }
    // A user's calibration: the same bursts of a camera of timingSize (the statistics of every frame scale
    // with its pixels; sampling and the fit with the squares', which are the study's).
    const double cameraStatsMsPerFrame = statisticsMsPerFrame(set, bench, set.timingSize);
    for (size_t i = 0; i < settings.size(); ++i) {
        const CalibrationKnobSetting& s = settings[i];
        const int frames = 6 * s.frames; // 3 gains x 2 light levels
        const double sampleAndFitMs = ms[i] / timedCampaigns;
        TradeoffRow row{s.knob,
                        s.name,
                        "RMS over campaigns of the worst relative error of alpha, sigma_d^2, sigma_r^2",
                        rmsOf(errors[i]),
                        // Statistics of every frame, sampling and the fit, per MP of burst input.
                        (frames * statsMsPerFrame + sampleAndFitMs) / (frames * frameMp),
                        s.knob == "Calibration RANSAC iterations" ? "the fit is a small part of the time"
                                                                  : "more data, smaller error, linear cost",
                        {}};
        row.campaignErrors = errors[i];
        row.errorStdError = rmsStandardError(errors[i]);
        row.framesToShoot = frames;
        row.secondsPerCalibration = (frames * cameraStatsMsPerFrame + sampleAndFitMs) / 1000;
        rows.push_back(row);
    }
}

} // namespace tradeoff_study

double rmsOf(const std::vector<double>& errors)
{
    double sum = 0;
    for (double e : errors)
        sum += e * e;
    return errors.empty() ? 0.0 : std::sqrt(sum / errors.size());
}

double rmsStandardError(const std::vector<double>& errors)
{
    const size_t n = errors.size();
    const double rms = rmsOf(errors);
    if (n < 2 || rms == 0)
        return 0;
    double spread = 0;
    for (double e : errors)
        spread += (e * e - rms * rms) * (e * e - rms * rms);
    // d sqrt(m) = dm / (2 sqrt(m)), m the mean square, whose standard error is sd(e^2) / sqrt(n).
    return std::sqrt(spread / (n - 1) / n) / (2 * rms);
}

ErrorFall pairedFall(const std::vector<double>& before, const std::vector<double>& after)
{
    CV_Assert(before.size() == after.size());
    const size_t n = before.size();
    ErrorFall f;
    if (n == 0)
        return f;
    std::vector<double> d(n);
    for (size_t c = 0; c < n; ++c)
        d[c] = before[c] * before[c] - after[c] * after[c];
    for (double x : d)
        f.meanSquareFall += x / n;
    if (n < 2)
        return f;
    double spread = 0;
    for (double x : d)
        spread += (x - f.meanSquareFall) * (x - f.meanSquareFall);
    f.stdError = std::sqrt(spread / (n - 1) / n);
    return f;
}

} // namespace rawgment_apps
