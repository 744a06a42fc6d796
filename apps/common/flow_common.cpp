// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "pipeline.hpp"

#include "app_tools.hpp"
#include "chart_patches.hpp"
#include "flow_common.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <functional>
#include <stdexcept>

namespace rawgment_apps {

using namespace cv::rawgment;

std::vector<std::string> readFileList(const cv::FileNode& node, const std::string& base,
                                      const std::string& where)
{
    if (!node.isSeq() || node.size() == 0)
        throw std::runtime_error(where + ": 'files' must be a non-empty list");
    std::vector<std::string> files;
    for (const cv::FileNode& f : node) {
        files.push_back(resolvePath(base, std::string(f)));
        // A frame listed twice (under one name or two: ./a.dng and a.dng) would count as two identical
        // captures: zero variance, a wrong model.
        const std::string canonical = canonicalPath(files.back());
        for (auto it = files.begin(); it + 1 != files.end(); ++it)
            if (canonicalPath(*it) == canonical)
                throw std::runtime_error(where + ": '" + files.back() + "' is listed twice" +
                                         (*it == files.back() ? std::string() : " (also as '" + *it + "')"));
    }
    return files;
}

void requireKnownKeys(const cv::FileNode& map, const std::vector<std::string>& valid,
                      const std::string& where)
{
    try {
        rejectUnknownKeys(map, valid);
    } catch (const cv::Exception& e) {
        throw std::runtime_error(where + ": " + e.err);
    }
}

void refuseExisting(const std::vector<std::string>& outputs)
{
    for (const std::string& p : outputs)
        if (pathExists(p))
            throw std::runtime_error(
                "'" + p + "' already exists; outputs are never overwritten (choose another --out)");
}

std::vector<cv::Rect> manifestSquares(const std::string& patches, const std::string& firstFrame, int side,
                                      std::vector<std::string>& notes)
{
    if (patches != "detect")
        return rawgment_helpers::readChartPatches(patches).squares;
    const LoadedMosaic m = loadMosaicFile(firstFrame);
    RawImage image;
    image.mosaic = m.mosaic;
    image.format = m.format;
    // Detection needs a visible chart: expose the preview so that the brightest 1% reaches 90%.
    cv::Mat signal;
    subtractBlackLevel(m.mosaic, m.format, signal, true);
    cv::Mat sorted = signal.reshape(1, 1).clone();
    cv::sort(sorted, sorted, cv::SORT_ASCENDING);
    const float p99 = sorted.at<float>(static_cast<int>(sorted.total() * 0.99));
    const double exposure = p99 > 0 ? std::min(64.0, std::max(1.0, 0.9 / p99)) : 1.0;
    rawgment_helpers::ChartPatches found;
    std::string why;
    if (!rawgment_helpers::findChartPatches(rawgment_helpers::renderDetectionPreview(image, exposure), side,
                                            found, why))
        throw std::runtime_error("'" + firstFrame + "': " + why);
    notes.push_back(
        cv::format("patches detected with cv::mcc on %s (exposure x%.2f)", firstFrame.c_str(), exposure));
    return found.squares;
}

void addDarkShadingPattern(cv::Size size, double amplitude, uint64_t seed, cv::rawgment::NoiseModel& model)
{
    cv::Mat perGain(size, CV_32FC1), offset(size, CV_32FC1);
    cv::RNG rng(seed ^ 0x5ad1ull);
    rng.fill(perGain, cv::RNG::NORMAL, 0, amplitude / 4);
    rng.fill(offset, cv::RNG::NORMAL, 0, amplitude);
    for (int c = 0; c < size.width; ++c)
        perGain.col(c) += amplitude / 2 * c / size.width;
    for (int r = 0; r < size.height; ++r)
        offset.row(r) += 2 * amplitude * r / size.height;
    model.darkShadingPerGain = perGain;
    model.darkShadingOffset = offset;
}

} // namespace rawgment_apps
