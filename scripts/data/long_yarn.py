#!/usr/bin/env python3
"""One continuous yarn as a real weft knit has it: stockinette courses joined end to end (the yarn
runs back along every other course), written as a single OBJ polyline for `weft gen --input`.

Course r follows the loop shape of data_gen/cloth/pattern.cpp (knit_centerlines):
x = W(t/2pi + a sin 2t), y = rH + h(1 - cos t)/2, z = D cos t, mirrored in x on odd courses.
Sizes are for the cotton preset in mm (W = 0.975, H = 1.2, D = 0.27 from its envelope radius).

  scripts/data/long_yarn.py --points 10000 --out long.obj   # 0.085 mm of yarn per point
"""
import argparse
import math


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, required=True, help="centreline points (the yarn's length)")
    ap.add_argument("--wales", type=int, default=20, help="stitches per course")
    ap.add_argument("--per-stitch", type=int, default=48, help="points per stitch")
    ap.add_argument("--out", required=True, help="output .obj")
    a = ap.parse_args()
    r_env = 0.15
    W, H, D, loop, amp = 6.5 * r_env, 8.0 * r_env, 1.8 * r_env, 1.5 * 8.0 * r_env, 0.05
    pts = []
    course = 0
    while len(pts) < a.points:
        n = a.wales * a.per_stitch
        for k in range(n + 1):
            if len(pts) >= a.points:
                break
            t = 2.0 * math.pi * k / a.per_stitch
            x = W * (t / (2.0 * math.pi) + amp * math.sin(2.0 * t))
            if course % 2 == 1:
                x = W * a.wales - x
            pts.append((x, course * H + 0.5 * loop * (1.0 - math.cos(t)), D * math.cos(t)))
        course += 1
    with open(a.out, "w") as f:
        f.write(f"# weft scripts/data/long_yarn.py: one yarn, {len(pts)} points, {course} courses of {a.wales} stitches (mm)\n")
        for p in pts:
            f.write(f"v {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}\n")
        f.write("l " + " ".join(str(i + 1) for i in range(len(pts))) + "\n")


if __name__ == "__main__":
    main()
