// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Noise-accounted augmentation of RAW files with a scene or a random policy.
#include "app_tools.hpp"
#include "pipeline.hpp"

#include <opencv2/core/utility.hpp>

#include <iostream>
#include <stdexcept>

namespace {

/* The keys of OpenCV's parser from the one table of augment flags (rawgment_pipeline::augmentFlags(), which
 * python3 -m rawgment.batch builds its parser from too). */
std::string commandLineKeys()
{
    std::string keys = "{help h usage ? |      | print this message }";
    for (const rawgment_pipeline::AugmentFlag& f : rawgment_pipeline::augmentFlags())
        keys += "{" + f.name + (f.shortName.empty() ? "" : " " + f.shortName) + " | " + f.defaultValue +
                " | " + f.help + " }";
    return keys + "{@inputs        |      | input files (RAW files, or mosaics with a .yml sidecar) }";
}

} // namespace

int main(int argc, char** argv)
{
    const std::string keysText = commandLineKeys();
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
    try {
        for (const rawgment_pipeline::AugmentFlag& f : rawgment_pipeline::augmentFlags())
            rawgment_pipeline::setAugmentOption(o, f.name, parser.get<std::string>(f.name));
    } catch (const std::invalid_argument& e) {
        std::cerr << "rawgment_augment: " << e.what() << "\n";
        return 2;
    }
    // CommandLineParser keeps one positional value; the rest of the command line are inputs too.
    for (int i = 1; i < argc; ++i)
        if (argv[i][0] != '-')
            o.inputs.push_back(argv[i]);
    if (!parser.check() || o.model.empty() || o.outDir.empty() || o.inputs.empty() ||
        (o.scene.empty() == o.policy.empty())) {
        parser.printErrors();
        std::cerr << "usage: rawgment_augment --model=<m.yml> | --model=<noiseprofiles.json> --camera=<name> "
                     "(--scene=<s.yml> | --policy=<p.yml>) --out=<dir> [--variants=N] <inputs...>\n";
        return 2;
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
