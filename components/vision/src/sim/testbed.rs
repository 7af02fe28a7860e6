//! Objects at random resting poses on a table, seen by the head camera, with
//! an optional occluder hiding a chosen fraction of the target.
//!
//! What: [`Testbed`] loads a scene file (its robot, its obstacles — one of
//! them the table — and its head camera), drops the scene's own objects, and
//! renders [`Trial`]s: a target object at a random stable pose on the table
//! top, optionally a second object placed between the camera and the target
//! so that a given fraction of the target's visible pixels is hidden.
//!
//! Why: the accuracy benchmark and the tests need many images whose truth is
//! known, generated the same way on every machine.
//!
//! How: a pose is a resting orientation of the object (upright, upside down,
//! on either side; bottles only upright or lying), a uniform yaw, and a
//! uniform position on the table top away from its edges, lowered until the
//! mesh touches the top. The head looks at the target's centroid. The
//! occluder stands upright in front of the target (as seen from the camera),
//! a gap away from it, and slides sideways; bisection on the sideways offset
//! finds the requested occluded fraction, measured by ray casting labels
//! (the target's pixels with and without the occluder). Everything is drawn
//! from a ChaCha stream seeded by the trial's seed.
//!
//! Clutter ([`Clutter`], [`Testbed::trial_in`]; issue 26): a wall 0–6 cm
//! behind the table's far edge; the floor, so the table's legs and the floor
//! show below the table's near edge; distractors (other models at random
//! resting poses on the table, 3 cm or more from the target and each other,
//! beside or behind the target as seen from the camera, never in front of
//! it); the target in chosen resting modes only (lying, upside down); the
//! noise's σ and dropout drawn per trial from ranges; or the target left out
//! (a frame with everything but the target, for false positives). The default
//! clutter draws nothing more, so [`Testbed::trial`] renders what it always did.

use std::collections::HashMap;
use std::path::Path;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector2, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tsukami_body::object::ObjectModel;
use tsukami_body::scene::Scene;

use super::head::HeadCamera;
use super::noise::NoiseModel;
use super::render::{pixel_box, render, trace, Region};
use super::world::SimWorld;
use crate::camera::{Camera, Intrinsics};
use crate::depth::DepthImage;
use crate::error::{invalid, Result, VisionError};

/// An object placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// Object model name (`objects/<model>`).
    pub model: String,
    /// Pose of the object frame in the world.
    pub pose: Isometry3<f64>,
}

/// What else a trial shows besides the target and its occluder.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Clutter {
    /// A wall behind the table (0–6 cm behind its far edge, drawn).
    pub wall: bool,
    /// The floor: the table's legs and the floor show below its near edge.
    pub floor: bool,
    /// Fewest and most distractors (drawn uniformly between).
    pub distractors: (usize, usize),
    /// Distractor models (the target's own model is never one).
    pub pool: Vec<String>,
    /// The target's resting modes, indices into [`resting_modes`] (empty: all).
    pub modes: Vec<usize>,
    /// Range of the depth noise's σ (m), drawn per trial (none: the testbed's).
    pub sigma: Option<(f64, f64)>,
    /// Range of the dropout probability, drawn per trial (none: the testbed's).
    pub dropout: Option<(f64, f64)>,
    /// Leave the target out of the image (it still chooses where the camera looks).
    pub hide_target: bool,
}

/// Every model a distractor of the benchmark's clutter may be.
pub const DISTRACTOR_POOL: [&str; 5] = ["can_350ml", "can_200ml", "pet_500ml", "box", "vase"];

impl Clutter {
    /// The vision benchmark's clutter (issue 26): a wall behind the table, the
    /// floor and the table's legs, 1–3 distractors from [`DISTRACTOR_POOL`];
    /// `noisy`: σ 1–3 mm and 0.5–3 % dropout drawn per frame; `modes`: the
    /// target's resting modes (indices into [`resting_modes`], empty: all).
    pub fn benchmark(noisy: bool, modes: &[usize]) -> Clutter {
        Clutter {
            wall: true,
            floor: true,
            distractors: (1, 3),
            pool: DISTRACTOR_POOL.iter().map(|m| m.to_string()).collect(),
            modes: modes.to_vec(),
            sigma: noisy.then_some((0.001, 0.003)),
            dropout: noisy.then_some((0.005, 0.03)),
            hide_target: false,
        }
    }
}

