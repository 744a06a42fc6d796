#!/usr/bin/env python3
"""Benchmark of the Python module (a measurement, not a test): prints a Markdown table.

In one run, on a 12 MP uint16 mosaic (4000 x 3000):
  * the binding's overhead: rawgment.colorJitter from Python against the same C++ call timed in C++;
  * what users write today: the same noise-accounted colour jitter (ACCOUNT_PRIOR, Eq. 11) in pure numpy
    and in pure torch (scale, variance from the model, standard normal, add, round, clip);
  * the same jitter written as efficiently as each library allows: buffers allocated once (rawgment's
    output too, through dst=), every operation in place, the frame split over as many threads as rawgment uses (numpy: one thread per
    half with its own Generator, ufuncs release the GIL; torch: torch.set_num_threads). rawgment and the
    two are timed in interleaved rounds and each ratio is of the minima (a slow round of a loaded
    machine cannot favour one side);
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


def added_line(model, gain, photon_ratio, gain_ratio):
    """The slope and offset of the variance Eq. 11 adds, from the model's own lines: the target gain's line
    less the prior's scaled by (p_u p_g)^2, the slope at the prior's mean."""
    scale = photon_ratio * gain_ratio
    prior, target = model.lineAtGain(gain), model.lineAtGain(gain * gain_ratio)
    return scale * target.a - scale * scale * prior.a, target.b - scale * scale * prior.b


def numpy_jitter(raw, fmt, model, photon_ratio, gain_ratio, rng):
    """Eq. 11 with the paper's prior-mean estimate, as a numpy user writes it."""
    black = np.float32(fmt.blackLevel[0])
    x = raw.astype(np.float32) - black
    mu = np.maximum(x, 0)
    pu, pg = photon_ratio, gain_ratio
    slope, offset = added_line(model, fmt.gain, pu, pg)
    v = np.float32(slope) * mu + np.float32(offset)
    out = np.float32(pu * pg) * x + np.sqrt(np.maximum(v, 0)) * rng.standard_normal(x.shape, dtype=np.float32)
    return np.clip(np.rint(out + black), 0, fmt.whiteLevel).astype(np.uint16)


def torch_jitter(raw, fmt, model, photon_ratio, gain_ratio, generator):
    black = fmt.blackLevel[0]
    x = torch.from_numpy(raw.astype(np.float32)) - black
    pu, pg = photon_ratio, gain_ratio
    slope, offset = added_line(model, fmt.gain, pu, pg)
    v = slope * x.clamp(min=0) + offset
    out = (pu * pg) * x + v.clamp(min=0).sqrt() * torch.randn(x.shape, generator=generator)
    return torch.clamp(torch.round(out + black), 0, fmt.whiteLevel).to(torch.int32).numpy().astype(np.uint16)


