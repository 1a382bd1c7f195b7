"""Two real TUM RGB-D frames (shared/data/tum-rgbd: 1.png, 2.png and their depth at 5000 per
metre; no ground truth for the pair): the relative pose from `mrtmap track` beside OpenCV's
(ORB features, brute-force Hamming matching with cross-check, solvePnPRansac on the first frame's
depth, then refined on the inliers), and their difference.

    python3 bench/tum_pair_peer.py MRTMAP DATA_DIR WORK
"""
import json
import os
import subprocess
import sys

import cv2
import numpy as np
from scipy.spatial.transform import Rotation

mrtmap, data, work = sys.argv[1:4]
src = os.path.join(data, "tum-rgbd")
fx, fy, cx, cy = 520.9, 521.0, 325.1, 249.7  # SOURCES.md
rec = os.path.join(work, "tum-pair")
os.makedirs(rec, exist_ok=True)
for name in ("1.png", "2.png", "1_depth.png", "2_depth.png"):
    dst = os.path.join(rec, name)
    if not os.path.exists(dst):
        os.symlink(os.path.abspath(os.path.join(src, name)), dst)
cam = f"width = 640\nheight = 480\nfx = {fx}\nfy = {fy}\ncx = {cx}\ncy = {cy}\n"
ident = 'translation = [0.0, 0.0, 0.0]\nrotation_xyzw = [0.0, 0.0, 0.0, 1.0]\n'
open(os.path.join(rec, "rig.toml"), "w").write(
    f"[depth]\n{cam}depth_scale = 5000.0\n\n[thermal]\nwidth = 160\nheight = 120\nfx = 150.0\nfy = 150.0\n"
    f"cx = 79.5\ncy = 59.5\nencoding = \"centikelvin\"\n\n[thermal.depth_from_thermal]\n{ident}\n"
    f"[rgb]\n{cam}\n[rgb.depth_from_rgb]\n{ident}")
open(os.path.join(rec, "rgb.txt"), "w").write("0.000 1.png\n0.033 2.png\n")
open(os.path.join(rec, "depth.txt"), "w").write("0.000 1_depth.png\n0.033 2_depth.png\n")
open(os.path.join(rec, "thermal.txt"), "w").write("")
out = os.path.join(work, "tum-pair-track")
subprocess.run([mrtmap, "track", rec, "--out", out, "--no-loops"], check=True, capture_output=True)
rows = [[float(x) for x in l.split()] for l in open(os.path.join(out, "trajectory.txt")) if not l.startswith("#")]


def matrix(r):
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(r[4:8]).as_matrix()
    m[:3, 3] = r[1:4]
    return m


ours = np.linalg.inv(matrix(rows[1])) @ matrix(rows[0]) if len(rows) == 2 else None  # second_from_first

# OpenCV: the first frame's ORB corners with depth, located in the second by PnP.
g1 = cv2.imread(os.path.join(src, "1.png"), cv2.IMREAD_GRAYSCALE)
g2 = cv2.imread(os.path.join(src, "2.png"), cv2.IMREAD_GRAYSCALE)
d1 = cv2.imread(os.path.join(src, "1_depth.png"), cv2.IMREAD_UNCHANGED).astype(float) / 5000.0
orb = cv2.ORB_create(2000)
k1, des1 = orb.detectAndCompute(g1, None)
k2, des2 = orb.detectAndCompute(g2, None)
matches = cv2.BFMatcher(cv2.NORM_HAMMING, crossCheck=True).match(des1, des2)
obj, img = [], []
for m in matches:
    u, v = k1[m.queryIdx].pt
    z = d1[int(round(v)), int(round(u))]
    if z > 0:
        obj.append([(u - cx) * z / fx, (v - cy) * z / fy, z])
        img.append(k2[m.trainIdx].pt)
K = np.array([[fx, 0, cx], [0, fy, cy], [0, 0, 1]])
obj, img = np.array(obj), np.array(img)
ok, rvec, tvec, inl = cv2.solvePnPRansac(obj, img, K, None, reprojectionError=2.0, iterationsCount=1000,
                                         flags=cv2.SOLVEPNP_EPNP)
rvec, tvec = cv2.solvePnPRefineLM(obj[inl[:, 0]], img[inl[:, 0]], K, None, rvec, tvec)
theirs = np.eye(4)
theirs[:3, :3] = cv2.Rodrigues(rvec)[0]
theirs[:3, 3] = tvec[:, 0]


def describe(t):
    ang = np.degrees(np.arccos(np.clip((np.trace(t[:3, :3]) - 1) / 2, -1, 1)))
    return {"translation_m": [round(v, 4) for v in t[:3, 3]], "rotation_deg": round(float(ang), 3)}


result = {"opencv": {**describe(theirs), "matches": len(matches), "with_depth": len(obj), "inliers": len(inl)}}
if ours is not None:
    diff = np.linalg.inv(theirs) @ ours
    result["mrtmap"] = describe(ours)
    result["difference"] = {"translation_m": round(float(np.linalg.norm(diff[:3, 3])), 4),
                            "rotation_deg": describe(diff)["rotation_deg"]}
else:
    result["mrtmap"] = f"tracked {len(rows)} of 2 frames"
print(json.dumps(result))
