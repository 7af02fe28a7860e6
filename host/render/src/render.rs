//! A software renderer: a [`Drawing`] seen through a pinhole camera, as a
//! picture, without a GPU, a display or a browser.
//!
//! What: [`Camera`] (eye, target, up, vertical field of view), [`render`]
//! into a [`Picture`] of RGB pixels, and [`Picture::to_png`].
//!
//! Why: the headless robot PC, CI artifacts and the README need a picture of
//! the plan; a z-buffer of a few thousand triangles takes milliseconds.
//!
//! How: every triangle is moved into the camera frame (looking down −z),
//! projected, and filled by edge functions over its screen bounding box with
//! a depth test on the interpolated inverse depth. Shading is Lambert with a
//! headlight (`0.35 + 0.65 |n·v|`, two-sided). Opaque groups are drawn first;
//! translucent ones are then blended over them without writing depth; last,
//! the annotations ([`crate::drawing::Group::on_top`]) over everything, with
//! a fresh depth buffer. Triangles reaching behind the near plane are
//! skipped.

use nalgebra::{Isometry3, Point3, Vector3};

use crate::drawing::{Drawing, Group};

/// Nearest distance drawn in front of the camera (m).
const NEAR: f64 = 0.01;

/// A pinhole camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Where it is.
    pub eye: Point3<f64>,
    /// What it looks at.
    pub target: Point3<f64>,
    /// Which way is up in the picture.
    pub up: Vector3<f64>,
    /// Vertical field of view (rad).
    pub fov_y: f64,
}

impl Camera {
    /// A camera at `eye` looking at `target`, 40° vertical field of view.
    pub fn looking_at(eye: Point3<f64>, target: Point3<f64>, up: Vector3<f64>) -> Self {
        Self {
            eye,
            target,
            up,
            fov_y: 40f64.to_radians(),
        }
    }

    /// A camera at `target + offset` looking at `target`, world z up (a
    /// grasp picture: `offset` is [`crate::grasp_view::DEFAULT_EYE`] unless
    /// the user moves it).
    pub fn offset_from(target: Point3<f64>, offset: Vector3<f64>) -> Self {
        Self::looking_at(target + offset, target, Vector3::z())
    }

    /// A camera looking along `direction` at the centre of the box
    /// `lo`–`hi`, far enough back for the whole box to fit (world z up).
    pub fn framing(lo: &Point3<f64>, hi: &Point3<f64>, direction: &Vector3<f64>) -> Self {
        let center = nalgebra::center(lo, hi);
        let radius = (hi - lo).norm() / 2.0;
        let fov_y = 40f64.to_radians();
        let distance = radius.max(1e-3) / (fov_y / 2.0).sin();
        let eye = center - direction.normalize() * distance;
        Self {
            fov_y,
            ..Self::looking_at(eye, center, Vector3::z())
        }
    }

    /// World to camera frame (the camera looks down −z).
    fn view(&self) -> Isometry3<f64> {
        Isometry3::look_at_rh(&self.eye, &self.target, &self.up)
    }

    /// Focal length in pixels for a picture `height` pixels high.
    fn focal(&self, height: u32) -> f64 {
        0.5 * f64::from(height) / (self.fov_y / 2.0).tan()
    }

    /// Where `p` lands in a `width × height` picture (pixel x, y from the
    /// top-left), or `None` when it is behind the near plane.
    pub fn project(&self, p: &Point3<f64>, width: u32, height: u32) -> Option<[f64; 2]> {
        let c = self.view() * p;
        (-c.z >= NEAR).then(|| {
            let f = self.focal(height);
            [
                f64::from(width) / 2.0 + f * c.x / -c.z,
                f64::from(height) / 2.0 - f * c.y / -c.z,
            ]
        })
    }
}

/// An RGB picture, rows top to bottom.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` pixels.
    pub pixels: Vec<[u8; 3]>,
    /// The colour where nothing was drawn.
    pub background: [u8; 3],
}

