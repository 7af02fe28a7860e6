//! Depth images: decoding and encoding 16-bit PNG (millimetres) and raw float32
//! (metres), with the checks that keep bad input from reaching the pipeline.
//!
//! What: [`DepthImage`] holds one depth value per pixel in metres, row-major;
//! `0.0` means "no measurement" (PNG value 0, a NaN, infinite or negative
//! float).
//!
//! Why: depth cameras deliver either 16-bit millimetre PNGs (Kinect, RealSense)
//! or float32 metres; both come in from files or over the bus and must be
//! refused with a clear message when malformed or of the wrong size.
//!
//! How: PNGs are decoded with the `png` crate (header first, so an oversized
//! image is refused before any allocation); only 16-bit greyscale is accepted.
//! Float32 data is little-endian, `width × height × 4` bytes.
//!
//! ```
//! use tsukami_vision::depth::DepthImage;
//! let img = DepthImage::new(3, 2, vec![0.5, 0.0, 1.25, 0.001, 2.0, 65.535]).unwrap();
//! let png = img.to_png16_mm().unwrap();
//! let back = DepthImage::from_png16_mm(&png, "example").unwrap();
//! assert_eq!(back, img);
//! assert!(DepthImage::from_png16_mm(b"not a png", "example").is_err());
//! ```

use std::io::Cursor;
use std::path::Path;

use crate::camera::MAX_SIDE;
use crate::error::{invalid, Result, VisionError};

/// A depth image in metres (`0.0` = no measurement).
#[derive(Debug, Clone, PartialEq)]
pub struct DepthImage {
    width: u32,
    height: u32,
    data: Vec<f32>,
}

/// The encodings a depth image can arrive in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DepthEncoding {
    /// 16-bit greyscale PNG, millimetres, 0 = no measurement.
    Png16Mm,
    /// Raw little-endian float32, metres, row-major.
    F32LeM,
}

