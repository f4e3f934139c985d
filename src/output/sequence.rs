//! The files of a sequence or sweep ([`crate::render::sequence`]): each
//! frame as `irsig render` writes it (EXR + PNG quicklook + JSON summary),
//! a contact sheet PNG of every frame's `sensor_radiance` under one common
//! stretch, and `index.json` listing the frames with their value and
//! statistics (mean, min, max and standard deviation of band radiance and
//! apparent temperature), so that the phenomena can be read from numbers.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::{Deserialize, Serialize};

use super::exr::read_exr;
use super::frame::{QuicklookOptions, min_span_radiance};
use super::frame::{read_complete, write_rendered};
use super::quicklook::{
    QuicklookStyle, Stretch, percentile_stretch, with_min_span, write_quicklook_described,
};
use super::{OutputError, OutputSet, PlaneStats};
use crate::render::Reused;
use crate::render::sequence::{FramePlan, Frames, SequenceFrame};
use crate::trace::Backend;

/// Pixels between contact-sheet cells.
pub const GAP_PX: u32 = 4;

/// One frame of the index.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FrameEntry {
    /// Frame number (0-based, in order).
    pub index: usize,
    /// The swept value as given (sweep) or the local time (sequence).
    pub value: String,
    /// The value as a number when it is one.
    pub value_number: Option<f64>,
    /// Local image time as the scene states it.
    pub local_time: String,
    /// Image time, RFC 3339 UTC.
    pub image_time_utc: String,
    /// The frame's EXR file (beside the index).
    pub exr: String,
    /// The frame's PNG quicklook.
    pub png: String,
    /// The frame's JSON summary.
    pub json: String,
    /// Sun zenith angle, degrees.
    pub sun_zenith_deg: f64,
    /// Sun azimuth, degrees clockwise from north.
    pub sun_azimuth_deg: f64,
    /// The frame's band.
    pub band: String,
    /// Statistics of the band radiance, W m⁻² sr⁻¹ µm⁻¹.
    pub band_radiance_w_m2_sr_um: PlaneStats,
    /// Statistics of the apparent temperature, K.
    pub apparent_temperature_k: PlaneStats,
    /// What this frame shared with the frame before.
    pub reused: Reused,
    /// Render time (trace + thermal + radiometry + sensor), s.
    pub seconds: f64,
}

impl FrameEntry {
    /// The index entry of `f` (file names from its stem).
    pub fn of(f: &SequenceFrame) -> anyhow::Result<FrameEntry> {
        let r = &f.image;
        Ok(FrameEntry {
            index: f.index,
            value_number: f.value.parse().ok(),
            value: f.value.clone(),
            local_time: f.local.format("%Y-%m-%dT%H:%M:%S").to_string(),
            image_time_utc: r
                .image_time_utc
                .to_rfc3339_opts(chrono::SecondsFormat::Secs, true),
            exr: format!("{}.exr", f.stem),
            png: format!("{}.png", f.stem),
            json: format!("{}.json", f.stem),
            sun_zenith_deg: r.sun_zenith_deg,
            sun_azimuth_deg: r.sun_azimuth_deg,
            band: r.band.clone(),
            band_radiance_w_m2_sr_um: f.plane("band_radiance")?.stats(),
            apparent_temperature_k: f.plane("apparent_temperature")?.stats(),
            reused: f.reused,
            seconds: f.seconds(),
        })
    }
}

/// The contact sheet's layout and stretch.
#[derive(Clone, Debug, Serialize)]
pub struct SheetInfo {
    /// The contact sheet's PNG.
    pub file: String,
    /// The plane shown.
    pub plane: String,
    /// Its unit.
    pub unit: String,
    /// How the stretch was chosen.
    pub stretch: String,
    /// Value drawn black.
    pub stretch_lo: f32,
    /// Value drawn white.
    pub stretch_hi: f32,
    /// Cells across.
    pub columns: u32,
    /// Cells down.
    pub rows: u32,
    /// Cell width, pixels.
    pub cell_width_px: u32,
    /// Cell height, pixels.
    pub cell_height_px: u32,
    /// Gap between cells, pixels.
    pub gap_px: u32,
    /// The order of the frames in the grid.
    pub order: String,
}

