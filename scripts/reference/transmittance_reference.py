#!/usr/bin/env python3
"""High-precision reference values for the transmittance laws' hard cases.

Writes tests/data/transmittance/reference.csv, read by tests/unit/transmittance/reference_test.cpp.
Every value is computed with mpmath at 60 significant digits and cross-checked at 90 digits;
the inputs (t, parameters) are doubles, converted to mpmath exactly, so the only rounding in
the table is the final conversion to double.

Usage: pip install mpmath && python3 scripts/reference/transmittance_reference.py [OUT.csv]
"""
import math
import sys
from pathlib import Path

import mpmath as mp

INF = float("inf")


def to_csv(x):
    """Shortest round-trip text of a double (mpmath value converted with round-to-nearest)."""
    f = float(x)
    if f == INF:
        return "inf"
    if f == -INF:
        return "-inf"
    return repr(f)


# Each evaluator returns (T, logT, pdf, hazard) as mpmath numbers (or ±inf) for double inputs.
def gamma_law(mean_extinction, alpha, t):
    mu, a, t = mp.mpf(mean_extinction), mp.mpf(alpha), mp.mpf(t)
    if t == mp.inf:
        return 0, -mp.inf, 0, 0
    x = mu * t / a
    log_t = -a * mp.log1p(x)
    hazard = mu / (1 + x)
    return mp.exp(log_t), log_t, hazard * mp.exp(log_t), hazard


def gamma_path(k, theta, t):
    k, theta, t = mp.mpf(k), mp.mpf(theta), mp.mpf(t)
    if t == mp.inf:
        return 0, -mp.inf, 0, 1 / theta
    x = t / theta
    if x == 0:
        pdf = mp.inf if k < 1 else (1 / theta if k == 1 else mp.mpf(0))
        return mp.mpf(1), mp.mpf(0), pdf, pdf
    if x < k:  # Q near 1: go through the lower function so log Q keeps its digits
        p = mp.gammainc(k, 0, x, regularized=True)
        q, log_q = 1 - p, mp.log1p(-p)
    else:
        q = mp.gammainc(k, x, mp.inf, regularized=True)
        log_q = mp.log(q)
    log_pdf = (k - 1) * mp.log(x) - x - mp.loggamma(k) - mp.log(theta)
    return q, log_q, mp.exp(log_pdf), mp.exp(log_pdf - log_q)


def erlang_source(k, rate, t):
    """(1/k) sum_{j=1..k} Q(j, rate t); pdf = rate/k Q(k, rate t)."""
    k, rate, t = int(k), mp.mpf(rate), mp.mpf(t)
    if t == mp.inf:
        return 0, -mp.inf, 0, rate
    x = rate * t
    pdf = rate / k * mp.gammainc(k, x, mp.inf, regularized=True)
    if x < 1:
        lower = mp.fsum(mp.gammainc(j, 0, x, regularized=True) for j in range(1, k + 1)) / k
        return 1 - lower, mp.log1p(-lower), pdf, pdf / (1 - lower)
    value = mp.fsum(mp.gammainc(j, x, mp.inf, regularized=True) for j in range(1, k + 1)) / k
    return value, mp.log(value), pdf, pdf / value


def linear(mean_extinction, _unused, t):
    mu, t = mp.mpf(mean_extinction), mp.mpf(t)
    if mu == 0:
        return mp.mpf(1), mp.mpf(0), mp.mpf(0), mp.mpf(0)
    r = 1 - mu * t if t != mp.inf else mp.mpf(-1)
    if r <= 0:
        return mp.mpf(0), -mp.inf, mp.mpf(0), mp.inf
    return r, mp.log1p(-mu * t), mu, mu / r


def exponential(mu, _unused, t):
    mu, t = mp.mpf(mu), mp.mpf(t)
    if mu == 0:
        return mp.mpf(1), mp.mpf(0), mp.mpf(0), mp.mpf(0)
    if t == mp.inf:
        return mp.mpf(0), -mp.inf, mp.mpf(0), mu
    return mp.exp(-mu * t), -mu * t, mu * mp.exp(-mu * t), mu


