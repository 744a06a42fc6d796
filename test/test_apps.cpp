// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// End-to-end tests of the apps: each one run as a user runs it, on small inputs.
#include "app_runs.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace {

using namespace rawgment_app_tests;

TEST(Apps, everyAppHasHelpAndRejectsBadArguments)
{
    for (const char* app :
         {"rawgment_demo", "rawgment_simulate", "rawgment_calibrate", "rawgment_validate", "rawgment_augment",
          "rawgment_tradeoffs", "rawgment_cameras", "rawgment_convert"}) {
        const AppRun help = runApp(app, "--help");
        EXPECT_EQ(0, help.status) << app;
        EXPECT_NE(std::string::npos, help.output.find(app)) << app << " --help:\n" << help.output;
    }
    EXPECT_EQ(2, runApp("rawgment_simulate", "").status) << "--out is required";
    const AppRun badList = runApp("rawgment_simulate", "--out=/nonexistent/x --gains=6,x");
    EXPECT_NE(0, badList.status);
    EXPECT_NE(std::string::npos, badList.output.find("'x' in '6,x' is not a number")) << badList.output;
    EXPECT_EQ(2, runApp("rawgment_calibrate", "").status);
    EXPECT_EQ(2, runApp("rawgment_calibrate", "m.yml --out=/tmp/x --method=magic").status);
    EXPECT_EQ(
        2,
        runApp("rawgment_augment", "--model=m.yml --scene=s.yml --policy=p.yml --out=/tmp/x in.dng").status)
        << "a scene and a policy at once";
    const AppRun missing = runApp("rawgment_calibrate", "/nonexistent/manifest.yml --out=/tmp/never");
    EXPECT_EQ(1, missing.status);
    EXPECT_NE(std::string::npos, missing.output.find("no such file")) << missing.output;
}

TEST(Apps, unknownOrMalformedOptionsAreErrorsNamingThem)
{
    // cv::CommandLineParser ignores what it does not know: every app checks its command line first.
    const struct
    {
        const char* app;
        const char* args;
        const char* says;
    } cases[] = {
        {"rawgment_demo", "--bogus=3", "unknown option '--bogus=3'"},
        {"rawgment_simulate", "--out=/nonexistent/x --frames=abc", "'--frames': 'abc' is not a number"},
        {"rawgment_augment", "--model m.yml --scene=s.yml --out=/nonexistent/y a.dng",
         "'--model' needs a value"},
        {"rawgment_calibrate", "m.yml --out=/nonexistent/z --plots=maybe", "'--plots' is true or false"},
        {"rawgment_validate", "m.yml --modle=x.yml --out=/nonexistent/v", "unknown option '--modle=x.yml'"},
        {"rawgment_tradeoffs", "--out=/nonexistent/t --quik", "unknown option '--quik'"},
    };
    for (const auto& c : cases) {
        const AppRun r = runApp(c.app, c.args);
        EXPECT_EQ(2, r.status) << c.app << " " << c.args << "\n" << r.output;
        EXPECT_NE(std::string::npos, r.output.find(c.says)) << c.app << ": " << r.output;
        EXPECT_NE(std::string::npos, r.output.find("valid options: --help")) << r.output;
    }
}

TEST(Apps, badManifestsAreErrorsNamingTheKeyOrTheFile)
{
    const std::string dir = freshDir("manifest_keys");
    std::ofstream(dir + "/m.yml") << "%YAML:1.0\ncalibration_manifest:\n  patchs: detect\n"
                                  << "  bursts:\n    - { gain_db: 6, files: [a.dng] }\n";
    AppRun r = runApp("rawgment_calibrate", "'" + dir + "/m.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos,
              r.output.find("unknown key 'patchs' (valid keys: patches, base_iso, bursts)"))
        << r.output;
    std::ofstream(dir + "/twice.yml") << "%YAML:1.0\ncalibration_manifest:\n  bursts:\n"
                                      << "    - { gain_db: 6, files: [a.dng, b.dng, a.dng] }\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/twice.yml' --out='" + dir + "/cal3'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("a.dng' is listed twice")) << r.output;
    std::ofstream(dir + "/b.yml")
        << "%YAML:1.0\ncalibration_manifest:\n  bursts:\n    - { gain: 6, files: [a.dng] }\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/b.yml' --out='" + dir + "/cal2'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("unknown key 'gain'")) << r.output;
    std::ofstream(dir + "/dark.yml")
        << "%YAML:1.0\ncalibration_manifest:\n  bursts:\n    - { dark: maybe, files: [a.dng] }\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/dark.yml' --out='" + dir + "/cal4'");
    EXPECT_NE(std::string::npos, r.output.find("'dark' must be true or false")) << r.output;
    std::ofstream(dir + "/iso.yml") << "%YAML:1.0\ncalibration_manifest:\n  base_iso: -100\n  bursts:\n"
                                    << "    - { files: [a.dng] }\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/iso.yml' --out='" + dir + "/cal5'");
    EXPECT_NE(std::string::npos, r.output.find("'base_iso' must be a number in [1, 1e+07]")) << r.output;
    for (const char* iso : {"1e300", "1e-300"}) {
        std::ofstream(dir + "/iso.yml") << "%YAML:1.0\ncalibration_manifest:\n  base_iso: " << iso
                                        << "\n  bursts:\n    - { files: [a.dng] }\n";
        r = runApp("rawgment_calibrate", "'" + dir + "/iso.yml' --out='" + dir + "/cal5'");
        EXPECT_NE(std::string::npos, r.output.find("'base_iso' must be a number in [1, 1e+07]")) << r.output;
    }
    // A mosaic that does not say its ISO needs a gain_db when other bursts have a gain.
    {
        cv::rawgment::MosaicMetadata meta;
        for (const char* name : {"/u0.png", "/u1.png", "/u2.png", "/u3.png"})
            cv::rawgment::writeMosaic(dir + name, cv::Mat(16, 16, CV_16UC1, cv::Scalar(500)), meta);
    }
    std::ofstream(dir + "/noiso.yml") << "%YAML:1.0\ncalibration_manifest:\n  patches: none\n  bursts:\n"
                                      << "    - { files: [u0.png, u1.png] }\n"
                                      << "    - { gain_db: 6, files: [u2.png, u3.png] }\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/noiso.yml' --out='" + dir + "/cal6'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("u0.png' does not say its ISO: give this burst a gain_db"))
        << r.output;
    // A word where a number belongs was read as 0 (gain 0 dB, factor 0) before the manifest had a reader.
    cv::rawgment::NoiseModel(1, 1, 1).save(dir + "/model.yml");
    const auto validate = [&](const std::string& fields, const std::string& target, const char* expected) {
        std::ofstream(dir + "/v.yml", std::ios::trunc)
            << "%YAML:1.0\nvalidation_manifest:\n"
            << fields << "  bright: [a.dng]\n  targets:\n    - { " << target << ", files: [b.dng] }\n";
        const AppRun v = runApp("rawgment_validate", "'" + dir + "/v.yml' --model='" + dir +
                                                         "/model.yml' --out='" + dir + "/val'");
        EXPECT_EQ(1, v.status) << v.output;
        EXPECT_NE(std::string::npos, v.output.find(expected)) << v.output;
    };
    validate("  gain_db: twelve\n", "factor: 0.5", "'gain_db' must be a finite number");
    validate("", "factor: half", "target 1: 'factor' must be a number in (0, 1]");
}

