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
//! planes (RANSAC; each a connected surface wider than the model), cut the
//! rest into object-sized segments ([`crate::segment`]: clusters, their
//! pieces at a smaller gap, unions of two; no wider than the model; a cluster
//! with no object-sized piece is skipped before the clusters are counted). For each segment, start ICP from every
//! principal-axis hypothesis ([`crate::hypotheses`]) and every resting pose
//! of the model on the plane under it ([`crate::resting`]) with a short
//! coarse ICP (nearest samples by the template's lookup grid), and rank each
//! fit by a quick verification against the image: the fraction of the
//! segment it explains times the agreement of its visible surface with the
//! measured depths (free space seen through counts against it), halved when
//! it does not rest on the plane. The best few fits of every segment, best
//! ranked first, get a full ICP, a last ICP with exact pairing on the
//! full-resolution points gathered around the model, and a refinement by
//! visible-surface agreement ([`crate::freespace`]) for the directions the
//! points leave free; then the full verification. The candidate with the
//! highest confidence wins, reported in its symmetry class's canonical form.
//! The work is bounded whatever the image holds: segments and clusters are
//! thinned to [`DetectParams::max_segment_points`], no more coarse fits start
//! once [`DetectParams::max_work`] point evaluations less the fine fits' share
//! are spent, and no more fine fits once all are (counted, not timed, so the
//! answer does not depend on the machine). "Not found" says what was seen:
//! when nothing is object-sized, the cluster nearest the object's size and
//! its width against the object's; otherwise the best candidate, where it is,
//! how wide its cluster, and why its confidence is too low.

use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;

use nalgebra::{Isometry3, Point3, Vector3};
use tsukami_body::files::ModelRoots;

use crate::camera::Camera;
use crate::cloud::{Moments, PointCloud};
use crate::depth::DepthImage;
use crate::error::{invalid, Result};
use crate::freespace::{settle, SettleParams};
use crate::hypotheses::from_principal_axes;
use crate::icp::{refine, IcpFit, IcpParams};
use crate::plane::{find_planes, FoundPlane, PlaneParams};
use crate::resting::on_plane;
use crate::segment::{segments, Grid, Segment, SegmentParams};
use crate::template::ObjectTemplate;
use crate::verify::{verify, Verdict, VerifyParams};

/// Default [`DetectParams::max_segment_points`]: an object filling a 1280 × 1024
/// image at stride 2 is about 60 000 points; the fits use at most 1200 of them.
pub const MAX_SEGMENT_POINTS: usize = 20_000;
/// Default [`DetectParams::max_work`], in point evaluations: ten times the most a
/// detection in the tests' and benchmarks' 640 × 480 frames spends (measured:
/// about 300,000).
pub const MAX_WORK: u64 = 3_000_000;

/// Default [`SegmentParams::max_clusters`]: object-sized clusters kept (the
/// oversize ones do not count). Each costs at most about 160,000 point
/// evaluations of coarse fits (48 starts × 250 points × 13 pairings), so the
/// coarse share of [`MAX_WORK`] covers about 17 of them: the budget, not this
/// count, bounds a cluttered frame, and the largest are fitted first.
pub const MAX_CLUSTERS: usize = 24;

/// Settings of the pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct DetectParams {
    /// Pixel stride of the segmentation cloud.
    pub stride: u32,
    /// Plane removal.
    pub plane: PlaneParams,
    /// Clustering and object-sized segments.
    pub segment: SegmentParams,
    /// Coarse ICP per hypothesis.
    pub coarse: IcpParams,
    /// Points used by the coarse ICP.
    pub coarse_points: usize,
    /// Quick verification ranking the coarse fits.
    pub rank: VerifyParams,
    /// Coarse fits per segment kept for the full ICP.
    pub refine_top: usize,
    /// Full ICP.
    pub fine: IcpParams,
    /// Points used by the full ICP.
    pub fine_points: usize,
    /// Iterations of the last ICP, on the gathered full-resolution points
    /// with exact pairing.
    pub exact_iterations: usize,
    /// Full-resolution points farther than this from the fitted model are not gathered (m).
    pub gather: f64,
    /// Refinement by visible-surface agreement after the last ICP (none: off).
    pub settle: Option<SettleParams>,
    /// Verification.
    pub verify: VerifyParams,
    /// Fine fits examined (best ranked coarse fits first).
    pub max_fine: usize,
    /// Stop examining fine fits once one reaches this confidence.
    pub early_accept: f64,
    /// Also start from the model's resting poses on the plane under a segment.
    pub resting_hypotheses: bool,
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
    /// Most points of one segment (and of the cluster it is verified against):
    /// a larger one is thinned evenly to this many (deterministic).
    pub max_segment_points: usize,
    /// The work budget of one detection, in point evaluations (a point of the
    /// cloud, a point paired once by an ICP iteration or checked once by a
    /// verification, a pixel looked at while gathering): no more fits are
    /// started once it is spent.
    pub max_work: u64,
}

