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

With --demosaics FRAMES it also measures c per colour for darktable's PPG and RCD demosaics
(python/tools/darktable_demosaic.py) on flat fields of shot noise at colour balances (green's level over
red's and blue's) 1 to 3, and the line the red or blue over green slope ratio follows in the balance:
PPG 0.284 + 0.946 k, RCD 0.592 + 0.962 k with FRAMES = 4; on grey, c of green is 0.0798 (PPG) and 0.0474
(RCD), of red and blue 0.098 and 0.073. docs/real_cameras.md ("Which demosaic") shows the whole output.

With --study N (and the build's Python module on PYTHONPATH) it also measures a known sensor the way
darktable's tool does, N times, and imports each result with rawgment.readCameraProfiles: the check of
the whole chain that python/tests/test_camera_profiles.py runs twice. Result of --study 8 (seeds 1-8),
imported over truth, mean +- standard error:

    alpha 1.0005 +- 0.0013   sigma_d^2 1.245 +- 0.067   sigma_r^2 1.178 +- 0.031
"""
import argparse
import json
import os
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from darktable_demosaic import BORDER, ppg, ppg_green, rcd  # noqa: E402

SIZE = 1024


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


#: darktable's demosaics for Bayer sensors: PPG, the default until 3.4, and RCD, the default from 3.6 (2021).
DEMOSAICS = {"PPG": ppg, "RCD": rcd}
#: Green over red (and over blue) raw level of the flat fields the colour study runs: 1 is grey; an
#: un-white-balanced raw of a grey scene has green brightest, about 2 for red and 1.5 for blue in daylight.
BALANCES = (1.0, 1.5, 2.0, 2.5, 3.0)


def flat_field_ratios(demosaic, balance, rng, size=512, level=0.3, slope=1e-5):
    """c of each colour (the Haar-MAD variance of the demosaiced colour over the per-pixel shot variance of that
    colour's raw sites) on a flat RGGB field with green at `level` and red and blue at level / balance, shot
    noise of variance slope x at each site. The noise is small against the level, as in a profile's bright
    bins, so the demosaic's clamps and ratios act as they do there."""
    rows, cols = np.mgrid[0:size, 0:size]
    red = (rows % 2 == 0) & (cols % 2 == 0)
    blue = (rows % 2 == 1) & (cols % 2 == 1)
    levels = np.where(red | blue, level / balance, level)
    mosaic = levels + np.sqrt(slope * levels) * rng.standard_normal((size, size))
    out = demosaic(mosaic)[BORDER:-BORDER, BORDER:-BORDER]
    own = (level / balance, level, level / balance)
    return np.array([haar_mad_variance(out[..., k]) / (slope * own[k]) for k in range(3)])


def demosaic_study(frames=4, seed=1):
    """c per demosaic and colour on grey, and the line the red or blue over green slope ratio follows in the
    colour balance: ratio = intercept + slope * balance, least squares over BALANCES (red and blue pooled,
    the two are symmetric)."""
    rng = np.random.default_rng(seed)
    result = {}
    for name, demosaic in DEMOSAICS.items():
        per_balance = {k: np.mean([flat_field_ratios(demosaic, k, rng) for _ in range(frames)], 0) for k in BALANCES}
        grey = per_balance[1.0]
        ks = np.array([k for k in BALANCES for _ in range(2)])
        ratios = np.array([per_balance[k][j] / per_balance[k][1] for k in BALANCES for j in (0, 2)])
        slope, intercept = np.polyfit(ks, ratios, 1)
        result[name] = {"c": grey, "ratio_line": (intercept, slope),
                        "ratios": {k: (v[0] / v[1], v[2] / v[1]) for k, v in per_balance.items()}}
    return result


def print_demosaic_study(frames):
    for name, r in demosaic_study(frames).items():
        print("%s on grey:  c red %.4f  green %.4f  blue %.4f" % ((name,) + tuple(r["c"])))
        for k, (red, blue) in r["ratios"].items():
            print("    green/red = green/blue = %.1f: slope ratio red/green %.3f  blue/green %.3f" % (k, red, blue))
        print("    ratio = %.3f + %.3f * balance" % r["ratio_line"])


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
    parser.add_argument("--demosaics", type=int, default=0, metavar="FRAMES",
                        help="c of PPG and RCD per colour and the slope ratios' line, FRAMES per balance (0: none)")
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    for name, demosaic in [("no demosaicing", lambda m: m), ("darktable PPG green", ppg_green)]:
        ratios = [haar_mad_variance(demosaic(rng.standard_normal((SIZE, SIZE)))) for _ in range(16)]
        print(f"{name + ':':21s} c = {np.mean(ratios):.4f} +- {np.std(ratios) / np.sqrt(len(ratios)):.4f}")
    if args.demosaics:
        print_demosaic_study(args.demosaics)
    if args.study:
        study(args.study)


if __name__ == "__main__":
    main()