TEST(Apps, unusableValuesAreRefusedAndFailedRunsLeaveNoEmptyFolder)
{
    const std::string dir = freshDir("refusals");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir + "/two' --frames=2");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("at least 3 frames")) << r.output;
    EXPECT_FALSE(exists(dir + "/two")) << "a failed run leaves no empty output folder";
    EXPECT_EQ(2, runApp("rawgment_calibrate", "m.yml --out='" + dir + "/c' --shapiro=-10").status);
    r = runApp("rawgment_calibrate", "'" + dir + "/missing.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_FALSE(exists(dir + "/cal")) << "a failed run leaves no empty output folder";
    std::ofstream(dir + "/model.yml")
        << "%YAML:1.0\nnoise_model: {format_version: 1, alpha: 1, sigma_d2: 1, sigma_r2: 1}\n";
    std::ofstream(dir + "/scene.yml")
        << "%YAML:1.0\nscene: {contrast: [1, 1, 1, 1], brightness: 0, gain_ratio: 1}\n";
    r = runApp("rawgment_augment", "--model='" + dir + "/model.yml' --scene='" + dir + "/scene.yml' --out='" +
                                       dir + "/aug' '" + dir + "'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("is not a file")) << r.output;
}

TEST(Apps, simulateResumesOnlyTheSameJobAndKeepsGainsApart)
{
    const std::string dir = freshDir("simulate_job");
    const std::string base = "--frames=3 --levels=0.5 --format=png --validation=false ";
    // An interrupted run (its manifest not yet written) is resumed by the same command...
    AppRun r = runApp("rawgment_simulate", base + "--gains=6 --out='" + dir + "/a'");
    ASSERT_EQ(0, r.status) << r.output;
    for (const char* f : {"manifest.yml", "truth_noise_model.yml", "patches.yml"})
        std::remove((dir + "/a/" + f).c_str());
    r = runApp("rawgment_simulate", base + "--gains=6 --out='" + dir + "/a'");
    EXPECT_EQ(0, r.status) << r.output;
    // ...and refused by another one, whose truth would not match the frames left there.
    for (const char* f : {"manifest.yml", "truth_noise_model.yml", "patches.yml"})
        std::remove((dir + "/a/" + f).c_str());
    r = runApp("rawgment_simulate", base + "--gains=6 --alpha=2 --out='" + dir + "/a'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("describes another simulation")) << r.output;
    // 12 and 12.4 dB used to share one folder (g12dB): now g12dB and g12.40dB.
    r = runApp("rawgment_simulate", base + "--gains=12,12.4 --out='" + dir + "/b'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_TRUE(exists(dir + "/b/g12dB_level0.50/frame_002.png"));
    EXPECT_TRUE(exists(dir + "/b/g12.40dB_level0.50/frame_002.png"));
    r = runApp("rawgment_simulate", base + "--gains=12.001,12.004 --out='" + dir + "/c'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("share the folder")) << r.output;
}

TEST(Apps, aRunRemovesTheTemporariesThatKilledRunsLeft)
{
    const std::string dir = freshDir("interrupts");
    // A temporary that a killed run (a pid that is gone) left is removed by the next run in that folder.
    pid_t gone = 4194000;
    while (::kill(gone, 0) == 0 || errno != ESRCH)
        --gone;
    std::ofstream(dir + "/manifest.yml.tmp-" + std::to_string(gone) + "-0") << "half a file";
    AppRun r =
        runApp("rawgment_simulate", "--out='" + dir + "' --frames=3 --gains=6 --levels=0.5 --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("removed 1 temporary file(s)")) << r.output;
    EXPECT_FALSE(exists(dir + "/manifest.yml.tmp-" + std::to_string(gone) + "-0"));
}

TEST(Apps, aRunStoppedWhileAPlotIsDrawnLeavesNoScriptBehind)
{
    // SIGINT while gnuplot ran left "<plot>.gp.<pid>.run" in the output folder. The run is stopped the
    // moment it has a gnuplot running on a plot script (a child process whose command line names one),
    // and nothing but finished files may stay.
    const std::string dir = freshDir("interrupted_plot");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir +
                                               "/sim' --frames=4 --gains=6,18 --levels=0.5 "
                                               "--format=png --validation=false");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string out = dir + "/cal", manifest = dir + "/sim/manifest.yml";
    const std::string app = std::string(RAWGMENT_APP_DIR) + "/rawgment_calibrate";
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        ::freopen("/dev/null", "w", stdout);
        ::freopen("/dev/null", "w", stderr);
        ::execl(app.c_str(), app.c_str(), manifest.c_str(), ("--out=" + out).c_str(),
                static_cast<char*>(nullptr));
        ::_exit(127);
    }
    const auto plotting = [&] {
        std::ifstream children("/proc/" + std::to_string(child) + "/task/" + std::to_string(child) +
                               "/children");
        for (std::string pid; children >> pid;) {
            // A process that just ended has no command line to read: read() fails, the text stays empty.
            std::string command(4096, '\0');
            const int fd = ::open(("/proc/" + pid + "/cmdline").c_str(), O_RDONLY);
            const ssize_t got = fd < 0 ? 0 : ::read(fd, &command[0], command.size());
            if (fd >= 0)
                ::close(fd);
            command.resize(got > 0 ? size_t(got) : 0);
            if (command.find("gnuplot") != std::string::npos &&
                command.find("--version") == std::string::npos)
                return true;
        }
        return false;
    };
    const auto start = std::chrono::steady_clock::now();
    bool sawScript = false;
    while (!sawScript && std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
        sawScript = plotting();
        int status = 0;
        if (!sawScript && ::waitpid(child, &status, WNOHANG) == child)
            FAIL() << "the run ended before its first plot";
    }
    ::kill(child, SIGINT);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(sawScript);
    for (const auto& entry : std::filesystem::directory_iterator(out)) {
        const std::string name = entry.path().filename().string();
        EXPECT_EQ(std::string::npos, name.find(".run")) << name;
        EXPECT_EQ(std::string::npos, name.find(".tmp-")) << name;
    }
}

TEST(Apps, anOutputFolderThatCannotBeWrittenIsRefusedBeforeAnyWork)
{
    const std::string dir = freshDir("unwritable");
    const AppRun sim =
        runApp("rawgment_simulate", "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --format=png");
    ASSERT_EQ(0, sim.status) << sim.output;
    // Root writes through permission bits: a read-only tmpfs is the folder root cannot write.
    const std::string locked = dir + "/locked";
    ASSERT_EQ(0, ::mkdir(locked.c_str(), 0755));
    bool mounted = false;
    if (::geteuid() == 0) {
        if (::mount("tmpfs", locked.c_str(), "tmpfs", MS_RDONLY, "size=64k") != 0)
            GTEST_SKIP() << "a read-only tmpfs cannot be mounted here: " << std::strerror(errno);
        mounted = true;
    } else {
        ASSERT_EQ(0, ::chmod(locked.c_str(), 0555));
    }
    const AppRun calibrate =
        runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + locked + "'");
    cv::rawgment::RandomScenePolicy().save(dir + "/policy.yml");
    const AppRun augment =
        runApp("rawgment_augment", "--model='" + dir + "/sim/truth_noise_model.yml' --policy='" + dir +
                                       "/policy.yml' --out='" + locked + "' '" + dir +
                                       "/sim/g06dB_level0.50/frame_000.png'");
    if (mounted)
        ::umount(locked.c_str());
    for (const auto& run :
         {std::make_pair("calibrate [", &calibrate), std::make_pair("augment [", &augment)}) {
        const AppRun& r = *run.second;
        EXPECT_NE(0, r.status) << r.output;
        EXPECT_NE(std::string::npos, r.output.find("the output folder '" + locked + "' cannot be written"))
            << r.output;
        // Refused before the work: no progress bar was drawn.
        EXPECT_EQ(std::string::npos, r.output.find(run.first)) << r.output;
    }
}

TEST(Apps, simulateHonoursTheSeedInEveryBurst)
{
    // Every burst, the validation bursts included, derives its seed from --seed: the same seed gives the
    // same bytes, another seed other noise.
    const std::string dir = freshDir("seeds");
    const auto simulate = [&](const std::string& name, int seed) {
        const AppRun r =
            runApp("rawgment_simulate",
                   "--out='" + dir + "/" + name +
                       "' --frames=3 --gains=6 --levels=0.5 --format=png --seed=" + std::to_string(seed));
        EXPECT_EQ(0, r.status) << r.output;
    };
    simulate("a", 5);
    simulate("b", 5);
    simulate("c", 6);
    for (const char* frame : {"g06dB_level0.50/frame_000.png", "validation/bright/frame_000.png",
                              "validation/x0.10/frame_001.png"}) {
        const std::string a = readText(dir + "/a/" + frame);
        ASSERT_FALSE(a.empty()) << frame;
        EXPECT_EQ(a, readText(dir + "/b/" + frame)) << frame << ": same seed, other bytes";
        EXPECT_NE(a, readText(dir + "/c/" + frame)) << frame << ": another seed, the same bytes";
    }
}

TEST(Apps, validateRefusesFramesOfAnotherSizeNamingTheFiles)
{
    // Target frames smaller than the bright ones were read out of bounds (ASan: heap-buffer-overflow).
    const std::string dir = freshDir("validate_sizes");
    for (const char* run : {"big --patch=40", "small --patch=20"}) {
        const std::string name(run, std::string(run).find(' '));
        const AppRun r =
            runApp("rawgment_simulate", "--out='" + dir + "/" + name + "' --frames=3 --gains=12 " +
                                            "--levels=0.5 --format=png " + (std::strchr(run, ' ') + 1));
        ASSERT_EQ(0, r.status) << r.output;
    }
    std::ofstream(dir + "/mixed.yml")
        << "%YAML:1.0\nvalidation_manifest:\n  gain_db: 12\n"
        << "  bright: [big/validation/bright/frame_000.png, "
           "big/validation/bright/frame_001.png]\n"
        << "  targets:\n    - { factor: 0.5, files: [small/validation/x0.50/frame_000.png, "
           "small/validation/x0.50/frame_001.png] }\n";
    const AppRun r =
        runApp("rawgment_validate", "'" + dir + "/mixed.yml' --model='" + dir +
                                        "/big/truth_noise_model.yml' --out='" + dir + "/val' --plots=false");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("small/validation/x0.50/frame_000.png")) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("one size and type")) << r.output;
}

TEST(Apps, simulateCalibrateValidateAugmentEndToEnd)
{
    const std::string dir = freshDir("pipeline");
    // 1. Simulate. 32 frames keep the test short and still pin the model (tolerances below).
    AppRun r = runApp("rawgment_simulate", "--out='" + dir + "/sim' --frames=32 --seed=5");
    ASSERT_EQ(0, r.status) << r.output;
    ASSERT_TRUE(exists(dir + "/sim/manifest.yml"));
    ASSERT_TRUE(exists(dir + "/sim/validation_manifest.yml"));
    r = runApp("rawgment_simulate", "--out='" + dir + "/sim' --frames=32 --seed=5");
    EXPECT_EQ(1, r.status) << "a second run must not overwrite the first";
    EXPECT_NE(std::string::npos, r.output.find("already exists")) << r.output;

    // 2. Calibrate.
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    ASSERT_EQ(0, r.status) << r.output;
    const cv::rawgment::NoiseModel truth = cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
    const cv::rawgment::NoiseModel fitted = cv::rawgment::NoiseModel::load(dir + "/cal/noise_model.yml");
    // The joint fit's spread over seeds at 100 frames is 0.08% / 0.45% / 1.7% (docs/performance.md,
    // study_calibration); a variance of 32 frames is sqrt(99/31) = 1.8x noisier. The bounds are about 5 of
    // those spreads.
    EXPECT_NEAR(truth.alpha, fitted.alpha, 0.01 * truth.alpha);
    EXPECT_NEAR(truth.sigmaD2, fitted.sigmaD2, 0.04 * truth.sigmaD2);
    EXPECT_NEAR(truth.sigmaR2, fitted.sigmaR2, 0.15 * truth.sigmaR2);
    for (const char* f : {"calibration_report.yml", "samples.csv", "lines.csv", "shapiro.csv"})
        EXPECT_TRUE(exists(dir + "/cal/" + f)) << f;
    for (const char* png :
         {"calib_mean_variance.png", "calib_histograms.png", "calib_cross_gain.png", "shapiro_pvalue.png"})
        expectPngDecodes(dir + "/cal/" + png);
    const std::string modelBefore = readText(dir + "/cal/noise_model.yml");
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status);
    EXPECT_EQ(modelBefore, readText(dir + "/cal/noise_model.yml"))
        << "an existing output is never overwritten";
    // A run that died before its plots and its last table is completed by the same command.
    std::remove((dir + "/cal/shapiro_pvalue.png").c_str());
    std::remove((dir + "/cal/variance_ratio_histogram.csv").c_str());
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(0, r.status) << r.output;
    expectPngDecodes(dir + "/cal/shapiro_pvalue.png");
    EXPECT_TRUE(exists(dir + "/cal/variance_ratio_histogram.csv"));
    EXPECT_EQ(modelBefore, readText(dir + "/cal/noise_model.yml"));
    // ...but never over an output that is not what it computes.
    std::remove((dir + "/cal/shapiro_pvalue.png").c_str());
    std::ofstream(dir + "/cal/lines.csv") << "not these lines\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_EQ("not these lines\n", readText(dir + "/cal/lines.csv"));

    // 2b. The same bursts with the patches detected by cv::mcc (the sample's method) instead of given.
    std::string manifest = readText(dir + "/sim/manifest.yml");
    const size_t at = manifest.find("patches.yml");
    ASSERT_NE(std::string::npos, at);
    manifest.replace(at - 1, std::string("\"patches.yml\"").size(), "detect");
    {
        std::ofstream f(dir + "/sim/manifest_detect.yml");
        f << manifest;
    }
    r = runApp("rawgment_calibrate",
               "'" + dir + "/sim/manifest_detect.yml' --side=12 --plots=false --out='" + dir + "/cal_detect'",
               AllocationStacks::FULL);
    ASSERT_EQ(0, r.status) << r.output << manifest;
    EXPECT_NE(std::string::npos, r.output.find("patches detected with cv::mcc")) << r.output;
    // A quarter of the pixels of the given squares: alpha still within 2% (about 5 of its spreads).
    EXPECT_NEAR(truth.alpha, cv::rawgment::NoiseModel::load(dir + "/cal_detect/noise_model.yml").alpha,
                0.02 * truth.alpha);

    // 3. Validate: ACCOUNT_PRIOR matches the real darker bursts, IGNORE_PRIOR overshoots, NONE undershoots.
    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/cal/noise_model.yml' --out='" + dir + "/val'");
    ASSERT_EQ(0, r.status) << r.output;
    expectPngDecodes(dir + "/val/validation.png");
    std::istringstream csv(readText(dir + "/val/validation.csv"));
    std::string line;
    std::getline(csv, line);
    double real = 0, none = 0, ignore = 0, account = 0;
    int rows = 0;
    while (std::getline(csv, line)) {
        std::vector<double> v;
        std::stringstream cells(line);
        std::string cell;
        while (std::getline(cells, cell, ','))
            v.push_back(std::stod(cell));
        ASSERT_EQ(11u, v.size()) << line;
        if (v[0] != 0.5)
            continue;
        real += v[5];
        none += v[6];
        ignore += v[7];
        account += v[8];
        ++rows;
    }
    ASSERT_GT(rows, 3);
    // Pooled over ~10k pixels x 31 degrees of freedom the ratio's noise is far below 1%; 3% allows for the
    // model error of a 32-frame calibration. The prior noise of the x0.5 conversion is half the target's
    // signal noise, so IGNORE_PRIOR lands ~1.5x high and NONE ~0.5x low.
    EXPECT_NEAR(1.0, account / real, 0.03);
    EXPECT_GT(ignore / real, 1.3);
    EXPECT_LT(none / real, 0.7);

    // 4. Augment two inputs twice each with a fixed scene; a second run resumes (skips everything).
    writeExposureScene(dir + "/scene.yml", 0.25, 2.0);
    const std::string in0 = dir + "/sim/g06dB_level0.90/frame_000.dng",
                      in1 = dir + "/sim/g06dB_level0.90/frame_001.dng";
    const std::string inputBytes = readText(in0);
    const std::string args = "--model='" + dir + "/cal/noise_model.yml' --scene='" + dir +
                             "/scene.yml' --out='" + dir + "/aug' --variants=2 --preview=true '" + in0 +
                             "' '" + in1 + "'";
    r = runApp("rawgment_augment", args);
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 4 outputs")) << r.output;
    cv::Mat out;
    const cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(dir + "/aug/frame_000_v01.dng", out);
    EXPECT_NEAR(2.0 * cv::rawgment::dbToLinearGain(6), meta.format.gain, 1e-9)
        << "the new gain is in the sidecar";
    EXPECT_TRUE(meta.hasScene);
    expectPngDecodes(dir + "/aug/frame_001_v00_preview.png");
    r = runApp("rawgment_augment", args);
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("skipped 4")) << r.output;
    EXPECT_EQ(inputBytes, readText(in0)) << "inputs are never modified";
}

