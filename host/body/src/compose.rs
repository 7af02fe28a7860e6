//! Attaching a hand to an arm: one robot from two descriptions, neither edited.
//!
//! What: [`compose`] puts a hand's links and joints under a link of an arm (or
//! a humanoid) through a new fixed joint at a given pose, optionally renaming
//! the hand's elements with a prefix, and rewrites relative mesh file names so
//! they still point at the same files from the composed file's folder.
//!
//! Why: hands and arms come from different vendors as separate URDFs; a
//! planner needs one kinematic tree. Editing either file by hand is how
//! mistakes get in; a command that composes them is repeatable.
//!
//! How: both files are read as plain records ([`crate::urdf_xml`]), the
//! hand's root link (the one link no joint has as child) is found, names are
//! checked for clashes (a clash is an error naming every clashing element,
//! with the advice to use a prefix), and the records are joined. The result
//! is written with [`crate::urdf_write::write_urdf`] and loads with
//! [`crate::urdf::load_urdf`] like any URDF.
//!
//! ```
//! use std::path::Path;
//! use tsukami_body::compose::{compose, Attach};
//! use tsukami_body::urdf_xml::{read_robot, Diagnostics, RawPose};
//! let read = |xml: &str| {
//!     read_robot(xml, &mut Diagnostics::new("x.urdf".into(), false), &Default::default()).unwrap()
//! };
//! let arm = read(r#"<robot name="arm"><link name="base"/><link name="flange"/>
//!   <joint name="j1" type="continuous"><parent link="base"/><child link="flange"/></joint></robot>"#);
//! let hand = read(r#"<robot name="hand"><link name="palm"/><link name="tip"/>
//!   <joint name="j1" type="fixed"><parent link="palm"/><child link="tip"/></joint></robot>"#);
//! let at = Attach {
//!     parent_link: "flange".into(),
//!     origin: RawPose { xyz: [0.0, 0.0, 0.05], rpy: [0.0; 3] },
//!     prefix: "hand_".into(),
//!     name: None,
//! };
//! let dirs = (Path::new("."), Path::new("."), Path::new("."));
//! let robot = compose(arm, hand, &at, dirs).unwrap();
//! assert_eq!(robot.links.len(), 4);
//! assert!(robot.joints.iter().any(|j| j.name == "hand_j1"));
//! assert!(robot.joints.iter().any(|j| j.parent == "flange" && j.child == "hand_palm"));
//! ```

use std::collections::HashSet;
use std::path::{Component, Path, PathBuf};

use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use crate::error::{BodyError, LoadWarning};
use crate::limits::{read_bounded, ParseLimits};
use crate::urdf_xml::{read_robot, Diagnostics, RawPose, RawRobot, RawShape};

/// Reads a URDF file into plain records (bounded like every URDF read), with
/// the quirks met as warnings (errors with `strict`).
pub fn read_raw(path: &Path, strict: bool) -> crate::error::Result<(RawRobot, Vec<LoadWarning>)> {
    let limits = ParseLimits::default();
    let bytes = read_bounded(path, limits.max_urdf_bytes, "URDF")?;
    let xml = String::from_utf8(bytes).map_err(|e| BodyError::Urdf {
        file: path.to_path_buf(),
        message: format!("not UTF-8 text: {}", e.utf8_error()),
    })?;
    let mut d = Diagnostics::new(path.to_path_buf(), strict);
    let robot = read_robot(&xml, &mut d, &limits)?;
    Ok((robot, d.warnings))
}

/// Where and how the hand goes on the arm.
#[derive(Debug, Clone, PartialEq)]
pub struct Attach {
    /// The arm's link the hand is fixed to (its flange or wrist).
    pub parent_link: String,
    /// Pose of the hand's root link in that link's frame.
    pub origin: RawPose,
    /// Prepended to every hand link and joint name ("" for none).
    pub prefix: String,
    /// The composed robot's name (`<arm>_<hand>` when `None`).
    pub name: Option<String>,
}

