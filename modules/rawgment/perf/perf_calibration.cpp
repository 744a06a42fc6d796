// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Calibration hot paths:
//   burst statistics of 100 frames of 4000x3000 CV_16UC1 against
//     - memcpy of the same input bytes (the floor: every byte must be read once),
//     - a naive OpenCV composition (convertTo, accumulate, accumulateSquare, then mean and variance);
//   the whole cross-gain fit on the paper-scale patch data (3 gains x 27,648 samples).
// The burst statistics run on the best CpuPath with every setting, and with the default setting on
// every path this CPU has (name suffix /baseline, /sse4.2, /avx2, /avx512).
#include "perf_common.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/calibration.hpp>
#include <opencv2/rawgment/cpu.hpp>

#include <cstring>

namespace {

using namespace cv;
using namespace cv::rawgment;

const Size kFrameSize(4000, 3000);
const int kFrames = 100;
const int kDistinctFrames = 4; // cycled: generating 100 distinct 12 MP frames would dominate set-up

const std::vector<Mat>& frames()
{
    static const std::vector<Mat> f = [] {
        std::vector<Mat> out(kDistinctFrames);
        RNG rng(7);
        for (Mat& m : out) {
            m.create(kFrameSize, CV_16UC1);
            rng.fill(m, RNG::NORMAL, 2000, 40);
        }
        return out;
    }();
    return f;
}

RawFormat format12bit()
{
    RawFormat f;
    f.blackLevel = Vec4d::all(256);
    f.whiteLevel = 4095;
    return f;
}

void setBytes(benchmark::State& state)
{
    state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(kFrames) * kFrameSize.area() * 2);
}

void BM_BurstStatistics_rawgment(benchmark::State& state)
{
    const std::vector<Mat>& f = frames();
    for (auto _ : state) {
        BurstStatistics stats(format12bit(), static_cast<int>(state.range(0)),
                              static_cast<int>(state.range(1)));
        for (int t = 0; t < kFrames; ++t)
            stats.add(f[t % kDistinctFrames]);
        Mat mean, var;
        stats.mean(mean);
        stats.variance(var);
        benchmark::DoNotOptimize(var.data);
    }
    setBytes(state);
    state.SetLabel(state.range(1) == CV_64F ? "float64 state" : "float32 state");
}

/* The same bursts through one object reset between them, as a calibration over many bursts runs: the state
 * and the group buffers are touched once, before the timing, instead of once per burst. */
void BM_BurstStatistics_rawgment_reused(benchmark::State& state)
{
    const std::vector<Mat>& f = frames();
    BurstStatistics stats(format12bit(), static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
    Mat mean, var;
    const auto oneBurst = [&] {
        stats.reset(format12bit());
        for (int t = 0; t < kFrames; ++t)
            stats.add(f[t % kDistinctFrames]);
        stats.mean(mean);
        stats.variance(var);
        benchmark::DoNotOptimize(var.data);
    };
    oneBurst();
    for (auto _ : state)
        oneBurst();
    setBytes(state);
    state.SetLabel(state.range(1) == CV_64F ? "float64 state, reused" : "float32 state, reused");
}

void BM_BurstStatistics_memcpy(benchmark::State& state)
{
    const std::vector<Mat>& f = frames();
    Mat dst(kFrameSize, CV_16UC1);
    for (auto _ : state) {
        for (int t = 0; t < kFrames; ++t)
            std::memcpy(dst.data, f[t % kDistinctFrames].data, dst.total() * dst.elemSize());
        benchmark::DoNotOptimize(dst.data);
        benchmark::ClobberMemory();
    }
    setBytes(state);
}

void BM_BurstStatistics_naiveOpenCV(benchmark::State& state)
{
    const std::vector<Mat>& f = frames();
    for (auto _ : state) {
        Mat sum = Mat::zeros(kFrameSize, CV_64F), sum2 = Mat::zeros(kFrameSize, CV_64F), x;
        for (int t = 0; t < kFrames; ++t) {
            f[t % kDistinctFrames].convertTo(x, CV_64F, 1.0, -256.0);
            accumulate(x, sum);
            accumulateSquare(x, sum2);
        }
        // Textbook sums (numerically fragile for large means, which BurstStatistics avoids).
        Mat mean = sum / kFrames;
        Mat var = (sum2 - sum.mul(mean)) / (kFrames - 1);
        benchmark::DoNotOptimize(var.data);
    }
    setBytes(state);
}

//! Paper-scale samples drawn from the model: 3 gains x 2 illuminations x 24 patches x 576 pixels.
const std::vector<NoiseSample>& paperScaleSamples()
{
    static const std::vector<NoiseSample> s = [] {
        const NoiseModel truth(0.4, 0.5, 2.0 + 1.0 / 12);
        std::vector<NoiseSample> out;
        RNG rng(11);
        for (double db : {6.0, 12.0, 24.0}) {
            const double g = dbToLinearGain(db);
            for (int i = 0; i < 2 * 24 * 576; ++i) {
                NoiseSample n;
                n.gain = g;
                n.dof = 99;
                n.mean = rng.uniform(5.0, 2500.0);
                const double v = truth.variance(n.mean, g);
                n.variance = std::max(0.0, v * (1.0 + std::sqrt(2.0 / 99) * rng.gaussian(1.0)));
                out.push_back(n);
            }
        }
        return out;
    }();
    return s;
}

void BM_CalibrationFit(benchmark::State& state)
{
    const std::vector<NoiseSample>& samples = paperScaleSamples();
    CalibrationParams params;
    params.method = static_cast<NoiseFitMethod>(state.range(0));
    for (auto _ : state) {
        const CalibrationReport r = calibrateNoiseModel(samples, params);
        benchmark::DoNotOptimize(r.model.alpha);
    }
    state.SetLabel(params.method == NOISE_FIT_JOINT ? "joint" : "two-stage");
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(samples.size()));
}

} // namespace

int main(int argc, char** argv)
{
    // "CPU" is the process's CPU time over all threads; "stolen" the hypervisor's share (perf_common.hpp).
    // The arguments are groupFrames (memory: that many buffered frames, against state traffic) and the
    // state's depth (float64, or float32 with half the traffic).
    perf::registerTimed("BM_BurstStatistics_rawgment", BM_BurstStatistics_rawgment)
        ->Args({8, CV_64F})
        ->Args({16, CV_64F})
        ->Args({32, CV_64F})
        ->Args({8, CV_32F})
        ->Args({16, CV_32F})
        ->Iterations(3);
    for (benchmark::internal::Benchmark* b :
         perf::registerOnEveryCpuPath("BM_BurstStatistics_rawgment", BM_BurstStatistics_rawgment))
        b->Args({8, CV_64F})->Iterations(3);
    perf::registerTimed("BM_BurstStatistics_rawgment_reused", BM_BurstStatistics_rawgment_reused)
        ->Args({8, CV_64F})
        ->Args({8, CV_32F})
        ->Iterations(3);
    perf::registerTimed("BM_BurstStatistics_memcpy", BM_BurstStatistics_memcpy)->Iterations(3);
    perf::registerTimed("BM_BurstStatistics_naiveOpenCV", BM_BurstStatistics_naiveOpenCV)->Iterations(2);
    perf::registerTimed("BM_CalibrationFit", BM_CalibrationFit)
        ->Arg(NOISE_FIT_JOINT)
        ->Arg(NOISE_FIT_TWO_STAGE);
    return perf::runRegisteredBenchmarks(argc, argv);
}
