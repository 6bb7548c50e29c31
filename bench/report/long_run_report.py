#!/usr/bin/python3
"""Report of bench/long_run.sh: memory and per-stage latency over a long rate-0 run.

Reads DIR/summary.json (the run's), DIR/rss.csv (resident memory sampled from /proc every 2 s),
and DIR/stats.csv.gz (`dynavins decode` of the DYNAVINS_STATS reports: per stage, cumulative since the
start); writes DIR/long_run.png and DIR/REPORT.md.

The stats carry cumulative counts and means, so the latency over time is recovered per interval:
mean over (t1, t2] = (n2 m2 - n1 m1) / (n2 - n1), pooled into bins of BIN_S seconds of wall time.
Memory growth per keyframe is the least-squares slope of RSS against the loop stage's keyframe count over
the second half of the run (after start-up allocations), set beside what the keyframe database itself
reports per keyframe: the difference is growth nothing accounts for.
"""
import argparse
import csv
import gzip
import json
import os
from datetime import datetime, timezone

import numpy as np
import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BIN_S = 60.0
STAGES = ["tracker", "estimator", "loop"]


def read_csv(path):
    opener = gzip.open if path.endswith(".gz") else open
    with opener(path, "rt") as f:
        return list(csv.DictReader(f))


def stage_series(rows, stage):
    """(wall_s, processed, mean_ms) of one stage's cumulative reports, in time order."""
    r = [x for x in rows if x["stage"] == stage]
    return (np.array([float(x["wall_s"]) for x in r]), np.array([float(x["processed"]) for x in r]),
            np.array([float(x["process_ms_mean"]) for x in r]))


def interval_means(t, n, m, bin_s=BIN_S):
    """Per-bin mean latency [ms] and items per bin from cumulative (count, mean) reports."""
    total = n * m
    edges = np.arange(0.0, t[-1] + bin_s, bin_s) if len(t) else np.array([0.0])
    centres, means, counts = [], [], []
    for a, b in zip(edges[:-1], edges[1:]):
        i0 = np.searchsorted(t, a, side="right") - 1
        i1 = np.searchsorted(t, b, side="right") - 1
        n0, s0 = (n[i0], total[i0]) if i0 >= 0 else (0.0, 0.0)
        dn, ds = n[i1] - n0, total[i1] - s0
        if i1 >= 0 and dn > 0:
            centres.append(0.5 * (a + b))
            means.append(ds / dn)
            counts.append(dn)
    return np.array(centres), np.array(means), np.array(counts)


