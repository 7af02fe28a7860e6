//! PLY meshes (the Stanford polygon format of scanners, MeshLab and Open3D):
//! a bounded reader for untrusted bytes, and a binary writer.
//!
//! What: [`read`] parses the bytes of a PLY file — ASCII, binary little
//! endian or binary big endian — into one unscaled, uncleaned
//! [`TriangleMesh`]: the `x y z` of the `vertex` element and the
//! `vertex_indices` (or `vertex_index`) lists of the `face` element, each
//! polygon fan-triangulated; every other property (normals, colours,
//! texture coordinates) and every other element (edges, materials, …) is
//! skipped. [`to_binary`] writes one (binary little endian, `float`
//! positions, `uchar`/`int` index lists). [`PlyError`] says what was wrong
//! and where — a header line, a vertex or face number, a data line or byte —
//! never what the file holds.
//!
//! Why: scans and datasets of household objects come as PLY, and a client on
//! another machine sends its scan as it is (issue #26). `mesh-loader` has no
//! PLY reader, and the crates that have one (`ply-rs`, unmaintained; its fork
//! `ply-rs-bw`, a map per vertex and a parser generator at build time;
//! `serde-ply`, young) read every element into their own types and leave
//! the bounds a hostile header needs to the caller: the positions and the
//! index lists are all this crate needs, in a few hundred lines.
//!
//! How: the header (at most [`MAX_HEADER_BYTES`], any line ending) is read
//! first. Before anything is allocated, the counts it states are checked
//! against [`ParseLimits::max_mesh_triangles`] (faces, and at most three
//! vertices per triangle) and against the bytes after it (in binary every
//! record needs at least its scalar properties and list counts, in ASCII two
//! bytes per value), so a header claiming 10¹² vertices is refused at once.
//! The records are then read in the header's order through one cursor
//! (binary) or one tokenizer (ASCII, values separated by any whitespace). A
//! face with an index outside the vertices, a negative list length, a face
//! of fewer than three vertices or a value that is not a number is an error
//! naming the face or vertex; NaN and infinite coordinates are passed on, so
//! that cleaning drops their triangles ([`crate::mesh_clean`]) as it does for
//! STL and OBJ. Bytes after the last element are ignored.
//!
//! ```
//! use tsukami_body::limits::ParseLimits;
//! use tsukami_body::mesh::TriangleMesh;
//! use tsukami_body::ply::{read, to_binary, PlyError};
//! // A square pyramid: four triangles and a quad, with a normal per vertex.
//! let text = "ply\nformat ascii 1.0\ncomment made by hand\n\
//!     element vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
//!     property float nx\nproperty float ny\nproperty float nz\n\
//!     element face 5\nproperty list uchar int vertex_indices\nend_header\n\
//!     0 0 0 0 0 -1\n1 0 0 0 0 -1\n1 1 0 0 0 -1\n0 1 0 0 0 -1\n0.5 0.5 1 0 0 1\n\
//!     4 0 3 2 1\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n";
//! let limits = ParseLimits::default();
//! let mesh = read(text.as_bytes(), &limits).unwrap();
//! assert_eq!(mesh.indices.len(), 6);
//! assert!(mesh.is_closed() && (mesh.volume() - 1.0 / 3.0).abs() < 1e-12);
//! // The binary file this crate writes reads back as the same mesh.
//! assert_eq!(read(&to_binary(&mesh), &limits).unwrap(), mesh);
//! // A header claiming more than the data can hold is refused before allocating.
//! let lying = "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000000\n\
//!     property float x\nproperty float y\nproperty float z\n\
//!     element face 0\nproperty list uchar int vertex_indices\nend_header\n";
//! assert!(matches!(read(lying.as_bytes(), &limits), Err(PlyError::TooLarge(_))));
//! ```

use nalgebra::Point3;

use crate::limits::ParseLimits;
use crate::mesh::TriangleMesh;

/// The longest header read, in bytes: far more than any exporter writes
/// (a few hundred bytes with comments), small enough to scan at once.
pub const MAX_HEADER_BYTES: usize = 64 << 10;

/// Why a PLY file was refused. Messages name header lines, records and
/// positions, never the file's words or values.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlyError {
    /// More faces, triangles or vertices than the limits allow (the message
    /// gives the count and the limit).
    #[error("{0}")]
    TooLarge(String),
    /// Not a PLY file, or one whose header or data is malformed.
    #[error("{0}")]
    Malformed(String),
}

fn bad(message: impl Into<String>) -> PlyError {
    PlyError::Malformed(message.into())
}

/// How the records after the header are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// A scalar type of the header (`char` … `double`, or their sized names).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(word: &[u8]) -> Option<Ty> {
        Some(match word {
            b"char" | b"int8" => Ty::I8,
            b"uchar" | b"uint8" => Ty::U8,
            b"short" | b"int16" => Ty::I16,
            b"ushort" | b"uint16" => Ty::U16,
            b"int" | b"int32" => Ty::I32,
            b"uint" | b"uint32" => Ty::U32,
            b"float" | b"float32" => Ty::F32,
            b"double" | b"float64" => Ty::F64,
            _ => return None,
        })
    }

    /// Bytes of one value in a binary file.
    fn size(self) -> u64 {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Ty::F32 | Ty::F64)
    }
}

/// One property of an element: a scalar, or a list (its length's type and
/// its items' type).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Scalar(Ty),
    List(Ty, Ty),
}

#[derive(Debug, Clone)]
struct Property {
    name: Vec<u8>,
    kind: Kind,
}

#[derive(Debug, Clone)]
struct Element {
    name: Vec<u8>,
    count: u64,
    /// The header line declaring it (1-based).
    line: usize,
    properties: Vec<Property>,
}

impl Element {
    /// How the element is called in messages: `vertex` and `face` by name,
    /// any other by its header line (its name is the file's word).
    fn label(&self) -> String {
        match self.name.as_slice() {
            b"vertex" | b"face" => String::from_utf8_lossy(&self.name).into_owned(),
            _ => format!("the element of header line {}", self.line),
        }
    }

