//! Floor contact by penalty springs on the corners of each link's box (the paper's eq. 3.6)
//! with Coulomb friction.
//!
//! For a corner at signed height `z = n·x − h` (below the floor when `z < 0`) moving with
//! velocity `ẋ`: normal force `f_n = max(0, −k_p z − k_v ż)` (it never pulls); tangential force
//! from a spring–damper to an anchor point `a` on the floor, `f_t = −k_t (x − a)_t − c_t ẋ_t`,
//! clipped to the friction cone `|f_t| ≤ μ f_n`. The anchor is set where the corner first
//! touches and is dragged along when the spring would exceed the cone (slip), so a body below the
//! friction angle sticks (no creep) and one above it slides with `|f_t| = μ f_n`.
//!
//! The normal gains are per link, the effective stiffness `k` (N/m) and damping `c` (N·s/m) of
//! the body region the link is ([`ContactGains`]; for the human body the published values of
//! [`crate::humanoid::tissue`]), shared by the corners in contact: a corner carries `k/4` and
//! `c/4`, so a box face landing flat (four corners) meets exactly the region's `k` and `c`, an
//! edge half of it. The tangential (stick) spring and damper stay per kilogram of link mass:
//! they only hold a corner where it touched and are capped by the friction cone.

use crate::dynamics::data::Data;
use crate::dynamics::linearly_implicit;
use crate::dynamics::spatial::{ArticulatedInertia, ForceVec, transpose_mul};
use glam::{DMat3, DVec3};
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

/// The normal contact gains of one link: the effective stiffness and damping of its body
/// region, as a lumped spring–damper between the region and a rigid floor.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactGains {
    /// Effective normal stiffness `k` (N/m).
    pub stiffness_n_per_m: f64,
    /// Effective normal damping `c` (N·s/m).
    pub damping_n_s_per_m: f64,
}

impl ContactGains {
    /// Gains proportional to a link's mass `m` (kg): `k = k̂ m`, `c = ĉ m`, for bodies with no
    /// tissue data (test boxes).
    pub fn per_kg(mass: f64, stiffness_per_kg: f64, damping_per_kg: f64) -> Self {
        Self {
            stiffness_n_per_m: stiffness_per_kg * mass,
            damping_n_s_per_m: damping_per_kg * mass,
        }
    }
}

/// Floor and contact parameters shared by every link; each link's own normal gains are its
/// [`ContactGains`], multiplied by `stiffness_scale` and `damping_scale` (1 = as published).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactParams {
    /// Factor on every link's normal stiffness (1 = the published values).
    pub stiffness_scale: f64,
    /// Factor on every link's normal damping (1 = the published values).
    pub damping_scale: f64,
    /// Tangential (stick) stiffness per corner per kg of link mass (N/m/kg).
    pub tangential_stiffness_per_kg: f64,
    /// Tangential damping per corner per kg (N·s/m/kg).
    pub tangential_damping_per_kg: f64,
    /// Coulomb friction coefficient μ.
    pub friction: f64,
    /// Floor height `h` along the normal (m).
    pub floor_height: f64,
    /// Unit floor normal (world), `(0, 1, 0)` for a level floor.
    pub floor_normal: DVec3,
    /// Take each corner's normal damping implicitly in a semi-implicit Euler step (as the
    /// integrator's implicit joint damping): the damper acts with the step's end velocity,
    /// `−c ż'` with `ż' = ż + h z̈`, so per pushing corner the body meets
    /// `(M + h c j jᵀ) q̈ = … + f(z, ż)` (`j` the corner's normal Jacobian). The spring stays
    /// explicit (semi-implicit Euler keeps its frequency to `asin(ωh/2)/(ωh/2)`); the damper no
    /// longer narrows the stable step, `h ≤ 2/ω` instead of `2(√(1+ζ²) − ζ)/ω`. RK4 keeps
    /// the damping explicit.
    pub implicit_damping: bool,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            stiffness_scale: 1.0,
            damping_scale: 1.0,
            tangential_stiffness_per_kg: 2.0e4,
            tangential_damping_per_kg: 100.0,
            friction: 0.8,
            floor_height: 0.0,
            floor_normal: DVec3::Y,
            implicit_damping: false,
        }
    }
}

