"""The wheel of the sffd package (scripts/python.sh). CMake builds the extension in the project's
build folder (target sffd_python, python/CMakeLists.txt), which assembles the whole package in
<build>/python/sffd: the .py files, _sffd and libsffd beside it (found through $ORIGIN). That folder
goes into the wheel as it is, so an installed wheel needs nothing from the build tree.
Environment: SFFD_BUILD_DIR (default <repo>/build), SFFD_PYTHON (the interpreter built for)."""
import os
import pathlib
import re
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

ROOT = pathlib.Path(__file__).resolve().parent.parent
BUILD = pathlib.Path(os.environ.get("SFFD_BUILD_DIR", ROOT / "build"))


class CMakeBuildPy(build_py):
    def run(self):
        python = os.environ.get("SFFD_PYTHON", sys.executable)
        subprocess.check_call(["cmake", "-S", str(ROOT), "-B", str(BUILD), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                               "-DSFFD_BUILD_PYTHON=ON", f"-DPython_EXECUTABLE={python}"], stdout=subprocess.DEVNULL)
        subprocess.check_call(["cmake", "--build", str(BUILD), "--target", "sffd_python", "-j", str(min(os.cpu_count() or 1, 2))])
        dest = pathlib.Path(self.build_lib) / "sffd"
        shutil.rmtree(dest, ignore_errors=True)
        shutil.copytree(BUILD / "python" / "sffd", dest, ignore=shutil.ignore_patterns("__pycache__"))


class BinaryDistribution(Distribution):
    def has_ext_modules(self):   # a platform wheel: the package holds compiled libraries
        return True


def header_version():
    """sffd.h's SFFD_VERSION_*: the one place of the version."""
    text = (ROOT / "include" / "sffd" / "sffd.h").read_text()
    parts = [re.search(rf"^#define SFFD_VERSION_{p} (\d+)$", text, re.M).group(1) for p in ("MAJOR", "MINOR", "PATCH")]
    return ".".join(parts)


setup(version=header_version(), packages=["sffd"], cmdclass={"build_py": CMakeBuildPy}, distclass=BinaryDistribution)
