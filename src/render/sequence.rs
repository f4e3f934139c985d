//! Sequences of frames: one frame per local clock time (the paper's
//! Fig. 12) or one per value of a scene key (a sweep, Figs. 13 and 14).
//!
//! A sequence is planned first ([`plan_sequence`], [`plan_sweep`]: a list
//! of [`FramePlan`]s, every sweep value's scene loaded and so validated
//! before any frame is rendered), then rendered frame by frame by the
//! iterator [`Frames`], which yields each [`SequenceFrame`] (its planes in
//! memory, its time, sun and what it shared with the frame before) without
//! writing anything; [`crate::output::sequence`] writes frames, the contact
//! sheet and `index.json`.
//!
//! The work shared between frames is done once: a sequence prepares the
//! static part (geometry, BVH, materials, band, atmosphere) once and only
//! the conditions (weather forcing, sun samples, thermal cache) per frame;
//! a sweep re-derives the static part per value with [`derive_static`],
//! which shares the geometry, tracer and atmosphere table whenever the
//! value leaves them unchanged.

use std::path::Path;

use anyhow::{Context, bail};
use chrono::{NaiveDate, NaiveDateTime, NaiveTime};

use super::frame::ProgressFn;
use super::image::{Rendered, render_at};
use super::prepare::{Reused, Static, derive_static};
use crate::scene::LoadedScene;
use crate::scene::spec::TimeSpec;
use crate::trace::Backend;

/// Most frames one sequence or sweep may render.
pub const MAX_FRAMES: usize = 1000;

/// The local times from `from` to `to` (inclusive when a step lands on it),
/// `step_s` seconds apart (> 0); at most [`MAX_FRAMES`].
pub fn time_steps(
    from: NaiveDateTime,
    to: NaiveDateTime,
    step_s: i64,
) -> anyhow::Result<Vec<NaiveDateTime>> {
    time_steps_named(TimeNames::CLI, from, to, step_s)
}

/// What the caller calls the start, end and step of a time range, for
/// its errors: the CLI's flags, the Python arguments, a batch spec's keys.
#[derive(Clone, Copy, Debug)]
pub struct TimeNames {
    /// The name of the start (`--from`, `from`, …).
    pub from: &'static str,
    /// The name of the end.
    pub to: &'static str,
    /// The name of the step.
    pub step: &'static str,
}

impl TimeNames {
    /// `irsig sequence --from --to --step`.
    pub const CLI: TimeNames = TimeNames {
        from: "--from",
        to: "--to",
        step: "--step",
    };
    /// `irsig.sequence_times(start=, stop=, step=)`.
    pub const PYTHON: TimeNames = TimeNames {
        from: "start",
        to: "stop",
        step: "step",
    };
    /// A batch spec's `[times]` keys.
    pub const SPEC: TimeNames = TimeNames {
        from: "from",
        to: "to",
        step: "step",
    };
}

/// As [`time_steps`], errors naming the range's parts as `names` do.
pub fn time_steps_named(
    names: TimeNames,
    from: NaiveDateTime,
    to: NaiveDateTime,
    step_s: i64,
) -> anyhow::Result<Vec<NaiveDateTime>> {
    let TimeNames {
        from: f,
        to: t,
        step: st,
    } = names;
    if step_s < 1 {
        bail!("{st} {step_s} s: expected a positive step");
    }
    if to < from {
        bail!("{t} {to} is before {f} {from}");
    }
    let span = (to - from).num_seconds();
    let n = span / step_s + 1;
    if n as usize > MAX_FRAMES {
        bail!("{f} {from} {t} {to} {st} {step_s} s would give {n} frames; at most {MAX_FRAMES}");
    }
    Ok((0..n)
        .map(|k| from + chrono::Duration::seconds(k * step_s))
        .collect())
}

/// Parses a duration such as `1h`, `30min`, `1h30m`, `90s`, `0.5h` into
/// whole seconds (> 0).
pub fn parse_step_s(s: &str) -> anyhow::Result<i64> {
    parse_step_s_named("--step", s)
}

