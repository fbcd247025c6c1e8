//! The `tetcdt` command: `tetcdt [-switches] FILE...`, TetGen style.
//!
//! Packed switch strings (`-zQ`, `-pq1.2`) are taken out of the arguments and parsed by
//! [`tetcdt::options`]; clap handles the rest (`--help`, `--version`, `-o PREFIX`,
//! `--check`, the batch options and the input files). The work itself is in `cli`.
//! Errors are printed as `tetcdt: <error>` on stderr and exit with the codes of
//! [`tetcdt::error`]: 0 ok, 1 meshing failed, 2 usage, 3 invalid input, 4 I/O.

mod cli;

use anyhow::anyhow;
use clap::{ArgAction, Parser};
use std::ffi::OsString;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;
use tetcdt::check::CheckFailure;
use tetcdt::error::{EXIT_MESH_FAILED, EXIT_OK, EXIT_USAGE};
use tetcdt::options::Options;

/// The switches, for `--help`.
const SWITCHES: &str = "\
Switches (TetGen style, packed after one '-', e.g. -zQ or -fenV):
  -p     Tetrahedralize a piecewise linear complex (.poly, .smesh, .off, .obj, .stl, .ply, .mesh)
  -C     Recover facets by cavity retriangulation (the default; needs -p)
  -F     Recover facets by flips (needs -p)
  -z     Number all output items from zero
  -e     Write all edges to the .edge file
  -n     Write the neighbours of each tet to the .neigh file
  -f     Write all faces (not only boundary faces) to the .face file
  -I     No iteration number in output names (cube.node, not cube.1.node)
  -c     Keep the convex hull: mesh the hull instead of carving the exterior (needs -p)
  -A     Give each tet the attribute of its region from the region list (needs -p)
  -M     Do not merge coplanar adjacent facets (needs -p)
  -q[r][/d] Refine until no tet has a radius-edge ratio over r (default 2) or, with
         /d, a dihedral angle under d degrees; the mesh stays a CDT (needs -p)
  -a[v]  Refine until no tet is larger than v; -a alone: each region's bound (needs -p)
  -Y     No Steiner point on segments and facets: refinement leaves the tets that
         would need one, and a PLC whose CDT needs one fails (exit 1; needs -p)
  -S[n]  At most n Steiner points (-S or -S0: no limit); reaching it is an error
  -J     Keep the input points that no tet uses (repeated points, points outside the
         domain or in holes) in .node; by default they are left out, as TetGen does
  -j     Leave those points out (the default; accepted for TetGen compatibility)
  -k     Also write the mesh as legacy VTK: <prefix>.vtk (region attribute as CELL_DATA)
  -g     Also write the mesh as Medit: <prefix>.mesh (subfaces as Triangles, tets with region ref)
  -O0    No mesh optimization (the only level we do; accepted for TetGen compatibility)
  -Q     Quiet: no terminal output except errors
  -V     Verbose: print statistics (-VV for more)
  -d     Only detect intersecting facets: list them, write their triangles to .face
         (with the points in .node); nothing is written when there are none
Other TetGen switches (-r, -T, -o2, -G, -K, ...) are recognised and refused.

Switches may come before or after FILE; put -- before a FILE whose name starts with '-'.

Several FILEs are meshed in parallel (--jobs N, default: the number of cores), each
with its own outputs; each model's messages are printed whole when it is done, errors
prefixed with its name, then a summary table (model, status, vertices, Steiner points,
tets, seconds; with -q, -a or -V also the worst radius-edge ratio, the smallest dihedral
angle and the tets refinement left) on stdout, also with -Q. --summary FILE writes it
as TSV (also for one input); --stats-json FILE writes one JSON line per model. -o needs
a single FILE.
Progress bars appear on stderr when it is a terminal and a run takes over a second
(never with -Q or when CI is set).

Output: <dir>/<base>.1.node, .ele, .face (and .edge, .neigh, .vtk, .mesh) next to the input; an input
named <base>.<n>.node gives <base>.<n+1>.*. Files are written atomically. The nodes
are the input points in input order, without those no tet uses (unless -J), then the
Steiner points.

--certify PREFIX FILE certifies an existing mesh (PREFIX.node, PREFIX.ele, from any
mesher) as a CDT of FILE (with -pc: its convex hull kept; with -pM: facets not merged)
and exits 1 listing the problems if it is not one.

Exit codes: 0 ok, 1 meshing failed (or --check found problems), 2 usage error,
3 invalid input, 4 I/O error. With several FILEs: the code of the first FILE (in
command-line order) that failed; the others are meshed all the same.";

