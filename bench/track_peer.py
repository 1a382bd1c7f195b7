"""The Open3D side of `bench/run track`: RGB-D odometry and a pose graph on the same frames.

    python3 bench/track_peer.py RECORDING OURS_TRAJECTORY

Every colour frame is paired with the nearest depth frame (as TUM's associate.py does), and
Open3D's `compute_rgbd_odometry` (hybrid photometric + geometric term, its default pyramid) runs
between consecutive frames, started from the previous frame's motion. Then, as Open3D's
reconstruction system does inside a fragment, keyframes (every 5th frame) are joined to older
keyframes that the odometry puts within 1 m and 30 degrees, each such pair registered by the same
odometry from the estimated relative pose and kept when Open3D calls it a success; the graph is
optimised by Open3D's global optimisation (Levenberg-Marquardt, line processes pruning edges above
0.25). Both trajectories, and mrtmap's from OURS_TRAJECTORY, are scored against groundtruth.txt
the same way: TUM's ATE (RMSE of positions after the best rigid alignment), the rotation left after
that alignment, and the drift over 1 s. Prints one JSON line.
"""
import json
import sys
import time
import tomllib

import numpy as np
import open3d as o3d
from scipy.spatial.transform import Rotation


def read_list(path):
    out = []
    for line in open(path):
        if line.strip() and not line.startswith("#"):
            t, p = line.split()[:2]
            out.append((float(t), p))
    return out


def read_poses(path):
    rows = [[float(x) for x in l.split()[:8]] for l in open(path) if l.strip() and not l.startswith("#")]
    return np.array(rows)


def to_matrices(rows):
    out = []
    for r in rows:
        m = np.eye(4)
        m[:3, :3] = Rotation.from_quat(r[4:8]).as_matrix()
        m[:3, 3] = r[1:4]
        out.append(m)
    return out


def interpolate(gt, times):
    """Ground-truth poses at `times` (linear in position, nearest in rotation at 200 Hz)."""
    mats = to_matrices(gt)
    out = []
    for t in times:
        k = int(np.clip(np.searchsorted(gt[:, 0], t), 1, len(gt) - 1))
        a, b = gt[k - 1, 0], gt[k, 0]
        s = 0.0 if b <= a else (t - a) / (b - a)
        m = (mats[k] if s > 0.5 else mats[k - 1]).copy()
        m[:3, 3] = (1 - s) * mats[k - 1][:3, 3] + s * mats[k][:3, 3]
        out.append(m)
    return out


def angle_deg(r):
    return float(np.degrees(np.arccos(np.clip((np.trace(r) - 1) / 2, -1, 1))))


def score(times, est, gt_rows):
    """ATE RMSE (m) and max, rotation after alignment (deg RMSE), drift over 1 s (m, deg RMSE)."""
    gt = interpolate(gt_rows, times)
    a = np.array([m[:3, 3] for m in est])
    b = np.array([m[:3, 3] for m in gt])
    ca, cb = a.mean(0), b.mean(0)
    u, _, vt = np.linalg.svd((a - ca).T @ (b - cb))
    d = np.eye(3)
    d[2, 2] = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ d @ u.T
    err = np.linalg.norm((r @ a.T).T + (cb - r @ ca) - b, axis=1)
    rot = [angle_deg((r @ e[:3, :3]).T @ g[:3, :3]) for e, g in zip(est, gt)]
    dt, dr = [], []
    j = 0
    for i in range(len(times)):
        while j < len(times) and times[j] < times[i] + 1.0:
            j += 1
        if j >= len(times):
            break
        rel_e = np.linalg.inv(est[i]) @ est[j]
        rel_g = np.linalg.inv(gt[i]) @ gt[j]
        e = np.linalg.inv(rel_g) @ rel_e
        dt.append(np.linalg.norm(e[:3, 3]))
        dr.append(angle_deg(e[:3, :3]))
    rms = lambda v: float(np.sqrt(np.mean(np.square(v))))
    return {
        "poses": len(times), "ate_rmse_m": rms(err), "ate_max_m": float(err.max()),
        "rotation_rmse_deg": rms(rot), "drift_1s_m": rms(dt), "drift_1s_deg": rms(dr),
    }


