//! URDF loading: validate every number, resolve mesh paths, load meshes, and
//! order the tree topologically.
//!
//! What: [`load_urdf`] (defaults), [`load_urdf_with`] ([`LoadOptions`]:
//! strict or lenient, package folders, limits, whether collision meshes are
//! required) and [`parse_urdf`] for text in memory. The result of
//! [`load_urdf_with`] carries the warnings ([`LoadedRobot`]).
//!
//! Why: real robot descriptions carry quirks that reference parsers accept,
//! meshes in several formats with the odd zero-area triangle, and
//! `package://` URIs that must resolve wherever the package is installed.
//! Kinematics never depend on meshes: a visual mesh that fails is skipped
//! with a warning naming it; a collision mesh is cleaned, not refused.
//!
//! How: [`crate::urdf_xml`] reads the XML into records and collects quirks;
//! here the records become a [`RobotModel`]. Quirks with a kinematic meaning
//! are decided as the reference parsers read them, and warned about (errors
//! with [`LoadOptions::strict`]):
//! - `lower > upper` on a revolute joint means "no limit" (the joint becomes
//!   continuous); on a prismatic joint the bounds are swapped;
//! - a missing `<limit>` on a revolute joint means no limit; missing
//!   `effort` or `velocity` are 0;
//! - `floating`, `planar` and `spherical` joints are kept at their zero pose
//!   (fixed);
//! - a `<mimic>` naming a missing joint holds the joint at its offset (the
//!   master is read as 0, as yourdfpy does); one on a fixed joint, naming a
//!   fixed joint, or in a cycle is ignored;
//! - a negative mass is read as 0.
//!
//! Mesh paths: `package://PKG/rest` goes through [`PackagePath`] (in its
//! documented order, ending with the URDF's ancestors); `file:///abs` is
//! `/abs`; other paths are relative to the URDF's folder.
//!
//! ```no_run
//! use tsukami_body::urdf::{load_urdf_with, LoadOptions};
//! let loaded = load_urdf_with(
//!     "models/robots/tsukami_humanoid/tsukami_humanoid.urdf".as_ref(),
//!     &LoadOptions::default(),
//! ).unwrap();
//! println!("{} links, {} warnings", loaded.model.links.len(), loaded.warnings.len());
//! ```

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use crate::error::{BodyError, LoadWarning, Result, WarningKind};
use crate::limits::{read_bounded, ParseLimits};
use crate::mesh::TriangleMesh;
use crate::model::{
    Geometry, GeometryElement, Inertial, Joint, JointKind, JointLimits, Link, Mimic, RobotModel,
};
use crate::packages::PackagePath;
use crate::urdf_xml::{
    read_robot, strip_file, Diagnostics, RawElement, RawJoint, RawPose, RawRobot, RawShape,
};

/// How a URDF is loaded.
#[derive(Debug, Clone)]
pub struct LoadOptions {
    /// Refuse every quirk instead of warning (`--strict`).
    pub strict: bool,
    /// Where `package://` URIs are looked up.
    pub packages: PackagePath,
    /// When true (the default), a collision element or mesh that cannot be
    /// found or read is an error; when false it is skipped with a
    /// [`WarningKind::CollisionSkipped`] warning (for kinematics-only use).
    pub require_collision_meshes: bool,
    /// Parse limits (XML depth, links, mesh triangles, file sizes).
    pub limits: ParseLimits,
}

impl Default for LoadOptions {
    fn default() -> Self {
        Self {
            strict: false,
            packages: PackagePath::default(),
            require_collision_meshes: true,
            limits: ParseLimits::default(),
        }
    }
}

impl LoadOptions {
    /// Options for kinematics only (FK, IK, inspection): lenient, and no
    /// mesh failure stops the load.
    pub fn kinematics_only() -> Self {
        Self {
            require_collision_meshes: false,
            ..Self::default()
        }
    }
}