/// One rendered trial.
#[derive(Debug, Clone)]
pub struct Trial {
    /// The seed it was drawn with.
    pub seed: u64,
    /// The target.
    pub target: Placement,
    /// The target's pose in the robot's base frame (what detection should report).
    pub truth: Isometry3<f64>,
    /// Other objects (the occluder).
    pub others: Vec<Placement>,
    /// Fraction of the target's visible pixels hidden by the others.
    pub occluded: f64,
    /// The camera, pose in the robot's base frame.
    pub camera: Camera,
    /// The head configuration.
    pub head: Vec<f64>,
    /// The measured depth image.
    pub image: DepthImage,
}

/// The table top: a rectangle at height `z` (world frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableTop {
    /// x range.
    pub x: (f64, f64),
    /// y range.
    pub y: (f64, f64),
    /// Height of the top.
    pub z: f64,
}

/// A scene's robot, obstacles and head camera, for rendering trials.
pub struct Testbed {
    /// The scene (robot and obstacles; its objects are not rendered).
    pub scene: Scene,
    /// The head camera.
    pub head: HeadCamera,
    /// The table top.
    pub table: TableTop,
    /// The noise of rendered images.
    pub noise: NoiseModel,
    objects_dir: std::path::PathBuf,
    models: HashMap<String, ObjectModel>,
    /// Obstacles of the current trial's clutter (wall, floor).
    extra: Vec<tsukami_body::collision::CollisionObject>,
}

impl Testbed {
    /// Loads `scene_path`; `table` names the obstacle objects are put on, and
    /// `objects_dir` holds `<model>/object.toml`.
    pub fn new(scene_path: &Path, table: &str, objects_dir: &Path) -> Result<Self> {
        let scene = Scene::load(scene_path)?;
        let head = HeadCamera::new(scene.robot.clone(), Intrinsics::head_camera())?;
        let obstacle = scene
            .obstacles
            .iter()
            .find(|o| o.name == table)
            .ok_or_else(|| {
                invalid(
                    "table",
                    format!("the scene has no obstacle named '{table}'"),
                )
            })?;
        let mut w = SimWorld::default();
        w.add_object(obstacle);
        let top = w.bodies[0]
            .shapes
            .iter()
            .max_by(|a, b| {
                let area = |s: &super::world::SimShape| {
                    let e = s.aabb.extents();
                    e.x * e.y
                };
                area(a).total_cmp(&area(b))
            })
            .ok_or_else(|| invalid("table", "the table has no shapes"))?;
        let table = TableTop {
            x: (top.aabb.mins.x, top.aabb.maxs.x),
            y: (top.aabb.mins.y, top.aabb.maxs.y),
            z: top.aabb.maxs.z,
        };
        Ok(Testbed {
            scene,
            head,
            table,
            noise: NoiseModel::default(),
            objects_dir: objects_dir.to_path_buf(),
            models: HashMap::new(),
            extra: Vec::new(),
        })
    }

    /// The object model `name`, loaded once.
    pub fn model(&mut self, name: &str) -> Result<&ObjectModel> {
        if !self.models.contains_key(name) {
            let path = self.objects_dir.join(name).join("object.toml");
            let model = ObjectModel::load(&path)?;
            self.models.insert(name.to_owned(), model);
        }
        Ok(&self.models[name])
    }

    /// A placement of `model` resting on the table top with rotation `q` and
    /// its footprint centred at `xy`.
    pub fn rest(
        &mut self,
        model: &str,
        q: UnitQuaternion<f64>,
        xy: Vector2<f64>,
    ) -> Result<Placement> {
        let z = self.table.z;
        let m = self.model(model)?;
        let (lo, hi) = rotated_box(m, &q);
        let centre = (lo + hi) * 0.5;
        let t = Vector3::new(xy.x - centre.x, xy.y - centre.y, z - lo.z + 2e-4);
        Ok(Placement {
            model: model.to_owned(),
            pose: Isometry3::from_parts(Translation3::from(t), q),
        })
    }

