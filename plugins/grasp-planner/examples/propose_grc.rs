//! Measures each grasp type's reference posture and proposes GRC boxes.
//!
//! Usage: `propose_grc [ROBOT [GRASP_TYPES.toml]]` (defaults: the project's
//! humanoid, `models/robots/tsukami_humanoid`, and its `grasp_types.toml`). For every grasp type it sets the
//! reference posture, finds the tips of the contacting links in the palm frame
//! and prints: the opening between the thumb tips and the finger tips along
//! palm x (GRCmax's x edge: the largest object the open posture admits), the
//! width of the finger row along palm y (GRCmin's y edge: the surface the
//! fingers need), and the centre between them (the GRC position), next to the
//! values in the file.
//!
//! To derive a new hand's grasp types from its kinematics (postures, contacts
//! and boxes), use `tsukami model grasp-types ROBOT_DIR` instead
//! (`tsukami_planner_kit::grasp_derive`, `docs/bring-your-own-robot.md`); this
//! example re-measures the postures of an existing file.
use nalgebra::Point3;
use tsukami_body::kinematics::FkState;
use tsukami_body::model::Geometry;
use tsukami_grasp_planner::hand::HandModel;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let request = tsukami_msgs::planner::SetRobot {
        robot: args.first().cloned().unwrap_or("tsukami_humanoid".into()),
        grasp_types: args.get(1).cloned(),
        package_dirs: Vec::new(),
    };
    let models = tsukami_planner_kit::models::Models::new(["models".into(), ".".into()]);
    let robot = tsukami_planner_kit::Robot::load(&models, &request)?;
    let hand = HandModel::from_robot(&robot)?;
    let mut fk = FkState::new(&hand.robot);
    for (t, g) in hand.config.grasp_types.iter().enumerate() {
        let mut q = hand.robot.rest_positions();
        hand.set_posture(t, &mut q);
        hand.robot.forward_kinematics(&q, &mut fk);
        let inv = fk.pose(hand.palm).inverse();
        let (mut thumb, mut fingers) = (Vec::new(), Vec::new());
        for c in &hand.types[t].contacts {
            let link = &hand.robot.links[c.link];
            let Some(e) = link.collisions.first() else {
                continue;
            };
            let r = match e.geometry {
                Geometry::Capsule { radius, .. } | Geometry::Sphere { radius } => radius,
                _ => 0.0,
            };
            // Capsules run along the link's x from the joint to the tip.
            let tip = inv * fk.pose(c.link) * Point3::new(2.0 * e.origin.translation.x, 0.0, 0.0);
            if link.name.contains("thumb") {
                thumb.push((tip, r));
            } else {
                fingers.push((tip, r));
            }
        }
        if thumb.is_empty() || fingers.is_empty() {
            println!("{}: needs a thumb and a finger contact", g.name);
            continue;
        }
        let thumb_x = thumb.iter().map(|(p, r)| p.x + r).fold(f64::MIN, f64::max);
        let finger_x = fingers
            .iter()
            .map(|(p, r)| p.x - r)
            .fold(f64::MAX, f64::min);
        let y_lo = fingers
            .iter()
            .map(|(p, r)| p.y - r)
            .fold(f64::MAX, f64::min);
        let y_hi = fingers
            .iter()
            .map(|(p, r)| p.y + r)
            .fold(f64::MIN, f64::max);
        let z = fingers
            .iter()
            .chain(thumb.iter())
            .map(|(p, _)| p.z)
            .sum::<f64>()
            / (fingers.len() + thumb.len()) as f64;
        println!(
            "{:18} opening x {:.3} (grc_max x {:.3})  finger row y {:.3} (grc_min y {:.3})  centre [{:.3}, {:.3}, {:.3}] (file {:?})",
            g.name,
            finger_x - thumb_x,
            g.grc_max.size[0],
            y_hi - y_lo,
            g.grc_min.size[1],
            0.5 * (thumb_x + finger_x),
            0.5 * (y_lo + y_hi),
            z,
            g.grc_des.position,
        );
    }
    Ok(())
}
