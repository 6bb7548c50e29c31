#!/usr/bin/python3
"""bench/report/init_speed.py on a constructed log and ground truth: every mono initialisation of the log
is found with its speed (a stereo one, which prints none, is skipped), and the true speed is read at its
time from a ground truth accelerating at a known rate.
Run with Debian's python (numpy): /usr/bin/python3 tests/bench/test_init_speed.py"""
import os
import sys

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import init_speed as isp  # noqa: E402
from checks import check  # noqa: E402  (tests/bench/checks.py, beside this script)

LOG = """[2026-12-05 22:00:00.000] [dynavins] [info] not initialised yet at t=100.500 s: not enough parallax
[2026-12-05 22:00:00.100] [dynavins] [info] mono initialisation: SfM reference frame 0 (0.51 px RMS), scale 0.396 (relative std 0.182), bg (0.0040, -0.0120, 0.0082), newest speed 0.75 m/s
[2026-12-05 22:00:00.110] [dynavins] [info] estimator initialised at t=102.000 s (mono mode, dynavins BA)
[2026-12-05 22:00:01.000] [dynavins] [warning] estimator reset at t=110.000 s: fewer than 2 features tracked
[2026-12-05 22:00:01.500] [dynavins] [info] estimator initialised at t=111.000 s (stereo mode, dynavins BA)
[2026-12-05 22:00:02.100] [dynavins] [info] mono initialisation: SfM reference frame 3 (0.40 px RMS), scale 1.2 (relative std 0.2), bg (0, 0, 0), newest speed 3.30 m/s
[2026-12-05 22:00:02.110] [dynavins] [info] estimator initialised at t=120.000 s (mono mode, dynavins BA)
"""

starts = isp.initialisations(LOG)
check(starts == [(102.0, 0.75), (120.0, 3.30)], f"the two mono initialisations, the stereo one skipped ({starts})")

# At rest until 101 s, then 1.5 m/s^2 along x up to 3 m/s (at 103 s), then cruising.
tg = np.arange(100.0, 130.0, 0.005)
v = np.clip(1.5 * (tg - 101.0), 0.0, 3.0)
x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(tg))])
gt = np.column_stack([tg, x, np.zeros((len(tg), 5)), np.ones_like(tg)])
check(abs(isp.true_speed(gt, 102.0) - 1.5) < 1e-2, f"1.5 m/s at 102 s ({isp.true_speed(gt, 102.0):.4f})")
check(abs(isp.true_speed(gt, 120.0) - 3.0) < 1e-6, f"3 m/s when cruising ({isp.true_speed(gt, 120.0):.6f})")
check(isp.true_speed(gt, 100.5) < 1e-9, "0 at rest")
