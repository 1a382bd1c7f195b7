#!/usr/bin/env python3
"""OpenCV on the real thermal + colour pairs, beside mrtmap calibrate's result on the same images.

    calib_real_peer.py PAIRS_DIR MRTMAP_CALIBRATION_JSON COLSxROWS SQUARE_M

OpenCV's classic detector (findChessboardCorners with adaptive threshold and normalisation,
cornerSubPix; the small thermal images upscaled ×4 first, grey from the false colours), then
calibrateCamera for each camera and stereoCalibrate (intrinsics fixed) on the pairs found in
both, k3 fixed as mrtmap; once as is, and once dropping views whose own error is more than twice
the median (as OpenCV's tutorials advise: cornerSubPix can slide several pixels along foil
glare). Prints one JSON line: detections, focal lengths, principal points, RMS, the thermal
camera's position and rotation in the colour frame, mrtmap's for the same images, and the
differences.
"""
import glob
import json
import os
import sys

import cv2
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rotations import quaternion_matrix, rotation_angle  # noqa: E402,F401


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
    # Pixel centres: x in the upscaled image is (x + 0.5) / scale - 0.5 in the original.
    return (c + 0.5) / scale - 0.5, (grey.shape[1] // scale, grey.shape[0] // scale)


def opencv_rig(names, found, dims, obj, reject):
    """calibrateCamera per camera, then stereoCalibrate with the intrinsics fixed, k3 fixed.
    With `reject` (a factor), views whose own RMS error exceeds reject × the median are dropped
    and the camera refitted until none is (as OpenCV's tutorials advise for bad detections)."""
    flags = cv2.CALIB_FIX_K3
    mono = {}
    kept = {}
    for cam in ("rgb", "thermal"):
        keys = list(found[cam])
        while True:
            pts = [found[cam][n] for n in keys]
            r = cv2.calibrateCameraExtended([obj] * len(pts), pts, dims[cam], None, None, flags=flags)
            rms, K, D, per_view = r[0], r[1], r[2], r[7].ravel()
            if reject is None:
                break
            limit = reject * float(np.median(per_view))
            keep = [n for n, e in zip(keys, per_view) if e <= limit]
            if len(keep) == len(keys):
                break
            keys = keep
        mono[cam] = (rms, K, D)
        kept[cam] = set(keys)
    both = [n for n in names if n in kept["rgb"] and n in kept["thermal"]]
    rms, _, _, _, _, R, T, _, _ = cv2.stereoCalibrate(
        [obj] * len(both), [found["rgb"][n] for n in both], [found["thermal"][n] for n in both],
        mono["rgb"][1], mono["rgb"][2], mono["thermal"][1], mono["thermal"][2], dims["rgb"],
        flags=cv2.CALIB_FIX_INTRINSIC)
    # R, T: p_thermal = R p_rgb + T; the thermal camera's centre in the colour frame is −Rᵀ T.
    return {"mono": mono, "views": {c: len(kept[c]) for c in kept}, "pairs": len(both),
            "rms": rms, "R": R, "centre": (-R.T @ T).ravel()}


def summary(rig):
    return {
        "views": rig["views"],
        "pairs": rig["pairs"],
        "rgb_f": [round(rig["mono"]["rgb"][1][0, 0], 1), round(rig["mono"]["rgb"][1][1, 1], 1)],
        "rgb_c": [round(rig["mono"]["rgb"][1][0, 2], 1), round(rig["mono"]["rgb"][1][1, 2], 1)],
        "thermal_f": [round(rig["mono"]["thermal"][1][0, 0], 1), round(rig["mono"]["thermal"][1][1, 1], 1)],
        "thermal_c": [round(rig["mono"]["thermal"][1][0, 2], 1), round(rig["mono"]["thermal"][1][1, 2], 1)],
        "thermal_k1": round(float(rig["mono"]["thermal"][2].ravel()[0]), 3),
        "rms_px": {"rgb": round(rig["mono"]["rgb"][0], 3), "thermal": round(rig["mono"]["thermal"][0], 3),
                   "stereo": round(rig["rms"], 3)},
        "thermal_centre_mm": [round(1000 * x, 1) for x in rig["centre"]],
        "rotation_deg": round(rotation_angle(rig["R"]), 2),
    }


def detect_all(pairs, grid, square):
    """The board's points and OpenCV's corners in every pair's images: names, found (per camera,
    by name), image sizes, object points."""
    cols, rows = (int(x) for x in grid.split("x"))
    obj = np.zeros((cols * rows, 3), np.float32)
    obj[:, :2] = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2) * square
    names = sorted(os.path.basename(p) for p in glob.glob(os.path.join(pairs, "rgb", "*.png")))
    found = {"rgb": {}, "thermal": {}}
    dims = {}
    for cam in ("rgb", "thermal"):
        for n in names:
            c, d = detect(os.path.join(pairs, cam, n), (cols, rows), cam == "thermal")
            dims[cam] = d
            if c is not None:
                found[cam][n] = c
    return names, found, dims, obj


