//! Bad models give errors that name the file and the element; nothing panics.
//! Quirks that reference parsers accept are errors only with `strict`.

use std::path::{Path, PathBuf};

use tsukami_body::urdf::{load_urdf, load_urdf_with, LoadOptions};
use tsukami_body::BodyError;

struct Dir(PathBuf);
impl Dir {
    fn new(tag: &str) -> Self {
        let d = std::env::temp_dir().join(format!("tsukami-bad-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        Dir(d)
    }
    fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }
}
impl Drop for Dir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

fn robot(body: &str) -> String {
    format!(r#"<?xml version="1.0"?><robot name="bad">{body}</robot>"#)
}

const TWO_LINKS: &str = r#"<link name="a"/><link name="b"/>"#;

fn joint(name: &str, parent: &str, child: &str, origin: &str) -> String {
    format!(
        r#"<joint name="{name}" type="revolute"><origin {origin}/><parent link="{parent}"/><child link="{child}"/>
           <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>"#
    )
}

fn load_err(dir: &Dir, file: &str, text: &str) -> (BodyError, String) {
    let p = dir.write(file, text);
    let e = load_urdf(&p).expect_err("must fail");
    let msg = e.to_string();
    assert!(msg.contains(file), "message does not name the file: {msg}");
    (e, msg)
}

/// Fails only in strict mode; the lenient default loads it with a warning
/// that names the file.
fn strict_err(dir: &Dir, file: &str, text: &str) -> (BodyError, String) {
    let p = dir.write(file, text);
    let lenient = load_urdf_with(&p, &LoadOptions::default()).expect("lenient loads");
    assert!(
        lenient
            .warnings
            .iter()
            .any(|w| w.to_string().contains(file)),
        "{:?}",
        lenient.warnings
    );
    let strict = LoadOptions {
        strict: true,
        ..LoadOptions::default()
    };
    let e = load_urdf_with(&p, &strict).expect_err("strict must fail");
    let msg = e.to_string();
    assert!(msg.contains(file), "message does not name the file: {msg}");
    (e, msg)
}

#[test]
fn malformed_xml() {
    let d = Dir::new("xml");
    let (e, _) = load_err(
        &d,
        "broken.urdf",
        "<robot name=\"x\"><link name=\"a\"></robot",
    );
    assert!(matches!(e, BodyError::Urdf { .. }), "{e:?}");
    let (e, _) = load_err(&d, "notxml.urdf", "this is not xml at all");
    assert!(matches!(e, BodyError::Urdf { .. }), "{e:?}");
}

#[test]
fn missing_mesh_file() {
    let d = Dir::new("mesh");
    let text = robot(
        r#"<link name="a"><collision><geometry><mesh filename="meshes/nothere.stl"/></geometry></collision></link>"#,
    );
    let (e, msg) = load_err(&d, "m.urdf", &text);
    assert!(matches!(e, BodyError::MissingMesh { .. }), "{e:?}");
    assert!(
        msg.contains("nothere.stl") && msg.contains("link 'a' collision 0"),
        "{msg}"
    );
}

#[test]
fn mesh_without_triangles() {
    let d = Dir::new("empty");
    d.write("empty.stl", "solid empty\nendsolid empty\n");
    let text = robot(
        r#"<link name="a"><collision><geometry><mesh filename="empty.stl"/></geometry></collision></link>"#,
    );
    let p = d.write("e.urdf", &text);
    let e = load_urdf(&p).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, BodyError::Mesh { .. }), "{e:?}");
    assert!(
        msg.contains("empty.stl") && msg.contains("no triangles"),
        "{msg}"
    );
    // A binary STL with zero triangles, and an OBJ with only vertices.
    let mut bin = vec![0u8; 80];
    bin.extend_from_slice(&0u32.to_le_bytes());
    std::fs::write(d.0.join("zero.stl"), bin).unwrap();
    d.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for f in ["zero.stl", "points.obj"] {
        let text = robot(&format!(
            r#"<link name="a"><collision><geometry><mesh filename="{f}"/></geometry></collision></link>"#
        ));
        let p = d.write("z.urdf", &text);
        let msg = load_urdf(&p).unwrap_err().to_string();
        assert!(msg.contains(f), "{msg}");
    }
}

