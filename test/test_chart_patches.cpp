// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The colour-checker patch extraction of samples/ on the real chart in ../shared/data/colorchart.dng.
#include "chart_patches.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment.hpp>

#include <unistd.h>

#include <fstream>

namespace {

std::string sharedDataFile(const std::string& name)
{
    const std::string path = std::string(RAWGMENT_SHARED_DATA_DIR) + "/" + name;
    return ::access(path.c_str(), R_OK) == 0 ? path : std::string();
}

TEST(ChartPatches, colorchartDngGivesTwentyFourDisjointSquaresInsideTheChartWithAnOrderedGreyRow)
{
    const std::string path = sharedDataFile("colorchart.dng");
    if (path.empty())
        GTEST_SKIP() << "test data file 'colorchart.dng' not found beside the checkout (../shared/data)";
    const cv::rawgment::RawImage image = cv::rawgment::readRaw(path);
    const cv::Mat preview = rawgment_helpers::renderDetectionPreview(image);
    ASSERT_EQ(image.mosaic.size(), preview.size()) << "preview and mosaic share coordinates";
    rawgment_helpers::ChartPatches patches;
    std::string why;
    ASSERT_TRUE(rawgment_helpers::findChartPatches(preview, 24, patches, why)) << why;
    ASSERT_EQ(24u, patches.squares.size());
    ASSERT_EQ(4u, patches.gridCorners.size());
    for (size_t i = 0; i < patches.squares.size(); ++i) {
        const cv::Rect& s = patches.squares[i];
        SCOPED_TRACE(cv::format("patch %zu", i + 1));
        EXPECT_EQ(cv::Size(24, 24), s.size());
        EXPECT_EQ(0, s.x % 2) << "CFA-aligned";
        EXPECT_EQ(0, s.y % 2) << "CFA-aligned";
        for (const cv::Point p : {s.tl(), s.br(), cv::Point(s.x, s.br().y), cv::Point(s.br().x, s.y)})
            EXPECT_GT(cv::pointPolygonTest(patches.gridCorners, cv::Point2f(p), false), 0)
                << "inside the chart";
        for (size_t j = 0; j < i; ++j)
            EXPECT_TRUE((s & patches.squares[j]).empty()) << "overlaps patch " << j + 1;
    }
    // The grey row, white (19) to black (24): each patch darker than the one before, in every channel.
    cv::Mat signal;
    cv::rawgment::subtractBlackLevel(image.mosaic, image.format, signal);
    std::vector<cv::Mat> planes;
    for (int k = 18; k < 24; ++k) {
        cv::rawgment::splitCfaPlanes(signal(patches.squares[k]), planes);
        if (k > 18) {
            std::vector<cv::Mat> previous;
            cv::rawgment::splitCfaPlanes(signal(patches.squares[k - 1]), previous);
            for (int s = 0; s < 4; ++s)
                EXPECT_LT(cv::mean(planes[s])[0], cv::mean(previous[s])[0])
                    << "patch " << k + 1 << " site " << s;
        }
    }
}

TEST(ChartPatches, squaresRoundTripThroughYaml)
{
    rawgment_helpers::ChartPatches p;
    p.gridCorners = {{0, 0}, {100, 0}, {100, 60}, {0, 60}};
    for (int i = 0; i < 24; ++i)
        p.squares.emplace_back(2 * i, 4, 8, 8);
    const std::string path = ::testing::TempDir() + "/chart_patches_roundtrip.yml";
    std::remove(path.c_str());
    rawgment_helpers::writeChartPatches(path, p);
    const rawgment_helpers::ChartPatches back = rawgment_helpers::readChartPatches(path);
    EXPECT_EQ(p.squares, back.squares);
    EXPECT_EQ(p.gridCorners, back.gridCorners);
}

TEST(ChartPatches, malformedFilesAreErrorsNamingTheFile)
{
    const std::string path = ::testing::TempDir() + "/chart_patches_malformed.yml";
    const auto readText = [&](const std::string& body) {
        std::ofstream(path, std::ios::trunc) << "%YAML:1.0\n---\nchart_patches:\n" << body;
        return rawgment_helpers::readChartPatches(path);
    };
    const auto expectError = [&](const std::string& body, const std::string& fragment) {
        try {
            readText(body);
            ADD_FAILURE() << "accepted:\n" << body;
        } catch (const cv::Exception& e) {
            EXPECT_NE(e.err.find(fragment), std::string::npos) << e.err;
            EXPECT_NE(e.err.find(path), std::string::npos) << e.err;
        }
    };
    EXPECT_EQ(1u, readText("   squares:\n      - [ 2, 4, 8, 8 ]\n").squares.size());
    // A corner plus a side beyond an int would overflow every later intersection.
    expectError("   squares:\n      - [ 2147483646, 4, 8, 8 ]\n", "lies outside");
    expectError("   squares:\n      - [ 2, 4, 8 ]\n", "must be a list of 4 integers");
    expectError("   squares:\n      - [ 2, 4, 8.5, 8 ]\n", "must be a list of 4 integers");
    expectError("   squares:\n      - [ 1, 4, 8, 8 ]\n", "not CFA-aligned");
    expectError("   grid_corners: [ 1, 2, 3 ]\n   squares:\n      - [ 2, 4, 8, 8 ]\n", "grid_corners");
    expectError("   grid_corners: hello\n   squares:\n      - [ 2, 4, 8, 8 ]\n", "grid_corners");
    expectError("   squares:\n      - [ 2, 4, 8, 8 ]\n   squares:\n      - [ 2, 4, 8, 8 ]\n",
                "appears twice");
}

} // namespace
