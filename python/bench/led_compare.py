#!/usr/bin/python3
"""rawgment's noise against its peer's, measured in one process (a measurement, not a test; opt-in).

The peer is LED's noise generator (Srameo/LED, "Lighting Every Darkness", ICCV 2023; its functions
`shot_noise`, `gaussian_noise`, `tukey_lambda_noise` and `row_noise` in led/data/noise_utils/common.py, the
ones its CalibratedNoisyPairGenerator composes). The project vendors none of LED's code: give the path of a
checkout of the pinned commit ee3d372, which this script checks and loads that one file from (it imports
only torch). Nothing is fetched.

    PYTHONPATH=build/release/python /usr/bin/python3 python/bench/led_compare.py --led PATH [--rounds 9]

Both add the same noise to the same 12 MP scene (4000 x 3000, DN above black): LED's randomly drawn
parameters are fixed (K, the read sigma, the row sigma, the Tukey-lambda scale set for the same read
variance), as are rawgment's (a NoiseModel with alpha = K at gain 1, sigma_r^2 = the read variance, the row
variance after the gain, IGNORE_PRIOR: the full model variance at the new mean). Each darkens the scene by
half first (LED scales its image by the ratio of its pair; rawgment's colorJitter by its contrast). Three
noises, as the issue measured them: Gaussian read noise; Poisson shot plus Gaussian read; Poisson shot plus
Tukey-lambda read plus row noise. rawgment runs on the mosaic as uint16 and as float32 (into a reused output);
LED on its packed float32 tensor (1 x 4 x 1500 x 2000, its layout), as its data loader gives it, allocating
as it does. Equal thread counts (torch.set_num_threads, rawgment.setNumThreads). Times are medians of
--rounds calls after a warm-up call.

The noise is checked first, on a flat scene (1000 DN, darkened to 500): the variance of each against the
expected K x + read + row, and the excess kurtosis of each (their difference in standard errors,
sqrt(24 / n) each, n = 12 M). Prints Markdown tables.
"""
import argparse
import importlib.util
import math
import os
import platform
import statistics
import subprocess
import sys
import time

import numpy as np
import torch

import rawgment as rg

PINNED = "ee3d372"
WIDTH, HEIGHT = 4000, 3000
BLACK, WHITE = 256.0, 4095.0
K = 0.5          # DN per electron
READ_SIGMA = 3.0  # DN
ROW_SIGMA = 1.0   # DN
TUKEY_LAMBDA = -0.1
DARKEN = 0.5