TEST(Apps, augmentKeepsInputsWithOneStemApartAndNeverTakesAnotherInputsOutput)
{
    // a/frame_000 and b/frame_000 used to race for one output name, so that one input's image could end
    // up with the other's sidecar and a rerun "skipped" an input that was never augmented.
    const std::string dir = freshDir("augment_stems");
    AppRun r =
        runApp("rawgment_simulate", "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    writeExposureScene(dir + "/scene.yml", 0.5, 1.0);
    const std::string a = dir + "/sim/g06dB_level0.50/frame_000.png",
                      b = dir + "/sim/validation/bright/frame_000.png";
    const std::string common =
        "--model='" + dir + "/sim/truth_noise_model.yml' --scene='" + dir + "/scene.yml' ";
    // The first input of a stem takes the stem, a later one the stem and a hash of its path.
    const auto hashed = [](const std::string& f) {
        return "frame_000-" + cv::format("%08llx", static_cast<unsigned long long>(
                                                       cv::rawgment::augmentedOutputSeed(0, f, 0) >> 32));
    };
    r = runApp("rawgment_augment",
               common + "--out='" + dir + "/both' --preview=true '" + a + "' '" + b + "'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 2 outputs")) << r.output;
    for (const auto& [f, name] :
         {std::make_pair(a, std::string("frame_000")), std::make_pair(b, hashed(b))}) {
        cv::Mat out;
        EXPECT_EQ(f, cv::rawgment::readMosaic(dir + "/both/" + name + "_v00.png", out).source)
            << "each output carries its own input's sidecar";
        expectPngDecodes(dir + "/both/" + name + "_v00_preview.png");
    }
    r = runApp("rawgment_augment",
               common + "--out='" + dir + "/both' --preview=true '" + b + "' '" + a + "'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("skipped 2")) << r.output << " (in another order too)";

    // One stem at a time into one folder: b is neither "skipped" on a's output nor renames it.
    r = runApp("rawgment_augment", common + "--out='" + dir + "/single' '" + a + "'");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_augment", common + "--out='" + dir + "/single' '" + b + "'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_TRUE(exists(dir + "/single/frame_000_v00.png") &&
                exists(dir + "/single/" + hashed(b) + "_v00.png"));
    r = runApp("rawgment_augment", common + "--out='" + dir + "/single' '" + a + "' '" + b + "'");
    EXPECT_NE(std::string::npos, r.output.find("skipped 2")) << r.output;
    // Outputs named as versions before 0.2 named every input of a shared stem (hashed, with the seeds of
    // those names) are recognised and skipped: a third input's output held the stem while a and b were
    // augmented, then went.
    const std::string c = dir + "/c/frame_000.png";
    ASSERT_EQ(
        0,
        std::system(("mkdir -p '" + dir + "/c' && cp '" + a + "' '" + a + ".yml' '" + dir + "/c/'").c_str()));
    ASSERT_EQ(0, runApp("rawgment_augment", common + "--out='" + dir + "/old' '" + c + "'").status);
    r = runApp("rawgment_augment", common + "--out='" + dir + "/old' '" + a + "' '" + b + "'");
    ASSERT_TRUE(exists(dir + "/old/" + hashed(a) + "_v00.png") &&
                exists(dir + "/old/" + hashed(b) + "_v00.png"))
        << r.output;
    ASSERT_EQ(
        0, std::system(
               ("rm '" + dir + "/old/frame_000_v00.png' '" + dir + "/old/frame_000_v00.png.yml'").c_str()));
    r = runApp("rawgment_augment", common + "--out='" + dir + "/old' '" + a + "' '" + b + "'");
    EXPECT_NE(std::string::npos, r.output.find("skipped 2")) << r.output;
    EXPECT_FALSE(exists(dir + "/old/frame_000_v00.png"));
    EXPECT_EQ(1, runApp("rawgment_augment", common + "--out='" + dir + "/x' '" + a + "' '" + a + "'").status)
        << "the same input twice";

    // A preview that is not this job's is never replaced.
    std::ofstream(dir + "/single/frame_000_v01_preview.png") << "not a preview";
    r = runApp("rawgment_augment",
               common + "--out='" + dir + "/single' --variants=2 --preview=true '" + a + "'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_EQ("not a preview", readText(dir + "/single/frame_000_v01_preview.png"));
}

TEST(Apps, twoIdenticalRunsIntoOneFolderBothFinishWithCompletePairs)
{
    // Both runs exited 1 in 13 of 15 tries and left an image without its sidecar: the process whose image
    // write lost the race removed the sidecar it had made, on which the winner's image depended, and every
    // rerun then refused the folder. The same job's files are now each run's output.
    const std::string dir = freshDir("augment_race");
    AppRun r =
        runApp("rawgment_simulate",
               "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    std::string inputs;
    for (int f = 0; f < 3; ++f)
        inputs += cv::format(" '%s/sim/g06dB_level0.50/frame_%03d.png'", dir.c_str(), f);
    for (int attempt = 0; attempt < 15; ++attempt) {
        const std::string out = dir + "/out" + std::to_string(attempt);
        const std::string run = std::string(RAWGMENT_APP_DIR) + "/rawgment_augment --model='" + dir +
                                "/sim/truth_noise_model.yml' --scene='" + dir +
                                "/scene.yml' --variants=4 --out='" + out + "'" + inputs;
        const std::string both = "(" + run + " > '" + dir + "/log1' 2>&1; echo $? > '" + dir +
                                 "/status1') & (" + run + " > '" + dir + "/log2' 2>&1; echo $? > '" + dir +
                                 "/status2') & wait";
        ASSERT_EQ(0, std::system(both.c_str()));
        EXPECT_EQ("0\n", readText(dir + "/status1")) << readText(dir + "/log1");
        EXPECT_EQ("0\n", readText(dir + "/status2")) << readText(dir + "/log2");
        int images = 0;
        for (const auto& entry : std::filesystem::directory_iterator(out)) {
            const std::string path = entry.path().string();
            const bool sidecar = path.size() > 4 && path.compare(path.size() - 4, 4, ".yml") == 0;
            if (sidecar)
                EXPECT_TRUE(exists(path.substr(0, path.size() - 4))) << path << " has no image";
            else if (path.find(".tmp-") == std::string::npos) {
                EXPECT_TRUE(exists(path + ".yml")) << path << " has no sidecar";
                ++images;
            }
        }
        EXPECT_EQ(12, images) << out;
    }
}

TEST(Apps, augmentPreviewsAreBrightenedBackAndOutputsKeepTheCaptureTags)
{
    // A darkening scene's preview shows its noise at the input's brightness (as the demo's gallery does),
    // not a dark frame; the output's sidecar and DNG state the capture it simulates.
    const std::string dir = freshDir("augment_preview");
    AppRun r = runApp("rawgment_simulate",
                      "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string input = dir + "/sim/g06dB_level0.50/frame_000.dng";
    const std::string model = "--model='" + dir + "/sim/truth_noise_model.yml' ";
    std::map<double, double> previewMean;
    for (double photons : {1.0, 0.125}) {
        const std::string tag = cv::format("x%g", photons);
        {
            cv::rawgment::Scene scene;
            scene.jitter = cv::rawgment::ColorJitter::exposureChange(photons, 2.0);
            cv::FileStorage fs(dir + "/" + tag + ".yml", cv::FileStorage::WRITE);
            scene.write(fs, "scene");
        }
        r = runApp("rawgment_augment", model + "--scene='" + dir + "/" + tag + ".yml' --out='" + dir + "/" +
                                           tag + "' --preview=true '" + input + "'");
        ASSERT_EQ(0, r.status) << r.output;
        const cv::Mat preview = cv::imread(dir + "/" + tag + "/frame_000_v00_preview.png");
        ASSERT_FALSE(preview.empty());
        previewMean[photons] = cv::mean(preview)[1];

        cv::Mat out;
        const cv::rawgment::MosaicMetadata meta =
            cv::rawgment::readMosaic(dir + "/" + tag + "/frame_000_v00.dng", out);
        ASSERT_TRUE(meta.hasCamera);
        // The input's sidecar has the exact tags; its DNG the ISO rounded to an integer and the exposure
        // time as a rational (LibRaw gives it back as a float: 1e-7 relative).
        cv::Mat inMosaic;
        const cv::rawgment::CameraTags in = cv::rawgment::readMosaic(input, inMosaic).camera;
        const cv::rawgment::RawImage inDng = cv::rawgment::readRaw(input),
                                     dng = cv::rawgment::readRaw(dir + "/" + tag + "/frame_000_v00.dng");
        EXPECT_EQ(inDng.iso, 200) << "rawgment_simulate writes ISO 100 g (g = 6 dB, rounded)";
        EXPECT_NEAR(in.iso, 100 * cv::rawgment::dbToLinearGain(6), 1e-9);
        EXPECT_NEAR(meta.camera.iso, in.iso * 2, 1e-9);
        EXPECT_EQ(dng.iso, std::round(in.iso * 2));
        EXPECT_NEAR(meta.camera.exposureTime, in.exposureTime * photons, 1e-15);
        EXPECT_NEAR(dng.exposureTime, in.exposureTime * photons, 1e-6 * in.exposureTime);
        EXPECT_EQ(dng.make, "cv::rawgment");
        EXPECT_EQ(dng.model, "simulated sensor");
        EXPECT_EQ(dng.noiseProfile,
                  cv::rawgment::dngNoiseProfile(
                      cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml"), meta.format));
    }
    // Unbrightened, x0.125 would be about 0.125^(1/2.2) = 39% of the x1 preview's mean; brightened back it
    // is the same scene with more noise, whose mean the tone curve's curvature moves by a few percent.
    EXPECT_NEAR(previewMean[0.125], previewMean[1.0], 0.1 * previewMean[1.0]);
}

TEST(Apps, augmentTakesACameraFilesGainFromItsIsoAndTheModelsBaseIso)
{
    // A user's camera file (no sidecar) at ISO 200, and models of that camera whose gain 1 is ISO 100 (as
    // rawgment_simulate's truth says, and rawgment_calibrate writes from ISO-tagged files) or unknown.
    const std::string dir = freshDir("augment_iso");
    AppRun r = runApp("rawgment_simulate",
                      "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false");
    ASSERT_EQ(0, r.status) << r.output;
    ASSERT_EQ(0, ::mkdir((dir + "/camera").c_str(), 0755));
    {
        std::ifstream in(dir + "/sim/g06dB_level0.50/frame_000.dng", std::ios::binary);
        std::ofstream out(dir + "/camera/shot.dng", std::ios::binary);
        out << in.rdbuf();
        ASSERT_TRUE(out.good());
    }
    const cv::rawgment::NoiseModel withBase =
        cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
    EXPECT_EQ(100.0, withBase.baseIso);
    cv::rawgment::NoiseModel withoutBase = withBase;
    withoutBase.baseIso = 0;
    withoutBase.save(dir + "/no_base.yml");
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    // ISO 200 over base ISO 100: the input is at gain 2 and the output at 4; the ISO tag is the input's
    // times the gain ratio. Without a base ISO the input's gain is unknown: refused, not taken at gain 1.
    r = runApp("rawgment_augment", "--model='" + dir + "/no_base.yml' --scene='" + dir +
                                       "/scene.yml' --out='" + dir + "/out_no_base' '" + dir +
                                       "/camera/shot.dng'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("the noise model has no base ISO")) << r.output;
    for (const auto& c : {std::make_pair(std::string("/sim/truth_noise_model.yml"), 4.0)}) {
        const std::string out = dir + "/out" + std::to_string(int(c.second));
        r = runApp("rawgment_augment", "--model='" + dir + c.first + "' --scene='" + dir +
                                           "/scene.yml' --out='" + out + "' '" + dir + "/camera/shot.dng'");
        ASSERT_EQ(0, r.status) << r.output;
        cv::Mat mosaic;
        const cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(out + "/shot_v00.dng", mosaic);
        EXPECT_DOUBLE_EQ(c.second, meta.format.gain) << c.first;
        EXPECT_DOUBLE_EQ(400.0, meta.camera.iso) << c.first;
        EXPECT_EQ(cv::rawgment::readRaw(out + "/shot_v00.dng").noiseProfile,
                  cv::rawgment::dngNoiseProfile(withBase, meta.format))
            << c.first;
    }
}

/* rawgment_convert: a camera file and a mosaic with its sidecar into .npy, the same pixels, format and tags;
 * the camera file's conversion augments to the same bytes as the camera file (its gain from its ISO); a
 * second run skips; an output holding another input is never overwritten. */
TEST(Apps, convertWritesNpyThatAugmentsAsItsSource)
{
    const std::string dir = freshDir("convert");
    AppRun r =
        runApp("rawgment_simulate",
               "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5 --validation=false --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_simulate",
               "--out='" + dir + "/dng' --frames=3 --gains=6 --levels=0.5 --validation=false");
    ASSERT_EQ(0, r.status) << r.output;
    ASSERT_EQ(0, ::mkdir((dir + "/camera").c_str(), 0755));
    {
        std::ifstream in(dir + "/dng/g06dB_level0.50/frame_000.dng", std::ios::binary);
        std::ofstream out(dir + "/camera/shot.dng", std::ios::binary);
        out << in.rdbuf();
        ASSERT_TRUE(out.good());
    }
    const std::string png = dir + "/sim/g06dB_level0.50/frame_001.png", camera = dir + "/camera/shot.dng";
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + png + "' '" + camera + "'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 2 files, skipped 0")) << r.output;
    cv::Mat fromPng, pngMosaic, fromCamera;
    const cv::rawgment::MosaicMetadata pngMeta =
        cv::rawgment::readMosaic(dir + "/npy/frame_001.npy", fromPng);
    const cv::rawgment::MosaicMetadata original = cv::rawgment::readMosaic(png, pngMosaic);
    EXPECT_EQ(0, cv::norm(fromPng, pngMosaic, cv::NORM_INF));
    EXPECT_EQ(original.format.gain, pngMeta.format.gain);
    EXPECT_FALSE(pngMeta.gainFromIso) << "a mosaic with a sidecar keeps its gain";
    EXPECT_EQ(png, pngMeta.source);
    const cv::rawgment::MosaicMetadata cameraMeta =
        cv::rawgment::readMosaic(dir + "/npy/shot.npy", fromCamera);
    const cv::rawgment::RawImage raw = cv::rawgment::readRaw(camera);
    EXPECT_EQ(0, cv::norm(fromCamera, raw.mosaic, cv::NORM_INF));
    EXPECT_TRUE(cameraMeta.gainFromIso && cameraMeta.hasCamera);
    EXPECT_EQ(raw.iso, cameraMeta.camera.iso);
    // The same augmentation of the camera file and of its conversion: the same pixels and gain.
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    const std::string model = dir + "/dng/truth_noise_model.yml";
    for (const char* input : {"/camera/shot.dng", "/npy/shot.npy"}) {
        r = runApp("rawgment_augment", "--model='" + model + "' --scene='" + dir +
                                           "/scene.yml' --format=npy --out='" + dir + "/aug" +
                                           std::string(input).substr(1, 3) + "' '" + dir + input + "'");
        ASSERT_EQ(0, r.status) << r.output;
    }
    cv::Mat a, b;
    const cv::rawgment::MosaicMetadata ma = cv::rawgment::readMosaic(dir + "/augcam/shot_v00.npy", a);
    const cv::rawgment::MosaicMetadata mb = cv::rawgment::readMosaic(dir + "/augnpy/shot_v00.npy", b);
    EXPECT_EQ(0, cv::norm(a, b, cv::NORM_INF));
    EXPECT_DOUBLE_EQ(ma.format.gain, mb.format.gain);
    EXPECT_DOUBLE_EQ(4.0, mb.format.gain) << "ISO 200 over the model's base ISO 100, times 2";
    // Again: nothing to do. Another input with the same output name: an error, the output untouched.
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + png + "' '" + camera + "'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 0 files, skipped 2")) << r.output;
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + dir + "/sim/g06dB_level0.50/frame_000.png'");
    EXPECT_EQ(0, r.status) << r.output;
    // Another input of an existing output's name takes the name and a hash; the existing one is untouched.
    const std::string other = dir + "/dng/g06dB_level0.50/frame_001.dng";
    const std::string before = readText(dir + "/npy/frame_001.npy.yml");
    r = runApp("rawgment_convert", "--out='" + dir + "/npy' '" + other + "'");
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_EQ(before, readText(dir + "/npy/frame_001.npy.yml"));
    EXPECT_TRUE(exists(dir + "/npy/frame_001-" +
                       cv::format("%08llx", static_cast<unsigned long long>(
                                                cv::rawgment::augmentedOutputSeed(0, other, 0) >> 32)) +
                       ".npy"));
    EXPECT_EQ(2, runApp("rawgment_convert", "--out='" + dir + "/x' --format=jpg '" + png + "'").status);
    // A folder: its files (not its sidecars), each converted.
    r = runApp("rawgment_convert", "--out='" + dir + "/folder' '" + dir + "/sim/g06dB_level0.50'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 3 files, skipped 0")) << r.output;
    EXPECT_TRUE(exists(dir + "/folder/frame_002.npy") && exists(dir + "/folder/frame_002.npy.yml"));
    r = runApp("rawgment_convert", "--out='" + dir + "/folder' '" + dir + "/sim/g06dB_level0.50'");
    EXPECT_NE(std::string::npos, r.output.find("wrote 0 files, skipped 3")) << r.output;
    // Into the input folder itself: a rerun over it would take the outputs for inputs (it converted them
    // again, growing on every run), so it is refused before anything is written.
    r = runApp("rawgment_convert", "--out='" + dir + "/camera' '" + dir + "/camera'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("lies in the output folder")) << r.output;
    EXPECT_FALSE(exists(dir + "/camera/shot.npy"));
    r = runApp("rawgment_augment", "--model='" + model + "' --scene='" + dir + "/scene.yml' --out='" + dir +
                                       "/camera' '" + camera + "'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("lies in the output folder")) << r.output;
}

TEST(Apps, augmentAsRealCamerasDrawsOnePerOutputAndRecordsIt)
{
    // A darktable file of two cameras (the project's own exports, joined), an Android profile, and the
    // catalogue app over the file.
    const std::string dir = freshDir("augment_cameras");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir + "/sim' --frames=3 --gains=6 --levels=0.5");
    ASSERT_EQ(0, r.status) << r.output;
    cv::rawgment::RawFormat format;
    format.blackLevel = cv::Vec4d(64, 64, 64, 64);
    format.whiteLevel = 4095;
    const auto modelsOf = [&](const cv::rawgment::NoiseModel& m, const std::string& name) {
        const std::string text =
            cv::rawgment::darktableNoiseProfiles(m, format, 100, {100, 400, 1600}, "Maker", name);
        const size_t from = text.find("{\n          \"model\"");
        const size_t to = text.rfind("      ]\n    }\n  ]");
        return text.substr(from, to - from);
    };
    {
        std::ofstream out(dir + "/noiseprofiles.json");
        out << "{\"version\": 0, \"noiseprofiles\": [{\"maker\": \"Maker\", \"models\": [\n"
            << modelsOf(cv::rawgment::NoiseModel(0.3, 0.05, 0.2), "Quiet") << ",\n"
            << modelsOf(cv::rawgment::NoiseModel(0.3, 2.0, 30.0), "Loud") << "]}]}\n";
        ASSERT_TRUE(out.good());
    }
    writeExposureScene(dir + "/scene.yml", 0.5, 2.0);
    const std::string input = "'" + dir + "/sim/g06dB_level0.50/frame_000.dng'";
    const std::string common = " --scene='" + dir + "/scene.yml' " + input;
    r = runApp("rawgment_augment", "--model='" + dir +
                                       "/noiseprofiles.json' --camera=usable --variants=8 --out='" + dir +
                                       "/out'" + common);
    ASSERT_EQ(0, r.status) << r.output;
    std::set<std::string> cameras;
    for (int v = 0; v < 8; ++v) {
        cv::Mat mosaic;
        const cv::rawgment::MosaicMetadata meta =
            cv::rawgment::readMosaic(dir + cv::format("/out/frame_000_v%02d.dng", v), mosaic);
        cameras.insert(meta.noiseCamera);
    }
    EXPECT_EQ(cameras, (std::set<std::string>{"Maker Loud", "Maker Quiet"}));
    // The same run again gives the same cameras and bytes (a second folder, compared file by file).
    r = runApp("rawgment_augment", "--model='" + dir +
                                       "/noiseprofiles.json' --camera=usable --variants=8 --out='" + dir +
                                       "/again'" + common);
    ASSERT_EQ(0, r.status) << r.output;
    for (int v = 0; v < 8; ++v)
        EXPECT_EQ(readText(dir + cv::format("/out/frame_000_v%02d.dng", v)),
                  readText(dir + cv::format("/again/frame_000_v%02d.dng", v)));

    r = runApp("rawgment_augment", "--model='" + dir + "/noiseprofiles.json' --out='" + dir + "/x'" + common);
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("choose with --camera")) << r.output;
    r = runApp("rawgment_augment", "--model='" + dir + "/noiseprofiles.json' --camera='Maker Lod' --out='" +
                                       dir + "/x'" + common);
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos,
              r.output.find("no camera named 'Maker Lod' among 2 cameras; the closest are 'Maker "
                            "Loud'"))
        << r.output;
    r = runApp("rawgment_augment", "--model='" + dir +
                                       "/sim/truth_noise_model.yml' --camera='Maker Loud' --out='" + dir +
                                       "/x'" + common);
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("is not one")) << r.output;

    // The validation takes a camera too, made at the bright burst's levels.
    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/noiseprofiles.json' --camera='Maker Quiet' --plots=false --out='" +
                                        dir + "/val'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, readText(dir + "/val/validation.md").find("ACCOUNT_PRIOR"));
    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/noiseprofiles.json' --plots=false --out='" + dir + "/val2'");
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("darktable noise-profile file of many cameras")) << r.output;

    // The catalogue and one camera's table.
    r = runApp("rawgment_cameras", "--profiles='" + dir + "/noiseprofiles.json'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("Maker Quiet")) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("2 of 2 cameras listed")) << r.output;
    r = runApp("rawgment_cameras", "--profiles='" + dir + "/noiseprofiles.json' --camera='maker loud'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("Maker Loud (noiseprofiles[0].models[1]): GOOD")) << r.output;
    r = runApp("rawgment_cameras", "--profiles='" + dir + "/noiseprofiles.json' --verdict=best");
    EXPECT_EQ(1, r.status);
    EXPECT_NE(std::string::npos, r.output.find("--verdict must be")) << r.output;
    r = runApp("rawgment_cameras",
               "--profiles='" + dir + "/noiseprofiles.json' --report='" + dir + "/report'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, readText(dir + "/report/report.md").find("2 GOOD, 0 ROUGH, 0 REFUSED"));
    expectPngDecodes(dir + "/report/real_cameras_slope.png");
}

TEST(Apps, calibrateTakesTheGainsFromTheFilesIsoWithOrWithoutAChart)
{
    // A user's own camera: DNG bursts that carry their ISO, no gain_db anywhere, no sidecars (so every
    // number comes from the files as LibRaw reads them). Gains 2, 4 and 16 give integer ISOs 200, 400
    // and 1600, which the DNG holds exactly.
    const std::string dir = freshDir("calibrate_iso");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir +
                                               "/sim' --frames=16 --gains=6.0206,12.0412,24.0824 "
                                               "--levels=0.2,0.65 --dark=true --validation=false --seed=9");
    ASSERT_EQ(0, r.status) << r.output;
    const cv::rawgment::NoiseModel truth = cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
    std::ostringstream files;
    std::vector<std::string> folders;
    for (const char* gain : {"6.02", "12.04", "24.08"})
        for (const char* level : {"0.20", "0.65"}) {
            const std::string folder = cv::format("g%sdB_level%s", gain, level);
            folders.push_back(folder);
            files << "    - files: [";
            for (int t = 0; t < 16; ++t) {
                ASSERT_EQ(
                    0,
                    std::remove(
                        cv::format("%s/sim/%s/frame_%03d.dng.yml", dir.c_str(), folder.c_str(), t).c_str()));
                files << (t ? ", " : "") << cv::format("sim/%s/frame_%03d.dng", folder.c_str(), t);
            }
            files << "]\n";
        }
    for (const char* dark : {"dark_g6.02dB", "dark_g12.04dB", "dark_g24.08dB"})
        for (int t = 0; t < 16; ++t)
            ASSERT_EQ(0,
                      std::remove(cv::format("%s/sim/%s/frame_%03d.dng.yml", dir.c_str(), dark, t).c_str()));
    std::ofstream(dir + "/chart.yml") << "%YAML:1.0\ncalibration_manifest:\n  patches: sim/patches.yml\n"
                                      << "  base_iso: 100\n  bursts:\n"
                                      << files.str();
    std::ofstream(dir + "/chartless.yml") << "%YAML:1.0\ncalibration_manifest:\n  patches: none\n"
                                          << "  base_iso: 100\n  bursts:\n"
                                          << files.str();
    // Spreads measured over seeds 1-8 of this very simulation (16 frames; rawgment_simulate --seed=S, then
    // rawgment_calibrate on its manifest, with and without patches: none): with the chart, alpha 0.16%,
    // sigma_d^2 0.65%, sigma_r^2 11.7%; without a chart (twice the pixels, seeds 1-4) alpha 0.1%,
    // sigma_d^2 0.2%, sigma_r^2 3.9%. sigma_r^2 is a small part of every offset here (0.9 of 6.9 DN^2 at
    // the lowest gain), hence its spread. The bounds are about 4 of those spreads.
    const auto expectTruth = [&](const cv::rawgment::NoiseModel& fitted, double scale, double sigmaR2Bound,
                                 const std::string& what) {
        EXPECT_NEAR(fitted.alpha, truth.alpha * scale, 0.01 * truth.alpha * scale) << what;
        EXPECT_NEAR(fitted.sigmaD2, truth.sigmaD2 * scale * scale, 0.03 * truth.sigmaD2 * scale * scale)
            << what;
        EXPECT_NEAR(fitted.sigmaR2, truth.sigmaR2, sigmaR2Bound * truth.sigmaR2) << what;
    };
    for (const char* mode : {"chart", "chartless"}) {
        r = runApp("rawgment_calibrate",
                   "'" + dir + "/" + mode + ".yml' --out='" + dir + "/cal_" + mode + "' --plots=false");
        ASSERT_EQ(0, r.status) << r.output;
        EXPECT_NE(std::string::npos, r.output.find("verdict: PASS")) << r.output;
        EXPECT_NE(std::string::npos, r.output.find("from ISO 1600 relative to base ISO 100 (manifest)"))
            << r.output;
        const cv::rawgment::NoiseModel fitted =
            cv::rawgment::NoiseModel::load(dir + "/cal_" + mode + "/noise_model.yml");
        expectTruth(fitted, 1.0, std::string(mode) == "chart" ? 0.47 : 0.16, mode);
        EXPECT_EQ(100.0, fitted.baseIso) << "the model knows the ISO of its gain 1";
        // The model carries its per-gain fits as measured lines, and the profile for darktable gives them
        // back through the catalogue, ISO by ISO.
        ASSERT_EQ(3u, fitted.measuredLines.size()) << "one line per gain with light";
        EXPECT_EQ(200.0, fitted.measuredLines[0].iso) << "the lowest light burst, 6.02 dB over ISO 100";
        EXPECT_GT(fitted.measuredLines[0].slopeStdError, 0);
        cv::rawgment::RawFormat format =
            cv::rawgment::readRaw(dir + "/sim/g6.02dB_level0.20/frame_000.dng").format;
        const cv::rawgment::NoiseModel viaDarktable =
            cv::rawgment::findCameraProfile(
                cv::rawgment::readCameraProfiles(dir + "/cal_" + mode + "/darktable_noiseprofiles.json"),
                "cv::rawgment simulated sensor")
                .modelFor(format);
        ASSERT_EQ(fitted.measuredLines.size(), viaDarktable.measuredLines.size());
        // The catalogue's gain 1 is its lowest ISO (200 here): the lines are compared ISO by ISO.
        for (const cv::rawgment::MeasuredNoiseLine& l : fitted.measuredLines) {
            const cv::rawgment::NoiseLine back = viaDarktable.lineAtGain(l.iso / viaDarktable.baseIso);
            EXPECT_NEAR(back.a, l.line.a, 1e-9 * l.line.a) << l.iso;
            EXPECT_NEAR(back.b, l.line.b, 1e-9 * l.line.b) << l.iso;
        }
        EXPECT_TRUE(exists(dir + "/cal_" + mode + "/android_noise_profile.yml"));
    }

    // A folder of burst folders, with the dark frames (lens cap) in the dark_* folders: gains relative to
    // the lowest ISO present (200), so the model's gain 1 is the simulator's gain 2 and its per-gain terms
    // are alpha g and sigma_d^2 g^2 at g = 2. Dark frames pin the read noise: over seeds 1-6 of this
    // simulation the spread of sigma_r^2 is 0.5% (11.7% with the chart alone), of sigma_d^2 0.07%, so 3%
    // is 6 spreads.
    r = runApp("rawgment_calibrate", "'" + dir + "/sim' --out='" + dir + "/cal_folder' --plots=false");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("verdict: PASS")) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("relative to base ISO 200 (the lowest in the files)"))
        << r.output;
    EXPECT_NE(std::string::npos, r.output.find("dark_g24.08dB/frame_000.dng, dark): gain 18.06 dB"))
        << r.output;
    expectTruth(cv::rawgment::NoiseModel::load(dir + "/cal_folder/noise_model.yml"), 2.0, 0.03, "folder");

    // A frame of another ISO in a burst is refused by name.
    std::ifstream src(dir + "/sim/g12.04dB_level0.20/frame_000.dng", std::ios::binary);
    std::ofstream(dir + "/sim/g6.02dB_level0.20/frame_999.dng", std::ios::binary) << src.rdbuf();
    r = runApp("rawgment_calibrate", "'" + dir + "/sim' --out='" + dir + "/cal_mixed' --plots=false");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("frame_999.dng' says ISO 400 where")) << r.output;
}

