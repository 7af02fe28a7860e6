//! The host depends on no plugin: no manifest under `host/` names a crate
//! under `plugins/`, by path or by package name.
//!
//! Why: a plugin is loaded from its file, never linked (`docs/plugins.md`, "A
//! plugin is loaded, never linked"); what the host shares with a plugin is a
//! host library (the drawing is `host/render`).

use std::path::{Path, PathBuf};

/// Every `Cargo.toml` below `dir` (not in `target/`).
fn manifests(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a folder").flatten() {
        let path = entry.path();
        if path.is_dir() && !path.ends_with("target") {
            manifests(&path, out);
        } else if path.file_name().is_some_and(|n| n == "Cargo.toml") {
            out.push(path);
        }
    }
}

/// The `name = "…"` of a manifest's `[package]`.
fn package_name(manifest: &Path) -> String {
    let text = std::fs::read_to_string(manifest).expect("a manifest");
    let table: toml::Table = text.parse().expect("TOML");
    table["package"]["name"]
        .as_str()
        .expect("a name")
        .to_owned()
}

#[test]
fn no_host_manifest_names_a_plugin_crate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let (mut host, mut plugins) = (Vec::new(), Vec::new());
    manifests(&root.join("host"), &mut host);
    manifests(&root.join("plugins"), &mut plugins);
    let names: Vec<String> = plugins.iter().map(|m| package_name(m)).collect();
    assert!(
        names.iter().any(|n| n == "tsukami-result-viewer"),
        "{names:?}"
    );
    assert!(host.len() >= 8, "{host:?}");
    for manifest in &host {
        let table: toml::Table = std::fs::read_to_string(manifest).unwrap().parse().unwrap();
        // The manifest itself, and each `[target.'cfg(…)']` table of it.
        let mut tables = vec![&table];
        if let Some(targets) = table.get("target").and_then(|t| t.as_table()) {
            tables.extend(targets.values().filter_map(|t| t.as_table()));
        }
        for (section, deps) in tables.iter().flat_map(|t| {
            ["dependencies", "dev-dependencies", "build-dependencies"]
                .into_iter()
                .filter_map(|s| Some((s, t.get(s)?.as_table()?)))
        }) {
            for (name, spec) in deps {
                let path = spec.get("path").and_then(|p| p.as_str()).unwrap_or("");
                assert!(
                    !names.contains(name) && !path.contains("plugins/"),
                    "{} names the plugin crate {name} in [{section}]",
                    manifest.display()
                );
            }
        }
    }
}
