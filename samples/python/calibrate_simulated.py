#!/usr/bin/env python3
"""Calibrates a noise model from simulated colour-checker bursts, as you would from your camera's.

Three gains, one burst each: per-pixel temporal statistics of the burst (BurstStatistics), the
(mean, variance) samples of the chart's patches, then the joint fit of alpha, sigma_d^2 and sigma_r^2.
The simulator's own model is the truth the result is printed against.

    /usr/bin/python3 samples/python/calibrate_simulated.py [--frames 32] [--save model.yml]
"""
import argparse

import numpy as np

import rawgment as rg


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--frames", type=int, default=32, help="frames per burst (default 32)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the simulated bursts")
    parser.add_argument("--save", help="save the calibrated model to this .yml/.json file")
    args = parser.parse_args()

    sensor = rg.SensorSimulator(rg.SensorParams(noise=rg.NoiseModel(0.3, 2.0, 1.0)), (560, 384))
    chart = rg.makeColorCheckerScene(rg.ColorCheckerOptions(patchSize=80, border=10, illumination=3000))
    mean = np.zeros((384, 560), np.float32)
    h, w = chart.meanAtUnitGain.shape
    mean[:h, :w] = chart.meanAtUnitGain
    squares = rg.cfaAlignedSquares(chart.patches, 48)

    samples = []
    for i, db in enumerate((0.0, 6.0, 12.0)):
        gain = rg.dbToLinearGain(db)
        stats = rg.BurstStatistics(sensor.rawFormat(gain))
        for frame in sensor.captureBurst(mean, gain, 0.5, args.frames, rg.deriveSeed(args.seed, rg.SEED_SIMULATED_BURST, i)):
            stats.add(frame)
        samples += rg.sampleBurstPatches(stats, squares, gain)
        print("gain %5.2f dB: %d samples" % (db, len(samples)))

    report = rg.calibrateNoiseModel(samples)
    truth = sensor.effectiveModel()
    print("%-8s %12s %12s %9s" % ("", "calibrated", "truth", "error"))
    for name in ("alpha", "sigmaD2", "sigmaR2"):
        got, want = getattr(report.model, name), getattr(truth, name)
        print("%-8s %12.5f %12.5f %8.2f%%" % (name, got, want, 100 * (got - want) / want))
    for note in report.notes:
        print("note:", note)
    if args.save:
        report.model.save(args.save)
        print("saved", args.save)


if __name__ == "__main__":
    main()
