//! `irsig render <scene> -o <path>.exr|.tif`: renders the scene and writes
//! the EXR or the GeoTIFF (every plane), a PNG quicklook and a JSON summary
//! beside it, and the other formats asked for (`--exr`, `--geotiff`,
//! `--envi`); see [`crate::output::frame`].

use std::path::PathBuf;

use super::log::{ProgressReporter, note};
use crate::output::exr::ExrCompression;
use crate::output::frame::{Formats, MapGrid, QuicklookOptions, write_rendered};
use crate::output::quicklook::Colormap;
use crate::render::{Progress, prepare_conditions, prepare_static, render_conditions};
use crate::trace::Backend;

#[derive(clap::Args, Debug)]
/// `irsig render`: one frame of a scene.
pub struct Args {
    /// The scene file (TOML).
    pub scene: PathBuf,
    /// Output path: `x.exr` (OpenEXR) or `x.tif` (GeoTIFF, with the
    /// float64 geolocation in `x_geo.tif`); the PNG quicklook (.png), the
    /// JSON summary (.json) and the other formats asked for are written
    /// beside it.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Override a scene key before loading, e.g. `--set sensor.band=lwir`
    /// or `--set weather.constant.wind_m_s=4.47` (repeatable). An inline
    /// table replaces a whole table, e.g. the pose of Fig. 14:
    /// `--set 'sensor.pose={slant_range={slant_range_m=10000.0,view_zenith_deg=75.0,azimuth_deg=180.0}}'`.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Remove a scene key (a value or a whole table) before the `--set`
    /// overrides, e.g. `--unset sensor.pose.altitude` to switch pose
    /// tables, or `--unset 'object[1]'` (repeatable).
    #[arg(long = "unset", value_name = "KEY")]
    pub unset: Vec<String>,
    /// Refuse what would only be a warning (a weather station more than
    /// 0.5 deg from the site).
    #[arg(long)]
    pub strict: bool,
    /// Also write ENVI cubes: the radiance cube (x.img/.hdr), the float64
    /// truth cube (x_truth.img) and the material classification
    /// (x_class.img).
    #[arg(long)]
    pub envi: bool,
    /// Also write the georeferenced GeoTIFF (x.tif and x_geo.tif).
    #[arg(long)]
    pub geotiff: bool,
    /// Also write the EXR (x.exr), when -o names a .tif.
    #[arg(long)]
    pub exr: bool,
    /// The north-up map-grid GeoTIFF (x_map.tif, the planes resampled at
    /// the GSD: bilinear, nearest for material/facet/case/dn): `auto`
    /// writes it for nadir views whose transform is rotated (a north-up
    /// view's x.tif is a map grid already; an oblique view's x.tif carries
    /// GCPs and GDAL GEOLOCATION metadata pointing at x_geo.tif); `off`
    /// never.
    #[arg(long, value_enum, default_value_t = MapGrid::Auto, value_name = "auto|off")]
    pub map_grid: MapGrid,
    /// The PNG quicklook's colour map: grey, or inferno (perceptually
    /// uniform); a colour bar with the stretch's ends and the unit is drawn
    /// below the image.
    #[arg(long, value_enum, default_value_t = Colormap::Grey, value_name = "grey|inferno")]
    pub colormap: Colormap,
    /// The quicklook's stretch (2-98 percentiles) spans at least this many
    /// kelvin of apparent temperature about the median (0: never widened),
    /// so a scene with a 1 K contrast is not shown black and white.
    #[arg(long, default_value_t = 2.0, value_name = "K")]
    pub quicklook_min_span_k: f64,
    /// Write only these planes to the EXR and the GeoTIFF (comma-separated,
    /// e.g. `--planes band_radiance,apparent_temperature,material`;
    /// default: all). The PNG, the ENVI cubes and the geolocation are not
    /// affected.
    #[arg(long, value_delimiter = ',', value_name = "PLANE,...")]
    pub planes: Vec<String>,
    /// The EXR's compression, all lossless: none, rle, zips (zlib per scan
    /// line), zip (zlib per 16 lines), piz (wavelet). Default: the scene's
    /// `output.exr_compression`, itself zips by default, chosen by measured
    /// write time and size (BENCHMARKS.md, "EXR compression").
    #[arg(long, value_name = "none|rle|zips|zip|piz")]
    pub exr_compression: Option<ExrCompression>,
    /// Ray-tracing backend (default: the scene's `render.tracer`).
    #[arg(long, value_enum)]
    pub tracer: Option<Backend>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Print the rays cast and skipped, thermal solves and cache hits, the
    /// time per stage and the peak resident memory beside its estimate
    /// (`memory`), as JSON alone on stdout (the "wrote" line goes to
    /// stderr).
    #[arg(long)]
    pub stats: bool,
}

