// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What calibration accuracy costs: the error of alpha, sigma_d^2 and sigma_r^2 against the number of
// frames (8 to 100) and of patches (6, 12, 24), on the paper's protocol from the sensor simulator,
// averaged over several seeds, with the time of the statistics and of the fit. Prints a Markdown table.
//
//   build/release/bin/study_calibration [seeds=4]
#include "calibration_bench.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>

using namespace cv;
using namespace cv::rawgment;

namespace {

struct Cell
{
    double err[3] = {0, 0, 0}; // sums of squared relative errors
    double fitMs = 0;
    int runs = 0;
};

double now()
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

} // namespace

int main(int argc, char** argv)
{
    const int seeds = argc > 1 ? std::atoi(argv[1]) : 4;
    if (seeds < 1) {
        std::fprintf(stderr, "usage: study_calibration [seeds >= 1]\n");
        return 2;
    }
    SensorParams p;
    p.noise = NoiseModel(0.4, 0.5, 2.0);
    p.blackLevel = Vec4d::all(256);
    p.bitDepth = 12;
    ColorCheckerOptions chart;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    const rawgment_studies::CalibrationBench bench(chart, p);
    const NoiseModel& truth = bench.truth;
    const std::vector<Rect> squares = cfaAlignedSquares(bench.scene.patches, 24);
    const std::vector<int> frameCounts = {8, 16, 32, 64, 100};
    const std::vector<int> patchCounts = {6, 12, 24};
    std::map<std::pair<int, int>, Cell> cells;
    double statsMs = 0;
    for (int seed = 0; seed < seeds; ++seed) {
        std::fprintf(stderr, "seed %d/%d\n", seed + 1, seeds);
        // samples[frames][patch] from one stream of 100 frames, cut at each frame count.
        std::map<int, std::vector<std::vector<NoiseSample>>> samples;
        uint64 streamSeed = 1000 * (seed + 1);
        for (double db : {6.0, 12.0, 24.0}) {
            const double g = dbToLinearGain(db);
            for (double level : {0.2, 0.65}) {
                statsMs += rawgment_studies::simulateLightBurst(
                    bench, g, level, streamSeed, frameCounts.back(), frameCounts,
                    [&](int frames, const BurstStatistics& stats) {
                        auto& perPatch = samples[frames];
                        perPatch.resize(squares.size());
                        for (size_t k = 0; k < squares.size(); ++k) {
                            const std::vector<NoiseSample> s = sampleBurstPatches(stats, {squares[k]}, g);
                            perPatch[k].insert(perPatch[k].end(), s.begin(), s.end());
                        }
                    });
                ++streamSeed;
            }
        }
        for (int frames : frameCounts)
            for (int patches : patchCounts) {
                std::vector<NoiseSample> use;
                // Every (24 / patches)-th patch, so that the subset spans the chart's range of means.
                for (int k = 0; k < 24; k += 24 / patches)
                    use.insert(use.end(), samples[frames][k].begin(), samples[frames][k].end());
                const double t0 = now();
                const CalibrationReport r = calibrateNoiseModel(use);
                Cell& cell = cells[{frames, patches}];
                cell.fitMs += now() - t0;
                const double e[3] = {r.model.alpha / truth.alpha - 1, r.model.sigmaD2 / truth.sigmaD2 - 1,
                                     r.model.sigmaR2 / truth.sigmaR2 - 1};
                for (int i = 0; i < 3; ++i)
                    cell.err[i] += e[i] * e[i];
                ++cell.runs;
            }
    }
    std::printf(
        "| frames | patches | RMS error alpha | RMS error sigma_d^2 | RMS error sigma_r^2 | fit time |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|\n");
    for (int frames : frameCounts)
        for (int patches : patchCounts) {
            const Cell& c = cells[{frames, patches}];
            std::printf("| %d | %d | %.2f%% | %.2f%% | %.2f%% | %.0f ms |\n", frames, patches,
                        100 * std::sqrt(c.err[0] / c.runs), 100 * std::sqrt(c.err[1] / c.runs),
                        100 * std::sqrt(c.err[2] / c.runs), c.fitMs / c.runs);
        }
    std::printf("\nBurst statistics: %.2f ms per 248x168 frame; %d seeds; truth alpha %.3f, sigma_d^2 %.3f, "
                "sigma_r^2 %.4f (quantisation included).\n",
                statsMs / (seeds * 6.0 * frameCounts.back()), seeds, truth.alpha, truth.sigmaD2,
                truth.sigmaR2);
    return 0;
}