    /// The fewest bytes one record can take.
    fn min_record_bytes(&self, encoding: Encoding) -> u64 {
        match encoding {
            // A value is at least one character and a separator.
            Encoding::Ascii => 2 * self.properties.len() as u64,
            _ => self
                .properties
                .iter()
                .map(|p| match p.kind {
                    Kind::Scalar(t) | Kind::List(t, _) => t.size(),
                })
                .sum(),
        }
    }
}

#[derive(Debug)]
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Lines in the header, `end_header` included.
    lines: usize,
}

/// Reads a PLY file's bytes into one mesh (unscaled, uncleaned), within
/// `limits.max_mesh_triangles`; see the module documentation.
pub fn read(bytes: &[u8], limits: &ParseLimits) -> Result<TriangleMesh, PlyError> {
    let (header, start) = parse_header(bytes)?;
    let data = bytes.get(start..).unwrap_or_default();
    let layout = Layout::of(&header)?;
    check_counts(&header, &layout, data.len(), limits)?;
    match header.encoding {
        Encoding::Ascii => {
            let mut source = Ascii {
                data,
                pos: 0,
                line: header.lines + 1,
            };
            read_elements(&header, &layout, &mut source, limits)
        }
        encoding => {
            let mut source = Binary {
                data,
                pos: 0,
                big_endian: encoding == Encoding::BigEndian,
            };
            read_elements(&header, &layout, &mut source, limits)
        }
    }
}

/// The header's lines, one at a time, within [`MAX_HEADER_BYTES`].
struct HeaderLines<'a> {
    bytes: &'a [u8],
    pos: usize,
    number: usize,
}

impl<'a> HeaderLines<'a> {
    /// The next line without its `\n` or `\r\n`, or why there is none.
    fn next(&mut self) -> Result<&'a [u8], PlyError> {
        let window = &self.bytes[..self.bytes.len().min(MAX_HEADER_BYTES)];
        let rest = window.get(self.pos..).unwrap_or_default();
        let (line, advance) = match rest.iter().position(|&b| b == b'\n') {
            Some(end) => (&rest[..end], end + 1),
            None if self.bytes.len() > MAX_HEADER_BYTES => {
                return Err(bad(format!(
                    "no `end_header` within the first {MAX_HEADER_BYTES} bytes"
                )))
            }
            None if rest.is_empty() => {
                return Err(bad("the header has no `end_header` line (truncated?)"))
            }
            // The last line of a file that is only a header.
            None => (rest, rest.len()),
        };
        self.pos += advance;
        self.number += 1;
        Ok(line.strip_suffix(b"\r").unwrap_or(line))
    }
}

/// The header, and where the data begins.
fn parse_header(bytes: &[u8]) -> Result<(Header, usize), PlyError> {
    let mut lines = HeaderLines {
        bytes,
        pos: 0,
        number: 0,
    };
    if !bytes.starts_with(b"ply") || lines.next()? != b"ply" {
        return Err(bad("not a PLY file: the first line is not `ply`"));
    }
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let line = lines.next()?;
        let n = lines.number;
        let words: Vec<&[u8]> = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty())
            .collect();
        match words.first().copied() {
            None | Some(b"comment" | b"obj_info") => {}
            Some(b"end_header") => break,
            Some(b"format") if encoding.is_some() => {
                return Err(bad(format!("header line {n}: a second `format` line")))
            }
            Some(b"format") => encoding = Some(format_line(&words, n)?),
            Some(b"element") => elements.push(element_line(&words, n)?),
            Some(b"property") => {
                let Some(element) = elements.last_mut() else {
                    return Err(bad(format!(
                        "header line {n}: a property before any element"
                    )));
                };
                element.properties.push(property_line(&words, n)?);
            }
            Some(_) => {
                return Err(bad(format!(
                    "header line {n}: not a header keyword (format, element, property, comment, obj_info or end_header)"
                )))
            }
        }
    }
    let encoding = encoding.ok_or_else(|| bad("the header has no `format` line"))?;
    let header = Header {
        encoding,
        elements,
        lines: lines.number,
    };
    Ok((header, lines.pos))
}

const UNKNOWN_ENCODING: &str =
    "unknown encoding (ascii, binary_little_endian or binary_big_endian)";

/// `format ascii|binary_little_endian|binary_big_endian 1.0`.
fn format_line(words: &[&[u8]], n: usize) -> Result<Encoding, PlyError> {
    let [_, encoding, version] = words else {
        return Err(bad(format!(
            "header line {n}: `format` takes an encoding and a version"
        )));
    };
    let encoding = match *encoding {
        b"ascii" => Encoding::Ascii,
        b"binary_little_endian" => Encoding::LittleEndian,
        b"binary_big_endian" => Encoding::BigEndian,
        _ => return Err(bad(format!("header line {n}: {UNKNOWN_ENCODING}"))),
    };
    if !matches!(*version, b"1.0" | b"1") {
        return Err(bad(format!(
            "header line {n}: the format version is not 1.0"
        )));
    }
    Ok(encoding)
}

/// `element <name> <count>`.
fn element_line(words: &[&[u8]], n: usize) -> Result<Element, PlyError> {
    let [_, name, count] = words else {
        return Err(bad(format!(
            "header line {n}: `element` takes a name and a count"
        )));
    };
    let count = std::str::from_utf8(count)
        .ok()
        .and_then(|c| c.parse::<u64>().ok())
        .ok_or_else(|| {
            bad(format!(
                "header line {n}: the element count is not a whole number below 2^64"
            ))
        })?;
    Ok(Element {
        name: name.to_vec(),
        count,
        line: n,
        properties: Vec::new(),
    })
}

