"""Shared helpers of the Python module's tests: the CLI beside the module (WEDGE_BIN, set by ctest
from the build tree), a runner for it, and a tiny render setup so that each test takes well under
a second or two."""
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import wedge

WEDGE_BIN = os.environ.get("WEDGE_BIN", "")
SOURCE_DIR = Path(os.environ.get("WEDGE_SOURCE_DIR", Path(__file__).resolve().parents[2]))

# The render every test shares: small, a few samples, one fixed seed.
SCENE = "cornell"
RESOLUTION = (24, 16)
SPP = 2
SEED = 3


def run_cli(*args, check=True):
    """Runs `wedge ARGS...`; returns the CompletedProcess (text mode)."""
    assert WEDGE_BIN, "WEDGE_BIN is not set: run the tests through ctest (make test)"
    proc = subprocess.run([WEDGE_BIN, *map(str, args)], capture_output=True, text=True)
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def cli_error(*args):
    """The message `wedge ARGS...` prints for bad input (exit code 2), without 'wedge: error: '."""
    proc = run_cli(*args, check=False)
    assert proc.returncode == 2, (proc.returncode, proc.stderr)
    first = proc.stderr.splitlines()[0]
    prefix = "wedge: error: "
    assert first.startswith(prefix), proc.stderr
    return first[len(prefix):]


def read_pfm(path):
    """A PFM colour image as wedge writes it (little-endian, rows bottom to top) -> (H, W, 3) float32."""
    data = Path(path).read_bytes()
    header, rest = data.split(b"\n", 1)
    assert header == b"PF"
    size, rest = rest.split(b"\n", 1)
    scale, rest = rest.split(b"\n", 1)
    w, h = map(int, size.split())
    assert float(scale) < 0, "expected little-endian"
    return np.frombuffer(rest, dtype="<f4").reshape(h, w, 3)[::-1]


@pytest.fixture(scope="session")
def cornell():
    return wedge.load_scene(SCENE)
