// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Augmentation of a 4000x3000 CV_16UC1 mosaic, and of the same mosaic as CV_32FC1 (the *F32 benchmarks), all
// in one run:
//   colour jitter (ACCOUNT_PRIOR; also with Tukey-lambda read noise and with Poisson shot draws), motion
//   blur (length 13), scaling by 3%, a full random scene, colour jitter and blur with a dark-frame bank as
//   the read noise (NoiseOptions::darkBank: two 12 MP frames read from .npy files per step, in the time),
//   the same colour jitter composed naively with OpenCV calls (convertTo, RNG::fill NORMAL, Mat
//   arithmetic, sqrt), and a memcpy of the frame (the floor); and standard normals alone
//   (fillStandardNormal); and exact Poisson draws alone, in vector lanes (detail::fillPoisson) against the
//   scalar sampler they replaced (CounterRng::poisson, a loop per value); and the Philox words alone, the
//   generator's ceiling for the normals, by each version of the generator this CPU runs (/sse2, /avx2,
//   /avx512_at_512_bits). Every benchmark of the library runs once per CpuPath this CPU has (name suffix
//   /baseline, /sse4.2, /avx2, /avx512), so the paths are compared in one run.
#include "../src/random.hpp"
#include "perf_common.hpp"

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/augment.hpp>
#include <opencv2/rawgment/cpu.hpp>
#include <opencv2/rawgment/dark_frames.hpp>
#include <opencv2/rawgment/mosaic_files.hpp>
#include <opencv2/rawgment/simulate.hpp>

#include <cstring>
#include <filesystem>
#include <unistd.h>

