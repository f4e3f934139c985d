//! What the commands tell the user on stderr: notes ("loading scene"),
//! progress, and with `-v` more detail; nothing with `-q`. Off a terminal
//! (batch jobs, logs) progress is plain lines, one per stage and per tenth
//! of it, instead of a progress bar. Standard output carries only the
//! command's result (text or JSON).

use std::io::IsTerminal;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU8, Ordering};
use std::time::Instant;

use crate::render::{Progress, Stage};

/// Prints the scene's precision warning ([`crate::scene::LocalFrame::warning`]),
/// if any, and its input warnings ([`crate::scene::LoadedScene::warnings`])
/// to stderr.
pub fn warn_about_frame(s: &crate::scene::LoadedScene) {
    for w in s.frame.warning().iter().chain(&s.warnings) {
        eprintln!("irsig: warning: {w}");
    }
}

/// Prints warnings about the inputs to stderr, or with `--strict` refuses
/// them (an error listing them).
pub fn warn_or_refuse(warnings: &[String], strict: bool) -> anyhow::Result<()> {
    if strict && !warnings.is_empty() {
        anyhow::bail!("{} (refused with --strict)", warnings.join("; "));
    }
    for w in warnings {
        eprintln!("irsig: warning: {w}");
    }
    Ok(())
}

/// 0: quiet, 1: normal, 2: verbose.
static LEVEL: AtomicU8 = AtomicU8::new(1);

/// Sets the level from the global `-q`/`-v` flags (`-q` wins).
pub fn set_level(quiet: bool, verbose: u8) {
    let level = if quiet { 0 } else { 1 + verbose.min(1) };
    LEVEL.store(level, Ordering::Relaxed);
}

/// A note on stderr ("irsig: loading scene"), unless `-q`.
pub fn note(msg: &str) {
    if LEVEL.load(Ordering::Relaxed) >= 1 {
        eprintln!("irsig: {msg}");
    }
}

/// A detail on stderr, only with `-v`.
pub fn detail(msg: &str) {
    if LEVEL.load(Ordering::Relaxed) >= 2 {
        eprintln!("irsig: {msg}");
    }
}

/// The name of a stage in progress lines.
pub fn stage_name(s: Stage) -> &'static str {
    match s {
        Stage::Trace => "tracing (blocks)",
        Stage::Thermal => "temperatures (samples)",
        Stage::Radiometry => "radiometry (samples)",
    }
}

/// The plain-line form of progress (off a terminal): one line when a stage
/// first starts and one each time it passes another tenth, nothing else.
/// A frame is rendered band by band, so the stages alternate (trace,
/// temperatures, radiometry, trace, ...); each stage's count runs on across
/// its bands, and coming back to a stage prints nothing. With `verbose`,
/// each return to a stage is a line too (where it stands). Reports may come
/// from any worker thread and out of order, so a stage's position only
/// grows.
#[derive(Default)]
pub struct ProgressLines {
    verbose: bool,
    /// Per stage (trace, thermal, radiometry): (units done, tenths printed).
    stages: [Option<(u64, u64)>; 3],
    current: Option<Stage>,
}

fn stage_index(s: Stage) -> usize {
    match s {
        Stage::Trace => 0,
        Stage::Thermal => 1,
        Stage::Radiometry => 2,
    }
}

impl ProgressLines {
    /// Progress reporting on stderr; `verbose` adds a line per stage.
    pub fn new(verbose: bool) -> ProgressLines {
        ProgressLines {
            verbose,
            ..Default::default()
        }
    }

    /// The lines (without the `irsig: ` prefix and the time) that report
    /// `p` calls for: none, a stage start, or a tenth passed.
    pub fn lines(&mut self, p: Progress) -> Vec<String> {
        let mut out = Vec::new();
        let tenths = |done: u64| (done * 10).checked_div(p.total).unwrap_or(10).min(10);
        let name = stage_name(p.stage);
        let switched = self.current != Some(p.stage);
        self.current = Some(p.stage);
        let slot = &mut self.stages[stage_index(p.stage)];
        match slot {
            None => {
                out.push(format!("{name} started, 0/{}", p.total));
                *slot = Some((0, 0));
            }
            Some((done, _)) if switched && self.verbose => {
                out.push(format!("{name} resumed at {done}/{}", p.total));
            }
            _ => {}
        }
        let (done, printed) = slot.as_mut().expect("set above");
        if p.done > *done {
            *done = p.done;
            let t = tenths(p.done);
            if t > *printed {
                *printed = t;
                out.push(format!("{name} {}/{} ({} %)", p.done, p.total, t * 10));
            }
        }
        out
    }
}

/// Progress of a render on stderr: a bar on a terminal, else plain lines
/// ([`ProgressLines`]: the stage starts and each tenth done, with the
/// elapsed time).
pub struct ProgressReporter {
    bar: Option<indicatif::ProgressBar>,
    /// The bar's stage and position (the bar only moves forward).
    state: Mutex<(Option<Stage>, [u64; 3])>,
    lines: Mutex<ProgressLines>,
    start: Instant,
}

impl ProgressReporter {
    /// A reporter, or `None` with `-q`.
    pub fn new() -> Option<ProgressReporter> {
        let level = LEVEL.load(Ordering::Relaxed);
        if level == 0 {
            return None;
        }
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = indicatif::ProgressBar::new(0);
            bar.set_style(
                indicatif::ProgressStyle::with_template(
                    "irsig: {msg:<22} [{bar:32}] {pos}/{len} {elapsed_precise} (eta {eta})",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            bar
        });
        Some(ProgressReporter {
            bar,
            state: Mutex::new((None, [0; 3])),
            lines: Mutex::new(ProgressLines::new(level >= 2)),
            start: Instant::now(),
        })
    }

    /// Reports one progress event (a bar on a terminal, lines otherwise).
    pub fn report(&self, p: Progress) {
        match &self.bar {
            Some(b) => {
                let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
                let i = stage_index(p.stage);
                if st.0 != Some(p.stage) {
                    st.0 = Some(p.stage);
                    b.set_message(stage_name(p.stage));
                    b.set_length(p.total);
                    b.set_position(st.1[i]);
                }
                if p.done > st.1[i] {
                    st.1[i] = p.done;
                    b.set_position(p.done);
                }
            }
            None => {
                let mut l = self.lines.lock().unwrap_or_else(|e| e.into_inner());
                for line in l.lines(p) {
                    eprintln!("irsig: {line}, {:.1} s", self.start.elapsed().as_secs_f64());
                }
            }
        }
    }

    /// Ends the progress bar, if one is shown.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
