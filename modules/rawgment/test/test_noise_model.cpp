// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include "../src/noise_terms.hpp"

#include <opencv2/rawgment/noise_model.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>

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
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 6\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"),
                             "format_version 6 is not supported");
    // base_iso came with version 2: a version 1 file that has it was not written by this project.
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml("  format_version: 1\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n  base_iso: 100\n"),
        "unknown key 'base_iso'");
    // A base ISO far outside any camera's under- or overflows the gains: 1e300 wrote a model of zeros.
    for (const char* iso : {"0", "1e300", "1e-300", "-5", ".nan"}) {
        SCOPED_TRACE(iso);
        EXPECT_CV_ERROR_CONTAINS(readFromYaml(std::string("  format_version: 2\n  alpha: 1\n  sigma_d2: 1\n  "
                                                          "sigma_r2: 1\n  base_iso: ") +
                                              iso + "\n"),
                                 "field 'base_iso' must lie in [1, 1e+07]");
    }
    NoiseModel far(1, 1, 1);
    far.baseIso = 1e300;
    EXPECT_CV_ERROR_CONTAINS(far.validate(),
                             "NoiseModel.baseIso must lie in [1, 1e+07], or be 0 for unknown");
    // Version 0 was never written: it is no newer file.
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 0\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"),
                             "format_version 0 is not a version of this format");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"),
                             "'format_version' is missing");
    FileStorage empty("%YAML:1.0\nother: 1\n", FileStorage::READ | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::read(empty["noise_model"]), "expected a map");
}

TEST(NoiseModel, aFailedCalibrationsModelIsMarkedAndRefusedUnlessAccepted)
{
    const std::string dir = test::makeTempDir("noise_model_failed_calibration");
    NoiseModel m(0.25, 1.5, 0.8);
    m.baseIso = 100;
    m.failedCalibration = "frames per burst, residuals per gain and mean bin";
    for (const char* name : {"/failed.yml", "/failed.json"}) {
        SCOPED_TRACE(name);
        const std::string path = dir + name;
        m.save(path);
        // The mark takes version 4, so an older build (which reads up to 3) refuses the file as well.
        FileStorage written(path, FileStorage::READ);
        EXPECT_EQ(4, int(written["noise_model"]["format_version"]));
        EXPECT_EQ(m.failedCalibration, std::string(written["noise_model"]["failed_calibration"]));
        EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(path),
                                 "comes from a calibration whose verdict was FAIL "
                                 "(frames per burst, residuals per gain and mean bin)");
        EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(path), path);
        const NoiseModel accepted = NoiseModel::load(path, true);
        EXPECT_EQ(m.failedCalibration, accepted.failedCalibration);
        EXPECT_EQ(m.alpha, accepted.alpha);
        EXPECT_EQ(m.baseIso, accepted.baseIso);
    }
    // A model without the mark keeps its version and loads as before.
    m.failedCalibration.clear();
    m.save(dir + "/passed.yml");
    EXPECT_EQ(2, int(FileStorage(dir + "/passed.yml", FileStorage::READ)["noise_model"]["format_version"]));
    EXPECT_TRUE(NoiseModel::load(dir + "/passed.yml").failedCalibration.empty());
    // The key belongs to version 4, and it must say what failed.
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 3\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"
                                          "  failed_calibration: x\n"),
                             "unknown key 'failed_calibration'");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 4\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"
                                          "  failed_calibration: \"\"\n"),
                             "'failed_calibration' must be a non-empty string");
}

//! Eq. 5 (0.4, 0.5, 2.0) with lines at gains 1, 2 and 8 that leave it (0.68 is 0.85 of Eq. 5's 0.8).
NoiseModel modelWithMeasuredLines()
{
    NoiseModel m(0.4, 0.5, 2.0);
    const double lines[3][3] = {{1, 0.4, 2.6}, {2, 0.68, 4.5}, {8, 3.6, 34.0}};
    for (const auto& l : lines) {
        MeasuredNoiseLine entry;
        entry.gain = l[0];
        entry.line.a = l[1];
        entry.line.b = l[2];
        m.measuredLines.push_back(entry);
    }
    m.validate();
    return m;
}

