// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Sample: noise-accounted darkening inside an ordinary OpenCV pipeline. A bright RAW mosaic (a 16-bit
// PNG with a sidecar, or a simulated chart when no file is given) becomes a 10x darker capture at 4x
// the gain, with the noise the sensor would have had; both are demosaiced with cv::cvtColor and
// written as 8-bit previews.
//
//     sample_color_jitter_pipeline [mosaic.png model.yml] out_folder
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment.hpp>

#include <cstdio>
#include <string>

namespace {

// The usual OpenCV way to look at a mosaic: black-subtracted, demosaiced, scaled to 8 bits.
cv::Mat preview(const cv::Mat& mosaic, const cv::rawgment::RawFormat& format, double exposure)
{
    cv::Mat signal, bayer16, bgr;
    cv::rawgment::subtractBlackLevel(mosaic, format, signal, true); // [0, 1]
    signal.convertTo(bayer16, CV_16U, 65535.0 * exposure);
    cv::cvtColor(bayer16, bgr, cv::COLOR_BayerBG2BGR); // OpenCV's name for an RGGB mosaic
    bgr.convertTo(bgr, CV_8U, 1.0 / 256);
    return bgr;
}

} // namespace

int main(int argc, char** argv)
{
    using namespace cv::rawgment;
    if (argc != 2 && argc != 4) {
        std::fprintf(stderr, "usage: %s [mosaic.png model.yml] out_folder\n", argv[0]);
        return 2;
    }
    try {
        cv::Mat mosaic;
        RawFormat format;
        NoiseModel model;
        if (argc == 4) {
            format = readMosaic(argv[1], mosaic).format;
            model = NoiseModel::load(argv[2]);
        } else {
            ColorCheckerOptions chart;
            chart.patchSize = 48;
            const ColorCheckerScene scene = makeColorCheckerScene(chart);
            const SensorSimulator sensor(SensorParams(), scene.meanAtUnitGain.size());
            const cv::Mat mean = scene.meanAtUnitGain;
            format = sensor.rawFormat(1.0);
            sensor.capture(mean, 1.0, 1.0, 7, 0, mosaic);
            model = sensor.effectiveModel();
        }
        const std::string out = argv[argc - 1];

        // A tenth of the light at four times the gain: the paper's Eq. 11 with the prior noise accounted.
        cv::Mat dark;
        RawFormat darkFormat;
        AugmentReport report;
        colorJitter(mosaic, format, model, ColorJitter::exposureChange(0.1, 4.0), NoiseOptions(), 1, dark,
                    darkFormat, &report);

        const bool written = cv::imwrite(out + "/bright.png", preview(mosaic, format, 1.0)) &&
                             cv::imwrite(out + "/dark.png", preview(dark, darkFormat, 1.0 / (0.1 * 4.0)));
        if (!written) {
            std::fprintf(stderr, "cannot write the previews into '%s'\n", out.c_str());
            return 1;
        }
        std::printf("gain %.2f -> %.2f, %lld saturated input pixels, %lld brightening pixels\n", format.gain,
                    darkFormat.gain, static_cast<long long>(report.saturatedPixels),
                    static_cast<long long>(report.brighteningPixels));
        std::printf("wrote %s/bright.png and %s/dark.png (the dark one brightened back by 2.5x)\n",
                    out.c_str(), out.c_str());
    } catch (const cv::Exception& e) {
        std::fprintf(stderr, "%s\n", e.err.c_str());
        return 1;
    }
    return 0;
}
