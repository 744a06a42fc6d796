"""Writes a noise model with every dark-frame component the library models, for the ablation study's
run on such a sensor (docs/results.md): the simulator's default sensor (alpha 0.25 DN/e-, sigma_d^2
1.5 DN^2, sigma_r^2 0.8 DN^2 plus the rounding's 1/12) with

* row noise: 0.2 DN^2 before the gain and 0.5 DN^2 after it (at the study's +12 dB, 3.7 DN^2 of a
  read variance of 25 DN^2: visible banding, as on many CMOS sensors);
* Tukey-lambda read noise, lambda -0.1 (heavier tails than the Gaussian: excess kurtosis 3.79, from
  the Beta-function moments of its quantile function);
* dark shading: a per-gain map (amp glow in one corner and column structure, up to 1.5 DN per unit
  gain) and an offset map (a gentle gradient and fixed column offsets, up to 2 DN), 512x512, larger
  than every capture of the study (maps are read from their top-left corner).

Usage: PYTHONPATH=build/release/python /usr/bin/python3 studies/ablation/dark_components_model.py OUT.yml
"""
import sys

import numpy as np

import rawgment as rg

SIZE = 512


def model():
    m = rg.NoiseModel(alpha=0.25, sigmaD2=1.5, sigmaR2=0.8 + 1.0 / 12.0)
    m.rowSigmaD2, m.rowSigmaR2 = 0.2, 0.5
    m.tukeyRead, m.tukeyLambda = True, -0.1
    y, x = np.mgrid[0:SIZE, 0:SIZE].astype(np.float64) / SIZE
    columns = np.random.default_rng(7).normal(0.0, 1.0, SIZE)
    glow = 1.2 * np.exp(-((1 - x) ** 2 + y ** 2) / 0.05)
    m.darkShadingPerGain = (glow + 0.3 * np.tanh(columns)[None, :]).astype(np.float32)
    m.darkShadingOffset = (1.0 * (x - 0.5) + 0.5 * (y - 0.5) + np.tanh(columns)[None, ::-1]).astype(np.float32)
    return m


def main(argv):
    if len(argv) != 2 or argv[1].startswith("-"):
        print(__doc__, file=sys.stderr)
        return 2
    model().save(argv[1])
    print(argv[1])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
