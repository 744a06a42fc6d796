// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Writes simulated colour-checker bursts (the project's ground truth) for rawgment_calibrate and
// rawgment_validate: frames with sidecars, manifests, the patch squares and the true noise model.
#include "app_tools.hpp"
#include "pipeline.hpp"

#include <opencv2/core/utility.hpp>

#include <cmath>
#include <iostream>
#include <stdexcept>

int main(int argc, char** argv)
{
    const std::string keysText =
        "{help h usage ? |          | print this message }"
        "{out o          |          | output directory (required) }"
        "{gains          | 6,12,24  | analog gains in dB }"
        "{levels         | 0.3,0.9  | white-patch level of each burst, fraction of the range }"
        "{frames         | 100      | frames per burst (>= 3) }"
        "{patch          | 40       | patch side in pixels (even) }"
        "{alpha          | 0.25     | sensor: shot-noise slope at gain 1 }"
        "{sigma_d2       | 1.5      | sensor: read-noise variance before the gain (DN^2) }"
        "{sigma_r2       | 0.8      | sensor: noise variance after the gain (DN^2) }"
        "{bits           | 12       | sensor: ADC bits }"
        "{pattern        | RGGB     | sensor: colour filter RGGB, BGGR, GRBG or GBRG, or MONO for none "
        "(monochrome) }"
        "{outliers       | 0        | sensor: fraction of hot + dead + noisy pixels }"
        "{seed           | 1        | noise seed }"
        "{format         | dng      | frame container: " +
        rawgment_apps::writtenContainerNames() +
        " }"
        "{dark           | false    | also a burst of dark frames (no light, as under a lens cap) per gain }"
        "{row_noise      | 0,0      | sensor: row-noise variance before, after the gain (DN^2) }"
        "{tukey_lambda   | none     | sensor: Tukey-lambda shape of the read noise (none: Gaussian) }"
        "{dark_shading   | 0        | sensor: amplitude of a dark-shading pattern (DN; 0: none) }"
        "{validation     | true     | also write the bright and x0.5, x0.1 bursts for rawgment_validate }";
    const char* keys = keysText.c_str();
    if (!rawgment_apps::checkCommandLine(argc, argv, keys, "rawgment_simulate"))
        return 2;
    rawgment_apps::installInterruptCleanup();
    cv::CommandLineParser parser(argc, argv, keys);
    parser.about("rawgment_simulate: simulated colour-checker bursts with a known noise model");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    try {
        rawgment_apps::SimulateOptions o;
        o.outDir = parser.get<std::string>("out");
        o.gainsDb = rawgment_apps::parseNumberList(parser.get<std::string>("gains"));
        o.levels = rawgment_apps::parseNumberList(parser.get<std::string>("levels"));
        o.frames = parser.get<int>("frames");
        o.validationFrames = o.frames;
        o.patchSize = parser.get<int>("patch");
        o.sensor.noise = cv::rawgment::NoiseModel(parser.get<double>("alpha"), parser.get<double>("sigma_d2"),
                                                  parser.get<double>("sigma_r2"));
        o.sensor.bitDepth = parser.get<int>("bits");
        try {
            o.sensor.pattern = cv::rawgment::cfaPatternFromName(parser.get<std::string>("pattern"));
        } catch (const cv::Exception& e) {
            std::cerr << "rawgment_simulate: --pattern: " << e.err << "\n";
            return 2;
        }
        const double outliers = parser.get<double>("outliers");
        o.sensor.hotPixelFraction = o.sensor.deadPixelFraction = o.sensor.noisyPixelFraction = outliers / 3;
        o.seed = rawgment_apps::seedOption(parser, "rawgment_simulate");
        const std::string format = parser.get<std::string>("format");
        o.extension = rawgment_apps::writtenContainerExtension(format);
        o.validation = parser.get<bool>("validation");
        o.dark = parser.get<bool>("dark");
        const std::vector<double> rowNoise =
            rawgment_apps::parseNumberList(parser.get<std::string>("row_noise"));
        if (rowNoise.size() != 2)
            throw std::runtime_error("--row_noise takes two variances: before,after the gain");
        o.sensor.noise.rowSigmaD2 = rowNoise[0];
        o.sensor.noise.rowSigmaR2 = rowNoise[1];
        const std::string lambda = parser.get<std::string>("tukey_lambda");
        if (lambda != "none") {
            o.sensor.noise.tukeyRead = true;
            try {
                size_t used = 0;
                o.sensor.noise.tukeyLambda = std::stod(lambda, &used);
                if (used != lambda.size())
                    throw std::invalid_argument(lambda);
            } catch (const std::logic_error&) {
                throw std::runtime_error("--tukey_lambda must be a number or none (got '" + lambda + "')");
            }
        }
        o.darkShading = parser.get<double>("dark_shading");
        if (!(o.darkShading >= 0 && std::isfinite(o.darkShading)))
            throw std::runtime_error("--dark_shading must be a finite amplitude >= 0");
        if (!parser.check() || o.outDir.empty()) {
            parser.printErrors();
            std::cerr << "rawgment_simulate: --out is required (see --help)\n";
            return 2;
        }
        if (o.extension.empty()) {
            std::cerr << "rawgment_simulate: --format must be " << rawgment_apps::writtenContainerNames()
                      << "\n";
            return 2;
        }
        o.sensor.validate();
        rawgment_apps::OutputDirectory outputDirectory(o.outDir);
        const rawgment_apps::SimulateResult r = rawgment_apps::simulateBursts(o);
        std::cout << "wrote " << r.files << " frames\n  calibration manifest: " << r.manifest << "\n";
        if (!r.validationManifest.empty())
            std::cout << "  validation manifest:  " << r.validationManifest << "\n";
        std::cout << "  true noise model:     " << r.truthModel << "\n";
        outputDirectory.keep();
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_simulate: " << e.what() << "\n";
        return 1;
    }
}
