//! The vision component on the bus: `<ns>/vision/detect` and
//! `<ns>/vision/pose/<object>`.
//!
//! What: [`VisionService::handle`] answers one [`DetectRequest`] (no bus
//! involved, so it is tested directly); [`serve`] puts it on the bus through
//! a [`tsukami_bus::Component`].
//!
//! Why: detection takes tens of milliseconds; zenoh's callback must stay
//! quick, so queries are queued (bounded) to one worker thread, which replies,
//! publishes the pose and, on request, sends it on as the object's pose.
//!
//! How: a request's image is decoded and checked ([`crate::convert`]);
//! without one the [`SceneCamera`] renders a frame. Not found is an
//! `infeasible` error with `details.reason = "not_found"` and the pipeline's
//! explanation; bad input is `invalid_value`/`model_error` naming the field.

use std::sync::mpsc::{sync_channel, TrySendError};
use std::time::Duration;

use serde_json::json;
use tsukami_body::files::ModelRoots;
use tsukami_bus::serve::{check_size, parse_query, reply_error, reply_json};
use tsukami_bus::{BusClient, Component};
use tsukami_msgs::keys::planner::SET_OBJECT;
use tsukami_msgs::planner::{ObjectShape, SetObject};
use tsukami_msgs::vision::{DetectRequest, ObjectPose};
use tsukami_msgs::{ErrorCode, ErrorReply, KeySpace};

use crate::convert::{detection_to_msg, frame_from_msg};
use crate::detect::{detect_with, DetectParams, Detector, Outcome};
use crate::error::VisionError;
use crate::sim::scene_camera::SceneCamera;
use crate::template::is_plain_name;

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

impl VisionService {
    /// A service loading object models from `roots`, with an optional simulated camera.
    pub fn new(roots: ModelRoots, params: DetectParams, camera: Option<SceneCamera>) -> Self {
        VisionService {
            detector: Detector::new(roots, params),
            camera,
            frames: 0,
        }
    }

    /// Answers one request.
    pub fn handle(&mut self, req: &DetectRequest) -> Result<Handled, ErrorReply> {
        if !is_plain_name(&req.object) {
            return Err(ErrorReply::new(
                ErrorCode::InvalidValue,
                "object: an object name is a folder name under objects/ (letters, digits, '_', '-')",
            ));
        }
        let mut params = self.detector.params.clone();
        if let Some(c) = req.min_confidence {
            if !(0.0..=1.0).contains(&c) {
                return Err(ErrorReply::new(
                    ErrorCode::InvalidValue,
                    format!("min_confidence: {c} must be within [0, 1]"),
                ));
            }
            params.min_confidence = c;
        }
        let (image, camera) = match &req.image {
            Some(frame) => frame_from_msg(frame).map_err(|e| error_reply(&e))?,
            None => {
                let cam = self.camera.as_ref().ok_or_else(|| {
                    ErrorReply::new(
                        ErrorCode::NotReady,
                        "no image in the request and no camera: start the component with --scene",
                    )
                })?;
                let seed = req.seed.unwrap_or(self.frames);
                self.frames += 1;
                cam.frame(&req.object, seed).map_err(|e| error_reply(&e))?
            }
        };
        let template = self
            .detector
            .template(&req.object)
            .map_err(|e| error_reply(&e))?;
        let outcome =
            detect_with(&template, &image, &camera, &params).map_err(|e| error_reply(&e))?;
        match outcome {
            Outcome::Found(d) => {
                let pose = detection_to_msg(&d, &template.symmetry);
                let set_object = req.set_object.then(|| SetObject {
                    name: Some(req.object.clone()),
                    shape: ObjectShape::Model {
                        name: req.object.clone(),
                    },
                    mass: template.model.mass,
                    friction: Some(template.model.friction),
                    pose: pose.pose,
                    center_of_mass: None,
                });
                Ok(Handled { pose, set_object })
            }
            Outcome::NotFound(n) => Err(ErrorReply::new(
                ErrorCode::Infeasible,
                format!("'{}' not found: {}", req.object, n.reason),
            )
            .with_details(json!({
                "reason": "not_found",
                "best_confidence": n.best.as_ref().map(|b| b.confidence),
            }))),
        }
    }
}

/// Where found poses are sent on (`set_object` in the request): the world's
/// `set_object`.
pub fn set_object_key(keys: &KeySpace) -> String {
    keys.world(SET_OBJECT)
}

/// Serves `service` on `component`'s bus until the component closes.
/// Returns the queryable (keep it alive) and the worker's handle.
pub fn serve(
    component: &Component,
    mut service: VisionService,
    set_object_timeout: Duration,
) -> anyhow::Result<(zenoh::query::Queryable<()>, std::thread::JoinHandle<()>)> {
    let keys = component.keys().clone();
    let (tx, rx) = sync_channel::<zenoh::query::Query>(QUEUE);
    let queryable = component.serve_query(&keys.vision_detect(), move |query| {
        // An oversized request is refused here, before it takes a queue slot.
        if let Err(error) = check_size(&query) {
            return reply_error(&query, error);
        }
        if let Err(TrySendError::Full(q)) = tx.try_send(query) {
            reply_error(
                &q,
                ErrorReply::new(
                    ErrorCode::Busy,
                    format!("busy: {QUEUE} detections are queued, the most that wait; retry later"),
                ),
            );
        }
    })?;
    let client = BusClient::on_session(component.session().clone(), keys.namespace());
    let session = component.session().clone();
    let worker = std::thread::Builder::new()
        .name("vision-detect".into())
        .spawn(move || {
            while let Ok(query) = rx.recv() {
                let req: DetectRequest = match parse_query(&query) {
                    Ok(r) => r,
                    Err(e) => {
                        reply_error(&query, e);
                        continue;
                    }
                };
                match service.handle(&req) {
                    Ok(mut handled) => {
                        if let Some(set) = handled.set_object.take() {
                            let key = set_object_key(client.keys());
                            let payload = serde_json::to_vec(&set).unwrap_or_default();
                            match client.request_key(&key, &payload, set_object_timeout) {
                                Ok(_) => handled.pose.sent_to = Some(key),
                                Err(e) => {
                                    let code = e.code().unwrap_or(ErrorCode::Timeout);
                                    reply_error(
                                        &query,
                                        ErrorReply::new(
                                            code,
                                            format!("'{}' found, but sending it on to {key} failed: {e}", req.object),
                                        ),
                                    );
                                    continue;
                                }
                            }
                        }
                        publish(&session, &keys, &handled.pose);
                        tracing::info!(
                            object = %req.object,
                            confidence = handled.pose.confidence,
                            fit_error = handled.pose.fit_error,
                            "found"
                        );
                        reply_json(&query, &handled.pose);
                    }
                    Err(e) => {
                        tracing::info!(object = %req.object, error = %e.error.message, "detect failed");
                        reply_error(&query, e);
                    }
                }
            }
        })?;
    Ok((queryable, worker))
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
