//! Writes the generated test meshes used by `irsig crosscheck` in the set-up
//! and in CI: `scenes/meshes/mixed.obj` (shared-edge grid, boxes, slivers,
//! coplanar overlap, degenerate triangles) and `scenes/meshes/bench.obj`
//! (the 5,000-triangle benchmark scene). `cargo run --example gen_meshes`.

use irsig::trace::meshgen;

fn main() -> std::io::Result<()> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/meshes");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(dir.join("mixed.obj"), meshgen::mixed_scene().to_obj())?;
    std::fs::write(dir.join("bench.obj"), meshgen::bench_scene().to_obj())?;
    Ok(())
}
