//! Plans a grasp of a cylinder on a table in front of the robot and prints the
//! reply. Usage: `plan_can X Y TABLE_TOP RADIUS HEIGHT MASS [SEED]`.
use std::sync::atomic::AtomicBool;
use tsukami_grasp_planner::planner::Planner;
use tsukami_msgs::planner::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().unwrap())
        .collect();
    let (x, y, top, r, h, m) = (a[0], a[1], a[2], a[3], a[4], a[5]);
    let seed = a.get(6).copied().unwrap_or(0.0) as u64;
    let dir = std::env::temp_dir().join("tsukami-plan-can");
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("cyl.stl");
    tsukami_body::mesh::TriangleMesh::cylinder(r, h, 32).write_stl(&path)?;
    let p = Planner::new("models");
    p.set_robot(&SetRobot {
        robot: "tsukami_humanoid".into(),
        grasp_types: None,
        package_dirs: Vec::new(),
    })?;
    let s = p.set_object(&SetObject {
        name: None,
        shape: ObjectShape::Mesh {
            path: path.display().to_string(),
            scale: None,
        },
        mass: m,
        friction: None,
        center_of_mass: None,
        pose: pose_at([x, y, top + h / 2.0]),
    })?;
    println!("{}", serde_json::to_string(&s.regions)?);
    p.set_env(&SetEnv {
        obstacles: vec![Obstacle {
            name: "table".into(),
            shape: ObstacleShape::Box {
                size: [0.5, 0.8, 0.04],
            },
            pose: pose_at([x + 0.1, y, top - 0.02]),
        }],
        replace: true,
    })?;
    let t = std::time::Instant::now();
    let r = p.plan(
        &PlanOptions {
            seed,
            ..Default::default()
        },
        &AtomicBool::new(false),
        &mut |_| {},
    );
    println!("{:?} ms", t.elapsed().as_secs_f64() * 1e3);
    match r {
        Ok(r) => println!("{}", serde_json::to_string_pretty(&r)?),
        Err(e) => println!("ERROR {e}"),
    }
    Ok(())
}
