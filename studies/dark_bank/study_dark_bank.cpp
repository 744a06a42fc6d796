// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// study_dark_bank --out=DIR [--campaigns=N]: the dark-frame bank against independent captures on simulated
// sensors that depart from the parametric components, beside the calibrated components and the plain
// Gaussian; writes DIR/dark_bank_study.md (the table of docs/dark_frame_bank.md).
#include "dark_bank_study.hpp"

#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment/files.hpp>

#include <chrono>
#include <filesystem>
#include <iostream>

int main(int argc, char** argv)
{
    const char* keys = "{help h usage ? | | print this message }"
                       "{out o | | output folder (required; created) }"
                       "{campaigns | 8 | campaigns, each with its own sensor, bank, inputs and targets }";
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about("study_dark_bank: the dark-frame bank, the calibrated components and the Gaussian against "
                 "independent captures");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    const std::string out = parser.get<std::string>("out");
    rawgment_studies::DarkBankStudySettings settings;
    settings.campaigns = parser.get<int>("campaigns");
    if (!parser.check() || out.empty() || settings.campaigns < 2) {
        parser.printErrors();
        std::cerr << "usage: study_dark_bank --out=DIR [--campaigns=N >= 2]\n";
        return 2;
    }
    try {
        std::filesystem::create_directories(out);
        settings.workDir = out + "/banks";
        const auto start = std::chrono::steady_clock::now();
        const rawgment_studies::DarkBankStudy study = rawgment_studies::runDarkBankStudy(settings);
        const std::string md = rawgment_studies::darkBankStudyMarkdown(study, settings);
        cv::rawgment::writeFileAtomically(out + "/dark_bank_study.md", md.data(), md.size(), true);
        std::cout << md
                  << cv::format(
                         "(%.1f s)\n",
                         std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "study_dark_bank: " << e.what() << "\n";
        return 1;
    }
}