#[test]
fn joint_naming_a_missing_link() {
    let d = Dir::new("link");
    let text = robot(&format!(
        "{TWO_LINKS}{}",
        joint("j", "a", "ghost", "xyz=\"0 0 0\"")
    ));
    let (e, msg) = load_err(&d, "l.urdf", &text);
    assert!(matches!(e, BodyError::UnknownLinkInJoint { .. }), "{e:?}");
    assert!(
        msg.contains("'j'") && msg.contains("ghost") && msg.contains("child"),
        "{msg}"
    );
}

#[test]
fn loops() {
    let d = Dir::new("loop");
    // A link with two parents.
    let text = robot(&format!(
        r#"{TWO_LINKS}<link name="c"/>{}{}{}"#,
        joint("ab", "a", "b", ""),
        joint("ac", "a", "c", ""),
        joint("cb", "c", "b", "")
    ));
    let (e, msg) = load_err(&d, "two_parents.urdf", &text);
    assert!(matches!(e, BodyError::Loop { .. }), "{e:?}");
    assert!(
        msg.contains("'b'") && msg.contains("'ab'") && msg.contains("'cb'"),
        "{msg}"
    );
    // A cycle: a -> b -> a.
    let text = robot(&format!(
        "{TWO_LINKS}{}{}",
        joint("ab", "a", "b", ""),
        joint("ba", "b", "a", "")
    ));
    let (e, _) = load_err(&d, "cycle.urdf", &text);
    assert!(matches!(e, BodyError::Loop { .. }), "{e:?}");
    // A cycle beside a proper root.
    let text = robot(&format!(
        r#"{TWO_LINKS}<link name="root"/>{}{}"#,
        joint("ab", "a", "b", ""),
        joint("ba", "b", "a", "")
    ));
    let (e, msg) = load_err(&d, "cycle2.urdf", &text);
    assert!(
        matches!(e, BodyError::Loop { .. }) && msg.contains("cycle"),
        "{e:?}"
    );
    // A mimic cycle.
    let text = robot(&format!(
        r#"{TWO_LINKS}<link name="c"/>
        <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/>
          <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j2"/></joint>
        <joint name="j2" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 0 1"/>
          <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="j1"/></joint>"#
    ));
    let (e, _) = strict_err(&d, "mimic.urdf", &text);
    assert!(matches!(e, BodyError::Mimic { .. }), "{e:?}");
}

#[test]
fn nan_in_an_origin() {
    let d = Dir::new("nan");
    let text = robot(&format!(
        "{TWO_LINKS}{}",
        joint("elbow", "a", "b", "xyz=\"0 NaN 0.1\"")
    ));
    let (e, msg) = load_err(&d, "n.urdf", &text);
    assert!(matches!(e, BodyError::Invalid { .. }), "{e:?}");
    assert!(msg.contains("joint 'elbow' origin xyz"), "{msg}");
    let text = robot(
        r#"<link name="a"><collision><origin rpy="0 inf 0"/><geometry><sphere radius="1"/></geometry></collision></link>"#,
    );
    let (_, msg) = load_err(&d, "n2.urdf", &text);
    assert!(msg.contains("link 'a' collision 0 origin rpy"), "{msg}");
    let text = robot(&format!(
        "{TWO_LINKS}{}",
        joint("j", "a", "b", "").replace("upper=\"1\"", "upper=\"nan\"")
    ));
    let (_, msg) = load_err(&d, "n3.urdf", &text);
    assert!(msg.contains("joint 'j' limit"), "{msg}");
}

#[test]
fn other_invalid_values() {
    let d = Dir::new("misc");
    let text = robot(
        r#"<link name="a"><collision><geometry><box size="0.1 -1 0.1"/></geometry></collision></link>"#,
    );
    let (_, msg) = strict_err(&d, "box.urdf", &text);
    assert!(msg.contains("box: size -1"), "{msg}");
    let text = robot(&format!(
        "{TWO_LINKS}{}",
        joint("j", "a", "b", "").replace("0 0 1", "0 0 0")
    ));
    let (_, msg) = load_err(&d, "axis.urdf", &text);
    assert!(msg.contains("joint 'j' axis"), "{msg}");
    let text = robot(r#"<link name="a"/><link name="a"/>"#);
    let (_, msg) = load_err(&d, "dup.urdf", &text);
    assert!(msg.contains("duplicate"), "{msg}");
    assert!(load_urdf(Path::new("/nonexistent/x.urdf"))
        .unwrap_err()
        .to_string()
        .contains("x.urdf"));
}