def main(pairs, calib_json, grid, square):
    names, found, dims, obj = detect_all(pairs, grid, square)
    plain = opencv_rig(names, found, dims, obj, None)
    careful = opencv_rig(names, found, dims, obj, 2.0)
    ours = json.load(open(calib_json))
    t = np.array(ours["rgb_from_thermal"]["translation"])
    x, y, z, w = ours["rgb_from_thermal"]["rotation_xyzw"]
    used = [p for p in ours["pairs"] if p.get("result", {}).get("status") == "used"]
    R_ours = quaternion_matrix(x, y, z, w)
    # The stereo RMS as OpenCV's: over every corner distance of both cameras in the used pairs.
    sq, n = 0.0, 0
    for p in used:
        for cam in ("rgb_error", "thermal_error"):
            e = p["result"][cam]
            sq += e["rms_px"] ** 2 * e["corners"]
            n += e["corners"]
    ours_found = {
        "rgb": sum(1 for p in ours["pairs"] if p.get("rgb_corners")),
        "thermal": sum(1 for p in ours["pairs"] if p.get("thermal_corners")),
    }
    out = {
        "images": len(names),
        "opencv_found": {"rgb": len(found["rgb"]), "thermal": len(found["thermal"]),
                         "both": sum(1 for n in names if n in found["rgb"] and n in found["thermal"])},
        "mrtmap_found": ours_found,
        "mrtmap": {
            "pairs": len(used),
            "rgb_f": [round(ours["rgb"]["fx"], 1), round(ours["rgb"]["fy"], 1)],
            "rgb_c": [round(ours["rgb"]["cx"], 1), round(ours["rgb"]["cy"], 1)],
            "thermal_f": [round(ours["thermal"]["fx"], 1), round(ours["thermal"]["fy"], 1)],
            "thermal_c": [round(ours["thermal"]["cx"], 1), round(ours["thermal"]["cy"], 1)],
            "thermal_k1": round(ours["thermal"]["distortion"]["k1"], 3),
            "stereo_rms_px": round((sq / max(n, 1)) ** 0.5, 3),
            "thermal_centre_mm": [round(1000 * v, 1) for v in t],
            "rotation_deg": round(rotation_angle(R_ours), 2),
        },
    }
    for name, rig in (("opencv", plain), ("opencv_view_rejection", careful)):
        s = summary(rig)
        # rgb_from_thermal (ours) · thermal_from_rgb (OpenCV's R) is the identity when they agree.
        s["vs_mrtmap"] = {
            "thermal_f_pct": [round(100 * (a / b - 1), 1) for a, b in zip(out["mrtmap"]["thermal_f"], s["thermal_f"])],
            "centre_difference_mm": round(float(np.linalg.norm(t * 1000 - rig["centre"] * 1000)), 1),
            "rotation_difference_deg": round(rotation_angle(R_ours @ rig["R"]), 2),
            "stereo_rms_ratio": round(out["mrtmap"]["stereo_rms_px"] / rig["rms"], 3),
        }
        out[name] = s
    print(json.dumps(out))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]))
