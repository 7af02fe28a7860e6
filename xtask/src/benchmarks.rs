//! `cargo benchmarks [--only NAME,…] [--list]`: runs the bench targets and
//! writes what they print into `docs/benchmarks.md`.
//!
//! What: every bench target (and the example that prints the object
//! benchmark, the physics subset `bench/physics/ci.sh` and the clean build
//! `bench/build_time.sh`) in [`BENCHES`] is run in turn; its standard output replaces the
//! fenced block between `<!-- bench-output NAME -->` and
//! `<!-- /bench-output -->` in the page, and the block between `<!-- machine -->`
//! and `<!-- /machine -->` is replaced by this machine's description (CPU,
//! cores, memory, OS, toolchain, load, date).
//!
//! Why: figures copied by hand go stale and lose the machine they came from.
//! The prose around each block (what is measured, targets, analysis) stays
//! written by people; the numbers come from one command.
//!
//! How: `cargo bench`/`cargo run --release` (or `bash` for a script) as child processes, output
//! captured, each block headed by the machine line; a bench that fails leaves its block saying so (with its exit
//! status) and the command goes on with the others, then exits non-zero.

use std::path::Path;
use std::process::Command;

/// One bench: its block name in the page and the command that runs it.
pub struct Bench {
    /// The block's name (`<!-- bench-output NAME -->`).
    pub name: &'static str,
    /// The program: `cargo` (this cargo), or `bash` for a script of `bench/`.
    pub program: &'static str,
    /// Its arguments (after `cargo`, or the script and its own).
    pub args: &'static [&'static str],
}

impl Bench {
    /// The command line, as the page and `--list` show it.
    pub fn command_line(&self) -> String {
        format!("{} {}", self.program, self.args.join(" "))
    }
}

/// Every bench target whose output the page holds, in page order.
#[rustfmt::skip]
pub const BENCHES: &[Bench] = &[
    Bench { name: "roundtrip", program: "cargo", args: &["bench", "-p", "tsukami-e2e", "--bench", "roundtrip"] },
    Bench { name: "viewer", program: "cargo", args: &["bench", "-p", "tsukami-e2e", "--bench", "viewer"] },
    Bench { name: "body", program: "cargo", args: &["bench", "-p", "tsukami-body", "--bench", "body", "--", "--warm-up-time", "1", "--measurement-time", "3"] },
    Bench { name: "force_closure", program: "cargo", args: &["bench", "-p", "tsukami-grasp", "--bench", "force_closure", "--", "--warm-up-time", "1", "--measurement-time", "3"] },
    Bench { name: "fc_default", program: "cargo", args: &["bench", "-p", "tsukami", "--bench", "fc_default"] },
    Bench { name: "plan_scenes", program: "cargo", args: &["bench", "-p", "tsukami-e2e", "--bench", "plan_scenes"] },
    Bench { name: "plan_scenes_in_process", program: "cargo", args: &["bench", "-p", "tsukami-grasp-planner", "--bench", "plan_scenes", "--", "--warm-up-time", "1", "--measurement-time", "3"] },
    Bench { name: "antipodal_plan_can", program: "cargo", args: &["bench", "-p", "tsukami-antipodal-planner", "--bench", "plan_can", "--", "--warm-up-time", "1", "--measurement-time", "3"] },
    Bench { name: "concurrency", program: "cargo", args: &["bench", "-p", "tsukami-e2e", "--bench", "concurrency"] },
    Bench { name: "object_bench", program: "cargo", args: &["run", "--release", "-p", "tsukami-grasp-planner", "--example", "object_bench"] },
    Bench { name: "physics", program: "bash", args: &["bench/physics/ci.sh"] },
    Bench { name: "motion_scenes", program: "cargo", args: &["bench", "-p", "tsukami-trajectory-planner", "--bench", "motion_scenes"] },
    Bench { name: "toppra", program: "bash", args: &["bench/toppra/run.sh"] },
    Bench { name: "object_motions", program: "cargo", args: &["run", "--release", "-p", "tsukami-trajectory-planner", "--example", "object_motions"] },
    Bench { name: "vision", program: "cargo", args: &["bench", "-p", "tsukami-vision", "--bench", "vision"] },
    Bench { name: "build_time", program: "bash", args: &["bench/build_time.sh"] },
];

