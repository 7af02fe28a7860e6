//! Meshes handed over inline: base64 text in a request, decoded and parsed in
//! memory, bounded.
//!
//! What: [`encode_base64`] makes what a client sends; [`decode_base64`]
//! turns the base64 text of a mesh file into its bytes, refusing it before
//! decoding when the bytes would be more than a limit ([`decoded_len`] gives
//! the exact count from the text alone);
//! [`TriangleMesh::from_base64`] decodes and parses (STL, OBJ, PLY, Collada, as
//! [`TriangleMesh::from_bytes_with`]), scales and cleans. [`InlineError`] says
//! what was wrong: no data, too many bytes (with the count and the limit), not
//! base64 (with the offset), too many triangles, or the mesh itself.
//!
//! Why: a client on another machine (a remote client, the vision PC) cannot
//! name a file on the host's disk; it sends the file's bytes in the JSON
//! request. Those bytes are untrusted: the size is checked before anything is
//! allocated for them, nothing touches the disk, and no error quotes them.
//!
//! How: the standard base64 alphabet (`A–Z a–z 0–9 + /`), `=` padding
//! optional, ASCII whitespace (the line breaks of `base64` tools) ignored. The
//! text is scanned once to count its symbols; only when it has whitespace is a
//! copy without it made before decoding.
//!
//! ```
//! use nalgebra::Vector3;
//! use tsukami_body::limits::ParseLimits;
//! use tsukami_body::mesh::TriangleMesh;
//! use tsukami_body::mesh_inline::{decode_base64, encode_base64, InlineError};
//! use tsukami_body::mesh_io::Format;
//! // One triangle as ASCII STL, base64.
//! let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\nendloop\nendfacet\nendsolid t\n";
//! let text = encode_base64(stl.as_bytes());
//! let (mesh, _) = TriangleMesh::from_base64(&text, Format::Stl, Vector3::repeat(1.0), &ParseLimits::default()).unwrap();
//! assert_eq!(mesh.indices.len(), 1);
//! // More bytes than the limit: refused before decoding, naming both counts.
//! assert_eq!(decode_base64(&text, 10), Err(InlineError::TooLarge { decoded: stl.len() as u64, limit: 10 }));
//! assert!(matches!(decode_base64("no base64!", 100), Err(InlineError::NotBase64(_))));
//! ```

use std::path::Path;

use base64::engine::general_purpose::STANDARD_PAD_INDIFFERENT;
use base64::{DecodeError, Engine};
use nalgebra::Vector3;

use crate::error::BodyError;
use crate::limits::ParseLimits;
use crate::mesh::TriangleMesh;
use crate::mesh_clean::MeshCleanup;
use crate::mesh_io::Format;

/// Why an inline mesh was refused.
#[derive(Debug, thiserror::Error)]
pub enum InlineError {
    /// The text has no base64 symbols.
    #[error("no data: the mesh's bytes are missing")]
    Empty,
    /// The decoded bytes would be more than the limit (checked before decoding).
    #[error("{} decoded, more than the limit of {}", size(*decoded), size(*limit))]
    TooLarge {
        /// Bytes the text decodes to.
        decoded: u64,
        /// The limit, bytes.
        limit: u64,
    },
    /// The text is not base64; the message says where, never what.
    #[error("not base64 (standard alphabet A-Z a-z 0-9 + /, `=` padding): {0}")]
    NotBase64(String),
    /// The mesh has more triangles than `ParseLimits::max_mesh_triangles`
    /// (the message gives the count and the limit).
    #[error("{0}")]
    Triangles(String),
    /// The bytes are not a usable mesh of the format (the parser's message,
    /// first line only, tokens quoted from the data replaced by `…`).
    #[error("{0}")]
    Mesh(String),
}

impl PartialEq for InlineError {
    fn eq(&self, other: &Self) -> bool {
        self.to_string() == other.to_string()
    }
}

/// `n` bytes as people read them: `812 bytes`, `4.0 KiB (4096 bytes)`,
/// `80.0 MiB (83886080 bytes)`.
pub fn size(n: u64) -> String {
    const KIB: f64 = 1024.0;
    match n {
        0..1024 => format!("{n} bytes"),
        1024..1_048_576 => format!("{:.1} KiB ({n} bytes)", n as f64 / KIB),
        _ => format!("{:.1} MiB ({n} bytes)", n as f64 / (KIB * KIB)),
    }
}

/// `bytes` as base64 text (standard alphabet, padded): what a client puts in
/// an inline mesh's `data_base64`.
pub fn encode_base64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// The number of bytes `text` decodes to (exact for valid base64; ASCII
/// whitespace ignored), from one scan of the text.
pub fn decoded_len(text: &str) -> u64 {
    let symbols = text.bytes().filter(|b| !b.is_ascii_whitespace()).count() as u64;
    let padding = text
        .bytes()
        .rev()
        .filter(|b| !b.is_ascii_whitespace())
        .take(2)
        .take_while(|&b| b == b'=')
        .count() as u64;
    let data = symbols - padding;
    data / 4 * 3 + [0, 0, 1, 2][(data % 4) as usize]
}

