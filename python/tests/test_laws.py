"""Transmittance laws through Python: closed forms, vectorization, sampling, CLI identity."""

import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import weft


def gamma_T(t, alpha, mean_extinction):
    # Jarabo et al. 2018: T(t) = (1 + sigma t / beta)^-alpha with sigma C_bar = mean extinction,
    # beta = alpha / C_bar, i.e. (1 + mean_extinction t / alpha)^-alpha.
    return (1.0 + mean_extinction * t / alpha) ** -alpha


def test_gamma_by_registry_names_matches_closed_form():
    law = weft.law("gamma", alpha=0.5, mean_extinction=1.0)
    t = np.array([0.0, 0.1, 1.0, 7.5, 100.0])
    np.testing.assert_allclose(law.T(t), gamma_T(t, 0.5, 1.0), rtol=1e-13)
    np.testing.assert_allclose(law.log_T(t), np.log(gamma_T(t, 0.5, 1.0)), rtol=1e-12, atol=1e-15)
    # p = -dT/dt = mean_extinction (1 + mean_extinction t / alpha)^-(alpha + 1); Sigma = p / T.
    p = (1.0 + t / 0.5) ** -1.5
    np.testing.assert_allclose(law.p(t), p, rtol=1e-12)
    np.testing.assert_allclose(law.sigma(t), p / gamma_T(t, 0.5, 1.0), rtol=1e-12)
    assert law.name == "gamma"
    assert law.parameters["alpha"] == pytest.approx(0.5)


def test_vectorized_shapes_and_scalars():
    law = weft.law("exponential", mu=2.0)
    t = np.linspace(0.0, 3.0, 12).reshape(3, 4)
    out = law.T(t)
    assert out.shape == (3, 4)
    np.testing.assert_allclose(out, np.exp(-2.0 * t), rtol=1e-15)
    assert isinstance(law.T(0.5), float)
    assert law.T(0.5) == pytest.approx(math.exp(-1.0), rel=1e-15)
    assert law.T([0, 1]).shape == (2,)  # lists and ints convert
    assert law.T(np.inf) == 0.0


def test_every_registered_law_round_trips_its_parameters():
    t = np.array([0.0, 0.3, 2.0])
    for name in weft.law_names():
        if name == "tabulated":
            continue  # needs a table file
        law = {"exponential": lambda: weft.law("exponential", mu=1.5),
               "gamma": lambda: weft.law("gamma", alpha=2.0, mean_extinction=1.5),
               }.get(name)
        if law is None:
            continue
        law = law()
        again = weft.law(law.name, **law.parameters)
        np.testing.assert_array_equal(again.T(t), law.T(t))
    assert {"exponential", "gamma"} <= set(weft.law_names())
    assert "alpha" in weft.describe_law("gamma")


def test_samples_follow_the_law():
    # Mean of the draws vs the mean free path, and the empirical CDF vs 1 - T, each within
    # 5 standard errors (fixed seed).
    law = weft.law("gamma", alpha=4.0, mean_extinction=2.0)
    n = 200000
    x = law.sample(n, seed=11)
    assert x.shape == (n,) and np.all(x >= 0)
    ell = law.mean_free_path
    assert ell == pytest.approx(4.0 / (2.0 * 3.0), rel=1e-12)  # alpha / (mu (alpha - 1))
    assert abs(x.mean() - ell) < 5 * x.std() / math.sqrt(n)
    for t in [0.1, 0.5, 1.0, 2.0]:
        F = 1.0 - law.T(t)
        assert abs(np.mean(x <= t) - F) < 5 * math.sqrt(F * (1 - F) / n)


