// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Sample: the paper's random augmentation. A RandomScenePolicy draws a scene (shift, scale, contrast,
// hue, gain, motion blur) per seed and applyScene() renders it with the sensor's noise; a bounding box
// follows the geometry, as a detector's label must.
#include <opencv2/rawgment.hpp>

#include <cstdio>

int main()
{
    using namespace cv::rawgment;
    const SensorSimulator sensor(SensorParams(), cv::Size(256, 192));
    const ColorCheckerScene chart = makeColorCheckerScene(ColorCheckerOptions());
    cv::Mat mean = cv::Mat::zeros(sensor.size(), CV_32FC1), mosaic;
    chart
        .meanAtUnitGain(cv::Rect(cv::Point(), sensor.size()) &
                        cv::Rect(cv::Point(), chart.meanAtUnitGain.size()))
        .copyTo(
            mean(cv::Rect(cv::Point(), sensor.size()) & cv::Rect(cv::Point(), chart.meanAtUnitGain.size())));
    sensor.capture(mean, 1.0, 1.0, 3, 0, mosaic);
    const RawFormat format = sensor.rawFormat(1.0);
    const NoiseModel model = sensor.effectiveModel();

    RandomScenePolicy policy; // the paper's ranges
    policy.geometryProbability = 1;
    for (uint64 seed = 1; seed <= 3; ++seed) {
        const Scene scene = policy.draw(mosaic, format, seed);
        std::vector<cv::Rect> boxes = {chart.patches[18]}; // the white patch
        cv::Mat out;
        RawFormat outFormat;
        AugmentReport report;
        applyScene(mosaic, format, model, scene, seed, out, outFormat, &report, &boxes);
        std::printf("seed %llu: shift (%d, %d), scale %.3f, contrast %.3f, gain x%.2f, %zu steps; white "
                    "patch box (%d, %d, %d, %d)\n",
                    static_cast<unsigned long long>(seed), scene.shift.x, scene.shift.y, scene.scale,
                    scene.jitter.contrast[0], outFormat.gain / format.gain, report.steps.size(), boxes[0].x,
                    boxes[0].y, boxes[0].width, boxes[0].height);
    }
    return 0;
}
