"""The fibre ground truth from Python (docs/validate.md, Fibre ground truth): the same numbers as
the closed form of one straight fibre, and the fibres of a weft gen grid."""
import os
import subprocess

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


def test_a_grid_moved_after_gen_is_refused_not_measured_against_missing_fibres(small_cloth):
    # The same voxels at another index origin (world position moved by 40 voxels along x), the
    # provenance copied: the regenerated fibres no longer lie in the grid.
    g = small_cloth.grid
    lo, _ = g.bbox
    moved = weft.Grid.from_numpy(g.to_numpy(), voxel_size=g.voxel_size,
                                 index_origin=(lo[0] + 40, lo[1], lo[2]))
    for key, value in g.metadata.items():
        moved.set_metadata(key, value)
    assert len(weft.Fibres.of_grid(g)) > 0
    with pytest.raises(weft.Error, match="moved or edited after weft gen"):
        weft.Fibres.of_grid(moved)


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