/// Runs the chosen benches (all when `only` is empty) and rewrites `page`.
pub fn run(root: &Path, only: &[String]) -> Result<(), String> {
    let unknown: Vec<&String> = only
        .iter()
        .filter(|n| !BENCHES.iter().any(|b| b.name == n.as_str()))
        .collect();
    if !unknown.is_empty() {
        return Err(format!(
            "unknown bench {unknown:?}; `cargo benchmarks --list` names them"
        ));
    }
    let page_path = root.join("docs/benchmarks.md");
    let machine = machine();
    update(
        &page_path,
        "<!-- machine -->",
        "<!-- /machine -->",
        &machine,
    )?;
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".to_owned());
    let mut failed = Vec::new();
    for b in BENCHES
        .iter()
        .filter(|b| only.is_empty() || only.iter().any(|n| n == b.name))
    {
        eprintln!("== {}: {}", b.name, b.command_line());
        let program: &str = if b.program == "cargo" {
            &cargo
        } else {
            b.program
        };
        let out = Command::new(program)
            .args(b.args)
            .current_dir(root)
            .output();
        let text = match out {
            Ok(o) if o.status.success() => without_noise(&String::from_utf8_lossy(&o.stdout)),
            Ok(o) => {
                failed.push(b.name);
                format!(
                    "(failed: {}; stderr tail)\n{}",
                    o.status,
                    tail(&o.stderr, 20)
                )
            }
            Err(e) => {
                failed.push(b.name);
                format!("(could not run cargo: {e})")
            }
        };
        let open = format!("<!-- bench-output {} -->", b.name);
        let block = format!(
            "```text\n# {machine}\n$ {}\n{}```",
            b.command_line(),
            ensure_newline(&text)
        );
        update(&page_path, &open, "<!-- /bench-output -->", &block)?;
    }
    match failed.as_slice() {
        [] => Ok(()),
        f => Err(format!("benches failed: {f:?} (their blocks say why)")),
    }
}

/// Re-reads the page (people may edit it while a bench runs), replaces one
/// block and writes it back.
fn update(page_path: &Path, open: &str, close: &str, body: &str) -> Result<(), String> {
    let page = std::fs::read_to_string(page_path)
        .map_err(|e| format!("reading {}: {e}", page_path.display()))?;
    let page = replace_block(&page, open, close, body)?;
    std::fs::write(page_path, page).map_err(|e| format!("writing {}: {e}", page_path.display()))
}

/// The output without criterion's outlier lists (`Found N outliers…` and
/// the indented counts below it).
fn without_noise(text: &str) -> String {
    let noise = |l: &str| {
        let t = l.trim_start();
        (t.starts_with("Found ") && t.contains(" outliers among "))
            || (l.starts_with(' ') && (t.ends_with(" mild") || t.ends_with(" severe")))
    };
    text.lines()
        .filter(|l| !noise(l))
        .map(|l| format!("{l}\n"))
        .collect()
}

fn ensure_newline(s: &str) -> String {
    if s.ends_with('\n') {
        s.to_owned()
    } else {
        format!("{s}\n")
    }
}

fn tail(bytes: &[u8], lines: usize) -> String {
    let text = String::from_utf8_lossy(bytes);
    let all: Vec<&str> = text.lines().collect();
    all[all.len().saturating_sub(lines)..].join("\n")
}

/// `page` with the text between `open` and the next `close` replaced by
/// `body` (the markers stay).
fn replace_block(page: &str, open: &str, close: &str, body: &str) -> Result<String, String> {
    let start = page
        .find(open)
        .ok_or_else(|| format!("docs/benchmarks.md has no `{open}` marker"))?
        + open.len();
    let end = page[start..]
        .find(close)
        .ok_or_else(|| format!("docs/benchmarks.md: `{open}` has no `{close}` after it"))?
        + start;
    Ok(format!(
        "{}\n{}\n{}",
        &page[..start],
        body.trim_end(),
        &page[end..]
    ))
}