/// `index.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Index {
    /// The command that wrote it (`sequence`, `sweep`).
    pub command: String,
    /// The scene file.
    pub scene: String,
    /// The swept key (sweep only).
    pub key: Option<String>,
    /// The band.
    pub band: String,
    /// The contact sheet.
    pub contact_sheet: SheetInfo,
    /// Every frame, in order.
    pub frames: Vec<FrameEntry>,
}

/// Frames tiled row-major, and the one stretch they are shown under.
#[derive(Clone, Debug)]
pub struct ContactSheet {
    /// Sheet width, pixels.
    pub width: u32,
    /// Sheet height, pixels.
    pub height: u32,
    /// Row-major values (gaps and unused cell area are NaN: no data,
    /// drawn black).
    pub data: Vec<f32>,
    /// The one stretch every cell is shown under.
    pub stretch: Stretch,
    /// Cells across.
    pub columns: u32,
    /// Cells down.
    pub rows: u32,
    /// Cell width, pixels.
    pub cell_width: u32,
    /// Cell height, pixels.
    pub cell_height: u32,
    /// Gap between cells, pixels.
    pub gap: u32,
}

/// Tiles equally sized or smaller frames (`(width, height, data)`) into a
/// grid of ⌈√n⌉ columns, `gap` pixels apart, to be shown under the
/// stretch `s`.
pub fn tile_sheet(frames: &[(u32, u32, &[f32])], s: Stretch, gap: u32) -> ContactSheet {
    let n = frames.len().max(1) as u32;
    let cols = (n as f64).sqrt().ceil() as u32;
    let rows = n.div_ceil(cols);
    let cw = frames.iter().map(|f| f.0).max().unwrap_or(1);
    let ch = frames.iter().map(|f| f.1).max().unwrap_or(1);
    let (w, h) = (cols * cw + (cols - 1) * gap, rows * ch + (rows - 1) * gap);
    let mut tiled = vec![f32::NAN; (w * h) as usize];
    for (k, (fw, fh, data)) in frames.iter().enumerate() {
        let (c, r) = (k as u32 % cols, k as u32 / cols);
        let (x0, y0) = (c * (cw + gap), r * (ch + gap));
        for y in 0..*fh {
            let dst = ((y0 + y) * w + x0) as usize;
            let src = (y * fw) as usize;
            tiled[dst..dst + *fw as usize].copy_from_slice(&data[src..src + *fw as usize]);
        }
    }
    ContactSheet {
        width: w,
        height: h,
        data: tiled,
        stretch: s,
        columns: cols,
        rows,
        cell_width: cw,
        cell_height: ch,
        gap,
    }
}

/// The contact sheet of frames (`(width, height, data)`), [`GAP_PX`]
/// apart, under one stretch: the 2-98 % percentile stretch of all their
/// values together, widened to a span of at least `min_span` (the data's
/// units; see [`with_min_span`]), as a single render's quicklook is.
pub fn contact_sheet(frames: &[(u32, u32, &[f32])], min_span: f32) -> ContactSheet {
    let all: Vec<f32> = frames.iter().flat_map(|q| q.2.iter().copied()).collect();
    let stretch = with_min_span(percentile_stretch(&all), min_span);
    drop(all);
    tile_sheet(frames, stretch, GAP_PX)
}

/// The smallest stretch span (radiance) of a contact sheet, for
/// `opts.min_span_k` kelvin: [`min_span_radiance`] about the median of the
/// frames' median apparent temperatures (`medians_k`), over the band
/// `band_um` (the first frame's; frames of a band sweep share one span, a
/// display choice).
pub fn sheet_min_span(medians_k: &[f32], band_um: (f64, f64), opts: QuicklookOptions) -> f32 {
    min_span_radiance(medians_k, band_um, opts.min_span_k)
}

/// The median of the finite values of `data` (NaN when there are none).
pub fn median_of(data: &[f32]) -> f32 {
    let mut v: Vec<f32> = data.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return f32::NAN;
    }
    v.sort_by(f32::total_cmp);
    v[v.len() / 2]
}

