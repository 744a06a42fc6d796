// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The frame every benchmark works on (a 4000x3000 CV_16UC1 mosaic, 12-bit with black 256), and the
// registration of a benchmark on every CPU path.
#ifndef OPENCV_RAWGMENT_PERF_COMMON_HPP
#define OPENCV_RAWGMENT_PERF_COMMON_HPP

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/rawgment/bayer.hpp>
#include <opencv2/rawgment/cpu.hpp>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace cv {
namespace rawgment {
namespace perf {

//! The format of perfFrame() at a linear gain.
inline RawFormat perfFrameFormat(double gain = 1.0)
{
    RawFormat f;
    f.blackLevel = Vec4d::all(256);
    f.whiteLevel = 4095;
    f.gain = gain;
    return f;
}

//! A 12-megapixel mosaic of uniform random values between black and white, made once.
inline const Mat& perfFrame()
{
    static const Mat m = [] {
        Mat f(3000, 4000, CV_16UC1);
        RNG(5).fill(f, RNG::UNIFORM, 256, 4000);
        return f;
    }();
    return m;
}

/** The machine's CPU time stolen by the hypervisor and its total CPU time, in jiffies, from /proc/stat
 * (both 0 where it cannot be read). */
inline std::pair<double, double> stolenAndTotalJiffies()
{
    std::ifstream stat("/proc/stat");
    std::string cpu;
    double value = 0, total = 0, steal = 0;
    stat >> cpu;
    // user nice system idle iowait irq softirq steal (guest times are inside user and nice).
    for (int field = 0; field < 8 && stat >> value; ++field) {
        total += value;
        if (field == 7)
            steal = value;
    }
    return cpu == "cpu" ? std::make_pair(steal, total) : std::make_pair(0.0, 0.0);
}

/** Runs a benchmark and adds the counter "stolen": the share of the machine's CPU time its hypervisor
 * took during the run. A virtual machine whose cores are shared shows wall time well above CPU time
 * for no fault of the code; this counter says when that is the reason. */
inline void runWithStolenShare(void (*run)(benchmark::State&), benchmark::State& state)
{
    const std::pair<double, double> before = stolenAndTotalJiffies();
    run(state);
    const std::pair<double, double> after = stolenAndTotalJiffies();
    const double total = after.second - before.second;
    state.counters["stolen"] = total > 0 ? (after.first - before.first) / total : 0.0;
}

/** Registers `run` under `name` in milliseconds of wall time, with the process's CPU time over all
 * threads beside it and the counter "stolen" (runWithStolenShare()). */
inline benchmark::internal::Benchmark* registerTimed(const std::string& name, void (*run)(benchmark::State&))
{
    return benchmark::RegisterBenchmark(name.c_str(),
                                        [run](benchmark::State& state) { runWithStolenShare(run, state); })
        ->Unit(benchmark::kMillisecond)
        ->MeasureProcessCPUTime()
        ->UseRealTime();
}

/** Registers `run` once per CPU path this machine has, named `name/<path>` and run on that path, in
 * milliseconds of wall time with the process's CPU time over all threads beside it (on 2 cores a
 * fully parallel loop shows about twice its wall time; less tells how long a thread waited) and the
 * counter "stolen" (runWithStolenShare()). */
inline std::vector<benchmark::internal::Benchmark*> registerOnEveryCpuPath(const std::string& name,
                                                                           void (*run)(benchmark::State&))
{
    std::vector<benchmark::internal::Benchmark*> registered;
    for (CpuPath path : availableCpuPaths())
        registered.push_back(benchmark::RegisterBenchmark((name + "/" + cpuPathName(path)).c_str(),
                                                          [run, path](benchmark::State& state) {
                                                              setCpuPath(path);
                                                              runWithStolenShare(run, state);
                                                              setCpuPath(CpuPath::AUTO);
                                                          })
                                 ->Unit(benchmark::kMillisecond)
                                 ->MeasureProcessCPUTime()
                                 ->UseRealTime());
    return registered;
}

//! What BENCHMARK_MAIN() does, for programs that register their benchmarks in main().
inline int runRegisteredBenchmarks(int argc, char** argv)
{
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}

} // namespace perf
} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_PERF_COMMON_HPP