/// `property <type> <name>` or `property list <count type> <item type> <name>`.
fn property_line(words: &[&[u8]], n: usize) -> Result<Property, PlyError> {
    let unknown = || {
        bad(format!(
            "header line {n}: unknown property type (char, uchar, short, ushort, int, uint, float, double or their sized names)"
        ))
    };
    let (kind, name) = match words {
        [_, b"list", count, item, name] => {
            let count = Ty::parse(count).ok_or_else(unknown)?;
            if !count.is_integer() {
                return Err(bad(format!(
                    "header line {n}: a list's length must have an integer type"
                )));
            }
            (
                Kind::List(count, Ty::parse(item).ok_or_else(unknown)?),
                name,
            )
        }
        [_, b"list", ..] => {
            return Err(bad(format!(
                "header line {n}: a list property takes a length type, an item type and a name"
            )))
        }
        [_, ty, name] => (Kind::Scalar(Ty::parse(ty).ok_or_else(unknown)?), name),
        _ => {
            return Err(bad(format!(
                "header line {n}: `property` takes a type and a name"
            )))
        }
    };
    Ok(Property {
        name: name.to_vec(),
        kind,
    })
}

/// Which elements and properties hold the mesh.
struct Layout {
    vertex: usize,
    /// For each vertex property, the coordinate it holds (0, 1, 2) if any.
    coordinate: Vec<Option<usize>>,
    face: usize,
    /// The face property holding the index list.
    indices: usize,
}

impl Layout {
    fn of(header: &Header) -> Result<Layout, PlyError> {
        let vertex = only_element(header, b"vertex")?
            .ok_or_else(|| bad("the header has no `vertex` element"))?;
        let face = only_element(header, b"face")?
            .ok_or_else(|| bad("the header has no `face` element: a point cloud, not a mesh"))?;
        let properties = &header.elements[vertex].properties;
        let mut coordinate = vec![None; properties.len()];
        for (axis, name) in [b"x", b"y", b"z"].into_iter().enumerate() {
            let k = only_property(&header.elements[vertex], name)?.ok_or_else(|| {
                bad(format!(
                    "the vertex element has no `{}` property",
                    char::from(name[0])
                ))
            })?;
            if !matches!(properties[k].kind, Kind::Scalar(_)) {
                return Err(bad(format!(
                    "vertex property `{}` is a list, not a number",
                    char::from(name[0])
                )));
            }
            coordinate[k] = Some(axis);
        }
        let face_element = &header.elements[face];
        let indices = match only_property(face_element, b"vertex_indices")? {
            Some(k) => k,
            None => only_property(face_element, b"vertex_index")?.ok_or_else(|| {
                bad("the face element has no `vertex_indices` (or `vertex_index`) list")
            })?,
        };
        match face_element.properties[indices].kind {
            Kind::List(_, item) if item.is_integer() => {}
            Kind::List(..) => {
                return Err(bad("the face element's vertex indices are not integers"))
            }
            Kind::Scalar(_) => return Err(bad("the face element's vertex indices are not a list")),
        }
        Ok(Layout {
            vertex,
            coordinate,
            face,
            indices,
        })
    }
}

/// The one element called `name`, if any; two are an error.
fn only_element(header: &Header, name: &[u8]) -> Result<Option<usize>, PlyError> {
    let mut found = header
        .elements
        .iter()
        .enumerate()
        .filter(|(_, e)| e.name == name);
    let first = found.next().map(|(k, _)| k);
    match found.next() {
        Some((_, second)) => Err(bad(format!(
            "header line {}: a second `{}` element",
            second.line,
            String::from_utf8_lossy(name)
        ))),
        None => Ok(first),
    }
}

/// The one property of `element` called `name`, if any; two are an error.
fn only_property(element: &Element, name: &[u8]) -> Result<Option<usize>, PlyError> {
    let mut found = element
        .properties
        .iter()
        .enumerate()
        .filter(|(_, p)| p.name == name);
    let first = found.next().map(|(k, _)| k);
    match found.next() {
        Some(_) => Err(bad(format!(
            "the {} element has two `{}` properties",
            element.label(),
            String::from_utf8_lossy(name)
        ))),
        None => Ok(first),
    }
}

/// Refuses, before anything is allocated, counts over the limits and counts
/// the data cannot hold.
fn check_counts(
    header: &Header,
    layout: &Layout,
    data_len: usize,
    limits: &ParseLimits,
) -> Result<(), PlyError> {
    let max = limits.max_mesh_triangles as u64;
    let faces = header.elements[layout.face].count;
    if faces > max {
        return Err(PlyError::TooLarge(format!(
            "{faces} faces, more than the limit of {max} triangles"
        )));
    }
    let vertices = header.elements[layout.vertex].count;
    let most = max.saturating_mul(3).min(u64::from(u32::MAX));
    if vertices > most {
        return Err(PlyError::TooLarge(format!(
            "{vertices} vertices, more than {most} (three per triangle of the limit of {max})"
        )));
    }
    // The last ASCII value needs no separator after it.
    let available = data_len as u128 + u128::from(header.encoding == Encoding::Ascii);
    let mut needed: u128 = 0;
    for element in &header.elements {
        let each = element.min_record_bytes(header.encoding);
        needed += u128::from(element.count) * u128::from(each);
        if needed > available {
            return Err(bad(format!(
                "{}: {} records of at least {each} bytes each do not fit in the {data_len} bytes after the header (truncated, or the count is wrong)",
                element.label(),
                element.count
            )));
        }
    }
    Ok(())
}

/// Where the values come from: binary bytes or ASCII words.
trait Source {
    /// The next value, read as `ty` (integers exactly), or why not.
    fn value(&mut self, ty: Ty) -> Result<f64, &'static str>;
    /// Skips `n` values of `ty`.
    fn skip(&mut self, ty: Ty, n: u64) -> Result<(), &'static str>;
    /// Where the reader is, for messages: ` (line 12)`, ` (byte 345 of the data)`.
    fn position(&self) -> String;
}

