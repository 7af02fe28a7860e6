//! The vision component on the bus: `<ns>/vision/detect`, `<ns>/vision/look`
//! and `<ns>/vision/pose/<object>`.
//!
//! What: [`VisionService::handle`] answers one [`DetectRequest`] and
//! [`VisionService::look`] one [`LookRequest`] (no bus involved, so they are
//! tested directly); [`serve`] puts them on the bus through a
//! [`tsukami_bus::Component`].
//!
//! Why: detection takes tens of milliseconds; zenoh's callback must stay
//! quick, so queries are queued (bounded) to one worker thread, which replies,
//! publishes the pose and, on request, sends it on as the object's pose.
//!
//! How: a request's image is decoded and checked ([`crate::convert`]);
//! without one the component looks ([`crate::look`]): the [`SceneCamera`]
//! renders the robot's views, aimed where the object is expected, until one
//! sees it. Both keys share one queue and worker. Not found is an
//! `infeasible` error with `details.reason = "not_found"` and the pipeline's
//! explanation; bad input is `invalid_value`/`model_error` naming the field.

use std::sync::mpsc::{sync_channel, SyncSender, TrySendError};
use std::sync::Arc;
use std::time::Duration;

use nalgebra::Point3;
use serde_json::json;
use tsukami_body::files::ModelRoots;
use tsukami_bus::serve::{check_size, parse_query, reply_error, reply_json};
use tsukami_bus::{BusClient, Component};
use tsukami_msgs::keys::planner::SET_OBJECT;
use tsukami_msgs::planner::{ObjectShape, SetObject};
use tsukami_msgs::vision::{DetectRequest, LookReply, LookRequest, LookView, ObjectPose};
use tsukami_msgs::{ErrorCode, ErrorReply, KeySpace};

use crate::convert::{attempt_to_msg, detection_to_msg, frame_from_msg};
use crate::detect::{detect_with, DetectParams, Detector, Outcome};
use crate::error::VisionError;
use crate::look::{Looked, Target, MAX_VIEWS};
use crate::sim::scene_camera::SceneCamera;
use crate::template::{is_plain_name, ObjectTemplate};

/// Detections waiting for the worker before new ones are refused.
const QUEUE: usize = 8;

/// The component's state: the detector, its camera and its frame counter.
pub struct VisionService {
    detector: Detector,
    camera: Option<SceneCamera>,
    frames: u64,
}

/// A request's outcome before it goes on the bus.
#[derive(Debug)]
pub struct Handled {
    /// The reply.
    pub pose: ObjectPose,
    /// The `set_object` payload to send, when the request asked for it.
    pub set_object: Option<SetObject>,
    /// For a look: the index of the view the pose was found in, and every
    /// view taken.
    pub look: Option<(u32, Vec<LookView>)>,
}

fn error_reply(e: &VisionError) -> ErrorReply {
    let code = match e {
        VisionError::Model { .. } | VisionError::Body(_) | VisionError::Io { .. } => {
            ErrorCode::ModelError
        }
        VisionError::Invalid { .. } | VisionError::Decode { .. } => ErrorCode::InvalidValue,
    };
    ErrorReply::new(code, e.to_string())
}

fn invalid_value(message: String) -> ErrorReply {
    ErrorReply::new(ErrorCode::InvalidValue, message)
}

impl VisionService {
    /// A service loading object models from `roots`, with an optional simulated camera.
    pub fn new(roots: ModelRoots, params: DetectParams, camera: Option<SceneCamera>) -> Self {
        VisionService {
            detector: Detector::new(roots, params),
            camera,
            frames: 0,
        }
    }

    /// Answers one detect request: in its image, else by looking with the
    /// camera (as [`VisionService::look`] without an expected position).
    pub fn handle(&mut self, req: &DetectRequest) -> Result<Handled, ErrorReply> {
        let Some(frame) = &req.image else {
            let mut handled = self.look(&LookRequest {
                object: req.object.clone(),
                expected: None,
                max_views: None,
                set_object: req.set_object,
                min_confidence: req.min_confidence,
                seed: req.seed,
            })?;
            handled.look = None;
            return Ok(handled);
        };
        let (params, template) = self.prepare(&req.object, req.min_confidence)?;
        let (image, camera) = frame_from_msg(frame).map_err(|e| error_reply(&e))?;
        let outcome =
            detect_with(&template, &image, &camera, &params).map_err(|e| error_reply(&e))?;
        answer(&req.object, req.set_object, &template, outcome, None)
    }

