#!/usr/bin/env python3
"""OpenCV on the real thermal + colour pairs, beside mrtmap calibrate's result on the same images.

    calib_real_peer.py PAIRS_DIR MRTMAP_CALIBRATION_JSON COLSxROWS SQUARE_M

OpenCV's classic detector (findChessboardCorners with adaptive threshold and normalisation,
cornerSubPix; the small thermal images upscaled ×4 first, grey from the false colours), then
calibrateCamera for each camera and stereoCalibrate (intrinsics fixed) on the pairs found in
both, k3 fixed as mrtmap. Prints one JSON line: detections, focal lengths, RMS, the thermal
camera's position and rotation in the colour frame, and mrtmap's for the same images.
"""
import glob
import json
import os
import sys

import cv2
import numpy as np


def detect(path, size, thermal):
    img = cv2.imread(path, cv2.IMREAD_COLOR)
    grey = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    scale = 4 if thermal else 1
    if scale > 1:
        grey = cv2.resize(grey, None, fx=scale, fy=scale, interpolation=cv2.INTER_CUBIC)
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
    ok, c = cv2.findChessboardCorners(grey, size, flags)
    if not ok:
        ok, c = cv2.findChessboardCorners(255 - grey, size, flags)
    if not ok:
        return None, grey.shape[::-1]
    c = cv2.cornerSubPix(grey, c, (5, 5), (-1, -1),
                         (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 50, 1e-4))
    return c / scale, (grey.shape[1] // scale, grey.shape[0] // scale)


def main(pairs, calib_json, grid, square):
    cols, rows = (int(x) for x in grid.split("x"))
    size = (cols, rows)
    obj = np.zeros((cols * rows, 3), np.float32)
    obj[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * square
    names = sorted(os.path.basename(p) for p in glob.glob(os.path.join(pairs, "rgb", "*.png")))
    found = {"rgb": {}, "thermal": {}}
    dims = {}
    for cam in ("rgb", "thermal"):
        for n in names:
            c, d = detect(os.path.join(pairs, cam, n), size, cam == "thermal")
            dims[cam] = d
            if c is not None:
                found[cam][n] = c
    flags = cv2.CALIB_FIX_K3
    mono = {}
    for cam in ("rgb", "thermal"):
        pts = list(found[cam].values())
        rms, K, D, _, _ = cv2.calibrateCamera([obj] * len(pts), pts, dims[cam], None, None, flags=flags)
        mono[cam] = (rms, K, D)
    both = [n for n in names if n in found["rgb"] and n in found["thermal"]]
    # Orientation: the classic detector may number a symmetric board either way; keep the
    # thermal numbering whose per-pair relative rotation agrees with the majority.
    rms, _, _, _, _, R, T, _, _ = cv2.stereoCalibrate(
        [obj] * len(both), [found["rgb"][n] for n in both], [found["thermal"][n] for n in both],
        mono["rgb"][1], mono["rgb"][2], mono["thermal"][1], mono["thermal"][2], dims["rgb"],
        flags=cv2.CALIB_FIX_INTRINSIC)
    # R, T: p_thermal = R p_rgb + T; the thermal camera's centre in the colour frame is −Rᵀ T.
    centre = (-R.T @ T).ravel()
    angle = float(np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1, 1))))
    ours = json.load(open(calib_json))
    t = ours["rgb_from_thermal"]["translation"]
    q = ours["rgb_from_thermal"]["rotation_xyzw"]
    our_angle = float(np.degrees(2 * np.arccos(min(1.0, abs(q[3])))))
    used = sum(1 for p in ours["pairs"] if p.get("result", {}).get("status") == "used")
    x, y, z, w = q
    R_ours = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
    # rgb_from_thermal (ours) · thermal_from_rgb (OpenCV's R) is the identity when they agree.
    d = R_ours @ R
    rotation_difference = float(np.degrees(np.arccos(np.clip((np.trace(d) - 1) / 2, -1, 1))))
    print(json.dumps({
        "images": len(names),
        "opencv_found": {"rgb": len(found["rgb"]), "thermal": len(found["thermal"]), "both": len(both)},
        "opencv_rgb_f": [round(mono["rgb"][1][0, 0], 1), round(mono["rgb"][1][1, 1], 1)],
        "opencv_thermal_f": [round(mono["thermal"][1][0, 0], 1), round(mono["thermal"][1][1, 1], 1)],
        "opencv_thermal_k1": round(float(mono["thermal"][2].ravel()[0]), 3),
        "opencv_rms_px": {"rgb": round(mono["rgb"][0], 3), "thermal": round(mono["thermal"][0], 3), "stereo": round(rms, 3)},
        "opencv_thermal_centre_mm": [round(1000 * x, 1) for x in centre],
        "opencv_rotation_deg": round(angle, 2),
        "mrtmap_pairs_used": used,
        "mrtmap_rgb_f": [round(ours["rgb"]["fx"], 1), round(ours["rgb"]["fy"], 1)],
        "mrtmap_thermal_f": [round(ours["thermal"]["fx"], 1), round(ours["thermal"]["fy"], 1)],
        "mrtmap_thermal_centre_mm": [round(1000 * x, 1) for x in t],
        "mrtmap_rotation_deg": round(our_angle, 2),
        "centre_difference_mm": round(float(np.linalg.norm(np.array(t) * 1000 - centre * 1000)), 1),
        "rotation_difference_deg": round(rotation_difference, 2),
    }))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]))
