#!/usr/bin/env python3
"""The robustness study: every preset room x seeds x noise, simulate a short walk, run the whole
pipeline, and compare the map with the truth.

    robustness.py MRTMAP WORKDIR [--rooms office,l-shaped,radiant-ceiling] [--seeds 1-10]
                  [--noise realistic,none] [--drift none] [--seconds 60]
                  [--camera-errors auto|none|realistic] [--depth-hz 30] [--glass auto|on|off]
                  [--thermal-lag-ms MS] [--thermal-time-constant-ms MS]
                  [--surfaces auto|black|grey] [--score-scene BIN] [--keep]

Prints one row per scan and a summary per room and noise; writes WORKDIR/robustness.json. Each
row also says how many nodes' errors lie within twice the standard error the run states. A scan
whose segmentation fails counts as a failure with its message. Grid errors are at the truth's
20x20 nodes (mrtmap mrt --frame scan on the run's scene); a node the run refuses (outside its
room or inside its furniture) is counted, not compared. The worst error is given over all nodes
and over the nodes at least 10 cm from the room's furniture (a node on a bookcase's face is not
a place a globe can measure). With --score-scene (the mrtmap-sim example `score_scene`) each row
also scores the features against the truth: every window found (temperature error, found area
over true area), features of over 0.2 m² matching no true feature; and from fusion.json the
thermal clock offset found against the truth's -(lag + time constant), and the frames used. Where the
recording has simulated contact readings, each row also gives their own error's effect on the level
(the simulated thermometer has sigma 0.1 K, so with two readings a walk in twenty is 0.2 K off from
the readings alone) and the grid's worst error with exact readings. With --keep the
recordings stay in WORKDIR and a later study reuses them (only the pipeline runs again). In grey
rooms (the simulator's default with realistic noise: --surfaces) each row also gives every window's
surface_temperature_c (what a contact thermometer reads) against its true temperature."""
import argparse
import json
import tomllib
import math
import os
import shutil
import subprocess
import sys
import time


def seeds(spec):
    out = []
    for part in spec.split(","):
        if "-" in part:
            a, b = part.split("-")
            out += range(int(a), int(b) + 1)
        else:
            out.append(int(part))
    return out


def mrt_at(mrtmap, scene, places):
    """(MRT, its stated standard error) at each place (None where refused), in chunks; a refused
    chunk goes point by point."""
    def call(chunk):
        args = [mrtmap, "mrt", "--scene", scene, "--frame", "scan", "--json"]
        for p in chunk:
            args.append("--at=" + ",".join(f"{v:.5f}" for v in p))
        r = subprocess.run(args, capture_output=True, text=True)
        if r.returncode != 0:
            return None
        return [(o["mrt_c"], o["std_error_k"]) for o in json.loads(r.stdout)["points"]]

    out = []
    for k in range(0, len(places), 40):
        chunk = places[k:k + 40]
        got = call(chunk)
        if got is None:
            got = [(call([p]) or [None])[0] for p in chunk]
        out += got
    return out


def near_furniture(rec, nodes, clearance=0.1):
    """Which nodes lie within `clearance` of a piece of the room's furniture (room.toml): a point
    touching a bookcase's face is not a place a globe can measure, and its MRT turns on
    millimetres."""
    try:
        room = tomllib.load(open(os.path.join(rec, "room.toml"), "rb"))
    except OSError:
        return [False] * len(nodes)
    boxes = [(f["min"], f["max"]) for f in room.get("furniture", [])]
    out = []
    for n in nodes:
        p = n["xyz_room"]
        d = min((math.sqrt(sum(max(lo[k] - p[k], 0.0, p[k] - hi[k]) ** 2 for k in range(3)))
                 for lo, hi in boxes), default=float("inf"))
        out.append(d < clearance)
    return out


def room_label(room):
    """A preset's name, or a room file's name without its folder and .toml."""
    return os.path.splitext(os.path.basename(room))[0] if room.endswith(".toml") else room