/// The values of a binary file.
struct Binary<'a> {
    data: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], &'static str> {
        let end = self.pos.checked_add(N).ok_or(ENDS)?;
        let bytes: [u8; N] = self
            .data
            .get(self.pos..end)
            .and_then(|b| b.try_into().ok())
            .ok_or(ENDS)?;
        self.pos = end;
        Ok(bytes)
    }
}

const ENDS: &str = "the data ends";

macro_rules! number {
    ($self:ident, $t:ty) => {{
        let b = $self.take::<{ std::mem::size_of::<$t>() }>()?;
        let v = if $self.big_endian {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        };
        f64::from(v)
    }};
}

impl Source for Binary<'_> {
    fn value(&mut self, ty: Ty) -> Result<f64, &'static str> {
        Ok(match ty {
            Ty::I8 => number!(self, i8),
            Ty::U8 => number!(self, u8),
            Ty::I16 => number!(self, i16),
            Ty::U16 => number!(self, u16),
            Ty::I32 => number!(self, i32),
            Ty::U32 => number!(self, u32),
            Ty::F32 => number!(self, f32),
            Ty::F64 => number!(self, f64),
        })
    }

    fn skip(&mut self, ty: Ty, n: u64) -> Result<(), &'static str> {
        let len = usize::try_from(ty.size().saturating_mul(n)).map_err(|_| ENDS)?;
        let end = self.pos.checked_add(len).ok_or(ENDS)?;
        if end > self.data.len() {
            return Err(ENDS);
        }
        self.pos = end;
        Ok(())
    }

    fn position(&self) -> String {
        format!(" (byte {} of the data)", self.pos)
    }
}

/// The values of an ASCII file: words between any whitespace.
struct Ascii<'a> {
    data: &'a [u8],
    pos: usize,
    /// The line of the file at `pos` (1-based, header included).
    line: usize,
}

impl<'a> Ascii<'a> {
    fn word(&mut self) -> Option<&'a [u8]> {
        while let Some(&b) = self.data.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            self.line += usize::from(b == b'\n');
            self.pos += 1;
        }
        let rest = self.data.get(self.pos..)?;
        let len = rest
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .unwrap_or(rest.len());
        self.pos += len;
        (len > 0).then(|| &rest[..len])
    }
}

impl Source for Ascii<'_> {
    fn value(&mut self, ty: Ty) -> Result<f64, &'static str> {
        let word = self.word().ok_or(ENDS)?;
        let v: f64 = std::str::from_utf8(word)
            .ok()
            .and_then(|w| w.parse().ok())
            .ok_or("a value is not a number")?;
        if ty.is_integer() && v.fract() != 0.0 {
            return Err("an integer value is not a whole number");
        }
        Ok(v)
    }

    fn skip(&mut self, _ty: Ty, n: u64) -> Result<(), &'static str> {
        for _ in 0..n {
            self.word().ok_or(ENDS)?;
        }
        Ok(())
    }

    fn position(&self) -> String {
        format!(" (line {})", self.line)
    }
}

/// Every element in the header's order: vertices and faces kept, the rest
/// skipped.
fn read_elements(
    header: &Header,
    layout: &Layout,
    source: &mut impl Source,
    limits: &ParseLimits,
) -> Result<TriangleMesh, PlyError> {
    // Both counts are bounded by the limits and by the data (check_counts).
    let vertices = header.elements[layout.vertex].count;
    let faces = header.elements[layout.face].count;
    let mut mesh = TriangleMesh {
        vertices: Vec::with_capacity(vertices as usize),
        indices: Vec::with_capacity(faces as usize),
    };
    for (k, element) in header.elements.iter().enumerate() {
        if k == layout.vertex {
            read_vertices(element, &layout.coordinate, source, &mut mesh.vertices)?;
        } else if k == layout.face {
            let faces = Faces {
                element,
                list: layout.indices,
                vertices,
                max_triangles: limits.max_mesh_triangles as u64,
            };
            faces.read(source, &mut mesh.indices)?;
        } else {
            skip_element(element, source)?;
        }
    }
    Ok(mesh)
}

/// An error in `record` (`vertex 3`, `face 7`, …) at the reader's position.
fn in_record(record: &str, why: &str, source: &impl Source) -> PlyError {
    bad(format!("{record}{}: {why}", source.position()))
}

/// A list's length, read as `ty`.
fn list_length(source: &mut impl Source, ty: Ty) -> Result<u64, &'static str> {
    let n = source.value(ty)?;
    if n < 0.0 {
        return Err("a negative list length");
    }
    // Whole and non-negative (an integer type, checked by the reader).
    Ok(n as u64)
}

/// Skips one value of `property`.
fn skip_property(source: &mut impl Source, kind: Kind) -> Result<(), &'static str> {
    match kind {
        Kind::Scalar(ty) => source.skip(ty, 1),
        Kind::List(count, item) => {
            let n = list_length(source, count)?;
            source.skip(item, n)
        }
    }
}

fn read_vertices(
    element: &Element,
    coordinate: &[Option<usize>],
    source: &mut impl Source,
    out: &mut Vec<Point3<f64>>,
) -> Result<(), PlyError> {
    for v in 0..element.count {
        let mut p = [0.0; 3];
        for (property, axis) in element.properties.iter().zip(coordinate) {
            let step = match (property.kind, axis) {
                (Kind::Scalar(ty), Some(axis)) => source.value(ty).map(|x| p[*axis] = x),
                (kind, _) => skip_property(source, kind),
            };
            step.map_err(|why| in_record(&format!("vertex {v}"), why, source))?;
        }
        out.push(Point3::new(p[0], p[1], p[2]));
    }
    Ok(())
}

/// Skips every record of an element that holds no part of the mesh.
fn skip_element(element: &Element, source: &mut impl Source) -> Result<(), PlyError> {
    // Records without properties take no bytes, however many there are.
    if element.properties.is_empty() {
        return Ok(());
    }
    for r in 0..element.count {
        for property in &element.properties {
            skip_property(source, property.kind).map_err(|why| {
                in_record(&format!("record {r} of {}", element.label()), why, source)
            })?;
        }
    }
    Ok(())
}

