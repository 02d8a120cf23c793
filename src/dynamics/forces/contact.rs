//! Floor contact by penalty springs on the corners of each link's box (the paper's eq. 3.6)
//! with Coulomb friction.
//!
//! For a corner at signed height `z = n·x − h` (below the floor when `z < 0`) moving with
//! velocity `ẋ`: normal force `f_n = max(0, −k_p z − k_v ż)` (it never pulls); tangential force
//! from a spring–damper to an anchor point `a` on the floor, `f_t = −k_t (x − a)_t − c_t ẋ_t`,
//! clipped to the friction cone `|f_t| ≤ μ f_n`. The anchor is set where the corner first
//! touches and is dragged along when the spring would exceed the cone (slip), so a body below the
//! friction angle sticks (no creep) and one above it slides with `|f_t| = μ f_n`.
//! Gains are given per kilogram of link mass (`k_p = k̂_p m_link`), so every link has about the
//! same contact frequency (hence one stable step for all) and the same static sink
//! `g / (corners · k̂_p)` under its own weight. The price: a light link that lands under much of
//! the body's weight (an upper arm under the torso) sinks deeper than a heavy one would.

use crate::dynamics::data::Data;
use crate::dynamics::spatial::ForceVec;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A contact box on a link: centre and half-extents in the link frame (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinkBox {
    /// Centre in the link frame (m).
    pub center: DVec3,
    /// Half edge lengths along the link axes (m).
    pub half: DVec3,
}

impl LinkBox {
    /// The 8 corners in the link frame.
    pub fn corners(&self) -> [DVec3; 8] {
        let mut out = [DVec3::ZERO; 8];
        for (k, o) in out.iter_mut().enumerate() {
            let s = DVec3::new(
                if k & 1 == 0 { -1.0 } else { 1.0 },
                if k & 2 == 0 { -1.0 } else { 1.0 },
                if k & 4 == 0 { -1.0 } else { 1.0 },
            );
            *o = self.center + s * self.half;
        }
        out
    }

    /// Radius of the sphere about the centre that holds the box (m).
    pub fn radius(&self) -> f64 {
        self.half.length()
    }
}

/// Floor and contact parameters.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactParams {
    /// Normal stiffness per corner per kg of link mass, `k̂_p` (N/m/kg).
    pub stiffness_per_kg: f64,
    /// Normal damping per corner per kg of link mass, `k̂_v` (N·s/m/kg).
    pub damping_per_kg: f64,
    /// Tangential (stick) stiffness per corner per kg (N/m/kg).
    pub tangential_stiffness_per_kg: f64,
    /// Tangential damping per corner per kg (N·s/m/kg).
    pub tangential_damping_per_kg: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// Floor height `h` along the normal (m).
    pub floor_height: f64,
    /// Unit floor normal (world), `(0, 1, 0)` for a level floor.
    pub floor_normal: DVec3,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            stiffness_per_kg: 1.2e5,
            damping_per_kg: 40.0,
            tangential_stiffness_per_kg: 2.0e4,
            tangential_damping_per_kg: 100.0,
            friction: 0.8,
            floor_height: 0.0,
            floor_normal: DVec3::Y,
        }
    }
}

/// Contact state carried between steps: the friction anchor of each corner in contact.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactState {
    /// Per link and corner (`link·8 + corner`), the anchor point on the floor, if touching.
    pub anchors: Vec<Option<DVec3>>,
}

impl ContactState {
    /// No corner in contact.
    pub fn new(nlinks: usize) -> Self {
        Self {
            anchors: vec![None; nlinks * 8],
        }
    }
}

/// The contact geometry of a body: its boxes' corners and the per-link gains.
#[derive(Clone, Debug)]
pub struct ContactModel {
    /// Corners of each link's box, link frame.
    pub corners: Vec<[DVec3; 8]>,
    /// Box centre (link frame) and bounding radius per link, for a quick rejection.
    pub bounds: Vec<(DVec3, f64)>,
    /// Link masses (kg).
    pub masses: Vec<f64>,
    /// The parameters.
    pub params: ContactParams,
}

impl ContactModel {
    /// Contact model for `boxes` on links of `masses`.
    pub fn new(boxes: &[LinkBox], masses: &[f64], params: ContactParams) -> Self {
        Self {
            corners: boxes.iter().map(|b| b.corners()).collect(),
            bounds: boxes.iter().map(|b| (b.center, b.radius())).collect(),
            masses: masses.to_vec(),
            params,
        }
    }

