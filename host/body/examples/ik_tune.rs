//! Scratch: IK success vs options (temporary).
use nalgebra::Isometry3;
use rand::{Rng, SeedableRng};
use tsukami_body::ik::{IkOptions, IkSolver, RIGHT_ARM};
use tsukami_body::kinematics::{FkState, JointSelection};
fn main() {
    let a: Vec<f64> = std::env::args().skip(1).map(|s| s.parse().unwrap()).collect();
    let m = tsukami_body::urdf::load_urdf("models/robots/tsukami_humanoid/tsukami_humanoid.urdf".as_ref()).unwrap();
    let palm = m.link_id("r_palm").unwrap();
    let sel = JointSelection::from_names(&m, &RIGHT_ARM).unwrap();
    let mut o = IkOptions::default();
    o.max_iterations = a[0] as usize; o.orientation_weight = a[1]; o.min_damping = a[2]; o.null_space_gain = a[3];
    let mut s = IkSolver::new(&m, palm, sel, o).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut fk = FkState::new(&m);
    let rest = m.rest_positions();
    let (mut ok, mut it, mut att) = (0, 0, 0);
    let mut times = vec![];
    for _ in 0..1000 {
        let mut q = rest.clone();
        for n in RIGHT_ARM { let j = m.joint_id(n).unwrap(); let l = m.joints[j].limits; q[j] = rng.random_range(l.lower..=l.upper); }
        m.forward_kinematics(&q, &mut fk);
        let t: Isometry3<f64> = *fk.pose(palm);
        let t0 = std::time::Instant::now();
        let r = s.solve(&t, true, &rest, None);
        times.push(t0.elapsed().as_secs_f64()*1e6);
        if r.ok { ok += 1 } it += r.iterations; att += r.attempts;
    }
    times.sort_by(|a,b| a.partial_cmp(b).unwrap());
    println!("ok {ok} it {} att {} p50 {:.1}us p99 {:.1}us", it/1000, att as f64/1000.0, times[500], times[990]);
}
