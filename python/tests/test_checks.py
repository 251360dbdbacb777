"""One set of checks: Python refuses what the CLI refuses, through the same library code, and says
so in Python's words (docs/python.md "One set of checks")."""

import json
import re
import subprocess
import warnings

import numpy as np
import pytest

import weft
from conftest import random_grid

# The rule's own words, written once in weft/volume/beam_checks.cpp and said by both front ends.
AXIS_RULE = "axis beams' rays in one voxel column cross the same voxels"


def no_cli_flag(message):
    return re.search(r"(^|\s)--[a-z]", message) is None


@pytest.mark.parametrize("kwargs, said", [
    ({"rays_per_column": 4}, "rays_per_column=4"),
    ({"jitter": True}, "jitter=True"),
    ({"rays_per_column": 0}, "rays_per_column must be >= 1, got 0"),
])
def test_axis_beam_rays_and_jitter_refused_as_the_cli_does(kwargs, said):
    g, _ = random_grid()
    with pytest.raises(weft.Error) as e:
        weft.measure_beam(g, "x", **kwargs)
    assert said in str(e.value) and no_cli_flag(str(e.value)), str(e.value)
    if "must be" not in said:
        assert AXIS_RULE in str(e.value)


def test_the_cli_refuses_the_same_with_its_flag(tmp_path, weft_bin):
    g, _ = random_grid()
    g.save(tmp_path / "g.vdb")
    r = subprocess.run([weft_bin, "measure", "--grid", str(tmp_path / "g.vdb"), "--sigma", "1", "--direction", "x",
                        "--rays", "4", "--out", str(tmp_path / "m")], capture_output=True, text=True)
    assert r.returncode == 2 and "--rays 4: " + AXIS_RULE in r.stderr, r.stderr
    assert not (tmp_path / "m").exists()


def test_oblique_beams_take_more_rays_and_count_distinct_rays():
    g, _ = random_grid()
    one = weft.measure_beam(g, direction=(1, 1, 1), sigma=1)
    four = weft.measure_beam(g, direction=(1, 1, 1), sigma=1, rays_per_column=4, jitter=True)
    # Oblique: every ray counts (jittered origins enter or miss the box: about 4x, not exactly).
    assert four.rays == four.rays_traced > 3 * one.rays > 0
    axis = weft.measure_beam(g, "z", sigma=1)
    assert axis.rays == axis.rays_traced == g.to_numpy().shape[0] * g.to_numpy().shape[1]


def test_validate_refuses_more_rays_in_python_words(small_cloth):
    with pytest.raises(weft.Error) as e:
        weft.validate(small_cloth.grid, rays_per_column=2)
    assert "rays_per_column=2: " + AXIS_RULE in str(e.value) and no_cli_flag(str(e.value))


def without_timings(report):
    """The report without its timings (per axis, and the cost per stage), its curves (numpy
    arrays) as lists."""
    report.pop("cost_seconds", None)
    for axis in report["axes"]:
        axis.pop("timings", None)
        for key in ("depth", "T_gt", "stderr"):
            axis[key] = axis[key].tolist()
        axis["T"] = {name: t.tolist() for name, t in axis["T"].items()}
    return report


def test_validate_takes_a_number_and_axes_as_a_tuple(small_cloth):
    g = small_cloth.grid
    by_text = without_timings(weft.validate(g, window="0.3", axes="x,z"))
    by_value = without_timings(weft.validate(g, window=0.3, axes=("x", "z")))
    assert by_value == by_text
    assert without_timings(weft.validate(g, window=0.3, axes=(0, 2))) == by_text
    assert [a["axis"] for a in by_value["axes"]] == ["+x", "+z"]


@pytest.mark.parametrize("kwargs, exc, said", [
    ({"window": 0}, weft.Error, "window must be"),
    ({"window": -0.3}, weft.Error, "window must be"),
    ({"window": "yran"}, weft.Error, "is not yarn"),
    ({"window": [0.3]}, TypeError, "validate: window must be a number"),
    ({"axes": ("x", "w")}, weft.Error, "'w' is not x, y or z"),
    ({"axes": ("x", "x")}, weft.Error, "given twice"),
    ({"axes": 3}, TypeError, "validate: axes must be"),
    ({"seed": "one"}, TypeError, "validate: seed must be an integer"),
    ({"sigma": "2"}, TypeError, "validate: sigma must be a number"),
])
def test_validate_bad_arguments_in_python_words(small_cloth, kwargs, exc, said):
    with pytest.raises(exc) as e:
        weft.validate(small_cloth.grid, **kwargs)
    assert said in str(e.value) and "_validate_json" not in str(e.value) and no_cli_flag(str(e.value)), str(e.value)


