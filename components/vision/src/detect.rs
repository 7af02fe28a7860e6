//! The detection pipeline: depth image + camera + object model → pose, or
//! "not found" with the reason.
//!
//! What: [`detect_with`] runs the pipeline for one template; [`Detector`]
//! caches templates loaded from the model roots and holds the settings.
//!
//! Why: this is what `<ns>/vision/detect` answers and what the benchmark
//! measures.
//!
//! How: back-project every `stride`-th pixel, remove the large horizontal
//! planes (RANSAC), cluster the rest on the pixel grid (and split each cluster
//! again with a smaller gap, since an occluder close in front of the target
//! joins it), add the unions of two clusters that together are no larger than
//! the object (an occluder in front can cut the target in two), keep pieces no
//! larger than the object; for each, try every principal-axis hypothesis and
//! every resting pose on the plane under it ([`crate::resting`]) with a short
//! coarse ICP, refine the best few with a full ICP, then gather the
//! full-resolution points around the fitted model and refine once more; the
//! candidate with the highest verified confidence wins, reported in its
//! symmetry class's canonical form.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::files::ModelRoots;

use crate::camera::Camera;
use crate::cloud::{Moments, PointCloud};
use crate::cluster;
use crate::depth::DepthImage;
use crate::error::{invalid, Result};
use crate::hypotheses::from_principal_axes;
use crate::icp::{refine, IcpFit, IcpParams};
use crate::plane::{find_planes, FoundPlane, PlaneParams};
use crate::resting::on_plane;
use crate::template::ObjectTemplate;
use crate::verify::{verify, Verdict, VerifyParams};

/// Settings of the pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectParams {
    /// Pixel stride of the segmentation cloud.
    pub stride: u32,
    /// Plane removal.
    pub plane: PlaneParams,
    /// Largest 3-D gap inside a cluster (m).
    pub cluster_gap: f64,
    /// Each cluster is split again with these fractions of `cluster_gap`,
    /// each split's pieces candidates of their own.
    pub split_gaps: Vec<f64>,
    /// Smallest cluster (points of the strided cloud).
    pub min_cluster_points: usize,
    /// Most clusters examined (largest first).
    pub max_clusters: usize,
    /// Coarse ICP per hypothesis.
    pub coarse: IcpParams,
    /// Points used by the coarse ICP.
    pub coarse_points: usize,
    /// Hypotheses per cluster refined fully.
    pub refine_top: usize,
    /// Full ICP.
    pub fine: IcpParams,
    /// Points used by the full ICP.
    pub fine_points: usize,
    /// Full-resolution points farther than this from the fitted model are not gathered (m).
    pub gather: f64,
    /// Verification.
    pub verify: VerifyParams,
    /// Fine fits examined (best coarse scores first).
    pub max_fine: usize,
    /// Stop examining fine fits once one reaches this confidence.
    pub early_accept: f64,
    /// Also start from the model's resting poses on the plane under a segment.
    pub resting_hypotheses: bool,
    /// ... only for a segment whose best principal-axis coarse score is below this.
    pub resting_below: f64,
    /// Also try the union of two clusters no larger than the object together.
    pub merge_pairs: bool,
    /// Report only poses resting on a found plane (within the two limits below).
    pub require_support: bool,
    /// Deepest a model may sink into the plane under it (m).
    pub max_penetration: f64,
    /// Highest a model may float above the plane under it (m).
    pub max_rest_gap: f64,
    /// A pose is reported only at this confidence or more.
    pub min_confidence: f64,
    /// Base-frame direction the x axis of a symmetric object's reported pose follows.
    pub preferred_x: Vector3<f64>,
}

impl Default for DetectParams {
    fn default() -> Self {
        DetectParams {
            stride: 2,
            plane: PlaneParams::default(),
            cluster_gap: 0.012,
            split_gaps: vec![0.6],
            min_cluster_points: 25,
            max_clusters: 6,
            coarse: IcpParams {
                iterations: 12,
                gate_start: 0.04,
                gate_end: 0.01,
                ..IcpParams::default()
            },
            coarse_points: 250,
            refine_top: 3,
            fine: IcpParams {
                iterations: 20,
                gate_start: 0.02,
                gate_end: 0.005,
                ..IcpParams::default()
            },
            fine_points: 1200,
            gather: 0.008,
            verify: VerifyParams::default(),
            max_fine: 4,
            early_accept: 0.9,
            resting_hypotheses: true,
            resting_below: 0.96,
            merge_pairs: true,
            require_support: true,
            max_penetration: 0.01,
            max_rest_gap: 0.02,
            min_confidence: 0.8,
            preferred_x: -Vector3::x(),
        }
    }
}

