// Do the calibration's 95% intervals hold the truth 95% of the time? Over many simulated campaigns of
// the trade-off sensor (alpha 0.4, sigma_d^2 0.5, sigma_r^2 2 plus quantisation, 12 bits; 3 gains, 6 to
// 24 dB), for both fit methods, it counts how often each parameter's interval holds the simulator's
// effective model, and prints the mean and RMS of the errors in standard errors (0 and 1 when the errors
// are what they claim). Scenarios:
//  - chart: ColorChecker levels at 20%, 65% and 105% of white (the brightest patches clip) and a burst of
//    dark frames per gain, as docs/calibrate_your_camera.md asks a user to shoot; clean, and with 5%
//    outlier pixels (2% hot, 1% dead, 2% noisy);
//  - no chart: a natural static scene (gradients, blobs, hard edges, a textured region) at 80% of white,
//    sampled by sampleStaticScene (rawgment_calibrate's mode for a folder of burst folders), no dark frames;
//  - heavy tails: the chart with Tukey-lambda read noise (lambda -0.05, excess kurtosis 2.1, as measured on
//    real sensors), with dark frames and without, the kurtosis estimated from the samples.
// Prints Markdown.
//
//   build/release/bin/study_calibration_coverage [campaigns=80] [frames=16]
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <array>
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
    double kurtosis = 0;            // sum of the kurtosis the fits used
    int bootstrapSource = 0;
};

struct Scenario
{
    const char* name;
    bool chart = true, dark = true, outliers = false, tails = false;
};

/* A static scene without a chart, at unit gain and exposure, its brightest pixel 1: a gradient, 12 soft
 * blobs, 6 rectangles of another brightness (hard edges), and an 8-pixel random texture in one region. */
Mat naturalScene(Size size, uint64 seed)
{
    RNG rng(seed);
    Mat s(size, CV_32FC1);
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c)
            s.at<float>(r, c) = float(0.15 + 0.5 * c / size.width + 0.2 * r / size.height);
    for (int i = 0; i < 12; ++i) {
        const double cy = rng.uniform(0.0, double(size.height)), cx = rng.uniform(0.0, double(size.width)),
                     rad = rng.uniform(8.0, 40.0), amp = rng.uniform(-0.2, 0.4);
        for (int r = 0; r < size.height; ++r)
            for (int c = 0; c < size.width; ++c)
                s.at<float>(r, c) +=
                    float(amp * std::exp(-((r - cy) * (r - cy) + (c - cx) * (c - cx)) / (2 * rad * rad)));
    }
    for (int i = 0; i < 6; ++i) {
        const Rect box(rng.uniform(0, size.width - 20), rng.uniform(0, size.height - 20), rng.uniform(10, 80),
                       rng.uniform(10, 80));
        Mat roi = s(box & Rect(Point(), size));
        roi *= rng.uniform(0.3, 1.5);
    }
    Mat texture(size.height / 8, size.width / 8, CV_32FC1), big;
    rng.fill(texture, RNG::UNIFORM, 0.0, 1.0);
    resize(texture, big, Size(texture.cols * 8, texture.rows * 8), 0, 0, INTER_NEAREST);
    const Rect region(0, 0, size.width / 3, size.height / 2);
    Mat roi = s(region);
    roi = roi.mul(1 + 0.3 * big(region));
    max(s, 0.02, s);
    double hi = 0;
    minMaxLoc(s, nullptr, &hi);
    return s / hi;
}

} // namespace

