//! Compiles the vendored Qhull (`vendor/qhull/libqhull_r`) and its one entry point
//! (`csrc/hull.c`) with the `cc` crate: a C compiler is all this needs.

const QHULL_DIR: &str = "vendor/qhull/libqhull_r";
const QHULL_SOURCES: [&str; 14] = [
    "geom2_r.c",
    "geom_r.c",
    "global_r.c",
    "io_r.c",
    "libqhull_r.c",
    "mem_r.c",
    "merge_r.c",
    "poly2_r.c",
    "poly_r.c",
    "qset_r.c",
    "random_r.c",
    "stat_r.c",
    "user_r.c",
    "usermem_r.c",
];

fn main() {
    let mut build = cc::Build::new();
    for file in QHULL_SOURCES {
        build.file(format!("{QHULL_DIR}/{file}"));
    }
    build
        .file("csrc/hull.c")
        .include(QHULL_DIR)
        // Hull construction is the hot path of Ferrari–Canny; optimise it even
        // in debug builds, and keep Qhull's own warnings out of ours.
        .opt_level(2)
        .warnings(false)
        .compile("tsukami_qhull");
    println!("cargo:rerun-if-changed=csrc/hull.c");
    println!("cargo:rerun-if-changed={QHULL_DIR}");
}
