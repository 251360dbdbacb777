"""Fig. S.13 on a cloth: log T(t) of the ground truth against the paper's gamma law and the
exponential baseline, per axis.

Generates a cloth, runs ``weft.validate`` on its grid (sigma and the window from the grid's
provenance, as ``weft validate --grid``) and plots, per axis, ln T(t) of the DDA ground truth
(band: 2 standard errors), the paper's gamma law and the exponential. With matplotlib the figure
is OUT/fig_s13.png (and ``weft.plot_validation`` draws all ten models into OUT/validation.png);
without it a table is printed. The curves are always written to OUT/fig_s13.csv.

    PYTHONPATH=build/ci/python python3 examples/fig_s13.py --out fig_s13/           # default cloth
    PYTHONPATH=build/ci/python python3 examples/fig_s13.py --out fig_s13/ --quick   # 2x2 yarns
"""

import argparse
import csv
import math
import os

import numpy as np

import weft

MODELS = ("gamma", "exponential")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="fig_s13", help="output folder")
    parser.add_argument("--quick", action="store_true", help="a small cloth (seconds, for CI)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    small = dict(yarns=(2, 2), voxel_size=0.02, seed=5, warp_yarn={"fiber_count": 12},
                 weft_yarn={"fiber_count": 12})
    cloth = weft.gen(**small) if args.quick else weft.gen()
    result = weft.validate(cloth.grid)
    print("%r, sigma %.4g (%s), window %s = %.4g mm" % (cloth, result["sigma"], result["sigma_source"].split(":")[0],
                                                     result["window"]["rule"], result["window"]["length"][0]))

    with open(os.path.join(args.out, "fig_s13.csv"), "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["axis", "depth", "T_gt", "stderr"] + ["T_" + m for m in MODELS])
        for a in result["axes"]:
            for row in zip(a["depth"], a["T_gt"], a["stderr"], *(a["T"][m] for m in MODELS)):
                out.writerow([a["axis"]] + ["%.6g" % v for v in row])

    print("axis  depth[mm]  ln T_gt   s.e.(ln)  ln T_gamma  ln T_exp   (every quarter of the depth)")
    for a in result["axes"]:
        t, gt, se = a["depth"], a["T_gt"], a["stderr"]
        for i in np.linspace(0, len(t) - 1, 5).round().astype(int)[1:]:
            ln = [math.log(max(v, 1e-300)) for v in (gt[i], a["T"]["gamma"][i], a["T"]["exponential"][i])]
            print("%-4s  %8.3f  %8.3f  %8.3f  %10.3f  %9.3f" % (a["axis"], t[i], ln[0], se[i] / max(gt[i], 1e-300),
                                                               ln[1], ln[2]))
    print("axis  rms|dT| gamma  rms|dT| exponential  gamma/exponential")
    for a in result["axes"]:
        g, e = (a["errors"][m]["rms_abs_T"] for m in MODELS)
        if not (math.isfinite(g) and math.isfinite(e)):
            raise SystemExit("fig_s13: non-finite error on %s" % a["axis"])
        print("%-4s  %13.4f  %19.4f  %17.3f" % (a["axis"], g, e, g / e))

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: table only (apt install python3-matplotlib for the figure)")
        return
    fig, panels = plt.subplots(1, len(result["axes"]), figsize=(12, 3.8), squeeze=False)
    for panel, a in zip(panels[0], result["axes"]):
        t, gt, se = a["depth"], a["T_gt"], a["stderr"]
        floor = 1e-6  # ln T below the ground truth's resolution is not drawn
        panel.fill_between(t, np.log(np.maximum(gt - 2 * se, floor)), np.log(np.maximum(gt + 2 * se, floor)),
                           color="0.8", label="ground truth ± 2 s.e.")
        panel.plot(t, np.log(np.maximum(gt, floor)), "k", lw=2, label="ground truth (DDA)")
        for m, style in zip(MODELS, ("C0-", "C3--")):
            panel.plot(t, np.log(np.maximum(a["T"][m], floor)), style, label=m)
        bottom = min(-1.0, 2.5 * math.log(max(gt.min(), floor)))  # the exponential may leave the panel
        panel.set(title=a["axis"], xlabel="depth t [mm]", ylabel="ln T(t)", ylim=(bottom, 0.1))
    panels[0][-1].legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "fig_s13.png"))
    weft.plot_validation(result, os.path.join(args.out, "validation.png"), log=True)
    print("wrote", os.path.join(args.out, "fig_s13.png"), "and validation.png")


if __name__ == "__main__":
    main()
