// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Helpers shared by the unit tests.
#ifndef OPENCV_RAWGMENT_TEST_COMMON_HPP
#define OPENCV_RAWGMENT_TEST_COMMON_HPP

#ifdef RAWGMENT_OPENCV_TEST_FRAMEWORK
// Built inside OpenCV (opencv_test_rawgment): OpenCV's own copy of GoogleTest, whose TEST macros report
// its SkipTestException as a skip. That copy predates GTEST_SKIP(), which the tests use as usual.
#include <opencv2/ts.hpp>
// OpenCV's TEST macros check that a test lives in namespace opencv_test; these live in cv::rawgment.
using opencv_test::required_opencv_test_namespace;
namespace cv {
namespace rawgment {
namespace test {
struct SkipWithMessage
{
    [[noreturn]] void operator=(const ::testing::Message& message) const
    {
        throw ::cvtest::SkipTestException(message.GetString());
    }
};
} // namespace test
} // namespace rawgment
} // namespace cv
#define GTEST_SKIP() return ::cv::rawgment::test::SkipWithMessage() = ::testing::Message()
#else
#include <gtest/gtest.h>
#endif
#include <opencv2/core.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <map>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {
namespace test {

/** Path of a test data file: $RAWGMENT_TEST_DATA_DIR/name, then ../shared/data/name next to the
 * source tree. Empty when neither exists. */
std::string findDataFile(const std::string& name);

/** A fresh, empty directory for one test's files, removed by nobody (under the build's temp area). */
std::string makeTempDir(const std::string& testName);

/** Counts the elements of a float Mat that are NaN or infinite. */
int countNonFinite(const Mat& m);

//! The bytes of a file (empty when it cannot be read).
std::vector<char> readBytes(const std::string& path);
//! Writes bytes to a file, failing the test when it cannot.
void writeBytes(const std::string& path, const std::vector<char>& bytes);
//! How many times this test program has called fork() (interposed by test_common.cpp) since it began.
long forkCalls();
//! The names in a folder, sorted, without the ones starting with '.'.
std::vector<std::string> filesIn(const std::string& dir);

/** The ground-truth sensor of the augmentation and calibration tests: alpha 0.4, sigma_d^2 0.5,
 * sigma_r^2 2 (plus 1/12 of quantisation), 12 bits, black 256. Its sigma_r^2 is small next to
 * g^2 sigma_d^2 at the top gain (251 * 0.5 = 126 at 24 dB), the case where the paper's two-stage fit
 * struggles. */
SensorParams referenceSensorParams();

/** referenceSensorParams() with every dark-frame component: row noise 0.3 g^2 + 0.5 DN^2 (mostly before
 * the gain: the banding of high-gain captures), Tukey-lambda read noise of `lambda`, and dark shading of
 * `size` (B_d: scatter 0.8 plus a ramp of 2 across the columns; B_r: scatter 2 DN) drawn from `seed`. */
SensorParams darkComponentSensorParams(Size size, double lambda, uint64 seed);

/** Pearson's chi-square of integer counts against Poisson(lambda): cells grown from 0 upwards until their
 * expected count in n draws reaches 20, the rest above (every larger count) joined to the last. `dof` is set
 * to the cells less one, and `mass` to the Poisson probability of the counts looked at, 0 to 4 lambda + 59. A
 * correct sampler gives about dof, with standard deviation sqrt(2 dof). */
double poissonChiSquare(const std::map<int64_t, int>& counts, double lambda, double n, int& dof,
                        double* mass = nullptr);

//! The mean of independent values and its standard error, sqrt(sample variance / n); n >= 2.
void meanAndStandardError(const std::vector<double>& values, double& mean, double& standardError);

} // namespace test
} // namespace rawgment
} // namespace cv

//! Sets `var` to the data file's path, or skips the test naming the missing file.
#define RAWGMENT_DATA_FILE_OR_SKIP(var, name)                                                                \
    const std::string var = ::cv::rawgment::test::findDataFile(name);                                        \
    if (var.empty())                                                                                         \
    GTEST_SKIP() << "test data file '" << (name)                                                             \
                 << "' not found (set RAWGMENT_TEST_DATA_DIR or put ../shared/data beside the checkout)"

//! Expects `stmt` to throw cv::Exception whose message contains `fragment`.
#define EXPECT_CV_ERROR_CONTAINS(stmt, fragment)                                                             \
    do {                                                                                                     \
        try {                                                                                                \
            stmt;                                                                                            \
            ADD_FAILURE() << "expected cv::Exception containing '" << (fragment) << "' from: " #stmt;        \
        } catch (const cv::Exception& e_) {                                                                  \
            EXPECT_NE(e_.err.find(fragment), std::string::npos)                                              \
                << "message '" << e_.err << "' lacks '" << (fragment) << "'";                                \
        }                                                                                                    \
    } while (0)

#endif // OPENCV_RAWGMENT_TEST_COMMON_HPP
