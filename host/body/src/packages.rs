//! `package://` resolution: where a robot's meshes live.
//!
//! What: [`PackagePath`], an ordered list of places to look for a ROS package
//! by name, and [`PackagePath::resolve`], which turns `package://PKG/rest`
//! into a file path or says which places it searched.
//!
//! Why: a URDF copied out of its package, or a package installed elsewhere,
//! must still load. ROS users expect `ROS_PACKAGE_PATH` (ROS 1) and
//! `AMENT_PREFIX_PATH` (ROS 2) to work; everyone else needs an explicit
//! option.
//!
//! How: the search order, documented in `docs/robots.md`, is
//! 1. every folder of `ROS_PACKAGE_PATH` ([`PackagePath::with_env`]),
//! 2. `PREFIX/share` of every prefix of `AMENT_PREFIX_PATH`,
//! 3. `--package-dir` folders of the command line, in the order given,
//! 4. the package folders named in the SetRobot request,
//! 5. the URDF's own folder and its ancestors.
//!
//! In a folder `D` of steps 1–4, the package is `D` itself when `D` is named
//! `PKG`, else `D/PKG`, else a folder named `PKG` at most two levels below
//! `D` (ROS workspaces keep packages in `src/...`). An entry `PKG=DIR` maps
//! one package to one folder. In step 5, the package is the nearest ancestor
//! named `PKG`, or `A/PKG` for an ancestor `A`. The library never reads the
//! environment by itself: callers opt in with [`PackagePath::with_env`].
//!
//! ```
//! use tsukami_body::packages::PackagePath;
//! let dir = std::env::temp_dir().join(format!("tsukami-pkg-doc-{}", std::process::id()));
//! std::fs::create_dir_all(dir.join("share/my_robot/meshes")).unwrap();
//! let path = PackagePath::default().with_dirs([dir.join("share")]);
//! let found = path.resolve("my_robot", "meshes/a.stl", "/elsewhere".as_ref()).unwrap();
//! assert_eq!(found, dir.join("share/my_robot/meshes/a.stl"));
//! let err = path.resolve("other", "x.stl", "/elsewhere".as_ref()).unwrap_err();
//! assert!(err.contains(&dir.join("share")));
//! std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::path::{Path, PathBuf};

/// How deep below a search folder a package folder is looked for.
const CRAWL_DEPTH: usize = 2;
/// Most folders listed while crawling one search folder.
const CRAWL_BUDGET: usize = 4096;

/// One place to look for packages.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Entry {
    /// A folder holding packages, or a package folder itself.
    Dir(PathBuf),
    /// One package mapped to one folder (`PKG=DIR`).
    Mapped(String, PathBuf),
}

/// The ordered places where `package://` URIs are looked up (see the module
/// documentation for the order).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PackagePath {
    entries: Vec<Entry>,
}

impl PackagePath {
    /// Appends the folders of `ROS_PACKAGE_PATH`, then `PREFIX/share` for
    /// every prefix of `AMENT_PREFIX_PATH` (steps 1 and 2).
    pub fn with_env(self) -> Self {
        let ros = std::env::var_os("ROS_PACKAGE_PATH");
        let ament = std::env::var_os("AMENT_PREFIX_PATH");
        self.with_env_values(ros.as_deref(), ament.as_deref())
    }

    /// [`PackagePath::with_env`] with the two variables' values given.
    pub fn with_env_values(
        mut self,
        ros_package_path: Option<&std::ffi::OsStr>,
        ament_prefix_path: Option<&std::ffi::OsStr>,
    ) -> Self {
        if let Some(v) = ros_package_path {
            self.entries.extend(
                std::env::split_paths(v)
                    .filter(|p| !p.as_os_str().is_empty())
                    .map(Entry::Dir),
            );
        }
        if let Some(v) = ament_prefix_path {
            self.entries.extend(
                std::env::split_paths(v)
                    .filter(|p| !p.as_os_str().is_empty())
                    .map(|p| Entry::Dir(p.join("share"))),
            );
        }
        self
    }

    /// Appends folders (steps 3 and 4). A folder holds packages or is one; an
    /// entry written `PKG=DIR` maps package `PKG` to `DIR`.
    pub fn with_dirs<P: Into<PathBuf>>(mut self, dirs: impl IntoIterator<Item = P>) -> Self {
        for d in dirs {
            let d: PathBuf = d.into();
            let mapped = d
                .to_str()
                .and_then(|s| s.split_once('='))
                .and_then(|(k, v)| {
                    let plain = !k.is_empty() && !k.contains(['/', '\\']);
                    plain.then(|| Entry::Mapped(k.to_string(), PathBuf::from(v)))
                });
            self.entries.push(mapped.unwrap_or(Entry::Dir(d)));
        }
        self
    }

