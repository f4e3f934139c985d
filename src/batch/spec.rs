//! The batch spec (`irsig batch plan SPEC.toml`): scenes, and the product
//! of time ranges, sweeps over scene keys and random draws that expands
//! into one frame per combination. Read with [`TomlSource`], so that every
//! error names the file, the line and the key. The format is documented in
//! `docs/batch.md`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::scene::error::SceneError;
use crate::scene::tomlsrc::{Seg, TomlSource};

/// Most frames one batch may expand to (a manifest line is ~0.5 kB; one
/// million frames is a 0.5 GB manifest and a month of core-hours).
pub const MAX_BATCH_FRAMES: usize = 1_000_000;

/// A batch spec as written.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BatchSpec {
    /// A name for the batch (job names, titles); default: the spec's file
    /// stem.
    #[serde(default)]
    pub name: Option<String>,
    /// Default number of shards (Slurm array tasks); default 1.
    #[serde(default = "one")]
    pub shards: usize,
    /// The scenes; every frame combination is rendered for each.
    #[serde(rename = "scene")]
    pub scenes: Vec<SceneEntry>,
    /// Local image times (absent: each scene's own `[time]`).
    #[serde(default)]
    pub time: Option<TimeRange>,
    /// Sweeps over scene keys; their product.
    #[serde(default, rename = "sweep")]
    pub sweeps: Vec<Sweep>,
    /// Random draws (training data): `count` frames per scene, each with
    /// every `vary` key drawn anew.
    #[serde(default)]
    pub random: Option<Random>,
    /// Every frame's PNG quicklook and the merged contact sheet span at
    /// least this many kelvin of apparent temperature (default 2; as
    /// `irsig render --quicklook-min-span-k`, the same bound).
    #[serde(default)]
    pub quicklook_min_span_k: Option<f64>,
    /// Their colour map: `grey` (default) or `inferno`.
    #[serde(default)]
    pub colormap: Option<crate::output::quicklook::Colormap>,
}

fn one() -> usize {
    1
}

/// One scene of the batch.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneEntry {
    /// The scene file, relative to the spec's folder.
    pub path: PathBuf,
    /// Label in frame ids and the merged stack; default: the file stem.
    #[serde(default)]
    pub id: Option<String>,
    /// Fixed overrides for every frame of this scene (dotted key → TOML
    /// value), as `irsig render --set`.
    #[serde(default)]
    pub set: BTreeMap<String, toml::Value>,
}

/// Local clock times: `from`..`to` every `step`, or the list `at`.
/// Clock times (`HH:MM`) fall on each scene's image date.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeRange {
    /// First clock time (`HH:MM`), with `to` and `step`.
    #[serde(default)]
    pub from: Option<String>,
    /// Last clock time (`HH:MM`), inclusive.
    #[serde(default)]
    pub to: Option<String>,
    /// Interval, e.g. `"1h"` (as `irsig sequence --step`).
    #[serde(default)]
    pub step: Option<String>,
    /// Or the clock times as a list.
    #[serde(default)]
    pub at: Option<Vec<String>>,
}

/// A sweep: one frame per value of a dotted scene key.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// The dotted scene key (as `--set` takes it).
    pub key: String,
    /// Its values, one frame each.
    pub values: Vec<toml::Value>,
}

/// Random draws.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Random {
    /// Draws per scene.
    pub count: usize,
    /// Seed of the ChaCha8 generator: same seed, same frames.
    #[serde(default)]
    pub seed: u64,
    /// The keys drawn for every frame.
    pub vary: Vec<Vary>,
}

/// One randomly drawn key: uniform over `range` (numbers, or `HH:MM`
/// clock times for the key `time`) or uniform over the list `choice`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vary {
    /// The dotted scene key (or `time`).
    pub key: String,
    /// Uniform over [lo, hi].
    #[serde(default)]
    pub range: Option<[toml::Value; 2]>,
    /// Or uniform over these values.
    #[serde(default)]
    pub choice: Option<Vec<toml::Value>>,
}

/// A spec read from its file, kept with its text for located errors.
pub struct SpecFile {
    /// The spec's text, for located errors.
    pub src: TomlSource,
    /// The spec as parsed.
    pub spec: BatchSpec,
}

/// The key path of a spec item, for [`TomlSource::invalid`].
pub fn at(parts: &[&str]) -> Vec<Seg> {
    parts
        .iter()
        .map(|p| match p.parse::<usize>() {
            Ok(i) => Seg::Index(i),
            Err(_) => Seg::Key(p.to_string()),
        })
        .collect()
}

impl SpecFile {
    /// Reads and checks the structure of a spec (types, unknown keys,
    /// empty lists, ranges).
    pub fn read(path: &Path) -> Result<SpecFile, SceneError> {
        let src = TomlSource::read(path)?;
        let spec: BatchSpec = src.parse()?;
        let f = SpecFile { src, spec };
        f.check()?;
        Ok(f)
    }

