// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Colour-checker patch extraction from a RAW mosaic with cv::mcc: the one helper that the samples
// (samples/colorchecker_patches.cpp) and the apps (rawgment_calibrate, rawgment_simulate) share. It
// depends on the installed library and OpenCV only, never on the apps.
#ifndef RAWGMENT_HELPERS_CHART_PATCHES_HPP
#define RAWGMENT_HELPERS_CHART_PATCHES_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <string>
#include <vector>

namespace rawgment_helpers {

/** Where the 24 patches of a classic colour checker are in a mosaic. */
struct ChartPatches
{
    //! Corners of the 6x4 patch grid in mosaic pixels, in the chart's own order: the corner next to
    //! patch 1 (dark skin), then patch 6 (bluish green), patch 24 (black) and patch 19 (white).
    std::vector<cv::Point2f> gridCorners;
    //! One CFA-aligned square per patch (even corner and side), in the chart's order: patch 1 first,
    //! the grey row (white ... black) last.
    std::vector<cv::Rect> squares;
};

/** An 8-bit sRGB preview of the mosaic for the detector: camera white balance and colour matrix,
 * sRGB tone curve, at the mosaic's full resolution so that preview and mosaic share coordinates. */
cv::Mat renderDetectionPreview(const cv::rawgment::RawImage& image, double exposure = 1.0);

/** Finds the chart in `preview` (8-bit BGR, the mosaic's size) with cv::mcc (MCC24) and places a
 * CFA-aligned `side` x `side` square at the centre of each patch. The square must fit in the middle
 * half of its grid cell, well away from the patch's edge (a patch fills about 80% of its cell).
 * @return false with the reason in `why` when no chart is found or the patches are too small. */
bool findChartPatches(const cv::Mat& preview, int side, ChartPatches& patches, std::string& why);

/** Draws the grid outline and the numbered squares on a copy of the preview. */
cv::Mat drawChartPatches(const cv::Mat& preview, const ChartPatches& patches);

/** Writes the patches as YAML (map `chart_patches` with `grid_corners` and `squares`), atomically. */
void writeChartPatches(const std::string& path, const ChartPatches& patches);

/** Reads what writeChartPatches() wrote. @throws cv::Exception naming the file and the field. */
ChartPatches readChartPatches(const std::string& path);

} // namespace rawgment_helpers

#endif // RAWGMENT_HELPERS_CHART_PATCHES_HPP
