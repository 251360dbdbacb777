"""Ground truth, window statistics and fits through Python, against numpy oracles and the CLI."""

import csv
import json
import threading

import numpy as np
import pytest

import weft
from conftest import random_grid


def beam_oracle(a, sigma, h, axis):
    """T(t_k) of an axis beam by numpy: one ray per column, tau summed voxel by voxel."""
    c = np.moveaxis(a.astype(np.float64), axis, -1)
    tau = sigma * h * np.concatenate([np.zeros(c.shape[:-1] + (1,)), np.cumsum(c, axis=-1)], axis=-1)
    e = np.exp(-tau).reshape(-1, tau.shape[-1])
    return e.mean(axis=0), e.std(axis=0) / np.sqrt(e.shape[0]), e.shape[0]


@pytest.mark.parametrize("axis", [0, 1, 2])
def test_axis_beam_matches_numpy_oracle(axis):
    g, a = random_grid(shape=(5, 6, 7), zero_fraction=0.2)
    # Full columns: the active bbox is the whole array when its faces have active voxels.
    a[0, 0, 0] = a[-1, -1, -1] = 0.5
    g = weft.Grid.from_numpy(a, voxel_size=0.5)
    curve = weft.measure_beam(g, axis, sigma=1.7)
    T, se, rays = beam_oracle(a, 1.7, 0.5, axis)
    assert curve.rays == rays
    np.testing.assert_allclose(curve.depth, 0.5 * np.arange(a.shape[axis] + 1), rtol=1e-12)
    np.testing.assert_allclose(curve.T, T, rtol=1e-9)
    np.testing.assert_allclose(curve.log_T, np.log(T), rtol=1e-9)
    # stderr: of the mean over rays (population std / sqrt(n) up to the n/(n-1) convention).
    np.testing.assert_allclose(curve.stderr[1:], se[1:], rtol=5.0 / rays)
    depths, T2, stderr = curve  # unpacks
    np.testing.assert_array_equal(T2, curve.T)


def test_axis_spellings_agree():
    g, _ = random_grid()
    a = weft.measure_beam(g, "x", sigma=2.0)
    b = weft.measure_beam(g, 0, sigma=2.0)
    c = weft.measure_beam(g, direction=(3.0, 0.0, 0.0), sigma=2.0)
    np.testing.assert_array_equal(a.T, b.T)
    np.testing.assert_array_equal(a.T, c.T)
    assert tuple(a.direction) == (1.0, 0.0, 0.0)


def test_oblique_beam_two_implementations_agree():
    # weft's hierarchical DDA against OpenVDB's own DDA on the same rays; and in a uniform medium
    # (mu = sigma C = 1) rays that leave the box stop accumulating, so T(t) >= exp(-t), = at 0.
    g, _ = random_grid(shape=(9, 8, 10), zero_fraction=0.3)
    ours = weft.measure_beam(g, direction=(1.0, 2.0, 3.0), sigma=2.0, method="per-ray")
    ref = weft.measure_beam(g, direction=(1.0, 2.0, 3.0), sigma=2.0, method="openvdb")
    np.testing.assert_allclose(ours.T, ref.T, rtol=1e-9)
    a = np.full((12, 12, 12), 0.25, dtype=np.float32)
    u = weft.measure_beam(weft.Grid.from_numpy(a, voxel_size=0.1), direction=(1.0, 1.0, 1.0), sigma=4.0)
    assert u.T[0] == 1.0
    assert np.all(u.T >= np.exp(-u.depth) * (1 - 1e-12))
    assert u.T[-1] < 1.0


def test_identical_to_cli(tmp_path, run_cli, small_cloth):
    path = tmp_path / "cloth.vdb"
    small_cloth.grid.save(path)
    run_cli("measure", "--grid", path, "--direction", "x", "--sigma", "106.1", "--out", tmp_path / "m")
    with open(tmp_path / "m" / "beams.csv") as f:
        # The first line records sigma and the grid (a comment), then the CSV header.
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    curve = weft.measure_beam(weft.load_grid(path), "x", sigma=106.1)
    assert len(rows) == len(curve)
    fmt = lambda x: "%.10g" % x
    assert [r["t"] for r in rows] == [fmt(x) for x in curve.depth]
    assert [r["T"] for r in rows] == [fmt(x) for x in curve.T]
    assert [r["stderr"] for r in rows] == [fmt(x) for x in curve.stderr]


