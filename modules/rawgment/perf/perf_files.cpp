// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Reading the module's text files: openFileStorageForReading() (a bounded read, libyaml or nlohmann-json,
// the values written anew by OpenCV's writer, then OpenCV's parser) against cv::FileStorage opening the
// same file by itself, for a noise model, a mosaic's sidecar and darktable's noise profiles. The parse and
// write alone (textForOpenCv, the "validatorOnly" cases) are measured too, to show where the time goes.
#include "../src/precomp.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/rawgment/camera_profiles.hpp>
#include <opencv2/rawgment/files.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/noise_model.hpp>
#include <opencv2/rawgment/raw_io.hpp>

#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <unistd.h>

namespace {

using namespace cv::rawgment;

//! The files read, written once into a folder of their own: the kind's name, its path, its top-level map.
struct PerfFile
{
    std::string path;
    const char* topLevel;
};

std::string perfFolder()
{
    static const std::string folder = [] {
        char pattern[] = "/tmp/rawgment_perf_files_XXXXXX";
        if (!::mkdtemp(pattern))
            throw std::runtime_error("cannot create a folder for the benchmark's files");
        return std::string(pattern);
    }();
    return folder;
}

const PerfFile& modelFile()
{
    static const PerfFile f = [] {
        NoiseModel model(0.4, 0.5, 2.0);
        model.baseIso = 100;
        const std::string path = perfFolder() + "/noise_model.yml";
        model.save(path);
        return PerfFile{path, "noise_model"};
    }();
    return f;
}

const PerfFile& sidecarFile()
{
    static const PerfFile f = [] {
        MosaicMetadata metadata;
        metadata.format.blackLevel = cv::Vec4d::all(256);
        metadata.format.whiteLevel = 4095;
        metadata.hasScene = true;
        metadata.seed = 7;
        const std::string image = perfFolder() + "/mosaic.png";
        writeMosaic(image, cv::Mat(8, 8, CV_16UC1, cv::Scalar(300)), metadata);
        return PerfFile{sidecarPathOf(image), "mosaic_metadata"};
    }();
    return f;
}

//! darktable's own file where the install script put it, else the project's export of one camera.
const PerfFile& darktableFile()
{
    static const PerfFile f = [] {
        const std::string installed = darktableProfilesPath();
        if (!installed.empty())
            return PerfFile{installed, "noiseprofiles"};
        RawFormat format;
        format.blackLevel = cv::Vec4d::all(256);
        format.whiteLevel = 4095;
        const std::string text = darktableNoiseProfiles(NoiseModel(0.4, 0.5, 2.0), format, 100,
                                                        {100, 200, 400, 800}, "Maker", "Cam");
        const std::string path = perfFolder() + "/noiseprofiles.json";
        writeFileAtomically(path, text.data(), text.size(), true);
        return PerfFile{path, "noiseprofiles"};
    }();
    return f;
}

void readWithOpenCv(benchmark::State& state, const PerfFile& file)
{
    for (auto _ : state) {
        cv::FileStorage fs(file.path, cv::FileStorage::READ);
        benchmark::DoNotOptimize(fs[file.topLevel].size());
    }
}

void readWithRawgment(benchmark::State& state, const PerfFile& file)
{
    for (auto _ : state) {
        cv::FileStorage fs = openFileStorageForReading(file.path, "benchmark file");
        benchmark::DoNotOptimize(fs[file.topLevel].size());
    }
}

void validateOnly(benchmark::State& state, const PerfFile& file)
{
    const std::string text = readFileBounded(file.path, MAX_TEXT_FILE_BYTES, "benchmark file");
    for (auto _ : state)
        benchmark::DoNotOptimize(detail::textForOpenCv(file.path, text).size());
}

void BM_Files_model_opencv(benchmark::State& s)
{
    readWithOpenCv(s, modelFile());
}
void BM_Files_model_rawgment(benchmark::State& s)
{
    readWithRawgment(s, modelFile());
}
void BM_Files_model_validatorOnly(benchmark::State& s)
{
    validateOnly(s, modelFile());
}
void BM_Files_model_noiseModelLoad(benchmark::State& s)
{
    for (auto _ : s)
        benchmark::DoNotOptimize(NoiseModel::load(modelFile().path).alpha);
}
void BM_Files_sidecar_opencv(benchmark::State& s)
{
    readWithOpenCv(s, sidecarFile());
}
void BM_Files_sidecar_rawgment(benchmark::State& s)
{
    readWithRawgment(s, sidecarFile());
}
void BM_Files_sidecar_validatorOnly(benchmark::State& s)
{
    validateOnly(s, sidecarFile());
}
void BM_Files_darktable_opencv(benchmark::State& s)
{
    readWithOpenCv(s, darktableFile());
}
void BM_Files_darktable_rawgment(benchmark::State& s)
{
    readWithRawgment(s, darktableFile());
}
void BM_Files_darktable_validatorOnly(benchmark::State& s)
{
    validateOnly(s, darktableFile());
}

BENCHMARK(BM_Files_model_opencv)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Files_model_rawgment)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Files_model_validatorOnly)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Files_model_noiseModelLoad)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Files_sidecar_opencv)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Files_sidecar_rawgment)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Files_sidecar_validatorOnly)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Files_darktable_opencv)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Files_darktable_rawgment)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Files_darktable_validatorOnly)->Unit(benchmark::kMillisecond);

} // namespace

int main(int argc, char** argv)
{
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv))
        return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    for (const char* name : {"/noise_model.yml", "/mosaic.png", "/mosaic.png.yml", "/noiseprofiles.json"})
        std::remove((perfFolder() + name).c_str());
    ::rmdir(perfFolder().c_str());
    return 0;
}