def features_and_clock(score_bin, rec, run):
    """Windows, spurious features and the thermal clock of a run, against the truth."""
    out = {}
    fusion = json.load(open(os.path.join(run, "fuse", "fusion.json")))
    truth = json.load(open(os.path.join(rec, "truth.json")))
    clock = fusion.get("clock", {})
    expected = -(truth.get("thermal_lag_s", 0.0) + truth.get("thermal_time_constant_s", 0.0))
    out["clock_error_ms"] = round(1000 * (clock.get("offset_s", 0.0) - expected), 1)
    out["clock_weak"] = clock.get("weak")
    out["frames_used"] = fusion["used_frames"]
    out["frames_listed"] = fusion["thermal_frames"]
    out["skipped"] = fusion.get("skipped", {})
    if score_bin:
        r = subprocess.run([score_bin, rec, os.path.join(run, "segment", "scene.json"), "--json"],
                           capture_output=True, text=True)
        if r.returncode == 0:
            s = json.loads(r.stdout)
            out["windows"] = [
                {"truth": f["truth_id"], "found": f["found"] is not None,
                 "dt_k": f["temperature_error_k"],
                 "area_ratio": (f["area_m2"] / f["truth_area_m2"]) if f["area_m2"] else None}
                for f in s["features"] if "window" in f["truth_label"]]
            out["spurious_over_0_2"] = [
                (i, round(a, 2)) for i, a in zip(s["spurious_features"], s.get("spurious_areas_m2", []))
                if a > 0.2]
    return out