    /// True when no folder is configured (only the URDF's ancestors are
    /// searched).
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The file `rest` inside package `package`, looked up in the configured
    /// folders, then from `urdf_dir` upwards. On failure, the list of places
    /// searched, in order.
    pub fn resolve(
        &self,
        package: &str,
        rest: &str,
        urdf_dir: &Path,
    ) -> std::result::Result<PathBuf, Vec<PathBuf>> {
        let mut searched = Vec::new();
        let valid = !package.is_empty() && !package.contains(['/', '\\']) && package != "..";
        if valid {
            for entry in &self.entries {
                let found = match entry {
                    Entry::Mapped(name, dir) if name == package => {
                        searched.push(dir.clone());
                        dir.is_dir().then(|| dir.clone())
                    }
                    Entry::Mapped(..) => None,
                    Entry::Dir(dir) => {
                        searched.push(dir.clone());
                        find_package(dir, package)
                    }
                };
                if let Some(pkg) = found {
                    return Ok(join_rest(&pkg, rest));
                }
            }
        }
        for dir in urdf_dir.ancestors() {
            if dir.as_os_str().is_empty() {
                continue;
            }
            searched.push(dir.to_path_buf());
            if dir.file_name().is_some_and(|n| n == package) {
                return Ok(join_rest(dir, rest));
            }
            let nested = dir.join(package);
            if valid && nested.is_dir() {
                return Ok(join_rest(&nested, rest));
            }
        }
        Err(searched)
    }
}

fn join_rest(pkg: &Path, rest: &str) -> PathBuf {
    if rest.is_empty() {
        pkg.to_path_buf()
    } else {
        pkg.join(rest)
    }
}

/// `dir` itself when named `package`, `dir/package`, or a folder named
/// `package` at most [`CRAWL_DEPTH`] levels below (breadth first, sorted, so
/// the result does not depend on the file system's listing order).
fn find_package(dir: &Path, package: &str) -> Option<PathBuf> {
    if dir.file_name().is_some_and(|n| n == package) && dir.is_dir() {
        return Some(dir.to_path_buf());
    }
    let mut level = vec![dir.to_path_buf()];
    let mut budget = CRAWL_BUDGET;
    for _ in 0..=CRAWL_DEPTH {
        let mut next = Vec::new();
        for d in &level {
            let candidate = d.join(package);
            if candidate.is_dir() {
                return Some(candidate);
            }
            let Ok(read) = std::fs::read_dir(d) else {
                continue;
            };
            let mut subs: Vec<PathBuf> = read
                .filter_map(|e| e.ok())
                .filter(|e| e.file_type().is_ok_and(|t| t.is_dir()))
                .map(|e| e.path())
                .filter(|p| {
                    !p.file_name()
                        .is_some_and(|n| n.to_string_lossy().starts_with('.'))
                })
                .take(budget)
                .collect();
            budget = budget.saturating_sub(subs.len());
            subs.sort();
            next.extend(subs);
        }
        if budget == 0 || next.is_empty() {
            break;
        }
        level = next;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("tsukami-pkg-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn order_is_env_then_dirs_then_ancestors() {
        let d = tmp("order");
        for p in [
            "ros/robot",
            "ament/share/robot",
            "cli/robot",
            "ws/src/group/robot",
        ] {
            std::fs::create_dir_all(d.join(p)).unwrap();
        }
        let ros = d.join("ros");
        let ament = d.join("ament");
        let path = PackagePath::default()
            .with_env_values(Some(ros.as_os_str()), Some(ament.as_os_str()))
            .with_dirs([d.join("cli")]);
        assert_eq!(
            path.resolve("robot", "m.stl", Path::new("/x")).unwrap(),
            d.join("ros/robot/m.stl")
        );
        let path = PackagePath::default()
            .with_env_values(None, Some(ament.as_os_str()))
            .with_dirs([d.join("cli")]);
        assert_eq!(
            path.resolve("robot", "m.stl", Path::new("/x")).unwrap(),
            d.join("ament/share/robot/m.stl")
        );
        // A workspace: the package two levels down.
        let ws = PackagePath::default().with_dirs([d.join("ws")]);
        assert_eq!(
            ws.resolve("robot", "a/b.dae", Path::new("/x")).unwrap(),
            d.join("ws/src/group/robot/a/b.dae")
        );
        // PKG=DIR mapping.
        let mapped =
            PackagePath::default().with_dirs([format!("robot={}", d.join("cli").display())]);
        assert_eq!(
            mapped.resolve("robot", "m.stl", Path::new("/x")).unwrap(),
            d.join("cli/m.stl")
        );
        std::fs::remove_dir_all(&d).ok();
    }

    #[test]
    fn ancestors_and_failures_list_what_was_searched() {
        let d = tmp("anc");
        std::fs::create_dir_all(d.join("my_pkg/urdf")).unwrap();
        let none = PackagePath::default();
        assert_eq!(
            none.resolve("my_pkg", "meshes/a.stl", &d.join("my_pkg/urdf"))
                .unwrap(),
            d.join("my_pkg/meshes/a.stl")
        );
        let searched = PackagePath::default()
            .with_dirs([d.join("nowhere")])
            .resolve("other", "a.stl", &d.join("my_pkg/urdf"))
            .unwrap_err();
        assert_eq!(searched[0], d.join("nowhere"));
        assert!(searched.contains(&d.join("my_pkg/urdf")));
        // A package name cannot climb out.
        assert!(PackagePath::default()
            .with_dirs([d.clone()])
            .resolve("..", "etc/passwd", Path::new("/"))
            .is_err());
        std::fs::remove_dir_all(&d).ok();
    }
}
