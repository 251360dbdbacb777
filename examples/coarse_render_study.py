"""The coarse-cloth render study, from Python: what does a coarse model of a cloth cost in an image?

Renders a small cloth (backlit, seen at 35 degrees, as in docs/render.md section 5c) with the fine
grid as reference R, then candidates at fewer samples: the fine grid again, the grid downsampled
N x (block means in numpy: volume-conserving, exponential per coarse voxel) and a homogeneous
slab with the gamma law of the grid's pooled window statistics (predicted, never fitted to R).
Over the cloth's pixels (where R differs from the empty scene by > 5 standard errors) it prints
per candidate the bias (sqrt of |X - R|^2 - var X - var R, the error left at convergence) and
the RMSE at its spp, as `weft render --study` defines them. Writes OUT/study.csv.

    PYTHONPATH=build/ci/python python3 examples/coarse_render_study.py --out study/ [--quick]
"""

import argparse
import math
import os

import numpy as np

import weft


def downsample(grid, factor, path):
    """Block means of `factor`^3 fine voxels, with the fine grid's active box at the coarse origin."""
    lo = np.array(grid.bbox[0])
    a = grid.to_numpy()
    a = np.pad(a, [(0, -n % factor) for n in a.shape])
    blocks = a.reshape(a.shape[0] // factor, factor, a.shape[1] // factor, factor, a.shape[2] // factor, factor)
    h = grid.voxel_size
    coarse = weft.Grid.from_numpy(blocks.mean(axis=(1, 3, 5)), voxel_size=h * factor,
                                  origin=tuple(np.array(grid.origin) + h * lo))
    coarse.save(path)
    return coarse


def scene(lo, hi, medium, spp, seed, size):
    """Camera 35 degrees off the cloth's normal (z), an emitting panel below, a grazing light."""
    centre, extent = (lo + hi) / 2, max(hi[0] - lo[0], hi[1] - lo[1])
    view = np.array([0.0, -math.sin(math.radians(35)), math.cos(math.radians(35))])
    s = {"camera": {"position": list(centre + 2.4 * extent * view), "look_at": list(centre), "up": [0, 0, 1],
                    "fov": 35, "width": size[0], "height": size[1]},
         "integrator": {"spp": spp, "seed": seed, "max_depth": 64, "rr_depth": 6},
         "materials": {"boundary": {"type": "null"}}, "media": {}, "shapes": [],
         "lights": [{"type": "directional", "direction": [0.773, 0.580, -0.259], "irradiance": 3.0},
                    {"type": "environment", "radiance": 0.05}]}
    panel = 1.2 * (hi - lo)
    s["shapes"].append({"type": "rectangle", "corner": [centre[0] - panel[0] / 2, centre[1] - panel[1] / 2,
                                                        centre[2] - extent / 2],
                        "edge_u": [panel[0], 0, 0], "edge_v": [0, panel[1], 0], "emission": 2.0})
    if medium is not None:
        s["media"]["cloth"] = dict(medium, albedo=[0.95, 0.9, 0.8], g=0.3)
        s["shapes"].append({"type": "box", "min": list(lo), "max": list(hi), "material": "boundary",
                            "interior": "cloth"})
    return s


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="coarse_render_study", help="output folder")
    parser.add_argument("--quick", action="store_true", help="a tiny film and few samples (for CI)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    size, spp, ref_spp = ((48, 36), 16, 128) if args.quick else ((160, 120), 64, 1024)

    cloth = weft.gen(yarns=(2, 2), voxel_size=0.02, seed=5, warp_yarn={"fiber_count": 16},
                     weft_yarn={"fiber_count": 16})
    grid, h = cloth.grid, cloth.grid.voxel_size
    sigma = float(grid.metadata["weft:sigma_per_concentration"])
    grid.save(os.path.join(args.out, "fine.vdb"))
    lo = np.array(grid.origin) + h * np.array(grid.bbox[0])
    hi = np.array(grid.origin) + h * (np.array(grid.bbox[1]) + 1)
    box = (lo - h, hi + 4 * h)  # one fine voxel round the grid, and room for the coarse blocks' padding
    fine = {"type": "grid", "file": "fine.vdb", "sigma": sigma}
    candidates = {"fine": (fine, box)}
    for n in (2, 4):
        downsample(grid, n, os.path.join(args.out, "coarse%d.vdb" % n))
        candidates["exponential-%dx" % n] = ({"type": "grid", "file": "coarse%d.vdb" % n, "sigma": sigma}, box)
    stats = weft.pool([weft.window_stats(grid, axis, float(grid.metadata["weft:yarn_diameter"])) for axis in "xyz"])
    fit = weft.gamma_from_moments(stats.mean, stats.variance, sigma)
    law = {"name": "gamma", "sigma": sigma, "mean_concentration": fit.mean_concentration,
           "var_concentration": fit.var_concentration}
    candidates["slab-gamma"] = ({"type": "homogeneous", "law": law}, (lo, hi))

    def render(medium, bounds, n, seed):
        return weft.render(scene(*bounds, medium, n, seed, size), stats=True, base_dir=args.out)

    ref, ref_stats = render(fine, box, ref_spp, 101)
    empty, empty_stats = render(None, box, max(16, ref_spp // 4), 102)
    mask = np.any(np.abs(ref - empty) > 5 * np.sqrt(ref_stats["variance"] + empty_stats["variance"]), axis=2)
    print("film %dx%d, reference %d spp, candidates %d spp; %d cloth pixels, mean %.4f"
          % (size[0], size[1], ref_spp, spp, mask.sum(), ref[mask].mean()))
    if mask.sum() < 10:
        raise SystemExit("coarse_render_study: the cloth covers fewer than 10 pixels")
    rows = []
    print("%-16s %8s %8s %9s %8s" % ("candidate", "bias", "bias/mean", "mean diff", "RMSE"))
    for seed, (name, (medium, bounds)) in enumerate(candidates.items(), start=201):
        image, st = render(medium, bounds, spp, seed)
        d2, var_x, var_r = (image - ref)[mask] ** 2, st["variance"][mask], ref_stats["variance"][mask]
        bias2 = float(np.mean(d2 - var_x - var_r))
        row = (name, math.sqrt(max(bias2, 0.0)), math.sqrt(max(bias2, 0.0)) / ref[mask].mean(),
               float(np.mean((image - ref)[mask])), math.sqrt(max(0.0, float(np.mean(d2 - var_r)))))
        if not all(math.isfinite(v) for v in row[1:]):
            raise SystemExit("coarse_render_study: non-finite statistics for %s" % name)
        rows.append(row)
        print("%-16s %8.4f %8.1f%% %+9.4f %8.4f" % (row[0], row[1], 100 * row[2], row[3], row[4]))
    with open(os.path.join(args.out, "study.csv"), "w") as f:
        f.write("candidate,cloth_bias,cloth_relative_bias,cloth_difference,cloth_rmse\n")
        f.writelines("%s,%.6g,%.6g,%.6g,%.6g\n" % r for r in rows)


if __name__ == "__main__":
    main()
