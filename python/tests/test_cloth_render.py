"""weft.gen and weft.render through Python: identity with the CLI, fibre arrays, bad input."""

import json
import os

import numpy as np
import pytest

import weft


def test_gen_identical_to_cli(tmp_path, run_cli, small_cloth, small_cloth_spec):
    spec_file = tmp_path / "spec.json"
    spec_file.write_text(json.dumps(small_cloth_spec))
    run_cli("gen", "--config", spec_file, "--out", tmp_path / "cli")
    cli = weft.load_grid(tmp_path / "cli" / "cloth.vdb")
    g = small_cloth.grid
    assert cli.active_voxel_count == g.active_voxel_count > 0
    assert cli.bbox == g.bbox
    np.testing.assert_array_equal(cli.to_numpy(g.bbox), g.to_numpy())
    assert cli.metadata["generator"] == g.metadata["generator"]
    assert json.loads((tmp_path / "cli" / "cloth.json").read_text()) == small_cloth.spec


def test_fibres_as_arrays(small_cloth):
    f = small_cloth.fibers
    n = len(f["radius"])
    assert n == small_cloth.report["fiber_count"] > 0
    assert f["points"].shape[1] == 3 and f["offsets"][0] == 0 and f["offsets"][-1] == len(f["points"])
    assert np.all(np.diff(f["offsets"]) >= 2)
    for key in ("yarn", "ply", "fiber", "kind"):
        assert len(f[key]) == n
    assert set(np.unique(f["kind"])) <= {0, 1, 2}
    np.testing.assert_allclose(f["radius"][f["kind"] == 0], 0.006)  # the cotton preset's fibre radius
    # Fibre volume = sum of polyline length x pi r^2 (fibers.h), from the arrays alone.
    seg = np.linalg.norm(np.diff(f["points"], axis=0), axis=1)
    first = f["offsets"][:-1]
    keep = np.ones(len(seg), bool)
    keep[first[1:] - 1] = False  # segments that join two polylines are not fibre
    per_point_r = np.repeat(f["radius"], np.diff(f["offsets"]))[:-1]
    volume = np.sum(seg[keep] * np.pi * per_point_r[keep] ** 2)
    assert volume == pytest.approx(small_cloth.report["fiber_volume"], rel=1e-9)
    # The grid holds that volume (the voxelizer conserves it up to the clamped overlap).
    g = small_cloth.grid
    assert g.sum() * g.voxel_size ** 3 == pytest.approx(small_cloth.report["grid_volume"], rel=1e-5)


def test_gen_seed_changes_cloth(small_cloth_spec, small_cloth):
    other = weft.gen(dict(small_cloth_spec, seed=6))
    assert not np.array_equal(other.grid.to_numpy(small_cloth.grid.bbox), small_cloth.grid.to_numpy())


@pytest.mark.parametrize("spec, exc", [
    ({"warp_count": -1}, weft.Error),
    ({"pattern": "lace"}, weft.Error),
    ({"voxel_size": float("nan")}, weft.Error),
    ({"voxel_size": "small"}, weft.Error),
    ({"warp_yarn": {"fiber_radius": -1}}, weft.Error),
    ({"bogus_field": 1}, weft.Error),
    ({"pattern": "import", "input": "/nonexistent/yarns.bcc"}, weft.Error),
    ({"voxel_size": 1e-6}, weft.Error),  # refused by the memory estimate, before any work
    ("plain", TypeError),
    ({"seed": object()}, weft.Error),
])
def test_gen_bad_input(spec, exc):
    with pytest.raises(exc):
        weft.gen(spec)


def tiny_scene():
    scene = json.loads(weft.builtin_scene("cloth_patch"))
    scene["camera"]["width"], scene["camera"]["height"] = 24, 16
    return scene


def test_render_identical_to_cli(tmp_path, run_cli):
    scene_file = tmp_path / "tiny.json"
    scene_file.write_text(json.dumps(tiny_scene()))
    run_cli("render", scene_file, "--spp", 2, "--seed", 3, "-o", tmp_path / "cli.exr")
    cli = weft.read_exr(str(tmp_path / "cli.exr"))
    from_file = weft.render(scene_file, spp=2, seed=3)
    from_dict = weft.render(tiny_scene(), spp=2, seed=3)
    assert from_file.shape == (16, 24, 3) and from_file.dtype == np.float32
    np.testing.assert_array_equal(from_file, cli)
    np.testing.assert_array_equal(from_dict, cli)
    assert np.all(np.isfinite(cli)) and cli.max() > 0


def test_render_stats_and_noise_scale():
    # The per-pixel variance of the mean shrinks as 1/spp: compare the mean variance at 2 and 8 spp.
    img2, s2 = weft.render(tiny_scene(), spp=2, seed=1, stats=True)
    img8, s8 = weft.render(tiny_scene(), spp=8, seed=1, stats=True)
    assert s2["spp"] == 2 and s8["spp"] == 8 and s8["invalid_samples"] == 0
    ratio = s2["variance"].mean() / s8["variance"].mean()
    assert 2.0 < ratio < 8.0  # 4 expected; wide because variance estimates are themselves noisy
    # Two images of independent noise differ by about their combined standard errors.
    z = (img2 - img8) / np.sqrt(s2["variance"] + s8["variance"] + 1e-30)
    assert abs(z.mean()) < 0.5


@pytest.mark.parametrize("args, exc", [
    (("/nonexistent/scene.json",), weft.Error),
    (("no_such_builtin",), weft.Error),
    (({"camera": 1},), weft.Error),
    (({"camera": {"fov": float("nan")}},), weft.Error),
    ((3,), TypeError),
    ((None,), TypeError),
])
def test_render_bad_input(args, exc):
    with pytest.raises(exc):
        weft.render(*args, spp=1)


def test_render_bad_options():
    with pytest.raises(weft.Error):
        weft.render(tiny_scene(), spp=0)
    with pytest.raises(weft.Error):
        weft.render(tiny_scene(), integrator="fast")
    with pytest.raises(TypeError):
        weft.render(tiny_scene(), spp="many")
    with pytest.raises(weft.Error):
        weft.read_exr(os.devnull)
