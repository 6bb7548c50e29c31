#!/usr/bin/python3
"""What a run's true loops' relative-pose error follows (issue 21, README "Loop closure").

Reads `loops.csv` of a `dynavins run` on simulated input (its error_m / error_deg columns compare each
verified loop's T_m^k with the ground truth) and the scene's `groundtruth.tum`, and prints, for the
true loops: the error's median and 90th percentile, the error per bin of the ground-truth distance
between the two keyframes, and the error's correlation with that distance, with the loop's rotation
error, with the camera speed at the query keyframe and with the PnP inlier count. An error from the
3-D points' depth grows with the distance (at zero distance the bearings alone fix the pose); one
from timing grows with speed; PnP's rotation / sideways-shift ambiguity makes it follow the rotation
error.

Usage: /usr/bin/python3 bench/report/loop_error_breakdown.py RUN_DIR GROUNDTRUTH_TUM
(Debian's python, with numpy.)
"""

import csv
import sys

import numpy as np

DISTANCE_BINS_M = [0.0, 0.5, 1.0, 2.0, 4.0, float("inf")]


def load_true_loops(loops_csv):
    """(query_t_s, match_t_s, error_m, error_deg, inliers) arrays of the loops marked true."""
    rows = [r for r in csv.DictReader(open(loops_csv)) if r["true_loop"] == "1"]
    cols = ([int(r["query_t_ns"]) * 1e-9 for r in rows], [int(r["match_t_ns"]) * 1e-9 for r in rows],
            [float(r["error_m"]) for r in rows], [float(r["error_deg"]) for r in rows],
            [int(r["inliers"]) for r in rows])
    return tuple(np.array(c, dtype=float) for c in cols)


def position_and_speed(gt, t):
    """Ground-truth position [n,3] at the sample at or just after each time of t, and the speed there
    (central difference)."""
    i = np.clip(np.searchsorted(gt[:, 0], t), 1, len(gt) - 2)
    v = (gt[i + 1, 1:4] - gt[i - 1, 1:4]) / (gt[i + 1, 0] - gt[i - 1, 0])[:, None]
    return gt[i, 1:4], np.linalg.norm(v, axis=1)


def correlation(a, b):
    """Pearson correlation; nan when either side is constant (to rounding) or there are fewer than 3 loops."""
    def constant(x):
        return np.ptp(x) <= 1e-9 * max(1.0, float(np.abs(x).max()))
    if len(a) < 3 or constant(a) or constant(b):
        return float("nan")
    return float(np.corrcoef(a, b)[0, 1])


def breakdown(loops_csv, groundtruth_tum):
    """The figures printed by main(), as a dict (for tests)."""
    tq, tm, err, err_deg, inliers = load_true_loops(loops_csv)
    gt = np.loadtxt(groundtruth_tum, ndmin=2)
    out = {"true_loops": len(err)}
    if len(err) == 0:
        return out
    pq, speed = position_and_speed(gt, tq)
    pm, _ = position_and_speed(gt, tm)
    distance = np.linalg.norm(pq - pm, axis=1)
    out.update(median_m=float(np.median(err)), p90_m=float(np.percentile(err, 90)),
               median_deg=float(np.median(err_deg)),
               corr_distance=correlation(err, distance), corr_rotation=correlation(err, err_deg),
               corr_speed=correlation(err, speed), corr_inliers=correlation(err, inliers), bins=[])
    for lo, hi in zip(DISTANCE_BINS_M[:-1], DISTANCE_BINS_M[1:]):
        m = (distance >= lo) & (distance < hi)
        if m.any():
            out["bins"].append((lo, hi, int(m.sum()), float(np.median(err[m]))))
    return out


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    run_dir, gt_path = argv[1], argv[2]
    b = breakdown(run_dir.rstrip("/") + "/loops.csv", gt_path)
    print(f"{run_dir}: {b['true_loops']} true loops")
    if b["true_loops"] == 0:
        return
    print(f"  error: median {b['median_m']:.3f} m, p90 {b['p90_m']:.3f} m; rotation error median "
          f"{b['median_deg']:.3f} deg")
    for lo, hi, n, med in b["bins"]:
        print(f"  keyframes {lo:g}-{hi:g} m apart: {n} loops, median error {med:.3f} m")
    print(f"  correlation of the error with: distance {b['corr_distance']:.2f}, rotation error "
          f"{b['corr_rotation']:.2f}, speed {b['corr_speed']:.2f}, inliers {b['corr_inliers']:.2f}")


if __name__ == "__main__":
    main(sys.argv)