/// Why two descriptions cannot be composed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ComposeError {
    /// The arm has no link of that name.
    #[error("the arm '{arm}' has no link '{link}' to attach the hand to")]
    NoSuchLink {
        /// The arm's robot name.
        arm: String,
        /// The link asked for.
        link: String,
    },
    /// The hand has no unique root link.
    #[error("the hand '{hand}' must have exactly one root link (a link no joint has as child); it has {roots:?}")]
    HandRoot {
        /// The hand's robot name.
        hand: String,
        /// Its root links.
        roots: Vec<String>,
    },
    /// Hand and arm use the same names.
    #[error(
        "the hand's {what} clash with the arm's: {names:?}; give a prefix (e.g. --prefix hand_)"
    )]
    Clash {
        /// `links` or `joints`.
        what: &'static str,
        /// The clashing names (after the prefix), at most 10.
        names: Vec<String>,
    },
}

/// A frame link inserted above a hand's root (see [`insert_frame`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Name of the new link (e.g. `palm`).
    pub name: String,
    /// Its pose in the frame of the link it goes above (the hand's root).
    pub origin: RawPose,
}

/// Inserts an empty link `frame.name` between link `below` and its parent
/// joint, so that `below` keeps its place: the parent joint now ends at the
/// new link (its origin times `frame.origin`), and a fixed joint
/// `<name>_to_<below>` carries the inverse of `frame.origin`. When `below` is
/// a root, the new link becomes the root.
///
/// Why: the planner's palm frame is a link's frame (+z palm normal, +x toward
/// the fingertips, `docs/grasp-types.md`); a hand whose palm link has other
/// axes gets a frame link with the convention's axes that is still an
/// ancestor of every finger, without editing the hand's file.
pub fn insert_frame(robot: &mut RawRobot, below: &str, frame: &Frame) -> Result<(), ComposeError> {
    if !robot.links.iter().any(|l| l.name == below) {
        return Err(ComposeError::NoSuchLink {
            arm: robot.name.clone(),
            link: below.to_owned(),
        });
    }
    let joint = format!("{}_to_{below}", frame.name);
    let clash = |names: Vec<&str>, n: &str| names.contains(&n);
    for (what, taken, name) in [
        (
            "links",
            robot.links.iter().map(|l| l.name.as_str()).collect(),
            &frame.name,
        ),
        (
            "joints",
            robot.joints.iter().map(|j| j.name.as_str()).collect(),
            &joint,
        ),
    ] {
        if clash(taken, name) {
            return Err(ComposeError::Clash {
                what,
                names: vec![name.clone()],
            });
        }
    }
    let offset = to_isometry(&frame.origin);
    if let Some(j) = robot.joints.iter_mut().find(|j| j.child == below) {
        j.origin = from_isometry(&(to_isometry(&j.origin) * offset));
        j.child = frame.name.clone();
    }
    robot.links.push(crate::urdf_xml::RawLink {
        name: frame.name.clone(),
        inertial: None,
        visuals: Vec::new(),
        collisions: Vec::new(),
    });
    robot.joints.push(crate::urdf_xml::RawJoint {
        name: joint,
        kind: "fixed".into(),
        parent: frame.name.clone(),
        child: below.to_owned(),
        origin: from_isometry(&offset.inverse()),
        axis: [1.0, 0.0, 0.0],
        limit: None,
        mimic: None,
    });
    Ok(())
}

fn to_isometry(p: &RawPose) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(p.xyz[0], p.xyz[1], p.xyz[2]),
        UnitQuaternion::from_euler_angles(p.rpy[0], p.rpy[1], p.rpy[2]),
    )
}

fn from_isometry(m: &Isometry3<f64>) -> RawPose {
    let (r, p, y) = m.rotation.euler_angles();
    let t = m.translation.vector;
    // Round-off below a femtometre or femtoradian written as 0.
    let clean = |v: [f64; 3]| v.map(|x| if x.abs() < 1e-15 { 0.0 } else { x });
    RawPose {
        xyz: clean([t.x, t.y, t.z]),
        rpy: clean([r, p, y]),
    }
}

