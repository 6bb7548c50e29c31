#!/usr/bin/python3
"""bench/report/static_point_fit.py against constructed tracks with known truth: a static point fits
(r_j ~ 0, also without parallax), a point crossing the view does not, a point receding along the line
of sight is indistinguishable from a static one, stale rows of features.csv are not taken as
observations, and a stereo run's right pixels separate a point that keeps pace with the camera. Run with Debian's python (numpy): /usr/bin/python3 tests/bench/test_static_point_fit.py"""
import os
import sys
import tempfile

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bench", "report"))
import static_point_fit as spf  # noqa: E402
from checks import check  # noqa: E402  (tests/bench/checks.py, beside this script)

# Camera = body, looking along +z; pinhole without distortion (fx = fy = 400).
CAM = [400.0, 400.0, 320.0, 240.0, 0.0, 0.0, 0.0, 0.0]


def cameras(n, speed):
    """n camera poses 0.1 s apart driving along +z at `speed` m/s: R_cw, p_wc."""
    return np.repeat(np.eye(3)[None], n, 0), np.array([[0.0, 0.0, speed * 0.1 * k] for k in range(n)])


def observe(points, p_wc):
    """Normalised image coordinates of world points [n,3] seen from p_wc (identity rotations)."""
    pc = points - p_wc
    return pc[:, :2] / pc[:, 2:3]


def residual_of(points, speed=3.0):
    R_cw, p_wc = cameras(len(points), speed)
    return spf.best_static_residual(R_cw, p_wc, observe(points, p_wc))


def main():
    n = 20
    static = np.repeat(np.array([[2.0, -1.0, 15.0]]), n, 0)
    check(residual_of(static) < 1e-6, "a static point fits")
    check(residual_of(static, speed=0.0) < 1e-6, "a static point seen without parallax fits (no degenerate start)")
    crossing = static + np.array([[0.5 * 0.1 * k, 0.0, 0.0] for k in range(n)])  # 0.5 m/s sideways
    check(residual_of(crossing) > 1.0, "a point crossing the view is not explained by a static point")
    receding = static + np.array([[0.0, 0.0, 1.5 * 0.1 * k] for k in range(n)])  # 1.5 m/s away, ahead
    check(residual_of(receding) < 1e-3, "a point receding along the line of sight looks static (unseparable)")

    # track_residuals on files: the repeated (stale) pixel after the feature is lost is not an observation.
    with tempfile.TemporaryDirectory() as tmp:
        cfg, cam, gt, feats = (os.path.join(tmp, f) for f in ("cfg.yaml", "cam0.yaml", "gt.tum", "features.csv"))
        open(cfg, "w").write('%YAML:1.0\ncam0_calib: "cam0.yaml"\nbody_T_cam0: !!opencv-matrix\n'
                             "   rows: 4\n   cols: 4\n   dt: d\n   data: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n")
        open(cam, "w").write("%YAML:1.0\nmodel_type: PINHOLE\ndistortion_parameters:\n   k1: 0\n   k2: 0\n"
                             "   p1: 0\n   p2: 0\nprojection_parameters:\n   fx: 400\n   fy: 400\n"
                             "   cx: 320\n   cy: 240\n")
        _, p_wc = cameras(n, 3.0)
        t_ns = [10**9 + 10**8 * k for k in range(n)]
        open(gt, "w").write("".join(f"{t * 1e-9:.9f} {p[0]} {p[1]} {p[2]} 0 0 0 1\n" for t, p in zip(t_ns, p_wc)))
        rows = ["t_ns,seq,feature_id,u,v,weight,times_solved,sim_label,x,y,z"]
        for fid, label, pts in ((1, 0, static), (2, 3, crossing)):
            uv = observe(pts, p_wc) * 400.0 + np.array([320.0, 240.0])
            for k in range(n):
                j = min(k, 11)  # tracked until frame 11, then its last pixel repeats in the window output
                rows.append(f"{t_ns[k]},{k},{fid},{uv[j, 0]:.6f},{uv[j, 1]:.6f},0.9,{k + 1},{label},0,0,0")
        open(feats, "w").write("\n".join(rows) + "\n")
        fits = spf.track_residuals(feats, gt, cfg)
        check(set(fits) == {"1", "2"} and fits["1"][1] == 0 and fits["2"][1] == 3, "both features fitted, labels kept")
        check(fits["1"][0] < 1e-6, "stale rows after the track ends do not count as observations")
        check(fits["2"][0] > 1.0, "the crossing feature is separable")
        check(abs(spf.read_pinhole(cam)[0] - 400.0) < 1e-12, "camera read from the config's cam0_calib")

        # Stereo: cam1 0.5 m to the right of cam0 (body = cam0). A point 8 m ahead that keeps pace with
        # the camera never moves in the left image, so a point at infinity explains the left track; its
        # disparity (400 * 0.5 / 8 = 25 px) does not agree with infinity. A static point stays explained.
        open(cfg, "a").write('cam1_calib: "cam0.yaml"\nbody_T_cam1: !!opencv-matrix\n'
                             "   rows: 4\n   cols: 4\n   dt: d\n   data: [1,0,0,0.5, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n")
        pacing = np.array([[1.0, 0.5, 8.0]]) + p_wc
        rows = ["t_ns,seq,feature_id,u,v,weight,times_solved,sim_label,x,y,z,u_r,v_r"]
        for fid, label, pts in ((1, 0, static), (4, 2, pacing)):
            uv = observe(pts, p_wc) * 400.0 + np.array([320.0, 240.0])
            uv_r = observe(pts, p_wc + np.array([0.5, 0.0, 0.0])) * 400.0 + np.array([320.0, 240.0])
            for k in range(n):
                # the pacing point's left pixel never changes: give it sub-pixel tracking jitter so that
                # every row is a new observation, as a real track's would be
                jitter = 1e-3 * k if fid == 4 else 0.0
                rows.append(f"{t_ns[k]},{k},{fid},{uv[k, 0] + jitter:.6f},{uv[k, 1]:.6f},0.9,{k + 1},{label},0,0,0,"
                            f"{uv_r[k, 0] + jitter:.6f},{uv_r[k, 1]:.6f}")
        open(feats, "w").write("\n".join(rows) + "\n")
        stereo = spf.track_residuals(feats, gt, cfg)
        check(stereo["1"][0] < 1e-6, "stereo: a static point still fits its left and right pixels")
        check(stereo["4"][0] > 1.0, "stereo: a point keeping pace is separable by its disparity")
        left_only = os.path.join(tmp, "left_only.csv")
        open(left_only, "w").write("\n".join(",".join(r.split(",")[:11]) for r in rows) + "\n")
        check(spf.track_residuals(left_only, gt, cfg)["4"][0] < 1e-3,
              "without right pixels the same pacing point looks static (a point at infinity)")


if __name__ == "__main__":
    main()
