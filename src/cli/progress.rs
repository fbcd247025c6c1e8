//! Progress bars on stderr: one line per running model showing its stage, and in a
//! batch a bar counting finished models.
//!
//! Bars exist only when they can help: stderr is a terminal, `-Q` was not given and the
//! `CI` variable is unset. Even then nothing is drawn until the work has taken
//! [`REVEAL_AFTER`], so that quick runs leave the terminal as TetGen would. stdout is
//! never touched, and messages printed while bars are shown go through [`Bars::suspend`].

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;
use tetcdt::progress::Stage;

/// How long the work must take before bars appear.
pub const REVEAL_AFTER: Duration = Duration::from_millis(1000);

/// [`REVEAL_AFTER`], unless `TETCDT_PROGRESS_DELAY_MS` says otherwise (tests use 0 to
/// see bars on quick models).
fn reveal_after() -> Duration {
    std::env::var("TETCDT_PROGRESS_DELAY_MS")
        .ok()
        .and_then(|v| v.parse().ok())
        .map_or(REVEAL_AFTER, Duration::from_millis)
}

/// How often spinners move.
const TICK: Duration = Duration::from_millis(120);

/// Whether progress bars are wanted: not quiet, not under CI, stderr a terminal.
pub fn wanted(quiet: bool) -> bool {
    !quiet && std::env::var_os("CI").is_none() && std::io::stderr().is_terminal()
}

/// The progress display of a run (single model or batch); inert when disabled.
pub struct Bars {
    live: Option<Live>,
}

/// The indicatif state of enabled bars.
struct Live {
    multi: MultiProgress,
    /// The count of finished models (batches only).
    overall: Option<ProgressBar>,
    /// Dropping the sender tells the reveal thread that the work is over.
    reveal: Option<(mpsc::Sender<()>, JoinHandle<()>)>,
}

impl Bars {
    /// Bars for a run over `models` inputs, drawn only if `enabled`.
    pub fn new(enabled: bool, models: usize) -> Bars {
        if !enabled {
            return Bars { live: None };
        }
        // Hidden at first: the reveal thread switches to stderr once the work is slow.
        let multi = MultiProgress::with_draw_target(ProgressDrawTarget::hidden());
        let overall = (models > 1).then(|| {
            let pb = multi.add(ProgressBar::with_draw_target(
                Some(models as u64),
                ProgressDrawTarget::hidden(),
            ));
            pb.set_style(
                ProgressStyle::with_template("{prefix} [{bar:30}] {pos}/{len} models, {elapsed}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            pb.set_prefix("tetcdt");
            pb.enable_steady_tick(TICK);
            pb
        });
        let delay = reveal_after();
        if delay.is_zero() {
            // No race with the reveal thread: shown from the first stage on.
            multi.set_draw_target(ProgressDrawTarget::stderr());
        }
        let (tx, rx) = mpsc::channel::<()>();
        let shown = multi.clone();
        let thread = std::thread::spawn(move || {
            if delay.is_zero() {
                return;
            }
            if let Err(mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(delay) {
                shown.set_draw_target(ProgressDrawTarget::stderr());
            }
        });
        Bars {
            live: Some(Live {
                multi,
                overall,
                reveal: Some((tx, thread)),
            }),
        }
    }

    /// A spinner line for the model `name`, removed when the returned bar is dropped.
    pub fn model(&self, name: &str) -> ModelBar {
        let Some(live) = &self.live else {
            return ModelBar { bar: None };
        };
        // Born hidden: a new bar would draw on stderr at once, before joining the group.
        let pb = ProgressBar::with_draw_target(None, ProgressDrawTarget::hidden());
        pb.set_style(
            ProgressStyle::with_template("{spinner} {prefix}: {msg} ({elapsed})")
                .unwrap_or_else(|_| ProgressStyle::default_spinner()),
        );
        pb.set_prefix(name.to_owned());
        // Model lines go above the overall count, which stays last.
        let pb = match &live.overall {
            Some(o) => live.multi.insert_before(o, pb),
            None => live.multi.add(pb),
        };
        pb.enable_steady_tick(TICK);
        ModelBar {
            bar: Some((live.multi.clone(), pb)),
        }
    }

    /// Counts one more finished model.
    pub fn model_done(&self) {
        if let Some(o) = self.live.as_ref().and_then(|l| l.overall.as_ref()) {
            o.inc(1);
        }
    }

    /// Runs `f` (which prints) with the bars cleared, then redraws them.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.live {
            Some(live) => live.multi.suspend(f),
            None => f(),
        }
    }

    /// Removes the bars from the terminal.
    pub fn finish(mut self) {
        self.close();
    }

    fn close(&mut self) {
        if let Some(mut live) = self.live.take() {
            if let Some((tx, thread)) = live.reveal.take() {
                drop(tx);
                let _ = thread.join();
            }
            if let Some(o) = &live.overall {
                o.finish_and_clear();
            }
            let _ = live.multi.clear();
        }
    }
}

impl Drop for Bars {
    fn drop(&mut self) {
        self.close();
    }
}

/// The spinner line of one model; inert when bars are disabled.
pub struct ModelBar {
    bar: Option<(MultiProgress, ProgressBar)>,
}

impl ModelBar {
    /// Shows that `stage` has begun.
    pub fn stage(&self, stage: Stage) {
        self.message(stage.name());
    }

    /// Shows a free-form step (e.g. "check").
    pub fn message(&self, msg: &str) {
        if let Some((_, pb)) = &self.bar {
            pb.set_message(msg.to_owned());
        }
    }

    /// Runs `f` (which prints) with the bars cleared, then redraws them.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        match &self.bar {
            Some((multi, _)) => multi.suspend(f),
            None => f(),
        }
    }
}

impl Drop for ModelBar {
    fn drop(&mut self) {
        if let Some((multi, pb)) = self.bar.take() {
            pb.finish_and_clear();
            multi.remove(&pb);
        }
    }
}