/// A detected object.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// Object name.
    pub object: String,
    /// Pose (object → base), the canonical member of its symmetry class.
    pub pose: Isometry3<f64>,
    /// RMS point-to-surface distance of the final fit (m).
    pub rms: f64,
    /// Confidence in [0, 1] (see [`crate::verify`]).
    pub confidence: f64,
    /// The verification's counts.
    pub verdict: Verdict,
    /// Measured points in the final fit.
    pub points: usize,
}

/// Why nothing was reported.
#[derive(Debug, Clone, PartialEq)]
pub struct NotFound {
    /// What the pipeline saw.
    pub reason: String,
    /// The best candidate, if any, below the confidence threshold.
    pub best: Option<Detection>,
}

/// The result of a detection.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The object, with a confident pose.
    Found(Detection),
    /// Not found.
    NotFound(NotFound),
}

/// A detector with a template cache.
#[derive(Debug)]
pub struct Detector {
    roots: ModelRoots,
    templates: HashMap<String, Arc<ObjectTemplate>>,
    /// Pipeline settings.
    pub params: DetectParams,
}

impl Detector {
    /// A detector loading object models from `roots` (`objects/<name>/object.toml`).
    pub fn new(roots: ModelRoots, params: DetectParams) -> Self {
        Detector {
            roots,
            templates: HashMap::new(),
            params,
        }
    }

    /// The template of `object`, loaded once.
    pub fn template(&mut self, object: &str) -> Result<Arc<ObjectTemplate>> {
        if let Some(t) = self.templates.get(object) {
            return Ok(t.clone());
        }
        let t = Arc::new(ObjectTemplate::load(&self.roots, object)?);
        self.templates.insert(object.to_owned(), t.clone());
        Ok(t)
    }

    /// Looks for `object` in `image` taken by `camera`.
    pub fn detect(&mut self, object: &str, image: &DepthImage, camera: &Camera) -> Result<Outcome> {
        check_input(image, camera)?;
        let template = self.template(object)?;
        detect_with(&template, image, camera, &self.params)
    }
}

/// Checks that the camera is valid and the image matches its intrinsics.
pub fn check_input(image: &DepthImage, camera: &Camera) -> Result<()> {
    camera.validate()?;
    let k = &camera.intrinsics;
    if (image.width(), image.height()) != (k.width, k.height) {
        return Err(invalid(
            "image",
            format!(
                "the image is {} x {} but the intrinsics say {} x {}",
                image.width(),
                image.height(),
                k.width,
                k.height
            ),
        ));
    }
    Ok(())
}

struct Candidate {
    fit: IcpFit,
    verdict: Verdict,
}

