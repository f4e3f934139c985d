//! The files of a sequence or sweep ([`crate::render::sequence`]): each
//! frame as `irsig render` writes it (EXR + PNG quicklook + JSON summary),
//! a contact sheet PNG of every frame's `sensor_radiance` under one common
//! stretch, and `index.json` listing the frames with their value and
//! statistics (mean, min, max and standard deviation of band radiance and
//! apparent temperature), so that the phenomena can be read from numbers.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use serde::Serialize;

use super::quicklook::{Stretch, percentile_stretch, to_grey, write_grey_png};
use super::{PlaneStats, frame::write_rendered, write_atomic};
use crate::render::Reused;
use crate::render::sequence::{FramePlan, Frames, SequenceFrame};
use crate::trace::Backend;

/// Pixels between contact-sheet cells.
pub const GAP_PX: u32 = 4;

/// One frame of the index.
#[derive(Clone, Debug, Serialize)]
pub struct FrameEntry {
    pub index: usize,
    /// The swept value as given (sweep) or the local time (sequence).
    pub value: String,
    /// The value as a number when it is one.
    pub value_number: Option<f64>,
    pub local_time: String,
    pub image_time_utc: String,
    pub exr: String,
    pub png: String,
    pub json: String,
    pub sun_zenith_deg: f64,
    pub sun_azimuth_deg: f64,
    pub band_radiance_w_m2_sr_um: PlaneStats,
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
            image_time_utc: r.image_time_utc.to_rfc3339(),
            exr: format!("{}.exr", f.stem),
            png: format!("{}.png", f.stem),
            json: format!("{}.json", f.stem),
            sun_zenith_deg: r.sun_zenith_deg,
            sun_azimuth_deg: r.sun_azimuth_deg,
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
    pub file: String,
    pub plane: String,
    pub unit: String,
    pub stretch: String,
    pub stretch_lo: f32,
    pub stretch_hi: f32,
    pub columns: u32,
    pub rows: u32,
    pub cell_width_px: u32,
    pub cell_height_px: u32,
    pub gap_px: u32,
    pub order: String,
}

/// `index.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Index {
    pub command: String,
    pub scene: String,
    /// The swept key (sweep only).
    pub key: Option<String>,
    pub band: String,
    pub contact_sheet: SheetInfo,
    pub frames: Vec<FrameEntry>,
}

/// An 8-bit grey image of frames tiled row-major under one stretch.
#[derive(Clone, Debug)]
pub struct ContactSheet {
    pub width: u32,
    pub height: u32,
    /// Row-major grey values (gaps and unused cell area are 0).
    pub grey: Vec<u8>,
    pub stretch: Stretch,
    pub columns: u32,
    pub rows: u32,
    pub cell_width: u32,
    pub cell_height: u32,
    pub gap: u32,
}

/// Tiles equally sized or smaller frames (`(width, height, data)`) into a
/// grid of ⌈√n⌉ columns under the stretch `s`, `gap` pixels apart.
pub fn tile_sheet(frames: &[(u32, u32, &[f32])], s: Stretch, gap: u32) -> ContactSheet {
    let n = frames.len().max(1) as u32;
    let cols = (n as f64).sqrt().ceil() as u32;
    let rows = n.div_ceil(cols);
    let cw = frames.iter().map(|f| f.0).max().unwrap_or(1);
    let ch = frames.iter().map(|f| f.1).max().unwrap_or(1);
    let (w, h) = (cols * cw + (cols - 1) * gap, rows * ch + (rows - 1) * gap);
    let mut grey = vec![0u8; (w * h) as usize];
    for (k, (fw, fh, data)) in frames.iter().enumerate() {
        let (c, r) = (k as u32 % cols, k as u32 / cols);
        let (x0, y0) = (c * (cw + gap), r * (ch + gap));
        let g = to_grey(data, s);
        for y in 0..*fh {
            let dst = ((y0 + y) * w + x0) as usize;
            let src = (y * fw) as usize;
            grey[dst..dst + *fw as usize].copy_from_slice(&g[src..src + *fw as usize]);
        }
    }
    ContactSheet {
        width: w,
        height: h,
        grey,
        stretch: s,
        columns: cols,
        rows,
        cell_width: cw,
        cell_height: ch,
        gap,
    }
}

/// The contact sheet of frames (`(width, height, data)`) under one 2-98 %
/// percentile stretch of all their values together, [`GAP_PX`] apart.
pub fn contact_sheet(frames: &[(u32, u32, &[f32])]) -> ContactSheet {
    let all: Vec<f32> = frames.iter().flat_map(|q| q.2.iter().copied()).collect();
    let stretch = percentile_stretch(&all);
    drop(all);
    tile_sheet(frames, stretch, GAP_PX)
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
}

