// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The simulated calibration campaigns of the trade-off report's calibration knobs (apps/tradeoffs), which the
// calibration studies (studies/calibration) run too: the simulated chart and sensor of a campaign, and a
// light burst of it simulated frame by frame into burst statistics, cut at the burst lengths a study
// compares.
#ifndef RAWGMENT_STUDIES_CALIBRATION_BENCH_HPP
#define RAWGMENT_STUDIES_CALIBRATION_BENCH_HPP

#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace rawgment_studies {

//! The simulated colour chart and sensor of calibration campaigns, and the sensor's truth.
struct CalibrationBench
{
    cv::rawgment::ColorCheckerOptions chart;
    cv::rawgment::ColorCheckerScene scene;
    cv::rawgment::SensorSimulator sensor;
    cv::rawgment::NoiseModel truth; //!< SensorSimulator::effectiveModel(): quantisation included

    CalibrationBench(const cv::rawgment::ColorCheckerOptions& chartOptions,
                     const cv::rawgment::SensorParams& params);

    /** The exposure of a burst at light `level`: a perfect white reflector at that fraction of the DN
     * range above black, level x range / (gain x the chart's illumination). */
    double exposureFor(double level, double gain) const;
};

/** Simulates a light burst of `frames` frames of the chart at linear `gain` and light `level` (the capture
 * seed `seed`, frame t its stream), adds each frame to one BurstStatistics, and after each frame count in
 * `cuts` calls `atCut(frames so far, the statistics)`. Returns the milliseconds spent in
 * BurstStatistics::add(). */
double simulateLightBurst(const CalibrationBench& bench, double gain, double level, uint64_t seed, int frames,
                          const std::vector<int>& cuts,
                          const std::function<void(int, const cv::rawgment::BurstStatistics&)>& atCut);

} // namespace rawgment_studies

#endif // RAWGMENT_STUDIES_CALIBRATION_BENCH_HPP