    /// Normal and tangential force on one corner at world point `x` with velocity `xd`.
    /// Returns `(f_n, f_t, z)` or `None` when the corner is above the floor.
    #[inline]
    fn corner_force(
        &self,
        link: usize,
        x: DVec3,
        xd: DVec3,
        anchor: Option<DVec3>,
    ) -> Option<(f64, DVec3, f64)> {
        let p = &self.params;
        let n = p.floor_normal;
        let z = n.dot(x) - p.floor_height;
        if z >= 0.0 {
            return None;
        }
        let m = self.masses[link];
        let zd = n.dot(xd);
        let fnorm = (-p.stiffness_per_kg * m * z - p.damping_per_kg * m * zd).max(0.0);
        let vt = xd - n * zd;
        let stretch = match anchor {
            Some(a) => {
                let d = x - a;
                d - n * n.dot(d)
            }
            None => DVec3::ZERO,
        };
        let mut ft =
            -stretch * (p.tangential_stiffness_per_kg * m) - vt * (p.tangential_damping_per_kg * m);
        let cap = p.friction * fnorm;
        let l2 = ft.length_squared();
        if l2 > cap * cap {
            ft *= cap / l2.sqrt();
        }
        Some((fnorm, ft, z))
    }

    /// Adds the contact force of every link to `f_ext` (body coordinates) after
    /// [`kinematics`](crate::dynamics::kinematics::kinematics); writes each link's total normal force (N)
    /// into `normal` and returns the deepest penetration (m, ≥ 0).
    pub fn apply(
        &self,
        data: &Data,
        state: &ContactState,
        f_ext: &mut [ForceVec],
        normal: &mut [f64],
    ) -> f64 {
        let p = &self.params;
        let n = p.floor_normal;
        let mut deepest: f64 = 0.0;
        for (i, corners) in self.corners.iter().enumerate() {
            normal[i] = 0.0;
            let rot = data.rot[i];
            let pos = data.pos[i];
            let (c, r) = self.bounds[i];
            if n.dot(pos + rot * c) - p.floor_height > r {
                continue;
            }
            let v = data.v[i];
            let mut f_body = ForceVec::ZERO;
            for (k, &cl) in corners.iter().enumerate() {
                let x = pos + rot * cl;
                if n.dot(x) - p.floor_height >= 0.0 {
                    continue;
                }
                let xd = rot * (v.lin + v.ang.cross(cl));
                if let Some((fnorm, ft, z)) = self.corner_force(i, x, xd, state.anchors[i * 8 + k])
                {
                    deepest = deepest.max(-z);
                    normal[i] += fnorm;
                    let f_world = n * fnorm + ft;
                    f_body += ForceVec::at_point(rot.transpose() * f_world, cl);
                }
            }
            f_ext[i] += f_body;
        }
        deepest
    }

    /// Updates the friction anchors for the state in `data` (call once per step): a corner that
    /// left the floor loses its anchor, a new contact anchors where it touches, and a corner
    /// whose spring would leave the friction cone drags its anchor to the cone's edge (slip).
    pub fn update_anchors(&self, data: &Data, state: &mut ContactState) {
        let p = &self.params;
        let n = p.floor_normal;
        for (i, corners) in self.corners.iter().enumerate() {
            let rot = data.rot[i];
            let pos = data.pos[i];
            let (c, r) = self.bounds[i];
            if n.dot(pos + rot * c) - p.floor_height > r {
                state.anchors[i * 8..i * 8 + 8].fill(None);
                continue;
            }
            let v = data.v[i];
            let m = self.masses[i];
            for (k, &cl) in corners.iter().enumerate() {
                let x = pos + rot * cl;
                let z = n.dot(x) - p.floor_height;
                let slot = &mut state.anchors[i * 8 + k];
                if z >= 0.0 {
                    *slot = None;
                    continue;
                }
                let on_floor = x - n * z;
                match *slot {
                    None => *slot = Some(on_floor),
                    Some(a) => {
                        let xd = rot * (v.lin + v.ang.cross(cl));
                        let zd = n.dot(xd);
                        let fnorm =
                            (-p.stiffness_per_kg * m * z - p.damping_per_kg * m * zd).max(0.0);
                        let d = x - a;
                        let stretch = d - n * n.dot(d);
                        let max_stretch = p.friction * fnorm / (p.tangential_stiffness_per_kg * m);
                        let s = stretch.length();
                        if s > max_stretch {
                            let keep = if s > 0.0 { max_stretch / s } else { 0.0 };
                            *slot = Some(on_floor - stretch * keep);
                        }
                    }
                }
            }
        }
    }

