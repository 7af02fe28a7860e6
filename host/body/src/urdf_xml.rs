//! URDF text to plain records: the XML half of URDF loading.
//!
//! What: [`read_robot`] turns URDF text into a [`RawRobot`] (links, joints,
//! geometry, limits and mimics as written), and [`Diagnostics`] collects the
//! quirks it meets: warnings in the default lenient mode, errors in strict
//! mode.
//!
//! Why: public robot descriptions carry quirks that the reference parsers
//! (urdfdom, yourdfpy) accept: a `<material>` inside `<geometry>`, a missing
//! `velocity`, a single-number mesh scale, commas in vectors, undeclared
//! `xacro:` prefixes. Reading the XML ourselves lets each quirk be named,
//! reported and, with `--strict`, refused. Kinematic meaning is decided in
//! [`crate::urdf`], not here.
//!
//! How: the text's nesting is checked first ([`check_xml_depth`]), then
//! `roxmltree` (an iterative parser, with a node limit) builds a tree, which
//! is walked without recursion beyond the URDF's fixed four levels. Numbers
//! that do not parse are errors in joints and links; in a visual or collision
//! element they make the loader skip that element.
//!
//! ```
//! use tsukami_body::urdf_xml::{read_robot, Diagnostics};
//! let xml = r#"<robot name="r"><link name="a"><visual><geometry>
//!   <sphere radius="0.1"/><material name="red"/></geometry></visual></link></robot>"#;
//! let mut d = Diagnostics::new("r.urdf".into(), false);
//! let robot = read_robot(xml, &mut d, &Default::default()).unwrap();
//! assert_eq!(robot.links[0].visuals.len(), 1);
//! assert!(d.warnings[0].message.contains("<material> inside <geometry>"));
//! let mut strict = Diagnostics::new("r.urdf".into(), true);
//! assert!(read_robot(xml, &mut strict, &Default::default()).is_err());
//! ```

use std::path::PathBuf;

use roxmltree::{Document, Node, ParsingOptions};

use crate::error::{BodyError, LoadWarning, Result, WarningKind};
use crate::limits::{check_xml_depth, ParseLimits};

/// Collects warnings; in strict mode a quirk is an error instead.
#[derive(Debug)]
pub struct Diagnostics {
    /// The file being read (named in every warning and error).
    pub file: PathBuf,
    /// True to refuse quirks.
    pub strict: bool,
    /// True when a collision element that cannot be read is an error even
    /// when lenient (the default; false for kinematics-only loading).
    pub collision_required: bool,
    /// Warnings so far, in file order.
    pub warnings: Vec<LoadWarning>,
}

impl Diagnostics {
    /// A collector for `file`.
    pub fn new(file: PathBuf, strict: bool) -> Self {
        Self {
            file,
            strict,
            collision_required: true,
            warnings: Vec::new(),
        }
    }

    /// An error about `element`.
    pub fn invalid(&self, element: impl Into<String>, message: impl Into<String>) -> BodyError {
        BodyError::Invalid {
            file: self.file.clone(),
            element: element.into(),
            message: message.into(),
        }
    }

    /// A quirk: a warning when lenient, an error when strict.
    pub fn quirk(&mut self, element: impl Into<String>, message: impl Into<String>) -> Result<()> {
        if self.strict {
            return Err(self.invalid(element, message));
        }
        self.warn(WarningKind::Quirk, element, message);
        Ok(())
    }

    /// A warning in both modes.
    pub fn warn(
        &mut self,
        kind: WarningKind,
        element: impl Into<String>,
        message: impl Into<String>,
    ) {
        self.warnings.push(LoadWarning {
            kind,
            file: self.file.clone(),
            element: element.into(),
            message: message.into(),
        });
    }
}

/// An `<origin>` as written (zeros when absent).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RawPose {
    /// Translation.
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw.
    pub rpy: [f64; 3],
}

/// A `<geometry>` shape as written.
#[derive(Debug, Clone, PartialEq)]
pub enum RawShape {
    /// `<box size>`.
    Box([f64; 3]),
    /// `<cylinder radius length>`.
    Cylinder(f64, f64),
    /// `<capsule radius length>`.
    Capsule(f64, f64),
    /// `<sphere radius>`.
    Sphere(f64),
    /// `<mesh filename scale>`.
    Mesh(String, [f64; 3]),
}

