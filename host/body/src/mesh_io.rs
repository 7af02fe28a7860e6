//! Mesh files: reading STL (ASCII and binary), OBJ, PLY and Collada (`.dae`),
//! and writing STL, OBJ and PLY.
//!
//! What: [`TriangleMesh::load`] and [`TriangleMesh::load_with`] read a mesh
//! file, scale it, clean it ([`crate::mesh_clean`]) and refuse it only when no
//! triangle is left; [`TriangleMesh::from_bytes_with`] does the same with a
//! file's bytes already in memory (an inline mesh, [`crate::mesh_inline`]);
//! [`TriangleMesh::write_stl`], [`TriangleMesh::write_obj`] and
//! [`TriangleMesh::write_ply`] write one.
//!
//! Why: robot collections ship STL, OBJ and Collada (about 30 % of mesh
//! references in a common collection are `.dae`); objects come as scans,
//! often PLY.
//!
//! How: a binary STL is read directly (one pass, the same values
//! `mesh-loader` gives); `mesh-loader` (from the urdf-rs authors) parses
//! ASCII STL, OBJ and Collada; for Collada it applies the node transforms and the `<unit meter>` scale
//! (the `up_axis` is ignored, as ROS tools do; node placement is done in
//! [`crate::collada`]); PLY is read by [`crate::ply`]. The file is read through
//! [`crate::limits::read_bounded`], a Collada file's nesting is checked
//! before parsing, and the triangle count is checked against
//! [`ParseLimits::max_mesh_triangles`] (for binary STL and PLY before
//! parsing, from the header). OBJ material libraries are not read. A parser panic on a
//! hostile file becomes an error.
//!
//! ```
//! use nalgebra::Vector3;
//! use tsukami_body::mesh::TriangleMesh;
//! let path = std::env::temp_dir().join(format!("tsukami-mesh-io-doc-{}.stl", std::process::id()));
//! TriangleMesh::cylinder(0.03, 0.1, 12).write_stl(&path).unwrap();
//! let (mesh, report) = TriangleMesh::load_with(&path, Vector3::repeat(1.0), &Default::default()).unwrap();
//! assert!(mesh.is_closed());
//! assert_eq!(report.dropped(), 0);
//! std::fs::remove_file(&path).unwrap();
//! ```

use std::io::Write;
use std::path::Path;

use nalgebra::{Point3, Vector3};

use crate::collada::read_collada;
use crate::error::{BodyError, Result};
use crate::limits::{check_xml_depth, read_bounded, ParseLimits};
use crate::mesh::TriangleMesh;
use crate::mesh_clean::MeshCleanup;
use crate::ply::PlyError;

/// The mesh formats the loader reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// STL, binary or ASCII.
    Stl,
    /// Wavefront OBJ (material libraries are not read).
    Obj,
    /// PLY (Stanford polygon format), ASCII or binary.
    Ply,
    /// Collada (`.dae`).
    Collada,
}

impl Format {
    /// The format of a file, by its extension (case-insensitive), or a
    /// message naming the extension.
    pub fn of_path(path: &Path) -> std::result::Result<Format, String> {
        format_of(path)
    }
}

impl TriangleMesh {
    /// Loads an STL (binary or ASCII), OBJ, PLY or Collada file with the default
    /// [`ParseLimits`], scales every vertex by `scale` component-wise and
    /// cleans it. The format is chosen by the extension.
    pub fn load(path: &Path, scale: Vector3<f64>) -> Result<Self> {
        Self::load_with(path, scale, &ParseLimits::default()).map(|(m, _)| m)
    }

    /// [`TriangleMesh::load`] with explicit limits; also returns what
    /// cleaning changed. Fails when the file cannot be read or parsed,
    /// exceeds a limit, the scale is not finite and non-zero, or no triangle
    /// is left after cleaning (the error gives the counts and a first
    /// example).
    pub fn load_with(
        path: &Path,
        scale: Vector3<f64>,
        limits: &ParseLimits,
    ) -> Result<(Self, MeshCleanup)> {
        let err = |message: String| BodyError::Mesh {
            file: path.to_path_buf(),
            message,
        };
        if !scale.iter().all(|s| s.is_finite() && *s != 0.0) {
            return Err(err(format!(
                "scale {:?} must be finite and non-zero",
                scale.as_slice()
            )));
        }
        let format = format_of(path).map_err(err)?;
        let bytes = read_bounded(path, limits.max_mesh_bytes, "mesh")?;
        Self::from_bytes_with(&bytes, format, scale, limits, path)
    }