/// Writes the contact sheet `sheet` as a single render's quicklook is
/// drawn (`opts`' colour map, a colour bar below with the stretch's ends
/// and `caption`), with `what` (the layout) and `min_span` (the smallest
/// span its stretch was widened to) in the PNG's `Description`.
pub fn write_contact_sheet(
    set: &mut OutputSet,
    path: &Path,
    sheet: &ContactSheet,
    min_span: f32,
    opts: QuicklookOptions,
    caption: &str,
    what: &str,
) -> Result<(), OutputError> {
    let style = QuicklookStyle {
        colormap: opts.colormap,
        min_span,
        caption: caption.into(),
    };
    write_quicklook_described(
        set,
        path,
        (sheet.width, sheet.height),
        &sheet.data,
        Some(sheet.stretch),
        &style,
        what,
    )?;
    Ok(())
}

/// What a sequence's files are and where they go.
#[derive(Clone, Debug)]
pub struct SequenceOutput {
    /// Output folder (created if needed).
    pub dir: PathBuf,
    /// `sequence` or `sweep` (recorded in the index and each frame).
    pub command: String,
    /// The swept key (sweep only).
    pub key: Option<String>,
    /// The scene file as given (recorded in the index).
    pub scene: String,
    /// Also write an ENVI cube per frame.
    pub envi: bool,
    /// The frames' EXR compression (`None`: each frame's scene's).
    pub exr_compression: Option<super::exr::ExrCompression>,
    /// How every frame's quicklook and the contact sheet are drawn.
    pub quicklook: QuicklookOptions,
}

impl SequenceOutput {
    /// The path of a frame's EXR (its PNG, JSON and ENVI cube beside it).
    pub fn exr_path(&self, plan: &FramePlan) -> PathBuf {
        self.dir.join(format!("{}.exr", plan.stem))
    }

    /// The path of `index.json`, the marker of the whole sequence.
    pub fn index_path(&self) -> PathBuf {
        self.dir.join("index.json")
    }

    /// What a finished frame of `plan` records as its job: the plan's job
    /// (scene, value, time), the command, key, ENVI option, EXR compression
    /// and irsig version.
    pub fn job(&self, plan: &FramePlan) -> serde_json::Value {
        serde_json::json!({
            "irsig": env!("CARGO_PKG_VERSION"),
            "command": self.command,
            "key": self.key,
            "envi": self.envi,
            "exr_compression": self.exr_compression.map(|c| c.name()),
            "plan": plan.job,
        })
    }
}

/// Checks the output folder, creates it, removes stale temporary files of
/// killed runs and the previous `index.json` (the folder is an unfinished
/// sequence until [`write_index`] writes it again). Frames already there
/// are kept: [`frame_complete`] tells which need no rendering.
pub fn begin_sequence(out: &SequenceOutput) -> anyhow::Result<()> {
    let dir = &out.dir;
    if dir.extension().is_some_and(|e| e == "exr" || e == "png") {
        bail!(
            "-o {}: expected an output folder, not a file",
            dir.display()
        );
    }
    super::check_output_dir(dir)?;
    super::set::remove_stale_partials(dir)
        .with_context(|| format!("cannot clean {}", dir.display()))?;
    let index = out.index_path();
    match std::fs::remove_file(&index) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(OutputError::Io {
            path: index,
            reason: e,
        })?,
        _ => Ok(()),
    }
}

/// The index entry of the frame of `plan` when its files in `out.dir` are
/// a complete output set of the same job ([`SequenceOutput::job`]);
/// `None` when the frame must be rendered (missing, interrupted, or made
/// from another scene, value or option).
pub fn frame_complete(out: &SequenceOutput, plan: &FramePlan) -> Option<FrameEntry> {
    let v = read_complete(&out.exr_path(plan).with_extension("json"))?;
    let frame = v.get("frame")?;
    // The recorded job went through JSON text: compare it with the
    // expected job after the same trip.
    let want: serde_json::Value =
        serde_json::from_str(&serde_json::to_string(&out.job(plan)).ok()?).ok()?;
    if frame.get("job")? != &want {
        return None;
    }
    serde_json::from_value(frame.get("entry")?.clone()).ok()
}