TEST(Apps, calibrateFromIsoTaggedFilesIsAsAccurateAsTheTradeoffReportSays)
{
    // The trade-off report's campaign (apps/common/tradeoff_measures.cpp: alpha 0.4, sigma_d^2 0.5,
    // sigma_r^2 2, gains 6/12/24 dB, levels 0.2/0.65, 32 px patches sampled in 24 px squares) written as
    // DNG files that carry their ISO and no sidecar, calibrated from the files alone. docs/performance.md's
    // trade-off table gives 0.0591 at 16 frames: the RMS over 3 campaigns of the worst relative error of
    // the three parameters, against the effective truth (sigma_r^2 2 plus the 1/12 DN^2 of rounding), so
    // one campaign stays within 3 of it, 0.177. Sharper: each parameter lies within 4 of the standard
    // errors the report states (a 1-in-16,000 miss when they are right).
    const std::string dir = freshDir("calibrate_tradeoff_sensor");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir +
                                               "/sim' --frames=16 --gains=6.0206,12.0412,24.0824 "
                                               "--levels=0.2,0.65 --alpha=0.4 --sigma_d2=0.5 --sigma_r2=2 "
                                               "--patch=32 --validation=false --seed=9");
    ASSERT_EQ(0, r.status) << r.output;
    std::ostringstream manifest;
    manifest << "%YAML:1.0\ncalibration_manifest:\n  patches: sim/patches.yml\n  base_iso: 100\n  bursts:\n";
    for (const char* burst : {"g6.02dB_level0.20", "g6.02dB_level0.65", "g12.04dB_level0.20",
                              "g12.04dB_level0.65", "g24.08dB_level0.20", "g24.08dB_level0.65"}) {
        manifest << "    - files: [";
        for (int t = 0; t < 16; ++t) {
            const std::string frame = cv::format("sim/%s/frame_%03d.dng", burst, t);
            ASSERT_EQ(0, std::remove((dir + "/" + frame + ".yml").c_str())) << frame;
            manifest << (t ? ", " : "") << frame;
        }
        manifest << "]\n";
    }
    std::ofstream(dir + "/m.yml") << manifest.str();
    r = runApp("rawgment_calibrate", "'" + dir + "/m.yml' --out='" + dir + "/cal' --plots=false");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("verdict: PASS")) << r.output;
    const cv::rawgment::NoiseModel fitted = cv::rawgment::NoiseModel::load(dir + "/cal/noise_model.yml");
    const double truth[3] = {0.4, 0.5, 2.0 + 1.0 / 12};
    const double worst =
        std::max({std::abs(fitted.alpha / truth[0] - 1), std::abs(fitted.sigmaD2 / truth[1] - 1),
                  std::abs(fitted.sigmaR2 / truth[2] - 1)});
    EXPECT_LT(worst, 3 * 0.0591) << "alpha " << fitted.alpha << ", sigma_d^2 " << fitted.sigmaD2
                                 << ", sigma_r^2 " << fitted.sigmaR2;
    const cv::rawgment::CalibrationReport report =
        cv::rawgment::CalibrationReport::load(dir + "/cal/calibration_report.yml");
    const double fittedValues[3] = {fitted.alpha, fitted.sigmaD2, fitted.sigmaR2};
    for (int k = 0; k < 3; ++k) {
        ASSERT_GT(report.uncertainty.stdError[k], 0) << k;
        EXPECT_LT(std::abs(fittedValues[k] - truth[k]) / report.uncertainty.stdError[k], 4.0) << k;
    }
}