    /// [`TriangleMesh::load_with`] on a file's bytes already in memory (an
    /// inline mesh of a request, [`crate::mesh_inline`]): parses `bytes` as
    /// `format`, scales and cleans. `label` stands for the file in errors
    /// (e.g. `inline STL`); nothing is read from or written to the disk.
    /// Checks everything `load_with` does but the byte size, which is the
    /// caller's (it holds the bytes already).
    pub fn from_bytes_with(
        bytes: &[u8],
        format: Format,
        scale: Vector3<f64>,
        limits: &ParseLimits,
        label: &Path,
    ) -> Result<(Self, MeshCleanup)> {
        let err = |message: String| BodyError::Mesh {
            file: label.to_path_buf(),
            message,
        };
        if !scale.iter().all(|s| s.is_finite() && *s != 0.0) {
            return Err(err(format!(
                "scale {:?} must be finite and non-zero",
                scale.as_slice()
            )));
        }
        let mut mesh = parse(label, bytes, format, limits)?;
        for v in &mut mesh.vertices {
            v.coords.component_mul_assign(&scale);
        }
        // A negative scale determinant mirrors the mesh: flip the winding so
        // the normals stay outward.
        if scale.x * scale.y * scale.z < 0.0 {
            for t in &mut mesh.indices {
                t.swap(1, 2);
            }
        }
        let report = mesh.clean();
        if mesh.indices.is_empty() {
            let what = if report.triangles_in == 0 {
                "the mesh has no triangles".to_string()
            } else {
                format!("no usable triangle: {}", report.summary())
            };
            return Err(err(what));
        }
        Ok((mesh, report))
    }

    /// Writes a binary STL file.
    pub fn write_stl(&self, path: &Path) -> Result<()> {
        let io_err = |source| BodyError::Io {
            file: path.to_path_buf(),
            source,
        };
        let mut out = Vec::with_capacity(84 + 50 * self.indices.len());
        out.extend_from_slice(&[0u8; 80]);
        out.extend_from_slice(&(self.indices.len() as u32).to_le_bytes());
        for k in 0..self.indices.len() {
            let n = self.triangle_normal(k);
            let n = if n.iter().all(|c| c.is_finite()) {
                n
            } else {
                Vector3::zeros()
            };
            let corners = self.triangle(k);
            for c in std::iter::once(n).chain(corners.iter().map(|p| p.coords)) {
                for x in c.iter() {
                    out.extend_from_slice(&(*x as f32).to_le_bytes());
                }
            }
            out.extend_from_slice(&[0, 0]);
        }
        std::fs::write(path, out).map_err(io_err)
    }

    /// Writes a binary little-endian PLY file ([`crate::ply::to_binary`]).
    pub fn write_ply(&self, path: &Path) -> Result<()> {
        std::fs::write(path, crate::ply::to_binary(self)).map_err(|source| BodyError::Io {
            file: path.to_path_buf(),
            source,
        })
    }

    /// Writes a Wavefront OBJ file (positions and faces only).
    pub fn write_obj(&self, path: &Path) -> Result<()> {
        let io_err = |source| BodyError::Io {
            file: path.to_path_buf(),
            source,
        };
        let mut out = std::io::BufWriter::new(std::fs::File::create(path).map_err(io_err)?);
        writeln!(out, "# generated by tsukami-body").map_err(io_err)?;
        for v in &self.vertices {
            writeln!(out, "v {:.6} {:.6} {:.6}", v.x, v.y, v.z).map_err(io_err)?;
        }
        for t in &self.indices {
            writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1).map_err(io_err)?;
        }
        out.flush().map_err(io_err)
    }
}

fn format_of(path: &Path) -> std::result::Result<Format, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    match ext.as_str() {
        "stl" => Ok(Format::Stl),
        "obj" => Ok(Format::Obj),
        "ply" => Ok(Format::Ply),
        "dae" => Ok(Format::Collada),
        _ => Err(format!(
            "unsupported mesh format '.{ext}' (use .stl, .obj, .ply or .dae)"
        )),
    }
}