/// Writes the frame `f` of `plan` into `out.dir` as one output set (EXR,
/// PNG, ENVI with `out.envi`, and the JSON last, which records the frame's
/// job and index entry); returns the entry.
pub fn write_frame(
    out: &SequenceOutput,
    plan_job: serde_json::Value,
    f: &SequenceFrame,
) -> anyhow::Result<FrameEntry> {
    let entry = FrameEntry::of(f)?;
    let frame_info = serde_json::json!({
        "command": out.command,
        "index": f.index,
        "key": out.key,
        "value": f.value,
        "local_time": f.local.format("%Y-%m-%dT%H:%M:%S").to_string(),
        "job": plan_job,
        "entry": entry,
    });
    let exr = out.dir.join(format!("{}.exr", f.stem));
    let formats = super::frame::Formats {
        exr: true,
        geotiff: false,
        envi: out.envi,
        planes: None,
        exr_compression: out.exr_compression,
        quicklook: out.quicklook,
        ..Default::default()
    };
    write_rendered(&exr, &f.image, formats, Some(frame_info))?;
    Ok(entry)
}

/// The `sensor_radiance` plane of an EXR written by a frame: (width,
/// height, values, the median apparent temperature).
fn quicklook_of(exr: &Path) -> anyhow::Result<(u32, u32, Vec<f32>, f32)> {
    let (w, h, chans) = read_exr(exr).map_err(|e| anyhow::anyhow!("cannot read frame {e}"))?;
    let median_k = chans
        .iter()
        .find(|(n, _)| n == "apparent_temperature")
        .map_or(f32::NAN, |c| median_of(&c.1));
    let data = chans
        .into_iter()
        .find(|(n, _)| n == "sensor_radiance")
        .map(|c| c.1)
        .with_context(|| format!("{}: no sensor_radiance plane", exr.display()))?;
    Ok((w, h, data, median_k))
}

/// The band support (µm) a render's JSON summary records (`band_um`);
/// (0, 0) when it cannot be read (the minimum span is then not applied).
pub fn band_of(summary_json: &Path) -> (f64, f64) {
    let v: Option<serde_json::Value> = std::fs::read_to_string(summary_json)
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let at = |i: usize| {
        v.as_ref()
            .and_then(|v| v["band_um"][i].as_f64())
            .unwrap_or(0.0)
    };
    (at(0), at(1))
}

