// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The pipeline layer (pipeline/) called directly, as the apps and the Python module call it: output
// names that stay put, writes that never replace another file, output folders, conversions and
// augmentation jobs that give the same bytes wherever they run.
#include "augment_jobs.hpp"
#include "output_files.hpp"

#include <gtest/gtest.h>
#include <opencv2/rawgment.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace cv::rawgment;
using namespace rawgment_pipeline;

//! A new, empty folder for one test under the system's temporary folder.
std::string freshFolder(const std::string& name)
{
    const fs::path dir =
        fs::temp_directory_path() / ("rawgment_pipeline_test_" + std::to_string(getpid())) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir.string();
}

std::string bytesOf(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

//! A 64x48 mosaic of the reference format at gain 2, written with its sidecar.
void writeInput(const std::string& path, int level)
{
    RawFormat format;
    format.blackLevel = cv::Vec4d::all(64);
    format.whiteLevel = 4095;
    format.gain = 2;
    cv::Mat mosaic(48, 64, CV_16UC1);
    cv::randu(mosaic, level, level + 200);
    MosaicMetadata meta;
    meta.format = format;
    writeMosaic(path, mosaic, meta);
}

TEST(Pipeline, outputNamesAreStemsUntilTheyCollideAndNeverChangeInALaterRun)
{
    const auto none = [](size_t, const std::string&) { return std::optional<std::string>(); };
    EXPECT_EQ(uniqueOutputNames({"a/x.dng", "a/y.dng"}, none), (std::vector<std::string>{"x", "y"}));
    const std::vector<std::string> both = uniqueOutputNames({"a/x.dng", "b/x.dng"}, none);
    EXPECT_EQ(both[0], "x");
    ASSERT_EQ(both[1].size(), 1 + 1 + 8u) << both[1];
    EXPECT_EQ(both[1].substr(0, 2), "x-");
    // A later run that adds b/x.dng before a/x.dng: a/x.dng's existing output x records it, so it keeps x.
    const auto existing = [](size_t, const std::string& name) {
        return name == "x" ? std::optional<std::string>("a/x.dng") : std::optional<std::string>();
    };
    const std::vector<std::string> later = uniqueOutputNames({"b/x.dng", "a/x.dng"}, existing);
    EXPECT_EQ(later[1], "x");
    EXPECT_EQ(later[0], both[1]) << "b/x.dng is named by its path's hash, whatever the order";
    EXPECT_THROW(uniqueOutputNames({"a/x.dng", "a/x.dng"}, none), std::runtime_error);
}

TEST(Pipeline, aNewFileNeverReplacesAnotherButKeepsItsOwnBytes)
{
    const std::string dir = freshFolder("never_replace");
    const std::string path = dir + "/report.md";
    writeNewText(path, "first");
    EXPECT_NO_THROW(writeNewText(path, "first")) << "the same bytes: an interrupted run of the same job";
    try {
        writeNewText(path, "second");
        ADD_FAILURE() << "a different file was replaced";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_EQ(bytesOf(path), "first");
    const cv::Mat image(8, 8, CV_8UC3, cv::Scalar(1, 2, 3));
    writeNewImage(dir + "/a.png", image);
    EXPECT_NO_THROW(writeNewImage(dir + "/a.png", image));
    EXPECT_THROW(writeNewImage(dir + "/a.png", image + cv::Scalar::all(1)), std::runtime_error);
    writeTextAtomically(path, "replaced on purpose");
    EXPECT_EQ(bytesOf(path), "replaced on purpose");
    EXPECT_TRUE(isRegularFile(path));
    EXPECT_FALSE(isRegularFile(dir));
    EXPECT_TRUE(pathExists(dir));
    EXPECT_FALSE(pathExists(dir + "/missing"));
}

TEST(Pipeline, anOutputFolderLosesOnlyTheTemporariesOfItsOutputsWhoseRunsAreGone)
{
    const std::string dir = freshFolder("temporaries");
    // A process id that is not running: fork a child that exits at once, and wait for it.
    const pid_t gone = fork();
    if (gone == 0)
        _exit(0);
    ASSERT_GT(gone, 0);
    int status = 0;
    ASSERT_EQ(waitpid(gone, &status, 0), gone);
    const std::string stale = dir + "/out.npy.tmp-" + std::to_string(gone) + "-1";
    // The parent (ctest or a shell) is alive; this process's own pid would collide with its own writer's
    // names.
    const std::string live = dir + "/out.npy.tmp-" + std::to_string(getppid()) + "-1";
    for (const std::string& p : {stale, live, dir + "/keep.npy"})
        std::ofstream(p) << "x";
    const std::string other = dir + "/other.npy.tmp-" + std::to_string(gone) + "-1";
    std::ofstream(other) << "x";
    prepareOutputDirectory(dir);
    EXPECT_TRUE(pathExists(stale)) << "preparing a folder removes nothing (round 5 item 16)";
    writeNewText(dir + "/out.npy", "new");
    EXPECT_FALSE(pathExists(stale)) << "a killed run's temporary of this output stays";
    EXPECT_TRUE(pathExists(live)) << "a running process's temporary was removed";
    EXPECT_TRUE(pathExists(other)) << "a temporary of a file this run did not write was removed";
    EXPECT_TRUE(pathExists(dir + "/keep.npy"));
    prepareOutputDirectory(dir + "/new/nested");
    EXPECT_TRUE(fs::is_directory(dir + "/new/nested"));
    std::ofstream(dir + "/file") << "x";
    EXPECT_THROW(prepareOutputDirectory(dir + "/file/below"), std::runtime_error);
}

TEST(Pipeline, pathsResolveAndNameTheirParts)
{
    EXPECT_EQ(stemOf("a/b/frame.01.npy"), "frame.01");
    EXPECT_EQ(directoryOf("a/b/frame.npy"), "a/b");
    EXPECT_EQ(directoryOf("frame.npy"), ".");
    EXPECT_EQ(resolvePath("/data/run", "x.npy"), "/data/run/x.npy");
    EXPECT_EQ(resolvePath("/data/run", "/abs/x.npy"), "/abs/x.npy");
    const std::string dir = freshFolder("paths");
    std::ofstream(dir + "/x.npy") << "x";
    EXPECT_TRUE(sameInput(dir + "/x.npy", dir + "/./x.npy"));
    EXPECT_FALSE(sameInput(dir + "/x.npy", dir + "/y.npy"));
}

TEST(Pipeline, conversionsSkipWhatTheyFinishedAndNeverTakeAnotherInputsOutput)
{
    const std::string dir = freshFolder("convert");
    writeInput(dir + "/a.npy", 300);
    writeInput(dir + "/b.npy", 900);
    int advanced = 0;
    const auto advance = [&] { ++advanced; };
    const ConvertResult first =
        convertMosaics({dir + "/a.npy", dir + "/b.npy"}, dir + "/out", ".npy", advance);
    EXPECT_EQ(first.written, 2);
    EXPECT_EQ(advanced, 2);
    cv::Mat source, converted;
    readMosaic(dir + "/a.npy", source);
    const MosaicMetadata meta = readMosaic(first.outputs[0], converted);
    EXPECT_EQ(cv::norm(source, converted, cv::NORM_INF), 0);
    EXPECT_EQ(meta.source, dir + "/a.npy");
    const ConvertResult again =
        convertMosaics({dir + "/a.npy", dir + "/b.npy"}, dir + "/out", ".npy", advance);
    EXPECT_EQ(again.written, 0);
    EXPECT_EQ(again.skipped, 2);
    // Another input whose output name is taken by a's output: named apart, never written over it.
    fs::create_directories(dir + "/other");
    writeInput(dir + "/other/a.npy", 1500);
    const ConvertResult other = convertMosaics({dir + "/other/a.npy"}, dir + "/out", ".npy", advance);
    EXPECT_EQ(other.written, 1);
    EXPECT_NE(other.outputs[0], first.outputs[0]);
    EXPECT_THROW(
        convertMosaics({dir + "/out/" + stemOf(first.outputs[0]) + ".npy"}, dir + "/out", ".npy", advance),
        std::runtime_error)
        << "an input inside the output folder";
}

TEST(Pipeline, aJobGivesTheSameBytesInAnyFolderAndAFinishedRunIsNotRedone)
{
    const std::string dir = freshFolder("jobs");
    writeInput(dir + "/in.npy", 500);
    NoiseModel(0.4, 0.5, 2.0).save(dir + "/model.yml");
    {
        cv::FileStorage fs(dir + "/scene.yml", cv::FileStorage::WRITE);
        Scene scene;
        scene.jitter = ColorJitter::exposureChange(0.25, 2.0);
        scene.scale = 1.02;
        scene.write(fs, "scene");
    }
    std::map<std::string, std::string> bytes[2];
    for (int run = 0; run < 2; ++run) {
        AugmentOptions o;
        o.inputs = {dir + "/in.npy"};
        o.model = dir + "/model.yml";
        o.scene = dir + "/scene.yml";
        o.outDir = dir + "/out" + std::to_string(run);
        o.variants = 2;
        o.seed = 7;
        const AugmentPlan plan = planAugmentJobs(o);
        ASSERT_EQ(plan.jobs.size(), 2u);
        EXPECT_NE(plan.jobs[0].seed, plan.jobs[1].seed);
        const AugmentRecipe recipe = loadAugmentRecipe(o);
        for (const AugmentJob& job : plan.jobs) {
            runAugmentJob(job, recipe);
            bytes[run][stemOf(job.out)] = bytesOf(job.out);
        }
        const AugmentPlan replanned = planAugmentJobs(o);
        EXPECT_TRUE(replanned.jobs.empty()) << "a finished run is done again";
        EXPECT_EQ(replanned.skipped, 2);
    }
    EXPECT_EQ(bytes[0], bytes[1]);
    EXPECT_NE(bytes[0].begin()->second, std::next(bytes[0].begin())->second) << "two variants, one output";
}

} // namespace
