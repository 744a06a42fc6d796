// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The C++ side of the Python bit-for-bit tests (test_same_bits_as_cxx.py): computes a fixed set of
// results with the C++ API and writes them as .npy files (arrays) and one text file (numbers at full
// precision) into the folder given. The Python test computes the same with the module and compares.
#include <opencv2/rawgment.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

using namespace cv;
using namespace cv::rawgment;

namespace {

std::string folder;

//! A .npy file (format 1.0) of a Mat: the dtype, the shape, the rows.
void saveNpy(const std::string& name, const Mat& m)
{
    const char* descr = nullptr;
    switch (m.depth()) {
    case CV_8U:
        descr = "|u1";
        break;
    case CV_16U:
        descr = "<u2";
        break;
    case CV_32F:
        descr = "<f4";
        break;
    case CV_64F:
        descr = "<f8";
        break;
    default:
        throw std::runtime_error("saveNpy: unsupported depth");
    }
    std::string shape = std::to_string(m.rows) + ", " + std::to_string(m.cols);
    if (m.channels() > 1)
        shape += ", " + std::to_string(m.channels());
    std::string header =
        std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': (" + shape + "), }";
    while ((10 + header.size() + 1) % 64 != 0)
        header += ' ';
    header += '\n';
    std::ofstream out(folder + "/" + name + ".npy", std::ios::binary);
    out.write("\x93NUMPY\x01\x00", 8);
    const unsigned short len = static_cast<unsigned short>(header.size());
    out.put(static_cast<char>(len & 0xff));
    out.put(static_cast<char>(len >> 8));
    out << header;
    for (int r = 0; r < m.rows; ++r)
        out.write(reinterpret_cast<const char*>(m.ptr(r)),
                  static_cast<std::streamsize>(m.cols * m.elemSize()));
    if (!out)
        throw std::runtime_error("saveNpy: cannot write " + name);
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 2) {
        std::cerr << "usage: rawgment_python_reference <output folder>\n";
        return 2;
    }
    folder = argv[1];
    try {
        std::ofstream numbers(folder + "/numbers.txt");
        numbers.precision(17);

        // The parameters below are repeated in test_same_bits_as_cxx.py.
        SensorParams params;
        params.blackLevel = Vec4d(64, 66, 65, 63);
        params.bitDepth = 12;
        const SensorSimulator sim(params, Size(128, 96));
        ColorCheckerOptions chartOptions;
        chartOptions.patchSize = 16;
        chartOptions.border = 4;
        const ColorCheckerScene chart = makeColorCheckerScene(chartOptions);
        Mat mean = Mat::zeros(96, 128, CV_32F);
        chart.meanAtUnitGain.copyTo(mean(Rect(0, 0, chart.meanAtUnitGain.cols, chart.meanAtUnitGain.rows)));
        Mat capture;
        sim.capture(mean, 2.0, 1.0, 11, 3, capture);
        saveNpy("capture", capture);

        const RawFormat format = sim.rawFormat(2.0);
        const NoiseModel model = sim.effectiveModel();
        // The inputs as numbers, for the test of cv2.rawgment (python/tests_opencv), which has no simulator.
        numbers << "format_black " << format.blackLevel[0] << " " << format.blackLevel[1] << " "
                << format.blackLevel[2] << " " << format.blackLevel[3] << "\nformat_white "
                << format.whiteLevel << "\nformat_gain " << format.gain << "\n";
        numbers << "model_alpha " << model.alpha << "\nmodel_sigmaD2 " << model.sigmaD2 << "\nmodel_sigmaR2 "
                << model.sigmaR2 << "\nmodel_variance_100_3 " << model.variance(100, 3) << "\n";
        RawImage dngImage;
        dngImage.mosaic = capture;
        dngImage.format = format;
        dngImage.format.gain = 1;
        dngImage.iso = 200;
        writeDng(folder + "/capture.dng", dngImage);
        ColorJitter jitter = ColorJitter::exposureChange(0.2, 2.0);
        jitter.contrast = Vec4d(0.4, 0.38, 0.41, 0.5);
        jitter.brightness = -3;
        Mat jittered, mask;
        RawFormat jitteredFormat;
        AugmentReport report;
        colorJitter(capture, format, model, jitter, NoiseAlignment::ACCOUNT_PRIOR, 5, jittered,
                    jitteredFormat, &report, mask);
        saveNpy("jitter", jittered);
        saveNpy("jitter_mask", mask);
        numbers << "jitter_gain " << jitteredFormat.gain << "\n";
        numbers << "jitter_brightening " << report.brighteningPixels << "\n";

        Mat blurred;
        motionBlur(capture, format, model, linearMotionKernel(9, 30), NoiseAlignment::ACCOUNT_PRIOR, 6,
                   blurred);
        saveNpy("blur", blurred);
        Mat scaled;
        scaleMosaic(capture, format, model, 1.03, NoiseAlignment::IGNORE_PRIOR, 7, scaled);
        saveNpy("scale", scaled);

        // A dark-frame bank of the same sensor: four frames at gains 2 and 4, beside its file in the folder.
        std::vector<String> darkFiles;
        for (double gain : {2.0, 4.0})
            for (int t = 0; t < 4; ++t) {
                Mat dark;
                sim.capture(Mat::zeros(96, 128, CV_32F), gain, 1.0, 12, t, dark);
                MosaicMetadata meta;
                meta.format = sim.rawFormat(gain);
                darkFiles.push_back(folder + cv::format("/dark_g%g_%d.png", gain, t));
                writeMosaic(darkFiles.back(), dark, meta);
            }
        DarkFrameBank bank = DarkFrameBank::create(darkFiles, NoiseModel());
        bank.save(folder + "/bank.yml");
        NoiseOptions banked;
        banked.darkBank = folder + "/bank.yml";
        banked.darkBankTied = true;
        Mat bankJittered, bankBlurred;
        RawFormat bankFormat;
        AugmentReport bankReport;
        colorJitter(capture, format, model, ColorJitter::exposureChange(0.3, 2.0), banked, 8, bankJittered,
                    bankFormat, &bankReport);
        saveNpy("bank_jitter", bankJittered);
        numbers << "bank_read_brightening " << bankReport.readBrighteningPixels << "\n";
        banked.darkBankTied = false;
        motionBlur(capture, format, model, linearMotionKernel(9, 30), banked, 9, bankBlurred);
        saveNpy("bank_blur", bankBlurred);

        RandomScenePolicy policy;
        policy.blurProbability = 1;
        policy.geometryProbability = 1;
        const uint64 sceneSeed = augmentedOutputSeed(1, "frame", 2);
        const Scene scene = policy.draw(capture, format, sceneSeed);
        std::vector<Rect> boxes{Rect(10, 12, 30, 20), Rect(100, 80, 20, 10)};
        Mat augmented;
        RawFormat augmentedFormat;
        applyScene(capture, format, model, scene, sceneSeed, augmented, augmentedFormat, nullptr, &boxes);
        saveNpy("scene", augmented);
        numbers << "scene_gain " << augmentedFormat.gain << "\n";
        for (size_t i = 0; i < boxes.size(); ++i)
            numbers << "scene_box" << i << " " << boxes[i].x << " " << boxes[i].y << " " << boxes[i].width
                    << " " << boxes[i].height << "\n";

        // A monochrome frame (the capture's values, one black level): a random scene with hue, blur and
        // geometry asked for, which it takes on its pixel grid with one contrast, and its grey preview.
        RawFormat monoFormat = format;
        monoFormat.pattern = CFA_MONO;
        monoFormat.blackLevel = Vec4d::all(64);
        RandomScenePolicy monoPolicy;
        monoPolicy.blurProbability = 1;
        monoPolicy.geometryProbability = 1;
        monoPolicy.hueProbability = 1;
        const uint64 monoSeed = augmentedOutputSeed(1, "mono", 0);
        const Scene monoScene = monoPolicy.draw(capture, monoFormat, monoSeed);
        Mat monoAugmented, monoPreview;
        RawFormat monoAugmentedFormat;
        applyScene(capture, monoFormat, model, monoScene, monoSeed, monoAugmented, monoAugmentedFormat);
        saveNpy("mono_scene", monoAugmented);
        saveNpy("mono_kernel", monoScene.motionKernel);
        numbers << "mono_scene_gain " << monoAugmentedFormat.gain << "\n";
        renderSimpleIsp(monoAugmented, monoAugmentedFormat, monoPreview);
        saveNpy("mono_isp", monoPreview);

        Mat normals;
        fillStandardNormal(normals, Size(33, 17), 9);
        saveNpy("normal", normals);
        const ShapiroWilkResult sw = shapiroWilk(normals);
        numbers << "sw_W " << sw.W << "\nsw_p " << sw.pValue << "\n";

        std::vector<NoiseSample> samples;
        const std::vector<Rect> squares = cfaAlignedSquares(chart.patches, 8);
        for (const Rect& patch : chart.patches)
            numbers << "patch " << patch.x << " " << patch.y << " " << patch.width << " " << patch.height
                    << "\n";
        for (int g = 0; g < 3; ++g) {
            const double gain = dbToLinearGain(6.0 * g);
            std::vector<Mat> burst;
            sim.captureBurst(mean, gain, 1.0, 16, 100 + g, burst);
            BurstStatistics stats(sim.rawFormat(gain));
            for (const Mat& f : burst)
                stats.add(f);
            Mat stacked;
            vconcat(burst, stacked);
            saveNpy("burst_g" + std::to_string(g), stacked);
            if (g == 0) {
                Mat v;
                stats.variance(v);
                saveNpy("burst_variance", v);
            }
            const std::vector<NoiseSample> s = sampleBurstPatches(stats, squares, gain);
            samples.insert(samples.end(), s.begin(), s.end());
        }
        const CalibrationReport calibration = calibrateNoiseModel(samples);
        numbers << "calibration_samples " << samples.size() << "\n";
        numbers << "calibration_alpha " << calibration.model.alpha << "\ncalibration_sigmaD2 "
                << calibration.model.sigmaD2 << "\ncalibration_sigmaR2 " << calibration.model.sigmaR2 << "\n";

        // The dark-frame components: maps of exact binary values (so Python builds the same floats).
        NoiseModel dark = model;
        dark.rowSigmaD2 = 0.2;
        dark.rowSigmaR2 = 0.4;
        dark.tukeyRead = true;
        dark.tukeyLambda = -0.05;
        dark.darkShadingPerGain.create(96, 128, CV_32F);
        dark.darkShadingOffset.create(96, 128, CV_32F);
        for (int r = 0; r < 96; ++r)
            for (int c = 0; c < 128; ++c) {
                dark.darkShadingPerGain.at<float>(r, c) = static_cast<float>((c % 7) * 0.25 - 0.5);
                dark.darkShadingOffset.at<float>(r, c) = static_cast<float>((r % 5) - 2 + (c % 3) * 0.5);
            }
        Mat darkJittered, darkBlurred;
        RawFormat darkFormat;
        colorJitter(capture, format, dark, ColorJitter::exposureChange(0.1, 4.0),
                    NoiseAlignment::ACCOUNT_PRIOR, 8, darkJittered, darkFormat);
        saveNpy("dark_jitter", darkJittered);
        motionBlur(capture, format, dark, linearMotionKernel(9, 30), NoiseAlignment::ACCOUNT_PRIOR, 9,
                   darkBlurred);
        saveNpy("dark_blur", darkBlurred);
        SensorParams darkParams = params;
        darkParams.noise.rowSigmaD2 = dark.rowSigmaD2;
        darkParams.noise.rowSigmaR2 = dark.rowSigmaR2;
        darkParams.noise.tukeyRead = true;
        darkParams.noise.tukeyLambda = dark.tukeyLambda;
        darkParams.noise.darkShadingPerGain = dark.darkShadingPerGain;
        darkParams.noise.darkShadingOffset = dark.darkShadingOffset;
        const SensorSimulator darkSim(darkParams, Size(128, 96));
        std::vector<std::vector<Mat>> darkBursts(2);
        for (int g = 0; g < 2; ++g)
            darkSim.captureBurst(Mat::zeros(96, 128, CV_32F), 1.0 + 7 * g, 1.0, 4, 200 + g, darkBursts[g]);
        saveNpy("dark_capture", darkBursts[1][0]);
        const DarkCalibrationReport darkCalibration =
            calibrateDarkNoise(darkBursts, {1.0, 8.0}, darkSim.rawFormat(1.0), darkSim.effectiveModel());
        numbers << "dark_row_d2 " << darkCalibration.model.rowSigmaD2 << "\ndark_row_r2 "
                << darkCalibration.model.rowSigmaR2 << "\ndark_lambda " << darkCalibration.model.tukeyLambda
                << "\n";
        saveNpy("dark_shading_per_gain", darkCalibration.model.darkShadingPerGain);

        Mat bgr;
        renderSimpleIsp(capture, format, bgr);
        saveNpy("isp", bgr);

        // The camera catalogue, when darktable's file is installed.
        const String profiles = darktableProfilesPath();
        if (!profiles.empty()) {
            const std::vector<CameraNoiseProfile> cameras = readCameraProfiles(profiles);
            numbers << "cameras " << cameras.size() << "\n";
            const CameraNoiseProfile d3 = findCameraProfile(cameras, "Nikon D3");
            const NoiseModel d3Model = d3.modelFor(format);
            numbers << "camera_d3 " << d3.verdict << " " << d3Model.alpha << " " << d3Model.variance(100, 3)
                    << "\n";
        }
        if (!numbers)
            throw std::runtime_error("cannot write numbers.txt");
    } catch (const std::exception& e) {
        std::cerr << "rawgment_python_reference: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
