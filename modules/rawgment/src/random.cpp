// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
#include "random.hpp"

#include <limits>

namespace cv {
namespace rawgment {
namespace detail {

double logFactorial(int64_t k)
{
    static const std::array<double, 32> table = [] {
        std::array<double, 32> t{};
        double sum = 0;
        for (int i = 1; i < 32; ++i) {
            sum += std::log(static_cast<double>(i));
            t[i] = sum;
        }
        return t;
    }();
    if (k < 32)
        return table[static_cast<size_t>(k)];
    const double x = static_cast<double>(k), inv = 1.0 / x, inv2 = inv * inv;
    return x * std::log(x) - x + 0.5 * std::log(2.0 * CV_PI * x) +
           inv * (1.0 / 12 - inv2 * (1.0 / 360 - inv2 / 1260));
}

int64_t CounterRng::poisson(double lambda)
{
    if (!(lambda > 0))
        return 0;
    if (lambda < 10) {
        // Inversion by sequential search over the CDF; the tail beyond 200 has mass below 1e-200.
        const double u = uniform();
        double p = std::exp(-lambda), cdf = p;
        int64_t k = 0;
        while (u > cdf && k < 200) {
            ++k;
            p *= lambda / static_cast<double>(k);
            cdf += p;
        }
        return k;
    }
    const double sqrtLambda = std::sqrt(lambda), logLambda = std::log(lambda);
    const double b = 0.931 + 2.53 * sqrtLambda;
    const double a = -0.059 + 0.02483 * b;
    const double invAlpha = 1.1239 + 1.1328 / (b - 3.4);
    const double vr = 0.9277 - 3.6224 / (b - 2);
    for (;;) {
        const double u = uniform() - 0.5;
        const double v = uniform();
        const double us = 0.5 - std::abs(u);
        const double kd = std::floor((2 * a / us + b) * u + lambda + 0.43);
        if (us >= 0.07 && v <= vr)
            return static_cast<int64_t>(kd);
        if (kd < 0 || (us < 0.013 && v > us))
            continue;
        const int64_t k = static_cast<int64_t>(kd);
        if (std::log(v) + std::log(invAlpha) - std::log(a / (us * us) + b) <=
            -lambda + kd * logLambda - logFactorial(k))
            return k;
    }
}

} // namespace detail
} // namespace rawgment
} // namespace cv