/// A `<visual>` or `<collision>`.
#[derive(Debug, Clone, PartialEq)]
pub struct RawElement {
    /// Its `name` attribute.
    pub name: Option<String>,
    /// Its origin.
    pub origin: RawPose,
    /// Its shape.
    pub shape: RawShape,
}

/// An `<inertial>`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RawInertial {
    /// Its origin.
    pub origin: RawPose,
    /// Mass.
    pub mass: f64,
    /// ixx, ixy, ixz, iyy, iyz, izz.
    pub inertia: [f64; 6],
}

/// A `<link>`.
#[derive(Debug, Clone, PartialEq)]
pub struct RawLink {
    /// Name.
    pub name: String,
    /// Inertial, if given.
    pub inertial: Option<RawInertial>,
    /// Visual elements that could be read.
    pub visuals: Vec<RawElement>,
    /// Collision elements that could be read.
    pub collisions: Vec<RawElement>,
}

/// A `<limit>`; `None` fields were absent.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RawLimit {
    /// Lower position limit.
    pub lower: Option<f64>,
    /// Upper position limit.
    pub upper: Option<f64>,
    /// Effort.
    pub effort: Option<f64>,
    /// Velocity.
    pub velocity: Option<f64>,
}

/// A `<mimic>`.
#[derive(Debug, Clone, PartialEq)]
pub struct RawMimic {
    /// The master joint.
    pub joint: String,
    /// Multiplier (1 when absent).
    pub multiplier: f64,
    /// Offset (0 when absent).
    pub offset: f64,
}

/// A `<joint>`.
#[derive(Debug, Clone, PartialEq)]
pub struct RawJoint {
    /// Name.
    pub name: String,
    /// `type` as written.
    pub kind: String,
    /// Parent link name.
    pub parent: String,
    /// Child link name.
    pub child: String,
    /// Origin.
    pub origin: RawPose,
    /// Axis (`1 0 0` when absent).
    pub axis: [f64; 3],
    /// Limit, if given.
    pub limit: Option<RawLimit>,
    /// Mimic, if given.
    pub mimic: Option<RawMimic>,
}

/// A whole `<robot>`.
#[derive(Debug, Clone, PartialEq)]
pub struct RawRobot {
    /// Robot name.
    pub name: String,
    /// Links in file order.
    pub links: Vec<RawLink>,
    /// Joints in file order.
    pub joints: Vec<RawJoint>,
}

/// Reads URDF text (see the module documentation).
pub fn read_robot(xml: &str, d: &mut Diagnostics, limits: &ParseLimits) -> Result<RawRobot> {
    let urdf_err = |message: String| BodyError::Urdf {
        file: d.file.clone(),
        message,
    };
    check_xml_depth(xml, limits.max_xml_depth).map_err(urdf_err)?;
    let options = ParsingOptions {
        allow_dtd: false,
        nodes_limit: u32::try_from(limits.max_links.saturating_mul(200)).unwrap_or(u32::MAX),
    };
    let declared;
    let doc = match Document::parse_with_options(xml, options) {
        Ok(doc) => doc,
        Err(roxmltree::Error::UnknownNamespace(prefix, _)) if !d.strict => {
            declared = declare_prefixes(xml);
            let doc = Document::parse_with_options(&declared, options)
                .map_err(|e| urdf_err(e.to_string()))?;
            d.quirk(
                "robot",
                format!("undeclared XML prefix '{prefix}:' (xacro leftovers?); its elements are ignored"),
            )?;
            return read_document(&doc, d, limits);
        }
        Err(e) if !d.strict => {
            declared = repair(xml).ok_or_else(|| urdf_err(e.to_string()))?;
            let doc = Document::parse_with_options(&declared, options)
                .map_err(|_| urdf_err(e.to_string()))?;
            d.quirk(
                "robot",
                format!(
                    "{e}: read after dropping misplaced XML declarations and text after </robot>"
                ),
            )?;
            return read_document(&doc, d, limits);
        }
        Err(e) => return Err(urdf_err(e.to_string())),
    };
    read_document(&doc, d, limits)
}