/// Writes the contact sheet and `index.json` (its marker, last) of the
/// finished frames `entries` (in index order) from their files in
/// `out.dir`, as one output set; returns the index.
pub fn write_index(out: &SequenceOutput, entries: Vec<FrameEntry>) -> anyhow::Result<Index> {
    let o = out;
    let n = entries.len();
    let quicklooks = entries
        .iter()
        .map(|e| quicklook_of(&o.dir.join(&e.exr)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let views: Vec<(u32, u32, &[f32])> = quicklooks
        .iter()
        .map(|(w, h, d, _)| (*w, *h, d.as_slice()))
        .collect();
    let medians: Vec<f32> = quicklooks.iter().map(|q| q.3).collect();
    let band_um = entries
        .first()
        .map_or((0.0, 0.0), |e| band_of(&o.dir.join(&e.json)));
    let min_span = sheet_min_span(&medians, band_um, o.quicklook);
    let sheet = contact_sheet(&views, min_span);
    let stretch_text = format!(
        "linear, 2-98 percentile of all frames together widened to at least {} K of apparent \
         temperature ({min_span} W m-2 sr-1 um-1): {} .. {} W m-2 sr-1 um-1; colour map {}, \
         colour bar below the frames",
        o.quicklook.min_span_k,
        sheet.stretch.lo,
        sheet.stretch.hi,
        o.quicklook.colormap.name()
    );
    let labels: Vec<&str> = entries.iter().map(|e| e.value.as_str()).collect();
    let what = match &o.key {
        Some(k) => format!("sweep of {k} over {}", labels.join(", ")),
        None => format!("sequence at local times {}", labels.join(", ")),
    };
    let ContactSheet {
        width,
        height,
        columns: cols,
        rows,
        cell_width: cw,
        cell_height: ch,
        ..
    } = sheet;
    let index_path = o.index_path();
    let mut set = OutputSet::new(&index_path)?;
    write_contact_sheet(
        &mut set,
        &o.dir.join("contact_sheet.png"),
        &sheet,
        min_span,
        o.quicklook,
        "sensor_radiance [W m-2 sr-1 um-1]",
        &format!(
            "irsig {what}; plane sensor_radiance; {n} frames row-major in {cols} columns x {rows} rows \
             of {cw}x{ch} px with {GAP_PX} px gaps ({width}x{height} px); common stretch for all \
             frames: {stretch_text}"
        ),
    )?;
    let index = Index {
        command: o.command.clone(),
        scene: o.scene.clone(),
        key: o.key.clone(),
        band: entries.first().map(|e| e.band.clone()).unwrap_or_default(),
        contact_sheet: SheetInfo {
            file: "contact_sheet.png".into(),
            plane: "sensor_radiance".into(),
            unit: "W m-2 sr-1 um-1".into(),
            stretch: stretch_text,
            stretch_lo: sheet.stretch.lo,
            stretch_hi: sheet.stretch.hi,
            columns: cols,
            rows,
            cell_width_px: cw,
            cell_height_px: ch,
            gap_px: GAP_PX,
            order: "row-major, frames in index order".into(),
        },
        frames: entries,
    };
    let json = serde_json::to_string_pretty(&index)?;
    set.stage(&index_path, |w| {
        std::io::Write::write_all(w, json.as_bytes()).map_err(|e| e.to_string())
    })?;
    set.commit()?;
    Ok(index)
}

/// What happened to one frame of [`write_sequence`].
pub enum FrameDone<'a> {
    /// Rendered and written now.
    Rendered(&'a SequenceFrame),
    /// Found complete on disk (same job) and not rendered again.
    Skipped,
}

/// Renders the planned frames (in the current rayon pool) that are not
/// already complete in `out.dir` ([`frame_complete`], unless `resume` is
/// false) and writes each as one output set, then the contact sheet and
/// `index.json`, as `irsig sequence` and `irsig sweep` do; so a killed run
/// started again goes on from its finished frames. `on_frame(what, entry,
/// exr path)` is called after each frame (progress). Returns the index.
pub fn write_sequence(
    plans: Vec<FramePlan>,
    tracer: Option<Backend>,
    out: SequenceOutput,
    resume: bool,
    on_frame: &mut dyn FnMut(FrameDone, &FrameEntry, &Path),
) -> anyhow::Result<Index> {
    begin_sequence(&out)?;
    let mut entries = Vec::with_capacity(plans.len());
    let mut frames = Frames::new(plans, tracer);
    while let Some(plan) = frames.peek() {
        let exr = out.exr_path(plan);
        if let Some(entry) = frame_complete(&out, plan).filter(|_| resume) {
            frames.skip_next();
            on_frame(FrameDone::Skipped, &entry, &exr);
            entries.push(entry);
            continue;
        }
        let job = out.job(plan);
        let Some(f) = frames.next() else { break };
        let f = f?;
        let entry = write_frame(&out, job, &f)?;
        on_frame(FrameDone::Rendered(&f), &entry, &exr);
        entries.push(entry);
    }
    write_index(&out, entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sheet_tiles_frames_under_one_stretch() {
        let a = [0.0f32; 4];
        let b = [10.0f32; 4];
        let c = [5.0f32; 4];
        let s = Stretch { lo: 0.0, hi: 10.0 };
        let t = tile_sheet(&[(2, 2, &a[..]), (2, 2, &b[..]), (2, 2, &c[..])], s, 1);
        assert_eq!((t.columns, t.rows, t.width, t.height), (2, 2, 5, 5));
        assert_eq!(t.data[0], 0.0); // frame a
        assert_eq!(t.data[3], 10.0); // frame b, right of the 1-px gap
        assert_eq!(t.data[3 * 5], 5.0); // frame c, below
        assert!(t.data[2].is_nan() && t.data[4 * 5 + 4].is_nan()); // a gap, the empty cell
        // the sheet's stretch: all frames' 2-98 %, widened about its centre
        let sheet = contact_sheet(&[(2, 2, &a[..]), (2, 2, &b[..])], 0.0);
        assert_eq!(sheet.stretch, Stretch { lo: 0.0, hi: 10.0 });
        let wide = contact_sheet(&[(2, 2, &a[..]), (2, 2, &b[..])], 30.0);
        assert_eq!(
            wide.stretch,
            Stretch {
                lo: -10.0,
                hi: 20.0
            }
        );
    }

    #[test]
    fn stats_of_known_values() {
        let s = super::super::plane_stats(&[1.0, 2.0, 3.0, 4.0, f32::NAN]);
        assert_eq!(s.count, 4);
        assert!((s.mean - 2.5).abs() < 1e-12);
        assert!((s.std - 1.25f64.sqrt()).abs() < 1e-12);
        assert_eq!((s.min, s.max), (1.0, 4.0));
    }
}
