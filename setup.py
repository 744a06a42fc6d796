"""The build of `pip install .` and `pip wheel .`: setuptools runs the project's CMake build of the Python
module (no tests, benchmarks or apps) and takes the package `rawgment` (with the shared library inside it,
found by the module through $ORIGIN) from CMake's install into a staging folder. The studies (studies/) are
not part of it: they run from a build tree.

The CMake build folder is build/pip (RAWGMENT_PIP_BUILD_DIR to change it), so that `pip install .` and
`pip wheel .` after it compile once."""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent

# What the build needs before CMake can say more: each with the Debian package that has it.
BUILD_TOOLS = [
    ("cmake", "cmake"),
    ("c++", "build-essential"),
    ("doxygen", "doxygen"),
]


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    found = re.search(r"project\(Rawgment VERSION ([0-9.]+)", text)
    if not found:
        raise SystemExit("setup.py: no `project(Rawgment VERSION x.y.z)` in CMakeLists.txt")
    return found.group(1)


def check_build_tools():
    missing = [(tool, package) for tool, package in BUILD_TOOLS if shutil.which(tool) is None]
    try:
        import pybind11  # noqa: F401
    except ImportError:
        missing.append(("pybind11 (Python)", "python3-pybind11 pybind11-dev"))
    try:
        import numpy  # noqa: F401
    except ImportError:
        missing.append(("numpy", "python3-numpy"))
    if missing:
        raise SystemExit("rawgment needs to build: %s.\nOn Debian 12: apt install %s (and run pip with "
                         "--no-build-isolation in a venv made with --system-site-packages)"
                         % (", ".join(t for t, _ in missing), " ".join(p for _, p in missing)))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        check_build_tools()
        build = Path(os.environ.get("RAWGMENT_PIP_BUILD_DIR", ROOT / "build" / "pip")).resolve()
        stage = build / "stage"
        generator = ["-G", "Ninja"] if shutil.which("ninja") else []
        configure = ["cmake", "-S", str(ROOT), "-B", str(build), *generator, "-DCMAKE_BUILD_TYPE=Release",
                     "-DRAWGMENT_PYTHON_WHEEL=ON", "-DRAWGMENT_BUILD_PYTHON=ON", "-DRAWGMENT_BUILD_TESTS=OFF",
                     "-DRAWGMENT_BUILD_PERF=OFF", "-DRAWGMENT_BUILD_APPS=OFF", "-DRAWGMENT_BUILD_SAMPLES=OFF",
                     "-DRAWGMENT_PYTHON_INSTALL_DIR=python", "-DPython3_EXECUTABLE=" + sys.executable]
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build), "--parallel", str(os.cpu_count() or 1)], check=True)
        shutil.rmtree(stage, ignore_errors=True)
        subprocess.run(["cmake", "--install", str(build), "--prefix", str(stage)], check=True,
                       stdout=subprocess.DEVNULL)
        target = Path(self.build_lib)
        shutil.rmtree(target / "rawgment", ignore_errors=True)
        shutil.copytree(stage / "python" / "rawgment", target / "rawgment", symlinks=False)
        module = target / "rawgment" / Path(self.get_ext_filename(ext.name)).name
        if not module.exists():
            raise SystemExit("setup.py: CMake installed no %s" % module)


setup(
    version=project_version(),
    packages=[],
    ext_modules=[Extension("rawgment._rawgment", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