def window_surface_errors(rec, run):
    """Each true window's surface_temperature_c in the run's scene (the window feature nearest to
    it) minus its true temperature (K); empty in black rooms."""
    truth = json.load(open(os.path.join(rec, "truth.json")))
    scene = json.load(open(os.path.join(run, "segment", "scene.json")))
    pose = scene.get("world_from_room")
    if not pose:
        return []
    x, y, z, w = pose["rotation_xyzw"]
    rot = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
           [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
           [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    to_world = lambda p: [sum(rot[i][j] * p[j] for j in range(3)) + pose["translation"][i]
                          for i in range(3)]
    centre = lambda poly: [sum(p[i] for p in poly) / len(poly) for i in range(3)]
    found = [(to_world(centre(f["polygon"])), f.get("surface_temperature_c"))
             for s in scene["surfaces"] for f in s.get("features", []) if "window" in f["label"]]
    out = []
    for s in truth["scene"]["surfaces"]:
        for f in s.get("features", []):
            if "window" not in f["label"] or f.get("surface_temperature_c") is None:
                continue
            c = centre(f["polygon"])
            near = min(found, key=lambda g: sum((a - b) ** 2 for a, b in zip(g[0], c)), default=None)
            if near is None or near[1] is None or math.dist(near[0], c) > 0.5:
                out.append(None)
            else:
                out.append(round(near[1] - f["surface_temperature_c"], 3))
    return out


def reference_level(rec):
    """What the simulated contact thermometer's own reading errors do to the level: the level
    fit's change at temperature T (K) when the readings are replaced by the truth
    (radiometric_truth.json's references), as a function of T (the pipeline's fit, weighted least
    squares camera = a + b*true, is linear in the readings: two readings on temperatures 2 K or
    more apart fix offset and gain, one (or close ones) the offset alone). None without them."""
    try:
        refs = json.load(open(os.path.join(rec, "radiometric_truth.json"))).get("references") or []
    except OSError:
        return None
    if not refs:
        return None
    xs = [r["true_c"] for r in refs]
    es = [r["temperature_c"] - r["true_c"] for r in refs]
    mx, me = sum(xs) / len(xs), sum(es) / len(es)
    sxx = sum((x - mx) ** 2 for x in xs)
    if len(refs) >= 2 and max(xs) - min(xs) >= 2.0:
        slope = sum((x - mx) * (e - me) for x, e in zip(xs, es)) / sxx
        return lambda t: me + slope * (t - mx)
    return lambda t: me


def one(mrtmap, work, room, seed, noise, drift, secs, keep, camera, reuse_fusion=False,
        depth_hz=None, glass="auto", score_bin=None, lag_ms=None, tau_ms=None, surfaces="auto"):
    name = f"{room_label(room)}-s{seed}-{noise}-{drift}-cam{camera}"
    if surfaces != "auto":
        name += f"-{surfaces}"
    if depth_hz:
        name += f"-d{depth_hz}"
    if glass != "auto":
        name += f"-glass{glass}"
    if lag_ms is not None:
        name += f"-lag{lag_ms:g}"
    if tau_ms is not None:
        name += f"-tau{tau_ms:g}"
    rec, run = os.path.join(work, name), os.path.join(work, name + ".run")
    row = {"room": room_label(room), "seed": seed, "noise": noise, "drift": drift,
           "camera_errors": camera}
    t0 = time.time()
    if not os.path.exists(os.path.join(rec, "truth.json")):
        shutil.rmtree(rec + ".partial", ignore_errors=True)
        extra = (["--depth-hz", str(depth_hz)] if depth_hz else []) + ["--glass", glass]
        extra += ["--thermal-lag-ms", str(lag_ms)] if lag_ms is not None else []
        extra += ["--thermal-time-constant-ms", str(tau_ms)] if tau_ms is not None else []
        extra += ["--surfaces", surfaces] if surfaces != "auto" else []
        subprocess.run([mrtmap, "simulate", "--room", room, "--seed", str(seed), "--noise", noise,
                        "--drift", drift, "--camera-errors", camera, "--seconds", str(secs),
                        "--out", rec] + extra,
                       check=True, capture_output=True)
    t1 = time.time()
    if reuse_fusion and os.path.exists(os.path.join(run, "fuse", "cloud.ply")):
        for entry in os.listdir(run):
            if entry != "fuse":
                path = os.path.join(run, entry)
                shutil.rmtree(path) if os.path.isdir(path) else os.remove(path)
    else:
        shutil.rmtree(run, ignore_errors=True)
    r = subprocess.run([mrtmap, "run", rec, "--out", run], capture_output=True, text=True)
    t2 = time.time()
    row["simulate_s"], row["run_s"] = round(t1 - t0, 1), round(t2 - t1, 1)
    if r.returncode != 0:
        row["error"] = (r.stderr.strip().splitlines() or ["?"])[-1]
    else:
        truth = json.load(open(os.path.join(rec, "truth.json")))
        nodes = [n for n in truth["grid"]["nodes"] if n["mrt_c"] is not None]
        got = mrt_at(mrtmap, os.path.join(run, "segment", "scene.json"),
                     [n["xyz_world"] for n in nodes] + [p["xyz_world"] for p in truth["points"]])
        g = [(v[0] - n["mrt_c"]) for v, n in zip(got, nodes) if v is not None]
        covered = [abs(v[0] - n["mrt_c"]) <= 2.0 * v[1] for v, n in zip(got, nodes) if v is not None]
        clear = [(v[0] - n["mrt_c"]) for v, n, near in zip(got, nodes, near_furniture(rec, nodes))
                 if v is not None and not near]
        pts = {p["name"]: (None if v is None else round(v[0] - p["mrt_c"], 3))
               for p, v in zip(truth["points"], got[len(nodes):])}
        level = reference_level(rec)
        if level is not None:
            # The grid's error with the readings' own errors taken out: what the pipeline would
            # have given from exact contact readings (to first order: the MRT of a node moves
            # with the level at the node's temperature).
            exact = [(v[0] - n["mrt_c"]) - level(n["mrt_c"]) for v, n in zip(got, nodes)
                     if v is not None]
            row["references_level_k"] = round(level(sum(n["mrt_c"] for n in nodes) / len(nodes)), 3)
            row["exact_refs_max_abs_k"] = max(abs(x) for x in exact) if exact else None
        row.update({
            "nodes": len(g), "refused": len(nodes) - len(g),
            "max_abs_k": max(abs(x) for x in g) if g else None,
            "rmse_k": math.sqrt(sum(x * x for x in g) / len(g)) if g else None,
            "within_2se": sum(covered) / len(covered) if covered else None,
            "clear_nodes": len(clear),
            "clear_max_abs_k": max(abs(x) for x in clear) if clear else None,
            "clear_rmse_k": math.sqrt(sum(x * x for x in clear) / len(clear)) if clear else None,
            "points_k": pts,
        })
        row.update(features_and_clock(score_bin, rec, run))
        row["window_surface_dt_k"] = window_surface_errors(rec, run)
    if not keep:
        shutil.rmtree(rec, ignore_errors=True)
        shutil.rmtree(run, ignore_errors=True)
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mrtmap")
    ap.add_argument("work")
    ap.add_argument("--rooms", default="office,l-shaped,radiant-ceiling",
                    help="preset names or room files (.toml, docs/simulator.md's format)")
    ap.add_argument("--seeds", default="1-10")
    ap.add_argument("--noise", default="realistic,none")
    ap.add_argument("--drift", default="none")
    ap.add_argument("--seconds", default="60")
    ap.add_argument("--camera-errors", default="auto",
                    help="the simulator's radiometric camera errors: auto (realistic with realistic "
                         "noise, corrected from two reference readings), none, realistic")
    ap.add_argument("--depth-hz", type=float, default=None,
                    help="the simulated depth camera's frame rate (default: the simulator's 30 Hz)")
    ap.add_argument("--glass", default="auto", help="the simulator's glass: auto, on, off")
    ap.add_argument("--thermal-lag-ms", type=float, default=None,
                    help="the thermal stamps' lag (default: the simulator's, drawn with realistic noise)")
    ap.add_argument("--thermal-time-constant-ms", type=float, default=None,
                    help="the bolometer's time constant (default: the simulator's)")
    ap.add_argument("--score-scene", default=None,
                    help="the mrtmap-sim example score_scene, to score features against the truth")
    ap.add_argument("--keep", action="store_true")
    ap.add_argument("--surfaces", default="auto", help="the simulator's surfaces: auto, black, grey")
    ap.add_argument("--reuse-fusion", action="store_true",
                    help="with --keep: keep the fusion of an earlier study (segmentation work)")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    rows = []
    for noise in a.noise.split(","):
        for drift in a.drift.split(","):
            for room in a.rooms.split(","):
                for seed in seeds(a.seeds):
                    row = one(a.mrtmap, a.work, room, seed, noise, drift, a.seconds, a.keep,
                              a.camera_errors, a.reuse_fusion, a.depth_hz, a.glass,
                              a.score_scene, a.thermal_lag_ms, a.thermal_time_constant_ms,
                              a.surfaces)
                    rows.append(row)
                    if "error" in row:
                        desc = "FAILED: " + row["error"]
                    else:
                        desc = (f"grid max |Δ| {row['max_abs_k']:.3f} K, RMSE {row['rmse_k']:.3f} K "
                                f"(10 cm clear of furniture: {row['clear_max_abs_k']:.3f}, "
                                f"{row['clear_rmse_k']:.3f} K), "
                                f"{row['refused']} nodes refused, "
                                f"{100 * row['within_2se']:.0f} % within 2σ; " +
                                (f"readings' own error {row['references_level_k']:+.3f} K, "
                                 f"grid max with exact readings {row['exact_refs_max_abs_k']:.3f} K; "
                                 if row.get("exact_refs_max_abs_k") is not None else "") +
                                " ".join(f"{k} {v:+.3f}" if v is not None else f"{k} —"
                                         for k, v in row["points_k"].items()) +
                                f"; clock {row['clock_error_ms']:+.1f} ms"
                                f"{' (weak)' if row['clock_weak'] else ''}, frames "
                                f"{row['frames_used']}/{row['frames_listed']}" +
                                "".join(f"; {w['truth']} " + (
                                    f"ΔT {w['dt_k']:+.2f} K, area x{w['area_ratio']:.2f}"
                                    if w["found"] else "MISSED") for w in row.get("windows", [])) +
                                (f"; spurious {row['spurious_over_0_2']}"
                                 if row.get("spurious_over_0_2") else "") +
                                "".join(f"; window surface T {d:+.2f} K" if d is not None
                                        else "; window surface T —"
                                        for d in row.get("window_surface_dt_k", [])))
                    print(f"{room:<16} seed {seed:>3} {noise:<9} {drift:<8} run {row['run_s']:5.1f} s  {desc}",
                          flush=True)
    print("\nsummary (room, noise, drift: scans, failures, worst grid max |Δ| and RMSE (over nodes 10 cm "
          "clear of furniture), median run time):")
    groups = {}
    for r in rows:
        groups.setdefault((r["room"], r["noise"], r["drift"]), []).append(r)
    for (room, noise, drift), rs in groups.items():
        ok = [r for r in rs if "error" not in r]
        worst = max((r["max_abs_k"] for r in ok), default=float("nan"))
        clear = max((r["clear_max_abs_k"] for r in ok), default=float("nan"))
        clear_rmse = max((r["clear_rmse_k"] for r in ok), default=float("nan"))
        rmse = max((r["rmse_k"] for r in ok), default=float("nan"))
        times = sorted(r["run_s"] for r in rs)
        cover = min((r["within_2se"] for r in ok), default=float("nan"))
        exact = [r["exact_refs_max_abs_k"] for r in ok if r.get("exact_refs_max_abs_k") is not None]
        win = [abs(d) for r in ok for d in r.get("window_surface_dt_k", []) if d is not None]
        print(f"  {room:<16} {noise:<9} {drift:<8} {len(rs):>3} scans, {len(rs) - len(ok)} failed, "
              f"max |Δ| {worst:.3f} K, RMSE {rmse:.3f} K (clear of furniture: {clear:.3f}, "
              f"{clear_rmse:.3f} K), at least {100 * cover:.0f} % of nodes within 2σ, "
              f"run {times[len(times) // 2]:.1f} s" +
              (f"; with exact contact readings max |Δ| {max(exact):.3f} K" if exact else "") +
              (f"; windows' surface T worst |Δ| {max(win):.2f} K" if win else ""))
    json.dump(rows, open(os.path.join(a.work, "robustness.json"), "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
