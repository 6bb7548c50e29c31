#!/usr/bin/python3
"""bench/report/speed_ratio.py on constructed trajectories with a known scale: an estimate 3 % too fast
from 10 s on reads 1.00 before and 1.03 after, whatever rigid transform it is expressed in; a bin where
the camera stands still is left out.
Run with Debian's python (numpy): /usr/bin/python3 tests/bench/test_speed_ratio.py"""
import os
import sys

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import speed_ratio as sr  # noqa: E402
from checks import check  # noqa: E402  (tests/bench/checks.py, beside this script)


def tum(t, p):
    return np.column_stack([t, p, np.zeros((len(t), 3)), np.ones_like(t)])


# Ground truth at 200 Hz: at rest for 3 s, then a 3 m/s drive along a curve.
tg = np.arange(0.0, 30.0, 0.005)
s = 3.0 * np.clip(tg - 3.0, 0.0, None)
gt_p = np.column_stack([20.0 * np.sin(s / 20.0), 20.0 * (1 - np.cos(s / 20.0)), np.zeros_like(s)])
gt = tum(tg + 100.0, gt_p)

# Estimate at 20 Hz, from 0.5 s on: the true path, its steps 3 % longer from 10 s on, then turned and moved.
te = np.arange(0.5, 29.9, 0.05)
p = np.column_stack([np.interp(te, tg, gt_p[:, k]) for k in range(3)])
step = np.diff(p, axis=0) * np.where(te[1:] >= 10.0, 1.03, 1.0)[:, None]
p = np.vstack([p[:1], p[0] + np.cumsum(step, axis=0)])
R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
est = tum(te + 100.0, p @ R.T + [5.0, -2.0, 1.0])

ratios = sr.speed_ratios(est, gt, 2.0)
check(ratios[0][0] == 2.5, f"the bin at rest (0.5-2.5 s) is left out, bins start at the estimate's first pose ({ratios[0][0]})")
before = [r for t, r in ratios if t + 2.0 <= 10.0]
after = [r for t, r in ratios if t >= 10.0]
check(len(before) >= 3 and all(abs(r - 1.0) < 1e-3 for r in before), f"1.00 before 10 s ({before})")
check(len(after) >= 8 and all(abs(r - 1.03) < 1e-3 for r in after), f"1.03 from 10 s on ({after})")
