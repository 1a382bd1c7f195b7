#!/usr/bin/env python3
"""The MRT of a run's scene at the truth's grid nodes and points, against the truth.

    level_check.py MRTMAP RUN_DIR RECORDING   prints one JSON line

Absolute errors, errors with their mean removed (the map relative to itself), the largest error in
a difference between two nodes (all nodes, neighbouring nodes, nodes 30 cm or more from the grid's
box), the errors' slope against the true MRT (a camera gain error) and the largest difference
error without it, and how often the stated standard error covers the error (|Δ| ≤ 2σ)."""
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
    # Neighbouring nodes (the map's gradients), and nodes 30 cm or more inside the grid's box (the
    # box of the nodes widened by the grid's margin: the walls of a box room).
    at = {(n["i"], n["j"]): x for n, x in zip(nodes, g)}
    adjacent = [abs(x - at[(i + a, j + b)]) for (i, j), x in at.items()
                for a, b in ((1, 0), (0, 1)) if (i + a, j + b) in at]
    margin = truth["grid"]["margin_m"]
    lo = [min(n["xyz_room"][k] for n in nodes) - margin for k in (0, 1)]
    hi = [max(n["xyz_room"][k] for n in nodes) + margin for k in (0, 1)]
    inner = [x for n, x in zip(nodes, g)
             if all(lo[k] + 0.3 <= n["xyz_room"][k] <= hi[k] - 0.3 for k in (0, 1))]
    # The errors' slope against the true MRT: a camera gain error stretches every contrast.
    t = [n["mrt_c"] for n in nodes]
    tm = sum(t) / len(t)
    slope = sum((a - tm) * (b - m) for a, b in zip(t, g)) / sum((a - tm) ** 2 for a in t)
    flat = [b - m - slope * (a - tm) for a, b in zip(t, g)]
    print(json.dumps({
        "grid_nodes": len(g),
        "grid_max_abs_k": max(abs(x) for x in g),
        "grid_rmse_k": math.sqrt(sum(x * x for x in g) / len(g)),
        "grid_mean_k": m,
        "grid_relative_max_abs_k": max(abs(x) for x in rel),
        # The largest error in a difference between two nodes (the map relative to itself).
        "grid_difference_max_k": max(g) - min(g),
        "grid_adjacent_difference_max_k": max(adjacent),
        "grid_inner_nodes": len(inner),
        "grid_inner_difference_max_k": max(inner) - min(inner) if inner else None,
        "grid_error_slope": slope,
        "grid_difference_max_without_slope_k": max(flat) - min(flat),
        "points_k": {p["name"]: round(x, 3) for p, x in zip(truth["points"], d[len(nodes):])},
        "stated_se_median_k": sorted(se)[len(se) // 2],
        "covered_at_2se": sum(abs(x) <= 2 * s for x, s in zip(d, se)) / len(d),
    }))


if __name__ == "__main__":
    main(*sys.argv[1:4])
