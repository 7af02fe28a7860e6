//! The demo's progress: what it is doing now, on standard error.
//!
//! What: [`Status`]. On a terminal, one line rewritten in place for each step
//! (`can_breast: planning the motion …`) and cleared before a table row is
//! printed; otherwise plain lines (`tsukami demo: can_breast: planning the
//! motion`), one per step, which logs and CI keep.
//!
//! Why: a scene takes seconds (more in a debug build); a newcomer must see that
//! the demo is working and what it is waiting for.

use std::cell::Cell;
use std::io::{IsTerminal, Write};

/// Where the demo reports its steps.
pub struct Status {
    terminal: bool,
    open: Cell<bool>,
}

impl Status {
    /// Status on standard error, rewritten in place when it is a terminal.
    pub fn on_stderr() -> Status {
        Status {
            terminal: std::io::stderr().is_terminal(),
            open: Cell::new(false),
        }
    }

    /// Reports that `scene` is now doing `what`.
    pub fn step(&self, scene: &str, what: &str) {
        let mut err = std::io::stderr().lock();
        if self.terminal {
            let _ = write!(err, "\r\x1b[2K{scene}: {what} …");
            self.open.set(true);
        } else {
            let _ = writeln!(err, "tsukami demo: {scene}: {what}");
        }
        let _ = err.flush();
    }

    /// Clears the in-place line (before printing to standard output).
    pub fn clear(&self) {
        if self.open.replace(false) {
            let mut err = std::io::stderr().lock();
            let _ = write!(err, "\r\x1b[2K");
            let _ = err.flush();
        }
    }
}
