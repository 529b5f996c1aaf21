"""Shared paths for the Python package's tests. They import sffd as installed (scripts/python.sh) or,
when that fails, from the build tree (build/python, what scripts/test.sh builds)."""
import os
import pathlib
import sys

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
try:
    import sffd  # noqa: F401
except ImportError:
    sys.path.insert(0, str(ROOT / "build" / "python"))

DATA = ROOT / "tests" / "data"
PYGEM = DATA / "pygem"
CLI = pathlib.Path(os.environ.get("SFFD_CLI", ROOT / "build" / "sffd"))


@pytest.fixture(scope="session")
def sphere():
    """The test sphere as (vertices, triangles, normals): 362 vertices, 720 triangles, normals from the file."""
    import sffd
    return sffd.read_mesh(str(DATA / "sphere.obj"))


def points_txt(path):
    return np.loadtxt(path, dtype=np.float64)