/// The face element and what bounds its index lists.
struct Faces<'a> {
    element: &'a Element,
    /// The property holding the index list.
    list: usize,
    vertices: u64,
    max_triangles: u64,
}

impl Faces<'_> {
    fn read(&self, source: &mut impl Source, out: &mut Vec<[u32; 3]>) -> Result<(), PlyError> {
        let mut polygon: Vec<u32> = Vec::new();
        for f in 0..self.element.count {
            for (k, property) in self.element.properties.iter().enumerate() {
                match property.kind {
                    Kind::List(count, item) if k == self.list => {
                        let triangles = out.len() as u64;
                        self.polygon(f, source, (count, item), triangles, &mut polygon)?;
                        fan(&polygon, out);
                    }
                    kind => skip_property(source, kind)
                        .map_err(|why| in_record(&format!("face {f}"), why, source))?,
                }
            }
        }
        Ok(())
    }

    /// Reads face `f`'s index list into `polygon`, checking its length, the
    /// triangle limit (`triangles` made so far) and every index.
    fn polygon(
        &self,
        f: u64,
        source: &mut impl Source,
        (count, item): (Ty, Ty),
        triangles: u64,
        polygon: &mut Vec<u32>,
    ) -> Result<(), PlyError> {
        let face = || format!("face {f}");
        let n = list_length(source, count).map_err(|why| in_record(&face(), why, source))?;
        if n < 3 {
            let why = format!("{n} vertices; a face needs at least three");
            return Err(in_record(&face(), &why, source));
        }
        let total = triangles.saturating_add(n - 2);
        if total > self.max_triangles {
            return Err(PlyError::TooLarge(format!(
                "{total} triangles by face {f} ({n} vertices), more than the limit of {}",
                self.max_triangles
            )));
        }
        polygon.clear();
        for corner in 0..n {
            let i = source
                .value(item)
                .map_err(|why| in_record(&face(), why, source))?;
            if !(0.0..self.vertices as f64).contains(&i) {
                let why = format!(
                    "corner {corner} of {n} names a vertex outside the {} of the file",
                    self.vertices
                );
                return Err(in_record(&face(), &why, source));
            }
            polygon.push(i as u32);
        }
        Ok(())
    }
}

/// Fan-triangulates a polygon (its winding kept) onto `out`.
fn fan(polygon: &[u32], out: &mut Vec<[u32; 3]>) {
    if let Some((&first, rest)) = polygon.split_first() {
        out.extend(rest.windows(2).map(|w| [first, w[0], w[1]]));
    }
}

