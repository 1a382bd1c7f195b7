#!/usr/bin/env python3
"""Peer check of `mrtmap validate`: the globe → MRT conversions beside pythermalcomfort's.

    globe_peer.py write GRID_CSV GLOBE_CSV   random globe readings at grid nodes of a map
    globe_peer.py check VALIDATION_JSON       pythermalcomfort on the same rows; prints JSON

The rows span what a field kit sees: globe 15–35 °C, air within ±6 K of it, air speed 0.05–1 m/s,
globes of 38 mm (ping-pong), 50 mm and 150 mm, emissivity 0.93–0.97.
"""
import csv
import json
import random
import sys
import warnings

warnings.filterwarnings("ignore")


def write(grid_csv, globe_csv, rows=400, seed=7):
    rng = random.Random(seed)
    nodes = list(csv.DictReader(open(grid_csv)))
    with open(globe_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["label", "x", "y", "z", "tg_c", "ta_c", "va_m_s", "diameter_m", "emissivity"])
        for k in range(rows):
            n = rng.choice(nodes)
            tg = rng.uniform(15, 35)
            w.writerow([f"G{k}", n["x"], n["y"], n["z"], f"{tg:.2f}", f"{tg + rng.uniform(-6, 6):.2f}",
                        f"{rng.uniform(0.05, 1.0):.2f}", rng.choice(["0.038", "0.05", "0.15"]),
                        f"{rng.uniform(0.93, 0.97):.3f}"])


def check(validation_json):
    import numpy as np
    from pythermalcomfort.environment import mean_radiant_tmp

    rows = json.load(open(validation_json))
    g = lambda k: np.array([r["globe"][k] for r in rows], dtype=float)
    ours = lambda k: np.array([np.nan if r[k] is None else r[k] for r in rows], dtype=float)
    args = (g("tg_c"), g("ta_c"), g("va_m_s"), g("diameter_m"), g("emissivity"))
    iso = mean_radiant_tmp(*args, standard="ISO")
    mixed = mean_radiant_tmp(*args, standard="Mixed Convection")
    d_iso = np.abs(iso - ours("mrt_iso_c"))
    # pythermalcomfort leaves the mixed-convection model undefined (NaN) outside 40–150 mm globes;
    # mrtmap leaves it null there, with a note.
    ok, ours_ok = ~np.isnan(mixed), ~np.isnan(ours("mrt_mixed_c"))
    d_mixed = np.abs(mixed[ok] - ours("mrt_mixed_c")[ok])
    print(json.dumps({"rows": len(rows), "mixed_rows": int(ok.sum()),
                      "mixed_defined_alike": bool((ok == ours_ok).all()),
                      "iso_max_abs_diff_k": float(d_iso.max()),
                      "mixed_max_abs_diff_k": float(d_mixed.max()) if ok.any() else None}))


if __name__ == "__main__":
    if sys.argv[1] == "write":
        write(sys.argv[2], sys.argv[3])
    else:
        check(sys.argv[2])