def test_scatterer_samples_follow_the_reciprocal_partner():
    law = weft.law("gamma", alpha=4.0, mean_extinction=2.0)
    pair = weft.TransmittancePair.reciprocal(law)
    s = pair.scatterer
    n = 100000
    x = law.sample(n, from_="scatterer", seed=2)
    np.testing.assert_array_equal(x, pair.sample(n, from_="scatterer", seed=2))
    for t in [0.1, 0.5, 1.5]:
        F = 1.0 - s.T(t)
        assert abs(np.mean(x <= t) - F) < 5 * math.sqrt(F * (1 - F) / n)
    # Reciprocity: p_Q(t) = T_S(t) / l_S.
    t = np.linspace(0.0, 5.0, 11)
    np.testing.assert_allclose(pair.p("source", t), s.T(t) / s.mean_free_path, rtol=1e-10)
    assert pair.mode == "reciprocal"
    same = weft.TransmittancePair.same(law)
    np.testing.assert_array_equal(same.T("S", t), law.T(t))


def test_seeds_are_reproducible_and_differ():
    law = weft.law("exponential", mu=1.0)
    np.testing.assert_array_equal(law.sample(100, seed=3), law.sample(100, seed=3))
    assert not np.array_equal(law.sample(100, seed=3), law.sample(100, seed=4))
    assert law.sample(0).shape == (0,)


def test_sampler_choice_is_the_clis(run_cli, weft_bin):
    # One rule (the registry) for weft.law(sampler=) and `weft model --sampler`: only gamma-path has a choice.
    law = weft.law("gamma-path", k=2.0, theta=1.0, sampler="inversion")
    out = run_cli("model", "--law", "gamma-path", "--k", "2", "--theta", "1", "--pair", "same",
                  "--sampler", "inversion", "--sample", "200", "--seed", "5")
    np.testing.assert_array_equal(law.sample(200, seed=5), np.array([float(v) for v in out.split()]))
    for sampler in ["proportional", "inversion"]:
        with pytest.raises(weft.Error, match="gamma law: no choice of sampler"):
            weft.law("gamma", mean_extinction=2.0, alpha=2.0, sampler=sampler)
    cli = subprocess.run([weft_bin, "model", "--law", "gamma", "--mean-extinction", "2", "--alpha", "2",
                          "--sampler", "inversion", "--sample", "3"], capture_output=True, text=True)
    assert cli.returncode == 2 and "gamma law: no choice of sampler" in cli.stderr
    # p proportional to T (S.55-S.57) is the source law of the pair given as T_S, in both front ends.
    gamma = weft.law("gamma", mean_extinction=2.0, alpha=2.0)
    out = run_cli("model", "--law", "gamma", "--mean-extinction", "2", "--alpha", "2", "--given", "S",
                  "--from", "source", "--sample", "100", "--seed", "4")
    np.testing.assert_array_equal(weft.TransmittancePair.reciprocal(gamma, "scatterer").source.sample(100, seed=4),
                                  np.array([float(v) for v in out.split()]))


def test_subnormal_parameters_as_the_cli(run_cli):
    law = weft.law("exponential", mu=1e-320)
    out = run_cli("model", "--law", "exponential", "--mu", "1e-320", "--t", "1", "--json")
    assert '"mu": 1e-320' in out or '"mu": 9.99988671826831e-321' in out
    assert law.T(1.0) == 1.0


@pytest.mark.parametrize("origin", ["source", "scatterer"])
def test_samples_identical_to_cli(run_cli, origin):
    law = weft.law("gamma", alpha=0.5, mean_extinction=1.0)
    x = law.sample(500, from_=origin, seed=7)
    out = run_cli("model", "--law", "gamma", "--alpha", "0.5", "--mean-extinction", "1", "--sample", "500",
                  "--from", origin, "--seed", "7")
    cli = np.array([float(v) for v in out.split()])
    np.testing.assert_array_equal(x, cli)  # printed with 17 digits: exact


