// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Converts camera RAWs and mosaics into the .npy container once, so that a training run decodes nothing.
#include "app_tools.hpp"
#include "pipeline.hpp"

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <filesystem>
#include <iostream>

namespace {

/** The files of the command line, each folder replaced by its files in name order (not its sub-folders,
 * sidecars or hidden files): every one must then be a camera RAW or a mosaic with a sidecar. */
std::vector<std::string> filesOf(const std::vector<std::string>& inputs)
{
    std::vector<std::string> files;
    for (const std::string& in : inputs) {
        std::error_code error;
        if (!std::filesystem::is_directory(in, error)) {
            files.push_back(in);
            continue;
        }
        std::vector<std::string> inFolder;
        for (const auto& entry : std::filesystem::directory_iterator(in)) {
            const std::string name = entry.path().filename().string();
            const bool sidecar = name.size() > 4 && name.compare(name.size() - 4, 4, ".yml") == 0;
            if (entry.is_regular_file() && !sidecar && name[0] != '.')
                inFolder.push_back(entry.path().string());
        }
        if (inFolder.empty())
            throw std::runtime_error("'" + in + "' holds no file to convert");
        std::sort(inFolder.begin(), inFolder.end());
        files.insert(files.end(), inFolder.begin(), inFolder.end());
    }
    return files;
}

} // namespace

int main(int argc, char** argv)
{
    const std::string keysText = "{help h usage ? |      | print this message }"
                                 "{out o          |      | output directory (required; created if missing) }"
                                 "{format         | npy  | output container: " +
                                 rawgment_apps::writtenContainerNames() +
                                 " }"
                                 "{@inputs        |      | input files (camera RAWs, or mosaics with a .yml "
                                 "sidecar) or folders of them }";
    const char* keys = keysText.c_str();
    if (!rawgment_apps::checkCommandLine(argc, argv, keys, "rawgment_convert"))
        return 2;
    rawgment_apps::installInterruptCleanup();
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about(
        "rawgment_convert: RAW files and mosaics rewritten once as <out>/<input stem>.npy with a .yml "
        "sidecar\n"
        "(format, camera tags, source): numpy's uncompressed format, which readMosaic(), RawFolderDataset "
        "and\n"
        "np.load(mmap_mode='r') read at the speed of a copy. The mosaic is unchanged: a camera RAW augments\n"
        "from its conversion exactly as from itself. Existing outputs of the same inputs are skipped, so an\n"
        "interrupted run resumes; nothing is ever overwritten.");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    const std::string outDir = parser.get<std::string>("out"), format = parser.get<std::string>("format");
    std::vector<std::string> inputs;
    // CommandLineParser keeps one positional value; the rest of the command line are inputs too.
    for (int i = 1; i < argc; ++i)
        if (argv[i][0] != '-')
            inputs.push_back(argv[i]);
    if (!parser.check() || outDir.empty() || inputs.empty()) {
        parser.printErrors();
        std::cerr << "usage: rawgment_convert --out=<dir> [--format=npy] <files or folders...>\n";
        return 2;
    }
    if (rawgment_apps::writtenContainerExtension(format).empty()) {
        std::cerr << "rawgment_convert: --format must be " << rawgment_apps::writtenContainerNames()
                  << " (got '" << format << "')\n";
        return 2;
    }
    try {
        const std::vector<std::string> files = filesOf(inputs);
        rawgment_apps::OutputDirectory outputDirectory(outDir);
        rawgment_apps::ProgressBar progress("convert", files.size());
        const rawgment_apps::ConvertResult r = rawgment_apps::convertMosaics(
            files, outDir, rawgment_apps::writtenContainerExtension(format), [&] { progress.advance(); });
        progress.finish();
        std::cout << "wrote " << r.written << " files, skipped " << r.skipped << " converted before, in "
                  << outDir << "\n";
        outputDirectory.keep();
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_convert: " << e.what() << "\n";
        return 1;
    }
}
