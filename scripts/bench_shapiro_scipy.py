#!/usr/bin/python3
"""Times scipy.stats.shapiro in a Python loop over the paper's calibration set (27,648 series of
n = 100) and compares it with cv::rawgment's batched Shapiro-Wilk from the same machine.

Usage: /usr/bin/python3 scripts/bench_shapiro_scipy.py [build/release/bin/perf_normality]
Needs SciPy (Debian package python3-scipy); prints a note and exits 0 without it.
"""
import json
import subprocess
import sys
import time

SERIES, LENGTH = 27648, 100


def main():
    perf = sys.argv[1] if len(sys.argv) > 1 else "build/release/bin/perf_normality"
    try:
        import numpy as np
        from scipy import stats
    except ImportError:
        print("SciPy is not installed for /usr/bin/python3 (apt-get install python3-scipy): skipping")
        return 0
    rng = np.random.default_rng(2023)
    data = rng.normal(1000.0, 30.0, size=(SERIES, LENGTH))
    start = time.perf_counter()
    for row in data:
        stats.shapiro(row)
    scipy_seconds = time.perf_counter() - start

    out = subprocess.run([perf, "--benchmark_filter=BM_ShapiroWilk", "--benchmark_format=json"],
                         check=True, capture_output=True, text=True).stdout
    times = {b["name"]: b["real_time"] * {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[b["time_unit"]]
             for b in json.loads(out)["benchmarks"]}
    batch = times["BM_ShapiroWilk_batch/real_time"]
    single = times["BM_ShapiroWilk_single_loop/real_time"]
    print(f"scipy.stats.shapiro loop : {scipy_seconds * 1e3:9.1f} ms ({scipy_seconds / SERIES * 1e6:.2f} us/series)")
    print(f"rawgment single-form loop: {single * 1e3:9.1f} ms ({single / SERIES * 1e6:.2f} us/series)")
    print(f"rawgment batch           : {batch * 1e3:9.1f} ms ({batch / SERIES * 1e6:.2f} us/series)")
    print(f"batch vs single loop: {single / batch:.1f}x faster; batch vs SciPy loop: {scipy_seconds / batch:.1f}x faster")
    return 0


if __name__ == "__main__":
    sys.exit(main())
