#!/usr/bin/env python3
"""`mrtmap coverage` against the full run, on the walks a robustness study kept.

    coverage_study.py MRTMAP STUDY_DIR [STUDY_DIR ...] [--repeat 3] [--target-k 0.2]

For every walk of each study (a folder written by robustness.py --keep, with its robustness.json)
this runs `mrtmap coverage` on the recording (`--repeat` times; the median time is reported) and
compares its verdict with the full run's grid max |Δ| against the truth: "good enough" should be
said exactly when the full run is within the target. A walk whose full run missed the target only
through the simulated contact readings' own error (the grid max with exact readings is within it)
is counted apart: no scan check can see a thermometer's error. Borderline walks (the full run
within 0.05 K of the target) are counted and listed.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("mrtmap")
    ap.add_argument("studies", nargs="+")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--target-k", type=float, default=0.2)
    a = ap.parse_args()
    rows = []
    for study in a.studies:
        runs = json.load(open(os.path.join(study, "robustness.json")))
        for r in runs:
            name = f"{r['room']}-s{r['seed']}-{r['noise']}-{r['drift']}-cam{r['camera_errors']}"
            recs = [d for d in os.listdir(study)
                    if d.startswith(name) and not d.endswith(".run")
                    and os.path.isdir(os.path.join(study, d))]
            if not recs:
                continue
            rec = os.path.join(study, recs[0])
            times, verdict = [], None
            for _ in range(a.repeat):
                t0 = time.time()
                p = subprocess.run([a.mrtmap, "coverage", rec, "--json",
                                    "--target-k", str(a.target_k)],
                                   capture_output=True, text=True)
                times.append(time.time() - t0)
                if p.returncode != 0:
                    verdict = {"error": p.stderr.strip().splitlines()[-1:]}
                    break
                verdict = json.loads(p.stdout)
            full = r.get("max_abs_k")
            exact = r.get("exact_refs_max_abs_k")
            rows.append({
                "study": study, "walk": name, "seconds": statistics.median(times),
                "good": None if "error" in verdict else verdict["good_enough"],
                "reasons": verdict.get("reasons", verdict.get("error")),
                "full_max_k": full, "exact_refs_max_k": exact,
            })
            row = rows[-1]
            full_s = "failed" if full is None else f"{full:.3f} K"
            print(f"{name:<45} coverage {row['seconds']:5.1f} s  "
                  f"{'good' if row['good'] else 'not good'}  full run {full_s}"
                  + ("" if row["good"] else f"  ({'; '.join(row['reasons'] or [])[:160]})"),
                  flush=True)
    agree = reading = border = 0
    disagree = []
    for row in rows:
        full = row["full_max_k"]
        ok_full = full is not None and full <= a.target_k
        if row["good"] == ok_full:
            agree += 1
        elif (row["good"] and row["exact_refs_max_k"] is not None
              and row["exact_refs_max_k"] <= a.target_k):
            reading += 1
        elif full is not None and abs(full - a.target_k) < 0.05:
            border += 1
            disagree.append(row)
        else:
            disagree.append(row)
    times = [r["seconds"] for r in rows]
    print()
    print(f"{len(rows)} walks: verdict agrees with the full run on {agree}; "
          f"{reading} missed the target only through the contact readings' own error; "
          f"{border} borderline (within 0.05 K of the target); "
          f"{len(disagree) - border} disagree")
    for row in disagree:
        print(f"  {row['walk']}: coverage {'good' if row['good'] else 'not good'}, "
              f"full run {row['full_max_k']}")
    if times:
        print(f"coverage time: median {statistics.median(times):.1f} s, max {max(times):.1f} s")
    json.dump(rows, open(os.path.join(a.studies[0], "coverage.json"), "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
