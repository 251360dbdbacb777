#!/usr/bin/env python3
"""Checks scripts/study_distance's table against the matrix runs it tabulates (docs/render.md §6e
"Bias against viewing distance"): usage check_study_distance.py DIR Y1 Y2 (Y2 = 2 Y1).

- every representation of every run has its row, and each row's figures are the run's own
  matrix.json headline figures (the script computes nothing);
- the cloth framed to fill the same film with twice the yarns is seen from further away: a
  block's footprint in pixels falls, by at most 2 (the yarns' ratio) and by less with few yarns,
  whose frame holds a margin that does not scale with them (flyaways, the crimp; measured 1.44
  from 1 to 2 yarns at the quick film, 1.81 and 1.88 from 8 to 16 and 16 to 32).
"""
import json
import sys
from pathlib import Path

d, y1, y2 = Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
lines = (d / "distance.md").read_text().splitlines()
first = lines[2:lines.index("")] if "" in lines else lines[2:]  # the representations' table
rows = [[c.strip() for c in l.strip("|").split("|")] for l in first]
by_key = {(r[0], r[1], int(r[2])): r for r in rows}
foot = {}
for y in (y1, y2):
    m = json.loads((d / f"y{y}" / "matrix.json").read_text())
    for h in m["headlines"]:
        for r in h["representations"]:
            name = r["name"]
            if not any(name.startswith(f) for f in ("exponential-", "local-gamma-", "shadow-corrected-")):
                continue
            if name.startswith("local-gamma-segment"):
                continue
            row = by_key.get((h["cloth"], name, y))
            if row is None:
                sys.exit(f"distance.md has no row for {h['cloth']} {name} at {y} yarns")
            want = f"{100.0 * r['worst_relative_bias_by_block'][0]:.1f}"
            if row[4] != want:
                sys.exit(f"{h['cloth']} {name} at {y} yarns: table says {row[4]}, matrix.json {want}")
            want_level = f"{100.0 * r['worst_relative_level']:.1f}"
            if row[8] != want_level:
                sys.exit(f"{h['cloth']} {name} at {y} yarns: level {row[8]}, matrix.json {want_level}")
            foot[(h["cloth"], name, y)] = float(row[3])
ratios = [foot[(c, n, y1)] / foot[(c, n, y2)] for (c, n, y) in foot if y == y1 and (c, n, y2) in foot]
if not ratios:
    sys.exit("no representation appears at both yarn counts")
for q in ratios:
    if not 1.2 < q <= 2.0 * 1.02:
        sys.exit(f"block footprint at {y1} yarns / at {y2} yarns = {q:.3f}: not in (1.2, 2]")
print(f"{len(foot)} rows checked; footprint ratios {min(ratios):.3f}-{max(ratios):.3f}")