def test_window_stats_match_numpy():
    g, a = random_grid(shape=(4, 5, 8), zero_fraction=0.3)
    a[0, 0, 0] = a[-1, -1, -1] = 0.5
    g = weft.Grid.from_numpy(a, voxel_size=0.5)
    s = weft.window_stats(g, "z")  # window = the extent: one sample per column
    col = a.astype(np.float64).mean(axis=2).ravel()
    assert s.samples == col.size
    assert s.mean == pytest.approx(col.mean(), rel=1e-6)
    assert s.variance == pytest.approx(col.var(), rel=1e-5)
    assert s.window == pytest.approx(4.0)
    # Window of 2 voxels: every position along every column.
    s2 = weft.window_stats(g, 2, window=1.0)
    w = (a[:, :, :-1].astype(np.float64) + a[:, :, 1:]) / 2
    assert s2.samples == w.size
    assert s2.mean == pytest.approx(w.mean(), rel=1e-6)
    assert s2.variance == pytest.approx(w.var(), rel=1e-5)
    fit = weft.gamma_from_moments(s.mean, s.variance, 3.0)
    assert fit.alpha == pytest.approx(s.mean ** 2 / s.variance)
    assert fit.beta == pytest.approx(s.mean / s.variance)
    t = np.array([0.0, 0.5, 2.0])
    np.testing.assert_allclose(fit.law().T(t), (1 + 3.0 * t / fit.beta) ** -fit.alpha, rtol=1e-12)
    np.testing.assert_allclose(fit.exponential_law().T(t), np.exp(-3.0 * s.mean * t), rtol=1e-12)
    pooled = weft.pool([weft.window_stats(g, ax) for ax in range(3)])
    assert pooled.mean == pytest.approx(np.mean([weft.window_stats(g, ax).mean for ax in range(3)]))


def test_least_squares_recovers_a_gamma_curve():
    # A medium whose column means are gamma-like: the fit must at least beat the exponential.
    g, a = random_grid(shape=(30, 30, 6), zero_fraction=0.5, seed=9)
    curve = weft.measure_beam(g, "z", sigma=5.0)
    s = weft.window_stats(g, "z")
    moments = weft.gamma_from_moments(s.mean, s.variance, 5.0)
    lsq = weft.fit_gamma_to_curve(curve, 5.0, moments)
    err_lsq = weft.compare(curve, weft.log_curve(lsq.fit.law(), curve.depth))
    err_exp = weft.compare(curve, weft.log_curve(moments.exponential_law(), curve.depth))
    assert lsq.converged
    assert err_lsq.rms_abs_t <= err_exp.rms_abs_t
    assert err_lsq.rms_abs_t == pytest.approx(lsq.rms, rel=1e-6, abs=1e-12)


def test_progress_callback_and_errors_from_it():
    g, _ = random_grid(shape=(40, 40, 40), zero_fraction=0.1)
    calls = []
    weft.measure_beam(g, direction=(1, 2, 3), sigma=1,
                      progress=lambda label, done, total: calls.append((label, done, total)))
    assert calls and all(0 <= d <= t for _, d, t in calls)
    assert calls[-1][1] == calls[-1][2]

    def boom(label, done, total):
        raise ValueError("stop here")
    with pytest.raises(ValueError, match="stop here"):
        weft.measure_beam(g, direction=(1, 2, 3), sigma=1, progress=boom)
    with pytest.raises(TypeError):
        weft.measure_beam(g, "x", sigma=1, progress=lambda: None)  # wrong signature: its TypeError propagates


def test_gil_is_released_during_long_calls():
    # Another Python thread keeps running while measure_beam works.
    g, _ = random_grid(shape=(60, 60, 60), zero_fraction=0.1)
    ticks = []
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            stop.wait(0.001)
    thread = threading.Thread(target=count)
    thread.start()
    for _ in range(3):
        weft.measure_beam(g, direction=(1, 2, 3), sigma=1)
    stop.set()
    thread.join()
    assert len(ticks) > 1


@pytest.mark.parametrize("kwargs, exc", [
    (dict(axis="w"), weft.Error),
    (dict(axis=3), weft.Error),
    (dict(axis=1.5), TypeError),
    (dict(axis="x", direction=(1, 0, 0)), weft.Error),
    (dict(direction=(0, 0, 0)), weft.Error),
    (dict(direction=(np.nan, 0, 1)), weft.Error),
    (dict(direction=(1, 0)), TypeError),
    (dict(axis="x", sigma=0.0), weft.Error),
    (dict(axis="x", sigma=np.nan), weft.Error),
    (dict(axis="x", sigma="1"), TypeError),
    (dict(axis="x", rays_per_column=0), weft.Error),
    (dict(axis="x", method="magic"), weft.Error),
    (dict(direction=(1, 1, 0), method="streaming"), weft.Error),
    (dict(axis="x", depth_step=-1.0), weft.Error),
])
def test_measure_bad_input(kwargs, exc):
    g, _ = random_grid()
    with pytest.raises(exc):
        weft.measure_beam(g, **({"sigma": 1.0} | kwargs))