def metres(x):
    return "not computed" if x is None else f"{x:.3f} m"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", required=True)
    ap.add_argument("--ate-odometry", required=True, help="dynavins eval --json of odometry.tum")
    ap.add_argument("--ate-trajectory", required=True, help="dynavins eval --json of trajectory.tum")
    ap.add_argument("--command", default="bench/long_run.sh")
    ap.add_argument("--loop", default="dynavins", help="the run's --loop mode")
    a = ap.parse_args()

    s = json.load(open(os.path.join(a.dir, "summary.json")))
    rss = read_csv(os.path.join(a.dir, "rss.csv"))
    stats = read_csv(os.path.join(a.dir, "stats.csv.gz"))
    ate_odo = json.load(open(a.ate_odometry))["ate"]["rmse"]
    ate_traj = json.load(open(a.ate_trajectory))["ate"]["rmse"]

    t_rss = np.array([float(x["wall_s"]) for x in rss])
    mb = np.array([float(x["rss_kb"]) for x in rss]) / 1024.0
    t_kf, n_kf, _ = stage_series(stats, "loop")
    kf_at_rss = np.interp(t_rss, t_kf, n_kf) if len(t_kf) else np.zeros_like(t_rss)
    half = t_rss >= 0.5 * t_rss[-1]
    slope_mb_per_min = np.polyfit(t_rss[half] / 60.0, mb[half], 1)[0] if half.sum() > 2 else float("nan")
    slope_kb = float("nan")
    if half.sum() > 2 and np.ptp(kf_at_rss[half]) > 0:
        slope_kb = np.polyfit(kf_at_rss[half], mb[half] * 1024.0, 1)[0]
    lp = s.get("loop", {})
    keyframes = lp.get("keyframes", 0)
    db_kb_per_kf = lp.get("memory_kb", 0.0) / keyframes if keyframes else float("nan")

    # Real-time factor per bin: sensor time advances with the tracker's frames (20 Hz here).
    t_tr, n_tr, _ = stage_series(stats, "tracker")
    fps = s["frames_in"] / s["data_s"] if s.get("data_s") else 20.0

    fig, ax = plt.subplots(3, 1, figsize=(10, 10), sharex=True)
    tm = t_rss / 60.0
    ax[0].plot(tm, mb, color="tab:blue", lw=1.2)
    ax[0].set_ylabel("resident memory [MB]", color="tab:blue")
    if len(t_kf) and n_kf[-1] > 0:
        ax0b = ax[0].twinx()
        ax0b.plot(t_kf / 60.0, n_kf, color="tab:gray", lw=1.0, ls="--")
        ax0b.set_ylabel("keyframes in the loop closer's database", color="tab:gray")
    stopped = " (stopped: interrupted)" if s.get("interrupted") else ""
    ax[0].set_title(f"long_run: {s['data_s'] / 60:.1f} min of data at rate 0{stopped}, stereo, dynavins BA, loop "
                    f"closure {a.loop}, LCM outputs on; second half: {slope_mb_per_min:+.2f} MB/min", fontsize=9)
    for stage, colour in zip(STAGES, ["tab:green", "tab:orange", "tab:red"]):
        t, n, m = stage_series(stats, stage)
        if len(t) == 0:
            continue
        c, mean, _ = interval_means(t, n, m)
        ax[1].plot(c / 60.0, mean, color=colour, lw=1.2, label=f"{stage} (mean over {BIN_S:.0f} s)")
    ax[1].set_ylabel("time per item [ms]")
    ax[1].set_yscale("log")
    ax[1].yaxis.set_major_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax[1].yaxis.set_minor_formatter(matplotlib.ticker.FormatStrFormatter("%g"))
    ax[1].tick_params(axis="y", which="minor", labelsize=7)
    ax[1].legend(fontsize=8, loc="upper left")
    ax[1].grid(alpha=0.3)
    c, _, cnt = interval_means(t_tr, n_tr, np.zeros_like(n_tr))
    span = np.minimum(c + 0.5 * BIN_S, t_tr[-1]) - (c - 0.5 * BIN_S)  # the last bin ends with the run
    ax[2].plot(c / 60.0, cnt / fps / span, color="k", lw=1.2, label="real-time factor (sensor s per wall s)")
    ax[2].axhline(1.0, color="k", lw=0.6, ls=":")
    ax[2].set_ylabel("real-time factor")
    ax[2].set_xlabel("wall time [min]")
    ax[2].legend(fontsize=8, loc="upper left")
    ax[2].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(a.dir, "long_run.png"), dpi=90)

    def at_fraction(f):
        i = min(len(mb) - 1, int(f * (len(mb) - 1)))
        return f"{mb[i]:.0f} MB ({kf_at_rss[i]:.0f} kf)" if keyframes else f"{mb[i]:.0f} MB"

    def stage_row(stage):
        t, n, m = stage_series(stats, stage)
        if len(t) == 0:
            return f"| {stage} | - | - | - | - |"
        c, mean, _ = interval_means(t, n, m)
        first, last = mean[: max(1, len(mean) // 6)], mean[-max(1, len(mean) // 6):]
        st = s["stage_ms"].get(stage, {})
        return (f"| {stage} | {int(n[-1])} | {np.mean(first):.1f} | {np.mean(last):.1f} | {st.get('mean', 0):.1f} / "
                f"{st.get('p95', 0):.1f} |")

    lines = [
        f"# Long run (`--loop {a.loop}`): memory and latency over {s['data_s'] / 60:.1f} minutes of data",
        "",
    ] + ([f"**Stopped (SIGINT) after {s['wall_s'] / 60:.0f} min of wall time, at {s['data_s']:.0f} s of data "
          f"(not the whole scene): these figures cover that part only** (summary.json: interrupted: true).", ""]
         if s.get("interrupted") else []) + [
        f"`{a.command.strip()}`, {datetime.now(timezone.utc):%Y-%m-%d}: the `long_run` scene "
        f"(bench/scenarios/long_run.yaml) at rate 0 (lossless), stereo, `--ba dynavins --loop {a.loop}`, every "
        f"LCM output recorded (file:// provider). Memory: VmRSS sampled every 2 s. Latency: per-stage time per "
        f"item from the stats reports (one a second), mean per {BIN_S:.0f} s of wall time.",
        "",
        "![memory and latency over time](long_run.png)",
        "",
        "| data | wall | real-time factor | frames in / estimated / dropped | resets | ATE odometry | ATE loop-corrected |",
        "|---|---|---|---|---|---|---|",
        f"| {s['data_s']:.0f} s | {s['wall_s']:.0f} s | {s['real_time_factor']:.2f} | {s['frames_in']} / "
        f"{s['frames_estimated']} / {s['frames_dropped']} | {s['resets']} | {metres(ate_odo)} | {metres(ate_traj)} |",
        "",
        "**Memory.** " + f"peak {s['peak_rss_mb']:.0f} MB; at 10 % of the run {at_fraction(0.1)}, at 50 % "
        f"{at_fraction(0.5)}, at the end {at_fraction(1.0)}. Growth over the second half (least squares): "
        f"**{slope_mb_per_min:+.2f} MB per minute**" + (
            f", **{slope_kb:.1f} kB per keyframe** (RSS against the loop closer's keyframes); the keyframe "
            f"database reports {db_kb_per_kf:.1f} kB per keyframe ({lp.get('memory_kb', 0) / 1024:.0f} MB for "
            f"{keyframes})." if keyframes else " (no loop closer)."),
        "",
        "**Latency per stage** (ms per item; first and last sixth of the run, and the whole run's mean / p95 from "
        "summary.json; percentiles are histogram bins, within ~4.5 %). At rate 0 a stage's time per item includes "
        "waiting for room in its output queue (lossless backpressure), so a slow stage downstream shows in the "
        "stages before it:",
        "",
        "| stage | items | first sixth | last sixth | whole run mean / p95 |",
        "|---|---|---|---|---|",
    ] + [stage_row(x) for x in STAGES] + [
        "",
        "**Loop closure.** off." if a.loop == "off" else f"**Loop closure.** {keyframes} keyframes ({lp.get('keyframes_dropped', 0)} dropped), {lp.get('loops', 0)} "
        f"verified loops ({lp.get('true_loops', 0)} true, {lp.get('false_loops', 0)} false against the ground truth), "
        f"{lp.get('false_loops_used', 0)} false used, {lp.get('true_loops_used', 0)} true used; "
        f"{lp.get('optimizations', 0)} optimisations, {lp.get('optimization_ms_mean', 0):.0f} ms mean, "
        f"{lp.get('optimization_ms_max', 0):.0f} ms max; {lp.get('keyframe_ms_mean', 0):.1f} ms per keyframe "
        f"(p95 {lp.get('keyframe_ms_p95', 0):.1f}, max {lp.get('keyframe_ms_max', 0):.0f}; the loop thread's CPU "
        f"{lp.get('keyframe_cpu_ms_mean', float('nan')):.1f} ms per keyframe).",
        "",
        "Raw: summary.json, rss.csv, stats.csv.gz and queues.csv.gz (decoded stats reports), loops.csv.gz, "
        "decode.txt (the LCM recording's check).",
    ]
    with open(os.path.join(a.dir, "REPORT.md"), "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
