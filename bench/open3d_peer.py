"""The Open3D side of `bench/run fusion`: the same clouds, the same operations, medians of 5.

Voxel downsampling at 3 cm of raw.ply; point-to-plane ICP of source.ply onto target.ply (normals
from the file, max correspondence 0.1 m, 30 iterations), error against the known transform.
"""
import json
import sys
import time

import numpy as np
import open3d as o3d

d = sys.argv[1]
raw = o3d.io.read_point_cloud(f"{d}/raw.ply")
times = []
for _ in range(5):
    t = time.perf_counter()
    down = raw.voxel_down_sample(0.03)
    times.append(time.perf_counter() - t)
t_down = float(np.median(times))
# Same voxels, same centroids? Match mrtmap's downsampled points to Open3D's by voxel index.
ours = np.asarray(o3d.io.read_point_cloud(f"{d}/down.ply").points)
theirs = np.asarray(down.points)
origin = np.asarray(raw.get_min_bound()) - 0.015
key = lambda p: [tuple(k) for k in np.floor((p - origin) / 0.03).astype(np.int64)]
mine = dict(zip(key(ours), ours))
diffs = [np.linalg.norm(mine[k] - p) for k, p in zip(key(theirs), theirs) if k in mine]
centroid_max_diff = float(max(diffs)) if diffs else float("nan")
matched = len(diffs)
target = o3d.io.read_point_cloud(f"{d}/target.ply")
source = o3d.io.read_point_cloud(f"{d}/source.ply")
truth = np.array(eval(open(f"{d}/truth.txt").read())).reshape(4, 4).T  # column-major from nalgebra
times = []
for _ in range(5):
    t = time.perf_counter()
    reg = o3d.pipelines.registration.registration_icp(
        source, target, 0.1, np.eye(4),
        o3d.pipelines.registration.TransformationEstimationPointToPlane(),
        o3d.pipelines.registration.ICPConvergenceCriteria(max_iteration=30),
    )
    times.append(time.perf_counter() - t)
err = reg.transformation @ np.linalg.inv(truth)
angle = np.degrees(np.arccos(np.clip((np.trace(err[:3, :3]) - 1) / 2, -1, 1)))
print(json.dumps({
    "raw_points": len(raw.points), "downsampled": len(down.points), "downsample_s": t_down,
    "voxels_matched": matched, "centroid_max_diff_m": centroid_max_diff,
    "target": len(target.points), "source": len(source.points), "icp_s": float(np.median(times)),
    "icp_fitness": reg.fitness, "icp_inlier_rmse_m": reg.inlier_rmse,
    "icp_translation_error_m": float(np.linalg.norm(err[:3, 3])), "icp_rotation_error_deg": float(angle),
}))