/// Runs the pipeline for one template.
pub fn detect_with(
    template: &ObjectTemplate,
    image: &DepthImage,
    camera: &Camera,
    params: &DetectParams,
) -> Result<Outcome> {
    check_input(image, camera)?;
    let started = Instant::now();
    let not_found =
        |reason: String, best: Option<Detection>| Ok(Outcome::NotFound(NotFound { reason, best }));
    let cloud = PointCloud::from_depth(image, camera, params.stride);
    if cloud.len() < params.min_cluster_points {
        return not_found("the image has (almost) no depth measurements".into(), None);
    }
    let planes = find_planes(&cloud.points, &params.plane);
    let size_limit = template.radius * 1.25 + 0.01;
    let (mut clusters, mut pieces) = segment(&cloud, &planes, image.width(), params);
    if params.merge_pairs {
        add_unions(&mut clusters, &mut pieces, size_limit);
    }
    let segments = candidate_sets(&pieces, size_limit);
    let t_segment = started.elapsed();
    let coarse = coarse_fits(template, &segments, &planes, &camera.centre(), params);
    let t_coarse = started.elapsed();
    let best = best_fine(
        template, &segments, &clusters, &coarse, image, camera, &planes, params,
    );
    tracing::debug!(
        object = %template.name,
        points = cloud.len(),
        planes = planes.len(),
        clusters = clusters.len(),
        candidates = segments.len(),
        hypotheses = coarse.len(),
        segment_ms = t_segment.as_secs_f64() * 1e3,
        coarse_ms = (t_coarse - t_segment).as_secs_f64() * 1e3,
        fine_ms = (started.elapsed() - t_coarse).as_secs_f64() * 1e3,
        "detect"
    );
    let Some(best) = best else {
        return not_found(
            format!(
                "no object-sized cluster above the supporting plane ({} clusters, {} planes)",
                clusters.len(),
                planes.len()
            ),
            None,
        );
    };
    let detection = Detection {
        object: template.name.clone(),
        pose: template
            .symmetry
            .canonical(&best.fit.pose, &params.preferred_x),
        rms: best.fit.rms,
        confidence: best.verdict.confidence,
        verdict: best.verdict,
        points: best.fit.paired,
    };
    if detection.confidence >= params.min_confidence {
        return Ok(Outcome::Found(detection));
    }
    let reason = explain(&best.verdict, params.min_confidence);
    not_found(reason, Some(detection))
}

/// Why a candidate's confidence is too low, in words.
fn explain(v: &Verdict, min_confidence: f64) -> String {
    format!(
        "best candidate's confidence {:.2} is below {:.2}: the model explains {:.0} % of its cluster's points; \
         of the model's {} measured pixels {} agree, {} see through it, {} are hidden; resting on a plane: {}",
        v.confidence,
        min_confidence,
        v.explained * 100.0,
        v.supported + v.violations + v.near_misses + v.occluded,
        v.supported,
        v.violations,
        v.occluded,
        if v.resting { "yes" } else { "no" },
    )
}

/// Every principal-axis hypothesis on every cluster, after a short coarse
/// ICP: the best `refine_top` of each cluster, best first, as (score,
/// cluster index, fit).
fn coarse_fits(
    template: &ObjectTemplate,
    segments: &[&Segment],
    planes: &[FoundPlane],
    cam: &Point3<f64>,
    params: &DetectParams,
) -> Vec<(f64, usize, IcpFit)> {
    let mut coarse: Vec<(f64, usize, IcpFit)> = Vec::new();
    for (si, seg) in segments.iter().enumerate() {
        let Some(m) = Moments::of(&seg.points) else {
            continue;
        };
        let pts = thin(&seg.points, params.coarse_points);
        let fit = |h: Isometry3<f64>| {
            let f = refine(template, &pts, Some(*cam), h, &params.coarse);
            (score(&f), si, f)
        };
        let mut fits: Vec<(f64, usize, IcpFit)> = from_principal_axes(template, &m, cam)
            .into_iter()
            .map(fit)
            .collect();
        let best = fits.iter().map(|f| f.0).fold(f64::NEG_INFINITY, f64::max);
        if params.resting_hypotheses && best < params.resting_below {
            if let Some(plane) = plane_below(planes, &m.centroid) {
                fits.extend(
                    on_plane(template, &seg.points, &plane.plane, cam)
                        .into_iter()
                        .map(fit),
                );
            }
        }
        fits.sort_by(|a, b| b.0.total_cmp(&a.0));
        coarse.extend(fits.into_iter().take(params.refine_top));
    }
    coarse.sort_by(|a, b| b.0.total_cmp(&a.0));
    coarse
}

/// The verified fine fit of highest confidence among the best `max_fine`
/// coarse fits (stopping early at `early_accept`).
#[allow(clippy::too_many_arguments)]
fn best_fine(
    template: &ObjectTemplate,
    segments: &[&Segment],
    clusters: &[Vec<Point3<f64>>],
    coarse: &[(f64, usize, IcpFit)],
    image: &DepthImage,
    camera: &Camera,
    planes: &[FoundPlane],
    params: &DetectParams,
) -> Option<Candidate> {
    let mut best: Option<Candidate> = None;
    for (_, si, c) in coarse.iter().take(params.max_fine) {
        let cand = fine_fit(
            template,
            &segments[*si].points,
            &clusters[segments[*si].parent],
            c.pose,
            image,
            camera,
            planes,
            params,
        );
        if best
            .as_ref()
            .is_none_or(|b| cand.verdict.confidence > b.verdict.confidence)
        {
            best = Some(cand);
        }
        if best
            .as_ref()
            .is_some_and(|b| b.verdict.confidence >= params.early_accept)
        {
            break;
        }
    }
    best
}

