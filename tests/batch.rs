//! Tests of batch runs: several inputs in one call, the summary table and its TSV, the
//! JSON Lines records, the exit code rule, `--jobs`, no progress bars off a terminal,
//! and the Makefile example.

use assert_cmd::Command;
use std::fs;
use std::path::Path;

/// Good models copied from `data/` (-p), in command-line order.
const GOOD: &[&str] = &[
    "examples/cube.poly",
    "examples/box_with_hole.poly",
    "plc/sphere.off",
    "plc/star.off",
    "plc/gridbox_3.smesh",
    "examples/tet.obj",
];

/// A model whose face names a vertex that does not exist: exit 3.
const BROKEN: &str = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";

fn tetcdt() -> Command {
    Command::cargo_bin("tetcdt").unwrap()
}

/// Runs tetcdt in `dir` with `args`; returns (exit code, stdout, stderr).
fn run_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = tetcdt().current_dir(dir).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Copies the good models and writes `broken.off` (third) into `dir`; returns the file
/// names in command-line order.
fn setup(dir: &Path) -> Vec<String> {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    let mut names = Vec::new();
    for (i, m) in GOOD.iter().enumerate() {
        let name = Path::new(m)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        fs::copy(data.join(m), dir.join(&name)).unwrap();
        names.push(name);
        if i == 1 {
            fs::write(dir.join("broken.off"), BROKEN).unwrap();
            names.push("broken.off".into());
        }
    }
    names
}

/// The models of `setup` that mesh.
fn good_models(names: &[String]) -> Vec<&str> {
    names
        .iter()
        .map(String::as_str)
        .filter(|n| *n != "broken.off")
        .collect()
}

/// The base name of a model: `cube.poly` -> `cube`.
fn stem(name: &str) -> &str {
    name.rsplit_once('.').unwrap().0
}

/// The first number of a mesh file (its count).
fn header_count(path: &Path) -> usize {
    let text = fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .and_then(|l| l.split_whitespace().next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{}: no count", path.display()))
}

/// The raw JSON value of `key` in a one-line object (numbers and simple strings).
fn json_field<'a>(record: &'a str, key: &str) -> Option<&'a str> {
    let at = record.find(&format!("\"{key}\": "))? + key.len() + 4;
    let rest = &record[at..];
    let end = if let Some(s) = rest.strip_prefix('"') {
        s.find('"')? + 2
    } else {
        rest.find([',', '}'])?
    };
    Some(rest[..end].trim_matches('"'))
}

/// Whether text holds terminal control characters (progress bars would).
fn has_control(text: &str) -> bool {
    text.chars().any(|c| c == '\x1b' || c == '\r')
}