def test_a_grid_without_yarn_diameter_is_told_the_window_keyword():
    g = weft.Grid.from_numpy(np.full((4, 4, 4), 0.5, dtype=np.float32), voxel_size=0.1)
    with pytest.raises(weft.Error) as e:
        weft.validate(g, sigma=2.0)
    assert "window=LENGTH" in str(e.value) and no_cli_flag(str(e.value)), str(e.value)


def scene_with_spare_medium():
    scene = json.loads(weft.builtin_scene("cloth_patch"))
    scene["camera"].update(width=8, height=6)
    scene["media"]["spare"] = dict(scene["media"]["cloth"])  # named by no shape
    return scene


def test_an_unused_medium_is_a_warning_in_python():
    with pytest.warns(weft.Warning, match="weft.render: medium 'spare' is not the interior or exterior of any shape"):
        weft.render(scene_with_spare_medium(), spp=1)
    assert issubclass(weft.Warning, UserWarning)
    scene = scene_with_spare_medium()
    del scene["media"]["spare"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the same scene without it: no warning
        weft.render(scene, spp=1)


def test_saturated_loops_are_a_warning_of_gen_in_the_callers_words():
    loopy = {"preset": "cotton", "loop_density": 100}
    with pytest.warns(weft.Warning, match=r"weft.gen: yarns: loop_density=100 puts 3 loop flyaways over each fibre"):
        weft.gen(yarns=(2, 2), voxel_size=0.05, warp_yarn=loopy, weft_yarn=loopy)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the preset's 2 loops per mm: no warning
        weft.gen(yarns=(2, 2), voxel_size=0.05)


def test_an_unused_medium_is_a_warning_in_the_cli(tmp_path, weft_bin):
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene_with_spare_medium()))
    r = subprocess.run([weft_bin, "--quiet", "render", str(path), "--spp", "1", "-o", str(tmp_path / "img.exr")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # On stderr, with the program's name, and not silenced by --quiet.
    assert "weft: warning: medium 'spare' is not the interior or exterior of any shape" in r.stderr
    assert "warning" not in r.stdout


def scene_with_grid(tmp_path, values, sigma=20.0):
    """The cloth_patch scene with its box filled by a grid medium of `values` (a 3-D array)."""
    grid = weft.Grid(voxel_size=0.5)
    for (i, j, k), v in np.ndenumerate(values):
        grid.set_value(i - 6, j - 6, k, float(v))  # active even when 0 (set_value activates)
    grid.save(tmp_path / "g.vdb")
    scene = scene_with_spare_medium()
    del scene["media"]["spare"]
    scene["media"]["cloth"] = {"type": "grid", "file": "g.vdb", "sigma": sigma, "albedo": 0.8}
    return scene


@pytest.mark.parametrize("values, sigma, empty", [
    (np.zeros((12, 12, 1)), 20.0, True),   # active voxels, every one 0
    (np.full((12, 12, 1), 0.3), 0.0, True),   # a zero sigma
    (np.full((12, 12, 1), 0.3), 20.0, False),  # a real medium: no warning
])
def test_an_empty_grid_medium_is_a_warning_in_python_and_the_cli(tmp_path, weft_bin, values, sigma, empty):
    scene = scene_with_grid(tmp_path, values, sigma)
    said = "medium 'cloth' has zero extinction everywhere"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        weft.render(scene, spp=1, base_dir=tmp_path)
    assert [str(w.message) for w in caught if issubclass(w.category, weft.Warning) and said in str(w.message)] == (
        ["weft.render: " + said + " (its grid's active voxels are all 0, or its sigma or mu is 0), so it does not "
         "affect the image"] if empty else [])
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    r = subprocess.run([weft_bin, "--quiet", "render", str(path), "--spp", "1", "-o", str(tmp_path / "img.exr")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (("weft: warning: " + said) in r.stderr) == empty, r.stderr


# Integer arguments out of their C++ type's range, and threads past the CLI's --threads range, are
# refused by weft in its words, not by pybind11 with a TypeError naming the private binding.
@pytest.mark.parametrize("kwargs, said", [
    ({"seed": -1}, "render: seed must be >= 0, got -1"),
    ({"seed": 2**64}, "render: seed must be <= 18446744073709551615"),
    ({"spp": 2**40}, "render: spp must be <= 16777216"),
    ({"spp": np.int64(0)}, "render: spp must be >= 1, got 0"),
    ({"threads": 2000}, "threads=2000: must be in [1, 1024]"),
])
def test_render_integers_out_of_range_are_weft_errors(kwargs, said):
    with pytest.raises(weft.Error) as e:
        weft.render("cornell_media", **kwargs)
    assert said in str(e.value), str(e.value)


def small_scene_dict():
    scene = json.loads(weft.builtin_scene("cornell_media"))
    scene["camera"]["width"] = 8
    scene["camera"]["height"] = 6
    return scene


def test_numpy_numbers_in_a_scene_dict_are_numbers():
    plain = weft.render(small_scene_dict(), spp=1, seed=3)
    scene = small_scene_dict()
    scene["camera"]["width"] = np.int64(8)
    scene["camera"]["height"] = np.int32(6)
    scene["camera"]["position"] = np.asarray(scene["camera"]["position"], dtype=np.float64)
    scene["camera"]["fov"] = np.float32(scene["camera"]["fov"])
    image = weft.render(scene, spp=np.int64(1), seed=np.uint64(3))
    assert np.array_equal(image, plain)


@pytest.mark.parametrize("where, value, said", [
    (("camera", "fov"), float("nan"), "render: camera.fov must be a finite number, got nan"),
    (("camera", "position"), np.array([0.0, np.inf, 3.6]), "render: camera.position[1] must be a finite number"),
])
def test_a_non_finite_number_in_a_scene_dict_is_named(where, value, said):
    scene = small_scene_dict()
    scene[where[0]][where[1]] = value
    with pytest.raises(weft.Error) as e:
        weft.render(scene, spp=1)
    assert said in str(e.value), str(e.value)


# One tilt range, the library's, for the CLI and Python: [0, 80).
def test_tilt_80_is_refused_before_any_cloth_by_python_and_the_cli(tmp_path, weft_bin):
    with pytest.raises(weft.Error) as e:
        weft.render_matrix(quick=True, cloths="plain", lightings="back", tilts=80, out=tmp_path / "m")
    assert "tilt 80 degrees is not in [0, 80)" in str(e.value), str(e.value)
    assert not (tmp_path / "m").exists()
    for flags in (["--tilt", "80"], ["--study", "--study-tilts", "80"], ["--study", "--study-tilts", "nan"]):
        r = subprocess.run([weft_bin, "render", *flags, "--out", str(tmp_path / "c")], capture_output=True, text=True)
        assert r.returncode == 2 and "must be degrees in [0, 80)" in r.stderr, (flags, r.stderr)


# Coordinates beyond what single-precision Embree traces (docs/render.md §1, "Where Embree's
# floats are") used to abort inside Embree and take the interpreter with them; they are a weft.Error
# naming the key, and the interpreter goes on.
@pytest.mark.parametrize("edit, said", [
    (lambda s: s["camera"].update(position=[0, 0, 1e20]), "camera.position reaches 1e+20"),
    (lambda s: s["camera"].update(aperture_radius=1e20), "camera.aperture_radius reaches 1e+20"),
    (lambda s: s["shapes"].append({"type": "sphere", "radius": 1e30, "material": "white"}),
     "shapes[9]: coordinates reach 1e+30"),
    (lambda s: s["shapes"].append({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1e30], "material": "white"}),
     "shapes[9]: coordinates reach 1e+30"),
])
def test_render_beyond_what_embree_traces_is_a_weft_error(edit, said):
    scene = small_scene_dict()
    edit(scene)
    with pytest.raises(weft.Error) as e:
        weft.render(scene, spp=1)
    assert said in str(e.value), str(e.value)
    assert weft.render(small_scene_dict(), spp=1).shape == (6, 8, 3)  # the interpreter lives on



def test_local_fields_refuse_a_block_that_holds_the_whole_cloth():
    # One coarse voxel over the whole active box would spread the cloth over its vacuum (the CLI's
    # `weft fit --block` refuses it the same way); a block below the largest extent is taken.
    grid = weft.Grid.from_numpy(np.full((6, 4, 2), 0.5, np.float32), voxel_size=0.1)
    with pytest.raises(weft.Error, match=r"^local_fields: block=6: one coarse voxel of 6 voxels .* holds the whole "
                                         r"active box of grid .* \(6x4x2 voxels\).*use a block below 6$"):
        weft.local_fields(grid, 6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a block within the cloth on every axis: no warning
        assert weft.local_fields(grid, 2).blocks > 0
    # Thicker than the cloth along y and z (4 and 2 voxels): taken, with the CLI's warning.
    with pytest.warns(weft.Warning, match=r"blocks of 5 voxels are thicker than the cloth along yz \(2 voxels there\)"):
        assert weft.local_fields(grid, 5).blocks > 0
