//! Between bus messages ([`tsukami_msgs::vision`]) and the library's types.
//!
//! What: cameras, depth frames (base64 payloads), poses and detections in
//! both directions, each checked, with errors naming the field; the views of
//! a look out to the reply.
//!
//! Why: the bus speaks JSON with quaternions `[x, y, z, w]` and base64
//! images; the pipeline speaks nalgebra and [`DepthImage`].

use base64::Engine;
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use tsukami_body::model::RobotModel;
use tsukami_msgs::common::Pose;
use tsukami_msgs::vision::{
    CameraInfo, CameraIntrinsics, DepthEncoding as MsgEncoding, DepthFrame, LookView, ObjectPose,
    Symmetry as MsgSymmetry, SymmetryAxis,
};

use crate::camera::{Camera, Intrinsics};
use crate::depth::{DepthEncoding, DepthImage};
use crate::detect::{Detection, Outcome};
use crate::error::{invalid, Result};
use crate::look::Attempt;
use crate::symmetry::Symmetry;

/// Largest base64 payload accepted for an image (bytes of text).
pub const MAX_IMAGE_TEXT: usize = 96 << 20;

/// A message pose as an isometry; the error names `field`.
pub fn pose_from_msg(pose: &Pose, field: &str) -> Result<Isometry3<f64>> {
    pose.validate().map_err(|which| {
        invalid(
            format!("{field}.{which}"),
            "must be finite (and the quaternion of usable norm)",
        )
    })?;
    let [x, y, z, w] = pose.quaternion;
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    let [px, py, pz] = pose.position;
    Ok(Isometry3::from_parts(Translation3::new(px, py, pz), q))
}

/// An isometry as a message pose.
pub fn pose_to_msg(iso: &Isometry3<f64>) -> Pose {
    let q = iso.rotation.quaternion();
    let t = iso.translation.vector;
    Pose {
        position: [t.x, t.y, t.z],
        quaternion: [q.i, q.j, q.k, q.w],
    }
}

/// A camera from its message, validated.
pub fn camera_from_msg(info: &CameraInfo) -> Result<Camera> {
    let k = &info.intrinsics;
    let camera = Camera {
        intrinsics: Intrinsics {
            width: k.width,
            height: k.height,
            fx: k.fx,
            fy: k.fy,
            cx: k.cx,
            cy: k.cy,
        },
        pose: pose_from_msg(&info.camera_pose, "camera.camera_pose")?,
    };
    camera.validate()?;
    Ok(camera)
}

/// A camera as a message.
pub fn camera_to_msg(camera: &Camera) -> CameraInfo {
    let k = &camera.intrinsics;
    CameraInfo {
        intrinsics: CameraIntrinsics {
            width: k.width,
            height: k.height,
            fx: k.fx,
            fy: k.fy,
            cx: k.cx,
            cy: k.cy,
        },
        camera_pose: pose_to_msg(&camera.pose),
    }
}

/// Decodes a frame: the camera, then the base64 image, checked against the intrinsics.
pub fn frame_from_msg(frame: &DepthFrame) -> Result<(DepthImage, Camera)> {
    let camera = camera_from_msg(&frame.camera)?;
    if frame.data.len() > MAX_IMAGE_TEXT {
        return Err(invalid(
            "image.data",
            format!(
                "{} bytes of base64 is over the limit of {MAX_IMAGE_TEXT}",
                frame.data.len()
            ),
        ));
    }
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(frame.data.as_bytes())
        .map_err(|e| invalid("image.data", format!("not base64: {e}")))?;
    let encoding = match frame.encoding {
        MsgEncoding::Png16Mm => DepthEncoding::Png16Mm,
        MsgEncoding::F32LeM => DepthEncoding::F32LeM,
    };
    let k = &camera.intrinsics;
    let image = DepthImage::decode(&bytes, encoding, k.width, k.height, "image.data")?;
    Ok((image, camera))
}

/// Encodes a frame (PNG in millimetres or float32 metres).
pub fn frame_to_msg(
    image: &DepthImage,
    camera: &Camera,
    encoding: DepthEncoding,
) -> Result<DepthFrame> {
    let (bytes, enc) = match encoding {
        DepthEncoding::Png16Mm => (image.to_png16_mm()?, MsgEncoding::Png16Mm),
        DepthEncoding::F32LeM => (image.to_f32_le(), MsgEncoding::F32LeM),
    };
    Ok(DepthFrame {
        encoding: enc,
        data: base64::engine::general_purpose::STANDARD.encode(bytes),
        camera: camera_to_msg(camera),
    })
}

/// A symmetry as a message (`None` for an asymmetric object).
pub fn symmetry_to_msg(sym: &Symmetry) -> Option<MsgSymmetry> {
    if sym.is_none() {
        return None;
    }
    let discrete: Vec<Pose> = sym.discrete.iter().skip(1).map(pose_to_msg).collect();
    let mut note = String::new();
    if let Some((p, d)) = &sym.axis {
        note.push_str(&format!(
            "any rotation about the axis through ({:.4}, {:.4}, {:.4}) along ({:.3}, {:.3}, {:.3}) (object frame) \
             leaves the object unchanged; the reported pose's x axis points as far along the base's -x as the axis allows",
            p.x, p.y, p.z, d.x, d.y, d.z
        ));
    }
    if !discrete.is_empty() {
        if !note.is_empty() {
            note.push_str("; ");
        }
        note.push_str(&format!(
            "{} further discrete motion(s) leave it unchanged; the reported one has its z axis most upward",
            discrete.len()
        ));
    }
    Some(MsgSymmetry {
        axis: sym.axis.map(|(p, d)| SymmetryAxis {
            point: [p.x, p.y, p.z],
            direction: [d.x, d.y, d.z],
        }),
        discrete,
        note,
    })
}

/// A detection as the reply message.
pub fn detection_to_msg(d: &Detection, sym: &Symmetry) -> ObjectPose {
    ObjectPose {
        object: d.object.clone(),
        pose: pose_to_msg(&d.pose),
        fit_error: d.rms,
        confidence: d.confidence,
        points: d.points as u64,
        occluded: d.verdict.occluded_fraction(),
        symmetry: symmetry_to_msg(sym),
        sent_to: None,
    }
}

/// A view a look took, with what it saw, as the reply message: the joints
/// of the posture away from `rest`, by name.
pub fn attempt_to_msg(a: &Attempt, robot: &RobotModel, rest: &[f64]) -> LookView {
    let joints = robot
        .joints
        .iter()
        .enumerate()
        .filter(|(j, joint)| joint.is_movable() && (a.view.q[*j] - rest[*j]).abs() > 1e-9)
        .map(|(j, joint)| (joint.name.clone(), a.view.q[j]))
        .collect();
    let (found, confidence, occluded, reason) = match &a.outcome {
        Outcome::Found(d) => (
            true,
            Some(d.confidence),
            Some(d.verdict.occluded_fraction()),
            None,
        ),
        Outcome::NotFound(n) => (
            false,
            n.best.as_ref().map(|b| b.confidence),
            None,
            Some(n.reason.clone()),
        ),
    };
    LookView {
        name: a.view.name.to_owned(),
        joints,
        camera_pose: pose_to_msg(&a.view.camera.pose),
        self_hidden: a.view.hidden.fraction(),
        found,
        confidence,
        occluded,
        reason,
    }
}