TEST(Apps, calibrationVerdictFailsANonLinearFileAndGainsTooClose)
{
    const std::string dir = freshDir("calibrate_verdict");
    AppRun r = runApp("rawgment_simulate", "--out='" + dir +
                                               "/sim' --frames=16 --gains=6,7 --levels=0.2,0.65 "
                                               "--validation=false --format=png --seed=3");
    ASSERT_EQ(0, r.status) << r.output;
    // Gains 1 dB apart: the offsets cannot separate sigma_d^2 from sigma_r^2.
    r = runApp("rawgment_calibrate",
               "'" + dir + "/sim/manifest.yml' --out='" + dir + "/close' --plots=false");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("verdict: FAIL")) << r.output;
    EXPECT_NE(std::string::npos,
              r.output.find("FAIL separability of sigma_d^2 and sigma_r^2: gain ratio 1.12"))
        << r.output;
    const std::string report = readText(dir + "/close/report.md");
    EXPECT_EQ(0u, report.find("# Calibration report\n\n**Verdict: FAIL**")) << report;

    // Gains 4x apart, but a sensor without read noise before the gain: sigma_d^2's 95% interval reaches 0,
    // so the data cannot tell it from 0 and the split fails on the intervals, not on the gains.
    r = runApp("rawgment_simulate", "--out='" + dir +
                                        "/nopre' --frames=16 --gains=6,18 --levels=0.2,0.65 --sigma_d2=0 "
                                        "--validation=false --format=png --seed=3");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_calibrate",
               "'" + dir + "/nopre/manifest.yml' --out='" + dir + "/nopre_cal' --plots=false");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos,
              r.output.find("FAIL separability of sigma_d^2 and sigma_r^2: gain ratio 3.98 (12.0 "
                            "dB) over 2 gains; 95% intervals sigma_d^2 [-"))
        << r.output;

    // The same bursts through a tone curve (x^(1/2.2) of the signal, as a processed file has): not linear.
    std::ostringstream manifest;
    manifest << "%YAML:1.0\ncalibration_manifest:\n  patches: sim/patches.yml\n  bursts:\n";
    for (const char* burst : {"g06dB_level0.20", "g06dB_level0.65", "g07dB_level0.20", "g07dB_level0.65"}) {
        const std::string folder = dir + "/curved/" + burst;
        ASSERT_EQ(0, mkdir((dir + "/curved").c_str(), 0755) == 0 || errno == EEXIST ? 0 : -1);
        ASSERT_EQ(0, mkdir(folder.c_str(), 0755));
        manifest << "    - { gain_db: " << (std::string(burst).substr(1, 2) == "06" ? 6 : 7) << ", files: [";
        for (int t = 0; t < 16; ++t) {
            cv::Mat frame;
            const cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(
                cv::format("%s/sim/%s/frame_%03d.png", dir.c_str(), burst, t), frame);
            const double black = meta.format.blackLevel[0], range = meta.format.whiteLevel - black;
            cv::Mat signal, curved;
            frame.convertTo(signal, CV_64F, 1.0 / range, -black / range);
            signal = cv::max(signal, 0.0);
            cv::pow(signal, 1 / 2.2, curved);
            curved.convertTo(frame, CV_16U, range, black);
            cv::rawgment::writeMosaic(cv::format("%s/frame_%03d.png", folder.c_str(), t), frame, meta);
            manifest << (t ? ", " : "") << cv::format("curved/%s/frame_%03d.png", burst, t);
        }
        manifest << "] }\n";
    }
    std::ofstream(dir + "/curved.yml") << manifest.str();
    r = runApp("rawgment_calibrate", "'" + dir + "/curved.yml' --out='" + dir + "/curved_cal' --plots=false");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("FAIL linearity (curvature of variance against mean)"))
        << r.output;

    // Too few frames is named with the burst.
    std::ofstream(dir + "/few.yml")
        << "%YAML:1.0\ncalibration_manifest:\n  patches: sim/patches.yml\n  bursts:\n"
        << "    - { gain_db: 6, files: [sim/g06dB_level0.20/frame_000.png, "
           "sim/g06dB_level0.20/frame_001.png, sim/g06dB_level0.20/frame_002.png] }\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/few.yml' --out='" + dir + "/few' --plots=false");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("FAIL frames per burst: fewest 3")) << r.output;
}

