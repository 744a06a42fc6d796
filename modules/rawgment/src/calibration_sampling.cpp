// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// Noise samples from bursts and single frames: CFA-aligned squares, per-pixel and per-square samples.
#include "opencv2/rawgment/calibration.hpp"
#include "precomp.hpp"

#include <algorithm>

namespace cv {
namespace rawgment {

std::vector<Rect> cfaAlignedSquares(const std::vector<Rect>& patches, int side)
{
    if (side < 2 || side % 2)
        CV_Error(Error::StsBadArg, format("cfaAlignedSquares: side must be even and >= 2 (got %d)", side));
    std::vector<Rect> out;
    for (size_t i = 0; i < patches.size(); ++i) {
        const Rect& p = patches[i];
        // The largest even corner that keeps the square inside the patch, nearest to centred.
        int x = p.x + (p.width - side) / 2, y = p.y + (p.height - side) / 2;
        x += x & 1;
        y += y & 1;
        if (x + side > p.x + p.width)
            x -= 2;
        if (y + side > p.y + p.height)
            y -= 2;
        if (p.width < side || p.height < side || x < p.x || y < p.y)
            CV_Error(Error::StsBadArg,
                     format("cfaAlignedSquares: patch %d (%dx%d at %d,%d) cannot hold a CFA-aligned "
                            "%dx%d square",
                            static_cast<int>(i), p.width, p.height, p.x, p.y, side, side));
        out.emplace_back(x, y, side, side);
    }
    return out;
}

namespace {

void checkSquares(const std::vector<Rect>& squares, Size size, const char* who)
{
    const Rect frame(Point(0, 0), size);
    for (size_t i = 0; i < squares.size(); ++i)
        if ((squares[i] & frame) != squares[i] || squares[i].area() == 0)
            CV_Error(Error::StsBadArg,
                     format("%s: square %d (%dx%d at %d,%d) is empty or outside the %dx%d frame", who,
                            static_cast<int>(i), squares[i].width, squares[i].height, squares[i].x,
                            squares[i].y, size.width, size.height));
}

//! The temporal sample of pixel (r, c) of a burst.
NoiseSample temporalSample(const BurstStatistics& stats, const Mat& mean, const Mat& var, int r, int c,
                           double gain)
{
    NoiseSample s;
    s.mean = mean.at<double>(r, c);
    s.variance = var.at<double>(r, c);
    s.gain = gain;
    s.dof = stats.frames() - 1;
    s.channel = cfaChannelAt(stats.format().pattern, r, c);
    s.pixel = static_cast<int64>(r) * mean.cols + c;
    return s;
}

} // namespace

std::vector<NoiseSample> sampleDarkBurst(const BurstStatistics& stats, const std::vector<Rect>& squares,
                                         double gain)
{
    std::vector<NoiseSample> samples = sampleBurstPatches(stats, squares, gain);
    for (NoiseSample& sample : samples)
        sample.mean = 0;
    return samples;
}

std::vector<NoiseSample> sampleBurstPatches(const BurstStatistics& stats, const std::vector<Rect>& squares,
                                            double gain)
{
    detail::checkFinitePositive(gain, "sampleBurstPatches: gain");
    Mat mean, var, clipped;
    stats.mean(mean);
    stats.variance(var);
    stats.clippedMask(clipped);
    checkSquares(squares, stats.size(), "sampleBurstPatches");
    std::vector<NoiseSample> out;
    for (const Rect& sq : squares) {
        /* A patch near white keeps only the pixels that never clipped, whose variance is cut short: one
         * clipped pixel drops its whole CFA plane in this square, which leaves out every plane within
         * about 3.5 standard deviations of white (16 frames of a 24x24 square draw 2304 values). */
        bool planeClipped[2][2] = {{false, false}, {false, false}};
        for (int r = sq.y; r < sq.y + sq.height; ++r)
            for (int c = sq.x; c < sq.x + sq.width; ++c)
                planeClipped[r & 1][c & 1] = planeClipped[r & 1][c & 1] || clipped.at<uchar>(r, c) != 0;
        for (int r = sq.y; r < sq.y + sq.height; ++r)
            for (int c = sq.x; c < sq.x + sq.width; ++c)
                if (!planeClipped[r & 1][c & 1])
                    out.push_back(temporalSample(stats, mean, var, r, c, gain));
    }
    return out;
}

std::vector<NoiseSample> sampleStaticScene(const BurstStatistics& stats, double gain, int maxSamples)
{
    detail::checkFinitePositive(gain, "sampleStaticScene: gain");
    if (maxSamples < 4)
        CV_Error(Error::StsBadArg, format("sampleStaticScene: maxSamples %d must be >= 4", maxSamples));
    if (stats.frames() < 2)
        CV_Error(Error::StsBadArg, "sampleStaticScene: the burst needs at least 2 frames");
    Mat mean, var, clipped;
    stats.mean(mean);
    stats.variance(var);
    stats.clippedMask(clipped);
    const int border = 4, rows = mean.rows, cols = mean.cols;
    const int blockRows = (rows - 2 * border) / 2, blockCols = (cols - 2 * border) / 2;
    if (blockRows < 1 || blockCols < 1)
        return {};
    // The smallest step whose grid of blocks (4 pixels each) fits maxSamples.
    int step = 1;
    while (double((blockRows + step - 1) / step) * double((blockCols + step - 1) / step) * 4 > maxSamples)
        ++step;
    const double frames = stats.frames();
    std::vector<NoiseSample> out;
    for (int by = 0; by < blockRows; by += step)
        for (int bx = 0; bx < blockCols; bx += step)
            for (int site = 0; site < 4; ++site) {
                const int r = border + 2 * by + site / 2, c = border + 2 * bx + site % 2;
                if (clipped.at<uchar>(r, c))
                    continue;
                const double mp = mean.at<double>(r, c);
                // The noise of the means from the median variance of the eight neighbours, never the
                // pixel's own: a tolerance that grew with its own variance let noisier pixels pass more
                // often, a selection on the very quantity the fit measures (alpha +0.4%, 5 standard errors,
                // on natural scenes). The pixel's own mean, of Gaussian noise, is independent of its own
                // variance. The median, because shake inflates the variance of the very pixels whose
                // means it smears (at most three along an edge); unlike the least variance, it stays near
                // the truth for bursts of a few frames.
                double v[8];
                int n = 0;
                bool flat = !clipped.at<uchar>(r, c);
                for (int dy = -2; dy <= 2; dy += 2)
                    for (int dx = -2; dx <= 2; dx += 2) {
                        if (dy == 0 && dx == 0)
                            continue;
                        flat = flat && !clipped.at<uchar>(r + dy, c + dx);
                        v[n++] = var.at<double>(r + dy, c + dx);
                    }
                std::nth_element(v, v + 4, v + 8);
                const double upper = v[4], lower = *std::max_element(v, v + 4);
                const double vmed = 0.5 * (lower + upper);
                const double tolerance = 4 * std::sqrt(2 * vmed / frames) + 0.002 * std::abs(mp);
                for (int dy = -2; dy <= 2 && flat; dy += 2)
                    for (int dx = -2; dx <= 2 && flat; dx += 2)
                        flat = std::abs(mean.at<double>(r + dy, c + dx) - mp) <= tolerance;
                if (!flat)
                    continue;
                out.push_back(temporalSample(stats, mean, var, r, c, gain));
            }
    return out;
}

std::vector<NoiseSample> sampleSingleFramePatches(InputArray _raw, const RawFormat& format,
                                                  const std::vector<Rect>& squares, double gain)
{
    detail::checkFinitePositive(gain, "sampleSingleFramePatches: gain");
    format.validate();
    const Mat raw = detail::twoDimensional(_raw, "sampleSingleFramePatches: raw");
    if (raw.type() != CV_16UC1 && raw.type() != CV_32FC1)
        CV_Error(Error::StsBadArg, "sampleSingleFramePatches: raw must be CV_16UC1 or CV_32FC1");
    checkSquares(squares, raw.size(), "sampleSingleFramePatches");
    Mat raw64;
    raw.convertTo(raw64, CV_64F);
    if (!checkRange(raw64, true))
        CV_Error(Error::StsBadArg, "sampleSingleFramePatches: raw contains NaN or Inf");
    std::vector<NoiseSample> out;
    for (const Rect& sq : squares) {
        for (int site = 0; site < 4; ++site) {
            // Least squares of v = p0 + p1 x + p2 y over the site's pixels: 3x3 normal equations.
            Matx33d A = Matx33d::zeros();
            Vec3d rhs(0, 0, 0);
            std::vector<Vec3d> points;
            bool isClipped = false;
            for (int r = sq.y + (site / 2 + sq.y) % 2; r < sq.y + sq.height; r += 2)
                for (int c = sq.x + (site % 2 + sq.x) % 2; c < sq.x + sq.width; c += 2) {
                    const double v = raw64.at<double>(r, c);
                    isClipped = isClipped || v <= 0 || v >= format.whiteLevel;
                    const Vec3d f(1.0, c - sq.x, r - sq.y);
                    points.emplace_back(f[1], f[2], v - format.blackAt(r, c));
                    A += f * f.t();
                    rhs += f * (v - format.blackAt(r, c));
                }
            const int n = static_cast<int>(points.size());
            if (isClipped || n < 4)
                continue;
            Vec3d p;
            if (!solve(A, rhs, p, DECOMP_SVD))
                continue;
            double ss = 0, mean = 0;
            for (const Vec3d& q : points) {
                const double fit = p[0] + p[1] * q[0] + p[2] * q[1];
                ss += (q[2] - fit) * (q[2] - fit);
                mean += fit;
            }
            NoiseSample s;
            s.mean = mean / n;
            s.variance = ss / (n - 3);
            s.gain = gain;
            s.dof = n - 3;
            s.channel = cfaChannelAt(format.pattern, sq.y + site / 2, sq.x + site % 2);
            out.push_back(s);
        }
    }
    return out;
}

} // namespace rawgment
} // namespace cv
