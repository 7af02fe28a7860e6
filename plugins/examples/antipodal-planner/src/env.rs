//! Obstacles of the environment (tables, shelves, walls) as collision bodies.
//!
//! What: [`build_obstacle`] turns one `set_env` obstacle into a
//! [`CollisionObject`], checking every dimension; errors name the obstacle's
//! index and field (`obstacles[2].shape`).
//!
//! Why: `set_env` is all-or-nothing — every obstacle is built before the
//! planner's map of obstacles is touched.

use tsukami_body::collision::CollisionObject;
use tsukami_msgs::planner::Obstacle;
use tsukami_scenes::geometry::{self, ObstacleError};

use crate::error::PlanError;

/// Builds obstacle `index` of a `set_env` request (through `tsukami-scenes`, the
/// project's one definition of a valid obstacle), naming `obstacles[index].<field>`
/// in errors.
pub fn build_obstacle(index: usize, o: &Obstacle) -> Result<CollisionObject, PlanError> {
    geometry::build_obstacle(o).map_err(|e| match e {
        ObstacleError::Invalid { field, message } => {
            PlanError::invalid(format!("obstacles[{index}].{field}"), message)
        }
        ObstacleError::Model { field, message } => PlanError::Model {
            field: format!("obstacles[{index}].{field}"),
            message,
        },
    })
}
