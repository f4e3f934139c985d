//! Expanding a batch spec into its manifest: one [`FrameJob`] per frame,
//! in scene-major order (scene, then sweep and random combinations, then
//! times innermost), so that consecutive frames share the most static work
//! and a contiguous shard holds as few scenes as possible.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use chrono::{NaiveDateTime, Timelike};
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};

use super::spec::{SpecFile, at, number, override_text};
use crate::render::sequence::{parse_local_time, sanitise};

/// Format of local times in the manifest.
pub const LOCAL_FORMAT: &str = "%Y-%m-%dT%H:%M:%S";

/// One frame of a batch: everything `batch run` needs to render it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrameJob {
    /// Unique id; the outputs' file stem.
    pub id: String,
    /// 0-based position in the manifest.
    pub index: usize,
    /// The scene file (absolute).
    pub scene: PathBuf,
    /// Overrides applied to the scene (dotted key, TOML value), in order.
    pub overrides: Vec<(String, String)>,
    /// Local image time (`YYYY-MM-DDTHH:MM:SS`); `None`: the scene's own.
    pub local_time: Option<String>,
    /// The frame's coordinates: `scene` and every varied dimension (`time`,
    /// sweep and random keys) → its value as a label.
    pub labels: BTreeMap<String, String>,
    /// The random draw's number (0-based, per scene), for a spec with
    /// `[random]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub draw: Option<usize>,
    /// Output files relative to the batch folder.
    pub outputs: Outputs,
}

/// A frame's files, relative to the batch folder.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outputs {
    /// The EXR.
    pub exr: PathBuf,
    /// The PNG quicklook.
    pub png: PathBuf,
    /// The JSON summary (the set's marker).
    pub json: PathBuf,
}

impl Outputs {
    fn of(id: &str) -> Outputs {
        let f = |ext: &str| PathBuf::from("frames").join(format!("{id}.{ext}"));
        Outputs {
            exr: f("exr"),
            png: f("png"),
            json: f("json"),
        }
    }
}

/// A batch: its name, the spec it came from, the default shard count, the
/// dimensions that vary, and the frames.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The batch's name.
    pub name: String,
    /// The spec it was planned from.
    pub spec: PathBuf,
    /// The default shard count.
    pub shards: usize,
    /// The label keys that vary across frames, `scene` first.
    pub dimensions: Vec<String>,
    /// The axes of the batch's product, in order: `scene`, `time` (of
    /// `[time]`), each sweep key, `draw` (of `[random]`); the merged stack's
    /// dimensions where the frames are regular over them.
    pub axes: Vec<String>,
    /// The frames, in manifest order.
    pub frames: Vec<FrameJob>,
    /// How the frames' quicklooks and the contact sheet are drawn (kept in
    /// `batch.json`, see [`super::BatchInfo`]).
    #[serde(skip)]
    pub quicklook: crate::output::frame::QuicklookOptions,
}

/// One axis of the product: (dimension, values as (override or time,
/// label)).
struct Axis {
    dim: String,
    /// (override value text, label)
    values: Vec<(String, String)>,
}