/// The nearest plane below `p`, if any.
fn plane_below<'a>(planes: &'a [FoundPlane], p: &Point3<f64>) -> Option<&'a FoundPlane> {
    planes
        .iter()
        .filter(|pl| pl.plane.distance(p) > 0.0)
        .min_by(|a, b| a.plane.distance(p).total_cmp(&b.plane.distance(p)))
}

/// A cluster, or a piece of one, and the index of its whole cluster.
struct Segment {
    points: Vec<Point3<f64>>,
    parent: usize,
}

/// The off-plane points of the strided cloud, clustered (largest first), and
/// each cluster's pieces when a smaller gap splits it.
fn segment(
    cloud: &PointCloud,
    planes: &[FoundPlane],
    width: u32,
    params: &DetectParams,
) -> (Vec<Vec<Point3<f64>>>, Vec<Segment>) {
    let s = params.stride.max(1);
    let gw = width.div_ceil(s) as usize;
    let gh = cloud
        .pixels
        .iter()
        .map(|p| p / width / s)
        .max()
        .map_or(0, |v| v as usize + 1);
    let mut in_plane = vec![false; cloud.len()];
    for p in planes {
        for &i in &p.inliers {
            in_plane[i] = true;
        }
    }
    let mut grid = vec![None; gw * gh];
    for (i, (p, px)) in cloud.points.iter().zip(&cloud.pixels).enumerate() {
        if !in_plane[i] {
            let (u, v) = (px % width / s, px / width / s);
            grid[v as usize * gw + u as usize] = Some(*p);
        }
    }
    let (mut parents, mut out) = (Vec::new(), Vec::new());
    for (pi, parent) in cluster::clusters(&grid, gw, params.cluster_gap, params.min_cluster_points)
        .into_iter()
        .take(params.max_clusters)
        .enumerate()
    {
        // Split again with smaller gaps: an occluder standing close in front
        // of the target joins it at first.
        let mut sub = vec![None; grid.len()];
        for &i in &parent {
            sub[i] = grid[i];
        }
        let points =
            |c: &[usize]| -> Vec<Point3<f64>> { c.iter().filter_map(|&i| grid[i]).collect() };
        parents.push(points(&parent));
        out.push(Segment {
            points: points(&parent),
            parent: pi,
        });
        for factor in &params.split_gaps {
            let children = cluster::clusters(
                &sub,
                gw,
                params.cluster_gap * factor,
                params.min_cluster_points,
            );
            if children.len() > 1 {
                out.extend(children.iter().map(|c| Segment {
                    points: points(c),
                    parent: pi,
                }));
            }
        }
    }
    (parents, out)
}

/// Adds, as a cluster and a segment of its own, the union of every two
/// clusters that together are no larger than the object: an occluder standing
/// in front of the target can cut what is seen of it in two.
fn add_unions(clusters: &mut Vec<Vec<Point3<f64>>>, pieces: &mut Vec<Segment>, size_limit: f64) {
    let n = clusters.len();
    let centroids: Vec<Option<Point3<f64>>> = clusters
        .iter()
        .map(|c| Moments::of(c).map(|m| m.centroid))
        .collect();
    for a in 0..n {
        for b in a + 1..n {
            let (Some(ca), Some(cb)) = (centroids[a], centroids[b]) else {
                continue;
            };
            if (ca - cb).norm() > 2.0 * size_limit {
                continue;
            }
            let union: Vec<Point3<f64>> = clusters[a].iter().chain(&clusters[b]).copied().collect();
            if extent(&union) <= size_limit {
                pieces.push(Segment {
                    points: union.clone(),
                    parent: clusters.len(),
                });
                clusters.push(union);
            }
        }
    }
}

/// Largest distance of a point from the centroid (infinite for < 3 points).
fn extent(points: &[Point3<f64>]) -> f64 {
    match Moments::of(points) {
        Some(m) => points
            .iter()
            .map(|p| (p - m.centroid).norm())
            .fold(0.0, f64::max),
        None => f64::INFINITY,
    }
}

