// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The read part of a noise step drawn from a dark-frame bank (bank_noise.hpp).
#include "bank_noise.hpp"
#include "file_access.hpp"

#include "precomp.hpp"

#include <algorithm>
#include <cmath>
#include <list>
#include <mutex>

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
    FileStamp stamp;
    if (!fileStampOf(path, stamp))
        CV_Error(Error::StsError, format("dark-frame bank file '%s' is missing", path.c_str()));
    const long long bytes = stamp.bytes, modified = stamp.modifiedNs;
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

//! The pixel part's variance of a mosaic at `origin` in a group: its rows' pooled variance less the row
//! noise, and each noisy pixel's own less the row noise; times scale^2.
PixelPartVariance pixelPartVariance(const DarkFrameGroup& g, Point origin, Size size, double scale)
{
    const DarkFrameStatistics& s = g.statistics;
    PixelPartVariance v;
    const double s2 = scale * scale;
    v.byRow.create(size.height, 2, CV_32FC1);
    for (int r = 0; r < size.height; ++r)
        for (int p = 0; p < 2; ++p) {
            const int R = r + origin.y, C = p + origin.x;
            v.byRow.at<float>(r, p) = static_cast<float>(
                s2 * std::max(0.0, s.rowVariance.at<double>(R, C & 1) - s.rowNoiseVariance[cfaSite(R, C)]));
        }
    std::vector<std::pair<Point, float>> inside;
    const Rect crop(origin, size);
    for (size_t i = 0; i < s.noisyPixels.size(); ++i)
        if (crop.contains(s.noisyPixels[i])) {
            const Point p = s.noisyPixels[i];
            inside.emplace_back(
                p - origin,
                static_cast<float>(
                    s2 * std::max(0.0, s.noisyVariance[i] - s.rowNoiseVariance[cfaSite(p.y, p.x)])));
        }
    std::sort(inside.begin(), inside.end(),
              [](const std::pair<Point, float>& x, const std::pair<Point, float>& y) {
                  return std::make_pair(x.first.y, x.first.x) < std::make_pair(y.first.y, y.first.x);
              });
    v.rowStart.assign(static_cast<size_t>(size.height) + 1, 0);
    for (const auto& e : inside) {
        v.column.push_back(e.first.x);
        v.variance.push_back(e.second);
        ++v.rowStart[static_cast<size_t>(e.first.y) + 1];
    }
    for (int r = 0; r < size.height; ++r)
        v.rowStart[static_cast<size_t>(r) + 1] += v.rowStart[static_cast<size_t>(r)];
    return v;
}