    /// The folder relative scene paths start from.
    pub fn base_dir(&self) -> PathBuf {
        match self.src.path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        }
    }

    /// The batch's name: `name`, or the spec file's stem.
    pub fn name(&self) -> String {
        self.spec.name.clone().unwrap_or_else(|| {
            self.src
                .path
                .file_stem()
                .map_or("batch".into(), |s| s.to_string_lossy().into_owned())
        })
    }

    fn bad(&self, path: &[&str], msg: String) -> SceneError {
        self.src.invalid(&at(path), msg)
    }

    fn check(&self) -> Result<(), SceneError> {
        let s = &self.spec;
        if s.scenes.is_empty() {
            return Err(self.bad(
                &[],
                "no [[scene]]: expected at least one scene, e.g. [[scene]] path = \"airfield.toml\""
                    .into(),
            ));
        }
        if let Some(k) = s.quicklook_min_span_k {
            crate::bounds::args::QUICKLOOK_MIN_SPAN_K
                .check(k)
                .map_err(|m| self.bad(&["quicklook_min_span_k"], m))?;
        }
        if !(1..=10_000).contains(&s.shards) {
            return Err(self.bad(
                &["shards"],
                format!("shards = {}: expected 1 to 10000", s.shards),
            ));
        }
        for (i, sc) in s.scenes.iter().enumerate() {
            let i = i.to_string();
            if let Some(id) = &sc.id
                && !valid_label(id)
            {
                return Err(self.bad(
                    &["scene", &i, "id"],
                    format!("id {id:?}: expected 1-40 letters, digits, '.', '+', '-' or '_'"),
                ));
            }
            for k in sc.set.keys() {
                check_key(k).map_err(|m| self.bad(&["scene", &i, "set"], m))?;
            }
        }
        if let Some(t) = &s.time {
            let range = t.from.is_some() || t.to.is_some() || t.step.is_some();
            match (&t.at, range) {
                (Some(_), true) => {
                    return Err(self.bad(
                        &["time", "at"],
                        "[time]: give either `at = [...]` or `from`/`to`/`step`, not both".into(),
                    ));
                }
                (Some(at), false) if at.is_empty() => {
                    return Err(self.bad(
                        &["time", "at"],
                        "[time] at = []: an empty list gives no frames; expected at least one time"
                            .into(),
                    ));
                }
                (None, true) if t.from.is_none() || t.to.is_none() || t.step.is_none() => {
                    return Err(self.bad(
                        &["time"],
                        "[time]: expected all of from, to and step (e.g. from = \"08:00\", to = \"15:00\", step = \"1h\")"
                            .into(),
                    ));
                }
                (None, false) => {
                    return Err(self.bad(
                        &["time"],
                        "[time] is empty: expected `at = [...]` or from/to/step".into(),
                    ));
                }
                _ => {}
            }
        }
        for (i, sw) in s.sweeps.iter().enumerate() {
            let i = i.to_string();
            check_key(&sw.key).map_err(|m| self.bad(&["sweep", &i, "key"], m))?;
            if sw.values.is_empty() {
                return Err(self.bad(
                    &["sweep", &i, "values"],
                    format!(
                        "sweep over {}: values = [] gives no frames; expected at least one value",
                        sw.key
                    ),
                ));
            }
        }
        if let Some(r) = &s.random {
            if r.count == 0 {
                return Err(self.bad(
                    &["random", "count"],
                    "[random] count = 0 gives no frames; expected at least 1".into(),
                ));
            }
            if r.vary.is_empty() {
                return Err(self.bad(
                    &["random", "vary"],
                    "[random]: expected at least one [[random.vary]] key".into(),
                ));
            }
            for (i, v) in r.vary.iter().enumerate() {
                let i = i.to_string();
                if v.key != "time" {
                    check_key(&v.key).map_err(|m| self.bad(&["random", "vary", &i, "key"], m))?;
                }
                match (&v.range, &v.choice) {
                    (Some(_), Some(_)) | (None, None) => {
                        return Err(self.bad(
                            &["random", "vary", &i],
                            format!(
                                "random key {}: expected exactly one of range = [lo, hi] or choice = [...]",
                                v.key
                            ),
                        ));
                    }
                    (None, Some(c)) if c.is_empty() => {
                        return Err(self.bad(
                            &["random", "vary", &i, "choice"],
                            format!("random key {}: choice = [] is empty", v.key),
                        ));
                    }
                    (Some([lo, hi]), None) if v.key != "time" => {
                        let (Some(a), Some(b)) = (number(lo), number(hi)) else {
                            return Err(self.bad(
                                &["random", "vary", &i, "range"],
                                format!("random key {}: range = [lo, hi] must be numbers", v.key),
                            ));
                        };
                        if !(a.is_finite() && b.is_finite() && a <= b) {
                            return Err(self.bad(
                                &["random", "vary", &i, "range"],
                                format!(
                                    "random key {}: range [{a}, {b}]: expected finite lo <= hi",
                                    v.key
                                ),
                            ));
                        }
                    }
                    _ => {}
                }
            }
        }
        Ok(())
    }
}

/// A TOML number as f64.
pub fn number(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(f) => Some(*f),
        _ => None,
    }
}

/// The text of a spec value as an override value (`irsig render --set`
/// syntax: TOML, strings quoted) and as a label (strings bare).
pub fn override_text(v: &toml::Value) -> (String, String) {
    match v {
        toml::Value::String(s) => (toml::Value::String(s.clone()).to_string(), s.clone()),
        other => (other.to_string(), other.to_string()),
    }
}

/// A dotted scene key: non-empty parts; `time` is reserved for the image
/// time.
fn check_key(k: &str) -> Result<(), String> {
    if k.trim().is_empty() || k.split('.').any(|p| p.trim().is_empty()) {
        return Err(format!(
            "key {k:?}: expected a dotted scene key such as weather.constant.wind_m_s"
        ));
    }
    if k == "time" || k.starts_with("time.") {
        return Err(format!(
            "key {k:?}: image times are set by [time] (or a random key `time`), not a scene key"
        ));
    }
    Ok(())
}

/// Labels used in file names: 1-40 of `[A-Za-z0-9._+-]`.
fn valid_label(s: &str) -> bool {
    (1..=40).contains(&s.len())
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-' | '_'))
}