/// The options clap sees; packed switch strings are removed beforehand.
#[derive(Parser, Debug)]
#[command(
    name = "tetcdt",
    version,
    about = "Constrained Delaunay tetrahedralizations with exact predicates, TetGen-compatible files",
    override_usage = "tetcdt [-switches] [options] FILE...",
    after_help = SWITCHES,
    disable_version_flag = true
)]
struct Cli {
    /// Write PREFIX.node, PREFIX.ele, ... instead of names derived from FILE.
    #[arg(short = 'o', long = "output", value_name = "PREFIX")]
    output: Option<PathBuf>,
    /// Validate the mesh after writing it; exit 1 listing the problems if any.
    #[arg(long)]
    check: bool,
    /// Certify the mesh PREFIX.node/PREFIX.ele as a CDT of FILE (any mesher's); exit 1
    /// listing the problems if it is not one. Nothing is meshed.
    #[arg(long, value_name = "PREFIX")]
    certify: Option<PathBuf>,
    /// Write the run's statistics (with -p, the paper's Table 1 figures) as JSON to FILE
    /// (one line per model).
    #[arg(long = "stats-json", value_name = "FILE")]
    stats_json: Option<PathBuf>,
    /// Mesh this many models at once (default: the number of cores).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..=4096))]
    jobs: Option<u64>,
    /// Write the summary (model, status, vertices, Steiner points, tets, seconds) as TSV.
    #[arg(long, value_name = "FILE")]
    summary: Option<PathBuf>,
    /// Print the version.
    #[arg(long, action = ArgAction::Version)]
    version: Option<bool>,
    /// The input models: .node, .poly, .smesh, .off, .obj, .stl, .ply or .mesh files.
    #[arg(value_name = "FILE", required = true, num_args = 1..)]
    files: Vec<PathBuf>,
}

/// A failed run: the exit code and the error to print.
struct Failure {
    code: i32,
    err: anyhow::Error,
}

impl Failure {
    fn new(code: i32, err: impl Into<anyhow::Error>) -> Self {
        Failure {
            code,
            err: err.into(),
        }
    }
}

impl From<tetcdt::Error> for Failure {
    fn from(e: tetcdt::Error) -> Self {
        Failure::new(e.exit_code(), e)
    }
}

/// Splits the arguments (after the program name) into packed switch strings and the
/// arguments for clap. A switch string is an argument starting with `-` that is not a
/// long option, `-o` (whose value follows), `-h`, `-` alone, or after `--`.
fn split_args(args: &[OsString]) -> Result<(Vec<String>, Vec<OsString>), Failure> {
    let mut switches = Vec::new();
    let mut rest = Vec::new();
    let mut iter = args.iter();
    while let Some(arg) = iter.next() {
        let bytes = arg.as_encoded_bytes();
        if bytes == b"--" {
            rest.push(arg.clone());
            rest.extend(iter.by_ref().cloned());
            break;
        }
        if bytes == b"-o" || bytes == b"--output" {
            rest.push(arg.clone());
            if let Some(value) = iter.next() {
                rest.push(value.clone());
            }
            continue;
        }
        if bytes.starts_with(b"--") || bytes == b"-h" || bytes == b"-" || !bytes.starts_with(b"-") {
            rest.push(arg.clone());
            continue;
        }
        match arg.to_str() {
            Some(s) => switches.push(s.to_owned()),
            None => {
                return Err(Failure::new(
                    EXIT_USAGE,
                    anyhow!("switch string {arg:?} is not valid UTF-8"),
                ))
            }
        }
    }
    Ok((switches, rest))
}

/// Parses the command line into options and the input files. `Ok(None)` means that
/// clap printed help or the version.
fn parse_args(args: &[OsString]) -> Result<Option<cli::Invocation>, Failure> {
    let (switches, rest) = split_args(args)?;
    let cli = match Cli::try_parse_from(std::iter::once(OsString::from("tetcdt")).chain(rest)) {
        Ok(cli) => cli,
        Err(e) => {
            use clap::error::ErrorKind;
            if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                let _ = e.print();
                return Ok(None);
            }
            let text = e.render().to_string();
            let text = text
                .strip_prefix("error: ")
                .unwrap_or(&text)
                .trim_end()
                .to_owned();
            return Err(Failure::new(EXIT_USAGE, anyhow!(text)));
        }
    };
    let mut opts = Options::from_switches(switches.iter().map(String::as_str))
        .map_err(|e| Failure::new(EXIT_USAGE, anyhow!("{e} (see tetcdt --help)")))?;
    opts.output = cli.output;
    opts.check = cli.check;
    opts.stats_json = cli.stats_json;
    if cli.certify.is_some() {
        let meshing = opts.check
            || opts.stats_json.is_some()
            || opts.output.is_some()
            || cli.summary.is_some()
            || cli.jobs.is_some()
            || opts.detect_intersections;
        if cli.files.len() != 1 || meshing {
            return Err(Failure::new(
                EXIT_USAGE,
                anyhow!("--certify PREFIX takes one input FILE and no meshing options (-o, -d, --check, --stats-json, --summary, --jobs)"),
            ));
        }
    }
    if opts.detect_intersections && (opts.check || opts.stats_json.is_some()) {
        return Err(Failure::new(
            EXIT_USAGE,
            anyhow!("-d only detects intersecting facets and makes no mesh: --check and --stats-json do not apply"),
        ));
    }
    Ok(Some(cli::Invocation {
        opts,
        files: cli.files,
        jobs: cli.jobs.map(|n| n as usize),
        summary: cli.summary,
        switches,
        certify: cli.certify,
    }))
}