/// As [`parse_step_s`], errors naming the step `name` (`step` in Python
/// and batch specs). Steps longer than a year are refused.
pub fn parse_step_s_named(name: &str, s: &str) -> anyhow::Result<i64> {
    let err = || {
        anyhow::anyhow!(
            "{name} {s:?}: expected a positive duration of at most a year, such as 1h, 30min, \
             1h30m or 90s"
        )
    };
    let t = s.trim();
    let mut total = 0.0;
    let mut rest = t;
    if rest.is_empty() {
        return Err(err());
    }
    while !rest.is_empty() {
        let num_end = rest
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .ok_or_else(err)?;
        let value: f64 = rest[..num_end].parse().map_err(|_| err())?;
        rest = &rest[num_end..];
        let unit_end = rest
            .find(|c: char| c.is_ascii_digit() || c == '.')
            .unwrap_or(rest.len());
        let scale = match rest[..unit_end].trim() {
            "h" | "hr" | "hrs" | "hour" | "hours" => 3600.0,
            "m" | "min" | "mins" | "minute" | "minutes" => 60.0,
            "s" | "sec" | "secs" | "second" | "seconds" => 1.0,
            _ => return Err(err()),
        };
        total += value * scale;
        rest = &rest[unit_end..];
    }
    let secs = total.round();
    if !(1.0..=366.0 * 86400.0).contains(&secs) {
        return Err(err());
    }
    Ok(secs as i64)
}

/// Parses a local time: `HH:MM[:SS]` on `date`, or a full local date-time
/// (`YYYY-MM-DDTHH:MM[:SS]`, a space instead of `T` accepted).
pub fn parse_local_time(flag: &str, s: &str, date: NaiveDate) -> anyhow::Result<NaiveDateTime> {
    let t = s.trim();
    for f in ["%H:%M", "%H:%M:%S"] {
        if let Ok(tm) = NaiveTime::parse_from_str(t, f) {
            return Ok(date.and_time(tm));
        }
    }
    for f in [
        "%Y-%m-%dT%H:%M",
        "%Y-%m-%dT%H:%M:%S",
        "%Y-%m-%d %H:%M",
        "%Y-%m-%d %H:%M:%S",
    ] {
        if let Ok(dt) = NaiveDateTime::parse_from_str(t, f) {
            use chrono::Datelike;
            crate::bounds::time::YEAR
                .check(dt.year().into())
                .map_err(|m| anyhow::anyhow!("{flag} {s:?}: {m}"))?;
            return Ok(dt);
        }
    }
    bail!(
        "{flag} {s:?}: expected a local clock time HH:MM[:SS] (on the scene's image date {date}) \
         or a local date-time YYYY-MM-DDTHH:MM[:SS]"
    )
}

/// One planned frame.
pub struct FramePlan {
    /// The value label (sweep value as given, or local time
    /// `YYYY-MM-DDTHH:MM:SS`).
    pub value: String,
    /// File stem of the frame's outputs inside an output folder.
    pub stem: String,
    /// The frame's scene; `None`: the previous frame's static part as is.
    pub scene: Option<LoadedScene>,
    /// Local image time; `None`: the scene's `[time]`.
    pub local: Option<NaiveDateTime>,
    /// What identifies the frame's result: the frame's scene as loaded
    /// (every key, as JSON), its value and local time. A finished frame on
    /// disk that records the same job need not be rendered again (files
    /// the scene names, e.g. OBJ meshes or weather, are not part of it).
    pub job: serde_json::Value,
}

/// The job of a frame of `scene` with `value` at `local`.
fn job_of(scene: &LoadedScene, value: &str, local: NaiveDateTime) -> serde_json::Value {
    serde_json::json!({
        "scene": serde_json::to_value(&scene.scene).unwrap_or_default(),
        "value": value,
        "local_time": local.format("%Y-%m-%dT%H:%M:%S").to_string(),
    })
}

