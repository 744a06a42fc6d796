// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// A noise step's model prepared once per call (step_noise.hpp), and the dark terms' rows.
#include "step_noise.hpp"

#include "bank_noise.hpp"
#include "dark_frames.hpp"

#include "precomp.hpp"

namespace cv {
namespace rawgment {
namespace detail {

void DarkShading::checkCovers(Size size, const char* who) const
{
    const Size maps = perGain_.size();
    if ((Rect(origin_, size) & Rect(Point(), maps)) != Rect(origin_, size))
        CV_Error(
            Error::StsBadArg,
            format("%s: the model's dark shading is %dx%d but the mosaic %dx%d at sensor origin (%d, %d) "
                   "does not lie inside it; the maps are per pixel of the sensor: give a crop its offset "
                   "(RawFormat::sensorOrigin, or RawFormat::cropped())",
                   who, maps.width, maps.height, size.width, size.height, origin_.x, origin_.y));
}

StepNoise::StepNoise(const ValidatedNoiseModel& valid, const RawFormat& format, const NoiseOptions& options_,
                     double gainRatio, Size size, const char* who, double exposureOut_)
    : options(options_), gainIn(format.gain), gainOut(format.gain * gainRatio),
      exposureIn(format.exposureTime), exposureOut(exposureOut_ > 0 ? exposureOut_ : format.exposureTime)
{
    const NoiseModel& model = valid.model();
    in = valid.termsAt(gainIn);
    out = gainRatio == 1 ? in : valid.termsAt(gainOut);
    measured = model.hasMeasuredLines();
    rowNoise = model.hasRowNoise();
    rowSigmaD2 = model.rowSigmaD2;
    rowSigmaR2 = model.rowSigmaR2;
    tails = model.tukeyRead;
    tukeyLambda = model.tukeyLambda;
    if (addsNoise() && !options.darkBank.empty()) {
        bank = cachedDarkFrameBank(options.darkBank); // load() refuses a bank without groups
        try {
            bankGroupOut = bank->nearestGroup(gainOut, exposureOut);
        } catch (const Exception& e) {
            CV_Error(e.code, cv::format("%s: the output: ", who) + e.err);
        }
        // The input's own read noise at any gain: the nearest group's, scaled by the model's lines; of the
        // input's exposure, since dark current grows with it (#79 item 10).
        try {
            bankGroupIn = nearestGainGroup(bank->groups, gainIn, exposureIn, bank->path);
        } catch (const Exception& e) {
            CV_Error(e.code, cv::format("%s: the input: ", who) + e.err);
        }
        const auto scaleTo = [&](const NoiseTerms<double>& at, int group) {
            const double there = valid.termsAt(bank->groups[static_cast<size_t>(group)].gain).read();
            return there > 0 ? std::sqrt(at.read() / there) : 1.0;
        };
        bankScaleIn = scaleTo(in, bankGroupIn);
        bankScaleOut = scaleTo(out, bankGroupOut);
        for (NoiseTerms<double>* t : {&in, &out})
            t->readBeforeGain = t->readAfterGain = 0;
        rowNoise = false;
        tails = false;
    }
    if (addsNoise() && model.hasDarkShading() && !bank) {
        shading = DarkShading(model.darkShadingPerGain, model.darkShadingOffset, gainIn, format.sensorOrigin);
        shading.checkCovers(size, who);
    }
}

void throwNonFiniteShading(const char* who)
{
    CV_Error(Error::StsBadArg, format("%s: the model's dark shading contains NaN or Inf", who));
}

bool darkRowExtra(const DarkTerms& d, uint64_t rowKey, int r, int cols, float* extra)
{
    const int even = 2 * (r & 1);
    float amp[2] = {0, 0};
    if (d.row) {
        CounterRng rng(rowKey, static_cast<uint64_t>(r));
        const float z = static_cast<float>(rng.gaussian());
        amp[0] = d.rowSigma[even] * z;
        amp[1] = d.rowSigma[even + 1] * z;
    }
    if (d.shading.empty()) {
        for (int c = 0; c < cols; ++c)
            extra[c] = amp[c & 1];
        return true;
    }
    const float *bd = d.shading.perGainRow(r), *br = d.shading.offsetRow(r);
    // A pair of columns (both sites of the row) per iteration, each with its site's coefficients.
    const float g0 = d.shadingPerGain[even], g1 = d.shadingPerGain[even + 1];
    const float o0 = d.shadingOffset[even], o1 = d.shadingOffset[even + 1];
    for (int c = 0; c + 1 < cols; c += 2) {
        extra[c] = amp[0] + g0 * bd[c] + o0 * br[c];
        extra[c + 1] = amp[1] + g1 * bd[c + 1] + o1 * br[c + 1];
    }
    if (cols & 1)
        extra[cols - 1] = amp[0] + g0 * bd[cols - 1] + o0 * br[cols - 1];
    // x - x is 0 for every finite x and NaN for NaN and Inf; the maps are checked, not the products, so
    // a coefficient of 0 cannot hide a bad value.
    float check = 0;
    for (int c = 0; c < cols; ++c)
        check += (bd[c] - bd[c]) + (br[c] - br[c]);
    return check == 0;
}

} // namespace detail
} // namespace rawgment
} // namespace cv