impl Default for DetectParams {
    fn default() -> Self {
        DetectParams {
            stride: 2,
            plane: PlaneParams::default(),
            segment: SegmentParams {
                cluster_gap: 0.012,
                split_gaps: vec![0.6],
                min_points: 25,
                max_clusters: MAX_CLUSTERS,
                merge_pairs: true,
                margin: 0.01,
            },
            coarse: IcpParams {
                iterations: 12,
                gate_start: 0.04,
                gate_end: 0.01,
                fast_pairing: true,
                ..IcpParams::default()
            },
            coarse_points: 250,
            rank: VerifyParams {
                sample_step: 8,
                fast_pairing: true,
                ..VerifyParams::default()
            },
            refine_top: 3,
            fine: IcpParams {
                iterations: 20,
                gate_start: 0.02,
                gate_end: 0.005,
                fast_pairing: true,
                ..IcpParams::default()
            },
            fine_points: 1200,
            exact_iterations: 6,
            gather: 0.008,
            settle: Some(SettleParams::default()),
            verify: VerifyParams::default(),
            max_fine: 4,
            early_accept: 0.9,
            resting_hypotheses: true,
            require_support: true,
            max_penetration: 0.01,
            max_rest_gap: 0.02,
            min_confidence: 0.8,
            preferred_x: -Vector3::x(),
            max_segment_points: MAX_SEGMENT_POINTS,
            max_work: MAX_WORK,
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
    /// The index of the cluster it was verified against.
    cluster: usize,
}

/// What every stage looks at: the model, the image, its planes, the settings.
struct View<'a> {
    template: &'a ObjectTemplate,
    image: &'a DepthImage,
    camera: &'a Camera,
    planes: &'a [FoundPlane],
    params: &'a DetectParams,
    /// Point evaluations spent so far (see [`DetectParams::max_work`]).
    work: std::cell::Cell<u64>,
    /// The coarse fits stopped for the budget before every segment's were made.
    coarse_cut: std::cell::Cell<bool>,
}

impl View<'_> {
    /// Counts `points` evaluations; false once the budget is spent.
    fn spend(&self, points: usize) -> bool {
        let spent = self.work.get().saturating_add(points as u64);
        self.work.set(spent);
        spent <= self.params.max_work
    }

    /// Counts `points` evaluations of coarse fits; false once the budget less
    /// the fine fits' share is spent (so the best coarse fits are always refined).
    fn spend_coarse(&self, points: usize) -> bool {
        let p = self.params;
        let fine = p.fine_points * (p.fine.iterations + p.exact_iterations) + p.max_segment_points;
        let reserve = (p.max_fine * fine) as u64;
        let within = self.spend(points) && self.work.get() <= p.max_work.saturating_sub(reserve);
        self.coarse_cut.set(self.coarse_cut.get() || !within);
        within
    }

    /// Said in every "not found" when the budget ran out before the fits did.
    fn budget_note(&self) -> String {
        let exhausted = self.work.get() > self.params.max_work;
        if !exhausted && !self.coarse_cut.get() {
            return String::new();
        }
        format!(
            "; the work budget ran out before every segment was fitted: {} point evaluations spent, the limit is {} (max_work)",
            self.work.get(),
            self.params.max_work
        )
    }
}

/// Thins every cluster and segment of more than `max` points to `max`, evenly.
fn thin_large(clusters: &mut [Vec<Point3<f64>>], segments: &mut [Segment], max: usize) {
    let all = clusters
        .iter_mut()
        .chain(segments.iter_mut().map(|s| &mut s.points));
    for points in all.filter(|p| p.len() > max) {
        *points = thin(points, max);
    }
}

