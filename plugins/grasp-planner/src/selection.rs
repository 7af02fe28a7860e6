//! Grasp-type selection (section 3.2, eqs. (1)–(5) and the score eq. (3)).
//!
//! What: [`select`] pairs every grasp type with every OCP region and every free
//! face of that region, keeps the pairs the hand can hold, and orders them by
//! the score `l_ij` of eq. (3) (smaller is better). [`Selection::rejected`]
//! says why the others were dropped, so "no grasp type fits" is explained.
//!
//! Why: the paper's size and mass conditions are orientation-free (sorted edge
//! lengths); the approach face is what makes a can's side and its top lead to
//! different types: four fingertips side by side need a face at least as wide
//! as the four fingers (GRCmin across the approach), which the side of a can
//! offers and its top does not.
//!
//! How: eqs. (1)–(2) compare sorted GRCmax / GRCmin edges with the sorted OCP
//! edges, eqs. (4)–(5) the mass range; then, per free face, the two GRC edges
//! across the approach vector must lie between GRCmin and GRCmax in one of the
//! two in-plane orientations (the other two of the four rotations of section
//! 3.2 are their mirror images and are resolved by [`crate::palm_pose`]).
//!
//! The mass range of eqs. (4)–(5) is a preference, not a wall: a type that fits
//! the size but not the mass is kept in [`Selection::fallback`], searched only
//! after every preferred candidate failed on every whole-body stage, and only
//! when the object is within the hand's capacity (the largest `m_max` of all
//! types). The exact force-closure check with the weight still decides. A
//! lying 0.5 kg bottle that no envelope type can wrap on a table is then held
//! by the fingertips; an object heavier than every type stays refused.

use nalgebra::Vector3;
use tsukami_msgs::planner::BoxFace;

use crate::grasp_type::{GraspType, GrcBox};
use crate::ocp::Ocp;
use crate::tilt::Tilt;

/// `sort(a)` of eq. (1): the elements in decreasing order.
pub fn sorted(v: &Vector3<f64>) -> Vector3<f64> {
    let mut a = [v.x, v.y, v.z];
    a.sort_by(|x, y| y.total_cmp(x));
    Vector3::from(a)
}

/// One feasible (grasp type, region, face) triple.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Index into the grasp-type list.
    pub grasp_type: usize,
    /// OCP region index.
    pub region: usize,
    /// Face of the OCP to approach.
    pub face: BoxFace,
    /// Eq. (3): `‖sort(e_des) − sort(e_o)‖` (m).
    pub score: f64,
    /// The approach turned toward a neighbour face ([`crate::tilt`]); `None`
    /// for the paper's approach along the face normal.
    pub tilt: Option<Tilt>,
}

/// Why a grasp type was not kept for a region or face.
#[derive(Debug, Clone, PartialEq)]
pub enum Rejection {
    /// Eq. (1) fails: the region does not fit in GRCmax.
    TooLarge,
    /// Eq. (2) fails: the region is smaller than GRCmin.
    TooSmall,
    /// Eq. (4) fails: the object is heavier than `m_max`.
    TooHeavy,
    /// Eq. (5) fails: the object is lighter than `m_min`.
    TooLight,
    /// No free face of the region fits the GRC across the approach direction.
    NoFreeFace,
}

impl std::fmt::Display for Rejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Rejection::TooLarge => "object larger than GRCmax (eq. 1)",
            Rejection::TooSmall => "object smaller than GRCmin (eq. 2)",
            Rejection::TooHeavy => "object heavier than m_max (eq. 4)",
            Rejection::TooLight => "object lighter than m_min (eq. 5)",
            Rejection::NoFreeFace => "no free face fits the GRC across the approach",
        })
    }
}

/// Result of [`select`].
#[derive(Debug, Clone, Default)]
pub struct Selection {
    /// Feasible candidates, best score first (ties: type order, then region).
    pub candidates: Vec<Candidate>,
    /// `(grasp type, region, reason)` of every rejected pair.
    pub rejected: Vec<(usize, usize, Rejection)>,
    /// Candidates that fit in size but not in the type's mass range (eqs.
    /// (4)–(5)) while the hand as a whole can carry the object: tried after
    /// all of [`Selection::candidates`] failed, ordered the same way.
    pub fallback: Vec<Candidate>,
}

impl Selection {
    /// A one-line summary of the rejections, for error messages.
    pub fn explain(&self, types: &[GraspType]) -> String {
        let mut parts: Vec<String> = self
            .rejected
            .iter()
            .map(|(t, r, why)| {
                let name = types.get(*t).map(|g| g.name.as_str()).unwrap_or("?");
                format!("{name} on region {r}: {why}")
            })
            .collect();
        parts.dedup();
        parts.join("; ")
    }
}