/// Expands a spec (read and checked by [`SpecFile::read`]) into its plan.
/// Every scene is loaded with its fixed overrides, and with each sweep
/// value and each end of every random range, so that a bad key or value
/// fails here, naming the spec's line; ids must be unique.
pub fn plan(spec_path: &Path) -> anyhow::Result<Plan> {
    let sf = SpecFile::read(spec_path)?;
    let spec = &sf.spec;
    let base = sf.base_dir();
    let spec_abs = std::path::absolute(spec_path)
        .with_context(|| format!("cannot resolve {}", spec_path.display()))?;

    let mut frames = Vec::new();
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut dims: Vec<String> = vec!["scene".into()];
    let mut add_dim = |d: &str| {
        if !dims.iter().any(|x| x == d) {
            dims.push(d.to_string());
        }
    };
    if spec.time.is_some() {
        add_dim("time");
    }
    for sw in &spec.sweeps {
        add_dim(&sw.key);
    }
    if let Some(r) = &spec.random {
        for v in &r.vary {
            add_dim(&v.key);
        }
    }
    // The product's axes: scene, time, the sweep keys, and the draw number.
    let mut axes: Vec<String> = dims
        .iter()
        .filter(|d| {
            *d == "scene"
                || (*d == "time" && spec.time.is_some())
                || spec.sweeps.iter().any(|s| s.key == **d)
        })
        .cloned()
        .collect();
    if spec.random.is_some() {
        axes.push("draw".into());
    }
    let n_scenes = spec.scenes.len();
    for (si, entry) in spec.scenes.iter().enumerate() {
        let loc = |k: &str| sf.src.loc_of(&at(&["scene", &si.to_string(), k]));
        let path = base.join(&entry.path);
        let path = std::path::absolute(&path).unwrap_or(path);
        let sid = match &entry.id {
            Some(id) => id.clone(),
            None => sanitise(
                &path
                    .file_stem()
                    .map_or("scene".into(), |s| s.to_string_lossy().into_owned()),
            ),
        };
        let fixed: Vec<(String, String)> = entry
            .set
            .iter()
            .map(|(k, v)| (k.clone(), override_text(v).0))
            .collect();
        let scene = crate::scene::load_with_overrides(&path, &fixed)
            .with_context(|| format!("{}: scene {}", loc("path"), path.display()))?;
        let date = scene.scene.time.local.date();
        // Every sweep value and random bound must load too.
        let check = |extra: (String, String), what: String| -> anyhow::Result<()> {
            let mut ov = fixed.clone();
            ov.push(extra);
            crate::scene::load_with_overrides(&path, &ov)
                .map(|_| ())
                .with_context(|| what)
        };
        let mut axes: Vec<Axis> = Vec::new();
        for (k, sw) in spec.sweeps.iter().enumerate() {
            let vals: Vec<(String, String)> = sw.values.iter().map(override_text).collect();
            for (o, l) in &vals {
                check(
                    (sw.key.clone(), o.clone()),
                    format!(
                        "{}: sweep {} = {l} on scene {}",
                        sf.src.loc_of(&at(&["sweep", &k.to_string(), "values"])),
                        sw.key,
                        path.display()
                    ),
                )?;
            }
            axes.push(Axis {
                dim: sw.key.clone(),
                values: vals,
            });
        }
        // Random draws: one combined axis of `count` draws.
        let mut draws: Vec<Vec<(String, String, String)>> = vec![Vec::new()];
        if let Some(r) = &spec.random {
            for (k, v) in r.vary.iter().enumerate() {
                if v.key == "time" {
                    continue;
                }
                let bounds: Vec<(String, String)> = match (&v.range, &v.choice) {
                    (Some(r), _) => r.iter().map(override_text).collect(),
                    (_, Some(c)) => c.iter().map(override_text).collect(),
                    _ => Vec::new(),
                };
                for (o, l) in bounds {
                    check(
                        (v.key.clone(), o),
                        format!(
                            "{}: random {} = {l} on scene {}",
                            sf.src.loc_of(&at(&["random", "vary", &k.to_string()])),
                            v.key,
                            path.display()
                        ),
                    )?;
                }
            }
            // One generator per scene, seeded from the spec's seed and the
            // scene's position: adding a scene does not change the others.
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(
                r.seed ^ (si as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
            );
            draws = (0..r.count)
                .map(|_| {
                    r.vary
                        .iter()
                        .enumerate()
                        .map(|(k, v)| draw(&sf, k, v, date, &mut rng))
                        .collect::<anyhow::Result<Vec<_>>>()
                })
                .collect::<anyhow::Result<_>>()?;
        }
        let times: Vec<Option<NaiveDateTime>> = match &spec.time {
            None => vec![None],
            Some(t) => {
                let loc = |k: &str| sf.src.loc_of(&at(&["time", k]));
                match &t.at {
                    Some(list) => list
                        .iter()
                        .map(|s| {
                            parse_local_time("at", s, date)
                                .map(Some)
                                .with_context(|| format!("{}", loc("at")))
                        })
                        .collect::<anyhow::Result<_>>()?,
                    None => {
                        let (f, to, st) = (
                            t.from.as_deref().unwrap_or(""),
                            t.to.as_deref().unwrap_or(""),
                            t.step.as_deref().unwrap_or(""),
                        );
                        let from = parse_local_time("from", f, date)
                            .with_context(|| format!("{}", loc("from")))?;
                        let to = parse_local_time("to", to, date)
                            .with_context(|| format!("{}", loc("to")))?;
                        let step = crate::render::sequence::parse_step_s_named("step", st)
                            .with_context(|| format!("{}", loc("step")))?;
                        crate::render::sequence::time_steps_named(
                            crate::render::sequence::TimeNames::SPEC,
                            from,
                            to,
                            step,
                        )
                        .with_context(|| format!("{}", loc("from")))?
                        .into_iter()
                        .map(Some)
                        .collect()
                    }
                }
            }
        };
        let multi_day = times
            .iter()
            .flatten()
            .any(|t| Some(t.date()) != times[0].map(|t0| t0.date()));
        let whole_min = times.iter().flatten().all(|t| t.second() == 0);
        let combos = product(&axes);
        let per_scene = combos.len() * draws.len() * times.len();
        if frames.len() + per_scene * (n_scenes - si) > super::spec::MAX_BATCH_FRAMES {
            bail!(
                "{}: the spec expands to more than {} frames ({} per scene here)",
                sf.src.path.display(),
                super::spec::MAX_BATCH_FRAMES,
                per_scene
            );
        }
        for combo in &combos {
            for (d, drawn) in draws.iter().enumerate() {
                for t in &times {
                    let mut labels = BTreeMap::new();
                    labels.insert("scene".to_string(), sid.clone());
                    let mut overrides = fixed.clone();
                    let mut stem = vec![sid.clone()];
                    for (axis, (o, l)) in axes.iter().zip(combo) {
                        overrides.push((axis.dim.clone(), o.clone()));
                        labels.insert(axis.dim.clone(), l.clone());
                        let last = axis.dim.rsplit('.').next().unwrap_or(&axis.dim);
                        stem.push(format!("{}-{}", sanitise(last), sanitise(l)));
                    }
                    let mut local = *t;
                    if spec.random.is_some() {
                        stem.push(format!("r{d:05}"));
                        for (k, o, l) in drawn {
                            if k == "time" {
                                local = NaiveDateTime::parse_from_str(o, LOCAL_FORMAT).ok();
                            } else {
                                overrides.push((k.clone(), o.clone()));
                            }
                            labels.insert(k.clone(), l.clone());
                        }
                    }
                    if let Some(tt) = t {
                        labels.insert("time".into(), tt.format(LOCAL_FORMAT).to_string());
                        stem.push(if !multi_day && whole_min {
                            tt.format("%H%M").to_string()
                        } else {
                            tt.format("%Y%m%dT%H%M%S").to_string()
                        });
                    }
                    let id = stem.join("_");
                    let index = frames.len();
                    if let Some(&other) = seen.get(&id) {
                        let o: &FrameJob = &frames[other];
                        let at_key = if spec.sweeps.is_empty() {
                            at(&["scene", &si.to_string()])
                        } else {
                            at(&["sweep"])
                        };
                        bail!(
                            "{}: frames {} ({:?}) and {} ({:?}) would both write frames/{id}.*: \
                             give the scenes distinct `id`s or make the sweep values distinct",
                            sf.src.loc_of(&at_key),
                            other + 1,
                            o.labels,
                            index + 1,
                            labels
                        );
                    }
                    seen.insert(id.clone(), index);
                    frames.push(FrameJob {
                        outputs: Outputs::of(&id),
                        id,
                        index,
                        scene: path.clone(),
                        overrides,
                        local_time: local.map(|t| t.format(LOCAL_FORMAT).to_string()),
                        labels,
                        draw: spec.random.is_some().then_some(d),
                    });
                }
            }
        }
    }
    Ok(Plan {
        name: sf.name(),
        spec: spec_abs,
        shards: spec.shards.min(frames.len().max(1)),
        dimensions: dims,
        axes,
        frames,
        quicklook: {
            let d = crate::output::frame::QuicklookOptions::default();
            crate::output::frame::QuicklookOptions {
                colormap: spec.colormap.unwrap_or(d.colormap),
                min_span_k: spec.quicklook_min_span_k.unwrap_or(d.min_span_k),
            }
        },
    })
}

/// The cartesian product of the axes' values (one empty combination when
/// there are no axes), the last axis varying fastest.
fn product(axes: &[Axis]) -> Vec<Vec<(String, String)>> {
    let mut out: Vec<Vec<(String, String)>> = vec![Vec::new()];
    for a in axes {
        out = out
            .into_iter()
            .flat_map(|c| {
                a.values.iter().map(move |v| {
                    let mut c = c.clone();
                    c.push(v.clone());
                    c
                })
            })
            .collect();
    }
    out
}

/// One random value of `v`: (key, override value or local time, label).
/// Numbers from a range are uniform and rounded to 1e-4; times to the whole
/// second.
fn draw(
    sf: &SpecFile,
    k: usize,
    v: &super::spec::Vary,
    date: chrono::NaiveDate,
    rng: &mut rand_chacha::ChaCha8Rng,
) -> anyhow::Result<(String, String, String)> {
    if let Some(c) = &v.choice {
        let (o, l) = override_text(&c[rng.random_range(0..c.len())]);
        if v.key == "time" {
            let t = parse_local_time("time", &l, date).with_context(|| {
                format!(
                    "{}",
                    sf.src.loc_of(&at(&["random", "vary", &k.to_string()]))
                )
            })?;
            let s = t.format(LOCAL_FORMAT).to_string();
            return Ok((v.key.clone(), s.clone(), s));
        }
        return Ok((v.key.clone(), o, l));
    }
    let Some([lo, hi]) = &v.range else {
        bail!("random key {}: no range or choice", v.key);
    };
    if v.key == "time" {
        let loc = || {
            format!(
                "{}",
                sf.src
                    .loc_of(&at(&["random", "vary", &k.to_string(), "range"]))
            )
        };
        let text = |x: &toml::Value| match x {
            toml::Value::String(s) => Ok(s.clone()),
            toml::Value::Datetime(d) => Ok(d.to_string()),
            _ => Err(anyhow::anyhow!(
                "{}: random time range: expected clock times such as \"08:00\"",
                loc()
            )),
        };
        let a = parse_local_time("time", &text(lo)?, date).with_context(loc)?;
        let b = parse_local_time("time", &text(hi)?, date).with_context(loc)?;
        if b < a {
            bail!("{}: random time range: {b} is before {a}", loc());
        }
        let span = (b - a).num_seconds();
        let t = a + chrono::Duration::seconds(rng.random_range(0..=span));
        let s = t.format(LOCAL_FORMAT).to_string();
        return Ok((v.key.clone(), s.clone(), s));
    }
    let (a, b) = (number(lo).unwrap_or(0.0), number(hi).unwrap_or(0.0));
    let x = if b > a { rng.random_range(a..=b) } else { a };
    let x = ((x * 1e4).round() / 1e4).clamp(a, b);
    // Always a TOML float (a whole number keeps its ".0").
    let s = if x.fract() == 0.0 {
        format!("{x:.1}")
    } else {
        format!("{x}")
    };
    Ok((v.key.clone(), s.clone(), s))
}
