#!/usr/bin/env python3
"""One MuJoCo round of the side-by-side falls bench (`cargo bench --bench falls_vs_mujoco`).

Usage: bench_vs_mujoco.py BODY.xml WORKLOAD.json THREADS

BODY.xml is the fall21 body as `marionette body fall21 --mjcf` writes it; WORKLOAD.json (written
by benches/falls_vs_mujoco.rs) holds the settled standing state, the per-DOF stance PD (target,
gains, strength), the joint friction, the falls' pushes, the step and the duration. MuJoCo gets
position actuators toward the stance on every hinge (force-limited to the strength), the neck's
ball joint a passive spring and damper with the neck's gains, joint friction as joint damping,
its own joint limits and soft contact, and rolls out every fall from the standing state with
`mujoco.rollout` (open loop: constant controls, the push as `xfrc_applied` on the torso at its
centre of mass with the torque of the push point at the start pose) on THREADS threads, with
`implicitfast` at the workload's step. Only the rollout call is timed. Prints one line of JSON:
{"mujoco": version, "falls": n, "steps": per fall, "seconds": wall, "falls_per_s": rate,
 "diverged": falls whose state went non-finite, "pelvis_end_m": mean pelvis height at the end}.
"""
import json
import sys
import time
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
from mujoco import rollout


def model_with_actuators(xml_path, work):
    tree = ET.parse(xml_path)
    root = tree.getroot()
    joints = {j.get("name"): j for j in root.iter("joint")}
    friction = work["friction_kv"]
    act = ET.SubElement(root, "actuator")
    neck = [d for d in work["dofs"] if d["name"].startswith("neck_")]
    for d in work["dofs"]:
        if d["name"] in joints:
            joints[d["name"]].set("damping", repr(friction))
            ET.SubElement(act, "position", {
                "name": d["name"], "joint": d["name"],
                "kp": repr(d["kp"]), "kv": repr(d["kv"]),
                "forcelimited": "true",
                "forcerange": f"{d['torque_min']!r} {d['torque_max']!r}",
            })
    # The neck's ball joint: its stance is the rest pose, held by a passive spring and damper.
    j = joints["neck"]
    j.set("stiffness", repr(max(d["kp"] for d in neck)))
    j.set("damping", repr(max(d["kv"] for d in neck) + friction))
    m = mujoco.MjModel.from_xml_string(ET.tostring(root, encoding="unicode"))
    m.opt.timestep = work["dt_s"]
    m.opt.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    return m


def main() -> int:
    xml, work_path, threads = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with open(work_path) as f:
        work = json.load(f)
    model = model_with_actuators(xml, work)
    data = mujoco.MjData(model)
    s = work["start"]
    root = model.joint("pelvis")
    qa = model.jnt_qposadr[root.id]
    data.qpos[qa:qa + 3] = s["root_position"]
    qx, qy, qz, qw = s["root_orientation"]
    data.qpos[qa + 3:qa + 7] = [qw, qx, qy, qz]
    ctrl = np.zeros(model.nu)
    for d, a in zip(work["dofs"], s["angles"]):
        if not d["name"].startswith("neck_"):
            data.qpos[model.jnt_qposadr[model.joint(d["name"]).id]] = a
            ctrl[model.actuator(d["name"]).id] = d["target"]
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    x0 = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, x0, spec)
    # Controls per step: the actuators' targets, then xfrc_applied of every body.
    cspec = mujoco.mjtState.mjSTATE_CTRL | mujoco.mjtState.mjSTATE_XFRC_APPLIED
    dt, nstep = work["dt_s"], int(round(work["duration_s"] / work["dt_s"]))
    torso = model.body("torso").id
    push = work["push"]
    rot = data.xmat[torso].reshape(3, 3)
    arm = data.xpos[torso] + rot @ np.array(push["point"]) - data.xipos[torso]
    direction = np.array(push["direction"]) / np.linalg.norm(push["direction"])
    forces = work["push_forces_n"]
    n = len(forces)
    control = np.zeros((n, nstep, model.nu + 6 * model.nbody))
    control[:, :, :model.nu] = ctrl
    t = np.arange(nstep) * dt
    on = (t >= push["start_s"]) & (t < push["start_s"] + push["duration_s"])
    base = model.nu + 6 * torso
    for i, fn in enumerate(forces):
        f = direction * fn
        control[i, on, base:base + 3] = f
        control[i, on, base + 3:base + 6] = np.cross(arm, f)
    datas = [mujoco.MjData(model) for _ in range(threads)]
    x0s = np.tile(x0, (n, 1))
    # Warm-up (thread pool, caches), then the timed rollout.
    rollout.rollout(model, datas, x0s[:threads], control[:threads, :10], control_spec=cspec)
    start = time.perf_counter()
    state, _ = rollout.rollout(model, datas, x0s, control, control_spec=cspec)
    seconds = time.perf_counter() - start
    diverged = int(np.sum(~np.all(np.isfinite(state[:, -1, :]), axis=1)))
    # FULLPHYSICS starts with the time, then qpos: the pelvis height is qpos[qa + 1].
    pelvis_end = float(np.nanmean(state[:, -1, 1 + qa + 1]))
    print(json.dumps({
        "mujoco": mujoco.__version__, "falls": n, "steps": nstep, "seconds": seconds,
        "falls_per_s": n / seconds, "diverged": diverged, "pelvis_end_m": pelvis_end,
    }))
    return 0


if __name__ == "__main__":
    sys.exit(main())
