//! Whole-body IK stages (section 3.4): the arm first, then arm + waist, then
//! arm + waist + the whole-body joints.
//!
//! What: [`stage_solver`] builds the IK solver of one [`Stage`] for the palm
//! link; [`StageSolver::reach`] solves one palm pose from a start
//! configuration, with the rest posture as the secondary target.

use nalgebra::Isometry3;
use tsukami_body::ik::{IkOptions, IkSolver};
use tsukami_body::kinematics::JointSelection;

use crate::robot::{Hand, Robot, Stage};

/// The IK of one stage.
pub struct StageSolver<'a> {
    /// The stage.
    pub stage: &'a Stage,
    solver: IkSolver<'a>,
}

/// The solver of `stage` for `hand`'s palm; `None` if the joints make no
/// valid selection.
pub fn stage_solver<'a>(
    robot: &'a Robot,
    hand: &Hand,
    stage: &'a Stage,
    options: IkOptions,
) -> Option<StageSolver<'a>> {
    let sel = JointSelection::new(&robot.model, &stage.joints).ok()?;
    let solver = IkSolver::new(&robot.model, hand.palm, sel, options).ok()?;
    Some(StageSolver { stage, solver })
}

/// IK options for palm poses: `attempts` restarts, 0.5 mm and 5 mrad.
pub fn palm_ik(attempts: usize, seed: u64) -> IkOptions {
    IkOptions {
        max_attempts: attempts,
        position_tolerance: 5e-4,
        orientation_tolerance: 5e-3,
        seed,
        ..IkOptions::default()
    }
}

impl StageSolver<'_> {
    /// The configuration putting the palm at `palm`, from `start`, staying
    /// near `rest`; `None` if the IK does not converge.
    pub fn reach(
        &mut self,
        palm: &Isometry3<f64>,
        start: &[f64],
        rest: &[f64],
    ) -> Option<Vec<f64>> {
        let sol = self.solver.solve(palm, true, start, Some(rest));
        sol.ok.then_some(sol.q)
    }
}