@pytest.mark.parametrize("call, exc", [
    (lambda: weft.law("gama", alpha=1, mean_extinction=1), weft.Error),
    (lambda: weft.law("gamma", alpha="x", mean_extinction=1), TypeError),
    (lambda: weft.law("gamma", alpha=True, mean_extinction=1), TypeError),
    (lambda: weft.law("gamma", alpha=float("nan"), mean_extinction=1), weft.Error),
    (lambda: weft.law("gamma", alpha=-1, mean_extinction=1), weft.Error),
    (lambda: weft.law("gamma", alfa=1, mean_extinction=1), weft.Error),
    (lambda: weft.law("tabulated", table="/nonexistent/table.csv"), weft.Error),
    (lambda: weft.law("tabulated", table=3), TypeError),
    (lambda: weft.law(3), TypeError),
    (lambda: weft.law("exponential", mu=1).T(float("nan")), weft.Error),
    (lambda: weft.law("exponential", mu=1).T([0.0, -1.0]), weft.Error),
    (lambda: weft.law("exponential", mu=1).T("abc"), TypeError),
    (lambda: weft.law("exponential", mu=1).T(None), weft.Error),  # refused: numpy would read None as NaN
    (lambda: weft.law("exponential", mu=1).p([[0.0], [np.nan]]), weft.Error),
    (lambda: weft.law("exponential", mu=1).sample(-1), weft.Error),
    (lambda: weft.law("exponential", mu=1).sample(10**12), weft.Error),
    (lambda: weft.law("exponential", mu=1).sample("ten"), TypeError),
    (lambda: weft.law("exponential", mu=1).sample(3, from_="nowhere"), weft.Error),
    (lambda: weft.law("exponential", mu=1).sample(3, seed=-1), weft.Error),  # out of the unsigned seed's range
    (lambda: weft.TransmittancePair.reciprocal(weft.law("exponential", mu=1), given="both"), weft.Error),
    (lambda: weft.TransmittancePair.same("gamma"), TypeError),
])
def test_bad_input_raises(call, exc):
    with pytest.raises(exc) as info:
        call()
    assert str(info.value)  # a message, one line, and a weft.Error also where it is a TypeError
    assert "\n" not in str(info.value).strip() and isinstance(info.value, weft.Error)


def test_error_message_names_the_problem():
    with pytest.raises(weft.Error, match="gamma"):
        weft.law("gama", alpha=1, mean_extinction=1)
    assert issubclass(weft.Error, Exception)


def test_docstrings_visible():
    assert "mean_extinction" in weft.law.__doc__
    assert "source" in weft.Law.sample.__doc__
    assert weft.Law.T.__doc__


def test_sample_over_the_memory_budget_is_refused_before_allocating(tmp_path):
    """Law.sample holds its n draws at once: n * 8 bytes over the memory budget (half of `ulimit
    -v` here, weft/core/memory.h) is a weft.Error before anything is allocated or drawn, while
    the same count fits the address space (so without the check it would be drawn)."""
    script = tmp_path / "budget.py"
    script.write_text(textwrap.dedent("""
        import resource, time
        resource.setrlimit(resource.RLIMIT_AS, (4 << 30, 4 << 30))  # budget: 2 GiB
        import weft
        law = weft.law("exponential", mu=1)
        start = time.monotonic()
        try:
            law.sample(300_000_000)  # 2.24 GiB
            print("drawn")
        except weft.Error as e:
            print("refused in %.2f s: %s" % (time.monotonic() - start, e))
        print(law.sample(10).shape)
    """))
    here = os.path.dirname(os.path.dirname(os.path.abspath(weft.__file__)))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([here, os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=env, timeout=120)
    assert out.returncode == 0, out.stderr
    first, second = out.stdout.splitlines()
    assert first.startswith("refused in "), out.stdout
    assert "300000000 samples would take 2.24 GiB, over the memory budget of 2.00 GiB" in first
    assert float(first.split()[2]) < 0.5  # nothing drawn: 300 million draws take seconds
    assert second == "(10,)"  # the interpreter and the module carry on
