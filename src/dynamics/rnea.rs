//! The recursive Newton–Euler algorithm (Featherstone 2008, §5.3, `ID`): inverse dynamics
//! `τ = ID(q, q̇, q̈, f_ext)`.
//!
//! Outward: `a_i = Xup_i a_λ(i) + S_i q̈_i + c_i` (with `a₀ = −g`),
//! `f_i = I_i a_i + v_i ×* I_i v_i − f_ext,i`. Inward: `τ_i = S_iᵀ f_i`, `f_λ(i) += Xup_iᵀ f_i`.

use super::data::Data;
use super::joint::JointType;
use super::kinematics::{base_acceleration, kinematics};
use super::model::{Model, ModelError, check_size};
use super::spatial::{ForceVec, MotionVec};
use glam::DVec3;

/// Inverse dynamics: returns `τ` (size nv, in `data.tau`) for `q` (nq), `v` (nv), `qdd` (nv)
/// and external body forces `f_ext` (body coordinates). A free root's entry is `[n; f]` in body
/// coordinates (zero for a consistent floating-base motion). A vector or `data` of another size
/// than the model's is a [`ModelError::SizeMismatch`].
pub fn rnea<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    qdd: &[f64],
    f_ext: &[ForceVec],
) -> Result<&'d [f64], ModelError> {
    model.check_data(data)?;
    model.check_state(q, v)?;
    check_size("qdd", model.nv, qdd.len())?;
    check_size("f_ext", model.nbodies(), f_ext.len())?;
    kinematics(model, data, q, v);
    let a0 = base_acceleration(model);
    for (i, body) in model.bodies.iter().enumerate() {
        let iv = model.v_idx[i];
        let a_parent = match body.parent {
            Some(p) => data.a[p],
            None => a0,
        };
        let mut a = data.xup[i].apply_motion(a_parent) + data.c[i];
        match body.joint {
            JointType::Free => {
                a += MotionVec::new(
                    DVec3::new(qdd[iv], qdd[iv + 1], qdd[iv + 2]),
                    DVec3::new(qdd[iv + 3], qdd[iv + 4], qdd[iv + 5]),
                );
            }
            _ => {
                for k in 0..body.joint.nv() {
                    a += data.s[i][k] * qdd[iv + k];
                }
            }
        }
        data.a[i] = a;
        let inertia = &body.inertia;
        let vi = data.v[i];
        data.f[i] = inertia.apply(a) + vi.cross_force(inertia.apply(vi)) - f_ext[i];
    }
    for i in (0..model.nbodies()).rev() {
        let body = &model.bodies[i];
        let iv = model.v_idx[i];
        let f = data.f[i];
        match body.joint {
            JointType::Free => {
                data.tau[iv..iv + 3].copy_from_slice(&f.ang.to_array());
                data.tau[iv + 3..iv + 6].copy_from_slice(&f.lin.to_array());
            }
            _ => {
                for k in 0..body.joint.nv() {
                    data.tau[iv + k] = data.s[i][k].dot(f);
                }
            }
        }
        if let Some(p) = body.parent {
            let fp = data.xup[i].inv_apply_force(f);
            data.f[p] += fp;
        }
    }
    Ok(&data.tau)
}
