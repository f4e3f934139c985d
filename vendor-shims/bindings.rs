// Shared by build.rs and tests/embree4_shim.rs (via `include!`): how the Rust
// bindings for the Embree shim are generated, and how the shim is compiled.

/// Runs bindgen over `vendor-shims/irsig_embree.h` against the Embree headers
/// in `include_dir` (the folder that holds `embree3/` or `embree4/`).
#[allow(dead_code)]
fn irsig_bindings(
    shim_dir: &std::path::Path,
    include_dir: &std::path::Path,
    embree4: bool,
) -> Result<bindgen::Bindings, String> {
    let mut b = bindgen::Builder::default()
        .header(shim_dir.join("irsig_embree.h").to_string_lossy().into_owned())
        .clang_arg(format!("-I{}", include_dir.display()))
        .allowlist_function("rtc.*")
        .allowlist_function("irsig_.*")
        .allowlist_type("RTC.*")
        .allowlist_var("RTC_.*")
        .derive_default(true)
        .derive_debug(true)
        .layout_tests(false)
        .generate_comments(false)
        .prepend_enum_name(false);
    if embree4 {
        b = b.clang_arg("-DIRSIG_EMBREE4");
    }
    // bindgen panics when libclang cannot be loaded; turn that into an error.
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || b.generate())) {
        Ok(Ok(bindings)) => Ok(bindings),
        Ok(Err(e)) => Err(format!("bindgen failed on the Embree headers in {}: {e}", include_dir.display())),
        Err(_) => Err("bindgen could not load libclang: install the Debian package `libclang-dev` (or set LIBCLANG_PATH)".to_string()),
    }
}
