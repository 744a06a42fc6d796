// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Running the apps of this build as a user runs them, for the end-to-end tests (app_runs.hpp).
#include "app_runs.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment.hpp>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace rawgment_app_tests {

std::string readText(const std::string& path)
{
    std::ifstream f(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

bool exists(const std::string& path)
{
    return std::ifstream(path).good();
}

std::pair<AppRun, AppRun> runTwiceAtOnce(const std::string& command, const std::string& dir)
{
    const auto one = [&](int k) {
        return "(" + command + " > '" + dir + "/log" + std::to_string(k) + "' 2>&1; echo $? > '" + dir +
               "/status" + std::to_string(k) + "')";
    };
    const std::string both = one(1) + " & " + one(2) + " & wait";
    if (std::system(both.c_str()) != 0)
        return {};
    const auto result = [&](int k) {
        AppRun r;
        const std::string status = readText(dir + "/status" + std::to_string(k));
        r.status = status.empty() ? -1 : std::atoi(status.c_str());
        r.output = readText(dir + "/log" + std::to_string(k));
        return r;
    };
    return {result(1), result(2)};
}

AppRun runApp(const std::string& app, const std::string& args, AllocationStacks stacks)
{
    static int counter = 0;
    const std::string log = ::testing::TempDir() + "/rawgment_app_" + std::to_string(::getpid()) + "_" +
                            std::to_string(counter++) + ".log";
    std::string command = std::string(RAWGMENT_APP_DIR) + "/" + app + " " + args;
    if (app == "rawgment_calibrate" && args.find("--bootstrap") == std::string::npos &&
        args.find("--emva") == std::string::npos)
        command += sanitizedBootstrapArgument();
    command += " > '" + log + "' 2>&1";
#ifdef RAWGMENT_LSAN_SUPPRESSIONS
    // The apps' own processes need the suppressions of OpenCV's process-lifetime caches too, also when
    // ctest runs here directly rather than through scripts/test.sh (whose LSAN_OPTIONS, if set, wins).
    if (!std::getenv("LSAN_OPTIONS"))
        command = "LSAN_OPTIONS='suppressions=" + std::string(RAWGMENT_LSAN_SUPPRESSIONS) + "' " + command;
    if (stacks == AllocationStacks::FULL) {
        const char* asan = std::getenv("ASAN_OPTIONS");
        command = "ASAN_OPTIONS='" + std::string(asan != nullptr ? asan : "") + ":fast_unwind_on_malloc=0' " +
                  command;
    }
#else
    (void)stacks;
#endif
    const int raw = std::system(command.c_str());
    AppRun r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.output = readText(log);
    std::remove(log.c_str());
    return r;
}

namespace {

//! Removes the folders of freshDir() when the test passed; a failed test leaves them for a look.
class ScratchFolders : public ::testing::Environment
{
public:
    void add(const std::string& dir) { dirs_.push_back(dir); }
    void TearDown() override
    {
        if (!::testing::UnitTest::GetInstance()->Passed())
            return;
        for (const std::string& dir : dirs_)
            EXPECT_EQ(0, std::system(("rm -rf '" + dir + "'").c_str())) << dir;
    }

private:
    std::vector<std::string> dirs_;
};
ScratchFolders* const scratchFolders =
    static_cast<ScratchFolders*>(::testing::AddGlobalTestEnvironment(new ScratchFolders));

} // namespace

std::string freshDir(const std::string& name)
{
    const std::string dir = ::testing::TempDir() + "/rawgment_e2e_" + name + "_" + std::to_string(::getpid());
    const std::string command = "rm -rf '" + dir + "' && mkdir -p '" + dir + "'";
    EXPECT_EQ(0, std::system(command.c_str()));
    scratchFolders->add(dir);
    return dir;
}

//! Writes a scene file of an exposure change (ColorJitter::exposureChange) to `path`.
void writeExposureScene(const std::string& path, double photonRatio, double gainRatio)
{
    cv::rawgment::Scene scene;
    scene.jitter = cv::rawgment::ColorJitter::exposureChange(photonRatio, gainRatio);
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    scene.write(fs, "scene");
}

//! gnuplot is a dependency (scripts/install-deps.sh), so every plot must exist and decode.
void expectPngDecodes(const std::string& path)
{
    EXPECT_FALSE(cv::imread(path).empty()) << path << " does not decode";
}

} // namespace rawgment_app_tests