/// One frame per local time of `scene` (the static part prepared once).
/// File stems are `frame_HHMM` when all times fall on one day at whole
/// minutes, `frame_YYYYMMDDTHHMMSS` otherwise.
pub fn plan_sequence(scene: LoadedScene, times: &[NaiveDateTime]) -> Vec<FramePlan> {
    let one_day = times.iter().all(|t| t.date() == times[0].date());
    let whole_minutes = times.iter().all(|t| chrono::Timelike::second(t) == 0);
    let jobs: Vec<serde_json::Value> = times
        .iter()
        .map(|t| job_of(&scene, &t.format("%Y-%m-%dT%H:%M:%S").to_string(), *t))
        .collect();
    let mut scene = Some(scene);
    times
        .iter()
        .zip(jobs)
        .map(|(t, job)| FramePlan {
            value: t.format("%Y-%m-%dT%H:%M:%S").to_string(),
            stem: if one_day && whole_minutes {
                t.format("frame_%H%M").to_string()
            } else {
                t.format("frame_%Y%m%dT%H%M%S").to_string()
            },
            scene: scene.take(),
            local: Some(*t),
            job,
        })
        .collect()
}

/// One frame per value of the dotted scene `key` (TOML values, e.g. `4.47`
/// or an inline table), applied to the scene text `text` of the file at
/// `path` (as read, with any other edits applied: see [`scene_text`];
/// `overrides` are the `--set` ones already in `text`, named in errors).
/// Every value's scene is loaded, and so validated, here. File stems are
/// `NN_<last key part>_<value>`.
pub fn plan_sweep(
    path: &Path,
    text: &str,
    overrides: &[(String, String)],
    key: &str,
    values: &[&str],
) -> anyhow::Result<Vec<FramePlan>> {
    let given = key;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(|p| p.trim().is_empty()) {
        bail!("--key {given:?}: expected a dotted scene key such as weather.constant.wind_m_s");
    }
    if values.iter().all(|v| v.trim().is_empty()) {
        bail!("--values is empty: expected comma-separated values, e.g. --values 0,4.47,8.94");
    }
    if let Some(i) = values.iter().position(|v| v.trim().is_empty()) {
        bail!(
            "--values {:?}: value {} is empty: expected comma-separated values, e.g. 0,4.47,8.94",
            values.join(","),
            i + 1
        );
    }
    if values.len() > MAX_FRAMES {
        bail!(
            "--values gives {} frames; at most {MAX_FRAMES}",
            values.len()
        );
    }
    check_pose_key(text, key)?;
    let last = key.rsplit('.').next().unwrap_or(key);
    values
        .iter()
        .map(|v| v.trim())
        .enumerate()
        .map(|(i, v)| -> anyhow::Result<FramePlan> {
            let set = (key.to_string(), v.to_string());
            let t = crate::scene::apply_overrides(path, text, std::slice::from_ref(&set))?;
            let all: Vec<(String, String)> = overrides.iter().cloned().chain([set]).collect();
            let scene = crate::scene::load_edited(path, t, &all)
                .with_context(|| format!("sweep --key {key} = {v}"))?;
            Ok(FramePlan {
                value: v.to_string(),
                stem: format!("{i:02}_{}_{}", sanitise(last), sanitise(v)),
                job: job_of(&scene, v, scene.scene.time.local),
                scene: Some(scene),
                local: None,
            })
        })
        .collect()
}

/// The text of the scene file `path` with the keys `unset` removed, then
/// the `overrides` (key, TOML value) applied.
pub fn scene_text(
    path: &Path,
    unset: &[String],
    overrides: &[(String, String)],
) -> anyhow::Result<String> {
    let text = crate::files::read_text(path, crate::bounds::sizes::MAX_TEXT_FILE_BYTES)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let text = if unset.is_empty() {
        text
    } else {
        crate::scene::remove_keys(path, &text, unset)?
    };
    Ok(crate::scene::apply_overrides(path, &text, overrides)?)
}