/// A coarse fit on a segment and its rank.
struct Hypothesis {
    rank: f64,
    segment: usize,
    fit: IcpFit,
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
    if cloud.len() < params.segment.min_points {
        return not_found("the image has (almost) no depth measurements".into(), None);
    }
    let size = 2.0 * template.radius;
    // No object's own top is wider than the object: a supporting plane is.
    let plane_params = PlaneParams {
        min_width: params.plane.min_width.max(size + params.segment.margin),
        ..params.plane.clone()
    };
    let planes = find_planes(&cloud.points, &plane_params);
    let grid = Grid {
        width: image.width(),
        stride: params.stride,
    };
    let cut = segments(&cloud, &planes, grid, size, &params.segment);
    let (oversize, nearest) = (cut.oversize, cut.nearest);
    let (mut clusters, mut segments) = (cut.clusters, cut.segments);
    thin_large(&mut clusters, &mut segments, params.max_segment_points);
    let t_segment = started.elapsed();
    let view = View {
        template,
        image,
        camera,
        planes: &planes,
        params,
        work: std::cell::Cell::new(cloud.len() as u64),
        coarse_cut: std::cell::Cell::new(false),
    };
    let coarse = coarse_fits(&view, &segments);
    let t_coarse = started.elapsed();
    let best = best_fine(&view, &segments, &clusters, &coarse);
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
        work = view.work.get(),
        "detect"
    );
    let budget = view.budget_note();
    let Some(best) = best else {
        let seen = if segments.is_empty() {
            nothing_object_sized(
                &template.name,
                size,
                oversize,
                nearest.as_ref(),
                planes.len(),
            )
        } else {
            format!(
                "{} object-sized segments in {} clusters above the supporting plane, but no fit of '{}' was made",
                segments.len(),
                clusters.len(),
                template.name
            )
        };
        return not_found(seen + &budget, None);
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
    let whole = &clusters[best.cluster];
    let width = crate::segment::diameter(whole);
    let c = detection.pose * template.moments.centroid;
    let reason = format!(
        "{}; it is at ({:.3}, {:.3}, {:.3}) m, fitted to {} cluster of {} points {:.3} m wide ('{}' is {:.3} m across)",
        explain(&best.verdict, params.min_confidence),
        c.x,
        c.y,
        c.z,
        if width > size + params.segment.margin {
            "a piece of a"
        } else {
            "a"
        },
        whole.len(),
        width,
        template.name,
        size
    ) + &budget;
    not_found(reason, Some(detection))
}

/// "Not found" when no segment is object-sized: how many clusters were too
/// wide, and the one nearest the object's size.
fn nothing_object_sized(
    object: &str,
    size: f64,
    oversize: usize,
    nearest: Option<&crate::segment::Oversize>,
    planes: usize,
) -> String {
    let Some(n) = nearest else {
        return format!(
            "nothing above the supporting plane: no cluster of points off the {planes} planes found"
        );
    };
    format!(
        "no object-sized cluster above the supporting plane: {oversize} clusters, all wider than '{object}' \
         ({size:.3} m across); the nearest in size is {:.3} m wide ({} points, centred at ({:.3}, {:.3}, {:.3}) m); \
         {planes} planes",
        n.width, n.points, n.centroid.x, n.centroid.y, n.centroid.z
    )
}

/// Why a candidate's confidence is too low, in words.
fn explain(v: &Verdict, min_confidence: f64) -> String {
    format!(
        "best candidate's confidence {:.2} is below {:.2}: the model explains {:.0} % of its cluster's points; \
         of the model's {} measured pixels {} agree, {} see through it, {} are hidden; {:.0} % of its camera-facing surface is outside the image; resting on a plane: {}",
        v.confidence,
        min_confidence,
        v.explained * 100.0,
        v.supported + v.violations + v.near_misses + v.occluded,
        v.supported,
        v.violations,
        v.occluded,
        v.outside * 100.0,
        if v.resting { "yes" } else { "no" },
    )
}

/// Every principal-axis hypothesis and every resting pose on every segment,
/// after a short coarse ICP, ranked by a quick verification: the best
/// `refine_top` of each segment, best first.
fn coarse_fits(view: &View, segments: &[Segment]) -> Vec<Hypothesis> {
    let (template, params) = (view.template, view.params);
    let cam = view.camera.centre();
    let mut all: Vec<Hypothesis> = Vec::new();
    for (si, seg) in segments.iter().enumerate() {
        if !view.spend_coarse(0) {
            break;
        }
        let Some(m) = Moments::of(&seg.points) else {
            continue;
        };
        let pts = thin(&seg.points, params.coarse_points);
        let mut starts = from_principal_axes(template, &m, &cam);
        if params.resting_hypotheses {
            if let Some(plane) = plane_below(view.planes, &m.centroid) {
                starts.extend(on_plane(template, &seg.points, &plane.plane, &cam));
            }
        }
        let cost = pts.len() * (params.coarse.iterations + 1);
        let mut fits: Vec<Hypothesis> = starts
            .into_iter()
            .take_while(|_| view.spend_coarse(cost))
            .map(|start| {
                let fit = refine(template, &pts, Some(cam), start, &params.coarse);
                Hypothesis {
                    rank: rank(view, &fit, &pts),
                    segment: si,
                    fit,
                }
            })
            .collect();
        fits.sort_by(|a, b| b.rank.total_cmp(&a.rank));
        all.extend(fits.into_iter().take(params.refine_top));
    }
    all.sort_by(|a, b| b.rank.total_cmp(&a.rank));
    all
}

