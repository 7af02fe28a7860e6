//! Measures a hand posture: prints where each finger link's tip and pad are in
//! the palm frame. Usage: `hand_posture [URDF] [joint=value ...]`.
use nalgebra::Point3;
use tsukami_body::kinematics::FkState;
use tsukami_body::urdf::load_urdf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let urdf = if args.first().is_some_and(|a| a.ends_with(".urdf")) {
        args.remove(0)
    } else {
        "models/robots/tsukami_humanoid/tsukami_humanoid.urdf".into()
    };
    let robot = load_urdf(urdf.as_ref())?;
    let mut pairs = Vec::new();
    for a in &args {
        let (n, v) = a.split_once('=').ok_or("expected joint=value")?;
        pairs.push((n.to_string(), v.parse::<f64>()?));
    }
    let q = robot.positions_from_named(pairs.iter().map(|(n, v)| (n.as_str(), *v)))?;
    let mut fk = FkState::new(&robot);
    robot.forward_kinematics(&q, &mut fk);
    let palm = robot.link_id("r_palm")?;
    let inv = fk.pose(palm).inverse();
    for (i, link) in robot.links.iter().enumerate() {
        if !link.name.contains("_l")
            || !(link.name.starts_with("r_thumb")
                || link.name.starts_with("r_index")
                || link.name.starts_with("r_middle")
                || link.name.starts_with("r_ring"))
        {
            continue;
        }
        let p0 = inv * fk.pose(i) * Point3::origin();
        // Capsules run along x from the joint to the link's tip.
        let len = link
            .collisions
            .first()
            .map_or(0.0, |c| 2.0 * c.origin.translation.x);
        let tip = inv * fk.pose(i) * Point3::new(len, 0.0, 0.0);
        println!(
            "{:12} base [{:7.3} {:7.3} {:7.3}]  tip [{:7.3} {:7.3} {:7.3}]",
            link.name, p0.x, p0.y, p0.z, tip.x, tip.y, tip.z
        );
    }
    Ok(())
}
