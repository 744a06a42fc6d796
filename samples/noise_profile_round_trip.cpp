// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Sample: a noise model in the forms other tools read, and back. The DNG NoiseProfile of an augmented
// capture (written into a DNG and read again), and darktable's noise-profile file across ISOs, each
// give the model's noise line back.
#include <opencv2/rawgment.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

int main(int argc, char** argv)
{
    using namespace cv::rawgment;
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s out_folder\n", argv[0]);
        return 2;
    }
    const std::string out = argv[1];
    try {
        NoiseModel model(0.8, 2.0, 6.0);
        model.baseIso = 100;
        RawFormat format;
        format.whiteLevel = 4095;
        format.blackLevel = cv::Vec4d::all(64);
        format.gain = 4; // ISO 400

        // The DNG NoiseProfile (tag 51041) at the capture's gain, through a file.
        RawImage image;
        image.mosaic = cv::Mat(64, 64, CV_16UC1, cv::Scalar(900));
        image.format = format;
        image.noiseProfile = dngNoiseProfile(model, format);
        const std::string dng = out + "/profile.dng";
        std::remove(dng.c_str());
        writeDng(dng, image);
        const RawImage back = readRaw(dng);
        RawFormat atGain = back.format;
        atGain.gain = format.gain;
        const NoiseLine fromDng = noiseLineFromDngProfile(back.noiseProfile, atGain, CFA_G1);
        const NoiseLine truth = model.lineAtGain(format.gain);
        std::printf("DNG:       a %.6f (model %.6f), b %.4f (model %.4f)\n", fromDng.a, truth.a, fromDng.b,
                    truth.b);

        // darktable's noiseprofiles.json form, at four ISOs, and the model it gives back.
        const std::string json = out + "/noiseprofiles.json";
        std::ofstream(json) << darktableNoiseProfiles(model, format, model.baseIso, {100, 200, 400, 800},
                                                      "Sample", "Camera");
        const NoiseModel fromDarktable =
            noiseModelFromDarktableExport(json, format, model.baseIso, "Sample", "Camera");
        std::printf("darktable: alpha %.6f, sigma_d^2 %.6f, sigma_r^2 %.6f (model %.1f, %.1f, %.1f)\n",
                    fromDarktable.alpha, fromDarktable.sigmaD2, fromDarktable.sigmaR2, model.alpha,
                    model.sigmaD2, model.sigmaR2);
        const bool same = std::abs(fromDng.a - truth.a) < 1e-9 * truth.a &&
                          std::abs(fromDarktable.alpha - model.alpha) < 1e-9 * model.alpha;
        std::printf("%s\n", same ? "round trip exact" : "round trip differs");
        return same ? 0 : 1;
    } catch (const cv::Exception& e) {
        std::fprintf(stderr, "%s\n", e.err.c_str());
        return 1;
    }
}