/// Parses `bytes` into one unscaled, uncleaned mesh.
fn parse(path: &Path, bytes: &[u8], format: Format, limits: &ParseLimits) -> Result<TriangleMesh> {
    let err = |message: String| BodyError::Mesh {
        file: path.to_path_buf(),
        message,
    };
    let too_many = |n: usize| BodyError::TooLarge {
        file: path.to_path_buf(),
        message: format!(
            "{n} triangles, more than the limit of {}",
            limits.max_mesh_triangles
        ),
    };
    match format {
        Format::Stl => {
            if let Some(n) = binary_stl_triangles(bytes) {
                if n > limits.max_mesh_triangles {
                    return Err(too_many(n));
                }
                return Ok(read_binary_stl(bytes, n));
            }
        }
        Format::Collada => {
            let text = std::str::from_utf8(bytes)
                .map_err(|e| err(format!("the Collada file is not UTF-8 text: {e}")))?;
            check_xml_depth(text, limits.max_xml_depth).map_err(err)?;
            return read_collada(text, path, limits.max_mesh_triangles).map_err(err);
        }
        Format::Ply => {
            return crate::ply::read(bytes, limits).map_err(|e| match e {
                PlyError::TooLarge(message) => BodyError::TooLarge {
                    file: path.to_path_buf(),
                    message,
                },
                PlyError::Malformed(m) => err(format!("cannot parse PLY: {m}")),
            });
        }
        Format::Obj => {}
    }
    let loader = mesh_loader::Loader::default().merge_meshes(true);
    let parsed = std::panic::catch_unwind(|| match format {
        Format::Stl => loader.load_stl_from_slice(bytes, path),
        Format::Collada | Format::Ply => Err(std::io::Error::other("read by this crate")),
        Format::Obj => loader.load_obj_from_slice_with_reader(bytes, path, |_| {
            Err(std::io::Error::other("material libraries are not read"))
        }),
    });
    let kind = match format {
        Format::Stl => "STL",
        Format::Obj => "OBJ",
        Format::Ply => "PLY",
        Format::Collada => "Collada",
    };
    let scene = match parsed {
        Ok(Ok(scene)) => scene,
        Ok(Err(e)) => return Err(err(format!("cannot parse {kind}: {}", first_line(&e)))),
        Err(_) => return Err(err(format!("the {kind} parser failed on this file"))),
    };
    let mesh = mesh_loader::Mesh::merge(scene.meshes);
    if mesh.faces.len() > limits.max_mesh_triangles {
        return Err(too_many(mesh.faces.len()));
    }
    Ok(TriangleMesh {
        vertices: mesh
            .vertices
            .iter()
            .map(|v| Point3::new(v[0] as f64, v[1] as f64, v[2] as f64))
            .collect(),
        indices: mesh.faces,
    })
}

/// The `n` triangles of a binary STL (see [`binary_stl_triangles`]), three
/// vertices each in file order: what `mesh-loader` returns for it (the same
/// values, f32 widened to f64), read in one pass without its normals, colours
/// and per-triangle copies — the bulk of loading a 100k-triangle scan.
fn read_binary_stl(bytes: &[u8], n: usize) -> TriangleMesh {
    let value = |b: &[u8]| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    let mut vertices = Vec::with_capacity(3 * n);
    for triangle in bytes[84..].chunks_exact(50).take(n) {
        // 12 bytes of normal, three corners of 12 bytes, 2 attribute bytes.
        for corner in triangle[12..48].chunks_exact(12) {
            vertices.push(Point3::new(
                value(&corner[0..4]),
                value(&corner[4..8]),
                value(&corner[8..12]),
            ));
        }
    }
    let indices = (0..n as u32)
        .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
        .collect();
    TriangleMesh { vertices, indices }
}

/// The parser's message without anything after its first line, so a message
/// never carries more than a short excerpt of the file.
fn first_line(e: &std::io::Error) -> String {
    let s = e.to_string();
    let line = s.lines().next().unwrap_or_default();
    line.chars().take(200).collect()
}

