// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#ifndef OPENCV_RAWGMENT_CPU_HPP
#define OPENCV_RAWGMENT_CPU_HPP

#include <opencv2/core.hpp>
#include <opencv2/rawgment/export.hpp>

#include <vector>

namespace cv {
namespace rawgment {

//! @addtogroup rawgment_cpu
//! @{

/** @brief The instruction sets the hot loops are compiled for. One binary holds them all and picks the
 * best the CPU has; every path gives the same bits for the same seed (the loops use no fused
 * multiply-add and no reassociation), so the choice changes speed only.
 */
enum class CpuPath
{
    AUTO = 0, //!< the best path this CPU runs (the default)
    BASELINE, //!< x86-64 (SSE2): any 64-bit x86 CPU, and the only path elsewhere
    SSE42,    //!< x86-64-v2: SSE4.2, POPCNT
    AVX2,     //!< x86-64-v3: AVX2, FMA, BMI2 (most CPUs since 2013-2015)
    AVX512    //!< x86-64-v4: AVX-512 F, BW, CD, DQ, VL
};

//! Whether this CPU (and this build) can run `path`; AUTO always can.
CV_RAWGMENT_EXPORTS bool isCpuPathAvailable(CpuPath path);

//! The paths this CPU runs, from BASELINE up (never AUTO).
CV_RAWGMENT_EXPORTS std::vector<CpuPath> availableCpuPaths();

/** @brief Forces the path of every later call in this process (benchmarks, and tests that compare
 * paths); AUTO returns to the best available.
 *
 * The environment variable `RAWGMENT_CPU_PATH` (auto, baseline, sse4.2, avx2, avx512) sets the initial
 * choice; this call overrides it.
 * @throws cv::Exception when the CPU cannot run `path`.
 */
CV_RAWGMENT_EXPORTS void setCpuPath(CpuPath path);

/** @brief The path the hot loops run now (never AUTO).
 * @throws cv::Exception when `RAWGMENT_CPU_PATH` names no path or one this CPU cannot run.
 */
CV_RAWGMENT_EXPORTS CpuPath activeCpuPath();

//! The name of a path as `RAWGMENT_CPU_PATH` spells it: auto, baseline, sse4.2, avx2, avx512.
CV_RAWGMENT_EXPORTS String cpuPathName(CpuPath path);

//! @}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_CPU_HPP