/// Two unit vectors that with the unit normal `n` make an orthonormal basis.
#[inline(always)]
fn tangents(n: DVec3) -> [DVec3; 2] {
    let a = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let t1 = (a - n * n.dot(a)).normalize();
    [t1, n.cross(t1)]
}

/// What a step takes implicitly of the floor's normal force, over a step of `h` seconds: its
/// damping ([`ContactParams::implicit_damping`]) and, with `stiffness`, its spring too
/// (`linearly_implicit`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitFloor {
    /// The step (s).
    pub h: f64,
    /// Take the spring implicitly too.
    pub stiffness: bool,
    /// The weight of the linearisation with the spring (`linearly_implicit::corner`: 1 at
    /// the step end, ½ at its midpoint); the damping alone is always taken at the step end.
    pub theta: f64,
}

/// One corner through the floor as its implicit terms need it: link `link`'s corner `cl`
/// (body coordinates), its velocity `xd` (world) and `zd` along the normal, its friction
/// spring's stretch, its friction force `ft`, and whether it has an anchor (`UPDATE` only).
struct CornerMotion {
    link: usize,
    cl: DVec3,
    xd: DVec3,
    zd: f64,
    stretch: DVec3,
    ft: DVec3,
    anchored: bool,
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
    /// Corners of each link's box, link frame, in [`LinkBox::corners`]' order (two values per
    /// axis, which the contact stage relies on; hence private: [`ContactModel::corners`]).
    corners: Vec<[DVec3; 8]>,
    /// Box centre (link frame) and bounding radius per link, for a quick rejection.
    pub bounds: Vec<(DVec3, f64)>,
    /// Link masses (kg), for the tangential gains.
    pub masses: Vec<f64>,
    /// Per link the normal stiffness and damping of one corner, `(k/4, c/4)` with the scales
    /// applied (N/m, N·s/m).
    pub corner_gains: Vec<(f64, f64)>,
    /// The parameters.
    pub params: ContactParams,
}

/// What the contact stage saw at one step start, per link: normal force (N), deepest corner
/// penetration (m), the power the normal forces take out of the body (W, `−Σ f_n ż`) and, where
/// the floor pushes, the vertical velocity of the box centre (m/s); and the deepest penetration
/// of any link (m).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ContactSample {
    /// Normal force per link (N).
    pub normal: Vec<f64>,
    /// Deepest corner penetration per link (m).
    pub depth: Vec<f64>,
    /// Power absorbed by the normal contact per link (W).
    pub absorbed_power: Vec<f64>,
    /// Velocity of each box centre along the floor normal (m/s) for the links the floor
    /// pushes (`normal > 0`, what a touchdown records); 0 for the others.
    pub center_normal_velocity: Vec<f64>,
    /// Deepest penetration of any link (m).
    pub penetration: f64,
}

impl ContactSample {
    /// Zeros for `nlinks` links.
    pub fn new(nlinks: usize) -> Self {
        Self {
            normal: vec![0.0; nlinks],
            depth: vec![0.0; nlinks],
            absorbed_power: vec![0.0; nlinks],
            center_normal_velocity: vec![0.0; nlinks],
            penetration: 0.0,
        }
    }
}

impl ContactModel {
    /// Contact model for `boxes` on links of `masses` (kg) with normal gains `gains`.
    pub fn new(
        boxes: &[LinkBox],
        masses: &[f64],
        gains: &[ContactGains],
        params: ContactParams,
    ) -> Self {
        Self {
            corners: boxes.iter().map(|b| b.corners()).collect(),
            bounds: boxes.iter().map(|b| (b.center, b.radius())).collect(),
            masses: masses.to_vec(),
            corner_gains: gains
                .iter()
                .map(|g| {
                    (
                        0.25 * g.stiffness_n_per_m * params.stiffness_scale,
                        0.25 * g.damping_n_s_per_m * params.damping_scale,
                    )
                })
                .collect(),
            params,
        }
    }

    /// The corners of each link's box in the link frame (m), in [`LinkBox::corners`]' order.
    pub fn corners(&self) -> &[[DVec3; 8]] {
        &self.corners
    }

