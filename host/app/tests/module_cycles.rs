//! No file of `host/app/src` imports a file that imports it back, however
//! long the way round.
//!
//! What: the file-level import graph of the library (`src/lib.rs`) and of the
//! binary (`src/main.rs`): an edge from file A to file B when A names an item
//! of B's module through `crate::…`, `super::…` or one of A's own child
//! modules (`children::locate`). The test fails naming every cycle.
//!
//! Why: files that import each other cannot be read, tested or moved one at a
//! time (`server.rs` and `world.rs` once did; the shared query helpers now sit
//! in `reply.rs`, and the demo's shared types in `demo/outcome.rs`).
//!
//! How: the module tree is followed from the crate roots through `mod name;`
//! (and `#[path]`); comments and `#[cfg(test)]` inline modules are left out
//! (a test module's `super::*` is its own file); a path is resolved to the
//! deepest module file it names.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A module's path (`["demo", "report"]`) and its file's text.
type Modules = BTreeMap<Vec<String>, (PathBuf, String)>;

/// The text without comment lines, trailing comments and `#[cfg(test)]` inline modules.
fn code(text: &str) -> String {
    let mut out: String = text
        .lines()
        .map(|l| match l.find("//") {
            Some(i) if !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n");
    while let Some(at) = out.find("#[cfg(test)]") {
        let rest = &out[at..];
        let end = match (rest.find('{'), rest.find(';')) {
            (Some(open), semi) if semi.is_none_or(|s| open < s) => {
                let mut depth = 0usize;
                let close = rest[open..].char_indices().find(|&(_, c)| {
                    depth = if c == '{' {
                        depth + 1
                    } else if c == '}' {
                        depth - 1
                    } else {
                        depth
                    };
                    c == '}' && depth == 0
                });
                open + close.map_or(rest.len() - open, |(i, _)| i + 1)
            }
            (_, Some(semi)) => semi + 1,
            _ => rest.len(),
        };
        out.replace_range(at..at + end, "");
    }
    out
}

/// `mod name;` declarations of a file (with their `#[path]`, if any).
fn declared(text: &str) -> Vec<(String, Option<String>)> {
    let mut path = None;
    let mut out = Vec::new();
    for line in text.lines().map(str::trim) {
        if let Some(p) = line.strip_prefix("#[path = \"") {
            path = p.strip_suffix("\"]").map(str::to_owned);
            continue;
        }
        let decl = line.strip_prefix("pub ").unwrap_or(line);
        let decl = decl.strip_prefix("pub(crate) ").unwrap_or(decl);
        if let Some(name) = decl.strip_prefix("mod ").and_then(|d| d.strip_suffix(';')) {
            out.push((name.to_owned(), path.take()));
        } else if !line.starts_with("#[") {
            path = None;
        }
    }
    out
}

/// Every module of the crate rooted at `root`.
fn modules(root: &Path) -> Modules {
    let mut found = Modules::new();
    let mut todo = vec![(Vec::new(), root.to_owned())];
    while let Some((module, file)) = todo.pop() {
        let text = code(&std::fs::read_to_string(&file).expect("a source file"));
        let own = file
            .file_name()
            .is_some_and(|n| n == "mod.rs" || n == "main.rs" || n == "lib.rs");
        let dir = if own {
            file.parent().unwrap().to_owned()
        } else {
            file.with_extension("")
        };
        for (name, path) in declared(&text) {
            let child = match path {
                Some(p) => file.parent().unwrap().join(p),
                None if dir.join(format!("{name}.rs")).is_file() => dir.join(format!("{name}.rs")),
                None => dir.join(&name).join("mod.rs"),
            };
            let mut m = module.clone();
            m.push(name);
            todo.push((m, child));
        }
        found.insert(module, (file, text));
    }
    found
}

/// The module paths `text` (of module `module`) names: `crate::a::b`,
/// `super::a`, `child::a`, and each branch of a `{…}` group after them.
fn named(text: &str, module: &[String], children: &[String]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let bytes = text.as_bytes();
    let word = |i: usize| i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_');
    let mut i = 0;
    while i < text.len() {
        if word(i) && (i == 0 || !(word(i - 1) || bytes[i - 1] == b':')) {
            let start = i;
            while word(i) {
                i += 1;
            }
            let first = &text[start..i];
            if text[i..].starts_with("::") {
                let base: Option<Vec<String>> = match first {
                    "crate" => Some(Vec::new()),
                    "super" => Some(module[..module.len().saturating_sub(1)].to_vec()),
                    c if children.iter().any(|n| n == c) => {
                        Some([module, &[c.to_owned()]].concat())
                    }
                    _ => None,
                };
                if let Some(base) = base {
                    tree(&text[i + 2..], base, &mut out);
                }
            }
        } else {
            i += 1;
        }
    }
    out
}

/// The paths of the use tree at the start of `rest`, below `base`.
fn tree(rest: &str, mut base: Vec<String>, out: &mut Vec<Vec<String>>) {
    let rest = rest.trim_start();
    if let Some(group) = rest.strip_prefix('{') {
        let (mut depth, mut from) = (0usize, 0usize);
        for (i, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => return tree_item(&group[from..i], &base, out),
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    tree_item(&group[from..i], &base, out);
                    from = i + 1;
                }
                _ => {}
            }
        }
        return;
    }
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    let segment = &rest[..end];
    if segment == "super" {
        base.pop();
    } else if !segment.is_empty() {
        base.push(segment.to_owned());
    }
    match rest[end..].strip_prefix("::") {
        Some(more) => tree(more, base, out),
        None => out.push(base),
    }
}

