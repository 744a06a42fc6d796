// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Sample: split a Bayer mosaic into its CFA planes, subtract the black level, and find each colour.
#include <opencv2/rawgment.hpp>

#include <cstdio>

int main()
{
    using namespace cv::rawgment;
    RawFormat format;
    format.pattern = CFA_GRBG;
    format.blackLevel = cv::Vec4d::all(64);
    format.whiteLevel = 1023;

    cv::Mat mosaic(8, 8, CV_16UC1);
    cv::randu(mosaic, 64, 1024);

    cv::Mat signal;
    subtractBlackLevel(mosaic, format, signal); // CV_32FC1, DN above black
    std::vector<cv::Mat> planes;
    splitCfaPlanes(signal, planes); // one plane per 2x2 site
    for (CfaChannel channel : {CFA_R, CFA_G1, CFA_G2, CFA_B}) {
        const int site = cfaSiteOfChannel(format.pattern, channel);
        std::printf("channel %d lies at site %d, mean %.1f DN\n", channel, site, cv::mean(planes[site])[0]);
    }
    // A crop starting at an odd column has another phase: the format follows it.
    const RawFormat crop = format.cropped(0, 1);
    std::printf("%s cropped at column 1 is %s\n", cfaPatternName(format.pattern).c_str(),
                cfaPatternName(crop.pattern).c_str());
    return 0;
}
