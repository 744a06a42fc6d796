// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Real cameras: darktable's measured profiles fitted to Eq. 5, the catalogue, camera draws, and the
// loader of every model file.
#include "test_common.hpp"

#include <tuple>

#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/camera_profiles.hpp>
#include <opencv2/rawgment/files.hpp>
#include <opencv2/rawgment/raw_io.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <map>

namespace cv {
namespace rawgment {
namespace test {
namespace {

RawFormat fourteenBitFormat()
{
    RawFormat f;
    f.pattern = CFA_RGGB;
    f.blackLevel = Vec4d(512, 512, 512, 512);
    f.whiteLevel = 16383;
    return f;
}

std::string writeText(const std::string& dir, const std::string& name, const std::string& text)
{
    writeFileAtomically(dir + "/" + name, text.data(), text.size());
    return dir + "/" + name;
}

//! One camera entry of a darktable file: profiles (iso, green a, green b), red and blue as green.
std::string cameraEntry(const std::string& model, const std::vector<Vec3d>& profiles,
                        const std::string& extra = "")
{
    std::string text = "{\"model\": \"" + model + "\", \"profiles\": [";
    for (size_t k = 0; k < profiles.size(); ++k)
        text += cv::format("%s{\"name\": \"p\", \"iso\": %.17g, \"a\": [%.17g, %.17g, %.17g], \"b\": [%.17g, "
                           "%.17g, %.17g]%s}",
                           k ? ", " : "", profiles[k][0], profiles[k][1], profiles[k][1], profiles[k][1],
                           profiles[k][2], profiles[k][2], profiles[k][2], extra.c_str());
    return text + "]}";
}

std::string profileFile(const std::string& maker, const std::vector<std::string>& models)
{
    std::string text = "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"" + maker + "\", \"models\": [";
    for (size_t k = 0; k < models.size(); ++k)
        text += (k ? ", " : "") + models[k];
    return text + "]}]}\n";
}

const CameraNoiseProfile& byModel(const std::vector<CameraNoiseProfile>& cams, const std::string& model)
{
    for (const CameraNoiseProfile& c : cams)
        if (c.model == model)
            return c;
    throw std::runtime_error("no camera " + model);
}

} // namespace

TEST(CameraProfiles, theProjectsOwnExportComesBackGoodWithItsModel)
{
    const std::string dir = makeTempDir("camera_profiles_own");
    const NoiseModel model(0.42, 1.7, 3.1);
    const RawFormat format = fourteenBitFormat();
    const std::string path =
        writeText(dir, "own.json",
                  darktableNoiseProfiles(model, format, 100, {100, 400, 800, 3200}, "Rawgment", "Sim"));
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    ASSERT_EQ(cams.size(), 1u);
    const CameraNoiseProfile& cam = cams[0];
    EXPECT_EQ(cam.name(), "Rawgment Sim");
    EXPECT_EQ(cam.verdict, CAMERA_PROFILE_GOOD) << cam.reason;
    EXPECT_EQ(cam.place, "noiseprofiles[0].models[0]");
    ASSERT_EQ(cam.isos.size(), 4u);
    EXPECT_EQ(cam.noise.baseIso, 100);
    // An exact model: every residual is rounding (17-digit text and one division by c).
    EXPECT_LT(cam.worstSlopeResidual, 1e-12);
    EXPECT_LT(cam.worstOffsetResidual, 1e-9);
    EXPECT_EQ(cam.medianColourSpread, 1);
    const NoiseModel back = cam.modelFor(format);
    EXPECT_NEAR(back.alpha, model.alpha, 1e-12 * model.alpha);
    EXPECT_NEAR(back.sigmaD2, model.sigmaD2, 1e-9 * model.sigmaD2);
    EXPECT_NEAR(back.sigmaR2, model.sigmaR2, 1e-9 * model.sigmaR2);
    EXPECT_EQ(back.baseIso, 100);
    // The model is per unit of range: a 12-bit format of the same camera scales alpha by the range and the
    // variances by its square.
    RawFormat twelve = format;
    twelve.blackLevel = Vec4d(128, 128, 128, 128);
    twelve.whiteLevel = 4095;
    const double ratio = (4095.0 - 128) / (16383 - 512);
    EXPECT_NEAR(cam.modelFor(twelve).alpha, model.alpha * ratio, 1e-12);
    EXPECT_NEAR(cam.modelFor(twelve).sigmaR2, model.sigmaR2 * ratio * ratio, 1e-9);
    // And the exact loader of the same file agrees.
    const NoiseModel exact = noiseModelFromDarktableExport(path, format, 100, "Rawgment", "Sim");
    EXPECT_NEAR(exact.alpha, back.alpha, 1e-12 * model.alpha);
}

TEST(CameraProfiles, anExportOfMeasuredLinesAtPerSiteBlackLevelsComesBackLineForLine)
{
    // A calibrated model carries its per-gain fits as measured lines, which its default export writes ISO by
    // ISO. The strict inverse refused such a file without saying what reads it, and the catalogue read its
    // lines 3e-5 off where the sites' black levels differ (the mean of four sites' range against green's).
    const std::string dir = makeTempDir("camera_profiles_lines");
    NoiseModel model(0.42, 1.7, 3.1);
    model.baseIso = 100;
    for (const auto& [gain, a, b] : {std::make_tuple(1.0, 0.45, 5.0), std::make_tuple(4.0, 1.62, 30.0),
                                     std::make_tuple(8.0, 3.5, 110.0)}) {
        MeasuredNoiseLine line;
        line.gain = gain;
        line.iso = 100 * gain;
        line.line.a = a;
        line.line.b = b;
        model.measuredLines.push_back(line);
    }
    RawFormat format = fourteenBitFormat();
    format.blackLevel = Vec4d(510, 512, 515, 509);
    const std::string path =
        writeText(dir, "calibrated.json",
                  darktableNoiseProfiles(model, format, 100, {100, 400, 800}, "Rawgment", "Cal"));
    EXPECT_CV_ERROR_CONTAINS(noiseModelFromDarktableExport(path, format, 100, "Rawgment", "Cal"),
                             "read it with readCameraProfiles() and CameraNoiseProfile::modelFor()");
    const NoiseModel back = readCameraProfiles(path).at(0).modelFor(format);
    ASSERT_EQ(3u, back.measuredLines.size());
    for (const MeasuredNoiseLine& m : model.measuredLines) {
        const NoiseLine got = back.lineAtGain(m.gain);
        EXPECT_NEAR(got.a, m.line.a, 1e-12 * m.line.a) << m.gain;
        EXPECT_NEAR(got.b, m.line.b, 1e-12 * m.line.b) << m.gain;
    }
}

TEST(CameraProfiles, aFitOfNoisyProfilesRecoversTheModelAndMeasuresItsResiduals)
{
    // Profiles of a known camera (per pixel: alpha 1e-4, sigma_d^2 1e-8, sigma_r^2 4e-8, over the range)
    // with each ISO's slope off by a known factor: the fit and the residuals follow the definitions.
    const double c = DARKTABLE_HAAR_VARIANCE_RATIO;
    const double alpha = 1e-4, sd = 1e-8, sr = 4e-8;
    const double isos[] = {100, 200, 400, 800, 1600};
    const double slopeError[] = {1.0, 0.95, 1.01, 0.99, 1.0};
    std::vector<Vec3d> profiles;
    for (int k = 0; k < 5; ++k) {
        const double g = isos[k] / 100;
        profiles.emplace_back(isos[k], c * g * alpha * slopeError[k], c * (g * g * sd + sr));
    }
    const std::string dir = makeTempDir("camera_profiles_fit");
    const std::string path =
        writeText(dir, "fit.json", profileFile("Maker", {cameraEntry("Five", profiles)}));
    const CameraNoiseProfile cam = readCameraProfiles(path)[0];
    ASSERT_EQ(cam.verdict, CAMERA_PROFILE_GOOD) << cam.reason;
    // The relative least squares through the origin: alpha = sum(1/e) / sum(1/e^2) with e the errors.
    double num = 0, den = 0;
    for (double e : slopeError) {
        num += 1 / e;
        den += 1 / (e * e);
    }
    EXPECT_NEAR(cam.noise.alpha, alpha * num / den, 1e-15);
    for (int k = 0; k < 5; ++k)
        EXPECT_NEAR(cam.isos[size_t(k)].slopeResidual, (num / den) / slopeError[k] - 1, 1e-12) << isos[k];
    EXPECT_EQ(cam.worstSlopeIso, 200);
    // Exact offsets are fitted exactly.
    EXPECT_NEAR(cam.noise.sigmaD2, sd, 1e-6 * sd);
    EXPECT_NEAR(cam.noise.sigmaR2, sr, 1e-6 * sr);
    EXPECT_LT(cam.worstOffsetResidual, 1e-6);
    EXPECT_TRUE(cam.monotoneSlope);
}

TEST(CameraProfiles, negativeOffsetsAreFittedWithNonNegativeTerms)
{
    // Offsets that dip below zero at low ISO (as 138 of darktable's cameras do): the fit keeps
    // sigma_r^2 >= 0, and a camera whose offsets are all negative is refused.
    const double c = DARKTABLE_HAAR_VARIANCE_RATIO;
    std::vector<Vec3d> dipping, negative;
    const double isos[] = {100, 200, 400, 800, 1600, 3200};
    for (double iso : isos) {
        const double g = iso / 100;
        dipping.emplace_back(iso, c * g * 1e-4, c * (g * g * 1e-8 - 2e-8));
        negative.emplace_back(iso, c * g * 1e-4, -c * 1e-8);
    }
    const std::string dir = makeTempDir("camera_profiles_negative");
    const std::string path =
        writeText(dir, "neg.json",
                  profileFile("Maker", {cameraEntry("Dipping", dipping), cameraEntry("Negative", negative)}));
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    const CameraNoiseProfile& dip = byModel(cams, "Dipping");
    EXPECT_TRUE(dip.usable()) << dip.reason;
    EXPECT_GE(dip.noise.sigmaR2, 0);
    EXPECT_GT(dip.noise.sigmaD2, 0);
    EXPECT_EQ(dip.negativeOffsets, 1); // ISO 100: 1e-8 - 2e-8
    const CameraNoiseProfile& neg = byModel(cams, "Negative");
    EXPECT_EQ(neg.verdict, CAMERA_PROFILE_REFUSED);
    EXPECT_NE(neg.reason.find("offsets below zero at all 6 ISOs"), std::string::npos) << neg.reason;
    EXPECT_CV_ERROR_CONTAINS(neg.modelFor(fourteenBitFormat()), "is REFUSED: offsets below zero");
}

TEST(CameraProfiles, malformedAndUnusableEntriesAreRefusedNamingTheirPlaceAndTheOthersRead)
{
    const double c = DARKTABLE_HAAR_VARIANCE_RATIO;
    const std::vector<Vec3d> good = {Vec3d(100, c * 1e-4, c * 4e-8), Vec3d(200, c * 2e-4, c * 5e-8),
                                     Vec3d(400, c * 4e-4, c * 8e-8)};
    const std::string dir = makeTempDir("camera_profiles_malformed");
    const std::string path = writeText(
        dir, "mixed.json",
        profileFile(
            "Maker",
            {cameraEntry("Good", good), cameraEntry("One ISO", {good[0]}),
             "{\"model\": \"Short\", \"profiles\": [{\"name\": \"p\", \"iso\": 100, \"a\": [1e-5, 1e-5], "
             "\"b\": [0, 0, 0]}]}",
             cameraEntry("Unknown key", good, ", \"colour\": 1"),
             "{\"model\": \"Text ISO\", \"profiles\": [{\"iso\": \"high\", \"a\": [1, 1, 1], \"b\": [1, 1, "
             "1]}]}",
             cameraEntry("Twice", {good[0], good[0], good[1]}), cameraEntry("good", good)}));
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    ASSERT_EQ(cams.size(), 7u);
    EXPECT_EQ(byModel(cams, "Good").verdict, CAMERA_PROFILE_GOOD);
    const auto reasonOf = [&](const std::string& model) { return byModel(cams, model).reason; };
    EXPECT_NE(reasonOf("One ISO").find("a single usable ISO (100)"), std::string::npos);
    EXPECT_NE(
        reasonOf("Short").find("malformed: noiseprofiles[0].models[2].profiles[0]: field 'a' must be a list "
                               "of 3 numbers"),
        std::string::npos)
        << reasonOf("Short");
    EXPECT_NE(reasonOf("Unknown key").find("noiseprofiles[0].models[3].profiles[0]: unknown key 'colour'"),
              std::string::npos)
        << reasonOf("Unknown key");
    EXPECT_NE(reasonOf("Text ISO").find("models[4].profiles[0]"), std::string::npos) << reasonOf("Text ISO");
    // Two profiles of one ISO are two measurements of it, both fitted.
    EXPECT_TRUE(byModel(cams, "Twice").usable()) << reasonOf("Twice");
    EXPECT_EQ(byModel(cams, "Twice").isos.size(), 3u);
    // "Maker good" repeats "Maker Good" but for case: selection by name would be ambiguous.
    EXPECT_NE(cams[6].reason.find("repeats an earlier entry"), std::string::npos);
    for (const CameraNoiseProfile& cam : cams)
        if (!cam.usable()) {
            EXPECT_FALSE(cam.reason.empty()) << cam.name();
        }

    // A file that is not darktable's form is an error naming it.
    const std::string notProfiles = writeText(dir, "other.json", "{\"noiseprofiles\": 3}\n");
    EXPECT_CV_ERROR_CONTAINS(readCameraProfiles(notProfiles), "other.json': expected a list 'noiseprofiles'");
    const std::string badMaker =
        writeText(dir, "maker.json", "{\"noiseprofiles\": [{\"maker\": 3, \"models\": []}]}\n");
    EXPECT_CV_ERROR_CONTAINS(readCameraProfiles(badMaker), "noiseprofiles[0]: a maker entry needs a string");
    DarktableImportParams wrong;
    wrong.haarVarianceRatio = 0;
    EXPECT_CV_ERROR_CONTAINS(readCameraProfiles(path, wrong), "haarVarianceRatio = 0 must lie in (0, 1]");
}

TEST(CameraProfiles, camerasAreFoundByNameAndAMissingOneListsTheClosest)
{
    const double c = DARKTABLE_HAAR_VARIANCE_RATIO;
    const std::vector<Vec3d> good = {Vec3d(100, c * 1e-4, c * 4e-8), Vec3d(200, c * 2e-4, c * 5e-8),
                                     Vec3d(400, c * 4e-4, c * 8e-8)};
    const std::vector<Vec3d> rough = {Vec3d(100, c * 1e-4, c * 4e-8), Vec3d(200, c * 3.6e-4, c * 5e-8),
                                      Vec3d(400, c * 4e-4, c * 8e-8)};
    const std::string dir = makeTempDir("camera_profiles_names");
    const std::string path =
        writeText(dir, "names.json",
                  profileFile("Nikon", {cameraEntry("D3", good), cameraEntry("D300", good),
                                        cameraEntry("D3S", rough), cameraEntry("Z 6", {good[0]})}));
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    EXPECT_EQ(findCameraProfile(cams, "  nikon   d3 ").model, "D3");
    EXPECT_CV_ERROR_CONTAINS(
        findCameraProfile(cams, "Nikon D3x"),
        "no camera named 'Nikon D3x' among 4 cameras; the closest are 'Nikon D3', 'Nikon D3S'");
    EXPECT_CV_ERROR_CONTAINS(findCameraProfile(cams, "Nikon Z 6"),
                             "'Nikon Z 6' is REFUSED: a single usable ISO");
    EXPECT_EQ(byModel(cams, "D3S").verdict, CAMERA_PROFILE_ROUGH);
    EXPECT_NE(byModel(cams, "D3S").reason.find("shot slope"), std::string::npos)
        << byModel(cams, "D3S").reason;

    EXPECT_EQ(selectCameraProfiles(cams, "good").size(), 2u);
    EXPECT_EQ(selectCameraProfiles(cams, "usable").size(), 3u);
    const std::vector<CameraNoiseProfile> listed = selectCameraProfiles(cams, "Nikon D300, nikon d3s");
    ASSERT_EQ(listed.size(), 2u);
    EXPECT_EQ(listed[1].model, "D3S");
    EXPECT_CV_ERROR_CONTAINS(selectCameraProfiles(cams, " , "), "names no camera");
    EXPECT_CV_ERROR_CONTAINS(selectCameraProfiles(cams, "Nikon D3, Canon X"), "no camera named 'Canon X'");
}

TEST(CameraProfiles, tinyAndDenormalShotSlopesAreRefusedNotFittedToNanOrZero)
{
    // A denormal green slope once made alpha NaN (judged GOOD: NaN passes every '>' bound), and a slope
    // of 1e-300 overflowed the fit's sums to alpha = 0 (a usable camera with no shot noise).
    const double c = DARKTABLE_HAAR_VARIANCE_RATIO;
    const std::string dir = makeTempDir("camera_profiles_tiny_slopes");
    std::vector<std::string> entries;
    const double tiny[] = {5e-324, 1e-310, 1e-300, 1e-13};
    for (int k = 0; k < 4; ++k)
        entries.push_back(cameraEntry(
            "T" + std::to_string(k),
            {Vec3d(100, tiny[k], c * 4e-8), Vec3d(200, c * 2e-4, c * 5e-8), Vec3d(400, c * 4e-4, c * 8e-8)}));
    entries.push_back(cameraEntry("Fine", {Vec3d(100, c * 1e-4, c * 4e-8), Vec3d(200, c * 2e-4, c * 5e-8),
                                           Vec3d(400, c * 4e-4, c * 8e-8)}));
    const std::vector<CameraNoiseProfile> cams =
        readCameraProfiles(writeText(dir, "tiny.json", profileFile("Tiny", entries)));
    for (int k = 0; k < 4; ++k) {
        const CameraNoiseProfile& cam = byModel(cams, "T" + std::to_string(k));
        EXPECT_EQ(CAMERA_PROFILE_REFUSED, cam.verdict) << cam.name() << ": " << cam.reason;
        EXPECT_NE(cam.reason.find("below 1e-12"), std::string::npos) << cam.reason;
    }
    EXPECT_EQ(CAMERA_PROFILE_GOOD, byModel(cams, "Fine").verdict) << byModel(cams, "Fine").reason;
    const std::vector<CameraNoiseProfile> good = selectCameraProfiles(cams, "good");
    ASSERT_EQ(1u, good.size());
    EXPECT_EQ("Fine", good[0].model);
}

TEST(CameraProfiles, aNameWithACommaIsSelectedAndControlCharactersAreRefusedShownEscaped)
{
    const double c = DARKTABLE_HAAR_VARIANCE_RATIO;
    const std::vector<Vec3d> good = {Vec3d(100, c * 1e-4, c * 4e-8), Vec3d(200, c * 2e-4, c * 5e-8),
                                     Vec3d(400, c * 4e-4, c * 8e-8)};
    const std::string dir = makeTempDir("camera_profiles_odd_names");
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(writeText(
        dir, "names.json",
        profileFile("Foo", {cameraEntry("X, Mark II", good), cameraEntry("X", good), cameraEntry("Y", good),
                            cameraEntry("Evil\\nInjected line", good), cameraEntry("Bell\\u0007", good)})));
    ASSERT_EQ(5u, cams.size());
    // Alone, in a list, and beside a camera whose name is its first piece.
    ASSERT_EQ(1u, selectCameraProfiles(cams, "Foo X, Mark II").size());
    EXPECT_EQ("X, Mark II", selectCameraProfiles(cams, "Foo X, Mark II")[0].model);
    const std::vector<CameraNoiseProfile> listed = selectCameraProfiles(cams, "Foo Y, Foo X, Mark II, Foo X");
    ASSERT_EQ(3u, listed.size());
    EXPECT_EQ("Y", listed[0].model);
    EXPECT_EQ("X, Mark II", listed[1].model);
    EXPECT_EQ("X", listed[2].model);
    EXPECT_EQ("X, Mark II", findCameraProfile(cams, "foo x, mark ii").model);
    // A newline or a bell in a name: kept escaped (one line in any listing), and the camera refused.
    for (const CameraNoiseProfile& cam : cams) {
        EXPECT_EQ(std::string::npos, cam.name().find_first_of("\n\a")) << cam.name();
    }
    EXPECT_EQ("Evil\\nInjected line", cams[3].model);
    EXPECT_EQ(CAMERA_PROFILE_REFUSED, cams[3].verdict);
    EXPECT_NE(cams[3].reason.find("1 control character"), std::string::npos) << cams[3].reason;
    EXPECT_EQ("Bell\\x07", cams[4].model);
    EXPECT_EQ(CAMERA_PROFILE_REFUSED, cams[4].verdict);
}

TEST(CameraProfiles, anAndroidProfileFileHoldsTheProfileAloneAndExportsKeepTheFailedMark)
{
    const std::string dir = makeTempDir("camera_profiles_android_root");
    const RawFormat format = fourteenBitFormat();
    NoiseModel model(0.42, 1.7, 3.1);
    const AndroidNoiseProfile android = androidNoiseProfile(model, format, 100);
    const std::string profile = cv::format(
        "android_noise_profile:\n   base_iso: 100\n   A: [%.17g, %.17g, %.17g, %.17g]\n   B: [0, 0, 0, 0]\n"
        "   C: [%.17g, %.17g, %.17g, %.17g]\n   D: [%.17g, %.17g, %.17g, %.17g]\n",
        android.A[0], android.A[1], android.A[2], android.A[3], android.C[0], android.C[1], android.C[2],
        android.C[3], android.D[0], android.D[1], android.D[2], android.D[3]);
    EXPECT_NO_THROW(loadAnyNoiseModel(writeText(dir, "alone.yml", profile), "", format));
    // A failed calibration's model beside it, or any other root key: an error naming the key.
    const std::string beside = writeText(dir, "beside.yml",
                                         "noise_model:\n   format_version: 1\n   alpha: 1\n   sigma_d2: 1\n"
                                         "   sigma_r2: 1\n   failed_calibration: \"fit\"\n" +
                                             profile);
    EXPECT_CV_ERROR_CONTAINS(loadAnyNoiseModel(beside, "", format), "unknown key 'noise_model'");
    EXPECT_CV_ERROR_CONTAINS(
        loadAnyNoiseModel(writeText(dir, "extra.yml", profile + "extra: 1\n"), "", format),
        "unknown key 'extra'");
    // Neither export has a place for the failed_calibration mark: a marked model is not exported.
    model.failedCalibration = "read noise: chi-square p = 1e-9";
    EXPECT_CV_ERROR_CONTAINS(androidNoiseProfile(model, format, 100), "marked failed_calibration");
    EXPECT_CV_ERROR_CONTAINS(darktableNoiseProfiles(model, format, 100, {100, 200}, "M", "C"),
                             "marked failed_calibration (read noise: chi-square p = 1e-9)");
}

TEST(CameraProfiles, cameraDrawsAreUniformAndAFunctionOfTheSeed)
{
    const int count = 7, draws = 70000;
    std::vector<int> hits(count, 0);
    for (int s = 0; s < draws; ++s) {
        const int k = drawCameraIndex(count, uint64(s));
        ASSERT_GE(k, 0);
        ASSERT_LT(k, count);
        ++hits[size_t(k)];
        ASSERT_EQ(k, drawCameraIndex(count, uint64(s)));
    }
    // Pearson's chi-square with 6 degrees of freedom: 22.46 is its 0.999 quantile, so a uniform draw
    // fails this one time in a thousand; a draw that favoured one camera by 5% would give about 40.
    double chi2 = 0;
    const double expected = double(draws) / count;
    for (int h : hits)
        chi2 += (h - expected) * (h - expected) / expected;
    EXPECT_LT(chi2, 22.46);
    EXPECT_EQ(drawCameraIndex(1, 12345), 0);
    EXPECT_CV_ERROR_CONTAINS(drawCameraIndex(0, 1), "0 cameras");
}

TEST(CameraProfiles, everyModelFileLoadsThroughOneCall)
{
    const std::string dir = makeTempDir("camera_profiles_any");
    const RawFormat format = fourteenBitFormat();
    const NoiseModel model(0.42, 1.7, 3.1);
    // Android's form, as rawgment_calibrate writes it.
    const AndroidNoiseProfile android = androidNoiseProfile(model, format, 100);
    const std::string yml = writeText(
        dir, "android_noise_profile.yml",
        cv::format(
            "%%YAML:1.0\n---\nandroid_noise_profile:\n   comment: \"x\"\n   base_iso: 100\n"
            "   A: [%.17g, %.17g, %.17g, %.17g]\n   B: [0, 0, 0, 0]\n   C: [%.17g, %.17g, %.17g, %.17g]\n"
            "   D: [%.17g, %.17g, %.17g, %.17g]\n",
            android.A[0], android.A[1], android.A[2], android.A[3], android.C[0], android.C[1], android.C[2],
            android.C[3], android.D[0], android.D[1], android.D[2], android.D[3]));
    const NoiseModel fromAndroid = loadAnyNoiseModel(yml, "", format);
    EXPECT_NEAR(fromAndroid.alpha, model.alpha, 1e-12);
    EXPECT_NEAR(fromAndroid.sigmaD2, model.sigmaD2, 1e-9);
    EXPECT_EQ(fromAndroid.baseIso, 100);
    // A NoiseModel file.
    NoiseModel withIso = model;
    withIso.baseIso = 200;
    withIso.save(dir + "/model.yml");
    EXPECT_EQ(loadAnyNoiseModel(dir + "/model.yml", "", format).baseIso, 200);
    // A darktable file needs a camera, and only it takes one.
    const std::string json = writeText(
        dir, "profiles.json", darktableNoiseProfiles(model, format, 100, {100, 800}, "Rawgment", "Sim"));
    EXPECT_EQ(noiseModelFileKind(yml), ANDROID_PROFILE_FILE);
    EXPECT_EQ(noiseModelFileKind(dir + "/model.yml"), NOISE_MODEL_FILE);
    EXPECT_EQ(noiseModelFileKind(json), DARKTABLE_PROFILE_FILE);
    EXPECT_NEAR(loadAnyNoiseModel(json, "rawgment sim", format).alpha, model.alpha, 1e-12);
    EXPECT_CV_ERROR_CONTAINS(loadAnyNoiseModel(json, "", format),
                             "is a darktable noise-profile file of many cameras");
    EXPECT_CV_ERROR_CONTAINS(loadAnyNoiseModel(yml, "Rawgment Sim", format),
                             "is not a darktable noise-profile file");
    const std::string broken =
        writeText(dir, "broken_android.yml",
                  "%YAML:1.0\n---\nandroid_noise_profile:\n   base_iso: 100\n   A: [1, 2]\n");
    EXPECT_CV_ERROR_CONTAINS(loadAnyNoiseModel(broken, "", format),
                             "broken_android.yml': field 'A' must be a list");
}

//! One profile of darktable's file as the file states it: green's a and b, straight from the JSON.
struct DarktableProfile
{
    std::string camera;
    double iso, a, b;
};

//! Every profile of darktable's file not marked skip, read here without the catalogue (the truth).
static std::vector<DarktableProfile> darktableGreenProfiles(const std::string& path)
{
    std::vector<DarktableProfile> out;
    FileStorage fs = openFileStorageForReading(path, "darktable noise profiles");
    for (const FileNode& maker : fs["noiseprofiles"])
        for (const FileNode& model : maker["models"])
            for (const FileNode& p : model["profiles"]) {
                if (!p["skip"].empty() && p["skip"].isInt() && int(p["skip"]) != 0)
                    continue;
                out.push_back({std::string(maker["maker"]) + " " + std::string(model["model"]),
                               double(p["iso"]), double(p["a"][1]), double(p["b"][1])});
            }
    return out;
}

static double quantile(std::vector<double> v, double q)
{
    std::sort(v.begin(), v.end());
    return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

TEST(CameraProfiles, everyUsableCameraIsAugmentedWithTheLinesDarktableMeasured)
{
    const std::string path = darktableProfilesPath();
    if (path.empty())
        GTEST_SKIP() << "darktable's noiseprofiles.json not found (run scripts/fetch-darktable-profiles.sh)";
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    std::map<std::string, const CameraNoiseProfile*> byName;
    for (const CameraNoiseProfile& c : cams)
        byName[c.name()] = &c;
    const RawFormat format = fourteenBitFormat();
    const double r = format.whiteLevel - format.blackLevel[0], c = DARKTABLE_HAAR_VARIANCE_RATIO;
    // The slope the augmentation uses at each measured ISO against darktable's a / c, and Eq. 5's.
    std::vector<double> measured, eq5;
    std::map<std::string, NoiseModel> models;
    for (const DarktableProfile& p : darktableGreenProfiles(path)) {
        const auto cam = byName.find(p.camera);
        if (cam == byName.end() || !cam->second->usable() || !(p.a > 0))
            continue;
        if (!models.count(p.camera))
            models[p.camera] = cam->second->modelFor(format);
        const NoiseModel& m = models[p.camera];
        NoiseModel summary = m;
        summary.measuredLines.clear();
        const double g = p.iso / m.baseIso, truth = p.a / c * r;
        measured.push_back(std::abs(m.lineAtGain(g).a / truth - 1));
        eq5.push_back(std::abs(summary.lineAtGain(g).a / truth - 1));
    }
    ASSERT_GT(measured.size(), 3000u);
    std::cout << "[ info ] " << measured.size() << " measured ISOs of " << models.size()
              << " usable cameras: the augmentation's slope against darktable's a / c, median "
              << 100 * quantile(measured, 0.5) << "%, 90th percentile " << 100 * quantile(measured, 0.9)
              << "% (Eq. 5 alone: " << 100 * quantile(eq5, 0.5) << "%, " << 100 * quantile(eq5, 0.9)
              << "%)\n";
    // The bounds; only an ISO that darktable measured twice with two lines leaves 0.
    EXPECT_LE(quantile(measured, 0.5), 0.02);
    EXPECT_LE(quantile(measured, 0.9), 0.05);
    // The bound of the lines is 5%: Eq. 5 alone must miss it, or this test would not tell them apart.
    EXPECT_GT(quantile(eq5, 0.9), 0.05) << "Eq. 5 alone meets the lines' bound";
}

TEST(CameraProfiles, expandedLowIsosAreNamedAndNeverTheBaseIso)
{
    const std::string dir = makeTempDir("camera_profiles_expanded");
    // Slopes of a full well of 40k electrons at ISO 100: an analog ladder, and the same with ISO 50 and 80
    // reusing ISO 100's raw (its slope) as expanded settings do.
    const double a100 = 1.0 / 40000 * DARKTABLE_HAAR_VARIANCE_RATIO, b = 1e-8;
    const std::vector<Vec3d> analog = {
        {100, a100, b}, {200, 2 * a100, b}, {400, 4 * a100, 2 * b}, {800, 8 * a100, 5 * b}};
    std::vector<Vec3d> withExpanded = {{50, a100, b}, {80, a100, b}};
    withExpanded.insert(withExpanded.end(), analog.begin(), analog.end());
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(writeText(
        dir, "p.json",
        profileFile("Test", {cameraEntry("analog", analog), cameraEntry("expanded", withExpanded)})));
    const CameraNoiseProfile &plain = byModel(cams, "analog"), &expanded = byModel(cams, "expanded");
    EXPECT_EQ(0, plain.expandedIsos);
    EXPECT_EQ(100.0, plain.noise.baseIso);
    EXPECT_EQ(2, expanded.expandedIsos);
    EXPECT_EQ(100.0, expanded.noise.baseIso) << "an expanded setting is never the base ISO";
    ASSERT_EQ(6u, expanded.isos.size());
    EXPECT_TRUE(expanded.isos[0].expanded && expanded.isos[1].expanded && !expanded.isos[2].expanded);
    EXPECT_EQ(0.5, expanded.isos[0].gain);
    // Left out of the fit: the expanded camera is fitted exactly as the analog one, and judged on it.
    EXPECT_EQ(plain.noise.alpha, expanded.noise.alpha);
    EXPECT_EQ(plain.verdict, expanded.verdict);
    EXPECT_EQ(plain.worstSlopeResidual, expanded.worstSlopeResidual);
    // Measured all the same: the augmentation follows ISO 50's line.
    const NoiseModel m = expanded.modelFor(fourteenBitFormat());
    EXPECT_NEAR(m.lineAtGain(0.5).a, m.lineAtGain(1).a, 1e-12 * m.lineAtGain(1).a);

    const std::string path = darktableProfilesPath();
    if (path.empty())
        GTEST_SKIP() << "darktable's noiseprofiles.json not found (run scripts/fetch-darktable-profiles.sh)";
    const std::vector<CameraNoiseProfile> real = readCameraProfiles(path);
    // Two cameras whose expanded settings are documented: the EOS 5D Mark III's L (ISO 50, whose profile in
    // the file has a negative blue slope, as have its third stops: inconsistent, never the base ISO either)
    // and the Nikon D3's Lo 1 to Lo 0.3 (ISO 100 to 160, written 100, 126 and 159 in the file).
    const CameraNoiseProfile& canon = findCameraProfile(real, "Canon EOS 5D Mark III");
    EXPECT_EQ(100.0, canon.noise.baseIso);
    EXPECT_EQ(7, canon.inconsistentProfiles) << "ISO 50, 160, 320, 640, 1250, 2500 and 5000";
    EXPECT_TRUE(canon.isos.front().inconsistent && !canon.isos.front().fitted());
    const NoiseModel canonModel = canon.modelFor(fourteenBitFormat());
    EXPECT_EQ(100.0, canonModel.measuredLines.front().iso) << "an inconsistent profile is no measured line";
    const CameraNoiseProfile& nikon = findCameraProfile(real, "Nikon D3");
    EXPECT_EQ(200.0, nikon.noise.baseIso);
    EXPECT_EQ(3, nikon.expandedIsos);
    int camerasWithExpanded = 0;
    for (const CameraNoiseProfile& cam : real)
        camerasWithExpanded += cam.expandedIsos > 0;
    std::cout << "[ info ] " << camerasWithExpanded << " of " << real.size()
              << " cameras have expanded low ISOs\n";
}

TEST(CameraProfiles, digitalSettingsAreNamedWithTheirRawIsoAndNotFitted)
{
    const std::string dir = makeTempDir("camera_profiles_digital");
    // A full well of 40k electrons at ISO 100 in third stops; in "pulled", ISO 160 and 320 have the slope of
    // 200 and 400 (their raw scaled with its white level, as Canon's third stops), in "pushed" ISO 4000 and
    // 5000 keep the raw of 3200 (as Fujifilm's high settings).
    const double a100 = 1.0 / 40000 * DARKTABLE_HAAR_VARIANCE_RATIO, b = 1e-8;
    std::vector<Vec3d> analog, pulled, pushed;
    for (double iso : {100.0, 125.0, 160.0, 200.0, 250.0, 320.0, 400.0, 500.0}) {
        analog.push_back(Vec3d(iso, a100 * iso / 100, b));
        const double raw = iso == 160 ? 200 : iso == 320 ? 400 : iso;
        pulled.push_back(Vec3d(iso, a100 * raw / 100, b));
    }
    for (double iso : {800.0, 1600.0, 3200.0, 4000.0, 5000.0})
        pushed.push_back(Vec3d(iso, a100 * std::min(iso, 3200.0) / 100, b * iso / 800));
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(
        writeText(dir, "p.json",
                  profileFile("Test", {cameraEntry("analog", analog), cameraEntry("pulled", pulled),
                                       cameraEntry("pushed", pushed)})));
    const CameraNoiseProfile &plain = byModel(cams, "analog"), &pull = byModel(cams, "pulled"),
                             &push = byModel(cams, "pushed");
    EXPECT_EQ(0, plain.digitalIsos) << "an analog ladder in thirds has no digital setting";
    ASSERT_EQ(2, pull.digitalIsos);
    for (const CameraIsoFit& f : pull.isos) {
        SCOPED_TRACE(cv::format("ISO %g", f.iso));
        EXPECT_EQ(f.rawIso, f.iso == 160 ? 200.0 : f.iso == 320 ? 400.0 : 0.0);
        EXPECT_EQ(f.fitted(), !f.digital());
    }
    // Left out, the digital settings leave Eq. 5 the analog ladder's alpha, exactly.
    EXPECT_NEAR(pull.noise.alpha, plain.noise.alpha, 1e-12 * plain.noise.alpha);
    EXPECT_EQ(pull.verdict, CAMERA_PROFILE_GOOD) << pull.reason;
    // Followed as measured all the same: ISO 160's line is ISO 200's slope.
    const NoiseModel m = pull.modelFor(fourteenBitFormat());
    EXPECT_NEAR(m.lineAtGain(1.6).a, m.lineAtGain(2).a, 1e-12 * m.lineAtGain(2).a);
    ASSERT_EQ(2, push.digitalIsos);
    EXPECT_EQ(3200.0, push.isos[3].rawIso);
    EXPECT_EQ(3200.0, push.isos[4].rawIso);
    EXPECT_EQ(800.0, push.noise.baseIso);

    const std::string path = darktableProfilesPath();
    if (path.empty())
        GTEST_SKIP() << "darktable's noiseprofiles.json not found (run scripts/fetch-darktable-profiles.sh)";
    const std::vector<CameraNoiseProfile> real = readCameraProfiles(path);
    // The Canon EOS M5's third stops 160, 320 and 640 are 200, 400 and 800 with the white level lowered
    // (their slopes differ by 3%, 0.2% and 1.9% from those ISOs' in the file).
    const CameraNoiseProfile& m5 = findCameraProfile(real, "Canon EOS M5");
    std::map<double, double> rawOf;
    for (const CameraIsoFit& f : m5.isos)
        rawOf[f.iso] = f.rawIso;
    EXPECT_EQ(200.0, rawOf[160]);
    EXPECT_EQ(400.0, rawOf[320]);
    EXPECT_EQ(800.0, rawOf[640]);
    EXPECT_EQ(0.0, rawOf[200]);
    EXPECT_EQ(0.0, rawOf[125]);
    EXPECT_EQ(100.0, m5.noise.baseIso);
    int camerasWithDigital = 0;
    for (const CameraNoiseProfile& cam : real)
        camerasWithDigital += cam.digitalIsos > 0;
    std::cout << "[ info ] " << camerasWithDigital << " of " << real.size()
              << " cameras have digital settings\n";
}

//! A camera entry whose red and blue slopes are the green slope times `ratios`.
static std::string colouredEntry(const std::string& model, const std::vector<double>& isos, Vec2d ratios)
{
    const double a100 = 1.0 / 40000 * DARKTABLE_HAAR_VARIANCE_RATIO, b = 1e-8;
    std::string text = "{\"model\": \"" + model + "\", \"profiles\": [";
    for (size_t k = 0; k < isos.size(); ++k) {
        const double a = a100 * isos[k] / 100;
        text +=
            cv::format("%s{\"name\": \"p\", \"iso\": %g, \"a\": [%.17g, %.17g, %.17g], \"b\": [%g, %g, %g]}",
                       k ? ", " : "", isos[k], a * ratios[0], a, a * ratios[1], b, b, b);
    }
    return text + "]}";
}

TEST(CameraProfiles, theDemosaicIsJudgedFromTheColourSlopeRatios)
{
    const std::string dir = makeTempDir("camera_profiles_demosaic");
    const std::vector<double> isos = {100, 200, 400, 800};
    // The lines of python/tools/darktable_haar_ratio.py --demosaics 4: on grey PPG gives 1.23, RCD 1.55.
    const std::vector<CameraNoiseProfile> cams =
        readCameraProfiles(writeText(dir, "d.json",
                                     profileFile("Test", {colouredEntry("copies", isos, Vec2d(1, 1)),
                                                          colouredEntry("ppg", isos, Vec2d(2.1, 1.3)),
                                                          colouredEntry("neither", isos, Vec2d(1.05, 1.9)),
                                                          colouredEntry("both", isos, Vec2d(2.2, 1.8))})));
    const CameraNoiseProfile& copies = byModel(cams, "copies");
    EXPECT_EQ(PROFILE_DEMOSAIC_UNDECIDED, copies.demosaic);
    EXPECT_NE(copies.demosaicReason.find("copies of green"), String::npos) << copies.demosaicReason;
    const CameraNoiseProfile& ppg = byModel(cams, "ppg");
    EXPECT_EQ(PROFILE_DEMOSAIC_PPG, ppg.demosaic) << ppg.demosaicReason;
    EXPECT_NE(ppg.demosaicReason.find("blue would be brighter than green"), String::npos)
        << ppg.demosaicReason;
    EXPECT_LT(ppg.balanceRcd[1], 1);
    EXPECT_EQ(PROFILE_DEMOSAIC_NEITHER, byModel(cams, "neither").demosaic);
    const CameraNoiseProfile& both = byModel(cams, "both");
    EXPECT_EQ(PROFILE_DEMOSAIC_UNDECIDED, both.demosaic);
    EXPECT_NEAR(both.colourSlopeRatios[0], 2.2, 1e-12);
    EXPECT_NEAR(both.balancePpg[0], (2.2 - 0.284) / 0.946, 1e-12);
    EXPECT_NEAR(both.balanceRcd[1], (1.8 - 0.592) / 0.962, 1e-12);
    for (const CameraNoiseProfile& cam : cams)
        EXPECT_EQ(DARKTABLE_HAAR_VARIANCE_RATIO, cam.haarVarianceRatio);
    DarktableImportParams rcd;
    rcd.haarVarianceRatio = DARKTABLE_RCD_HAAR_VARIANCE_RATIO;
    const std::vector<CameraNoiseProfile> asRcd = readCameraProfiles(dir + "/d.json", rcd);
    EXPECT_EQ(DARKTABLE_RCD_HAAR_VARIANCE_RATIO, asRcd[0].haarVarianceRatio);
    // RCD's smaller c makes every variance larger by the ratio of the two, so alpha (1 / full well) too.
    EXPECT_NEAR(asRcd[0].noise.alpha / copies.noise.alpha,
                DARKTABLE_HAAR_VARIANCE_RATIO / DARKTABLE_RCD_HAAR_VARIANCE_RATIO, 1e-9);

    const std::string path = darktableProfilesPath();
    if (path.empty())
        GTEST_SKIP() << "darktable's noiseprofiles.json not found (run scripts/fetch-darktable-profiles.sh)";
    std::map<int, int> counts;
    for (const CameraNoiseProfile& cam : readCameraProfiles(path))
        if (cam.usable()) {
            ++counts[cam.demosaic];
            EXPECT_FALSE(cam.demosaicReason.empty()) << cam.name();
        }
    std::cout << "[ info ] demosaic of the usable cameras' profiles: " << counts[PROFILE_DEMOSAIC_PPG]
              << " PPG, " << counts[PROFILE_DEMOSAIC_UNDECIDED] << " undecided, "
              << counts[PROFILE_DEMOSAIC_NEITHER] << " neither\n";
    EXPECT_GT(counts[PROFILE_DEMOSAIC_PPG], 0);
    EXPECT_GT(counts[PROFILE_DEMOSAIC_UNDECIDED], 0);
}

/* Flat frames as a real camera: a capture at the lowest ISO (half of the range), taken to every measured
 * ISO at 0.45 of the range by an exposure change with the prior accounted, has the variance darktable
 * measured there, (a x + b) / c in DN at its mean. 256 x 256 pixels: the spatial variance's standard error is
 * sqrt(2 / 65536) = 0.55%, 5 of them 2.8%. ISOs with a negative offset are left out: the model takes
 * it as 0 (a variance), which differs from the line by |b| / c at any level; so are inconsistent profiles,
 * which the model does not follow. */
TEST(CameraProfiles, flatFramesAugmentedAsARealCameraHaveTheVarianceDarktableMeasured)
{
    const std::string path = darktableProfilesPath();
    if (path.empty())
        GTEST_SKIP() << "darktable's noiseprofiles.json not found (run scripts/fetch-darktable-profiles.sh)";
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    const RawFormat format = fourteenBitFormat();
    const double r = format.whiteLevel - format.blackLevel[0];
    const Size size(256, 256);
    const double tolerance = 5 * std::sqrt(2.0 / (size.area() - 1));
    int tested = 0, camera = 0, tooNoisy = 0;
    for (const CameraNoiseProfile& cam : cams) {
        // The example and every 25th usable camera.
        if (!cam.usable() || (cam.name() != "Canon EOS 5D Mark III" && camera++ % 25 != 0))
            continue;
        SensorParams params;
        params.noise = cam.modelFor(format);
        params.pattern = format.pattern;
        params.blackLevel = format.blackLevel;
        params.bitDepth = 14;
        params.quantize = false;
        const SensorSimulator sensor(params, size);
        Mat base;
        // At the camera's lowest ISO, expanded or not: every other ISO then adds noise (below it, the
        // target would have less noise than the prior, which an augmentation cannot remove).
        const double lowest = cam.isos.front().gain;
        sensor.capture(Mat(size, CV_32FC1, Scalar(0.5 * r / lowest)), lowest, 1.0, 7, 0, base);
        for (const CameraIsoFit& f : cam.isos) {
            if (f.offset < 0 || f.inconsistent)
                continue;
            SCOPED_TRACE(cam.name() + cv::format(" at ISO %g", f.iso));
            // Every ISO's flat at 0.45 of the range, where it is at least 5 standard deviations from black
            // and white (clipping would cut the variance); the noisiest settings that are not are skipped.
            const double level = 0.45 * r, spread = std::sqrt(f.slope * r * level + f.offset * r * r);
            if (level - 5 * spread < -format.blackLevel[0] || level + 5 * spread > r) {
                ++tooNoisy;
                continue;
            }
            const double gainRatio = f.gain / lowest, factor = 0.9 / gainRatio;
            Mat out;
            RawFormat outFormat;
            colorJitter(base, sensor.rawFormat(lowest), params.noise,
                        ColorJitter::exposureChange(factor, gainRatio), NoiseAlignment::ACCOUNT_PRIOR,
                        100 + tested, out, outFormat);
            Mat x;
            subtractBlackLevel(out, outFormat, x);
            Scalar mean, sd;
            meanStdDev(x, mean, sd);
            const double variance = sd[0] * sd[0] * size.area() / (size.area() - 1.0);
            // darktable's own line at this ISO (the catalogue keeps a / c and b / c of a range of 1).
            const double expected = f.slope * r * mean[0] + f.offset * r * r;
            EXPECT_NEAR(variance / expected, 1.0, tolerance) << "mean " << mean[0];
            ++tested;
        }
    }
    std::cout << "[ info ] " << tested << " measured ISOs of flat frames within 5 standard errors; "
              << tooNoisy << " too noisy to stay clear of black and white\n";
    EXPECT_GT(tested, 100);
}

TEST(CameraProfiles, everyCameraOfDarktablesFileImportsOrIsRefusedWithAReason)
{
    const std::string path = darktableProfilesPath();
    if (path.empty()) {
        // CI runs the install script, which puts the file in place: there it must be found.
        const char* ci = std::getenv("CI");
        ASSERT_FALSE(ci && *ci) << "darktable's noiseprofiles.json is missing in CI (scripts/install-deps.sh "
                                   "fetches it)";
        GTEST_SKIP() << "darktable's noiseprofiles.json not found (run scripts/fetch-darktable-profiles.sh)";
    }
    const auto start = std::chrono::steady_clock::now();
    const std::vector<CameraNoiseProfile> cams = readCameraProfiles(path);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Debian 12's darktable 4.2.1 has 374; a later darktable has more.
    ASSERT_GE(cams.size(), 374u);
    std::map<int, int> verdicts;
    const RawFormat format = fourteenBitFormat();
    for (const CameraNoiseProfile& cam : cams) {
        ++verdicts[cam.verdict];
        SCOPED_TRACE(cam.name() + " at " + cam.place);
        EXPECT_FALSE(cam.maker.empty());
        if (!cam.usable()) {
            EXPECT_FALSE(cam.reason.empty());
            continue;
        }
        EXPECT_GE(cam.isos.size(), 2u);
        for (double v : {cam.noise.alpha, cam.noise.sigmaD2, cam.noise.sigmaR2, cam.worstSlopeResidual,
                         cam.worstOffsetResidual, cam.medianColourSpread})
            EXPECT_TRUE(std::isfinite(v));
        EXPECT_GT(cam.noise.alpha, 0);
        EXPECT_GE(cam.noise.sigmaD2, 0);
        EXPECT_GE(cam.noise.sigmaR2, 0);
        const NoiseModel m = cam.modelFor(format);
        EXPECT_NO_THROW(m.validate());
        // Every ISO's modelled variance at mid-grey is finite and positive.
        for (const CameraIsoFit& f : cam.isos)
            EXPECT_GT(m.variance(4000, f.gain), 0);
    }
    std::cout << "[ info ] " << cams.size() << " cameras in " << seconds
              << " s: " << verdicts[CAMERA_PROFILE_GOOD] << " GOOD, " << verdicts[CAMERA_PROFILE_ROUGH]
              << " ROUGH, " << verdicts[CAMERA_PROFILE_REFUSED] << " REFUSED\n";
    // Most of darktable's cameras are usable: a change that refused them wholesale would be a regression.
    EXPECT_GT(verdicts[CAMERA_PROFILE_GOOD] + verdicts[CAMERA_PROFILE_ROUGH], int(cams.size()) * 9 / 10);
}

} // namespace test
} // namespace rawgment
} // namespace cv