def test_measure_beam_takes_sigma_as_the_cli_does(tmp_path, run_cli, small_cloth):
    """sigma=None: the grid's provenance, as `weft measure --grid` (never a silent sigma = 1)."""
    g = small_cloth.grid
    path = tmp_path / "cloth.vdb"
    g.save(path)
    run_cli("measure", "--grid", path, "--direction", "z", "--out", tmp_path / "m")
    with open(tmp_path / "m" / "beams.csv") as f:
        rows = [line.split(",") for line in f.read().splitlines()[2:]]
    cli_t = np.array([float(r[5]) for r in rows])
    assert cli_t[-1] < 0.9  # the cloth's sigma, not 1, makes it this dark
    np.testing.assert_allclose(weft.measure_beam(g, "z").T, cli_t, rtol=1e-9)  # the CSV keeps 10 digits
    np.testing.assert_allclose(weft.measure_beam(g, "z", sigma=g.sigma).T, cli_t, rtol=1e-9)
    bare, _ = random_grid()  # no provenance: sigma must be given
    with pytest.raises(weft.Error, match="sigma=S"):
        weft.measure_beam(bare, "z")


def test_fit_bad_input():
    g, _ = random_grid()
    with pytest.raises(weft.Error):
        weft.measure_beam(weft.Grid(), "x")  # empty grid
    with pytest.raises(weft.Error):
        weft.window_stats(g, "x", window=-1.0)
    with pytest.raises(weft.Error):
        weft.gamma_from_moments(-1.0, 0.1, 1.0)
    with pytest.raises(weft.Error):
        weft.gamma_from_moments(0.5, 0.1, np.nan)
    # concentrations are >= 0: a zero mean holds no variance (it was dropped, giving T = 1)
    with pytest.raises(weft.Error, match="mean concentration 0 with variance 0.1 is impossible"):
        weft.gamma_from_moments(0.0, 0.1, 10)
    assert weft.gamma_from_moments(0.0, 0.0, 10).alpha == np.inf
    with pytest.raises(TypeError):
        weft.window_stats("grid", "x")
    c = weft.measure_beam(g, "x", sigma=1)
    with pytest.raises(weft.Error):
        weft.compare(c, [0.0])
    with pytest.raises(weft.Error):
        weft.log_curve(weft.law("exponential", mu=1), [-1.0])


def test_validate_equals_the_cli_report(tmp_path, run_cli, small_cloth):
    """weft.validate(grid) gives the same models and errors as `weft validate --grid` (same text)."""
    path = tmp_path / "cloth.vdb"
    small_cloth.grid.save(path)
    run_cli("validate", "--grid", path, "--no-plot", "--out", tmp_path / "v")
    with open(tmp_path / "v" / "report.json") as f:
        cli = json.load(f)
    py = weft.validate(weft.load_grid(path))
    assert py["sigma"] == cli["sigma"]
    assert len(py["axes"]) == len(cli["axes"]) == 3
    for a, b in zip(py["axes"], cli["axes"]):
        assert a["errors"] == b["errors"]
        assert a["best_predictive"] == b["best_predictive"]
        # Only the least-squares reference sees the ground truth.
        for name, model in a["models"].items():
            assert model["uses_ground_truth"] == (name == "least-squares")


def test_validate_refuses_a_grid_without_sigma():
    g = weft.Grid.from_numpy(np.full((4, 4, 4), 0.5, dtype=np.float32), voxel_size=0.1)
    with pytest.raises(weft.Error, match="sigma"):
        weft.validate(g)
    with pytest.raises(weft.Error, match="yarn diameter"):
        weft.validate(g, sigma=2.0)
    report = weft.validate(g, sigma=2.0, window="extent")
    # A uniform medium: every predictive model is the exponential, to rounding.
    for axis in report["axes"]:
        for name, err in axis["errors"].items():
            if name != "least-squares":
                assert err["rms_abs_T"] < 1e-9, name