//! The variance at mosaic column c of row r: a noisy pixel's own, else the row's at the column's parity.
float varianceAt(const PixelPartVariance& v, int r, int c)
{
    for (int i = v.rowStart[static_cast<size_t>(r)]; i < v.rowStart[static_cast<size_t>(r) + 1]; ++i)
        if (v.column[static_cast<size_t>(i)] == c)
            return v.variance[static_cast<size_t>(i)];
    return v.byRow.at<float>(r, c & 1);
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
    if (tied) {
        // Tied means the input was taken by the bank's own sensor: its black and white levels are the
        // frames' (#79 item 8). An input at black 512 and white 16383 against frames at 64 and 4095 is not.
        const RawFormat frames = bank.format.cropped(b.origin.y, b.origin.x);
        bool same = std::abs(frames.whiteLevel - format.whiteLevel) <= 1e-9 * frames.whiteLevel;
        for (int s = 0; s < 4; ++s)
            same = same && std::abs(frames.blackLevel[s] - format.blackLevel[s]) <= 1e-9 * frames.whiteLevel;
        if (!same)
            CV_Error(
                Error::StsBadArg,
                cv::format("%s: a tied dark-frame bank ('%s') holds its own sensor's frames, black (%g, %g, "
                           "%g, %g) and white %g at this crop, but the input is at black (%g, %g, %g, %g) "
                           "and white %g: another sensor (a bank of other sensors' frames is untied)",
                           who, step.options.darkBank.c_str(), frames.blackLevel[0], frames.blackLevel[1],
                           frames.blackLevel[2], frames.blackLevel[3], frames.whiteLevel,
                           format.blackLevel[0], format.blackLevel[1], format.blackLevel[2],
                           format.blackLevel[3], format.whiteLevel));
    }
    b.ignore = step.options.alignment == NoiseAlignment::IGNORE_PRIOR;
    for (int s = 0; s < 4; ++s)
        b.black[s] = static_cast<float>(bank.format.blackLevel[s]);
    // One frame of the target's group, from the step's own stream. ACCOUNT_PRIOR takes the group's mean out
    // of it: f_i - m is the frame less the mean of the others times (M - 1) / M, so sqrt(M / (M - 1)) (f_i -
    // m) has the frames' temporal variance, is uncorrelated with the mean (and so with the pattern estimated
    // from it), and keeps (1 + 1/(M - 1)^3) / (1 + 1/(M - 1))^2 of a frame's excess kurtosis (0.92 at M = 25;
    // a difference of two frames keeps half of it).
    CounterRng rng(stepKey(seed, static_cast<uint64_t>(stream)), 0);
    const int M = static_cast<int>(out.files.size());
    const int i = std::min(M - 1, static_cast<int>(rng.uniform() * M));
    b.frame = bank.readFrame(step.bankGroupOut, i);
    if (b.ignore) {
        b.drawScale = static_cast<float>(step.bankScaleOut);
        return b;
    }
    b.groupMean = out.statistics.mean;
    b.drawScale = static_cast<float>(step.bankScaleOut * std::sqrt(M / (M - 1.0)));

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
        for (int m = 0; m < 4; ++m) {
            const int S = cfaSite(m / 2 + b.origin.y, m % 2 + b.origin.x);
            b.pixelHeldBySite[m] =
                static_cast<float>(as2 * std::max(0.0, si.temporalVariance[S] - si.rowNoiseVariance[S]));
        }
    }
    // The pattern: tied, the input's (as the step leaves it) out and the target's in; untied, what the
    // target's variance lacks of the input's scaled one, as the target's own pattern.
    b.patternTarget = so.pattern;
    for (int m = 0; m < 4; ++m) {
        const int S = cfaSite(m / 2 + b.origin.y, m % 2 + b.origin.x);
        b.levelTarget[m] = static_cast<float>(so.level[S]);
        b.patternAmplitude[m] = static_cast<float>(pattern.amplitude[m]);
        const double a = pattern.amplitude[m], t = so.patternVariance[S], h = a * a * si.patternVariance[S];
        b.patternShare[m] = t > 0 ? static_cast<float>(std::sqrt(std::max(0.0, 1 - h / t))) : 0.0f;
    }
    if (tied && !pattern.held.empty()) {
        CV_Assert(pattern.held.type() == CV_32FC1 && pattern.held.size() == size);
        b.pattern = BankRead::SWAP_MOVED;
        b.movedPattern = pattern.held;
    } else if (tied) {
        b.pattern = BankRead::SWAP;
        b.patternInput = si.pattern;
    } else if (b.patternShare[0] > 0 || b.patternShare[1] > 0 || b.patternShare[2] > 0 ||
               b.patternShare[3] > 0) {
        b.pattern = BankRead::ADD_LACKING;
    }
    return b;
}

