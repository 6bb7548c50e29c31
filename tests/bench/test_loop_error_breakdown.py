#!/usr/bin/python3
"""bench/report/loop_error_breakdown.py on constructed loops with a known cause of error: an error made
proportional to the loop's rotation error is found to follow it (and not the distance), one made
proportional to the keyframes' distance is found to follow that; false loops are left out, and the
distance bins count the loops where the ground truth puts them.
Run with Debian's python (numpy): /usr/bin/python3 tests/bench/test_loop_error_breakdown.py"""
import os
import sys
import tempfile

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import loop_error_breakdown as leb  # noqa: E402
from checks import check  # noqa: E402  (tests/bench/checks.py, beside this script)

SPEED = 2.0  # m/s along +x, so two keyframes dt seconds apart are 2*dt metres apart


def write_scene(d, loops):
    """groundtruth.tum of a camera driving along +x at SPEED for 20 s (100 Hz), and loops.csv with
    `loops` = [(query_t_s, match_t_s, error_m, error_deg, true)]."""
    t = np.arange(0, 20, 0.01)
    gt = np.column_stack([t, SPEED * t, np.zeros_like(t), np.zeros_like(t),
                          np.zeros_like(t), np.zeros_like(t), np.zeros_like(t), np.ones_like(t)])
    np.savetxt(os.path.join(d, "groundtruth.tum"), gt)
    with open(os.path.join(d, "loops.csv"), "w") as f:
        f.write("mode,query_t_ns,match_t_ns,inliers,group,group_first_t_ns,hypothesis,weight,used,true_loop,"
                "error_m,error_deg\n")
        for i, (tq, tm, e, ed, true) in enumerate(loops):
            f.write(f"dynavins,{int(round(tq * 1e9))},{int(round(tm * 1e9))},{20 + i % 7},1,0,0,1,1,"
                    f"{1 if true else 0},{e},{ed}\n")
    return os.path.join(d, "loops.csv"), os.path.join(d, "groundtruth.tum")


rng = np.random.default_rng(3)
with tempfile.TemporaryDirectory() as d:
    # Error = 0.17 m per degree of rotation error; the keyframes' distance drawn independently.
    loops = []
    for k in range(60):
        dt = rng.uniform(0.1, 3.0)  # 0.2 .. 6 m apart
        ed = rng.uniform(0.01, 0.2)
        loops.append((10.0 + dt, 10.0, 0.17 * ed, ed, True))
    loops += [(15.0, 5.0, 40.0, 170.0, False)] * 5  # false loops: must not count
    b = leb.breakdown(*write_scene(d, loops))
    check(b["true_loops"] == 60, "the 5 false loops are left out (60 true loops)")
    check(b["corr_rotation"] > 0.99, f"an error made of the rotation error follows it ({b['corr_rotation']:.3f})")
    check(abs(b["corr_distance"]) < 0.4, f"... and not the distance ({b['corr_distance']:.3f})")
    check(abs(b["median_deg"] - np.median([l[3] for l in loops[:60]])) < 1e-9, "median rotation error")
    n_binned = sum(n for _, _, n, _ in b["bins"])
    check(n_binned == 60, "every true loop falls in one distance bin")
    expected_1_2 = sum(1 for l in loops[:60] if 1.0 <= SPEED * (l[0] - l[1]) < 2.0)
    got_1_2 = [n for lo, hi, n, _ in b["bins"] if lo == 1.0]
    check(got_1_2 == [expected_1_2], f"loops 1-2 m apart counted from the ground truth ({expected_1_2})")

with tempfile.TemporaryDirectory() as d:
    # Error = 1 % of the distance, rotation error drawn independently.
    loops = []
    for k in range(60):
        dt = rng.uniform(0.1, 3.0)
        loops.append((10.0 + dt, 10.0, 0.01 * SPEED * dt, rng.uniform(0.01, 0.2), True))
    b = leb.breakdown(*write_scene(d, loops))
    check(b["corr_distance"] > 0.99, f"an error made of the distance follows it ({b['corr_distance']:.3f})")
    check(abs(b["corr_rotation"]) < 0.4, f"... and not the rotation error ({b['corr_rotation']:.3f})")
    check(np.isnan(b["corr_speed"]), "constant speed: no correlation claimed")

with tempfile.TemporaryDirectory() as d:
    b = leb.breakdown(*write_scene(d, [(15.0, 5.0, 40.0, 170.0, False)]))
    check(b["true_loops"] == 0 and "median_m" not in b, "no true loop: nothing but the count")
print("all passed")
