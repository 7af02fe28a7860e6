//! The viewer's shared core: the world, the latest results, and what is made
//! of them — pictures, `.glb` files and the web page's JSON.
//!
//! What: [`Viewer`] holds the kit session with the host's world
//! ([`ViewerWorld`]) and the [`Board`] of followed results; it answers
//! [`Viewer::render`] (PNG) and [`Viewer::glb`], and the web server's
//! [`Viewer::scene_json`], [`Viewer::state_json`] and
//! [`Viewer::trajectory_json`], each cached until what it shows changes.
//!
//! Why: the plugin's commands and the web server's threads share one view of
//! the world and the results; caching keeps many open pages from costing
//! more than one.
//!
//! How: every product is built from a world snapshot (an `Arc`, taken without
//! waiting for changes) and a copy of the board's slots, outside any lock
//! but the cache's own.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use nalgebra::{Isometry3, Vector3};
use tsukami_body::collision::CollisionObject;
use tsukami_planner_kit::snapshot::Snapshot;
use tsukami_planner_kit::Session;

use tsukami_render::drawing::Drawing;
use tsukami_render::glb::to_glb;
use tsukami_render::grasp_view::{contact_marks, look_at, posture, GraspView};
use tsukami_render::render::{render, Camera};

use crate::latest::{Board, Outcome};
use crate::world::ViewerWorld;

/// A cached product and the key it was made for.
type Cached = Mutex<Option<((u64, u64), Arc<Vec<u8>>)>>;

/// The shared core (see the module docs).
pub struct Viewer {
    /// The world as the host set it.
    pub session: Session<ViewerWorld>,
    /// The latest results.
    pub board: Arc<Board>,
    scene: Cached,
    state: Cached,
    trajectory: Cached,
    /// Event-stream messages sent to pages.
    pub events_sent: AtomicU64,
    /// Pages connected to the event stream now.
    pub event_clients: AtomicU64,
}

/// A picture: PNG bytes, and whether the robot is at a planned posture.
pub struct Picture {
    /// The PNG file.
    pub png: Vec<u8>,
    /// `plan` or `rest`.
    pub posture: &'static str,
    /// Triangles drawn.
    pub triangles: usize,
    /// The world version drawn.
    pub world_version: u64,
}

fn cached(slot: &Cached, key: (u64, u64), make: impl FnOnce() -> Vec<u8>) -> Arc<Vec<u8>> {
    let mut slot = slot.lock().unwrap_or_else(|p| p.into_inner());
    match &*slot {
        Some((k, bytes)) if *k == key => bytes.clone(),
        _ => {
            let bytes = Arc::new(make());
            *slot = Some((key, bytes.clone()));
            bytes
        }
    }
}

impl Viewer {
    /// A viewer of `session`'s world and `board`'s results.
    pub fn new(session: Session<ViewerWorld>, board: Arc<Board>) -> Self {
        Viewer {
            session,
            board,
            scene: Mutex::new(None),
            state: Mutex::new(None),
            trajectory: Mutex::new(None),
            events_sent: AtomicU64::new(0),
            event_clients: AtomicU64::new(0),
        }
    }

    /// The bodies (see [`crate::scene::geometry`]), JSON.
    pub fn scene_json(&self) -> Arc<Vec<u8>> {
        let world = self.session.snapshot();
        cached(&self.scene, (world.version, 0), || {
            serde_json::to_vec(&crate::scene::geometry(&world)).unwrap_or_default()
        })
    }

    /// What changes with every result (see [`crate::scene::state`]), JSON.
    pub fn state_json(&self) -> Arc<Vec<u8>> {
        let world = self.session.snapshot();
        let (latest, generation) = self.board.read();
        cached(&self.state, (world.version, generation), || {
            serde_json::to_vec(&crate::scene::state(&world, &latest, generation))
                .unwrap_or_default()
        })
    }

    /// The last motion's link poses (see [`crate::scene::trajectory`]), JSON;
    /// `null` without a robot or a motion.
    pub fn trajectory_json(&self) -> Arc<Vec<u8>> {
        let world = self.session.snapshot();
        let (latest, _) = self.board.read();
        cached(&self.trajectory, (world.version, latest.motions), || {
            let value = match (world.robot.as_deref(), latest.motion.as_deref()) {
                (Some((robot, ())), Some(Outcome::Done(m))) => {
                    crate::scene::trajectory(&robot.model, &m.trajectory)
                }
                _ => serde_json::Value::Null,
            };
            serde_json::to_vec(&value).unwrap_or_default()
        })
    }

    /// The world with the robot at the last plan's posture (at rest without
    /// one, or when the plan does not fit this robot), and the camera target.
    fn drawing(
        &self,
        world: &Snapshot<ViewerWorld>,
    ) -> Result<(Drawing, &'static str, nalgebra::Point3<f64>), String> {
        let (robot, ()) = world
            .robot
            .as_deref()
            .ok_or("not_ready: no robot yet (set_robot)")?;
        let (latest, _) = self.board.read();
        let reply = match latest.plan.as_deref() {
            Some(Outcome::Done(r)) => posture(&robot.model, r).ok().map(|q| (r, q)),
            _ => None,
        };
        let contacts = reply
            .as_ref()
            .map(|(r, _)| contact_marks(r))
            .unwrap_or_default();
        let (q, label) = match &reply {
            Some((_, q)) => (q.clone(), "plan"),
            None => (robot.model.rest_positions(), "rest"),
        };
        let obstacles: Vec<CollisionObject> = world.env.values().cloned().collect();
        let hand = robot.hand();
        let object = world.object.as_deref().map(|(o, ())| (&o.mesh, o.pose));
        let target = match object {
            Some((mesh, pose)) => look_at(mesh, &pose, &contacts),
            None => nalgebra::Point3::from(hand_pose(robot, &q).translation.vector),
        };
        let view = GraspView {
            model: &robot.model,
            collision: &hand.collision,
            q: &q,
            hand_links: &hand.links,
            object,
            obstacles: &obstacles,
            contacts: &contacts,
        };
        Ok((view.drawing(), label, target))
    }

    /// A `width × height` picture seen from `eye` relative to the grasp.
    pub fn render(&self, width: u32, height: u32, eye: Vector3<f64>) -> Result<Picture, String> {
        let world = self.session.snapshot();
        let (drawing, posture, target) = self.drawing(&world)?;
        let camera = Camera::offset_from(target, eye);
        let png = render(&drawing, &camera, width, height)
            .to_png()
            .map_err(|e| format!("internal: encoding the PNG: {e}"))?;
        Ok(Picture {
            png,
            posture,
            triangles: drawing.triangle_count(),
            world_version: world.version,
        })
    }

    /// The same scene as a glTF 2.0 binary, and the world version drawn.
    pub fn glb(&self) -> Result<(Vec<u8>, u64), String> {
        let world = self.session.snapshot();
        let (drawing, _, _) = self.drawing(&world)?;
        Ok((to_glb(&drawing), world.version))
    }

    /// Counts a message sent on an event stream.
    pub fn sent(&self) {
        self.events_sent.fetch_add(1, Ordering::Relaxed);
    }
}

/// The palm's pose at `q` (where to look without an object).
fn hand_pose(robot: &tsukami_planner_kit::Robot, q: &[f64]) -> Isometry3<f64> {
    let mut fk = tsukami_body::kinematics::FkState::new(&robot.model);
    robot.model.forward_kinematics(q, &mut fk);
    *fk.pose(robot.hand().palm)
}