def test_validate_says_when_the_window_cannot_be_measured_or_is_clamped():
    uniform = weft.Grid.from_numpy(np.full((4, 4, 4), 0.3, np.float32), voxel_size=0.1)
    plate = weft.Grid.from_numpy(np.full((1, 10, 10), 0.3, np.float32), voxel_size=0.1)
    for g in (uniform, plate):
        with pytest.raises(weft.Error, match=r"^yarn scale: cannot be measured on grid 'density': its "
                                             r"concentration is uniform .*: pass window=LENGTH"):
            weft.validate(g, sigma=2, window="yarn-measured")
    g, _ = random_grid()
    with pytest.warns(weft.Warning, match="window=1e-09 is shorter than half a voxel") as caught:
        report = weft.validate(g, sigma=2, window=1e-9, axes="x")
    assert any("reproduce the ground truth" in str(w.message) for w in caught)
    h = g.voxel_size
    assert report["window"]["length"] == (1e-9,) * 3 and report["window"]["length_used"] == (h, h, h)
    assert report["axes"][0]["stats"]["window"] == h


def test_validate_does_not_depend_on_where_the_array_starts():
    """Grid.from_numpy puts element 0 at index_origin (0 by default): the same voxels at other
    index origins give the same prediction, every model (blocks anchored to the cloth,
    docs/validate.md)."""
    rng = np.random.default_rng(11)
    a = np.zeros((23, 19, 14), dtype=np.float32)
    a[:, ::2, 3:9] = rng.uniform(0.2, 0.8, size=(23, 10, 6))  # bands of "yarn" with holes between
    a[::3, :, 7:12] += rng.uniform(0.1, 0.5, size=(8, 19, 5)).astype(np.float32)
    runs = [weft.validate(weft.Grid.from_numpy(a, voxel_size=0.02, index_origin=o), sigma=40.0, window="0.1")
            for o in [(0, 0, 0), (1, 0, 0), (0, 3, 0), (0, 0, 4), (-7, 2, 13)]]
    for run in runs[1:]:
        for a0, a1 in zip(runs[0]["axes"], run["axes"]):
            assert a1["predicted"]["model"] == a0["predicted"]["model"]
            assert a1["predicted"]["uses_ground_truth"] is False
            assert a1["best_by_ground_truth"]["uses_ground_truth"] is True
            for name, err in a0["errors"].items():
                if a0["models"][name]["uses_ground_truth"]:
                    continue  # the least-squares reference is an iterative fit, not a prediction
                assert a1["errors"][name]["rms_abs_T"] == pytest.approx(err["rms_abs_T"], rel=1e-9, abs=1e-12), name


def test_fields_beam_identical_to_cli(tmp_path, run_cli, small_cloth):
    """weft.measure_fields_beam is `weft measure --fields` number for number (same rays, depths,
    sigma and memory rule), along an axis and an oblique direction."""
    path = tmp_path / "cloth.vdb"
    small_cloth.grid.save(path)
    fields = tmp_path / "fields.vdb"
    weft.local_fields(small_cloth.grid, 4).save(fields)
    run_cli("measure", "--grid", path, "--direction", "z", "--direction", "0,0.6,0.8", "--fields", fields,
            "--memory", "segment", "--out", tmp_path / "m")
    with open(tmp_path / "m" / "fields.csv") as f:
        rows = list(csv.DictReader(f))
    fmt = lambda x: "%.10g" % x
    grid = weft.load_grid(path)
    for beam, direction in enumerate([(0, 0, 1), (0, 0.6, 0.8)]):
        mine = [r for r in rows if r["beam"] == str(beam)]
        curve = weft.measure_fields_beam(fields, grid, direction=direction, memory="segment")
        truth = weft.measure_beam(grid, direction=direction)
        assert [r["t"] for r in mine] == [fmt(x) for x in curve.depth]
        assert [r["T_fields"] for r in mine] == [fmt(x) for x in curve.T]
        assert [r["T_voxel"] for r in mine] == [fmt(x) for x in truth.T]
        # A prediction, not the truth: the coarse law differs from the voxels somewhere.
        assert np.max(np.abs(curve.T - truth.T)) > 0
    report = json.loads((tmp_path / "m" / "measure.json").read_text())
    assert report["fields"]["memory"] == "segment"
    end = report["beams"][1]["fields"]
    assert end["relative_difference_at_depth_max"] == pytest.approx(curve.T[-1] / truth.T[-1] - 1, rel=1e-6)