/// Decodes base64 `text` into at most `limit` bytes.
pub fn decode_base64(text: &str, limit: u64) -> Result<Vec<u8>, InlineError> {
    let decoded = decoded_len(text);
    if decoded == 0 {
        return Err(InlineError::Empty);
    }
    if decoded > limit {
        return Err(InlineError::TooLarge { decoded, limit });
    }
    let spaced = text.bytes().any(|b| b.is_ascii_whitespace());
    let result = if spaced {
        let compact: Vec<u8> = text.bytes().filter(|b| !b.is_ascii_whitespace()).collect();
        STANDARD_PAD_INDIFFERENT.decode(compact)
    } else {
        STANDARD_PAD_INDIFFERENT.decode(text)
    };
    result.map_err(|e| InlineError::NotBase64(where_wrong(text, &e, spaced)))
}

/// Where the decoder stopped, as an offset into the original text; never the
/// offending character.
fn where_wrong(text: &str, e: &DecodeError, spaced: bool) -> String {
    // The decoder's offsets count symbols only: map them back to the text.
    let in_text = |k: usize| {
        if !spaced {
            return k;
        }
        text.bytes()
            .enumerate()
            .filter(|(_, b)| !b.is_ascii_whitespace())
            .nth(k)
            .map_or(text.len(), |(i, _)| i)
    };
    match e {
        DecodeError::InvalidByte(k, b'=') => {
            format!("padding `=` inside the data at offset {}", in_text(*k))
        }
        DecodeError::InvalidByte(k, _) => {
            format!("a character outside the alphabet at offset {}", in_text(*k))
        }
        DecodeError::InvalidLength(n) => {
            format!("{n} symbols cannot be base64 (a last group of one symbol)")
        }
        DecodeError::InvalidLastSymbol { offset, .. } => format!(
            "the last symbol, at offset {}, has bits that encode nothing (truncated or corrupted data)",
            in_text(*offset)
        ),
        DecodeError::InvalidPadding => "wrong padding".to_string(),
    }
}

