"""The built-in tracker on pose-less simulated walks (issue 54's done-when): for each preset room and
seed, simulate a walk without trajectory.txt, run `mrtmap track`, and read its accuracy against
groundtruth.txt from track.json (ATE after alignment: RMSE and the largest error of any pose).

    python3 bench/track_walks.py MRTMAP_BINARY WORK_DIR [SECONDS] [SEEDS]

Prints one line per walk and a summary per room; exits 1 when a pose lies more than 10 cm from the
truth or a walk's ATE RMSE exceeds 2 cm.
"""
import json
import os
import subprocess
import sys

binary, work = sys.argv[1], sys.argv[2]
seconds = float(sys.argv[3]) if len(sys.argv) > 3 else 30.0
seeds = range(1, int(sys.argv[4]) + 1) if len(sys.argv) > 4 else range(1, 11)
rooms = os.environ.get("MRTMAP_BENCH_TRACK_ROOMS", "office l-shaped radiant-ceiling").split()
os.makedirs(work, exist_ok=True)
worst_max, worst_rmse, failed = 0.0, 0.0, []
for room in rooms:
    rmses = []
    for seed in seeds:
        rec = os.path.join(work, f"{room}-{seconds:g}s-{seed}")
        if not os.path.exists(os.path.join(rec, "groundtruth.txt")):
            subprocess.run([binary, "simulate", "--room", room, "--seconds", str(seconds),
                            "--seed", str(seed), "--no-poses", "--out", rec],
                           check=True, capture_output=True)
        out = rec + "-track"
        r = subprocess.run([binary, "track", rec, "--out", out], capture_output=True, text=True)
        if r.returncode != 0:
            failed.append(f"{room} seed {seed}: {r.stderr.strip().splitlines()[-1]}")
            print(f"{room} seed {seed}: tracking failed: {r.stderr.strip().splitlines()[-1]}")
            continue
        t = json.load(open(os.path.join(out, "track.json")))
        a = t["accuracy"]
        rmses.append(a["ate_rmse_m"])
        worst_max, worst_rmse = max(worst_max, a["ate_max_m"]), max(worst_rmse, a["ate_rmse_m"])
        print(f"{room} seed {seed}: {t['tracked']} of {t['frames']} frames tracked, ATE RMSE "
              f"{a['ate_rmse_m'] * 1e3:.1f} mm, max {a['ate_max_m'] * 1e3:.1f} mm, "
              f"{t['outliers_dropped']} poses dropped, {t['lost']} lost", flush=True)
    if rmses:
        print(f"  {room}: ATE RMSE {min(rmses) * 1e3:.1f}–{max(rmses) * 1e3:.1f} mm over {len(rmses)} walks")
print(f"worst: ATE RMSE {worst_rmse * 1e3:.1f} mm (limit 20), a pose {worst_max * 1e3:.1f} mm from the truth "
      f"(limit 100); {len(failed)} walks failed")
sys.exit(1 if failed or worst_max > 0.10 or worst_rmse > 0.02 else 0)
