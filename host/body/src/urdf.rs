//! URDF loading: parse with `urdf-rs`, validate every number, resolve mesh
//! paths, load meshes, and order the tree topologically.
//!
//! ```no_run
//! let robot = tsukami_body::urdf::load_urdf(
//!     "models/robots/tsukami_humanoid/tsukami_humanoid.urdf".as_ref()).unwrap();
//! println!("{} links", robot.links.len());
//! ```
//!
//! # Tolerated quirks
//! `urdf-rs` 0.10 rejects two things that real-world URDFs often contain and
//! that do not affect kinematics or collision: a `<texture/>` without a
//! `filename` and a `<material>` without a `name`. Before parsing, such
//! `<texture>` elements are removed and such `<material>` elements get an empty
//! name (see [`tolerate_quirks`]). Everything else is strict: errors name the
//! file and the element.
//!
//! # Mesh paths
//! `package://PKG/rest` resolves to `DIR/rest` for the nearest ancestor `DIR`
//! of the URDF's folder named `PKG` (or `DIR/PKG/rest` where that exists);
//! `file:///abs` to `/abs`; other paths are relative to the URDF's folder.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use crate::error::{BodyError, Result};
use crate::mesh::TriangleMesh;
use crate::model::{
    Geometry, GeometryElement, Inertial, Joint, JointKind, JointLimits, Link, Mimic, RobotModel,
};

/// Loads and validates a URDF file.
pub fn load_urdf(path: &Path) -> Result<RobotModel> {
    let xml = std::fs::read_to_string(path).map_err(|source| BodyError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_urdf(&xml, path)
}

/// Parses URDF text as if read from `path` (used for error messages and to
/// resolve relative mesh paths).
pub fn parse_urdf(xml: &str, path: &Path) -> Result<RobotModel> {
    let xml = tolerate_quirks(xml);
    // urdf-rs may panic on some malformed inputs in its pre-processing; a
    // panic must not escape to the caller.
    let parsed = std::panic::catch_unwind(|| urdf_rs::read_from_string(&xml));
    let robot = match parsed {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            return Err(BodyError::Urdf {
                file: path.to_path_buf(),
                message: e.to_string(),
            })
        }
        Err(_) => {
            return Err(BodyError::Urdf {
                file: path.to_path_buf(),
                message: "the URDF parser failed on this input".into(),
            })
        }
    };
    Builder {
        file: path.to_path_buf(),
        base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        meshes: HashMap::new(),
    }
    .build(robot)
}

/// Removes `<texture>` elements without a `filename` and gives `<material>`
/// elements without a `name` an empty one, so `urdf-rs` accepts them.
pub fn tolerate_quirks(xml: &str) -> Cow<'_, str> {
    if !xml.contains("<texture") && !xml.contains("<material") {
        return Cow::Borrowed(xml);
    }
    let mut out = String::with_capacity(xml.len() + 64);
    let mut rest = xml;
    while let Some(start) = rest.find('<') {
        out.push_str(&rest[..start]);
        rest = &rest[start..];
        let Some(end) = rest.find('>') else { break };
        let tag = &rest[..=end];
        let name_end = tag[1..]
            .find(|c: char| c.is_whitespace() || c == '>' || c == '/')
            .map_or(tag.len(), |i| i + 1);
        let tag_name = &tag[1..name_end];
        if tag_name == "texture" && !has_attr(tag, "filename") {
            rest = &rest[end + 1..];
            if !tag.ends_with("/>") {
                // Skip up to and including the closing tag.
                match rest.find("</texture>") {
                    Some(close) => rest = &rest[close + "</texture>".len()..],
                    None => rest = "",
                }
            }
            continue;
        }
        if tag_name == "material" && !has_attr(tag, "name") {
            out.push_str("<material name=\"\"");
            out.push_str(&tag[name_end..]);
        } else {
            out.push_str(tag);
        }
        rest = &rest[end + 1..];
    }
    out.push_str(rest);
    Cow::Owned(out)
}

