#!/usr/bin/python3
"""bench/report/seed_sweep_table.py on made-up run directories: every ATE and reset count in its cell, the
mean over seeds per scene and setting, and a run without an ATE (mono never initialised) shown with its
tracked frames and leaving its column without a mean instead of a mean of the others; a run that
left no summary.json named as failed.
Run with Debian's python: /usr/bin/python3 tests/bench/test_seed_sweep_table.py"""
import json
import os
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import seed_sweep_table as sst  # noqa: E402
from checks import check  # noqa: E402  (tests/bench/checks.py, beside this script)


def run(d, name, summary):
    os.makedirs(os.path.join(d, name))
    with open(os.path.join(d, name, "summary.json"), "w") as f:
        json.dump(summary, f)


with tempfile.TemporaryDirectory() as d:
    ok = {"frames_tracked": 100, "frames_tracking": 95}
    run(d, "x-s1-huber", dict(ok, ate_se3_m=0.2))
    run(d, "x-s1-a", dict(ok, ate_se3_m=0.1))
    run(d, "x-s2-huber", dict(ok, ate_se3_m=31.0, resets=2))
    run(d, "x-s2-a", dict(ok, ate_se3_m=0.3))
    run(d, "y-s1-huber", dict(ok, ate_se3_m=0.5))
    run(d, "y-s1-a", {"frames_tracked": 1017, "frames_tracking": 58})  # never initialised: no ATE
    lines = [f"x 1 {d}/x-s1", f"x 2 {d}/x-s2", f"y 1 {d}/y-s1"]
    out = sst.table(lines, "", "", False, "", False)
    print("\n".join(out))
    check(out[1] == "| scene | seed | huber | a |", "columns: huber and a only when b and c were not run")
    check("| x | 2 | 31.000 (2 resets) | 0.300 |" in out, "each ATE in its cell, resets beside it")
    check("| x | **mean** | **15.600** | **0.200** |" in out, "the mean over the scene's seeds")
    check("| y | 1 | 0.500 | no ATE (tracking 58 of 1017 frames) |" in out, "a run without ATE says so")
    check("| y | **mean** | **0.500** | no mean: 1 of 1 runs without ATE |" in out,
          "... and its column has no mean")
    out = sst.table(lines[:1], "--set k=1", "--set k=2", True, "", False)
    check("b = dynavins --set k=2" in out[0], "the settings named in the header")
    check("| x | 1 | 0.200 | 0.100 | no summary.json (the run failed: see its .log) |" in out,
          "a run that left no summary.json is named as failed")
