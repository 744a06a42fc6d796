// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <opencv2/rawgment/noise_model.hpp>

#include <filesystem>
#include <fstream>

namespace cv {
namespace rawgment {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

TEST(NoiseModel, decibelsAndLinearGain)
{
    EXPECT_EQ(dbToLinearGain(0), 1.0);
    EXPECT_NEAR(dbToLinearGain(20), 10.0, 1e-12);
    EXPECT_NEAR(dbToLinearGain(-20), 0.1, 1e-15);
    EXPECT_NEAR(dbToLinearGain(6), 1.9952623149688795, 1e-14);
    EXPECT_NEAR(dbToLinearGain(60), 1000.0, 1e-9);
    for (double db : {-40.0, -6.0, 0.0, 0.01, 12.0, 24.0, 60.0})
        EXPECT_NEAR(linearGainToDb(dbToLinearGain(db)), db, 1e-12);
    EXPECT_CV_ERROR_CONTAINS(dbToLinearGain(kNaN), "gain in dB must be finite");
    EXPECT_CV_ERROR_CONTAINS(linearGainToDb(0), "linear gain must be finite and > 0");
    EXPECT_CV_ERROR_CONTAINS(linearGainToDb(-1), "linear gain must be finite and > 0");
    EXPECT_CV_ERROR_CONTAINS(linearGainToDb(kInf), "linear gain must be finite and > 0");
}

TEST(NoiseModel, constructorRejectsInvalidParameters)
{
    EXPECT_NO_THROW(NoiseModel(0, 0, 0));
    EXPECT_CV_ERROR_CONTAINS(NoiseModel(-0.1, 1, 1), "NoiseModel.alpha");
    EXPECT_CV_ERROR_CONTAINS(NoiseModel(0.1, kNaN, 1), "NoiseModel.sigmaD2");
    EXPECT_CV_ERROR_CONTAINS(NoiseModel(0.1, 1, kInf), "NoiseModel.sigmaR2");
    EXPECT_CV_ERROR_CONTAINS(NoiseModel(kInf, 1, 1), "NoiseModel.alpha");
}

TEST(NoiseModel, lineAndVarianceFollowEquation5)
{
    const NoiseModel m(0.8, 2.5, 0.3);
    for (double db : {-6.0, 0.0, 6.0, 12.0, 24.0, 60.0}) {
        const double g = dbToLinearGain(db);
        const NoiseLine line = m.lineAtGain(g);
        EXPECT_DOUBLE_EQ(line.a, g * 0.8);
        EXPECT_DOUBLE_EQ(line.b, g * g * 2.5 + 0.3);
        for (double mu : {0.0, 1.0, 100.0, 4000.0})
            EXPECT_DOUBLE_EQ(m.variance(mu, g), g * 0.8 * mu + g * g * 2.5 + 0.3);
    }
    // 60 dB: the read-noise term dominates by g^2 = 1e6.
    EXPECT_NEAR(m.variance(10, 1000), 800 * 10 + 2.5e6 + 0.3, 1e-6);
}

TEST(NoiseModel, negativeMeanHasNoShotNoise)
{
    const NoiseModel m(1.0, 4.0, 1.0);
    EXPECT_EQ(m.variance(-50, 2.0), m.variance(0, 2.0));
    EXPECT_EQ(m.variance(-50, 2.0), 4 * 4.0 + 1.0);
    EXPECT_GT(m.variance(-1e300, 1.0), 0);
}

TEST(NoiseModel, varianceRejectsBadArguments)
{
    const NoiseModel m(1.0, 4.0, 1.0);
    EXPECT_CV_ERROR_CONTAINS(m.variance(kNaN, 1.0), "mean must be finite");
    EXPECT_CV_ERROR_CONTAINS(m.variance(1.0, 0.0), "gain must be finite and > 0");
    EXPECT_CV_ERROR_CONTAINS(m.variance(1.0, -2.0), "gain must be finite and > 0");
    EXPECT_CV_ERROR_CONTAINS(m.variance(1.0, kInf), "gain must be finite and > 0");
    EXPECT_CV_ERROR_CONTAINS(m.lineAtGain(1e200), "overflows");
    NoiseModel broken;
    broken.alpha = kNaN;
    EXPECT_CV_ERROR_CONTAINS(broken.variance(1.0, 1.0), "NoiseModel.alpha");
}

TEST(NoiseModel, varianceImageMatchesScalarForm)
{
    const NoiseModel m(0.5, 3.0, 0.25);
    for (int type : {CV_32FC1, CV_64FC1}) {
        Mat mean(17, 33, type);
        randu(mean, -100, 4000);
        Mat var;
        m.variance(mean, 4.0, var);
        ASSERT_EQ(var.type(), type);
        ASSERT_EQ(var.size(), mean.size());
        Mat mean64, var64;
        mean.convertTo(mean64, CV_64F);
        var.convertTo(var64, CV_64F);
        for (int r = 0; r < mean.rows; ++r)
            for (int c = 0; c < mean.cols; ++c) {
                const double expected = m.variance(mean64.at<double>(r, c), 4.0);
                // float32 output: relative rounding of the products, ~1e-7 relative.
                EXPECT_NEAR(var64.at<double>(r, c), expected, 1e-6 * expected);
            }
    }
    Mat out;
    EXPECT_CV_ERROR_CONTAINS(m.variance(Mat(), 1.0, out), "mean is empty");
    EXPECT_CV_ERROR_CONTAINS(m.variance(Mat(2, 2, CV_16UC1), 1.0, out), "expected CV_32FC1 or CV_64FC1");
    Mat withNan(2, 2, CV_32FC1, Scalar(1));
    withNan.at<float>(1, 1) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(m.variance(withNan, 1.0, out), "NaN or Inf");
}

TEST(NoiseModel, fileRoundTripYamlAndJsonWithAndWithoutABaseIso)
{
    const std::string dir = test::makeTempDir("noise_model_round_trip");
    // Values that need all 17 significant digits to survive a text round trip.
    const NoiseModel m(0.1234567890123456789, 2.718281828459045, 1.0 / 12.0);
    for (const char* name : {"/model.yml", "/model.yaml", "/model.json"}) {
        const std::string path = dir + name;
        m.save(path);
        const NoiseModel r = NoiseModel::load(path);
        EXPECT_EQ(r.alpha, m.alpha) << name;
        EXPECT_EQ(r.sigmaD2, m.sigmaD2) << name;
        EXPECT_EQ(r.sigmaR2, m.sigmaR2) << name;
    }
    std::ifstream json(dir + "/model.json");
    const std::string text((std::istreambuf_iterator<char>(json)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("\"format_version\""), std::string::npos) << text;
    EXPECT_CV_ERROR_CONTAINS(m.save(dir + "/model.txt"), "expected .yml, .yaml or .json");
    // A base ISO takes version 2; a model without one is still written as version 1 for older readers.
    EXPECT_NE(text.find("\"format_version\": 1"), std::string::npos) << text;
    EXPECT_EQ(text.find("base_iso"), std::string::npos) << text;
    NoiseModel withIso = m;
    withIso.baseIso = 160;
    withIso.save(dir + "/iso.yml");
    const NoiseModel back = NoiseModel::load(dir + "/iso.yml");
    EXPECT_EQ(160.0, back.baseIso);
    EXPECT_EQ(m.alpha, back.alpha);
    EXPECT_EQ(0.0, NoiseModel::load(dir + "/model.yml").baseIso);
    FileStorage written(dir + "/iso.yml", FileStorage::READ);
    EXPECT_EQ(2, int(written["noise_model"]["format_version"]));
    withIso.baseIso = -1;
    EXPECT_CV_ERROR_CONTAINS(withIso.save(dir + "/bad.yml"), "NoiseModel.baseIso");
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(dir + "/missing.yml"), "cannot open");
}

NoiseModel readFromYaml(const std::string& body)
{
    FileStorage fs("%YAML:1.0\nnoise_model:\n" + body, FileStorage::READ | FileStorage::MEMORY);
    return NoiseModel::read(fs["noise_model"]);
}

TEST(NoiseModel, readingRejectsBadFilesNamingTheField)
{
    EXPECT_NO_THROW(readFromYaml("  format_version: 1\n  alpha: 1.0\n  sigma_d2: 2.0\n  sigma_r2: 0\n"));
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 1\n  alpha: 1.0\n  sigma_r2: 0.5\n"),
                             "'sigma_d2' is missing");
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml("  format_version: 1\n  alpha: -1.0\n  sigma_d2: 2.0\n  sigma_r2: 0\n"),
        "'alpha' must be finite and >= 0");
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml("  format_version: 1\n  alpha: .NaN\n  sigma_d2: 2.0\n  sigma_r2: 0\n"),
        "'alpha' must be finite");
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml("  format_version: 1\n  alpha: 1\n  sigma_d2: .Inf\n  sigma_r2: 0\n"),
        "'sigma_d2' must be finite");
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml("  format_version: 1\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: abc\n"),
        "'sigma_r2' is not a number");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 3\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"),
                             "format_version 3 is not supported");
    // base_iso came with version 2: a version 1 file that has it was not written by this project.
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml("  format_version: 1\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n  base_iso: 100\n"),
        "unknown key 'base_iso'");
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml("  format_version: 2\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n  base_iso: 0\n"),
        "'base_iso' must be finite and > 0");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"),
                             "'format_version' is missing");
    FileStorage empty("%YAML:1.0\nother: 1\n", FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::read(empty["noise_model"]), "expected a map");
}