/// The two edges of `grc` across the approach direction and its edge along it:
/// `(across_1, across_2, along)`, with `across_1` along the first palm axis
/// orthogonal to the approach (palm x for a z approach) — the GRC axes are
/// matched to palm axes by their directions.
pub fn grc_edges_in_palm(grc: &GrcBox, approach: &Vector3<f64>) -> (Vector3<f64>, usize) {
    let rot = grc.pose().rotation.to_rotation_matrix();
    // Edge lengths along the palm axes (the GRC is axis-aligned up to
    // permutations; a tilted box is measured by its projection).
    let m = rot.matrix();
    let e = grc.edges();
    let mut along_palm = Vector3::zeros();
    for k in 0..3 {
        along_palm[k] = (0..3).map(|c| m[(k, c)].abs() * e[c]).sum();
    }
    (along_palm, approach.iamax())
}

/// Keeps the grasp types that can hold `ocps` given `mass`, one candidate per
/// feasible free face, ordered by eq. (3).
pub fn select(types: &[GraspType], ocps: &[Ocp], mass: f64) -> Selection {
    let mut sel = Selection::default();
    // The hand's capacity: the heaviest object some type admits.
    let capacity = types.iter().map(|g| g.mass[1]).fold(0.0, f64::max);
    for (i, g) in types.iter().enumerate() {
        let (e_max, e_min, e_des) = (
            sorted(&g.grc_max.edges()),
            sorted(&g.grc_min.edges()),
            sorted(&g.grc_des.edges()),
        );
        for o in ocps {
            let e_o = sorted(&o.extents);
            let b_max = e_max - e_o; // eq. (1)
            let b_min = e_o - e_min; // eq. (2)
            let dm_max = g.mass[1] - mass; // eq. (4)
            let dm_min = mass - g.mass[0]; // eq. (5)
            let why = if b_max.min() <= 0.0 {
                Some(Rejection::TooLarge)
            } else if b_min.min() <= 0.0 {
                Some(Rejection::TooSmall)
            } else if dm_max <= 0.0 {
                Some(Rejection::TooHeavy)
            } else if dm_min <= 0.0 {
                Some(Rejection::TooLight)
            } else {
                None
            };
            let mass_only = matches!(why, Some(Rejection::TooHeavy | Rejection::TooLight));
            if let Some(why) = why {
                sel.rejected.push((i, o.region, why));
                if !(mass_only && mass < capacity) {
                    continue;
                }
            }
            let faces: Vec<BoxFace> = o.free_faces().filter(|&f| face_fits(g, o, f)).collect();
            if faces.is_empty() && !mass_only {
                sel.rejected.push((i, o.region, Rejection::NoFreeFace));
            }
            let into = match mass_only {
                true => &mut sel.fallback,
                false => &mut sel.candidates,
            };
            let score = (e_des - e_o).norm(); // eq. (3)
            into.extend(faces.into_iter().map(|face| Candidate {
                grasp_type: i,
                region: o.region,
                face,
                score,
                tilt: None,
            }));
        }
    }
    // Stable: equal scores keep type order, then region, then face order.
    sel.candidates.sort_by(|a, b| a.score.total_cmp(&b.score));
    sel.fallback.sort_by(|a, b| a.score.total_cmp(&b.score));
    sel
}

/// In-plane edges of an OCP face: the extents along the two box axes other
/// than the face normal, in increasing axis order, and the depth.
pub fn face_extents(o: &Ocp, face: BoxFace) -> (f64, f64, f64) {
    let k = face.axis();
    let (u, v) = ((k + 1) % 3, (k + 2) % 3);
    let (u, v) = (u.min(v), u.max(v));
    (o.extents[u], o.extents[v], o.extents[k])
}

