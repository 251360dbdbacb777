"""A small corpus sweep: how much better than the exponential is the gamma prediction, per cloth?

For each case (a weave pattern with a yarn preset) generates the cloth, runs ``weft.validate``
and averages over the three axes the RMS error |T_model - T_gt| of the paper's gamma law, of the
best predictive model (never fitted to the ground truth) and of the exponential baseline. Writes
OUT/corpus_sweep.csv, prints the table and, with matplotlib, draws OUT/corpus_sweep.png (bars).

    PYTHONPATH=build/ci/python python3 examples/corpus_sweep.py --out sweep/          # 4x4 yarns
    PYTHONPATH=build/ci/python python3 examples/corpus_sweep.py --out sweep/ --quick  # small, for CI
"""

import argparse
import csv
import math
import os

import weft

CASES = (("plain", "cotton"), ("twill22", "wool"), ("satin5", "silk"))
COLUMNS = ("gamma", "best predictive", "exponential")


def sweep_case(pattern, preset, quick):
    """The mean over axes of each model's RMS |dT|, and the best predictive model's names."""
    yarn = {"preset": preset, "fiber_count": 12} if quick else preset
    cloth = weft.gen(pattern=pattern, yarns=(5, 5) if pattern == "satin5" else (4, 4), warp_yarn=yarn,
                     weft_yarn=yarn, voxel_size=0.025 if quick else 0.01, seed=7)
    result = weft.validate(cloth.grid)
    axes = result["axes"]
    rms = {
        "gamma": sum(a["errors"]["gamma"]["rms_abs_T"] for a in axes) / len(axes),
        "best predictive": sum(a["errors"][a["best_predictive"]["model"]]["rms_abs_T"] for a in axes) / len(axes),
        "exponential": sum(a["errors"]["exponential"]["rms_abs_T"] for a in axes) / len(axes),
    }
    best = sorted({a["best_predictive"]["model"] for a in axes})
    return rms, best


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="corpus_sweep", help="output folder")
    parser.add_argument("--quick", action="store_true", help="thin yarns and coarse voxels (seconds, for CI)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    rows = []
    print("%-16s %8s %16s %12s %10s  best predictive" % (("case",) + COLUMNS + ("gamma/exp",)))
    for pattern, preset in CASES:
        rms, best = sweep_case(pattern, preset, args.quick)
        if not all(math.isfinite(v) and v >= 0 for v in rms.values()):
            raise SystemExit("corpus_sweep: non-finite error for %s %s: %r" % (pattern, preset, rms))
        name = "%s/%s" % (pattern, preset)
        rows.append((name, rms, best))
        print("%-16s %8.4f %16.4f %12.4f %10.3f  %s" % (name, rms["gamma"], rms["best predictive"],
                                                         rms["exponential"], rms["gamma"] / rms["exponential"],
                                                         ",".join(best)))

    with open(os.path.join(args.out, "corpus_sweep.csv"), "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["case"] + ["rms_abs_T_" + c.replace(" ", "_") for c in COLUMNS] + ["best_predictive"])
        for name, rms, best in rows:
            out.writerow([name] + ["%.6g" % rms[c] for c in COLUMNS] + [" ".join(best)])

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: table only (apt install python3-matplotlib for the plot)")
        return
    fig, ax = plt.subplots(figsize=(7, 3.8))
    width = 0.8 / len(COLUMNS)
    for k, column in enumerate(COLUMNS):
        ax.bar([i + (k - 1) * width for i in range(len(rows))], [r[1][column] for r in rows], width, label=column)
    ax.set_xticks(range(len(rows)), [r[0] for r in rows])
    ax.set(ylabel="RMS |T_model - T_gt| (mean over axes)", title="weft corpus sweep")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "corpus_sweep.png"))
    print("wrote", os.path.join(args.out, "corpus_sweep.png"))


if __name__ == "__main__":
    main()
