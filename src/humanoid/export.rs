use std::fmt::Write;

use glam::{DMat3, DVec3};

use crate::dynamics::JointType;
use crate::humanoid::body::HumanBody;

fn v3(v: DVec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

fn inertia_urdf(i: DMat3) -> String {
    format!(
        "ixx=\"{}\" ixy=\"{}\" ixz=\"{}\" iyy=\"{}\" iyz=\"{}\" izz=\"{}\"",
        i.x_axis.x, i.y_axis.x, i.z_axis.x, i.y_axis.y, i.z_axis.y, i.z_axis.z
    )
}

/// The revolute axes of body `b`'s joint, one per DOF, with the DOF names.
fn revolutes(body: &HumanBody, b: usize) -> Vec<(String, DVec3)> {
    let j = &body.figure.joints[b];
    let axes: Vec<DVec3> = match body.model.bodies()[b].joint {
        JointType::Pin { axis } => vec![axis],
        JointType::Universal { axis1, axis2 } => vec![axis1, axis2],
        JointType::Ball { axes } => vec![axes.x_axis, axes.y_axis, axes.z_axis],
        JointType::Free | JointType::Fixed => vec![],
    };
    j.dofs
        .iter()
        .zip(axes)
        .map(|(&d, a)| (body.figure.dofs[d].name.clone(), a))
        .collect()
}

/// The body as URDF. `ranges` and `strength` are per fall21 DOF (rad, N·m).
pub fn to_urdf(body: &HumanBody, ranges: &[(f64, f64)], strength: &[(f64, f64)]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<!-- fall21 human ({:.3} m, {:.2} kg) written by marionette. Frame: Y up, facing +Z, left +X; \
         load with a free-flyer root and gravity (0, -g, 0). -->",
        body.figure.height,
        body.model.total_mass()
    );
    let _ = writeln!(s, "<robot name=\"fall21\">");
    let dof_index = |name: &str| body.figure.dof_index(name).unwrap_or(0);
    for (b, mb) in body.model.bodies().iter().enumerate() {
        let i = &mb.inertia;
        let bx = &body.boxes[b];
        let _ = writeln!(s, "  <link name=\"{}\">", mb.name);
        let _ = writeln!(
            s,
            "    <inertial><origin xyz=\"{}\" rpy=\"0 0 0\"/><mass value=\"{}\"/><inertia {}/></inertial>",
            v3(i.com),
            i.mass,
            inertia_urdf(i.inertia_com)
        );
        let _ = writeln!(
            s,
            "    <collision><origin xyz=\"{}\" rpy=\"0 0 0\"/><geometry><box size=\"{}\"/></geometry></collision>",
            v3(bx.center),
            v3(bx.half * 2.0)
        );
        let _ = writeln!(s, "  </link>");
        let Some(parent) = mb.parent else { continue };
        let offset = body.figure.joints[b].offset;
        let revs = revolutes(body, b);
        let mut from = body.model.bodies()[parent].name.clone();
        if matches!(mb.joint, JointType::Fixed) {
            let _ = writeln!(
                s,
                "  <joint name=\"{}\" type=\"fixed\"><parent link=\"{from}\"/><child link=\"{}\"/>\
                 <origin xyz=\"{}\" rpy=\"0 0 0\"/></joint>",
                mb.joint_name,
                mb.name,
                v3(offset)
            );
        }
        for (k, (dof, axis)) in revs.iter().enumerate() {
            let last = k + 1 == revs.len();
            let to = if last {
                mb.name.clone()
            } else {
                format!("{}_{}", mb.joint_name, k + 1)
            };
            if !last {
                let _ = writeln!(s, "  <link name=\"{to}\"/>");
            }
            let d = dof_index(dof);
            let (lo, hi) = ranges[d];
            let effort = strength[d].0.abs().max(strength[d].1.abs());
            let origin = if k == 0 { offset } else { DVec3::ZERO };
            let _ = writeln!(
                s,
                "  <joint name=\"{dof}\" type=\"revolute\"><parent link=\"{from}\"/><child link=\"{to}\"/>\
                 <origin xyz=\"{}\" rpy=\"0 0 0\"/><axis xyz=\"{}\"/>\
                 <limit lower=\"{lo}\" upper=\"{hi}\" effort=\"{effort}\" velocity=\"20\"/></joint>",
                v3(origin),
                v3(*axis)
            );
            from = to;
        }
    }
    let _ = writeln!(s, "</robot>");
    s
}

