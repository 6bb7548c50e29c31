"""Which tracks a static point explains under the TRUE camera poses (the simulator's ground truth).

A feature on a moving object can only be rejected by DynaVINS when no static 3D point explains its
track: the weight step sees the track through the mean squared whitened reprojection residual r_j of
the best static point, and the feature's weight (no history) drops below 0.5 only when r_j > λw.
An object moving along the line of sight (a car far ahead, a truck that keeps pace with the camera)
looks exactly like a static point at another depth. This module measures that ceiling independently
of the estimator: it fits the best static point to each feature's observed left-camera track
(every frame of `features.csv`, not only one window) with the ground-truth poses, and returns its
r_j in the estimator's units (σ = 1.5 px at 460 px, VINS-Fusion's). For a stereo run, the right
pixels of the same observations (`features.csv`'s u_r, v_r) join the fit with cam1's true poses: the
disparity then also has to agree with one static point, which can separate an object that keeps pace
with the camera (it looks like a point at infinity to the left camera alone).

Only the simulator's pinhole-radtan cameras are handled (the scenes of this bench); numpy only.
"""

import csv
import os
import re
from collections import defaultdict

import numpy as np

SQRT_INFO = 460.0 / 1.5  # the estimator's whitening (window_optimizer.hpp, kNominalFocalPx / 1.5)


def quaternion_matrices(q):
    """Rotation matrices [N,3,3] of unit quaternions [N,4] in TUM order (qx, qy, qz, qw)."""
    x, y, z, w = (q / np.linalg.norm(q, axis=1, keepdims=True)).T
    return np.stack([np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
                     np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
                     np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1)], 1)


def _yaml_number(text, key):
    m = re.search(rf"^\s*{key}\s*:\s*([-+0-9.eE]+)", text, re.M)
    if not m:
        raise ValueError(f"no '{key}' in camera file")
    return float(m.group(1))


def read_pinhole(cam_yaml):
    """fx, fy, cx, cy, k1, k2, p1, p2 of a VINS-Fusion PINHOLE camera file."""
    text = open(cam_yaml).read()
    if not re.search(r"model_type\s*:\s*PINHOLE", text):
        raise ValueError(f"{cam_yaml}: not a PINHOLE camera")
    return [_yaml_number(text, k) for k in ("fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2")]


def read_body_T_cam(config_yaml, cam=0):
    """The 4x4 body_T_cam<cam> matrix of a VINS-Fusion config."""
    text = open(config_yaml).read()
    m = re.search(rf"body_T_cam{cam}\s*:.*?data\s*:\s*\[([^\]]*)\]", text, re.S)
    if not m:
        raise ValueError(f"{config_yaml}: no body_T_cam{cam}")
    return np.array([float(x) for x in m.group(1).split(",")]).reshape(4, 4)


def undistort(uv, cam):
    """Pixels [N,2] -> normalised image coordinates [N,2] (radial-tangential, fixed-point)."""
    fx, fy, cx, cy, k1, k2, p1, p2 = cam
    xd = np.column_stack(((uv[:, 0] - cx) / fx, (uv[:, 1] - cy) / fy))
    x = xd.copy()
    for _ in range(20):
        a, b = x[:, 0], x[:, 1]
        r2 = a * a + b * b
        radial = 1 + k1 * r2 + k2 * r2 * r2
        dx = np.column_stack((2 * p1 * a * b + p2 * (r2 + 2 * a * a), p1 * (r2 + 2 * b * b) + 2 * p2 * a * b))
        x = (xd - dx) / radial[:, None]
    return x


def _residuals(P, R_cw, p_wc, xy):
    """Whitened residuals [N,2] of world point P in cameras (R_cw: world->camera rotations)."""
    pc = np.einsum("nij,nj->ni", R_cw, P - p_wc)
    z = pc[:, 2:3]
    bad = z[:, 0] <= 1e-3
    e = SQRT_INFO * (pc[:, :2] / np.where(bad[:, None], 1.0, z) - xy)
    e[bad] = 1e2  # behind a camera: as bad as it gets (the estimator's convention)
    return e, pc