#[test]
fn batch_summary_records_and_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let names = setup(d);
    let mut args = vec!["-pQ", "--summary", "s.tsv", "--stats-json", "s.jsonl"];
    args.extend(names.iter().map(String::as_str));
    let (code, stdout, stderr) = run_in(d, &args);
    assert_eq!(code, 3, "the broken model's code: {stderr}");
    assert!(!has_control(&stderr), "{stderr:?}");
    assert_eq!(
        stderr.lines().collect::<Vec<_>>(),
        ["tetcdt: broken.off:6: face 0 has corner 7, but there are only 3 vertices (numbered from 0)"]
    );

    // Every good model has its outputs; the broken one none.
    for name in &names {
        let s = stem(name);
        for ext in ["node", "ele", "face", "edge"] {
            let p = d.join(format!("{s}.1.{ext}"));
            assert_eq!(p.exists(), name != "broken.off", "{}", p.display());
        }
    }
    let figures = |name: &str| {
        let s = stem(name);
        (
            header_count(&d.join(format!("{s}.1.node"))),
            header_count(&d.join(format!("{s}.1.ele"))),
        )
    };

    // The stdout table: a header, one row per model in command-line order, a count.
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), names.len() + 2, "{stdout}");
    let head: Vec<&str> = lines[0].split_whitespace().collect();
    assert_eq!(
        head,
        ["model", "status", "vertices", "Steiner", "tets", "seconds"]
    );
    for (name, line) in names.iter().zip(&lines[1..]) {
        let cells: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(cells[0], name, "{stdout}");
        if name == "broken.off" {
            assert!(line.contains("exit 3: broken.off:6: face 0"), "{line}");
            assert_eq!(cells[cells.len() - 4..cells.len() - 1], ["-", "-", "-"]);
        } else {
            let (points, tets) = figures(name);
            assert_eq!(cells[1], "ok", "{line}");
            assert_eq!(cells[2], points.to_string(), "{line}");
            assert_eq!(cells[4], tets.to_string(), "{line}");
            assert!(cells[5].parse::<f64>().unwrap() >= 0.0);
        }
    }
    assert_eq!(lines[names.len() + 1], "7 models: 6 ok, 1 failed");

    // The TSV: the same rows, tab-separated, with the whole reason.
    let tsv = fs::read_to_string(d.join("s.tsv")).unwrap();
    let rows: Vec<Vec<&str>> = tsv.lines().map(|l| l.split('\t').collect()).collect();
    assert_eq!(
        rows[0],
        [
            "model",
            "status",
            "exit_code",
            "vertices",
            "steiner_points",
            "tets",
            "seconds",
            "max_radius_edge_ratio",
            "min_dihedral",
            "refine_left",
            "reason"
        ]
    );
    assert_eq!(rows.len(), names.len() + 1);
    for (name, row) in names.iter().zip(&rows[1..]) {
        assert_eq!(row.len(), 11, "{tsv}");
        // -pQ computes no quality figures: their fields are empty.
        assert_eq!(row[7..10], ["", "", ""]);
        assert_eq!(row[0], name);
        if name == "broken.off" {
            assert_eq!(row[1..6], ["failed", "3", "", "", ""]);
            assert_eq!(
                row[10],
                "broken.off:6: face 0 has corner 7, but there are only 3 vertices (numbered from 0)"
            );
        } else {
            let (points, tets) = figures(name);
            assert_eq!(row[1..3], ["ok", "0"]);
            assert_eq!(row[3], points.to_string());
            assert_eq!(row[5], tets.to_string());
            assert_eq!(row[10], "");
        }
    }

    // The JSON Lines: one record per model, in order, matching the mesh files.
    let jsonl = fs::read_to_string(d.join("s.jsonl")).unwrap();
    let records: Vec<&str> = jsonl.lines().collect();
    assert_eq!(records.len(), names.len(), "{jsonl}");
    for (name, rec) in names.iter().zip(&records) {
        assert!(rec.starts_with('{') && rec.ends_with('}'), "{rec}");
        assert_eq!(json_field(rec, "model"), Some(name.as_str()), "{rec}");
        if name == "broken.off" {
            assert_eq!(json_field(rec, "status"), Some("failed"), "{rec}");
            assert_eq!(json_field(rec, "exit_code"), Some("3"), "{rec}");
            assert!(
                json_field(rec, "error").unwrap().contains("face 0"),
                "{rec}"
            );
            assert_eq!(json_field(rec, "output_tets"), None, "{rec}");
        } else {
            let (points, tets) = figures(name);
            assert_eq!(json_field(rec, "status"), Some("ok"), "{rec}");
            assert_eq!(json_field(rec, "exit_code"), Some("0"), "{rec}");
            assert_eq!(
                json_field(rec, "output_tets"),
                Some(tets.to_string().as_str())
            );
            assert_eq!(
                json_field(rec, "output_points"),
                Some(points.to_string().as_str())
            );
            let input: usize = json_field(rec, "input_points").unwrap().parse().unwrap();
            let steiner: usize = json_field(rec, "steiner_points").unwrap().parse().unwrap();
            assert_eq!(input + steiner, points, "{rec}");
            assert_eq!(json_field(rec, "plc"), Some("true"), "{rec}");
        }
    }
}

#[test]
fn one_job_and_two_jobs_write_the_same_files() {
    let mut tables = Vec::new();
    let mut dirs = Vec::new();
    for jobs in ["1", "2"] {
        let dir = tempfile::tempdir().unwrap();
        let names = setup(dir.path());
        let mut args = vec!["-pQ", "--jobs", jobs];
        args.extend(names.iter().map(String::as_str));
        let (code, stdout, stderr) = run_in(dir.path(), &args);
        assert_eq!(code, 3, "{stderr}");
        // The table without the seconds column.
        let table: Vec<String> = stdout
            .lines()
            .map(|l| {
                let mut c: Vec<&str> = l.split_whitespace().collect();
                if l.ends_with(char::is_numeric) && !l.contains("models:") {
                    c.pop();
                }
                c.join(" ")
            })
            .collect();
        tables.push(table);
        dirs.push(dir);
    }
    assert_eq!(tables[0], tables[1]);
    let listing = |d: &Path| {
        let mut v: Vec<String> = fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    };
    let files = listing(dirs[0].path());
    assert_eq!(files, listing(dirs[1].path()));
    assert!(files.len() > 20, "{files:?}");
    for f in &files {
        let a = fs::read(dirs[0].path().join(f)).unwrap();
        let b = fs::read(dirs[1].path().join(f)).unwrap();
        assert!(a == b, "{f} differs between --jobs 1 and --jobs 2");
    }
    // A batch model's files name that model alone, not the batch.
    let ele = fs::read_to_string(dirs[0].path().join("star.1.ele")).unwrap();
    assert!(
        ele.ends_with("# Generated by tetcdt -pQ star.off\n"),
        "{ele}"
    );
}