    /// The static sink (m) of link `i` carrying `load` newtons flat on its four lower corners.
    pub fn static_sink(&self, i: usize, load: f64) -> f64 {
        load / (4.0 * self.corner_gains[i].0)
    }

    /// Normal and tangential force on one corner below the floor with velocity `xd`, its
    /// velocity along the floor normal `zd = n·ẋ` and its friction spring's stretch
    /// `stretch = (x − a)_t` (zero without an anchor), for link `link`'s mass and the corner's
    /// normal force `fnorm`: `f_t = −k_t m stretch − c_t m ẋ_t`, clipped to `|f_t| ≤ μ f_n`.
    #[inline(always)]
    fn tangential_force(
        &self,
        link: usize,
        xd: DVec3,
        zd: f64,
        stretch: DVec3,
        fnorm: f64,
    ) -> DVec3 {
        let p = &self.params;
        let n = p.floor_normal;
        let m = self.masses[link];
        let vt = xd - n * zd;
        let mut ft =
            -stretch * (p.tangential_stiffness_per_kg * m) - vt * (p.tangential_damping_per_kg * m);
        let cap = p.friction * fnorm;
        let l2 = ft.length_squared();
        if l2 > cap * cap {
            ft *= cap / l2.sqrt();
        }
        ft
    }

    /// The friction force of [`Self::tangential_force`] before the cone's clip.
    #[inline(always)]
    fn stuck_force(&self, link: usize, xd: DVec3, zd: f64, stretch: DVec3) -> DVec3 {
        let p = &self.params;
        let m = self.masses[link];
        let vt = xd - p.floor_normal * zd;
        -stretch * (p.tangential_stiffness_per_kg * m) - vt * (p.tangential_damping_per_kg * m)
    }

    /// The contact force of link `i` (body coordinates), its total normal force (N) and its
    /// deepest corner penetration (m, ≥ 0) for the state in `data`, with the friction anchors
    /// `anchors` (its 8 corners). With `UPDATE` the anchors are first brought to this state: a
    /// corner that left the floor loses its anchor, a new contact anchors where it touches, and a
    /// corner whose spring would leave the friction cone drags its anchor to the cone's edge
    /// (slip). Also returns the power the normal forces absorb (W). With `implicit = Some((f,
    /// ic))` each pushing corner's normal damper is taken implicitly over the step `f.h`
    /// ([`ContactParams::implicit_damping`]): `ic` (body coordinates) gains `h c j jᵀ`,
    /// `j = [p × n; n]` the floor normal as a unit force at the corner `p`; with
    /// `f.stiffness` its spring too: `ic` gains `h (c + h k) j jᵀ` and the force `−h k ż j`
    /// ([`linearly_implicit::corner`]), and a sticking corner's friction spring and damper
    /// the same along both floor tangents.
    #[inline(always)]
    fn link_contact<const UPDATE: bool>(
        &self,
        data: &Data,
        i: usize,
        anchors: &mut [Option<DVec3>],
        mut implicit: Option<(ImplicitFloor, &mut ArticulatedInertia)>,
    ) -> (ForceVec, f64, f64, f64) {
        let p = &self.params;
        let n = p.floor_normal;
        let rot = data.rot[i];
        let pos = data.pos[i];
        let (c, r) = self.bounds[i];
        // Heights through the floor normal in body coordinates: `z = n·pos − h + n_b·p` for a
        // body point `p`, three products a corner instead of a rotation.
        let n_body = transpose_mul(&rot, n);
        let z_origin = n.dot(pos) - p.floor_height;
        if z_origin + n_body.dot(c) > r {
            if UPDATE {
                anchors.fill(None);
            }
            return (ForceVec::ZERO, 0.0, 0.0, 0.0);
        }
        let v = data.v[i];
        let m = self.masses[i];
        let (k_c, c_c) = self.corner_gains[i];
        let (mut f_body, mut normal, mut depth, mut power) = (ForceVec::ZERO, 0.0, 0.0f64, 0.0);
        // A box's corners take two values per axis (`LinkBox::corners`): their products with
        // the normal once per axis, summed as `n_b·p` sums them.
        let cs = &self.corners[i];
        let px = [n_body.x * cs[0].x, n_body.x * cs[1].x];
        let py = [n_body.y * cs[0].y, n_body.y * cs[2].y];
        let pz = [n_body.z * cs[0].z, n_body.z * cs[4].z];
        for (k, &cl) in cs.iter().enumerate() {
            let z = z_origin + ((px[k & 1] + py[(k >> 1) & 1]) + pz[k >> 2]);
            if z >= 0.0 {
                if UPDATE {
                    anchors[k] = None;
                }
                continue;
            }
            let x = pos + rot * cl;
            let xd = rot * (v.lin + v.ang.cross(cl));
            let zd = n.dot(xd);
            let fnorm = (-k_c * z - c_c * zd).max(0.0);
            let stretch = self.corner_stretch::<UPDATE>(&mut anchors[k], x, z, fnorm, m);
            let ft = self.tangential_force(i, xd, zd, stretch, fnorm);
            depth = depth.max(-z);
            normal += fnorm;
            power -= fnorm * zd;
            let f_world = n * fnorm + ft;
            f_body += ForceVec::at_point(rot.transpose() * f_world, cl);
            if let Some((imp, ic)) = implicit.as_mut()
                && fnorm > 0.0
            {
                let corner = CornerMotion {
                    link: i,
                    cl,
                    xd,
                    zd,
                    stretch,
                    ft,
                    anchored: UPDATE && anchors[k].is_some(),
                };
                self.implicit_corner(*imp, ic, &rot, &corner, &mut f_body);
            }
        }
        (f_body, normal, depth, power)
    }

