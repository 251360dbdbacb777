"""The keyword form of weft.gen says what `weft gen`'s options say (docs/python.md "Cloth")."""

import json
import subprocess

import numpy as np
import pytest

import weft

KEYWORDS = dict(pattern="plain", yarns=(2, 2), yarn="wool", voxel_size=0.03, seed=5)


@pytest.fixture(scope="module")
def wool():
    return weft.gen(**KEYWORDS)


def test_keywords_equal_the_cli_options(tmp_path, run_cli, wool):
    run_cli("gen", "--pattern", "plain", "--yarns", "2x2", "--yarn", "wool", "--voxel-size", "0.03", "--seed", "5",
            "--out", tmp_path / "cli")
    assert json.loads((tmp_path / "cli" / "cloth.json").read_text()) == wool.spec
    cli = weft.load_grid(tmp_path / "cli" / "cloth.vdb")
    assert cli.bbox == wool.grid.bbox
    np.testing.assert_array_equal(cli.to_numpy(wool.grid.bbox), wool.grid.to_numpy())


def test_a_yarn_keyword_gives_that_preset_entirely(wool):
    cotton = json.loads(weft.default_cloth_spec())["warp_yarn"]
    for key in ("warp_yarn", "weft_yarn"):
        y = wool.spec[key]
        assert y["preset"] == "wool"
        # Not cotton's numbers under a wool label: the preset's own fields differ from cotton's.
        assert any(y[f] != cotton[f] for f in cotton if f != "preset")
    assert (wool.spec["warp_count"], wool.spec["weft_count"]) == (2, 2)


def test_keywords_override_the_spec_dict(small_cloth_spec, small_cloth):
    same = weft.gen(dict(small_cloth_spec, seed=99), seed=small_cloth_spec["seed"])
    assert same.spec == small_cloth.spec


@pytest.mark.parametrize("kwargs, exc", [
    ({"yarns": 3}, TypeError),
    ({"yarns": (1, 2, 3)}, TypeError),
    ({"yarn": "lace"}, weft.Error),
    ({"voxel_sise": 0.02}, weft.Error),
    ({"voxel_size": -1}, weft.Error),
])
def test_bad_keywords(kwargs, exc):
    with pytest.raises(exc):
        weft.gen(**kwargs)


def test_a_preset_renamed_over_another_presets_fields_is_refused_by_python_and_the_cli(tmp_path, weft_bin):
    spec = json.loads(weft.default_cloth_spec())  # every field: cotton's
    spec["warp_yarn"]["preset"] = "wool"
    with pytest.raises(weft.Error) as python_error:
        weft.gen(spec)
    for word in ("warp_yarn.preset", "'wool'", "cotton's", "ply_radius 0.08, wool's 0.11"):
        assert word in str(python_error.value)
    path = tmp_path / "cloth.json"
    path.write_text(json.dumps(spec))
    cli = subprocess.run([weft_bin, "--quiet", "gen", "--config", str(path), "--out", str(tmp_path / "out")],
                         capture_output=True, text=True)
    assert cli.returncode == 1
    # One shared rule: the CLI's line is the Python message, from its own file name on.
    assert cli.stderr.startswith("weft: error: ") and cli.stderr.strip().endswith(
        str(python_error.value).split(": ", 1)[1])
    assert not (tmp_path / "out" / "cloth.vdb").exists()


def test_the_preset_fills_what_a_yarn_omits_and_the_label_records_changes(small_cloth_spec):
    wool = json.loads(weft.default_cloth_spec())["warp_yarn"]  # cotton's numbers, for comparison below
    cloth = weft.gen(dict(small_cloth_spec, warp_yarn={"preset": "wool", "fiber_count": 12},
                          weft_yarn={"preset": "wool"}))
    warp, weft_yarn = cloth.spec["warp_yarn"], cloth.spec["weft_yarn"]
    assert warp["preset"] == "wool (modified: fiber_count)" and warp["fiber_count"] == 12
    assert weft_yarn["preset"] == "wool"
    # The unset fields are wool's, not cotton's defaults.
    assert all(warp[f] == weft_yarn[f] for f in warp if f not in ("preset", "fiber_count"))
    assert warp["ply_radius"] != wool["ply_radius"]
    # The resolved spec reads back to itself (the label is recomputed, not trusted).
    assert weft.gen(cloth.spec).spec == cloth.spec
    # Editing one field of the default (full) spec is a recorded modification, not an error.
    edited = json.loads(weft.default_cloth_spec())
    edited.update(warp_count=2, weft_count=2, voxel_size=0.03)
    edited["warp_yarn"]["fiber_count"] = 12
    assert weft.gen(edited).spec["warp_yarn"]["preset"] == "cotton (modified: fiber_count)"


def test_the_memory_budget_is_named_in_pythons_words():
    with pytest.raises(weft.Error) as e:
        weft.gen(yarns=(40, 40), voxel_size=0.002, max_memory_mb=1)
    said = str(e.value)
    assert "memory budget" in said and "max_memory_mb=" in said and "voxel_size=" in said, said
    assert "--" not in said, said


CROSSING = "v 0 0.5 0.1\nv 2 0.5 -0.1\nv 1 0 -0.1\nv 1 1 0.1\nl 1 2\nl 3 4\n"


def test_input_curves_make_an_import_equal_to_the_cli(tmp_path, run_cli, monkeypatch):
    (tmp_path / "crossing.obj").write_text(CROSSING)
    monkeypatch.chdir(tmp_path)  # a relative input resolves against the current folder, as in the CLI
    cloth = weft.gen(input="crossing.obj", warp_yarn={"preset": "cotton", "fiber_count": 8}, voxel_size=0.04)
    assert cloth.spec["pattern"] == "import"
    assert cloth.spec["input"] == str(tmp_path / "crossing.obj")
    assert cloth.grid.active_voxel_count > 0
    run_cli("gen", "--input", "crossing.obj", "--set", "warp.fiber_count=8", "--voxel-size", "0.04", "--out", "cli",
            cwd=tmp_path)
    cli = weft.load_grid(tmp_path / "cli" / "cloth.vdb")
    assert json.loads((tmp_path / "cli" / "cloth.json").read_text()) == cloth.spec
    np.testing.assert_array_equal(cli.to_numpy(cloth.grid.bbox), cloth.grid.to_numpy())


@pytest.mark.parametrize("kwargs", [{"pattern": "twill22"}, {"yarns": (2, 2)}])
def test_input_curves_with_a_weave_or_yarn_counts_are_refused(tmp_path, kwargs):
    (tmp_path / "crossing.obj").write_text(CROSSING)
    with pytest.raises(weft.Error, match="conflict"):
        weft.gen(input=tmp_path / "crossing.obj", **kwargs)


@pytest.mark.parametrize("kwargs", [{}, {"voxel_size": 0.05}])
def test_an_empty_input_is_refused_not_read_as_no_curves(kwargs):
    # cloth.json's "input": "" means no curves; a keyword naming none is a mistake (as weft gen --input "").
    with pytest.raises(weft.Error, match="input must name a curve file"):
        weft.gen(input="", **kwargs)
