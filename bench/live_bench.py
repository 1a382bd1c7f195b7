"""`bench/run live`: `mrtmap live` following scans replayed at their own pace (`mrtmap replay`).

For a 20 s office scan at 15 and at 30 Hz depth: the median and largest time from a thermal file
written to its frame fused (the state's own measure: fused time minus the file's modification
time), how far fusion fell behind the newest frame listed (scan seconds), the longest gap between
two refreshes of the room model, and the final run against `mrtmap run` on the finished recording
(largest difference over the grid). Then a long scan (343 s by default) replayed at its own pace:
the process's resident memory sampled every second.

usage: python3 bench/live_bench.py MRTMAP_BINARY WORKDIR [LONG_SCAN_SECONDS]
"""
import csv
import json
import os
import statistics
import subprocess
import sys
import time
import urllib.request

BIN, WORK = sys.argv[1], sys.argv[2]
LONG_S = float(sys.argv[3]) if len(sys.argv) > 3 else 343.0


def sh(*args):
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def grid(run):
    with open(os.path.join(run, "map-1.10m", "mrt_grid.csv")) as f:
        return [float(r["mrt_c"]) if r["mrt_c"] else float("nan") for r in csv.DictReader(f)]


def follow(source, name):
    """Replays `source` and follows it live; returns the states seen and the run folders."""
    rec, out = os.path.join(WORK, name + "-rec"), os.path.join(WORK, name + "-out")
    for d in (rec, out):
        subprocess.run(["rm", "-rf", d], check=True)
    replay = subprocess.Popen([BIN, "replay", source, "--into", rec], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    while not os.path.exists(os.path.join(rec, "rig.toml")):
        time.sleep(0.02)
    live = subprocess.Popen([BIN, "live", rec, "--serve", "127.0.0.1:0", "--out", out, "--exit-when-idle", "3"],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    first = live.stderr.readline()
    addr = first.split("http://")[1].split()[0]
    states = []
    while live.poll() is None:
        t = time.time()
        try:
            s = json.load(urllib.request.urlopen(f"http://{addr}/state.json", timeout=5))
            if s.get("phase") == "following":
                states.append(s)
        except OSError:
            pass
        time.sleep(max(0.0, 1.0 - (time.time() - t)))
    live.stderr.read()
    replay.wait()
    assert live.returncode == 0, f"mrtmap live exited {live.returncode}"
    return states, rec, out


def short_scans():
    for hz in (15, 30):
        src = os.path.join(WORK, f"office20-{hz}hz")
        if not os.path.exists(os.path.join(src, "truth.json")):
            sh(BIN, "simulate", "--room", "office", "--seconds", "20", "--depth-hz", str(hz), "--out", src)
        states, rec, out = follow(src, f"live{hz}")
        last = states[-1]
        ref = os.path.join(WORK, f"live{hz}-ref")
        subprocess.run(["rm", "-rf", ref], check=True)
        sh(BIN, "run", rec, "--out", ref)
        diff = max(abs(a - b) for a, b in zip(grid(out), grid(ref)) if a == a and b == b)
        behind = max(s["behind_s"] for s in states)
        print(f"  20 s office scan, depth {hz} Hz: {last['frames_fused']} of {last['frames_received']} thermal frames fused; "
              f"written → fused median {last['latency_median_s']:.3f} s, largest {last['latency_max_s']:.3f} s; "
              f"fusion at most {behind:.2f} s of scan behind; {len(states)} states in {states[-1]['elapsed_s']:.0f} s; "
              f"room model refreshed {last['refreshes']} times, {last['refresh_took_s']:.2f} s the last, "
              f"longest gap {last['refresh_gap_max_s'] or 0:.2f} s; final run vs mrtmap run: largest difference {diff:.4f} K")


def long_scan():
    src = os.environ.get("MRTMAP_BENCH_SCAN", "target/bench/office343-exact-camera")
    if LONG_S != 343.0 or not os.path.exists(os.path.join(src, "truth.json")):
        src = os.path.join(WORK, f"office{LONG_S:.0f}")
        if not os.path.exists(os.path.join(src, "truth.json")):
            sh(BIN, "simulate", "--room", "office", "--seconds", str(LONG_S), "--out", src)
    states, _, _ = follow(src, "long")
    rss = [(s["elapsed_s"], s["rss_mb"]) for s in states if s.get("rss_mb")]
    n = len(rss)
    quarter = [rss[min(n - 1, k * n // 4)] for k in range(1, 4)] + [rss[-1]]
    lat = [s["latency_median_s"] for s in states if s.get("latency_median_s") is not None]
    gaps = max((s["refresh_gap_max_s"] or 0) for s in states)
    last = states[-1]
    print(f"  {LONG_S:.0f} s office scan replayed at its own pace: {last['frames_fused']} of {last['frames_received']} thermal frames fused, "
          f"{last['refreshes']} refreshes (last {last['refresh_took_s']:.2f} s, longest gap {gaps:.2f} s)")
    print("  resident memory (MB) at " + ", ".join(f"{t:.0f} s: {m:.0f}" for t, m in quarter)
          + f"; median of the per-second medians of written → fused {statistics.median(lat):.3f} s, largest median {max(lat):.3f} s")


os.makedirs(WORK, exist_ok=True)
short_scans()
if LONG_S > 0:
    long_scan()
