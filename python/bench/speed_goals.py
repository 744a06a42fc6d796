#!/usr/bin/env python3
"""The speed goals of issue #37 on this host, in one run, as a Markdown table (a measurement, not a test).

Runs perf_augment and perf_calibration (every benchmark of the library once per CPU path this machine has)
and, with --python, the efficient numpy and torch jitters of bench_python.py against rawgment's; then
prints each goal's ratio on each path, the Philox words alone per version of the generator, and the host
(lscpu's model name, CPU family and model), the machine's best path and the date, as docs/performance.md
names them. The ratios are of medians of --repetitions runs, each pair measured in the same run.

    /usr/bin/python3 python/bench/speed_goals.py --build build/release [--repetitions 3] [--python] [--out F]

--python needs the module: PYTHONPATH=build/release/python.
"""
import argparse
import datetime
import json
import os
import subprocess
import sys
import tempfile

PATHS = ("baseline", "sse4.2", "avx2", "avx512")
PHILOX_VERSIONS = ("sse2", "avx2", "avx512_at_512_bits")
NORMALS = 12_000_000  # the benchmarks' frame: 4000 x 3000

# (goal, target, numerator, denominator): benchmark names with {path} for the path's own run.
RATIO_GOALS = (
    ("1. Tukey-lambda read noise / jitter", 2.0, "BM_Augment_colorJitterTukeyRead/{path}",
     "BM_Augment_colorJitter/{path}"),
    ("2. POISSON shot draws / jitter", 4.0, "BM_Augment_colorJitterPoisson/{path}", "BM_Augment_colorJitter/{path}"),
    ("3. burst statistics (groups of 8) / memcpy of the burst", 4.0, "BM_BurstStatistics_rawgment/{path}/8/6",
     "BM_BurstStatistics_memcpy"),
    ("4. a random scene / jitter", 5.0, "BM_Augment_randomScene/{path}", "BM_Augment_colorJitter/{path}"),
)
AUGMENT_FILTER = "memcpy|standardNormals|colorJitter/|TukeyRead|colorJitterPoisson|randomScene|philoxWords"
CALIBRATION_FILTER = "BurstStatistics_rawgment/[a-z0-9.]+/8/6|BurstStatistics_memcpy"


class MissingBenchmark(RuntimeError):
    pass


