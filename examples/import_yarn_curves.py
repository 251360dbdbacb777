"""Import your own yarn centrelines: an OBJ polyline file -> fibres -> voxels -> a beam.

Writes OUT/crossing.obj, two yarn centrelines (``v`` and ``l`` elements, in mm) that cross once:
a warp along x passing over a weft along y. ``weft.gen(input=...)`` builds the plies and fibres of
the yarn preset around each centreline and voxelizes them (docs/cloth.md, Import); then
``weft.measure_beam`` traces the ground-truth transmittance through the crossing along z, with
sigma from the grid's provenance. Prints T(t) and writes it to OUT/beam.csv.

    PYTHONPATH=build/ci/python python3 examples/import_yarn_curves.py --out imported/ [--quick]
"""

import argparse
import math
import os

import numpy as np

import weft


def write_obj(path, half_length=1.2, lift=0.2, points=49):
    """Two crossing centrelines: the warp rises to +lift over the crossing, the weft dips to -lift."""
    s = np.linspace(-half_length, half_length, points)
    bump = lift * np.cos(0.5 * math.pi * s / half_length)
    warp = np.stack([s, np.zeros_like(s), bump], axis=1)
    weft_ = np.stack([np.zeros_like(s), s, -bump], axis=1)
    with open(path, "w") as f:
        f.write("# two crossing yarn centrelines, mm\n")
        for p in np.concatenate([warp, weft_]):
            f.write("v %.6f %.6f %.6f\n" % tuple(p))
        for first in (1, points + 1):  # OBJ indices start at 1; one `l` element per curve
            f.write("l " + " ".join(str(first + i) for i in range(points)) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", default="imported", help="output folder")
    parser.add_argument("--quick", action="store_true", help="fewer fibres and coarser voxels (for CI)")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    obj = os.path.join(args.out, "crossing.obj")
    write_obj(obj)

    yarn = {"preset": "cotton", "fiber_count": 16 if args.quick else 40}
    cloth = weft.gen(input=obj, warp_yarn=yarn, weft_yarn=yarn, voxel_size=0.02 if args.quick else 0.01, seed=3)
    curves = len(set(cloth.fibers["yarn"].tolist()))
    print("imported %s: %d centrelines -> %d fibres -> %r" % (os.path.basename(obj), curves,
                                                            len(cloth.fibers["radius"]), cloth.grid))
    if curves != 2:
        raise SystemExit("import_yarn_curves: expected 2 yarns from %s, got %d" % (obj, curves))

    sigma = float(cloth.grid.metadata["weft:sigma_per_concentration"])
    curve = weft.measure_beam(cloth.grid, "z", sigma=sigma)
    depth, T, stderr = curve
    if not (np.all(np.isfinite(T)) and np.all(np.diff(T) <= 1e-12) and 0 <= T[-1] < 1):
        raise SystemExit("import_yarn_curves: T(t) along z is not a decreasing curve in [0, 1]")
    np.savetxt(os.path.join(args.out, "beam.csv"), np.stack([depth, T, stderr], axis=1), delimiter=",",
               header="depth_mm,T,stderr", comments="", fmt="%.6g")
    print("beam along +z through the crossing: %d rays, sigma %.4g per mm" % (curve.rays, sigma))
    print("depth[mm]       T    s.e.")
    for i in np.linspace(0, len(depth) - 1, 6).round().astype(int):
        print("%9.3f  %6.4f  %6.4f" % (depth[i], T[i], stderr[i]))


if __name__ == "__main__":
    main()
