"""The conveniences of docs/python.md: cloth scenes and in-memory grids in scene dicts, image
writers, typed provenance, reprs, threads= and progress=True, local fields."""

import json
import struct
import sys

import numpy as np
import pytest

import weft
from conftest import random_grid


def without_grids(scene, name="cloth.vdb"):
    """The scene dict with every in-memory Grid replaced by a file name."""
    out = json.loads(json.dumps(scene, default=lambda o: name))
    return out


def test_cloth_scene_is_the_scene_weft_gen_writes(tmp_path, run_cli, small_cloth_spec, small_cloth):
    (tmp_path / "spec.json").write_text(json.dumps(small_cloth.spec))
    run_cli("gen", "--config", tmp_path / "spec.json", "--out", tmp_path / "cli")
    cli = json.loads((tmp_path / "cli" / "scene.json").read_text())
    scene = small_cloth.scene()
    assert isinstance(scene["media"]["cloth"]["file"], weft.Grid)
    assert without_grids(scene) == cli


def test_a_grid_object_in_a_scene_renders_as_its_file(tmp_path, small_cloth):
    scene = weft.cloth_scene(small_cloth.grid, lighting="back", tilt=20, width=24, height=16)
    in_memory = weft.render(scene, spp=2, seed=3)
    small_cloth.grid.save(tmp_path / "cloth.vdb")
    from_file = weft.render(without_grids(scene), spp=2, seed=3, base_dir=tmp_path)
    np.testing.assert_array_equal(in_memory, from_file)
    assert in_memory.shape == (16, 24, 3) and in_memory.max() > 0
    assert isinstance(scene["media"]["cloth"]["file"], weft.Grid)  # the caller's dict is left as it was


def test_an_empty_grid_in_a_scene_is_named_by_its_key_and_base_dir_must_be_a_folder(tmp_path, small_cloth):
    scene = weft.cloth_scene(small_cloth.grid, width=8, height=6)
    scene["media"]["cloth"]["file"] = weft.Grid(voxel_size=0.01)
    with pytest.raises(weft.Error, match=r"media\.cloth\.file: the weft\.Grid is empty") as caught:
        weft.render(scene, spp=1)
    assert "weft-scene-" not in str(caught.value)  # not the temporary file it would have been written to
    with pytest.raises(weft.Error, match="is not a folder"):
        weft.render("furnace", spp=1, base_dir=tmp_path / "missing")


@pytest.mark.parametrize("kwargs", [{"lighting": "disco"}, {"tilt": 95}, {"width": 0}])
def test_cloth_scene_bad_views(small_cloth, kwargs):
    with pytest.raises(weft.Error):
        weft.cloth_scene(small_cloth.grid, **kwargs)


def test_cloth_scene_needs_a_grid_with_provenance():
    with pytest.raises(weft.Error, match="sigma"):
        weft.cloth_scene(random_grid()[0])
    with pytest.raises(TypeError):
        weft.cloth_scene("cloth.vdb")


def test_write_exr_round_trips_and_write_png_is_a_png(tmp_path):
    image = np.random.default_rng(4).uniform(0, 2, size=(5, 7, 3)).astype(np.float32)
    weft.write_exr(tmp_path / "a.exr", image)
    np.testing.assert_array_equal(weft.read_exr(str(tmp_path / "a.exr")), image)
    weft.write_png(tmp_path / "a.png", image, exposure=0.5)
    data = (tmp_path / "a.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", data[16:24]) == (7, 5)  # IHDR: width, height


@pytest.mark.parametrize("image", [np.zeros((4, 4)), np.zeros((4, 4, 4)), np.full((2, 2, 3), np.nan),
                                   np.zeros((0, 3, 3))])
def test_image_writers_refuse_bad_arrays(tmp_path, image):
    for write in (weft.write_exr, weft.write_png):
        with pytest.raises(weft.Error):
            write(tmp_path / "bad.exr", image)
    assert not (tmp_path / "bad.exr").exists()


def test_typed_provenance(small_cloth):
    g = small_cloth.grid
    assert g.sigma == pytest.approx(float(g.metadata["weft:sigma_per_concentration"]), rel=1e-12)
    assert g.yarn_diameter == pytest.approx(float(g.metadata["weft:yarn_diameter"]), rel=1e-12)
    assert g.fiber_radius == pytest.approx(2 / (np.pi * g.sigma), rel=1e-9)  # sigma = 2/(pi r_f)
    assert g.units == "mm" and g.value_kind == "concentration"
    bare = random_grid()[0]
    assert (bare.sigma, bare.yarn_diameter, bare.units) == (None, None, None)


def test_reprs_name_the_type_and_what_matters(small_cloth):
    g = small_cloth.grid
    curve = weft.measure_beam(g, "z", sigma=g.sigma)
    stats = weft.window_stats(g, "z", g.yarn_diameter)
    fit = weft.gamma_from_moments(stats.mean, stats.variance, g.sigma)
    reprs = {
        "Grid": (g, "sigma="), "Cloth": (small_cloth, "fibres"), "TransmittanceCurve": (curve, "rays"),
        "ConcentrationStats": (stats, ""), "GammaFit": (fit, ""),
        "TransmittancePair": (weft.TransmittancePair.reciprocal(fit.law()), "reciprocal"),
        "LeastSquaresFit": (weft.fit_gamma_to_curve(curve, g.sigma), "alpha="),
        "CurveError": (weft.compare(curve, weft.log_curve(fit.law(), curve.depth)), ""),
        "LocalFields": (weft.local_fields(g, 4), "block=4"),
        "Fibres": (weft.Fibres([[(0, 0, 0), (1, 0, 0)]], 0.1), "1 fibres"),
    }
    for name, (obj, word) in reprs.items():
        text = repr(obj)
        assert text.startswith("<weft.%s" % name) and word in text, text
    # A law's repr is the call that makes it.
    law = fit.law()
    assert repr(law).startswith("weft.law('gamma'")
    assert eval(repr(law), {"weft": weft}).T(0.5) == law.T(0.5)


