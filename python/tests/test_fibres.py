"""The fibre ground truth from Python (docs/validate.md, Fibre ground truth): the same numbers as
the closed form of one straight fibre, and the fibres of a weft gen grid."""
import os
import subprocess

import numpy as np
import pytest

import weft


def test_single_fibre_blocks_its_shadow():
    # One opaque fibre of radius 0.05 across a z beam on cell-centred rays: 10 of 100 rows blocked.
    f = weft.Fibres([[(-0.5, 0.5, 0.5), (1.5, 0.5, 0.5)]], 0.05)
    assert len(f) == 1 and f.segments == 1
    depths, T, stderr = weft.measure_fibre_beam(f, direction="z", box=((0, 0, 0), (1, 1, 1)), cell=0.01)
    assert T[0] == 1.0
    assert T[-1] == pytest.approx(0.9, abs=1e-12)
    # Internal extinction: more light through than opaque fibres.
    c = weft.measure_fibre_beam(f, direction="z", box=((0, 0, 0), (1, 1, 1)), cell=0.01, extinction=20.0)
    assert 0.9 < c.T[-1] < 1.0


def test_fibres_of_a_generated_grid(tmp_path):
    out = tmp_path / "gen"
    subprocess.run([os.environ["WEFT_BIN"], "--quiet", "gen", "--yarns", "2x2", "--voxel-size", "0.02",
                    "--write", "grid", "--out", str(out)], check=True)
    g = weft.Grid.load(str(out / "cloth.vdb"))
    f = weft.Fibres.of_grid(g)
    assert len(f) > 0
    fibre = weft.measure_fibre_beam(f, g, direction="z")
    voxel = weft.measure_beam(g, "z", sigma=float(g.metadata["weft:sigma_per_concentration"]))
    assert len(fibre) == len(voxel)
    assert abs(fibre.T[-1] - voxel.T[-1]) < 0.05
    mu = weft.extinction_grid(g, float(g.metadata["weft:sigma_per_concentration"]), "opaque")
    assert len(weft.measure_beam(mu, "z")) == len(voxel)


def test_grid_without_fibres_is_refused():
    g = weft.Grid(0.1)
    g.set_value(0, 0, 0, 0.5)
    with pytest.raises(weft.Error, match="does not name its fibres"):
        weft.Fibres.of_grid(g)


def copy_of(g, **placement):
    """The voxels of g through numpy, placed by `placement` (from_numpy's keywords), with every
    metadata key copied: the provenance follows the grid wherever it is put."""
    moved = weft.Grid.from_numpy(g.to_numpy(), voxel_size=placement.pop("voxel_size", g.voxel_size), **placement)
    for key, value in g.metadata.items():
        moved.set_metadata(key, value)
    return moved


def test_a_grid_moved_after_gen_is_refused_not_measured_against_missing_fibres(small_cloth):
    # The same voxels at another index origin (world position moved by 40 voxels along x), the
    # provenance copied: the regenerated fibres no longer lie in the grid.
    g = small_cloth.grid
    lo, _ = g.bbox
    moved = copy_of(g, index_origin=(lo[0] + 40, lo[1], lo[2]), origin=g.origin)
    assert len(weft.Fibres.of_grid(g)) > 0
    with pytest.raises(weft.Error, match=r"moved relative to its fibres: .* low corner by \(\+40, \+0, \+0\) voxels"):
        weft.Fibres.of_grid(moved)


def test_the_fibres_of_a_grid_are_measured_only_on_a_grid_on_their_lattice(small_cloth):
    """docs/validate.md §Fibre ground truth: Fibres.of_grid keeps the lattice weft gen voxelized
    the fibres on, and measure_fibre_beam refuses a grid not on it (moved half a voxel with its
    provenance copied, or another grid), as Fibres.of_grid and weft measure --fibres refuse it;
    fibres built from arrays have no lattice and take any grid."""
    g = small_cloth.grid
    lo, _ = g.bbox
    f = weft.Fibres.of_grid(g)
    moved = copy_of(g, index_origin=lo)  # from_numpy's default origin: half a voxel off
    with pytest.raises(weft.Error, match=r"^measure_fibre_beam: grid '.*': the grid was moved relative to its "
                                         r"fibres: its active box's low corner by \(-0\.5, -0\.5, -0\.5\) voxels") as e:
        weft.measure_fibre_beam(f, moved, direction="x")
    assert "\n" not in str(e.value)
    other = weft.Grid.from_numpy(np.ones((3, 3, 3), np.float32), voxel_size=g.voxel_size, origin=g.origin)
    with pytest.raises(weft.Error, match=r"^measure_fibre_beam: grid .* moved relative to its fibres"):
        weft.measure_fibre_beam(f, other, direction="x")
    # On the lattice (the same world at other indices): the same curve.
    h = g.voxel_size
    reindexed = copy_of(g, origin=tuple(o + i * h for o, i in zip(g.origin, lo)))
    np.testing.assert_array_equal(weft.measure_fibre_beam(f, reindexed, direction="x").T,
                                  weft.measure_fibre_beam(f, g, direction="x").T)
    plain = weft.Fibres([[(-1.0, 0.1, 0.0), (2.0, 0.1, 0.0)]], 0.05)
    assert len(weft.measure_fibre_beam(plain, moved, direction="x")) > 0


