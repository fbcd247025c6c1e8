//! The command's work once its arguments are parsed: one model ([`model`]), several
//! ([`batch`]), progress bars ([`progress`]) and the reports ([`summary`]).

pub mod batch;
pub mod certify;
pub mod model;
pub mod progress;
pub mod summary;

use crate::Failure;
use anyhow::anyhow;
use model::{run_model, ModelReport, Say};
use progress::Bars;
use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::Instant;
use summary::Row;
use tetcdt::error::{EXIT_IO, EXIT_OK};
use tetcdt::options::Options;

/// A parsed command line.
pub struct Invocation {
    /// The switches and the long options that apply to every model.
    pub opts: Options,
    /// The inputs, at least one.
    pub files: Vec<PathBuf>,
    /// `--jobs N`: models meshed at once (default: the number of cores).
    pub jobs: Option<usize>,
    /// `--summary FILE`: the summary as TSV.
    pub summary: Option<PathBuf>,
    /// The switch strings as given (for the comment closing a batch's files).
    pub switches: Vec<String>,
    /// `--certify PREFIX`: certify that mesh against the one input instead of meshing.
    pub certify: Option<PathBuf>,
}

/// Runs the command; `comment` closes the output files of a single input and `start`
/// is when the command began. Returns the exit code, or the failure to print.
pub fn run(inv: Invocation, comment: String, start: Instant) -> Result<i32, Failure> {
    if let Some(prefix) = &inv.certify {
        return certify::run(prefix, &inv.files[0], &inv.opts);
    }
    if inv.files.len() > 1 {
        return batch::run_batch(inv);
    }
    let file = &inv.files[0];
    let bars = Bars::new(progress::wanted(inv.opts.quiet), 1);
    let bar = bars.model(&file.display().to_string());
    let say = Say::direct(inv.opts.quiet, &bar);
    let model_start = Instant::now();
    let result = run_model(file, &inv.opts, comment, start, &say, &bar);
    drop(say);
    drop(bar);
    bars.finish();
    let Some(path) = &inv.summary else {
        return result.map(|_| EXIT_OK);
    };
    let report = ModelReport {
        file: file.clone(),
        result,
        secs: model_start.elapsed().as_secs_f64(),
    };
    let written = write_report_file(path, &summary::tsv(&[Row::of(&report)]));
    // The model's own failure matters more than the summary's.
    report.result?;
    written.map(|_| EXIT_OK)
}

/// Writes a report (`--summary`, a batch's `--stats-json`); failing is an I/O error.
pub fn write_report_file(path: &Path, text: &str) -> Result<(), Failure> {
    std::fs::write(path, text)
        .map_err(|e| Failure::new(EXIT_IO, anyhow!("{}: {e}", path.display())))
}

thread_local! {
    /// The batch model this thread is meshing, for the panic message.
    static CURRENT_MODEL: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Records which batch model this thread meshes (`None` when done).
pub fn set_current_model(name: Option<String>) {
    CURRENT_MODEL.with(|m| *m.borrow_mut() = name);
}

/// The batch model this thread meshes, if any.
pub fn current_model() -> Option<String> {
    CURRENT_MODEL.with(|m| m.borrow().clone())
}
