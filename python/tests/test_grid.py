"""Grids through Python: dense round trips, .vdb files, metadata, memory checks, bad input."""

import copy
import math
import os

import warnings

import numpy as np
import pytest

import weft
from conftest import random_grid


def test_dense_round_trip_and_counts():
    g, a = random_grid()
    assert g.active_voxel_count == np.count_nonzero(a)
    nz = np.argwhere(a > 0)
    assert g.bbox == (tuple(nz.min(axis=0)), tuple(nz.max(axis=0)))
    assert g.sum() == pytest.approx(float(a.astype(np.float64).sum()), rel=1e-6)
    box = ((0, 0, 0), tuple(s - 1 for s in a.shape))
    np.testing.assert_array_equal(g.to_numpy(box), a)
    i, j, k = nz[len(nz) // 2]
    assert g.value(int(i), int(j), int(k)) == a[i, j, k]


def test_sub_box_and_offset_origin():
    rng = np.random.default_rng(1)
    a = rng.uniform(0.1, 1, size=(4, 3, 5)).astype(np.float32)
    g = weft.Grid.from_numpy(a, voxel_size=0.25, index_origin=(10, -3, 2))
    assert g.bbox == ((10, -3, 2), (13, -1, 6))
    np.testing.assert_array_equal(g.to_numpy(), a)  # default box: the active bbox
    sub = g.to_numpy(((11, -3, 3), (12, -2, 8)))
    assert sub.shape == (2, 2, 6)
    np.testing.assert_array_equal(sub[:, :, :4], a[1:3, 0:2, 1:5])
    np.testing.assert_array_equal(sub[:, :, 4:], 0)  # outside the data: background
    assert sub.dtype == np.float32


def test_save_load_keeps_values_transform_and_metadata(tmp_path):
    g, a = random_grid(voxel_size=0.125)
    g.origin = (1.0, -2.0, 0.5)
    g.set_metadata("note", "from pytest")
    path = tmp_path / "g.vdb"
    g.save(path)
    h = weft.load_grid(str(path))
    assert h.voxel_size == 0.125
    assert h.origin == pytest.approx((1.0, -2.0, 0.5))
    assert h.metadata["note"] == "from pytest"
    assert h.name == "density"
    np.testing.assert_array_equal(h.to_numpy(((0, 0, 0), (5, 4, 6))), a)


@pytest.mark.parametrize("n", [64, 128])
@pytest.mark.parametrize("fill", ["constant", "binary", "random"])
def test_save_load_round_trips_grids_whose_leaf_arrays_compress(tmp_path, n, fill):
    # A .vdb lists one mask byte and one size per leaf, compressed: constant and binary grids pack
    # (n/8)³ entries into far fewer bytes, and the file is still valid (docs/robustness.md, finding 4).
    if fill == "constant":
        a = np.full((n, n, n), 0.5, np.float32)
    elif fill == "binary":
        a = (np.indices((n, n, n)).sum(axis=0) % 2).astype(np.float32)
    else:
        a = np.random.default_rng(5).uniform(0.1, 1, size=(n, n, n)).astype(np.float32)
    path = tmp_path / "grid.vdb"
    weft.Grid.from_numpy(a, voxel_size=0.01).save(str(path))
    back = weft.load_grid(str(path))
    np.testing.assert_array_equal(back.to_numpy(((0, 0, 0), (n - 1, n - 1, n - 1))), a)


def test_memory_check_refuses_before_allocating():
    g, _ = random_grid()
    huge = ((0, 0, 0), (100000, 100000, 100000))  # 4e15 bytes
    with pytest.raises(weft.Error, match="MiB"):
        g.to_numpy(huge)
    with pytest.raises(weft.Error, match="limit"):
        g.to_numpy(((0, 0, 0), (99, 99, 99)), max_memory_mb=1.0)  # 3.8 MiB > 1 MiB
    assert g.to_numpy(((0, 0, 0), (99, 99, 99)), max_memory_mb=4.0).shape == (100, 100, 100)
    # A limit is finite and > 0 (as `weft export --max-memory-mb`); a tiny one is 1 byte, never "no limit".
    for bad in [0.0, -1.0, math.inf, math.nan]:
        with pytest.raises(weft.Error, match="max_memory_mb must be finite and > 0"):
            g.to_numpy(((0, 0, 0), (1, 1, 1)), max_memory_mb=bad)
    with pytest.raises(weft.Error, match="over the limit of 1 byte"):
        g.to_numpy(((0, 0, 0), (1, 1, 1)), max_memory_mb=1e-320)


def test_provenance_of_generated_cloth(small_cloth, small_cloth_spec):
    md = small_cloth.grid.metadata
    assert md["value_kind"] == "concentration"
    assert md["units"] == "mm"
    assert md["seed"] == str(small_cloth_spec["seed"])
    assert '"warp_count": 2' in md["generator"] or '"warp_count":2' in md["generator"]


@pytest.mark.parametrize("call, exc", [
    (lambda tmp: weft.Grid.load(os.path.join(tmp, "missing.vdb")), weft.Error),
    (lambda tmp: weft.Grid.load(3), TypeError),
    (lambda tmp: weft.Grid.load(_write(tmp, "junk.vdb", b"\x20\xbd\xb3\x56" + os.urandom(200))), weft.Error),
    (lambda tmp: weft.Grid.load(_write(tmp, "empty.vdb", b"")), weft.Error),
    (lambda tmp: weft.Grid.from_numpy(np.array([[1.0]])), weft.Error),
    (lambda tmp: weft.Grid.from_numpy(np.full((2, 2, 2), np.nan)), weft.Error),
    (lambda tmp: weft.Grid.from_numpy(np.full((2, 2, 2), -1.0)), weft.Error),
    (lambda tmp: weft.Grid.from_numpy(np.ones((2, 2, 2)), voxel_size=0.0), weft.Error),
    (lambda tmp: weft.Grid.from_numpy(np.ones((2, 2, 2)), voxel_size=np.nan), weft.Error),
    # below OpenVDB's smallest scale (h^3 >= 3e-15): 10 um given in metres
    (lambda tmp: weft.Grid.from_numpy(np.ones((2, 2, 2)), voxel_size=1e-5), weft.Error),
    (lambda tmp: weft.Grid(voxel_size=1e-30), weft.Error),
    (lambda tmp: weft.Grid.from_numpy("abc"), TypeError),
    (lambda tmp: weft.Grid.from_numpy(np.ones((2, 2, 2)), index_origin=(0, 0)), TypeError),
    (lambda tmp: random_grid()[0].to_numpy(((3, 3, 3), (0, 0, 0))), weft.Error),
    (lambda tmp: random_grid()[0].to_numpy("all"), TypeError),
    (lambda tmp: weft.Grid().to_numpy(), weft.Error),
    (lambda tmp: random_grid()[0].set_value(0, 0, 0, float("inf")), weft.Error),
    (lambda tmp: random_grid()[0].save(os.path.join(tmp, "no", "such", "dir", "g.vdb")), weft.Error),
])
def test_bad_input_raises(tmp_path, call, exc):
    with pytest.raises(exc):
        call(str(tmp_path))


@pytest.mark.parametrize("values, message", [
    (np.full((2, 2, 2), np.nan), r"^from_numpy: value nan at index \(0, 0, 0\); grid values must be finite and >= 0$"),
    (np.array([[[1.0, 2.0], [3.0, -4.0]]]), r"^from_numpy: value -4 at index \(0, 1, 1\); grid values must be finite"),
    # Finite, but past float32's range: named as given, not as the inf NumPy's cast would make it.
    (np.array([[[1.0, 2.0], [1e300, 4.0]]]),
     r"^Grid.from_numpy: values: value 1e\+300 at index \(0, 1, 0\) is past the range of a 32-bit float"),
], ids=["nan", "negative", "past-float"])
def test_a_bad_value_is_named_as_from_numpy_s(values, message):
    """The array's errors name the call the user made, not the library's dense copy under it."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # and no NumPy overflow warning on the way
        with pytest.raises(weft.Error, match=message):
            weft.Grid.from_numpy(values)


KMAX = 2**31 - 4097  # volume::kMaxIndex (docs/robustness.md "Index range")
BEYOND = r"the index range of a grid, \|index\| <= 2147479551 \(OpenVDB's 32-bit node origins overflow past it\)$"


@pytest.mark.parametrize("call, message", [
    # OpenVDB's dense copies stepped past 2^31 - 1 here: a crash (to_numpy) or a hang (from_numpy).
    (lambda: random_grid()[0].to_numpy(box=((2**31 - 1, 0, 0), (2**31 - 1, 0, 0))),
     r"^to_numpy: box \(2147483647, 0, 0\)\.\.\(2147483647, 0, 0\) reaches beyond "),
    (lambda: random_grid()[0].to_numpy(box=((0, 0, KMAX + 1), (0, 0, KMAX + 1))), r"^to_numpy: box .* reaches beyond "),
    (lambda: random_grid()[0].to_numpy(box=((-KMAX - 1, 0, 0), (0, 0, 0))), r"^to_numpy: box .* reaches beyond "),
    (lambda: weft.Grid.from_numpy(np.ones((1, 1, 1), np.float32), index_origin=(2**31 - 1, 0, 0)),
     r"^from_numpy: index_origin \(2147483647, 0, 0\) with shape \(1, 1, 1\) leaves"),
    (lambda: weft.Grid.from_numpy(np.ones((2, 1, 1), np.float32), index_origin=(KMAX, 0, 0)),
     r"^from_numpy: index_origin \(2147479551, 0, 0\) with shape \(2, 1, 1\) leaves"),
    (lambda: weft.Grid.from_numpy(np.ones((1, 1, 1), np.float32), index_origin=(0, -KMAX - 1, 0)),
     r"^from_numpy: index_origin \(0, -2147479552, 0\) with shape \(1, 1, 1\) leaves"),
    (lambda: weft.Grid(0.1).set_value(0, 0, 2**31 - 1, 1.0), r"^set_value: voxel .* is beyond "),
    (lambda: weft.Grid(0.1).set_value(-2**31, 0, 0, 1.0), r"^set_value: voxel .* is beyond "),
], ids=["to_numpy_int_max", "to_numpy_outer_child", "to_numpy_below", "from_numpy_int_max", "from_numpy_outer_child",
        "from_numpy_below", "set_value_int_max", "set_value_int_min"])
def test_an_index_beyond_the_index_range_is_refused_in_one_line(call, message):
    with pytest.raises(weft.Error, match=message + ".*" + BEYOND) as e:
        call()
    assert "\n" not in str(e.value)


def test_the_last_index_of_the_range_round_trips():
    for corner in ((KMAX, -KMAX, 0), (-KMAX, 0, KMAX)):
        g = weft.Grid.from_numpy(np.full((1, 1, 1), 0.5, np.float32), index_origin=corner)
        assert g.bbox == (corner, corner)
        np.testing.assert_array_equal(g.to_numpy(), [[[0.5]]])
        g.set_value(*corner, 0.25)
        assert g.value(*corner) == 0.25


def test_a_box_far_from_index_zero_round_trips():
    """A box past index 2^30 (|min + max| > 2^31 - 1) crashed to_numpy (SIGSEGV): OpenVDB's parallel
    dense copy split it at (min + max) >> 1 in int32 (docs/robustness.md "Index range")."""
    values = np.random.default_rng(5).random((8, 8, 8)).astype(np.float32) + 0.01
    for far in (2**30, KMAX - 7, -2**31 + 5000):
        for axis in range(3):
            origin = [3, -2, 0]
            origin[axis] = far
            g = weft.Grid.from_numpy(values, voxel_size=0.02, index_origin=tuple(origin))
            np.testing.assert_array_equal(g.to_numpy(), values)


def test_copies_are_independent_grids():
    """docs/python.md (Grid): copy.copy and copy.deepcopy give a new grid with the same values,
    metadata, voxel size and origin; changing the copy leaves the original as it was."""
    g, a = random_grid()
    g.set_metadata("weft:units", "mm")
    g.origin = (0.25, -1.5, 3.0)
    for c in (copy.copy(g), copy.deepcopy(g), copy.deepcopy({"g": g})["g"]):
        assert c is not g
        assert (c.voxel_size, c.origin, c.bbox, c.metadata, c.name) == (g.voxel_size, g.origin, g.bbox, g.metadata,
                                                                        g.name)
        np.testing.assert_array_equal(c.to_numpy(), g.to_numpy())
        i, j, k = g.bbox[0]
        c.set_value(i, j, k, 7.0)
        c.set_metadata("weft:units", "m")
        assert g.value(i, j, k) != 7.0 and g.metadata["weft:units"] == "mm"
    np.testing.assert_array_equal(g.to_numpy(((0, 0, 0), tuple(s - 1 for s in a.shape))), a)


def test_the_smallest_voxel_openvdb_represents_is_accepted_and_named():
    # 15 um in metres is just above OpenVDB's limit (h >= 1.443e-5); 14 um is refused in weft's words.
    g = weft.Grid.from_numpy(np.ones((2, 2, 2)), voxel_size=1.5e-5)
    assert g.voxel_size == pytest.approx(1.5e-5)
    with pytest.raises(weft.Error, match="smaller unit"):
        weft.Grid.from_numpy(np.ones((2, 2, 2)), voxel_size=1.4e-5)


def test_an_origin_openvdb_cannot_copy_is_refused_when_the_grid_is_made(tmp_path):
    # OpenVDB recomputes h = (t + h) - t on every copy and write (t = origin + h/2): 0 from
    # |t| = 2^54 h on, where origin 1e20 made save fail ("Non-zero scale values required").
    values = np.ones((6, 5, 4), np.float32) * 0.3
    for origin in (2.0**52 * 0.1, -(2.0**52) * 0.1, 1e15):
        g = weft.Grid.from_numpy(values, voxel_size=0.1, origin=[origin, 0, 0])
        g.save(tmp_path / "f.vdb")
        back = weft.load_grid(tmp_path / "f.vdb")
        assert back.voxel_size == 0.1 and back.origin == g.origin
        # OpenVDB's own copy would have voxels of 0.125 at 1e15: weft's keep the grid's
        assert weft.extinction_grid(g, sigma=2.0).voxel_size == 0.1
    for origin in (2.0**54 * 0.1, 1e20):
        with pytest.raises(weft.Error, match=r"^grid 'density': origin \(.*\) is too far from 0 for voxels of 0.1: "):
            weft.Grid.from_numpy(values, voxel_size=0.1, origin=[origin, 0, 0])


def _write(folder, name, data):
    path = os.path.join(folder, name)
    with open(path, "wb") as f:
        f.write(data)
    return path


def test_failed_save_leaves_no_file(tmp_path):
    target = tmp_path / "out.vdb"
    os.mkdir(target)  # a folder where the file should go
    with pytest.raises(weft.Error):
        random_grid()[0].save(target)
    assert os.listdir(tmp_path) == ["out.vdb"]