/// Runs the command; returns the exit code of a finished or help run.
fn run(args: Vec<OsString>) -> Result<i32, Failure> {
    let start = Instant::now();
    let Some(inv) = parse_args(&args)? else {
        return Ok(EXIT_OK);
    };
    cli::run(inv, generated_by(&args), start)
}

/// The failure of `--check`: how many problems there are, then the listed ones, one per
/// line.
fn check_failure(problems: &CheckFailure) -> Failure {
    let mut msg = format!("mesh check failed with {} problem(s):", problems.total);
    for p in problems.to_string().lines() {
        msg.push_str("\n  ");
        msg.push_str(p);
    }
    Failure::new(EXIT_MESH_FAILED, anyhow!(msg))
}

/// The text of the comment line closing the output files.
fn generated_by(args: &[OsString]) -> String {
    let mut s = String::from("Generated by tetcdt");
    for a in args {
        s.push(' ');
        s.push_str(&a.to_string_lossy());
    }
    s
}

/// The error and its causes, joined by ": ", skipping a cause whose text the message
/// already ends with (errors that print their source themselves).
fn error_chain(err: &anyhow::Error) -> String {
    let mut msg = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if msg.is_empty() {
            msg = text;
        } else if !msg.ends_with(&text) {
            msg.push_str(": ");
            msg.push_str(&text);
        }
    }
    msg
}

fn main() {
    // A panic is a bug: report it as an internal error (exit 1), never as a crash.
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let model = cli::current_model()
            .map(|m| format!("{m}: "))
            .unwrap_or_default();
        let _ = writeln!(
            std::io::stderr(),
            "tetcdt: {model}internal error: {msg}{at}"
        );
    }));
    let args: Vec<OsString> = std::env::args_os().skip(1).collect();
    let code = match std::panic::catch_unwind(move || run(args)) {
        Ok(Ok(code)) => code,
        Ok(Err(f)) => {
            let _ = writeln!(std::io::stderr(), "tetcdt: {}", error_chain(&f.err));
            f.code
        }
        Err(_) => EXIT_MESH_FAILED,
    };
    std::process::exit(code);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn os(v: &[&str]) -> Vec<OsString> {
        v.iter().map(OsString::from).collect()
    }

    #[test]
    fn switch_strings_are_split_from_clap_arguments() {
        let (sw, rest) = split_args(&os(&[
            "-zQ", "f.node", "-o", "-weird", "--check", "-V", "-h", "-", "--", "-x",
        ]))
        .ok()
        .unwrap();
        assert_eq!(sw, ["-zQ", "-V"]);
        assert_eq!(
            rest,
            os(&["f.node", "-o", "-weird", "--check", "-h", "-", "--", "-x"])
        );
        let (sw, rest) = split_args(&os(&["--output", "-p", "-p", "--output=x"]))
            .ok()
            .unwrap();
        assert_eq!(sw, ["-p"]);
        assert_eq!(rest, os(&["--output", "-p", "--output=x"]));
    }

    #[test]
    fn parsed_arguments() {
        let inv = parse_args(&os(&["m.node", "-fe", "-o", "out/x", "--check"]))
            .ok()
            .unwrap()
            .unwrap();
        let opts = inv.opts;
        assert_eq!(inv.files, [PathBuf::from("m.node")]);
        assert!(opts.all_faces && opts.write_edges && opts.check);
        assert_eq!(opts.output, Some(PathBuf::from("out/x")));
        let f = parse_args(&os(&["-q", "m.node"])).err().unwrap();
        assert_eq!(f.code, EXIT_USAGE);
        assert!(error_chain(&f.err).contains("switch -q (quality"));
        let f = parse_args(&os(&[])).err().unwrap();
        assert_eq!(f.code, EXIT_USAGE);
    }

    #[test]
    fn error_chains_skip_repeated_causes() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "gone");
        let e = tetcdt::Error::Output {
            file: PathBuf::from("a.node"),
            source: io,
        };
        assert_eq!(error_chain(&anyhow::Error::new(e)), "a.node: gone");
        let e = anyhow!("inner").context("outer");
        assert_eq!(error_chain(&e), "outer: inner");
    }

    #[test]
    fn check_failures_list_every_problem() {
        let f = check_failure(&CheckFailure {
            listed: vec!["tet 3 is inverted".into(), "face 7 is not Delaunay".into()],
            total: 2,
        });
        assert_eq!(f.code, EXIT_MESH_FAILED);
        assert_eq!(
            error_chain(&f.err),
            "mesh check failed with 2 problem(s):\n  tet 3 is inverted\n  face 7 is not Delaunay"
        );
    }

    /// The count is of every problem, not of the lines listed (twenty, and one for the
    /// rest): 33 shims were once announced as "21 problem(s)".
    #[test]
    fn check_failures_count_the_problems_not_listed() {
        let f = check_failure(&CheckFailure {
            listed: vec!["tet 3 is a shim".into()],
            total: 14,
        });
        assert_eq!(
            error_chain(&f.err),
            "mesh check failed with 14 problem(s):\n  tet 3 is a shim\n  ... and 13 more problems"
        );
    }
}
