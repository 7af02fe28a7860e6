//! One version of the world, shared by every plan that runs on it.
//!
//! What: [`Snapshot`] — version, robot, object and obstacles, each behind an
//! `Arc` with the planner's derived data — and [`Snapshot::apply`], which
//! builds the next snapshot from a change without touching this one.
//!
//! Why: a plan holds the snapshot it started with, so a `set_object` arriving
//! mid-plan builds a new snapshot beside it and the plan under way never sees a
//! half-applied change. Unchanged parts are shared, not copied.
//!
//! How: `apply` validates and builds everything first (robot files, object,
//! every obstacle) and only then assembles the new snapshot: all or nothing.

use std::collections::BTreeMap;
use std::sync::Arc;

use tsukami_body::collision::CollisionObject;
use tsukami_msgs::host::WorldChange;
use tsukami_msgs::planner::{EnvSummary, ObjectSummary, RemoveEnv, SetEnv};

use crate::config::PlannerConfig;
use crate::env::build_obstacle;
use crate::object::Object;
use crate::planner::{GraspPlanner, World};
use crate::robot::Robot;
use crate::KitError;

/// One version of the world with the planner's data.
pub struct Snapshot<P: GraspPlanner> {
    /// Version (0 before any change).
    pub version: u64,
    /// Robot and the planner's robot data.
    pub robot: Option<Arc<(Robot, P::RobotData)>>,
    /// Object and the planner's object data.
    pub object: Option<Arc<(Object, P::ObjectData)>>,
    /// Obstacles by name.
    pub env: Arc<BTreeMap<String, CollisionObject>>,
}

impl<P: GraspPlanner> Clone for Snapshot<P> {
    fn clone(&self) -> Self {
        Snapshot {
            version: self.version,
            robot: self.robot.clone(),
            object: self.object.clone(),
            env: self.env.clone(),
        }
    }
}

impl<P: GraspPlanner> Default for Snapshot<P> {
    fn default() -> Self {
        Snapshot {
            version: 0,
            robot: None,
            object: None,
            env: Arc::default(),
        }
    }
}

fn to_json<T: serde::Serialize>(v: &T) -> Vec<u8> {
    // Plain data of finite numbers and strings: serialising cannot fail.
    serde_json::to_vec(v).unwrap_or_default()
}

impl<P: GraspPlanner> Snapshot<P> {
    /// The world a plan sees, or `not_ready` naming what is missing.
    pub fn world(&self) -> Result<World<'_, P>, KitError> {
        let robot = self.robot.as_deref().ok_or(KitError::NotReady {
            missing: "robot",
            command: "set_robot",
        })?;
        let object = self.object.as_deref().ok_or(KitError::NotReady {
            missing: "object",
            command: "set_object",
        })?;
        Ok(World {
            version: self.version,
            robot: &robot.0,
            robot_data: &robot.1,
            object: &object.0,
            object_data: &object.1,
            obstacles: self.env.values().collect(),
        })
    }

    /// The snapshot `change` makes as `version`, and the reply (JSON) to it.
    pub fn apply(
        &self,
        planner: &P,
        config: &PlannerConfig,
        change: &WorldChange,
        version: u64,
    ) -> Result<(Snapshot<P>, Vec<u8>), KitError> {
        let mut next = Snapshot {
            version,
            ..self.clone()
        };
        let reply = match change {
            WorldChange::SetRobot(req) => {
                let robot = Robot::load(&config.models, req)?;
                let data = planner.robot_data(&robot)?;
                let mut summary = robot.summary(planner.grasp_types(&robot, &data));
                summary.world_version = version;
                next.robot = Some(Arc::new((robot, data)));
                to_json(&summary)
            }
            WorldChange::SetObject(req) => {
                let object = Object::build(&config.models, req, &config.limits)?;
                let data = planner.object_data(&object)?;
                let summary = ObjectSummary {
                    name: object.name.clone(),
                    mass: object.mass,
                    center_of_mass: object.center_of_mass.coords.into(),
                    triangles: object.mesh.indices.len(),
                    regions: planner.regions(&object, &data),
                    world_version: version,
                    warnings: object.warnings.clone(),
                };
                next.object = Some(Arc::new((object, data)));
                to_json(&summary)
            }
            WorldChange::SetEnv(req) => {
                next.env = Arc::new(self.with_obstacles(req, config)?);
                to_json(&next.env_summary())
            }
            WorldChange::RemoveEnv(req) => {
                next.env = Arc::new(self.without_obstacles(req)?);
                to_json(&next.env_summary())
            }
        };
        Ok((next, reply))
    }

    fn with_obstacles(
        &self,
        req: &SetEnv,
        config: &PlannerConfig,
    ) -> Result<BTreeMap<String, CollisionObject>, KitError> {
        let mut names = std::collections::BTreeSet::new();
        let mut built = Vec::new();
        for (i, o) in req.obstacles.iter().enumerate() {
            if !names.insert(o.name.as_str()) {
                return Err(KitError::invalid(
                    format!("obstacles[{i}].name"),
                    format!("`{}` appears twice in this request", o.name),
                ));
            }
            built.push((
                o.name.clone(),
                build_obstacle(&config.models, i, o, &config.limits)?,
            ));
        }
        let mut env = if req.replace {
            BTreeMap::new()
        } else {
            (*self.env).clone()
        };
        env.extend(built);
        Ok(env)
    }

    fn without_obstacles(
        &self,
        req: &RemoveEnv,
    ) -> Result<BTreeMap<String, CollisionObject>, KitError> {
        if req.all {
            return Ok(BTreeMap::new());
        }
        if let Some((i, n)) = req
            .names
            .iter()
            .enumerate()
            .find(|(_, n)| !self.env.contains_key(*n))
        {
            return Err(KitError::invalid(
                format!("names[{i}]"),
                format!("no obstacle named `{n}`"),
            ));
        }
        let mut env = (*self.env).clone();
        for n in &req.names {
            env.remove(n);
        }
        Ok(env)
    }

    fn env_summary(&self) -> EnvSummary {
        EnvSummary {
            obstacles: self.env.keys().cloned().collect(),
            world_version: self.version,
        }
    }
}
