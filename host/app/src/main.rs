//! `tsukami`: the host and its command-line client.
//!
//! `tsukami run` serves plugins on the bus; the client subcommands send the
//! GraspBar commands (SetRobot, SetObject, SetEnv, Plan, Stop) over the bus and print
//! the JSON reply; `tsukami demo` runs the main job.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