TEST(Apps, calibrateTheRealColourChartInSingleFrameModeSaysWhatItCannotDetermine)
{
    const std::string chart = std::string(RAWGMENT_SHARED_DATA_DIR) + "/colorchart.dng";
    if (!exists(chart))
        GTEST_SKIP() << chart << " is missing (see ../shared/data/SOURCES.md)";
    const std::string dir = freshDir("calibrate_colorchart");
    std::ofstream(dir + "/m.yml") << "%YAML:1.0\ncalibration_manifest:\n  patches: detect\n  bursts:\n"
                                  << "    - { files: ['" << chart << "'] }\n";
    const AppRun r =
        runApp("rawgment_calibrate", "'" + dir + "/m.yml' --out='" + dir + "/cal'", AllocationStacks::FULL);
    ASSERT_EQ(0, r.status) << r.output;
    const std::string report = readText(dir + "/cal/report.md");
    // One frame at one unknown gain: the line of this capture, and a verdict that says why it is no more.
    EXPECT_NE(std::string::npos, report.find("**Verdict: FAIL**")) << report;
    EXPECT_NE(std::string::npos, report.find("| frames per burst | **FAIL** | fewest 1")) << report;
    EXPECT_NE(std::string::npos, report.find("| separability of sigma_d^2 and sigma_r^2 | **FAIL**"))
        << report;
    EXPECT_NE(std::string::npos, report.find("the files do not say their ISO")) << report;
    EXPECT_NE(std::string::npos, report.find("single-frame mode")) << report;
    EXPECT_NE(std::string::npos, report.find("patches detected with cv::mcc")) << report;
    EXPECT_FALSE(exists(dir + "/cal/noise_model.yml")) << "no model from one gain";
    EXPECT_EQ(std::string::npos, r.output.find("arning")) << "no plot is attempted without its data";
}

TEST(Apps, calibrateDarkComponentsFromSimulatedDarkBurstsWithPlotsAndMaps)
{
    const std::string dir = freshDir("dark_components");
    AppRun r =
        runApp("rawgment_simulate", "--frames=8 --levels=0.5 --format=png --validation=false --gains=6,18 "
                                    "--dark=true --row_noise=0.05,0.5 --tukey_lambda=-0.05 --dark_shading=4 "
                                    "--out='" +
                                        dir + "/sim'");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_calibrate",
               "'" + dir + "/sim/manifest.yml' --dark_components=true --out='" + dir + "/cal'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("dark frames: row noise")) << r.output;
    for (const char* f : {"dark_calibration.yml", "dark_rows.csv", "dark_ppcc.csv", "dark_rows.png",
                          "dark_ppcc.png", "dark_shading.png", "noise_model.dark_shading_per_gain.tiff"})
        EXPECT_TRUE(exists(dir + "/cal/" + f)) << f;
    expectPngDecodes(dir + "/cal/dark_shading.png");
    EXPECT_NE(std::string::npos, readText(dir + "/cal/report.md").find("## Dark-frame components"));
    // The model file and its maps load as a pair, and the truth's components come back (8 frames of
    // 296 x 200 at two gains: the row variances to about 10%, lambda to 0.02). 8 frames fail the verdict's
    // 16, so the model is accepted explicitly.
    const cv::rawgment::NoiseModel fitted =
                                       cv::rawgment::NoiseModel::load(dir + "/cal/noise_model.yml", true),
                                   truth = cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
    ASSERT_TRUE(fitted.hasDarkShading());
    EXPECT_EQ(truth.darkShadingPerGain.size(), fitted.darkShadingPerGain.size());
    EXPECT_NEAR(fitted.rowVariance(8), truth.rowVariance(8), 0.15 * truth.rowVariance(8));
    EXPECT_NEAR(fitted.tukeyLambda, truth.tukeyLambda, 0.03);
    // The read terms are the pixel's own, without the rows and unbiased by the shading: within 10% (the
    // trade-off report's worst parameter error at 8 frames is 8.8%). Uncorrected, 4 DN of shading took 3%
    // from alpha and 59% from sigma_r^2 (16 frames at 6, 12 and 24 dB).
    EXPECT_NEAR(fitted.sigmaD2, truth.sigmaD2, 0.1 * truth.sigmaD2);
    EXPECT_NEAR(fitted.alpha, truth.alpha, 0.1 * truth.alpha);
    // Without dark bursts the option is an error that says what it needs.
    r = runApp("rawgment_simulate",
               "--frames=3 --levels=0.5 --format=png --validation=false --gains=6 --out='" + dir + "/plain'");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_calibrate",
               "'" + dir + "/plain/manifest.yml' --dark_components=true --out='" + dir + "/c2'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("needs dark bursts")) << r.output;
}

TEST(Apps, aSensorTheDarkComponentsDescribePassesTheVerdictAt16Frames)
{
    // The verdict judged the pixel's own read noise without the rows it had just separated (+25% residuals
    // with row noise 0.5, 0.5), and read the median of sample variances of heavy-tailed read noise as if
    // Gaussian (-6% at Tukey lambda -0.1): a sensor the components describe failed. 16 frames at 6, 12 and
    // 24 dB (three seeds each were checked by hand; this is one).
    const std::string dir = freshDir("dark_verdict");
    for (const char* sensor : {"--row_noise=0.5,0.5", "--tukey_lambda=-0.1"}) {
        const std::string name = std::string(sensor).substr(2, 3);
        AppRun r = runApp("rawgment_simulate", std::string("--frames=16 --validation=false --dark=true ") +
                                                   sensor + " --out='" + dir + "/" + name + "'");
        ASSERT_EQ(0, r.status) << r.output;
        r = runApp("rawgment_calibrate", "'" + dir + "/" + name +
                                             "/manifest.yml' --dark_components=true --plots=false "
                                             "--out='" +
                                             dir + "/" + name + "_cal'");
        ASSERT_EQ(0, r.status) << r.output;
        const std::string report = readText(dir + "/" + name + "_cal/report.md");
        EXPECT_NE(std::string::npos, report.find("**Verdict: PASS**")) << sensor << "\n" << report;
        EXPECT_NO_THROW(cv::rawgment::NoiseModel::load(dir + "/" + name + "_cal/noise_model.yml")) << sensor;
    }
}