#[test]
fn messages_come_whole_per_model_without_progress_bars() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let names = setup(d);
    fs::write(
        d.join("open.off"),
        "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n",
    )
    .unwrap();
    let mut args = vec!["-pV", "--jobs", "2", "open.off"];
    args.extend(names.iter().map(String::as_str));
    let (code, stdout, stderr) = run_in(d, &args);
    assert_eq!(code, 3, "{stderr}");
    // Progress bars draw with escape sequences and carriage returns: none off a terminal.
    assert!(!has_control(&stdout) && !has_control(&stderr), "{stderr:?}");
    // Errors name their model.
    assert!(
        stderr.lines().any(|l| l.starts_with("tetcdt: open.off: ")),
        "{stderr}"
    );
    assert!(stderr.contains("tetcdt: broken.off:6: "), "{stderr}");
    // Each good model's block runs from "Opening" to its Table 1 without another model's
    // lines in between.
    let lines: Vec<&str> = stdout.lines().collect();
    for name in names.iter().filter(|n| *n != "broken.off") {
        let s = stem(name);
        let open = lines
            .iter()
            .position(|l| *l == format!("Opening {name}."))
            .unwrap_or_else(|| panic!("no block for {name}:\n{stdout}"));
        let end = open
            + lines[open..]
                .iter()
                .position(|l| l.contains("(16) total CDT seconds"))
                .unwrap();
        let block = &lines[open..=end];
        assert!(
            block
                .iter()
                .all(|l| !l.starts_with("Opening ") || l.contains(name.as_str())),
            "{name}: {block:?}"
        );
        for ext in ["node", "ele", "face", "edge"] {
            let want = format!("Writing {s}.1.{ext}.");
            assert!(block.contains(&want.as_str()), "{name}: {block:?}");
        }
    }
    assert!(stdout.ends_with("8 models: 6 ok, 2 failed\n"), "{stdout}");
}

#[test]
fn the_first_failing_model_sets_the_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("broken.off"), BROKEN).unwrap();
    // missing.off is an I/O error (4), broken.off an input error (3).
    let (code, _, stderr) = run_in(d, &["-pQ", "missing.off", "broken.off"]);
    assert_eq!(code, 4, "{stderr}");
    let (code, _, stderr) = run_in(d, &["-pQ", "broken.off", "missing.off"]);
    assert_eq!(code, 3, "{stderr}");
    assert!(stderr.contains("tetcdt: missing.off: "), "{stderr}");
}

#[test]
fn batch_usage_errors_mesh_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d);
    let table: &[(&[&str], &str)] = &[
        (
            &["-pQ", "-o", "out", "cube.poly", "star.off"],
            "-o/--output names the outputs of a single input, but 2 inputs were given",
        ),
        (
            &["-pQ", "cube.poly", "star.off", "./cube.poly"],
            "./cube.poly is given twice",
        ),
        (
            &["-pQ", "--jobs", "0", "cube.poly", "star.off"],
            "invalid value '0' for '--jobs <N>'",
        ),
    ];
    for (args, want) in table {
        let (code, stdout, stderr) = run_in(d, args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert!(stderr.contains(want), "{args:?}: {stderr:?} lacks {want:?}");
        assert!(stdout.is_empty(), "{args:?}: {stdout}");
    }
    fs::copy(d.join("star.off"), d.join("cube.off")).unwrap();
    let (code, _, stderr) = run_in(d, &["-pQ", "cube.poly", "cube.off"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("cube.poly and cube.off would both write cube.1.node"),
        "{stderr}"
    );
    assert!(
        !fs::read_dir(d)
            .unwrap()
            .any(|e| e.unwrap().file_name().to_string_lossy().contains(".1.")),
        "no model may be meshed"
    );
}

#[test]
fn single_input_summary_and_stats_json() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    setup(d);
    let (code, stdout, stderr) = run_in(
        d,
        &[
            "-pQ",
            "--summary",
            "s.tsv",
            "--stats-json",
            "s.json",
            "cube.poly",
        ],
    );
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout, "", "one input prints no summary table");
    let tsv = fs::read_to_string(d.join("s.tsv")).unwrap();
    let rows: Vec<&str> = tsv.lines().collect();
    assert_eq!(rows.len(), 2, "{tsv}");
    assert!(rows[1].starts_with("cube.poly\tok\t0\t8\t0\t6\t"), "{tsv}");
    // A single run's record is the run's statistics on one line, as before batches.
    let json = fs::read_to_string(d.join("s.json")).unwrap();
    assert_eq!(json.lines().count(), 1, "{json}");
    assert_eq!(json_field(&json, "output_tets"), Some("6"));
    assert_eq!(json_field(&json, "status"), None, "{json}");

    // A failing single input still gets its summary row, and keeps its own exit code.
    fs::write(d.join("broken.off"), BROKEN).unwrap();
    let (code, _, stderr) = run_in(d, &["-pQ", "--summary", "f.tsv", "broken.off"]);
    assert_eq!(code, 3, "{stderr}");
    assert!(stderr.starts_with("tetcdt: broken.off:6:"), "{stderr}");
    let tsv = fs::read_to_string(d.join("f.tsv")).unwrap();
    assert!(
        tsv.lines()
            .nth(1)
            .unwrap()
            .starts_with("broken.off\tfailed\t3\t\t\t\t"),
        "{tsv}"
    );
}

