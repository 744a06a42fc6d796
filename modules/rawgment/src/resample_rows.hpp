// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The rows both resampling steps share (motionBlur() in motion_blur.cpp, scaleMosaic() in resample.cpp):
// the step's constants (paper Eq. 15 with the step's weights), plane rows in and out of the mosaic, and
// the end of every resampled row (its noise, dark terms and black level).
#ifndef OPENCV_RAWGMENT_SRC_RESAMPLE_ROWS_HPP
#define OPENCV_RAWGMENT_SRC_RESAMPLE_ROWS_HPP

#include "augment_steps.hpp"
#include "bank_noise.hpp"
#include "noise_step.hpp"

#include "noise_terms.hpp"
#include <functional>

#include <atomic>

namespace cv {
namespace rawgment {
namespace detail {

/* The grid a resampling step works on. A Bayer mosaic is four half-resolution CFA planes, one per site,
 * each resampled on its own (plane pixel j of site s is mosaic column 2 j + s % 2, plane row i mosaic row
 * 2 i + s / 2). A monochrome frame (CFA_MONO) is one plane, site 0, at full resolution: its neighbours
 * see the same light, so a blur or a scale reads them all. */
struct PlaneGrid
{
    int step;  // mosaic pixels per plane pixel: 2, or 1 for a monochrome frame
    int sites; // planes: 4, or 1
    explicit PlaneGrid(const RawFormat& format)
        : step(format.isMonochrome() ? 1 : 2), sites(format.isMonochrome() ? 1 : 4)
    {
    }
    Size plane(Size mosaic) const { return Size(mosaic.width / step, mosaic.height / step); }
    int mosaicRow(int site, int planeRow) const { return step * planeRow + site / 2; }
};

// Constants of a resampling step (blur or scale) on one mosaic: Eq. 15 with the step's weights.
struct ResampleConstants
{
    PlaneGrid grid{RawFormat()};
    float black[4];
    float white;
    float shot;     // g alpha
    float floorVar; // g^2 sigma_d^2 + sigma_r^2: the read noise a weighted sum removes, (1 - sum w^2) of it
    NoiseAlignment alignment;
    ShotNoiseSampling sampling;
    uint64_t key, poissonKey; // the step's Gaussian and Poisson streams
    // The dark-frame components (resampleDarkTerms()): the rows' variance to restore, the shading to
    // restore (dark.shading, the target's, added after the step), the tails; their streams.
    DarkTerms dark;
    double rowVariance = 0;   // the input's row variance at its gain
    DarkShading inputShading; // ACCOUNT_PRIOR: the input's dark shading, taken out before the step
    uint64_t rowKey = 0, tukeyKey = 0;
    // A dark-frame bank's read part (resampleBankRead()), and the count of pixels whose read part the input
    // already exceeded; null without a bank.
    const BankRead* bank = nullptr;
    std::atomic<int64>* readBrightening = nullptr;
    std::atomic<bool>* nonFiniteShading = nullptr; // set when a shading row held NaN or Inf
    // Set when a float input row held NaN or Inf; null when the step's input is not to be checked.
    std::atomic<bool>* nonFiniteInput = nullptr;
};

// The buffers of a task's rows, sized once per task for plane rows of n pixels (whole blocks where a
// vector kernel reads them): a row allocates nothing.
struct RowScratch
{
    std::vector<float> z, extra, t, factor;
    std::vector<NoiseSplit> splits;
    std::vector<double> means, counts;
    explicit RowScratch(int n)
        : z(wholeBlocks(n)), extra(wholeBlocks(n)), t(static_cast<size_t>(n)), factor(static_cast<size_t>(n)),
          splits(static_cast<size_t>(n)), means(static_cast<size_t>(n)), counts(static_cast<size_t>(n))
    {
    }
};

void siteColumns(const ushort* row, int column, int width, float black, float* out);
void siteColumns(const float* row, int column, int width, float black, float* out);

/* Both sites of a mosaic row (plane rows `even` and `odd`, CFA columns 0 and 1) interleaved into it;
 * 16-bit values rounded half to even, in [0, white]. */
void storeMosaicRow(const float* even, const float* odd, ushort* d, int width);
void storeMosaicRow(const float* even, const float* odd, float* d, int width);

//! A monochrome frame's row (PlaneGrid with step 1): the plane row is the frame's row.
void storeFrameRow(const float* values, ushort* d, int width);
void storeFrameRow(const float* values, float* d, int width);

/* Plane row i of `site`, finished in means[site % 2], into dst: a monochrome frame's row at once, a mosaic
 * row once its second site is (a task makes the sites of plane row i in turn, so it writes mosaic rows 2 i
 * and 2 i + 1 whole). */
template <typename T>
void storePlaneRow(const PlaneGrid& grid, const std::vector<float> (&means)[2], int site, int i, int width,
                   Mat& dst)
{
    if (grid.sites == 1)
        storeFrameRow(means[0].data(), dst.ptr<T>(i), width);
    else if (site % 2 == 1)
        storeMosaicRow(means[0].data(), means[1].data(), dst.ptr<T>(2 * i + site / 2), width);
}

// Plane row `planeRow` of site `site`, black-subtracted (and without the input's dark shading when
// `shading` is not empty), into out[0..pad + width + pad) with the plane's edge replicated `pad` columns
// on each side. Returns false when a float mosaic's values there are not all finite (the step's check of
// its input: every step loads each site of each row it reads).
template <typename T>
bool loadPlaneRow(const Mat& src, const PlaneGrid& grid, int site, int planeRow, int pad, float black,
                  float* out, const DarkShading& shading, bool checkValues)
{
    const int width = src.cols / grid.step;
    const int r = grid.mosaicRow(site, planeRow);
    if (grid.step == 2) {
        siteColumns(src.ptr<T>(r), site % 2, width, black, out + pad);
    } else {
        const T* in = src.ptr<T>(r);
        for (int j = 0; j < width; ++j)
            out[pad + j] = static_cast<float>(in[j]) - black;
    }
    // The black level is finite, so the values less it are finite exactly where the values are.
    const bool finite = !checkValues || !std::is_same<T, float>::value || rowIsFinite(out + pad, width);
    if (!shading.empty()) {
        const float *bd = shading.perGainRow(r) + site % 2, *br = shading.offsetRow(r) + site % 2;
        for (int j = 0; j < width; ++j)
            out[pad + j] -= shading.at(bd, br, grid.step * j);
    }
    for (int j = 0; j < pad; ++j) {
        out[j] = out[pad];
        out[pad + width + j] = out[pad + width - 1];
    }
    return finite;
}

// The end of every resampled row: its noise streams (site, row), the noise, the dark terms, the black
// level, in `mean`; storeMosaicRow() stores it with the row's other site (storeFrameRow() alone).
void finishPlaneRow(std::vector<float>& mean, const float* shotSum, const float* readFactor,
                    RowScratch& scratch, const ResampleConstants& k, int n, int site, int planeRow,
                    float rowKeep = 1);

ResampleConstants resampleConstants(int depth, const RawFormat& format, const StepNoise& step, uint64 seed,
                                    RandomStream gaussian, RandomStream poisson);

/* The dark-frame components a resampling step adds (docs/mathematics.md, "Dark-frame noise"). The step
 * keeps the gain, so the target has the input's components in full. A weighted sum keeps sum W^2 of the
 * input's row variance (W the weights per source row: resampledDarkRow()). ACCOUNT_PRIOR takes the
 * input's dark shading S out of the values before the step (so that it is neither resampled nor taken
 * for signal by the shot-noise estimate of Eq. 15) and adds S after it; IGNORE_PRIOR adds S on top.
 * The read part keeps sum w^2 of its variance and sum w^4 of its fourth cumulant: the added part's
 * lambda is addedReadLambda() with the step's typical weights (sumW2, sumW4; per pixel they vary near
 * edges and, for scaling, along the row: the variance stays exact per pixel, the kurtosis is matched
 * on average). */
void resampleDarkTerms(ResampleConstants& k, const StepNoise& step, double sumW2, double sumW4, uint64 seed,
                       RandomStream rowStream, RandomStream tukeyStream);

/* A resampling step's read part from a dark-frame bank (bank_noise.hpp), for a step whose typical sum of w^2
 * is sumW2: it keeps that share of the input's pixel part (each pixel's own, 1 - its read factor) and rowKeep
 * of its row part; an untied bank's input pattern spreads as sqrt(sumW2) of its own, a tied bank's is the
 * step's own output of it without noise (`withoutNoise`, on a float mosaic of `format` with another black
 * level). */
BankRead resampleBankRead(const StepNoise& step, const RawFormat& format, Size size, double sumW2,
                          uint64 seed, RandomStream stream, const char* who,
                          const std::function<void(const Mat&, const RawFormat&, Mat&)>& withoutNoise);

/** What a resampling step (scale, blur) prepares alike: its input's format, the seed, the model and the
 * depth, the shape it needs (whole 2x2 blocks) and the model's terms at the input's gain, which it keeps. */
class ResampleStep : public NoiseStep
{
protected:
    void prepareResampling(const StepContext& context, const char* who)
    {
        format_ = context.format;
        seed_ = context.seed;
        model_ = &context.model;
        depth_ = context.depth;
        checkResampleShape(context.size, who);
        step_.reset(new StepNoise(context.model, format_, context.noise, 1, context.size, who));
    }

    RawFormat format_;
    uint64 seed_ = 0;
    const ValidatedNoiseModel* model_ = nullptr;
    int depth_ = CV_16U;
    std::unique_ptr<StepNoise> step_;
};

} // namespace detail
} // namespace rawgment
} // namespace cv

#endif
