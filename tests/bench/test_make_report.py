#!/usr/bin/python3
"""bench/report/make_report.py on a tiny synthetic results directory: feature precision / recall
on final weights, failed runs rendered (never dropped), README headline block rewritten, the loop-closure
section (ATE per loop mode, per-group hypotheses from loops.csv, loop timing, the loop-edge figure).
Run with Debian's python (numpy, matplotlib): /usr/bin/python3 tests/bench/test_make_report.py"""
import json
import os
import subprocess
import sys
import tempfile
from checks import check  # tests/bench/checks.py, beside this script

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SCRIPT = os.path.join(ROOT, "bench", "report", "make_report.py")


def write(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)


def trajectory(n=200, offset=0.0):
    """A curved TUM trajectory (not a straight line: Umeyama needs it)."""
    lines = ["# t x y z qx qy qz qw"]
    for i in range(n):
        t = 100.0 + 0.05 * i
        lines.append(f"{t:.6f} {i * 0.1 + offset:.6f} {0.02 * (i - n / 2) ** 2 / n:.6f} 1.0 0 0 0 1")
    return "\n".join(lines) + "\n"


def make_run(results, scenario, name, summary, features=None):
    d = os.path.join(results, "runs", scenario, name)
    os.makedirs(d, exist_ok=True)
    if summary is not None:
        write(os.path.join(d, "summary.json"), json.dumps(summary))
        write(os.path.join(d, "groundtruth.tum"), trajectory())
        write(os.path.join(d, "odometry.tum"), trajectory(offset=0.01))
    if features is not None:
        write(os.path.join(d, "features.csv"),
              "t_ns,seq,feature_id,u,v,weight,times_solved,sim_label,x,y,z\n" + features)
    return d


def summary(ate, tracking=100, resets=0, ok=True):
    return {"ok": ok, "frames_in": 100, "frames_tracking": tracking, "resets": resets,
            "ate_se3_m": ate, "ate_sim3_m": ate * 0.9, "ba_ms_mean": 20.0, "ba_ms_p95": 30.0,
            "alternations_mean": 1.2, "real_time_factor": 1.5, "peak_rss_mb": 100.0,
            "stage_ms": {"tracker": {"mean": 10.0, "p95": 15.0}}}


# feature 1: moving, first kept then rejected (final row counts) -> true positive
# feature 2: moving, kept -> missed; feature 3: static kept; feature 4: static rejected -> false positive
# feature 5: static, never solved -> ignored; feature 6: unknown label -> ignored
FEATURES = "\n".join([
    "1,1,1,0,0,0.9,1,3,0,0,0",
    "1,1,3,0,0,0.9,1,0,0,0,0",
    "2,2,1,0,0,0.1,2,3,0,0,0",
    "2,2,2,0,0,0.8,1,4,0,0,0",
    "2,2,3,0,0,0.95,2,0,0,0,0",
    "2,2,4,0,0,0.2,1,0,0,0,0",
    "2,2,5,0,0,0.1,0,0,0,0,0",
    "2,2,6,0,0,0.1,3,-1,0,0,0",
]) + "\n"
# a scene where nothing moves (a static twin): three static features solved, one of them rejected
STATIC_FEATURES = "\n".join([
    "1,1,1,0,0,0.9,1,0,0,0,0",
    "1,1,2,0,0,0.2,1,0,0,0,0",
    "1,1,3,0,0,0.95,2,0,0,0,0",
]) + "\n"


