//! Public robot collections: how many URDFs load in Tsukami versus a
//! reference parser (yourdfpy), and whether forward kinematics agree.
//!
//! Needs the corpus fetched from PyPI by `tests/data/urdf/fetch_corpus.sh`,
//! which also runs the reference (`reference_fk.py`) and sets:
//! - `TSUKAMI_URDF_CORPUS`: the folder searched for `*.urdf`;
//! - `TSUKAMI_URDF_REFERENCE`: the reference's JSON (load result and link
//!   poses for 3 configurations per robot);
//! - `TSUKAMI_URDF_PACKAGES`: `:`-separated `--package-dir` folders.
//!
//! Run: `cargo test -p tsukami-body --test corpus -- --ignored --nocapture`.
//! It prints the table recorded in `docs/robots.md` and fails if fewer than
//! 98 % of the files the reference loads also load here, or if any link pose
//! differs by more than 1e-9.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use tsukami_body::kinematics::FkState;
use tsukami_body::packages::PackagePath;
use tsukami_body::urdf::{load_urdf_with, LoadOptions};
use tsukami_body::WarningKind;

#[derive(serde::Deserialize)]
struct Entry {
    file: String,
    ok: bool,
    #[serde(default)]
    error: Option<String>,
    #[serde(default)]
    configs: Vec<Config>,
}

#[derive(serde::Deserialize)]
struct Config {
    q: BTreeMap<String, f64>,
    poses: BTreeMap<String, Vec<f64>>,
}

#[derive(Default, Debug)]
struct Tally {
    files: usize,
    reference: usize,
    tsukami: usize,
    both: usize,
    strict: usize,
    with_collision: usize,
}

fn collection(file: &str) -> String {
    file.split('/').next().unwrap_or_default().to_string()
}

#[test]
#[ignore = "needs the corpus: run tests/data/urdf/fetch_corpus.sh"]
fn public_collections_load_and_fk_agrees() {
    let (Some(corpus), Some(reference)) = (
        std::env::var_os("TSUKAMI_URDF_CORPUS"),
        std::env::var_os("TSUKAMI_URDF_REFERENCE"),
    ) else {
        panic!("set TSUKAMI_URDF_CORPUS and TSUKAMI_URDF_REFERENCE (see fetch_corpus.sh)");
    };
    let corpus = PathBuf::from(corpus);
    let dirs: Vec<PathBuf> = std::env::var_os("TSUKAMI_URDF_PACKAGES")
        .map(|v| std::env::split_paths(&v).collect())
        .unwrap_or_default();
    let entries: Vec<Entry> =
        serde_json::from_str(&std::fs::read_to_string(&reference).unwrap()).unwrap();
    let packages = PackagePath::default().with_dirs(dirs);
    let kin = LoadOptions {
        packages: packages.clone(),
        ..LoadOptions::kinematics_only()
    };
    let strict = LoadOptions {
        strict: true,
        ..kin.clone()
    };
    let full = LoadOptions {
        packages,
        ..LoadOptions::default()
    };
    let mut tallies: BTreeMap<String, Tally> = BTreeMap::new();
    let mut refused: Vec<String> = Vec::new();
    let mut warnings: BTreeMap<String, usize> = BTreeMap::new();
    let (mut links_compared, mut poses_compared, mut worst) = (0usize, 0usize, 0.0f64);
    let mut fk_failures: Vec<String> = Vec::new();
    for e in &entries {
        let t = tallies.entry(collection(&e.file)).or_default();
        t.files += 1;
        t.reference += usize::from(e.ok);
        let path = corpus.join(&e.file);
        let loaded = load_urdf_with(&path, &kin);
        t.strict += usize::from(load_urdf_with(&path, &strict).is_ok());
        t.with_collision += usize::from(load_urdf_with(&path, &full).is_ok());
        let loaded = match loaded {
            Ok(l) => l,
            Err(err) => {
                let why = err
                    .to_string()
                    .replace(&format!("{}: ", path.display()), "");
                refused.push(format!(
                    "{} (reference: {}): {why}",
                    e.file,
                    e.error.as_deref().unwrap_or("loads")
                ));
                continue;
            }
        };
        t.tsukami += 1;
        for w in &loaded.warnings {
            let kind = match w.kind {
                WarningKind::Quirk => "quirk",
                WarningKind::VisualSkipped => "visual skipped",
                WarningKind::CollisionSkipped => "collision skipped",
                WarningKind::MeshCleaned => "mesh cleaned",
            };
            *warnings.entry(kind.to_string()).or_default() += 1;
        }
        if !e.ok {
            continue;
        }
        t.both += 1;
        let model = &loaded.model;
        let mut fk = FkState::new(model);
        for c in &e.configs {
            let q = match model.positions_from_named(c.q.iter().map(|(k, v)| (k.as_str(), *v))) {
                Ok(q) => q,
                Err(err) => {
                    fk_failures.push(format!("{}: {err}", e.file));
                    break;
                }
            };
            model.forward_kinematics(&q, &mut fk);
            poses_compared += 1;
            for (name, m) in &c.poses {
                let Ok(id) = model.link_id(name) else {
                    fk_failures.push(format!("{}: link '{name}' missing", e.file));
                    continue;
                };
                let h = fk.pose(id).to_homogeneous();
                let err = (0..16)
                    .map(|k| (h[(k / 4, k % 4)] - m[k]).abs())
                    .fold(0.0, f64::max);
                links_compared += 1;
                if err > worst {
                    worst = err;
                }
                if err > 1e-9 {
                    fk_failures.push(format!("{}: link '{name}' differs by {err:.3e}", e.file));
                }
            }
        }
    }
    println!("| collection | URDF files | yourdfpy loads | Tsukami loads (kinematics) | both | Tsukami --strict | Tsukami, collision meshes required |");
    println!("|---|---|---|---|---|---|---|");
    let mut total = Tally::default();
    for (name, t) in &tallies {
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} |",
            t.files, t.reference, t.tsukami, t.both, t.strict, t.with_collision
        );
        total.files += t.files;
        total.reference += t.reference;
        total.tsukami += t.tsukami;
        total.both += t.both;
        total.strict += t.strict;
        total.with_collision += t.with_collision;
    }
    println!(
        "| total | {} | {} | {} | {} | {} | {} |",
        total.files, total.reference, total.tsukami, total.both, total.strict, total.with_collision
    );
    println!("\nwarnings by kind: {warnings:?}");
    println!(
        "FK: {links_compared} link poses over {poses_compared} configurations, worst |ΔT| {worst:.2e}"
    );
    println!("\nrefused by Tsukami ({}):", refused.len());
    for r in &refused {
        println!("- {r}");
    }
    let mut seen = std::collections::BTreeSet::new();
    for f in &fk_failures {
        if seen.insert(f.split(':').next().unwrap_or_default().to_string()) {
            println!("FK mismatch: {f}");
        }
    }
    let rate = total.both as f64 / total.reference.max(1) as f64;
    assert!(
        rate >= 0.98,
        "only {:.1} % of the reference's files load",
        100.0 * rate
    );
    assert!(
        fk_failures.is_empty(),
        "{} FK mismatches",
        fk_failures.len()
    );
    assert!(Path::new(&corpus).is_dir());
}
