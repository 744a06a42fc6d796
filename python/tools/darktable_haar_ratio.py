#!/usr/bin/python3
"""The ratio c of darktable's measured noise variance to the per-pixel raw variance (green channel).

darktable's profiling tool (tools/noise in darktable's source: darktable-gen-noiseprofile,
noiseprofile.c, profiling-shot.xmp) exports the raw file demosaiced, without white balance, and
measures each colour's noise as the MAD-based variance of the one-level Haar HH coefficient
(p00 - p01 - p10 + p11) / 4. For independent pixel noise of variance v that is v / 4; demosaicing
interpolates half the green sites from their neighbours, which correlates the block and lowers it.
This script measures c on white Gaussian noise for no demosaicing and for the green interpolation of
darktable's PPG demosaic (direction by gradient, Hamilton-Adams guess clamped to the two neighbours),
written here from the algorithm's description. Result (seed 1, 16 frames of 1024 x 1024):

    no demosaicing:       c = 0.2500 +- 0.0003
    darktable PPG green:  c = 0.0794 +- 0.0001

cv::rawgment's DARKTABLE_HAAR_VARIANCE_RATIO is the second.
Run: /usr/bin/python3 python/tools/darktable_haar_ratio.py
"""
import numpy as np

SIZE = 1024


def ppg_green(mosaic):
    """Green of an RGGB mosaic: kept at green sites, interpolated at red and blue sites."""
    rows_, cols_ = mosaic.shape
    pad = np.pad(mosaic, 3, mode="reflect")

    def at(dy, dx):
        return pad[3 + dy:3 + dy + rows_, 3 + dx:3 + dx + cols_]

    c = at(0, 0)
    xm, xp, xm2, xp2, xm3, xp3 = at(0, -1), at(0, 1), at(0, -2), at(0, 2), at(0, -3), at(0, 3)
    ym, yp, ym2, yp2, ym3, yp3 = at(-1, 0), at(1, 0), at(-2, 0), at(2, 0), at(-3, 0), at(3, 0)
    grad_x = (abs(xm2 - c) + abs(xp2 - c) + abs(xm - xp)) * 3 + (abs(xp3 - xp) + abs(xm3 - xm)) * 2
    grad_y = (abs(ym2 - c) + abs(yp2 - c) + abs(ym - yp)) * 3 + (abs(yp3 - yp) + abs(ym3 - ym)) * 2
    guess_x = np.clip(((xm + c + xp) * 2 - xp2 - xm2) / 4, np.minimum(xm, xp), np.maximum(xm, xp))
    guess_y = np.clip(((ym + c + yp) * 2 - yp2 - ym2) / 4, np.minimum(ym, yp), np.maximum(ym, yp))
    interpolated = np.where(grad_x > grad_y, guess_y, guess_x)
    rows, cols = np.mgrid[0:rows_, 0:cols_]
    green = mosaic.copy()
    red_or_blue = (rows + cols) % 2 == 0
    green[red_or_blue] = interpolated[red_or_blue]
    return green


def haar_hh(channel):
    """The one-level Haar HH coefficient of each 2 x 2 block, as darktable's lifting scheme gives it."""
    return (channel[0::2, 0::2] - channel[0::2, 1::2] - channel[1::2, 0::2] + channel[1::2, 1::2]) / 4


def haar_ll(channel):
    """The block's mean, by which darktable bins the HH coefficients."""
    return (channel[0::2, 0::2] + channel[0::2, 1::2] + channel[1::2, 0::2] + channel[1::2, 1::2]) / 4


def haar_mad_variance(channel):
    return (np.median(np.abs(haar_hh(channel))) / 0.6745) ** 2


def main():
    rng = np.random.default_rng(1)
    for name, demosaic in [("no demosaicing", lambda m: m), ("darktable PPG green", ppg_green)]:
        ratios = [haar_mad_variance(demosaic(rng.standard_normal((SIZE, SIZE)))) for _ in range(16)]
        print(f"{name + ':':21s} c = {np.mean(ratios):.4f} +- {np.std(ratios) / np.sqrt(len(ratios)):.4f}")


if __name__ == "__main__":
    main()