def gamma_mixture(components, t):
    """T = sum w_i (1 + mu_i t/alpha_i)^-alpha_i over (w_i, alpha_i, mu_i); alpha_i = inf is
    exp(-mu_i t), mu_i = 0 a gap (T_i = 1). Weights are divided by their exact sum, as the law does."""
    t = mp.mpf(t)
    total = mp.fsum(mp.mpf(w) for w, _, _ in components)
    # deficit = 1 - T = sum w_i (1 - T_i), with 1 - T_i = -expm1(-E_i): log T = log1p(-deficit)
    # keeps its digits where T is within 1e-40 of 1 (t = 1e-300).
    value, pdf, deficit = mp.mpf(0), mp.mpf(0), mp.mpf(0)
    for w, alpha, mu in components:
        w, mu = mp.mpf(w) / total, mp.mpf(mu)
        if w == 0:
            continue
        if mu == 0:
            value += w
            continue
        if t == mp.inf:
            deficit += w
            continue
        if alpha == INF:
            e, hi = mu * t, mu
        else:
            a = mp.mpf(alpha)
            x = mu * t / a
            e, hi = a * mp.log1p(x), mu / (1 + x)
        ti = mp.exp(-e)
        value += w * ti
        deficit += w * -mp.expm1(-e)
        pdf += w * ti * hi
    if t == mp.inf:
        # Limit of the hazard: a gap or any gamma tail (Sigma ~ alpha/t) gives 0; all exponential,
        # the smallest extinction.
        live = [(a, m) for w, a, m in components if w > 0]
        hazard = 0 if any(m == 0 or a != INF for a, m in live) else mp.mpf(min(m for _, m in live))
        return value, (mp.log(value) if value > 0 else -mp.inf), mp.mpf(0), hazard
    log_value = mp.log1p(-deficit) if deficit < mp.mpf("0.5") else mp.log(value)
    return value, log_value, pdf, pdf / value


def gap_gamma(mean_extinction, alpha, t, gap):
    """f0 + (1 - f0)(1 + mu_c t/alpha)^-alpha: the mixture {(f0, gap), (1 - f0, alpha, mu_c)}; 1 - f0
    in exact arithmetic (the law's double 1 - f0 is exact for f0 >= 1/2)."""
    f0 = mp.mpf(gap)
    return gamma_mixture([(f0, INF, 0.0), (1 - f0, alpha, mean_extinction)], t)


LAWS = {"gamma": gamma_law, "gamma-path": gamma_path, "erlang": None, "erlang-source": erlang_source,
        "linear": linear, "exponential": exponential}


def cases():
    t_gamma = [0.0, 1e-300, 1e-10, 1.0, 1e10, 1e300, INF]
    for alpha in [1e-6, 1e-3, 0.5, 1 - 1e-9, 1.0, 1 + 1e-9, 2.0, 1e3, 1e8, 1e15]:
        for t in t_gamma:
            yield "gamma", 1.0, alpha, t
    for t in [0.0, 1e-3, 0.25, 4.0, 1e3]:  # a mean extinction other than 1
        yield "gamma", 7.5, 0.3, t
    for k in [1e-3, 0.5, 1.0, 4.0, 100.0, 1e4]:
        xs = {0.0, 1e-300, 1e-10, 0.1, 1.0, 10.0, 100.0, 1e3, 5e3, 1e4, k, 2 * k, k + 10 * math.sqrt(k)}
        for theta in [1.0, 0.5]:
            for x in sorted(xs):
                if x <= max(1e4, 2 * k):
                    yield "gamma-path", k, theta, x * theta
            yield "gamma-path", k, theta, INF
    for k in [1.0, 2.0, 5.0, 50.0]:
        for t in [0.0, 1e-10, 0.1, 1.0, 3.0, 20.0, 300.0, 2000.0, INF]:
            yield "erlang", k, 2.0, t
    for k in [1.0, 2.0, 7.0]:
        for t in [0.0, 1e-10, 0.5, 2.0, 30.0, 400.0]:
            yield "erlang-source", k, 1.0, t
    third = 1.0 / 3.0
    for t in [0.0, 1e-300, 0.1, math.nextafter(third, 0.0), third, math.nextafter(third, 1.0), 0.5, 1e300, INF]:
        yield "linear", 3.0, 0.0, t
    for t in [0.0, 0.5, math.nextafter(1.0, 0.0), 1.0, math.nextafter(1.0, 2.0), 2.0]:
        yield "linear", 1.0, 0.0, t
    for mu in [0.0, 1.0, 1e300]:
        for t in [0.0, 1e-300, 1e-10, 1.0, 1e10, 1e300, INF]:
            yield "exponential", mu, 0.0, t
    # gap-gamma: f0 -> 0 (the gamma law), f0 -> 1, alpha tiny and -> inf (gap + exponential), t huge.
    for gap in [0.0, 1e-300, 0.3, 1 - 1e-12]:
        for alpha in [1e-6, 0.5, 2.0, 1e8, 1e15, INF]:
            for t in [0.0, 1e-300, 1e-10, 1.0, 1e10, 1e300, INF]:
                yield "gap-gamma", 1.0, alpha, t, f"gap={gap!r}"
    for t in [0.0, 1e-3, 0.25, 4.0, 1e3]:
        yield "gap-gamma", 7.5, 0.3, t, "gap=0.6"
    for t in [0.0, 1.0, INF]:  # mean extinction 0: T = 1
        yield "gap-gamma", 0.0, 2.0, t, "gap=0.3"
    for components in MIXTURES:
        for t in [0.0, 1e-300, 1e-10, 1e-3, 1.0, 30.0, 1e10, 1e300, INF]:
            yield "gamma-mixture", 0.0, 0.0, t, mixture_text(components)


