//! `tsukami fc [--input FILE|-]`: force-closure tests on the command line.
//!
//! Reads one problem or a JSON array of problems and writes one result per problem,
//! in order; a malformed problem gets an error object naming its index and field
//! while the others are still answered. The field contract lives in `host/grasp`'s
//! `problem` module.

use anyhow::{Context, Result};
use std::io::Read;
use std::path::PathBuf;

/// Options of `tsukami fc`.
#[derive(clap::Args, Debug)]
pub struct FcArgs {
    /// The problem file, or `-` (the default) for standard input.
    #[arg(long, default_value = "-")]
    input: PathBuf,
}

/// Runs `tsukami fc`.
pub fn run(args: &FcArgs) -> Result<()> {
    let text = if args.input.as_os_str() == "-" {
        let mut text = String::new();
        std::io::stdin()
            .read_to_string(&mut text)
            .context("reading standard input")?;
        text
    } else {
        std::fs::read_to_string(&args.input)
            .with_context(|| format!("reading {}", args.input.display()))?
    };
    println!("{}", tsukami_grasp::problem::solve_json(&text));
    Ok(())
}