def best_static_residual(R_cw, p_wc, xy):
    """r_j of the best static point: linear triangulation, then Levenberg-Marquardt on the point."""
    # Linear: [x]_x R_cw (P - p) = 0 for every observation, stacked.
    S = np.zeros((len(xy), 2, 3))
    S[:, 0, 0] = S[:, 1, 1] = 1.0
    S[:, :, 2] = -xy
    A = np.einsum("nij,njk->nik", S, R_cw)
    P = np.linalg.lstsq(A.reshape(-1, 3), np.einsum("nij,nj->ni", A, p_wc).reshape(-1), rcond=None)[0]
    # Without parallax the linear point is arbitrary (even behind the camera): start from the best of
    # it and points along the first bearing, from 2 m to far beyond any parallax.
    ray = R_cw[0].T @ np.array([xy[0, 0], xy[0, 1], 1.0])
    starts = [P] + [p_wc[0] + d * ray for d in (2.0, 5.0, 10.0, 20.0, 50.0, 100.0, 1e3, 1e4)]
    P = min(starts, key=lambda X: float((_residuals(X, R_cw, p_wc, xy)[0] ** 2).sum()))
    e, pc = _residuals(P, R_cw, p_wc, xy)
    cost, lam = float((e ** 2).sum()), 1e-3
    for _ in range(30):
        z = np.maximum(pc[:, 2], 1e-3)
        J = np.zeros((len(xy), 2, 3))  # d residual / d P = SQRT_INFO * dproj/dpc * R_cw
        J[:, 0, 0] = J[:, 1, 1] = 1 / z
        J[:, 0, 2] = -pc[:, 0] / z ** 2
        J[:, 1, 2] = -pc[:, 1] / z ** 2
        J = SQRT_INFO * np.einsum("nij,njk->nik", J, R_cw).reshape(-1, 3)
        H, g = J.T @ J, J.T @ e.reshape(-1)
        # lstsq, not solve: a track of identical observations leaves H singular along the depth
        step = -np.linalg.lstsq(H + lam * np.diag(np.diag(H) + 1e-12), g, rcond=None)[0]
        e_new, pc_new = _residuals(P + step, R_cw, p_wc, xy)
        c_new = float((e_new ** 2).sum())
        if c_new < cost:
            P, e, pc, cost, lam = P + step, e_new, pc_new, c_new, lam * 0.3
            if np.linalg.norm(step) < 1e-6 * (1 + np.linalg.norm(P)):
                break
        else:
            lam *= 10
    return cost / len(xy)  # mean squared norm of the 2-D whitened residual, as r_j


def camera_file(config_yaml, cam=0):
    """The cam<cam> calibration file a VINS-Fusion config names (cam0_calib, relative to the config)."""
    m = re.search(rf"^\s*cam{cam}_calib\s*:\s*\"?([^\"\n]+)\"?", open(config_yaml).read(), re.M)
    if not m:
        raise ValueError(f"{config_yaml}: no cam{cam}_calib")
    return os.path.join(os.path.dirname(config_yaml), m.group(1).strip())


def _camera_poses(gt, ts, T_bc):
    """World->camera rotations [N,3,3] and camera positions [N,3] at times ts (nearest ground truth)."""
    t_gt = gt[:, 0]
    i = np.clip(np.searchsorted(t_gt, ts), 0, len(t_gt) - 1)
    i = np.where((i > 0) & (np.abs(t_gt[i - 1] - ts) < np.abs(t_gt[i] - ts)), i - 1, i)
    R_wb = quaternion_matrices(gt[i, 4:8])
    R_wc = R_wb @ T_bc[:3, :3]
    p_wc = gt[i, 1:4] + np.einsum("nij,j->ni", R_wb, T_bc[:3, 3])
    return np.transpose(R_wc, (0, 2, 1)), p_wc


def track_residuals(features_csv, groundtruth_tum, config_yaml):
    """{feature_id: (r_j under the true poses, final sim_label)} for the features solved at least once
    with a known label (the features the scoring counts). Right pixels (stereo runs) join the fit."""
    cam0 = read_pinhole(camera_file(config_yaml))
    T_bc0 = read_body_T_cam(config_yaml, 0)
    gt = np.loadtxt(groundtruth_tum)
    tracks, last = defaultdict(list), {}
    with open(features_csv, newline="") as f:
        for row in csv.DictReader(f):
            fid = row["feature_id"]
            right = (float(row["u_r"]), float(row["v_r"])) if row.get("u_r") else None
            tracks[fid].append((int(row["t_ns"]) * 1e-9, float(row["u"]), float(row["v"]), right))
            last[fid] = (int(row["times_solved"]), int(row["sim_label"]))
    stereo = any(r is not None for rows in tracks.values() for *_, r in rows)
    if stereo:
        cam1 = read_pinhole(camera_file(config_yaml, 1))
        T_bc1 = read_body_T_cam(config_yaml, 1)
    out = {}
    for fid, (solved, label) in last.items():
        if solved == 0 or label < 0:
            continue
        # A row's (u, v) is the feature's latest observation in the window: the row's own frame only
        # while it is tracked; once lost (or its newest slot dropped) an older pixel is repeated. Every
        # pixel first appears in the row of the frame that observed it: keep each pixel once, there,
        # with the right pixel of that same row.
        obs, seen = {}, set()
        for t, u, v, right in tracks[fid]:
            if (u, v) not in seen and t not in obs:
                obs[t] = (u, v, right)
            seen.add((u, v))
        if len(obs) < 2:
            continue  # one frame: no track to judge
        ts = np.array(sorted(obs))
        R_cw, p_wc = _camera_poses(gt, ts, T_bc0)
        xy = undistort(np.array([obs[t][:2] for t in ts]), cam0)
        if stereo:
            tr = np.array([t for t in ts if obs[t][2] is not None])
            if len(tr):
                R1, p1 = _camera_poses(gt, tr, T_bc1)
                R_cw, p_wc = np.concatenate((R_cw, R1)), np.concatenate((p_wc, p1))
                xy = np.concatenate((xy, undistort(np.array([obs[t][2] for t in tr]), cam1)))
        out[fid] = (best_static_residual(R_cw, p_wc, xy), label)
    return out
