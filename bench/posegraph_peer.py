"""bench/run posegraph: mrtmap's pose-graph optimisation (tiny-solver) beside GTSAM on the same
graphs. A handheld scan circling a room LOOPS times (NODES nodes, RTAB-Map-like noisy odometry,
loop closures where a lap passes the same spot), written as g2o; both optimise it from the
integrated odometry; both results are scored by GTSAM's objective and against the true poses.

    python3 bench/posegraph_peer.py EXAMPLE_BINARY WORK_DIR
"""
import json
import math
import statistics
import subprocess
import sys
import time
from pathlib import Path

import gtsam
import numpy as np

exe, work = sys.argv[1], Path(sys.argv[2])
work.mkdir(parents=True, exist_ok=True)
SIG_T, SIG_R = 0.01, 0.005        # odometry, m and rad
CL_T, CL_R = 0.005, 0.002         # loop closures


def pose(t, rpy):
    return gtsam.Pose3(gtsam.Rot3.Ypr(rpy[2], rpy[1], rpy[0]), gtsam.Point3(*t))


def noisy(p, rng, st, sr):
    d = np.concatenate([rng.normal(0, sr, 3), rng.normal(0, st, 3)])
    return p.compose(gtsam.Pose3.Expmap(d))


def graph(nodes, loops, seed):
    rng = np.random.default_rng(seed)
    per = nodes // loops
    truth = []
    for i in range(nodes):
        a = 2 * math.pi * (i % per) / per
        lap = i // per
        truth.append(pose([2.5 * math.cos(a) + 0.05 * lap, 1.8 * math.sin(a), 1.2 + 0.15 * math.sin(3 * a)],
                          [0.05 * math.sin(2 * a), 0.03 * math.cos(a), a + math.pi / 2]))
    edges = []
    for i in range(1, nodes):
        edges.append((i - 1, i, noisy(truth[i - 1].between(truth[i]), rng, SIG_T, SIG_R), SIG_T, SIG_R))
    for i in range(per, nodes, 5):
        j = i - per
        edges.append((i, j, noisy(truth[i].between(truth[j]), rng, CL_T, CL_R), CL_T, CL_R))
    init = [truth[0]]
    for (a, b, z, _, _) in edges[: nodes - 1]:
        init.append(init[-1].compose(z))
    return truth, init, edges


def write_g2o(path, init, edges):
    out = []
    for i, p in enumerate(init):
        t, q = p.translation(), p.rotation().toQuaternion()
        out.append(f"VERTEX_SE3:QUAT {i} {t[0]} {t[1]} {t[2]} {q.x()} {q.y()} {q.z()} {q.w()}")
    for a, b, z, st, sr in edges:
        t, q = z.translation(), z.rotation().toQuaternion()
        # g2o's rotation error is the quaternion vector (half the angle): 4/σ² there.
        diag = [1 / st ** 2] * 3 + [4 / sr ** 2] * 3
        upper = [diag[i] if i == j else 0.0 for i in range(6) for j in range(i, 6)]
        out.append(f"EDGE_SE3:QUAT {a} {b} {t[0]} {t[1]} {t[2]} {q.x()} {q.y()} {q.z()} {q.w()} " + " ".join(map(str, upper)))
    path.write_text("\n".join(out) + "\n")


def gtsam_graph(truth, edges):
    g = gtsam.NonlinearFactorGraph()
    g.add(gtsam.PriorFactorPose3(0, truth[0], gtsam.noiseModel.Diagonal.Sigmas(np.full(6, 1e-6))))
    for a, b, z, st, sr in edges:
        g.add(gtsam.BetweenFactorPose3(a, b, z, gtsam.noiseModel.Diagonal.Sigmas(np.array([sr] * 3 + [st] * 3))))
    return g


def values(poses):
    v = gtsam.Values()
    for i, p in enumerate(poses):
        v.insert(i, p)
    return v


def read_g2o(path, n):
    poses = [None] * n
    for line in path.read_text().splitlines():
        f = line.split()
        x, y, z, qx, qy, qz, qw = map(float, f[2:9])
        poses[int(f[1])] = gtsam.Pose3(gtsam.Rot3.Quaternion(qw, qx, qy, qz), gtsam.Point3(x, y, z))
    return poses


def ate(poses, truth):
    e = np.array([np.linalg.norm(p.translation() - t.translation()) for p, t in zip(poses, truth)])
    return float(np.sqrt((e ** 2).mean())), float(e.max())


print(f"{'graph':<24} {'':>8} {'objective':>12} {'RMS pos err':>12} {'max pos err':>12} {'time':>9}")
for nodes, loops in [(300, 3), (1000, 10), (3000, 15)]:
    truth, init, edges = graph(nodes, loops, 7)
    g2o = work / f"loops-{nodes}.g2o"
    write_g2o(g2o, init, edges)
    g = gtsam_graph(truth, edges)
    times = []
    for _ in range(3):
        t = time.perf_counter()
        params = gtsam.LevenbergMarquardtParams()
        res = gtsam.LevenbergMarquardtOptimizer(g, values(init), params).optimize()
        times.append(time.perf_counter() - t)
    theirs = [res.atPose3(i) for i in range(nodes)]
    ours_out = work / f"loops-{nodes}-mrtmap.g2o"
    j = json.loads(subprocess.run([exe, g2o, ours_out], check=True, capture_output=True, text=True).stdout)
    ours = read_g2o(ours_out, nodes)
    label = f"{nodes} nodes, {len(edges)} edges"
    o0 = g.error(values(init))
    print(f"{label:<24} {'odometry':>8} {o0:12.1f} {ate(init, truth)[0]:12.4f} {ate(init, truth)[1]:12.4f}")
    oo, ot = g.error(values(ours)), g.error(res)
    (r_o, m_o), (r_t, m_t) = ate(ours, truth), ate(theirs, truth)
    print(f"{'':<24} {'mrtmap':>8} {oo:12.1f} {r_o:12.4f} {m_o:12.4f} {j['seconds']:8.3f}s")
    print(f"{'':<24} {'GTSAM':>8} {ot:12.1f} {r_t:12.4f} {m_t:12.4f} {statistics.median(times):8.3f}s")
    print(f"{'':<24} {'ratio':>8} {oo / ot:12.3f} {r_o / r_t:12.3f} {m_o / m_t:12.3f} {j['seconds'] / statistics.median(times):8.2f}x GTSAM's time")
