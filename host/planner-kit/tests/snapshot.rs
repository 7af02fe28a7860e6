//! A plan keeps the world it started with: a `set_object` that arrives while a
//! plan runs is answered at once with the next version, and the plan under way
//! never sees it (no half-applied change); the next plan sees it whole.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::{mpsc, Arc, Mutex};

use nalgebra::Point3;
use tsukami_msgs::planner::{pose_at, ObjectShape, PlanOptions, SetObject, SetRobot};
use tsukami_planner_kit::*;

/// A planner that reports the world it sees, waiting for the test in between.
struct Observer {
    started: mpsc::SyncSender<()>,
    gate: Mutex<mpsc::Receiver<()>>,
    seen: Mutex<Vec<(u64, Point3<f64>)>>,
}

impl GraspPlanner for Observer {
    type RobotData = ();
    type ObjectData = ();
    fn info() -> PlannerInfo {
        PlannerInfo {
            name: "observer",
            version: "0",
            description: "records the world it plans on",
        }
    }
    fn new(_: &PlannerConfig) -> Result<Self, String> {
        Err("built by the test".into())
    }
    fn robot_data(&self, _: &Robot) -> Result<(), KitError> {
        Ok(())
    }
    fn object_data(&self, _: &Object) -> Result<(), KitError> {
        Ok(())
    }
    fn plan(&self, w: &World<'_, Self>, _: &PlanOptions, _: &mut Run) -> Result<Grasp, NoGrasp> {
        let before = (w.version, w.object.center_of_mass);
        let _ = self.started.send(());
        let _ = self.gate.lock().unwrap().recv();
        // Everything read again after the change was accepted elsewhere.
        let after = (w.version, w.object.center_of_mass);
        self.seen.lock().unwrap().extend([before, after]);
        Err(NoGrasp::Exhausted)
    }
}

fn can_at(x: f64) -> SetObject {
    SetObject {
        name: None,
        shape: ObjectShape::Model {
            name: "can_350ml".into(),
        },
        mass: 0.15,
        friction: None,
        pose: pose_at([x, -0.25, 1.05]),
        center_of_mass: None,
    }
}

#[test]
fn a_plan_never_sees_a_change_made_while_it_runs() {
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let (started_tx, started) = mpsc::sync_channel(4);
    let (open, gate) = mpsc::channel();
    let planner = Observer {
        started: started_tx,
        gate: Mutex::new(gate),
        seen: Mutex::new(vec![]),
    };
    let session = Arc::new(Session::with_planner(
        planner,
        PlannerConfig::with_roots([models]),
    ));
    session
        .set_robot(&SetRobot {
            robot: "tsukami_humanoid".into(),
            grasp_types: None,
            package_dirs: Vec::new(),
        })
        .unwrap();
    let first = session.set_object(&can_at(0.45)).unwrap();
    let running = {
        let s = session.clone();
        std::thread::spawn(move || {
            s.plan(
                &PlanOptions::default(),
                &AtomicBool::new(false),
                &mut |_| {},
            )
        })
    };
    started.recv().unwrap();
    let moved = session.set_object(&can_at(0.55)).unwrap();
    assert_eq!(moved.world_version, first.world_version + 1);
    open.send(()).unwrap();
    let e = running.join().unwrap().unwrap_err();
    assert_eq!(e.details()["world_version"], first.world_version, "{e}");
    open.send(()).unwrap();
    let e = session
        .plan(
            &PlanOptions::default(),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap_err();
    assert_eq!(e.details()["world_version"], moved.world_version);
    let seen = session.planner().seen.lock().unwrap().clone();
    let old = Point3::from(first.center_of_mass);
    let new = Point3::from(moved.center_of_mass);
    assert_eq!(seen[0], (first.world_version, old));
    assert_eq!(
        seen[1],
        (first.world_version, old),
        "the running plan saw the change"
    );
    assert_eq!(seen[2], (moved.world_version, new));
    assert!((new - old).norm() > 0.09);
}

#[test]
fn a_refused_change_keeps_the_world_and_its_version() {
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../models");
    let session: Session<tsukami_planner_kit::conformance::Null> = Session::new(models);
    session
        .set_robot(&SetRobot {
            robot: "tsukami_humanoid".into(),
            grasp_types: None,
            package_dirs: Vec::new(),
        })
        .unwrap();
    let ok = session.set_object(&can_at(0.45)).unwrap();
    let mut bad = can_at(0.45);
    bad.center_of_mass = Some([10.0, 0.0, 0.0]);
    let e = session.set_object(&bad).unwrap_err();
    assert_eq!(e.code(), tsukami_msgs::ErrorCode::InvalidValue);
    assert!(e.to_string().contains("center_of_mass"), "{e}");
    assert_eq!(session.snapshot().version, ok.world_version);
}