impl DepthImage {
    /// An image from row-major metres; values that are not finite and
    /// positive become "no measurement". Errors when the length does not
    /// match the size.
    pub fn new(width: u32, height: u32, mut data: Vec<f32>) -> Result<Self> {
        check_size(width, height, "image")?;
        let expected = width as usize * height as usize;
        if data.len() != expected {
            return Err(invalid(
                "image.data",
                format!(
                    "{} values for a {width} x {height} image (expected {expected})",
                    data.len()
                ),
            ));
        }
        for d in &mut data {
            if !(d.is_finite() && *d > 0.0) {
                *d = 0.0;
            }
        }
        Ok(Self {
            width,
            height,
            data,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Row-major depths in metres (`0.0` = none).
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// Depth at `(u, v)` in metres, `None` when there is no measurement or
    /// the pixel is outside the image.
    #[inline]
    pub fn get(&self, u: u32, v: u32) -> Option<f64> {
        if u >= self.width || v >= self.height {
            return None;
        }
        let d = self.data[(v * self.width + u) as usize];
        (d > 0.0).then_some(d as f64)
    }

    /// Number of pixels with a measurement.
    pub fn valid_count(&self) -> usize {
        self.data.iter().filter(|d| **d > 0.0).count()
    }

    /// Decodes a 16-bit greyscale PNG in millimetres. `source_name` names the
    /// origin in error messages.
    pub fn from_png16_mm(bytes: &[u8], source_name: &str) -> Result<Self> {
        let decode = |message: String| VisionError::Decode {
            source_name: source_name.to_owned(),
            message,
        };
        let mut decoder = png::Decoder::new(Cursor::new(bytes));
        let header = decoder
            .read_header_info()
            .map_err(|e| decode(format!("not a PNG ({e})")))?;
        let (w, h) = (header.width, header.height);
        let (color, depth) = (header.color_type, header.bit_depth);
        check_size(w, h, "image")?;
        if color != png::ColorType::Grayscale || depth != png::BitDepth::Sixteen {
            return Err(decode(format!(
                "expected a 16-bit greyscale PNG, got {color:?} with {depth:?} bits"
            )));
        }
        let mut reader = decoder
            .read_info()
            .map_err(|e| decode(format!("malformed PNG ({e})")))?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| decode("image too large".into()))?;
        let mut buf = vec![0u8; size];
        let info = reader
            .next_frame(&mut buf)
            .map_err(|e| decode(format!("malformed PNG data ({e})")))?;
        let line = info.line_size;
        let mut data = Vec::with_capacity(w as usize * h as usize);
        for row in buf.chunks_exact(line).take(h as usize) {
            data.extend(
                row[..2 * w as usize]
                    .chunks_exact(2)
                    .map(|b| u16::from_be_bytes([b[0], b[1]]) as f32 * 1e-3),
            );
        }
        Self::new(w, h, data)
    }

    /// Encodes as a 16-bit greyscale PNG in millimetres (rounded; depths
    /// beyond 65.535 m and missing values become 0).
    pub fn to_png16_mm(&self) -> Result<Vec<u8>> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width, self.height);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Sixteen);
        let fail = |e: png::EncodingError| invalid("image", format!("cannot encode PNG: {e}"));
        let mut writer = enc.write_header().map_err(fail)?;
        let mut bytes = Vec::with_capacity(self.data.len() * 2);
        for d in &self.data {
            let mm = (*d as f64 * 1e3).round();
            let v = if (1.0..=65535.0).contains(&mm) {
                mm as u16
            } else {
                0
            };
            bytes.extend_from_slice(&v.to_be_bytes());
        }
        writer.write_image_data(&bytes).map_err(fail)?;
        writer.finish().map_err(fail)?;
        Ok(out)
    }

    /// Decodes raw little-endian float32 metres of a `width × height` image.
    pub fn from_f32_le(bytes: &[u8], width: u32, height: u32) -> Result<Self> {
        check_size(width, height, "image")?;
        let expected = width as usize * height as usize * 4;
        if bytes.len() != expected {
            return Err(invalid(
                "image.data",
                format!(
                    "{} bytes of float32 for a {width} x {height} image (expected {expected})",
                    bytes.len()
                ),
            ));
        }
        let data = bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Self::new(width, height, data)
    }

    /// Encodes as raw little-endian float32 metres.
    pub fn to_f32_le(&self) -> Vec<u8> {
        self.data.iter().flat_map(|d| d.to_le_bytes()).collect()
    }

    /// Decodes bytes in the given encoding (`width`/`height` are needed for
    /// float32 and checked against the PNG's own size otherwise).
    pub fn decode(
        bytes: &[u8],
        encoding: DepthEncoding,
        width: u32,
        height: u32,
        source_name: &str,
    ) -> Result<Self> {
        let img = match encoding {
            DepthEncoding::Png16Mm => Self::from_png16_mm(bytes, source_name)?,
            DepthEncoding::F32LeM => Self::from_f32_le(bytes, width, height)?,
        };
        if (img.width, img.height) != (width, height) {
            return Err(invalid(
                "image",
                format!(
                    "{source_name} is {} x {} but the intrinsics say {width} x {height}",
                    img.width, img.height
                ),
            ));
        }
        Ok(img)
    }

    /// Reads a depth file: `.png` (16-bit mm) or anything else as float32
    /// (`width × height` from the intrinsics).
    pub fn load(path: &Path, width: u32, height: u32) -> Result<Self> {
        let bytes = std::fs::read(path).map_err(|source| VisionError::Io {
            file: path.to_path_buf(),
            source,
        })?;
        let name = path.display().to_string();
        Self::decode(&bytes, encoding_of(path), width, height, &name)
    }

    /// Writes a depth file in the encoding its extension names (see [`DepthImage::load`]).
    pub fn save(&self, path: &Path) -> Result<()> {
        let bytes = match encoding_of(path) {
            DepthEncoding::Png16Mm => self.to_png16_mm()?,
            DepthEncoding::F32LeM => self.to_f32_le(),
        };
        std::fs::write(path, bytes).map_err(|source| VisionError::Io {
            file: path.to_path_buf(),
            source,
        })
    }
}

/// The encoding a file name implies: `.png` → PNG, otherwise float32.
pub fn encoding_of(path: &Path) -> DepthEncoding {
    match path.extension().and_then(|e| e.to_str()) {
        Some(e) if e.eq_ignore_ascii_case("png") => DepthEncoding::Png16Mm,
        _ => DepthEncoding::F32LeM,
    }
}

fn check_size(width: u32, height: u32, field: &str) -> Result<()> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(invalid(
            field,
            format!("size {width} x {height} must be within 1..={MAX_SIDE} on each side"),
        ));
    }
    Ok(())
}
