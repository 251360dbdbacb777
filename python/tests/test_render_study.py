"""The image study, its matrix and the baselines from Python (docs/python.md "The coarse-cloth
image study"): the same reports as `weft render --study` for the same spec and seed, the shapes
of what comes back, a spec whose coarse models are exact, the baselines' closed forms, and the
errors."""

import json
import math
import os
import subprocess

import numpy as np
import pytest

import weft

# What depends on the clock (docs/render.md §6e: timing keys end in "seconds"; speed-ups, cost
# ratios and the headlines quote them).
TIMED = {"speedup", "speedup_ceiling", "error_for_3x", "cost_ratio", "headline", "text"}


def untimed(value):
    if isinstance(value, dict):
        return {k: untimed(v) for k, v in value.items() if not k.endswith("seconds") and k not in TIMED}
    if isinstance(value, list):
        return [untimed(v) for v in value]
    return value


def cli(weft_bin, *args, cwd=None):
    result = subprocess.run([weft_bin, "--quiet", "--threads", "2", *map(str, args)], cwd=cwd, capture_output=True,
                            text=True)
    assert result.returncode == 0, result.stderr
    return result


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory, small_cloth):
    """The small cloth back-lit on a 32 x 24 film, as a scene file beside its grid."""
    folder = tmp_path_factory.mktemp("scene")
    small_cloth.grid.save(str(folder / "cloth.vdb"))
    scene = weft.cloth_scene(small_cloth.grid, lighting="back", width=32, height=24)
    scene["media"]["cloth"]["file"] = "cloth.vdb"
    path = folder / "scene.json"
    path.write_text(json.dumps(scene))
    return path


STUDY_ARGS = dict(quick=True, spp=4, reference_spp=32, factors=(2, 4), memory=("optical-depth", "segment"))


@pytest.fixture(scope="module")
def study(scene_file, tmp_path_factory):
    out = tmp_path_factory.mktemp("py_study")
    return weft.render_study(str(scene_file), out=out, threads=2, **STUDY_ARGS), out


def test_study_equals_the_cli_report(study, scene_file, weft_bin, tmp_path):
    result, out = study
    cli(weft_bin, "render", scene_file, "--study", "--quick", "--study-spp", 4, "--reference-spp", 32,
        "--study-factors", "2,4", "--study-memory", "optical-depth,segment", "--out", tmp_path)
    text = (tmp_path / "scene.study.json").read_text()
    # The candidates' scene files are in each run's own folder.
    text = text.replace(json.dumps(str(tmp_path / "scene.study"))[1:-1], json.dumps(str(out))[1:-1])
    assert untimed(result.to_dict()) == untimed(json.loads(text))
    assert result.to_dict() == json.loads(result.to_json())
    # The images are the CLI's, bit for bit.
    assert np.array_equal(result.reference_image, weft.read_exr(str(tmp_path / "scene.exr")))
    for c in result.candidates:
        assert np.array_equal(c.image, weft.read_exr(str(tmp_path / "scene.study" / (c.name + ".exr")))), c.name


@pytest.mark.parametrize("window, said", [("1e300", "longer than the active box along x, y, z: the box's extent is used"),
                                           ("1e-300", "shorter than half a voxel")])
