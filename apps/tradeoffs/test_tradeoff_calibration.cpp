// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The trade-off study's calibration rows read the right way: each error carries its standard error, and the
// error falls with more frames and larger patches by more than the standard errors of those falls.
#include "tradeoff_study.hpp"

#include <gtest/gtest.h>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <map>

namespace {

using namespace rawgment_apps;

std::map<std::string, const TradeoffRow*> bySetting(const std::vector<TradeoffRow>& rows,
                                                    const std::string& knob)
{
    std::map<std::string, const TradeoffRow*> out;
    for (const TradeoffRow& r : rows)
        if (r.knob == knob)
            out[r.setting] = &r;
    return out;
}

/* Over 32 campaigns of up to 32-frame bursts (the report's seeds, whose default run has 100-frame bursts
 * too), the mean squared error must fall from 8 to 16 to 32 frames, and from 8x8 to 16x16 to 24x24 squares,
 * by more than the standard error of each fall (paired over the campaigns). The RMS falls expected are
 * 1/sqrt(T - 1) per frame count (1.46x and 1.44x) and 1/side per patch (2x and 1.5x). Measured: 1.6, 3.6, 2.9
 * and 2.8 standard errors. 8 -> 16 frames is the weakest because 8-frame errors have a heavy tail (chi-square
 * of 7 degrees of freedom per pixel); two standard errors there would take about 60 campaigns, a minute of
 * both cores. */
TEST(Tradeoffs, calibrationErrorFallsWithFramesAndPatchesBeyondItsStandardError)
{
    TradeoffSettings set;
    set.seeds = 32;
    set.burstLengths = {8, 16, 32};
    set.precision = false;
    set.ransacIterations.clear();
    set.repeats = 1;
    std::vector<TradeoffRow> rows;
    std::vector<PrecisionRow> precision;
    ProgressBar progress("tradeoff test", 9 * static_cast<size_t>(set.seeds));
    tradeoff_study::measureCalibrationKnobs(set, rows, precision, progress);
    progress.finish();
    EXPECT_TRUE(precision.empty());
    const auto expectFalls = [&](const std::string& knob, const std::vector<std::string>& settings) {
        const std::map<std::string, const TradeoffRow*> row = bySetting(rows, knob);
        for (size_t k = 0; k < settings.size(); ++k) {
            ASSERT_TRUE(row.count(settings[k])) << settings[k];
            const TradeoffRow& r = *row.at(settings[k]);
            ASSERT_EQ(r.campaignErrors.size(), 32u);
            EXPECT_GT(r.errorStdError, 0) << settings[k];
            EXPECT_LT(r.errorStdError, 0.25 * r.error) << settings[k] << ": too few campaigns to tell apart";
            EXPECT_GT(r.secondsPerCalibration, 0);
            if (k == 0)
                continue;
            const TradeoffRow& before = *row.at(settings[k - 1]);
            const ErrorFall f = pairedFall(before.campaignErrors, r.campaignErrors);
            std::cout << knob << ", " << settings[k - 1] << " -> " << settings[k] << ": RMS " << before.error
                      << " -> " << r.error << ", mean square falls by " << f.meanSquareFall << " +- "
                      << f.stdError << " (" << f.meanSquareFall / f.stdError << " SE)\n";
            EXPECT_GT(f.meanSquareFall, f.stdError) << settings[k - 1] << " -> " << settings[k];
            EXPECT_LT(r.error, before.error);
        }
    };
    expectFalls("Calibration burst length", {"8 frames", "16 frames", "32 frames"});
    expectFalls("Calibration patch size", {"8x8", "16x16", "24x24 (paper)"});
    // A calibration of more frames takes longer: the frames are what a user pays for.
    const std::map<std::string, const TradeoffRow*> frames = bySetting(rows, "Calibration burst length");
    EXPECT_EQ(frames.at("8 frames")->framesToShoot, 48);
    EXPECT_LT(frames.at("8 frames")->secondsPerCalibration, frames.at("32 frames")->secondsPerCalibration);
}

TEST(Tradeoffs, rmsAndPairedFallsFollowTheirDefinitions)
{
    const std::vector<double> a = {0.3, 0.4, 0.5, 0.1}, b = {0.1, 0.2, 0.2, 0.1};
    // RMS of a: sqrt((0.09 + 0.16 + 0.25 + 0.01) / 4); the mean square's standard error is sd(e^2) / 2.
    EXPECT_NEAR(rmsOf(a), std::sqrt(0.51 / 4), 1e-15);
    const double m = 0.51 / 4;
    double ss = 0;
    for (double e : a)
        ss += (e * e - m) * (e * e - m);
    EXPECT_NEAR(rmsStandardError(a), std::sqrt(ss / 3 / 4) / (2 * std::sqrt(m)), 1e-15);
    EXPECT_EQ(rmsStandardError({0.2}), 0);
    // Differences of squares 0.08, 0.12, 0.21, 0: mean 0.1025.
    const ErrorFall f = pairedFall(a, b);
    EXPECT_NEAR(f.meanSquareFall, 0.1025, 1e-15);
    double sd = 0;
    for (double d : {0.08, 0.12, 0.21, 0.0})
        sd += (d - 0.1025) * (d - 0.1025);
    EXPECT_NEAR(f.stdError, std::sqrt(sd / 3 / 4), 1e-15);
    EXPECT_THROW(pairedFall(a, {0.1}), cv::Exception);
}

// The study fits most campaigns without the bootstrap: the model must be the one a user's default fit gives.
TEST(Tradeoffs, theBootstrapChangesTheStatedErrorsButNotTheModel)
{
    cv::rawgment::ColorCheckerOptions chart;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    const cv::rawgment::ColorCheckerScene scene = cv::rawgment::makeColorCheckerScene(chart);
    cv::rawgment::SensorParams params;
    params.noise = cv::rawgment::NoiseModel(0.4, 0.5, 2.0);
    const cv::rawgment::SensorSimulator sensor(params, scene.meanAtUnitGain.size());
    std::vector<cv::rawgment::NoiseSample> samples;
    for (double g : {2.0, 8.0}) {
        cv::rawgment::BurstStatistics stats(sensor.rawFormat(g));
        for (int t = 0; t < 8; ++t) {
            cv::Mat raw;
            sensor.capture(scene.meanAtUnitGain, g, 0.5 * 3839 / (g * 1000), 3, t, raw);
            stats.add(raw);
        }
        const auto s =
            cv::rawgment::sampleBurstPatches(stats, cv::rawgment::cfaAlignedSquares(scene.patches, 12), g);
        samples.insert(samples.end(), s.begin(), s.end());
    }
    cv::rawgment::CalibrationParams none;
    none.bootstrapReplicates = 0;
    const cv::rawgment::CalibrationReport with = cv::rawgment::calibrateNoiseModel(samples),
                                          without = cv::rawgment::calibrateNoiseModel(samples, none);
    EXPECT_EQ(with.model.alpha, without.model.alpha);
    EXPECT_EQ(with.model.sigmaD2, without.model.sigmaD2);
    EXPECT_EQ(with.model.sigmaR2, without.model.sigmaR2);
    EXPECT_EQ(with.uncertainty.bootstrapReplicates, 200);
    EXPECT_EQ(without.uncertainty.bootstrapReplicates, 0);
}

/* The bank's pattern against the sensor's (DSNU 1 DN under about 30 DN^2 of temporal noise): its mean square
 * error is expected at 2 s_F^2 (1 - sqrt(w)), w = s_F^2 / (s_F^2 + v / M) the shrinkage (the pattern keeps
 * the sensor's variance, and sqrt(w) of its correlation with the truth): RMS 1.14, 1.04, 0.91, 0.81 and
 * 0.65 DN for 4, 8, 16, 25 and 50 frames. Measured: 1.04, 1.01, 0.91, 0.81, 0.66 (at 4 and 8 frames the
 * shrinkage, estimated from so few frames, does better than the formula's w). Over 16 campaigns each fall
 * must exceed 2 standard errors of the paired fall (one-sided, p < 0.023). Measured: 3.2, 13, 17 and 46; the
 * first is the weakest because w estimated from 4 or 8 frames is itself noisy and small at both. */
TEST(Tradeoffs, theBanksPatternComesCloserToTheSensorsWithEveryFramePerGain)
{
    TradeoffSettings set;
    set.seeds = 16;
    set.repeats = 1;
    // The time is the report's business (a 12 MP camera's); a small camera's is timed here.
    set.timingSize = cv::Size(800, 600);
    std::vector<TradeoffRow> rows;
    tradeoff_study::measureDarkBankFrames(set, rows);
    const std::map<std::string, const TradeoffRow*> row = bySetting(rows, "Dark-frame bank frames per gain");
    // The sensor's temporal variance at gain 4 (tradeoff_dark_bank.cpp): read noise, row noise 0.3 g^2 + 0.5,
    // rounding; its pattern's variance s_F^2 = 1 DN^2 (DSNU 1 DN).
    cv::rawgment::NoiseModel m = cv::rawgment::SensorParams().noise;
    m.rowSigmaD2 = 0.3;
    m.rowSigmaR2 = 0.5;
    const double gain = 4, v = m.variance(0, gain) + m.rowVariance(gain) + 1.0 / 12;
    ASSERT_EQ(row.size(), set.bankFrames.size());
    for (size_t k = 0; k < set.bankFrames.size(); ++k) {
        const TradeoffRow& r = *row.at(cv::format("%d frames", set.bankFrames[k]));
        std::cout << r.setting << ": RMS " << r.error << " +- " << r.errorStdError << " DN (expected about "
                  << std::sqrt(2 * (1 - std::sqrt(1 / (1 + v / set.bankFrames[k])))) << "), "
                  << r.secondsPerCalibration << " s for a " << set.timingSize.width << "x"
                  << set.timingSize.height << " camera\n";
        EXPECT_EQ(r.framesToShoot, set.bankFrames[k]);
        EXPECT_GT(r.secondsPerCalibration, 0);
        if (k == 0)
            continue;
        const TradeoffRow& before = *row.at(cv::format("%d frames", set.bankFrames[k - 1]));
        const ErrorFall f = pairedFall(before.campaignErrors, r.campaignErrors);
        std::cout << "  fall from " << before.setting << ": " << f.meanSquareFall / f.stdError << " SE\n";
        EXPECT_GT(f.meanSquareFall, 2 * f.stdError) << r.setting;
    }
}

} // namespace