def test_fibres_are_compared_only_with_the_grid_on_their_lattice(small_cloth):
    """docs/validate.md §Fibre ground truth: the grid must sit where weft gen voxelized the fibres
    (its voxel size, origin and active box as recorded), within rounding. A shift of a fraction
    of a voxel or of one voxel once passed a tolerance of two voxels and gave another
    voxelization error (the voxels of other rays); each is refused with how far it moved."""
    g = small_cloth.grid
    lo, _ = g.bbox
    h = g.voxel_size
    assert list(g.origin) == [0.0, 0.0, 0.0]  # weft gen's lattice
    shifted = {
        "half a voxel (from_numpy's default origin, -h/2)": (copy_of(g, index_origin=lo), r"-0\.5, -0\.5, -0\.5"),
        "a quarter voxel": (copy_of(g, index_origin=lo, origin=(0.25 * h, 0.0, 0.0)), r"\+0\.25, \+0, \+0"),
        "one voxel": (copy_of(g, index_origin=(lo[0], lo[1] + 1, lo[2]), origin=g.origin), r"\+0, \+1, \+0"),
        "two voxels": (copy_of(g, index_origin=(lo[0], lo[1], lo[2] - 2), origin=g.origin), r"\+0, \+0, -2"),
    }
    for what, (moved, by) in shifted.items():
        with pytest.raises(weft.Error, match="grid was moved relative to its fibres: its active box's low corner by "
                                             r"\(" + by + r"\) voxels") as e:
            weft.Fibres.of_grid(moved)
        assert "\n" not in str(e.value), what
    resampled = copy_of(g, voxel_size=2 * h, index_origin=lo, origin=g.origin)
    with pytest.raises(weft.Error, match=r"grid was resampled relative to its fibres: voxels of 0\.04 against the 0\.02"):
        weft.Fibres.of_grid(resampled)
    # Cut: one face of the active box moved, the other not.
    a = g.to_numpy()
    a[:, :, -1] = 0
    cut = weft.Grid.from_numpy(a, voxel_size=h, index_origin=lo, origin=g.origin)
    for key, value in g.metadata.items():
        cut.set_metadata(key, value)
    with pytest.raises(weft.Error, match=r"low corner by \(\+0, \+0, \+0\) voxels and its high corner by "
                                         r"\(\+0, \+0, -1\)"):
        weft.Fibres.of_grid(cut)
    # A grid that records no lattice (an earlier weft gen) cannot be checked: refused, not trusted.
    legacy = weft.Grid.from_numpy(g.to_numpy(), voxel_size=h, index_origin=lo, origin=g.origin)
    for key, value in g.metadata.items():
        if key != "voxelized_lattice":
            legacy.set_metadata(key, value)
    with pytest.raises(weft.Error, match="does not record the lattice its fibres were voxelized on"):
        weft.Fibres.of_grid(legacy)


def test_the_documented_round_trip_keeps_the_grid_on_its_fibres_lattice(small_cloth):
    """docs/python.md (Grid.from_numpy): to_numpy -> from_numpy with the grid's voxel size, index
    box and origin is exact; so is the same world with other indices (the origin moved back)."""
    g = small_cloth.grid
    lo, _ = g.bbox
    h = g.voxel_size
    same = copy_of(g, index_origin=lo, origin=g.origin)
    assert (same.origin, same.voxel_size, same.bbox) == (g.origin, g.voxel_size, g.bbox)
    assert np.array_equal(same.to_numpy(), g.to_numpy())
    reindexed = copy_of(g, origin=tuple(o + i * h for o, i in zip(g.origin, lo)))
    assert reindexed.bbox[0] == (0, 0, 0)
    fibres = weft.Fibres.of_grid(g)
    for grid in (same, reindexed):
        f = weft.Fibres.of_grid(grid)
        assert (len(f), f.volume) == (len(fibres), fibres.volume)
        for axis in ("x", "z"):
            np.testing.assert_array_equal(weft.measure_fibre_beam(f, grid, direction=axis).T,
                                          weft.measure_fibre_beam(fibres, g, direction=axis).T)
    # Exact far from 0 too, where origin + h/2 rounds: the origin reads back bit for bit.
    for origin in ((1234.5678, -0.001, 3e-9), (-7e5 / 3, 1e6 + 0.1, -0.3)):
        far = weft.Grid.from_numpy(g.to_numpy(), voxel_size=h, index_origin=lo, origin=origin)
        back = weft.Grid.from_numpy(far.to_numpy(), voxel_size=far.voxel_size, index_origin=far.bbox[0],
                                    origin=far.origin)
        assert (back.origin, back.voxel_size, back.bbox) == (far.origin, far.voxel_size, far.bbox)
        np.testing.assert_array_equal(weft.measure_beam(back, "x", sigma=50.0).T,
                                      weft.measure_beam(far, "x", sigma=50.0).T)


@pytest.mark.parametrize("box, words", [
    (((1, 1, 1), (0, 0, 0)), "box min must be <= max per axis"),
    (((0, 0, 1), (1, 1, 0)), "box min must be <= max per axis"),
    (((0, float("nan"), 0), (1, 1, 1)), "box corners must be finite"),
    (((0, 0, 0), (1, 1, float("inf"))), "box corners must be finite"),
])
def test_a_bad_box_is_refused(box, words):
    # Once an inverted box returned "2 depths to -1" with T = 1, as if measured.
    f = weft.Fibres([[(0, 0, 0), (1, 0, 0)]], 0.1)
    with pytest.raises(weft.Error, match="fibre beam: " + words):
        weft.measure_fibre_beam(f, box=box, cell=0.1)
    for cell in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(weft.Error, match="cell"):
            weft.measure_fibre_beam(f, box=((0, 0, 0), (1, 1, 1)), cell=cell)