@pytest.mark.parametrize("kwargs,words", [
    ({"memory": "forever"}, "unknown memory rule 'forever'"),
    ({"direction": (0, 0, 0)}, "direction"),
    ({"depth_step": -1.0}, "depth_step"),
])
def test_fields_beam_bad_input(tmp_path, small_cloth, kwargs, words):
    fields = tmp_path / "fields.vdb"
    weft.local_fields(small_cloth.grid, 4).save(fields)
    with pytest.raises(weft.Error, match=words):
        weft.measure_fields_beam(fields, small_cloth.grid, **kwargs)
    with pytest.raises(weft.Error, match="missing.vdb"):
        weft.measure_fields_beam(tmp_path / "missing.vdb", small_cloth.grid)


def test_full_chords_on_an_axis_beam_is_refused_as_the_cli_refuses_it():
    """An axis beam's rays all cross the whole box: full_chords=True would change nothing, and
    `weft measure --full-chords` with only axis directions is refused (weft/volume/beam_checks.cpp)."""
    g, _ = random_grid()
    fibres = weft.Fibres([[(-0.5, 0.5, 0.5), (1.5, 0.5, 0.5)]], 0.05)
    calls = [lambda: weft.measure_beam(g, "z", sigma=1, full_chords=True),
             lambda: weft.measure_beam(g, direction=(0, -1, 0), sigma=1, full_chords=True),
             lambda: weft.measure_fields_beam("no-such-fields.vdb", g, "x", sigma=1, full_chords=True),
             lambda: weft.measure_fibre_beam(fibres, direction="z", cell=0.1, full_chords=True)]
    for call in calls:
        with pytest.raises(weft.Error) as e:
            call()
        said = str(e.value)
        assert "full_chords=True changes oblique beams only" in said and "--" not in said, said
    assert weft.measure_beam(g, direction=(1, 0, 2), sigma=1, full_chords=True).rays > 0


def uniform_slab(index_origin=(0, 0, 0), origin=(0.0, 0.0, 0.0)):
    """A uniform 8 x 8 x 3 slab of voxels 0.1 wide: a square face across x and y."""
    a = np.full((8, 8, 3), 0.3, dtype=np.float32)
    return weft.Grid.from_numpy(a, voxel_size=0.1, index_origin=index_origin, origin=origin)


@pytest.mark.parametrize("far", [False, True])
def test_full_chords_exactly_45_degrees_across_a_square_face_is_refused(far):
    """Only the diagonal crosses a square face's box face to face at exactly 45 degrees: refused
    before any ray is traced, in Python's words, wherever the grid is indexed."""
    shift = np.array([2**29 + 3, 5, -2**29]) if far else np.zeros(3, dtype=np.int64)
    g = uniform_slab(tuple(int(v) for v in shift), tuple(float(v) for v in -0.1 * shift))
    for d in [(1, 1, 0), (-1, 1, 0), (1, -1, 0)]:
        with pytest.raises(weft.Error) as e:
            weft.measure_beam(g, direction=d, sigma=1, full_chords=True)
        assert str(e.value).startswith("measure_beam: full_chords=True: beam (") and "no ray crosses the box" in str(e.value)
        assert weft.measure_beam(g, direction=d, sigma=1).rays > 0
    # Tilted out of the square's plane, the slab's two large faces set the depth: rays are kept.
    assert weft.measure_beam(g, direction=(1, 1, 3), sigma=1, full_chords=True).rays > 0


def test_a_grid_indexed_far_away_gives_the_same_beam_bytes():
    """The same slab in the same place, indexed from 2^29 away: the same T, byte for byte, with
    and without full chords (docs/validate.md "Beams far from index 0")."""
    rng = np.random.default_rng(5)
    a = rng.uniform(0.05, 1.0, size=(9, 7, 5)).astype(np.float32)
    shift = np.array([2**30, 5, -2**29])
    near = weft.Grid.from_numpy(a, voxel_size=0.02, index_origin=(-6, -6, -17), origin=(0.0, 0.0, 0.0))
    far = weft.Grid.from_numpy(a, voxel_size=0.02, index_origin=tuple(int(v) for v in shift + (-6, -6, -17)),
                               origin=tuple(float(v) for v in -0.02 * shift))
    for full in (False, True):
        b0 = weft.measure_beam(near, direction=(1, 0, 2), sigma=3, rays_per_column=3, full_chords=full)
        b1 = weft.measure_beam(far, direction=(1, 0, 2), sigma=3, rays_per_column=3, full_chords=full)
        assert b0.rays == b1.rays > 0
        for x, y in zip(b0, b1):
            assert np.array_equal(x, y)


