// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The calibration studies' simulated campaigns (calibration_bench.hpp).
#include "calibration_bench.hpp"

#include <algorithm>
#include <chrono>

namespace rawgment_studies {

using namespace cv;
using namespace cv::rawgment;

CalibrationBench::CalibrationBench(const ColorCheckerOptions& chartOptions, const SensorParams& params)
    : chart(chartOptions), scene(makeColorCheckerScene(chartOptions)),
      sensor(params, scene.meanAtUnitGain.size()), truth(sensor.effectiveModel())
{
}

double CalibrationBench::exposureFor(double level, double gain) const
{
    const RawFormat unitFormat = sensor.rawFormat(1);
    return level * (unitFormat.whiteLevel - unitFormat.blackLevel[0]) / (gain * chart.illumination);
}

double simulateLightBurst(const CalibrationBench& bench, double gain, double level, uint64_t seed, int frames,
                          const std::vector<int>& cuts,
                          const std::function<void(int, const BurstStatistics&)>& atCut)
{
    BurstStatistics stats(bench.sensor.rawFormat(gain));
    double addMs = 0;
    for (int t = 0; t < frames; ++t) {
        Mat raw;
        bench.sensor.capture(bench.scene.meanAtUnitGain, gain, bench.exposureFor(level, gain), seed, t, raw);
        const auto start = std::chrono::steady_clock::now();
        stats.add(raw);
        addMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (std::find(cuts.begin(), cuts.end(), t + 1) != cuts.end())
            atCut(t + 1, stats);
    }
    return addMs;
}

} // namespace rawgment_studies
