// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Sample: calibrate the noise model from bursts of a chart, as from your camera's. Three gains, one
// burst each: the per-pixel temporal statistics (BurstStatistics), the (mean, variance) samples of the
// chart's patches, then the joint fit with its error bars, printed against the simulator's truth.
#include <opencv2/rawgment.hpp>

#include <cmath>
#include <cstdio>

int main()
{
    using namespace cv::rawgment;
    SensorParams params;
    params.noise = NoiseModel(0.3, 2.0, 1.0);
    const SensorSimulator sensor(params, cv::Size(560, 384));
    ColorCheckerOptions options;
    options.patchSize = 80;
    options.border = 10;
    options.illumination = 3000;
    const ColorCheckerScene chart = makeColorCheckerScene(options);
    cv::Mat mean = cv::Mat::zeros(sensor.size(), CV_32FC1);
    chart.meanAtUnitGain.copyTo(mean(cv::Rect(cv::Point(), chart.meanAtUnitGain.size())));
    const std::vector<cv::Rect> squares = cfaAlignedSquares(chart.patches, 48);

    std::vector<NoiseSample> samples;
    const double gainsDb[] = {0, 6, 12};
    for (int i = 0; i < 3; ++i) {
        const double gain = dbToLinearGain(gainsDb[i]);
        BurstStatistics stats(sensor.rawFormat(gain));
        std::vector<cv::Mat> burst;
        sensor.captureBurst(mean, gain, 0.5, 32, deriveSeed(1, SEED_SIMULATED_BURST, uint64(i)), burst);
        for (const cv::Mat& frame : burst)
            stats.add(frame);
        const std::vector<NoiseSample> burstSamples = sampleBurstPatches(stats, squares, gain);
        samples.insert(samples.end(), burstSamples.begin(), burstSamples.end());
    }

    const CalibrationReport report = calibrateNoiseModel(samples);
    const NoiseModel truth = sensor.effectiveModel();
    const struct
    {
        const char* name;
        double fitted, truth;
        NoiseModelParameter param;
    } rows[] = {{"alpha", report.model.alpha, truth.alpha, NOISE_PARAM_ALPHA},
                {"sigma_d^2", report.model.sigmaD2, truth.sigmaD2, NOISE_PARAM_SIGMA_D2},
                {"sigma_r^2", report.model.sigmaR2, truth.sigmaR2, NOISE_PARAM_SIGMA_R2}};
    std::printf("%zu samples from 3 bursts of 32 frames\n%-10s %10s %10s %10s\n", samples.size(), "",
                "calibrated", "+- s.e.", "truth");
    bool within = true;
    for (const auto& row : rows) {
        const double se = report.uncertainty.stdError[row.param];
        std::printf("%-10s %10.5f %10.5f %10.5f\n", row.name, row.fitted, se, row.truth);
        within = within && std::abs(row.fitted - row.truth) <= 4 * se;
    }
    // 4 standard errors: a miss 1 time in 16,000 per parameter when the stated errors are right.
    std::printf("%s\n", within ? "every parameter within 4 standard errors of the truth"
                               : "a parameter is more than 4 standard errors from the truth");
    return within ? 0 : 1;
}
