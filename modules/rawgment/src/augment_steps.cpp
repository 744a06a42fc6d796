// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Noise options and the checks that every noise step of the augment topic shares.
#include "augment_steps.hpp"
#include "cpu_dispatch.hpp"

#include <atomic>
#include <cstdint>
#include <cstring>

namespace cv {
namespace rawgment {
namespace detail {

namespace {

RAWGMENT_KERNEL bool rowIsFiniteKernel(const float* p, int n)
{
    uint32_t nonFinite = 0;
    for (int i = 0; i < n; ++i) {
        uint32_t bits;
        std::memcpy(&bits, p + i, sizeof(bits));
        nonFinite |= static_cast<uint32_t>((bits & 0x7f800000u) == 0x7f800000u); // exponent all ones
    }
    return nonFinite == 0;
}

} // namespace

RAWGMENT_DISPATCHED(bool, rowIsFinite, (const float* p, int n), (p, n))

void checkMosaicType(const Mat& src, const char* who)
{
    if (src.empty())
        CV_Error(Error::StsBadArg, format("%s: src is empty", who));
    if (src.type() != CV_16UC1 && src.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, format("%s: src type %s is not supported; expected CV_16UC1 or CV_32FC1",
                                          who, typeToString(src.type()).c_str()));
}

void checkMosaicInput(const Mat& src, const char* who)
{
    checkMosaicType(src, who);
    if (src.type() != CV_32FC1)
        return;
    std::atomic<bool> nonFinite{false};
    parallel_for_(Range(0, src.rows), [&](const Range& rows) {
        for (int r = rows.start; r < rows.end; ++r)
            if (!rowIsFinite(src.ptr<float>(r), src.cols))
                nonFinite = true;
    });
    if (nonFinite)
        throwNonFiniteInput(who);
}

void throwNonFiniteInput(const char* who)
{
    CV_Error(Error::StsBadArg, format("%s: src contains NaN or Inf", who));
}

void checkResampleShape(Size size, const char* who)
{
    if (size.height % 2 || size.width % 2)
        CV_Error(Error::StsBadArg,
                 cv::format("%s: both sides must be even (got %dx%d)", who, size.width, size.height));
}

void recordStep(AugmentReport* report, const char* name, std::chrono::steady_clock::time_point start)
{
    if (!report)
        return;
    report->steps.push_back(name);
    report->stepSeconds.push_back(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

void reportSaturation(const Mat& src, const RawFormat& format, AugmentReport* report, OutputArray mask)
{
    if (!report && !mask.needed())
        return;
    Mat saturated;
    compare(src, format.whiteLevel, saturated, CMP_GE);
    if (report)
        report->saturatedPixels += countNonZero(saturated);
    if (mask.needed())
        mask.assign(saturated);
}

Mat stepOutput(const Mat& src, OutputArray dst)
{
    if (dst.kind() == _InputArray::MAT) {
        Mat m = dst.getMat();
        const bool overlaps = m.datastart < src.dataend && src.datastart < m.dataend;
        if (!m.empty() && m.size() == src.size() && m.type() == src.type() && !overlaps)
            return m;
    }
    Mat out(src.size(), src.type());
    adviseHugePages(out);
    return out;
}

bool isIdentityKernel(const Mat& kernel)
{
    return kernel.empty() || kernel.total() == 1;
}

} // namespace detail

void NoiseOptions::validate() const
{
    if (alignment != NoiseAlignment::NONE && alignment != NoiseAlignment::IGNORE_PRIOR &&
        alignment != NoiseAlignment::ACCOUNT_PRIOR)
        CV_Error(Error::StsBadArg, format("NoiseOptions: unknown alignment %d", static_cast<int>(alignment)));
    if (shotSampling != ShotNoiseSampling::GAUSSIAN && shotSampling != ShotNoiseSampling::POISSON)
        CV_Error(Error::StsBadArg,
                 format("NoiseOptions: unknown shotSampling %d", static_cast<int>(shotSampling)));
    if (priorMean != PriorMeanEstimate::PIXEL_VALUE && priorMean != PriorMeanEstimate::LOCAL_MEAN)
        CV_Error(Error::StsBadArg, format("NoiseOptions: unknown priorMean %d", static_cast<int>(priorMean)));
    if (blurNoiseSum != BlurNoiseSum::EXACT && blurNoiseSum != BlurNoiseSum::FROM_BLURRED_MEAN)
        CV_Error(Error::StsBadArg,
                 format("NoiseOptions: unknown blurNoiseSum %d", static_cast<int>(blurNoiseSum)));
}

void NoiseOptions::writeFields(FileStorage& fs) const
{
    fs << "alignment" << static_cast<int>(alignment) << "shot_sampling" << static_cast<int>(shotSampling)
       << "prior_mean" << static_cast<int>(priorMean) << "blur_noise_sum" << static_cast<int>(blurNoiseSum);
    if (!darkBank.empty()) {
        writeString(fs, "dark_bank", darkBank);
        fs << "dark_bank_tied" << static_cast<int>(darkBankTied);
    }
}

NoiseOptions NoiseOptions::readFields(const FileNode& map)
{
    NoiseOptions o;
    const auto field = [&](const char* name, int current) {
        try {
            return detail::readOptionalIntField(map, name, current);
        } catch (const Exception& e) {
            CV_Error(e.code, "noise options: " + e.err);
        }
    };
    o.alignment = static_cast<NoiseAlignment>(field("alignment", static_cast<int>(o.alignment)));
    o.shotSampling = static_cast<ShotNoiseSampling>(field("shot_sampling", static_cast<int>(o.shotSampling)));
    o.priorMean = static_cast<PriorMeanEstimate>(field("prior_mean", static_cast<int>(o.priorMean)));
    o.blurNoiseSum = static_cast<BlurNoiseSum>(field("blur_noise_sum", static_cast<int>(o.blurNoiseSum)));
    const FileNode bank = map["dark_bank"];
    if (!bank.empty()) {
        if (!bank.isString() || bank.string().empty())
            CV_Error(Error::StsParseError,
                     "noise options: 'dark_bank' must be the path of a dark-frame bank file");
        o.darkBank = bank.string();
    }
    try {
        o.darkBankTied = detail::readOptionalFlagField(map, "dark_bank_tied", false);
    } catch (const Exception& e) {
        CV_Error(e.code, "noise options: " + e.err);
    }
    o.validate();
    return o;
}

} // namespace rawgment
} // namespace cv
