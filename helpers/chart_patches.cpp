// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "chart_patches.hpp"

#include <opencv2/core/utils/filesystem.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/mcc.hpp>
#include <opencv2/rawgment/isp.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <algorithm>
#include <cmath>

namespace rawgment_helpers {

namespace {

// cv::mcc's model of the classic chart (its box, in chart units): patches 2.5 wide at a pitch of 2.75,
// the first starting 0.25 from the box's edge, so a 6x4 grid spans 16.75 x 11.25 units.
constexpr double kBoxWidth = 16.75, kBoxHeight = 11.25, kPitch = 2.75, kFirstCentre = 1.5, kPatch = 2.5;

cv::Point2f mapPoint(const cv::Matx33d& h, double x, double y)
{
    const cv::Vec3d p = h * cv::Vec3d(x, y, 1.0);
    return cv::Point2f(static_cast<float>(p[0] / p[2]), static_cast<float>(p[1] / p[2]));
}

int roundDownToEven(double v)
{
    const int i = static_cast<int>(std::floor(v));
    return i - (((i % 2) + 2) % 2);
}

} // namespace

cv::Mat renderDetectionPreview(const cv::rawgment::RawImage& image, double exposure)
{
    cv::rawgment::IspParams isp;
    isp.tone = cv::rawgment::ToneCurve::srgb();
    isp.whiteBalance = image.whiteBalance;
    isp.colorMatrix = image.cameraToSrgb;
    isp.exposure = exposure;
    cv::Mat preview;
    cv::rawgment::renderSimpleIsp(image.mosaic, image.format, preview, isp);
    return preview;
}

bool findChartPatches(const cv::Mat& preview, int side, ChartPatches& patches, std::string& why)
{
    CV_CheckTypeEQ(preview.type(), CV_8UC3, "findChartPatches: the preview must be 8-bit BGR");
    if (side < 2 || side % 2)
        CV_Error(cv::Error::StsBadArg, cv::format("findChartPatches: side %d must be even and >= 2", side));
    cv::Ptr<cv::mcc::CCheckerDetector> detector = cv::mcc::CCheckerDetector::create();
    if (!detector->process(preview, cv::mcc::MCC24, 1)) {
        why = "cv::mcc found no 24-patch colour checker in the preview";
        return false;
    }
    const std::vector<cv::Point2f> box = detector->getBestColorChecker()->getBox();
    if (box.size() != 4) {
        why = "cv::mcc returned a chart without four corners";
        return false;
    }
    const std::vector<cv::Point2f> model = {
        {0.f, 0.f}, {float(kBoxWidth), 0.f}, {float(kBoxWidth), float(kBoxHeight)}, {0.f, float(kBoxHeight)}};
    const cv::Matx33d toImage = cv::getPerspectiveTransform(model, box);
    const cv::Matx33d toModel = toImage.inv();
    ChartPatches out;
    // The grid's corners are the outer corners of the corner patches.
    const double lo = kFirstCentre - kPatch / 2, right = kFirstCentre + 5 * kPitch + kPatch / 2,
                 bottom = kFirstCentre + 3 * kPitch + kPatch / 2;
    out.gridCorners = {mapPoint(toImage, lo, lo), mapPoint(toImage, right, lo),
                       mapPoint(toImage, right, bottom), mapPoint(toImage, lo, bottom)};
    const cv::Rect frame(0, 0, preview.cols, preview.rows);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 6; ++c) {
            const double cx = kFirstCentre + kPitch * c, cy = kFirstCentre + kPitch * r;
            const cv::Point2f centre = mapPoint(toImage, cx, cy);
            const cv::Rect square(roundDownToEven(centre.x - side / 2.0 + 1),
                                  roundDownToEven(centre.y - side / 2.0 + 1), side, side);
            // "Well inside": every corner of the square within the middle half of the patch.
            for (const cv::Point2f corner : {cv::Point2f(square.tl()), cv::Point2f(square.br()),
                                             cv::Point2f(float(square.x), float(square.br().y)),
                                             cv::Point2f(float(square.br().x), float(square.y))}) {
                const cv::Point2f m = mapPoint(toModel, corner.x, corner.y);
                if (std::abs(m.x - cx) > kPatch / 4 || std::abs(m.y - cy) > kPatch / 4) {
                    why =
                        cv::format("patch %d is too small in the image for a %dx%d square in its middle half "
                                   "(use a smaller side)",
                                   r * 6 + c + 1, side, side);
                    return false;
                }
            }
            if ((square & frame) != square) {
                why = cv::format("patch %d lies partly outside the image", r * 6 + c + 1);
                return false;
            }
            out.squares.push_back(square);
        }
    patches = out;
    return true;
}