/// The body as MJCF (MuJoCo). `ranges` are per fall21 DOF (rad); the ball joint's range is not
/// written (MuJoCo limits a ball by one cone angle, the engine per component). The boxes collide
/// with the floor only, as in the engine (no self-contact).
pub fn to_mjcf(body: &HumanBody, ranges: &[(f64, f64)], gravity: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "<!-- fall21 human ({:.3} m, {:.2} kg) written by marionette. Frame: Y up, facing +Z, left +X. -->",
        body.figure.height,
        body.model.total_mass()
    );
    let _ = writeln!(s, "<mujoco model=\"fall21\">");
    let _ = writeln!(
        s,
        "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>"
    );
    let _ = writeln!(s, "  <option gravity=\"0 {} 0\"/>", -gravity);
    let _ = writeln!(s, "  <worldbody>");
    let _ = writeln!(
        s,
        "    <geom name=\"floor\" type=\"plane\" size=\"10 10 0.1\" contype=\"0\" conaffinity=\"1\" quat=\"0.7071067811865476 -0.7071067811865476 0 0\"/>"
    );
    write_mjcf_body(&mut s, body, 0, ranges, 0);
    let _ = writeln!(s, "  </worldbody>");
    let _ = writeln!(s, "</mujoco>");
    s
}

/// Body `b` of `body` as an MJCF `<body>` at nesting `depth` (its inertial, joints and box),
/// its children inside.
fn write_mjcf_body(
    s: &mut String,
    body: &HumanBody,
    b: usize,
    ranges: &[(f64, f64)],
    depth: usize,
) {
    let pad = "  ".repeat(depth + 2);
    let mb = &body.model.bodies()[b];
    let pos = if mb.parent.is_some() {
        body.figure.joints[b].offset
    } else {
        DVec3::ZERO
    };
    let _ = writeln!(s, "{pad}<body name=\"{}\" pos=\"{}\">", mb.name, v3(pos));
    let i = &mb.inertia;
    let c = i.inertia_com;
    let _ = writeln!(
        s,
        "{pad}  <inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{} {} {} {} {} {}\"/>",
        v3(i.com),
        i.mass,
        c.x_axis.x,
        c.y_axis.y,
        c.z_axis.z,
        c.y_axis.x,
        c.z_axis.x,
        c.z_axis.y
    );
    match mb.joint {
        JointType::Free => {
            let _ = writeln!(s, "{pad}  <freejoint name=\"{}\"/>", mb.joint_name);
        }
        JointType::Ball { .. } => {
            let _ = writeln!(
                s,
                "{pad}  <joint name=\"{}\" type=\"ball\" limited=\"false\"/>",
                mb.joint_name
            );
        }
        _ => {
            for (dof, axis) in revolutes(body, b) {
                let d = body.figure.dof_index(&dof).unwrap_or(0);
                let (lo, hi) = ranges[d];
                let _ = writeln!(
                    s,
                    "{pad}  <joint name=\"{dof}\" type=\"hinge\" axis=\"{}\" range=\"{lo} {hi}\" limited=\"true\"/>",
                    v3(axis)
                );
            }
        }
    }
    let bx = &body.boxes[b];
    let _ = writeln!(
        s,
        "{pad}  <geom name=\"{}_box\" type=\"box\" pos=\"{}\" size=\"{}\" contype=\"1\" conaffinity=\"0\"/>",
        mb.name,
        v3(bx.center),
        v3(bx.half)
    );
    for (k, child) in body.model.bodies().iter().enumerate() {
        if child.parent == Some(b) {
            write_mjcf_body(s, body, k, ranges, depth + 1);
        }
    }
    let _ = writeln!(s, "{pad}</body>");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::humanoid::ranges::{AgeGroup, RangeTable};

    #[test]
    fn the_files_name_every_dof_once_and_carry_the_whole_mass() {
        let b = crate::humanoid::body::fall21_body(1.70, 65.0, 9.81).unwrap();
        let r = RangeTable::builtin(AgeGroup::Elderly)
            .for_figure(&b.figure)
            .unwrap();
        let t = crate::humanoid::strength::torque_limits(AgeGroup::Elderly);
        let urdf = to_urdf(&b, &r, &t);
        let mjcf = to_mjcf(&b, &r, 9.81);
        for d in b.figure.dof_names() {
            assert_eq!(
                urdf.matches(&format!("<joint name=\"{d}\"")).count(),
                1,
                "{d}"
            );
            if !d.starts_with("neck") {
                assert_eq!(
                    mjcf.matches(&format!("<joint name=\"{d}\"")).count(),
                    1,
                    "{d}"
                );
            }
        }
        let mass: f64 = urdf
            .split("<mass value=\"")
            .skip(1)
            .map(|x| x.split('"').next().unwrap().parse::<f64>().unwrap())
            .sum();
        assert!((mass - 65.0).abs() < 1e-9, "{mass}");
        assert_eq!(mjcf.matches("<body ").count(), 15);
        assert_eq!(
            mjcf.matches("<body ").count(),
            mjcf.matches("</body>").count()
        );
    }
}