TEST(Apps, everyFileAnAppReadsNested100000DeepIsAnErrorNotACrash)
{
    // 60,000 nested brackets overflowed the stack in OpenCV's recursive reader: rawgment_cameras,
    // rawgment_augment --model and the manifests died with exit 139. Each is now an error naming the file.
    const std::string dir = freshDir("deep_files");
    const std::string deep = std::string(100000, '[') + "1" + std::string(100000, ']');
    const auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir + "/" + name) << text;
        return dir + "/" + name;
    };
    const std::string json = write("deep.json", "{\"noiseprofiles\": " + deep + "}\n");
    const std::string model =
        write("model.yml", "noise_model:\n   format_version: 1\n   alpha: " + deep + "\n");
    const std::string good = dir + "/good.yml";
    cv::rawgment::NoiseModel(0.4, 0.5, 2.0).save(good);
    const std::string scene = write("scene.yml", "scene:\n   shift: " + deep + "\n");
    const std::string policy =
        write("policy.yml", "random_scene_policy:\n   format_version: 1\n   noise: " + deep + "\n");
    const std::string manifest = write("manifest.yml", "calibration_manifest:\n   bursts: " + deep + "\n");
    const std::string validation = write("validation.yml", "validation_manifest:\n   pairs: " + deep + "\n");
    const std::string patches = write("patches.yml", "chart_patches:\n   squares: " + deep + "\n");
    const std::string patchesManifest =
        write("patches_manifest.yml",
              "calibration_manifest:\n   patches: '" + patches +
                  "'\n   bursts:\n      - { gain_db: 6, files: [ in0.png, in1.png, in2.png ] }\n");
    const std::string input = dir + "/in.png";
    cv::rawgment::writeMosaic(input, cv::Mat(8, 8, CV_16UC1, cv::Scalar(300)),
                              cv::rawgment::MosaicMetadata());
    for (int k = 0; k < 3; ++k)
        cv::rawgment::writeMosaic(dir + "/in" + std::to_string(k) + ".png",
                                  cv::Mat(8, 8, CV_16UC1, cv::Scalar(300)), cv::rawgment::MosaicMetadata());
    const struct
    {
        const char* app;
        std::string args, file;
    } runs[] = {
        {"rawgment_cameras", "--profiles='" + json + "'", json},
        {"rawgment_augment",
         "--model='" + model + "' --policy='" + policy + "' --out='" + dir + "/o1' '" + input + "'", model},
        {"rawgment_augment",
         "--model='" + json + "' --camera=x --policy='" + policy + "' --out='" + dir + "/o2' '" + input + "'",
         json},
        {"rawgment_augment",
         "--model='" + good + "' --scene='" + scene + "' --out='" + dir + "/o3' '" + input + "'", scene},
        {"rawgment_augment",
         "--model='" + good + "' --policy='" + policy + "' --out='" + dir + "/o4' '" + input + "'", policy},
        {"rawgment_calibrate", "'" + manifest + "' --out='" + dir + "/c1'", manifest},
        {"rawgment_calibrate", "'" + patchesManifest + "' --out='" + dir + "/c2'", patches},
        {"rawgment_validate", "'" + validation + "' --model='" + good + "' --out='" + dir + "/v1'",
         validation},
    };
    for (const auto& run : runs) {
        const AppRun r = runApp(run.app, run.args);
        EXPECT_EQ(1, r.status) << run.app << " " << run.args << "\n" << r.output;
        EXPECT_NE(std::string::npos, r.output.find("nested more than 64 levels")) << run.app << "\n"
                                                                                  << r.output;
        EXPECT_NE(std::string::npos, r.output.find(run.file)) << run.app << "\n" << r.output;
    }
}

TEST(Apps, calibrateDarkComponentsRefusesDarkFramesOfAnotherFormatNamingBoth)
{
    // Dark frames of another camera (BGGR for RGGB, black 64 for 256, white 1023 for 4095, same size)
    // were taken without a word: sigma_r^2 came out about 15 instead of 0.87.
    const std::string dir = freshDir("dark_other_format");
    AppRun r = runApp("rawgment_simulate", "--frames=3 --levels=0.5 --format=png --validation=false "
                                           "--gains=6,18 --dark=true --out='" +
                                               dir + "/sim'");
    ASSERT_EQ(0, r.status) << r.output;
    std::ostringstream manifest;
    manifest << "calibration_manifest:\n  patches: none\n  bursts:\n";
    for (const char* burst : {"g06dB_level0.50", "g18dB_level0.50", "dark_g06dB", "dark_g18dB"}) {
        const bool dark = std::string(burst).rfind("dark", 0) == 0;
        manifest << "    - { gain_db: " << (std::string(burst).find("18dB") != std::string::npos ? 18 : 6)
                 << ", dark: " << (dark ? "true" : "false") << ", files: [";
        for (int t = 0; t < 3; ++t) {
            std::string file = cv::format("%s/sim/%s/frame_%03d.png", dir.c_str(), burst, t);
            if (dark) {
                cv::Mat mosaic;
                cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(file, mosaic);
                meta.format.pattern = cv::rawgment::CFA_BGGR;
                meta.format.blackLevel = cv::Vec4d::all(64);
                meta.format.whiteLevel = 1023;
                meta.hasScene = false;
                cv::Mat clipped = cv::min(mosaic, 1023);
                file = cv::format("%s/%s_%03d.png", dir.c_str(), burst, t);
                cv::rawgment::writeMosaic(file, clipped, meta);
            }
            manifest << (t ? ", " : "") << "'" << file << "'";
        }
        manifest << "] }\n";
    }
    std::ofstream(dir + "/m.yml") << manifest.str();
    r = runApp("rawgment_calibrate",
               "'" + dir + "/m.yml' --plots=false --dark_components=true --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos,
              r.output.find("(BGGR, black 64/64/64/64, white 1023) has another format than"))
        << r.output;
    EXPECT_NE(std::string::npos, r.output.find("(RGGB, black 256/256/256/256, white 4095)")) << r.output;
    EXPECT_FALSE(exists(dir + "/cal/noise_model.yml"));
}

TEST(Apps, calibrateReadsBurstsOfDifferentFrameSizesEachInsideItsOwnFrame)
{
    // patches: none with a light burst and the dark bursts cropped: the sampling read beyond the smaller
    // frames (a heap overflow under ASan, an ROI assertion in Release).
    const std::string dir = freshDir("mixed_sizes");
    AppRun r = runApp("rawgment_simulate", "--frames=4 --levels=0.5 --format=png --validation=false "
                                           "--gains=6,18 --dark=true --dark_shading=2 --out='" +
                                               dir + "/sim'");
    ASSERT_EQ(0, r.status) << r.output;
    const auto cropped = [&](const std::string& burst, int frame, cv::Size size) {
        const std::string in = cv::format("%s/sim/%s/frame_%03d.png", dir.c_str(), burst.c_str(), frame),
                          out = cv::format("%s/%s_%03d.png", dir.c_str(), burst.c_str(), frame);
        cv::Mat mosaic;
        const cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(in, mosaic);
        cv::rawgment::writeMosaic(out, mosaic(cv::Rect(cv::Point(), size)).clone(), meta);
        return out;
    };
    cv::Mat probe;
    const cv::Size full = cv::rawgment::readMosaic(dir + "/sim/g06dB_level0.50/frame_000.png", probe).size;
    const cv::Size light(full.width - 40, full.height - 30), dark(full.width - 100, full.height - 60);
    std::ostringstream manifest;
    manifest << "%YAML:1.0\ncalibration_manifest:\n  patches: none\n  bursts:\n";
    const struct
    {
        const char* burst;
        int gainDb;
        bool dark;
        cv::Size size;
    } bursts[] = {{"g06dB_level0.50", 6, false, full},
                  {"g18dB_level0.50", 18, false, light},
                  {"dark_g06dB", 6, true, dark},
                  {"dark_g18dB", 18, true, dark}};
    for (const auto& b : bursts) {
        manifest << "    - { gain_db: " << b.gainDb << ", dark: " << (b.dark ? "true" : "false")
                 << ", files: [";
        for (int t = 0; t < 4; ++t)
            manifest << (t ? ", " : "") << "'" << cropped(b.burst, t, b.size) << "'";
        manifest << "] }\n";
    }
    std::ofstream(dir + "/m.yml") << manifest.str();
    for (const char* darkComponents : {"false", "true"}) {
        r = runApp("rawgment_calibrate", "'" + dir +
                                             "/m.yml' --plots=false --dark_components=" + darkComponents +
                                             " --out='" + dir + "/cal_" + darkComponents + "'");
        ASSERT_EQ(0, r.status) << r.output;
        // 4 frames fail the verdict's 16: the model is accepted explicitly.
        const cv::rawgment::NoiseModel fitted =
            cv::rawgment::NoiseModel::load(dir + "/cal_" + darkComponents + "/noise_model.yml", true);
        const cv::rawgment::NoiseModel truth =
            cv::rawgment::NoiseModel::load(dir + "/sim/truth_noise_model.yml");
        // 4 frames: alpha within 10% (the trade-off report's worst parameter error at 8 frames is 8.8%;
        // alpha, fitted from every light pixel, is the best determined of them).
        EXPECT_NEAR(fitted.alpha, truth.alpha, 0.1 * truth.alpha) << darkComponents;
    }
}

TEST(Apps, calibrateRefusesFramesOfTwoCamerasNamingBoth)
{
    // Bursts of two make/model tags were calibrated into one model named after the first camera.
    const std::string dir = freshDir("two_cameras");
    AppRun r = runApp("rawgment_simulate", "--frames=4 --levels=0.5 --format=png --validation=false "
                                           "--gains=6,18 --out='" +
                                               dir + "/sim'");
    ASSERT_EQ(0, r.status) << r.output;
    // Frame t of burst 18 dB copied, tagged as another camera's from frame `otherFrom` on.
    const auto copyBurst = [&](const std::string& name, int otherFrom) {
        std::string files;
        for (int t = 0; t < 4; ++t) {
            cv::Mat mosaic;
            cv::rawgment::MosaicMetadata meta = cv::rawgment::readMosaic(
                cv::format("%s/sim/g18dB_level0.50/frame_%03d.png", dir.c_str(), t), mosaic);
            if (t >= otherFrom)
                meta.camera.model = "other sensor";
            const std::string out = cv::format("%s/%s_%03d.png", dir.c_str(), name.c_str(), t);
            cv::rawgment::writeMosaic(out, mosaic, meta);
            files += (t ? ", '" : "'") + out + "'";
        }
        return files;
    };
    const std::string first = "'" + dir + "/sim/g06dB_level0.50/frame_000.png', '" + dir +
                              "/sim/g06dB_level0.50/frame_001.png', '" + dir +
                              "/sim/g06dB_level0.50/frame_002.png', '" + dir +
                              "/sim/g06dB_level0.50/frame_003.png'";
    const struct
    {
        const char* name;
        int otherFrom;
        const char* firstNamed;
    } cases[] = {{"across", 0, "g06dB_level0.50/frame_000.png' from camera 'cv::rawgment simulated sensor'"},
                 {"within", 2, "within_000.png' from camera 'cv::rawgment simulated sensor'"}};
    for (const auto& c : cases) {
        std::ofstream(dir + "/" + c.name + ".yml")
            << "%YAML:1.0\ncalibration_manifest:\n  patches: none\n  bursts:\n"
            << "    - { gain_db: 6, files: [" << first << "] }\n"
            << "    - { gain_db: 18, files: [" << copyBurst(c.name, c.otherFrom) << "] }\n";
        r = runApp("rawgment_calibrate",
                   "'" + dir + "/" + c.name + ".yml' --plots=false --out='" + dir + "/cal_" + c.name + "'");
        EXPECT_EQ(1, r.status) << r.output;
        EXPECT_NE(std::string::npos, r.output.find("from camera 'cv::rawgment other sensor'")) << r.output;
        EXPECT_NE(std::string::npos, r.output.find(c.firstNamed)) << r.output;
        EXPECT_NE(std::string::npos, r.output.find("calibrate each camera on its own")) << r.output;
        EXPECT_FALSE(std::ifstream(dir + "/cal_" + std::string(c.name) + "/noise_model.yml").good());
    }
}

TEST(Apps, aFailedCalibrationLeavesNoFileThatSilentlyWorks)
{
    // A FAIL verdict (4 frames against the 16 the verdict asks for) wrote noise_model.yml and the
    // darktable and Android exports with no mark, and rawgment_augment used them.
    const std::string dir = freshDir("failed_verdict");
    AppRun r =
        runApp("rawgment_simulate", "--frames=4 --levels=0.3,0.9 --format=png --out='" + dir + "/sim'");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --plots=false --out='" + dir + "/cal'");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string report = readText(dir + "/cal/report.md");
    EXPECT_NE(std::string::npos, report.find("**Verdict: FAIL**")) << report;
    EXPECT_NE(std::string::npos, report.find("`failed_calibration` in noise_model.yml")) << report;
    EXPECT_TRUE(exists(dir + "/cal/noise_model.yml"));
    EXPECT_FALSE(exists(dir + "/cal/darktable_noiseprofiles.json"));
    EXPECT_FALSE(exists(dir + "/cal/android_noise_profile.yml"));
    EXPECT_NE(std::string::npos,
              readText(dir + "/cal/noise_model.yml").find("failed_calibration: frames per burst"));
    writeExposureScene(dir + "/scene.yml", 0.5, 1.0);
    const std::string frame = "'" + dir + "/sim/g06dB_level0.90/frame_000.png'";
    r = runApp("rawgment_augment", "--model='" + dir + "/cal/noise_model.yml' --scene='" + dir +
                                       "/scene.yml' --out='" + dir + "/aug' " + frame);
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("verdict was FAIL (frames per burst")) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("--accept_failed_calibration")) << r.output;
    EXPECT_FALSE(exists(dir + "/aug/frame_000_v00.png"));
    r = runApp("rawgment_validate", "'" + dir + "/sim/validation_manifest.yml' --model='" + dir +
                                        "/cal/noise_model.yml' --plots=false --out='" + dir + "/val'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("verdict was FAIL")) << r.output;
    // Asked for explicitly, it works.
    r = runApp("rawgment_augment", "--accept_failed_calibration=true --model='" + dir +
                                       "/cal/noise_model.yml' --scene='" + dir + "/scene.yml' --out='" + dir +
                                       "/aug' " + frame);
    EXPECT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("wrote 1 outputs")) << r.output;
}