    /// Answers one look request: the views of [`crate::look::Looker::look`] around the
    /// expected position (else where the camera's scene has the object),
    /// each rendered and detected in.
    pub fn look(&mut self, req: &LookRequest) -> Result<Handled, ErrorReply> {
        let (params, template) = self.prepare(&req.object, req.min_confidence)?;
        let max_views = match req.max_views {
            None => MAX_VIEWS,
            Some(n) if (1..=MAX_VIEWS as u32).contains(&n) => n as usize,
            Some(n) => {
                return Err(invalid_value(format!(
                    "max_views: {n} must be within 1 to {MAX_VIEWS}"
                )))
            }
        };
        if req
            .expected
            .is_some_and(|p| !p.iter().all(|x| x.is_finite()))
        {
            return Err(invalid_value(
                "expected: must be three finite numbers (m)".into(),
            ));
        }
        let seed = req.seed.unwrap_or(self.frames);
        self.frames += 1;
        let cam = self.camera.as_ref().ok_or_else(|| {
            ErrorReply::new(
                ErrorCode::NotReady,
                "no image in the request and no camera: start the component with --scene",
            )
        })?;
        let target = match req.expected {
            Some(p) => Target {
                centre: Point3::from(p),
                radius: template.radius,
            },
            None => cam.target(&req.object, template.radius),
        };
        let looked = cam
            .looker
            .look(&target, max_views, |view| {
                let (image, camera) = cam.render(&view.q, seed)?;
                detect_with(&template, &image, &camera, &params)
            })
            .map_err(|e| error_reply(&e))?;
        let robot = &cam.looker.head.robot;
        let rest = robot.rest_positions();
        let views: Vec<LookView> = looked
            .attempts
            .iter()
            .map(|a| attempt_to_msg(a, robot, &rest))
            .collect();
        let shown = looked
            .chosen
            .or_else(|| most_confident(&looked))
            .unwrap_or(0);
        let outcome = looked.attempts.get(shown).map(|a| a.outcome.clone());
        let outcome = outcome.ok_or_else(|| {
            ErrorReply::new(ErrorCode::Infeasible, "no view of the object may be taken")
        })?;
        answer(
            &req.object,
            req.set_object,
            &template,
            outcome,
            Some((shown as u32, views)),
        )
    }

    /// The detection settings of a request (its `min_confidence` checked) and
    /// the object's template (its name checked).
    fn prepare(
        &mut self,
        object: &str,
        min_confidence: Option<f64>,
    ) -> Result<(DetectParams, Arc<ObjectTemplate>), ErrorReply> {
        if !is_plain_name(object) {
            return Err(invalid_value(
                "object: an object name is a folder name under objects/ (letters, digits, '_', '-')"
                    .into(),
            ));
        }
        let mut params = self.detector.params.clone();
        if let Some(c) = min_confidence {
            if !(0.0..=1.0).contains(&c) {
                return Err(invalid_value(format!(
                    "min_confidence: {c} must be within [0, 1]"
                )));
            }
            params.min_confidence = c;
        }
        let template = self
            .detector
            .template(object)
            .map_err(|e| error_reply(&e))?;
        Ok((params, template))
    }
}

/// The attempt whose best candidate was the most confident (the first of
/// equals), when none found the object.
fn most_confident(looked: &Looked) -> Option<usize> {
    let confidence = |o: &Outcome| match o {
        Outcome::Found(d) => d.confidence,
        Outcome::NotFound(n) => n.best.as_ref().map_or(-1.0, |b| b.confidence),
    };
    looked
        .attempts
        .iter()
        .enumerate()
        .max_by(|a, b| {
            confidence(&a.1.outcome)
                .total_cmp(&confidence(&b.1.outcome))
                .then(b.0.cmp(&a.0))
        })
        .map(|(i, _)| i)
}

/// The reply to a detection of `object`: the pose (with the `set_object` to
/// send on, if asked), or the not-found error — a look's views in its details.
fn answer(
    object: &str,
    set_object: bool,
    template: &ObjectTemplate,
    outcome: Outcome,
    look: Option<(u32, Vec<LookView>)>,
) -> Result<Handled, ErrorReply> {
    match outcome {
        Outcome::Found(d) => {
            let pose = detection_to_msg(&d, &template.symmetry);
            let set_object = set_object.then(|| SetObject {
                name: Some(object.to_owned()),
                shape: ObjectShape::Model {
                    name: object.to_owned(),
                },
                mass: template.model.mass,
                friction: Some(template.model.friction),
                pose: pose.pose,
                center_of_mass: None,
            });
            Ok(Handled {
                pose,
                set_object,
                look,
            })
        }
        Outcome::NotFound(n) => {
            let (message, views) = match &look {
                Some((shown, views)) => (
                    format!(
                        "'{object}' not found in {} view(s); in view '{}': {}",
                        views.len(),
                        views.get(*shown as usize).map_or("", |v| v.name.as_str()),
                        n.reason
                    ),
                    Some(views),
                ),
                None => (format!("'{object}' not found: {}", n.reason), None),
            };
            Err(
                ErrorReply::new(ErrorCode::Infeasible, message).with_details(json!({
                    "reason": "not_found",
                    "best_confidence": n.best.as_ref().map(|b| b.confidence),
                    "views": views,
                })),
            )
        }
    }
}