def _copy_of(grid, array=None, kind=None):
    """``grid``'s voxels (or ``array`` on its lattice) and weft: metadata in a new grid; ``kind``
    recorded as weft:value_kind ("": none recorded)."""
    lo = grid.bbox[0]
    out = weft.Grid.from_numpy(grid.to_numpy() if array is None else array, voxel_size=grid.voxel_size,
                               index_origin=tuple(int(v) for v in lo), origin=list(grid.origin))
    for key, value in grid.metadata.items():
        if key.startswith("weft:") and not (kind is not None and key == "weft:value_kind"):
            out.set_metadata(key, value)
    if kind:
        out.set_metadata("weft:value_kind", kind)
    return out


def test_fields_beam_refuses_the_fields_of_another_cloth(tmp_path, small_cloth):
    """The fields must be the grid's own block means (docs/validate.md "Fields along any direction"):
    those of a part of the cloth, on the same lattice, are refused naming the file and the cell,
    with advice in Python's words; the grid's own, through a copy, are taken."""
    grid = small_cloth.grid
    a = grid.to_numpy()
    part = a.copy()
    part[:, :, a.shape[2] // 2:] = 0.0
    fields = tmp_path / "part_fields.vdb"
    weft.local_fields(_copy_of(grid, part), 4).save(fields)
    with pytest.raises(weft.Error) as e:
        weft.measure_fields_beam(fields, grid, direction=(1, 0, 1))
    text = str(e.value)
    assert text.startswith("measure_fields_beam: local-gamma fields '%s': not grid" % fields)
    assert "its cell at" in text and "weft.local_fields(grid, B).save(path)" in text and "--" not in text
    own = tmp_path / "own_fields.vdb"
    weft.local_fields(_copy_of(grid), 4).save(own)
    assert len(weft.measure_fields_beam(own, grid, direction=(1, 0, 1))) > 1


def test_fields_beam_value_kind_advice_names_no_cli_option(tmp_path, small_cloth):
    """Fields recording the other value kind: Python's advice is one a Python caller can follow
    (the grid's metadata, weft.local_fields), never `--values`."""
    grid = small_cloth.grid
    fields = tmp_path / "extinction_fields.vdb"
    weft.local_fields(_copy_of(grid, kind="extinction"), 4).save(fields)
    for g, words in ((_copy_of(grid, kind="concentration"), "fields of another grid"),
                     (_copy_of(grid, kind=""), "grid.set_metadata('weft:value_kind', 'extinction')")):
        with pytest.raises(weft.Error) as e:
            weft.measure_fields_beam(fields, g, direction=(1, 0, 1), sigma=30.0)
        assert words in str(e.value) and "--values" not in str(e.value)


@pytest.mark.parametrize("call", ["measure_beam", "measure_fields_beam"])
@pytest.mark.parametrize("kwargs", [
    dict(axis="w"), dict(axis=5), dict(axis="x", direction=(1, 0, 0)), dict(direction=(1, 0)),
    dict(direction=(np.nan, 0, 1)), dict(axis="x", rays_per_column=0), dict(axis="x", jitter=True),
    dict(axis="x", column_stride=5000), dict(axis="x", depth_step=1e-300),
])
def test_beam_calls_name_themselves_once(tmp_path, small_cloth, call, kwargs):
    """Every refusal of a beam call starts with the call's name, once (docs/python.md)."""
    grid = small_cloth.grid
    args = (grid,)
    if call == "measure_fields_beam":
        fields = tmp_path / "fields.vdb"
        weft.local_fields(grid, 4).save(fields)
        args = (fields, grid)
    with pytest.raises(weft.Error) as e:
        getattr(weft, call)(*args, **kwargs)
    text = str(e.value)
    assert text.startswith(call + ": "), text
    assert text.count("measure_") == text.count(call + ": ") + text.count("weft.measure_beam("), text
    assert "axis: axis" not in text and text.count(call + ": ") == 1, text


def test_streaming_on_an_oblique_beam_is_refused_in_pythons_words(small_cloth):
    with pytest.raises(weft.Error, match=r"^measure_beam: method='streaming' traces axis beams only, and direction "
                                         r"\(0.7071, 0, 0.7071\) is oblique; use method='auto' or 'per-ray'$"):
        weft.measure_beam(small_cloth.grid, direction=(1, 0, 1), method="streaming")
