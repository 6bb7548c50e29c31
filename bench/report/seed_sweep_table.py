#!/usr/bin/python3
"""The table of bench/seed_sweep.sh: every run's SE3 ATE per scene and seed, and the mean over seeds.

Reads lines `SCENE SEED RUN_BASE` on stdin, one per scene and seed; the runs are RUN_BASE-huber,
RUN_BASE-a and, when asked for, RUN_BASE-b and RUN_BASE-c, each a `dynavins run --out` directory with
its summary.json. A run without an ATE (mono that never initialised, or too few poses to align) is
shown as such with how many frames it tracked, and its scene gets no mean in that column: a mean of the
other draws would pass a failure off as a figure.

Usage: ... | /usr/bin/python3 bench/report/seed_sweep_table.py A_OPTIONS B_OPTIONS HAVE_B C_OPTIONS HAVE_C
(HAVE_B / HAVE_C: 1 when that setting was run).
"""

import collections
import json
import os
import sys


def ate(run_dir):
    """(SE3 ATE [m] or None when the run has none, the cell's text)."""
    path = run_dir + "/summary.json"
    if not os.path.exists(path):
        return None, "no summary.json (the run failed: see its .log)"
    s = json.load(open(path))
    if "ate_se3_m" not in s:
        return None, "no ATE (tracking %s of %s frames)" % (s.get("frames_tracking", "?"), s.get("frames_tracked", "?"))
    resets = s.get("resets", 0)
    return s["ate_se3_m"], "%.3f%s" % (s["ate_se3_m"], " (%d resets)" % resets if resets else "")


def mean(values):
    """The bold mean, or none at all when a run has no ATE."""
    if None in values:
        return "no mean: %d of %d runs without ATE" % (values.count(None), len(values))
    return "**%.3f**" % (sum(values) / len(values))


def table(lines, a, b, have_b, c, have_c):
    """The Markdown table (a list of lines) for the `SCENE SEED RUN_BASE` lines."""
    cols = ["huber", "a"] + (["b"] if have_b else []) + (["c"] if have_c else [])
    out = ["SE3 ATE [m], rate 0, loop off; a = dynavins %s; b = dynavins %s%s"
           % (a or "(defaults)", b if have_b else "(not run)", "; c = dynavins %s" % c if have_c else ""),
           "| scene | seed | " + " | ".join(cols) + " |",
           "|---|---|" + "---|" * len(cols)]
    values = collections.defaultdict(lambda: collections.defaultdict(list))
    for line in lines:
        if not line.strip():
            continue
        scene, seed, base = line.split()
        cells = []
        for col in cols:
            v, text = ate(base + "-" + col)
            values[scene][col].append(v)
            cells.append(text)
        out.append("| %s | %s | %s |" % (scene, seed, " | ".join(cells)))
    for scene, per_col in values.items():
        out.append("| %s | **mean** | %s |" % (scene, " | ".join(mean(per_col[col]) for col in cols)))
    return out


def main():
    if len(sys.argv) != 6:
        raise SystemExit("usage: seed_sweep_table.py A_OPTIONS B_OPTIONS HAVE_B C_OPTIONS HAVE_C < runs")
    a, b, have_b, c, have_c = sys.argv[1], sys.argv[2], sys.argv[3] == "1", sys.argv[4], sys.argv[5] == "1"
    print("\n".join(table(sys.stdin, a, b, have_b, c, have_c)))


if __name__ == "__main__":
    main()
