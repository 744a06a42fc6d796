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

With --study N (and the build's Python module on PYTHONPATH) it also measures a known sensor the way
darktable's tool does, N times, and imports each result with rawgment.readCameraProfiles: the check of
the whole chain that python/tests/test_camera_profiles.py runs twice. Result of --study 8 (seeds 1-8),
imported over truth, mean +- standard error:

    alpha 1.0005 +- 0.0013   sigma_d^2 1.245 +- 0.067   sigma_r^2 1.178 +- 0.031
"""
import argparse
import json
import os
import tempfile

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


def darktable_profile(mosaic):
    """What darktable's profiling tool reports for one RGGB frame normalised to [0, 1]: the variance of the
    green Haar HH coefficients (MAD, 300 brightness bins of LL) fitted as a x + b on [0, 0.8], each bin
    weighted by its count squared (gnuplot's fit with an error of 1 / count)."""
    green = ppg_green(np.maximum(mosaic, 0))  # darktable's PFM reader clamps below zero
    hh = np.abs(haar_hh(green)).ravel()
    bins = np.clip((haar_ll(green) * 300).astype(int), 0, 299).ravel()
    order = np.argsort(bins, kind="stable")
    bins, hh = bins[order], hh[order]
    edges = np.searchsorted(bins, np.arange(301))
    x, y, w = [], [], []
    for b in range(240):  # brightness < 0.8
        seg = hh[edges[b]:edges[b + 1]]
        if len(seg):
            x.append(b / 300)
            y.append((np.median(seg) / 0.6745) ** 2)
            w.append(len(seg))
    x, y, w = np.array(x), np.array(y), np.array(w, float)
    design = np.stack([x, np.ones_like(x)], 1) * w[:, None]
    a, b = np.linalg.lstsq(design, y * w, rcond=None)[0]
    return a, b


#: The study's sensor: 20,000 e- full well, 5 e- of read noise before the gain and 20 e- after, over a
#: range of 1 (alpha, sigma_d^2, sigma_r^2).
STUDY_SENSOR = (1 / 20000.0, (5 / 20000.0) ** 2, (20 / 20000.0) ** 2)


def measured_sensor_profiles(seed, sensor=STUDY_SENSOR, isos=(100, 200, 400, 800, 1600)):
    """A darktable noise-profile document of the sensor measured as darktable measures: Gaussian noise of the
    model's variance on a ramp from black to 0.8 of white, one 1024 x 1024 frame per ISO."""
    alpha, sd, sr = sensor
    rng = np.random.default_rng(seed)
    ramp = np.tile(np.linspace(0.0, 0.8, 1024), (1024, 1))
    profiles = []
    for iso in isos:
        g = iso / isos[0]
        noisy = ramp + rng.standard_normal(ramp.shape) * np.sqrt(g * alpha * ramp + g * g * sd + sr)
        a, b = darktable_profile(noisy)
        profiles.append({"name": "sim iso %d" % iso, "iso": iso, "a": [a] * 3, "b": [b] * 3})
    return {"version": 0, "noiseprofiles": [{"maker": "Sim", "models": [{"model": "Sensor", "profiles": profiles}]}]}


def study(campaigns):
    import rawgment

    ratios = []
    with tempfile.TemporaryDirectory() as folder:
        for seed in range(1, campaigns + 1):
            path = os.path.join(folder, "sim%d.json" % seed)
            with open(path, "w") as f:
                json.dump(measured_sensor_profiles(seed), f)
            camera = rawgment.readCameraProfiles(path)[0]
            ratios.append((camera.noise.alpha / STUDY_SENSOR[0], camera.noise.sigmaD2 / STUDY_SENSOR[1],
                           camera.noise.sigmaR2 / STUDY_SENSOR[2]))
    ratios = np.array(ratios)
    mean, se = ratios.mean(0), ratios.std(0, ddof=1) / np.sqrt(len(ratios))
    print("imported over truth: alpha %.4f +- %.4f   sigma_d^2 %.3f +- %.3f   sigma_r^2 %.3f +- %.3f" %
          (mean[0], se[0], mean[1], se[1], mean[2], se[2]))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0], allow_abbrev=False)
    parser.add_argument("--study", type=int, default=0, help="campaigns of the import check (0: none)")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    for name, demosaic in [("no demosaicing", lambda m: m), ("darktable PPG green", ppg_green)]:
        ratios = [haar_mad_variance(demosaic(rng.standard_normal((SIZE, SIZE)))) for _ in range(16)]
        print(f"{name + ':':21s} c = {np.mean(ratios):.4f} +- {np.std(ratios) / np.sqrt(len(ratios)):.4f}")
    if args.study:
        study(args.study)


if __name__ == "__main__":
    main()