TEST(NoiseModel, measuredLinesAreFollowedAtBetweenAndBeyondTheirGains)
{
    const NoiseModel m = modelWithMeasuredLines();
    // At a measured gain, the measured line itself (the same bits).
    for (const MeasuredNoiseLine& l : m.measuredLines) {
        EXPECT_EQ(l.line.a, m.lineAtGain(l.gain).a);
        EXPECT_EQ(l.line.b, m.lineAtGain(l.gain).b);
        EXPECT_EQ(l.line.a * 100 + l.line.b, m.variance(100, l.gain));
    }
    // Between: the slope linear in g, the offset linear in g^2 (written out here as the docs state it).
    const double g = 4, t = (4.0 - 2) / (8 - 2), t2 = (16.0 - 4) / (64 - 4);
    EXPECT_NEAR(0.68 + t * (3.6 - 0.68), m.lineAtGain(g).a, 1e-12);
    EXPECT_NEAR(4.5 + t2 * (34.0 - 4.5), m.lineAtGain(g).b, 1e-12);
    // Exact for neighbours that follow Eq. 5 with parameters of their own.
    NoiseModel own(0.4, 0.5, 2.0);
    const NoiseModel other(0.3, 1.7, 0.9);
    for (double gain : {1.5, 6.0}) {
        MeasuredNoiseLine l;
        l.gain = gain;
        l.line = other.lineAtGain(gain);
        own.measuredLines.push_back(l);
    }
    for (double between : {1.6, 2.5, 4.0, 5.9}) {
        EXPECT_NEAR(other.lineAtGain(between).a, own.lineAtGain(between).a,
                    1e-12 * other.lineAtGain(between).a);
        EXPECT_NEAR(other.lineAtGain(between).b, own.lineAtGain(between).b,
                    1e-12 * other.lineAtGain(between).b);
    }
    // Beyond: the edge line carried on by Eq. 5's trend, with no jump at the edge.
    const NoiseLine below = m.lineAtGain(0.5), above = m.lineAtGain(16);
    EXPECT_NEAR(0.4 * 0.5, below.a, 1e-15);
    EXPECT_NEAR(2.6 * (0.25 * 0.5 + 2.0) / (0.5 + 2.0), below.b, 1e-12);
    EXPECT_NEAR(3.6 * 2, above.a, 1e-12);
    EXPECT_NEAR(34.0 * (256 * 0.5 + 2.0) / (64 * 0.5 + 2.0), above.b, 1e-9);
    EXPECT_NEAR(m.lineAtGain(8 * (1 + 1e-12)).b, 34.0, 1e-9);
    EXPECT_NEAR(m.lineAtGain(1 * (1 - 1e-12)).b, 2.6, 1e-9);
}

