// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The per-gain line fit (calibration_lines.hpp): R^2 as the burst length allows, robustness to outliers,
// and two-frame bursts unbiased by their ties.
#include "test_calibration_common.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <numeric>

namespace cv {
namespace rawgment {
namespace {

using namespace calibration_test;

const std::vector<NoiseSample>& outlierProtocol()
{
    static const std::vector<NoiseSample> samples = [] {
        ProtocolOptions o;
        o.sensor.hotPixelFraction = 0.02;
        o.sensor.deadPixelFraction = 0.01;
        o.sensor.noisyPixelFraction = 0.02; // 5% outliers in all
        o.sensor.noisyPixelVariance = 400;
        o.seed = 4242;
        return protocolSamples(o);
    }();
    return samples;
}

TEST(Calibration, perGainRSquaredIsWhatTheBurstLengthAllows)
{
#ifdef RAWGMENT_SANITIZED_BUILD
    // 600 simulated frames for one statistic; the line fit runs under the sanitizers in every calibration
    // test.
    GTEST_SKIP() << "R^2 against the burst length is measured in the Release build only";
#endif
    const std::vector<NoiseSample>& samples = cleanProtocol();
    const CalibrationReport report = calibrateNoiseModel(samples, modelOnly());
    ASSERT_EQ(report.perGain.size(), 3u);
    const NoiseModel truth = truthModel();
    for (const NoiseLineFit& f : report.perGain) {
        // A sample variance of T frames scatters around its expectation v with a relative standard
        // deviation sqrt(2 / (T - 1)). So E[SS_res] = sum 2 v^2 / (T - 1) and E[SS_tot] adds that to the
        // spread of the expectations: R^2 = 1 - E[SS_res] / E[SS_tot].
        double ssNoise = 0, sum = 0, sum2 = 0;
        int n = 0;
        for (const NoiseSample& s : samples) {
            if (s.gain != f.gain)
                continue;
            const double v = truth.variance(s.mean, s.gain);
            ssNoise += 2.0 * v * v / s.dof;
            sum += v;
            sum2 += v * v;
            ++n;
        }
        const double ssSpread = sum2 - sum * sum / n;
        const double expected = 1.0 - ssNoise / (ssSpread + ssNoise);
        std::cout << "gain " << linearGainToDb(f.gain) << " dB: R^2 " << f.rSquared
                  << ", expected from T = 100: " << expected << ", inliers " << f.inliers << "/" << f.samples
                  << "\n";
        // SS_res is a sum of ~27,000 terms dominated by the brightest few thousand; its relative
        // standard error is about 3%, so 1 - R^2 must match within 15% (5 standard errors).
        EXPECT_NEAR(1.0 - f.rSquared, 1.0 - expected, 0.15 * (1.0 - expected));
        EXPECT_GT(f.inliers, 0.995 * f.samples); // clean data: RANSAC keeps nearly everything
    }
}

TEST(Calibration, robustFitsSurviveFivePercentOutliersAndPlainLeastSquaresDoesNot)
{
#ifdef RAWGMENT_SANITIZED_BUILD
    // 600 simulated frames for two accuracy figures; both fits run under the sanitizers in
    // reportRoundTripsThroughYamlAndJson, on data with hot pixels to set aside.
    GTEST_SKIP() << "robustness to outliers is measured in the Release build only";
#endif
    const std::vector<NoiseSample>& samples = outlierProtocol();
    const CalibrationReport robust = calibrateNoiseModel(samples, modelOnly());
    const Errors e = relativeErrors(robust.model, truthModel());
    std::cout << "robust joint fit with 5% outliers: " << e << "\n";
    EXPECT_LT(std::abs(e.alpha), 0.005);
    EXPECT_LT(std::abs(e.sigmaD2), 0.03);
    EXPECT_LT(std::abs(e.sigmaR2), 0.05);
    EXPECT_LT(robust.samplesUsed, 0.97 * robust.samples); // the outliers were set aside

    CalibrationParams plain = modelOnly();
    plain.line.robust = false;
    const CalibrationReport naive = calibrateNoiseModel(samples, plain);
    const Errors n = relativeErrors(naive.model, truthModel());
    std::cout << "plain least squares with 5% outliers: " << n << "\n";
    EXPECT_TRUE(std::abs(n.alpha) > 0.005 || std::abs(n.sigmaD2) > 0.03 || std::abs(n.sigmaR2) > 0.05);
}

/* A reset burst statistics object gives the bits of a new one: bursts of one size and type in the same
 * memory (the group of 3 leaves a partial group pending at each reset), then one of another size and type. */
TEST(Calibration, twoFrameBurstsAreNotBiasedByTheirTies)
{
    // Flat steps of two frames each (an EMVA 1288 series): a pixel's variance is d^2 / 2 of an integer
    // difference d, and 0 for the ~9% of pixels whose readings tie at 3 DN of noise. The inlier band used to
    // drop every tie, which put the read variance 10% and the slope 2% high (set 001 and this sensor alike).
    SensorParams p;
    p.noise = NoiseModel(0.1, 0.0, 9.0);
    p.blackLevel = Vec4d::all(64);
    const Size size(256, 192);
    const SensorSimulator sensor(p, size);
    const double truthRead = 9.0 + 1.0 / 12;
    std::vector<double> slopes, offsets;
    for (int seed = 1; seed <= 6; ++seed) {
        std::vector<NoiseSample> samples;
        for (int k = 0; k < 4; ++k) {
            std::vector<Mat> frames;
            // Signals 0 (dark) and 100, 400, 900 DN: the tied pixels are most of the bias at the bottom.
            sensor.captureBurst(Mat(size, CV_32FC1, Scalar(100.0 * k * k)), 1.0, 1.0, 2,
                                uint64(100 * seed + k), frames);
            BurstStatistics stats(sensor.rawFormat(1.0));
            for (const Mat& f : frames)
                stats.add(f);
            const std::vector<NoiseSample> s = sampleStaticScene(stats, 1.0);
            samples.insert(samples.end(), s.begin(), s.end());
        }
        const NoiseLineFit fit = fitNoiseLine(samples);
        slopes.push_back(fit.line.a);
        offsets.push_back(fit.line.b);
    }
    // Six seeds of 4 x 49,152 pixels: the offset's mean is known to about 0.3%, the slope's to 0.2%; the
    // bounds are five times that, and a fifth of the bias the ties made.
    const double slope = std::accumulate(slopes.begin(), slopes.end(), 0.0) / 6;
    const double offset = std::accumulate(offsets.begin(), offsets.end(), 0.0) / 6;
    EXPECT_NEAR(offset / truthRead, 1.0, 0.015);
    EXPECT_NEAR(slope / 0.1, 1.0, 0.01);
}

} // namespace
} // namespace rawgment
} // namespace cv