/// Parses `KEY=VALUE` overrides.
pub fn parse_overrides(set: &[String]) -> anyhow::Result<Vec<(String, String)>> {
    set.iter()
        .map(|s| match s.split_once('=') {
            Some((k, v)) if !k.trim().is_empty() => {
                Ok((k.trim().to_string(), v.trim().to_string()))
            }
            _ => anyhow::bail!("--set {s}: expected KEY=VALUE, e.g. --set sensor.band=lwir"),
        })
        .collect()
}

use crate::render::thread_pool;

/// Runs `irsig render`; returns the process exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    // Check the output path before spending time on the render.
    let mut formats =
        Formats::of_path(&a.output, a.exr, a.geotiff, a.envi)?.with_planes(&a.planes)?;
    formats.exr_compression = a.exr_compression;
    formats.map_grid = a.map_grid;
    crate::bounds::args::QUICKLOOK_MIN_SPAN_K
        .check_flag(a.quicklook_min_span_k)
        .map_err(anyhow::Error::msg)?;
    formats.quicklook = QuicklookOptions {
        colormap: a.colormap,
        min_span_k: a.quicklook_min_span_k,
    };
    crate::output::check_output_file(&a.output)?;
    let overrides = parse_overrides(&a.set)?;
    let pool = thread_pool(a.threads)?;
    note("loading scene");
    let scene = crate::scene::load_with_edits(&a.scene, &a.unset, &overrides)?;
    super::log::warn_about_frame(&scene);
    super::log::warn_or_refuse(&crate::render::weather::weather_warnings(&scene)?, a.strict)?;
    let memory = crate::render::memory::estimate(&scene);
    let image = pool.install(|| -> anyhow::Result<_> {
        let st = prepare_static(scene, a.tracer)?;
        let t = st.scene.scene.time.utc(&st.scene.scene.site);
        note("weather, sun and thermal forcing");
        let cond = prepare_conditions(&st, t)?;
        note("rendering");
        let bar = ProgressReporter::new();
        let report = bar.as_ref().map(|b| move |p: Progress| b.report(p));
        let image = render_conditions(
            &st,
            &cond,
            report.as_ref().map(|f| f as &(dyn Fn(Progress) + Sync)),
        )?;
        if let Some(b) = &bar {
            b.finish();
        }
        let implausible = crate::render::plausible::surface_temperature_warnings(
            &st,
            &cond,
            &image.frame.planes,
        )?;
        super::log::warn_or_refuse(&implausible, a.strict)?;
        // On the same pool: the EXR blocks are compressed in parallel.
        write_rendered(&a.output, &image, formats, None)?;
        // (the conditions freed beside the rest of the command; not the
        // scene: Embree's globals must outlive its scene)
        crate::render::drop_in_background(cond);
        Ok(image)
    })?;
    let s = &image.frame.stats;
    let wrote = format!(
        "wrote {} ({}x{}), {:.2} s",
        a.output.display(),
        image.frame.planes.width,
        image.frame.planes.height,
        s.seconds.trace + s.seconds.thermal + s.seconds.radiometry + s.seconds.sensor
    );
    if a.stats {
        // The statistics are the result: JSON alone on stdout.
        note(&wrote);
        let mut v = serde_json::to_value(s)?;
        v["memory"] = serde_json::json!({
            "peak_resident_mib": crate::bench::peak_rss_mib(),
            "estimated_mib": memory.total_mib,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        println!("{wrote}");
    }
    Ok(0)
}
