// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The real cameras of a darktable noise-profile file: the catalogue, one camera's fit, the report.
#include "app_tools.hpp"
#include "pipeline.hpp"

#include <iostream>

int main(int argc, char** argv)
{
    const char* keys =
        "{help h usage ? |      | print this message }"
        "{profiles p     |      | darktable's noiseprofiles.json (default: the install script's copy, "
        "or darktable's) }"
        "{verdict        | all  | list only: all, good, rough, usable or refused }"
        "{camera         |      | show the fit per ISO of this camera (or a comma-separated list) }"
        "{report         |      | write the report on Eq. 5 (report.md, CSVs, PNGs) into this new "
        "folder }";
    if (!rawgment_apps::checkCommandLine(argc, argv, keys, "rawgment_cameras"))
        return 2;
    rawgment_apps::installInterruptCleanup();
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about(
        "rawgment_cameras: the real cameras of darktable's measured noise profiles, each fitted to the\n"
        "paper's model (Eq. 5) with a verdict: GOOD (imported, close), ROUGH (imported, some ISO off by\n"
        "more; the reason says which) or REFUSED (the reason says why). Columns: full well and read noise\n"
        "in electrons at the base ISO, the share of the read variance before the gain at the highest ISO,\n"
        "the median and worst shot-slope residuals, the worst offset residual, the colours' slope spread.\n"
        "Use a camera with: rawgment_augment --model=<noiseprofiles.json> --camera=\"<name>\" ...");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    rawgment_apps::CamerasOptions o;
    o.profiles = parser.get<std::string>("profiles");
    o.verdict = parser.get<std::string>("verdict");
    o.camera = parser.get<std::string>("camera");
    o.reportDir = parser.get<std::string>("report");
    if (!parser.check()) {
        parser.printErrors();
        return 2;
    }
    try {
        std::unique_ptr<rawgment_apps::OutputDirectory> outputDirectory;
        if (!o.reportDir.empty())
            outputDirectory.reset(new rawgment_apps::OutputDirectory(o.reportDir));
        const rawgment_apps::CamerasResult r = rawgment_apps::runCameras(o);
        std::cout << r.text;
        for (const std::string& n : r.notes)
            std::cout << "note: " << n << "\n";
        for (const std::string& p : r.pngs)
            std::cout << "plot: " << p << "\n";
        if (outputDirectory)
            outputDirectory->keep();
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_cameras: " << e.what() << "\n";
        return 1;
    }
}
