#!/usr/bin/env python3
"""The MRT of a run's scene at the truth's grid nodes and points, against the truth.

    level_check.py MRTMAP RUN_DIR RECORDING   prints one JSON line

Absolute errors, errors with their mean removed (the map relative to itself), and how often the
stated standard error covers the error (|Δ| ≤ 2σ)."""
import json
import math
import subprocess
import sys


def main(mrtmap, run, rec):
    truth = json.load(open(f"{rec}/truth.json"))
    scene = f"{run}/segment/scene.json"
    nodes = [n for n in truth["grid"]["nodes"] if n["mrt_c"] is not None]
    places = nodes + truth["points"]
    args = [mrtmap, "mrt", "--scene", scene, "--frame", "scan", "--json"]
    for p in places:
        args += ["--at=" + ",".join(f"{v:.5f}" for v in p["xyz_world"])]
    out = json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)["points"]
    d = [o["mrt_c"] - p["mrt_c"] for o, p in zip(out, places)]
    se = [o["std_error_k"] for o in out]
    g = d[: len(nodes)]
    m = sum(g) / len(g)
    rel = [x - m for x in g]
    print(json.dumps({
        "grid_nodes": len(g),
        "grid_max_abs_k": max(abs(x) for x in g),
        "grid_rmse_k": math.sqrt(sum(x * x for x in g) / len(g)),
        "grid_mean_k": m,
        "grid_relative_max_abs_k": max(abs(x) for x in rel),
        # The largest error in a difference between two nodes (the map relative to itself).
        "grid_difference_max_k": max(g) - min(g),
        "points_k": {p["name"]: round(x, 3) for p, x in zip(truth["points"], d[len(nodes):])},
        "stated_se_median_k": sorted(se)[len(se) // 2],
        "covered_at_2se": sum(abs(x) <= 2 * s for x, s in zip(d, se)) / len(d),
    }))


if __name__ == "__main__":
    main(*sys.argv[1:4])
