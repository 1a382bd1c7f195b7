#!/usr/bin/env python3
"""Peer check of `mrtmap comfort`: operative temperature and PMV/PPD beside pythermalcomfort's.

    comfort_peer.py write INPUT_CSV [ROWS]   random cases (500) around ISO 7730's ranges
    comfort_peer.py check OUTPUT_CSV          pythermalcomfort on the same rows until 400 are
                                              compared; prints a summary

pythermalcomfort 4.8.1: pmv_ppd_iso(tdb, tr, vr, rh, met, clo, model="7730-2005",
round_output=False) with vr = v_relative(v, met) (the relative air speed mrtmap uses too), and
operative_tmp(tdb, tr, v, standard="ISO"). Cases where pythermalcomfort returns NaN (outside its
limits, or |PMV| > 2) are counted and left out.
"""
import csv
import json
import math
import random
import sys
import warnings

warnings.filterwarnings("ignore")


def write(path, rows=500, seed=11):
    rng = random.Random(seed)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["ta", "tr", "v", "rh", "met", "clo"])
        for _ in range(rows):
            ta = rng.uniform(16, 30)
            w.writerow([f"{ta:.2f}", f"{ta + rng.uniform(-6, 8):.2f}", f"{rng.uniform(0.0, 0.6):.2f}",
                        f"{rng.uniform(20, 80):.1f}", f"{rng.uniform(1.0, 2.0):.2f}",
                        f"{rng.uniform(0.3, 1.5):.2f}"])


def check(path):
    from pythermalcomfort.models import pmv_ppd_iso
    from pythermalcomfort.utilities import operative_tmp, v_relative

    d_pmv, d_ppd, d_to, nan, n = [], [], [], 0, 0
    for r in csv.DictReader(open(path)):
        if len(d_pmv) == 400:
            break
        ta, tr, v, rh, met, clo = (float(r[k]) for k in ("ta", "tr", "v", "rh", "met", "clo"))
        vr = float(v_relative(v, met))
        peer = pmv_ppd_iso(tdb=ta, tr=tr, vr=vr, rh=rh, met=met, clo=clo, model="7730-2005",
                           round_output=False)
        to = float(operative_tmp(ta, tr, v, standard="ISO"))
        d_to.append(abs(to - float(r["operative_c"])))
        n += 1
        if math.isnan(float(peer.pmv)) or r["pmv"] == "":
            nan += 1
            continue
        d_pmv.append(abs(float(peer.pmv) - float(r["pmv"])))
        d_ppd.append(abs(float(peer.ppd) - float(r["ppd"])))
    print(json.dumps({
        "cases": n,
        "compared": len(d_pmv),
        "outside_peer_limits": nan,
        "max_abs_diff_pmv": max(d_pmv),
        "max_abs_diff_ppd_pct": max(d_ppd),
        "max_abs_diff_operative_k": max(d_to),
        "within_1e-6 (the CSV's 6 decimals)": all(a <= 1e-6 for a in d_pmv) and all(b <= 1e-6 for b in d_ppd),
    }))


if __name__ == "__main__":
    if sys.argv[1] == "write":
        write(sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 500)
    else:
        check(sys.argv[2])