cv::Mat drawChartPatches(const cv::Mat& preview, const ChartPatches& patches)
{
    cv::Mat canvas = preview.clone();
    const int thickness = std::max(1, canvas.cols / 600);
    std::vector<cv::Point> grid;
    for (const cv::Point2f& p : patches.gridCorners)
        grid.emplace_back(cvRound(p.x), cvRound(p.y));
    if (grid.size() == 4)
        cv::polylines(canvas, grid, true, cv::Scalar(255, 200, 0), thickness, cv::LINE_AA);
    for (size_t i = 0; i < patches.squares.size(); ++i) {
        const cv::Rect& s = patches.squares[i];
        cv::rectangle(canvas, s, cv::Scalar(0, 255, 0), thickness);
        cv::putText(canvas, std::to_string(i + 1), s.tl() + cv::Point(0, -3), cv::FONT_HERSHEY_SIMPLEX,
                    0.4 * thickness, cv::Scalar(0, 255, 255), thickness, cv::LINE_AA);
    }
    return canvas;
}

void writeChartPatches(const std::string& path, const ChartPatches& patches)
{
    cv::FileStorage fs(".yml",
                       cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    fs << "chart_patches"
       << "{";
    fs << "grid_corners" << patches.gridCorners;
    fs << "squares"
       << "[";
    for (const cv::Rect& s : patches.squares)
        fs << s;
    fs << "]";
    fs << "}";
    const std::string text = fs.releaseAndGetString();
    cv::rawgment::writeFileAtomically(path, text.data(), text.size(), true);
}

ChartPatches readChartPatches(const std::string& path)
{
    cv::FileStorage fs = cv::rawgment::openFileStorageForReading(path, "chart patches");
    const cv::FileNode node = fs["chart_patches"];
    if (!node.isMap())
        CV_Error(cv::Error::StsParseError, "'" + path + "': no map 'chart_patches'");
    try {
        cv::rawgment::rejectUnknownKeys(node, {"grid_corners", "squares"});
    } catch (const cv::Exception& e) {
        CV_Error(e.code, "'" + path + "': " + e.err);
    }
    ChartPatches p;
    const cv::FileNode corners = node["grid_corners"];
    if (!corners.empty()) {
        // Read number by number (x0, y0, ..., x3, y3): OpenCV's vector reader trusts the node's shape.
        if (!corners.isSeq() || (corners.size() != 0 && corners.size() != 8))
            CV_Error(cv::Error::StsParseError,
                     "'" + path + "': field 'grid_corners' must be empty or 8 numbers (4 points x, y)");
        for (size_t k = 0; k < corners.size(); k += 2) {
            const cv::FileNode x = corners[int(k)], y = corners[int(k + 1)];
            if (!(x.isReal() || x.isInt()) || !(y.isReal() || y.isInt()) || !std::isfinite(double(x)) ||
                !std::isfinite(double(y)))
                CV_Error(cv::Error::StsParseError, "'" + path + "': 'grid_corners' must be finite numbers");
            p.gridCorners.emplace_back(float(double(x)), float(double(y)));
        }
    }
    const cv::FileNode squares = node["squares"];
    if (!squares.isSeq() || squares.size() == 0)
        CV_Error(cv::Error::StsParseError, "'" + path + "': field 'squares' is missing or empty");
    for (const cv::FileNode& s : squares) {
        if (!s.isSeq() || s.size() != 4)
            CV_Error(cv::Error::StsParseError,
                     cv::format("'%s': square %d must be a list of 4 integers (x, y, width, height)",
                                path.c_str(), int(p.squares.size()) + 1));
        int v[4];
        for (int k = 0; k < 4; ++k) {
            if (!s[k].isInt())
                CV_Error(cv::Error::StsParseError,
                         cv::format("'%s': square %d must be a list of 4 integers (x, y, width, height)",
                                    path.c_str(), int(p.squares.size()) + 1));
            v[k] = int(s[k]);
        }
        const cv::Rect r(v[0], v[1], v[2], v[3]);
        // Far beyond any sensor, and small enough that corner + side cannot overflow an int.
        const int limit = 1 << 20;
        if (r.x < 0 || r.y < 0 || r.x > limit || r.y > limit || r.width > limit || r.height > limit)
            CV_Error(cv::Error::StsParseError, cv::format("'%s': square %d lies outside [0, %d]",
                                                          path.c_str(), int(p.squares.size()) + 1, limit));
        if (r.width <= 0 || r.height <= 0 || r.x % 2 || r.y % 2 || r.width % 2 || r.height % 2)
            CV_Error(cv::Error::StsParseError,
                     cv::format("'%s': square %d is empty or not CFA-aligned (even corner and sides)",
                                path.c_str(), int(p.squares.size()) + 1));
        p.squares.push_back(r);
    }
    return p;
}

} // namespace rawgment_helpers
