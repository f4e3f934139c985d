//! The Embree 4 branch of the C shim and its bindgen bindings must compile,
//! even on machines that only have Embree 3 (Debian 12). This compiles
//! `vendor-shims/irsig_embree.c` against the vendored Embree 4.2 headers
//! with the system C compiler, generates the Rust bindings with bindgen and
//! type-checks them with rustc. Nothing is linked.

use std::path::{Path, PathBuf};
use std::process::Command;

include!("../vendor-shims/bindings.rs");

fn tmpdir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("irsig-embree4-check-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn shim_and_bindings_compile_against_embree4_headers() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shim = root.join("vendor-shims");
    let inc = shim.join("embree4-include");
    let out = tmpdir();

    // 1. The C shim, Embree 4 branch.
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let obj = out.join("shim4.o");
    let status = Command::new(&cc)
        .args(["-c", "-Wall", "-Werror", "-DIRSIG_EMBREE4"])
        .arg(format!("-I{}", inc.display()))
        .arg(format!("-I{}", shim.display()))
        .arg(shim.join("irsig_embree.c"))
        .arg("-o")
        .arg(&obj)
        .status()
        .expect("a C compiler (cc) is installed");
    assert!(
        status.success(),
        "the Embree 4 branch of the shim does not compile"
    );

    // 2. The bindings, generated exactly as build.rs does.
    let bindings = irsig_bindings(&shim, &inc, true).expect("bindgen over the Embree 4 headers");
    let text = bindings.to_string();
    assert!(text.contains("pub struct RTCRayHit16"));
    assert!(text.contains("pub fn irsig_intersect16"));
    // Embree 4.2 hits carry instance primitive ids only when configured;
    // the generated header decides, never a hand-written struct.
    let rs = out.join("bindings4.rs");
    std::fs::write(&rs, format!("#![allow(warnings)]\n{text}")).unwrap();

    // 3. Type-check the bindings as a library crate.
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let status = Command::new(rustc)
        .args([
            "--edition",
            "2024",
            "--crate-type",
            "lib",
            "--emit",
            "metadata",
            "--crate-name",
            "embree4_bindings",
        ])
        .arg("--out-dir")
        .arg(&out)
        .arg(&rs)
        .status()
        .expect("rustc is available");
    assert!(
        status.success(),
        "the generated Embree 4 bindings do not compile"
    );
    let _ = std::fs::remove_dir_all(&out);
}
