"""The keyword form of weft.gen says what `weft gen`'s options say (docs/python.md "Cloth")."""

import json

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