/// The text without XML declarations (`<?xml ...?>`) and without anything
/// after the last `</robot>`, or `None` when that changes nothing.
fn repair(xml: &str) -> Option<String> {
    let mut out = String::with_capacity(xml.len());
    let mut rest = xml;
    while let Some(i) = rest.find("<?xml") {
        out.push_str(&rest[..i]);
        rest = rest[i..].find("?>").map_or("", |e| &rest[i + e + 2..]);
    }
    out.push_str(rest);
    if let Some(end) = out.rfind("</robot>") {
        out.truncate(end + "</robot>".len());
    }
    let out = out.trim_start().to_string();
    (out != xml).then_some(out)
}

/// Declares every `prefix:` used in element or attribute names on the root
/// element, so leftovers such as `<xacro:property>` parse.
fn declare_prefixes(xml: &str) -> String {
    let mut prefixes: Vec<&str> = Vec::new();
    for (i, _) in xml.match_indices(':') {
        let start = xml[..i]
            .rfind(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
            .map_or(0, |s| s + 1);
        let before = xml[..start].chars().last();
        let name = &xml[start..i];
        let is_name = matches!(
            before,
            Some('<') | Some('/') | Some(' ') | Some('\n') | Some('\t')
        );
        if is_name
            && !name.is_empty()
            && name != "xmlns"
            && name != "xml"
            && !prefixes.contains(&name)
        {
            prefixes.push(name);
        }
        if prefixes.len() > 64 {
            break;
        }
    }
    let Some(root) = xml.find("<robot") else {
        return xml.to_string();
    };
    let at = root + "<robot".len();
    let decls: String = prefixes
        .iter()
        .filter(|p| !xml.contains(&format!("xmlns:{p}=")))
        .map(|p| format!(" xmlns:{p}=\"urn:undeclared:{p}\""))
        .collect();
    format!("{}{}{}", &xml[..at], decls, &xml[at..])
}

fn read_document(doc: &Document, d: &mut Diagnostics, limits: &ParseLimits) -> Result<RawRobot> {
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(BodyError::Urdf {
            file: d.file.clone(),
            message: format!(
                "the root element is <{}>, not <robot>",
                root.tag_name().name()
            ),
        });
    }
    let name = match root.attribute("name") {
        Some(n) => n.to_string(),
        None => {
            d.quirk("robot", "no name attribute")?;
            String::new()
        }
    };
    let mut robot = RawRobot {
        name,
        links: Vec::new(),
        joints: Vec::new(),
    };
    for child in root.children().filter(Node::is_element) {
        if child.tag_name().namespace().is_some() {
            continue; // xacro:*, gazebo extensions with a namespace
        }
        match child.tag_name().name() {
            "link" => robot.links.push(read_link(child, d)?),
            "joint" => robot.joints.push(read_joint(child, d)?),
            _ => {} // material, transmission, gazebo, ...: not kinematics
        }
        if robot.links.len() > limits.max_links || robot.joints.len() > limits.max_links {
            return Err(BodyError::TooLarge {
                file: d.file.clone(),
                message: format!("more than {} links or joints", limits.max_links),
            });
        }
    }
    Ok(robot)
}

fn elements<'a, 'i>(node: Node<'a, 'i>, tag: &'a str) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(move |c| {
        c.is_element() && c.tag_name().name() == tag && c.tag_name().namespace().is_none()
    })
}

fn first<'a, 'i>(node: Node<'a, 'i>, tag: &'a str) -> Option<Node<'a, 'i>> {
    elements(node, tag).next()
}

/// A required attribute.
fn attr<'a>(node: Node<'a, '_>, name: &str, element: &str, d: &Diagnostics) -> Result<&'a str> {
    node.attribute(name).ok_or_else(|| {
        d.invalid(
            element,
            format!("<{}> has no '{name}' attribute", node.tag_name().name()),
        )
    })
}

/// A number; `None` when absent.
fn number(node: Node, name: &str, element: &str, d: &Diagnostics) -> Result<Option<f64>> {
    let Some(text) = node.attribute(name) else {
        return Ok(None);
    };
    let v: f64 = text.trim().parse().map_err(|_| {
        d.invalid(
            format!("{element} {name}"),
            format!("'{}' is not a number", excerpt(text)),
        )
    })?;
    if !v.is_finite() {
        return Err(d.invalid(format!("{element} {name}"), format!("non-finite value {v}")));
    }
    Ok(Some(v))
}

/// Up to 40 characters of an attribute value for messages.
fn excerpt(text: &str) -> String {
    text.chars().take(40).collect()
}