    /// [`update_anchors`](Self::update_anchors) then [`apply`](Self::apply) in one pass over the
    /// corners (the step-start evaluation): same results, corner positions computed once; also
    /// writes each link's deepest corner penetration (m) into `depth`.
    pub fn update_and_apply(
        &self,
        data: &Data,
        state: &mut ContactState,
        f_ext: &mut [ForceVec],
        normal: &mut [f64],
        depth: &mut [f64],
    ) -> f64 {
        let p = &self.params;
        let n = p.floor_normal;
        let mut deepest: f64 = 0.0;
        for (i, corners) in self.corners.iter().enumerate() {
            normal[i] = 0.0;
            depth[i] = 0.0;
            let rot = data.rot[i];
            let pos = data.pos[i];
            let (c, r) = self.bounds[i];
            if n.dot(pos + rot * c) - p.floor_height > r {
                state.anchors[i * 8..i * 8 + 8].fill(None);
                continue;
            }
            let v = data.v[i];
            let m = self.masses[i];
            let mut f_body = ForceVec::ZERO;
            for (k, &cl) in corners.iter().enumerate() {
                let x = pos + rot * cl;
                let z = n.dot(x) - p.floor_height;
                let slot = &mut state.anchors[i * 8 + k];
                if z >= 0.0 {
                    *slot = None;
                    continue;
                }
                let xd = rot * (v.lin + v.ang.cross(cl));
                let on_floor = x - n * z;
                match *slot {
                    None => *slot = Some(on_floor),
                    Some(a) => {
                        let zd = n.dot(xd);
                        let fnorm =
                            (-p.stiffness_per_kg * m * z - p.damping_per_kg * m * zd).max(0.0);
                        let d = x - a;
                        let stretch = d - n * n.dot(d);
                        let max_stretch = p.friction * fnorm / (p.tangential_stiffness_per_kg * m);
                        let s = stretch.length();
                        if s > max_stretch {
                            let keep = if s > 0.0 { max_stretch / s } else { 0.0 };
                            *slot = Some(on_floor - stretch * keep);
                        }
                    }
                }
                if let Some((fnorm, ft, z)) = self.corner_force(i, x, xd, *slot) {
                    deepest = deepest.max(-z);
                    depth[i] = depth[i].max(-z);
                    normal[i] += fnorm;
                    let f_world = n * fnorm + ft;
                    f_body += ForceVec::at_point(rot.transpose() * f_world, cl);
                }
            }
            f_ext[i] += f_body;
        }
        deepest
    }

    /// An upper bound on the contact natural frequency of link `i` (rad/s) and its damping ratio:
    /// with `w = 1/m + max_c λ_max([r_c]×ᵀ I_c⁻¹ [r_c]×)` the largest inverse effective mass at a
    /// corner of the free link (the tree only adds mass), four corners down give
    /// `ω² ≤ 4 k w`, `2ζω ≤ 4 c w`.
    pub fn link_frequency(&self, i: usize, inertia: &crate::dynamics::spatial::Inertia) -> (f64, f64) {
        let p = &self.params;
        let iinv = inertia.inertia_com.inverse();
        let mut w: f64 = 0.0;
        for &cl in &self.corners[i] {
            let r = cl - inertia.com;
            let rx = crate::dynamics::spatial::skew(r);
            let a = rx.transpose() * iinv * rx;
            // λ_max of a symmetric PSD 3×3 by power iteration.
            let mut x = DVec3::new(1.0, 0.7, 0.3).normalize();
            let mut lam = 0.0;
            for _ in 0..50 {
                let y = a * x;
                lam = y.length();
                if lam == 0.0 {
                    break;
                }
                x = y / lam;
            }
            w = w.max(1.0 / inertia.mass + lam);
        }
        let m = inertia.mass;
        let k = p.stiffness_per_kg * m;
        let c = p.damping_per_kg * m;
        let omega = (4.0 * k * w).sqrt();
        let zeta = if omega > 0.0 {
            2.0 * c * w / omega
        } else {
            0.0
        };
        (omega, zeta)
    }
}
