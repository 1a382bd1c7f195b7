#!/usr/bin/env python3
"""OpenCV's calibrateCamera / stereoCalibrate on mrtmap calibrate's own detections.

    calib_peer.py stereo REPORT/calibration.json [truth.json]
    calib_peer.py mono   REPORT/calibration.json

Reads the corners mrtmap found (and the views or pairs it used), hands the same corners to
OpenCV with the same distortion model (k1 k2 p1 p2, or k1 k2 where mrtmap's held-out choice left
p1 p2 out; k3 fixed) and prints both reprojection
errors: mean per-corner distance (MRE) and RMS (what OpenCV returns). With a truth.json from
`mrtmap simulate-board`, also the focal-length and extrinsic errors of both.
"""
import json
import sys
import time

import cv2
import numpy as np

FLAGS = cv2.CALIB_FIX_K3


def model_flags(camera):
    """OpenCV's flags for the model mrtmap fitted: k3 fixed, and the tangential pair too when
    mrtmap's held-out choice left it out (p1 = p2 = 0 exactly)."""
    d = camera["distortion"]
    return FLAGS | (cv2.CALIB_ZERO_TANGENT_DIST if d["p1"] == 0.0 and d["p2"] == 0.0 else 0)


def points(corners, square):
    c = np.asarray(corners, dtype=np.float64)
    obj = np.zeros((len(c), 3), np.float32)
    obj[:, 0] = c[:, 0] * square
    obj[:, 1] = c[:, 1] * square
    return obj, c[:, 2:4].astype(np.float32).reshape(-1, 1, 2)


def errors(obj, img, K, D, rvecs, tvecs):
    d = []
    for o, i, r, t in zip(obj, img, rvecs, tvecs):
        p, _ = cv2.projectPoints(o, r, t, K, D)
        d.append(np.linalg.norm(p.reshape(-1, 2) - i.reshape(-1, 2), axis=1))
    d = np.concatenate(d)
    return d.mean(), np.sqrt((d ** 2).mean()), len(d)


def mono_cv(obj, img, size, flags=FLAGS):
    t = time.perf_counter()
    rms, K, D, rv, tv = cv2.calibrateCamera(obj, img, size, None, None, flags=flags)
    dt = time.perf_counter() - t
    mre, rms2, n = errors(obj, img, K, D, rv, tv)
    return K, D, mre, rms, n, dt


def line(name, ours_mre, ours_rms, cv_mre, cv_rms, n):
    verdict = "no worse" if ours_rms <= cv_rms * 1.0005 else "WORSE"
    return (f"  {name:<26} {n:5d} corners  MRE mrtmap {ours_mre:.4f} px  OpenCV {cv_mre:.4f} px"
            f"   RMS mrtmap {ours_rms:.4f}  OpenCV {cv_rms:.4f}  ({verdict})")