/// This machine, as the page describes it.
fn machine() -> String {
    let read = |p: &str| std::fs::read_to_string(p).unwrap_or_default();
    let cpuinfo = read("/proc/cpuinfo");
    let cpu = cpuinfo
        .lines()
        .find_map(|l| l.strip_prefix("model name"))
        .map(|l| l.trim_start_matches([' ', '\t', ':']).to_owned())
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let mem_kib: u64 = read("/proc/meminfo")
        .lines()
        .find_map(|l| l.strip_prefix("MemTotal:"))
        .and_then(|l| l.split_whitespace().next()?.parse().ok())
        .unwrap_or(0);
    let os = read("/etc/os-release")
        .lines()
        .find_map(|l| l.strip_prefix("PRETTY_NAME="))
        .map(|l| l.trim_matches('"').to_owned())
        .unwrap_or_else(|| std::env::consts::OS.into());
    let rustc = Command::new("rustc")
        .arg("--version")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_default();
    let load = read("/proc/loadavg")
        .split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ");
    let date = Command::new("date")
        .args(["-u", "+%Y-%m-%d %H:%M UTC"])
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .unwrap_or_default();
    format!(
        "Generated by `cargo benchmarks` on {date}: {cpu}, {cores} cores, {:.0} GiB, {os}, \
         {rustc}; load average at the start {load}.",
        mem_kib as f64 / 1048576.0
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_replaced_between_their_markers_only() {
        let page = "a\n<!-- x -->\nold\n<!-- /x -->\nb\n<!-- y -->\nkeep\n<!-- /x -->\n";
        let new = replace_block(page, "<!-- x -->", "<!-- /x -->", "new").unwrap();
        assert_eq!(
            new,
            "a\n<!-- x -->\nnew\n<!-- /x -->\nb\n<!-- y -->\nkeep\n<!-- /x -->\n"
        );
        assert!(replace_block(page, "<!-- z -->", "<!-- /x -->", "n").is_err());
    }

    #[test]
    fn criterion_outlier_lists_are_dropped() {
        let out = "g/a\n   time: [1 ns 2 ns 3 ns]\nFound 2 outliers among 100 measurements (2.00%)\n  1 (1.00%) high mild\n  1 (1.00%) low severe\nnext\n";
        assert_eq!(without_noise(out), "g/a\n   time: [1 ns 2 ns 3 ns]\nnext\n");
    }

    #[test]
    fn every_section_has_a_block_and_every_block_a_bench() {
        let page = include_str!("../../docs/benchmarks.md");
        for section in page.split("\n## ").skip(1) {
            let title = section.lines().next().unwrap_or_default();
            assert!(
                section.contains("<!-- bench-output "),
                "docs/benchmarks.md: section `{title}` has no `<!-- bench-output NAME -->` block"
            );
        }
        for block in page.split("<!-- bench-output ").skip(1) {
            let name = block.split(" -->").next().unwrap_or_default();
            assert!(
                BENCHES.iter().any(|b| b.name == name),
                "docs/benchmarks.md: block `{name}` is no bench of BENCHES"
            );
        }
    }

    #[test]
    fn every_bench_target_of_the_workspace_is_run() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let workspace: toml::Table = std::fs::read_to_string(root.join("Cargo.toml"))
            .unwrap()
            .parse()
            .unwrap();
        let members = workspace["workspace"]["members"].as_array().unwrap();
        for member in members.iter().filter_map(|m| m.as_str()) {
            let manifest: toml::Table =
                std::fs::read_to_string(root.join(member).join("Cargo.toml"))
                    .unwrap()
                    .parse()
                    .unwrap();
            let package = manifest["package"]["name"].as_str().unwrap();
            let benches = manifest.get("bench").and_then(|b| b.as_array());
            for bench in benches.into_iter().flatten() {
                let name = bench["name"].as_str().unwrap();
                let run = BENCHES.iter().any(|b| {
                    b.args.windows(2).any(|w| w == ["-p", package])
                        && b.args.windows(2).any(|w| w == ["--bench", name])
                });
                assert!(run, "bench {package}/{name} is in no entry of BENCHES");
            }
        }
    }

    #[test]
    fn every_bench_has_its_block_in_the_page() {
        let page = include_str!("../../docs/benchmarks.md");
        assert!(page.contains("<!-- machine -->") && page.contains("<!-- /machine -->"));
        for b in BENCHES {
            let open = format!("<!-- bench-output {} -->", b.name);
            assert!(page.contains(&open), "docs/benchmarks.md lacks {open}");
        }
    }
}
