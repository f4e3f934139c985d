//! A render opens its weather file once (issue 31): the load (the site's
//! station when the scene leaves its coordinates out), the warnings (the
//! station's distance, the sunlight check), the atmosphere's choice with
//! `model = "auto"` and every frame of a sequence share the loaded scene's
//! weather record. The count is `irsig::files::opened_count`, kept by the
//! one reader every input file goes through, for a copy of the weather file
//! that no other test reads.

use std::path::Path;

use irsig::render::prepare::prepare_static;
use irsig::render::render_at;
use irsig::render::weather::weather_warnings;

#[test]
fn a_render_opens_its_weather_file_once() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let weather = dir.path().join("once-tmy3.csv");
    std::fs::copy(
        root.join("scenes/airfield/weather/greensboro-nc-tmy3-2001-08-04_09.csv"),
        &weather,
    )
    .unwrap();
    let set = |k: &str, v: String| (k.to_string(), v);
    let overrides = [
        set(
            "weather.file.path",
            format!("{:?}", weather.display().to_string()),
        ),
        set("weather.file.stand_in", "false".into()),
        set("atmosphere.model", "\"auto\"".into()),
        set("sensor.width_px", "8".into()),
        set("sensor.height_px", "8".into()),
        // The scene's own allowance (its shared material library) and the
        // copy's folder.
        set(
            "files.allow",
            format!("[\"..\", {:?}]", dir.path().display().to_string()),
        ),
    ];
    let unset = [
        "site.latitude_deg".to_string(),
        "site.longitude_deg".to_string(),
    ];
    let scene =
        irsig::scene::load_with_edits(&root.join("scenes/airfield/scene.toml"), &unset, &overrides)
            .unwrap();
    // The site came from the file's station (read at load).
    assert!((scene.scene.site.location.latitude_deg - 36.1).abs() < 0.1);
    assert_eq!(irsig::files::opened_count(&weather), 1);
    let warnings = weather_warnings(&scene).unwrap();
    let st = prepare_static(scene, None).unwrap();
    let t = st.scene.scene.time.utc(&st.scene.scene.site);
    for k in 0..2 {
        render_at(&st, t + chrono::Duration::hours(k), None).unwrap();
    }
    assert_eq!(
        irsig::files::opened_count(&weather),
        1,
        "the weather file was opened more than once (warnings: {warnings:?})"
    );
}
