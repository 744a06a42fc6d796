// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Noise-accounted augmentation of RAW files with a scene or a random policy.
#include "app_tools.hpp"
#include "pipeline.hpp"

#include <opencv2/core/utility.hpp>

#include <iostream>

int main(int argc, char** argv)
{
    const std::string keysText =
        "{help h usage ? |      | print this message }"
        "{model m        |      | noise model of the camera (required): a NoiseModel YAML/JSON, an Android "
        "profile YAML, or darktable's noiseprofiles.json with --camera }"
        "{camera         |      | with a darktable file: a camera name, a comma-separated list of names, "
        "good "
        "or usable (several: each output draws one, recorded in its sidecar) }"
        "{scene          |      | a scene file (map 'scene') applied to every input }"
        "{policy         |      | a random policy file (map 'random_scene_policy') }"
        "{out o          |      | output directory (required) }"
        "{variants n     | 1    | variants per input }"
        "{seed           | 1    | seed: same seed, same outputs, on any number of threads }"
        "{format         |      | output container: " +
        rawgment_apps::writtenContainerNames() +
        " (npy: numpy's uncompressed format, "
        "fastest to train from; default: dng for RAW inputs) }"
        "{preview        | false| also write an sRGB preview PNG of each output }"
        "{accept_failed_calibration | false | also use a model whose calibration's verdict was FAIL }"
        "{dark_bank      |      | a dark-frame bank file (rawgment_calibrate --dark_bank): its real dark "
        "frames "
        "are the read noise of every output, accounted for the input's own }"
        "{dark_bank_tied | false| the inputs come from the bank's own sensor at its exposure and "
        "temperature: "
        "their fixed pattern is swapped for the target's }"
        "{@inputs        |      | input files (RAW files, or mosaics with a .yml sidecar) }";
    const char* keys = keysText.c_str();
    if (!rawgment_apps::checkCommandLine(argc, argv, keys, "rawgment_augment"))
        return 2;
    rawgment_apps::installInterruptCleanup();
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about(
        "rawgment_augment: darker, noisier, blurred RAW variants with the noise a real sensor would give.\n"
        "Outputs are <out>/<input stem>_vNN.<ext> with a .yml sidecar (format, scene, seed); existing\n"
        "outputs are skipped, so an interrupted run resumes; inputs are never overwritten.");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    rawgment_apps::AugmentOptions o;
    o.model = parser.get<std::string>("model");
    o.camera = parser.get<std::string>("camera");
    o.scene = parser.get<std::string>("scene");
    o.policy = parser.get<std::string>("policy");
    o.outDir = parser.get<std::string>("out");
    o.variants = parser.get<int>("variants");
    o.seed = rawgment_apps::seedOption(parser, "rawgment_augment");
    const std::string format = parser.get<std::string>("format");
    o.previews = parser.get<bool>("preview");
    o.acceptFailedCalibration = parser.get<bool>("accept_failed_calibration");
    o.darkBank = parser.get<std::string>("dark_bank");
    o.darkBankTied = parser.get<bool>("dark_bank_tied");
    // CommandLineParser keeps one positional value; the rest of the command line are inputs too.
    for (int i = 1; i < argc; ++i)
        if (argv[i][0] != '-')
            o.inputs.push_back(argv[i]);
    if (!parser.check() || o.model.empty() || o.outDir.empty() || o.inputs.empty() || o.variants < 1 ||
        (o.scene.empty() == o.policy.empty())) {
        parser.printErrors();
        std::cerr << "usage: rawgment_augment --model=<m.yml> | --model=<noiseprofiles.json> --camera=<name> "
                     "(--scene=<s.yml> | --policy=<p.yml>) --out=<dir> [--variants=N] <inputs...>\n";
        return 2;
    }
    if (!format.empty()) {
        o.extension = rawgment_apps::writtenContainerExtension(format);
        if (o.extension.empty()) {
            std::cerr << "rawgment_augment: --format must be " << rawgment_apps::writtenContainerNames()
                      << "\n";
            return 2;
        }
    }
    try {
        rawgment_apps::OutputDirectory outputDirectory(o.outDir);
        const rawgment_apps::AugmentResult r = rawgment_apps::augmentFiles(o);
        std::cout << "wrote " << r.written << " outputs, skipped " << r.skipped
                  << " that already existed, in " << o.outDir << "\n";
        outputDirectory.keep();
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_augment: " << e.what() << "\n";
        return 1;
    }
}