/// The triangle count of a binary STL (header, count, 50 bytes per
/// triangle), or `None` when the bytes are not one. A text file is never
/// taken for one: its bytes 80–83 are characters (tab or above), so the count
/// they spell is at least 0x0909_0909 (151 million triangles, a 7.5 GB
/// file), and larger counts are refused here.
fn binary_stl_triangles(bytes: &[u8]) -> Option<usize> {
    let count: [u8; 4] = bytes.get(80..84)?.try_into().ok()?;
    let n = u32::from_le_bytes(count) as usize;
    (n < 0x0909_0909 && bytes.len() == 84 + 50 * n).then_some(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> std::path::PathBuf {
        let d = std::env::temp_dir().join(format!("tsukami-mesh-io-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d.join(name)
    }

    #[test]
    fn stl_obj_and_ply_round_trip_with_scale() {
        let c = TriangleMesh::cylinder(0.03, 0.1, 12);
        for name in ["c.stl", "c.obj", "c.ply", "C.PLY"] {
            let p = tmp(name);
            match Format::of_path(&p).unwrap() {
                Format::Stl => c.write_stl(&p).unwrap(),
                Format::Obj => c.write_obj(&p).unwrap(),
                _ => c.write_ply(&p).unwrap(),
            }
            let back = TriangleMesh::load(&p, Vector3::new(2.0, 2.0, 2.0)).unwrap();
            assert_eq!(back.indices.len(), c.indices.len());
            assert!(back.is_closed(), "{name}");
            assert!((back.volume() - 8.0 * c.volume()).abs() < 1e-6, "{name}");
            // Mirroring keeps the normals outward.
            let m = TriangleMesh::load(&p, Vector3::new(-1.0, 1.0, 1.0)).unwrap();
            assert!(m.volume() > 0.0, "{name}");
        }
    }

    #[test]
    fn binary_stl_reads_as_mesh_loader_reads_it() {
        let p = tmp("direct.stl");
        TriangleMesh::uv_sphere(0.05, 7, 11).write_stl(&p).unwrap();
        let mut bytes = std::fs::read(&p).unwrap();
        // Exporters often begin a binary header with "solid".
        bytes[..12].copy_from_slice(b"solid sphere");
        let n = binary_stl_triangles(&bytes).unwrap();
        let direct = read_binary_stl(&bytes, n);
        let scene = mesh_loader::Loader::default()
            .merge_meshes(true)
            .load_stl_from_slice(&bytes, &p)
            .unwrap();
        let theirs = mesh_loader::Mesh::merge(scene.meshes);
        assert_eq!(direct.indices, theirs.faces);
        let widened: Vec<Point3<f64>> = theirs
            .vertices
            .iter()
            .map(|v| Point3::new(v[0] as f64, v[1] as f64, v[2] as f64))
            .collect();
        assert_eq!(direct.vertices, widened);
        assert_eq!(n, TriangleMesh::uv_sphere(0.05, 7, 11).indices.len());
        // One byte more or less: not a binary STL by size.
        assert_eq!(binary_stl_triangles(&bytes[..bytes.len() - 1]), None);
    }

    #[test]
    fn ascii_stl_with_a_degenerate_triangle_is_cleaned() {
        let p = tmp("ascii.stl");
        let mut text = String::from("solid t\n");
        let c = TriangleMesh::cuboid(Vector3::new(1.0, 2.0, 3.0));
        let mut tris: Vec<[Point3<f64>; 3]> = (0..12).map(|k| c.triangle(k)).collect();
        tris.insert(5, [Point3::origin(); 3]);
        for t in tris {
            text.push_str("facet normal 0 0 0\nouter loop\n");
            for v in t {
                text.push_str(&format!("vertex {} {} {}\n", v.x, v.y, v.z));
            }
            text.push_str("endloop\nendfacet\n");
        }
        text.push_str("endsolid t\n");
        std::fs::write(&p, text).unwrap();
        let (m, r) =
            TriangleMesh::load_with(&p, Vector3::repeat(1.0), &ParseLimits::default()).unwrap();
        assert_eq!(
            (r.triangles_in, r.triangles_out, r.dropped_degenerate),
            (13, 12, 1)
        );
        assert_eq!(
            r.first_problem.as_deref(),
            Some("triangle 5 [15, 16, 17] has zero area")
        );
        assert!(m.is_closed());
    }

    #[test]
    fn refusals_name_the_file_and_the_count() {
        let bad = tmp("bad.stl");
        std::fs::write(&bad, b"solid x\nendsolid x\n").unwrap();
        let e = TriangleMesh::load(&bad, Vector3::repeat(1.0))
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.stl") && e.contains("no triangles"), "{e}");
        let big = tmp("big.stl");
        TriangleMesh::uv_sphere(1.0, 20, 20)
            .write_stl(&big)
            .unwrap();
        let limits = ParseLimits {
            max_mesh_triangles: 100,
            ..ParseLimits::default()
        };
        let e = TriangleMesh::load_with(&big, Vector3::repeat(1.0), &limits)
            .unwrap_err()
            .to_string();
        assert!(e.contains("big.stl") && e.contains("760 triangles"), "{e}");
        let off = tmp("x.off");
        std::fs::write(&off, b"OFF\n").unwrap();
        let e = TriangleMesh::load(&off, Vector3::repeat(1.0))
            .unwrap_err()
            .to_string();
        assert!(e.contains("unsupported mesh format '.off'"), "{e}");
        assert!(e.contains(".stl, .obj, .ply or .dae"), "{e}");
        let ply = tmp("x.ply");
        std::fs::write(&ply, b"ply\n").unwrap();
        let e = TriangleMesh::load(&ply, Vector3::repeat(1.0))
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.ply") && e.contains("cannot parse PLY"), "{e}");
        TriangleMesh::uv_sphere(1.0, 20, 20)
            .write_ply(&ply)
            .unwrap();
        let e = TriangleMesh::load_with(&ply, Vector3::repeat(1.0), &limits)
            .unwrap_err()
            .to_string();
        assert!(e.contains("x.ply: too large: 760 faces"), "{e}");
        let deep = tmp("deep.dae");
        std::fs::write(&deep, "<COLLADA>".repeat(10_000)).unwrap();
        let e = TriangleMesh::load(&deep, Vector3::repeat(1.0))
            .unwrap_err()
            .to_string();
        assert!(e.contains("deep.dae") && e.contains("nested deeper"), "{e}");
    }

    #[test]
    fn collada_applies_node_transforms_and_units() {
        // One triangle, unit = centimetres, node translated by 10 units in x.
        let dae = r##"<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
 <asset><unit meter="0.01" name="centimeter"/><up_axis>Z_UP</up_axis></asset>
 <library_geometries><geometry id="g"><mesh>
  <source id="p"><float_array id="pa" count="9">0 0 0 1 0 0 0 1 0</float_array>
   <technique_common><accessor source="#pa" count="3" stride="3">
    <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
   </accessor></technique_common></source>
  <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
  <triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
 </mesh></geometry></library_geometries>
 <library_visual_scenes><visual_scene id="s"><node id="n">
  <translate>10 0 0</translate><instance_geometry url="#g"/></node></visual_scene></library_visual_scenes>
 <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>"##;
        let p = tmp("t.dae");
        std::fs::write(&p, dae).unwrap();
        let m = TriangleMesh::load(&p, Vector3::repeat(1.0)).unwrap();
        assert_eq!(m.indices.len(), 1);
        let (lo, hi) = m.aabb();
        assert!(
            (lo.x - 0.1).abs() < 1e-6 && (hi.x - 0.11).abs() < 1e-6,
            "{lo} {hi}"
        );
        assert!((hi.y - 0.01).abs() < 1e-6, "{hi}");
        // Nested nodes compose parent first; a geometry instanced twice is
        // placed twice.
        let nested = dae.replace(
            r##"<node id="n">
  <translate>10 0 0</translate><instance_geometry url="#g"/></node>"##,
            r##"<node id="a"><rotate>0 0 1 90</rotate>
  <node id="b"><translate>10 0 0</translate><instance_geometry url="#g"/></node>
  <node id="c"><instance_geometry url="#g"/></node></node>"##,
        );
        assert_ne!(nested, dae);
        let p = tmp("nested.dae");
        std::fs::write(&p, nested).unwrap();
        let m = TriangleMesh::load(&p, Vector3::repeat(1.0)).unwrap();
        assert_eq!(m.indices.len(), 2);
        let (lo, hi) = m.aabb();
        // Rotating (10, 0, 0) cm by 90° about z gives (0, 0.1) m.
        assert!(
            (hi.y - 0.11).abs() < 1e-6 && (lo.x + 0.01).abs() < 1e-6,
            "{lo} {hi}"
        );
    }
}
