//! Several inputs in one call: each model meshed on a rayon pool of `--jobs` threads,
//! with its own outputs and status; one failure never stops the others. Each model's
//! messages are printed whole when it is done, errors on stderr prefixed with its name;
//! the summary table follows on stdout.
//!
//! Exit code: 0 if every model succeeded, else the code of the first model, in
//! command-line order, that failed (so it does not depend on `--jobs`).

use super::model::{run_model, ModelReport, Say};
use super::progress::{self, Bars};
use super::summary::{self, Row};
use super::{write_report_file, Invocation};
use crate::{error_chain, Failure};
use anyhow::anyhow;
use rayon::prelude::*;
use std::collections::HashMap;
use std::io::Write;
use std::panic::AssertUnwindSafe;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tetcdt::error::{EXIT_MESH_FAILED, EXIT_OK, EXIT_USAGE};
use tetcdt::io::write::{self as writer, WriteOptions};
use tetcdt::options::Options;

/// The default of `--jobs`: the number of cores.
pub fn default_jobs() -> usize {
    tetcdt::cores()
}

/// Meshes every input of `inv` (more than one); returns the exit code.
pub fn run_batch(inv: Invocation) -> Result<i32, Failure> {
    if inv.opts.output.is_some() {
        return Err(Failure::new(
            EXIT_USAGE,
            anyhow!(
                "-o/--output names the outputs of a single input, but {} inputs were given",
                inv.files.len()
            ),
        ));
    }
    check_distinct_outputs(&inv.files, &inv.opts)?;
    let jobs = inv.jobs.unwrap_or_else(default_jobs);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .map_err(|e| Failure::new(EXIT_MESH_FAILED, anyhow!("cannot start {jobs} jobs: {e}")))?;
    // Records are written for the whole batch at the end, not by each model.
    let mut opts = inv.opts.clone();
    opts.stats_json = None;

    let bars = Bars::new(progress::wanted(opts.quiet), inv.files.len());
    let reports: Vec<ModelReport> = pool.install(|| {
        inv.files
            .par_iter()
            .map(|f| run_one(f, &opts, &inv.switches, &bars))
            .collect()
    });
    bars.finish();

    let rows: Vec<Row> = reports.iter().map(Row::of).collect();
    {
        let mut out = std::io::stdout().lock();
        let _ = out.write_all(summary::table(&rows).as_bytes());
        let _ = out.flush();
    }
    let code = rows.iter().map(|r| r.code).find(|&c| c != 0);
    let mut file_problem = None;
    if let Some(path) = &inv.summary {
        file_problem = write_report_file(path, &summary::tsv(&rows)).err();
    }
    if let Some(path) = &inv.opts.stats_json {
        let mut lines = String::new();
        for r in &reports {
            lines.push_str(&summary::json_record(r));
            lines.push('\n');
        }
        if let Err(f) = write_report_file(path, &lines) {
            file_problem.get_or_insert(f);
        }
    }
    match (code, file_problem) {
        (Some(code), Some(f)) => {
            let _ = writeln!(std::io::stderr(), "tetcdt: {}", error_chain(&f.err));
            Ok(code)
        }
        (None, Some(f)) => Err(f),
        (code, None) => Ok(code.unwrap_or(EXIT_OK)),
    }
}

/// Meshes one model of a batch and prints its kept messages and error whole.
fn run_one(file: &Path, opts: &Options, switches: &[String], bars: &Bars) -> ModelReport {
    let name = file.display().to_string();
    let bar = bars.model(&name);
    let say = Say::kept(opts.quiet, &bar);
    let start = Instant::now();
    let comment = comment_for(switches, file);
    super::set_current_model(Some(name.clone()));
    let result = std::panic::catch_unwind(AssertUnwindSafe(|| {
        run_model(file, opts, comment, start, &say, &bar)
    }))
    .unwrap_or_else(|_| {
        // The panic hook has printed the panic, naming the model.
        Err(Failure::new(
            EXIT_MESH_FAILED,
            anyhow!("internal error (see the message above)"),
        ))
    });
    super::set_current_model(None);
    let secs = start.elapsed().as_secs_f64();
    let kept = say.into_kept();
    drop(bar);
    bars.suspend(|| {
        // Both locks at once, so that no other model's lines come in between.
        let mut out = std::io::stdout().lock();
        let mut err = std::io::stderr().lock();
        if !kept.out.is_empty() {
            // A blank line closes each model's block.
            let _ = out.write_all(kept.out.as_bytes());
            let _ = out.write_all(b"\n");
        }
        let _ = out.flush();
        for line in &kept.err {
            let _ = writeln!(err, "tetcdt: {name}: {line}");
        }
        if let Err(f) = &result {
            let msg = error_chain(&f.err);
            // Reader errors begin with the file name already.
            if msg.starts_with(&name) {
                let _ = writeln!(err, "tetcdt: {msg}");
            } else {
                let _ = writeln!(err, "tetcdt: {name}: {msg}");
            }
        }
    });
    bars.model_done();
    ModelReport {
        file: file.to_path_buf(),
        result,
        secs,
    }
}

