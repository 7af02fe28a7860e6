//! Sending a mesh file of the client's own disk inline, for a host on another
//! machine.
//!
//! What: [`inline_local_mesh`] turns a `set_object` request that names a mesh
//! file by path (`shape.mesh.path`, on the client's disk) into one that
//! carries the file's bytes (`shape.inline`, base64), keeping its scale and
//! naming the object after the file when the request names none;
//! `tsukami set-object --inline` sends it.
//!
//! Why: the host reads mesh paths on its own disk, inside its model roots; a
//! client on another machine (a laptop, the vision PC) has its object's mesh on
//! its disk. The same request works locally and, with `--inline`, remotely.
//!
//! How: the file is read bounded ([`tsukami_body::limits::read_bounded`], a
//! regular file of at most `max_bytes`), its format taken from the extension
//! (`.stl`, `.obj`, `.ply`); nothing is parsed here — the host checks the mesh and
//! refuses one over its `max_mesh_bytes` or `max_payload_bytes`.
//!
//! ```
//! use tsukami::inline::inline_local_mesh;
//! use tsukami_msgs::planner::{ObjectShape, SetObject};
//! let path = std::env::temp_dir().join(format!("tsukami-inline-doc-{}.stl", std::process::id()));
//! std::fs::write(&path, b"solid x\nendsolid x\n").unwrap();
//! let mut req: SetObject = serde_json::from_value(serde_json::json!({
//!     "shape": {"mesh": {"path": path, "scale": 0.001}}, "mass": 0.2,
//!     "pose": {"position": [0.5, 0, 1]}})).unwrap();
//! inline_local_mesh(&mut req, 1 << 20).unwrap();
//! let ObjectShape::Inline { data_base64, scale, .. } = &req.shape else { panic!() };
//! assert_eq!(data_base64, "c29saWQgeAplbmRzb2xpZCB4Cg==");
//! assert_eq!(*scale, Some(0.001));
//! assert!(req.name.as_deref().unwrap().starts_with("tsukami-inline-doc"));
//! std::fs::remove_file(&path).unwrap();
//! ```

use std::path::Path;

use anyhow::{bail, Context, Result};
use tsukami_body::mesh_inline::encode_base64;
use tsukami_msgs::planner::{MeshFormat, ObjectShape, SetObject};

/// Replaces `req.shape`'s `mesh` (a path on this machine) with the file's
/// bytes inline; the file may have at most `max_bytes` bytes.
pub fn inline_local_mesh(req: &mut SetObject, max_bytes: u64) -> Result<()> {
    let ObjectShape::Mesh { path, scale } = &req.shape else {
        bail!("--inline sends the file named by `shape.mesh.path`; this request names none");
    };
    let file = Path::new(path);
    let ext = file.extension().and_then(|e| e.to_str()).unwrap_or("");
    let Some(format) = MeshFormat::from_extension(ext) else {
        bail!("{path}: an inline mesh is an .stl, .obj or .ply file, not `.{ext}`");
    };
    let bytes = tsukami_body::limits::read_bounded(file, max_bytes, "mesh")
        .with_context(|| format!("reading the mesh to send inline ({path})"))?;
    if req.name.is_none() {
        req.name = file.file_stem().map(|s| s.to_string_lossy().into_owned());
    }
    req.shape = ObjectShape::Inline {
        format,
        data_base64: encode_base64(&bytes),
        scale: *scale,
    };
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(shape: serde_json::Value) -> SetObject {
        serde_json::from_value(serde_json::json!({
            "shape": shape, "mass": 0.2, "pose": {"position": [0.5, 0, 1]}}))
        .unwrap()
    }

    #[test]
    fn only_a_local_stl_obj_or_ply_within_the_limit_is_sent() {
        let dir = std::env::temp_dir().join(format!("tsukami-inline-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let dae = dir.join("a.dae");
        std::fs::write(&dae, b"<COLLADA/>\n").unwrap();
        let ply = dir.join("scan.ply");
        std::fs::write(&ply, b"ply\n").unwrap();
        let mut scan = request(serde_json::json!({"mesh": {"path": ply, "scale": 0.001}}));
        inline_local_mesh(&mut scan, 100).unwrap();
        assert_eq!(scan.name.as_deref(), Some("scan"));
        assert_eq!(
            scan.shape,
            ObjectShape::Inline {
                format: MeshFormat::Ply,
                data_base64: encode_base64(b"ply\n"),
                scale: Some(0.001),
            }
        );
        let obj = dir.join("Box.OBJ");
        std::fs::write(&obj, b"v 0 0 0\n").unwrap();
        let mut named = request(serde_json::json!({"mesh": {"path": obj}}));
        named.name = Some("mine".into());
        inline_local_mesh(&mut named, 100).unwrap();
        assert_eq!(named.name.as_deref(), Some("mine"));
        assert!(matches!(
            named.shape,
            ObjectShape::Inline {
                format: MeshFormat::Obj,
                scale: None,
                ..
            }
        ));
        let e = |shape, limit| {
            inline_local_mesh(&mut request(shape), limit)
                .unwrap_err()
                .to_string()
        };
        let collada = e(serde_json::json!({"mesh": {"path": dae}}), 100);
        assert!(
            collada.contains("an .stl, .obj or .ply file, not `.dae`"),
            "{collada}"
        );
        let big = e(serde_json::json!({"mesh": {"path": obj}}), 4);
        assert!(big.contains("reading the mesh to send inline"), "{big}");
        let model = e(serde_json::json!({"model": {"name": "can_350ml"}}), 100);
        assert!(model.contains("shape.mesh.path"), "{model}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