def main():
    rec, ours_path = sys.argv[1:3]
    rig = tomllib.load(open(f"{rec}/rig.toml", "rb"))
    cam = rig["rgb"]
    ext = cam.get("depth_from_rgb", {})
    if any(abs(v) > 1e-9 for v in ext.get("translation", [0, 0, 0])):
        sys.exit("track_peer.py: colour and depth cameras differ; Open3D's RGBDImage needs them registered")
    O = o3d.t.pipelines.odometry
    K = o3d.core.Tensor([[cam["fx"], 0, cam["cx"]], [0, cam["fy"], cam["cy"]], [0, 0, 1]], dtype=o3d.core.Dtype.Float64)
    scale = rig["depth"].get("depth_scale", 1000.0)
    colour = read_list(f"{rec}/rgb.txt")
    if len(sys.argv) > 3:  # a quick look at the first N frames
        colour = colour[: int(sys.argv[3])]
    depth = read_list(f"{rec}/depth.txt")
    dts = np.array([t for t, _ in depth])
    criteria = [O.OdometryConvergenceCriteria(20), O.OdometryConvergenceCriteria(10), O.OdometryConvergenceCriteria(5)]

    def rgbd(k):
        t, p = colour[k]
        j = int(np.argmin(np.abs(dts - t)))
        return o3d.t.geometry.RGBDImage(o3d.t.io.read_image(f"{rec}/{p}"), o3d.t.io.read_image(f"{rec}/{depth[j][1]}"))

    def odometry_pair(source, target, init):
        """target_from_source, fitness and information (Open3D's convention: source to target);
        None where Open3D gives up (it raises on a singular system)."""
        try:
            r = O.rgbd_odometry_multi_scale(source, target, K, o3d.core.Tensor(init), scale, 3.5, criteria, O.Method.Hybrid)
        except RuntimeError:
            return None
        trans = r.transformation.numpy()
        info = O.compute_odometry_information_matrix(
            source.depth, target.depth, K, r.transformation, 0.07, scale, 3.5).numpy()
        return trans, r.fitness, info

    t0 = time.perf_counter()
    keep = {0: rgbd(0)}  # keyframes' images (every 5th frame), for the loops
    previous = keep[0]
    poses = [np.eye(4)]  # world_from_frame
    odometry = []  # (later_from_earlier, information) of consecutive frames
    motion = np.eye(4)  # the previous pair's later_from_earlier: the next pair's start
    failed = 0
    for k in range(1, len(colour)):
        current = rgbd(k)
        # As in Open3D's make_fragments: the earlier frame is the source, the later the target.
        got = odometry_pair(previous, current, motion)
        if got is None:
            failed += 1  # keep the previous motion (constant velocity)
            info = np.eye(6)
        else:
            motion, _, info = got
        previous = current
        if k % 5 == 0:
            keep[k] = current
        odometry.append((motion, info))
        poses.append(poses[-1] @ np.linalg.inv(motion))
    t_odometry = time.perf_counter() - t0
    # Keyframes every 5th frame, each tried against the two nearest older keyframes (at least 30
    # frames back) that the odometry puts within 1 m and 30 degrees.
    t1 = time.perf_counter()
    graph = o3d.pipelines.registration.PoseGraph()
    for p in poses:
        graph.nodes.append(o3d.pipelines.registration.PoseGraphNode(p))
    for k, (trans, info) in enumerate(odometry):
        graph.edges.append(o3d.pipelines.registration.PoseGraphEdge(k, k + 1, trans, info, uncertain=False))
    keys = sorted(keep)
    tried = accepted = 0
    for a in keys:
        near = []
        for b in keys:
            if b > a - 30:
                break
            rel = np.linalg.inv(poses[a]) @ poses[b]  # a_from_b
            dist = np.linalg.norm(rel[:3, 3])
            if dist <= 1.0 and angle_deg(rel[:3, :3]) <= 30:
                near.append((dist, b, rel))
        for _, b, rel in sorted(near, key=lambda x: x[0])[:2]:
            tried += 1
            got = odometry_pair(keep[b], keep[a], rel)
            if got is not None and got[1] >= 0.5:
                trans, _, info = got
                accepted += 1
                graph.edges.append(o3d.pipelines.registration.PoseGraphEdge(b, a, trans, info, uncertain=True))
    o3d.utility.set_verbosity_level(o3d.utility.VerbosityLevel.Error)
    o3d.pipelines.registration.global_optimization(
        graph,
        o3d.pipelines.registration.GlobalOptimizationLevenbergMarquardt(),
        o3d.pipelines.registration.GlobalOptimizationConvergenceCriteria(),
        o3d.pipelines.registration.GlobalOptimizationOption(
            max_correspondence_distance=0.03, edge_prune_threshold=0.25, reference_node=0),
    )
    t_graph = time.perf_counter() - t1
    optimised = [n.pose for n in graph.nodes]
    gt = read_poses(f"{rec}/groundtruth.txt")
    times = [t for t, _ in colour]
    ours = read_poses(ours_path)
    ours = ours[ours[:, 0] <= times[-1] + 1e-6]
    print(json.dumps({
        "frames": len(colour),
        "open3d_odometry": {**score(times, poses, gt), "failed": failed, "seconds": t_odometry},
        "open3d_pose_graph": {**score(times, optimised, gt), "loops_tried": tried,
                               "loops_accepted": accepted, "seconds": t_odometry + t_graph},
        "mrtmap": score(list(ours[:, 0]), to_matrices(ours), gt),
    }))


if __name__ == "__main__":
    main()
