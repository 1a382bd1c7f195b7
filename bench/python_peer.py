#!/usr/bin/env python3
"""The Python package beside pythermalcomfort and beside the command line (issue 39).

    python_peer.py MRTMAP_BIN

1. PMV/PPD on 777×444 inputs (pythermalcomfort #227's size), three sets: random inputs over ISO
   7730's ranges, inputs all valid (no NaN out), and docs/python.md's broadcast grid (a column of
   air temperatures against a row of radiant ones): mrtmap.pmv_ppd_iso beside
   pythermalcomfort.models.pmv_ppd_iso, same arrays, round_output=False; medians of 5 alternated
   runs after one warm-up each (numba compiles on its first call); the largest difference.
   `python_peer.py --pmv-only` runs this part alone.
2. MRT on a 100×100 grid at 1.1 m of the example office: `scene.map(grid=(100, 100))` from Python
   beside `mrtmap map --grid 100x100` (wall time of the process, which also draws the PNG and SVG)
   and beside the map's own compute time the CLI reports; and `scene.mrt` at the same 10,000
   points. Exact view factors (medians of 15; about 40 ms each, so noisy) and Monte Carlo with
   4,000 rays per node (medians of 5; seconds each). Python's and the CLI's runs alternate.
Prints one JSON object.
"""
import json
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

warnings.filterwarnings("ignore")


def median_time(f, runs=5):
    times = []
    out = None
    for _ in range(runs):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def pmv_inputs():
    """The three input sets (issue 54), each 777×444 (pythermalcomfort #227's size)."""
    rng = np.random.default_rng(1)
    shape = (777, 444)
    iso = dict(tdb=rng.uniform(10, 30, shape), tr=rng.uniform(10, 40, shape),
               vr=rng.uniform(0, 1, shape), rh=rng.uniform(5, 95, shape),
               met=rng.uniform(0.8, 4, shape), clo=rng.uniform(0, 2, shape))
    # Every element within ISO 7730's ranges, the PMV too: no NaN comes out.
    valid = dict(tdb=rng.uniform(22, 25, shape), tr=rng.uniform(22, 26, shape),
                 vr=rng.uniform(0, 0.2, shape), rh=rng.uniform(30, 60, shape),
                 met=rng.uniform(1.1, 1.3, shape), clo=rng.uniform(0.5, 0.8, shape))
    # docs/python.md's example: a column of air temperatures against a row of radiant ones.
    grid = dict(tdb=np.linspace(18, 28, 777)[:, None], tr=np.linspace(15, 35, 444)[None, :],
                vr=0.1, rh=50, met=1.2, clo=0.7)
    return {"random_iso_ranges": iso, "all_valid": valid, "docs_broadcast_grid": grid}


def comfort(runs=5):
    """PMV/PPD beside pythermalcomfort on each input set: the two tools' calls alternated in one
    process (so that the machine's slow and fast moments fall on both alike), medians of `runs`
    after one warm-up each (numba compiles on its first call)."""
    import mrtmap
    from pythermalcomfort.models import pmv_ppd_iso

    out = {}
    for name, args in pmv_inputs().items():
        pmv_ppd_iso(**args, round_output=False)
        mrtmap.pmv_ppd_iso(**args, round_output=False)
        tp, to = [], []
        for _ in range(runs):
            t0 = time.perf_counter()
            peer = pmv_ppd_iso(**args, round_output=False)
            t1 = time.perf_counter()
            ours = mrtmap.pmv_ppd_iso(**args, round_output=False)
            tp.append(t1 - t0)
            to.append(time.perf_counter() - t1)
        t_peer, t_ours = statistics.median(tp), statistics.median(to)
        same_nan = bool((np.isnan(ours.pmv) == np.isnan(peer.pmv)).all())
        d = float(np.nanmax(np.abs(ours.pmv - peer.pmv)))
        dp = float(np.nanmax(np.abs(ours.ppd - peer.ppd)))
        out[name] = {
            "cells": int(np.size(ours.pmv)),
            "nan_cells": int(np.isnan(ours.pmv).sum()),
            "pythermalcomfort_s": round(t_peer, 4),
            "mrtmap_s": round(t_ours, 4),
            "speedup": round(t_peer / t_ours, 1),
            "max_abs_diff_pmv": d,
            "max_abs_diff_ppd": dp,
            "nan_alike": same_nan,
            "within_1e-6": bool(d <= 1e-6 and dp <= 1e-6 and same_nan),
        }
    return out


def grid(bin_path, runs, **mrt):
    import mrtmap

    scene = mrtmap.Scene.example()
    flags = [a for k, v in mrt.items() for a in (f"--{k}", str(v))]
    # Python's map and the CLI's alternated, so that the machine's slow and fast moments fall on
    # both alike; the CLI's own compute time (summary.json) beside its process's wall time.
    py, py_computes, walls, computes = [], [], [], []
    with tempfile.TemporaryDirectory() as d:
        for _ in range(runs):
            t0 = time.perf_counter()
            m = scene.map(height=1.1, grid=(100, 100), **mrt)
            t1 = time.perf_counter()
            subprocess.run([bin_path, "map", "--grid", "100x100", "--out", d, *flags], check=True,
                           capture_output=True)
            walls.append(time.perf_counter() - t1)
            py.append(t1 - t0)
            py_computes.append(m.compute_secs)
            summary = json.load(open(f"{d}/summary.json"))
            computes.append(summary["compute_secs"])
    t_py, py_compute, t_cli, cli_compute = (
        statistics.median(x) for x in (py, py_computes, walls, computes))
    ok = np.isfinite(m.mrt_c)
    pts = m.xyz[ok]
    t_pts, r = median_time(lambda: scene.mrt(pts, **mrt), runs)
    return {
        "settings": mrt or "exact (the example's auto)",
        "nodes": int(ok.sum()),
        "python_map_s": round(t_py, 4),
        "python_map_compute_s": round(py_compute, 4),
        "python_points_s": round(t_pts, 4),
        "cli_map_wall_s": round(t_cli, 4),
        "cli_map_compute_s": round(cli_compute, 4),
        "python_map_over_cli_wall": round(t_py / t_cli, 3),
        "python_map_over_cli_compute": round(t_py / cli_compute, 3),
        "computes_ratio": round(py_compute / cli_compute, 3),
        "same_mean_c": abs(float(np.nanmean(m.mrt_c)) - summary["mean_c"]) < 1e-9,
        "points_equal_map": bool(np.allclose(r.mrt_c, m.mrt_c[ok], atol=1e-9, rtol=0))
        if not mrt else "streams differ (point k vs node j·nx+i)",
    }


if __name__ == "__main__":
    if sys.argv[1:] == ["--pmv-only"]:
        print(json.dumps({"pmv_ppd_777x444": comfort()}, indent=1))
        sys.exit(0)
    print(json.dumps({
        "pmv_ppd_777x444": comfort(),
        "mrt_100x100_exact": grid(sys.argv[1], 15),
        "mrt_100x100_montecarlo": grid(sys.argv[1], 5, method="montecarlo", rays=4000),
    }, indent=1))
