#!/usr/bin/python3
"""Where a run's scale goes wrong (issue 23, README "Street scenes"): estimated path length over true
path length per time bin.

Reads a trajectory a `dynavins run` wrote (`odometry.tum` or `trajectory.tum`) and the scene's
`groundtruth.tum`, and prints, for every bin of BIN seconds (default 2) in which the camera moved at
least 0.5 m, the bin's start (seconds since the ground truth's first sample) and the ratio of the
estimate's path length to the ground truth's over the same poses. Path length does not depend on the
alignment, so the ratio reads the scale of each stretch of the run directly: 1.00 is right, 1.03 is
3 % too fast, which a mono run's SE3 ATE then pays for the rest of the run.

Usage: /usr/bin/python3 bench/report/speed_ratio.py TRAJECTORY_TUM GROUNDTRUTH_TUM [--bin SECONDS]
(Debian's python, with numpy.)
"""

import argparse

import numpy as np

from make_report import path_length  # bench/report/, beside this script

MIN_BIN_PATH_M = 0.5  # below this the ratio is mostly noise (the camera at rest)


def speed_ratios(estimate, groundtruth, bin_s=2.0):
    """[(bin start [s since the ground truth's start], estimated / true path length)] over the bins
    where the ground truth moved at least MIN_BIN_PATH_M. `estimate` and `groundtruth` are TUM arrays
    (t, x, y, z, qx, qy, qz, qw); the ground truth is interpolated at the estimate's times."""
    te, pe = estimate[:, 0], estimate[:, 1:4]
    tg, pg = groundtruth[:, 0], groundtruth[:, 1:4]
    inside = (te >= tg[0]) & (te <= tg[-1])
    te, pe = te[inside], pe[inside]
    pt = np.column_stack([np.interp(te, tg, pg[:, k]) for k in range(3)])
    out = []
    for start in np.arange(te[0], te[-1] - bin_s + 1e-9, bin_s):
        m = (te >= start) & (te < start + bin_s)
        if m.sum() < 3:
            continue
        true = path_length(pt[m])
        if true >= MIN_BIN_PATH_M:
            out.append((float(start - tg[0]), path_length(pe[m]) / true))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("trajectory", help="odometry.tum or trajectory.tum of a run")
    ap.add_argument("groundtruth", help="the scene's groundtruth.tum")
    ap.add_argument("--bin", type=float, default=2.0, help="bin length [s] (default 2)")
    a = ap.parse_args()
    ratios = speed_ratios(np.loadtxt(a.trajectory, ndmin=2), np.loadtxt(a.groundtruth, ndmin=2), a.bin)
    if not ratios:
        raise SystemExit(f"speed_ratio: no {a.bin:g} s bin of {a.trajectory} where the camera moved "
                         f"{MIN_BIN_PATH_M} m")
    print("t [s]  estimated / true path length")
    for t, r in ratios:
        print(f"{t:6.1f}  {r:.3f}")


if __name__ == "__main__":
    main()