TEST(NoiseModel, loadNamesTheFileOnBadContent)
{
    const std::string dir = test::makeTempDir("noise_model_bad_file");
    const std::string path = dir + "/newer.json";
    {
        std::ofstream f(path);
        f << R"({"noise_model": {"format_version": 99, "alpha": 1, "sigma_d2": 1, "sigma_r2": 1}})";
    }
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(path), path);
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(path), "format_version 99");
}

TEST(NoiseModel, saveIsAtomicAndLeavesNoTemporaryFiles)
{
    const std::string dir = test::makeTempDir("noise_model_atomic");
    const NoiseModel m(1, 2, 3);
    m.save(dir + "/m.yml");
    NoiseModel(4, 5, 6).save(dir + "/m.yml"); // replacing an existing model file is allowed
    EXPECT_EQ(NoiseModel::load(dir + "/m.yml").alpha, 4);
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        ++files;
        EXPECT_EQ(entry.path().filename(), "m.yml");
    }
    EXPECT_EQ(files, 1);
}

TEST(NoiseModel, aMisspelledKeyIsAnErrorNamingIt)
{
    FileStorage fs(
        "%YAML:1.0\nnoise_model: {format_version: 1, alpha: 1, sigma_d2: 2, sigma_r2: 3, sigma_r: 4}\n",
        FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::read(fs["noise_model"]),
                             "noise model: unknown key 'sigma_r' (valid keys: format_version, alpha");
}

