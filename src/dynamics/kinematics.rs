//! Forward kinematics (the first pass shared by ABA and RNEA): joint transforms `Xup`, motion
//! subspaces, body velocities `v_i = Xup_i v_λ(i) + v_J`, velocity products
//! `c_i = c_J + v_i ×m v_J`, and world poses of every body.

use super::axis_rotation::JointRotation;
use super::data::Data;
use super::model::{Model, ModelError};
use super::spatial::{MotionVec, SpatialTransform};

/// Fills `data.xup, s, v, c, rot, pos` for configuration `q` (size nq) and velocity `v` (size nv).
/// The first pass of every step, it does not check sizes (a wrong one panics on an index);
/// callers check once at their entry ([`Model::check_state`], [`Model::check_data`]).
#[inline(always)]
pub fn kinematics(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) {
    debug_assert_eq!(q.len(), model.nq);
    debug_assert_eq!(v.len(), model.nv);
    // Every per-body buffer as a slice of length n (each body index is then known in bounds).
    let n = model.nbodies();
    let Data {
        xup,
        xup_rotation,
        s,
        v: vel,
        c,
        rot,
        pos,
        q_sin_cos: (q_sin, q_cos),
        ..
    } = data;
    super::trig::sin_cos_at(q, &model.axis_angles, q_sin, q_cos);
    let (xups, rots, ss) = (&mut xup[..n], &mut xup_rotation[..n], &mut s[..n]);
    let (vs, cs) = (&mut vel[..n], &mut c[..n]);
    let (world_rot, world_pos) = (&mut rot[..n], &mut pos[..n]);
    for (i, body) in model.bodies[..n].iter().enumerate() {
        let (iq, iv) = (model.q_idx[i], model.v_idx[i]);
        let j = &body.joint;
        let axes = model.joint_axes[i];
        let jq = iq..iq + j.nq();
        let (xj, vj, cj, rotation) = j.jcalc_axes(
            axes,
            (&q[jq.clone()], &q_sin[jq.clone()], &q_cos[jq]),
            &v[iv..iv + j.nv()],
            &mut ss[i],
        );
        let xup = match rotation {
            // `X_tree` is a pure translation and `X_J` a pure rotation: `X_J X_tree` is
            // `rot(E_J)` with the tree's translation.
            JointRotation::General => xj * body.x_tree,
            _ => SpatialTransform {
                rot: xj.rot,
                trans: body.x_tree.trans,
            },
        };
        xups[i] = xup;
        rots[i] = rotation;
        match body.parent {
            Some(p) => {
                let vi = xup.apply_motion(vs[p]) + vj;
                vs[i] = vi;
                cs[i] = cj + vi.cross_motion(vj);
                let rp = world_rot[p];
                world_rot[i] = match rotation {
                    JointRotation::General => rp * xup.rot.transpose(),
                    JointRotation::One(r) => r.mul_right(&rp),
                    JointRotation::Two(r1, r2) => r2.mul_right(&r1.mul_right(&rp)),
                };
                world_pos[i] = world_pos[p] + rp * xup.trans;
            }
            None => {
                vs[i] = vj;
                cs[i] = cj + vj.cross_motion(vj);
                world_rot[i] = xup.rot.transpose();
                world_pos[i] = xup.trans;
            }
        }
    }
}

/// The spatial gravity acceleration `a₀ = [0; −g]` that ABA and RNEA give the fixed base.
#[inline]
pub fn base_acceleration(model: &Model) -> MotionVec {
    MotionVec::new(glam::DVec3::ZERO, -model.gravity)
}

/// Mechanical energy `(T, V)` (J) of the tree: `T = Σ ½ v_iᵀ I_i v_i`,
/// `V = −Σ m_i g·x_com,i` (zero potential at world height 0). Uses and overwrites `data`. A
/// vector or `data` of another size than the model's is a [`ModelError::SizeMismatch`].
pub fn mechanical_energy(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<(f64, f64), ModelError> {
    model.check_data(data)?;
    model.check_state(q, v)?;
    kinematics(model, data, q, v);
    let mut t = 0.0;
    let mut pot = 0.0;
    for (i, b) in model.bodies.iter().enumerate() {
        t += b.inertia.kinetic_energy(data.v[i]);
        let com = data.pos[i] + data.rot[i] * b.inertia.com;
        pot -= b.inertia.mass * model.gravity.dot(com);
    }
    Ok((t, pot))
}

/// World position of body `i`'s point `p` (body coordinates) after [`kinematics`].
#[inline]
pub fn world_point(data: &Data, i: usize, p: glam::DVec3) -> glam::DVec3 {
    data.pos[i] + data.rot[i] * p
}

/// World velocity of body `i`'s point `p` (body coordinates) after [`kinematics`]:
/// `R (v + ω × p)`.
#[inline]
pub fn world_point_velocity(data: &Data, i: usize, p: glam::DVec3) -> glam::DVec3 {
    let v = data.v[i];
    data.rot[i] * (v.lin + v.ang.cross(p))
}