class EfficientNumpyJitter:
    """Eq. 11 in numpy with preallocated float32 buffers and in-place ufuncs, over `threads` row bands."""

    def __init__(self, raw, fmt, model, photon_ratio, gain_ratio, threads):
        from concurrent.futures import ThreadPoolExecutor

        self.raw, self.black, self.white = raw, np.float32(fmt.blackLevel[0]), fmt.whiteLevel
        pu, pg = photon_ratio, gain_ratio
        slope, offset = added_line(model, fmt.gain, pu, pg)
        self.slope, self.offset = np.float32(slope), np.float32(offset)
        self.scale = np.float32(pu * pg)
        rows = raw.shape[0]
        self.bands = [slice(rows * k // threads, rows * (k + 1) // threads) for k in range(threads)]
        self.x = np.empty(raw.shape, np.float32)
        self.v = np.empty(raw.shape, np.float32)
        self.z = np.empty(raw.shape, np.float32)
        self.out = np.empty(raw.shape, np.uint16)
        self.rngs = [np.random.default_rng(k) for k in range(threads)]
        self.pool = ThreadPoolExecutor(threads)

    def band(self, k):
        b = self.bands[k]
        x, v, z = self.x[b], self.v[b], self.z[b]
        np.subtract(self.raw[b], self.black, out=x, dtype=np.float32)
        np.maximum(x, 0, out=v)
        v *= self.slope
        v += self.offset
        np.maximum(v, 0, out=v)
        np.sqrt(v, out=v)
        self.rngs[k].standard_normal(out=z, dtype=np.float32)
        v *= z
        x *= self.scale
        x += v
        x += self.black
        np.rint(x, out=x)
        np.clip(x, 0, self.white, out=x)
        self.out[b] = x  # the cast to uint16 in the copy

    def __call__(self):
        list(self.pool.map(self.band, range(len(self.bands))))
        return self.out


class EfficientTorchJitter:
    """Eq. 11 in torch with preallocated tensors and in-place operations (torch's own threads)."""

    def __init__(self, raw, fmt, model, photon_ratio, gain_ratio):
        self.raw = torch.from_numpy(raw.astype(np.int32))  # torch has no uint16 arithmetic
        self.black, self.white = float(fmt.blackLevel[0]), float(fmt.whiteLevel)
        pu, pg = photon_ratio, gain_ratio
        self.slope, self.offset = added_line(model, fmt.gain, pu, pg)
        self.scale = pu * pg
        self.x = torch.empty(raw.shape, dtype=torch.float32)
        self.v = torch.empty(raw.shape, dtype=torch.float32)
        self.z = torch.empty(raw.shape, dtype=torch.float32)
        self.out = torch.empty(raw.shape, dtype=torch.int32)
        self.generator = torch.Generator().manual_seed(1)

    def __call__(self):
        x, v = self.x, self.v
        torch.sub(self.raw, self.black, out=x)
        torch.clamp(x, min=0, out=v)
        v.mul_(self.slope).add_(self.offset).clamp_(min=0).sqrt_()
        torch.randn(x.shape, generator=self.generator, out=self.z)
        v.mul_(self.z)
        x.mul_(self.scale).add_(v).add_(self.black).round_().clamp_(0, self.white)
        self.out.copy_(x)
        return self.out


def interleaved_minima(functions, rounds):
    """The minimum time of each function over `rounds` rounds, each round calling every function once."""
    best = [float("inf")] * len(functions)
    for _ in range(rounds):
        for k, fn in enumerate(functions):
            start = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - start)
    return best


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


def jitter_frame():
    """The benchmark's 12 MP mosaic of a simulated sensor, its format and model, and the jitter timed on it."""
    sensor = rg.SensorSimulator(rg.SensorParams(), SIZE)
    y, x = np.mgrid[0:SIZE[1], 0:SIZE[0]].astype(np.float32)
    scene = (200 + 2000 * (x / SIZE[0]) * (y / SIZE[1])).astype(np.float32)
    raw = sensor.capture(scene, 1.0, 1.0, seed=1)
    return raw, sensor.rawFormat(1.0), sensor.effectiveModel(), rg.ColorJitter.exposureChange(0.1, 2.0)


def efficient_minima(raw, fmt, model, jitter, rounds):
    """Minima in seconds over `rounds` interleaved rounds of rawgment's colorJitter into a reused dst and of
    the efficient numpy and torch jitters of the same exposure change (`jitter`, without brightness), each
    on as many threads as rawgment uses: (rawgment, numpy, torch, threads)."""
    threads = rg.getNumThreads()
    torch.set_num_threads(threads)
    gain_ratio = jitter.gainRatio
    photon_ratio = jitter.contrast[0] / gain_ratio  # exposureChange(p_u, p_g) has contrast p_u p_g
    efficient_np = EfficientNumpyJitter(raw, fmt, model, photon_ratio, gain_ratio, threads)
    efficient_torch = EfficientTorchJitter(raw, fmt, model, photon_ratio, gain_ratio)
    noise = rg.NoiseOptions()
    # The baselines reuse their buffers; so does rawgment here, through dst.
    reused = np.empty_like(raw)
    ours, best_np, best_torch = interleaved_minima(
        [lambda: rg.colorJitter(raw, fmt, model, jitter, noise, seed=1, dst=reused), efficient_np, efficient_torch],
        rounds)
    return ours, best_np, best_torch, threads


def main():
    parser = argparse.ArgumentParser(description="Benchmark of the Python module", allow_abbrev=False)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    torch.set_num_threads(os.cpu_count())

    raw, fmt, model, jitter = jitter_frame()
    noise = rg.NoiseOptions()

    cxx = statistics.median(rg._benchmark.colorJitterSeconds(raw, fmt, model, jitter, noise, 1, args.repeats))
    py = median_seconds(lambda: rg.colorJitter(raw, fmt, model, jitter, noise, seed=1), args.repeats)
    rng = np.random.default_rng(1)
    naive_np = median_seconds(lambda: numpy_jitter(raw, fmt, model, 0.1, 2.0, rng), max(3, args.repeats // 2))
    generator = torch.Generator().manual_seed(1)
    naive_torch = median_seconds(lambda: torch_jitter(raw, fmt, model, 0.1, 2.0, generator), max(3, args.repeats // 2))

    ours, best_np, best_torch, threads = efficient_minima(raw, fmt, model, jitter, max(5, args.repeats))

    rows = [
        ("colorJitter, C++ call timed in C++", "%.1f ms" % (cxx * 1e3), ""),
        ("colorJitter from Python", "%.1f ms" % (py * 1e3), "binding overhead %+.1f%%" % (100 * (py - cxx) / cxx)),
        ("same jitter in pure numpy", "%.1f ms" % (naive_np * 1e3), "rawgment %.1fx faster" % (naive_np / py)),
        ("same jitter in pure torch (%d threads)" % torch.get_num_threads(), "%.1f ms" % (naive_torch * 1e3),
         "rawgment %.1fx faster" % (naive_torch / py)),
        ("colorJitter from Python into a reused dst, minimum of %d interleaved rounds" % max(5, args.repeats),
         "%.1f ms" % (ours * 1e3), ""),
        ("same jitter in efficient numpy (%d threads, in place), same rounds" % threads, "%.1f ms" % (best_np * 1e3),
         "rawgment %.1fx faster (goal: 10x)" % (best_np / ours)),
        ("same jitter in efficient torch (%d threads, in place), same rounds" % threads,
         "%.1f ms" % (best_torch * 1e3), "rawgment %.1fx faster (goal: 10x)" % (best_torch / ours)),
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