/// A loaded robot and what the loader warned about.
#[derive(Debug, Clone)]
pub struct LoadedRobot {
    /// The model.
    pub model: RobotModel,
    /// Quirks accepted, elements skipped and meshes cleaned, in file order.
    pub warnings: Vec<LoadWarning>,
}

/// Loads and validates a URDF file with [`LoadOptions::default`] (lenient,
/// collision meshes required); warnings are dropped.
pub fn load_urdf(path: &Path) -> Result<RobotModel> {
    load_urdf_with(path, &LoadOptions::default()).map(|l| l.model)
}

/// Loads and validates a URDF file.
pub fn load_urdf_with(path: &Path, options: &LoadOptions) -> Result<LoadedRobot> {
    let bytes = read_bounded(path, options.limits.max_urdf_bytes, "URDF")?;
    let xml = String::from_utf8(bytes).map_err(|e| BodyError::Urdf {
        file: path.to_path_buf(),
        message: format!("not UTF-8 text: {}", e.utf8_error()),
    })?;
    parse_urdf_with(&xml, path, options)
}

/// Parses URDF text as if read from `path` (used for error messages and to
/// resolve relative mesh paths), with [`LoadOptions::default`].
pub fn parse_urdf(xml: &str, path: &Path) -> Result<RobotModel> {
    parse_urdf_with(xml, path, &LoadOptions::default()).map(|l| l.model)
}

/// Parses URDF text as if read from `path`.
pub fn parse_urdf_with(xml: &str, path: &Path, options: &LoadOptions) -> Result<LoadedRobot> {
    let mut d = Diagnostics::new(path.to_path_buf(), options.strict);
    d.collision_required = options.require_collision_meshes;
    let raw = read_robot(xml, &mut d, &options.limits)?;
    let model = Builder {
        base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        options,
        meshes: HashMap::new(),
        d: &mut d,
    }
    .build(raw)?;
    Ok(LoadedRobot {
        model,
        warnings: d.warnings,
    })
}

impl RobotModel {
    /// Parses a URDF string; relative mesh paths resolve against `base_dir`.
    pub fn from_urdf_str(xml: &str, base_dir: &Path) -> Result<Self> {
        parse_urdf(xml, &base_dir.join("<string>"))
    }
}

fn pose(p: &RawPose) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    )
}

type MeshKey = (PathBuf, [u64; 3]);

struct Builder<'a> {
    base_dir: PathBuf,
    options: &'a LoadOptions,
    meshes: HashMap<MeshKey, std::result::Result<Arc<TriangleMesh>, String>>,
    d: &'a mut Diagnostics,
}

/// The tree's order: links depth-first from the root, and for every link its
/// parent joint (by index into the raw joints).
struct Order {
    links: Vec<usize>,
    parent_joint: Vec<Option<usize>>,
    children: Vec<Vec<usize>>,
    link_of: HashMap<String, usize>,
}

