//! Bad input gets a clear error naming what was wrong, and the service keeps serving.

use std::path::PathBuf;

use base64::Engine;
use nalgebra::{Isometry3, Vector3};
use tsukami_body::files::ModelRoots;
use tsukami_msgs::vision::{DepthEncoding, DepthFrame, DetectRequest};
use tsukami_msgs::ErrorCode;
use tsukami_vision::camera::{Camera, Intrinsics};
use tsukami_vision::convert::{camera_to_msg, frame_to_msg};
use tsukami_vision::depth::{self, DepthImage};
use tsukami_vision::detect::{DetectParams, Detector};
use tsukami_vision::service::VisionService;

fn roots() -> ModelRoots {
    ModelRoots::new([PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models")])
}

fn camera() -> Camera {
    Camera {
        intrinsics: Intrinsics {
            width: 8,
            height: 6,
            fx: 5.0,
            fy: 5.0,
            cx: 3.5,
            cy: 2.5,
        },
        pose: Isometry3::new(Vector3::new(0.1, 0.0, 1.4), Vector3::new(2.0, 0.0, 0.0)),
    }
}

fn flat() -> DepthImage {
    DepthImage::new(8, 6, vec![0.9; 48]).unwrap()
}

fn request(frame: DepthFrame) -> DetectRequest {
    DetectRequest {
        object: "can_350ml".into(),
        image: Some(frame),
        set_object: false,
        min_confidence: None,
        seed: None,
    }
}

#[test]
fn malformed_png_is_refused_with_its_source_named() {
    let err = DepthImage::from_png16_mm(b"\x89PNG\r\n\x1a\nnot really", "frame.png").unwrap_err();
    let text = err.to_string();
    assert!(text.contains("frame.png") && text.contains("PNG"), "{text}");
    // Truncated data of a real PNG.
    let png = flat().to_png16_mm().unwrap();
    let err = DepthImage::from_png16_mm(&png[..png.len() - 20], "cut.png").unwrap_err();
    assert!(err.to_string().contains("cut.png"), "{err}");
}

#[test]
fn eight_bit_png_is_refused() {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, 2, 2);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header()
        .unwrap()
        .write_image_data(&[1, 2, 3, 4])
        .unwrap();
    let err = DepthImage::from_png16_mm(&out, "gray8.png")
        .unwrap_err()
        .to_string();
    assert!(err.contains("16-bit greyscale"), "{err}");
}

#[test]
fn wrong_sizes_are_refused() {
    let err = DepthImage::new(8, 6, vec![1.0; 47])
        .unwrap_err()
        .to_string();
    assert!(err.contains("image.data") && err.contains("48"), "{err}");
    let err = DepthImage::from_f32_le(&[0u8; 10], 2, 2)
        .unwrap_err()
        .to_string();
    assert!(err.contains("16"), "{err}");
    // An image that does not match the intrinsics.
    let mut det = Detector::new(roots(), DetectParams::default());
    let small = DepthImage::new(4, 3, vec![0.9; 12]).unwrap();
    let err = det
        .detect("can_350ml", &small, &camera())
        .unwrap_err()
        .to_string();
    assert!(err.contains("4 x 3") && err.contains("8 x 6"), "{err}");
    let png = small.to_png16_mm().unwrap();
    let err = DepthImage::decode(&png, depth::DepthEncoding::Png16Mm, 8, 6, "x.png")
        .unwrap_err()
        .to_string();
    assert!(err.contains("intrinsics"), "{err}");
}

#[test]
fn nan_intrinsics_and_poses_are_refused() {
    let mut det = Detector::new(roots(), DetectParams::default());
    let mut cam = camera();
    cam.intrinsics.fx = f64::NAN;
    let err = det
        .detect("can_350ml", &flat(), &cam)
        .unwrap_err()
        .to_string();
    assert!(err.contains("intrinsics.fx"), "{err}");
    let mut cam = camera();
    cam.intrinsics.width = 0;
    assert!(det
        .detect("can_350ml", &flat(), &cam)
        .unwrap_err()
        .to_string()
        .contains("intrinsics.width"));

    let mut service = VisionService::new(roots(), DetectParams::default(), None);
    let mut frame = frame_to_msg(&flat(), &camera(), depth::DepthEncoding::Png16Mm).unwrap();
    frame.camera.intrinsics.cy = f64::INFINITY;
    let err = service.handle(&request(frame)).unwrap_err();
    assert_eq!(err.error.code, ErrorCode::InvalidValue);
    assert!(
        err.error.message.contains("intrinsics.cy"),
        "{}",
        err.error.message
    );
    let mut frame = frame_to_msg(&flat(), &camera(), depth::DepthEncoding::Png16Mm).unwrap();
    frame.camera.camera_pose.position[1] = f64::NAN;
    let err = service.handle(&request(frame)).unwrap_err();
    assert!(
        err.error.message.contains("camera_pose.position"),
        "{}",
        err.error.message
    );
}

#[test]
fn service_names_bad_payloads_and_keeps_serving() {
    let mut service = VisionService::new(roots(), DetectParams::default(), None);
    let good = frame_to_msg(&flat(), &camera(), depth::DepthEncoding::F32LeM).unwrap();
    // Not base64.
    let mut frame = good.clone();
    frame.data = "%%% not base64 %%%".into();
    let err = service.handle(&request(frame)).unwrap_err();
    assert!(err.error.message.contains("image.data") && err.error.message.contains("base64"));
    // A malformed PNG inside valid base64.
    let frame = DepthFrame {
        encoding: DepthEncoding::Png16Mm,
        data: base64::engine::general_purpose::STANDARD.encode(b"garbage"),
        camera: camera_to_msg(&camera()),
    };
    let err = service.handle(&request(frame)).unwrap_err();
    assert_eq!(err.error.code, ErrorCode::InvalidValue);
    assert!(err.error.message.contains("PNG"), "{}", err.error.message);
    // Object names cannot leave the model roots.
    let mut req = request(good.clone());
    req.object = "../../etc/passwd".into();
    let err = service.handle(&req).unwrap_err();
    assert_eq!(err.error.code, ErrorCode::InvalidValue);
    let mut req = request(good.clone());
    req.object = "no_such_object".into();
    let err = service.handle(&req).unwrap_err();
    assert_eq!(err.error.code, ErrorCode::ModelError);
    let mut req = request(good.clone());
    req.min_confidence = Some(1.5);
    assert!(service
        .handle(&req)
        .unwrap_err()
        .error
        .message
        .contains("min_confidence"));
    // No image and no camera.
    let mut req = request(good.clone());
    req.image = None;
    assert_eq!(
        service.handle(&req).unwrap_err().error.code,
        ErrorCode::NotReady
    );
    // Still serving: a valid flat frame is answered (not found, with the reason).
    let err = service.handle(&request(good)).unwrap_err();
    assert_eq!(err.error.code, ErrorCode::Infeasible);
    assert_eq!(err.error.details.unwrap()["reason"], "not_found");
}

/// A camera of `width` × `height` pixels looking down from the head's height.
fn big_camera(width: u32, height: u32) -> Camera {
    Camera {
        intrinsics: Intrinsics {
            width,
            height,
            fx: 1050.0,
            fy: 1050.0,
            cx: (width as f64 - 1.0) / 2.0,
            cy: (height as f64 - 1.0) / 2.0,
        },
        ..camera()
    }
}

/// Every pixel at 1 mm: a small PNG (it compresses to a few KB) that is one
/// cluster of every point.
fn one_mm(camera: &Camera) -> DepthFrame {
    let k = &camera.intrinsics;
    let image = DepthImage::new(k.width, k.height, vec![0.001; k.pixels()]).unwrap();
    frame_to_msg(&image, camera, depth::DepthEncoding::Png16Mm).unwrap()
}

/// 2048 × 2048 is over the pixel limit: refused before it is decoded, naming
/// the limit.
#[test]
fn an_image_over_the_pixel_limit_is_refused_naming_it() {
    use tsukami_vision::camera::MAX_PIXELS;
    let mut service = VisionService::new(roots(), DetectParams::default(), None);
    let frame = one_mm(&big_camera(2048, 2048));
    eprintln!("2048 x 2048 at 1 mm: {} bytes of base64", frame.data.len());
    let err = service.handle(&request(frame)).unwrap_err();
    assert_eq!(err.error.code, ErrorCode::InvalidValue);
    let message = &err.error.message;
    assert!(
        message.contains("intrinsics") && message.contains(&MAX_PIXELS.to_string()),
        "{message}"
    );
}

/// The largest image accepted, every pixel at 1 mm (one cluster of all its
/// 327,680 points): answered, not found, with the work bounded — segments thinned
/// to `max_segment_points` and no more fits once `max_work` point evaluations are
/// spent (unbounded it took 33 s). The answer names the budget.
#[test]
fn one_cluster_of_every_point_is_bounded_work() {
    let mut service = VisionService::new(roots(), DetectParams::default(), None);
    let good = frame_to_msg(&flat(), &camera(), depth::DepthEncoding::F32LeM).unwrap();
    // The model's template is loaded (once) by a first, small frame.
    assert!(service.handle(&request(good.clone())).is_err());
    let frame = one_mm(&big_camera(1280, 1024));
    let started = std::time::Instant::now();
    let err = service.handle(&request(frame.clone())).unwrap_err();
    eprintln!(
        "1280 x 1024 at 1 mm: {} in {:.2} s",
        err.error.message,
        started.elapsed().as_secs_f64()
    );
    assert_eq!(err.error.code, ErrorCode::Infeasible, "{err}");
    assert!(
        err.error.message.contains("max_work"),
        "{}",
        err.error.message
    );
    // A budget the cloud alone overruns: nothing is fitted, and the answer says so.
    let tight = DetectParams {
        max_work: 1000,
        ..DetectParams::default()
    };
    let mut service = VisionService::new(roots(), tight, None);
    let err = service.handle(&request(frame)).unwrap_err();
    assert_eq!(err.error.code, ErrorCode::Infeasible, "{err}");
    assert!(
        err.error.message.contains("max_work") && err.error.message.contains("1000"),
        "{}",
        err.error.message
    );
    // Still serving.
    let err = service.handle(&request(good)).unwrap_err();
    assert_eq!(err.error.details.unwrap()["reason"], "not_found");
}
