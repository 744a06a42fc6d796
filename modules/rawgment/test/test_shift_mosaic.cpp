// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The shift step (shift_mosaic.cpp): the CFA phase kept, boxes moved, the plane-wise composition matched, and
// the sensor's dark shading left where the sensor has it.
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

TEST(Augment, aShiftKeepsTheSensorsDarkShadingWhereTheSensorHasIt)
{
    // applyScene shifted the dark-shading pattern together with the content: on a noiseless flat input
    // carrying the pattern, a shift of (8, 6) changed the output by the pattern's own difference
    // S(x - d) - S(x), where 0 is right because the pattern belongs to the sensor.
    const Size size(96, 64);
    const NoiseModel model = darkComponentSensor(size).noise;
    ASSERT_TRUE(model.hasDarkShading());
    const RawFormat fmt = SensorSimulator(darkComponentSensor(size), size).rawFormat(kGain);
    const Mat pattern = model.darkShadingAt(kGain);
    const Mat flat = flatWithPattern(fmt, pattern, 500);
    const Rect inside(8, 6, size.width - 8, size.height - 6);
    const double patternMove =
        norm(pattern(inside - Point(8, 6)), pattern(inside), NORM_L2) / std::sqrt(double(inside.area()));
    ASSERT_GT(patternMove, 1.0) << "the test needs a pattern that a shift visibly moves";
    Scene shifted;
    shifted.shift = Point(8, 6);
    Mat out;
    RawFormat outFmt;
    applyScene(flat, fmt, model, shifted, 3, out, outFmt);
    // Float arithmetic of values below 2^12: a few ulps.
    EXPECT_LT(norm(out, flat, NORM_INF), 1e-3) << "the pattern moved by " << patternMove << " DN RMS";
    // An integer mosaic is rounded once more: within 1 DN, and a pixel differs (by 1) with probability
    // E|rounding error| = 1/4, so the RMS is 0.5 on average; 4 standard errors of that share over 6144
    // pixels (0.0055 each) allow 0.53.
    Mat flat16, out16, diff;
    flat.convertTo(flat16, CV_16U);
    applyScene(flat16, fmt, model, shifted, 3, out16, outFmt);
    absdiff(out16, flat16, diff);
    EXPECT_LE(norm(diff, NORM_INF), 1);
    EXPECT_LE(norm(diff, NORM_L2) / std::sqrt(double(diff.total())), 0.53);
    // Shifted and darkened x0.5: over 24 seeds the mean output is the darker content plus the sensor's
    // pattern in place; its residual is the mean's noise alone, below 1.5 sqrt(target variance / 24) RMS
    // (the target's variance bounds what ACCOUNT_PRIOR adds to a noiseless input; 1.5 leaves room for the
    // RMS over only 6144 pixels).
    shifted.jitter = ColorJitter::exposureChange(0.5, 1);
    const int seeds = 24;
    Mat sum = Mat::zeros(size, CV_64FC1);
    for (int seed = 0; seed < seeds; ++seed) {
        applyScene(flat, fmt, model, shifted, uint64(seed), out, outFmt);
        accumulate(out, sum);
    }
    Mat expected(size, CV_64FC1);
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c)
            expected.at<double>(r, c) = fmt.blackAt(r, c) + 250 + pattern.at<float>(r, c);
    const double residual = norm(sum / seeds, expected, NORM_L2) / std::sqrt(double(size.area()));
    const double noise = std::sqrt((model.variance(250, kGain) + model.rowVariance(kGain)) / seeds);
    EXPECT_LT(residual, 1.5 * noise) << "pattern move " << patternMove;
}

TEST(Augment, shiftKeepsTheCfaPhaseAndMovesBoxes)
{
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat src(16, 16, CV_16UC1);
    for (int r = 0; r < 16; ++r)
        for (int c = 0; c < 16; ++c)
            src.at<ushort>(r, c) = static_cast<ushort>(1000 * cfaSite(r, c) + 10 * r + c);
    Scene scene;
    scene.shift = Point(3, 2); // x rounds to an even 4
    std::vector<Rect> boxes = {Rect(2, 2, 4, 4), Rect(14, 0, 2, 2)};
    Mat out;
    RawFormat f;
    applyScene(src, fmt, model, scene, 0, out, f, nullptr, &boxes);
    for (int r = 2; r < 16; ++r)
        for (int c = 4; c < 16; ++c)
            ASSERT_EQ(out.at<ushort>(r, c), src.at<ushort>(r - 2, c - 4));
    for (int r = 0; r < 16; ++r)
        for (int c = 0; c < 16; ++c)
            ASSERT_EQ(out.at<ushort>(r, c) / 1000, cfaSite(r, c)); // every pixel keeps its site's colour
    EXPECT_EQ(boxes[0], Rect(6, 4, 4, 4));
    EXPECT_EQ(boxes[1].area(), 0); // moved out of the frame
}

TEST(Augment, shiftMatchesThePlaneWiseComposition)
{
    // The one-pass shift against what it replaced: each CFA plane moved by half the shift with
    // warpAffine (nearest, edge replicated), for shifts inside, at and beyond the middle, up to the
    // whole frame, on both depths and on a view that is not continuous.
    const RawFormat fmt = SensorSimulator(test::referenceSensorParams(), Size(2, 2)).rawFormat(kGain);
    const NoiseModel model(0.4, 0.5, 2.0);
    Mat big(22, 40, CV_16UC1);
    randu(big, 0, 4096);
    for (const Mat& src : {big(Rect(4, 2, 30, 18)), Mat(big(Rect(4, 2, 30, 18)).clone())})
        for (int depth : {CV_16U, CV_32F})
            for (const Point shift : {Point(2, 0), Point(0, -4), Point(6, 8), Point(-12, 10), Point(-30, -18),
                                      Point(30, 18), Point(28, -16)}) {
                Mat typed;
                src.convertTo(typed, depth);
                std::vector<Mat> planes;
                splitCfaPlanes(typed, planes);
                for (Mat& plane : planes) {
                    Mat moved;
                    warpAffine(plane, moved, Matx23d(1, 0, shift.x / 2, 0, 1, shift.y / 2), plane.size(),
                               INTER_NEAREST, BORDER_REPLICATE);
                    plane = moved;
                }
                Mat expected, out;
                mergeCfaPlanes(planes, expected);
                Scene scene;
                scene.shift = shift;
                RawFormat f;
                applyScene(typed, fmt, model, scene, 0, out, f);
                ASSERT_EQ(out.type(), typed.type());
                EXPECT_EQ(0, norm(out, expected, NORM_INF)) << "shift " << shift << ", depth " << depth;
            }
}

} // namespace
} // namespace rawgment
} // namespace cv
