// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The read part of a noise step drawn from a dark-frame bank (bank_noise.hpp).
#include "bank_noise.hpp"

#include "precomp.hpp"

#include <cmath>
#include <list>
#include <mutex>
#include <sys/stat.h>

namespace cv {
namespace rawgment {
namespace detail {

std::shared_ptr<const DarkFrameBank> cachedDarkFrameBank(const String& path)
{
    struct Entry
    {
        String path;
        long long bytes;
        long long modified;
        std::shared_ptr<const DarkFrameBank> bank;
    };
    // A few banks: a data loader uses one, a comparison two or three.
    static std::mutex mutex;
    static std::list<Entry> entries;
    struct stat info;
    if (::stat(path.c_str(), &info) != 0)
        CV_Error(Error::StsError, format("dark-frame bank file '%s' is missing", path.c_str()));
    const long long bytes = static_cast<long long>(info.st_size),
                    modified =
                        static_cast<long long>(info.st_mtim.tv_sec) * 1000000000LL + info.st_mtim.tv_nsec;
    {
        std::lock_guard<std::mutex> lock(mutex);
        for (auto it = entries.begin(); it != entries.end(); ++it)
            if (it->path == path && it->bytes == bytes && it->modified == modified) {
                entries.splice(entries.begin(), entries, it);
                return entries.front().bank;
            }
    }
    std::shared_ptr<const DarkFrameBank> bank =
        std::make_shared<const DarkFrameBank>(DarkFrameBank::load(path));
    std::lock_guard<std::mutex> lock(mutex);
    entries.remove_if([&](const Entry& e) { return e.path == path; });
    entries.push_front({path, bytes, modified, bank});
    while (entries.size() > 4)
        entries.pop_back();
    return bank;
}

namespace {

//! The pixel part's variance of each pixel of a mosaic at `origin` in a group: its row's pooled variance less
//! the row noise, a noisy pixel's own less the row noise; times scale^2.
Mat pixelPartVariance(const DarkFrameGroup& g, Point origin, Size size, double scale)
{
    const DarkFrameStatistics& s = g.statistics;
    Mat v(size, CV_32FC1);
    const double s2 = scale * scale;
    for (int r = 0; r < size.height; ++r) {
        float* out = v.ptr<float>(r);
        const int R = r + origin.y;
        for (int c = 0; c < size.width; ++c) {
            const int C = c + origin.x;
            out[c] = static_cast<float>(
                s2 * std::max(0.0, s.rowVariance.at<double>(R, C & 1) - s.rowNoiseVariance[cfaSite(R, C)]));
        }
    }
    const Rect inside(origin, size);
    for (size_t i = 0; i < s.noisyPixels.size(); ++i) {
        const Point p = s.noisyPixels[i];
        if (inside.contains(p))
            v.at<float>(p - origin) = static_cast<float>(
                s2 * std::max(0.0, s.noisyVariance[i] - s.rowNoiseVariance[cfaSite(p.y, p.x)]));
    }
    return v;
}

} // namespace

Mat bankInputPattern(const StepNoise& step, const RawFormat& format, Size size)
{
    const DarkFrameGroup& in = step.bank->groups[static_cast<size_t>(step.bankGroupIn)];
    return in.statistics.pattern(Rect(format.sensorOrigin, size)).clone();
}

BankRead prepareBankRead(const StepNoise& step, const RawFormat& format, Size size,
                         const BankPattern& pattern, uint64 seed, RandomStream stream, const char* who)
{
    CV_Assert(step.bank);
    const DarkFrameBank& bank = *step.bank;
    BankRead b;
    b.origin = format.sensorOrigin;
    if ((Rect(b.origin, size) & Rect(Point(), bank.size)) != Rect(b.origin, size))
        CV_Error(
            Error::StsBadArg,
            cv::format("%s: the mosaic %dx%d at sensor origin (%d, %d) lies outside the dark-frame bank's "
                       "%dx%d frames ('%s')",
                       who, size.width, size.height, b.origin.x, b.origin.y, bank.size.width,
                       bank.size.height, step.options.darkBank.c_str()));
    if (bank.format.cropped(b.origin.y, b.origin.x).pattern != format.pattern)
        CV_Error(Error::StsBadArg,
                 cv::format(
                     "%s: the mosaic is %s at sensor origin (%d, %d), where the dark-frame bank's frames are "
                     "%s: another sensor, or a crop without its offset",
                     who, cfaPatternName(format.pattern).c_str(), b.origin.x, b.origin.y,
                     cfaPatternName(bank.format.cropped(b.origin.y, b.origin.x).pattern).c_str()));
    const DarkFrameGroup &out = bank.groups[static_cast<size_t>(step.bankGroupOut)],
                         &in = bank.groups[static_cast<size_t>(step.bankGroupIn)];
    const bool tied = step.options.darkBankTied;
    if (tied && std::abs(std::log(in.gain / step.gainIn)) > 1e-3)
        CV_Error(Error::StsBadArg,
                 cv::format(
                     "%s: a tied dark-frame bank takes the input's own pattern out, but it has no frames at "
                     "the input's gain %g (its nearest is %g)",
                     who, step.gainIn, in.gain));
    b.ignore = step.options.alignment == NoiseAlignment::IGNORE_PRIOR;
    b.scale = static_cast<float>(step.bankScaleOut);
    for (int s = 0; s < 4; ++s)
        b.black[s] = static_cast<float>(bank.format.blackLevel[s]);
    // Two different frames of the target's group, from the step's own stream.
    CounterRng rng(stepKey(seed, static_cast<uint64_t>(stream)), 0);
    const int M = static_cast<int>(out.files.size());
    const int i = std::min(M - 1, static_cast<int>(rng.uniform() * M));
    const int j = (i + 1 + std::min(M - 2, static_cast<int>(rng.uniform() * (M - 1)))) % M;
    bank.readFrame(step.bankGroupOut, i).convertTo(b.frameA, CV_32F);
    if (b.ignore)
        return b;
    bank.readFrame(step.bankGroupOut, j).convertTo(b.frameB, CV_32F);

    const DarkFrameStatistics &so = out.statistics, &si = in.statistics;
    const double at2 = step.bankScaleOut * step.bankScaleOut, as2 = step.bankScaleIn * step.bankScaleIn;
    for (int m = 0; m < 4; ++m) {
        const int S = cfaSite(m / 2 + b.origin.y, m % 2 + b.origin.x); // the sensor's site of mosaic site m
        b.rowTarget[m] = static_cast<float>(at2 * so.rowNoiseVariance[S]);
        b.rowHeld[m] = static_cast<float>(as2 * si.rowNoiseVariance[S]);
    }
    // The pixel part: per row and column parity, and per noisy pixel, as the groups measured it; the input's
    // own by row and pixel only when it is the bank's sensor (tied), else pooled per site.
    b.pixelTarget = pixelPartVariance(out, b.origin, size, step.bankScaleOut);
    if (tied) {
        b.pixelHeld = pixelPartVariance(in, b.origin, size, step.bankScaleIn);
    } else {
        b.pixelHeld.create(size, CV_32FC1);
        for (int r = 0; r < size.height; ++r)
            for (int c = 0; c < size.width; ++c) {
                const int S = cfaSite(r + b.origin.y, c + b.origin.x);
                b.pixelHeld.at<float>(r, c) =
                    static_cast<float>(as2 * std::max(0.0, si.temporalVariance[S] - si.rowNoiseVariance[S]));
            }
    }
    // The pattern: tied, the input's (as the step leaves it) out and the target's in; untied, what the
    // target's variance lacks of the input's scaled one, as the target's own pattern.
    const Rect crop(b.origin, size);
    if (tied) {
        b.patternAdd = so.pattern(crop).clone();
        if (!pattern.held.empty()) {
            CV_Assert(pattern.held.type() == CV_32FC1 && pattern.held.size() == size);
            b.patternAdd -= pattern.held;
        } else {
            for (int r = 0; r < size.height; ++r) {
                float* p = b.patternAdd.ptr<float>(r);
                const float* f = si.pattern.ptr<float>(r + b.origin.y) + b.origin.x;
                for (int c = 0; c < size.width; ++c)
                    p[c] -= static_cast<float>(pattern.amplitude[cfaSite(r, c)]) * f[c];
            }
        }
        return b;
    }
    float share[4];
    bool any = false;
    for (int m = 0; m < 4; ++m) {
        const int S = cfaSite(m / 2 + b.origin.y, m % 2 + b.origin.x);
        const double a = pattern.amplitude[m], t = so.patternVariance[S], h = a * a * si.patternVariance[S];
        share[m] = t > 0 ? static_cast<float>(std::sqrt(std::max(0.0, 1 - h / t))) : 0.0f;
        any = any || share[m] > 0;
    }
    if (any) {
        b.patternAdd.create(size, CV_32FC1);
        for (int r = 0; r < size.height; ++r) {
            float* p = b.patternAdd.ptr<float>(r);
            const float* f = so.pattern.ptr<float>(r + b.origin.y) + b.origin.x;
            for (int c = 0; c < size.width; ++c)
                p[c] = share[cfaSite(r, c)] *
                       (f[c] - static_cast<float>(so.level[cfaSite(r + b.origin.y, c + b.origin.x)]));
        }
    }
    return b;
}

int64 bankRowExtra(const BankRead& b, int r, int first, int step, int n, const float rowFactor[2],
                   const float* pixelFactor, float* extra)
{
    const int R = r + b.origin.y, x0 = b.origin.x;
    const float* a = b.frameA.ptr<float>(R);
    if (b.ignore) {
        for (int j = 0; j < n; ++j) {
            const int C = first + step * j + x0;
            extra[j] = b.scale * (a[C] - b.black[cfaSite(R, C)]);
        }
        return 0;
    }
    const float* f = b.frameB.ptr<float>(R);
    // The row part at each sensor column parity: the difference's mean over the sensor's whole row there.
    double sum[2] = {0, 0};
    const int width = b.frameA.cols;
    for (int C = 0; C < width; ++C)
        sum[C & 1] += static_cast<double>(a[C]) - f[C];
    const float k = b.scale * static_cast<float>(1 / std::sqrt(2.0));
    const float sensorRho[2] = {k * static_cast<float>(sum[0] / ((width + 1) / 2)),
                                width > 1 ? k * static_cast<float>(sum[1] / (width / 2)) : 0.0f};
    float rho[2], rowShare[2];
    bool rowExceeded[2];
    for (int p = 0; p < 2; ++p) {
        rho[p] = sensorRho[(p + x0) & 1];
        const int m = 2 * (r & 1) + p;
        const float held = rowFactor[p] * b.rowHeld[m], target = b.rowTarget[m];
        rowExceeded[p] = held > target;
        rowShare[p] = target > 0 ? std::sqrt(std::max(0.0f, 1 - held / target)) : 0.0f;
    }
    const float *pt = b.pixelTarget.ptr<float>(r), *ph = b.pixelHeld.ptr<float>(r);
    const float* pattern = b.patternAdd.empty() ? nullptr : b.patternAdd.ptr<float>(r);
    int64 exceeded = 0;
    for (int j = 0; j < n; ++j) {
        const int c = first + step * j, p = c & 1;
        const float d = k * (a[c + x0] - f[c + x0]);
        const float held = pixelFactor[j] * ph[c], target = pt[c];
        const float share = target > 0 ? std::sqrt(std::max(0.0f, 1 - held / target)) : 0.0f;
        exceeded += held > target || rowExceeded[p];
        extra[j] = rowShare[p] * rho[p] + share * (d - rho[p]) + (pattern ? pattern[c] : 0.0f);
    }
    return exceeded;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
