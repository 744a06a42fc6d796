"""The EMVA 1288 case below the standard's 0.49 DN floor, stated in docs/emva1288.md.

An 8-bit sensor of the project's simulator (K 0.05, 0.1 DN^2 of read noise before rounding, DSNU 0.5 DN, PRNU
1%, hot pixels; 640x480, 12 steps of two frames, 8 seeds) through calibrateEmva1288 and the standard's
estimator. Truth: the variance of the rounded dark values the frames hold, computed exactly per pixel from the
simulator's own offsets (its fixed pattern) and averaged over 20,000 pixels.

Run from a build: PYTHONPATH=build/release/python /usr/bin/python3 python/tools/emva1288_below_floor.py
"""
from math import erf, sqrt

import numpy as np

import rawgment as rg

READ, K, SIZE, STEPS = 0.1, 0.05, (640, 480), 12


def rounded_variance(offsets, sigma):
    """The variance of round(u + N(0, sigma^2)) for each offset u."""
    cdf = np.vectorize(lambda x: 0.5 * (1 + erf(x / (sigma * sqrt(2)))))
    values = np.floor(offsets)[:, None] + np.arange(-4, 5)[None, :]
    p = cdf(values + 0.5 - offsets[:, None]) - cdf(values - 0.5 - offsets[:, None])
    mean = (p * values).sum(1)
    return (p * values ** 2).sum(1) - mean ** 2


def main():
    params = rg.SensorParams()
    params.noise = rg.NoiseModel(alpha=K, sigmaD2=0, sigmaR2=READ)
    params.bitDepth, params.blackLevel = 8, (8, 8, 8, 8)
    params.prnu, params.dsnu, params.hotPixelFraction = 0.01, 0.5, 1e-4
    sim = rg.SensorSimulator(params, SIZE)
    _, offsets, defects = sim.fixedPattern()
    u = (8 + offsets[defects == 0]).ravel()
    pick = np.random.default_rng(0).choice(u.size, 20000, replace=False)
    truth = rounded_variance(u[pick], sqrt(READ)).mean()
    light = np.full(SIZE[::-1], 1.15 * (255 - 8) / STEPS, np.float32)
    dark = np.zeros(SIZE[::-1], np.float32)
    slopes, model, standard = [], [], []
    for seed in range(1, 9):
        pairs = []
        for k in range(STEPS):
            b = sim.captureBurst(light, 1.0, k + 1, 2, seed * 1000 + 2 * k)
            d = sim.captureBurst(dark, 1.0, k + 1, 2, seed * 1000 + 2 * k + 1)
            pairs.append(rg.measureEmva1288Pair(b[0], b[1], k + 1, 1000.0 * (k + 1), False))
            pairs.append(rg.measureEmva1288Pair(d[0], d[1], k + 1, 0, True))
        results = rg.emva1288Results(pairs)
        report = rg.calibrateEmva1288([results], [1.0])
        slopes.append(report.model.alpha)
        model.append(sqrt(report.model.sigmaR2))
        standard.append(results.sigmaYDark)
    rule = READ + 1 / 12
    print("the frames hold %.4f DN^2 of dark variance (sigma %.4f DN); the 1/12 rule says %.4f (sigma %.4f)"
          % (truth, sqrt(truth), rule, sqrt(rule)))
    print("model: K %+.2f%%, sigma_y.dark %.4f DN (%+.2f%% of the frames', %+.2f%% of the rule); "
          "the standard's sigma_y.dark %.4f DN (its floor is 0.49)"
          % (100 * (np.mean(slopes) / K - 1), np.mean(model), 100 * (np.mean(model) / sqrt(truth) - 1),
             100 * (np.mean(model) / sqrt(rule) - 1), np.mean(standard)))


if __name__ == "__main__":
    main()
