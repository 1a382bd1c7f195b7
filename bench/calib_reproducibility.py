#!/usr/bin/env python3
"""How reproducible a rig calibration of real pairs is: mrtmap and OpenCV on subsets and mild
perturbations of the same pairs.

    calib_reproducibility.py MRTMAP PAIRS_DIR COLSxROWS SQUARE_M [WORKDIR]

The sets: all pairs; the two interleaved halves (even and odd pairs by name, as the shared
`thermal-rgb-pairs` is every other pair of a larger set); all pairs saved as JPEG of quality 60;
all pairs blurred (Gaussian, sigma 2 px colour, 0.8 px thermal); all pairs with grey noise (sigma
6 of 255). On each, `mrtmap calibrate --pairs` and OpenCV as `calib_real_peer.py` runs it (classic
detector, cornerSubPix, calibrateCamera per camera, stereoCalibrate with the intrinsics fixed, k3
fixed, no view dropped). Prints one line per set and tool (focal lengths, the thermal camera's
centre in the colour frame, rotation), then one JSON line: for each tool the largest distance
between two sets' centres and the largest angle between their rotations, and per set the
distance between the tools. A pose that moves by more between halves of its own images than
between two tools cannot be compared to a few centimetres.
"""
import glob
import json
import os
import subprocess
import sys
import tempfile

import cv2
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from calib_real_peer import detect_all, opencv_rig  # noqa: E402
from rotations import quaternion_matrix, rotation_angle  # noqa: E402


def write_set(src, dst, names, change):
    for cam in ("rgb", "thermal"):
        os.makedirs(os.path.join(dst, cam), exist_ok=True)
        for n in names:
            path = os.path.join(src, cam, n)
            out = os.path.join(dst, cam, n)
            if change is None:
                os.symlink(os.path.abspath(path), out)
                continue
            img = cv2.imread(path, cv2.IMREAD_COLOR)
            cv2.imwrite(out, change(img, cam == "thermal"))


def jpeg(img, _thermal):
    _, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 60])
    return cv2.imdecode(buf, cv2.IMREAD_COLOR)


def blur(img, thermal):
    return cv2.GaussianBlur(img, (0, 0), 0.8 if thermal else 2.0)


def noise(img, _thermal, rng=np.random.default_rng(1)):
    return np.clip(img.astype(float) + rng.normal(0, 6, img.shape), 0, 255).astype(np.uint8)


def run_mrtmap(mrtmap, pairs, grid, square, report):
    subprocess.run([mrtmap, "calibrate", "--pairs", pairs, "--board", grid, "--square-m",
                    str(square), "--report", report], check=True, capture_output=True)
    c = json.load(open(os.path.join(report, "calibration.json")))
    return {
        "rgb_f": c["rgb"]["fx"], "thermal_f": c["thermal"]["fx"],
        "centre": np.array(c["rgb_from_thermal"]["translation"]),
        "R": quaternion_matrix(*c["rgb_from_thermal"]["rotation_xyzw"]),
    }


def run_opencv(pairs, grid, square):
    names, found, dims, obj = detect_all(pairs, grid, square)
    rig = opencv_rig(names, found, dims, obj, None)
    # OpenCV's R takes colour to thermal; rgb_from_thermal is its transpose.
    return {"rgb_f": rig["mono"]["rgb"][1][0, 0], "thermal_f": rig["mono"]["thermal"][1][0, 0],
            "centre": rig["centre"], "R": rig["R"].T}


def spread(results):
    keys = list(results)
    dist, ang = 0.0, 0.0
    for a in range(len(keys)):
        for b in range(a + 1, len(keys)):
            ra, rb = results[keys[a]], results[keys[b]]
            dist = max(dist, float(np.linalg.norm(ra["centre"] - rb["centre"])) * 1000)
            ang = max(ang, rotation_angle(ra["R"] @ rb["R"].T))
    return round(dist, 1), round(ang, 2)


def main(mrtmap, pairs, grid, square, work):
    names = sorted(os.path.basename(p) for p in glob.glob(os.path.join(pairs, "rgb", "*.png")))
    sets = {
        "all": (names, None),
        "even": (names[0::2], None),
        "odd": (names[1::2], None),
        "jpeg60": (names, jpeg),
        "blur": (names, blur),
        "noise": (names, noise),
    }
    out = {"mrtmap": {}, "opencv": {}}
    for name, (subset, change) in sets.items():
        d = os.path.join(work, name)
        write_set(pairs, d, subset, change)
        out["mrtmap"][name] = run_mrtmap(mrtmap, d, grid, square, os.path.join(work, name + "-report"))
        out["opencv"][name] = run_opencv(d, grid, square)
        for tool in ("mrtmap", "opencv"):
            r = out[tool][name]
            print(f"{name:7s} {len(subset):3d} pairs  {tool:6s}  colour f {r['rgb_f']:6.1f}  "
                  f"thermal f {r['thermal_f']:5.1f}  centre (mm) "
                  f"{' '.join(f'{1000 * v:7.1f}' for v in r['centre'])}  "
                  f"rotation {rotation_angle(r['R']):5.2f} deg", flush=True)
    summary = {tool: dict(zip(("centre_spread_mm", "rotation_spread_deg"), spread(out[tool])))
               for tool in out}
    for tool in out:
        halves = {k: out[tool][k] for k in ("even", "odd")}
        summary[tool]["halves"] = dict(zip(("centre_mm", "rotation_deg"), spread(halves)))
    summary["between_tools"] = {
        name: {"centre_mm": round(float(np.linalg.norm(out["mrtmap"][name]["centre"]
                                                       - out["opencv"][name]["centre"])) * 1000, 1),
               "rotation_deg": round(rotation_angle(out["mrtmap"][name]["R"]
                                                    @ out["opencv"][name]["R"].T), 2)}
        for name in sets
    }
    print(json.dumps(summary))


if __name__ == "__main__":
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    work = sys.argv[5] if len(sys.argv) > 5 else tempfile.mkdtemp(prefix="calib-repro-")
    main(sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4]), work)