namespace {

using namespace cv;
using namespace cv::rawgment;

const NoiseModel kModel(0.4, 0.5, 2.0);

RawFormat frameFormat()
{
    return perf::perfFrameFormat(2);
}

const Mat& frame()
{
    return perf::perfFrame();
}

//! The same frame as CV_32FC1: the *F32 benchmarks time every step on float input beside the uint16 one.
const Mat& floatFrame()
{
    static const Mat f = [] {
        Mat m;
        perf::perfFrame().convertTo(m, CV_32F);
        return m;
    }();
    return f;
}

const ColorJitter kJitter = ColorJitter::exposureChange(0.2, 2.0);

//! The jitter of kJitter with `model` and `noise`, a new seed per iteration, into one reused output.
void timeColorJitter(benchmark::State& state, const NoiseModel& model, const NoiseOptions& noise,
                     const Mat& input = frame())
{
    Mat out;
    RawFormat f;
    uint64 seed = 0;
    for (auto _ : state) {
        colorJitter(input, frameFormat(), model, kJitter, noise, ++seed, out, f);
        benchmark::DoNotOptimize(out.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(input.total()));
}

void BM_Augment_colorJitter(benchmark::State& state)
{
    timeColorJitter(state, kModel, NoiseAlignment::ACCOUNT_PRIOR);
}

void BM_Augment_colorJitterF32(benchmark::State& state)
{
    timeColorJitter(state, kModel, NoiseAlignment::ACCOUNT_PRIOR, floatFrame());
}

void BM_Augment_colorJitterTukeyRead(benchmark::State& state)
{
    // kModel with heavy-tailed read noise (Tukey lambda -0.1, excess kurtosis about 3.4).
    NoiseModel model = kModel;
    model.tukeyRead = true;
    model.tukeyLambda = -0.1;
    timeColorJitter(state, model, NoiseAlignment::ACCOUNT_PRIOR);
}

NoiseOptions poissonNoise()
{
    NoiseOptions noise(NoiseAlignment::ACCOUNT_PRIOR);
    noise.shotSampling = ShotNoiseSampling::POISSON;
    return noise;
}

void BM_Augment_colorJitterPoisson(benchmark::State& state)
{
    timeColorJitter(state, kModel, poissonNoise());
}

void BM_Augment_colorJitterPoissonF32(benchmark::State& state)
{
    timeColorJitter(state, kModel, poissonNoise(), floatFrame());
}

/* A bank of 12 MP dark frames of perfFrame()'s format, three at each of gains 2 and 4 (the jitter's input and
 * output), saved once per run as .npy files with sidecars in a temporary folder removed at exit. */
//! A folder removed with everything in it when the program ends.
struct TemporaryFolder
{
    std::string path;
    TemporaryFolder()
        : path((std::filesystem::temp_directory_path() / ("rawgment_perf_bank_" + std::to_string(::getpid())))
                   .string())
    {
        std::filesystem::create_directories(path);
    }
    ~TemporaryFolder()
    {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
};

const String& darkBankPath()
{
    static const TemporaryFolder folder;
    static const String path = [] {
        std::vector<String> files;
        for (double gain : {2.0, 4.0})
            for (int t = 0; t < 3; ++t) {
                Mat noise(frame().size(), CV_32FC1), dark;
                RNG(100 + t + static_cast<int>(gain)).fill(noise, RNG::NORMAL, 256, gain);
                noise.convertTo(dark, CV_16U);
                MosaicMetadata meta;
                meta.format = perf::perfFrameFormat(gain);
                files.push_back(folder.path + format("/dark_g%g_%d.npy", gain, t));
                writeMosaic(files.back(), dark, meta);
            }
        DarkFrameBank bank = DarkFrameBank::create(files, kModel);
        bank.save(folder.path + "/bank.yml");
        return String(folder.path + "/bank.yml");
    }();
    return path;
}

NoiseOptions bankNoise()
{
    NoiseOptions noise(NoiseAlignment::ACCOUNT_PRIOR);
    noise.darkBank = darkBankPath();
    return noise;
}

void BM_Augment_colorJitterDarkBank(benchmark::State& state)
{
    timeColorJitter(state, kModel, bankNoise());
}

void BM_Augment_colorJitterNaiveOpenCV(benchmark::State& state)
{
    // Eq. 11 with whole-frame OpenCV operations and temporaries.
    // The added line is the target gain's line less the prior's, scaled by (p_u p_g)^2 (the model's lines).
    const RawFormat fmt = frameFormat();
    const double pu = 0.2, pg = 2.0, scale = pu * pg;
    const NoiseLine prior = kModel.lineAtGain(fmt.gain), target = kModel.lineAtGain(fmt.gain * pg);
    RNG rng(1);
    for (auto _ : state) {
        Mat x, mu, v, noise, out;
        frame().convertTo(x, CV_32F, 1.0, -256.0);
        mu = max(x, 0.0);
        v = mu * (scale * target.a - scale * scale * prior.a) + (target.b - scale * scale * prior.b);
        v = max(v, 0.0);
        sqrt(v, v);
        noise.create(x.size(), CV_32F);
        rng.fill(noise, RNG::NORMAL, 0, 1);
        out = x * (pu * pg) + v.mul(noise) + 256.0;
        out.convertTo(out, CV_16U);
        benchmark::DoNotOptimize(out.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(frame().total()));
}

void timeMotionBlur13(benchmark::State& state, const Mat& input,
                      const NoiseOptions& noise = NoiseAlignment::ACCOUNT_PRIOR)
{
    const Mat kernel = linearMotionKernel(13, 30);
    Mat out;
    uint64 seed = 0;
    for (auto _ : state) {
        motionBlur(input, frameFormat(), kModel, kernel, noise, ++seed, out);
        benchmark::DoNotOptimize(out.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(input.total()));
}

void BM_Augment_motionBlur13(benchmark::State& state)
{
    timeMotionBlur13(state, frame());
}

void BM_Augment_motionBlur13F32(benchmark::State& state)
{
    timeMotionBlur13(state, floatFrame());
}

void BM_Augment_motionBlur13DarkBank(benchmark::State& state)
{
    timeMotionBlur13(state, frame(), bankNoise());
}

void timeScale103(benchmark::State& state, const Mat& input)
{
    Mat out;
    uint64 seed = 0;
    for (auto _ : state) {
        scaleMosaic(input, frameFormat(), kModel, 1.03, NoiseAlignment::ACCOUNT_PRIOR, ++seed, out);
        benchmark::DoNotOptimize(out.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(input.total()));
}

void BM_Augment_scale103(benchmark::State& state)
{
    timeScale103(state, frame());
}

void BM_Augment_scale103F32(benchmark::State& state)
{
    timeScale103(state, floatFrame());
}

void timeRandomScene(benchmark::State& state, const Mat& input)
{
    RandomScenePolicy policy;
    policy.blurProbability = 1; // the expensive case: every scene blurs
    Mat out;
    RawFormat f;
    uint64 seed = 0;
    for (auto _ : state) {
        const Scene s = policy.draw(input, frameFormat(), ++seed);
        applyScene(input, frameFormat(), kModel, s, seed, out, f);
        benchmark::DoNotOptimize(out.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(input.total()));
}

void BM_Augment_randomScene(benchmark::State& state)
{
    timeRandomScene(state, frame());
}

void BM_Augment_randomSceneF32(benchmark::State& state)
{
    timeRandomScene(state, floatFrame());
}

void BM_Augment_standardNormals(benchmark::State& state)
{
    Mat z(frame().size(), CV_32FC1);
    uint64 seed = 0;
    for (auto _ : state) {
        fillStandardNormal(z, Size(), ++seed);
        benchmark::DoNotOptimize(z.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(z.total()));
}

//! The Poisson means of the POISSON jitter benchmark: the electrons its exposure change adds to each pixel
//! of the frame (0 to about 750), one row of doubles per mosaic row.
const Mat& poissonMeans()
{
    static const Mat m = [] {
        const double q = kJitter.gainRatio * kModel.lineAtGain(frameFormat().gain).a;
        const double pu = kJitter.contrast[0] / kJitter.gainRatio;
        Mat x;
        frame().convertTo(x, CV_64F, 1.0, -256.0);
        return Mat(max(x, 0.0) * (pu * (1 - pu) * kJitter.gainRatio * kJitter.gainRatio *
                                  kModel.lineAtGain(frameFormat().gain).a / (q * q)));
    }();
    return m;
}

//! Times `drawRow(key, row, means, counts, cols)` over every row of poissonMeans(), rows split among
//! threads as the noise steps split them, a new key per iteration.
template <typename DrawRow> void timePoissonRows(benchmark::State& state, DrawRow drawRow)
{
    const Mat& means = poissonMeans();
    Mat counts(means.size(), CV_64F);
    uint64 seed = 0;
    for (auto _ : state) {
        const uint64 key = ++seed;
        parallel_for_(Range(0, means.rows), [&](const Range& rows) {
            for (int r = rows.start; r < rows.end; ++r)
                drawRow(key, r, means.ptr<double>(r), counts.ptr<double>(r), means.cols);
        });
        benchmark::DoNotOptimize(counts.data);
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(means.total()));
}

void BM_Augment_poissonDraws(benchmark::State& state)
{
    timePoissonRows(state, [](uint64 key, int r, const double* m, double* k, int cols) {
        rawgment::detail::fillPoisson(key, static_cast<uint64_t>(r), m, k, cols);
    });
}

void BM_Augment_poissonDrawsScalar(benchmark::State& state)
{
    timePoissonRows(state, [](uint64 key, int r, const double* m, double* k, int cols) {
        rawgment::detail::CounterRng rng(key, static_cast<uint64_t>(r));
        for (int c = 0; c < cols; ++c)
            k[c] = static_cast<double>(rng.poisson(m[c]));
    });
}

#if RAWGMENT_HAVE_CPU_PATHS
/* A row of Philox4x32-10 words, eight blocks at a time, by each version of the eight-block generator, in a
 * function of its target, so that the generator is inlined into a loop compiled for that target, as it is
 * into the noise kernels. */
void philoxRowSse2(const std::array<uint32_t, 2>& key, uint64_t stream, uint32_t* words, int n)
{
    for (int base = 0; base < n; base += 32)
        rawgment::detail::philox8BlocksSse2(static_cast<uint32_t>(base / 4), stream, key, words + base);
}
__attribute__((target("arch=x86-64-v3"))) void philoxRowAvx2(const std::array<uint32_t, 2>& key,
                                                             uint64_t stream, uint32_t* words, int n)
{
    for (int base = 0; base < n; base += 32)
        rawgment::detail::philox8BlocksAvx2(static_cast<uint32_t>(base / 4), stream, key, words + base);
}
__attribute__((target("arch=x86-64-v4"))) void philoxRowAvx512(const std::array<uint32_t, 2>& key,
                                                               uint64_t stream, uint32_t* words, int n)
{
    for (int base = 0; base < n; base += 32)
        rawgment::detail::philox8BlocksAvx512(static_cast<uint32_t>(base / 4), stream, key, words + base);
}

/** Philox4x32-10 words alone, 12 M as 3000 rows of 4000 (each row its own stream, rows split among threads
 * as the noise steps split them) into a row buffer per task that stays in cache, as the normals' kernel
 * takes them: the generator's ceiling for every transform on its words. One benchmark per version of the
 * eight-block generator this CPU runs (SSE2, AVX2, and AVX-512 at 512 bits, which no path's kernels call:
 * cpu_dispatch.hpp), so that the share of a path's normals that is the generator's shows in the same run. */
void timePhiloxWords(benchmark::State& state,
                     void (*philoxRow)(const std::array<uint32_t, 2>&, uint64_t, uint32_t*, int))
{
    const int rows = frame().rows, cols = frame().cols; // a multiple of 32 words
    uint64 seed = 0;
    for (auto _ : state) {
        const std::array<uint32_t, 2> key = {static_cast<uint32_t>(++seed), 0u};
        parallel_for_(Range(0, rows), [&](const Range& range) {
            std::vector<uint32_t> words(static_cast<size_t>(cols));
            for (int r = range.start; r < range.end; ++r) {
                philoxRow(key, static_cast<uint64_t>(r), words.data(), cols);
                benchmark::DoNotOptimize(words.data());
                benchmark::ClobberMemory();
            }
        });
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(frame().total()));
}

void BM_Augment_philoxWordsSse2(benchmark::State& state)
{
    timePhiloxWords(state, philoxRowSse2);
}
void BM_Augment_philoxWordsAvx2(benchmark::State& state)
{
    timePhiloxWords(state, philoxRowAvx2);
}
void BM_Augment_philoxWordsAvx512(benchmark::State& state)
{
    timePhiloxWords(state, philoxRowAvx512);
}
#endif

void BM_Augment_memcpy(benchmark::State& state)
{
    Mat out(frame().size(), frame().type());
    for (auto _ : state) {
        std::memcpy(out.data, frame().data, frame().total() * frame().elemSize());
        benchmark::DoNotOptimize(out.data);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(frame().total()));
}

} // namespace

int main(int argc, char** argv)
{
    // "CPU" is the process's CPU time over all threads; "stolen" the hypervisor's share (perf_common.hpp).
    perf::registerTimed("BM_Augment_memcpy", BM_Augment_memcpy);
    perf::registerTimed("BM_Augment_colorJitterNaiveOpenCV", BM_Augment_colorJitterNaiveOpenCV);
    perf::registerTimed("BM_Augment_poissonDrawsScalar", BM_Augment_poissonDrawsScalar);
#if RAWGMENT_HAVE_CPU_PATHS
    perf::registerTimed("BM_Augment_philoxWords/sse2", BM_Augment_philoxWordsSse2);
    if (isCpuPathAvailable(CpuPath::AVX2))
        perf::registerTimed("BM_Augment_philoxWords/avx2", BM_Augment_philoxWordsAvx2);
    if (isCpuPathAvailable(CpuPath::AVX512))
        perf::registerTimed("BM_Augment_philoxWords/avx512_at_512_bits", BM_Augment_philoxWordsAvx512);
#endif
    const std::pair<const char*, void (*)(benchmark::State&)> library[] = {
        {"BM_Augment_standardNormals", BM_Augment_standardNormals},
        {"BM_Augment_colorJitter", BM_Augment_colorJitter},
        {"BM_Augment_colorJitterF32", BM_Augment_colorJitterF32},
        {"BM_Augment_colorJitterTukeyRead", BM_Augment_colorJitterTukeyRead},
        {"BM_Augment_colorJitterDarkBank", BM_Augment_colorJitterDarkBank},
        {"BM_Augment_colorJitterPoisson", BM_Augment_colorJitterPoisson},
        {"BM_Augment_colorJitterPoissonF32", BM_Augment_colorJitterPoissonF32},
        {"BM_Augment_poissonDraws", BM_Augment_poissonDraws},
        {"BM_Augment_motionBlur13", BM_Augment_motionBlur13},
        {"BM_Augment_motionBlur13F32", BM_Augment_motionBlur13F32},
        {"BM_Augment_motionBlur13DarkBank", BM_Augment_motionBlur13DarkBank},
        {"BM_Augment_scale103", BM_Augment_scale103},
        {"BM_Augment_scale103F32", BM_Augment_scale103F32},
        {"BM_Augment_randomScene", BM_Augment_randomScene},
        {"BM_Augment_randomSceneF32", BM_Augment_randomSceneF32}};
    for (const auto& b : library)
        perf::registerOnEveryCpuPath(b.first, b.second);
    return perf::runRegisteredBenchmarks(argc, argv);
}