    /// Radius of the footprint of `model` under rotation `q` (m).
    pub fn footprint(&mut self, model: &str, q: &UnitQuaternion<f64>) -> Result<f64> {
        let m = self.model(model)?;
        let (lo, hi) = rotated_box(m, q);
        Ok(((hi.x - lo.x).powi(2) + (hi.y - lo.y).powi(2)).sqrt() * 0.5)
    }

    /// A random resting pose of `model` on the table, drawn from `rng`.
    pub fn random_rest(&mut self, model: &str, rng: &mut ChaCha8Rng) -> Result<Placement> {
        self.random_rest_in(model, &[], rng)
    }

    /// [`Testbed::random_rest`] in one of the resting modes `only` (indices
    /// into [`resting_modes`]; empty: any).
    pub fn random_rest_in(
        &mut self,
        model: &str,
        only: &[usize],
        rng: &mut ChaCha8Rng,
    ) -> Result<Placement> {
        let all = resting_modes(model);
        let modes: Vec<UnitQuaternion<f64>> = if only.is_empty() {
            all
        } else {
            only.iter().filter_map(|&i| all.get(i).copied()).collect()
        };
        if modes.is_empty() {
            return Err(invalid(
                "modes",
                format!("'{model}' has no resting mode {only:?}"),
            ));
        }
        let mode = modes[rng.random_range(0..modes.len())];
        let yaw = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw) * mode;
        let r = self.footprint(model, &q)?;
        let t = self.table;
        let (xlo, xhi) = ((t.x.0 + 0.13 + r).max(0.45), (t.x.1 - 0.03 - r).min(0.72));
        let (ylo, yhi) = ((t.y.0 + 0.05 + r).max(-0.45), (t.y.1 - 0.05 - r).min(0.05));
        if xlo >= xhi || ylo >= yhi {
            return Err(invalid(
                "table",
                "the table top is too small for the object",
            ));
        }
        let xy = Vector2::new(rng.random_range(xlo..xhi), rng.random_range(ylo..yhi));
        self.rest(model, q, xy)
    }

    /// The renderable world: obstacles, the robot at `q`, and `placements`.
    pub fn world(&mut self, placements: &[Placement], q: &[f64]) -> Result<SimWorld> {
        let mut w = SimWorld::default();
        for o in self.scene.obstacles.iter().chain(&self.extra) {
            w.add_object(o);
        }
        let cam_world = self.scene.robot_base * self.head.pose(q);
        let centre = Point3::from(cam_world.translation.vector);
        w.add_robot(&self.scene.robot, q, &self.scene.robot_base, &centre)?;
        for p in placements {
            let mut obj = self.model(&p.model)?.collision_object(p.pose)?;
            obj.name = p.model.clone();
            w.add_object(&obj);
        }
        Ok(w)
    }

    /// The head configuration looking at a world point.
    pub fn look_at(&self, world_point: &Point3<f64>) -> Vec<f64> {
        self.head
            .look_at(&(self.scene.robot_base.inverse() * world_point))
    }

    /// The head camera at `q` with its pose in the world.
    pub fn world_camera(&self, q: &[f64]) -> Camera {
        let camera = self.head.camera(q);
        Camera {
            intrinsics: camera.intrinsics,
            pose: self.scene.robot_base * camera.pose,
        }
    }

    /// Renders `placements` seen with the head at `q`: the image and the
    /// camera (pose in the base frame).
    pub fn render(
        &mut self,
        placements: &[Placement],
        q: &[f64],
        seed: u64,
    ) -> Result<(DepthImage, Camera)> {
        let world = self.world(placements, q)?;
        let r = render(&world, &self.world_camera(q), &self.noise, seed)?;
        Ok((r.image, self.head.camera(q)))
    }

    /// A trial: `target` at a random resting pose; with `occluder`, that
    /// object placed to hide `occlusion` of the target's visible pixels.
    /// Tries successive random poses until one fits (at most 50).
    pub fn trial(
        &mut self,
        target: &str,
        occluder: Option<&str>,
        occlusion: f64,
        seed: u64,
    ) -> Result<Trial> {
        self.trial_in(target, occluder, occlusion, seed, &Clutter::default())
    }

    /// [`Testbed::trial`] with `clutter` around the target.
    pub fn trial_in(
        &mut self,
        target: &str,
        occluder: Option<&str>,
        occlusion: f64,
        seed: u64,
        clutter: &Clutter,
    ) -> Result<Trial> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        self.extra = self.clutter_obstacles(clutter, &mut rng)?;
        let noise = self.noise.clone();
        if let Some((lo, hi)) = clutter.sigma {
            self.noise.sigma = rng.random_range(lo..=hi);
        }
        if let Some((lo, hi)) = clutter.dropout {
            self.noise.dropout = rng.random_range(lo..=hi);
        }
        let trial = self.draw_trial(target, occluder, occlusion, seed, clutter, &mut rng);
        self.noise = noise;
        trial
    }

    /// The wall and the floor of `clutter`.
    fn clutter_obstacles(
        &self,
        clutter: &Clutter,
        rng: &mut ChaCha8Rng,
    ) -> Result<Vec<tsukami_body::collision::CollisionObject>> {
        use tsukami_body::collision::{CollisionObject, Part};
        use tsukami_body::model::Geometry;
        let slab = |name: &str, centre: Vector3<f64>, size: Vector3<f64>| -> Result<_> {
            let part = Part::from_geometry(&Isometry3::identity(), &Geometry::Box { size })?;
            Ok(CollisionObject::new(
                name,
                Isometry3::from_parts(Translation3::from(centre), UnitQuaternion::identity()),
                vec![part],
            ))
        };
        let t = self.table;
        let mut out = Vec::new();
        if clutter.wall {
            let x = t.x.1 + rng.random_range(0.0..0.06) + 0.025;
            let y = 0.5 * (t.y.0 + t.y.1);
            out.push(slab(
                "wall",
                Vector3::new(x, y, 0.9),
                Vector3::new(0.05, 3.0, 1.8),
            )?);
        }
        if clutter.floor {
            out.push(slab(
                "floor",
                Vector3::new(1.0, 0.0, -0.01),
                Vector3::new(4.0, 4.0, 0.02),
            )?);
        }
        Ok(out)
    }

    /// The trial's placements and image (see [`Testbed::trial_in`]).
    fn draw_trial(
        &mut self,
        target: &str,
        occluder: Option<&str>,
        occlusion: f64,
        seed: u64,
        clutter: &Clutter,
        rng: &mut ChaCha8Rng,
    ) -> Result<Trial> {
        for _ in 0..50 {
            let placement = self.random_rest_in(target, &clutter.modes, rng)?;
            let centroid = placement.pose * centre_of(self.model(target)?);
            let q = self.look_at(&centroid);
            let mut others = Vec::new();
            let mut occluded = 0.0;
            if let Some(occ) = occluder {
                match self.place_occluder(&placement, occ, occlusion, &q, rng)? {
                    Some((p, f)) => {
                        others.push(p);
                        occluded = f;
                    }
                    None => continue,
                }
            }
            let mut all = vec![placement.clone()];
            all.extend(others.iter().cloned());
            let extra = self.distractors(&all, clutter, &q, rng)?;
            others.extend(extra.iter().cloned());
            all.extend(extra);
            if clutter.hide_target {
                all.remove(0);
            }
            let (image, camera) = self.render(&all, &q, rng.random())?;
            return Ok(Trial {
                seed,
                truth: self.scene.robot_base.inverse() * placement.pose,
                target: placement,
                others,
                occluded,
                camera,
                head: q,
                image,
            });
        }
        Err(VisionError::Invalid {
            field: "trial".into(),
            message: format!("no placement of '{target}' fits the table after 50 tries"),
        })
    }

    /// Distractors for `clutter` beside or behind `placed[0]` (the target),
    /// clear of everything in `placed` and of each other.
    fn distractors(
        &mut self,
        placed: &[Placement],
        clutter: &Clutter,
        q: &[f64],
        rng: &mut ChaCha8Rng,
    ) -> Result<Vec<Placement>> {
        let (lo, hi) = clutter.distractors;
        let pool: Vec<String> = clutter
            .pool
            .iter()
            .filter(|m| **m != placed[0].model)
            .cloned()
            .collect();
        if hi == 0 || pool.is_empty() {
            return Ok(Vec::new());
        }
        let count = rng.random_range(lo..=hi.max(lo));
        let cam = (self.scene.robot_base * self.head.pose(q))
            .translation
            .vector
            .xy();
        let mut taken: Vec<(Vector2<f64>, f64)> = Vec::new();
        for p in placed {
            taken.push((
                self.centre_xy(p)?,
                self.footprint(&p.model, &p.pose.rotation)?,
            ));
        }
        let (target, rt) = taken[0];
        let d = (target - cam).normalize();
        let mut out = Vec::new();
        for _ in 0..count {
            let model = pool[rng.random_range(0..pool.len())].clone();
            for _ in 0..30 {
                let p = self.random_rest_on_table(&model, rng)?;
                let (c, r) = (
                    self.centre_xy(&p)?,
                    self.footprint(&model, &p.pose.rotation)?,
                );
                let clear = taken.iter().all(|(o, ro)| (c - o).norm() > r + ro + 0.03);
                // Not in front: behind the target's front, or off its line of sight.
                let rel = c - target;
                let beside = (rel - d * rel.dot(&d)).norm() > rt + r + 0.03;
                if clear && (rel.dot(&d) > -rt || beside) {
                    taken.push((c, r));
                    out.push(p);
                    break;
                }
            }
        }
        Ok(out)
    }

    /// A random resting pose of `model` anywhere on the table top (5 cm from its edges).
    fn random_rest_on_table(&mut self, model: &str, rng: &mut ChaCha8Rng) -> Result<Placement> {
        let modes = resting_modes(model);
        let mode = modes[rng.random_range(0..modes.len())];
        let yaw = rng.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw) * mode;
        let r = self.footprint(model, &q)?;
        let t = self.table;
        let (xlo, xhi) = (t.x.0 + 0.05 + r, t.x.1 - 0.05 - r);
        let (ylo, yhi) = (t.y.0 + 0.05 + r, t.y.1 - 0.05 - r);
        if xlo >= xhi || ylo >= yhi {
            return Err(invalid(
                "table",
                format!("the table top is too small for '{model}'"),
            ));
        }
        let xy = Vector2::new(rng.random_range(xlo..xhi), rng.random_range(ylo..yhi));
        self.rest(model, q, xy)
    }

    /// The centre of a placement's footprint (world xy).
    fn centre_xy(&mut self, p: &Placement) -> Result<Vector2<f64>> {
        let (lo, hi) = rotated_box(self.model(&p.model)?, &p.pose.rotation);
        Ok(p.pose.translation.vector.xy() + (lo.xy() + hi.xy()) * 0.5)
    }

    /// Places `model` upright between the camera and `target` so that about
    /// `fraction` of the target's pixels are hidden; `None` if it does not fit.
    fn place_occluder(
        &mut self,
        target: &Placement,
        model: &str,
        fraction: f64,
        q: &[f64],
        rng: &mut ChaCha8Rng,
    ) -> Result<Option<(Placement, f64)>> {
        // Not ±π: the range is part of every seeded trial drawn so far.
        #[allow(clippy::approx_constant)]
        let yaw = rng.random_range(-3.14..3.14);
        let qo = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
        let (rt, ro) = (
            self.footprint(&target.model, &target.pose.rotation)?,
            self.footprint(model, &qo)?,
        );
        let (lo, hi) = rotated_box(self.model(&target.model)?, &target.pose.rotation);
        let ct = target.pose.translation.vector.xy() + (lo.xy() + hi.xy()) * 0.5;
        let cam = (self.scene.robot_base * self.head.pose(q))
            .translation
            .vector
            .xy();
        let d = (ct - cam).normalize();
        let perp = Vector2::new(-d.y, d.x) * if rng.random::<bool>() { 1.0 } else { -1.0 };
        let base = ct - d * (rt + ro + 0.015);
        let visible = |tb: &mut Self, occ: Option<&Placement>| -> Result<usize> {
            let mut all = vec![target.clone()];
            all.extend(occ.cloned());
            let world = tb.world(&all, q)?;
            let t_idx = world.bodies.len() - all.len();
            let cam = tb.world_camera(q);
            let region = body_region(&world, t_idx, &cam);
            let hits = trace(&world, &cam, region, &|_| true);
            Ok(hits.iter().flatten().filter(|h| h.body == t_idx).count())
        };
        let alone = visible(self, None)? as f64;
        if alone < 50.0 {
            return Ok(None);
        }
        let at = |tb: &mut Self, s: f64| -> Result<Option<(Placement, f64)>> {
            let xy = base + perp * s;
            let p = tb.rest(model, qo, xy)?;
            let t = tb.table;
            if xy.x - ro < t.x.0 || xy.x + ro > t.x.1 || xy.y - ro < t.y.0 || xy.y + ro > t.y.1 {
                return Ok(None);
            }
            let f = 1.0 - visible(tb, Some(&p))? as f64 / alone;
            Ok(Some((p, f)))
        };
        let (mut lo_s, mut hi_s) = (0.0, rt + ro + 0.03);
        let mut best: Option<(Placement, f64)> = None;
        for _ in 0..10 {
            let s = 0.5 * (lo_s + hi_s);
            let Some((p, f)) = at(self, s)? else {
                return Ok(None);
            };
            if best
                .as_ref()
                .is_none_or(|(_, bf)| (f - fraction).abs() < (bf - fraction).abs())
            {
                best = Some((p, f));
            }
            if (f - fraction).abs() < 0.01 {
                break;
            }
            if f > fraction {
                lo_s = s;
            } else {
                hi_s = s;
            }
        }
        Ok(best.filter(|(_, f)| (f - fraction).abs() < 0.05))
    }
}