/// The hand's root link (the one link no joint has as child), before any prefix.
pub fn root_link(hand: &RawRobot) -> Result<String, ComposeError> {
    hand_root(hand)
}

/// The arm with the hand attached. `dirs` are the folders of the arm's file,
/// the hand's file and the composed file: relative mesh file names are
/// rewritten relative to the last.
pub fn compose(
    mut arm: RawRobot,
    mut hand: RawRobot,
    at: &Attach,
    dirs: (&Path, &Path, &Path),
) -> Result<RawRobot, ComposeError> {
    if !arm.links.iter().any(|l| l.name == at.parent_link) {
        return Err(ComposeError::NoSuchLink {
            arm: arm.name,
            link: at.parent_link.clone(),
        });
    }
    let root = hand_root(&hand)?;
    rename(&mut hand, &at.prefix);
    check_clashes(&arm, &hand)?;
    rebase_meshes(&mut arm, dirs.0, dirs.2);
    rebase_meshes(&mut hand, dirs.1, dirs.2);
    let root = format!("{}{root}", at.prefix);
    let joint_names: HashSet<&str> = arm
        .joints
        .iter()
        .chain(&hand.joints)
        .map(|j| j.name.as_str())
        .collect();
    let mut name = format!("{root}_attach");
    while joint_names.contains(name.as_str()) {
        name.push('_');
    }
    let attach = crate::urdf_xml::RawJoint {
        name,
        kind: "fixed".into(),
        parent: at.parent_link.clone(),
        child: root,
        origin: at.origin,
        axis: [1.0, 0.0, 0.0],
        limit: None,
        mimic: None,
    };
    Ok(RawRobot {
        name: at
            .name
            .clone()
            .unwrap_or_else(|| format!("{}_{}", arm.name, hand.name)),
        links: arm.links.into_iter().chain(hand.links).collect(),
        joints: arm
            .joints
            .into_iter()
            .chain(std::iter::once(attach))
            .chain(hand.joints)
            .collect(),
    })
}

fn hand_root(hand: &RawRobot) -> Result<String, ComposeError> {
    let children: HashSet<&str> = hand.joints.iter().map(|j| j.child.as_str()).collect();
    let roots: Vec<String> = hand
        .links
        .iter()
        .filter(|l| !children.contains(l.name.as_str()))
        .map(|l| l.name.clone())
        .collect();
    match roots.as_slice() {
        [one] => Ok(one.clone()),
        _ => Err(ComposeError::HandRoot {
            hand: hand.name.clone(),
            roots: roots.into_iter().take(10).collect(),
        }),
    }
}

fn rename(hand: &mut RawRobot, prefix: &str) {
    if prefix.is_empty() {
        return;
    }
    let p = |s: &mut String| *s = format!("{prefix}{s}");
    for l in &mut hand.links {
        p(&mut l.name);
    }
    for j in &mut hand.joints {
        p(&mut j.name);
        p(&mut j.parent);
        p(&mut j.child);
        if let Some(m) = &mut j.mimic {
            p(&mut m.joint);
        }
    }
}

fn check_clashes(arm: &RawRobot, hand: &RawRobot) -> Result<(), ComposeError> {
    let clash = |a: Vec<&str>, b: Vec<&str>| -> Vec<String> {
        let a: HashSet<&str> = a.into_iter().collect();
        b.into_iter()
            .filter(|n| a.contains(n))
            .take(10)
            .map(str::to_owned)
            .collect()
    };
    let links = clash(
        arm.links.iter().map(|l| l.name.as_str()).collect(),
        hand.links.iter().map(|l| l.name.as_str()).collect(),
    );
    if !links.is_empty() {
        return Err(ComposeError::Clash {
            what: "links",
            names: links,
        });
    }
    let joints = clash(
        arm.joints.iter().map(|j| j.name.as_str()).collect(),
        hand.joints.iter().map(|j| j.name.as_str()).collect(),
    );
    if !joints.is_empty() {
        return Err(ComposeError::Clash {
            what: "joints",
            names: joints,
        });
    }
    Ok(())
}

