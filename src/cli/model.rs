//! One model's run, the work of `tetcdt FILE`: name the outputs, read, mesh, write,
//! print the statistics, check. A single run streams its messages; a batch keeps each
//! model's messages and prints them whole when the model is done.

use super::progress::ModelBar;
use crate::{check_failure, Failure};
use anyhow::anyhow;
use std::cell::RefCell;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tetcdt::error::EXIT_USAGE;
use tetcdt::io::write::{self as writer, WriteOptions};
use tetcdt::options::Options;
use tetcdt::progress::Stage;
use tetcdt::Stats;

/// A model's messages kept for printing whole: stdout text and stderr lines.
#[derive(Default)]
pub struct Kept {
    /// What would have gone to stdout, newline-terminated lines.
    pub out: String,
    /// Lines for stderr (warnings), without the model prefix.
    pub err: Vec<String>,
}

/// Where a model's messages go. Write errors (a closed pipe) are ignored.
pub struct Say<'a> {
    quiet: bool,
    bar: &'a ModelBar,
    /// `None`: straight to stdout and stderr; `Some`: kept (batches).
    kept: Option<RefCell<Kept>>,
}

impl<'a> Say<'a> {
    /// Messages printed as they come, around the progress bar `bar`.
    pub fn direct(quiet: bool, bar: &'a ModelBar) -> Self {
        Say {
            quiet,
            bar,
            kept: None,
        }
    }

    /// Messages kept until [`Say::into_kept`].
    pub fn kept(quiet: bool, bar: &'a ModelBar) -> Self {
        Say {
            quiet,
            bar,
            kept: Some(RefCell::new(Kept::default())),
        }
    }

    /// One line for stdout, unless quiet.
    pub fn line(&self, msg: std::fmt::Arguments<'_>) {
        if self.quiet {
            return;
        }
        match &self.kept {
            Some(k) => {
                let mut k = k.borrow_mut();
                let _ = std::fmt::Write::write_fmt(&mut k.out, msg);
                k.out.push('\n');
            }
            None => self.bar.suspend(|| {
                let mut out = std::io::stdout().lock();
                let _ = out.write_fmt(msg);
                let _ = out.write_all(b"\n");
                let _ = out.flush();
            }),
        }
    }

    /// A warning for stderr, unless quiet.
    pub fn warn(&self, w: &str) {
        if self.quiet {
            return;
        }
        match &self.kept {
            Some(k) => k.borrow_mut().err.push(format!("Warning: {w}")),
            None => self.bar.suspend(|| {
                let _ = writeln!(std::io::stderr().lock(), "Warning: {w}");
            }),
        }
    }

    /// The kept messages (empty for direct messages).
    pub fn into_kept(self) -> Kept {
        self.kept.map(RefCell::into_inner).unwrap_or_default()
    }
}

macro_rules! say {
    ($s:expr, $($arg:tt)*) => { $s.line(format_args!($($arg)*)) };
}

/// The figures of a model meshed and written.
pub struct Done {
    /// The run's statistics.
    pub stats: Stats,
    /// Nodes written (input points and Steiner points).
    pub points: usize,
}

/// How one model of a run ended.
pub struct ModelReport {
    /// The input file as given.
    pub file: PathBuf,
    /// The figures, or why the model failed.
    pub result: Result<Done, Failure>,
    /// Wall seconds of the model's run, from reading to checking.
    pub secs: f64,
}