impl TriangleMesh {
    /// Decodes an inline mesh (base64 `text` of a `format` file) within
    /// `limits.max_mesh_bytes` and parses it as
    /// [`TriangleMesh::from_bytes_with`] does (scaled, cleaned, within
    /// `limits.max_mesh_triangles`), in memory only.
    pub fn from_base64(
        text: &str,
        format: Format,
        scale: Vector3<f64>,
        limits: &ParseLimits,
    ) -> Result<(Self, MeshCleanup), InlineError> {
        let bytes = decode_base64(text, limits.max_mesh_bytes)?;
        let label = match format {
            Format::Stl => "inline STL",
            Format::Obj => "inline OBJ",
            Format::Ply => "inline PLY",
            Format::Collada => "inline Collada",
        };
        Self::from_bytes_with(&bytes, format, scale, limits, Path::new(label)).map_err(|e| {
            // Nothing quoted from the bytes: the first line, tokens redacted.
            let message = crate::files::redact(&e.to_string());
            match e {
                BodyError::TooLarge { .. } => InlineError::Triangles(message),
                _ => InlineError::Mesh(message),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b64(bytes: &[u8]) -> String {
        encode_base64(bytes)
    }

    fn binary_stl(mesh: &TriangleMesh) -> Vec<u8> {
        let dir = std::env::temp_dir().join(format!("tsukami-inline-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("m.stl");
        mesh.write_stl(&p).unwrap();
        let bytes = std::fs::read(&p).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        bytes
    }

    #[test]
    fn decoded_len_is_exact_with_and_without_padding_and_line_breaks() {
        for n in 0..40 {
            let data: Vec<u8> = (0..n as u8).collect();
            let text = b64(&data);
            assert_eq!(decoded_len(&text), n as u64, "{text}");
            let bare = text.trim_end_matches('=');
            assert_eq!(decoded_len(bare), n as u64, "{bare}");
            let wrapped: String = text
                .as_bytes()
                .chunks(7)
                .map(|c| std::str::from_utf8(c).unwrap())
                .collect::<Vec<_>>()
                .join("\r\n");
            assert_eq!(decoded_len(&wrapped), n as u64);
            if n > 0 {
                assert_eq!(decode_base64(&wrapped, 100).unwrap(), data);
                assert_eq!(decode_base64(bare, 100).unwrap(), data);
            }
        }
    }

    #[test]
    fn a_binary_stl_decodes_to_the_same_mesh_as_its_file() {
        let cyl = TriangleMesh::cylinder(0.03, 0.1, 16);
        let bytes = binary_stl(&cyl);
        let (mesh, report) = TriangleMesh::from_base64(
            &b64(&bytes),
            Format::Stl,
            Vector3::repeat(2.0),
            &ParseLimits::default(),
        )
        .unwrap();
        assert_eq!(report.dropped(), 0);
        assert_eq!(mesh.indices.len(), cyl.indices.len());
        assert!(mesh.is_closed());
        assert!((mesh.volume() - 8.0 * cyl.volume()).abs() < 1e-6);
    }

    #[test]
    fn refusals_say_what_and_where_never_the_data() {
        let limits = ParseLimits::default();
        let one = Vector3::repeat(1.0);
        let parse = |text: &str, format| TriangleMesh::from_base64(text, format, one, &limits);
        assert_eq!(parse("", Format::Stl).unwrap_err(), InlineError::Empty);
        assert_eq!(parse(" \n==", Format::Stl).unwrap_err(), InlineError::Empty);
        let e = parse("QUJD!EVG", Format::Stl).unwrap_err().to_string();
        assert!(e.contains("outside the alphabet at offset 4"), "{e}");
        assert!(!e.contains('!'), "{e}");
        let e = parse("QUJD\nRE=V", Format::Stl).unwrap_err().to_string();
        assert!(e.contains("padding `=` inside the data at offset 7"), "{e}");
        let e = parse("QUJDR", Format::Stl).unwrap_err().to_string();
        assert!(e.contains("5 symbols cannot be base64"), "{e}");
        let secret = "solid SECRET-TOKEN-123\nfacet nonsense 'SECRET-TOKEN-123-and-more'\n";
        for format in [Format::Stl, Format::Obj, Format::Ply, Format::Collada] {
            let e = parse(&b64(secret.as_bytes()), format)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("inline "), "{e}");
            assert!(!e.contains("SECRET"), "{e}");
        }
        // Binary STL whose header claims more triangles than the limit.
        let small = ParseLimits {
            max_mesh_triangles: 10,
            ..limits
        };
        let bytes = binary_stl(&TriangleMesh::uv_sphere(0.05, 6, 8));
        let e = TriangleMesh::from_base64(&b64(&bytes), Format::Stl, one, &small)
            .unwrap_err()
            .to_string();
        assert!(e.contains("more than the limit of 10"), "{e}");
        assert!(matches!(
            TriangleMesh::from_base64(&b64(&bytes), Format::Stl, one, &small),
            Err(InlineError::Triangles(_))
        ));
        let tight = ParseLimits {
            max_mesh_bytes: 1000,
            ..limits
        };
        let e = TriangleMesh::from_base64(&b64(&bytes), Format::Stl, one, &tight).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!(
                "{} decoded, more than the limit of 1000 bytes",
                size(bytes.len() as u64)
            )
        );
    }

    #[test]
    fn a_ply_decodes_to_the_mesh_written_and_its_refusals_name_no_data() {
        let cyl = TriangleMesh::cylinder(0.03, 0.1, 16);
        let limits = ParseLimits::default();
        let (mesh, report) = TriangleMesh::from_base64(
            &b64(&crate::ply::to_binary(&cyl)),
            Format::Ply,
            Vector3::repeat(2.0),
            &limits,
        )
        .unwrap();
        assert_eq!(report.dropped(), 0);
        assert_eq!(mesh.indices.len(), cyl.indices.len());
        assert!(mesh.is_closed());
        assert!((mesh.volume() - 8.0 * cyl.volume()).abs() < 1e-6);
        let one = Vector3::repeat(1.0);
        let lying = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 3000000\n\
            property list uchar int vertex_indices\nend_header\n";
        let e = TriangleMesh::from_base64(&b64(lying.as_bytes()), Format::Ply, one, &limits);
        assert!(
            matches!(&e, Err(InlineError::Triangles(m)) if m == "inline PLY: too large: 3000000 faces, more than the limit of 2000000 triangles"),
            "{e:?}"
        );
        let secret =
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
            property float z\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n\
            0 'SECRET-TOKEN' 0\n";
        let e = TriangleMesh::from_base64(&b64(secret.as_bytes()), Format::Ply, one, &limits)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "inline PLY: bad mesh: cannot parse PLY: vertex 0 (line 10): a value is not a number"
        );
    }

    #[test]
    fn obj_from_bytes_ignores_material_libraries() {
        let obj = "mtllib /etc/passwd\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
        let (mesh, _) = TriangleMesh::from_base64(
            &b64(obj.as_bytes()),
            Format::Obj,
            Vector3::repeat(1.0),
            &ParseLimits::default(),
        )
        .unwrap();
        assert_eq!(mesh.indices.len(), 4);
        assert!(mesh.is_closed());
    }

    #[test]
    fn sizes_read_as_people_read_them() {
        assert_eq!(size(812), "812 bytes");
        assert_eq!(size(4096), "4.0 KiB (4096 bytes)");
        assert_eq!(size(80 << 20), "80.0 MiB (83886080 bytes)");
    }
}
