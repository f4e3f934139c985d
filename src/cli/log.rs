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

fn stage_name(s: Stage) -> &'static str {
    match s {
        Stage::Trace => "tracing (blocks)",
        Stage::Thermal => "temperatures (samples)",
        Stage::Radiometry => "radiometry (samples)",
    }
}

/// Progress of a render on stderr: a bar on a terminal, else plain lines
/// (the stage, then each tenth done with the elapsed time). Reports may
/// come from any worker thread and out of order, so the position only
/// grows within a stage.
pub struct ProgressReporter {
    bar: Option<indicatif::ProgressBar>,
    /// (stage, units done, tenths printed).
    state: Mutex<Option<(Stage, u64, u64)>>,
    start: Instant,
}

impl ProgressReporter {
    /// A reporter, or `None` with `-q`.
    pub fn new() -> Option<ProgressReporter> {
        if LEVEL.load(Ordering::Relaxed) == 0 {
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
            state: Mutex::new(None),
            start: Instant::now(),
        })
    }

    pub fn report(&self, p: Progress) {
        let mut st = self.state.lock().unwrap_or_else(|e| e.into_inner());
        let tenths = |done: u64| (done * 10).checked_div(p.total).unwrap_or(10);
        match *st {
            Some((stage, done, printed)) if stage == p.stage => {
                if p.done <= done {
                    return;
                }
                let t = tenths(p.done);
                *st = Some((stage, p.done, t.max(printed)));
                match &self.bar {
                    Some(b) => b.set_position(p.done),
                    None if t > printed => eprintln!(
                        "irsig: {} {}/{} ({} %), {:.1} s",
                        stage_name(stage),
                        p.done,
                        p.total,
                        t * 10,
                        self.start.elapsed().as_secs_f64()
                    ),
                    None => {}
                }
            }
            _ => {
                *st = Some((p.stage, p.done, tenths(p.done)));
                match &self.bar {
                    Some(b) => {
                        b.reset();
                        b.set_message(stage_name(p.stage));
                        b.set_length(p.total);
                        b.set_position(p.done);
                    }
                    None => eprintln!(
                        "irsig: {} 0/{}, {:.1} s",
                        stage_name(p.stage),
                        p.total,
                        self.start.elapsed().as_secs_f64()
                    ),
                }
            }
        }
    }

    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
