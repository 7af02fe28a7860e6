//! `tsukami fc [--input FILE|-]`: force-closure tests on the command line.
//!
//! Reads one problem or a JSON array of problems and writes one result per problem,
//! in order; a malformed problem gets an error object naming its index and field
//! while the others are still answered. The problem is in [`super::fc_problem`],
//! the result in [`super::fc_solve`]; the mechanics are `tsukami_grasp`'s.
//! Without `"methods"` a problem runs the fast methods (ellipsoid and exact);
//! `"methods": [..., "ferrari_canny"]` adds Ferrari–Canny ε.
//!
//! # Errors
//!
//! A problem that cannot be evaluated is answered, in its place, with
//! `{"error": {"code", "message", "index", "field"}}`. `field` is a path such as
//! `contacts[1].normal` (or `null`), `index` the problem's position (0 for a
//! single problem; `null` when the document itself does not parse, which is
//! answered with that one error). JSON has no NaN: a non-number where a number
//! belongs is an `invalid_type`.

use anyhow::{Context, Result};
use serde_json::Value;
use std::io::Read;
use std::path::PathBuf;

use super::fc_problem::{Problem, ProblemError};
use super::fc_solve::solve_problem;

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
    println!("{}", solve_json(&text));
    Ok(())
}

/// Answers one problem given as a JSON value: a result object or an error object.
pub fn solve_value(v: &Value, index: usize) -> Value {
    match Problem::from_value(v).and_then(|p| solve_problem(&p)) {
        Ok(r) => serde_json::to_value(r).unwrap_or_else(|e| {
            ProblemError::MethodFailed {
                method: "serialize",
                message: e.to_string(),
            }
            .to_json(Some(index))
        }),
        Err(e) => e.to_json(Some(index)),
    }
}

/// Answers a JSON document holding one problem or an array of problems: one
/// result (or error object) per problem, in the same order, as JSON text.
/// A document that is not JSON is answered with a single error object.
pub fn solve_json(input: &str) -> String {
    let answer = match serde_json::from_str::<Value>(input) {
        Err(e) => ProblemError::Parse(e.to_string()).to_json(None),
        Ok(Value::Array(problems)) => Value::Array(
            problems
                .iter()
                .enumerate()
                .map(|(i, p)| solve_value(p, i))
                .collect(),
        ),
        Ok(one) => solve_value(&one, 0),
    };
    answer.to_string()
}

#[cfg(test)]
#[path = "fc_tests.rs"]
mod tests;