/// `mesh` as a binary little-endian PLY file: `float` positions, one
/// `uchar`-counted `int` (`uint` past 2³¹ vertices) index list per triangle.
pub fn to_binary(mesh: &TriangleMesh) -> Vec<u8> {
    let index = if mesh.vertices.len() > i32::MAX as usize {
        "uint"
    } else {
        "int"
    };
    let header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by tsukami-body\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar {index} vertex_indices\nend_header\n",
        mesh.vertices.len(),
        mesh.indices.len()
    );
    let mut out =
        Vec::with_capacity(header.len() + 12 * mesh.vertices.len() + 13 * mesh.indices.len());
    out.extend_from_slice(header.as_bytes());
    for v in &mesh.vertices {
        for c in v.iter() {
            out.extend_from_slice(&(*c as f32).to_le_bytes());
        }
    }
    for t in &mesh.indices {
        out.push(3);
        for i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// How a test file is laid out.
    #[derive(Clone, Copy)]
    struct Layout {
        encoding: Encoding,
        /// The coordinates' type.
        coordinate: Ty,
        /// Normals, colours and a list per vertex, a flag per face.
        extras: bool,
        /// Elements that hold no part of the mesh, before and after.
        others: bool,
    }

    const PLAIN: Layout = Layout {
        encoding: Encoding::LittleEndian,
        coordinate: Ty::F32,
        extras: false,
        others: false,
    };

    fn put(out: &mut Vec<u8>, encoding: Encoding, ty: Ty, v: f64) {
        macro_rules! bytes {
            ($t:ty) => {{
                let v = v as $t;
                match encoding {
                    Encoding::BigEndian => out.extend_from_slice(&v.to_be_bytes()),
                    _ => out.extend_from_slice(&v.to_le_bytes()),
                }
            }};
        }
        match (encoding, ty) {
            (Encoding::Ascii, _) => out.extend_from_slice(format!("{v} ").as_bytes()),
            (_, Ty::I8) => bytes!(i8),
            (_, Ty::U8) => bytes!(u8),
            (_, Ty::I16) => bytes!(i16),
            (_, Ty::U16) => bytes!(u16),
            (_, Ty::I32) => bytes!(i32),
            (_, Ty::U32) => bytes!(u32),
            (_, Ty::F32) => bytes!(f32),
            (_, Ty::F64) => bytes!(f64),
        }
    }

    fn end_record(out: &mut Vec<u8>, encoding: Encoding) {
        if encoding == Encoding::Ascii {
            out.push(b'\n');
        }
    }

    /// An element of `n` records of a uchar and a list of shorts, for
    /// skipping.
    fn other_element(out: &mut Vec<u8>, encoding: Encoding, n: usize) {
        for r in 0..n {
            put(out, encoding, Ty::U8, r as f64);
            put(out, encoding, Ty::U8, (r % 3) as f64);
            for k in 0..r % 3 {
                put(out, encoding, Ty::I16, -(k as f64));
            }
            end_record(out, encoding);
        }
    }

    fn header(layout: Layout, vertices: usize, faces: usize) -> String {
        let encoding = match layout.encoding {
            Encoding::Ascii => "ascii",
            Encoding::LittleEndian => "binary_little_endian",
            Encoding::BigEndian => "binary_big_endian",
        };
        let c = match layout.coordinate {
            Ty::F64 => "double",
            Ty::F32 => "float32",
            Ty::I32 => "int",
            _ => unreachable!(),
        };
        let mut h = format!("ply\r\nformat {encoding} 1.0\ncomment a test\nobj_info none\n");
        let other = "element material 3\nproperty uchar id\nproperty list uchar short ids\n";
        if layout.others {
            h.push_str(other);
        }
        h.push_str(&format!("element vertex {vertices}\n"));
        if layout.extras {
            h.push_str("property float nx\n");
        }
        h.push_str(&format!("property {c} x\nproperty {c} y\nproperty {c} z\n"));
        if layout.extras {
            h.push_str("property float ny\nproperty float nz\nproperty uchar red\n");
            h.push_str("property list uint8 float32 texcoord\n");
        }
        h.push_str(&format!("element face {faces}\n"));
        if layout.extras {
            h.push_str("property int flags\n");
        }
        h.push_str("property list uchar uint vertex_indices\n");
        if layout.extras {
            h.push_str("property uchar alpha\n");
        }
        if layout.others {
            h.push_str("element edge 2\nproperty int vertex1\nproperty int vertex2\n");
            h.push_str("element empty 18446744073709551615\n");
        }
        h.push_str("end_header\n");
        h
    }

    /// `vertices` and `faces` (polygons) as a PLY file laid out as `layout`.
    fn encode(vertices: &[Point3<f64>], faces: &[Vec<u32>], layout: Layout) -> Vec<u8> {
        let e = layout.encoding;
        let mut out = header(layout, vertices.len(), faces.len()).into_bytes();
        if layout.others {
            other_element(&mut out, e, 3);
        }
        for v in vertices {
            if layout.extras {
                put(&mut out, e, Ty::F32, 0.25);
            }
            for c in v.iter() {
                put(&mut out, e, layout.coordinate, *c);
            }
            if layout.extras {
                let values = [0.5, -1.0, 200.0, 2.0, 0.1, 0.2];
                let types = [Ty::F32, Ty::F32, Ty::U8, Ty::U8, Ty::F32, Ty::F32];
                for (x, ty) in values.into_iter().zip(types) {
                    put(&mut out, e, ty, x);
                }
            }
            end_record(&mut out, e);
        }
        for f in faces {
            if layout.extras {
                put(&mut out, e, Ty::I32, -7.0);
            }
            put(&mut out, e, Ty::U8, f.len() as f64);
            for i in f {
                put(&mut out, e, Ty::U32, f64::from(*i));
            }
            if layout.extras {
                put(&mut out, e, Ty::U8, 255.0);
            }
            end_record(&mut out, e);
        }
        if layout.others {
            for _ in 0..2 {
                put(&mut out, e, Ty::I32, 0.0);
                put(&mut out, e, Ty::I32, 1.0);
                end_record(&mut out, e);
            }
        }
        out
    }

    /// A 1 × 2 × 3 box as eight corners and six outward quads.
    fn box_quads() -> (Vec<Point3<f64>>, Vec<Vec<u32>>) {
        let corners = (0..8)
            .map(|k| {
                Point3::new(
                    f64::from(k & 1),
                    f64::from(k >> 1 & 1) * 2.0,
                    f64::from(k >> 2) * 3.0,
                )
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        (corners, quads.iter().map(|q| q.to_vec()).collect())
    }

    fn triangles(mesh: &TriangleMesh) -> Vec<Vec<u32>> {
        mesh.indices.iter().map(|t| t.to_vec()).collect()
    }

    fn every_layout() -> Vec<Layout> {
        let mut all = Vec::new();
        for encoding in [Encoding::Ascii, Encoding::LittleEndian, Encoding::BigEndian] {
            for coordinate in [Ty::F32, Ty::F64, Ty::I32] {
                for (extras, others) in [(false, false), (true, false), (false, true), (true, true)]
                {
                    all.push(Layout {
                        encoding,
                        coordinate,
                        extras,
                        others,
                    });
                }
            }
        }
        all
    }

    fn limits() -> ParseLimits {
        ParseLimits::default()
    }

    fn error(bytes: &[u8]) -> String {
        read(bytes, &limits()).unwrap_err().to_string()
    }

    #[test]
    fn every_encoding_and_type_reads_the_same_box_with_extras_skipped() {
        let (corners, quads) = box_quads();
        for layout in every_layout() {
            let mesh = read(&encode(&corners, &quads, layout), &limits()).unwrap();
            assert_eq!(mesh.vertices, corners);
            // Fan-triangulated: two triangles per quad, the winding kept.
            assert_eq!(mesh.indices.len(), 12);
            assert_eq!(mesh.indices[0], [0, 2, 3]);
            assert_eq!(mesh.indices[1], [0, 3, 1]);
            assert!(mesh.is_closed());
            assert!((mesh.volume() - 6.0).abs() < 1e-12, "{}", mesh.volume());
        }
    }

    #[test]
    fn a_cylinder_round_trips_through_every_encoding_and_the_writer() {
        let c = TriangleMesh::cylinder(0.03, 0.1, 16);
        for encoding in [Encoding::Ascii, Encoding::LittleEndian, Encoding::BigEndian] {
            let layout = Layout {
                encoding,
                coordinate: Ty::F64,
                ..PLAIN
            };
            let back = read(&encode(&c.vertices, &triangles(&c), layout), &limits()).unwrap();
            assert_eq!(back, c, "{encoding:?}");
        }
        // The writer's floats: the same triangles, the volume to float precision.
        let back = read(&to_binary(&c), &limits()).unwrap();
        assert_eq!(back.indices, c.indices);
        assert!(back.is_closed());
        assert!((back.volume() - c.volume()).abs() < 1e-9);
        let header = to_binary(&c);
        assert!(header.starts_with(b"ply\nformat binary_little_endian 1.0\n"));
    }

    #[test]
    fn polygons_are_fans_and_non_finite_values_pass_to_cleaning() {
        let hexagon: Vec<Point3<f64>> = (0..6)
            .map(|k| {
                let a = f64::from(k) * std::f64::consts::FRAC_PI_3;
                Point3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let faces = vec![(0..6).collect::<Vec<u32>>()];
        let mesh = read(&encode(&hexagon, &faces, PLAIN), &limits()).unwrap();
        assert_eq!(
            mesh.indices,
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]
        );
        let text =
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n\
            property double z\nelement face 1\nproperty list uchar int vertex_index\nend_header\n\
            nan 0 0\n1 inf 0\n0 1 -infinity\n3 0 1 2\n";
        let mesh = read(text.as_bytes(), &limits()).unwrap();
        assert!(mesh.vertices[0].x.is_nan() && mesh.vertices[1].y == f64::INFINITY);
        // Loaded through the mesh loader, cleaning drops the triangle.
        let e = TriangleMesh::from_bytes_with(
            text.as_bytes(),
            crate::mesh_io::Format::Ply,
            Vector3::repeat(1.0),
            &limits(),
            std::path::Path::new("n.ply"),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("no usable triangle") && e.contains("1 non-finite"),
            "{e}"
        );
    }

    const VERTEX: &str = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    const FACE: &str = "element face 1\nproperty list uchar int vertex_indices\n";

    /// One triangle, ASCII.
    fn triangle() -> String {
        format!("ply\nformat ascii 1.0\n{VERTEX}{FACE}end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    }

    /// Each `(from, to, message)`: [`triangle`] with its first `from` made
    /// `to` is refused with an error containing `message`.
    fn refused_as(edits: &[(&str, &str, &str)]) {
        for (from, to, expected) in edits {
            let text = triangle().replacen(from, to, 1);
            assert_ne!(text, triangle(), "{from:?} is not in the file");
            let e = error(text.as_bytes());
            assert!(
                e.contains(expected),
                "{expected:?} not in {e:?} for {text:?}"
            );
        }
    }

    #[test]
    fn malformed_header_lines_are_refused_naming_the_line() {
        assert_eq!(
            read(triangle().as_bytes(), &limits())
                .unwrap()
                .indices
                .len(),
            1
        );
        let second_format = format!("{VERTEX}format ascii 1.0\n");
        refused_as(&[
            (
                "ascii 1.0",
                "ascii 2.0",
                "header line 2: the format version is not 1.0",
            ),
            ("ascii 1.0", "utf8 1.0", "header line 2: unknown encoding"),
            (
                "ascii 1.0",
                "ascii",
                "header line 2: `format` takes an encoding and a version",
            ),
            ("format ascii 1.0\n", "", "the header has no `format` line"),
            (
                VERTEX,
                &second_format,
                "header line 7: a second `format` line",
            ),
            (
                "element vertex",
                "property float w\nelement vertex",
                "header line 3: a property before any element",
            ),
            (
                "vertex 3",
                "vertex -3",
                "header line 3: the element count is not a whole number",
            ),
            (
                "vertex 3",
                "vertex 3 4",
                "header line 3: `element` takes a name and a count",
            ),
            (
                "float y",
                "quaternion y",
                "header line 5: unknown property type",
            ),
            (
                "float y",
                "float",
                "header line 5: `property` takes a type and a name",
            ),
            (
                "uchar int",
                "float int",
                "header line 8: a list's length must have an integer type",
            ),
            (
                "uchar int vertex_indices",
                "uchar int",
                "header line 8: a list property takes a length type",
            ),
            (
                "end_header",
                "end-header",
                "header line 9: not a header keyword",
            ),
            (
                "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "",
                "no `end_header` line",
            ),
            (
                "\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "",
                "vertex: 3 records of at least 6 bytes each do not fit in the 0 bytes",
            ),
        ]);
    }

    #[test]
    fn not_ply_and_endless_headers_are_refused() {
        for not_ply in ["solid x\nendsolid x\n", "plyfoo\n", ""] {
            assert!(
                error(not_ply.as_bytes()).contains("not a PLY file: the first line is not `ply`")
            );
        }
        let long = format!("ply\n{}", "comment long\n".repeat(MAX_HEADER_BYTES / 10));
        assert!(error(long.as_bytes()).contains("no `end_header` within the first 65536 bytes"));
    }

    #[test]
    fn a_header_without_a_mesh_is_refused_saying_what_is_missing() {
        let two_faces = format!("{FACE}{FACE}");
        refused_as(&[
            (
                FACE,
                "",
                "the header has no `face` element: a point cloud, not a mesh",
            ),
            (VERTEX, "", "the header has no `vertex` element"),
            (FACE, &two_faces, "header line 9: a second `face` element"),
            (
                "float z",
                "float x",
                "the vertex element has two `x` properties",
            ),
            (
                "float z",
                "float w",
                "the vertex element has no `z` property",
            ),
            (
                "property float z",
                "property list uchar float z",
                "vertex property `z` is a list",
            ),
            (
                "uchar int",
                "uchar float",
                "the face element's vertex indices are not integers",
            ),
            (
                "list uchar int vertex_indices",
                "int vertex_indices",
                "vertex indices are not a list",
            ),
            (
                "vertex_indices",
                "corners",
                "no `vertex_indices` (or `vertex_index`) list",
            ),
        ]);
    }

    #[test]
    fn bad_data_is_refused_naming_the_record() {
        let (corners, quads) = box_quads();
        let text = |faces: &[Vec<u32>]| {
            let layout = Layout {
                encoding: Encoding::Ascii,
                ..PLAIN
            };
            String::from_utf8(encode(&corners, faces, layout)).unwrap()
        };
        let mut bad_index = quads.clone();
        bad_index[4][2] = 8;
        let e = error(text(&bad_index).as_bytes());
        assert_eq!(
            e,
            "face 4 (line 24): corner 2 of 4 names a vertex outside the 8 of the file"
        );
        let mut two = quads.clone();
        two[1] = vec![0, 1];
        let e = error(text(&two).as_bytes());
        assert!(
            e.starts_with("face 1 (line 21): 2 vertices; a face needs at least three"),
            "{e}"
        );
        // The first `from` of the data replaced by `to`.
        let in_data = |from: &str, to: &str| {
            let t = text(&quads);
            let start = t.find("end_header\n").unwrap();
            format!("{}{}", &t[..start], t[start..].replacen(from, to, 1))
        };
        let e = error(in_data("2 ", "SECRET-VALUE ").as_bytes());
        assert!(
            e.starts_with("vertex 2 (line 14): a value is not a number"),
            "{e}"
        );
        assert!(!e.contains("SECRET"), "{e}");
        let e = error(in_data("4 0 ", "4.5 0 ").as_bytes());
        assert!(
            e.starts_with("face 0 (line 20): an integer value is not a whole number"),
            "{e}"
        );
        // A negative index in a signed type, in binary.
        let header = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\n\
            property float y\nproperty float z\nelement face 1\nproperty list char int vertex_indices\nend_header\n";
        let mut bytes = header.as_bytes().to_vec();
        bytes.extend(std::iter::repeat_n(0u8, 36));
        bytes.push(3);
        for i in [0i32, -1, 2] {
            bytes.extend_from_slice(&i.to_be_bytes());
        }
        let e = error(&bytes);
        assert!(
            e.starts_with("face 0 (byte 45 of the data): corner 1 of 3 names a vertex outside"),
            "{e}"
        );
        bytes[header.len() + 36] = 0xFF; // a length of -1
        assert!(error(&bytes).contains("a negative list length"));
    }

    #[test]
    fn huge_counts_are_refused_before_allocating() {
        let header = |vertices: &str, faces: &str, other: &str| {
            format!(
                "ply\nformat binary_little_endian 1.0\nelement vertex {vertices}\nproperty float x\n\
                 property float y\nproperty float z\n{other}element face {faces}\n\
                 property list uint int vertex_indices\nend_header\n"
            )
        };
        let e = read(header("1000000000000", "1", "").as_bytes(), &limits()).unwrap_err();
        assert_eq!(
            e,
            PlyError::TooLarge(
                "1000000000000 vertices, more than 6000000 (three per triangle of the limit of 2000000)".into()
            )
        );
        let e = read(header("3", "2000001", "").as_bytes(), &limits()).unwrap_err();
        assert!(
            matches!(e, PlyError::TooLarge(m) if m == "2000001 faces, more than the limit of 2000000 triangles")
        );
        // Within the limits, but more than the bytes after the header hold.
        let e = error(header("5000000", "1", "").as_bytes());
        assert_eq!(e, "vertex: 5000000 records of at least 12 bytes each do not fit in the 0 bytes after the header (truncated, or the count is wrong)");
        let other = "element junk 18446744073709551615\nproperty double a\n";
        let e = error(header("0", "0", other).as_bytes());
        assert!(
            e.starts_with(
                "the element of header line 7: 18446744073709551615 records of at least 8 bytes"
            ),
            "{e}"
        );
        // A face whose list claims four billion corners: over the triangle limit.
        let mut bytes = header("3", "1", "").into_bytes();
        bytes.extend(std::iter::repeat_n(0u8, 36));
        bytes.extend_from_slice(&u32::MAX.to_le_bytes());
        let e = read(&bytes, &limits()).unwrap_err();
        assert!(
            matches!(&e, PlyError::TooLarge(m) if m.starts_with("4294967293 triangles by face 0")),
            "{e}"
        );
        // The same list in an element that is skipped: the data ends.
        let skipped = "element junk 1\nproperty list uint double a\n";
        let mut bytes = header("3", "0", skipped).into_bytes();
        bytes.extend(std::iter::repeat_n(0u8, 36));
        bytes.extend_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(
            error(&bytes),
            "record 0 of the element of header line 7 (byte 40 of the data): the data ends"
        );
        // Quads within the face limit whose triangles are not.
        let (corners, quads) = box_quads();
        let small = ParseLimits {
            max_mesh_triangles: 11,
            ..limits()
        };
        let e = read(&encode(&corners, &quads, PLAIN), &small).unwrap_err();
        assert_eq!(
            e,
            PlyError::TooLarge(
                "12 triangles by face 5 (4 vertices), more than the limit of 11".into()
            )
        );
    }

    #[test]
    fn errors_never_quote_the_file() {
        let text = "ply\nformat ascii 1.0\ncomment SECRET\nelement SECRET 99\nproperty SECRET x\nend_header\n";
        let e = error(text.as_bytes());
        assert!(e.contains("header line 5") && !e.contains("SECRET"), "{e}");
        let text = "ply\nformat ascii 1.0\nelement SECRET 99\nproperty float x\nelement vertex 0\n\
            property float x\nproperty float y\nproperty float z\nelement face 0\n\
            property list uchar int vertex_indices\nend_header\n1 2 SECRET\n";
        let e = error(text.as_bytes());
        assert!(
            e.contains("the element of header line 3") && !e.contains("SECRET"),
            "{e}"
        );
        let e = error(b"ply\nformat ascii 1.0\nSECRET line\n");
        assert!(!e.contains("SECRET"), "{e}");
    }

    #[test]
    fn every_truncation_and_corruption_is_an_error_or_a_mesh_never_a_panic() {
        let (corners, quads) = box_quads();
        for layout in every_layout().into_iter().filter(|l| l.extras && l.others) {
            let bytes = encode(&corners, &quads, layout);
            for cut in 0..bytes.len() {
                let r = read(&bytes[..cut], &limits());
                // Every byte of a binary file counts; an ASCII file cut inside
                // its last number may still read.
                if layout.encoding != Encoding::Ascii {
                    assert!(
                        r.is_err(),
                        "{layout:?} cut at {cut}",
                        layout = layout.encoding
                    );
                }
            }
            for k in 0..bytes.len() {
                for flip in [0xFF, 0x80, 0x01] {
                    let mut corrupt = bytes.clone();
                    corrupt[k] ^= flip;
                    let _ = read(&corrupt, &limits());
                }
            }
        }
    }
}
