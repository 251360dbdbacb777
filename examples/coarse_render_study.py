"""The coarse-cloth render study from Python: what does a coarse model of a cloth cost in an image?

`weft.render_study` (docs/render.md §6c, the library call behind `weft render --study`) on a
small back-lit cloth (the lighting of docs/render.md §5c): the fine grid rendered to low noise
is the reference R; then, two images each at fewer samples, the fine grid itself, the grid
downsampled N x (exponential-Nx), the local gamma fields of N^3-voxel blocks with the `optical-depth`
(default) and `segment` memory rules (local-gamma-Nx, local-gamma-segment-Nx), the baseline
corrected for self-shadowing (shadow-corrected-Nx, docs/render.md §6d; `weft.shadowed_downsample`)
and a slab with the gamma law of the grid's pooled window statistics (predicted, never fitted
to R). Over the cloth's pixels it prints each candidate's bias (the error left at convergence),
its z (bias^2 in standard errors: |z| < 5 is no detectable bias), the mean difference (> 0:
brighter than the fine grid), RMSE and noise, and the memory each representation holds; writes
the study's CSV (OUT/study.csv, the columns of `weft render --study`'s .study.csv) and the
reference image. With --matrix it also runs `weft.render_matrix` (docs/render.md §6e) on the
plain weave in three light set-ups and prints the headline.

    PYTHONPATH=build/ci/python python3 examples/coarse_render_study.py --out study/ [--quick] [--matrix]
"""

import argparse
import math
import os

import weft


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="coarse_render_study", help="output folder")
    parser.add_argument("--quick", action="store_true", help="a tiny film and few samples (for CI)")
    parser.add_argument("--matrix", action="store_true", help="also the study matrix on the plain weave")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    size, spp, ref_spp, factors = ((48, 36), 16, 128, (2, 4)) if args.quick else ((160, 120), 64, 1024, (2, 4, 8))

    cloth = weft.gen(yarns=(2, 2), voxel_size=0.02, seed=5, warp_yarn={"fiber_count": 16},
                     weft_yarn={"fiber_count": 16})
    scene = cloth.scene(lighting="back", width=size[0], height=size[1])
    result = weft.render_study(scene, spp=spp, reference_spp=ref_spp, factors=factors,
                               memory=("optical-depth", "segment"), seed=101, out=os.path.join(args.out, "study"))
    ref = result.reference
    print("film %dx%d, reference %d spp, candidates %d spp; %d cloth pixels, mean %.4f"
          % (ref["width"], ref["height"], ref["spp"], spp, ref["cloth_pixels"], ref["cloth_mean_pixel"]))
    print("%-28s %8s %9s %7s %9s %8s %8s %10s" % ("candidate", "bias", "bias/mean", "z", "mean diff", "RMSE",
                                                  "noise", "memory"))
    for c in result.candidates:
        numbers = (c.cloth_bias, c.cloth_bias / ref["cloth_mean_pixel"], c.cloth_bias_sq / c.cloth_bias_sq_stderr,
                   c.cloth_difference, c.cloth_rmse, c.cloth_noise)
        if not all(math.isfinite(v) for v in numbers):
            raise SystemExit("coarse_render_study: non-finite statistics for %s" % c.name)
        print("%-28s %8.4f %8.1f%% %7.1f %+9.4f %8.4f %8.4f %9d B"
              % ((c.name, numbers[0], 100 * numbers[1]) + numbers[2:] + (c.memory_bytes,)))
    print("headline: %s" % result.headline)
    with open(os.path.join(args.out, "study.csv"), "w") as f:
        f.write(result.csv)
    weft.write_exr(os.path.join(args.out, "reference.exr"), result.reference_image)
    weft.write_png(os.path.join(args.out, "reference.png"), result.reference_image)

    if args.matrix:
        matrix = weft.render_matrix(quick=args.quick, cloths="plain", tilts=45, factors=factors,
                                    out=os.path.join(args.out, "matrix"))
        for h in matrix.headlines:
            print("matrix headline: %s" % h.text)
        with open(os.path.join(args.out, "matrix.csv"), "w") as f:
            f.write(matrix.csv)


if __name__ == "__main__":
    main()