/// Whether the face's in-plane edges fit between GRCmin and GRCmax across the
/// approach in one of the two in-plane orientations.
pub fn face_fits(g: &GraspType, o: &Ocp, face: BoxFace) -> bool {
    let a = g.approach();
    let (max_p, ka) = grc_edges_in_palm(&g.grc_max, &a);
    let (min_p, _) = grc_edges_in_palm(&g.grc_min, &a);
    let (p1, p2) = ((ka + 1) % 3, (ka + 2) % 3);
    let (eu, ev, _) = face_extents(o, face);
    let fits = |x: f64, y: f64| x < max_p[p1] && y < max_p[p2] && x > min_p[p1] && y > min_p[p2];
    fits(eu, ev) || fits(ev, eu)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grasp_type::GraspTypeConfig;
    use nalgebra::{Point3, Rotation3};

    fn can_ocp() -> Ocp {
        // Axis 0 along the can (world z), axis 1 = −x world, axis 2 = axis0 × axis1.
        let x = Vector3::z();
        let y = -Vector3::x();
        let z = x.cross(&y);
        Ocp {
            region: 0,
            center: Point3::new(0.5, 0.0, 1.061),
            rotation: Rotation3::from_matrix_unchecked(nalgebra::Matrix3::from_columns(&[x, y, z])),
            extents: Vector3::new(0.122, 0.066, 0.066),
            blocked: [
                None,
                Some(tsukami_msgs::planner::FaceBlock::Support),
                None,
                None,
                None,
                None,
            ],
        }
    }

    /// One grasp type of the test hand: GRC boxes centred 0.1 m along the
    /// palm's x axis, `grc_max` 0.30 m wide, the style read off the name.
    fn grasp_type(name: &str, mass: [f64; 2], min: [f64; 3], des: [f64; 3], max_x: f64) -> String {
        let style = name.trim_end_matches("_mid");
        let grc = |s: [f64; 3]| format!("{{ position = [0.1, 0, 0.05], size = {s:?} }}");
        format!(
            "[[grasp_type]]\nname = \"{name}\"\nstyle = \"{style}\"\nsize = \"mid\"\n\
             mass = {mass:?}\napproach = [0, 0, 1]\nclosing_step = 0.02\nposture = {{}}\n\
             contacts = [{{ link = \"l\", joint = \"j\" }}]\ngrc_max = {}\ngrc_min = {}\n\
             grc_des = {}\n",
            grc([max_x, 0.30, 0.30]),
            grc(min),
            grc(des)
        )
    }

    /// The test hand's three mid-size types.
    fn types() -> GraspTypeConfig {
        let text = [
            grasp_type(
                "fingertip4_mid",
                [0.0, 0.3],
                [0.03, 0.085, 0.02],
                [0.065, 0.12, 0.065],
                0.09,
            ),
            grasp_type(
                "fingertip3_mid",
                [0.0, 0.3],
                [0.02, 0.04, 0.01],
                [0.06, 0.06, 0.06],
                0.09,
            ),
            grasp_type(
                "envelope4_mid",
                [0.25, 1.5],
                [0.04, 0.085, 0.04],
                [0.07, 0.15, 0.07],
                0.10,
            ),
        ]
        .concat();
        GraspTypeConfig::from_toml_str(&text).unwrap()
    }

    #[test]
    fn can_side_and_top_lead_to_different_types() {
        let cfg = types();
        let sel = select(&cfg.grasp_types, &[can_ocp()], 0.15);
        let by = |name: &str| -> Vec<BoxFace> {
            sel.candidates
                .iter()
                .filter(|c| cfg.grasp_types[c.grasp_type].name == name)
                .map(|c| c.face)
                .collect()
        };
        // Axis 0 is the can axis: ±x faces are top/bottom, the rest are sides.
        let ft4 = by("fingertip4_mid");
        assert!(
            !ft4.contains(&BoxFace::PosX),
            "fingertip4 must not take the top: {ft4:?}"
        );
        assert_eq!(ft4.len(), 4, "four side faces: {ft4:?}");
        let ft3 = by("fingertip3_mid");
        assert!(
            ft3.contains(&BoxFace::PosX),
            "fingertip3 takes the top: {ft3:?}"
        );
        assert!(
            !ft3.contains(&BoxFace::NegX),
            "the bottom rests on the table"
        );
        // Too light for the enveloping grasp.
        assert!(by("envelope4_mid").is_empty());
        assert!(sel.rejected.contains(&(2, 0, Rejection::TooLight)));
        // Scores ascending.
        assert!(sel.candidates.windows(2).all(|w| w[0].score <= w[1].score));
    }

    #[test]
    fn heavy_object_gets_the_envelope() {
        let cfg = types();
        let sel = select(&cfg.grasp_types, &[can_ocp()], 0.35);
        assert!(sel
            .candidates
            .iter()
            .all(|c| cfg.grasp_types[c.grasp_type].name == "envelope4_mid"));
        assert!(!sel.candidates.is_empty());
        assert!(sel.explain(&cfg.grasp_types).contains("heavier"));
    }

    #[test]
    fn huge_object_fits_nothing() {
        let cfg = types();
        let mut o = can_ocp();
        o.extents = Vector3::new(0.5, 0.4, 0.4);
        let sel = select(&cfg.grasp_types, &[o], 0.15);
        assert!(sel.candidates.is_empty());
        assert!(sel.rejected.iter().all(|r| r.2 == Rejection::TooLarge));
    }
}
