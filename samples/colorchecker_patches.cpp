// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Colour-checker patch extraction: RAW file in, CFA-aligned patch squares (YAML) and an annotated
// preview (PNG) out. The squares feed calibration: a burst shares one set of squares.
//
//   sample_colorchecker_patches --side=24 ../shared/data/colorchart.dng patches.yml annotated.png
#include "chart_patches.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/core/utils/filesystem.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment.hpp>

#include <cstdio>
#include <iostream>

int main(int argc, char** argv)
{
    const char* keys =
        "{help h usage ? |    | print this message }"
        "{side           | 24 | side of each square in Bayer pixels (even) }"
        "{exposure       | 1  | digital gain of the detection preview (raise it for dark shots) }"
        "{@raw           |    | the RAW file (any format LibRaw reads) }"
        "{@patches       |    | output YAML with the squares }"
        "{@annotated     |    | optional output PNG: the preview with the squares drawn }";
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about("Finds a 24-patch colour checker in a RAW file with cv::mcc and writes one CFA-aligned\n"
                 "square per patch, in RAW pixel coordinates.");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    const std::string rawPath = parser.get<std::string>("@raw"),
                      outPath = parser.get<std::string>("@patches"),
                      annotatedPath = parser.get<std::string>("@annotated");
    const int side = parser.get<int>("side");
    const double exposure = parser.get<double>("exposure");
    if (!parser.check() || rawPath.empty() || outPath.empty()) {
        parser.printErrors();
        std::cerr << "usage: sample_colorchecker_patches [--side=24] <raw> <patches.yml> [annotated.png]\n";
        return 2;
    }
    try {
        // 1. Read the mosaic and render a preview in the mosaic's own coordinates.
        const cv::rawgment::RawImage image = cv::rawgment::readRaw(rawPath);
        const cv::Mat preview = rawgment_helpers::renderDetectionPreview(image, exposure);
        // 2. Detect the chart and place one square in the middle of each patch.
        rawgment_helpers::ChartPatches patches;
        std::string why;
        if (!rawgment_helpers::findChartPatches(preview, side, patches, why)) {
            std::cerr << rawPath << ": " << why << "\n";
            return 1;
        }
        // 3. Report each square's mean green level, black subtracted: the grey row (19..24) must fall.
        cv::Mat signal;
        cv::rawgment::subtractBlackLevel(image.mosaic, image.format, signal);
        for (size_t i = 0; i < patches.squares.size(); ++i)
            std::printf("patch %2zu  square %4d,%4d %dx%d  mean %.1f DN\n", i + 1, patches.squares[i].x,
                        patches.squares[i].y, side, side, cv::mean(signal(patches.squares[i]))[0]);
        if (cv::utils::fs::exists(outPath) ||
            (!annotatedPath.empty() && cv::utils::fs::exists(annotatedPath))) {
            std::cerr << "an output already exists; it is never overwritten\n";
            return 1;
        }
        rawgment_helpers::writeChartPatches(outPath, patches);
        if (!annotatedPath.empty()) {
            // Encoded by the path's extension, then written atomically without replacing a file.
            const size_t dot = annotatedPath.find_last_of('.');
            std::vector<uchar> image;
            if (dot == std::string::npos ||
                !cv::imencode(annotatedPath.substr(dot), rawgment_helpers::drawChartPatches(preview, patches),
                              image)) {
                std::cerr << annotatedPath << ": cannot encode an image with this extension\n";
                return 1;
            }
            cv::rawgment::writeFileAtomically(annotatedPath, image.data(), image.size());
        }
        std::printf("wrote %s%s%s\n", outPath.c_str(), annotatedPath.empty() ? "" : " and ",
                    annotatedPath.c_str());
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 1;
    }
}
