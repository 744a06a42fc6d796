// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Do the calibration's 95% intervals hold the truth 95% of the time? Over many simulated campaigns of
// the trade-off sensor (alpha 0.4, sigma_d^2 0.5, sigma_r^2 2 plus quantisation, 12 bits; 3 gains, 6 to
// 24 dB; ColorChecker levels at 20%, 65% and 105% of white, so that the brightest patches clip, and a
// burst of dark frames per gain, as docs/calibrate_your_camera.md asks a user to shoot), for
// both fit methods, with and without 5% outlier pixels (2% hot, 1% dead, 2% noisy), it counts how
// often each parameter's interval holds the simulator's effective model, and prints the mean and RMS
// of the errors in standard errors (0 and 1 when the errors are what they claim). Prints Markdown.
//
//   build/release/bin/study_calibration_coverage [campaigns=40] [frames=16]
#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace cv;
using namespace cv::rawgment;

namespace {

struct Tally
{
    int campaigns = 0;
    int covered[3] = {0, 0, 0};
    double z[3] = {0, 0, 0};        // sums of (estimate - truth) / standard error
    double zz[3] = {0, 0, 0};       // sums of their squares
    double relError[3] = {0, 0, 0}; // sums of relative standard errors
    int bootstrapSource = 0;
};

} // namespace

int main(int argc, char** argv)
{
    const int campaigns = argc > 1 ? std::atoi(argv[1]) : 40;
    const int frames = argc > 2 ? std::atoi(argv[2]) : 16;
    if (campaigns < 2 || frames < 3) {
        std::fprintf(stderr, "usage: study_calibration_coverage [campaigns >= 2] [frames >= 3]\n");
        return 2;
    }
    ColorCheckerOptions chart;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    const ColorCheckerScene scene = makeColorCheckerScene(chart);
    const std::vector<Rect> squares = cfaAlignedSquares(scene.patches, 24);
    const char* methodNames[2] = {"joint", "two-stage"};
    Tally tally[2][2]; // [outliers][method]
    for (int outliers = 0; outliers < 2; ++outliers) {
        SensorParams p;
        p.noise = NoiseModel(0.4, 0.5, 2.0);
        p.blackLevel = Vec4d::all(256);
        p.bitDepth = 12;
        if (outliers) {
            p.hotPixelFraction = 0.02;
            p.deadPixelFraction = 0.01;
            p.noisyPixelFraction = 0.02;
        }
        const SensorSimulator sensor(p, scene.meanAtUnitGain.size());
        const NoiseModel truth = sensor.effectiveModel();
        const double white = (1 << p.bitDepth) - 1 - p.blackLevel[0];
        for (int c = 0; c < campaigns; ++c) {
            std::fprintf(stderr, "\r%s outliers: campaign %d/%d", outliers ? "with" : "without", c + 1,
                         campaigns);
            std::vector<NoiseSample> samples;
            uint64 seed = 100000 * (c + 1) + 1000 * outliers;
            for (double db : {6.0, 12.0, 24.0}) {
                const double g = dbToLinearGain(db);
                for (double level : {0.2, 0.65, 1.05}) {
                    BurstStatistics stats(sensor.rawFormat(g));
                    for (int t = 0; t < frames; ++t) {
                        Mat raw;
                        sensor.capture(scene.meanAtUnitGain, g, level * white / (g * 1000), seed, t, raw);
                        stats.add(raw);
                    }
                    ++seed;
                    const std::vector<NoiseSample> s = sampleBurstPatches(stats, squares, g);
                    samples.insert(samples.end(), s.begin(), s.end());
                }
                // Dark frames (a lens cap), sampled as rawgment_calibrate samples them.
                BurstStatistics dark(sensor.rawFormat(g));
                for (int t = 0; t < frames; ++t) {
                    Mat raw;
                    sensor.capture(Mat::zeros(scene.meanAtUnitGain.size(), CV_32FC1), g, 1.0, seed, t, raw);
                    dark.add(raw);
                }
                ++seed;
                const std::vector<NoiseSample> d = sampleDarkBurst(dark, squares, g);
                samples.insert(samples.end(), d.begin(), d.end());
            }
            for (int m = 0; m < 2; ++m) {
                CalibrationParams params;
                params.method = m == 0 ? NOISE_FIT_JOINT : NOISE_FIT_TWO_STAGE;
                params.line.seed = static_cast<uint64>(c);
                const CalibrationReport r = calibrateNoiseModel(samples, params);
                Tally& t = tally[outliers][m];
                const double est[3] = {r.model.alpha, r.model.sigmaD2, r.model.sigmaR2};
                const double tru[3] = {truth.alpha, truth.sigmaD2, truth.sigmaR2};
                for (int k = 0; k < 3; ++k) {
                    const Vec2d ci = r.interval(static_cast<NoiseModelParameter>(k));
                    t.covered[k] += ci[0] <= tru[k] && tru[k] <= ci[1] ? 1 : 0;
                    const double se = r.uncertainty.stdError[k];
                    const double z = se > 0 ? (est[k] - tru[k]) / se : 0.0;
                    t.z[k] += z;
                    t.zz[k] += z * z;
                    t.relError[k] += se / tru[k];
                }
                t.bootstrapSource += r.uncertainty.source == UNCERTAINTY_BOOTSTRAP ? 1 : 0;
                ++t.campaigns;
            }
        }
        std::fprintf(stderr, "\n");
    }
    std::printf(
        "%d campaigns of %d frames per burst. When the standard errors are right, the 95%% interval "
        "holds the truth in 95%% of campaigns (binomial spread at %d campaigns: +-%.1f%%), mean z is 0 "
        "(+-%.2f) and RMS z 1 (+-%.2f).\n\n",
        campaigns, frames, campaigns, 100 * std::sqrt(0.95 * 0.05 / campaigns), 1 / std::sqrt(campaigns),
        std::sqrt(0.5 / campaigns));
    std::printf("| outliers | method | parameter | coverage | mean z | RMS z | relative standard error | "
                "bootstrap used |\n|---|---|---|---:|---:|---:|---:|---:|\n");
    const char* names[3] = {"alpha", "sigma_d^2", "sigma_r^2"};
    for (int o = 0; o < 2; ++o)
        for (int m = 0; m < 2; ++m)
            for (int k = 0; k < 3; ++k) {
                const Tally& t = tally[o][m];
                std::printf("| %s | %s | %s | %.1f%% | %+.2f | %.2f | %.3f%% | %d/%d |\n", o ? "5%" : "none",
                            methodNames[m], names[k], 100.0 * t.covered[k] / t.campaigns,
                            t.z[k] / t.campaigns, std::sqrt(t.zz[k] / t.campaigns),
                            100.0 * t.relError[k] / t.campaigns, t.bootstrapSource, t.campaigns);
            }
    return 0;
}