    /// The friction spring's stretch `(x − a)_t` of a corner at `x`, `z` through the floor
    /// (`z < 0`), toward its anchor `a`, for link mass `m` and the corner's normal force
    /// `fnorm` (zero without an anchor). With `UPDATE` the anchor is first brought to this
    /// state: a new contact anchors where it touches, and a spring that would leave the
    /// friction cone (`k_t m |stretch| > μ f_n`) drags its anchor to the cone's edge (slip).
    #[inline(always)]
    fn corner_stretch<const UPDATE: bool>(
        &self,
        anchor: &mut Option<DVec3>,
        x: DVec3,
        z: f64,
        fnorm: f64,
        m: f64,
    ) -> DVec3 {
        let p = &self.params;
        let n = p.floor_normal;
        // The friction spring's stretch `(x − a)_t` toward anchor `a`.
        let stretch_to = |x: DVec3, a: DVec3| {
            let d = x - a;
            d - n * n.dot(d)
        };
        match *anchor {
            Some(a) if UPDATE => {
                let stretch = stretch_to(x, a);
                let max_stretch = p.friction * fnorm / (p.tangential_stiffness_per_kg * m);
                let s = stretch.length();
                if s > max_stretch {
                    // Slip: the anchor is dragged to the cone's edge.
                    let keep = if s > 0.0 { max_stretch / s } else { 0.0 };
                    let a = (x - n * z) - stretch * keep;
                    *anchor = Some(a);
                    stretch_to(x, a)
                } else {
                    stretch
                }
            }
            Some(a) => stretch_to(x, a),
            None if UPDATE => {
                // A new contact anchors where it touches.
                let a = x - n * z;
                *anchor = Some(a);
                stretch_to(x, a)
            }
            None => DVec3::ZERO,
        }
    }