fn has_attr(tag: &str, attr: &str) -> bool {
    tag.match_indices(attr).any(|(i, _)| {
        let before = tag[..i].chars().last();
        let after = tag[i + attr.len()..].trim_start().chars().next();
        before.is_some_and(char::is_whitespace) && after == Some('=')
    })
}

struct Builder {
    file: PathBuf,
    base_dir: PathBuf,
    meshes: HashMap<(PathBuf, [u64; 3]), Arc<TriangleMesh>>,
}

impl Builder {
    fn invalid(&self, element: impl Into<String>, message: impl Into<String>) -> BodyError {
        BodyError::Invalid {
            file: self.file.clone(),
            element: element.into(),
            message: message.into(),
        }
    }

    fn finite(&self, element: &str, values: &[f64]) -> Result<()> {
        if values.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(self.invalid(element, format!("non-finite value in {values:?}")))
        }
    }

    fn pose(&self, element: &str, p: &urdf_rs::Pose) -> Result<Isometry3<f64>> {
        self.finite(&format!("{element} origin xyz"), &p.xyz.0)?;
        self.finite(&format!("{element} origin rpy"), &p.rpy.0)?;
        Ok(Isometry3::from_parts(
            Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
            UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
        ))
    }

    fn build(mut self, robot: urdf_rs::Robot) -> Result<RobotModel> {
        // Names must be unique.
        let mut link_of: HashMap<&str, usize> = HashMap::new();
        for (i, l) in robot.links.iter().enumerate() {
            if link_of.insert(l.name.as_str(), i).is_some() {
                return Err(self.invalid(format!("link '{}'", l.name), "duplicate link name"));
            }
        }
        if robot.links.is_empty() {
            return Err(self.invalid("robot", "the robot has no links"));
        }
        let mut joint_of: HashMap<&str, usize> = HashMap::new();
        for (i, j) in robot.joints.iter().enumerate() {
            if joint_of.insert(j.name.as_str(), i).is_some() {
                return Err(self.invalid(format!("joint '{}'", j.name), "duplicate joint name"));
            }
        }
        // Parent / child links exist; each link has at most one parent.
        let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
        for (ji, j) in robot.joints.iter().enumerate() {
            let find = |role: &'static str, name: &str| {
                link_of
                    .get(name)
                    .copied()
                    .ok_or_else(|| BodyError::UnknownLinkInJoint {
                        file: self.file.clone(),
                        joint: j.name.clone(),
                        role,
                        link: name.to_string(),
                    })
            };
            let p = find("parent", &j.parent.link)?;
            let c = find("child", &j.child.link)?;
            if p == c {
                return Err(BodyError::Loop {
                    file: self.file.clone(),
                    message: format!(
                        "joint '{}' connects link '{}' to itself",
                        j.name, j.parent.link
                    ),
                });
            }
            if let Some(other) = parent_joint[c] {
                return Err(BodyError::Loop {
                    file: self.file.clone(),
                    message: format!(
                        "link '{}' has two parent joints, '{}' and '{}'",
                        j.child.link, robot.joints[other].name, j.name
                    ),
                });
            }
            parent_joint[c] = Some(ji);
            children[p].push(ji);
        }
        let roots: Vec<usize> = (0..robot.links.len())
            .filter(|&l| parent_joint[l].is_none())
            .collect();
        let root = match roots.as_slice() {
            [r] => *r,
            [] => {
                return Err(BodyError::Loop {
                    file: self.file.clone(),
                    message: "every link has a parent, so the joints form a cycle".into(),
                })
            }
            many => {
                let names: Vec<&str> = many.iter().map(|&l| robot.links[l].name.as_str()).collect();
                return Err(self.invalid(
                    "robot",
                    format!("more than one root link (links without a parent joint): {names:?}"),
                ));
            }
        };
        // Depth-first order from the root.
        let mut order: Vec<usize> = Vec::with_capacity(robot.links.len());
        let mut stack = vec![root];
        while let Some(l) = stack.pop() {
            order.push(l);
            for &ji in children[l].iter().rev() {
                stack.push(link_of[robot.joints[ji].child.link.as_str()]);
            }
        }
        if order.len() != robot.links.len() {
            let mut reached = vec![false; robot.links.len()];
            order.iter().for_each(|&l| reached[l] = true);
            let names: Vec<&str> = (0..robot.links.len())
                .filter(|&l| !reached[l])
                .map(|l| robot.links[l].name.as_str())
                .collect();
            return Err(BodyError::Loop {
                file: self.file.clone(),
                message: format!(
                    "links {names:?} form a cycle not connected to root link '{}'",
                    robot.links[root].name
                ),
            });
        }
        let mut new_link = vec![0usize; robot.links.len()];
        for (new, &old) in order.iter().enumerate() {
            new_link[old] = new;
        }

        let mut links = Vec::with_capacity(order.len());
        for &old in &order {
            let l = &robot.links[old];
            let parent_j = parent_joint[old];
            links.push(Link {
                name: l.name.clone(),
                parent: parent_j.map(|ji| new_link[link_of[robot.joints[ji].parent.link.as_str()]]),
                parent_joint: parent_j.map(|_| new_link[old] - 1),
                children: children[old]
                    .iter()
                    .map(|&ji| new_link[link_of[robot.joints[ji].child.link.as_str()]])
                    .collect(),
                inertial: self.inertial(l)?,
                visuals: l
                    .visual
                    .iter()
                    .enumerate()
                    .map(|(i, v)| {
                        self.element(
                            &format!("link '{}' visual {i}", l.name),
                            &v.name,
                            &v.origin,
                            &v.geometry,
                        )
                    })
                    .collect::<Result<_>>()?,
                collisions: l
                    .collision
                    .iter()
                    .enumerate()
                    .map(|(i, c)| {
                        self.element(
                            &format!("link '{}' collision {i}", l.name),
                            &c.name,
                            &c.origin,
                            &c.geometry,
                        )
                    })
                    .collect::<Result<_>>()?,
            });
        }
        // Joint j is the parent joint of link j + 1.
        let mut joints = Vec::with_capacity(order.len() - 1);
        for &old_link in &order[1..] {
            let ji = parent_joint[old_link].expect("non-root links have a parent joint");
            joints.push(self.joint(&robot.joints[ji], &link_of, &new_link)?);
        }
        // Resolve mimic masters to independent joints.
        let index: HashMap<String, usize> = joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.name.clone(), i))
            .collect();
        let declared: Vec<Option<(String, f64, f64)>> = order[1..]
            .iter()
            .map(|&l| {
                let j = &robot.joints[parent_joint[l].unwrap_or_default()];
                j.mimic.as_ref().map(|m| {
                    (
                        m.joint.clone(),
                        m.multiplier.unwrap_or(1.0),
                        m.offset.unwrap_or(0.0),
                    )
                })
            })
            .collect();
        for j in 0..joints.len() {
            let Some((name, mult, off)) = declared[j].clone() else {
                continue;
            };
            let mimic_err = |message: String| BodyError::Mimic {
                file: self.file.clone(),
                joint: joints[j].name.clone(),
                message,
            };
            if !mult.is_finite() || !off.is_finite() {
                return Err(mimic_err("multiplier and offset must be finite".into()));
            }
            if joints[j].kind == JointKind::Fixed {
                return Err(mimic_err("a fixed joint cannot mimic".into()));
            }
            let (mut master, mut m_mult, mut m_off) = (j, 1.0, 0.0);
            let mut hops = 0;
            let mut next = Some((name, mult, off));
            while let Some((n, k, o)) = next {
                let Some(&target) = index.get(&n) else {
                    return Err(mimic_err(format!("master joint '{n}' does not exist")));
                };
                hops += 1;
                if target == j || hops > joints.len() {
                    return Err(mimic_err("mimic couplings form a cycle".into()));
                }
                if joints[target].kind == JointKind::Fixed {
                    return Err(mimic_err(format!("master joint '{n}' is fixed")));
                }
                // q_master_prev = k * q_target + o
                m_off += m_mult * o;
                m_mult *= k;
                master = target;
                next = declared[target].clone();
            }
            let (name, mult, off) = declared[j].clone().unwrap_or_default();
            joints[j].mimic = Some(Mimic {
                joint_name: name,
                multiplier: mult,
                offset: off,
                master,
                master_multiplier: m_mult,
                master_offset: m_off,
            });
        }
        Ok(RobotModel::assemble(
            robot.name,
            self.file.clone(),
            links,
            joints,
        ))
    }

    fn inertial(&self, l: &urdf_rs::Link) -> Result<Inertial> {
        let el = format!("link '{}' inertial", l.name);
        let i = &l.inertial;
        let origin = self.pose(&el, &i.origin)?;
        let t = &i.inertia;
        let vals = [i.mass.value, t.ixx, t.ixy, t.ixz, t.iyy, t.iyz, t.izz];
        self.finite(&el, &vals)?;
        if i.mass.value < 0.0 {
            return Err(self.invalid(el, format!("negative mass {}", i.mass.value)));
        }
        Ok(Inertial {
            mass: i.mass.value,
            origin,
            inertia: Matrix3::new(
                t.ixx, t.ixy, t.ixz, t.ixy, t.iyy, t.iyz, t.ixz, t.iyz, t.izz,
            ),
        })
    }

    fn element(
        &mut self,
        el: &str,
        name: &Option<String>,
        origin: &urdf_rs::Pose,
        geometry: &urdf_rs::Geometry,
    ) -> Result<GeometryElement> {
        let origin = self.pose(el, origin)?;
        let positive = |what: &str, v: f64| -> Result<f64> {
            if v.is_finite() && v > 0.0 {
                Ok(v)
            } else {
                Err(self.invalid(
                    format!("{el} {what}"),
                    format!("{v} must be finite and > 0"),
                ))
            }
        };
        let geometry = match geometry {
            urdf_rs::Geometry::Box { size } => Geometry::Box {
                size: Vector3::new(
                    positive("box size", size[0])?,
                    positive("box size", size[1])?,
                    positive("box size", size[2])?,
                ),
            },
            urdf_rs::Geometry::Cylinder { radius, length } => Geometry::Cylinder {
                radius: positive("cylinder radius", *radius)?,
                length: positive("cylinder length", *length)?,
            },
            urdf_rs::Geometry::Capsule { radius, length } => Geometry::Capsule {
                radius: positive("capsule radius", *radius)?,
                length: {
                    if !(length.is_finite() && *length >= 0.0) {
                        return Err(self.invalid(
                            format!("{el} capsule length"),
                            format!("{length} must be finite and >= 0"),
                        ));
                    }
                    *length
                },
            },
            urdf_rs::Geometry::Sphere { radius } => Geometry::Sphere {
                radius: positive("sphere radius", *radius)?,
            },
            urdf_rs::Geometry::Mesh { filename, scale } => {
                let scale = scale.map_or(Vector3::repeat(1.0), |s| Vector3::new(s[0], s[1], s[2]));
                self.finite(&format!("{el} mesh scale"), scale.as_slice())?;
                let path = self.resolve(filename);
                if !path.is_file() {
                    return Err(BodyError::MissingMesh {
                        file: self.file.clone(),
                        element: el.to_string(),
                        mesh: path,
                    });
                }
                let key = (
                    path.clone(),
                    [scale.x.to_bits(), scale.y.to_bits(), scale.z.to_bits()],
                );
                let mesh = match self.meshes.get(&key) {
                    Some(m) => m.clone(),
                    None => {
                        let m = Arc::new(TriangleMesh::load(&path, scale)?);
                        self.meshes.insert(key, m.clone());
                        m
                    }
                };
                Geometry::Mesh { path, scale, mesh }
            }
        };
        Ok(GeometryElement {
            name: name.clone(),
            origin,
            geometry,
        })
    }

    fn resolve(&self, filename: &str) -> PathBuf {
        if let Some(rest) = filename.strip_prefix("package://") {
            let (pkg, tail) = rest.split_once('/').unwrap_or((rest, ""));
            for dir in self.base_dir.ancestors() {
                if dir.file_name().is_some_and(|n| n == pkg) {
                    return dir.join(tail);
                }
                let nested = dir.join(pkg).join(tail);
                if nested.exists() {
                    return nested;
                }
            }
            return self.base_dir.join(tail);
        }
        if let Some(abs) = filename.strip_prefix("file://") {
            return PathBuf::from(abs);
        }
        self.base_dir.join(filename)
    }

    fn joint(
        &self,
        j: &urdf_rs::Joint,
        link_of: &HashMap<&str, usize>,
        new_link: &[usize],
    ) -> Result<Joint> {
        let el = format!("joint '{}'", j.name);
        let kind = match j.joint_type {
            urdf_rs::JointType::Revolute => JointKind::Revolute,
            urdf_rs::JointType::Continuous => JointKind::Continuous,
            urdf_rs::JointType::Prismatic => JointKind::Prismatic,
            urdf_rs::JointType::Fixed => JointKind::Fixed,
            ref other => {
                return Err(self.invalid(el, format!("unsupported joint type {other:?}")));
            }
        };
        let origin = self.pose(&el, &j.origin)?;
        self.finite(&format!("{el} axis"), &j.axis.xyz.0)?;
        let axis_v = Vector3::new(j.axis.xyz[0], j.axis.xyz[1], j.axis.xyz[2]);
        let axis = if kind == JointKind::Fixed {
            Unit::new_normalize(if axis_v.norm() > 0.0 {
                axis_v
            } else {
                Vector3::x()
            })
        } else {
            Unit::try_new(axis_v, 1e-12)
                .ok_or_else(|| self.invalid(format!("{el} axis"), "the axis is zero"))?
        };
        let lim = &j.limit;
        let (lower, upper) = match kind {
            JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY),
            JointKind::Fixed => (0.0, 0.0),
            _ => {
                self.finite(&format!("{el} limit lower/upper"), &[lim.lower, lim.upper])?;
                if lim.lower > lim.upper {
                    return Err(self.invalid(
                        format!("{el} limit"),
                        format!("lower {} > upper {}", lim.lower, lim.upper),
                    ));
                }
                (lim.lower, lim.upper)
            }
        };
        for (what, v) in [("effort", lim.effort), ("velocity", lim.velocity)] {
            if v.is_nan() || v < 0.0 {
                return Err(self.invalid(format!("{el} limit {what}"), format!("{v} must be >= 0")));
            }
        }
        Ok(Joint {
            name: j.name.clone(),
            kind,
            parent: new_link[link_of[j.parent.link.as_str()]],
            child: new_link[link_of[j.child.link.as_str()]],
            origin,
            axis,
            limits: JointLimits {
                lower,
                upper,
                effort: lim.effort,
                velocity: lim.velocity,
            },
            mimic: None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quirks_are_tolerated() {
        let xml = r#"<robot name="r"><material><color rgba="1 0 0 1"/><texture/></material>
            <link name="a"><visual><geometry><sphere radius="0.1"/></geometry>
            <material><texture></texture></material></visual></link></robot>"#;
        let fixed = tolerate_quirks(xml);
        assert!(!fixed.contains("<texture"));
        assert_eq!(fixed.matches("<material name=\"\"").count(), 2);
        let m = parse_urdf(xml, Path::new("/tmp/q.urdf")).unwrap();
        assert_eq!(m.links.len(), 1);
        // Named materials and textures with files are left alone.
        let ok = r#"<material name="x"><texture filename="t.png"/></material>"#;
        assert_eq!(tolerate_quirks(ok), ok);
    }
}
