// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The simple ISP and RAW reading on 12-megapixel mosaics, all in one run:
//   renderSimpleIsp (bilinear, edge-aware, half size; 8-bit output),
//   the same preview composed naively with OpenCV calls (convertTo, cv::demosaicing, cv::pow),
//   readRaw of a 4000x3000 DNG written by writeDng, and of ../shared/data/colorchart.dng when present.
#include "perf_common.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/rawgment/isp.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <cstdio>
#include <unistd.h>

namespace {

using namespace cv;
using namespace cv::rawgment;

RawFormat frameFormat()
{
    return perf::perfFrameFormat();
}

const Mat& frame()
{
    return perf::perfFrame();
}

void BM_Isp_renderSimpleIsp(benchmark::State& state)
{
    IspParams p;
    p.demosaic = static_cast<DemosaicMethod>(state.range(0));
    Mat out;
    for (auto _ : state) {
        renderSimpleIsp(frame(), frameFormat(), out, p);
        benchmark::DoNotOptimize(out.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(frame().total()));
    state.SetLabel(p.demosaic == DEMOSAIC_BILINEAR     ? "bilinear"
                   : p.demosaic == DEMOSAIC_EDGE_AWARE ? "edge-aware"
                                                       : "half size");
}

void BM_Isp_naiveOpenCV(benchmark::State& state)
{
    // The same bilinear gamma-5 preview from whole-frame OpenCV operations and float temporaries.
    const RawFormat f = frameFormat();
    Mat normalised, codes, bgr16, bgr, toned, out;
    for (auto _ : state) {
        frame().convertTo(normalised, CV_32F, 1.0 / (f.whiteLevel - f.blackLevel[0]),
                          -f.blackLevel[0] / (f.whiteLevel - f.blackLevel[0]));
        normalised = cv::max(cv::min(normalised, 1.0), 0.0);
        normalised.convertTo(codes, CV_16U, 65535.0);
        demosaicing(codes, bgr16, COLOR_BayerBG2BGR);
        bgr16.convertTo(bgr, CV_32F, 1.0 / 65535);
        pow(bgr, 1.0 / 5.0, toned);
        toned.convertTo(out, CV_8U, 255.0);
        benchmark::DoNotOptimize(out.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(frame().total()));
}

const std::string& syntheticDng()
{
    static const std::string path = [] {
        const std::string p = "/tmp/rawgment_perf_isp_" + std::to_string(::getpid()) + ".dng";
        RawImage img;
        img.mosaic = frame();
        img.format = frameFormat();
        writeDng(p, img);
        return p;
    }();
    return path;
}

void BM_RawIo_readRawSyntheticDng(benchmark::State& state)
{
    const std::string& path = syntheticDng();
    for (auto _ : state) {
        RawImage img = readRaw(path);
        benchmark::DoNotOptimize(img.mosaic.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(frame().total()));
}

void BM_RawIo_readRawColorchartDng(benchmark::State& state)
{
    const std::string path = std::string(RAWGMENT_SHARED_DATA_DIR) + "/colorchart.dng";
    if (::access(path.c_str(), R_OK) != 0) {
        state.SkipWithError("../shared/data/colorchart.dng not found");
        return;
    }
    int64_t pixels = 0;
    for (auto _ : state) {
        RawImage img = readRaw(path);
        pixels += static_cast<int64_t>(img.mosaic.total());
        benchmark::DoNotOptimize(img.mosaic.data);
    }
    state.SetItemsProcessed(pixels);
}

BENCHMARK(BM_Isp_renderSimpleIsp)
    ->Arg(DEMOSAIC_BILINEAR)
    ->Arg(DEMOSAIC_EDGE_AWARE)
    ->Arg(DEMOSAIC_HALF_SIZE)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Isp_naiveOpenCV)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RawIo_readRawSyntheticDng)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_RawIo_readRawColorchartDng)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace

int main(int argc, char** argv)
{
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    std::remove(syntheticDng().c_str());
    return 0;
}