    /// A pushing corner's dampers (and springs) taken implicitly over the step `imp.h`
    /// ([`ContactParams::implicit_damping`]): `ic` gains `h c j jᵀ`, `j = [p × n; n]` the floor
    /// normal as a unit force at the corner `p`; with `imp.stiffness`, `ic` gains
    /// `h (c + h k) j jᵀ` and `f_body` the force `−h k ż j` ([`linearly_implicit::corner`]),
    /// and a sticking corner's friction spring and damper the same along both floor tangents.
    #[inline(always)]
    fn implicit_corner(
        &self,
        imp: ImplicitFloor,
        ic: &mut ArticulatedInertia,
        rot: &DMat3,
        corner: &CornerMotion,
        f_body: &mut ForceVec,
    ) {
        let p = &self.params;
        let n = p.floor_normal;
        let &CornerMotion {
            link,
            cl,
            xd,
            zd,
            stretch,
            ft,
            anchored,
        } = corner;
        let m = self.masses[link];
        let (k_c, c_c) = self.corner_gains[link];
        let j = ForceVec::at_point(rot.transpose() * n, cl);
        if imp.stiffness {
            // I + h (c + h k) j jᵀ, and the force at the step end's position.
            let (w, df) = linearly_implicit::corner(imp.h, imp.theta, k_c, c_c, zd);
            ic.sub_outer(j, -w);
            *f_body += j * df;
            // A sticking corner's friction spring and damper along both tangents, the same
            // way (a slipping one's force is the cone's, not linearised).
            if anchored && ft == self.stuck_force(link, xd, zd, stretch) {
                let (kt, ct) = (
                    p.tangential_stiffness_per_kg * m,
                    p.tangential_damping_per_kg * m,
                );
                for t in tangents(n) {
                    let jt = ForceVec::at_point(rot.transpose() * t, cl);
                    let (w, df) = linearly_implicit::corner(imp.h, imp.theta, kt, ct, t.dot(xd));
                    ic.sub_outer(jt, -w);
                    *f_body += jt * df;
                }
            }
        } else {
            // I + h c j jᵀ.
            ic.sub_outer(j, -imp.h * c_c);
        }
    }

    /// Adds the contact force of every link to `f_ext` (body coordinates) after
    /// [`kinematics`](crate::dynamics::kinematics::kinematics), with the anchors of `state` as
    /// they are; writes each link's total normal force (N) into `normal` and returns the
    /// deepest penetration (m, ≥ 0). Used at every evaluation inside a step.
    pub fn apply(
        &self,
        data: &Data,
        state: &ContactState,
        f_ext: &mut [ForceVec],
        normal: &mut [f64],
    ) -> f64 {
        let mut deepest: f64 = 0.0;
        for i in 0..self.corners.len() {
            let mut anchors = [None; 8];
            anchors.copy_from_slice(&state.anchors[i * 8..i * 8 + 8]);
            let (f, fn_i, d, _) = self.link_contact::<false>(data, i, &mut anchors, None);
            normal[i] = fn_i;
            deepest = deepest.max(d);
            f_ext[i] += f;
        }
        deepest
    }

    /// The step-start evaluation: updates the friction anchors for the state in `data` (once
    /// per step), then does what [`apply`](Self::apply) does, writing what each link felt into
    /// `sample` (the force law at this state).
    pub fn update_and_apply(
        &self,
        data: &Data,
        state: &mut ContactState,
        f_ext: &mut [ForceVec],
        sample: &mut ContactSample,
    ) {
        self.update_and_apply_implicit(data, state, f_ext, sample, None);
    }

    /// [`update_and_apply`](Self::update_and_apply) with the normal force taken implicitly
    /// as `implicit = Some((f, added))` says ([`ImplicitFloor`]: the damping, and with
    /// `f.stiffness` the spring too): `added` is cleared, then holds per touching link
    /// its implicit inertia `Σ h c j jᵀ` or `Σ h (c + h k) j jᵀ` (body coordinates) for
    /// [`aba_passes`](crate::dynamics::aba::aba_passes); `f_ext` gets the forces at the state
    /// (with the spring, plus each pushing corner's `−h k ż j`).
    #[inline(always)]
    pub fn update_and_apply_implicit(
        &self,
        data: &Data,
        state: &mut ContactState,
        f_ext: &mut [ForceVec],
        sample: &mut ContactSample,
        mut implicit: Option<(ImplicitFloor, &mut Vec<(usize, ArticulatedInertia)>)>,
    ) {
        let mut deepest: f64 = 0.0;
        let n = self.params.floor_normal;
        if let Some((_, added)) = implicit.as_mut() {
            added.clear();
        }
        for i in 0..self.corners.len() {
            let anchors = &mut state.anchors[i * 8..i * 8 + 8];
            let (f, fn_i, d, power) = match implicit.as_mut() {
                Some((h, added)) => {
                    let mut ic = ArticulatedInertia::ZERO;
                    let out = self.link_contact::<true>(data, i, anchors, Some((*h, &mut ic)));
                    if ic != ArticulatedInertia::ZERO {
                        added.push((i, ic));
                    }
                    out
                }
                None => self.link_contact::<true>(data, i, anchors, None),
            };
            sample.normal[i] = fn_i;
            sample.depth[i] = d;
            sample.absorbed_power[i] = power;
            // Only a link the floor pushes can touch down (`ContactStats::accumulate`).
            sample.center_normal_velocity[i] = if fn_i > 0.0 {
                let (c, _) = self.bounds[i];
                let v = data.v[i];
                n.dot(data.rot[i] * (v.lin + v.ang.cross(c)))
            } else {
                0.0
            };
            deepest = deepest.max(d);
            f_ext[i] += f;
        }
        sample.penetration = deepest;
    }

