//! glTF 2.0 binary export (`.glb`) of a [`Drawing`].
//!
//! What: [`to_glb`] writes one scene whose root node (`tsukami`) turns the
//! world's z-up frame into glTF's y-up frame and has one child node per group;
//! each group is a mesh with one indexed triangle primitive and a material of
//! the group's colour (blended when translucent, double-sided).
//!
//! Why: the same scene as the picture, openable in Blender, three.js or any
//! glTF viewer on a desktop.
//!
//! How: one binary buffer holds, per group, the positions (`VEC3` of `f32`,
//! with the `min`/`max` the specification requires) and the indices
//! (`SCALAR` of `u32`), each in its own buffer view, 4-byte aligned. Normals
//! are left out: glTF viewers then compute flat normals, as the specification
//! asks of them. The container is the 12-byte header, a JSON chunk padded with
//! spaces and a BIN chunk padded with zeros.

use serde_json::{json, Value};

use crate::drawing::{Drawing, Group};

/// `glTF` in little-endian.
const MAGIC: u32 = 0x4654_6C67;
/// Chunk type of the JSON chunk.
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type of the binary chunk.
const CHUNK_BIN: u32 = 0x004E_4942;
/// Component types and buffer-view targets of the specification.
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
/// Triangles primitive mode.
const TRIANGLES: u32 = 4;
/// −90° about x: world z-up to glTF y-up (x, y, z, w).
const Z_UP_TO_Y_UP: [f64; 4] = [
    -std::f64::consts::FRAC_1_SQRT_2,
    0.0,
    0.0,
    std::f64::consts::FRAC_1_SQRT_2,
];

/// The drawing as a `.glb` file.
pub fn to_glb(drawing: &Drawing) -> Vec<u8> {
    let mut bin = Vec::new();
    let mut parts = Parts::default();
    for (i, g) in drawing.groups.iter().enumerate() {
        parts.add(i, g, &mut bin);
    }
    let root_children: Vec<usize> = (1..=drawing.groups.len()).collect();
    let mut nodes =
        vec![json!({"name": "tsukami", "rotation": Z_UP_TO_Y_UP, "children": root_children})];
    nodes.extend(
        drawing
            .groups
            .iter()
            .enumerate()
            .map(|(i, g)| json!({"name": g.name, "mesh": i})),
    );
    let mut document = json!({
        "asset": {"version": "2.0", "generator": concat!("tsukami-render ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"name": "grasp", "nodes": [0]}],
        "nodes": nodes,
    });
    if !drawing.groups.is_empty() {
        document["meshes"] = Value::Array(parts.meshes);
        document["materials"] = Value::Array(parts.materials);
        document["accessors"] = Value::Array(parts.accessors);
        document["bufferViews"] = Value::Array(parts.views);
        document["buffers"] = json!([{"byteLength": bin.len()}]);
    }
    container(
        &serde_json::to_vec(&document).expect("JSON of plain values"),
        &bin,
    )
}

/// The JSON arrays being built, one entry per group (two accessors and views).
#[derive(Default)]
struct Parts {
    meshes: Vec<Value>,
    materials: Vec<Value>,
    accessors: Vec<Value>,
    views: Vec<Value>,
}

impl Parts {
    /// Appends group `i`'s positions and indices to `bin` and describes them.
    fn add(&mut self, i: usize, g: &Group, bin: &mut Vec<u8>) {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        let start = bin.len();
        for p in &g.positions {
            for k in 0..3 {
                let v = p[k] as f32;
                lo[k] = lo[k].min(v);
                hi[k] = hi[k].max(v);
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
        self.view(start, bin.len() - start, ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": 2 * i, "componentType": FLOAT, "count": g.positions.len(),
            "type": "VEC3", "min": lo, "max": hi,
        }));
        let start = bin.len();
        for index in g.triangles.iter().flatten() {
            bin.extend_from_slice(&index.to_le_bytes());
        }
        self.view(start, bin.len() - start, ELEMENT_ARRAY_BUFFER);
        self.accessors.push(json!({
            "bufferView": 2 * i + 1, "componentType": UNSIGNED_INT,
            "count": 3 * g.triangles.len(), "type": "SCALAR",
        }));
        self.meshes.push(json!({"name": g.name, "primitives": [{
            "attributes": {"POSITION": 2 * i}, "indices": 2 * i + 1, "material": i, "mode": TRIANGLES,
        }]}));
        let c = g.color.0;
        let mut material = json!({
            "name": g.name,
            "pbrMetallicRoughness": {"baseColorFactor": c, "metallicFactor": 0.0, "roughnessFactor": 0.8},
            "doubleSided": true,
        });
        if g.color.is_translucent() {
            material["alphaMode"] = json!("BLEND");
        }
        self.materials.push(material);
    }

    /// A buffer view of `length` bytes at `offset` (both multiples of 4).
    fn view(&mut self, offset: usize, length: usize, target: u32) {
        self.views.push(
            json!({"buffer": 0, "byteOffset": offset, "byteLength": length, "target": target}),
        );
    }
}

/// The GLB container: header, JSON chunk, BIN chunk (when there is data).
fn container(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| n.div_ceil(4) * 4;
    let mut json_chunk = json.to_vec();
    json_chunk.resize(pad(json.len()), b' ');
    let mut bin_chunk = bin.to_vec();
    bin_chunk.resize(pad(bin.len()), 0);
    let mut total = 12 + 8 + json_chunk.len();
    if !bin_chunk.is_empty() {
        total += 8 + bin_chunk.len();
    }
    let mut out = Vec::with_capacity(total);
    for word in [MAGIC, 2, total as u32, json_chunk.len() as u32, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json_chunk);
    if !bin_chunk.is_empty() {
        out.extend_from_slice(&(bin_chunk.len() as u32).to_le_bytes());
        out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
        out.extend_from_slice(&bin_chunk);
    }
    out
}
