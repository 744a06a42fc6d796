// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What the calibration tests share (test_calibration_samples.cpp, _lines, _fit, _dark): the paper's
// protocol of bursts on the reference sensor, its samples, and the relative errors of a fit.
#ifndef OPENCV_RAWGMENT_TEST_CALIBRATION_COMMON_HPP
#define OPENCV_RAWGMENT_TEST_CALIBRATION_COMMON_HPP

#include "test_common.hpp"

#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <ostream>
#include <vector>

namespace cv {
namespace rawgment {
namespace calibration_test {

struct ProtocolOptions
{
    std::vector<double> gainsDb{6, 12, 24};
    std::vector<double> levels{0.2, 0.65}; // brightest patch at this fraction of the range
    int frames = 100;
    int square = 24;
    bool darkFrames = false; // a burst with the lens cap on per gain, counted at mean 0
    SensorParams sensor = test::referenceSensorParams();
    uint64 seed = 42;
};

/** The paper's protocol (Sec. 4.3) on the simulator: per gain and illumination, a burst of a chart,
 * temporal statistics, then the pixels of a 24x24 square in each of the 24 patches. */
inline std::vector<NoiseSample> protocolSamples(const ProtocolOptions& o)
{
    ColorCheckerOptions chart;
    chart.pattern = o.sensor.pattern;
    chart.patchSize = 32;
    chart.border = 8;
    chart.illumination = 1000;
    const ColorCheckerScene scene = makeColorCheckerScene(chart);
    const SensorSimulator sensor(o.sensor, scene.meanAtUnitGain.size());
    const std::vector<Rect> squares = cfaAlignedSquares(scene.patches, o.square);
    std::vector<NoiseSample> all;
    uint64 seed = o.seed;
    for (double db : o.gainsDb) {
        const double g = dbToLinearGain(db);
        const RawFormat fmt = sensor.rawFormat(g);
        const double range = fmt.whiteLevel - fmt.blackLevel[0];
        for (double level : o.levels) {
            const double exposure = level * range / (g * chart.illumination);
            BurstStatistics stats(fmt);
            for (int t = 0; t < o.frames; ++t) {
                Mat raw;
                sensor.capture(scene.meanAtUnitGain, g, exposure, seed, t, raw);
                stats.add(raw);
            }
            ++seed;
            const std::vector<NoiseSample> s = sampleBurstPatches(stats, squares, g);
            all.insert(all.end(), s.begin(), s.end());
        }
        if (o.darkFrames) {
            BurstStatistics dark(fmt);
            for (int t = 0; t < o.frames; ++t) {
                Mat raw;
                sensor.capture(Mat::zeros(scene.meanAtUnitGain.size(), CV_32FC1), g, 1.0, seed, t, raw);
                dark.add(raw);
            }
            ++seed;
            const std::vector<NoiseSample> d = sampleDarkBurst(dark, squares, g);
            all.insert(all.end(), d.begin(), d.end());
        }
    }
    return all;
}

inline const std::vector<NoiseSample>& cleanProtocol()
{
    static const std::vector<NoiseSample> samples = protocolSamples(ProtocolOptions());
    return samples;
}

struct Errors
{
    double alpha, sigmaD2, sigmaR2;
};

inline Errors relativeErrors(const NoiseModel& fit, const NoiseModel& truth)
{
    return {fit.alpha / truth.alpha - 1, fit.sigmaD2 / truth.sigmaD2 - 1, fit.sigmaR2 / truth.sigmaR2 - 1};
}

inline std::ostream& operator<<(std::ostream& os, const Errors& e)
{
    return os << "alpha " << 100 * e.alpha << "%, sigma_d^2 " << 100 * e.sigmaD2 << "%, sigma_r^2 "
              << 100 * e.sigmaR2 << "%";
}

/** Calibration parameters without the bootstrap, for tests that read the fitted model alone: the bootstrap
 * only confirms the standard errors (CalibrationUncertainty) and changes no fitted value, and its 200
 * replicates of every sample are most of a large calibration's time. */
inline CalibrationParams modelOnly()
{
    CalibrationParams params;
    params.bootstrapReplicates = 0;
    return params;
}

inline NoiseModel truthModel()
{
    return SensorSimulator(test::referenceSensorParams(), Size(2, 2)).effectiveModel();
}

} // namespace calibration_test
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_TEST_CALIBRATION_COMMON_HPP
