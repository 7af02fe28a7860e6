//! Project tasks behind cargo aliases (see `.cargo/config.toml`).
//!
//! `cargo demo [ARGS]`: builds every crate of the workspace in release mode — the
//! host binary, the plugin libraries and the component binaries (`tsukami-vision`,
//! `tsukami-controller`), which `cargo run -p tsukami` alone would not build — then
//! runs `target/release/tsukami demo [ARGS]`, which finds the components beside
//! itself.
//!
//! `cargo benchmarks [--only NAME,…] [--list]`: runs the bench targets and
//! writes their output and the machine's description into `docs/benchmarks.md`
//! ([`benchmarks`]).

mod benchmarks;

use std::process::{Command, ExitCode};

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let task = args.next().unwrap_or_default();
    let rest: Vec<String> = args.collect();
    match task.as_str() {
        "demo" => run_release("demo", &rest),
        "host" => run_release("run", &rest),
        "benchmarks" => run_benchmarks(&rest),
        _ => {
            eprintln!("usage: cargo demo [ARGS] | cargo host [ARGS] | cargo benchmarks [--only A,B] [--list]");
            ExitCode::from(2)
        }
    }
}

fn run_release(subcommand: &str, rest: &[String]) -> ExitCode {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let built = Command::new(&cargo)
        .args(["build", "--release", "--workspace", "--exclude", "xtask"])
        .status();
    if !matches!(built, Ok(s) if s.success()) {
        eprintln!("cargo build --release --workspace failed");
        return ExitCode::FAILURE;
    }
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let target = std::env::var("CARGO_TARGET_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|_| root.join("target"));
    let exe = target
        .join("release")
        .join(format!("tsukami{}", std::env::consts::EXE_SUFFIX));
    match Command::new(&exe).arg(subcommand).args(rest).status() {
        Ok(status) if status.success() => ExitCode::SUCCESS,
        Ok(status) => ExitCode::from(u8::try_from(status.code().unwrap_or(1)).unwrap_or(1)),
        Err(e) => {
            eprintln!("could not run {}: {e}", exe.display());
            ExitCode::FAILURE
        }
    }
}

fn run_benchmarks(rest: &[String]) -> ExitCode {
    if rest.iter().any(|a| a == "--list") {
        for b in benchmarks::BENCHES {
            println!("{:<24} {}", b.name, b.command_line());
        }
        return ExitCode::SUCCESS;
    }
    let only: Vec<String> = match rest {
        [] => Vec::new(),
        [flag, names] if flag == "--only" => names.split(',').map(str::to_owned).collect(),
        _ => {
            eprintln!("usage: cargo benchmarks [--only NAME,NAME] [--list]");
            return ExitCode::from(2);
        }
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    match benchmarks::run(&root, &only) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("cargo benchmarks: {e}");
            ExitCode::FAILURE
        }
    }
}