TEST(NoiseModel, measuredLinesRoundTripAsVersion5AndAreValidated)
{
    const std::string dir = test::makeTempDir("noise_model_measured_lines");
    NoiseModel m = modelWithMeasuredLines();
    m.baseIso = 100;
    m.measuredLines[1].slopeStdError = 0.0123456789012345678;
    m.measuredLines[1].offsetStdError = 0.1;
    m.measuredLines[2].iso = 800;
    for (const char* name : {"/lines.yml", "/lines.json"}) {
        SCOPED_TRACE(name);
        m.save(dir + name);
        EXPECT_EQ(5, int(FileStorage(dir + name, FileStorage::READ)["noise_model"]["format_version"]));
        const NoiseModel r = NoiseModel::load(dir + name);
        ASSERT_EQ(m.measuredLines.size(), r.measuredLines.size());
        for (size_t i = 0; i < m.measuredLines.size(); ++i) {
            const MeasuredNoiseLine &a = m.measuredLines[i], &b = r.measuredLines[i];
            EXPECT_EQ(a.gain, b.gain);
            EXPECT_EQ(a.line.a, b.line.a);
            EXPECT_EQ(a.line.b, b.line.b);
            EXPECT_EQ(a.slopeStdError, b.slopeStdError);
            EXPECT_EQ(a.offsetStdError, b.offsetStdError);
            EXPECT_EQ(a.iso, b.iso);
        }
        EXPECT_EQ(m.lineAtGain(3).b, r.lineAtGain(3).b);
    }
    // Without lines, the version of the model's other contents, as before.
    NoiseModel plain = m;
    plain.measuredLines.clear();
    plain.save(dir + "/plain.yml");
    EXPECT_EQ(2, int(FileStorage(dir + "/plain.yml", FileStorage::READ)["noise_model"]["format_version"]));

    NoiseModel bad = modelWithMeasuredLines();
    bad.measuredLines[2].gain = 2;
    EXPECT_CV_ERROR_CONTAINS(bad.validate(), "measuredLines[2]: gain 2 does not follow 2");
    bad = modelWithMeasuredLines();
    bad.measuredLines[0].line.b = -1;
    EXPECT_CV_ERROR_CONTAINS(bad.validate(), "measuredLines[0]: offset b must be finite and >= 0");
    bad = modelWithMeasuredLines();
    bad.measuredLines[1].line.a = kNaN;
    EXPECT_CV_ERROR_CONTAINS(bad.lineAtGain(2), "measuredLines[1]: slope a must be finite");
    bad = modelWithMeasuredLines();
    bad.measuredLines[1].gain = kInf;
    EXPECT_CV_ERROR_CONTAINS(bad.save(dir + "/bad.yml"), "measuredLines[1]: gain must be finite and > 0");

    const std::string head = "  format_version: 5\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n";
    EXPECT_NO_THROW(readFromYaml(head + "  measured_lines:\n    - { gain: 1, a: 1, b: 2 }\n"));
    EXPECT_CV_ERROR_CONTAINS(readFromYaml(head + "  measured_lines:\n    - { gain: 1, a: 1, b: 2, c: 3 }\n"),
                             "measured_lines[0]: unknown key 'c'");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml(head + "  measured_lines:\n    - { gain: 1, a: 1 }\n"),
                             "measured_lines[0]: field 'b' is missing");
    EXPECT_CV_ERROR_CONTAINS(
        readFromYaml(head + "  measured_lines:\n    - { gain: 1, a: 1, b: 1, a_std_error: 0.1 }\n"),
        "a_std_error and b_std_error come together");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml(head + "  measured_lines:\n    - { gain: 2, a: 1, b: 1 }\n"
                                                 "    - { gain: 1, a: 1, b: 1 }\n"),
                             "gain 1 does not follow 2");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml(head + "  measured_lines: []\n"), "non-empty list");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 4\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"
                                          "  measured_lines:\n    - { gain: 1, a: 1, b: 2 }\n"),
                             "unknown key 'measured_lines'");
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

// The image that a saved model file names for its dark-shading map `key` (per_gain or offset).
std::string shadingImageOf(const std::string& modelPath, const char* key)
{
    FileStorage fs(modelPath, FileStorage::READ);
    return fs["noise_model"]["dark_shading"][key]["image"].string();
}