    /// An upper bound on the contact natural frequency of link `i` (rad/s) and its damping ratio:
    /// with `w = 1/m + max_c λ_max([r_c]×ᵀ I_c⁻¹ [r_c]×)` the largest inverse effective mass at a
    /// corner of the free link (the tree only adds mass), four corners down give
    /// `ω² ≤ 4 k w`, `2ζω ≤ 4 c w`.
    pub fn link_frequency(
        &self,
        i: usize,
        inertia: &crate::dynamics::spatial::Inertia,
    ) -> (f64, f64) {
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
        let (k, c) = self.corner_gains[i];
        let omega = (4.0 * k * w).sqrt();
        let zeta = if omega > 0.0 {
            2.0 * c * w / omega
        } else {
            0.0
        };
        (omega, zeta)
    }
}

/// What the floor did to each link over a run: peak normal force (N), normal impulse (N·s),
/// deepest corner penetration (m), the first touchdown (time, and the box centre's velocity
/// along the normal then, m/s, negative when moving into the floor), the energy the normal
/// contact absorbed (J, `∫ −Σ f_n ż dt`: the spring's stored energy comes back, so this is what
/// the damping dissipated plus what is still stored), and the deepest penetration of any link
/// (m). The paper's damage (eq. 5.1) weighs the peaks.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct ContactStats {
    /// Peak normal force per link (N).
    pub peak: Vec<f64>,
    /// Normal impulse per link (N·s).
    pub impulse: Vec<f64>,
    /// Deepest penetration per link (m).
    pub max_depth: Vec<f64>,
    /// Time of the first step start at which the link touched (s).
    pub touchdown_s: Vec<Option<f64>>,
    /// Box-centre velocity along the floor normal at touchdown (m/s).
    pub touchdown_velocity: Vec<f64>,
    /// Energy absorbed by the normal contact per link (J).
    pub absorbed_j: Vec<f64>,
    /// Deepest penetration of any link (m).
    pub max_penetration: f64,
}

impl ContactStats {
    /// Zeros for `nlinks` links.
    pub fn new(nlinks: usize) -> Self {
        Self {
            peak: vec![0.0; nlinks],
            impulse: vec![0.0; nlinks],
            max_depth: vec![0.0; nlinks],
            touchdown_s: vec![None; nlinks],
            touchdown_velocity: vec![0.0; nlinks],
            absorbed_j: vec![0.0; nlinks],
            max_penetration: 0.0,
        }
    }

    /// Accounts for one step of `dt` seconds starting at time `t` (s) whose start saw `sample`.
    #[inline(always)]
    pub fn accumulate(&mut self, sample: &ContactSample, t: f64, dt: f64) {
        for i in 0..sample.normal.len() {
            let f = sample.normal[i];
            if f == 0.0 && sample.depth[i] == 0.0 && sample.absorbed_power[i] == 0.0 {
                // A link off the floor adds nothing (the same bits as adding its zeros).
                continue;
            }
            self.peak[i] = self.peak[i].max(f);
            self.impulse[i] += f * dt;
            self.max_depth[i] = self.max_depth[i].max(sample.depth[i]);
            self.absorbed_j[i] += sample.absorbed_power[i] * dt;
            if f > 0.0 && self.touchdown_s[i].is_none() {
                self.touchdown_s[i] = Some(t);
                self.touchdown_velocity[i] = sample.center_normal_velocity[i];
            }
        }
        self.max_penetration = self.max_penetration.max(sample.penetration);
    }
}