/// A swept key inside one pose table (`sensor.pose.<kind>.…`) while the
/// scene has another pose table is an error that says how to switch.
fn check_pose_key(text: &str, key: &str) -> anyhow::Result<()> {
    let parts: Vec<&str> = key.split('.').map(str::trim).collect();
    let ["sensor", "pose", kind, _, ..] = parts.as_slice() else {
        return Ok(());
    };
    let Ok(doc) = text.parse::<toml_edit::DocumentMut>() else {
        return Ok(()); // the loader reports bad TOML
    };
    let others: Vec<String> = doc
        .get("sensor")
        .and_then(|s| s.as_table_like())
        .and_then(|s| s.get("pose"))
        .and_then(|p| p.as_table_like())
        .map(|p| {
            p.iter()
                .map(|(k, _)| k.to_string())
                .filter(|k| k != kind)
                .collect()
        })
        .unwrap_or_default();
    if let Some(o) = others.first() {
        bail!(
            "--key {key}: the scene's pose is [sensor.pose.{o}], and a pose has exactly one table; \
             switch with --unset sensor.pose.{o} and --set sensor.pose.{kind}.<key>=<value> for its \
             other keys, or give the whole pose: --set 'sensor.pose={{{kind}={{...}}}}'"
        );
    }
    Ok(())
}

/// Keeps letters, digits, `.`, `+`, `-`; anything else becomes `_`.
pub fn sanitise(s: &str) -> String {
    let t: String = s
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-') {
                c
            } else {
                '_'
            }
        })
        .take(40)
        .collect();
    if t.is_empty() { "_".into() } else { t }
}

/// One rendered frame of a sequence or sweep, with what describes it.
pub struct SequenceFrame {
    /// 0-based position in the plan.
    pub index: usize,
    /// The plan's value label.
    pub value: String,
    /// The plan's file stem.
    pub stem: String,
    /// Local image time.
    pub local: NaiveDateTime,
    /// What this frame shared with the frame before.
    pub reused: Reused,
    /// The image: planes, statistics, UTC time, sun, band.
    pub image: Rendered,
}

impl SequenceFrame {
    /// Render time (trace + thermal + radiometry + sensor), s.
    pub fn seconds(&self) -> f64 {
        let s = &self.image.frame.stats.seconds;
        s.trace + s.thermal + s.radiometry + s.sensor
    }

    /// Plane `name` (an error if the render gave none).
    pub fn plane(&self, name: &str) -> anyhow::Result<&crate::render::planes::Plane> {
        self.image
            .frame
            .planes
            .get(name)
            .ok_or_else(|| anyhow::anyhow!("render gave no {name} plane"))
    }
}

/// Renders planned frames one after another (each parallel inside, in the
/// current rayon pool), deriving each frame's static part from the one
/// before; an iterator of [`SequenceFrame`]s. Nothing is written.
pub struct Frames {
    plans: std::vec::IntoIter<FramePlan>,
    tracer: Option<Backend>,
    st: Option<Static>,
    /// The scene of a skipped plan, for the frames after it.
    pending: Option<LoadedScene>,
    next: usize,
    total: usize,
    /// Keep each frame's samples ([`Static::keep_samples`]); default false.
    pub keep_samples: bool,
}

impl Frames {
    /// The frames of `plans` (the first must have a scene), traced with
    /// `tracer` (default: each scene's `render.tracer`).
    pub fn new(plans: Vec<FramePlan>, tracer: Option<Backend>) -> Frames {
        Frames {
            total: plans.len(),
            plans: plans.into_iter(),
            tracer,
            st: None,
            pending: None,
            next: 0,
            keep_samples: false,
        }
    }

    /// The plan of the next frame.
    pub fn peek(&self) -> Option<&FramePlan> {
        self.plans.as_slice().first()
    }

