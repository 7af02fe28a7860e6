//! The agreement sweep behind `docs/force-closure.md`: random grasps on the
//! 350 ml can and a box, every method against the exact conic reference.
//!
//! `cargo run --release --example fc_agreement -p tsukami-grasp [-- CASES_PER_SHAPE]`

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::Sweep;

fn main() {
    let cases: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5000);
    let counts = [3, 4, 5, 6];
    let t0 = Instant::now();
    let s = common::sweep(cases, 0x0054_5355_4b41_4d49, &counts, 8, 50);
    println!("{} grasps ({} per shape, can and box), 3–6 contacts, μ in [0.2, 1], f_max 10 N, 8-sided pyramids, seed fixed; {:.1} s", 2 * cases, cases, t0.elapsed().as_secs_f64());
    println!();
    println!(
        "exact (8-pyramid) vs Ferrari–Canny eps_L1 > 0:   {}",
        s.exact_vs_l1
    );
    println!(
        "exact (8-pyramid) vs Ferrari–Canny eps_Linf > 0: {}",
        s.exact_vs_linf
    );
    println!(
        "exact 8-pyramid vs exact circular cone:          {}",
        s.poly_vs_circular
    );
    println!();
    println!("ellipsoid vs exact (circular cone), alpha = 1/sqrt(2), inscribed centre:");
    println!("  force closure, delta_f = 0:     {}", s.ellipsoid_closure);
    println!(
        "  force closure, delta_f = n - 1: {}",
        s.ellipsoid_closure_inner
    );
    println!("  weight,        delta_f = 0:     {}", s.ellipsoid_weight);
    println!(
        "  weight,        delta_f = n - 1: {}",
        s.ellipsoid_weight_inner
    );
    println!();
    println!("delta_f giving zero false positives (a grasp passes when margin > delta_f):");
    println!("  contacts | closure delta_f | closure FN at it | weight delta_f | weight FN at it");
    let mut rows: Vec<Option<usize>> = counts.iter().map(|&n| Some(n)).collect();
    rows.push(None);
    for n in rows {
        let dc = Sweep::zero_fp_delta(&s.closure_margins, n);
        let (fnc, pc) = Sweep::false_negatives_at(&s.closure_margins, dc, n);
        let dw = Sweep::zero_fp_delta(&s.weight_margins, n);
        let (fnw, pw) = Sweep::false_negatives_at(&s.weight_margins, dw, n);
        println!(
            "  {:>8} | {:>15.4} | {:>7} / {:<6} | {:>14.4} | {:>6} / {:<6}",
            n.map_or("all".to_string(), |n| n.to_string()),
            dc,
            fnc,
            pc,
            dw,
            fnw,
            pw
        );
    }
}
