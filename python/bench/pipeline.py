#!/usr/bin/python3
"""The training pipeline, measured (a measurement, not a test): where a sample's time goes from file to tensor,
and how fast a DataLoader gives samples. Prints Markdown tables.

In one run, on 12 MP mosaics (4000 x 3000, 12-bit, a simulated sensor):

* **Per sample** (RawFolderDataset, pack=True, in this process), for each container (.npy, uncompressed
  TIFF, PNG, and DNG through LibRaw) and each policy (augmentation off, jitter only, the default random
  scene): the time in reading and decoding (rawgment.torch.loadMosaic), in each augmentation step
  (AugmentReport.stepSeconds: shift, scale, colorJitter, motionBlur), in the conversion to the tensor (one
  pass: rawgment.packCfaPlanes into the tensor), and everything else (the sample's own time less those: the
  policy's draw, Python, copies), as medians over samples and rounds, each part timed inside the item's own
  call (RawFolderDataset(timings=True)).
* **The floor**, in the same run: a copy (np.copyto) of the sample's uint16 mosaic and of its float32
  tensor into memory already touched, and np.load of the .npy.
* **A DataLoader** over each container's folder with 0, 1 and 2 workers (persistent, batch size 1), for each
  policy: samples per second, after a warm-up epoch, medians of interleaved rounds of at
  least 2 s each.
* **POISSON against the Gaussian jitter**: colorJitter of the mosaic with each shot sampling.

    PYTHONPATH=build/release/python /usr/bin/python3 python/bench/pipeline.py [--samples 4] [--rounds 3]

Before and after a change, on the same files: `--keep DIR` writes the files into DIR (and keeps them), and
`--loaders FOLDER` prints only the DataLoader rates over one of its folders with whichever build of
rawgment is on PYTHONPATH (an older build's RawFolderDataset, for instance).
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
import rawgment.torch as rgt

SIZE = (4000, 3000)  # width, height: 12 MP
STEPS = ("shift", "scale", "colorJitter", "motionBlur")


def make_folders(root, samples):
    """One folder per container with `samples` simulated 12 MP mosaics (the .npy, TIFF and PNG with sidecars,
    the DNGs as a camera gives them)."""
    params = rg.SensorParams(noise=rg.NoiseModel(0.25, 1.5, 0.8), bitDepth=12)
    sensor = rg.SensorSimulator(params, SIZE)
    x = np.linspace(0, 1, SIZE[0], dtype=np.float32)
    y = np.linspace(0, 1, SIZE[1], dtype=np.float32)[:, None]
    scene = (200 + 2600 * (0.5 + 0.5 * np.sin(9 * x) * np.cos(7 * y))).astype(np.float32)
    folders = {ext: os.path.join(root, ext) for ext in ("npy", "tif", "png", "dng")}
    for folder in folders.values():
        os.makedirs(folder)
    for i in range(samples):
        raw = sensor.capture(scene, 1.0, 1.0, seed=100 + i)
        fmt = sensor.rawFormat(1.0)
        name = "frame_%02d" % i
        rg.writeDng(os.path.join(folders["dng"], name + ".dng"), rg.RawImage(mosaic=raw, format=fmt, iso=100))
        for ext in ("npy", "tif", "png"):
            rg.writeMosaic(os.path.join(folders[ext], name + "." + ext), raw, rg.MosaicMetadata(format=fmt))
    return sensor.params().noise, folders


def policies():
    jitter = rg.RandomScenePolicy(blurProbability=0, geometryProbability=0)
    return {"off": None, "jitter only": jitter, "default": rg.RandomScenePolicy()}


def profile_samples(folder, model, policy, rounds):
    """Median seconds per part of a sample, and of the whole sample, over every sample and round, as the
    dataset records them (RawFolderDataset(timings=True): each part timed inside the item's own call)."""
    dataset = rgt.RawFolderDataset(folder, model, policy=policy, baseSeed=1, pack=True, augment=policy is not None,
                                   timings=True)
    for r in range(rounds):
        dataset.set_epoch(r)
        for index in range(len(dataset)):
            dataset[index]
    keys = ("read",) + STEPS + ("tensor", "other", "total")
    return {k: statistics.median(t.get(k, 0.0) for t in dataset.timings) for k in keys}


def floor(folder, rounds):
    """Medians of the floor and of the tensor's pass, like with like: copies of the uint16 mosaic and of the
    float32 planes into memory already touched and into new memory (a new tensor's pages are first touched
    by whatever writes it), np.load of the .npy, and the one-pass conversion into touched and new tensors
    beside the conversion before it (subtractBlackLevel, then the planes split and stacked)."""
    path = os.path.join(folder, sorted(os.listdir(folder))[0])
    mosaic = np.load(path)
    fmt = rg.readMosaic(path)[1].format
    copy16 = np.empty_like(mosaic)
    planes = torch.ones((4, SIZE[1] // 2, SIZE[0] // 2))
    touched = torch.zeros_like(planes)
    cases = {
        "memcpy mosaic, touched memory": lambda: np.copyto(copy16, mosaic),
        "np.load of the .npy": lambda: np.load(path),
        "memcpy tensor, touched memory": lambda: touched.copy_(planes),
        "memcpy tensor, new memory": lambda: planes.clone(),
        "tensor pass, touched memory": lambda: rg.packCfaPlanes(mosaic, fmt, out=touched.numpy()),
        "tensor pass, new tensor": lambda: rg.packCfaPlanes(mosaic, fmt, out=torch.empty(planes.shape).numpy()),
        "before: subtract, split, stack": lambda: rgt.packCfaPlanes(rg.subtractBlackLevel(mosaic, fmt, normalize=True),
                                                                    fmt),
    }
    times = {name: [] for name in cases}
    for _ in range(5 * rounds):
        for name, fn in cases.items():
            start = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - start)
    return {k: statistics.median(v) for k, v in times.items()}


def loader_rates(folder, model, policy, rounds, seconds=2.0):
    """Samples per second of a DataLoader with 0, 1 and 2 workers (persistent, batch size 1): the three loaders
    made once and warmed up, then timed in interleaved rounds of whole epochs lasting at least `seconds`
    each (a loaded moment of the machine falls on all three), medians of the rounds."""
    loaders = {}
    for workers in (0, 1, 2):
        dataset = rgt.RawFolderDataset(folder, model, policy=policy, baseSeed=1, pack=True,
                                       augment=policy is not None)
        loader = torch.utils.data.DataLoader(dataset, batch_size=1, num_workers=workers,
                                             persistent_workers=workers > 0)
        dataset.set_epoch(0)
        for _ in loader:  # warm-up: workers started, files in the page cache
            pass
        loaders[workers] = (dataset, loader)
    rates = {workers: [] for workers in loaders}
    epoch = 1
    for _ in range(rounds):
        for workers, (dataset, loader) in loaders.items():
            count, start = 0, time.perf_counter()
            while time.perf_counter() - start < seconds:
                dataset.set_epoch(epoch)
                epoch += 1
                for _ in loader:
                    count += 1
            rates[workers].append(count / (time.perf_counter() - start))
    return [statistics.median(rates[w]) for w in (0, 1, 2)]


def jitter_ratio(folder, model, rounds):
    mosaic, fmt, _ = rgt.loadMosaic(os.path.join(folder, sorted(os.listdir(folder))[0]))
    jitter = rg.ColorJitter.exposureChange(0.1, 4.0)
    out = {}
    for name, sampling in (("GAUSSIAN", rg.ShotNoiseSampling.GAUSSIAN), ("POISSON", rg.ShotNoiseSampling.POISSON)):
        options = rg.NoiseOptions(shotSampling=sampling)
        times = []
        for r in range(3 * rounds):
            start = time.perf_counter()
            rg.colorJitter(mosaic, fmt, model, jitter, options, seed=r)
            times.append(time.perf_counter() - start)
        out[name] = statistics.median(times)
    return out


def host():
    try:
        model = next(line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name"))
    except (OSError, StopIteration):
        model = platform.processor()
    return "%s, %d cores, CPU path %s, %s" % (model, os.cpu_count(), rg.cpuPathName(rg.activeCpuPath()),
                                             time.strftime("%Y-%m-%d"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0], allow_abbrev=False)
    parser.add_argument("--samples", type=int, default=4, help="files per container (12 MP each)")
    parser.add_argument("--rounds", type=int, default=3, help="passes over the files per measurement")
    parser.add_argument("--keep", metavar="DIR", help="write the files into DIR (new) and keep them")
    parser.add_argument("--loaders", metavar="FOLDER", help="only the DataLoader rates over FOLDER's files")
    args = parser.parse_args()
    if args.samples < 1 or args.rounds < 1:
        parser.error("--samples and --rounds must be >= 1")
    if args.loaders:
        model = rg.NoiseModel(0.25, 1.5, 0.8)
        print("| folder | policy | 0 workers | 1 worker | 2 workers |\n|---|---|---:|---:|---:|")
        for name in ("off", "default"):
            rates = loader_rates(args.loaders, model, policies()[name], args.rounds)
            print("| %s | %s | %.2f | %.2f | %.2f |" % (args.loaders, name, *rates))
        return
    if args.keep:
        os.makedirs(args.keep)
        make_folders(args.keep, args.samples)
        print("wrote %s/{npy,tif,png,dng}" % args.keep)
        return
    print("Host: %s; rawgment threads %d.\n" % (host(), rg.getNumThreads()))
    with tempfile.TemporaryDirectory() as root:
        model, folders = make_folders(root, args.samples)
        base = floor(folders["npy"], args.rounds)
        print("| floor (12 MP) | ms |\n|---|---:|")
        for name, seconds in base.items():
            print("| %s | %.1f |" % (name, 1e3 * seconds))
        print("\n| container | policy | read | shift | scale | jitter | blur | tensor | other | total (ms) | "
              "other / total |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        profiles = {}
        for ext in ("npy", "tif", "png", "dng"):
            for name, policy in policies().items():
                p = profile_samples(folders[ext], model, policy, args.rounds)
                profiles[(ext, name)] = p
                print("| %s | %s | %s | %.1f | %.0f%% |" % (
                    ext, name, " | ".join("%.1f" % (1e3 * p[k]) for k in ("read",) + STEPS + ("tensor", "other")),
                    1e3 * p["total"], 100 * p["other"] / p["total"]))
        npy, default = profiles[("npy", "off")], profiles[("npy", "default")]
        print("\nGoals (.npy): read %.2fx a memcpy of the mosaic (goal <= 2); the tensor pass %.2fx a memcpy of the "
              "float output into new memory, %.2fx into touched memory (goal <= 1.5); time outside the library's "
              "kernels (read, steps and tensor are the kernels) %.0f%% of the sample with the default policy, "
              "%.0f%% with jitter only (goal <= 15%%)." % (
                  npy["read"] / base["memcpy mosaic, touched memory"],
                  base["tensor pass, new tensor"] / base["memcpy tensor, new memory"],
                  base["tensor pass, touched memory"] / base["memcpy tensor, touched memory"],
                  100 * default["other"] / default["total"],
                  100 * profiles[("npy", "jitter only")]["other"] / profiles[("npy", "jitter only")]["total"]))
        print("\n| DataLoader, samples/s | policy | 0 workers | 1 worker | 2 workers | 2 over 1 |\n"
              "|---|---|---:|---:|---:|---:|")
        for ext in ("npy", "tif", "png", "dng"):
            for name in ("off", "jitter only", "default"):
                rates = loader_rates(folders[ext], model, policies()[name], args.rounds)
                print("| %s | %s | %.2f | %.2f | %.2f | %.2fx |" % (ext, name, *rates, rates[2] / rates[1]))
        ratio = jitter_ratio(folders["npy"], model, args.rounds)
        print("\ncolorJitter of 12 MP: GAUSSIAN %.1f ms, POISSON %.1f ms: %.2fx (goal <= 4x)." % (
            1e3 * ratio["GAUSSIAN"], 1e3 * ratio["POISSON"], ratio["POISSON"] / ratio["GAUSSIAN"]))


if __name__ == "__main__":
    main()
