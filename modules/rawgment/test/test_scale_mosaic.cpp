// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The scale step (scale_mosaic.cpp, paper Eq. 15 with bilinear weights): the model's variance at every
// interpolation position, and boxes, phase and identity in a scene.
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

TEST(Augment, scaleKeepsTheModelVarianceAtEveryInterpolationPosition)
{
    const Size size(128, 128);
    const SensorSimulator sensor(test::referenceSensorParams(), size);
    const NoiseModel model = sensor.effectiveModel();
    const RawFormat fmt = sensor.rawFormat(kGain);
    const NoiseLine line = model.lineAtGain(kGain);
    // A horizontal ramp: the model variance is linear in the mean, so a bilinear mix of truly noisy
    // pixels must have exactly the model variance at the mixed mean (Eq. 15 with interpolation weights).
    Mat scene(size, CV_32FC1);
    for (int c = 0; c < size.width; ++c)
        scene.col(c).setTo(50.0 + 12.0 * c);
    const std::vector<Mat> burst = floatBurst(sensor, scene, 21);
    for (double scale : {1.03, 0.97}) {
        double worstNone = 1;
        for (NoiseAlignment mode : kAllAlignments) {
            Mat mean, var;
            statsAfterStep(
                burst, fmt,
                [&](const Mat& frame, int t, Mat& out) {
                    scaleMosaic(frame, fmt, model, scale, mode, 900 + t, out);
                },
                mean, var);
            const Mat expected = line.a * mean + line.b;
            double total = 0;
            // Columns away from the left/right edges, where replication makes constant patches.
            for (int c = 8; c < size.width - 8; ++c) {
                const double ratio = cv::mean(var.col(c))[0] / cv::mean(expected.col(c))[0];
                total += ratio;
                if (mode == NoiseAlignment::NONE)
                    worstNone = std::min(worstNone, ratio);
                // A column averages 128 variances of 64 frames (relative standard error sqrt(2/63) =
                // 17.8% each); neighbouring rows share source rows, so count 64 independent ones:
                // 2.2%, and 5 of them is 11%.
                if (mode == NoiseAlignment::ACCOUNT_PRIOR) {
                    EXPECT_NEAR(ratio, 1.0, 0.11) << "scale " << scale << ", column " << c;
                }
            }
            const double average = total / (size.width - 16);
            std::cout << "scale " << scale << ", mode " << static_cast<int>(mode)
                      << ": variance / model, average over columns " << average << "\n";
            if (mode == NoiseAlignment::ACCOUNT_PRIOR) { // ~14,000 pixels, half independent: 0.8% s.e.
                EXPECT_NEAR(average, 1.0, 0.04);
            }
            if (mode == NoiseAlignment::IGNORE_PRIOR) { // the prior noise is counted twice
                EXPECT_GT(average, 1.1);
            }
        }
        // Halfway between two pixels in both directions a bilinear mix keeps a quarter of the
        // variance; columns at x fraction 0.5 keep at most half: plain resampling is far too clean.
        EXPECT_LT(worstNone, 0.75) << "scale " << scale;
    }
}

TEST(Augment, scaleMovesBoxesKeepsThePhaseAndSkipsTheIdentity)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat src(64, 64, CV_16UC1);
    for (int r = 0; r < 64; ++r)
        for (int c = 0; c < 64; ++c)
            src.at<ushort>(r, c) = static_cast<ushort>(300 + 800 * cfaSite(r, c));
    Mat out;
    scaleMosaic(src, fmt, model, 1.0, NoiseAlignment::ACCOUNT_PRIOR, 1, out);
    EXPECT_EQ(out.data, src.data);
    // Each site resamples only its own plane: a constant plane stays constant (NONE adds no noise).
    scaleMosaic(src, fmt, model, 1.03, NoiseAlignment::NONE, 1, out);
    EXPECT_EQ(norm(out, src, NORM_INF), 0);
    // Boxes: the centre is fixed, edges scale about it, the result grows to whole pixels.
    EXPECT_EQ(scaleBox(Rect(16, 16, 32, 32), Size(64, 64), 1.5), Rect(8, 8, 48, 48));
    EXPECT_EQ(scaleBox(Rect(0, 0, 10, 10), Size(64, 64), 2.0).area(), 0); // pushed out of the frame
    EXPECT_EQ(scaleBox(Rect(30, 30, 4, 4), Size(64, 64), 0.5), Rect(31, 31, 2, 2));
    Scene scene;
    scene.scale = 2.0;
    std::vector<Rect> boxes = {Rect(16, 16, 32, 32)};
    RawFormat f;
    AugmentReport report;
    applyScene(src, fmt, model, scene, 3, out, f, &report, &boxes);
    EXPECT_EQ(boxes[0], Rect(0, 0, 64, 64));
    ASSERT_EQ(report.steps.size(), 1u);
    EXPECT_EQ(report.steps[0], "scale");
    EXPECT_CV_ERROR_CONTAINS(scaleMosaic(src, fmt, model, 0, NoiseAlignment::NONE, 1, out), "scale");
    EXPECT_CV_ERROR_CONTAINS(
        scaleMosaic(src, fmt, model, std::numeric_limits<double>::quiet_NaN(), NoiseAlignment::NONE, 1, out),
        "scale");
    EXPECT_CV_ERROR_CONTAINS(
        scaleMosaic(src(Rect(0, 0, 63, 64)), fmt, model, 1.1, NoiseAlignment::NONE, 1, out),
        "both sides must be even");
}

} // namespace
} // namespace rawgment
} // namespace cv
