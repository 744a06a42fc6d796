// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The paper's statistical validation: a bright burst converted to darker exposures against real bursts.
#include "app_tools.hpp"
#include "pipeline.hpp"

#include <opencv2/core/utility.hpp>

#include <iostream>

int main(int argc, char** argv)
{
    const char* keys =
        "{help h usage ? |      | print this message }"
        "{@manifest      |      | validation manifest (YAML) }"
        "{model m        |      | noise model: YAML/JSON from rawgment_calibrate, an Android "
        "profile YAML, or darktable's noiseprofiles.json with --camera }"
        "{camera         |      | the camera of a darktable noise-profile file (rawgment_cameras "
        "lists them) }"
        "{out o          |      | output directory (required) }"
        "{bins           | 10   | mean bins of the table }"
        "{seed           | 7    | noise seed of the conversions }"
        "{plots          | true | write a PNG plot with gnuplot }"
        "{accept_failed_calibration | false | also use a model whose calibration's verdict "
        "was FAIL }";
    if (!rawgment_apps::checkCommandLine(argc, argv, keys, "rawgment_validate"))
        return 2;
    rawgment_apps::installInterruptCleanup();
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about(
        "rawgment_validate: converts a bright burst by each target factor with NONE, IGNORE_PRIOR and\n"
        "ACCOUNT_PRIOR and compares the per-pixel variance with a real burst at that exposure.\n\n"
        "Manifest:\n"
        "  validation_manifest:\n"
        "    patches: patches.yml      # optional: only these squares\n"
        "    gain_db: 12               # optional: the bursts' gain\n"
        "    bright: [ bright/frame_000.dng, ... ]\n"
        "    targets:\n"
        "      - { factor: 0.5, files: [ ... ] }\n"
        "      - { factor: 0.1, files: [ ... ] }");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    rawgment_apps::ValidateOptions o;
    o.manifest = parser.get<std::string>("@manifest");
    o.model = parser.get<std::string>("model");
    o.camera = parser.get<std::string>("camera");
    o.outDir = parser.get<std::string>("out");
    o.bins = parser.get<int>("bins");
    o.seed = rawgment_apps::seedOption(parser, "rawgment_validate");
    o.plots = parser.get<bool>("plots");
    o.acceptFailedCalibration = parser.get<bool>("accept_failed_calibration");
    if (!parser.check() || o.manifest.empty() || o.model.empty() || o.outDir.empty() || o.bins < 1) {
        parser.printErrors();
        std::cerr << "usage: rawgment_validate <manifest.yml> --model=<model.yml> --out=<dir>\n";
        return 2;
    }
    try {
        rawgment_apps::OutputDirectory outputDirectory(o.outDir);
        const rawgment_apps::ValidateResult r = rawgment_apps::validateConversion(o);
        std::cout << r.table;
        for (const std::string& n : r.notes)
            std::cout << "note: " << n << "\n";
        for (const std::string& p : r.pngs)
            std::cout << "plot: " << p << "\n";
        outputDirectory.keep();
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_validate: " << e.what() << "\n";
        return 1;
    }
}
