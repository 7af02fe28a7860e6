//! Contact sets shared by the tests, the benchmark and the `fc_agreement`
//! example: textbook grasps and random grasps on a 350 ml can and a box.
#![allow(dead_code)]

use nalgebra::{Point3, Vector3};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use tsukami_grasp::contact::Contact;
use tsukami_grasp::grasp::Grasp;

/// 350 ml can: Ø66 × 122 mm.
pub const CAN_RADIUS: f64 = 0.033;
/// Half the can's height.
pub const CAN_HALF_HEIGHT: f64 = 0.061;
/// Box half extents (a 60 × 40 × 100 mm box).
pub const BOX_HALF: [f64; 3] = [0.03, 0.02, 0.05];

/// Object the random contacts are drawn on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// The can, centred at the origin, axis z.
    Can,
    /// The box, centred at the origin.
    Box,
}

impl Shape {
    /// Characteristic length for γ: about the object's radius.
    pub fn characteristic_length(self) -> f64 {
        match self {
            Shape::Can => CAN_RADIUS,
            Shape::Box => 0.04,
        }
    }

    /// Mass (kg): 0.35 for the full can, 0.2 for the box.
    pub fn mass(self) -> f64 {
        match self {
            Shape::Can => 0.35,
            Shape::Box => 0.2,
        }
    }
}

/// A uniformly random surface point of `shape` and its inward normal.
pub fn surface_contact(shape: Shape, rng: &mut ChaCha8Rng) -> Contact {
    match shape {
        Shape::Can => {
            let (r, h) = (CAN_RADIUS, CAN_HALF_HEIGHT);
            let side = std::f64::consts::TAU * r * 2.0 * h;
            let cap = std::f64::consts::PI * r * r;
            let pick = rng.random::<f64>() * (side + 2.0 * cap);
            if pick < side {
                let a = rng.random::<f64>() * std::f64::consts::TAU;
                let z = (rng.random::<f64>() * 2.0 - 1.0) * h;
                let out = Vector3::new(a.cos(), a.sin(), 0.0);
                Contact::new(Point3::new(r * out.x, r * out.y, z), -out).expect("unit normal")
            } else {
                // Uniform on the disc: radius ∝ √u.
                let rho = r * rng.random::<f64>().sqrt();
                let a = rng.random::<f64>() * std::f64::consts::TAU;
                let top = pick < side + cap;
                let z = if top { h } else { -h };
                let n = if top { -Vector3::z() } else { Vector3::z() };
                Contact::new(Point3::new(rho * a.cos(), rho * a.sin(), z), n).expect("unit normal")
            }
        }
        Shape::Box => {
            let e = BOX_HALF;
            let areas = [e[1] * e[2], e[0] * e[2], e[0] * e[1]];
            let total: f64 = areas.iter().sum::<f64>() * 2.0;
            let mut pick = rng.random::<f64>() * total;
            let mut axis = 0;
            for (k, a) in areas.iter().enumerate() {
                if pick < 2.0 * a {
                    axis = k;
                    break;
                }
                pick -= 2.0 * a;
                axis = k;
            }
            let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
            let mut p = Vector3::zeros();
            for k in 0..3 {
                p[k] = if k == axis {
                    sign * e[k]
                } else {
                    (rng.random::<f64>() * 2.0 - 1.0) * e[k]
                };
            }
            let mut n = Vector3::zeros();
            n[axis] = -sign;
            Contact::new(Point3::from(p), n).expect("unit normal")
        }
    }
}

/// One random problem: `n` contacts on `shape`, random μ in [0.2, 1.0],
/// f_max 10 N, reference at the centre (the centre of mass).
pub fn random_grasp(shape: Shape, n: usize, rng: &mut ChaCha8Rng) -> Grasp {
    let contacts: Vec<Contact> = (0..n).map(|_| surface_contact(shape, rng)).collect();
    let mu = 0.2 + 0.8 * rng.random::<f64>();
    Grasp::new(
        contacts,
        mu,
        10.0,
        shape.characteristic_length(),
        Point3::origin(),
    )
    .expect("valid grasp")
}

/// The weight wrench of `shape` under standard gravity.
pub fn weight(grasp: &Grasp, shape: Shape) -> tsukami_grasp::grasp_matrix::Wrench {
    grasp.weight_wrench(
        shape.mass(),
        &Vector3::new(0.0, 0.0, -9.81),
        &Point3::origin(),
    )
}

/// `n` fingers evenly spaced on the equator of a sphere of radius `r`.
pub fn equator_grasp(n: usize, r: f64, mu: f64) -> Grasp {
    let contacts = (0..n)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / n as f64;
            let out = Vector3::new(a.cos(), a.sin(), 0.0);
            Contact::new(Point3::from(out * r), -out).expect("unit normal")
        })
        .collect();
    Grasp::new(contacts, mu, 10.0, r, Point3::origin()).expect("valid grasp")
}

/// Counts of a comparison between a test and a reference.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Confusion {
    /// Both say yes.
    pub true_pos: usize,
    /// Both say no.
    pub true_neg: usize,
    /// Test yes, reference no.
    pub false_pos: usize,
    /// Test no, reference yes.
    pub false_neg: usize,
}

impl Confusion {
    /// Records one case.
    pub fn add(&mut self, test: bool, reference: bool) {
        match (test, reference) {
            (true, true) => self.true_pos += 1,
            (false, false) => self.true_neg += 1,
            (true, false) => self.false_pos += 1,
            (false, true) => self.false_neg += 1,
        }
    }
    /// Number of cases.
    pub fn total(&self) -> usize {
        self.true_pos + self.true_neg + self.false_pos + self.false_neg
    }
    /// Fraction of agreeing cases.
    pub fn agreement(&self) -> f64 {
        (self.true_pos + self.true_neg) as f64 / self.total().max(1) as f64
    }
}