# (weight, alpha, mean_extinction) per component: the gap + gamma example, gamma +
# exponential, shapes at both ends with scales far apart, exponentials with a gap, exponentials only.
MIXTURES = [
    [(0.2, 1.0, 0.0), (0.8, 3.0, 5.0)],
    [(0.25, 0.5, 1.0), (0.75, INF, 10.0)],
    [(0.5, 1e-6, 1e3), (0.25, 1e15, 1e-3), (0.25, 2.0, 1.0)],
    [(0.125, INF, 0.0), (0.375, INF, 1.0), (0.5, INF, 4.0)],
    [(0.5, INF, 1.0), (0.5, INF, 3.0)],
]


def mixture_text(components):
    """The registry's numbered keys, ';'-separated (the `more` column)."""
    keys = []
    for i, (w, a, m) in enumerate(components, start=1):
        keys += [f"weight_{i}={w!r}", f"alpha_{i}={to_csv(a)}", f"mean_extinction_{i}={m!r}"]
    return ";".join(keys)


def parse_more(more):
    return {k: float(v) for k, v in (item.split("=") for item in more.split(";"))} if more else {}


def evaluate(law, p1, p2, t, more=""):
    if law == "gap-gamma":
        return gap_gamma(p1, p2, t, parse_more(more)["gap"])
    if law == "gamma-mixture":
        keys = parse_more(more)
        n = len(keys) // 3
        return gamma_mixture([(keys[f"weight_{i}"], keys[f"alpha_{i}"], keys[f"mean_extinction_{i}"])
                              for i in range(1, n + 1)], t)
    if law == "erlang":
        return gamma_path_rate(p1, p2, t)
    return LAWS[law](p1, p2, t)


def gamma_path_rate(k, rate, t):
    # Erlang(k, rate) is gamma-path with θ = 1/rate exactly (in real numbers, not 1/rate rounded).
    return gamma_path(k, 1 / mp.mpf(rate), t)


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else (
        Path(__file__).resolve().parents[2] / "tests" / "data" / "transmittance" / "reference.csv")
    rows = []
    for law, p1, p2, t, *extra in cases():
        more = extra[0] if extra else ""
        mp.mp.dps = 90
        check = evaluate(law, p1, p2, t, more)
        mp.mp.dps = 60
        values = evaluate(law, p1, p2, t, more)
        for a, b in zip(values, check):
            if a not in (0, mp.inf, -mp.inf) and b != 0:
                assert abs(mp.mpf(a) / b - 1) < mp.mpf("1e-40"), (law, p1, p2, t, a, b)
        rows.append([law, to_csv(p1), to_csv(p2), to_csv(t)] + [to_csv(v) for v in values] + [more])
    with open(out, "w") as f:
        f.write("# Generated by scripts/reference/transmittance_reference.py (mpmath, 60 digits). Do not edit.\n")
        f.write("# gamma: p1 = mean_extinction, p2 = alpha; gamma-path: k, theta; erlang(-source): k, rate;\n")
        f.write("# linear: p1 = mean_extinction; exponential: p1 = mu; gap-gamma: p1 = mean_extinction (non-gap\n")
        f.write("# rays), p2 = alpha, more = gap; gamma-mixture: more = weight_N, alpha_N, mean_extinction_N.\n")
        f.write("# more: further registry parameters key=value;key=value (empty for two-parameter laws).\n")
        f.write("law,p1,p2,t,T,logT,pdf,hazard,more\n")
        for row in rows:
            f.write(",".join(row) + "\n")
    print(f"wrote {len(rows)} rows to {out}")


if __name__ == "__main__":
    main()
