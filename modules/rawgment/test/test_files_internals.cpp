// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The private field readers of the files topic (src/file_access.hpp): OpenCV's opencv_test_rawgment links
// the shared module, which exports none of them, so their tests live here (the standalone build only).
#include "test_common.hpp"

#include "../src/file_access.hpp"

#include <opencv2/rawgment/files.hpp>

#include <fstream>

namespace cv {
namespace rawgment {
namespace {

// JSON's booleans are flags, never numbers; a null is a key left out.
TEST(Files, aBooleanIsReadOnlyAsAFlagAndAFlagOnlyFromABoolean)
{
    const std::string path = test::makeTempDir("files_flags") + "/b.json";
    std::ofstream(path) << "{ \"t\": true, \"f\": false, \"n\": null, \"k\": 2, \"o\": 1 }";
    const FileStorage b = openFileStorageForReading(path, "x");
    EXPECT_TRUE(detail::readOptionalFlagField(b.root(), "t", false));
    EXPECT_FALSE(detail::readOptionalFlagField(b.root(), "f", true));
    EXPECT_TRUE(detail::readOptionalFlagField(b.root(), "o", false)); // a bool as OpenCV writes one
    EXPECT_TRUE(detail::readOptionalFlagField(b.root(), "n", true));
    EXPECT_CV_ERROR_CONTAINS(detail::readOptionalFlagField(b.root(), "k", false),
                             "field 'k' must be true or false");
    EXPECT_CV_ERROR_CONTAINS(detail::readRealField(b.root(), "t"), "field 't' is not a number");
    EXPECT_CV_ERROR_CONTAINS(detail::readOptionalIntField(b.root(), "f", 0), "field 'f' must be an integer");
}

} // namespace
} // namespace rawgment
} // namespace cv
