#!/usr/bin/env python3
"""The MRT of a run's scene at the truth's grid nodes and points, against the truth.

    level_check.py MRTMAP RUN_DIR RECORDING   prints one JSON line

Absolute errors, errors with their mean removed (the map relative to itself), the largest error in
a difference between two nodes (all nodes, neighbouring nodes, nodes 30 cm or more from the grid's
box), the errors' slope against the true MRT (a camera gain error) and the largest difference
error without it, and how often the stated standard error covers the error (|Δ| ≤ 2σ).

Twice: at the truth's places in the scan's frame (where the pose source puts them), and under
"room" at the same places measured from the room's walls, as a person with a tape measure from a
corner gives them (the scene's own room frame, `--frame room`): the truth's room coordinates
taken from the corner that the scene's origin corner is, turned by the multiple of 90° that
carries the truth's axes onto the scene's (the corners are those of the grid's box widened by its
margin: right for box rooms only). The two differ by where the fused map sits against the
pose source's frame (its displacement, not its shape)."""
import json
import math
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rotations import quaternion_matrix  # noqa: E402


def mrt_at(mrtmap, scene, frame, xyz):
    args = [mrtmap, "mrt", "--scene", scene, "--frame", frame, "--json"]
    args += ["--at=" + ",".join(f"{v:.5f}" for v in p) for p in xyz]
    return json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)["points"]


def taped(truth, scene_path, places):
    """The places' room coordinates in the scene's room frame, measured from its origin corner."""
    nodes = truth["grid"]["nodes"]
    a = np.array([n["xyz_room"] for n in nodes])
    b = np.array([n["xyz_world"] for n in nodes])
    # world_from_truth_room (exact: the truth's nodes in both frames), by the Kabsch fit.
    ma, mb = a.mean(0), b.mean(0)
    u, _, vt = np.linalg.svd((b - mb).T @ (a - ma))
    r_t = u @ np.diag([1, 1, np.linalg.det(u @ vt)]) @ vt
    t_t = mb - r_t @ ma
    w = json.load(open(scene_path))["world_from_room"]
    r_s = quaternion_matrix(*w["rotation_xyzw"])
    t_s = np.array(w["translation"])
    # scene_room_from_truth_room: a turn about the vertical (snapped to 90°) and a shift.
    r = r_s.T @ r_t
    yaw = math.degrees(math.atan2(r[1, 0], r[0, 0]))
    snapped = 90 * round(yaw / 90)
    if abs(yaw - snapped) < 3:
        yaw = snapped
    c, s = math.cos(math.radians(yaw)), math.sin(math.radians(yaw))
    turn = np.array([[c, -s], [s, c]])
    margin = truth["grid"]["margin_m"]
    lo, hi = a[:, :2].min(0) - margin, a[:, :2].max(0) + margin
    corners = [np.array([x, y]) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])]
    # The truth's corner that the scene's origin corner is: the nearest to where the fused map
    # puts the scene's origin.
    origin = (r_t.T @ (t_s - t_t))[:2]
    corner = min(corners, key=lambda k: np.linalg.norm(k - origin))
    out = []
    for p in places:
        q = turn @ (np.array(p["xyz_room"][:2]) - corner)
        out.append([q[0], q[1], p["xyz_room"][2]])
    return out


def metrics(truth, nodes, places, out):
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
    return {
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
    }


def main(mrtmap, run, rec):
    truth = json.load(open(f"{rec}/truth.json"))
    scene = f"{run}/segment/scene.json"
    nodes = [n for n in truth["grid"]["nodes"] if n["mrt_c"] is not None]
    places = nodes + truth["points"]
    result = metrics(truth, nodes, places,
                     mrt_at(mrtmap, scene, "scan", [p["xyz_world"] for p in places]))
    result["room"] = metrics(truth, nodes, places,
                             mrt_at(mrtmap, scene, "room", taped(truth, scene, places)))
    print(json.dumps(result))


if __name__ == "__main__":
    main(*sys.argv[1:4])
