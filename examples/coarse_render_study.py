"""The coarse-cloth render study from Python: what does a coarse model of a cloth cost in an image?

Renders a small backlit cloth (the lighting of docs/render.md §5c) with the fine grid as the
reference R, then at fewer samples: the fine grid, the grid downsampled N x in numpy (block
means: volume-conserving, exponential per coarse voxel), the local gamma fields of N^3-voxel
blocks (`weft.local_fields`, what `weft fit --block N` writes, rendered as a "local-gamma" medium
straight from the scene dict) and a slab with the gamma law of the grid's pooled window
statistics (predicted, never fitted to R). Over the cloth's pixels (R differs
from the empty scene by > 5 standard errors) it prints each candidate's bias (the error left at
convergence, sqrt(|X - R|^2 - var X - var R)) and RMSE, as `weft render --study` defines them,
and writes OUT/study.csv.

    PYTHONPATH=build/ci/python python3 examples/coarse_render_study.py --out study/ [--quick]
"""

import argparse
import math
import os

import numpy as np

import weft


def downsample(grid, factor, path):
    """Block means of factor^3 fine voxels (zero-padded), the fine grid's active box at the origin."""
    a = grid.to_numpy()
    a = np.pad(a, [(0, -n % factor) for n in a.shape])
    coarse = a.reshape([n for m in a.shape for n in (m // factor, factor)]).mean(axis=(1, 3, 5))
    weft.Grid.from_numpy(coarse, voxel_size=grid.voxel_size * factor,
                         origin=tuple(np.array(grid.origin) + grid.voxel_size * np.array(grid.bbox[0]))).save(path)


def scene(frame, medium, bounds, spp, seed, size):
    """`bounds` filled with `medium` (None: no cloth); camera 35 degrees off z, a panel below and a
    grazing light placed from `frame` (the fine grid's box), so that all images compare pixel by pixel."""
    lo, hi = frame
    centre, extent, panel = (lo + hi) / 2, max(hi[:2] - lo[:2]), 1.2 * (hi - lo)
    view = np.array([0.0, -math.sin(math.radians(35)), math.cos(math.radians(35))])
    s = {"camera": {"position": list(centre + 2.4 * extent * view), "look_at": list(centre), "up": [0, 0, 1],
                    "fov": 35, "width": size[0], "height": size[1]},
         "integrator": {"spp": spp, "seed": seed, "max_depth": 64, "rr_depth": 6},
         "materials": {"boundary": {"type": "null"}}, "media": {},
         "shapes": [{"type": "rectangle", "corner": list(centre - panel / 2 - [0, 0, extent / 2 - panel[2] / 2]),
                     "edge_u": [panel[0], 0, 0], "edge_v": [0, panel[1], 0], "emission": 2.0}],
         "lights": [{"type": "directional", "direction": [0.773, 0.580, -0.259], "irradiance": 3.0},
                    {"type": "environment", "radiance": 0.05}]}
    if medium is not None:
        s["media"]["cloth"] = dict(medium, albedo=[0.95, 0.9, 0.8], g=0.3)
        s["shapes"].append({"type": "box", "min": list(bounds[0]), "max": list(bounds[1]), "material": "boundary",
                            "interior": "cloth"})
    return s


def cloth_stats(image, st, ref, ref_var, mask):
    """bias, bias over the mean cloth pixel, mean difference and RMSE over the cloth's pixels."""
    d2 = (image - ref)[mask] ** 2
    bias = math.sqrt(max(0.0, float(np.mean(d2 - st["variance"][mask] - ref_var[mask]))))
    rmse = math.sqrt(max(0.0, float(np.mean(d2 - ref_var[mask]))))
    return bias, bias / ref[mask].mean(), float(np.mean((image - ref)[mask])), rmse


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="coarse_render_study", help="output folder")
    parser.add_argument("--quick", action="store_true", help="a tiny film and few samples (for CI)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    size, spp, ref_spp = ((48, 36), 16, 128) if args.quick else ((160, 120), 64, 1024)

    grid = weft.gen(yarns=(2, 2), voxel_size=0.02, seed=5, warp_yarn={"fiber_count": 16},
                    weft_yarn={"fiber_count": 16}).grid
    h, sigma = grid.voxel_size, float(grid.metadata["weft:sigma_per_concentration"])
    grid.save(os.path.join(args.out, "fine.vdb"))
    lo, hi = (np.array(grid.origin) + h * (np.array(grid.bbox[k]) + k) for k in (0, 1))
    box = (lo - h, hi + 4 * h)  # one fine voxel round the grid, and room for the coarse blocks' padding
    candidates = {"fine": ({"type": "grid", "file": "fine.vdb", "sigma": sigma}, box)}
    for n in (2, 4):
        downsample(grid, n, os.path.join(args.out, "coarse%d.vdb" % n))
        candidates["exponential-%dx" % n] = ({"type": "grid", "file": "coarse%d.vdb" % n, "sigma": sigma}, box)
    for n in (2, 4):
        # Blocks are aligned to multiples of n in index space, so they may reach past the fine box.
        fields = weft.local_fields(grid, n)
        m = fields.mean
        flo, fhi = (np.array(m.origin) + m.voxel_size * (np.array(m.bbox[k]) + k) for k in (0, 1))
        candidates["local-gamma-%dx" % n] = ({"type": "local-gamma", "fields": fields, "sigma": sigma},
                                             (np.minimum(box[0], flo), np.maximum(box[1], fhi)))
    stats = weft.pool([weft.window_stats(grid, axis, float(grid.metadata["weft:yarn_diameter"])) for axis in "xyz"])
    law = {"name": "gamma", "sigma": sigma, "mean_concentration": stats.mean, "var_concentration": stats.variance}
    candidates["slab-gamma"] = ({"type": "homogeneous", "law": law}, (lo, hi))

    def render(medium, bounds, n, seed):
        return weft.render(scene((lo, hi), medium, bounds, n, seed, size), stats=True, base_dir=args.out)

    ref, ref_st = render(candidates["fine"][0], box, ref_spp, 101)
    empty, empty_st = render(None, box, max(16, ref_spp // 4), 102)
    mask = np.any(np.abs(ref - empty) > 5 * np.sqrt(ref_st["variance"] + empty_st["variance"]), axis=2)
    if mask.sum() < 10:
        raise SystemExit("coarse_render_study: the cloth covers fewer than 10 pixels")
    print("film %dx%d, reference %d spp, candidates %d spp; %d cloth pixels, mean %.4f"
          % (size[0], size[1], ref_spp, spp, mask.sum(), ref[mask].mean()))
    print("%-16s %8s %9s %9s %8s" % ("candidate", "bias", "bias/mean", "mean diff", "RMSE"))
    rows = []
    for seed, (name, (medium, bounds)) in enumerate(candidates.items(), start=201):
        rows.append((name,) + cloth_stats(*render(medium, bounds, spp, seed), ref, ref_st["variance"], mask))
        if not all(math.isfinite(v) for v in rows[-1][1:]):
            raise SystemExit("coarse_render_study: non-finite statistics for %s" % name)
        print("%-16s %8.4f %8.1f%% %+9.4f %8.4f" % (rows[-1][:2] + (100 * rows[-1][2],) + rows[-1][3:]))
    with open(os.path.join(args.out, "study.csv"), "w") as f:
        f.write("candidate,cloth_bias,cloth_relative_bias,cloth_difference,cloth_rmse\n")
        f.writelines("%s,%.6g,%.6g,%.6g,%.6g\n" % r for r in rows)


if __name__ == "__main__":
    main()
