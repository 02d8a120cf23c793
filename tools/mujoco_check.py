#!/usr/bin/env python3
"""Replays the engine's pushed fall in MuJoCo on the MJCF body and compares the head height.

Usage: mujoco_check.py BODY.xml FALL.json TOL_M

FALL.json (written by tests/dynamics/body_cross_check.rs) holds the engine's settled standing
state, the
controller (stance PD held to its strength limits, the joint model), the push, the step, and the
engine's head-height record up to the first touchdown of a link other than the feet. MuJoCo
steps the same body with the same joint torques and push (applied as generalised forces, with
MuJoCo's own soft contact for the feet on the floor) by its semi-implicit Euler at the same step.
Prints the largest head-height difference up to that touchdown; exits non-zero above TOL_M.
"""
import json
import sys

import mujoco
import numpy as np


def rotvec_from_quat_wxyz(q):
    w, v = q[0], np.array(q[1:4])
    s = np.linalg.norm(v)
    if s < 1e-15:
        return 2.0 * v
    angle = 2.0 * np.arctan2(s, w)
    return v / s * angle


def main() -> int:
    xml, fall_path, tol = sys.argv[1], sys.argv[2], float(sys.argv[3])
    with open(fall_path) as f:
        fall = json.load(f)
    model = mujoco.MjModel.from_xml_path(xml)
    model.opt.timestep = fall["dt_s"]
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
    data = mujoco.MjData(model)
    dofs = fall["dofs"]
    # qpos / qvel addresses of every DOF; the neck's three components share the ball joint.
    ball = model.joint("neck")
    ball_axes = np.array(fall["neck_axes"])  # columns: the engine's ball axes (X, Z, Y)
    hinge = {}
    for d in dofs:
        if not d["name"].startswith("neck_"):
            j = model.joint(d["name"])
            hinge[d["name"]] = (model.jnt_qposadr[j.id], model.jnt_dofadr[j.id])
    root = model.joint("pelvis")
    qa = model.jnt_qposadr[root.id]
    x = fall["start"]
    data.qpos[qa:qa + 3] = x["root_position"]
    qx, qy, qz, qw = x["root_orientation"]
    data.qpos[qa + 3:qa + 7] = [qw, qx, qy, qz]
    for d, a in zip(dofs, x["angles"]):
        if d["name"] in hinge:
            data.qpos[hinge[d["name"]][0]] = a
    neck_angles = np.array([x["angles"][i] for i, d in enumerate(dofs) if d["name"].startswith("neck_")])
    r = ball_axes @ neck_angles
    angle = np.linalg.norm(r)
    ba = model.jnt_qposadr[ball.id]
    if angle > 0:
        data.qpos[ba:ba + 4] = [np.cos(angle / 2), *(np.sin(angle / 2) * r / angle)]
    else:
        data.qpos[ba:ba + 4] = [1, 0, 0, 0]
    mujoco.mj_forward(model, data)
    head = model.body("head").id
    torso = model.body("torso").id
    push = fall["push"]
    lim = fall["limits"]
    bd = model.jnt_dofadr[ball.id]
    neck_ix = [i for i, d in enumerate(dofs) if d["name"].startswith("neck_")]
    record = fall["head_height"]  # [[t, h], ...]
    worst, k, t = 0.0, 0, 0.0
    steps = 0
    while k < len(record):
        tr, hr = record[k]
        if abs(t - tr) < 0.5 * fall["dt_s"]:
            worst = max(worst, abs(data.xipos[head][1] - hr))
            k += 1
            continue
        # Joint torques: PD (clamped to strength) plus the joint model, per DOF.
        data.qfrc_applied[:] = 0.0
        rv = rotvec_from_quat_wxyz(data.qpos[ba:ba + 4])
        neck_theta = ball_axes.T @ rv
        neck_rate = ball_axes.T @ data.qvel[bd:bd + 3]
        neck_tau = np.zeros(3)
        for i, d in enumerate(dofs):
            if d["name"] in hinge:
                qi, vi = hinge[d["name"]]
                th, thd = data.qpos[qi], data.qvel[vi]
            else:
                n = neck_ix.index(i)
                th, thd = neck_theta[n], neck_rate[n]
            tau = d["kp"] * (d["target"] - th) - d["kv"] * thd
            tau = min(max(tau, d["torque_min"]), d["torque_max"])
            lo, hi = d["range"]
            if th > hi:
                tau += -lim["limit_kp"] * (th - hi) - lim["limit_kv"] * thd
            elif th < lo:
                tau += -lim["limit_kp"] * (th - lo) - lim["limit_kv"] * thd
            else:
                tau += -lim["friction_kv"] * thd
            if d["name"] in hinge:
                data.qfrc_applied[hinge[d["name"]][1]] += tau
            else:
                neck_tau[neck_ix.index(i)] = tau
        data.qfrc_applied[bd:bd + 3] += ball_axes @ neck_tau
        if push["start_s"] <= t < push["start_s"] + push["duration_s"]:
            rot = data.xmat[torso].reshape(3, 3)
            point = data.xpos[torso] + rot @ np.array(push["point"])
            force = np.array(push["direction"]) / np.linalg.norm(push["direction"]) * push["force_n"]
            mujoco.mj_applyFT(model, data, force, np.zeros(3), point, torso, data.qfrc_applied)
        mujoco.mj_step(model, data)
        steps += 1
        t = steps * fall["dt_s"]
    print(
        f"mujoco {mujoco.__version__}: head height agrees with the engine to {worst * 1000:.2f} mm "
        f"over {len(record)} frames until the first non-foot touchdown at {fall['until_s']:.3f} s"
    )
    return 0 if worst <= tol else 1


if __name__ == "__main__":
    sys.exit(main())
