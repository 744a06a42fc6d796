// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// What both resampling steps (paper Eq. 15) share: a monochrome frame's pixel grid, Poisson draws, and the
// dark-frame components they restore (each step alone: test_motion_blur.cpp, test_scale_mosaic.cpp).
#include "test_augment_common.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <functional>

namespace cv {
namespace rawgment {
namespace {

using namespace augment_test;

// A monochrome frame has no CFA planes: its neighbours see the same light, so blur and scale resample the
// whole pixel grid. Their means are a plain full-resolution filter (checked against OpenCV's filter2D and a
// bilinear reference computed here), and ACCOUNT_PRIOR keeps Eq. 5's variance (against a capture blurred
// before the noise, and the model line).
TEST(Augment, monochromeBlurAndScaleResampleThePixelGridWithTheModelVariance)
{
    const Size size(128, 128);
    SensorParams params = test::referenceSensorParams();
    params.pattern = CFA_MONO;
    const SensorSimulator sensor(params, size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    ASSERT_TRUE(fmt.isMonochrome());
    Mat scene(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c)
        scene.col(c).setTo((c / 16) % 2 ? 1500.0 : 60.0);
    // 13 mosaic pixels on the pixel grid: 13 taps wide, not the 7 of a CFA plane's kernel.
    const Mat kernel = linearMotionKernel(13, 0, CFA_MONO);
    EXPECT_EQ(kernel.cols, 15);
    EXPECT_EQ(linearMotionKernel(13, 0).cols, 9);
    const std::vector<Mat> sharp = floatBurst(sensor, scene, 9);

    // NONE is the plain filter, on the full grid (float sums in another order: 1e-3 DN on 4000 DN).
    Mat plain, signal, reference;
    motionBlur(sharp[0], fmt, model, kernel, NoiseAlignment::NONE, 1, plain);
    subtractBlackLevel(sharp[0], fmt, signal);
    filter2D(signal, reference, CV_32F, kernel, Point(-1, -1), 0, BORDER_REPLICATE);
    reference += fmt.blackLevel[0];
    EXPECT_LT(norm(plain, reference, NORM_INF), 1e-3);

    std::vector<Mat> truth(kFrames);
    for (int t = 0; t < kFrames; ++t) {
        sensor.captureBlurred(scene, kernel, kGain, 1.0, 77, t, truth[t]);
        truth[t].convertTo(truth[t], CV_32F);
    }
    Mat truthMean, truthVar, mean, var;
    temporalStats(truth, fmt, truthMean, truthVar);
    statsAfterStep(
        sharp, fmt,
        [&](const Mat& frame, int t, Mat& out) {
            motionBlur(frame, fmt, model, kernel, NoiseAlignment::ACCOUNT_PRIOR, 500 + t, out);
        },
        mean, var);
    // As motionBlurMatchesACaptureBlurredBeforeTheNoise: 16,384 pixels, a standard error of 0.55%; 3% is
    // more than 5 of them.
    const double blurRatio = cv::mean(var)[0] / cv::mean(truthVar)[0];
    std::cout << "monochrome blur variance / true blurred capture (ACCOUNT_PRIOR): " << blurRatio << "\n";
    EXPECT_NEAR(blurRatio, 1.0, 0.03);

    // Scaling: output pixel x reads C + (x - C) / scale of the same grid, C = (W - 1) / 2.
    const double scale = 1.07;
    Mat scaled;
    scaleMosaic(sharp[0], fmt, model, scale, NoiseAlignment::NONE, 1, scaled);
    const auto source = [&](int x, int n, int& i0, int& i1, double& f) {
        const double centre = (n - 1) / 2.0, at = centre + (x - centre) / scale, lo = std::floor(at);
        i0 = static_cast<int>(std::min(std::max(lo, 0.0), n - 1.0));
        i1 = static_cast<int>(std::min(std::max(lo + 1, 0.0), n - 1.0));
        f = i0 == i1 ? 0 : at - lo;
    };
    double worst = 0;
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c) {
            int r0, r1, c0, c1;
            double fy, fx;
            source(r, size.height, r0, r1, fy);
            source(c, size.width, c0, c1, fx);
            const auto at = [&](int rr, int cc) { return static_cast<double>(signal.at<float>(rr, cc)); };
            const double want = (1 - fy) * ((1 - fx) * at(r0, c0) + fx * at(r0, c1)) +
                                fy * ((1 - fx) * at(r1, c0) + fx * at(r1, c1)) + fmt.blackLevel[0];
            worst = std::max(worst, std::abs(scaled.at<float>(r, c) - want));
        }
    EXPECT_LT(worst, 1e-3);
    const NoiseLine line = model.lineAtGain(kGain);
    statsAfterStep(
        sharp, fmt,
        [&](const Mat& frame, int t, Mat& out) {
            scaleMosaic(frame, fmt, model, scale, NoiseAlignment::ACCOUNT_PRIOR, 900 + t, out);
        },
        mean, var);
    const Mat expected = line.a * mean + line.b;
    // The model variance is linear in the mean, so a bilinear mix of noisy pixels, bars' edges included,
    // has it at the mixed mean. As in scaleKeepsTheModelVarianceAtEveryInterpolationPosition, 4% is 5
    // standard errors of the average over columns.
    double total = 0;
    for (int c = 0; c < size.width; ++c)
        total += cv::mean(var.col(c))[0] / cv::mean(expected.col(c))[0];
    std::cout << "monochrome scale variance / model (ACCOUNT_PRIOR): " << total / size.width << "\n";
    EXPECT_NEAR(total / size.width, 1.0, 0.04);
}

TEST(Augment, poissonSamplingKeepsTheVarianceOfBlurAndScale)
{
    // A noiseless flat frame of 20 DN above black: the added variance is all there is to measure.
    const Size size(256, 256);
    const NoiseModel model(0.4, 0.5, 2.0);
    RawFormat fmt;
    fmt.blackLevel = Vec4d::all(64);
    fmt.whiteLevel = 65535;
    fmt.gain = 4;
    const Mat src(size, CV_32FC1, Scalar(64 + 20));
    const Mat kernel = linearMotionKernel(9, 30);
    for (int step = 0; step < 2; ++step) {
        double var[2] = {0, 0};
        for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON}) {
            NoiseOptions noise;
            noise.shotSampling = sampling;
            Mat out;
            if (step == 0)
                motionBlur(src, fmt, model, kernel, noise, 5, out);
            else
                scaleMosaic(src, fmt, model, 1.01, noise, 5, out);
            double mean = 0;
            spatialStats(out, fmt, mean, var[static_cast<int>(sampling)]);
            EXPECT_NEAR(mean, 20, 0.1);
        }
        // Neighbouring outputs are independent draws; the variance differs between pixels (scale)
        // but the frame averages are comparable: 5 x sqrt(2) x sqrt(3 / N) (kurtosis of a few-electron
        // Poisson below 1) = 4.8%.
        EXPECT_NEAR(var[1] / var[0], 1.0,
                    5 * std::sqrt(2.0) * std::sqrt(3.0 / static_cast<double>(size.area())))
            << (step == 0 ? "blur" : "scale");
    }
}

// A dark flat scene at a high gain, where the components are a large part of the noise: the target of a blur
// or a scale of a flat scene is a plain capture (captureBlurred of a flat scene is one).
void expectBlurAndScaleRestoreTheDarkFrameComponents(CfaPattern pattern, Size size)
{
    const int T = 32;
    const double gain = 8;
    SensorParams params = darkComponentSensor(size);
    params.pattern = pattern;
    const SensorSimulator sensor(params, size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(gain);
    const double black = fmt.blackLevel[0];
    const Mat scene(size, CV_32FC1, Scalar(2)); // 16 DN at gain 8: 5 electrons
    std::vector<Mat> input, target;
    sensor.captureBurst(scene, gain, 1.0, T, 9, input);
    sensor.captureBurst(scene, gain, 1.0, T, 10, target);
    const DarkStats truth = darkStats(target, black);
    const Mat kernel = linearMotionKernel(9, 30, pattern);
    typedef std::function<void(const Mat&, const NoiseOptions&, uint64, Mat&)> Step;
    const std::pair<const char*, Step> steps[] = {
        {"motionBlur", [&](const Mat& in, const NoiseOptions& o, uint64 seed,
                           Mat& out) { motionBlur(in, fmt, model, kernel, o, seed, out); }},
        {"scale 1.3", [&](const Mat& in, const NoiseOptions& o, uint64 seed, Mat& out) {
             scaleMosaic(in, fmt, model, 1.3, o, seed, out);
         }}};
    // Tolerances as in darkeningAddsTheDarkFrameComponentsATargetCaptureHas.
    const double rowTol = 5 * std::sqrt(2.0) * std::sqrt(2.0 / truth.dof);
    const double pixTol = 5 * std::sqrt(2.0) *
                          std::sqrt((2 + std::max(truth.kurtosis, 0.0)) / (truth.dof * (size.width - 1.0)));
    const double patternTol = 5 * std::sqrt(2.0 / size.area());
    for (const auto& step : steps) {
        SCOPED_TRACE(cfaPatternName(pattern) + ", " + step.first);
        auto stats = [&](const NoiseOptions& o) {
            std::vector<Mat> out(T);
            for (int t = 0; t < T; ++t)
                step.second(input[t], o, 300 + t, out[t]);
            return darkStats(out, black);
        };
        NoiseOptions poisson;
        poisson.shotSampling = ShotNoiseSampling::POISSON;
        const DarkStats account = stats(poisson), none = stats(NoiseAlignment::NONE),
                        ignore = stats(NoiseAlignment::IGNORE_PRIOR);
        EXPECT_NEAR(account.rowMeanVar / truth.rowMeanVar, 1, rowTol) << "row-mean variance";
        EXPECT_NEAR(account.pixelVar / truth.pixelVar, 1, pixTol) << "per-pixel variance";
        EXPECT_NEAR(fixedPatternExcess(account, truth, T, size.width), 0, patternTol) << "fixed pattern";
        // The added read part's shape matches the kurtosis of the step's typical weights: exact inside a
        // blur, on average along a scaled row; the tolerance is statistical only, which the measured
        // error (printed) stays within.
        EXPECT_NEAR(account.kurtosis, truth.kurtosis, 5 * std::hypot(account.kurtosisSE, truth.kurtosisSE))
            << "excess kurtosis";
        EXPECT_LT(none.rowMeanVar / truth.rowMeanVar, 1 - rowTol) << "NONE averages the rows away";
        EXPECT_LT(none.pixelVar / truth.pixelVar, 1 - pixTol) << "NONE averages the noise away";
        EXPECT_GT(fixedPatternExcess(none, truth, T, size.width), patternTol) << "NONE blurs the pattern";
        EXPECT_GT(ignore.rowMeanVar / truth.rowMeanVar, 1 + rowTol) << "IGNORE_PRIOR adds rows on top";
        EXPECT_GT(ignore.pixelVar / truth.pixelVar, 1 + pixTol) << "IGNORE_PRIOR adds noise on top";
        EXPECT_GT(fixedPatternExcess(ignore, truth, T, size.width), patternTol) << "IGNORE_PRIOR doubles it";
        std::cout << cfaPatternName(pattern) << ", " << step.first << ": row-mean var (capture "
                  << truth.rowMeanVar << ") NONE " << none.rowMeanVar << ", IGNORE " << ignore.rowMeanVar
                  << ", ACCOUNT " << account.rowMeanVar << "; pixel var (" << truth.pixelVar << ") "
                  << none.pixelVar << ", " << ignore.pixelVar << ", " << account.pixelVar << "; kurtosis ("
                  << truth.kurtosis << " +- " << truth.kurtosisSE << ") ACCOUNT " << account.kurtosis
                  << "; pattern excess " << fixedPatternExcess(none, truth, T, size.width) << ", "
                  << fixedPatternExcess(ignore, truth, T, size.width) << ", "
                  << fixedPatternExcess(account, truth, T, size.width) << "\n";
    }
}

TEST(Augment, blurAndScaleRestoreTheDarkFrameComponentsTheyAverageAway)
{
    expectBlurAndScaleRestoreTheDarkFrameComponents(CFA_RGGB, Size(256, 256));
    // A monochrome frame's rows and shading, read on its full pixel grid.
    expectBlurAndScaleRestoreTheDarkFrameComponents(CFA_MONO, Size(256, 256));
}

} // namespace
} // namespace rawgment
} // namespace cv