/// Meshes `file` as `opts` asks and writes its outputs; `comment` closes the output
/// files and `start` is when the run began (for "Total running seconds"). Writes
/// `opts.stats_json` too, when set (single runs; a batch writes its own records).
pub fn run_model(
    file: &Path,
    opts: &Options,
    comment: String,
    start: Instant,
    say: &Say<'_>,
    bar: &ModelBar,
) -> Result<Done, Failure> {
    // Name the outputs first, so that a naming problem costs no meshing time.
    let mut wopts = WriteOptions::from_options(opts);
    let prefix = writer::output_prefix(file, opts.output.as_deref(), opts.no_iteration)
        .map_err(|e| Failure::new(EXIT_USAGE, e))?;
    let outputs: Vec<PathBuf> = writer::file_kinds(opts.plc, &wopts)
        .into_iter()
        .map(|k| writer::output_path(&prefix, k))
        .collect();
    writer::check_outputs_spare_input(file, &outputs).map_err(|e| Failure::new(EXIT_USAGE, e))?;
    writer::check_output_dir(&prefix)?;

    bar.stage(Stage::Read);
    say!(say, "Opening {}.", file.display());
    let plc = tetcdt::io::read_plc(file).map_err(tetcdt::Error::from)?;
    // What reading found (dropped degenerate triangles) matters even if meshing fails.
    for w in &plc.warnings {
        say.warn(w);
    }

    if opts.detect_intersections {
        wopts.comment = Some(comment);
        detect_only(&plc, &prefix, &wopts, say)?;
        return Ok(Done {
            points: 0,
            stats: Stats::default(),
        });
    }

    if opts.plc {
        say!(say, "Constrained Delaunay tetrahedralization...");
    } else {
        say!(say, "Delaunizing vertices...");
    }
    wopts.comment = Some(comment);
    // A point set's nodes are its input points: their file is written on the other core
    // while the points are meshed (writing a million nodes takes a tenth of a second).
    let nodes = writer::Nodes::of_plc(&plc);
    let (meshed, early) = std::thread::scope(|s| {
        let early =
            (!opts.plc).then(|| s.spawn(|| writer::write_node_early(&nodes, &prefix, &wopts)));
        let meshed = tetcdt::tetrahedralize_with_progress(&plc, opts, &|st| bar.stage(st));
        let early = early.map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
        (meshed, early)
    });
    let meshed = meshed?;
    let early = early.transpose()?;
    say!(say, "Delaunay seconds:  {}", meshed.stats.delaunay_secs);
    for w in &meshed.warnings {
        say.warn(w);
    }

    // As TetGen (without -J): the output leaves out the points no tet uses and numbers
    // the rest in order; the library's mesh keeps input point i at node i, which the
    // check below relies on.
    let jettisoned = meshed.mesh.written(opts.keep_unused);
    let written = jettisoned.as_ref().unwrap_or(&meshed.mesh);
    let unused = meshed.mesh.points.len() - written.points.len();
    if unused > 0 && opts.verbose > 0 {
        say!(say, "");
        say!(
            say,
            "Points in no tet left out of the output: {unused} (duplicates, or outside the domain; -J keeps them)."
        );
    }

    bar.stage(Stage::Write);
    let out_start = Instant::now();
    say!(say, "");
    writer::write_files_with(
        written,
        &prefix,
        &wopts,
        &mut |p: &Path| {
            say!(say, "Writing {}.", p.display());
        },
        early,
    )?;
    say!(say, "");
    say!(
        say,
        "Output seconds:  {}",
        out_start.elapsed().as_secs_f64()
    );
    say!(
        say,
        "Total running seconds:  {}",
        start.elapsed().as_secs_f64()
    );

    if opts.verbose > 0 {
        print_statistics(say, &meshed, written.points.len());
    }
    if let Some(path) = &opts.stats_json {
        let json = meshed.stats.to_json(&file.to_string_lossy());
        std::fs::write(path, json + "\n").map_err(|e| {
            Failure::new(tetcdt::error::EXIT_IO, anyhow!("{}: {e}", path.display()))
        })?;
    }

    if opts.check {
        bar.message("check");
        say!(say, "");
        say!(say, "Checking the mesh...");
        let copts = tetcdt::check::CertifyOptions::of(opts);
        let cert = tetcdt::check::check_mesh(&plc, written, &copts)
            .map_err(|problems| check_failure(&problems))?;
        say!(
            say,
            "Mesh check passed: {} tets, {} Steiner points, {} faces on facets, {} edges on segments.",
            cert.tets,
            cert.steiner_points,
            cert.subfaces,
            cert.subsegments
        );
    }
    Ok(Done {
        points: written.points.len(),
        stats: meshed.stats,
    })
}

/// `-d`: report the intersecting facets and write their triangles; no meshing.
fn detect_only(
    plc: &tetcdt::Plc,
    prefix: &Path,
    wopts: &WriteOptions,
    say: &Say<'_>,
) -> Result<(), Failure> {
    say!(say, "Detecting self-intersecting facets...");
    let found = tetcdt::precheck::detect::detect(plc).map_err(tetcdt::Error::from)?;
    for w in &found.warnings {
        say.warn(w);
    }
    for line in found.report(plc) {
        say!(say, "{line}");
    }
    tetcdt::precheck::detect::write(plc, &found, prefix, wopts, &mut |p: &Path| {
        say!(say, "Writing {}.", p.display());
    })?;
    Ok(())
}

/// The `-V` statistics (with `-p`, the rows of the paper's Table 1).
fn print_statistics(say: &Say<'_>, meshed: &tetcdt::Meshed, mesh_points: usize) {
    let s = &meshed.stats;
    say!(say, "");
    say!(say, "Statistics:");
    say!(say, "");
    say!(say, "  Input points: {}", s.input_points);
    say!(say, "  Duplicate points: {}", s.duplicate_points);
    say!(say, "");
    say!(say, "  Mesh points: {mesh_points}");
    say!(say, "  Mesh tetrahedra: {}", s.output_tets);
    say!(say, "  Convex hull faces: {}", s.hull_faces);
    say!(say, "");
    say!(say, "  Sorting seconds: {}", s.sort_secs);
    say!(say, "  Check seconds: {}", s.precheck_secs);
    say!(say, "  Certify seconds: {}", s.certify_secs);
    say!(say, "  Delaunay seconds: {}", s.delaunay_secs);
    say!(say, "  Meshing seconds: {}", s.total_secs);
    if let Some(q) = &s.quality {
        say!(say, "");
        say!(say, "  Mesh quality:");
        for line in q.lines() {
            say!(say, "    {line}");
        }
    }
    let rows = s.table1_rows();
    if !rows.is_empty() {
        say!(say, "");
        say!(
            say,
            "  Constrained Delaunay (rows of Si & Shewchuk's Table 1):"
        );
        for (label, value) in rows {
            say!(say, "    {label:<45} {value}");
        }
    }
}
