#!/usr/bin/python3
"""How an estimate behaves while the ground truth stands still (issue 22: a minute at rest).

Usage: standstill_drift.py GROUNDTRUTH.tum ODOMETRY.tum
Finds the longest stretch where the true position moves less than 1 mm/s, and reports how far the
estimate wandered inside it (0.5 s in from each end, so braking and starting are left out) and the
largest step between two consecutive estimated poses over the whole run (a jump shows there).
"""
import sys

import numpy as np


def longest_still(t, p, speed_limit=1e-3):
    v = np.r_[0.0, np.linalg.norm(np.diff(p, axis=0), axis=1) / np.diff(t)]
    still = v < speed_limit
    best, i = (t[0], t[0]), 0
    while i < len(t):
        if not still[i]:
            i += 1
            continue
        j = i
        while j < len(t) and still[j]:
            j += 1
        if t[j - 1] - t[i] > best[1] - best[0]:
            best = (t[i], t[j - 1])
        i = j
    return best


def main():
    gt, est = np.loadtxt(sys.argv[1]), np.loadtxt(sys.argv[2])
    a, b = longest_still(gt[:, 0], gt[:, 1:4])
    inside = (est[:, 0] >= a + 0.5) & (est[:, 0] <= b - 0.5)
    if b - a < 2.0 or inside.sum() < 2:
        sys.exit(f"{sys.argv[1]}: no standstill of 2 s or more")
    e = est[inside, 1:4]
    wander = np.linalg.norm(e - e[0], axis=1)
    steps = np.linalg.norm(np.diff(est[:, 1:4], axis=0), axis=1)
    k = int(steps.argmax())
    print(f"{b - a:.1f} s still from {a - gt[0, 0]:.1f} s | {wander.max() * 1000:.1f} mm | "
          f"{wander[-1] * 1000:.1f} mm | {steps[k] * 1000:.0f} mm at {est[k + 1, 0] - gt[0, 0]:.1f} s")


if __name__ == "__main__":
    main()