impl Picture {
    /// The pixel at column `x`, row `y` (from the top).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// The picture as a PNG file.
    pub fn to_png(&self) -> Result<Vec<u8>, png::EncodingError> {
        let mut out = Vec::new();
        let mut encoder = png::Encoder::new(&mut out, self.width, self.height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header()?;
        writer.write_image_data(self.pixels.as_flattened())?;
        writer.finish()?;
        Ok(out)
    }
}

/// A triangle's corners in screen space: pixel x, pixel y, inverse depth.
type Screen = [[f64; 3]; 3];

/// Renders `drawing` through `camera` into a `width × height` picture.
pub fn render(drawing: &Drawing, camera: &Camera, width: u32, height: u32) -> Picture {
    let background = [246, 246, 242];
    let mut target = Target {
        width,
        height,
        color: vec![background; (width * height) as usize],
        inverse_depth: vec![0.0; (width * height) as usize],
    };
    let view = camera.view();
    let focal = camera.focal(height);
    let pass = |on_top: bool, translucent: bool| {
        move |g: &&Group| g.on_top == on_top && g.color.is_translucent() == translucent
    };
    let passes = [
        pass(false, false),
        pass(false, true),
        pass(true, false),
        pass(true, true),
    ];
    for (k, keep) in passes.iter().enumerate() {
        if k == 2 {
            // Annotations: tested against each other only.
            target.inverse_depth.iter_mut().for_each(|d| *d = 0.0);
        }
        for g in drawing.groups.iter().filter(keep) {
            let blend = g.color.is_translucent().then_some(f64::from(g.color.0[3]));
            for t in &g.triangles {
                let camera_frame = t.map(|i| view * g.positions[i as usize]);
                if camera_frame.iter().any(|p| -p.z < NEAR) {
                    continue;
                }
                let screen: Screen = camera_frame.map(|p| {
                    [
                        f64::from(width) / 2.0 + focal * p.x / -p.z,
                        f64::from(height) / 2.0 - focal * p.y / -p.z,
                        1.0 / -p.z,
                    ]
                });
                let c = g.color.0;
                let shade = shade(&camera_frame);
                target.fill(
                    &screen,
                    [c[0], c[1], c[2]].map(|v| f64::from(v) * shade),
                    blend,
                );
            }
        }
    }
    Picture {
        width,
        height,
        pixels: target.color,
        background,
    }
}

/// Lambert with a headlight, two-sided: `0.35 + 0.65 |n·v|`.
fn shade(t: &[Point3<f64>; 3]) -> f64 {
    let normal = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let light = normal.normalize().dot(&(-t[0].coords).normalize()).abs();
    if light.is_finite() {
        0.35 + 0.65 * light
    } else {
        0.35
    }
}

/// The buffers being drawn into.
struct Target {
    width: u32,
    height: u32,
    color: Vec<[u8; 3]>,
    inverse_depth: Vec<f64>,
}

impl Target {
    /// Fills a screen triangle with `rgb`; `alpha` blends without writing depth.
    fn fill(&mut self, s: &Screen, rgb: [f64; 3], alpha: Option<f64>) {
        let edge = |a: &[f64; 3], b: &[f64; 3], x: f64, y: f64| {
            (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])
        };
        let area = edge(&s[0], &s[1], s[2][0], s[2][1]);
        if area.abs() < 1e-12 {
            return;
        }
        let lo_x = s
            .iter()
            .map(|p| p[0])
            .fold(f64::INFINITY, f64::min)
            .floor()
            .max(0.0) as u32;
        let hi_x = s
            .iter()
            .map(|p| p[0])
            .fold(f64::NEG_INFINITY, f64::max)
            .ceil()
            .min(f64::from(self.width) - 1.0);
        let lo_y = s
            .iter()
            .map(|p| p[1])
            .fold(f64::INFINITY, f64::min)
            .floor()
            .max(0.0) as u32;
        let hi_y = s
            .iter()
            .map(|p| p[1])
            .fold(f64::NEG_INFINITY, f64::max)
            .ceil()
            .min(f64::from(self.height) - 1.0);
        if hi_x < 0.0 || hi_y < 0.0 {
            return;
        }
        for y in lo_y..=hi_y as u32 {
            for x in lo_x..=hi_x as u32 {
                let (px, py) = (f64::from(x) + 0.5, f64::from(y) + 0.5);
                let w = [
                    edge(&s[1], &s[2], px, py) / area,
                    edge(&s[2], &s[0], px, py) / area,
                    edge(&s[0], &s[1], px, py) / area,
                ];
                if w.iter().any(|&v| v < 0.0) {
                    continue;
                }
                let inverse_depth = w[0] * s[0][2] + w[1] * s[1][2] + w[2] * s[2][2];
                let i = (y * self.width + x) as usize;
                if inverse_depth <= self.inverse_depth[i] {
                    continue;
                }
                let old = self.color[i].map(f64::from);
                let new = match alpha {
                    None => {
                        self.inverse_depth[i] = inverse_depth;
                        rgb.map(|v| v * 255.0)
                    }
                    Some(a) => [0, 1, 2].map(|k| a * rgb[k] * 255.0 + (1.0 - a) * old[k]),
                };
                self.color[i] = new.map(|v| v.round().clamp(0.0, 255.0) as u8);
            }
        }
    }
}
