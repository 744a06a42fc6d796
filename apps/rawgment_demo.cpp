// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The demo: shows the noise model of a simulated sensor and how its variance grows with the mean and
// the gain. Later stages of the project extend it to the whole calibrate-validate-augment pipeline.
#include <opencv2/core/utility.hpp>
#include <opencv2/rawgment.hpp>

#include <cstdio>
#include <iostream>

namespace {

const char* const kKeys = "{help h usage ? |      | print this message }"
                          "{alpha          | 0.25 | shot-noise slope at gain 1 (DN per electron) }"
                          "{sigma_d2       | 1.5  | read-noise variance before the gain (DN^2) }"
                          "{sigma_r2       | 0.8  | noise variance after the gain (DN^2) }"
                          "{gains          | 0,6,12,24 | comma-separated gains in dB }"
                          "{white          | 4095 | white level minus black (DN), the top of the curve }"
                          "{out            |      | optional: save the model to this .yml/.json file }";

std::vector<double> parseList(const std::string& text)
{
    std::vector<double> values;
    size_t start = 0;
    while (start <= text.size()) {
        const size_t comma = text.find(',', start);
        const std::string item =
            text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
        size_t used = 0;
        const double v = std::stod(item, &used);
        if (used != item.size())
            throw std::invalid_argument("'" + item + "' is not a number");
        values.push_back(v);
        if (comma == std::string::npos)
            break;
        start = comma + 1;
    }
    return values;
}

} // namespace

int main(int argc, char** argv)
{
    cv::CommandLineParser parser(argc, argv, kKeys);
    parser.about("rawgment_demo: the heteroscedastic Gaussian noise model of cv::rawgment\n"
                 "sigma^2 = g*alpha*max(mu,0) + g^2*sigma_d^2 + sigma_r^2");
    if (parser.has("help")) {
        parser.printMessage();
        return 0;
    }
    try {
        const cv::rawgment::NoiseModel model(parser.get<double>("alpha"), parser.get<double>("sigma_d2"),
                                             parser.get<double>("sigma_r2"));
        const std::vector<double> gainsDb = parseList(parser.get<std::string>("gains"));
        const double white = parser.get<double>("white");
        const std::string out = parser.get<std::string>("out");
        if (!parser.check()) {
            parser.printErrors();
            return 2;
        }
        std::printf("Noise model: alpha = %g DN/e-, sigma_d^2 = %g DN^2, sigma_r^2 = %g DN^2\n\n",
                    model.alpha, model.sigmaD2, model.sigmaR2);
        std::printf("%8s %10s %12s %12s\n", "gain dB", "gain", "slope a", "offset b");
        for (double db : gainsDb) {
            const double g = cv::rawgment::dbToLinearGain(db);
            const cv::rawgment::NoiseLine line = model.lineAtGain(g);
            std::printf("%8.2f %10.4f %12.5f %12.5f\n", db, g, line.a, line.b);
        }
        std::printf("\nStandard deviation (DN) against the mean, one column per gain:\n%10s", "mean DN");
        for (double db : gainsDb)
            std::printf(" %9.1fdB", db);
        std::printf("\n");
        for (int i = 0; i <= 8; ++i) {
            const double mu = i == 0 ? 0.0 : white * std::pow(2.0, i - 8);
            std::printf("%10.1f", mu);
            for (double db : gainsDb)
                std::printf(" %11.3f", std::sqrt(model.variance(mu, cv::rawgment::dbToLinearGain(db))));
            std::printf("\n");
        }
        if (!out.empty()) {
            model.save(out);
            std::printf("\nSaved the model to %s\n", out.c_str());
        }
    } catch (const cv::Exception& e) {
        std::cerr << "rawgment_demo: " << e.err << "\n";
        return 1;
    } catch (const std::exception& e) {
        std::cerr << "rawgment_demo: bad argument: " << e.what() << "\n";
        return 2;
    }
    return 0;
}
