// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The trade-off studies of calibration (rawgment_tradeoffs): each knob's time and accuracy over simulated
// campaigns (the chart, sensor and light bursts of studies/calibration/calibration_bench.hpp), and the errors
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
} // namespace tradeoff_study
} // namespace rawgment_apps