def median_times(report):
    """{benchmark name without its suffixes: median wall time in ms} from Google Benchmark's JSON report.

    With repetitions the medians are the "median" aggregates; a benchmark run once (no aggregate) gives its
    one time. The name loses the suffixes the harness adds (/iterations:3, /process_time, /real_time)."""
    unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}
    singles, medians = {}, {}
    for b in report["benchmarks"]:
        name = "/".join(part for part in b["run_name"].split("/")
                        if not part.startswith("iterations:") and part not in ("process_time", "real_time"))
        ms = b["real_time"] * unit[b["time_unit"]]
        if b.get("run_type") == "aggregate":
            if b.get("aggregate_name") == "median":
                medians[name] = ms
        else:
            singles.setdefault(name, []).append(ms)
    times = {name: sorted(v)[len(v) // 2] for name, v in singles.items()}
    times.update(medians)
    return times


def time_of(times, name):
    if name not in times:
        raise MissingBenchmark("benchmark %s is not in the report (is the build's perf_* current?)" % name)
    return times[name]


def goal_rows(times, cores):
    """The table's rows: (goal, target, {path: (value, met)}) for the paths present in `times`."""
    paths = [p for p in PATHS if "BM_Augment_colorJitter/%s" % p in times]
    if not paths:
        raise MissingBenchmark("no BM_Augment_colorJitter/<path> in the report")
    rows = []
    for goal, target, numerator, denominator in RATIO_GOALS:
        cells = {}
        for p in paths:
            ratio = time_of(times, numerator.format(path=p)) / time_of(times, denominator.format(path=p))
            cells[p] = ("%.2fx" % ratio, ratio <= target)
        rows.append((goal, "at most %gx" % target, cells))
    cells = {}
    for p in paths:
        per_core = NORMALS / (time_of(times, "BM_Augment_standardNormals/%s" % p) * 1e-3) / cores / 1e9
        cells[p] = ("%.2f G" % per_core, per_core >= 1.0)
    rows.append(("5. standard normals per second per core", "at least 1 G", cells))
    return paths, rows


def philox_row(times, cores):
    """Philox words per second per core of each version of the generator this CPU ran."""
    return {v: NORMALS / (times["BM_Augment_philoxWords/%s" % v] * 1e-3) / cores / 1e9
            for v in PHILOX_VERSIONS if "BM_Augment_philoxWords/%s" % v in times}


def run_benchmarks(binary, pattern, repetitions):
    """Runs one perf_* program on `pattern` and returns median_times() of its JSON report."""
    if not os.access(binary, os.X_OK):
        raise FileNotFoundError("%s not found: build with RAWGMENT_BUILD_PERF=ON (scripts/build.sh release)" % binary)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "report.json")
        print("running %s --benchmark_filter='%s' (%d repetitions)" % (os.path.basename(binary), pattern,
                                                                       repetitions), file=sys.stderr, flush=True)
        subprocess.run([binary, "--benchmark_filter=" + pattern, "--benchmark_repetitions=%d" % repetitions,
                        "--benchmark_out=" + out, "--benchmark_out_format=json"],
                       check=True, stdout=subprocess.DEVNULL)
        with open(out) as f:
            return median_times(json.load(f))


def host_line(best_path):
    """lscpu's model name, CPU family and model, the cores, the best path the benchmarks ran on, the date."""
    fields = {}
    try:
        lscpu = subprocess.run(["lscpu"], check=True, capture_output=True, text=True).stdout
        for line in lscpu.splitlines():
            key, _, value = line.partition(":")
            fields[key.strip()] = value.strip()
    except (OSError, subprocess.CalledProcessError):
        pass
    return "%s (family %s, model %s), %d cores, best path %s, %s" % (
        fields.get("Model name", "unknown CPU"), fields.get("CPU family", "?"), fields.get("Model", "?"),
        os.cpu_count(), best_path, datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"))


def python_row(repeats):
    """Goal 6: rawgment's jitter from Python against the efficient numpy and torch jitters (bench_python.py)."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import bench_python  # noqa: E402 (needs rawgment and torch; only with --python)

    raw, fmt, model, jitter = bench_python.jitter_frame()
    ours, best_np, best_torch, threads = bench_python.efficient_minima(raw, fmt, model, jitter, repeats)
    path = bench_python.rg.cpuPathName(bench_python.rg.activeCpuPath())
    return path, ours, best_np, best_torch, threads


def markdown(host, paths, rows, philox, python):
    lines = ["Host: %s." % host, "",
             "| goal | target | " + " | ".join(paths) + " | met on every path |",
             "|---|---|" + "---:|" * len(paths) + "---|"]
    for goal, target, cells in rows:
        lines.append("| %s | %s | %s | %s |" % (goal, target, " | ".join(cells[p][0] for p in paths),
                                                "yes" if all(cells[p][1] for p in paths) else "no"))
    if python:
        path, ours, best_np, best_torch, threads = python
        ratio = min(best_np, best_torch) / ours
        lines.append("| 6. Python against efficient numpy and torch (%d threads, in place; minima) | at least 10x "
                     "| %s | %s |" % (threads, " | ".join(
                         "%.1fx (%.1f against %.1f and %.1f ms)" % (ratio, ours * 1e3, best_np * 1e3, best_torch * 1e3)
                         if p == path else "" for p in paths), "yes" if ratio >= 10 else "no"))
    if philox:
        lines += ["", "Philox4x32-10 words alone, per second per core (the ceiling of goal 5): " + ", ".join(
            "%s %.2f G" % (v, rate) for v, rate in philox.items()) + "."]
    return "\n".join(lines) + "\n"


def write_atomically(path, text, replace=False):
    """Writes text to path through a synced temporary beside it; an existing path is kept (FileExistsError)
    unless replace, and is never left half-written either way."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=folder, prefix=".speed_goals.")
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        if replace:
            os.replace(tmp, path)
        else:
            os.link(tmp, path)  # fails when path exists: "never replaced" without a race
            os.unlink(tmp)
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], allow_abbrev=False)
    parser.add_argument("--build", default="build/release", help="the build folder with bin/perf_augment")
    parser.add_argument("--repetitions", type=int, default=3, help="runs of each benchmark; their median counts")
    parser.add_argument("--python", action="store_true", help="also goal 6 (needs the module on PYTHONPATH)")
    parser.add_argument("--python-rounds", type=int, default=5, help="interleaved rounds of goal 6")
    parser.add_argument("--out", help="also write the table to this file (atomically; an existing file is an "
                                      "error unless --replace)")
    parser.add_argument("--replace", action="store_true", help="let --out replace an existing file")
    args = parser.parse_args(argv)
    if args.repetitions < 1 or args.python_rounds < 1:
        parser.error("--repetitions and --python-rounds must be at least 1")
    # Checked before the benchmarks, which take minutes: a table that cannot be written is said at once.
    if args.out:
        folder = os.path.dirname(os.path.abspath(args.out))
        if not os.path.isdir(folder):
            parser.error("--out '%s': the folder '%s' does not exist" % (args.out, folder))
        if os.path.isdir(args.out):
            parser.error("--out '%s' is a folder" % args.out)
        if os.path.lexists(args.out) and not args.replace:
            parser.error("--out '%s' exists; it is not replaced without --replace" % args.out)
    binaries = os.path.join(args.build, "bin")
    times = run_benchmarks(os.path.join(binaries, "perf_augment"), AUGMENT_FILTER, args.repetitions)
    times.update(run_benchmarks(os.path.join(binaries, "perf_calibration"), CALIBRATION_FILTER, args.repetitions))
    cores = os.cpu_count()
    paths, rows = goal_rows(times, cores)
    python = python_row(args.python_rounds) if args.python else None
    # The benchmarks ran on every path the library found on this CPU, in PATHS' order: the last is the best.
    text = markdown(host_line(paths[-1]), paths, rows, philox_row(times, cores), python)
    sys.stdout.write(text)
    if args.out:
        write_atomically(args.out, text, replace=args.replace)


if __name__ == "__main__":
    main()