#[test]
fn makefile_example_builds_meshes() {
    if std::process::Command::new("make")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("make is not installed: the Makefile example is not tested");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("some/dir");
    fs::create_dir_all(&sub).unwrap();
    setup(&sub);
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let bin = assert_cmd::cargo::cargo_bin("tetcdt");
    let make = |targets: &[&str]| {
        let out = std::process::Command::new("make")
            .current_dir(dir.path())
            .arg("-f")
            .arg(root.join("scripts/Makefile.example"))
            .arg(format!("TETCDT={}", bin.display()))
            .args(targets)
            .output()
            .unwrap();
        (
            out.status.code(),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    };
    let (code, out, err) = make(&["some/dir/star.1.ele", "some/dir/gridbox_3.1.node"]);
    assert_eq!(code, Some(0), "{out}{err}");
    for f in [
        "star.1.ele",
        "star.1.node",
        "star.1.face",
        "gridbox_3.1.ele",
    ] {
        assert!(sub.join(f).exists(), "{f}: {out}{err}");
    }
    assert!(
        !sub.join("cube.1.ele").exists(),
        "only the targets asked for"
    );
    // Up to date now: make runs nothing.
    let (code, out, _) = make(&["some/dir/star.1.ele"]);
    assert_eq!(code, Some(0));
    assert!(out.contains("up to date"), "{out}");
    // A broken model fails the make run with tetcdt's error.
    let (code, _, err) = make(&["some/dir/broken.1.ele"]);
    assert_ne!(code, Some(0));
    assert!(err.contains("broken.off:6:"), "{err}");
}

#[test]
fn progress_bars_only_on_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let names = setup(d);
    let good: Vec<&str> = good_models(&names);
    // Bars shown at once if at all: stderr is a pipe here, so none.
    for jobs in ["1", "2"] {
        let mut args = vec!["-p", "--jobs", jobs];
        args.extend(&good);
        let out = tetcdt()
            .current_dir(d)
            .env("TETCDT_PROGRESS_DELAY_MS", "0")
            .env_remove("CI")
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(0));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.is_empty(), "{stderr:?}");
        assert!(!has_control(&String::from_utf8_lossy(&out.stdout)));
    }

    // On a terminal (util-linux `script` gives one) they do appear, unless -Q or CI.
    if std::process::Command::new("script")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("script is not installed: bars on a terminal are not tested");
        return;
    }
    let bin = assert_cmd::cargo::cargo_bin("tetcdt");
    let on_tty = |switches: &str, ci: bool| {
        let cmd = format!(
            "'{}' {switches} --jobs 2 {} > /dev/null",
            bin.display(),
            good.join(" ")
        );
        let mut c = std::process::Command::new("script");
        c.current_dir(d)
            .stdin(std::process::Stdio::null())
            .env("TETCDT_PROGRESS_DELAY_MS", "0")
            .args(["-qec", &cmd, "/dev/null"]);
        if ci {
            c.env("CI", "true");
        } else {
            c.env_remove("CI");
        }
        let out = c.output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{out:?}");
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let shown = on_tty("-p", false);
    assert!(
        shown.contains("\x1b[") && shown.contains("cube.poly: "),
        "no bars on a terminal: {shown:?}"
    );
    let quiet = on_tty("-pQ", false);
    assert!(!quiet.contains("\x1b["), "{quiet:?}");
    let ci = on_tty("-p", true);
    assert!(!ci.contains("\x1b["), "{ci:?}");
}

