// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The fuzz targets of the emva1288 topic (test/fuzz/rawgment_fuzz.cpp runs them).
#include "fuzz_target.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/rawgment/emva1288.hpp>

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace rawgment_fuzz {

using namespace cv::rawgment;
namespace fs = std::filesystem;

std::vector<Target> emva1288Targets()
{
    std::vector<Target> targets;
    // EMVA 1288: the descriptor (its images beside it, 16x12 12-bit PNGs of rising signal) read and
    // reduced to the standard's figures; and one image of such a series, mutated.
    const auto emvaImages = [](const std::string& work) {
        cv::RNG rng(1288);
        // Steps 0-3 are the temporal pairs, step 4 the spatial stacks' frames: a series lists a file once.
        for (int s = 0; s < 5; ++s)
            for (const char* kind : {"b", "d"})
                for (int f = 0; f < (s < 4 ? 2 : 3); ++f) {
                    cv::Mat image(12, 16, CV_16UC1);
                    const double level = 100 + (*kind == 'b' ? 600.0 * (s + 1) : 0.0);
                    rng.fill(image, cv::RNG::NORMAL, level, std::sqrt(9 + (level - 100) * 0.3));
                    const std::string name = work + cv::format("/%s%d_%d.png", kind, s, f);
                    if (!cv::imwrite(name, image))
                        throw std::runtime_error("cannot write '" + name + "'");
                }
    };
    targets.push_back(
        {"emva1288", "EMVA1288_Data.txt", false, Errors::LIBRARY,
         [emvaImages](const std::string& work) {
             emvaImages(work);
             std::string text = "# EMVA 1288 seed\r\nv 3.0\r\nn 12 16 12\r\n";
             for (int s = 0; s < 4; ++s)
                 text += cv::format("b %d %d\r\ni b%d_0.png\r\ni b%d_1.png\r\nd %d\r\ni d%d_0.png\r\ni "
                                    "d%d_1.png\r\n",
                                    1000 * (s + 1), 2000 * (s + 1), s, s, 1000 * (s + 1), s, s);
             std::string spatial = "v 4.0\nn 12 16 12\n";
             for (int s = 0; s < 4; ++s)
                 spatial += cv::format("b %d,5 %d\ni images\\..\\b%d_0.png\ni b%d_1.png\nd %d,5\ni "
                                       "d%d_0.png\ni d%d_1.png\n",
                                       s + 1, 2000 * (s + 1), s, s, s + 1, s, s);
             spatial += "b 9 500\ni b4_0.png\ni b4_1.png\ni b4_2.png\nd 9\ni d4_0.png\ni d4_1.png\ni "
                        "d4_2.png\n";
             fs::create_directories(work + "/images");
             return std::vector<std::string>{text, spatial};
         },
         [](const std::string& in) {
             const Emva1288Series series = readEmva1288(in);
             if (series.bits < 1 || series.bits > MAX_EMVA1288_BITS || series.width < 1 ||
                 series.height < 1 || (long long)series.width * series.height > MAX_EMVA1288_PIXELS)
                 return std::string("accepted an 'n' line outside the caps");
             for (const Emva1288Images& g : series.temporal)
                 if (g.images.size() != 2 || !(g.exposureNs >= 0) || !(g.photons >= 0))
                     return std::string("accepted a temporal step that is not a pair of a valid exposure");
             const Emva1288Results r = emva1288Results(series);
             if (!(std::isfinite(r.K) && r.K > 0 && std::isfinite(r.sigmaD) && r.sigmaYDark >= 0.48))
                 return cv::format("gave K %g, sigma_y.dark %g, sigma_d %g", r.K, r.sigmaYDark, r.sigmaD);
             if (r.photonsGiven && !(std::isfinite(r.eta) && r.eta > 0 && std::isfinite(r.muPMin)))
                 return cv::format("gave eta %g and mu_p.min %g with photon counts", r.eta, r.muPMin);
             if (!std::isfinite(r.snrMaxDb) && !(r.muESat <= 0))
                 return cv::format("gave SNR_max %g dB", r.snrMaxDb);
             return std::string();
         }});
    targets.push_back({"emva1288_image", "input.png", true, Errors::LIBRARY,
                       [emvaImages](const std::string& work) {
                           emvaImages(work);
                           std::vector<std::string> seeds{readBytes(work + "/b0_0.png")};
                           cv::Mat image(12, 16, CV_16UC1, cv::Scalar(1000));
                           if (!cv::imwrite(work + "/seed.tif", image))
                               throw std::runtime_error("cannot write the TIFF seed");
                           seeds.push_back(readBytes(work + "/seed.tif"));
                           return seeds;
                       },
                       [](const std::string& in) {
                           Emva1288Series series;
                           series.path = "fuzzed series";
                           series.bits = 12;
                           series.width = 16;
                           series.height = 12;
                           const cv::Mat image = readEmva1288Image(series, in, 1);
                           double maxValue = 0;
                           cv::minMaxLoc(image, nullptr, &maxValue);
                           if (image.size() != cv::Size(16, 12) ||
                               (image.type() != CV_8UC1 && image.type() != CV_16UC1) || maxValue > 4095)
                               return std::string("accepted an image that does not match its series");
                           return std::string();
                       }});
    return targets;
}

} // namespace rawgment_fuzz