/// A vector of `n` numbers (space separated; commas and a wrong count are
/// quirks). `None` when absent.
fn vector<const N: usize>(
    node: Node,
    name: &str,
    element: &str,
    d: &mut Diagnostics,
) -> Result<Option<[f64; N]>> {
    let Some(text) = node.attribute(name) else {
        return Ok(None);
    };
    let el = format!("{element} {name}");
    if text.contains(',') {
        d.quirk(
            &el,
            format!("'{}' uses commas between numbers", excerpt(text)),
        )?;
    }
    let mut values = Vec::with_capacity(N);
    for part in text
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|p| !p.is_empty())
    {
        let v: f64 = part
            .parse()
            .map_err(|_| d.invalid(&el, format!("'{}' is not a number", excerpt(part))))?;
        if !v.is_finite() {
            return Err(d.invalid(&el, format!("non-finite value in '{}'", excerpt(text))));
        }
        values.push(v);
    }
    if values.len() != N {
        if values.len() > N || N == 1 {
            d.quirk(
                &el,
                format!(
                    "{} numbers where {N} are expected; extra ones ignored",
                    values.len()
                ),
            )?;
        } else {
            d.quirk(
                &el,
                format!(
                    "{} numbers where {N} are expected; missing ones are 0",
                    values.len()
                ),
            )?;
        }
        values.resize(N, 0.0);
    }
    let mut out = [0.0; N];
    out.copy_from_slice(&values[..N]);
    Ok(Some(out))
}

fn pose(node: Node, element: &str, d: &mut Diagnostics) -> Result<RawPose> {
    let Some(o) = first(node, "origin") else {
        return Ok(RawPose::default());
    };
    let el = format!("{element} origin");
    Ok(RawPose {
        xyz: vector::<3>(o, "xyz", &el, d)?.unwrap_or_default(),
        rpy: vector::<3>(o, "rpy", &el, d)?.unwrap_or_default(),
    })
}

fn read_link(node: Node, d: &mut Diagnostics) -> Result<RawLink> {
    let name = attr(node, "name", "link", d)?.to_string();
    let el = format!("link '{name}'");
    let inertial = match first(node, "inertial") {
        Some(i) => Some(read_inertial(i, &format!("{el} inertial"), d)?),
        None => None,
    };
    let mut link = RawLink {
        name,
        inertial,
        visuals: Vec::new(),
        collisions: Vec::new(),
    };
    for (tag, collision) in [("visual", false), ("collision", true)] {
        for (i, v) in elements(node, tag).enumerate() {
            let ve = format!("{el} {tag} {i}");
            match read_element(v, &ve, d) {
                Ok(Some(e)) if collision => link.collisions.push(e),
                Ok(Some(e)) => link.visuals.push(e),
                Ok(None) => {}
                Err(e) if d.strict || (collision && d.collision_required) => return Err(e),
                Err(e) => {
                    let kind = if collision {
                        WarningKind::CollisionSkipped
                    } else {
                        WarningKind::VisualSkipped
                    };
                    d.warn(kind, ve, format!("skipped: {}", strip_file(&e, &d.file)));
                }
            }
        }
    }
    Ok(link)
}

/// An error's message without its leading `file: ` (the warning names the
/// file itself).
pub(crate) fn strip_file(e: &BodyError, file: &std::path::Path) -> String {
    let s = e.to_string();
    let prefix = format!("{}: ", file.display());
    s.strip_prefix(&prefix).map(str::to_string).unwrap_or(s)
}

