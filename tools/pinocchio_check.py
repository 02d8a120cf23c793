#!/usr/bin/env python3
"""Holds the engine's ABA and RNEA against Pinocchio's on the fall21 body written as URDF.

Usage: pinocchio_check.py BODY.urdf STATES.json

STATES.json (written by tests/dynamics/body_cross_check.rs) holds random states of the engine's
body with
the engine's inverse dynamics (RNEA) and forward dynamics (ABA) at each. The URDF is loaded with a
free-flyer root and the engine's gravity (0, -g, 0). Velocity coordinates are matched by DOF
name; the free root's engine order [angular; linear] is Pinocchio's [linear; angular]. The neck
is a ball joint in the engine and three revolutes in the URDF, equal at the identity: the states
keep the neck there at rest (its acceleration and torque are free). Exits non-zero on a mismatch
larger than TOL relative to max(1, |value|).
"""
import json
import sys

import numpy as np
import pinocchio as pin

TOL = 1e-9


def main() -> int:
    urdf, states_path = sys.argv[1], sys.argv[2]
    with open(states_path) as f:
        data = json.load(f)
    model = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
    model.gravity.linear = np.array([0.0, -data["gravity"], 0.0])
    pdata = model.createData()
    dofs = data["dofs"]  # name -> {"v": engine v index, "q": engine q index or null}
    pin_v = {n: model.joints[model.getJointId(n)].idx_v for n in dofs}
    pin_q = {n: model.joints[model.getJointId(n)].idx_q for n in dofs}
    if model.nv != len(dofs) + 6:
        print(f"Pinocchio nv {model.nv}, expected {len(dofs) + 6}")
        return 1

    def to_pin_v(ve):
        out = np.zeros(model.nv)
        out[0:3] = ve[3:6]
        out[3:6] = ve[0:3]
        for n, ix in dofs.items():
            out[pin_v[n]] = ve[ix["v"]]
        return out

    def to_pin_q(qe):
        out = np.zeros(model.nq)
        out[0:7] = qe[0:7]
        for n, ix in dofs.items():
            out[pin_q[n]] = 0.0 if ix["q"] is None else qe[ix["q"]]
        return out

    worst = 0.0
    for k, s in enumerate(data["states"]):
        q = to_pin_q(s["q"])
        v = to_pin_v(s["v"])
        a = to_pin_v(s["a"])
        tau = pin.rnea(model, pdata, q, v, a)
        tau_e = to_pin_v(s["tau_rnea"])
        qdd = pin.aba(model, pdata, q, v, to_pin_v(s["tau_in"]))
        qdd_e = to_pin_v(s["qdd_aba"])
        for what, x, y in (("RNEA", tau, tau_e), ("ABA", qdd, qdd_e)):
            err = np.max(np.abs(x - y) / np.maximum(1.0, np.abs(y)))
            worst = max(worst, err)
            if err > TOL:
                i = int(np.argmax(np.abs(x - y)))
                print(f"state {k}: {what} differs by {err:.3e} at v index {i}: pinocchio {x[i]} engine {y[i]}")
                return 1
    print(f"pinocchio {pin.__version__}: ABA and RNEA agree on {len(data['states'])} states, worst relative error {worst:.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
