// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// rawgment_simulate: resuming only the same job, gains kept apart, the seed in every burst.
#include "app_runs.hpp"

#include <gtest/gtest.h>
#include <opencv2/rawgment.hpp>

#include <algorithm>
#include <cstring>

namespace {

using namespace rawgment_app_tests;

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

} // namespace
