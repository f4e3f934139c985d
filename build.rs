//! Finds the system Embree (4 preferred, 3 accepted), runs bindgen over the
//! shim header in `vendor-shims/`, compiles the C shim with `cc` and links.
//! `EMBREE_INCLUDE_DIR` (folder holding `embree4/` or `embree3/`) and
//! `EMBREE_LIB_DIR` override discovery.

use std::path::{Path, PathBuf};

include!("vendor-shims/bindings.rs");

fn fail(msg: &str) -> ! {
    // cargo shows build-script stderr on failure; keep it to one sentence.
    eprintln!("\nirsig build error: {msg}\n");
    std::process::exit(1);
}

/// Returns (include dir, major version).
fn find_embree() -> (PathBuf, u32) {
    let mut candidates: Vec<PathBuf> = Vec::new();
    if let Ok(d) = std::env::var("EMBREE_INCLUDE_DIR") {
        candidates.push(PathBuf::from(d));
    }
    candidates.extend(
        ["/usr/include", "/usr/local/include", "/opt/embree/include"]
            .iter()
            .map(PathBuf::from),
    );
    for major in [4u32, 3] {
        for dir in &candidates {
            if dir.join(format!("embree{major}/rtcore.h")).is_file() {
                return (dir.clone(), major);
            }
        }
    }
    fail(
        "Embree headers not found (looked for embree4/rtcore.h and embree3/rtcore.h): \
         install the Debian package `libembree-dev` or set EMBREE_INCLUDE_DIR",
    )
}

/// The git commit of the source tree (12 hex digits), or "unknown" outside
/// a git checkout (e.g. a crates.io source), for `irsig --version`; tells
/// cargo to rerun when HEAD or the branch it points to moves.
fn git_commit() -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    for r in ["HEAD", "packed-refs"] {
        // Only a file that exists: cargo reruns a build script whose
        // watched path is missing every time (a checkout with no packed
        // refs rebuilt irsig on every cargo call).
        if let Some(p) =
            git(&["rev-parse", "--git-path", r]).filter(|p| std::path::Path::new(p).exists())
        {
            println!("cargo:rerun-if-changed={p}");
        }
    }
    if let Some(p) = git(&["symbolic-ref", "-q", "HEAD"])
        .and_then(|branch| git(&["rev-parse", "--git-path", &branch]))
    {
        println!("cargo:rerun-if-changed={p}");
    }
    git(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_else(|| "unknown".into())
}

/// `RTC_VERSION_STRING` of the Embree headers (e.g. "3.13.5").
fn embree_version(inc: &Path, major: u32) -> String {
    let cfg = inc.join(format!("embree{major}/rtcore_config.h"));
    std::fs::read_to_string(&cfg)
        .ok()
        .and_then(|t| {
            t.lines()
                .filter_map(|l| l.trim().strip_prefix("#define RTC_VERSION_STRING"))
                .map(|v| v.trim().trim_matches('"').to_string())
                .next()
        })
        .unwrap_or_else(|| format!("{major}.x"))
}

fn main() {
    let shim_dir = Path::new("vendor-shims");
    println!("cargo:rustc-env=IRSIG_GIT_COMMIT={}", git_commit());
    println!("cargo:rerun-if-changed=vendor-shims/irsig_embree.h");
    println!("cargo:rerun-if-changed=vendor-shims/irsig_embree.c");
    println!("cargo:rerun-if-changed=vendor-shims/bindings.rs");
    println!("cargo:rerun-if-env-changed=EMBREE_INCLUDE_DIR");
    println!("cargo:rerun-if-env-changed=EMBREE_LIB_DIR");

    let (inc, major) = find_embree();
    let lib = format!("embree{major}");
    let lib_dir = std::env::var("EMBREE_LIB_DIR").ok().map(PathBuf::from);
    if let Some(d) = &lib_dir {
        if !d.is_dir() {
            fail(&format!("EMBREE_LIB_DIR={} is not a folder", d.display()));
        }
        println!("cargo:rustc-link-search=native={}", d.display());
    } else {
        let known = [
            "/usr/lib/x86_64-linux-gnu",
            "/usr/lib/aarch64-linux-gnu",
            "/usr/lib",
            "/usr/local/lib",
            "/usr/lib64",
        ];
        let found = known
            .iter()
            .any(|d| Path::new(d).join(format!("lib{lib}.so")).exists());
        if !found {
            fail(&format!(
                "Embree {major} headers found in {} but lib{lib}.so is not installed: \
                 install the Debian package `libembree-dev` or set EMBREE_LIB_DIR",
                inc.display()
            ));
        }
    }
    println!("cargo:rustc-link-lib=dylib={lib}");
    println!(
        "cargo:rustc-env=IRSIG_EMBREE_VERSION={}",
        embree_version(&inc, major)
    );
    println!("cargo:rustc-cfg=embree_major=\"{major}\"");
    println!("cargo:rustc-check-cfg=cfg(embree_major, values(\"3\", \"4\"))");

    let mut build = cc::Build::new();
    build
        .file(shim_dir.join("irsig_embree.c"))
        .include(&inc)
        .include(shim_dir)
        .opt_level(2)
        .warnings(true);
    if major == 4 {
        build.define("IRSIG_EMBREE4", None);
    }
    build.compile("irsig_embree_shim");

    let bindings = irsig_bindings(shim_dir, &inc, major == 4).unwrap_or_else(|e| fail(&e));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    bindings
        .write_to_file(out.join("embree_bindings.rs"))
        .unwrap_or_else(|e| fail(&format!("cannot write the Embree bindings: {e}")));
}