def quat_to_R(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def mono(path):
    cal = json.load(open(path))
    sq = cal["board"]["square_m"]
    cam = cal["camera"]
    views = [v for v in cal["views"] if v["error"] is not None]
    obj, img = zip(*(points(v["corners"], sq) for v in views))
    K, D, mre, rms, n, dt = mono_cv(list(obj), list(img), (cam["width"], cam["height"]), model_flags(cam))
    print(f"one camera, {len(views)} views used by mrtmap (same corners to OpenCV {cv2.__version__}):")
    print(line("intrinsics", cal["error"]["mean_px"], cal["error"]["rms_px"], mre, rms, n))
    print(f"  fx mrtmap {cam['fx']:.2f} OpenCV {K[0,0]:.2f}; fy {cam['fy']:.2f} / {K[1,1]:.2f}; "
          f"cx {cam['cx']:.2f} / {K[0,2]:.2f}; cy {cam['cy']:.2f} / {K[1,2]:.2f}; OpenCV solve {dt*1e3:.0f} ms")
    # OpenCV's own detectors on the same images, for the detection count.
    cols, rows = cal["board"]["cols"], cal["board"]["rows"]
    found_cl = found_sb = 0
    for v in cal["views"]:
        g = cv2.imread(v["path"], cv2.IMREAD_GRAYSCALE)
        if g is None:
            continue
        ok, _ = cv2.findChessboardCorners(g, (cols, rows), flags=cv2.CALIB_CB_ADAPTIVE_THRESH)
        found_cl += bool(ok)
        ok, _ = cv2.findChessboardCornersSB(g, (cols, rows), flags=cv2.CALIB_CB_EXHAUSTIVE)
        found_sb += bool(ok)
    n_found = sum(1 for v in cal["views"] if v["corners"] is not None)
    print(f"  board found: mrtmap {n_found}/{len(cal['views'])} images; OpenCV findChessboardCorners {found_cl}, "
          f"findChessboardCornersSB {found_sb} (both need the whole {cols}x{rows} grid)")


def stereo(path, truth_path=None):
    cal = json.load(open(path))
    sq = cal["board"]["square_m"]
    pairs = cal["pairs"]
    out = {}
    print(f"same detections to OpenCV {cv2.__version__} (the model mrtmap chose, k3 fixed):")
    for cam, key in (("rgb", "rgb_corners"), ("thermal", "thermal_corners")):
        alone = cal[f"{cam}_alone"]
        used = [k for k, e in enumerate(alone["view_errors"]) if e is not None]
        obj, img = zip(*(points(pairs[k][key], sq) for k in used))
        size = (cal[cam]["width"], cal[cam]["height"])
        K, D, mre, rms, n, dt = mono_cv(list(obj), list(img), size, model_flags(cal[cam]))
        out[cam] = (K, D, size)
        print(line(f"{cam} intrinsics alone", alone["error"]["mean_px"], alone["error"]["rms_px"], mre, rms, n))
    used = [p for p in pairs if p["result"]["status"] == "used"]
    objs, i1, i2 = [], [], []
    for p in used:
        r = {(int(c[0]), int(c[1])): c for c in p["rgb_corners"]}
        t = {(int(c[0]), int(c[1])): c for c in p["thermal_corners_tied"]}
        common = sorted(set(r) & set(t))
        o, a = points([r[k] for k in common], sq)
        _, b = points([t[k] for k in common], sq)
        objs.append(o); i1.append(a); i2.append(b)
    (K1, D1, s1), (K2, D2, s2) = out["rgb"], out["thermal"]
    tm = time.perf_counter()
    res = cv2.stereoCalibrate(objs, i1, i2, K1.copy(), D1.copy(), K2.copy(), D2.copy(), s1,
                              flags=model_flags(cal["rgb"]) | model_flags(cal["thermal"])
                              | cv2.CALIB_USE_INTRINSIC_GUESS,
                              criteria=(cv2.TERM_CRITERIA_COUNT + cv2.TERM_CRITERIA_EPS, 200, 1e-10))
    dt = time.perf_counter() - tm
    rms, K1, D1, K2, D2, R, T = res[:7]
    n = sum(len(o) for o in objs)
    # mrtmap's joint RMS over both cameras, as OpenCV counts it.
    er, et = cal["rgb_error"], cal["thermal_error"]
    ours_rms = np.sqrt((er["rms_px"] ** 2 * er["corners"] + et["rms_px"] ** 2 * et["corners"])
                       / (er["corners"] + et["corners"]))
    ours_mre = (er["mean_px"] * er["corners"] + et["mean_px"] * et["corners"]) / (er["corners"] + et["corners"])
    same = er["corners"] == n
    print(f"stereo, {len(used)} pairs, corners seen in both images{'' if same else ' (mrtmap used every corner: run it with --common-corners for the same input)'}:")
    print(f"  {'joint':<26} {2*n:5d} corners  MRE mrtmap {ours_mre:.4f} px"
          f"   RMS mrtmap {ours_rms:.4f}  OpenCV {rms:.4f}  ({'no worse' if ours_rms <= rms * 1.0005 else 'WORSE'}); OpenCV solve {dt*1e3:.0f} ms")
    # thermal_from_rgb of both
    q = cal["rgb_from_thermal"]["rotation_xyzw"]
    Rr = quat_to_R(q)
    tr = np.asarray(cal["rgb_from_thermal"]["translation"])
    ours_T = -Rr.T @ tr
    print(f"  thermal_from_rgb translation mm: mrtmap {np.round(ours_T*1e3, 2)}  OpenCV {np.round(T.ravel()*1e3, 2)}")
    if truth_path:
        tru = json.load(open(truth_path))
        tq = tru["rgb_from_thermal"]
        Rt = quat_to_R(tq["rotation_xyzw"])
        tt = np.asarray(tq["translation"])
        T_true = -Rt.T @ tt
        R_true = Rt.T

        def rot_err(Ra):
            c = (np.trace(Ra.T @ R_true) - 1) / 2
            return np.degrees(np.arccos(np.clip(c, -1, 1)))
        for name, fx_r, fx_t, Tv, Rv in (
            ("mrtmap", cal["rgb"]["fx"], cal["thermal"]["fx"], ours_T, Rr.T),
            ("OpenCV", K1[0, 0], K2[0, 0], T.ravel(), R),
        ):
            print(f"  against the truth, {name}: colour fx {100*(fx_r/tru['rgb']['fx']-1):+.3f} %, thermal fx "
                  f"{100*(fx_t/tru['thermal']['fx']-1):+.3f} %, translation {1e3*np.linalg.norm(Tv-T_true):.2f} mm, "
                  f"rotation {rot_err(Rv):.3f}°")


if __name__ == "__main__":
    if sys.argv[1] == "mono":
        mono(sys.argv[2])
    else:
        stereo(sys.argv[2], sys.argv[3] if len(sys.argv) > 3 else None)