fn read_inertial(node: Node, el: &str, d: &mut Diagnostics) -> Result<RawInertial> {
    let origin = pose(node, el, d)?;
    let mass = match first(node, "mass") {
        Some(m) => number(m, "value", &format!("{el} mass"), d)?,
        None => None,
    };
    let mass = match mass {
        Some(m) => m,
        None => {
            d.quirk(el, "no mass value; mass 0")?;
            0.0
        }
    };
    let mut inertia = [0.0; 6];
    match first(node, "inertia") {
        Some(t) => {
            for (k, n) in ["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]
                .iter()
                .enumerate()
            {
                inertia[k] = number(t, n, &format!("{el} inertia"), d)?.unwrap_or(0.0);
            }
        }
        None => d.quirk(el, "no <inertia>; inertia 0")?,
    }
    Ok(RawInertial {
        origin,
        mass,
        inertia,
    })
}

/// A visual or collision element; `Ok(None)` when it is dropped as a quirk
/// (a shape without volume).
fn read_element(node: Node, el: &str, d: &mut Diagnostics) -> Result<Option<RawElement>> {
    let origin = pose(node, el, d)?;
    let Some(g) = first(node, "geometry") else {
        return Err(d.invalid(el, "no <geometry>"));
    };
    let mut shapes = g.children().filter(Node::is_element);
    let Some(s) = shapes.next() else {
        return Err(d.invalid(el, "<geometry> is empty"));
    };
    for extra in shapes {
        d.quirk(
            el,
            format!(
                "stray <{}> inside <geometry> ignored",
                extra.tag_name().name()
            ),
        )?;
    }
    let ge = format!("{el} {}", s.tag_name().name());
    let req = |v: Option<f64>, what: &str, d: &Diagnostics| {
        v.ok_or_else(|| d.invalid(&ge, format!("no '{what}' attribute")))
    };
    let shape = match s.tag_name().name() {
        "box" => RawShape::Box(
            vector::<3>(s, "size", &ge, d)?.ok_or_else(|| d.invalid(&ge, "no 'size' attribute"))?,
        ),
        "cylinder" => RawShape::Cylinder(
            req(number(s, "radius", &ge, d)?, "radius", d)?,
            req(number(s, "length", &ge, d)?, "length", d)?,
        ),
        "capsule" => RawShape::Capsule(
            req(number(s, "radius", &ge, d)?, "radius", d)?,
            req(number(s, "length", &ge, d)?, "length", d)?,
        ),
        "sphere" => RawShape::Sphere(req(number(s, "radius", &ge, d)?, "radius", d)?),
        "mesh" => {
            let file = attr(s, "filename", &ge, d)?.to_string();
            let scale = match s.attribute("scale").map(|t| t.split_whitespace().count()) {
                Some(1) => {
                    let [k] = vector::<1>(s, "scale", &ge, d)?.unwrap_or([1.0]);
                    d.quirk(&ge, "a single number as scale; used for all three axes")?;
                    [k; 3]
                }
                _ => vector::<3>(s, "scale", &ge, d)?.unwrap_or([1.0; 3]),
            };
            RawShape::Mesh(file, scale)
        }
        other => return Err(d.invalid(el, format!("unknown shape <{other}>"))),
    };
    let sizes: Vec<f64> = match &shape {
        RawShape::Box(s) => s.to_vec(),
        RawShape::Cylinder(r, l) => vec![*r, *l],
        RawShape::Capsule(r, _) | RawShape::Sphere(r) => vec![*r],
        RawShape::Mesh(..) => vec![],
    };
    if let Some(bad) = sizes.iter().find(|v| **v <= 0.0) {
        d.quirk(
            &ge,
            format!("size {bad} is not > 0; the element is ignored"),
        )?;
        return Ok(None);
    }
    if matches!(shape, RawShape::Capsule(_, l) if l < 0.0) {
        d.quirk(&ge, "negative capsule length; the element is ignored")?;
        return Ok(None);
    }
    Ok(Some(RawElement {
        name: node.attribute("name").map(str::to_string),
        origin,
        shape,
    }))
}

fn read_joint(node: Node, d: &mut Diagnostics) -> Result<RawJoint> {
    let name = attr(node, "name", "joint", d)?.to_string();
    let el = format!("joint '{name}'");
    let kind = attr(node, "type", &el, d)?.to_string();
    let link_of = |tag: &str, d: &Diagnostics| -> Result<String> {
        let n = first(node, tag).ok_or_else(|| d.invalid(&el, format!("no <{tag}>")))?;
        Ok(attr(n, "link", &format!("{el} {tag}"), d)?.to_string())
    };
    let parent = link_of("parent", d)?;
    let child = link_of("child", d)?;
    let origin = pose(node, &el, d)?;
    let axis = match first(node, "axis") {
        Some(a) => vector::<3>(a, "xyz", &el.to_string(), d)?.unwrap_or([1.0, 0.0, 0.0]),
        None => [1.0, 0.0, 0.0],
    };
    let limit = match first(node, "limit") {
        Some(l) => {
            let le = format!("{el} limit");
            Some(RawLimit {
                lower: number(l, "lower", &le, d)?,
                upper: number(l, "upper", &le, d)?,
                effort: number(l, "effort", &le, d)?,
                velocity: number(l, "velocity", &le, d)?,
            })
        }
        None => None,
    };
    let mimic = match first(node, "mimic") {
        Some(m) => {
            let me = format!("{el} mimic");
            Some(RawMimic {
                joint: attr(m, "joint", &me, d)?.to_string(),
                multiplier: number(m, "multiplier", &me, d)?.unwrap_or(1.0),
                offset: number(m, "offset", &me, d)?.unwrap_or(0.0),
            })
        }
        None => None,
    };
    Ok(RawJoint {
        name,
        kind,
        parent,
        child,
        origin,
        axis,
        limit,
        mimic,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(xml: &str, strict: bool) -> (Result<RawRobot>, Vec<String>) {
        let mut d = Diagnostics::new("t.urdf".into(), strict);
        let r = read_robot(xml, &mut d, &ParseLimits::default());
        (r, d.warnings.iter().map(|w| w.to_string()).collect())
    }

    #[test]
    fn quirks_warn_when_lenient_and_fail_when_strict() {
        let cases = [
            (
                r#"<link name="a"><visual><origin xyz="1,2,3"/><geometry><sphere radius="1"/></geometry></visual></link>"#,
                "commas",
            ),
            (
                r#"<link name="a"><collision><geometry><sphere radius="0"/></geometry></collision></link>"#,
                "not > 0",
            ),
            (
                r#"<link name="a"><visual><geometry><mesh filename="m.stl" scale="0.001"/></geometry></visual></link>"#,
                "single number",
            ),
            (
                r#"<link name="a"><inertial><mass value="1"/></inertial></link>"#,
                "no <inertia>",
            ),
            (
                r#"<link name="a"/><xacro:property name="x" value="1"/>"#,
                "undeclared XML prefix 'xacro:'",
            ),
        ];
        for (body, want) in cases {
            let xml = format!(r#"<robot name="r">{body}</robot>"#);
            let (r, w) = read(&xml, false);
            assert!(r.is_ok(), "{body}: {r:?}");
            assert!(
                w.iter()
                    .any(|w| w.contains(want) && w.starts_with("t.urdf: ")),
                "{body}: {w:?}"
            );
            let (r, _) = read(&xml, true);
            assert!(r.is_err(), "strict accepted {body}");
        }
    }

    #[test]
    fn broken_visuals_are_skipped_broken_joints_are_errors() {
        let coll = r#"<robot name="r"><link name="a"><collision><origin xyz="0 ${pi} 0"/>
            <geometry><sphere radius="1"/></geometry></collision></link></robot>"#;
        assert!(read(coll, false).0.is_err());
        let mut d = Diagnostics::new("t.urdf".into(), false);
        d.collision_required = false;
        assert!(read_robot(coll, &mut d, &ParseLimits::default()).is_ok());
        assert_eq!(d.warnings[0].kind, WarningKind::CollisionSkipped);
        let xml = r#"<robot name="r"><link name="a"><visual><origin xyz="0 ${pi} 0"/>
            <geometry><sphere radius="1"/></geometry></visual></link></robot>"#;
        let (r, w) = read(xml, false);
        assert!(r.unwrap().links[0].visuals.is_empty());
        assert!(
            w[0].contains("link 'a' visual 0: skipped") && w[0].contains("'${pi}' is not a number"),
            "{w:?}"
        );
        let xml = r#"<robot name="r"><link name="a"/><link name="b"/><joint name="j" type="fixed">
            <origin xyz="0 ${pi} 0"/><parent link="a"/><child link="b"/></joint></robot>"#;
        let e = read(xml, false).0.unwrap_err().to_string();
        assert!(
            e.contains("joint 'j' origin xyz") && e.contains("${pi}"),
            "{e}"
        );
    }

    #[test]
    fn limits_hold() {
        let deep = format!("<robot name=\"r\">{}", "<link name=\"a\">".repeat(10_000));
        let e = read(&deep, false).0.unwrap_err().to_string();
        assert!(e.contains("nested deeper"), "{e}");
        let many: String = (0..20).map(|i| format!("<link name=\"l{i}\"/>")).collect();
        let mut d = Diagnostics::new("t.urdf".into(), false);
        let limits = ParseLimits {
            max_links: 10,
            ..ParseLimits::default()
        };
        let e = read_robot(
            &format!("<robot name=\"r\">{many}</robot>"),
            &mut d,
            &limits,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("more than 10 links"), "{e}");
    }
}
