// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Running the apps of this build as a user runs them: what the app tests (test/test_app_*.cpp) share.
// RAWGMENT_APP_DIR names the apps' folder.
#ifndef RAWGMENT_TEST_APP_RUNS_HPP
#define RAWGMENT_TEST_APP_RUNS_HPP

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <utility>

namespace rawgment_app_tests {

/** Whether this build checks what many frames buy. The sanitizer build runs each app about five times slower
 * (host H3: the 32-frame end-to-end test 12 s in Release, 56 s instrumented): there the tests that simulate
 * more frames than the calibration verdict needs simulate fewer, which run the same code, and leave their
 * accuracy bounds (derived for the full count) to the Release build. */
#ifdef RAWGMENT_SANITIZED_BUILD
constexpr bool kAccuracyChecked = false;
#else
constexpr bool kAccuracyChecked = true;
#endif

/** The bootstrap replicates rawgment_calibrate runs with where accuracy is not checked, unless a test gives
 * --bootstrap: its 200 replicates are 60% of an instrumented calibration's time, and 20 run the same code. */
constexpr int kSanitizedBootstrapReplicates = 20;

//! The argument rawgment_calibrate takes that: " --bootstrap=20" where accuracy is not checked, else "".
inline std::string sanitizedBootstrapArgument()
{
    return kAccuracyChecked ? std::string() : " --bootstrap=" + std::to_string(kSanitizedBootstrapReplicates);
}

//! `frames` where accuracy is checked, else a quarter of them but at least 16, the fewest the verdict passes.
inline int framesOfThisBuild(int frames)
{
    return kAccuracyChecked ? frames : std::max(16, frames / 4);
}

//! An app's exit status and everything it printed.
struct AppRun
{
    int status = -1;
    std::string output;
};

//! The content of a file ("" when it cannot be read).
std::string readText(const std::string& path);
//! Whether a file can be opened.
bool exists(const std::string& path);

/** How the sanitizer build's apps record where memory was allocated. FAST follows frame pointers, which
 * stop at the first frame of Debian's OpenCV (built without them). FULL unwinds every frame from the
 * debugging information, which more than doubled the time of this file's calibrations (36 s to 89 s for
 * one test on host H2), so only the runs that detect a chart with cv::mcc ask for it: OpenCV's
 * colour-conversion tables, which it keeps for the process's life, are allocated deep inside
 * libopencv_imgproc, and test/lsan_suppressions.txt can match them only on a complete stack. */
enum class AllocationStacks
{
    FAST,
    FULL
};

/** Runs an app of this build with arguments (shell-quoted by the caller), capturing stdout and stderr; where
 * accuracy is not checked, rawgment_calibrate's light calibrations get kSanitizedBootstrapReplicates. */
AppRun runApp(const std::string& app, const std::string& args,
              AllocationStacks stacks = AllocationStacks::FAST);

/** Runs a shell command (an app of this build with its arguments, shell-quoted by the caller) twice at the
 * same time, each with its own log in `dir`: two identical runs racing for one folder. */
std::pair<AppRun, AppRun> runTwiceAtOnce(const std::string& command, const std::string& dir);
//! A fresh, empty folder for one test, removed at the end when every test passed.
std::string freshDir(const std::string& name);

//! Writes a scene file of an exposure change (ColorJitter::exposureChange) to `path`.
void writeExposureScene(const std::string& path, double photonRatio, double gainRatio);

//! gnuplot is a dependency (scripts/install-deps.sh), so every plot must exist and decode.
void expectPngDecodes(const std::string& path);

} // namespace rawgment_app_tests

#endif // RAWGMENT_TEST_APP_RUNS_HPP