/// The object-sized segments.
fn candidate_sets(segments: &[Segment], size_limit: f64) -> Vec<&Segment> {
    segments
        .iter()
        .filter(|s| extent(&s.points) <= size_limit)
        .collect()
}

/// Full ICP from a coarse pose on `seg`, again on the gathered
/// full-resolution points, then verification against the `whole` cluster
/// `seg` is a piece of.
#[allow(clippy::too_many_arguments)]
fn fine_fit(
    template: &ObjectTemplate,
    seg: &[Point3<f64>],
    whole: &[Point3<f64>],
    start: Isometry3<f64>,
    image: &DepthImage,
    camera: &Camera,
    planes: &[FoundPlane],
    params: &DetectParams,
) -> Candidate {
    let cam = camera.centre();
    let fine_pts = thin(seg, params.fine_points);
    let fit = refine(template, &fine_pts, Some(cam), start, &params.fine);
    let gathered = gather(template, &fit.pose, image, camera, planes, params);
    let fit = if gathered.len() >= fine_pts.len() / 2 {
        let pts = thin(&gathered, params.fine_points);
        let mut last = params.fine.clone();
        last.gate_start = params.gather;
        last.iterations = 10;
        refine(template, &pts, Some(cam), fit.pose, &last)
    } else {
        fit
    };
    let mut verdict = verify(template, &fit.pose, whole, image, camera, &params.verify);
    let gap = rest_gap(template, &fit.pose, planes);
    verdict.resting = gap.is_some_and(|g| g >= -params.max_penetration && g <= params.max_rest_gap);
    if params.require_support && !verdict.resting {
        verdict.confidence = 0.0;
    }
    Candidate { fit, verdict }
}

/// The gap between the model at `pose` and the nearest plane below its
/// centroid: the least height of a model vertex above that plane (negative
/// when the model sinks into it); `None` when no plane lies below.
fn rest_gap(
    template: &ObjectTemplate,
    pose: &Isometry3<f64>,
    planes: &[FoundPlane],
) -> Option<f64> {
    let plane = plane_below(planes, &(pose * template.moments.centroid))?;
    Some(
        template
            .model
            .mesh
            .vertices
            .iter()
            .map(|v| plane.plane.distance(&(pose * v)))
            .fold(f64::INFINITY, f64::min),
    )
}

/// Ranking of coarse fits: paired fraction, then small residual.
fn score(f: &IcpFit) -> f64 {
    f.fraction() - f.rms.min(1.0) * 20.0
}

/// At most `n` points, evenly strided.
fn thin(points: &[Point3<f64>], n: usize) -> Vec<Point3<f64>> {
    let step = points.len().div_ceil(n.max(1)).max(1);
    points.iter().step_by(step).copied().collect()
}

/// Full-resolution points within `gather` of the model at `pose`, off the planes.
fn gather(
    template: &ObjectTemplate,
    pose: &Isometry3<f64>,
    image: &DepthImage,
    camera: &Camera,
    planes: &[FoundPlane],
    params: &DetectParams,
) -> Vec<Point3<f64>> {
    let k = &camera.intrinsics;
    let c = camera.pose.inverse() * (pose * template.moments.centroid);
    let Some((u, v)) = k.project(&c) else {
        return Vec::new();
    };
    let r = (k.fx.max(k.fy) * template.radius / c.z.max(0.05)).ceil() + 2.0;
    let clamp = |x: f64, hi: u32| x.clamp(0.0, hi as f64) as u32;
    let region = [
        clamp(u - r, k.width),
        clamp(v - r, k.height),
        clamp(u + r + 1.0, k.width),
        clamp(v + r + 1.0, k.height),
    ];
    let inv = pose.inverse();
    let gate2 = params.gather * params.gather;
    let centre = pose * template.moments.centroid;
    let reach2 = (template.radius + params.gather).powi(2);
    PointCloud::from_region(image, camera, region)
        .points
        .into_iter()
        .filter(|p| {
            (p - centre).norm_squared() <= reach2
                && planes
                    .iter()
                    .all(|pl| pl.plane.distance(p).abs() > params.plane.threshold)
                && template.nearest(&(inv * p)).1 <= gate2
        })
        .collect()
}
