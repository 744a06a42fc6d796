#!/usr/bin/python3
# This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
"""A/B of two builds of one Google Benchmark program, in one run, beside an A/A of the old one.

Each round runs old (A), new (B) and old again (A'), one after the other, so that a drift of the
machine (another load, a turbo state) falls on both sides; every run gives each case `--repetitions`
timings. The table gives per case the median of A, B and A' over all rounds, B/A and A'/A: B/A says
what the change costs, A'/A how far two runs of the same binary differ on this machine, so a B/A
inside the A/A spread is no cost that this machine can see.

    scripts/ab-bench.py --old OLD/bin/perf_augment --new build/release/bin/perf_augment \\
        --filter 'BM_Augment_(colorJitter|motionBlur13|scale103|randomScene)[A-Za-z]*/avx512' --rounds 3
"""
import argparse
import json
import statistics
import subprocess
import sys


def run(binary, pattern, repetitions):
    out = subprocess.run(
        [binary, "--benchmark_filter=" + pattern, "--benchmark_format=json",
         "--benchmark_repetitions=%d" % repetitions, "--benchmark_report_aggregates_only=false"],
        check=True, capture_output=True, text=True).stdout
    times = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("run_type") != "iteration":
            continue
        times.setdefault(b["run_name"], []).append(b["real_time"] * {"ns": 1e-6, "us": 1e-3, "ms": 1.0,
                                                                      "s": 1e3}[b["time_unit"]])
    return times


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--old", required=True, help="the benchmark program before the change (A)")
    p.add_argument("--new", required=True, help="the same program after it (B)")
    p.add_argument("--filter", required=True, help="--benchmark_filter of the cases to compare")
    p.add_argument("--rounds", type=int, default=3, help="rounds of A, B, A' (default 3)")
    p.add_argument("--repetitions", type=int, default=3, help="timings of each case per run (default 3)")
    a = p.parse_args()
    runs = {"A": {}, "B": {}, "A'": {}}
    for r in range(a.rounds):
        for side, binary in (("A", a.old), ("B", a.new), ("A'", a.old)):
            print("round %d/%d: %s" % (r + 1, a.rounds, side), file=sys.stderr, flush=True)
            for name, t in run(binary, a.filter, a.repetitions).items():
                runs[side].setdefault(name, []).extend(t)
    names = [n for n in runs["A"] if n in runs["B"]]
    if not names:
        sys.exit("ab-bench: no case ran in both programs under that filter")
    print("| case | A (ms) | B (ms) | A' (ms) | B/A | A'/A |")
    print("|---|---:|---:|---:|---:|---:|")
    for n in names:
        med = {s: statistics.median(runs[s][n]) for s in runs}
        print("| %s | %.2f | %.2f | %.2f | %.3f | %.3f |" % (n.replace("/process_time/real_time", ""), med["A"],
                                                            med["B"], med["A'"], med["B"] / med["A"],
                                                            med["A'"] / med["A"]))


if __name__ == "__main__":
    main()
