"""weft.validate returns the whole answer: the report plus, per axis, the curves behind it as
numpy arrays, sigma's and the window's source and the version (docs/python.md "validate")."""

import sys

import numpy as np
import pytest

import weft


@pytest.fixture(scope="module")
def report(small_cloth):
    return weft.validate(small_cloth.grid)


def test_ground_truth_arrays_are_the_beams(report, small_cloth):
    for axis in report["axes"]:
        assert axis["depth"].shape == axis["T_gt"].shape == axis["stderr"].shape
        beam = weft.measure_beam(small_cloth.grid, axis["axis"], sigma=report["sigma"])
        np.testing.assert_array_equal(axis["depth"], beam.depth)
        np.testing.assert_array_equal(axis["T_gt"], beam.T)
        np.testing.assert_array_equal(axis["stderr"], beam.stderr)


def test_every_model_curve_gives_its_reported_errors(report):
    for axis in report["axes"]:
        assert set(axis["T"]) == set(axis["errors"]) == set(axis["models"]) and len(axis["T"]) >= 5
        for name, T in axis["T"].items():
            d = np.abs(T - axis["T_gt"])
            assert np.sqrt(np.mean(d ** 2)) == pytest.approx(axis["errors"][name]["rms_abs_T"], rel=1e-9, abs=1e-15)
            assert d.max() == pytest.approx(axis["errors"][name]["max_abs_T"], rel=1e-9, abs=1e-15)


def test_sources_and_version(report, small_cloth):
    assert report["version"] == weft.__version__
    assert report["sigma_source"].startswith("grid provenance: ")
    assert report["window"]["rule"] == "yarn" and "provenance" in report["window"]["source"]
    given = weft.validate(small_cloth.grid, sigma=2.0, window=0.3, axes="z")
    assert given["sigma_source"] == "sigma=" and given["sigma"] == 2.0
    assert given["window"]["rule"] == "length" and given["window"]["length"] == (0.3, 0.3, 0.3)


def test_plot_validation_says_what_to_install_without_matplotlib(report, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(ImportError, match="plot_validation needs matplotlib: install it"):
        weft.plot_validation(report)


def test_plot_validation_draws_the_figure(report, tmp_path):
    pytest.importorskip("matplotlib")
    fig = weft.plot_validation(report, tmp_path / "validation.png")
    assert len(fig.axes) == len(report["axes"]) and (tmp_path / "validation.png").stat().st_size > 0


def test_the_prediction_alone_is_the_full_runs_prediction(report, small_cloth):
    alone = weft.validate(small_cloth.grid, models="predicted")
    assert alone["models_computed"] == "local-gamma-two-scale"
    for full_axis, axis in zip(report["axes"], alone["axes"]):
        assert set(axis["T"]) == {"local-gamma-two-scale", "exponential"}
        assert axis["stats"] is None
        np.testing.assert_array_equal(axis["T"]["local-gamma-two-scale"], full_axis["T"]["local-gamma-two-scale"])
        assert axis["predicted"] == full_axis["predicted"]
    some = weft.validate(small_cloth.grid, axes="z", models=("gamma", "local-gamma"))
    assert some["models_computed"] == "gamma,local-gamma" and "predicted" not in some["axes"][0]
    assert some["axes"][0]["acceptance_predicted_at_most_third_of_exponential"] is None


@pytest.mark.parametrize("models, error", [("gamma,bogus", weft.Error), (("gamma", 3), weft.ArgumentTypeError),
                                           (5, weft.ArgumentTypeError), ((), weft.Error),
                                           ("least-squares", weft.Error), ("gamma,", weft.Error),
                                           (b"gamma", weft.ArgumentTypeError)])
def test_bad_model_lists_are_refused(small_cloth, models, error):
    with pytest.raises(error, match="models"):
        weft.validate(small_cloth.grid, models=models)


def test_ratios_to_an_exact_exponential_are_undefined_not_failed(report, small_cloth):
    """At sigma = 1e-300, T = 1 everywhere: every model and the exponential baseline are exact,
    and a ratio to an error of 0 is undefined. It is null with the reason, and the acceptance is
    null (neither passed nor failed), as in report.json of weft validate (docs/validate.md)."""
    assert all(axis["ratios_undefined"] is None for axis in report["axes"])
    exact = weft.validate(small_cloth.grid, sigma=1e-300, axes="x,z")
    assert exact["acceptance_all_axes"] is None
    for axis in exact["axes"]:
        assert "exponential baseline is exact at this sigma" in axis["ratios_undefined"]
        assert axis["errors"]["exponential"]["rms_abs_T"] == 0.0
        assert set(axis["ratio_to_exponential_rms_T"].values()) == {None}
        assert axis["predicted"]["ratio_to_exponential_rms_T"] is None
        assert axis["acceptance_predicted_at_most_third_of_exponential"] is None
        assert axis["acceptance_gamma_at_most_third_of_exponential"] is None
