// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Uses the installed headers and library; exits non-zero when a result is wrong.
#include <opencv2/rawgment.hpp>

#include <cstdio>

int main()
{
    const cv::rawgment::NoiseModel model(0.5, 2.0, 1.0);
    const double v = model.variance(100.0, cv::rawgment::dbToLinearGain(20.0)); // 10*0.5*100 + 100*2 + 1
    std::vector<cv::Mat> planes;
    cv::rawgment::splitCfaPlanes(cv::Mat(4, 6, CV_16UC1, cv::Scalar(7)), planes);
    const bool ok = std::abs(v - 701.0) < 1e-9 && planes.size() == 4 && planes[3].size() == cv::Size(3, 2);
    std::printf("downstream: variance %.3f, %zu planes: %s\n", v, planes.size(), ok ? "ok" : "WRONG");
    return ok ? 0 : 1;
}