def load_led(checkout):
    """LED's noise functions from the checkout, which must be at the pinned commit."""
    try:
        head = subprocess.run(["git", "-C", checkout, "rev-parse", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError) as e:
        sys.exit("led_compare: %s is not a git checkout of Srameo/LED (%s)" % (checkout, e))
    if not head.startswith(PINNED):
        sys.exit("led_compare: %s is at %s; the comparison is pinned to %s (git -C %s checkout %s)" %
                 (checkout, head[:12], PINNED, checkout, PINNED))
    path = os.path.join(checkout, "led", "data", "noise_utils", "common.py")
    if not os.path.isfile(path):
        sys.exit("led_compare: %s is missing" % path)
    spec = importlib.util.spec_from_file_location("led_noise_common", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def tukey_unit_variance(lam):
    """Variance of the standard Tukey-lambda distribution (lambda != 0, > -1/2)."""
    return 2.0 / lam ** 2 * (1.0 / (1 + 2 * lam) - math.gamma(lam + 1) ** 2 / math.gamma(2 * lam + 2))


def scene():
    x = np.linspace(0, 1, WIDTH, dtype=np.float32)
    y = np.linspace(0, 1, HEIGHT, dtype=np.float32)[:, None]
    return (100 + 3000 * (0.5 + 0.5 * np.sin(9 * x) * np.cos(7 * y))).astype(np.float32)


def pack(mosaic):
    """LED's layout: 1 x 4 x H/2 x W/2 (R, G1, B, G2 for RGGB, as its _pack_bayer)."""
    m = torch.from_numpy(mosaic)
    return torch.stack((m[0::2, 0::2], m[0::2, 1::2], m[1::2, 1::2], m[1::2, 0::2]))[None].contiguous()


CASES = ("Gaussian read", "Poisson shot + Gaussian read", "Poisson shot + Tukey read + row")


def rawgment_setup(case):
    model = rg.NoiseModel(alpha=0.0 if case == CASES[0] else K, sigmaD2=0.0, sigmaR2=READ_SIGMA ** 2)
    noise = rg.NoiseOptions(rg.NoiseAlignment.IGNORE_PRIOR)
    if case != CASES[0]:
        noise.shotSampling = rg.ShotNoiseSampling.POISSON
    if case == CASES[2]:
        model.tukeyRead = True
        model.tukeyLambda = TUKEY_LAMBDA
        model.rowSigmaR2 = ROW_SIGMA ** 2
    return model, noise


def led_noise(led, case, x):
    """LED's composition (CalibratedNoisyPairGenerator.forward and add_noise) with fixed parameters."""
    if case == CASES[0]:
        return x + led.gaussian_noise(x, READ_SIGMA)
    out = x + led.shot_noise(x, K)
    if case == CASES[1]:
        return out + led.gaussian_noise(x, READ_SIGMA)
    scale = READ_SIGMA / math.sqrt(tukey_unit_variance(TUKEY_LAMBDA))
    return out + led.tukey_lambda_noise(x, scale, torch.tensor(TUKEY_LAMBDA)) + led.row_noise(x, ROW_SIGMA)


def run_led(led, case, packed):
    x = packed * DARKEN
    return led_noise(led, case, x).clamp_(0, WHITE - BLACK)


def run_rawgment(case, mosaic, fmt, out, seed):
    model, noise = rawgment_setup(case)
    jitter = rg.ColorJitter.exposureChange(DARKEN, 1.0)
    return rg.colorJitter(mosaic, fmt, model, jitter, noise, seed=seed, dst=out)[0]


def moments(values):
    v = values.astype(np.float64).ravel()
    d = v - v.mean()
    var = float(np.mean(d * d))
    return var, float(np.mean(d ** 4) / var ** 2 - 3)


def check(led, fmt, rows):
    flat = np.full((HEIGHT, WIDTH), 1000.0 + BLACK, np.float32)
    x = 1000.0 * DARKEN
    n = flat.size
    se = math.sqrt(24.0 / n)
    print("\n### The noise on a flat scene (%g DN, darkened to %g)\n" % (1000.0, x))
    print("| noise | expected variance | rawgment variance | LED variance | rawgment excess kurtosis | "
          "LED excess kurtosis | difference / SE |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for case in CASES:
        expected = (0 if case == CASES[0] else K * x) + READ_SIGMA ** 2 + (ROW_SIGMA ** 2 if case == CASES[2]
                                                                          else 0)
        ours = run_rawgment(case, flat, fmt, None, 7) - BLACK
        theirs = run_led(led, case, pack(flat - BLACK)).numpy()
        var_o, kurt_o = moments(ours)
        var_t, kurt_t = moments(theirs)
        diff = (kurt_o - kurt_t) / (math.sqrt(2) * se)
        print("| %s | %.3f | %.3f | %.3f | %.4f | %.4f | %.1f |" % (case, expected, var_o, var_t, kurt_o, kurt_t,
                                                                    diff))
        rows.append((case, expected, var_o, var_t, kurt_o, kurt_t))


def median_ms(run, rounds):
    run()
    times = []
    for _ in range(rounds):
        start = time.perf_counter()
        run()
        times.append((time.perf_counter() - start) * 1e3)
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--led", required=True, help="a checkout of Srameo/LED at %s" % PINNED)
    parser.add_argument("--rounds", type=int, default=9, help="timed calls per case (>= 7)")
    parser.add_argument("--threads", type=int, default=2, help="threads for both (default 2)")
    args = parser.parse_args()
    if args.rounds < 7:
        parser.error("--rounds must be at least 7")
    led = load_led(args.led)
    torch.set_num_threads(args.threads)
    rg.setNumThreads(args.threads)
    fmt = rg.RawFormat(blackLevel=(BLACK,) * 4, whiteLevel=WHITE)
    print("## rawgment against LED (%s), %d threads each, %s, torch %s\n" %
          (PINNED, args.threads, platform.processor() or platform.machine(), torch.__version__))
    print("Parameters: K %g DN/e-, read sigma %g DN, row sigma %g DN, Tukey lambda %g; the scene darkened by %g."
          % (K, READ_SIGMA, ROW_SIGMA, TUKEY_LAMBDA, DARKEN))
    check(led, fmt, [])

    signal = scene()
    as_float = signal + BLACK
    as_u16 = np.rint(as_float).astype(np.uint16)
    packed = pack(signal)
    out_u16, out_f32 = np.empty_like(as_u16), np.empty_like(as_float)
    print("\n### Time of one 12 MP frame (medians of %d calls after a warm-up)\n" % args.rounds)
    print("| noise | LED, float32 (ms) | rawgment, uint16 (ms) | rawgment, float32 (ms) | LED / rawgment uint16 | "
          "LED / rawgment float32 |")
    print("|---|---:|---:|---:|---:|---:|")
    seed = [0]

    def next_seed():
        seed[0] += 1
        return seed[0]

    for case in CASES:
        t_led = median_ms(lambda: run_led(led, case, packed), args.rounds)
        t_u16 = median_ms(lambda: run_rawgment(case, as_u16, fmt, out_u16, next_seed()), args.rounds)
        t_f32 = median_ms(lambda: run_rawgment(case, as_float, fmt, out_f32, next_seed()), args.rounds)
        print("| %s | %.1f | %.1f | %.1f | %.1fx | %.1fx |" % (case, t_led, t_u16, t_f32, t_led / t_u16,
                                                                t_led / t_f32))


if __name__ == "__main__":
    main()