#[test]
fn table1_script_tabulates_ours_beside_tetgen() {
    if std::process::Command::new("python3")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("python3 is not installed: scripts/table1.py is not tested");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let models = dir.path().join("models");
    fs::create_dir(&models).unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    fs::copy(data.join("plc/fig4_p.poly"), models.join("fig4_p.poly")).unwrap();
    fs::copy(data.join("plc/sphere.off"), models.join("sphere.off")).unwrap();
    fs::write(models.join("broken.off"), BROKEN).unwrap();
    let md = dir.path().join("t.md");
    let out = std::process::Command::new("python3")
        .arg(Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/table1.py"))
        .arg("--tetcdt")
        .arg(assert_cmd::cargo::cargo_bin("tetcdt"))
        .arg("--timeout")
        .arg("60")
        .arg("-o")
        .arg(&md)
        .arg(&models)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    let text = fs::read_to_string(&md).unwrap();
    let row = |label: &str| -> Vec<String> {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("| {label} |")))
            .unwrap_or_else(|| panic!("no row {label}:\n{text}"));
        line.trim_matches('|')
            .split('|')
            .map(|c| c.trim().to_string())
            .collect()
    };
    // Columns: broken, fig4_p, sphere (sorted), each "ours" then "TetGen".
    let head = row("row");
    assert_eq!(
        head[1..],
        [
            "broken ours",
            "broken TetGen",
            "fig4_p ours",
            "fig4_p TetGen",
            "sphere ours",
            "sphere TetGen"
        ]
    );
    let vertices = row("(1) input vertices");
    assert_eq!(vertices[1], "fail 3", "{text}");
    assert_eq!(vertices[3], "13");
    assert_eq!(vertices[5], "162");
    let tetgen = std::process::Command::new("tetgen")
        .arg("-h")
        .output()
        .is_ok();
    if tetgen {
        assert_eq!(vertices[4], "13");
        assert_eq!(vertices[6], "162");
        // The sphere needs no Steiner points: both give the same tets.
        let tets = row("(4) output tetrahedra");
        assert_eq!(tets[5], tets[6], "{text}");
    }
    // Our flip column is filled once -F exists, marked "n/a" while it is refused.
    let flips = row("(15) flip algorithm seconds");
    assert!(
        flips[3] == "n/a" || flips[3].parse::<f64>().is_ok(),
        "{text}"
    );
    assert!(text.contains("## Table 2"), "{text}");
    assert!(text.contains("| ours -p (cavity) | Delaunay |"), "{text}");
    assert!(
        text.contains("broken: `tetcdt -pQV`: MODEL:6: face 0 has corner 7"),
        "{text}"
    );
    // Nothing is written beside the models.
    assert_eq!(fs::read_dir(&models).unwrap().count(), 3);
}

#[test]
fn quality_batch_summary_has_quality_columns() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let names = setup(d);
    let good: Vec<&str> = good_models(&names).into_iter().take(3).collect();
    let mut args = vec!["-pq1.414Q", "--summary", "q.tsv"];
    args.extend(&good);
    let (code, stdout, stderr) = run_in(d, &args);
    assert_eq!(code, 0, "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        lines[0]
            .split("  ")
            .filter(|c| !c.is_empty())
            .map(str::trim)
            .collect::<Vec<_>>(),
        [
            "model",
            "status",
            "vertices",
            "Steiner",
            "tets",
            "seconds",
            "max ratio",
            "min dihedral",
            "left"
        ],
        "{stdout}"
    );
    let tsv = fs::read_to_string(d.join("q.tsv")).unwrap();
    for row in tsv.lines().skip(1) {
        let cells: Vec<&str> = row.split('\t').collect();
        let ratio: f64 = cells[7].parse().unwrap();
        let angle: f64 = cells[8].parse().unwrap();
        let left: usize = cells[9].parse().unwrap();
        // Every tet meets the bound, but those counted as left.
        assert!(ratio <= 1.414 || left > 0, "{row}");
        assert!(angle > 0.0 && angle < 90.0, "{row}");
        // The table shows the same figures.
        let line = lines.iter().find(|l| l.starts_with(cells[0])).unwrap();
        let shown: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(
            shown[shown.len() - 3..],
            [
                format!("{ratio:.3}"),
                format!("{angle:.2}"),
                left.to_string()
            ],
            "{line}"
        );
    }
}
