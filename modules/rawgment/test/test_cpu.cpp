// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "test_common.hpp"

#include <opencv2/rawgment.hpp>

#include <cstdint>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

namespace cv {
namespace rawgment {
namespace {

//! Restores the automatic choice when a test ends, whatever it forced.
struct AutoPathAfterwards
{
    ~AutoPathAfterwards() { setCpuPath(CpuPath::AUTO); }
};

TEST(Cpu, pathsAreNamedCheckedAndForced)
{
    const AutoPathAfterwards restore;
    const std::vector<CpuPath> paths = availableCpuPaths();
    ASSERT_FALSE(paths.empty());
    EXPECT_EQ(paths.front(), CpuPath::BASELINE) << "every CPU runs the baseline";
    EXPECT_TRUE(isCpuPathAvailable(CpuPath::AUTO));
    EXPECT_EQ(cpuPathName(CpuPath::SSE42), "sse4.2");
    EXPECT_EQ(cpuPathName(CpuPath::AVX512), "avx512");
    for (CpuPath p : paths) {
        setCpuPath(p);
        EXPECT_EQ(activeCpuPath(), p) << cpuPathName(p);
    }
    setCpuPath(CpuPath::AUTO);
    EXPECT_EQ(activeCpuPath(), paths.back()) << "AUTO takes the best path the CPU runs";
    for (CpuPath p : {CpuPath::SSE42, CpuPath::AVX2, CpuPath::AVX512})
        if (!isCpuPathAvailable(p))
            EXPECT_CV_ERROR_CONTAINS(setCpuPath(p), "this CPU cannot run " + cpuPathName(p));
    EXPECT_CV_ERROR_CONTAINS(setCpuPath(static_cast<CpuPath>(9)), "9 is not a CpuPath");
}

//! The outputs of every dispatched hot loop, through the public functions that run them.
std::vector<Mat> everyDispatchedLoop()
{
    std::vector<Mat> outs;
    const SensorSimulator sensor(test::referenceSensorParams(), Size(134, 98));
    const RawFormat format = sensor.rawFormat(4.0);
    Mat scene(sensor.size(), CV_32F);
    RNG(3).fill(scene, RNG::UNIFORM, 20, 3000);
    Mat src;
    sensor.capture(scene, 4.0, 1.0, 11, 0, src); // the simulator's Gaussian draws
    outs.push_back(src);
    const NoiseModel plain(0.4, 0.5, 2.0);
    // The dark-frame components add a row term and shading to the vector rows, and Tukey draws to the
    // jitter's vector rows and to the scalar rows of blur and scale (NoiseModel); POISSON takes the
    // jitter's split and noise kernels around the vector draws.
    NoiseModel dark = plain;
    dark.rowSigmaD2 = 0.2;
    dark.rowSigmaR2 = 0.4;
    dark.tukeyRead = true;
    dark.tukeyLambda = -0.05;
    dark.darkShadingPerGain.create(sensor.size(), CV_32FC1);
    dark.darkShadingOffset.create(sensor.size(), CV_32FC1);
    RNG(4).fill(dark.darkShadingPerGain, RNG::NORMAL, 0, 1);
    RNG(5).fill(dark.darkShadingOffset, RNG::NORMAL, 0, 2);
    NoiseModel rowsAndShading = dark;
    rowsAndShading.tukeyRead = false;
    Mat srcFloat;
    src.convertTo(srcFloat, CV_32F);
    NoiseOptions poisson;
    poisson.shotSampling = ShotNoiseSampling::POISSON;
    NoiseOptions localMean;
    localMean.priorMean = PriorMeanEstimate::LOCAL_MEAN;
    localMean.blurNoiseSum = BlurNoiseSum::FROM_BLURRED_MEAN;
    for (const NoiseModel& model : {plain, rowsAndShading, dark})
        for (const Mat& input : {src, srcFloat})
            for (NoiseAlignment a :
                 {NoiseAlignment::NONE, NoiseAlignment::IGNORE_PRIOR, NoiseAlignment::ACCOUNT_PRIOR})
                for (const NoiseOptions& base : {NoiseOptions(), poisson, localMean}) {
                    NoiseOptions noise = base;
                    noise.alignment = a;
                    Mat out;
                    RawFormat f;
                    // Brightening and darkening sites, a gain change; without brightness (ACCOUNT_PRIOR's
                    // variance is then a line per site) and with it (a share per pixel).
                    ColorJitter jitter;
                    jitter.contrast = Vec4d(0.3, 1.4, 0.25, 0.5);
                    jitter.gainRatio = 2;
                    for (double brightness : {0.0, -15.0}) {
                        jitter.brightness = brightness;
                        colorJitter(input, format, model, jitter, noise, 5, out, f);
                        outs.push_back(out);
                    }
                    motionBlur(input, format, model, linearMotionKernel(13, 30), noise, 6, out);
                    outs.push_back(out);
                    scaleMosaic(input, format, model, 1.07, noise, 7, out);
                    outs.push_back(out);
                }
    for (int depth : {CV_64F, CV_32F}) {
        BurstStatistics stats(format, 4, depth);
        for (int t = 0; t < 6; ++t) {
            Mat frame;
            sensor.capture(scene, 4.0, 1.0, 12, t, frame);
            stats.add(frame);
        }
        Mat mean, variance;
        stats.mean(mean);
        stats.variance(variance);
        outs.push_back(mean);
        outs.push_back(variance);
    }
    return outs;
}

/* The steps' settings that everyDispatchedLoop() leaves out: measured lines, a scene (shift, scale, jitter
 * and blur in one call, the shift swapping the dark shading), a crop read at its sensor origin, the
 * local-mean prior with the input's dark shading taken out, and an odd width on the jitter's rows. */
std::vector<Mat> everyNoiseStepSetting()
{
    std::vector<Mat> outs;
    const SensorSimulator sensor(test::referenceSensorParams(), Size(134, 98));
    const RawFormat format = sensor.rawFormat(2.0);
    Mat scene(sensor.size(), CV_32F);
    RNG(8).fill(scene, RNG::UNIFORM, 5, 3500);
    Mat src;
    sensor.capture(scene, 2.0, 1.0, 13, 0, src);
    NoiseModel measured(0.4, 0.5, 2.0);
    const double lines[3][3] = {{1, 0.4, 2.6}, {2, 0.68, 4.5}, {4, 2.08, 12.0}};
    for (const auto& l : lines) {
        MeasuredNoiseLine m;
        m.gain = l[0];
        m.line.a = l[1];
        m.line.b = l[2];
        measured.measuredLines.push_back(m);
    }
    NoiseModel dark(0.4, 0.5, 2.0);
    dark.rowSigmaD2 = 0.3;
    dark.rowSigmaR2 = 0.5;
    dark.tukeyRead = true;
    dark.tukeyLambda = 0.05;
    dark.darkShadingPerGain.create(Size(140, 104), CV_32FC1);
    dark.darkShadingOffset.create(Size(140, 104), CV_32FC1);
    RNG(9).fill(dark.darkShadingPerGain, RNG::NORMAL, 0, 1);
    RNG(10).fill(dark.darkShadingOffset, RNG::NORMAL, 0, 2);
    RawFormat cropFormat = format;
    cropFormat.sensorOrigin = Point(4, 6);
    Mat srcFloat;
    src.convertTo(srcFloat, CV_32F);
    const Mat oddWidth = src(Rect(0, 0, 133, 98));
    for (const Mat& input : {src, srcFloat})
        for (NoiseAlignment a : {NoiseAlignment::IGNORE_PRIOR, NoiseAlignment::ACCOUNT_PRIOR})
            for (ShotNoiseSampling sampling : {ShotNoiseSampling::GAUSSIAN, ShotNoiseSampling::POISSON})
                for (PriorMeanEstimate prior :
                     {PriorMeanEstimate::PIXEL_VALUE, PriorMeanEstimate::LOCAL_MEAN}) {
                    NoiseOptions noise;
                    noise.alignment = a;
                    noise.shotSampling = sampling;
                    noise.priorMean = prior;
                    Scene s;
                    s.jitter.contrast = Vec4d(0.35, 0.3, 1.2, 0.4);
                    s.jitter.gainRatio = 1.7;
                    s.motionKernel = linearMotionKernel(9, 60);
                    s.shift = Point(4, -2);
                    s.scale = 0.93;
                    s.noise = noise;
                    for (const NoiseModel& model : {measured, dark}) {
                        Mat out;
                        RawFormat f;
                        applyScene(input, cropFormat, model, s, 21, out, f);
                        outs.push_back(out);
                        colorJitter(input, cropFormat, model, s.jitter, noise, 22, out, f);
                        outs.push_back(out);
                    }
                    Mat out;
                    RawFormat f;
                    colorJitter(oddWidth, format, dark, s.jitter, noise, 23, out, f);
                    outs.push_back(out);
                }
    return outs;
}

//! FNV-1a over the rows' bytes: the same on every machine, whatever the Mat's step.
uint64_t bitsHash(const Mat& m)
{
    uint64_t h = 14695981039346656037ull;
    for (int r = 0; r < m.rows; ++r) {
        const uchar* p = m.ptr(r);
        for (size_t i = 0; i < m.cols * m.elemSize(); ++i)
            h = (h ^ p[i]) * 1099511628211ull;
    }
    return h;
}

/* The noise steps' outputs as they were recorded when the steps were restructured (issue #62's prepared
 * step noise): a change of structure, vector width or data type path must leave every bit. A deliberate
 * change of the numbers updates this table from the printed one, bumps the version and says why in the
 * changelog. */
TEST(Cpu, theNoiseStepsKeepTheirRecordedBits)
{
    std::vector<Mat> outs = everyDispatchedLoop();
    for (const Mat& m : everyNoiseStepSetting())
        outs.push_back(m);
    const uint64_t recorded[] = {
        0xc6ca754409c7cc54ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0xc603f4fd1b54fd92ull, 0xc603f4fd1b54fd92ull, 0xc603f4fd1b54fd92ull,
        0xc603f4fd1b54fd92ull, 0x08baa2466954775bull, 0x08baa2466954775bull, 0x08baa2466954775bull,
        0x08baa2466954775bull, 0xc603f4fd1b54fd92ull, 0xc603f4fd1b54fd92ull, 0xc603f4fd1b54fd92ull,
        0xc603f4fd1b54fd92ull, 0xcec76cc4114015cbull, 0xcec76cc4114015cbull, 0xcec76cc4114015cbull,
        0xcec76cc4114015cbull, 0xe0d59b7fc4952646ull, 0xe0d59b7fc4952646ull, 0xe0d59b7fc4952646ull,
        0xe0d59b7fc4952646ull, 0xcec76cc4114015cbull, 0xcec76cc4114015cbull, 0xcec76cc4114015cbull,
        0xcec76cc4114015cbull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0xea0c41c8ec2261afull, 0xea0c41c8ec2261afull, 0xea0c41c8ec2261afull,
        0xea0c41c8ec2261afull, 0x5ba7c7a7c9ac2e11ull, 0x5ba7c7a7c9ac2e11ull, 0x5ba7c7a7c9ac2e11ull,
        0x5ba7c7a7c9ac2e11ull, 0xea0c41c8ec2261afull, 0xea0c41c8ec2261afull, 0xea0c41c8ec2261afull,
        0xea0c41c8ec2261afull, 0x41a202a0098fdf6dull, 0x41a202a0098fdf6dull, 0x41a202a0098fdf6dull,
        0x41a202a0098fdf6dull, 0x7218d51fe3096e91ull, 0x7218d51fe3096e91ull, 0x7218d51fe3096e91ull,
        0x7218d51fe3096e91ull, 0x41a202a0098fdf6dull, 0x41a202a0098fdf6dull, 0x41a202a0098fdf6dull,
        0x41a202a0098fdf6dull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0xac1eed48bcf94c85ull, 0xac1eed48bcf94c85ull, 0xac1eed48bcf94c85ull,
        0xac1eed48bcf94c85ull, 0x8208a8dab5605b42ull, 0x8208a8dab5605b42ull, 0x8208a8dab5605b42ull,
        0x8208a8dab5605b42ull, 0xac1eed48bcf94c85ull, 0xac1eed48bcf94c85ull, 0xac1eed48bcf94c85ull,
        0xac1eed48bcf94c85ull, 0xa495ee2a711ba496ull, 0xa495ee2a711ba496ull, 0xa495ee2a711ba496ull,
        0xa495ee2a711ba496ull, 0x9aa34d9c6b87c994ull, 0x9aa34d9c6b87c994ull, 0x9aa34d9c6b87c994ull,
        0x9aa34d9c6b87c994ull, 0xa495ee2a711ba496ull, 0xa495ee2a711ba496ull, 0xa495ee2a711ba496ull,
        0xa495ee2a711ba496ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0xa3d633a82d0e2f9bull, 0xa3d633a82d0e2f9bull, 0xa3d633a82d0e2f9bull,
        0xa3d633a82d0e2f9bull, 0x6b119de0fd40f10bull, 0x6b119de0fd40f10bull, 0x6b119de0fd40f10bull,
        0x6b119de0fd40f10bull, 0xa3d633a82d0e2f9bull, 0xa3d633a82d0e2f9bull, 0xa3d633a82d0e2f9bull,
        0xa3d633a82d0e2f9bull, 0x9082b4708992939aull, 0x9082b4708992939aull, 0x9082b4708992939aull,
        0x9082b4708992939aull, 0x911ed8694e97a091ull, 0x911ed8694e97a091ull, 0x911ed8694e97a091ull,
        0x911ed8694e97a091ull, 0x9082b4708992939aull, 0x9082b4708992939aull, 0x9082b4708992939aull,
        0x9082b4708992939aull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull, 0x5ad29d131ddb1769ull,
        0x5ad29d131ddb1769ull, 0x049981a0472e2d6bull, 0x049981a0472e2d6bull, 0x049981a0472e2d6bull,
        0x049981a0472e2d6bull, 0x89292cb1a04acb3aull, 0x89292cb1a04acb3aull, 0x89292cb1a04acb3aull,
        0x89292cb1a04acb3aull, 0x049981a0472e2d6bull, 0x049981a0472e2d6bull, 0x049981a0472e2d6bull,
        0x049981a0472e2d6bull, 0x9aeee7eb3a35f4bfull, 0x9aeee7eb3a35f4bfull, 0x9aeee7eb3a35f4bfull,
        0x9aeee7eb3a35f4bfull, 0xc132505a0a6fee32ull, 0xc132505a0a6fee32ull, 0xc132505a0a6fee32ull,
        0xc132505a0a6fee32ull, 0x9aeee7eb3a35f4bfull, 0x9aeee7eb3a35f4bfull, 0x9aeee7eb3a35f4bfull,
        0x9aeee7eb3a35f4bfull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull, 0x559b8c90aae4a691ull,
        0x559b8c90aae4a691ull, 0x141bf1503b76d4a5ull, 0x141bf1503b76d4a5ull, 0x141bf1503b76d4a5ull,
        0x141bf1503b76d4a5ull, 0xbc795232b0fa62fdull, 0xbc795232b0fa62fdull, 0xbc795232b0fa62fdull,
        0xbc795232b0fa62fdull, 0x141bf1503b76d4a5ull, 0x141bf1503b76d4a5ull, 0x141bf1503b76d4a5ull,
        0x141bf1503b76d4a5ull, 0xd106c3231e992ee0ull, 0xd106c3231e992ee0ull, 0xd106c3231e992ee0ull,
        0xd106c3231e992ee0ull, 0x369a4479de4089c6ull, 0x369a4479de4089c6ull, 0x369a4479de4089c6ull,
        0x369a4479de4089c6ull, 0xd106c3231e992ee0ull, 0xd106c3231e992ee0ull, 0xd106c3231e992ee0ull,
        0xd106c3231e992ee0ull, 0xf3586ccf2bda32a4ull, 0xd0335fa3ed76cac8ull, 0xa6c3c47263fde6a1ull,
        0xb2d5d8380c740b81ull, 0x736c7d7811aea00aull, 0x736c7d7811aea00aull, 0xd92f5422e59a47bcull,
        0xd92f5422e59a47bcull, 0x2b59cd435aa6ffa7ull, 0x0d4856bedc912ae2ull, 0x0d4856bedc912ae2ull,
        0xe2625dc485c11d95ull, 0xe2625dc485c11d95ull, 0x580f81fa6127295eull, 0x04428f28bf6a283full,
        0x04428f28bf6a283full, 0x84aaded9d3651eb5ull, 0x84aaded9d3651eb5ull, 0x570a27108a1724e0ull,
        0x9848a687c55a39c9ull, 0x9848a687c55a39c9ull, 0x397b2047c1612651ull, 0x397b2047c1612651ull,
        0xf0440378b56ac3dcull, 0xfbd1aca717642ee1ull, 0xfbd1aca717642ee1ull, 0xd643018578354147ull,
        0xd643018578354147ull, 0x4d03c2b3513ded6aull, 0x93ace8862d62f3f7ull, 0x93ace8862d62f3f7ull,
        0x49098332ed80e1acull, 0x49098332ed80e1acull, 0x7aefa1b84f7f13f9ull, 0x7ee8916b4600e717ull,
        0x7ee8916b4600e717ull, 0x31b081d66178dd73ull, 0x31b081d66178dd73ull, 0x1fbb9d4a7d5fc294ull,
        0xdab992eeba8bb551ull, 0xdab992eeba8bb551ull, 0xbcf08f0ee36bdb6eull, 0xbcf08f0ee36bdb6eull,
        0x6a81df02caa660acull, 0x2d3bc3e1617a8321ull, 0x2d3bc3e1617a8321ull, 0xc5a9d166f983d0e6ull,
        0xc5a9d166f983d0e6ull, 0x2b59cd435aa6ffa7ull, 0xd612a07966530444ull, 0xd612a07966530444ull,
        0x905e6ae8381b09f7ull, 0x905e6ae8381b09f7ull, 0x580f81fa6127295eull, 0x21b4898db530fda6ull,
        0x21b4898db530fda6ull, 0x24a54fcdd84e4684ull, 0x24a54fcdd84e4684ull, 0x570a27108a1724e0ull,
        0xb67133c33e3f0150ull, 0xb67133c33e3f0150ull, 0xca51559d48d79f50ull, 0xca51559d48d79f50ull,
        0xf0440378b56ac3dcull, 0xc94ea1659c2518cbull, 0xc94ea1659c2518cbull, 0x928585616a035948ull,
        0x928585616a035948ull, 0x4d03c2b3513ded6aull, 0x60180a86c5e237c6ull, 0x60180a86c5e237c6ull,
        0x5d4791d44ab08360ull, 0x5d4791d44ab08360ull, 0x7aefa1b84f7f13f9ull, 0x215c345408f99ddbull,
        0x215c345408f99ddbull, 0x47f42d6b4ea6273eull, 0x47f42d6b4ea6273eull, 0x1fbb9d4a7d5fc294ull,
        0x29c0491049cd40d5ull, 0x29c0491049cd40d5ull, 0xaf05287e90206b82ull, 0xaf05287e90206b82ull,
        0x6a81df02caa660acull,
    };
    std::string table;
    for (const Mat& m : outs)
        table += format("0x%016llxull,\n", static_cast<unsigned long long>(bitsHash(m)));
    ASSERT_EQ(outs.size(), sizeof(recorded) / sizeof(recorded[0])) << table;
    size_t changed = 0;
    for (size_t i = 0; i < outs.size(); ++i)
        if (bitsHash(outs[i]) != recorded[i])
            ADD_FAILURE() << "output " << i << " changed (" << ++changed << " so far)";
    EXPECT_EQ(changed, 0u) << "today's table:\n" << table;
}

TEST(Cpu, everyPathGivesTheSameBits)
{
    // The promise of cpu.hpp: the path changes speed only. Odd widths leave a tail after the full vectors.
    const AutoPathAfterwards restore;
    const std::vector<CpuPath> paths = availableCpuPaths();
    setCpuPath(CpuPath::BASELINE);
    const std::vector<Mat> reference = everyDispatchedLoop();
    for (CpuPath p : paths) {
        setCpuPath(p);
        const std::vector<Mat> outs = everyDispatchedLoop();
        ASSERT_EQ(outs.size(), reference.size());
        for (size_t i = 0; i < outs.size(); ++i) {
            ASSERT_EQ(outs[i].type(), reference[i].type());
            EXPECT_EQ(0, std::memcmp(outs[i].data, reference[i].data, outs[i].total() * outs[i].elemSize()))
                << cpuPathName(p) << " differs from the baseline in output " << i;
        }
    }
    if (paths.size() < 4)
        std::cout << "[ NOTE     ] this CPU runs " << paths.size()
                  << " of the 4 paths; the others were not compared\n";
}

} // namespace
} // namespace rawgment
} // namespace cv