TEST(NoiseModel, integersBeyond32BitsAreRefusedNotWrapped)
{
    // OpenCV's reader keeps integers in an int: alpha 4294967297 would load as 1.
    const std::string dir = test::makeTempDir("noise_model_wrap");
    const auto writeText = [](const std::string& path, const std::string& text) {
        std::ofstream(path) << text;
    };
    writeText(dir + "/alpha.yml", "%YAML:1.0\nnoise_model:\n  format_version: 1\n  alpha: 4294967297\n"
                                  "  sigma_d2: 1\n  sigma_r2: 1\n");
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(dir + "/alpha.yml"),
                             "line 4: the integer 4294967297 does not fit");
    writeText(dir + "/version.json", "{\"noise_model\": {\"format_version\": 4294967297, \"alpha\": 1, "
                                     "\"sigma_d2\": 1, \"sigma_r2\": 1}}");
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(dir + "/version.json"), "the integer 4294967297 does not fit");
    writeText(dir + "/real.yml", "%YAML:1.0\nnoise_model:\n  format_version: 1\n  alpha: 4294967297.0\n"
                                 "  sigma_d2: 1\n  sigma_r2: 1\n");
    EXPECT_EQ(NoiseModel::load(dir + "/real.yml").alpha, 4294967297.0);
}

} // namespace
} // namespace rawgment
} // namespace cv