namespace {

template <typename T>
int64 bankRowExtraOf(const BankRead& b, int r, int first, int step, int n, const float rowFactor[2],
                     const float* pixelFactor, float* extra)
{
    const int R = r + b.origin.y, x0 = b.origin.x, width = b.frame.cols;
    const T* a = b.frame.ptr<T>(R);
    // The sensor row's black level at each column parity.
    const float black[2] = {b.black[cfaSite(R, 0)], b.black[cfaSite(R, 1)]};
    if (b.ignore) {
        for (int j = 0; j < n; ++j) {
            const int C = first + step * j + x0;
            extra[j] = b.drawScale * (static_cast<float>(a[C]) - black[C & 1]);
        }
        return 0;
    }
    const float* mean = b.groupMean.ptr<float>(R);
    // The row part at each sensor column parity: the draw's mean over the sensor's whole row there.
    double sum[2] = {0, 0};
    for (int C = 0; C < width; ++C)
        sum[C & 1] +=
            static_cast<double>(a[C]) - static_cast<double>(black[C & 1]) - static_cast<double>(mean[C]);
    const float k = b.drawScale;
    const float sensorRho[2] = {k * static_cast<float>(sum[0] / ((width + 1) / 2)),
                                width > 1 ? k * static_cast<float>(sum[1] / (width / 2)) : 0.0f};
    float rho[2], rowShare[2], target[2], held[2];
    bool rowExceeded[2];
    for (int p = 0; p < 2; ++p) {
        rho[p] = sensorRho[(p + x0) & 1];
        const int m = 2 * (r & 1) + p;
        const float rowHeld = rowFactor[p] * b.rowHeld[m], rowTarget = b.rowTarget[m];
        rowExceeded[p] = rowHeld > rowTarget;
        rowShare[p] = rowTarget > 0 ? std::sqrt(std::max(0.0f, 1 - rowHeld / rowTarget)) : 0.0f;
        target[p] = b.pixelTarget.byRow.at<float>(r, p);
        held[p] = b.pixelHeld.empty() ? b.pixelHeldBySite[m] : b.pixelHeld.byRow.at<float>(r, p);
    }
    const float* ft = b.pattern == BankRead::NO_PATTERN ? nullptr : b.patternTarget.ptr<float>(R) + x0;
    const float* fs = b.pattern == BankRead::SWAP ? b.patternInput.ptr<float>(R) + x0 : nullptr;
    const float* moved = b.pattern == BankRead::SWAP_MOVED ? b.movedPattern.ptr<float>(r) : nullptr;
    const int even = 2 * (r & 1);
    // The pixel part's share c from k^2 v_s + c^2 v_t = v_t, and whether the input already exceeds the
    // target.
    const auto shareOf = [&](int j, int p, float pixelTargetVariance, float pixelHeldVariance,
                             bool& exceeded) {
        const float h = pixelFactor[j] * pixelHeldVariance, t = pixelTargetVariance;
        exceeded = h > t || rowExceeded[p];
        return t > 0 ? std::sqrt(std::max(0.0f, 1 - h / t)) : 0.0f;
    };
    const auto pixel = [&](int j, float share) {
        const int c = first + step * j, p = c & 1;
        const int C = c + x0;
        const float d = k * (static_cast<float>(a[C]) - black[C & 1] - mean[C]);
        float value = rowShare[p] * rho[p] + share * (d - rho[p]);
        switch (b.pattern) {
        case BankRead::ADD_LACKING:
            value += b.patternShare[even + p] * (ft[c] - b.levelTarget[even + p]);
            break;
        case BankRead::SWAP:
            value += ft[c] - b.patternAmplitude[even + p] * fs[c];
            break;
        case BankRead::SWAP_MOVED:
            value += ft[c] - moved[c];
            break;
        case BankRead::NO_PATTERN:
            break;
        }
        return value;
    };
    int64 exceededCount = 0;
    // A row's pixels share their parity's variances, and mostly the step's factor: its share is reused while
    // the factor stays (the same arithmetic, so the same bits).
    float lastFactor[2] = {-1, -1}, lastShare[2] = {0, 0};
    bool lastExceeded[2] = {false, false};
    for (int j = 0; j < n; ++j) {
        const int p = (first + step * j) & 1;
        if (pixelFactor[j] != lastFactor[p]) {
            lastFactor[p] = pixelFactor[j];
            lastShare[p] = shareOf(j, p, target[p], held[p], lastExceeded[p]);
        }
        extra[j] = pixel(j, lastShare[p]);
        exceededCount += lastExceeded[p];
    }
    // Noisy pixels, of the target's group or (tied) of the input's: their own variances instead of their
    // row's.
    std::vector<int> noisy;
    for (const PixelPartVariance* v : {&b.pixelTarget, &b.pixelHeld})
        if (!v->empty())
            noisy.insert(noisy.end(), v->column.begin() + v->rowStart[static_cast<size_t>(r)],
                         v->column.begin() + v->rowStart[static_cast<size_t>(r) + 1]);
    std::sort(noisy.begin(), noisy.end());
    noisy.erase(std::unique(noisy.begin(), noisy.end()), noisy.end());
    for (int c : noisy) {
        if (c < first || (c - first) % step != 0 || (c - first) / step >= n)
            continue;
        const int j = (c - first) / step;
        bool before, now;
        shareOf(j, c & 1, target[c & 1], held[c & 1], before);
        const float heldVariance = b.pixelHeld.empty() ? held[c & 1] : varianceAt(b.pixelHeld, r, c);
        extra[j] = pixel(j, shareOf(j, c & 1, varianceAt(b.pixelTarget, r, c), heldVariance, now));
        exceededCount += static_cast<int64>(now) - static_cast<int64>(before);
    }
    return exceededCount;
}

} // namespace

int64 bankRowExtra(const BankRead& b, int r, int first, int step, int n, const float rowFactor[2],
                   const float* pixelFactor, float* extra)
{
    return b.frame.depth() == CV_16U
               ? bankRowExtraOf<ushort>(b, r, first, step, n, rowFactor, pixelFactor, extra)
               : bankRowExtraOf<float>(b, r, first, step, n, rowFactor, pixelFactor, extra);
}

} // namespace detail
} // namespace rawgment
} // namespace cv
