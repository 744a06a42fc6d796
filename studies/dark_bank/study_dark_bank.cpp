// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// study_dark_bank --out=DIR [--campaigns=N] [--emva1288=DESCRIPTOR]: the dark-frame bank against independent
// captures on simulated sensors that depart from the parametric components, beside the calibrated components
// and the plain Gaussian; writes DIR/dark_bank_study.md (the table of docs/dark_frame_bank.md). With an EMVA
// 1288 descriptor, the same methods on that real sensor too: DIR/emva1288_bank_study.md.
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
                       "{campaigns | 8 | campaigns, each with its own sensor, bank, inputs and targets }"
                       "{emva1288 | | an EMVA 1288 descriptor with a spatial set: the real-sensor study too }"
                       "{simulated | true | run the simulated campaigns (false: only the real sensor) }";
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
        std::cerr << "usage: study_dark_bank --out=DIR [--campaigns=N >= 2] [--emva1288=FILE] "
                     "[--simulated=false]\n";
        return 2;
    }
    try {
        std::filesystem::create_directories(out);
        settings.workDir = out + "/banks";
        const auto start = std::chrono::steady_clock::now();
        const auto report = [&](const std::string& name, const std::string& md) {
            cv::rawgment::writeFileAtomically(out + "/" + name, md.data(), md.size(), true);
            std::cout << md
                      << cv::format(
                             "(%.1f s)\n",
                             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        };
        if (parser.get<bool>("simulated"))
            report("dark_bank_study.md", rawgment_studies::darkBankStudyMarkdown(
                                             rawgment_studies::runDarkBankStudy(settings), settings));
        const std::string emva = parser.get<std::string>("emva1288");
        if (!emva.empty())
            report("emva1288_bank_study.md",
                   rawgment_studies::emva1288BankStudyMarkdown(
                       rawgment_studies::runEmva1288BankStudy(emva, out + "/emva1288_bank")));
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "study_dark_bank: " << e.what() << "\n";
        return 1;
    }
}
