"""Shared fixtures of the weft pytest suite (run by CTest: python.test_*)."""

import os
import subprocess

import numpy as np
import pytest

import weft


@pytest.fixture(scope="session")
def weft_bin():
    """The weft binary of the same build (CTest sets WEFT_BIN)."""
    path = os.environ.get("WEFT_BIN")
    if not path or not os.path.exists(path):
        pytest.fail("WEFT_BIN must name the weft binary of this build (CTest sets it)")
    return path


@pytest.fixture(scope="session")
def run_cli(weft_bin):
    def run(*args, cwd=None):
        result = subprocess.run([weft_bin, "--quiet", *map(str, args)], cwd=cwd, capture_output=True, text=True)
        assert result.returncode == 0, result.stderr
        return result.stdout
    return run


@pytest.fixture(scope="session")
def small_cloth_spec():
    """A cloth that generates and voxelizes in well under a second."""
    return {"pattern": "plain", "warp_count": 2, "weft_count": 2, "voxel_size": 0.02, "seed": 5,
            "warp_yarn": {"fiber_count": 12}, "weft_yarn": {"fiber_count": 12}}


@pytest.fixture(scope="session")
def small_cloth(small_cloth_spec):
    return weft.gen(small_cloth_spec)


def random_grid(shape=(6, 5, 7), seed=3, zero_fraction=0.4, voxel_size=0.5):
    """A grid of random concentrations with holes, and its dense array."""
    rng = np.random.default_rng(seed)
    a = rng.uniform(0.05, 1.0, size=shape).astype(np.float32)
    a[rng.uniform(size=shape) < zero_fraction] = 0.0
    return weft.Grid.from_numpy(a, voxel_size=voxel_size), a