int main(int argc, char** argv)
{
    const int campaigns = argc > 1 ? std::atoi(argv[1]) : 80;
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
    const Size naturalSize(384, 256);
    const char* methodNames[2] = {"joint", "two-stage"};
    const std::vector<Scenario> scenarios = {{"chart", true, true, false, false},
                                             {"chart, 5% outliers", true, true, true, false},
                                             {"no chart (natural scene)", false, false, false, false},
                                             {"heavy tails, dark frames", true, true, false, true},
                                             {"heavy tails, no dark frames", true, false, false, true}};
    // The sensor's noise, and the same with the heavy tails (Tukey lambda -0.05) of the tails scenarios.
    const NoiseModel gaussian(0.4, 0.5, 2.0);
    NoiseModel heavyTailed = gaussian;
    heavyTailed.tukeyRead = true;
    heavyTailed.tukeyLambda = -0.05;
    std::vector<std::array<Tally, 2>> tally(scenarios.size());
    for (size_t sc = 0; sc < scenarios.size(); ++sc) {
        const Scenario& o = scenarios[sc];
        SensorParams p;
        p.noise = o.tails ? heavyTailed : gaussian;
        p.blackLevel = Vec4d::all(256);
        p.bitDepth = 12;
        if (o.outliers) {
            p.hotPixelFraction = 0.02;
            p.deadPixelFraction = 0.01;
            p.noisyPixelFraction = 0.02;
        }
        const Size size = o.chart ? scene.meanAtUnitGain.size() : naturalSize;
        const SensorSimulator sensor(p, size);
        const NoiseModel truth = sensor.effectiveModel();
        const double white = (1 << p.bitDepth) - 1 - p.blackLevel[0];
        for (int c = 0; c < campaigns; ++c) {
            std::fprintf(stderr, "\r%s: campaign %d/%d   ", o.name, c + 1, campaigns);
            std::vector<NoiseSample> samples;
            uint64 seed = 100000 * (c + 1) + 1000 * sc;
            const Mat mean = o.chart ? scene.meanAtUnitGain : naturalScene(size, seed);
            const std::vector<double> levels =
                o.chart ? std::vector<double>{0.2, 0.65, 1.05} : std::vector<double>{0.8};
            for (double db : {6.0, 12.0, 24.0}) {
                const double g = dbToLinearGain(db);
                for (double level : levels) {
                    BurstStatistics stats(sensor.rawFormat(g));
                    const double exposure = level * white / (g * (o.chart ? 1000 : 1));
                    for (int t = 0; t < frames; ++t) {
                        Mat raw;
                        sensor.capture(mean, g, exposure, seed, t, raw);
                        stats.add(raw);
                    }
                    ++seed;
                    const std::vector<NoiseSample> s =
                        o.chart ? sampleBurstPatches(stats, squares, g) : sampleStaticScene(stats, g);
                    samples.insert(samples.end(), s.begin(), s.end());
                }
                if (!o.dark)
                    continue;
                // Dark frames (a lens cap), sampled as rawgment_calibrate samples them.
                BurstStatistics dark(sensor.rawFormat(g));
                for (int t = 0; t < frames; ++t) {
                    Mat raw;
                    sensor.capture(Mat::zeros(size, CV_32FC1), g, 1.0, seed, t, raw);
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
                Tally& t = tally[sc][size_t(m)];
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
                t.kurtosis += r.readExcessKurtosis;
                t.bootstrapSource += r.uncertainty.source == UNCERTAINTY_BOOTSTRAP ? 1 : 0;
                ++t.campaigns;
            }
        }
        std::fprintf(stderr, "\n");
    }
    std::printf(
        "%d campaigns of %d frames per burst. When the standard errors are right, the 95%% interval "
        "holds the truth in 95%% of campaigns (binomial spread at %d campaigns: +-%.1f%%), mean z is 0 "
        "(+-%.2f) and RMS z 1 (+-%.2f). The heavy tails' read noise has excess kurtosis %.2f.\n\n",
        campaigns, frames, campaigns, 100 * std::sqrt(0.95 * 0.05 / campaigns), 1 / std::sqrt(campaigns),
        std::sqrt(0.5 / campaigns), heavyTailed.readExcessKurtosis());
    std::printf("| scenario | method | parameter | coverage | mean z | RMS z | relative standard error | "
                "kurtosis used (mean) | bootstrap used |\n|---|---|---|---:|---:|---:|---:|---:|---:|\n");
    const char* names[3] = {"alpha", "sigma_d^2", "sigma_r^2"};
    for (size_t sc = 0; sc < scenarios.size(); ++sc)
        for (int m = 0; m < 2; ++m)
            for (int k = 0; k < 3; ++k) {
                const Tally& t = tally[sc][size_t(m)];
                std::printf("| %s | %s | %s | %.1f%% | %+.2f | %.2f | %.3f%% | %.2f | %d/%d |\n",
                            scenarios[sc].name, methodNames[m], names[k], 100.0 * t.covered[k] / t.campaigns,
                            t.z[k] / t.campaigns, std::sqrt(t.zz[k] / t.campaigns),
                            100.0 * t.relError[k] / t.campaigns, t.kurtosis / t.campaigns, t.bootstrapSource,
                            t.campaigns);
            }
    return 0;
}