/// Rewrites every relative mesh file name of `robot` (read from a file in
/// `from`) to name the same file from `to`. `package://` and `file://` URIs
/// and absolute paths are left alone.
fn rebase_meshes(robot: &mut RawRobot, from: &Path, to: &Path) {
    for link in &mut robot.links {
        for e in link.visuals.iter_mut().chain(link.collisions.iter_mut()) {
            if let RawShape::Mesh(file, _) = &mut e.shape {
                if !file.contains("://") && Path::new(file.as_str()).is_relative() {
                    *file = relative_to(&from.join(file.as_str()), to)
                        .display()
                        .to_string();
                }
            }
        }
    }
}

/// `target` as a path from folder `base` (both made absolute and lexically
/// normalised first); `target` itself when they share no root.
fn relative_to(target: &Path, base: &Path) -> PathBuf {
    let (t, b) = (normalise(target), normalise(base));
    let common = t
        .components()
        .zip(b.components())
        .take_while(|(x, y)| x == y)
        .count();
    if common == 0 {
        return t;
    }
    let ups = b.components().count() - common;
    std::iter::repeat_n(Component::ParentDir.as_os_str(), ups)
        .map(PathBuf::from)
        .chain(
            t.components()
                .skip(common)
                .map(|c| PathBuf::from(c.as_os_str())),
        )
        .collect()
}

fn normalise(p: &Path) -> PathBuf {
    let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let mut out = PathBuf::new();
    for c in abs.components() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other.as_os_str()),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_walk_up_and_down() {
        let r = relative_to(Path::new("/a/b/meshes/m.stl"), Path::new("/a/c/out"));
        assert_eq!(r, PathBuf::from("../../b/meshes/m.stl"));
        let same = relative_to(Path::new("/a/b/./m.stl"), Path::new("/a/b"));
        assert_eq!(same, PathBuf::from("m.stl"));
    }

    fn pose_of(robot: &RawRobot, child: &str) -> Isometry3<f64> {
        let j = robot.joints.iter().find(|j| j.child == child).unwrap();
        let up = robot.links.iter().any(|l| l.name == j.parent)
            && robot.joints.iter().any(|k| k.child == j.parent);
        let parent = if up {
            pose_of(robot, &j.parent)
        } else {
            Isometry3::identity()
        };
        parent * to_isometry(&j.origin)
    }

    #[test]
    fn an_inserted_frame_keeps_the_link_in_place() {
        let xml = r#"<robot name="r"><link name="base"/><link name="palm_link"/><link name="tip"/>
          <joint name="mount" type="fixed"><origin xyz="0.1 0 0.2" rpy="0.3 0.2 0.1"/>
            <parent link="base"/><child link="palm_link"/></joint>
          <joint name="f" type="revolute"><parent link="palm_link"/><child link="tip"/>
            <limit lower="0" upper="1"/></joint></robot>"#;
        let mut d = Diagnostics::new("x.urdf".into(), false);
        let mut robot = read_robot(xml, &mut d, &Default::default()).unwrap();
        let before = pose_of(&robot, "palm_link");
        let frame = Frame {
            name: "palm".into(),
            origin: RawPose {
                xyz: [0.011, 0.0, -0.0475],
                rpy: [0.0, -std::f64::consts::FRAC_PI_2, std::f64::consts::PI],
            },
        };
        insert_frame(&mut robot, "palm_link", &frame).unwrap();
        let after = pose_of(&robot, "palm_link");
        assert!(
            (before.to_homogeneous() - after.to_homogeneous())
                .abs()
                .max()
                < 1e-12
        );
        let palm = pose_of(&robot, "palm");
        let expected = before * to_isometry(&frame.origin);
        assert!(
            (palm.to_homogeneous() - expected.to_homogeneous())
                .abs()
                .max()
                < 1e-12
        );
        let again = insert_frame(&mut robot, "palm_link", &frame).unwrap_err();
        assert!(again.to_string().contains("palm"), "{again}");
        let missing = insert_frame(&mut robot, "nope", &frame).unwrap_err();
        assert!(missing.to_string().contains("nope"), "{missing}");
    }
}