def build_results(results):
    runs = [  # scenario, mode, ba, status, summary, features
        ("none", "stereo", "huber", "ok", summary(0.5), None),
        ("none", "stereo", "dynavins", "ok", summary(0.4), STATIC_FEATURES),
        ("high", "stereo", "huber", "exit1", None, None),                      # run error
        ("high", "stereo", "dynavins", "ok", summary(0.45, resets=2), FEATURES),
        ("none", "mono", "huber", "ok", summary(0.6), None),
        ("none", "mono", "dynavins", "ok", summary(0.5), None),
        ("high", "mono", "huber", "ok", summary(0.7, tracking=10), None),      # lost
        ("high", "mono", "dynavins", "ok", summary(0.55), FEATURES),
    ]
    manifest = ["kind\tscenario\tmode\tba\tvariant\tstatus\twall_s\tdir\tcommand"]
    for sc, mode, ba, status, summ, feats in runs:
        d = make_run(results, sc, f"{mode}-{ba}", summ, feats)
        manifest.append(f"run\t{sc}\t{mode}\t{ba}\t-\t{status}\t12.5\t{d}\tdynavins run --ba {ba}")
    # the degradation pair at one more noise seed (stereo only: mono's seed row must show ✗)
    for sc, ba, ate in (("none", "huber", 0.3), ("none", "dynavins", 0.2), ("high", "huber", 0.9),
                        ("high", "dynavins", 0.35)):
        feats = FEATURES if (sc, ba) == ("high", "dynavins") else None
        d = make_run(results, sc, f"stereo-{ba}-seed12", summary(ate), feats)
        manifest.append(f"run\t{sc}\tstereo\t{ba}\tseed12\tok\t12.5\t{d}\tdynavins run --ba {ba}")
    # the recorded-motion pair (stereo dynavins only: the other rows must show ✗, not a ratio)
    for sc, ate in (("mav_none", 0.02), ("mav_high", 0.03)):
        d = make_run(results, sc, "stereo-dynavins", summary(ate))
        manifest.append(f"run\t{sc}\tstereo\tdynavins\t-\tok\t12.5\t{d}\tdynavins run --ba dynavins")
    # a loop scene: the plain run (--loop dynavins: odometry 0.02, trajectory 0.04) and the baselines
    loop = {"keyframes": 100, "true_loops": 3, "false_loops": 2, "false_loops_used": 0, "keyframe_ms_mean": 12.0,
            "keyframe_ms_p95": 30.0, "keyframe_ms_max": 50.0, "keyframe_cpu_ms_mean": 9.0, "descriptors_ms_mean": 4.0, "query_ms_mean": 1.0,
            "verification_ms_mean": 5.0, "optimization_ms_mean": 20.0, "optimizations": 2, "memory_kb": 2500.0}
    for variant, traj, used in (("", 0.04, 0), ("loopall", 2.0, 5), ("loopswitchable", 0.05, 1)):
        summ = dict(summary(0.02), trajectory_ate_se3_m=traj, loop=dict(loop, false_loops_used=used))
        d = make_run(results, "e_shape", "stereo-dynavins" + (f"-{variant}" if variant else ""), summ)
        write(os.path.join(d, "trajectory.tum"), trajectory(offset=0.02))
        manifest.append(f"run\te_shape\tstereo\tdynavins\t{variant or '-'}\tok\t12.5\t{d}\tdynavins run --loop x")
    # loops.csv of the dynavins run: group 0 holds a true H0 (adopted) and a false H1 (rejected); group 1
    # only a false H0 (rejected); one loop outside any group
    rows = ["mode,query_t_ns,match_t_ns,inliers,group,group_first_t_ns,hypothesis,weight,used,true_loop,error_m,error_deg",
            "dynavins,105000000000,100500000000,40,0,104000000000,0,0.99,1,1,0.01,0.1",
            "dynavins,105100000000,100600000000,35,0,104000000000,0,0.99,1,1,0.02,0.1",
            "dynavins,105200000000,101000000000,20,0,104000000000,1,0.001,1,0,12.0,1.0",
            "dynavins,107000000000,101500000000,30,1,107000000000,0,0.0001,1,0,20.0,2.0",
            "dynavins,107100000000,101600000000,30,1,107000000000,0,0.0001,1,0,20.0,2.0",
            "dynavins,108000000000,102000000000,30,-1,-1,-1,0,0,1,0.01,0.1"]
    write(os.path.join(results, "runs", "e_shape", "stereo-dynavins", "loops.csv"), "\n".join(rows) + "\n")
    write(os.path.join(results, "manifest.tsv"), "\n".join(manifest) + "\n")
    write(os.path.join(results, "meta.tsv"),
          "mode\tquick\ncommit\tabc123\ndirty\tclean\ndate\t2026-01-01T00:00:00Z\nnproc\t2\n"
          "cpu\tTest CPU\nram_gb\t8\nbench_command\tscripts/bench.sh --quick\n")