/// The rank of a coarse fit: how much of the segment the model explains times
/// how much of the model's visible surface the image supports (a quick
/// [`verify`] on a subset of the model's samples), halved when the model does
/// not rest on the plane under it (coarse limits: twice the final ones).
fn rank(view: &View, fit: &IcpFit, points: &[Point3<f64>]) -> f64 {
    let p = &view.params.rank;
    let v = verify(view.template, &fit.pose, points, view.image, view.camera, p);
    let resting = rest_gap(view.template, &fit.pose, view.planes).is_some_and(|g| {
        g >= -2.0 * view.params.max_penetration && g <= 2.0 * view.params.max_rest_gap
    });
    let prior = if resting || !view.params.require_support {
        1.0
    } else {
        0.5
    };
    v.explained * v.agreement(p.unmeasured_weight) * prior
}

/// The verified fine fit of highest confidence among the best `max_fine`
/// coarse fits (stopping early at `early_accept`).
fn best_fine(
    view: &View,
    segments: &[Segment],
    clusters: &[Vec<Point3<f64>>],
    coarse: &[Hypothesis],
) -> Option<Candidate> {
    let mut best: Option<Candidate> = None;
    for h in coarse.iter().take(view.params.max_fine) {
        let seg = &segments[h.segment];
        let p = view.params;
        let cost =
            p.fine_points * (p.fine.iterations + p.exact_iterations) + clusters[seg.parent].len();
        if !view.spend(cost) {
            break;
        }
        let mut cand = fine_fit(view, &seg.points, &clusters[seg.parent], h.fit.pose);
        cand.cluster = seg.parent;
        if best
            .as_ref()
            .is_none_or(|b| cand.verdict.confidence > b.verdict.confidence)
        {
            best = Some(cand);
        }
        if best
            .as_ref()
            .is_some_and(|b| b.verdict.confidence >= view.params.early_accept)
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

/// Full ICP from a coarse pose on `seg`, again on the gathered
/// full-resolution points, then verification against the `whole` cluster
/// `seg` is a piece of.
fn fine_fit(
    view: &View,
    seg: &[Point3<f64>],
    whole: &[Point3<f64>],
    start: Isometry3<f64>,
) -> Candidate {
    let (template, params) = (view.template, view.params);
    let cam = view.camera.centre();
    let fine_pts = thin(seg, params.fine_points);
    let fit = refine(template, &fine_pts, Some(cam), start, &params.fine);
    let gathered = gather(view, &fit.pose);
    let (pts, gate) = if gathered.len() >= fine_pts.len() / 2 {
        (thin(&gathered, params.fine_points), params.gather)
    } else {
        (fine_pts, params.fine.gate_end)
    };
    // The last iterations pair exactly (the k-d tree): the data's accuracy.
    let last = IcpParams {
        iterations: params.exact_iterations,
        gate_start: gate,
        fast_pairing: false,
        ..params.fine.clone()
    };
    let mut fit = refine(template, &pts, Some(cam), fit.pose, &last);
    if let Some(settle_params) = &params.settle {
        fit.pose = settle(template, &fit.pose, view.image, view.camera, settle_params);
    }
    let mut verdict = verify(
        template,
        &fit.pose,
        whole,
        view.image,
        view.camera,
        &params.verify,
    );
    let gap = rest_gap(template, &fit.pose, view.planes);
    verdict.resting = gap.is_some_and(|g| g >= -params.max_penetration && g <= params.max_rest_gap);
    if params.require_support && !verdict.resting {
        verdict.confidence = 0.0;
    }
    Candidate {
        fit,
        verdict,
        cluster: 0,
    }
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

/// At most `n` points, evenly strided.
fn thin(points: &[Point3<f64>], n: usize) -> Vec<Point3<f64>> {
    let step = points.len().div_ceil(n.max(1)).max(1);
    points.iter().step_by(step).copied().collect()
}

/// Full-resolution points within `gather` of the model at `pose`, off the planes
/// (the region's pixels are counted as work).
fn gather(view: &View, pose: &Isometry3<f64>) -> Vec<Point3<f64>> {
    let (template, params, camera) = (view.template, view.params, view.camera);
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
    // Every pixel of the region is looked at.
    view.spend(
        region[2].saturating_sub(region[0]) as usize * region[3].saturating_sub(region[1]) as usize,
    );
    let inv = pose.inverse();
    let gate2 = params.gather * params.gather;
    let centre = pose * template.moments.centroid;
    let reach2 = (template.radius + params.gather).powi(2);
    PointCloud::from_region(view.image, camera, region)
        .points
        .into_iter()
        .filter(|p| {
            (p - centre).norm_squared() <= reach2
                && view
                    .planes
                    .iter()
                    .all(|pl| pl.plane.distance(p).abs() > params.plane.threshold)
                && template.nearest_fast(&(inv * p)).1 <= gate2
        })
        .collect()
}
