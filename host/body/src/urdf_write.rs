//! Plain URDF records back to URDF text.
//!
//! What: [`write_urdf`] writes a [`RawRobot`] as a URDF document that
//! [`crate::urdf_xml::read_robot`] reads back to the same records.
//!
//! Why: a composed robot ([`crate::compose`]) must be a file that every URDF
//! tool, and a SetRobot request, can read.
//!
//! How: one element per record, numbers in Rust's shortest round-trip form
//! (so reading the text back gives the same `f64`), names and file names
//! XML-escaped. What the records do not hold (materials, transmissions,
//! `<gazebo>` tags) is not written.
//!
//! ```
//! use tsukami_body::urdf_xml::{read_robot, Diagnostics};
//! use tsukami_body::urdf_write::write_urdf;
//! let xml = r#"<robot name="r"><link name="a"/><link name="b"/>
//!   <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
//!   <origin xyz="0.1 0 0" rpy="0 0 1.5"/><axis xyz="0 0 1"/>
//!   <limit lower="-1" upper="1" effort="2" velocity="3"/></joint></robot>"#;
//! let mut d = Diagnostics::new("r.urdf".into(), false);
//! let robot = read_robot(xml, &mut d, &Default::default()).unwrap();
//! let again = read_robot(&write_urdf(&robot), &mut d, &Default::default()).unwrap();
//! assert_eq!(robot, again);
//! ```

use std::fmt::Write;

use crate::urdf_xml::{RawElement, RawJoint, RawLink, RawPose, RawRobot, RawShape};

/// The URDF text of `robot`.
pub fn write_urdf(robot: &RawRobot) -> String {
    let mut out = String::from("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(out, "<robot name=\"{}\">", esc(&robot.name));
    for link in &robot.links {
        write_link(&mut out, link);
    }
    for joint in &robot.joints {
        write_joint(&mut out, joint);
    }
    out.push_str("</robot>\n");
    out
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn nums(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x:?}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn origin(out: &mut String, indent: &str, p: &RawPose) {
    if *p != RawPose::default() {
        let _ = writeln!(
            out,
            "{indent}<origin xyz=\"{}\" rpy=\"{}\"/>",
            nums(&p.xyz),
            nums(&p.rpy)
        );
    }
}

fn element(out: &mut String, tag: &str, e: &RawElement) {
    match &e.name {
        Some(n) => {
            let _ = writeln!(out, "    <{tag} name=\"{}\">", esc(n));
        }
        None => {
            let _ = writeln!(out, "    <{tag}>");
        }
    }
    origin(out, "      ", &e.origin);
    let shape = match &e.shape {
        RawShape::Box(s) => format!("<box size=\"{}\"/>", nums(s)),
        RawShape::Cylinder(r, l) => format!("<cylinder radius=\"{r:?}\" length=\"{l:?}\"/>"),
        RawShape::Capsule(r, l) => format!("<capsule radius=\"{r:?}\" length=\"{l:?}\"/>"),
        RawShape::Sphere(r) => format!("<sphere radius=\"{r:?}\"/>"),
        RawShape::Mesh(file, scale) => format!(
            "<mesh filename=\"{}\" scale=\"{}\"/>",
            esc(file),
            nums(scale)
        ),
    };
    let _ = writeln!(out, "      <geometry>{shape}</geometry>");
    let _ = writeln!(out, "    </{tag}>");
}

fn write_link(out: &mut String, l: &RawLink) {
    let _ = writeln!(out, "  <link name=\"{}\">", esc(&l.name));
    if let Some(i) = &l.inertial {
        out.push_str("    <inertial>\n");
        origin(out, "      ", &i.origin);
        let _ = writeln!(out, "      <mass value=\"{:?}\"/>", i.mass);
        let [xx, xy, xz, yy, yz, zz] = i.inertia;
        let _ = writeln!(
            out,
            "      <inertia ixx=\"{xx:?}\" ixy=\"{xy:?}\" ixz=\"{xz:?}\" iyy=\"{yy:?}\" iyz=\"{yz:?}\" izz=\"{zz:?}\"/>"
        );
        out.push_str("    </inertial>\n");
    }
    for v in &l.visuals {
        element(out, "visual", v);
    }
    for c in &l.collisions {
        element(out, "collision", c);
    }
    out.push_str("  </link>\n");
}

fn write_joint(out: &mut String, j: &RawJoint) {
    let _ = writeln!(
        out,
        "  <joint name=\"{}\" type=\"{}\">",
        esc(&j.name),
        esc(&j.kind)
    );
    let _ = writeln!(out, "    <parent link=\"{}\"/>", esc(&j.parent));
    let _ = writeln!(out, "    <child link=\"{}\"/>", esc(&j.child));
    origin(out, "    ", &j.origin);
    let _ = writeln!(out, "    <axis xyz=\"{}\"/>", nums(&j.axis));
    if let Some(l) = &j.limit {
        let mut attrs = String::new();
        for (name, v) in [
            ("lower", l.lower),
            ("upper", l.upper),
            ("effort", l.effort),
            ("velocity", l.velocity),
        ] {
            if let Some(v) = v {
                let _ = write!(attrs, " {name}=\"{v:?}\"");
            }
        }
        let _ = writeln!(out, "    <limit{attrs}/>");
    }
    if let Some(m) = &j.mimic {
        let _ = writeln!(
            out,
            "    <mimic joint=\"{}\" multiplier=\"{:?}\" offset=\"{:?}\"/>",
            esc(&m.joint),
            m.multiplier,
            m.offset
        );
    }
    out.push_str("  </joint>\n");
}