def main():
    sys.path.insert(0, os.path.dirname(SCRIPT))
    import make_report  # noqa: E402

    with tempfile.TemporaryDirectory() as tmp:
        results = os.path.join(tmp, "results")
        build_results(results)
        sc = make_report.feature_scores(os.path.join(results, "runs", "high", "stereo-dynavins", "features.csv"))
        check((sc["moving"], sc["static"], sc["tp"], sc["fp"]) == (2, 2, 1, 1), f"feature counts {sc}")
        check(abs(sc["precision"] - 0.5) < 1e-9 and abs(sc["recall"] - 0.5) < 1e-9, "precision and recall 0.5")
        check(abs(sc["static_kept"] - 0.5) < 1e-9, "static kept 0.5")

        readme = os.path.join(tmp, "README.md")
        write(readme, "# X\n\n<!-- bench-headline:start -->\nold\n<!-- bench-headline:end -->\n\ntail\n")
        subprocess.run([sys.executable, SCRIPT, "--results", results, "--readme", readme], check=True)
        report = open(os.path.join(results, "REPORT.md")).read()
        check("✗ run error" in report, "the failed run is shown as a run error")
        check("✗ lost (10% tracked)" in report, "the lost run is shown as lost")
        check("(2 resets)" in report, "resets are marked")
        check("| 0.500 | 0.500 | 0.500 |" in report, "precision / recall / static kept in the report")
        check("| `none` | `S-I` | 0 | 3 | — | — | 0.667 |" in report,
              "a scene where nothing moves has its static kept (no precision or recall)")
        check("0.300 → 0.400 (**1.33**)" in report, "degradation over seeds: mean ATEs (0.4, 0.2 / 0.45, 0.35) and ratio")
        check("| DynaVINS-`M-I` | 0.500 → 0.550 (1.10) | not run → not run (✗) | ✗ |" in report,
              "a mode with a missing seed run gets no mean (not averaged away)")
        check("| `S-I` | recall / static kept | 0.500 / 0.500 | 0.500 / 0.500 | **0.500 / 0.500** |" in report,
              "high's scores over the noise draws, with their mean")
        check("| `M-I` | recall / static kept | ✗ | ✗ | ✗ |" in report,
              "a mode with a draw not run gets no scores over the draws")
        check("**r_d = mav_high / mav_none**" in report, "Table III has the recorded-motion pair")
        check("| DynaVINS-`S-I` | 1.125 | 1.500 |" in report,
              "recorded-motion degradation is mav_high / mav_none (0.03 / 0.02), beside high / none (0.45 / 0.4)")
        check("| `e_shape` | S-I | 0.020 | 2.000 | 0.050 | 0.040 | 0.02 | 3 / 2 | 0 | 5 |" in report,
              "loop table: off = odometry ATE, all / switchable / dynavins = trajectory ATE, ratio, loops, false used")
        check("group 0 (t+4 s): H0: 2 loops, 2 true, w 0.99; H1: 1 loops, 0 true, w 0.00 → H0 won (true)" in report,
              "per group: the true hypothesis won")
        check("group 1 (t+7 s): H0: 2 loops, 0 true, w 0.00 → none adopted" in report,
              "per group: a lone false hypothesis is not adopted")
        check("| `e_shape` | S-I | 100 | 12.0 | 30.0 | 50.0 | 9.0 | 4.0 | 1.0 | 5.0 | 20.0 | 2 | 25.0 |" in report,
              "loop timing per keyframe (wall and the loop thread's CPU) and memory per keyframe (2500 kB / 100)")
        check(os.path.isfile(os.path.join(results, "loop_edges.png")), "loop_edges.png written")
        check("![verified loops on e_shape](loop_edges.png)" in report, "the loop-edge figure is in the report")
        check("not implemented" not in report and "`bench/lcm_bench.sh`" in report,
              "the LCM section says where the LCM figures are measured")
        check(os.path.isfile(os.path.join(results, "ate_bars.png")), "ate_bars.png written")
        check(os.path.isfile(os.path.join(results, "trajectories.png")), "trajectories.png written")
        text = open(readme).read()
        check("old" not in text and "abc123" in text and text.endswith("\n\ntail\n"),
              "README headline block rewritten in place")
        check("✗ run error" in text, "headline shows the failure")
        check("| degradation `mav_high / mav_none` | ✗ | 1.50 | ✗ | ✗ |" in text,
              "README headline row for the recorded-motion pair")


if __name__ == "__main__":
    main()