std::vector<std::string> filesOf(const std::string& dir)
{
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

// A model with every dark-frame component, maps of a small sensor.
NoiseModel darkComponentModel(Size size)
{
    NoiseModel m(0.25, 1.5, 0.8);
    m.rowSigmaD2 = 0.04;
    m.rowSigmaR2 = 0.3;
    m.tukeyRead = true;
    m.tukeyLambda = -0.05;
    m.darkShadingPerGain.create(size, CV_32FC1);
    m.darkShadingOffset.create(size, CV_32FC1);
    randu(m.darkShadingPerGain, -0.5, 1.5);
    randu(m.darkShadingOffset, -3.0, 3.0);
    return m;
}

TEST(NoiseModel, darkComponentsRoundTripWithTheirImagesAsVersion3)
{
    const std::string dir = test::makeTempDir("noise_model_dark_components");
    const NoiseModel m = darkComponentModel(Size(12, 8));
    for (const char* name : {"/dark.yml", "/dark.json"}) {
        m.save(dir + name);
        const NoiseModel r = NoiseModel::load(dir + name);
        EXPECT_EQ(m.rowSigmaD2, r.rowSigmaD2) << name;
        EXPECT_EQ(m.rowSigmaR2, r.rowSigmaR2) << name;
        EXPECT_TRUE(r.tukeyRead) << name;
        EXPECT_EQ(m.tukeyLambda, r.tukeyLambda) << name;
        EXPECT_EQ(0, norm(m.darkShadingPerGain, r.darkShadingPerGain, NORM_INF)) << name;
        EXPECT_EQ(0, norm(m.darkShadingOffset, r.darkShadingOffset, NORM_INF)) << name;
    }
    FileStorage written(dir + "/dark.yml", FileStorage::READ);
    EXPECT_EQ(3, int(written["noise_model"]["format_version"]));
    written.release();
    EXPECT_EQ("dark.yml.dark_shading_per_gain." + std::string(16, 'h') + ".tiff",
              std::regex_replace(shadingImageOf(dir + "/dark.yml", "per_gain"), std::regex("[0-9a-f]{16}"),
                                 std::string(16, 'h')));
    // Lambda 0 (logistic) is present, not absent: the flag says so.
    NoiseModel logistic(0.25, 1.5, 0.8);
    logistic.tukeyRead = true;
    logistic.save(dir + "/logistic.yml");
    const NoiseModel back = NoiseModel::load(dir + "/logistic.yml");
    EXPECT_TRUE(back.tukeyRead);
    EXPECT_EQ(0.0, back.tukeyLambda);
    EXPECT_FALSE(back.hasRowNoise());
    EXPECT_FALSE(back.hasDarkShading());
    // Without components a model stays version 1, readable by builds that predate them.
    NoiseModel plain(0.25, 1.5, 0.8);
    plain.save(dir + "/plain.yml");
    FileStorage plainFile(dir + "/plain.yml", FileStorage::READ);
    EXPECT_EQ(1, int(plainFile["noise_model"]["format_version"]));
}

TEST(NoiseModel, aSaveWithMapsIsAllOrNothingAndModelsInOneFolderKeepTheirOwnMaps)
{
    const std::string dir = test::makeTempDir("noise_model_maps_all_or_nothing");
    const NoiseModel a = darkComponentModel(Size(12, 8));
    NoiseModel b = darkComponentModel(Size(12, 8));
    b.darkShadingOffset += 1;
    // One folder, one stem, two formats: each file keeps its own maps.
    a.save(dir + "/cam.yml");
    b.save(dir + "/cam.json");
    EXPECT_EQ(0, norm(a.darkShadingOffset, NoiseModel::load(dir + "/cam.yml").darkShadingOffset, NORM_INF));
    EXPECT_EQ(0, norm(b.darkShadingOffset, NoiseModel::load(dir + "/cam.json").darkShadingOffset, NORM_INF));
    const std::vector<std::string> before = filesOf(dir);
    EXPECT_EQ(6u, before.size());

    // A refused save writes nothing: the old model and its maps load as they were.
    NoiseModel refused = b;
    refused.darkShadingPerGain = b.darkShadingPerGain.clone();
    refused.darkShadingPerGain.at<float>(2, 3) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_CV_ERROR_CONTAINS(refused.save(dir + "/cam.yml"), "darkShadingPerGain contains NaN or Inf");
    EXPECT_EQ(before, filesOf(dir));
    EXPECT_EQ(0, norm(a.darkShadingPerGain, NoiseModel::load(dir + "/cam.yml").darkShadingPerGain, NORM_INF));

    // Replacing the model: the new maps, and the old ones of that file gone, the other file untouched.
    b.save(dir + "/cam.yml");
    EXPECT_EQ(0, norm(b.darkShadingOffset, NoiseModel::load(dir + "/cam.yml").darkShadingOffset, NORM_INF));
    EXPECT_EQ(before.size(), filesOf(dir).size());
    EXPECT_EQ(0, norm(b.darkShadingOffset, NoiseModel::load(dir + "/cam.json").darkShadingOffset, NORM_INF));
    // Saving the same maps again keeps them; a model without shading leaves none of that file behind.
    b.save(dir + "/cam.yml");
    EXPECT_EQ(before.size(), filesOf(dir).size());
    NoiseModel(0.25, 1.5, 0.8).save(dir + "/cam.yml");
    EXPECT_EQ(4u, filesOf(dir).size());
    EXPECT_NO_THROW(NoiseModel::load(dir + "/cam.json"));
    // A damaged map of the same name is written again, not taken for this save's.
    std::ofstream(dir + "/" + shadingImageOf(dir + "/cam.json", "offset"), std::ios::trunc) << "junk";
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(dir + "/cam.json"), "dark_shading.offset: image");
    b.save(dir + "/cam.json");
    EXPECT_EQ(0, norm(b.darkShadingOffset, NoiseModel::load(dir + "/cam.json").darkShadingOffset, NORM_INF));
}

