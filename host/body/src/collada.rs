//! Collada (`.dae`) scenes: where each geometry sits, in metres.
//!
//! What: [`read_collada`] returns one mesh in metres from a Collada file,
//! with every `<instance_geometry>` placed by its node chain and the
//! document's `<unit meter>` applied.
//!
//! Why: `mesh-loader` 0.1.13 parses Collada geometry well, but composes node
//! transforms child-first (`node · parent` instead of `parent · node`), so a
//! file with a unit other than metres and a translated node, or with nested
//! rotated nodes, comes out misplaced; and a geometry instanced twice keeps
//! only one placement. Robot meshes exported in millimetres or inches with
//! node offsets are common.
//!
//! How: the visual scene is removed from the text before `mesh-loader` reads
//! it, so each geometry comes back untransformed under its id; the scene is
//! walked here (iteratively, with a budget on instances) composing
//! `<matrix>`, `<translate>`, `<rotate>` and `<scale>` in document order,
//! parent first, with the unit scale at the root. `up_axis` is ignored, as ROS
//! tools do. A file without a visual scene places every geometry once at the
//! origin.
//!
//! ```
//! // See the tests of `mesh_io` for a file with units and a node transform.
//! ```

use std::collections::HashMap;

use nalgebra::{Matrix4, Point3, Rotation3, Translation3, Unit, Vector3};
use roxmltree::{Document, Node};

use crate::mesh::TriangleMesh;

/// Most geometry instances placed from one file.
const MAX_INSTANCES: usize = 10_000;

/// Reads a Collada document into one mesh in metres, or a message.
/// `max_triangles` bounds the placed result.
pub fn read_collada(
    text: &str,
    path: &std::path::Path,
    max_triangles: usize,
) -> Result<TriangleMesh, String> {
    let doc = Document::parse_with_options(
        text,
        roxmltree::ParsingOptions {
            allow_dtd: false,
            nodes_limit: u32::MAX,
        },
    )
    .map_err(|e| format!("cannot parse Collada XML: {e}"))?;
    let root = doc.root_element();
    let unit = child(root, "asset")
        .and_then(|a| child(a, "unit"))
        .and_then(|u| u.attribute("meter"))
        .map(|m| m.trim().replace(',', "."))
        .and_then(|m| m.parse::<f64>().ok())
        .filter(|m| m.is_finite() && *m > 0.0)
        .unwrap_or(1.0);
    let scale = Matrix4::new_scaling(unit);
    let instances = instances(&doc, scale)?;
    // The geometry alone, without the scene, so mesh-loader applies nothing.
    let mut stripped = String::with_capacity(text.len());
    let mut cursor = 0;
    for n in root.children().filter(|n| {
        n.is_element() && matches!(n.tag_name().name(), "library_visual_scenes" | "scene")
    }) {
        let r = n.range();
        stripped.push_str(&text[cursor..r.start]);
        cursor = r.end;
    }
    stripped.push_str(&text[cursor..]);
    let loader = mesh_loader::Loader::default();
    let scene =
        std::panic::catch_unwind(|| loader.load_collada_from_slice(stripped.as_bytes(), path))
            .map_err(|_| "the Collada parser failed on this file".to_string())?
            .map_err(|e| {
                format!(
                    "cannot parse Collada: {}",
                    e.to_string().lines().next().unwrap_or_default()
                )
            })?;
    let geometries: HashMap<&str, &mesh_loader::Mesh> =
        scene.meshes.iter().map(|m| (m.name.as_str(), m)).collect();
    let placed: Vec<(&mesh_loader::Mesh, Matrix4<f64>)> = match instances {
        Some(list) => list
            .iter()
            .filter_map(|(id, m)| geometries.get(id.as_str()).map(|g| (*g, *m)))
            .collect(),
        None => scene.meshes.iter().map(|g| (g, scale)).collect(),
    };
    let total: usize = placed.iter().map(|(g, _)| g.faces.len()).sum();
    if total > max_triangles {
        return Err(format!(
            "{total} triangles, more than the limit of {max_triangles}"
        ));
    }
    let mut out = TriangleMesh {
        vertices: Vec::new(),
        indices: Vec::with_capacity(total),
    };
    for (g, m) in placed {
        let base = out.vertices.len() as u32;
        out.vertices.extend(
            g.vertices
                .iter()
                .map(|v| m.transform_point(&Point3::new(v[0] as f64, v[1] as f64, v[2] as f64))),
        );
        out.indices.extend(
            g.faces
                .iter()
                .map(|f| [base + f[0], base + f[1], base + f[2]]),
        );
    }
    Ok(out)
}