impl Builder<'_> {
    fn file(&self) -> PathBuf {
        self.d.file.clone()
    }

    fn build(mut self, robot: RawRobot) -> Result<RobotModel> {
        let order = self.order(&robot)?;
        let mut new_link = vec![0usize; robot.links.len()];
        for (new, &old) in order.links.iter().enumerate() {
            new_link[old] = new;
        }
        let mut links = Vec::with_capacity(order.links.len());
        for &old in &order.links {
            let l = &robot.links[old];
            let parent_j = order.parent_joint[old];
            let link_el = format!("link '{}'", l.name);
            let mut visuals = Vec::new();
            for (i, v) in l.visuals.iter().enumerate() {
                let el = format!("{link_el} visual {i}");
                if let Some(g) = self.element(&el, v, false)? {
                    visuals.push(g);
                }
            }
            let mut collisions = Vec::new();
            for (i, c) in l.collisions.iter().enumerate() {
                let el = format!("{link_el} collision {i}");
                if let Some(g) = self.element(&el, c, true)? {
                    collisions.push(g);
                }
            }
            links.push(Link {
                name: l.name.clone(),
                parent: parent_j.map(|ji| new_link[order.link_of[&robot.joints[ji].parent]]),
                parent_joint: parent_j.map(|_| new_link[old] - 1),
                children: order.children[old]
                    .iter()
                    .map(|&ji| new_link[order.link_of[&robot.joints[ji].child]])
                    .collect(),
                inertial: self.inertial(l)?,
                visuals,
                collisions,
            });
        }
        // Joint j is the parent joint of link j + 1.
        let raw_joints: Vec<&RawJoint> = order.links[1..]
            .iter()
            .filter_map(|&l| order.parent_joint[l].map(|ji| &robot.joints[ji]))
            .collect();
        let mut joints = Vec::with_capacity(raw_joints.len());
        for j in &raw_joints {
            joints.push(self.joint(j, &order.link_of, &new_link)?);
        }
        self.mimics(&raw_joints, &mut joints)?;
        for (j, r) in raw_joints.iter().enumerate() {
            let Some(m) = &r.mimic else { continue };
            let pinned = joints[j].is_movable()
                && joints[j].mimic.is_none()
                && !joints.iter().any(|o| o.name == m.joint);
            if pinned {
                // As the reference parsers read it: the missing master is at
                // 0, so the joint is held at its offset.
                let at = crate::kinematics::joint_motion(joints[j].kind, &joints[j].axis, m.offset);
                joints[j].origin *= at;
                joints[j].kind = JointKind::Fixed;
                joints[j].limits.lower = 0.0;
                joints[j].limits.upper = 0.0;
            }
        }
        Ok(RobotModel::assemble(robot.name, self.file(), links, joints))
    }

    /// Checks names, parents and children, finds the single root and orders
    /// the links depth-first.
    fn order(&mut self, robot: &RawRobot) -> Result<Order> {
        let mut link_of: HashMap<String, usize> = HashMap::new();
        for (i, l) in robot.links.iter().enumerate() {
            if link_of.insert(l.name.clone(), i).is_some() {
                return Err(self
                    .d
                    .invalid(format!("link '{}'", l.name), "duplicate link name"));
            }
        }
        if robot.links.is_empty() {
            return Err(self.d.invalid("robot", "the robot has no links"));
        }
        let mut seen: HashMap<&str, ()> = HashMap::new();
        for j in &robot.joints {
            if seen.insert(j.name.as_str(), ()).is_some() {
                return Err(self
                    .d
                    .invalid(format!("joint '{}'", j.name), "duplicate joint name"));
            }
        }
        let n = robot.links.len();
        let mut parent_joint: Vec<Option<usize>> = vec![None; n];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (ji, j) in robot.joints.iter().enumerate() {
            let find = |role: &'static str, name: &str| {
                link_of
                    .get(name)
                    .copied()
                    .ok_or_else(|| BodyError::UnknownLinkInJoint {
                        file: self.file(),
                        joint: j.name.clone(),
                        role,
                        link: name.to_string(),
                    })
            };
            let p = find("parent", &j.parent)?;
            let c = find("child", &j.child)?;
            if p == c {
                return Err(BodyError::Loop {
                    file: self.file(),
                    message: format!("joint '{}' connects link '{}' to itself", j.name, j.parent),
                });
            }
            if let Some(other) = parent_joint[c] {
                return Err(BodyError::Loop {
                    file: self.file(),
                    message: format!(
                        "link '{}' has two parent joints, '{}' and '{}'",
                        j.child, robot.joints[other].name, j.name
                    ),
                });
            }
            parent_joint[c] = Some(ji);
            children[p].push(ji);
        }
        let roots: Vec<usize> = (0..n).filter(|&l| parent_joint[l].is_none()).collect();
        let root = match roots.as_slice() {
            [r] => *r,
            [] => {
                return Err(BodyError::Loop {
                    file: self.file(),
                    message: "every link has a parent, so the joints form a cycle".into(),
                })
            }
            many => {
                let names: Vec<&str> = many
                    .iter()
                    .take(8)
                    .map(|&l| robot.links[l].name.as_str())
                    .collect();
                return Err(self.d.invalid(
                    "robot",
                    format!(
                        "{} root links (links without a parent joint), e.g. {names:?}",
                        many.len()
                    ),
                ));
            }
        };
        let mut links: Vec<usize> = Vec::with_capacity(n);
        let mut stack = vec![root];
        while let Some(l) = stack.pop() {
            links.push(l);
            for &ji in children[l].iter().rev() {
                stack.push(link_of[&robot.joints[ji].child]);
            }
        }
        if links.len() != n {
            let mut reached = vec![false; n];
            links.iter().for_each(|&l| reached[l] = true);
            let names: Vec<&str> = (0..n)
                .filter(|&l| !reached[l])
                .take(8)
                .map(|l| robot.links[l].name.as_str())
                .collect();
            return Err(BodyError::Loop {
                file: self.file(),
                message: format!(
                    "links {names:?} form a cycle not connected to root link '{}'",
                    robot.links[root].name
                ),
            });
        }
        Ok(Order {
            links,
            parent_joint,
            children,
            link_of,
        })
    }

    fn inertial(&mut self, l: &crate::urdf_xml::RawLink) -> Result<Inertial> {
        let Some(i) = &l.inertial else {
            return Ok(Inertial {
                mass: 0.0,
                origin: Isometry3::identity(),
                inertia: Matrix3::zeros(),
            });
        };
        let mut mass = i.mass;
        if mass < 0.0 {
            self.d.quirk(
                format!("link '{}' inertial mass", l.name),
                format!("negative mass {mass}; read as 0"),
            )?;
            mass = 0.0;
        }
        let [ixx, ixy, ixz, iyy, iyz, izz] = i.inertia;
        Ok(Inertial {
            mass,
            origin: pose(&i.origin),
            inertia: Matrix3::new(ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz),
        })
    }

    /// One geometry element; `None` when a failed mesh is skipped.
    fn element(
        &mut self,
        el: &str,
        e: &RawElement,
        collision: bool,
    ) -> Result<Option<GeometryElement>> {
        let geometry = match &e.shape {
            RawShape::Box(s) => Geometry::Box {
                size: Vector3::new(s[0], s[1], s[2]),
            },
            RawShape::Cylinder(radius, length) => Geometry::Cylinder {
                radius: *radius,
                length: *length,
            },
            RawShape::Capsule(radius, length) => Geometry::Capsule {
                radius: *radius,
                length: *length,
            },
            RawShape::Sphere(radius) => Geometry::Sphere { radius: *radius },
            RawShape::Mesh(filename, s) => {
                let scale = Vector3::new(s[0], s[1], s[2]);
                match self.mesh(el, filename, scale) {
                    Ok((path, mesh)) => Geometry::Mesh { path, scale, mesh },
                    Err(err) => {
                        let required = collision && self.options.require_collision_meshes;
                        if required || self.options.strict {
                            return Err(err);
                        }
                        let kind = if collision {
                            WarningKind::CollisionSkipped
                        } else {
                            WarningKind::VisualSkipped
                        };
                        let msg = strip_file(&err, &self.d.file);
                        self.d.warn(kind, el, format!("mesh skipped: {msg}"));
                        return Ok(None);
                    }
                }
            }
        };
        Ok(Some(GeometryElement {
            name: e.name.clone(),
            origin: pose(&e.origin),
            geometry,
        }))
    }

    /// Resolves, loads and cleans a mesh (each file and scale once).
    fn mesh(
        &mut self,
        el: &str,
        filename: &str,
        scale: Vector3<f64>,
    ) -> Result<(PathBuf, Arc<TriangleMesh>)> {
        let path = self.resolve(el, filename)?;
        if !path.is_file() {
            return Err(BodyError::MissingMesh {
                file: self.file(),
                element: el.to_string(),
                mesh: path,
            });
        }
        let key = (
            path.clone(),
            [scale.x.to_bits(), scale.y.to_bits(), scale.z.to_bits()],
        );
        if let Some(cached) = self.meshes.get(&key) {
            return match cached {
                Ok(m) => Ok((path, m.clone())),
                Err(message) => Err(BodyError::Mesh {
                    file: path,
                    message: message.clone(),
                }),
            };
        }
        match TriangleMesh::load_with(&path, scale, &self.options.limits) {
            Ok((mesh, report)) => {
                if report.dropped_any() {
                    if self.options.strict {
                        return Err(BodyError::Mesh {
                            file: path,
                            message: report.summary(),
                        });
                    }
                    self.d.warn(
                        WarningKind::MeshCleaned,
                        el,
                        format!("mesh {} cleaned: {}", path.display(), report.summary()),
                    );
                }
                let mesh = Arc::new(mesh);
                self.meshes.insert(key, Ok(mesh.clone()));
                Ok((path, mesh))
            }
            Err(e) => {
                let message = match &e {
                    BodyError::Mesh { message, .. } => message.clone(),
                    other => other.to_string(),
                };
                self.meshes.insert(key, Err(message));
                Err(e)
            }
        }
    }

    fn resolve(&self, el: &str, filename: &str) -> Result<PathBuf> {
        if let Some(rest) = filename.strip_prefix("package://") {
            let (pkg, tail) = rest.split_once('/').unwrap_or((rest, ""));
            return self
                .options
                .packages
                .resolve(pkg, tail, &self.base_dir)
                .map_err(|searched| BodyError::UnresolvedPackage {
                    file: self.file(),
                    element: el.to_string(),
                    package: pkg.to_string(),
                    searched,
                });
        }
        if let Some(abs) = filename.strip_prefix("file://") {
            return Ok(PathBuf::from(abs));
        }
        Ok(self.base_dir.join(filename))
    }

    fn joint(
        &mut self,
        j: &RawJoint,
        link_of: &HashMap<String, usize>,
        new_link: &[usize],
    ) -> Result<Joint> {
        let el = format!("joint '{}'", j.name);
        let mut kind = match j.kind.as_str() {
            "revolute" => JointKind::Revolute,
            "continuous" => JointKind::Continuous,
            "prismatic" => JointKind::Prismatic,
            "fixed" => JointKind::Fixed,
            "floating" | "planar" | "spherical" => {
                self.d.quirk(
                    &el,
                    format!("a {} joint is kept at its zero pose (fixed)", j.kind),
                )?;
                JointKind::Fixed
            }
            other => return Err(self.d.invalid(&el, format!("unknown joint type '{other}'"))),
        };
        let axis_v = Vector3::from(j.axis);
        let axis = if kind == JointKind::Fixed {
            Unit::try_new(axis_v, 1e-12).unwrap_or(Vector3::x_axis())
        } else {
            Unit::try_new(axis_v, 1e-12)
                .ok_or_else(|| self.d.invalid(format!("{el} axis"), "the axis is zero"))?
        };
        let (lower, upper) = self.position_limits(&el, j, &mut kind)?;
        let lim = j.limit.unwrap_or_default();
        let mut rate = |what: &str, v: Option<f64>| -> Result<f64> {
            match v {
                Some(v) if v >= 0.0 => Ok(v),
                Some(v) => Err(self
                    .d
                    .invalid(format!("{el} limit {what}"), format!("{v} must be >= 0"))),
                None if j.limit.is_some() && kind != JointKind::Fixed => {
                    self.d
                        .quirk(format!("{el} limit"), format!("no '{what}'; 0 assumed"))?;
                    Ok(0.0)
                }
                None => Ok(0.0),
            }
        };
        let effort = rate("effort", lim.effort)?;
        let velocity = rate("velocity", lim.velocity)?;
        Ok(Joint {
            name: j.name.clone(),
            kind,
            parent: new_link[link_of[&j.parent]],
            child: new_link[link_of[&j.child]],
            origin: pose(&j.origin),
            axis,
            limits: JointLimits {
                lower,
                upper,
                effort,
                velocity,
            },
            mimic: None,
        })
    }

    /// Position limits, with the quirks of the module documentation.
    fn position_limits(
        &mut self,
        el: &str,
        j: &RawJoint,
        kind: &mut JointKind,
    ) -> Result<(f64, f64)> {
        match *kind {
            JointKind::Continuous => return Ok((f64::NEG_INFINITY, f64::INFINITY)),
            JointKind::Fixed => return Ok((0.0, 0.0)),
            _ => {}
        }
        let Some(lim) = j.limit else {
            if *kind == JointKind::Revolute {
                self.d
                    .quirk(el, "no <limit>; read as an unlimited (continuous) joint")?;
                *kind = JointKind::Continuous;
                return Ok((f64::NEG_INFINITY, f64::INFINITY));
            }
            self.d.quirk(el, "no <limit>; position limits 0")?;
            return Ok((0.0, 0.0));
        };
        let (lower, upper) = (lim.lower.unwrap_or(0.0), lim.upper.unwrap_or(0.0));
        if lower <= upper {
            return Ok((lower, upper));
        }
        let what = format!("lower {lower} > upper {upper}");
        if *kind == JointKind::Revolute {
            self.d.quirk(
                format!("{el} limit"),
                format!("{what}: read as no limit (continuous)"),
            )?;
            *kind = JointKind::Continuous;
            return Ok((f64::NEG_INFINITY, f64::INFINITY));
        }
        self.d
            .quirk(format!("{el} limit"), format!("{what}: bounds swapped"))?;
        Ok((upper, lower))
    }

    /// Resolves mimic masters to independent joints; bad mimics are quirks
    /// (ignored when lenient).
    fn mimics(&mut self, raw: &[&RawJoint], joints: &mut [Joint]) -> Result<()> {
        let index: HashMap<&str, usize> = joints
            .iter()
            .enumerate()
            .map(|(i, j)| (j.name.as_str(), i))
            .collect();
        // First decide which declared mimics are usable on their own.
        let mut declared: Vec<Option<(usize, f64, f64)>> = vec![None; joints.len()];
        for (j, r) in raw.iter().enumerate() {
            let Some(m) = &r.mimic else { continue };
            let problem = if joints[j].kind == JointKind::Fixed {
                Some("a fixed joint cannot mimic".to_string())
            } else {
                match index.get(m.joint.as_str()) {
                    None => Some(format!(
                        "master joint '{}' does not exist; the joint is held at its offset {} (fixed)",
                        m.joint, m.offset
                    )),
                    Some(&t) if joints[t].kind == JointKind::Fixed => {
                        Some(format!("master joint '{}' is fixed", m.joint))
                    }
                    Some(&t) => {
                        declared[j] = Some((t, m.multiplier, m.offset));
                        None
                    }
                }
            };
            if let Some(p) = problem {
                let p = if p.contains("(fixed)") {
                    p
                } else {
                    format!("{p}; the mimic is ignored")
                };
                self.mimic_quirk(&joints[j].name, p)?;
            }
        }
        // Then follow chains to independent masters.
        for j in 0..joints.len() {
            let Some(first) = declared[j] else { continue };
            let (mut master, mut mult, mut off) = (j, 1.0, 0.0);
            let mut next = Some(first);
            let mut hops = 0;
            let mut cycle = false;
            while let Some((t, k, o)) = next {
                hops += 1;
                if t == j || hops > joints.len() {
                    cycle = true;
                    break;
                }
                off += mult * o;
                mult *= k;
                master = t;
                next = declared[t];
            }
            if cycle {
                self.mimic_quirk(
                    &joints[j].name,
                    "mimic couplings form a cycle; the mimic is ignored".into(),
                )?;
                continue;
            }
            let m = raw[j].mimic.as_ref().expect("declared mimics exist");
            joints[j].mimic = Some(Mimic {
                joint_name: m.joint.clone(),
                multiplier: m.multiplier,
                offset: m.offset,
                master,
                master_multiplier: mult,
                master_offset: off,
            });
        }
        Ok(())
    }

    fn mimic_quirk(&mut self, joint: &str, message: String) -> Result<()> {
        if self.d.strict {
            return Err(BodyError::Mimic {
                file: self.file(),
                joint: joint.to_string(),
                message,
            });
        }
        self.d.quirk(format!("joint '{joint}' mimic"), message)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(body: &str, strict: bool) -> (Result<LoadedRobot>, Vec<String>) {
        let xml = format!(r#"<robot name="r">{body}</robot>"#);
        let options = LoadOptions {
            strict,
            ..LoadOptions::default()
        };
        let r = parse_urdf_with(&xml, Path::new("/tmp/q.urdf"), &options);
        let w = r
            .as_ref()
            .map(|l| l.warnings.iter().map(|w| w.to_string()).collect())
            .unwrap_or_default();
        (r, w)
    }

    const AB: &str = r#"<link name="a"/><link name="b"/><link name="c"/>"#;

    #[test]
    fn kinematic_quirks_are_read_as_reference_parsers_do() {
        let body = format!(
            r#"{AB}<joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
            <axis xyz="0 0 1"/><limit lower="1" upper="-1" effort="1"/></joint>
            <joint name="j2" type="fixed"><parent link="b"/><child link="c"/><mimic joint="j1"/></joint>"#
        );
        let (r, w) = load(&body, false);
        let m = r.unwrap().model;
        assert_eq!(m.joints[0].kind, JointKind::Continuous);
        assert!(m.joints[1].mimic.is_none());
        assert!(
            w.iter()
                .any(|w| w.contains("lower 1 > upper -1: read as no limit")),
            "{w:?}"
        );
        assert!(w.iter().any(|w| w.contains("no 'velocity'")), "{w:?}");
        assert!(
            w.iter()
                .any(|w| w.contains("joint 'j2' mimic: a fixed joint cannot mimic")),
            "{w:?}"
        );
        assert!(load(&body, true).0.is_err());
        // A mimic naming a missing joint.
        let body = format!(
            r#"{AB}<joint name="j1" type="continuous"><parent link="a"/><child link="b"/><mimic joint="ghost"/></joint>
            <joint name="j2" type="floating"><parent link="b"/><child link="c"/></joint>"#
        );
        let (r, w) = load(&body, false);
        let m = r.unwrap().model;
        assert!(m.joints[0].mimic.is_none() && m.joints[1].kind == JointKind::Fixed);
        assert!(
            w.iter().any(|w| w.contains("'ghost' does not exist")),
            "{w:?}"
        );
        assert!(
            w.iter()
                .any(|w| w.contains("floating joint is kept at its zero pose")),
            "{w:?}"
        );
        let e = load(&body, true).0.unwrap_err().to_string();
        assert!(e.contains("floating"), "{e}");
        let e = load(&body.replace("floating", "fixed"), true)
            .0
            .unwrap_err();
        assert!(matches!(e, BodyError::Mimic { .. }), "{e:?}");
    }

    #[test]
    fn missing_meshes_visual_skipped_collision_required_unless_kinematics_only() {
        let body = r#"<link name="a"><visual><geometry><mesh filename="package://nopkg/m.dae"/></geometry></visual></link>"#;
        let (r, w) = load(body, false);
        assert!(r.unwrap().model.links[0].visuals.is_empty());
        assert!(
            w[0].contains("link 'a' visual 0: mesh skipped")
                && w[0].contains("package 'nopkg' not found; searched /tmp"),
            "{w:?}"
        );
        let coll = body.replace("visual", "collision");
        let e = load(&coll, false).0.unwrap_err();
        assert!(matches!(e, BodyError::UnresolvedPackage { .. }), "{e:?}");
        let xml = format!(r#"<robot name="r">{coll}</robot>"#);
        let l = parse_urdf_with(
            &xml,
            Path::new("/tmp/q.urdf"),
            &LoadOptions::kinematics_only(),
        )
        .unwrap();
        assert_eq!(l.warnings[0].kind, WarningKind::CollisionSkipped);
    }
}