/// The comment closing a batch model's files: the switches and that model alone, so
/// that a file does not depend on the other inputs or on `--jobs`.
fn comment_for(switches: &[String], file: &Path) -> String {
    let mut s = String::from("Generated by tetcdt");
    for sw in switches {
        s.push(' ');
        s.push_str(sw);
    }
    s.push(' ');
    s.push_str(&file.to_string_lossy());
    s
}

/// A path for comparing files: its directory made canonical when it exists.
fn file_key(p: &Path) -> PathBuf {
    let dir = match p.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (dir.canonicalize(), p.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => p.to_path_buf(),
    }
}

/// Refuses (as a usage error, before any meshing) a batch in which an input is given
/// twice, two models would write the same file, or a model would overwrite another's
/// input. Naming problems of one model are left to that model's run.
fn check_distinct_outputs(files: &[PathBuf], opts: &Options) -> Result<(), Failure> {
    let kinds = writer::file_kinds(opts.plc, &WriteOptions::from_options(opts));
    // Each file's user: the model's index and whether the file is its input.
    let mut user: HashMap<PathBuf, (usize, bool)> = HashMap::new();
    for (i, f) in files.iter().enumerate() {
        if let Some(&(j, _)) = user.get(&file_key(f)) {
            return Err(Failure::new(
                EXIT_USAGE,
                anyhow!(
                    "{} is given twice (as {} and {})",
                    f.display(),
                    files[j].display(),
                    f.display()
                ),
            ));
        }
        user.insert(file_key(f), (i, true));
    }
    for (i, f) in files.iter().enumerate() {
        let Ok(prefix) = writer::output_prefix(f, None, opts.no_iteration) else {
            continue;
        };
        for &k in &kinds {
            let out = writer::output_path(&prefix, k);
            match user.get(&file_key(&out)) {
                // Overwriting its own input is the model's own naming error.
                Some(&(j, true)) if j == i => continue,
                Some(&(j, true)) => {
                    return Err(Failure::new(
                        EXIT_USAGE,
                        anyhow!(
                            "meshing {} would overwrite the input {}",
                            f.display(),
                            files[j].display()
                        ),
                    ))
                }
                Some(&(j, false)) => {
                    return Err(Failure::new(
                        EXIT_USAGE,
                        anyhow!(
                            "{} and {} would both write {}",
                            files[j].display(),
                            f.display(),
                            out.display()
                        ),
                    ))
                }
                _ => {}
            }
            user.insert(file_key(&out), (i, false));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn code_of(files: &[&str], opts: &Options) -> Option<(i32, String)> {
        let files: Vec<PathBuf> = files.iter().map(PathBuf::from).collect();
        check_distinct_outputs(&files, opts)
            .err()
            .map(|f| (f.code, error_chain(&f.err)))
    }

    #[test]
    fn colliding_outputs_are_refused() {
        let opts = Options::default();
        assert!(code_of(&["a.node", "b.node"], &opts).is_none());
        let (code, msg) = code_of(&["a.node", "./a.node"], &opts).unwrap();
        assert_eq!(code, EXIT_USAGE);
        assert!(msg.contains("is given twice"), "{msg}");
        let (_, msg) = code_of(&["a.node", "a.off"], &opts).unwrap();
        assert_eq!(msg, "a.node and a.off would both write a.1.node");
        let (_, msg) = code_of(&["a.node", "a.1.node"], &opts).unwrap();
        assert_eq!(msg, "meshing a.node would overwrite the input a.1.node");
        // Own-input overwrites (-I) are the model's own usage error, not the batch's.
        let opts = Options {
            no_iteration: true,
            ..Default::default()
        };
        assert!(code_of(&["a.node", "b.node"], &opts).is_none());
    }

    #[test]
    fn batch_comments_name_one_model() {
        let c = comment_for(&["-pQ".into(), "-V".into()], Path::new("d/m.off"));
        assert_eq!(c, "Generated by tetcdt -pQ -V d/m.off");
    }
}