fn child<'a, 'i>(n: Node<'a, 'i>, name: &str) -> Option<Node<'a, 'i>> {
    n.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

fn by_id<'a, 'i>(doc: &'a Document<'i>, library: &str, id: &str) -> Option<Node<'a, 'i>> {
    let id = id.strip_prefix('#').unwrap_or(id);
    doc.root_element()
        .children()
        .filter(|l| l.is_element() && l.tag_name().name() == library)
        .flat_map(|l| l.descendants())
        .find(|n| n.is_element() && n.attribute("id") == Some(id))
}

/// `(geometry id, world matrix)` of each placed geometry instance.
type Placements = Vec<(String, Matrix4<f64>)>;

/// Every `(geometry id, world matrix)` of the instanced visual scene, or
/// `None` when the file has no visual scene.
fn instances(doc: &Document, root_matrix: Matrix4<f64>) -> Result<Option<Placements>, String> {
    let root = doc.root_element();
    let url = child(root, "scene")
        .and_then(|s| child(s, "instance_visual_scene"))
        .and_then(|i| i.attribute("url"));
    let scene = match url {
        Some(u) => by_id(doc, "library_visual_scenes", u),
        None => child(root, "library_visual_scenes").and_then(|l| child(l, "visual_scene")),
    };
    let Some(scene) = scene else {
        return Ok(None);
    };
    let mut out = Vec::new();
    let mut stack: Vec<(Node, Matrix4<f64>)> = scene
        .children()
        .filter(|c| c.is_element() && c.tag_name().name() == "node")
        .map(|c| (c, root_matrix))
        .collect();
    stack.reverse();
    let mut visited = 0usize;
    while let Some((node, parent)) = stack.pop() {
        visited += 1;
        if visited > MAX_INSTANCES * 10 || out.len() > MAX_INSTANCES {
            return Err(format!(
                "the visual scene has more than {MAX_INSTANCES} instances"
            ));
        }
        let world = parent * local_matrix(node)?;
        let mut next = Vec::new();
        for c in node.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "instance_geometry" => {
                    if let Some(u) = c.attribute("url") {
                        out.push((u.trim_start_matches('#').to_string(), world));
                    }
                }
                "node" => next.push((c, world)),
                "instance_node" => {
                    if let Some(n) = c
                        .attribute("url")
                        .and_then(|u| by_id(doc, "library_nodes", u))
                    {
                        next.push((n, world));
                    }
                }
                _ => {}
            }
        }
        stack.extend(next.into_iter().rev());
    }
    Ok(Some(out))
}

/// A node's own transform: its transform elements composed in order.
fn local_matrix(node: Node) -> Result<Matrix4<f64>, String> {
    let mut m: Matrix4<f64> = Matrix4::identity();
    for c in node.children().filter(Node::is_element) {
        let name = c.tag_name().name();
        if !matches!(name, "matrix" | "translate" | "rotate" | "scale") {
            continue;
        }
        let v: Vec<f64> = c
            .text()
            .unwrap_or_default()
            .split_whitespace()
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| {
                format!(
                    "<{name}> of node '{}' is not numbers",
                    node.attribute("id").unwrap_or("?")
                )
            })?;
        let bad = || {
            format!(
                "<{name}> of node '{}' has {} numbers",
                node.attribute("id").unwrap_or("?"),
                v.len()
            )
        };
        let t = match (name, v.len()) {
            ("matrix", 16) => Matrix4::from_row_slice(&v),
            ("translate", 3) => Translation3::new(v[0], v[1], v[2]).to_homogeneous(),
            ("scale", 3) => Matrix4::new_nonuniform_scaling(&Vector3::new(v[0], v[1], v[2])),
            ("rotate", 4) => {
                let axis = Vector3::new(v[0], v[1], v[2]);
                match Unit::try_new(axis, 1e-12) {
                    Some(a) => Rotation3::from_axis_angle(&a, v[3].to_radians()).to_homogeneous(),
                    None => Matrix4::identity(),
                }
            }
            _ => return Err(bad()),
        };
        m *= t;
    }
    if m.iter().all(|x| x.is_finite()) {
        Ok(m)
    } else {
        Err(format!(
            "node '{}' has a non-finite transform",
            node.attribute("id").unwrap_or("?")
        ))
    }
}