TEST(Apps, theVerdictNamesTheBurstWhoseGainDisagreesWithItsSlope)
{
    // Bursts shot at 24 dB but tagged 21 dB: the report blamed the worst residual bin (of whichever gain)
    // instead of the burst whose gain is wrong. Each gain's slope against the median alpha names it, with the
    // gain the slope implies (24 dB: 1.41 times the tag).
    const std::string dir = freshDir("wrong_gain");
    AppRun r =
        runApp("rawgment_simulate", "--frames=16 --format=png --validation=false --out='" + dir + "/sim'");
    ASSERT_EQ(0, r.status) << r.output;
    std::string manifest = readText(dir + "/sim/manifest.yml");
    for (size_t at = manifest.find("gain_db: 24."); at != std::string::npos;
         at = manifest.find("gain_db: 24."))
        manifest.replace(at, 12, "gain_db: 21.");
    std::ofstream(dir + "/sim/manifest.yml", std::ios::trunc) << manifest;
    r = runApp("rawgment_calibrate", "'" + dir + "/sim/manifest.yml' --plots=false --out='" + dir + "/cal'");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string report = readText(dir + "/cal/report.md");
    const size_t row = report.find("| gain of each burst against its slope | **FAIL** | 21.00 dB (");
    ASSERT_NE(std::string::npos, row) << report;
    const std::string line = report.substr(row, report.find('\n', row) - row);
    EXPECT_NE(std::string::npos, line.find("g24dB_level0.30/frame_000.png")) << line;
    EXPECT_EQ(std::string::npos, line.find("g12dB")) << line;
    // The implied gain is 24 dB within the slope's error (0.36%: 0.03 dB; 0.1 dB is 8 of them).
    const size_t says = line.find("its slope says gain ");
    ASSERT_NE(std::string::npos, says);
    const double impliedDb = std::stod(line.substr(line.find('(', says) + 1));
    EXPECT_NEAR(24.0, impliedDb, 0.1) << line;
    // Tagged right, the same bursts pass the check.
    r = runApp("rawgment_simulate", "--frames=16 --format=png --validation=false --out='" + dir + "/right'");
    ASSERT_EQ(0, r.status) << r.output;
    r = runApp("rawgment_calibrate",
               "'" + dir + "/right/manifest.yml' --plots=false --out='" + dir + "/cal2'");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos,
              readText(dir + "/cal2/report.md").find("| gain of each burst against its slope | pass |"));
}

TEST(Apps, readersRefuseDevicesAndFifosNamingThem)
{
    const std::string dir = freshDir("not_regular");
    for (const char* fifo : {"/frame.dng", "/b.dng", "/c.dng"})
        ASSERT_EQ(0, ::mkfifo((dir + fifo).c_str(), 0600));
    std::ofstream(dir + "/scene.yml") << "%YAML:1.0\nscene:\n  jitter: {}\n";
    AppRun r = runApp("rawgment_augment", "--model=/dev/zero --scene='" + dir + "/scene.yml' --out='" + dir +
                                              "/out' '" + dir + "/frame.dng'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("'/dev/zero': it is a device")) << r.output;
    // A manifest naming a FIFO: refused, not blocked on.
    std::ofstream(dir + "/m.yml") << "%YAML:1.0\ncalibration_manifest:\n  patches: none\n  bursts:\n"
                                  << "    - { gain_db: 6, files: [frame.dng, b.dng, c.dng] }\n";
    r = runApp("rawgment_calibrate", "'" + dir + "/m.yml' --out='" + dir + "/cal'");
    EXPECT_EQ(1, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("frame.dng': it is a FIFO")) << r.output;
}

TEST(Apps, demoWritesAReportAndAGallery)
{
    const std::string dir = freshDir("demo");
    AppRun r = runApp("rawgment_demo", "--out='" + dir + "/demo' --frames=8");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string report = readText(dir + "/demo/report.md");
    EXPECT_NE(std::string::npos, report.find("| alpha |")) << report;
    EXPECT_NE(std::string::npos, report.find("gallery.png"));
    expectPngDecodes(dir + "/demo/gallery.png");
    // The dark-frame components, calibrated and side by side with and without them.
    EXPECT_NE(std::string::npos, report.find("## Dark-frame noise beyond the paper")) << report;
    EXPECT_NE(std::string::npos, report.find("| read-noise Tukey lambda | -0.080 |")) << report;
    expectPngDecodes(dir + "/demo/dark_components.png");
    // The same dark scene as two real cameras, when darktable's profiles are on the machine (CI: always).
    EXPECT_NE(std::string::npos, report.find("## Real cameras")) << report;
    if (!cv::rawgment::darktableProfilesPath().empty()) {
        EXPECT_NE(std::string::npos, report.find("| camera | verdict | full well (e-) |")) << report;
        EXPECT_NE(std::string::npos,
                  report.find("| shot slope at 8x, measured | Eq. 5's | profiles' demosaic (c) |"))
            << report;
        expectPngDecodes(dir + "/demo/real_cameras.png");
        cv::Mat mosaic;
        EXPECT_FALSE(
            cv::rawgment::readMosaic(dir + "/demo/gallery/camera_0.dng", mosaic).noiseCamera.empty());
    }
    r = runApp("rawgment_demo", "--out='" + dir + "/demo' --frames=8");
    EXPECT_EQ(1, r.status) << "an existing report is never overwritten";
}

TEST(Apps, tradeoffReportMeasuresEveryKnob)
{
#ifdef RAWGMENT_SANITIZED_BUILD
    // Its simulated calibration campaigns take over 7 minutes under ASan on 2 cores (20 s in Release);
    // the library code it runs is covered by the unit tests under the sanitizers.
    GTEST_SKIP() << "the trade-off report runs in the Release build only";
#endif
    const std::string dir = freshDir("tradeoffs");
    AppRun r = runApp("rawgment_tradeoffs", "--quick --out='" + dir + "/t'");
    ASSERT_EQ(0, r.status) << r.output;
    const std::string md = readText(dir + "/t/tradeoffs.md");
    for (const char* knob :
         {"Shot-noise sampling", "Prior mean", "Motion-blur noise sum", "Arithmetic",
          "Calibration burst length", "Calibration patch size", "Calibration RANSAC iterations",
          "Shapiro-Wilk", "Row noise (dark-frame component)", "Dark shading (dark-frame component)",
          "Read-noise tails (dark-frame component)"})
        EXPECT_NE(std::string::npos, md.find(knob)) << knob;
    // What more data buys: a row per burst length, per square side, for two gains and for dark frames,
    // each with the stated and the made error of every parameter.
    const size_t precision = md.find("## Calibration precision: what more data buys");
    ASSERT_NE(std::string::npos, precision);
    for (const char* setup :
         {"24x24, 3 gains |", "8x8, 3 gains |", "2 gains (6 and 24 dB) |", "+ dark frames |"})
        EXPECT_NE(std::string::npos, md.find(setup, precision)) << setup;
    expectPngDecodes(dir + "/t/tradeoffs.png");
    // The figure: one view of every knob relative to its reference setting, then a panel per knob whose
    // y axis names the knob's own measure (the axes once said only "error").
    const std::string script = readText(dir + "/t/tradeoffs.png.gp");
    EXPECT_NE(std::string::npos, script.find("Which knob buys the most accuracy per millisecond?"));
    EXPECT_NE(std::string::npos, script.find("set ylabel \"KL(true || augmented)"));
    EXPECT_NE(std::string::npos, script.find("set ylabel \"RMS fixed-pattern difference (DN)"));
    EXPECT_EQ(std::string::npos, script.find("set ylabel 'error'"));
    // error and time of each (knob, setting) from the CSV: finite, and the orderings the knobs promise.
    std::map<std::string, double> error, errorOfKnob;
    std::istringstream csv(readText(dir + "/t/tradeoffs.csv"));
    const auto split = [](const std::string& line) {
        std::vector<std::string> cells;
        std::stringstream cellStream(line);
        for (std::string cell; std::getline(cellStream, cell, ',');)
            cells.push_back(cell);
        return cells;
    };
    std::string line;
    std::getline(csv, line);
    // Five columns, then the time on each CPU path this machine has.
    const size_t paths = cv::rawgment::availableCpuPaths().size();
    ASSERT_EQ(split(line).size(), 5 + paths) << line;
    EXPECT_EQ(split(line).back(),
              "ms_per_mp_" + cv::rawgment::cpuPathName(cv::rawgment::availableCpuPaths().back()));
    int rows = 0;
    while (std::getline(csv, line)) {
        std::vector<std::string> cells = split(line);
        ASSERT_LE(cells.size(), 5 + paths) << line;
        cells.resize(5 + paths);
        const double e = std::stod(cells[3]), t = std::stod(cells[4]);
        EXPECT_TRUE(std::isfinite(e) && e >= 0) << line;
        EXPECT_TRUE(std::isfinite(t) && t > 0) << line;
        // The augmentation and burst-statistics knobs run dispatched loops: timed on every path.
        const bool dispatched = cells[0].rfind("Calibration", 0) != 0 && cells[0] != "Shapiro-Wilk";
        for (size_t k = 5; k < cells.size(); ++k)
            if (dispatched)
                EXPECT_GT(std::stod(cells[k]), 0) << line;
            else
                EXPECT_TRUE(cells[k].empty()) << line;
        error[cells[1]] = e;
        errorOfKnob[cells[0] + " | " + cells[1]] = e;
        ++rows;
    }
    // 2 settings of 2 knobs, 4 blur rows, 2 burst lengths (--quick), 3 + 3, 2, and 2 for each of the
    // 3 dark-frame components.
    EXPECT_EQ(rows, 26);
    for (const char* component : {"Row noise", "Dark shading", "Read-noise tails"}) {
        const std::string knob = std::string(component) + " (dark-frame component) | ";
        EXPECT_LT(errorOfKnob[knob + "in the model"], errorOfKnob[knob + "absent from the model"] / 1.5)
            << knob;
    }
    // Text cells hold semicolons where the report has commas.
    EXPECT_LT(error["POISSON"], error["GAUSSIAN (paper)"] / 10) << "the lattice of a dark capture";
    EXPECT_LT(error["EXACT (Eq. 15); peaked 1x5 (1 4 6 4 1)"],
              error["FROM_BLURRED_MEAN; peaked 1x5 (1 4 6 4 1)"]);
    EXPECT_LT(error["LOCAL_MEAN"], error["PIXEL_VALUE (paper)"]) << "less clip bias at black";
    EXPECT_LT(error["float64 (default)"], error["float32"]);
    EXPECT_EQ(error["batched"], 0) << "batched Shapiro-Wilk gives the single form's numbers";
    r = runApp("rawgment_tradeoffs", "--quick --out='" + dir + "/t'");
    EXPECT_EQ(1, r.status) << "an existing report is never overwritten";
}

} // namespace
