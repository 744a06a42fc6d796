"""The noise the ablation's training inputs carry, against the oracle's: on flat grey scenes, the
variance (as a ratio to the oracle's) and the skewness of the green planes of IGNORE_PRIOR,
ACCOUNT_PRIOR and ORACLE inputs, through the study's own trainingInputs (12 crops of 256x256 per
condition and grey level; the relative standard error of a variance ratio is about 0.3%).
docs/results.md cites it for why blind networks trained on ACCOUNT_PRIOR trail the oracle.

Usage: PYTHONPATH=build/release/python /usr/bin/python3 studies/ablation/input_moments.py [POISSON]
(the argument: the augmented arms' ShotNoiseSampling, GAUSSIAN by default)

Output on host H2, 2026-11-25 (condition, grey level, then per arm the variance over the oracle's and
the skewness):

x0.5 0.05 IGNORE_PRIOR 1.4334 0.084 ACCOUNT_PRIOR 0.9965 0.081 ORACLE 1.0000 0.077
x0.5 0.18 IGNORE_PRIOR 1.4747 0.055 ACCOUNT_PRIOR 0.9976 0.055 ORACLE 1.0000 0.055
x0.5 0.6 IGNORE_PRIOR 1.4867 0.030 ACCOUNT_PRIOR 0.9966 0.030 ORACLE 1.0000 0.032
x0.2 0.05 IGNORE_PRIOR 1.1251 0.045 ACCOUNT_PRIOR 0.9972 0.044 ORACLE 1.0000 0.075
x0.2 0.18 IGNORE_PRIOR 1.1632 0.040 ACCOUNT_PRIOR 0.9937 0.041 ORACLE 1.0000 0.069
x0.2 0.6 IGNORE_PRIOR 1.1898 0.026 ACCOUNT_PRIOR 1.0003 0.027 ORACLE 1.0000 0.045
x0.05 0.05 IGNORE_PRIOR 1.0086 0.010 ACCOUNT_PRIOR 0.9949 0.010 ORACLE 1.0000 0.046
x0.05 0.18 IGNORE_PRIOR 1.0202 0.015 ACCOUNT_PRIOR 0.9930 0.016 ORACLE 1.0000 0.081
x0.05 0.6 IGNORE_PRIOR 1.0363 0.015 ACCOUNT_PRIOR 0.9965 0.015 ORACLE 1.0000 0.071
x0.01 0.05 IGNORE_PRIOR 0.9968 0.005 ACCOUNT_PRIOR 0.9961 0.005 ORACLE 1.0000 0.016
x0.01 0.18 IGNORE_PRIOR 0.9971 0.006 ACCOUNT_PRIOR 0.9952 0.006 ORACLE 1.0000 0.038
x0.01 0.6 IGNORE_PRIOR 1.0035 0.006 ACCOUNT_PRIOR 0.9993 0.006 ORACLE 1.0000 0.060

With POISSON, host H2, 2026-11-26 (Poisson counts by Ahrens and Dieter's PD; the library of commit
b4ca750, whose counts came from PTRS, gave the same to within the noise):

x0.5 0.05 IGNORE_PRIOR 1.4398 0.130 ACCOUNT_PRIOR 0.9989 0.122 ORACLE 1.0000 0.077
x0.5 0.18 IGNORE_PRIOR 1.4870 0.080 ACCOUNT_PRIOR 1.0041 0.079 ORACLE 1.0000 0.055
x0.5 0.6 IGNORE_PRIOR 1.4911 0.041 ACCOUNT_PRIOR 0.9982 0.042 ORACLE 1.0000 0.032
x0.2 0.05 IGNORE_PRIOR 1.1302 0.106 ACCOUNT_PRIOR 0.9992 0.106 ORACLE 1.0000 0.075
x0.2 0.18 IGNORE_PRIOR 1.1721 0.090 ACCOUNT_PRIOR 1.0011 0.093 ORACLE 1.0000 0.069
x0.2 0.6 IGNORE_PRIOR 1.1962 0.053 ACCOUNT_PRIOR 1.0048 0.055 ORACLE 1.0000 0.045
x0.05 0.05 IGNORE_PRIOR 1.0111 0.053 ACCOUNT_PRIOR 0.9969 0.050 ORACLE 1.0000 0.046
x0.05 0.18 IGNORE_PRIOR 1.0246 0.083 ACCOUNT_PRIOR 0.9977 0.082 ORACLE 1.0000 0.081
x0.05 0.6 IGNORE_PRIOR 1.0428 0.076 ACCOUNT_PRIOR 1.0026 0.077 ORACLE 1.0000 0.071
x0.01 0.05 IGNORE_PRIOR 0.9975 0.017 ACCOUNT_PRIOR 0.9968 0.017 ORACLE 1.0000 0.016
x0.01 0.18 IGNORE_PRIOR 0.9992 0.040 ACCOUNT_PRIOR 0.9975 0.039 ORACLE 1.0000 0.038
x0.01 0.6 IGNORE_PRIOR 1.0073 0.072 ACCOUNT_PRIOR 1.0031 0.071 ORACLE 1.0000 0.060
"""
import sys

import numpy as np
import torch

import rawgment_ablation.study as ab

ARMS = ("IGNORE_PRIOR", "ACCOUNT_PRIOR", "ORACLE")


def moments(planes):
    """Variance and skewness of the two green planes, each about its own mean."""
    green = planes[1:3].double()
    centred = green - green.mean(dim=(1, 2), keepdim=True)
    variance = float((centred ** 2).sum() / (green.numel() - 2))
    return variance, float((centred ** 3).mean()) / variance ** 1.5


def main():
    sampling = sys.argv[1] if len(sys.argv) > 1 else "GAUSSIAN"
    torch.set_num_threads(1)
    for condition in [ab.Condition("x0.5", 0.5), ab.Condition("x0.2", 0.2), ab.Condition("x0.05", 0.05),
                      ab.Condition("x0.01", 0.01)]:
        study = ab._Study(ab.AblationConfig(conditions=[condition], patch=256, shotSampling=sampling))
        for grey in (0.05, ab._MID_GREY, 0.6):
            mean = ab.mosaicOfScene(np.full((256, 256, 3), grey, np.float32), study.params.pattern, study.level)
            found = {arm: [] for arm in ARMS}
            for seed in range(12):
                for arm, planes in study.trainingInputs(mean, condition, ARMS, seed=100 + seed).items():
                    found[arm].append(moments(planes))
            oracle = np.mean([v for v, _ in found["ORACLE"]])
            print(condition.name, grey, " ".join(
                "%s %.4f %.3f" % (arm, np.mean([v for v, _ in found[arm]]) / oracle,
                                  np.mean([k for _, k in found[arm]])) for arm in ARMS))


if __name__ == "__main__":
    main()