def test_the_same_bytes_for_any_thread_count(small_cloth_spec):
    one = weft.gen(small_cloth_spec, threads=1)
    two = weft.gen(small_cloth_spec, threads=2)
    np.testing.assert_array_equal(one.grid.to_numpy(), two.grid.to_numpy())
    assert one.grid.metadata == two.grid.metadata
    g = one.grid
    a = weft.measure_beam(g, "x", sigma=g.sigma, threads=1)
    b = weft.measure_beam(g, "x", sigma=g.sigma, threads=2)
    np.testing.assert_array_equal(a.T, b.T)
    np.testing.assert_array_equal(a.stderr, b.stderr)
    scene = one.scene(width=20, height=14)
    np.testing.assert_array_equal(weft.render(scene, spp=2, threads=1), weft.render(scene, spp=2, threads=2))


def test_threads_limits_the_pool_while_the_call_runs(small_cloth):
    seen = []
    before = weft._weft._thread_limit()
    weft.measure_beam(small_cloth.grid, "x", sigma=1.0, threads=1,
                      progress=lambda label, done, total: seen.append(weft._weft._thread_limit()))
    assert seen and set(seen) == {1}
    assert weft._weft._thread_limit() == before


@pytest.mark.parametrize("threads, exc", [(0, weft.Error), (-2, weft.Error), ("2", TypeError), (1.5, TypeError)])
def test_bad_thread_counts(small_cloth_spec, threads, exc):
    with pytest.raises(exc):
        weft.gen(small_cloth_spec, threads=threads)


def test_progress_true_draws_a_bar_without_tqdm(small_cloth, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)  # as if tqdm were not installed
    weft.measure_beam(small_cloth.grid, "x", sigma=1.0, progress=True)
    err = capsys.readouterr().err
    # The CLI's line: percent, rate and, once the stage ends, the time it took.
    last = err.rstrip("\n").split("\r")[-1]
    assert "100.0%" in last and "/s" in last and "took" in last and err.endswith("\n")


def test_progress_true_uses_tqdm_when_installed(small_cloth, monkeypatch):
    calls = []

    class FakeTqdm:
        def __init__(self, total, desc, leave, file):
            self.n, self.total = 0, total
            calls.append(desc)

        def update(self, k):
            self.n += k

        def close(self):
            calls.append(("closed", self.n, self.total))

    monkeypatch.setitem(sys.modules, "tqdm", type(sys)("tqdm"))
    sys.modules["tqdm"].tqdm = FakeTqdm
    weft.gen(pattern="plain", yarns=(2, 2), voxel_size=0.03, warp_yarn={"fiber_count": 8}, progress=True)
    assert calls and isinstance(calls[0], str)
    closed = [c for c in calls if isinstance(c, tuple)]
    assert closed and all(n == total for _, n, total in closed)  # every bar ran to its end


def test_local_fields_equal_weft_fit_block(tmp_path, run_cli, small_cloth):
    small_cloth.grid.save(tmp_path / "cloth.vdb")
    run_cli("fit", "--grid", tmp_path / "cloth.vdb", "--block", 4, "--out", tmp_path / "fit")
    fields = weft.local_fields(small_cloth.grid, 4)
    cli_mean = weft.load_grid(tmp_path / "fit" / "local_fields.vdb", "mean_concentration")
    assert fields.block == 4 and fields.blocks > 0
    assert cli_mean.bbox == fields.mean.bbox
    np.testing.assert_array_equal(cli_mean.to_numpy(), fields.mean.to_numpy())
    cli_var = weft.load_grid(tmp_path / "fit" / "local_fields.vdb", "var_concentration_z")
    np.testing.assert_array_equal(cli_var.to_numpy(cli_mean.bbox), fields.variance[2].to_numpy(cli_mean.bbox))
    with pytest.raises(weft.Error):
        weft.local_fields(small_cloth.grid, 0)


def test_local_fields_render_from_a_scene_dict(small_cloth):
    scene = small_cloth.scene(lighting="back", width=20, height=14)
    fields = weft.local_fields(small_cloth.grid, 4)
    scene["media"]["cloth"] = {"type": "local-gamma", "fields": fields, "sigma": small_cloth.grid.sigma}
    image = weft.render(scene, spp=2, seed=1)
    assert np.all(np.isfinite(image)) and image.max() > 0


def test_a_half_variance_beyond_its_range_is_refused_where_it_enters(tmp_path, small_cloth):
    # The variances are stored as 16-bit floats (docs/render.md §5b "Storage"): a value past 65504
    # would be written as inf, which weft.Grid.load refuses; set_value refuses it instead, and
    # what it keeps is what the file gives back.
    fields = weft.local_fields(small_cloth.grid, 4)
    var = fields.variance[0]
    with pytest.raises(weft.Error, match=r"var_concentration_x.*65504.*70000"):
        var.set_value(0, 0, 0, 70000.0)
    var.set_value(0, 0, 0, 0.1)
    fields.save(tmp_path / "fields.vdb")
    back = weft.load_grid(tmp_path / "fields.vdb", "var_concentration_x")
    assert back.value(0, 0, 0) == var.value(0, 0, 0) != np.float32(0.1)