def test_a_window_the_grid_clamps_is_said_and_recorded(scene_file, weft_bin, tmp_path, window, said):
    """A window the cloth cannot hold is clamped per axis as validate clamps it (fit::scale_use)
    and said, before the renders and in the report's notes, in each front end's spelling: never
    changed in silence (docs/render.md §6c)."""
    run = subprocess.run([weft_bin, "render", str(scene_file), "--study", "--quick", "--study-spp", "1",
                          "--reference-spp", "16", "--study-factors", "2", "--study-window", window, "--out",
                          str(tmp_path / "cli")], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    given = f"{float(window):g}"
    assert f"warning: --study-window {given} is {said}" in run.stdout, run.stdout
    notes = json.loads((tmp_path / "cli" / "scene.study.json").read_text())["notes"]
    assert any(n.startswith(f"--study-window {given} is {said}") for n in notes), notes
    result = weft.render_study(str(scene_file), out=tmp_path / "py", quick=True, spp=1, reference_spp=16, factors=(2,),
                               window=window)
    assert any(n.startswith(f"window={given} is {said}") for n in result.notes), result.notes


def test_study_without_a_clamped_window_has_no_such_note(study):
    result, _ = study
    assert not any("window" in n for n in result.notes), result.notes


def test_study_shapes_and_rows(study):
    result, _ = study
    names = [c.name for c in result.candidates]
    assert names == ["fine", "exponential-2x", "local-gamma-2x", "local-gamma-segment-2x", "shadow-corrected-2x",
                     "shadow-directional-2x", "exponential-4x", "local-gamma-4x", "local-gamma-segment-4x",
                     "shadow-corrected-4x", "shadow-directional-4x", "slab-gamma"]
    h, w = result.reference["height"], result.reference["width"]
    assert max(h, w) == 48  # quick: the film's longest side
    assert result.reference_image.shape == result.reference_variance.shape == (h, w, 3)
    assert result.reference_image.dtype == np.float32
    assert result.cloth_mask.shape == (h, w) and result.cloth_mask.dtype == bool
    assert int(result.cloth_mask.sum()) == result.reference["cloth_pixels"] > 0
    for c in result.candidates:
        assert c.image.shape == c.error_map.shape == (h, w, 3)
        assert c.spp == 4 and c.fitted_to_images is False and c.uses_ground_truth is False
        assert c.bias_z == pytest.approx(c.bias_sq / c.bias_sq_stderr if c.bias_sq_stderr > 0 else 0.0)
        # The error map is |A - R| averaged over the channels.
        assert np.allclose(c.error_map[..., 0], np.abs(c.image - result.reference_image).mean(axis=2), atol=1e-6)
        assert c.to_dict() == result.to_dict()["candidates"][names.index(c.name)]
    assert result["slab-gamma"].factor == 0 and result["fine"].factor == 1
    # (c), the validation's best model, is chosen against the ground truth: labelled so, also
    # under its former key (docs/render.md §6c).
    assert result.best_by_ground_truth["uses_ground_truth"] is True
    assert result.best_predictive == result.best_by_ground_truth
    rows = result.rows()
    assert [r["name"] for r in rows] == names and "curve" not in rows[0] and "memory_bytes" in rows[0]
    assert result.csv.splitlines()[0].startswith("candidate,model,factor,spp")
    assert len(result.csv.splitlines()) == 1 + len(names)
    assert "slab-gamma" in repr(result["slab-gamma"]) and "%d candidates" % len(names) in repr(result)
    with pytest.raises(KeyError, match="no candidate 'exponential-8x'"):
        result["exponential-8x"]
    with pytest.raises(AttributeError, match="has no field 'biass'"):
        result["fine"].biass


def test_study_numbers_do_not_depend_on_the_thread_count(small_cloth):
    scene = small_cloth.scene(lighting="back", width=24, height=18)
    one, two = (weft.render_study(scene, spp=2, reference_spp=16, factors=(2,), threads=n) for n in (1, 2))
    # Each call's scene files are in its own temporary folder.
    def report(r):
        return untimed(json.loads(r.to_json().replace(os.path.dirname(r.reference["scene"]), "DIR")))
    assert report(one) == report(two)
    assert np.array_equal(one.reference_image, two.reference_image)
    for a, b in zip(one.candidates, two.candidates):
        assert np.array_equal(a.image, b.image), a.name


def test_a_spec_whose_coarse_models_are_exact_has_no_detectable_bias(small_cloth):
    """A uniform slab: every block is uniform, so the downsampled grid, the self-shadowing
    correction, the local fields (Var C = 0: exponential) and the slab all hold the fine grid's
    medium; each candidate's bias over the cloth must be within 5 standard errors of 0. The
    small cloth itself, under the same spec, shows the slab's bias."""
    uniform = weft.Grid.from_numpy(np.full((16, 16, 4), 0.3, dtype=np.float32), voxel_size=0.02)
    for key, value in small_cloth.grid.metadata.items():
        uniform.set_metadata(key, value)
    spec = dict(spp=8, reference_spp=128, factors=(2,), memory=("optical-depth", "segment"), window=0.06)
    result = weft.render_study(weft.cloth_scene(uniform, lighting="back", width=24, height=18), **spec)
    assert result.reference["cloth_pixels"] > 50
    for c in result.candidates:
        assert abs(c.cloth_bias_sq) < 5 * c.cloth_bias_sq_stderr, c
    cloth = weft.render_study(small_cloth.scene(lighting="back", width=24, height=18), **spec)
    slab = cloth["slab-gamma"]
    assert slab.cloth_bias_sq > 5 * slab.cloth_bias_sq_stderr, slab


@pytest.fixture(scope="module")
def matrix(tmp_path_factory):
    out = tmp_path_factory.mktemp("py_matrix")
    return weft.render_matrix(quick=True, cloths="plain", lightings="back", tilts=45, factors=(2, 4), out=out,
                              threads=2), out


def test_matrix_equals_the_cli_report(matrix, weft_bin, tmp_path):
    result, _ = matrix
    cli(weft_bin, "render", "--study", "--quick", "--study-cloths", "plain", "--study-lightings", "back",
        "--study-tilts", 45, "--study-factors", "2,4", "--out", tmp_path)
    assert result.csv == (tmp_path / "matrix.csv").read_text()  # timing-free: the same bytes
    assert untimed(result.to_dict()) == untimed(json.loads((tmp_path / "matrix.json").read_text()))
    assert result.markdown.splitlines()[0] == (tmp_path / "matrix.md").read_text().splitlines()[0]
    cost = [line.split(",")[:4] for line in result.cost_csv.splitlines()]
    assert cost == [line.split(",")[:4] for line in (tmp_path / "matrix.cost.csv").read_text().splitlines()]
    # The CLI's finished case, taken by Python's resume (one store, keyed by the spec): the
    # CLI's report, timings included.
    resumed = weft.render_matrix(quick=True, cloths=["plain"], lightings=["back"], tilts="45", factors="2,4",
                                 out=tmp_path, resume=True)
    assert resumed.resumed == 1
    assert resumed.to_dict() == json.loads((tmp_path / "matrix.json").read_text())


def test_matrix_rows_headlines_and_resume(matrix):
    result, out = matrix
    assert [c.case for c in result.cases] == ["plain-back-45deg"]
    case = result["plain-back-45deg"]
    assert case.fitted_on is True and len(case.albedo_factors) == 2
    names = [c.name for c in case.candidates]
    assert names[0] == "fine" and names[-1] == "slab-gamma"
    assert {"albedo-corrected-2x", "shadow-corrected-4x", "local-gamma-segment-4x"} <= set(names)
    assert len(result.rows()) == len(names)
    for row, c in zip(result.rows(), case.candidates):
        assert row["case"] == "plain-back-45deg" and row["name"] == c.name
        assert c.cloth_relative_bias == pytest.approx(c.cloth_bias / case.cloth_mean)
        assert c.memory_bytes > 0 and c.cloth_bias_sq_stderr > 0
    fine = case["fine"]
    assert abs(fine.cloth_bias_sq) < 5 * fine.cloth_bias_sq_stderr
    (headline,) = result.headlines
    assert headline.cloth == "plain" and [v.factor for v in headline.best] == [2, 4, 0]
    # Judged on the set-ups it was not fitted on: none here.
    assert not any(v.name.startswith("albedo-corrected") for v in headline.representations)
    # One floor per factor, its name and factor matching; a bias is a non-negative fraction.
    assert [(v.name, v.factor) for v in headline.resolution_floors] == [
        ("resolution-floor-2x", 2), ("resolution-floor-4x", 4)]
    assert all(v.worst_relative_bias >= 0.0 for v in headline.resolution_floors)
    assert result.spec["film"] == [32, 24] and result.spec["spp"] == 8 and result.spec["reference_spp"] == 128
    # The finished case is kept in out/matrix.units: resume takes it, and the report is the same.
    again = weft.render_matrix(quick=True, cloths="plain", lightings="back", tilts=45, factors=(2, 4), out=out,
                               resume=True)
    assert again.resumed == 1 and again.to_json() == result.to_json()
    # Another spec is refused, naming Python's argument, not the CLI's flag (docs/python.md).
    with pytest.raises(weft.Error, match=r"resume=True: '.*' holds the units of a different run.* without "
                                         r"resume=True") as e:
        weft.render_matrix(quick=True, cloths="plain", lightings="back", tilts=45, factors=(2, 4), spp=4, out=out,
                           resume=True)
    assert "--" not in str(e.value)


def test_albedo_fitted_to_images_is_labelled(scene_file):
    fits = weft.fit_albedo(str(scene_file), factors=(2,), spp=4, reference_spp=32, quick=True)
    (fit,) = fits
    assert fit.factor == 2 and fit.k > 0 and fit.renders >= 1
    assert fit.fitted_to_images is True and fit.uses_ground_truth is True
    if fit.converged:
        assert abs(fit.fitted - fit.target) <= fit.tolerance
    result = weft.render_study(str(scene_file), spp=4, reference_spp=32, factors=(2,), quick=True,
                               albedo={2: fit.k})
    corrected = result["albedo-corrected-2x"]
    assert corrected.albedo_factor == fit.k
    assert corrected.fitted_to_images is True and corrected.uses_ground_truth is True
    assert not any(c.fitted_to_images for c in result.candidates if c.name != "albedo-corrected-2x")
    fitted_here = weft.render_study(str(scene_file), spp=4, reference_spp=32, factors=(2,), quick=True, albedo="fit")
    assert [f.k for f in fitted_here.albedo_fits] == [fit.k]  # the same fit, inside the study
    assert fitted_here["albedo-corrected-2x"].albedo_factor == fit.k


def test_shadowed_downsample_closed_forms():
    """docs/render.md §6d (c): a uniform block needs no correction; a block whose half x < f/2
    holds C gives C/2 along x and -ln((1 + exp(-sigma C L))/2)/(sigma L) across it."""
    c, sigma, h = 0.4, 50.0, 0.02
    uniform = weft.Grid.from_numpy(np.full((4, 4, 4), c, dtype=np.float32), voxel_size=h)
    s = weft.shadowed_downsample(uniform, 2, sigma=sigma)
    linear = weft.downsample(uniform, 2).to_numpy()
    for g in (*s.per_axis, s.isotropic):
        assert np.array_equal(g.to_numpy(), linear)
        assert g.voxel_size == pytest.approx(2 * h)
    half = np.zeros((2, 2, 2), dtype=np.float32)
    half[0] = c
    s = weft.shadowed_downsample(weft.Grid.from_numpy(half, voxel_size=h), 2, sigma=sigma)
    length = 2 * h
    across = -math.log((1 + math.exp(-sigma * c * length)) / 2) / (sigma * length)
    got = [g.value(0, 0, 0) for g in s.per_axis]
    assert got == pytest.approx([c / 2, across, across], rel=1e-6)
    assert s.isotropic.value(0, 0, 0) == pytest.approx(sum(got) / 3, rel=1e-6)
    assert across < c / 2  # Jensen: below the linear mean
    assert "ShadowedGrids" in repr(s)


def test_coarse_grids_do_not_move_with_the_index_origin(small_cloth):
    """docs/render.md §5 "Coarse grids anchored to the cloth": the cloth's voxels stored from
    index (0, 0, 0) by Grid.from_numpy (the origin moved so the world is the same) coarsen to the
    same values at the same world positions as the generated grid, whose box starts elsewhere."""
    g = small_cloth.grid
    lo, _ = g.bbox
    assert lo != (0, 0, 0)
    h = g.voxel_size
    moved = weft.Grid.from_numpy(g.to_numpy(), voxel_size=h,
                                 origin=tuple(o + i * h for o, i in zip(g.origin, lo)))
    assert moved.bbox[0] == (0, 0, 0)
    for f in (2, 3, 4):
        a, b = weft.downsample(g, f), weft.downsample(moved, f)
        assert a.origin == pytest.approx(b.origin, abs=1e-12)
        np.testing.assert_allclose(b.to_numpy(), a.to_numpy(), rtol=1e-6)
        sa, sb = weft.shadowed_downsample(g, f, sigma=g.sigma), weft.shadowed_downsample(moved, f, sigma=g.sigma)
        np.testing.assert_allclose(sb.isotropic.to_numpy(), sa.isotropic.to_numpy(), rtol=1e-6)
        fa, fb = weft.local_fields(g, f), weft.local_fields(moved, f)
        np.testing.assert_allclose(fb.mean.to_numpy(), fa.mean.to_numpy(), rtol=1e-6)
        np.testing.assert_allclose(fb.variance[2].to_numpy(), fa.variance[2].to_numpy(), rtol=1e-5, atol=1e-9)


def test_shadowed_downsample_takes_sigma_from_the_provenance(small_cloth):
    g = small_cloth.grid
    assert np.array_equal(weft.shadowed_downsample(g, 2).isotropic.to_numpy(),
                          weft.shadowed_downsample(g, 2, sigma=g.sigma).isotropic.to_numpy())
    bare = weft.Grid.from_numpy(np.full((2, 2, 2), 0.5, dtype=np.float32))
    with pytest.raises(weft.Error, match="sigma=S"):
        weft.shadowed_downsample(bare, 2)
    with pytest.raises(weft.Error, match="shadowed_downsample: .*factor"):
        weft.shadowed_downsample(g, 0)
    with pytest.raises(weft.Error, match="downsample: .*factor"):
        weft.downsample(g, 5000)
    with pytest.raises(TypeError, match="factor must be an integer"):
        weft.shadowed_downsample(g, 2.0)


@pytest.mark.parametrize("kwargs, match", [
    (dict(factors=(1, 4)), r"render_study: factors=\[1, 4\]: .*factor 1"),
    (dict(factors=(2, 2)), r"factors=\[2, 2\]: .*twice"),
    (dict(memory=("segment", "bogus")), r"memory=\['segment', 'bogus'\]: unknown memory rule 'bogus'"),
    (dict(memory="segment,segment"), r"memory=\['segment', 'segment'\]: study: memory rule 'segment' is given twice"),
    (dict(components="local-gamma-renewal"),
     r"components=\['local-gamma-renewal'\]: .*renewal is not one of the study's memory rules \(optical-depth\); "
     r"add it to memory="),
    (dict(spp=0), r"spp=0: must be >= 1"),
    (dict(spp=4, seconds=2.0), r"spp= and seconds= exclude each other"),
    (dict(seconds=float("nan")), r"seconds=nan"),
    (dict(reference_spp=0), r"reference_spp=0"),
    # The CLI's limits (--study-spp, --study-time, --reference-spp), before any work.
    (dict(spp=2 ** 21), r"spp=2097152: .*spp must be at most 1048576"),
    (dict(seconds=1e-4), r"seconds=0.0001: .*time budget must be in \[0.001, 1e\+06\] seconds"),
    (dict(seconds=1e7), r"seconds=10000000: .*time budget must be in \[0.001, 1e\+06\] seconds"),
    (dict(reference_spp=2 ** 25), r"reference_spp=33554432: .*reference spp must be in \[1, 16777216\]"),
    # A family that names no candidate: without albedo= there is no albedo-corrected one.
    (dict(components="albedo-corrected"),
     r"components=\['albedo-corrected'\]: .*no albedo-corrected candidate; add them with albedo="),
    (dict(albedo={8: 1.1}, factors=(2,)), r"albedo=\{8: 1.1\}: .*not a coarsening factor"),
    (dict(albedo={2: -1.0}, factors=(2,)), r"albedo=\{2: -1\}: .*> 0"),
    (dict(albedo="fitted"), r"albedo='fitted'"),
    (dict(window="wide"), r"window='wide'"),
    (dict(threads=0), r"threads=0"),
    # Checked against the scene (docs/render.md §6c "Factors"): one coarse voxel holding the whole
    # cloth, and albedo factors that clamp every channel at 1.
    (dict(factors=(2, 4096)), r"coarsening factor 4096: one coarse voxel .* holds the whole active box"),
    (dict(factors=(4096,), albedo="fit"), r"coarsening factor 4096: one coarse voxel"),
    (dict(albedo={2: 100.0}, factors=(2,)), r"^render_study: study: albedo factor 2:100 takes the albedo .* above 1 in every channel"),
    (dict(albedo={2: 1e300}, factors=(2,)), r"albedo factor 2:1e\+300 takes the albedo"),
])
def test_study_bad_input_is_one_error_naming_the_argument(scene_file, tmp_path, kwargs, match):
    out = tmp_path / "out"
    with pytest.raises(weft.Error, match=match) as e:
        weft.render_study(str(scene_file), out=out, **kwargs)
    assert "\n" not in str(e.value)
    assert not out.exists() or not any(out.iterdir())  # refused before anything was written


def test_components_may_name_the_albedo_corrected_candidates_a_fit_will_make(scene_file):
    result = weft.render_study(str(scene_file), spp=1, reference_spp=8, factors=(2,), quick=True, albedo="fit",
                               components="albedo-corrected")
    assert result["albedo-corrected-2x"].components  # split, as asked


def _scene_dict(scene_file):
    scene = json.loads(scene_file.read_text())
    scene["media"]["cloth"]["file"] = str(scene_file.parent / "cloth.vdb")
    return scene


def test_the_study_refuses_a_box_that_cuts_the_cloth_or_is_seen(scene_file, tmp_path):
    """Each candidate's box is fitted to its own grid (docs/render.md §6c): a box that cut the fine
    grid would cut the coarse grids' blocks elsewhere, and a box a ray sees (glass) would change
    size with them. Either would compare other cloths, so both are refused before any work."""
    grid = weft.load_grid(str(scene_file.parent / "cloth.vdb"))
    (lo, hi), h = grid.bbox, grid.voxel_size
    cut = _scene_dict(scene_file)
    cut["shapes"][0]["min"] = [h * (lo[0] + hi[0]) / 2, h * lo[1], h * lo[2]]  # half the cloth in x
    out = tmp_path / "cut"
    with pytest.raises(weft.Error, match=r"the box holding medium 'cloth' .* cuts the active voxels of grid") as e:
        weft.render_study(cut, spp=1, reference_spp=8, factors=(2,), quick=True, out=out)
    assert "\n" not in str(e.value) and not out.exists()
    seen = _scene_dict(scene_file)
    seen["materials"]["glass"] = {"type": "dielectric", "ior": 1.5}
    seen["shapes"][0]["material"] = "glass"
    with pytest.raises(weft.Error, match=r"has material 'glass': .* must be a null boundary"):
        weft.render_study(seen, spp=1, reference_spp=8, factors=(2,), quick=True)
    with pytest.raises(weft.Error, match=r"cuts the active voxels"):
        weft.fit_albedo(cut, factors=(2,), spp=1, reference_spp=8, quick=True)


def test_a_laws_mu_is_the_same_cloth_as_sigma_times_mu(scene_file):
    """A grid medium's extinction is the law's mu times sigma times the value (docs/scene-format.md):
    every candidate (the fields, the self-shadowing correction, the slab) must take the product, so
    the study of mu = 3 is the study of 3 sigma, image for image."""
    with_mu = _scene_dict(scene_file)
    with_mu["media"]["cloth"]["law"] = {"name": "exponential", "mu": 3.0}
    with_sigma = _scene_dict(scene_file)
    with_sigma["media"]["cloth"]["sigma"] = 3.0 * with_sigma["media"]["cloth"]["sigma"]
    args = dict(spp=1, reference_spp=8, factors=(2,), quick=True)
    a, b = weft.render_study(with_mu, **args), weft.render_study(with_sigma, **args)
    assert [c.name for c in a.candidates] == [c.name for c in b.candidates]
    for ca, cb in zip(a.candidates, b.candidates):
        assert np.array_equal(ca.image, cb.image), ca.name
        assert ca.cloth_bias == cb.cloth_bias, ca.name


def test_a_study_whose_cloth_covers_no_pixel_is_refused(scene_file):
    away = _scene_dict(scene_file)
    camera = away["camera"]
    camera["look_at"] = [2 * p - q for p, q in zip(camera["position"], camera["look_at"])]  # turned round
    with pytest.raises(weft.Error, match=r"the cloth covers no pixel of the .* film"):
        weft.render_study(away, spp=1, reference_spp=8, factors=(2,), quick=True)


def test_a_resumed_case_whose_folder_was_removed_is_rendered_again(tmp_path):
    args = dict(quick=True, cloths="plain", lightings="back", tilts=(45, 8), factors=(2,), spp=1, reference_spp=8,
                out=tmp_path)
    first = weft.render_matrix(**args)
    import shutil
    shutil.rmtree(tmp_path / "cases" / "plain-back-8deg")
    again = weft.render_matrix(resume=True, **args)
    assert again.resumed == 1  # the other case; this one rendered again, the same bytes
    assert again.csv == first.csv
    assert (tmp_path / "cases" / "plain-back-8deg" / "reference.study.json").exists()


def test_study_refuses_a_scene_without_one_grid_medium():
    with pytest.raises(weft.Error, match="render_study: scene: study: the scene needs exactly one grid medium"):
        weft.render_study("cloth_patch")
    with pytest.raises(TypeError, match="render_study: scene must be"):
        weft.render_study(3)
    with pytest.raises(TypeError, match="render_study: factors must be integers"):
        weft.render_study("cloth_patch", factors="2,x")


@pytest.mark.parametrize("kwargs, match", [
    (dict(cloths="plain,bogus"), r"render_matrix: cloths=\['plain', 'bogus'\]: .*bogus"),
    (dict(lightings="back,sideways"), r"lightings=\['back', 'sideways'\]"),
    (dict(tilts=(45, 95)), r"tilts=\[45, 95\]: .*95"),
    (dict(film=(4, 4)), r"film=\(4, 4\): .*each side must be in \[8, 4096\] px"),
    (dict(yarns=0), r"yarns=0"),
    # The CLI's limits, refused before a cloth is made (the library checks them for both).
    (dict(film=(5000, 8)), r"film=\(5000, 8\): .*each side must be in \[8, 4096\] px"),
    (dict(yarns=65), r"yarns=65: .*yarns must be in \[1, 64\]"),
    (dict(spp=2 ** 21), r"spp=2097152: .*spp must be at most 1048576"),
    (dict(reference_spp=2 ** 25), r"reference_spp=33554432: .*reference spp must be in \[1, 16777216\]"),
    (dict(factors=()), r"factors=\[\]: .*no coarsening factors"),
    (dict(resume=True), r"resume=True needs out="),
    # A repeated cloth (an alias is its pattern), light set-up, view or memory rule would render the
    # same case or candidate twice under one name (docs/robustness.md).
    (dict(cloths="twill,twill22"), r"cloths=\['twill', 'twill22'\]: render matrix: cloth 'twill22' \(as 'twill', "
                                   r"'twill22'\) is given twice"),
    (dict(cloths=("satin", "satin5")), r"cloth 'satin5' \(as 'satin', 'satin5'\) is given twice"),
    (dict(lightings=("back", "back")), r"lightings=\['back', 'back'\]: render matrix: light set-up 'back' is given "
                                       r"twice"),
    (dict(tilts=(45, 45)), r"tilts=\[45, 45\]: render matrix: view at tilt 45 degrees is given twice"),
    (dict(memory="segment,segment"), r"memory=\['segment', 'segment'\]: study: memory rule 'segment' is given twice"),
    (dict(components="local-gamma-renewal"),
     r"renewal is not one of the study's memory rules \(optical-depth, segment\); add it to memory="),
])
def test_matrix_bad_input_is_one_error_naming_the_argument(tmp_path, kwargs, match):
    out = None if kwargs.get("resume") else tmp_path / "out"
    with pytest.raises(weft.Error, match=match) as e:
        weft.render_matrix(quick=True, out=out, **kwargs)
    assert "\n" not in str(e.value)
    assert "--" not in str(e.value)  # never a CLI flag (docs/python.md "One set of checks")
    assert out is None or not out.exists()  # no empty folder left either
    with pytest.raises(TypeError, match="film must be"):
        weft.render_matrix(film=32)
    with pytest.raises(TypeError, match="render_matrix: window must be a number"):
        weft.render_matrix(window=[0.3])


@pytest.mark.parametrize("out", ["/proc", "/proc/weft/matrix"])
def test_an_unwritable_out_is_refused_before_any_work(out):
    # /proc takes no new file even for root, whose rights chmod cannot take away.
    with pytest.raises(weft.Error, match=r"render_matrix: out=.* cannot be created|output folder '/proc' cannot be "
                                         r"written") as e:
        weft.render_matrix(quick=True, cloths="plain", lightings="back", tilts=45, factors=(2,), out=out)
    assert "\n" not in str(e.value)


def test_matrix_refuses_a_factor_whose_voxel_holds_the_cloth(weft_bin, tmp_path):
    """The matrix (Python and CLI) checks its factors on each generated cloth before any fit or
    render, and a refused run leaves nothing: the cloths it made and the folders it created go
    (docs/render.md §6c "Factors"); a folder that was there keeps what it held."""
    py_out = tmp_path / "py"
    with pytest.raises(weft.Error, match=r"coarsening factor 4096: one coarse voxel .* holds the whole active box"):
        weft.render_matrix(quick=True, cloths="plain", lightings="back", tilts=(45,), factors=(2, 4096), out=py_out)
    assert not py_out.exists()
    out = tmp_path / "m"
    out.mkdir()
    (out / "mine.txt").write_text("kept")
    r = subprocess.run([weft_bin, "--quiet", "render", "--study", "--quick", "--study-cloths", "plain",
                        "--study-lightings", "back", "--study-tilts", "45", "--study-factors", "2,4096",
                        "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, r.stderr
    assert r.stderr.strip().splitlines() == [r.stderr.strip()]
    # Which cloth is too small, not the grid's own name ("density"), which every cloth shares.
    assert "render matrix: cloth 'plain': study: coarsening factor 4096: one coarse voxel of 4096 voxels" in r.stderr
    assert sorted(p.name for p in out.iterdir()) == ["mine.txt"]