fn tree_item(item: &str, base: &[String], out: &mut Vec<Vec<String>>) {
    if !item.trim().is_empty() {
        tree(item, base.to_vec(), out);
    }
}

/// The file-level edges of one crate: (from, to) file names relative to `src`.
fn edges(src: &Path, root: &str) -> Vec<(String, String)> {
    let modules = modules(&src.join(root));
    let file_of = |path: &[String]| {
        (0..=path.len())
            .rev()
            .find_map(|n| modules.get(&path[..n]))
            .map(|(f, _)| f.strip_prefix(src).unwrap().display().to_string())
    };
    let mut out = Vec::new();
    for (module, (file, text)) in &modules {
        let children: Vec<String> = declared(text).into_iter().map(|(n, _)| n).collect();
        let from = file.strip_prefix(src).unwrap().display().to_string();
        for path in named(text, module, &children) {
            match file_of(&path) {
                Some(to) if to != from && !out.contains(&(from.clone(), to.clone())) => {
                    out.push((from.clone(), to))
                }
                _ => {}
            }
        }
    }
    out
}

/// The cycles among `edges`, each as its files in order.
fn cycles(edges: &[(String, String)]) -> Vec<Vec<String>> {
    fn walk(
        at: &str,
        edges: &[(String, String)],
        way: &mut Vec<String>,
        found: &mut Vec<Vec<String>>,
    ) {
        if let Some(i) = way.iter().position(|f| f == at) {
            let mut cycle = way[i..].to_vec();
            let min = (0..cycle.len()).min_by_key(|&k| &cycle[k]).unwrap();
            cycle.rotate_left(min);
            if !found.contains(&cycle) {
                found.push(cycle);
            }
            return;
        }
        way.push(at.to_owned());
        for (_, to) in edges.iter().filter(|(f, _)| f == at) {
            walk(to, edges, way, found);
        }
        way.pop();
    }
    let mut found = Vec::new();
    for (from, _) in edges {
        walk(from, edges, &mut Vec::new(), &mut found);
    }
    found
}

#[test]
fn no_file_imports_a_file_that_imports_it_back() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = edges(&src, "lib.rs");
    let bin = edges(&src, "main.rs");
    // The parser sees the imports that are there.
    for edge in [
        ("server.rs", "world.rs"),
        ("world.rs", "reply.rs"),
        ("demo/mod.rs", "demo/report.rs"),
    ] {
        assert!(
            lib.contains(&(edge.0.into(), edge.1.into())),
            "missing edge {edge:?} in {lib:?}"
        );
    }
    assert!(
        bin.contains(&("cli/fc.rs".into(), "cli/fc_problem.rs".into())),
        "{bin:?}"
    );
    let found: Vec<_> = cycles(&lib).into_iter().chain(cycles(&bin)).collect();
    assert!(found.is_empty(), "import cycles between files: {found:?}");
}

#[test]
fn a_cycle_is_found() {
    let e = |a: &str, b: &str| (a.to_owned(), b.to_owned());
    let found = cycles(&[
        e("a.rs", "b.rs"),
        e("b.rs", "c.rs"),
        e("c.rs", "a.rs"),
        e("c.rs", "d.rs"),
    ]);
    assert_eq!(
        found,
        vec![vec!["a.rs".to_owned(), "b.rs".into(), "c.rs".into()]]
    );
    let module = ["demo".to_owned(), "table".to_owned()];
    let paths = named(
        "use super::{step::{Step, X}, outcome::DemoScene};",
        &module,
        &[],
    );
    assert!(
        paths.contains(&vec!["demo".into(), "step".into(), "Step".into()]),
        "{paths:?}"
    );
    assert!(
        paths.contains(&vec!["demo".into(), "outcome".into(), "DemoScene".into()]),
        "{paths:?}"
    );
}
