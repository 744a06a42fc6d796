"""`cmake --install` puts an importable package into the interpreter's folder under the prefix, with
its stub, and the extension finds the installed library (no build tree on the path)."""
import os
import subprocess
import sys

import numpy as np

import rawgment as rg


def test_installed_package_imports_and_runs(tmp_path):
    build = os.environ["RAWGMENT_BUILD_DIR"]
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    site = prefix / "lib" / ("python%d.%d" % sys.version_info[:2]) / "dist-packages"
    assert (site / "rawgment" / "_rawgment.pyi").exists() and (site / "rawgment" / "py.typed").exists()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH")}
    env["PYTHONPATH"] = str(site)
    code = ("import rawgment, numpy; print(rawgment.__file__); "
            "print(rawgment.colorJitter(numpy.full((8, 8), 100, numpy.uint16), rawgment.RawFormat(), "
            "rawgment.NoiseModel(1, 1, 1), rawgment.ColorJitter.exposureChange(0.5, 1), seed=1)[0].sum())")
    # From another folder: the build tree's package must not be found through the working directory.
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=str(tmp_path), check=True, capture_output=True,
                         text=True)
    lines = out.stdout.split()
    assert lines[0].startswith(str(site))
    expected = rg.colorJitter(np.full((8, 8), 100, np.uint16), rg.RawFormat(), rg.NoiseModel(1, 1, 1),
                              rg.ColorJitter.exposureChange(0.5, 1), seed=1)[0].sum()
    assert int(lines[1]) == int(expected)