/// Where found poses are sent on (`set_object` in the request): the world's
/// `set_object`.
pub fn set_object_key(keys: &KeySpace) -> String {
    keys.world(SET_OBJECT)
}

/// Which key a query came on.
#[derive(Debug, Clone, Copy)]
enum Ask {
    Detect,
    Look,
}

/// The queryables of the component (keep them alive).
pub type Queryables = Vec<zenoh::query::Queryable<()>>;

/// Serves `service` on `component`'s bus (`<ns>/vision/detect` and
/// `<ns>/vision/look`) until the component closes. Returns the queryables
/// (keep them alive) and the worker's handle.
pub fn serve(
    component: &Component,
    mut service: VisionService,
    set_object_timeout: Duration,
) -> anyhow::Result<(Queryables, std::thread::JoinHandle<()>)> {
    let keys = component.keys().clone();
    let (tx, rx) = sync_channel::<(Ask, zenoh::query::Query)>(QUEUE);
    let queryables = vec![
        component.serve_query(&keys.vision_detect(), enqueue(tx.clone(), Ask::Detect))?,
        component.serve_query(&keys.vision_look(), enqueue(tx, Ask::Look))?,
    ];
    let client = BusClient::on_session(component.session().clone(), keys.namespace());
    let session = component.session().clone();
    let worker = std::thread::Builder::new()
        .name("vision-detect".into())
        .spawn(move || {
            while let Ok((ask, query)) = rx.recv() {
                let handled = match ask {
                    Ask::Detect => parse_query::<DetectRequest>(&query)
                        .map(|r| (r.object.clone(), service.handle(&r))),
                    Ask::Look => parse_query::<LookRequest>(&query)
                        .map(|r| (r.object.clone(), service.look(&r))),
                };
                match handled {
                    Err(e) => reply_error(&query, e),
                    Ok((object, Err(e))) => {
                        tracing::info!(%object, error = %e.error.message, "detect failed");
                        reply_error(&query, e);
                    }
                    Ok((object, Ok(handled))) => {
                        match send_on(&client, &object, handled, set_object_timeout) {
                            Ok(handled) => reply_found(&session, &keys, &query, handled),
                            Err(e) => reply_error(&query, e),
                        }
                    }
                }
            }
        })?;
    Ok((queryables, worker))
}

/// The queryable's callback: an oversized request is refused before it
/// takes a queue slot, a full queue is `busy`, anything else is queued.
fn enqueue(
    tx: SyncSender<(Ask, zenoh::query::Query)>,
    ask: Ask,
) -> impl Fn(zenoh::query::Query) + Send + Sync + 'static {
    move |query| {
        if let Err(error) = check_size(&query) {
            return reply_error(&query, error);
        }
        if let Err(TrySendError::Full((_, q))) = tx.try_send((ask, query)) {
            reply_error(
                &q,
                ErrorReply::new(
                    ErrorCode::Busy,
                    format!("busy: {QUEUE} detections are queued, the most that wait; retry later"),
                ),
            );
        }
    }
}

/// Sends a found pose on to the world when the request asked for it; the
/// reply's `sent_to` names the key.
fn send_on(
    client: &BusClient,
    object: &str,
    mut handled: Handled,
    timeout: Duration,
) -> Result<Handled, ErrorReply> {
    let Some(set) = handled.set_object.take() else {
        return Ok(handled);
    };
    let key = set_object_key(client.keys());
    let payload = serde_json::to_vec(&set).unwrap_or_default();
    match client.request_key(&key, &payload, timeout) {
        Ok(_) => {
            handled.pose.sent_to = Some(key);
            Ok(handled)
        }
        Err(e) => Err(ErrorReply::new(
            e.code().unwrap_or(ErrorCode::Timeout),
            format!("'{object}' found, but sending it on to {key} failed: {e}"),
        )),
    }
}

/// Publishes a found pose and replies with it (with the views, for a look).
fn reply_found(
    session: &zenoh::Session,
    keys: &KeySpace,
    query: &zenoh::query::Query,
    handled: Handled,
) {
    publish(session, keys, &handled.pose);
    tracing::info!(
        object = %handled.pose.object,
        confidence = handled.pose.confidence,
        fit_error = handled.pose.fit_error,
        view = handled.look.as_ref().map(|(v, _)| *v),
        "found"
    );
    match handled.look {
        Some((view, views)) => reply_json(
            query,
            &LookReply {
                pose: handled.pose,
                view,
                views,
            },
        ),
        None => reply_json(query, &handled.pose),
    }
}

fn publish(session: &zenoh::Session, keys: &KeySpace, pose: &ObjectPose) {
    use zenoh::Wait;
    let key = keys.vision_pose(&pose.object);
    let payload = serde_json::to_vec(pose).unwrap_or_default();
    if let Err(e) = session
        .put(&key, payload)
        .encoding(zenoh::bytes::Encoding::APPLICATION_JSON)
        .wait()
    {
        tracing::warn!("publishing {key}: {e}");
    }
}