/// Writes frames as they come, then the contact sheet and `index.json`.
pub struct SequenceWriter {
    out: SequenceOutput,
    entries: Vec<FrameEntry>,
    quicklooks: Vec<(u32, u32, Vec<f32>)>,
    band: String,
}

impl SequenceWriter {
    /// Checks and creates the output folder.
    pub fn new(out: SequenceOutput) -> anyhow::Result<SequenceWriter> {
        let dir = &out.dir;
        if dir.extension().is_some_and(|e| e == "exr" || e == "png") {
            bail!(
                "-o {}: expected an output folder, not a file",
                dir.display()
            );
        }
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        Ok(SequenceWriter {
            out,
            entries: Vec::new(),
            quicklooks: Vec::new(),
            band: String::new(),
        })
    }

    /// The path of a frame's EXR.
    pub fn exr_path(&self, f: &SequenceFrame) -> PathBuf {
        self.out.dir.join(format!("{}.exr", f.stem))
    }

    /// Writes one frame's files; returns its index entry.
    pub fn write(&mut self, f: &SequenceFrame) -> anyhow::Result<&FrameEntry> {
        let o = &self.out;
        let frame_info = serde_json::json!({
            "command": o.command,
            "index": f.index,
            "key": o.key,
            "value": f.value,
            "local_time": f.local.format("%Y-%m-%dT%H:%M:%S").to_string(),
        });
        write_rendered(&self.exr_path(f), &f.image, o.envi, Some(frame_info))?;
        let entry = FrameEntry::of(f)?;
        let p = &f.image.frame.planes;
        let ql = f.plane("sensor_radiance")?.data.clone();
        self.quicklooks.push((p.width, p.height, ql));
        self.band = f.image.band.clone();
        self.entries.push(entry);
        Ok(self.entries.last().expect("just pushed"))
    }

    /// Writes the contact sheet and `index.json`; returns the index.
    pub fn finish(self) -> anyhow::Result<Index> {
        let o = &self.out;
        let n = self.entries.len();
        let views: Vec<(u32, u32, &[f32])> = self
            .quicklooks
            .iter()
            .map(|(w, h, d)| (*w, *h, d.as_slice()))
            .collect();
        let sheet = contact_sheet(&views);
        let stretch_text = format!(
            "linear, 2-98 percentile of all frames together: {} .. {} W m-2 sr-1 um-1 -> 0 .. 255",
            sheet.stretch.lo, sheet.stretch.hi
        );
        let labels: Vec<&str> = self.entries.iter().map(|e| e.value.as_str()).collect();
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
        write_grey_png(
            &o.dir.join("contact_sheet.png"),
            width,
            height,
            &sheet.grey,
            &format!(
                "irsig {what}; plane sensor_radiance; {n} frames row-major in {cols} columns x {rows} rows \
                 of {cw}x{ch} px with {GAP_PX} px gaps; common stretch for all frames: {stretch_text}"
            ),
        )?;
        let index = Index {
            command: o.command.clone(),
            scene: o.scene.clone(),
            key: o.key.clone(),
            band: self.band,
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
            frames: self.entries,
        };
        let json = serde_json::to_string_pretty(&index)?;
        write_atomic(&o.dir.join("index.json"), |w| {
            std::io::Write::write_all(w, json.as_bytes()).map_err(|e| e.to_string())
        })?;
        Ok(index)
    }
}

/// Renders the planned frames (in the current rayon pool) and writes them,
/// the contact sheet and `index.json` into `out.dir`, as `irsig sequence`
/// and `irsig sweep` do; `on_frame(frame, entry, exr path)` is called after
/// each frame is written (progress). Returns the index.
pub fn write_sequence(
    plans: Vec<FramePlan>,
    tracer: Option<Backend>,
    out: SequenceOutput,
    on_frame: &mut dyn FnMut(&SequenceFrame, &FrameEntry, &Path),
) -> anyhow::Result<Index> {
    let mut w = SequenceWriter::new(out)?;
    for f in Frames::new(plans, tracer) {
        let f = f?;
        let exr = w.exr_path(&f);
        let entry = w.write(&f)?;
        on_frame(&f, entry, &exr);
    }
    w.finish()
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
        assert_eq!(t.grey[0], 0); // frame a
        assert_eq!(t.grey[3], 255); // frame b, right of the 1-px gap
        assert_eq!(t.grey[3 * 5], 128); // frame c, below
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
