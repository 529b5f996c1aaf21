"""SFFD_* variables set to a value docs/CLI.md ("Environment variables") does not give them are refused from
Python as the tool refuses them, when a device is opened or listed, instead of being taken as a default."""
import os
import pathlib
import re
import subprocess
import sys

import pytest

import sffd

REFUSED = [
    ("SFFD_CPU_AVX2", "banana", "0 or 1"),
    ("SFFD_CPU_THREADS", "0", "an integer 1..256"),
    ("SFFD_DEVICE_TIMEOUT", "abc", "a number of seconds > 0, like 60 or 0.5"),
    ("SFFD_SHADER_CACHE_DISABLE", "maybe", "0 or 1"),
    ("SFFD_STRICT_ROUNDING", "fix", "fixup or driver"),
    ("SFFD_TRACE_COMPILE", "yes", "0 or 1"),
    ("SFFD_VK_STAGING", "yes", "0 or 1"),
    ("SFFD_VK_VALIDATION", "true", "0 or 1"),
    ("SFFD_GL_PROVIDER", "vulkan", "egl, osmesa or glfw"),
    ("SFFD_GLES_LIMITS", "phone", "minimum or device"),
]


@pytest.mark.parametrize("variable,value,takes", REFUSED)
def test_a_value_the_docs_do_not_give_is_refused(monkeypatch, variable, value, takes):
    monkeypatch.setenv(variable, value)
    message = re.escape(f"{variable} must be {takes}, not '{value}'")
    with pytest.raises(sffd.InputError, match=message):
        sffd.Device("cpu")
    with pytest.raises(sffd.InputError, match=message):
        sffd.devices()


def test_documented_values_are_taken(monkeypatch):
    for variable, value in [("SFFD_CPU_AVX2", "0"), ("SFFD_CPU_THREADS", "3"), ("SFFD_VK_STAGING", "1"), ("SFFD_GL_PROVIDER", "osmesa")]:
        monkeypatch.setenv(variable, value)
    assert sffd.Device("cpu").name == "CPU reference (3 threads)"


def test_a_fresh_process_raises_before_any_work(tmp_path):
    # What a user sees: the first deform opens the device, and that raises; nothing ran on the AVX2 copy.
    code = ("import numpy as np, sffd\n"
            "v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float); t = np.array([[0, 1, 2]], np.uint32)\n"
            "sffd.deform(v, t, sffd.Lattice.fitted(v), backend='cpu')\n")
    env = dict(os.environ, SFFD_CPU_AVX2="banana", PYTHONPATH=str(pathlib.Path(sffd.__file__).parents[1]))
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1
    assert r.stderr.strip().endswith("sffd.InputError: SFFD_CPU_AVX2 must be 0 or 1, not 'banana'"), r.stderr