impl std::fmt::Display for Confusion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "agree {:.2}% ({} / {}), both yes {}, both no {}, false positives {}, false negatives {}",
            100.0 * self.agreement(),
            self.true_pos + self.true_neg,
            self.total(),
            self.true_pos,
            self.true_neg,
            self.false_pos,
            self.false_neg
        )
    }
}

/// Everything the agreement sweep measures.
#[derive(Debug, Clone, Default)]
pub struct Sweep {
    /// Exact with the k-pyramid vs Ferrari–Canny ε_L1 > 0.
    pub exact_vs_l1: Confusion,
    /// Exact with the k-pyramid vs ε_L∞ > 0 (only when `linf_up_to` allows).
    pub exact_vs_linf: Confusion,
    /// Exact polyhedral vs exact circular closure (pyramid ⊂ cone: no false positives possible).
    pub poly_vs_circular: Confusion,
    /// Ellipsoid (δf = 0) vs exact circular closure.
    pub ellipsoid_closure: Confusion,
    /// Ellipsoid (δf = n − 1, inner) vs exact circular closure.
    pub ellipsoid_closure_inner: Confusion,
    /// Ellipsoid (δf = 0) vs exact circular weight test.
    pub ellipsoid_weight: Confusion,
    /// Ellipsoid (δf = n − 1) vs exact circular weight test.
    pub ellipsoid_weight_inner: Confusion,
    /// Closure margins `n − f(0)` of exact-closed and exact-open (non-degenerate) cases, per n.
    pub closure_margins: Vec<(usize, f64, bool)>,
    /// Weight margins `n − f(−w)` with the exact answer, per n.
    pub weight_margins: Vec<(usize, f64, bool)>,
}

impl Sweep {
    /// Smallest δf with no false positives: the largest margin among the
    /// reference's negatives (a test passes when margin > δf).
    pub fn zero_fp_delta(margins: &[(usize, f64, bool)], n: Option<usize>) -> f64 {
        margins
            .iter()
            .filter(|(k, m, truth)| !truth && m.is_finite() && n.is_none_or(|n| n == *k))
            .map(|(_, m, _)| *m)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Reference positives rejected at threshold δf, and the number of positives.
    pub fn false_negatives_at(
        margins: &[(usize, f64, bool)],
        delta: f64,
        n: Option<usize>,
    ) -> (usize, usize) {
        let pos: Vec<f64> = margins
            .iter()
            .filter(|(k, _, truth)| *truth && n.is_none_or(|n| n == *k))
            .map(|(_, m, _)| *m)
            .collect();
        (pos.iter().filter(|m| **m <= delta).count(), pos.len())
    }
}

/// Runs `cases` random grasps per shape (contact counts cycling through
/// `contacts`), seeded, and compares the methods. ε_L∞ (≈0.5 s a grasp of
/// three contacts) is computed for the first `linf_per_shape` grasps of three
/// contacts of each shape.
pub fn sweep(
    cases: usize,
    seed: u64,
    contacts: &[usize],
    sides: usize,
    linf_per_shape: usize,
) -> Sweep {
    use rand::SeedableRng;
    use tsukami_grasp::ellipsoid::{ellipsoid_test, EllipsoidModel};
    use tsukami_grasp::exact::{exact_force_closure, exact_weight_scale, ConeModel};
    use tsukami_grasp::ferrari_canny::{epsilon_l1, epsilon_linf, FerrariCannyOptions};

    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut s = Sweep::default();
    let model = EllipsoidModel::default();
    let options = FerrariCannyOptions {
        sides,
        ..FerrariCannyOptions::default()
    };
    for shape in [Shape::Can, Shape::Box] {
        let mut linf_done = 0;
        for i in 0..cases {
            let n = contacts[i % contacts.len()];
            let g = random_grasp(shape, n, &mut rng);
            let w = weight(&g, shape);
            let poly = exact_force_closure(&g, ConeModel::Polyhedral { sides }).expect("solver");
            let circ = exact_force_closure(&g, ConeModel::Circular).expect("solver");
            let l1 = epsilon_l1(&g, sides).expect("hull");
            s.exact_vs_l1.add(l1 > 0.0, poly.force_closure);
            if n == 3 && linf_done < linf_per_shape {
                linf_done += 1;
                let linf = epsilon_linf(&g, &options).expect("hull");
                s.exact_vs_linf.add(linf > 0.0, poly.force_closure);
            }
            s.poly_vs_circular
                .add(poly.force_closure, circ.force_closure);
            let resists = exact_weight_scale(&g, ConeModel::Circular, &w)
                .expect("solver")
                .weight_scale
                >= 1.0;
            let e = ellipsoid_test(&g, &model, &w);
            let inner = n as f64 - 1.0;
            s.ellipsoid_closure
                .add(e.force_closure(0.0), circ.force_closure);
            s.ellipsoid_closure_inner
                .add(e.force_closure(inner), circ.force_closure);
            s.ellipsoid_weight.add(e.resists(0.0), resists);
            s.ellipsoid_weight_inner.add(e.resists(inner), resists);
            if !e.degenerate {
                s.closure_margins
                    .push((n, e.closure_margin(), circ.force_closure));
            }
            s.weight_margins.push((n, e.margin(), resists));
        }
    }
    s
}