TEST(NoiseModel, darkShadingImagesOfAnotherSaveOrMissingAreErrors)
{
    const std::string dir = test::makeTempDir("noise_model_dark_mismatch");
    const NoiseModel a = darkComponentModel(Size(12, 8));
    a.save(dir + "/a.yml");
    NoiseModel b = darkComponentModel(Size(12, 8));
    b.darkShadingOffset += 1;
    b.save(dir + "/b.yml");
    // a.yml with the images of b.yml: the checksums tell them apart.
    const std::string aOffset = dir + "/" + shadingImageOf(dir + "/a.yml", "offset"),
                      aPerGain = dir + "/" + shadingImageOf(dir + "/a.yml", "per_gain"),
                      bPerGain = shadingImageOf(dir + "/b.yml", "per_gain");
    std::rename((dir + "/" + shadingImageOf(dir + "/b.yml", "offset")).c_str(), aOffset.c_str());
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(dir + "/a.yml"), "different saves");
    std::remove(aPerGain.c_str());
    EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(dir + "/a.yml"), "is missing");
    // Image names are file names in the model's folder: no paths, no devices.
    std::ifstream original(dir + "/b.yml");
    const std::string text((std::istreambuf_iterator<char>(original)), std::istreambuf_iterator<char>());
    for (const std::string& hostile : {std::string("/dev/stdin"), "../" + bPerGain, std::string("..")}) {
        SCOPED_TRACE(hostile);
        std::string edited = text;
        const std::string& from = bPerGain;
        edited.replace(edited.find(from), from.size(), hostile);
        std::ofstream(dir + "/hostile.yml") << edited;
        EXPECT_CV_ERROR_CONTAINS(NoiseModel::load(dir + "/hostile.yml"),
                                 "must be a file name in the same folder");
    }
    // write() without image names cannot describe the maps.
    FileStorage fs(".yml", FileStorage::WRITE | FileStorage::MEMORY);
    EXPECT_CV_ERROR_CONTAINS(a.write(fs, "noise_model"), "needs the names of its two images");
}

TEST(NoiseModel, darkComponentsAreValidated)
{
    NoiseModel m(0.25, 1.5, 0.8);
    m.rowSigmaD2 = -1;
    EXPECT_CV_ERROR_CONTAINS(m.validate(), "NoiseModel.rowSigmaD2");
    m.rowSigmaD2 = 0;
    m.tukeyRead = true;
    m.tukeyLambda = -0.3;
    EXPECT_CV_ERROR_CONTAINS(m.validate(), "NoiseModel.tukeyLambda");
    m.tukeyLambda = 0;
    m.darkShadingPerGain = Mat::zeros(4, 4, CV_32FC1);
    EXPECT_CV_ERROR_CONTAINS(m.validate(), "both set or both empty");
    m.darkShadingOffset = Mat::zeros(4, 6, CV_32FC1);
    EXPECT_CV_ERROR_CONTAINS(m.validate(), "CV_32FC1 of 4x4");
    m.darkShadingOffset = Mat::zeros(4, 4, CV_32FC1);
    m.darkShadingOffset.at<float>(1, 1) = std::numeric_limits<float>::infinity();
    // A pass over the maps is too dear for validate(), which every step calls: a model with a bad map is
    // refused where it is written, read or simulated, and by the steps (test_augment).
    EXPECT_CV_ERROR_CONTAINS(m.save(test::makeTempDir("noise_model_nan_map") + "/m.yml"),
                             "darkShadingOffset contains NaN or Inf");
    SensorParams params;
    params.noise = m;
    EXPECT_CV_ERROR_CONTAINS(SensorSimulator(params, Size(4, 4)), "darkShadingOffset contains NaN or Inf");
    // A version-1 file may not carry the newer keys.
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 1\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"
                                          "  row_sigma_d2: 1\n"),
                             "row_sigma_d2");
    EXPECT_CV_ERROR_CONTAINS(readFromYaml("  format_version: 3\n  alpha: 1\n  sigma_d2: 1\n  sigma_r2: 1\n"
                                          "  row_sigma_d2: 1\n"),
                             "come together");
}

} // namespace
} // namespace rawgment
} // namespace cv
