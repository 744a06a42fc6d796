// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The rules every app keeps, each app run as a user runs it: --help, errors that name the flag, key or
// file, refused values, no temporaries or scripts left by killed runs, unwritable folders, hostile files.
#include "app_runs.hpp"

#include <gtest/gtest.h>
#include <opencv2/rawgment.hpp>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
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
    for (const char* replicates : {"1", "-3", "100001"})
        EXPECT_EQ(
            2, runApp("rawgment_calibrate", "m.yml --out='" + dir + "/c' --bootstrap=" + replicates).status)
            << replicates;
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

//! Small bursts at 6 and 18 dB in `dir`/sim, for the tests that need a calibration with plots.
AppRun simulateTwoGains(const std::string& dir)
{
    return runApp("rawgment_simulate",
                  "--out='" + dir +
                      "/sim' --frames=4 --gains=6,18 --levels=0.5 --format=png --validation=false");
}

std::string shellQuoted(const std::string& text)
{
    std::string quoted = "'";
    for (const char c : text)
        quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

TEST(Apps, aPlotsPathIsDataToGnuplotNeverAProgram)
{
    // An --out folder named to end gnuplot's quoted string and call system() ran the command: each
    // plot's data path went between single quotes unescaped. Every character gnuplot could act on is
    // in this one name: both quotes, backquotes, $(), a backslash, '@' (a macro), a newline and UTF-8.
    const std::string dir = freshDir("hostile_plot_paths");
    AppRun r = simulateTwoGains(dir);
    ASSERT_EQ(0, r.status) << r.output;
    const std::string hostile = "x'.system('touch PWNED1').'\" `touch PWNED2` $(touch PWNED3) \\ @x "
                                "\xc3\xa9\nline";
    const std::string out = dir + "/" + hostile;
    for (const char* name : {"PWNED1", "PWNED2", "PWNED3"})
        std::remove(name);
    r = runApp("rawgment_calibrate", shellQuoted(dir + "/sim/manifest.yml") + " --out=" + shellQuoted(out));
    ASSERT_EQ(0, r.status) << r.output;
    for (const char* name : {"PWNED1", "PWNED2", "PWNED3"}) {
        EXPECT_FALSE(exists(name)) << name;
        EXPECT_FALSE(exists(dir + "/" + name)) << name;
    }
    for (const char* png : {"calib_mean_variance.png", "calib_histograms.png", "calib_cross_gain.png"})
        expectPngDecodes(out + "/" + png);
    // The saved script names its files by the same escapes, so that a user can run it as it is.
    const std::string script = readText(out + "/calib_mean_variance.png.gp");
    EXPECT_EQ(std::string::npos, script.find("PWNED1')")) << script;
    EXPECT_NE(std::string::npos, script.find("\\047")) << script;
}

TEST(Apps, aPathWithBracketsOrBracesIsTextInEveryFileAnAppWrites)
{
    // An input "[in].png" broke the sidecar's YAML ("The closing '}' does not match the opening ']'"):
    // OpenCV's `fs << path` opened a list for it (#79 item 18). Every writer now writes paths as strings.
    const std::string dir = freshDir("brackets");
    AppRun r = simulateTwoGains(dir);
    ASSERT_EQ(0, r.status) << r.output;
    const std::string input = dir + "/[in] {x}.png";
    ASSERT_EQ(0, std::system(("cp '" + dir + "/sim/g06dB_level0.50/frame_000.png' '" + input + "' && cp '" +
                              dir + "/sim/g06dB_level0.50/frame_000.png.yml' '" + input + ".yml'")
                                 .c_str()));
    writeExposureScene(dir + "/[scene].yml", 0.25, 2.0);
    r = runApp("rawgment_augment", "--model='" + dir + "/sim/truth_noise_model.yml' --scene='" + dir +
                                       "/[scene].yml' --out='" + dir + "/{out}' '" + input + "'");
    ASSERT_EQ(0, r.status) << r.output;
    cv::Mat mosaic;
    const cv::rawgment::MosaicMetadata meta =
        cv::rawgment::readMosaic(dir + "/{out}/[in] {x}_v00.png", mosaic);
    EXPECT_EQ(input, meta.source);
    EXPECT_FALSE(mosaic.empty());
}

TEST(Apps, aFileSizeLimitIsAnErrorNamingTheFileAsAFullDiskIs)
{
    // Under `ulimit -f 16` rawgment_calibrate was killed by SIGXFSZ (exit 153), without a word, and left
    // samples.csv.tmp-*.
    const std::string dir = freshDir("file_size_limit");
    AppRun r = simulateTwoGains(dir);
    ASSERT_EQ(0, r.status) << r.output;
    const std::string log = dir + "/limited.log", out = dir + "/cal";
    const std::string command = "(ulimit -f 16; exec '" + std::string(RAWGMENT_APP_DIR) +
                                "/rawgment_calibrate' '" + dir + "/sim/manifest.yml' --out='" + out +
                                "') > '" + log + "' 2>&1";
    const int raw = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(raw)) << "killed by a signal: " << (WIFSIGNALED(raw) ? WTERMSIG(raw) : 0);
    EXPECT_EQ(1, WEXITSTATUS(raw));
    const std::string output = readText(log);
    EXPECT_NE(std::string::npos, output.find(std::strerror(EFBIG))) << output;
    EXPECT_NE(std::string::npos, output.find(out + "/")) << output;
    if (exists(out))
        for (const auto& entry : std::filesystem::recursive_directory_iterator(out))
            EXPECT_EQ(std::string::npos, entry.path().string().find(".tmp-")) << entry.path();
}

TEST(Apps, aRunRemovesTheTemporariesThatKilledRunsLeft)
{
    const std::string dir = freshDir("interrupts");
    // A temporary that a killed run (a pid that is gone) left is removed by the next run in that folder.
    pid_t gone = 4194000;
    while (::kill(gone, 0) == 0 || errno != ESRCH)
        --gone;
    std::ofstream(dir + "/manifest.yml.tmp-" + std::to_string(gone) + "-0") << "half a file";
    // Round 5 item 16: a user's files whose names look like temporaries, but not of this job's outputs,
    // stay; the cleanup used to walk the tree and remove "sub/thesis.tmp-20240101-1".
    ::mkdir((dir + "/sub").c_str(), 0755);
    const std::vector<std::string> users = {"sub/thesis.tmp-20240101-1",
                                            "notes.txt.tmp-" + std::to_string(gone) + "-0",
                                            "sub/manifest.yml.tmp-" + std::to_string(gone) + "-0"};
    for (const std::string& name : users)
        std::ofstream(dir + "/" + name) << "the user's";
    AppRun r =
        runApp("rawgment_simulate", "--out='" + dir + "' --frames=3 --gains=6 --levels=0.5 --format=png");
    ASSERT_EQ(0, r.status) << r.output;
    EXPECT_NE(std::string::npos, r.output.find("removed 1 temporary file(s)")) << r.output;
    EXPECT_FALSE(exists(dir + "/manifest.yml.tmp-" + std::to_string(gone) + "-0"));
    for (const std::string& name : users)
        EXPECT_TRUE(exists(dir + "/" + name)) << name;
}

TEST(Apps, aRunStoppedWhileAPlotIsDrawnLeavesNoScriptBehind)
{
    // SIGINT while gnuplot ran left "<plot>.gp.<pid>.run" in the output folder. The run is stopped the
    // moment it has a gnuplot running on a plot script (a child process whose command line names one),
    // and nothing but finished files may stay.
    const std::string dir = freshDir("interrupted_plot");
    AppRun r = simulateTwoGains(dir);
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

} // namespace