    /// Passes over the next frame without rendering it (e.g. because it is
    /// finished on disk); its scene serves the frames after it. Returns
    /// whether there was one.
    pub fn skip_next(&mut self) -> bool {
        let Some(plan) = self.plans.next() else {
            return false;
        };
        if plan.scene.is_some() {
            self.pending = plan.scene;
        }
        self.next += 1;
        true
    }

    /// Number of frames planned.
    pub fn total(&self) -> usize {
        self.total
    }

    /// The next frame, rendered with a progress callback (the iterator's
    /// `next` is `next_with(None)`).
    pub fn next_with(&mut self, progress: ProgressFn) -> Option<anyhow::Result<SequenceFrame>> {
        let plan = self.plans.next()?;
        let r = self.render_next(plan, progress);
        self.next += 1;
        Some(r)
    }

    fn render_next(
        &mut self,
        plan: FramePlan,
        progress: ProgressFn,
    ) -> anyhow::Result<SequenceFrame> {
        let i = self.next;
        let value = plan.value;
        if plan.scene.is_some() {
            self.pending = None;
        }
        let reused = match plan.scene.or_else(|| self.pending.take()) {
            Some(scene) => {
                let (mut s, r) = derive_static(self.st.as_ref(), scene, self.tracer)?;
                s.keep_samples = self.keep_samples;
                self.st = Some(s);
                r
            }
            None => Reused {
                geometry: true,
                atmosphere: true,
            },
        };
        let Some(st) = self.st.as_ref() else {
            bail!("frame {} ({value}): the first frame has no scene", i + 1);
        };
        let sc = &st.scene.scene;
        let local = plan.local.unwrap_or(sc.time.local);
        let utc = TimeSpec { local }.utc(&sc.site);
        let image =
            render_at(st, utc, progress).with_context(|| format!("frame {} ({value})", i + 1))?;
        Ok(SequenceFrame {
            index: i,
            value,
            stem: plan.stem,
            local,
            reused,
            image,
        })
    }
}

impl Iterator for Frames {
    type Item = anyhow::Result<SequenceFrame>;

    fn next(&mut self) -> Option<Self::Item> {
        self.next_with(None)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.plans.size_hint()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use chrono::NaiveDate;

    #[test]
    fn times_step() {
        let d = NaiveDate::from_ymd_opt(2001, 8, 8).unwrap();
        let a = d.and_hms_opt(8, 0, 0).unwrap();
        let b = d.and_hms_opt(15, 0, 0).unwrap();
        let t = time_steps(a, b, 3600).unwrap();
        assert_eq!(t.len(), 8);
        assert_eq!(t[7], b);
        // a step that does not land on --to stops before it
        assert_eq!(time_steps(a, b, 7200).unwrap().len(), 4);
        assert!(time_steps(b, a, 3600).is_err());
        assert!(time_steps(a, b, 1).is_err()); // too many frames
        assert!(time_steps(a, b, 0).is_err());
    }

    #[test]
    fn steps_parse() {
        assert_eq!(parse_step_s("1h").unwrap(), 3600);
        assert_eq!(parse_step_s("30min").unwrap(), 1800);
        assert_eq!(parse_step_s("1h30m").unwrap(), 5400);
        assert_eq!(parse_step_s("90s").unwrap(), 90);
        assert_eq!(parse_step_s("0.5h").unwrap(), 1800);
        for bad in ["", "0h", "h", "1", "1x", "-1h", "1h-"] {
            assert!(parse_step_s(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn times_parse() {
        let d = NaiveDate::from_ymd_opt(2001, 8, 8).unwrap();
        let a = parse_local_time("--from", "08:00", d).unwrap();
        let b = parse_local_time("--to", "2001-08-08T15:00", d).unwrap();
        assert_eq!(a.to_string(), "2001-08-08 08:00:00");
        assert_eq!(time_steps(a, b, 3600).unwrap()[7], b);
        assert!(parse_local_time("--from", "25:00", d).is_err());
    }
}
