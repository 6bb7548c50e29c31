#!/usr/bin/python3
"""How right a mono start is (issue 23, README "Street scenes"): the speed the initialisation gave the
newest frame of its window against the true speed then.

Reads the log of a `dynavins run` (what `bench/seed_sweep.sh` keeps beside each run directory) and the
scene's `groundtruth.tum`, and prints one line per initialisation in the log (a run initialises again
after a reset): its time (seconds since the ground truth's first sample), the estimated speed (the log's
"newest speed", from the visual-inertial alignment, before any BA solve), the true speed at that time and
their ratio. Stereo initialisations print no speed and are skipped.

Usage: /usr/bin/python3 bench/report/init_speed.py RUN_LOG GROUNDTRUTH_TUM
(Debian's python, with numpy.)
"""

import argparse
import re

import numpy as np

SPEED = re.compile(r"mono initialisation: .*newest speed ([0-9.]+) m/s")
START = re.compile(r"estimator initialised at t=([0-9.]+) s")


def initialisations(log_text):
    """[(t [s], estimated newest speed [m/s])] of every mono initialisation of a run log, in order."""
    out, speed = [], None
    for line in log_text.splitlines():
        m = SPEED.search(line)
        if m:
            speed = float(m.group(1))
            continue
        m = START.search(line)
        if m and speed is not None:
            out.append((float(m.group(1)), speed))
            speed = None
    return out


def true_speed(groundtruth, t):
    """Speed of the TUM ground truth at time t [m/s] (positions differentiated, then interpolated)."""
    tg, pg = groundtruth[:, 0], groundtruth[:, 1:4]
    v = np.gradient(pg, tg, axis=0)
    return float(np.linalg.norm([np.interp(t, tg, v[:, k]) for k in range(3)]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log", help="the log of a dynavins run")
    ap.add_argument("groundtruth", help="the scene's groundtruth.tum")
    a = ap.parse_args()
    with open(a.log) as f:
        starts = initialisations(f.read())
    if not starts:
        raise SystemExit(f"init_speed: no mono initialisation in {a.log}")
    gt = np.loadtxt(a.groundtruth, ndmin=2)
    print("t [s]  estimated [m/s]  true [m/s]  ratio")
    for t, v in starts:
        vt = true_speed(gt, t)
        print(f"{t - gt[0, 0]:6.2f}  {v:15.2f}  {vt:10.3f}  " + (f"{v / vt:.3f}" if vt > 0 else "-"))


if __name__ == "__main__":
    main()
