//! The composite-rigid-body algorithm (Featherstone 2008, §6.2, `HandC`): the joint-space
//! inertia matrix `H(q)`, and forward dynamics by `H q̈ = τ − C(q, q̇, f_ext)` with a Cholesky
//! factorisation — the O(n³) reference the articulated-body algorithm is checked against.
//!
//! `I^c_i = I_i + Σ_children Xupᵀ I^c Xup`; for each joint column `F = I^c_i S_i`,
//! `H_ii = S_iᵀ F`, then walking to the root `F ← Xup_jᵀ F`, `H_{i,λ(j)} = Fᵀ S_λ(j)`.

use super::data::Data;
use super::joint::JointType;
use super::kinematics::kinematics;
use super::model::{Model, ModelError, NotPositiveDefinite, check_size};
use super::rnea::rnea;
use super::spatial::{ForceVec, MotionVec};

#[inline]
fn column(data: &Data, joint: &JointType, i: usize, k: usize) -> MotionVec {
    match joint {
        JointType::Free => JointType::free_column(k),
        _ => data.s[i][k],
    }
}

/// Fills `data.h` (nv × nv, row-major) with the joint-space inertia matrix `H(q)`. A `q` or
/// `data` of another size than the model's is a [`ModelError::SizeMismatch`].
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d [f64], ModelError> {
    model.check_data(data)?;
    check_size("q", model.nq, q.len())?;
    let zeros = std::mem::take(&mut data.zeros);
    kinematics(model, data, q, &zeros);
    data.zeros = zeros;
    let nv = model.nv;
    let n = model.nbodies();
    for i in 0..n {
        data.ic[i] = model.inertia_blocks[i];
    }
    for i in (0..n).rev() {
        if let Some(p) = model.bodies[i].parent {
            let add = data.ic[i].transform_to_parent_with(&data.xup[i], &data.xup_rotation[i]);
            data.ic[p] += add;
        }
    }
    data.h.fill(0.0);
    for i in 0..n {
        let body = &model.bodies[i];
        let iv = model.v_idx[i];
        for k in 0..body.joint.nv() {
            let mut f: ForceVec = data.ic[i].apply(column(data, &body.joint, i, k));
            let row = iv + k;
            for m in 0..body.joint.nv() {
                let e = column(data, &body.joint, i, m).dot(f);
                data.h[row * nv + iv + m] = e;
            }
            let mut j = i;
            while let Some(p) = model.bodies[j].parent {
                f = data.xup[j].inv_apply_force(f);
                j = p;
                let bj = &model.bodies[j];
                let jv = model.v_idx[j];
                for m in 0..bj.joint.nv() {
                    let e = column(data, &bj.joint, j, m).dot(f);
                    data.h[row * nv + jv + m] = e;
                    data.h[(jv + m) * nv + row] = e;
                }
            }
        }
    }
    Ok(&data.h)
}

/// Factors the symmetric positive definite `h` (n × n, row-major) in place into `L Lᵀ`
/// (lower triangle holds `L`).
pub fn cholesky_factor(h: &mut [f64], n: usize) -> Result<(), NotPositiveDefinite> {
    for j in 0..n {
        let mut d = h[j * n + j];
        for k in 0..j {
            d -= h[j * n + k] * h[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return Err(NotPositiveDefinite { pivot: j, value: d });
        }
        let d = d.sqrt();
        h[j * n + j] = d;
        for i in j + 1..n {
            let mut s = h[i * n + j];
            for k in 0..j {
                s -= h[i * n + k] * h[j * n + k];
            }
            h[i * n + j] = s / d;
        }
    }
    Ok(())
}

/// Solves `L Lᵀ x = b` in place for a factor from [`cholesky_factor`].
pub fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
}

/// Forward dynamics by CRBA + Cholesky: `q̈ = H⁻¹(τ − C)` with `C = RNEA(q, q̇, 0, f_ext)`.
/// Returns `q̈` in `data.qdd`; a vector of another size than the model's is a
/// [`ModelError::SizeMismatch`], a singular `H` a [`ModelError::NotPositiveDefinite`].
pub fn forward_dynamics_crba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: &[ForceVec],
) -> Result<&'d [f64], ModelError> {
    check_size("tau", model.nv, tau.len())?;
    let nv = model.nv;
    let zeros = std::mem::take(&mut data.zeros);
    let c = rnea(model, data, q, v, &zeros, f_ext).map(|_| ());
    data.zeros = zeros;
    c?;
    for k in 0..nv {
        data.qdd[k] = tau[k] - data.tau[k];
    }
    crba(model, data, q)?;
    cholesky_factor(&mut data.h, nv)?;
    let mut b = std::mem::take(&mut data.qdd);
    cholesky_solve(&data.h, nv, &mut b);
    data.qdd = b;
    Ok(&data.qdd)
}
