// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "cpu_dispatch.hpp"
#include "precomp.hpp"

#include <atomic>
#include <cstdlib>

namespace cv {
namespace rawgment {

namespace {

const char* const kNames[] = {"auto", "baseline", "sse4.2", "avx2", "avx512"};

bool cpuRuns(CpuPath path)
{
#if RAWGMENT_HAVE_CPU_PATHS
    switch (path) {
    case CpuPath::AUTO:
    case CpuPath::BASELINE:
        return true;
    case CpuPath::SSE42:
        return __builtin_cpu_supports("x86-64-v2");
    case CpuPath::AVX2:
        return __builtin_cpu_supports("x86-64-v3");
    case CpuPath::AVX512:
        return __builtin_cpu_supports("x86-64-v4");
    }
    return false;
#else
    return path == CpuPath::AUTO || path == CpuPath::BASELINE;
#endif
}

CpuPath best()
{
    for (CpuPath p : {CpuPath::AVX512, CpuPath::AVX2, CpuPath::SSE42})
        if (cpuRuns(p))
            return p;
    return CpuPath::BASELINE;
}

String availableList()
{
    String list;
    for (CpuPath p : availableCpuPaths())
        list += (list.empty() ? "" : ", ") + cpuPathName(p);
    return list;
}

// The path chosen by RAWGMENT_CPU_PATH, or -1 with the reason it cannot be used; read once.
struct EnvironmentChoice
{
    int path = static_cast<int>(CpuPath::AUTO);
    String error;
};

const EnvironmentChoice& environmentChoice()
{
    static const EnvironmentChoice choice = [] {
        EnvironmentChoice c;
        const char* value = std::getenv("RAWGMENT_CPU_PATH");
        if (!value || !*value)
            return c;
        for (int i = 0; i < 5; ++i)
            if (String(value) == kNames[i]) {
                if (!cpuRuns(static_cast<CpuPath>(i))) {
                    c.error = format("RAWGMENT_CPU_PATH=%s: this CPU cannot run it (it runs %s)", value,
                                     availableList().c_str());
                    c.path = -1;
                } else {
                    c.path = i;
                }
                return c;
            }
        c.error = format(
            "RAWGMENT_CPU_PATH=%s names no path (expected auto, baseline, sse4.2, avx2 or avx512)", value);
        c.path = -1;
        return c;
    }();
    return choice;
}

// The override of setCpuPath(); -1 until it is called.
std::atomic<int> g_forced{-1};

} // namespace

bool isCpuPathAvailable(CpuPath path)
{
    return cpuRuns(path);
}

std::vector<CpuPath> availableCpuPaths()
{
    std::vector<CpuPath> paths;
    for (CpuPath p : {CpuPath::BASELINE, CpuPath::SSE42, CpuPath::AVX2, CpuPath::AVX512})
        if (cpuRuns(p))
            paths.push_back(p);
    return paths;
}

void setCpuPath(CpuPath path)
{
    const int value = static_cast<int>(path);
    if (value < 0 || value > static_cast<int>(CpuPath::AVX512))
        CV_Error(Error::StsBadArg, format("setCpuPath: %d is not a CpuPath", value));
    if (!cpuRuns(path))
        CV_Error(Error::StsBadArg, format("setCpuPath: this CPU cannot run %s (it runs %s)",
                                          cpuPathName(path).c_str(), availableList().c_str()));
    g_forced = value;
}

CpuPath activeCpuPath()
{
    int chosen = g_forced.load();
    if (chosen < 0) {
        const EnvironmentChoice& env = environmentChoice();
        if (env.path < 0)
            CV_Error(Error::StsBadArg, env.error);
        chosen = env.path;
    }
    // The CPU does not change under a running process: its best path is found once (every hot row asks).
    static const CpuPath bestPath = best();
    return chosen == static_cast<int>(CpuPath::AUTO) ? bestPath : static_cast<CpuPath>(chosen);
}

String cpuPathName(CpuPath path)
{
    const int value = static_cast<int>(path);
    if (value < 0 || value > static_cast<int>(CpuPath::AVX512))
        CV_Error(Error::StsBadArg, format("cpuPathName: %d is not a CpuPath", value));
    return kNames[value];
}

namespace detail {

CpuPath dispatchPath()
{
    // activeCpuPath() is cheap (an atomic load and a cached environment); an invalid environment throws
    // from the first hot loop, whose callers' parallel loops pass cv::Exception on.
    return activeCpuPath();
}

} // namespace detail

} // namespace rawgment
} // namespace cv