/// The resting orientations used for `model`: bottles stand or lie; other
/// objects also stand upside down and lie on either side.
pub fn resting_modes(model: &str) -> Vec<UnitQuaternion<f64>> {
    let rx = |a: f64| UnitQuaternion::from_axis_angle(&Vector3::x_axis(), a);
    let ry = |a: f64| UnitQuaternion::from_axis_angle(&Vector3::y_axis(), a);
    let half = std::f64::consts::FRAC_PI_2;
    if model.starts_with("pet") {
        vec![UnitQuaternion::identity(), rx(half)]
    } else {
        vec![
            UnitQuaternion::identity(),
            rx(2.0 * half),
            rx(half),
            ry(half),
        ]
    }
}

/// The bounding box of a model's vertices under rotation `q` (object origin fixed).
fn rotated_box(m: &ObjectModel, q: &UnitQuaternion<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let mut lo = Vector3::repeat(f64::INFINITY);
    let mut hi = Vector3::repeat(f64::NEG_INFINITY);
    for v in &m.mesh.vertices {
        let p = q * v.coords;
        lo = lo.inf(&p);
        hi = hi.sup(&p);
    }
    (lo, hi)
}

/// The pixel rectangle covering body `b`'s shapes.
fn body_region(world: &SimWorld, b: usize, camera: &Camera) -> Region {
    let k = &camera.intrinsics;
    let mut r = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for s in &world.bodies[b].shapes {
        let p = pixel_box(camera, s.aabb.mins, s.aabb.maxs);
        r = [
            r[0].min(p[0]),
            r[1].min(p[1]),
            r[2].max(p[2]),
            r[3].max(p[3]),
        ];
    }
    let c = |x: f64, hi: u32| x.clamp(0.0, hi as f64) as u32;
    [
        c(r[0], k.width),
        c(r[1], k.height),
        c(r[2] + 1.0, k.width),
        c(r[3] + 1.0, k.height),
    ]
}

/// The centre of a model's bounding box (object frame).
fn centre_of(m: &ObjectModel) -> Point3<f64> {
    let (lo, hi) = m.mesh.aabb();
    nalgebra::center(&lo, &hi)
}
