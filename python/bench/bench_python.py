#!/usr/bin/env python3
"""Benchmark of the Python module (a measurement, not a test): prints a Markdown table.

In one run, on a 12 MP uint16 mosaic (4000 x 3000):
  * the binding's overhead: rawgment.colorJitter from Python against the same C++ call timed in C++;
  * what users write today: the same noise-accounted colour jitter (ACCOUNT_PRIOR, Eq. 11) in pure numpy
    and in pure torch (scale, variance from the model, standard normal, add, round, clip);
  * a DataLoader over RawFolderDataset (2 MP DNGs) with 0 and 2 workers, in samples per second;
  * rawgment.batch on a Dask LocalCluster with 1 and 2 worker processes, in outputs per second.

    PYTHONPATH=build/release/python /usr/bin/python3 python/bench/bench_python.py [--repeats 5]
"""
import argparse
import os
import platform
import statistics
import tempfile
import time

import numpy as np
import torch

import rawgment as rg
import rawgment.batch
import rawgment.torch as rgt

SIZE = (4000, 3000)  # width, height: 12 MP


def median_seconds(fn, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def numpy_jitter(raw, fmt, model, photon_ratio, gain_ratio, rng):
    """Eq. 11 with the paper's prior-mean estimate, as a numpy user writes it."""
    black = np.float32(fmt.blackLevel[0])
    x = raw.astype(np.float32) - black
    g = fmt.gain
    mu = np.maximum(x, 0)
    pu, pg = photon_ratio, gain_ratio
    v = (pu * (1 - pu) * pg * pg * g * model.alpha) * mu + np.float32(
        (1 - pu * pu) * pg * pg * g * g * model.sigmaD2 + (1 - pu * pu * pg * pg) * model.sigmaR2)
    out = np.float32(pu * pg) * x + np.sqrt(np.maximum(v, 0)) * rng.standard_normal(x.shape, dtype=np.float32)
    return np.clip(np.rint(out + black), 0, fmt.whiteLevel).astype(np.uint16)


def torch_jitter(raw, fmt, model, photon_ratio, gain_ratio, generator):
    black = fmt.blackLevel[0]
    x = torch.from_numpy(raw.astype(np.float32)) - black
    g = fmt.gain
    pu, pg = photon_ratio, gain_ratio
    v = (pu * (1 - pu) * pg * pg * g * model.alpha) * x.clamp(min=0) + (
        (1 - pu * pu) * pg * pg * g * g * model.sigmaD2 + (1 - pu * pu * pg * pg) * model.sigmaR2)
    out = (pu * pg) * x + v.clamp(min=0).sqrt() * torch.randn(x.shape, generator=generator)
    return torch.clamp(torch.round(out + black), 0, fmt.whiteLevel).to(torch.int32).numpy().astype(np.uint16)


def dataloader_rate(folder, model, workers, epochs=2):
    dataset = rgt.RawFolderDataset(folder, model, baseSeed=1, pack=True)
    start = time.perf_counter()
    count = 0
    for epoch in range(epochs):
        dataset.set_epoch(epoch)
        for batch in torch.utils.data.DataLoader(dataset, batch_size=2, num_workers=workers):
            count += batch["raw"].shape[0]
    return count / (time.perf_counter() - start)


def dask_rate(inputs, model_path, policy_path, out, workers):
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        client.run(lambda: __import__("rawgment"))  # workers import the module before the clock starts
        start = time.perf_counter()
        result = rawgment.batch.augmentFiles(inputs, model_path, out, policy=policy_path, variants=2, seed=1,
                                             client=client)
        return result["written"] / (time.perf_counter() - start)


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def main():
    parser = argparse.ArgumentParser(description="Benchmark of the Python module", allow_abbrev=False)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    torch.set_num_threads(os.cpu_count())

    sensor = rg.SensorSimulator(rg.SensorParams(), SIZE)
    y, x = np.mgrid[0:SIZE[1], 0:SIZE[0]].astype(np.float32)
    scene = (200 + 2000 * (x / SIZE[0]) * (y / SIZE[1])).astype(np.float32)
    raw = sensor.capture(scene, 1.0, 1.0, seed=1)
    fmt, model = sensor.rawFormat(1.0), sensor.effectiveModel()
    jitter = rg.ColorJitter.exposureChange(0.1, 2.0)
    noise = rg.NoiseOptions()

    cxx = statistics.median(rg._benchmark.colorJitterSeconds(raw, fmt, model, jitter, noise, 1, args.repeats))
    py = median_seconds(lambda: rg.colorJitter(raw, fmt, model, jitter, noise, seed=1), args.repeats)
    rng = np.random.default_rng(1)
    naive_np = median_seconds(lambda: numpy_jitter(raw, fmt, model, 0.1, 2.0, rng), max(3, args.repeats // 2))
    generator = torch.Generator().manual_seed(1)
    naive_torch = median_seconds(lambda: torch_jitter(raw, fmt, model, 0.1, 2.0, generator), max(3, args.repeats // 2))

    rows = [
        ("colorJitter, C++ call timed in C++", "%.1f ms" % (cxx * 1e3), ""),
        ("colorJitter from Python", "%.1f ms" % (py * 1e3), "binding overhead %+.1f%%" % (100 * (py - cxx) / cxx)),
        ("same jitter in pure numpy", "%.1f ms" % (naive_np * 1e3), "rawgment %.1fx faster" % (naive_np / py)),
        ("same jitter in pure torch (%d threads)" % torch.get_num_threads(), "%.1f ms" % (naive_torch * 1e3),
         "rawgment %.1fx faster" % (naive_torch / py)),
    ]

    with tempfile.TemporaryDirectory() as tmp:
        small = rg.SensorSimulator(rg.SensorParams(), (1920, 1080))
        ys, xs = np.mgrid[0:1080, 0:1920].astype(np.float32)
        inputs = []
        for i in range(8):
            frame = small.capture((300 + 1500 * xs / 1920 * (1 + i % 3) / 3).astype(np.float32), 1, 1, seed=10 + i)
            path = os.path.join(tmp, "f%02d.dng" % i)
            rg.writeDng(path, rg.RawImage(mosaic=frame, format=small.rawFormat(1.0)))
            inputs.append(path)
        for workers in (0, 2):
            rate = dataloader_rate(tmp, small.effectiveModel(), workers)
            rows.append(("DataLoader, 2 MP DNGs, num_workers=%d" % workers, "%.1f samples/s" % rate, ""))
        model_path, policy_path = os.path.join(tmp, "model.yml"), os.path.join(tmp, "policy.yml")
        small.effectiveModel().save(model_path)
        rg.RandomScenePolicy().save(policy_path)
        for workers in (1, 2):
            rate = dask_rate(inputs, model_path, policy_path, os.path.join(tmp, "out%d" % workers), workers)
            rows.append(("rawgment.batch on Dask, %d worker%s, 2 MP" % (workers, "s" if workers > 1 else ""),
                         "%.1f outputs/s" % rate, ""))

    print("Host: %s, %d cores; CPU path %s; median of %d calls.\n" % (
        cpu_name(), os.cpu_count(), rg.cpuPathName(rg.activeCpuPath()), args.repeats))
    print("| what | time or rate | note |\n|---|---|---|")
    for row in rows:
        print("| %s | %s | %s |" % row)


if __name__ == "__main__":
    main()
