"""Checks the study matrix's bias against image scale and its component split (docs/render.md §6e).

usage: check_matrix_split.py MATRIX_JSON FAMILY...

Per case: the fine grid (the reference's own model) has no bias at any block size and no level
(|z| < 5 at every k with at least 10 blocks on the cloth; |level| < 5 standard errors), nor in any component;
the fine grid and the candidates of the FAMILY list carry the three components (transmission,
single, multiple) and no other candidate does (a run computes only what was asked); the three
components' levels add up to the full level within their standard errors.
"""
import json
import math
import re
import sys


def fail(msg):
    sys.exit(f"check_matrix_split: {msg}")


def main():
    matrix = json.load(open(sys.argv[1]))
    families = set(sys.argv[2:])
    for case in matrix["cases"]:
        name = case["case"]
        for c in case["candidates"]:
            scales = c["cloth_scales"]
            family = re.sub(r"-\d+x$", "", c["name"])
            split = c["name"] == "fine" or family in families
            comps = c["components"]
            if split != (len(comps) == 3):
                fail(f"{name}: {c['name']} has {len(comps)} components, expected {3 if split else 0}")
            if [b["block"] for b in scales["blocks"]] != [1, 2, 4, 8]:
                fail(f"{name}: {c['name']} block sizes {scales['blocks']}")
            level = scales["level"]
            if c["name"] == "fine":
                for b in scales["blocks"]:
                    # kMinBiasBlocks (bias_scales.h): fewer blocks have no usable standard error.
                    if b["count"] >= 10 and abs(b["bias_z"]) >= 5:
                        fail(f"{name}: the fine grid's bias at {b['block']} px has z = {b['bias_z']}")
                if abs(level["difference"]) >= 5 * level["difference_stderr"] + 1e-12:
                    fail(f"{name}: the fine grid's level {level} is not 0 within 5 standard errors")
                for k in comps:
                    b = k["bias"]["blocks"][0]
                    kl = k["bias"]["level"]
                    if abs(b["bias_z"]) >= 5 or abs(kl["difference"]) >= 5 * kl["difference_stderr"] + 1e-12:
                        fail(f"{name}: the fine grid's {k['name']} is biased: z {b['bias_z']}, level {kl}")
            if comps:
                if [k["name"] for k in comps] != ["transmission", "single", "multiple"]:
                    fail(f"{name}: {c['name']} components {[k['name'] for k in comps]}")
                total = sum(k["bias"]["level"]["difference"] for k in comps)
                se = math.sqrt(sum(k["bias"]["level"]["difference_stderr"] ** 2 for k in comps))
                if abs(total - level["difference"]) > 5 * se + 1e-9:
                    fail(f"{name}: {c['name']}: components add up to {total}, the full level is {level['difference']}")
    print(f"check_matrix_split: {len(matrix['cases'])} cases checked")


if __name__ == "__main__":
    main()
