//! Tests of the `tetcdt` command: switches, errors and exit codes, output naming and
//! atomic writes, and the writers' exact formats through the public API.

use assert_cmd::Command;
use std::fs;
use std::path::{Path, PathBuf};
use tetcdt::io::write::{self, FileKind, WriteOptions};
use tetcdt::MeshOut;

fn tetcdt() -> Command {
    Command::cargo_bin("tetcdt").unwrap()
}

/// Writes a `.node` file of `n` points in general position (a fixed pseudo-random
/// sequence), numbered from `first`.
fn write_points(path: &Path, n: usize, first: usize) -> Vec<[f64; 3]> {
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15 ^ n as u64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let pts: Vec<[f64; 3]> = (0..n).map(|_| [next(), next(), next()]).collect();
    let mut text = format!("# test points\n{n} 3 0 0\n");
    for (i, p) in pts.iter().enumerate() {
        text.push_str(&format!("{} {:?} {:?} {:?}\n", i + first, p[0], p[1], p[2]));
    }
    fs::write(path, text).unwrap();
    pts
}

/// The names of the files in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn stderr_of(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Runs tetcdt in `dir` with `args`; returns (exit code, stdout, stderr).
fn run_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = tetcdt().current_dir(dir).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr_of(&out),
    )
}

#[test]
fn usage_errors_exit_2_naming_the_switch() {
    let dir = tempfile::tempdir().unwrap();
    write_points(&dir.path().join("p.node"), 8, 1);
    let table: &[(&[&str], &str)] = &[
        (
            &["-c", "p.node"],
            "switch -c (convex hull retention) needs -p",
        ),
        (
            &["-q1.2", "p.node"],
            "switch -q (quality mesh generation) needs -p",
        ),
        (
            &["-a", "p.node"],
            "switch -a (maximum volume constraint) needs -p",
        ),
        (
            &["-pa0", "p.node"],
            "switch -a does not take the argument \"0\"",
        ),
        (&["-y", "p.node"], "unknown switch -y"),
        (&["-zy", "p.node"], "unknown switch -y"),
        (
            &["-O2", "p.node"],
            "switch -O2 (mesh optimization; only -O0 is accepted)",
        ),
        (&["-O", "p.node"], "switch -O (mesh optimization"),
        (&["-O/1", "p.node"], "switch -O/1 (mesh optimization"),
        (
            &["-C", "p.node"],
            "switch -C (cavity facet insertion) needs -p",
        ),
        (
            &["-F", "p.node"],
            "switch -F (flip facet insertion) needs -p",
        ),
        (&["-o2", "p.node"], "switch -o2 (second-order elements)"),
        (&["p.node", "-r"], "switch -r (reconstruct"),
        (
            &["-T1e-8Q", "p.node"],
            "switch -T1e-8 (coplanarity tolerance)",
        ),
        (&[], "required arguments were not provided"),
        (&["-zQ"], "required arguments were not provided"),
        (
            &["p.node", "q.node", "-o", "x"],
            "-o/--output names the outputs of a single input, but 2 inputs were given",
        ),
        (&["--bogus", "p.node"], "unexpected argument '--bogus'"),
        (
            &["p.node", "-o"],
            "a value is required for '--output <PREFIX>'",
        ),
    ];
    for (args, want) in table {
        let (code, stdout, stderr) = run_in(dir.path(), args);
        assert_eq!(code, 2, "tetcdt {args:?}: stderr {stderr}");
        assert!(stderr.starts_with("tetcdt: "), "tetcdt {args:?}: {stderr}");
        assert!(
            stderr.contains(want),
            "tetcdt {args:?}: {stderr:?} lacks {want:?}"
        );
        assert!(stdout.is_empty(), "tetcdt {args:?}: stdout {stdout}");
    }
    // Nothing was written by any of them.
    assert_eq!(listing(dir.path()), ["p.node"]);
}

#[test]
fn every_problem_of_a_switch_string_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    write_points(&dir.path().join("p.node"), 8, 1);
    let (code, _, stderr) = run_in(dir.path(), &["-pq1.2/95a0.5ryV", "p.node"]);
    assert_eq!(code, 2);
    for want in [
        "-q does not take the argument \"1.2/95\"",
        "-r (",
        "unknown switch -y",
    ] {
        assert!(stderr.contains(want), "{stderr:?} lacks {want:?}");
    }
}

#[test]
fn input_errors_exit_3_or_4() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(d.join("bad.node"), "4 3 0 0\n1 0 0 0\n2 1 zero 0\n").unwrap();
    fs::write(d.join("short.node"), "4 3 0 0\n1 0 0 0\n").unwrap();
    fs::write(d.join("binary.node"), [0u8, 159, 146, 150, 255, 10, 1, 2]).unwrap();
    fs::write(d.join("model.txt"), "hello\n").unwrap();
    fs::create_dir(d.join("adir.node")).unwrap();
    let table: &[(&str, i32, &str)] = &[
        ("missing.node", 4, "missing.node"),
        ("adir.node", 4, "adir.node"),
        ("bad.node", 3, "bad.node:3"),
        ("short.node", 3, "short.node"),
        ("binary.node", 3, "binary.node"),
        ("model.txt", 3, "unknown input format"),
    ];
    for &(file, want_code, want) in table {
        let (code, _, stderr) = run_in(d, &["-Q", file]);
        assert_eq!(code, want_code, "{file}: {stderr}");
        assert!(stderr.starts_with("tetcdt: "), "{file}: {stderr}");
        assert!(stderr.contains(want), "{file}: {stderr:?} lacks {want:?}");
        assert!(!stderr.contains("panicked"), "{file}: {stderr}");
    }
    let mut want = vec![
        "adir.node",
        "bad.node",
        "binary.node",
        "model.txt",
        "short.node",
    ];
    want.sort_unstable();
    assert_eq!(listing(d), want, "no output may be written");
}

#[test]
fn help_and_version() {
    for flag in ["--help", "-h"] {
        let out = tetcdt().arg(flag).output().unwrap();
        assert_eq!(out.status.code(), Some(0));
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("Usage: tetcdt [-switches]"), "{text}");
        for want in [
            "-z ",
            "-Q ",
            "-O0",
            "--check",
            "--output <PREFIX>",
            "Exit codes",
        ] {
            assert!(text.contains(want), "help lacks {want:?}:\n{text}");
        }
    }
    let out = tetcdt().arg("--version").output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(text.trim(), format!("tetcdt {}", env!("CARGO_PKG_VERSION")));
}

#[test]
fn check_validates_the_written_mesh() {
    let dir = tempfile::tempdir().unwrap();
    write_points(&dir.path().join("p.node"), 30, 1);
    let (code, stdout, stderr) = run_in(dir.path(), &["--check", "p.node"]);
    assert_eq!(code, 0, "{stderr}");
    // The figures are those of the files written, which --certify confirms.
    let tets = data_lines(&dir.path().join("p.1.ele")).len() - 1;
    assert!(
        stdout.contains(&format!("Mesh check passed: {tets} tets, 0 Steiner points")),
        "{stdout}"
    );
    let (code, stdout, stderr) = run_in(dir.path(), &["--certify", "p.1", "p.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains(&format!("{tets} tets")), "{stdout}");
    // The same files, one tet short: the certifier the check runs rejects them.
    let ele = dir.path().join("p.1.ele");
    let mut rows = data_lines(&ele);
    rows.pop();
    rows[0][0] = (tets - 1).to_string();
    let text: Vec<String> = rows.iter().map(|r| r.join(" ")).collect();
    fs::write(&ele, text.join("\n") + "\n").unwrap();
    let (code, _, stderr) = run_in(dir.path(), &["--certify", "p.1", "p.node"]);
    assert_eq!(code, 1, "{stderr}");
    assert!(
        stderr.contains("is not the Delaunay tetrahedralization"),
        "{stderr}"
    );
    let (code, stdout, stderr) = run_in(dir.path(), &["-Qz", "p.node", "--check"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout, "");
}

/// Reads a TetGen file's data lines (comments and blank lines dropped), as tokens.
fn data_lines(path: &Path) -> Vec<Vec<String>> {
    fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .map(|l| l.split_whitespace().map(str::to_owned).collect::<Vec<_>>())
        .filter(|t| !t.is_empty())
        .collect()
}

/// A mesh read back from tetcdt's files.
struct ReadBack {
    first: usize,
    points: Vec<[f64; 3]>,
    tets: Vec<[usize; 4]>,
}

/// Reads `<prefix>.node` and `<prefix>.ele` back and checks their headers, numbering and
/// tet orientation (TetGen's: orient3d < 0).
fn read_back(prefix: &Path) -> ReadBack {
    let node = data_lines(&write::output_path(prefix, FileKind::Node));
    let n: usize = node[0][0].parse().unwrap();
    assert_eq!(node[0][1], "3");
    assert_eq!(node.len(), n + 1);
    let first: usize = node[1][0].parse().unwrap();
    assert!(first <= 1);
    let mut points = Vec::new();
    for (i, l) in node[1..].iter().enumerate() {
        assert_eq!(l[0].parse::<usize>().unwrap(), i + first);
        points.push([
            l[1].parse().unwrap(),
            l[2].parse().unwrap(),
            l[3].parse().unwrap(),
        ]);
    }
    let ele = data_lines(&write::output_path(prefix, FileKind::Ele));
    let t: usize = ele[0][0].parse().unwrap();
    assert_eq!(ele[0][1..], ["4", "0"]);
    assert_eq!(ele.len(), t + 1);
    let mut tets = Vec::new();
    for (i, l) in ele[1..].iter().enumerate() {
        assert_eq!(l[0].parse::<usize>().unwrap(), i + first);
        let v: Vec<usize> = l[1..5]
            .iter()
            .map(|s| s.parse::<usize>().unwrap() - first)
            .collect();
        assert!(v.iter().all(|&x| x < n), "tet {l:?} out of range");
        tets.push([v[0], v[1], v[2], v[3]]);
    }
    let rb = ReadBack {
        first,
        points,
        tets,
    };
    for t in &rb.tets {
        assert!(
            orient(&rb, t[0], t[1], t[2], t[3]) < 0.0,
            "tet {t:?} not in TetGen's orientation"
        );
    }
    rb
}

fn orient(rb: &ReadBack, a: usize, b: usize, c: usize, d: usize) -> f64 {
    let p = |i: usize| robust::Coord3D {
        x: rb.points[i][0],
        y: rb.points[i][1],
        z: rb.points[i][2],
    };
    robust::orient3d(p(a), p(b), p(c), p(d))
}

/// Faces of the tets as sorted triples, with how many tets hold each.
fn face_counts(tets: &[[usize; 4]]) -> std::collections::BTreeMap<[usize; 3], usize> {
    let mut m = std::collections::BTreeMap::new();
    for t in tets {
        for j in 0..4 {
            let mut f: Vec<usize> = (0..4).filter(|&k| k != j).map(|k| t[k]).collect();
            f.sort_unstable();
            *m.entry([f[0], f[1], f[2]]).or_insert(0) += 1;
        }
    }
    m
}

/// Checks the `.face` file of a point set: the hull faces, once each, pointing out.
fn check_hull_faces(prefix: &Path, rb: &ReadBack) {
    let face = data_lines(&write::output_path(prefix, FileKind::Face));
    assert_eq!(face[0][1], "0", "hull faces carry no markers");
    let counts = face_counts(&rb.tets);
    let hull: Vec<&[usize; 3]> = counts.iter().filter(|e| *e.1 == 1).map(|e| e.0).collect();
    assert_eq!(face[0][0].parse::<usize>().unwrap(), hull.len());
    assert_eq!(face.len(), hull.len() + 1);
    let mut seen = Vec::new();
    for l in &face[1..] {
        assert_eq!(l.len(), 4, "{l:?}");
        let f: Vec<usize> = l[1..4]
            .iter()
            .map(|s| s.parse::<usize>().unwrap() - rb.first)
            .collect();
        let t = rb
            .tets
            .iter()
            .find(|t| f.iter().all(|x| t.contains(x)))
            .expect("face of no tet");
        let apex = *t.iter().find(|x| !f.contains(x)).unwrap();
        assert!(
            orient(rb, f[0], f[1], f[2], apex) > 0.0,
            "hull face {l:?} points inwards"
        );
        let mut s = f.clone();
        s.sort_unstable();
        seen.push(s);
    }
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), hull.len());
}

#[test]
fn default_names_progress_and_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let pts = write_points(&d.join("cube.node"), 12, 1);
    let (code, stdout, stderr) = run_in(d, &["-O0", "cube.node"]);
    assert_eq!(code, 0, "{stderr}");
    for want in [
        "Opening cube.node.",
        "Delaunizing vertices...",
        "Writing cube.1.node.",
        "Writing cube.1.ele.",
        "Writing cube.1.face.",
    ] {
        assert!(stdout.contains(want), "stdout lacks {want:?}:\n{stdout}");
    }
    assert!(!stdout.contains("Statistics"), "{stdout}");
    assert_eq!(
        listing(d),
        ["cube.1.ele", "cube.1.face", "cube.1.node", "cube.node"]
    );
    let rb = read_back(&d.join("cube.1"));
    assert_eq!(rb.first, 1);
    assert_eq!(rb.points, pts, "coordinates must read back exactly");
    check_hull_faces(&d.join("cube.1"), &rb);
    let text = fs::read_to_string(d.join("cube.1.ele")).unwrap();
    assert!(
        text.ends_with("# Generated by tetcdt -O0 cube.node\n"),
        "{text}"
    );

    // A second run on the first run's output increments the iteration number, as TetGen does.
    fs::copy(d.join("cube.node"), d.join("x.1.node")).unwrap();
    let (code, _, stderr) = run_in(d, &["-Q", "x.1.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        d.join("x.2.node").exists() && d.join("x.2.ele").exists() && d.join("x.2.face").exists()
    );
}

#[test]
fn file_names_starting_with_a_dash_follow_double_dash() {
    let dir = tempfile::tempdir().unwrap();
    write_points(&dir.path().join("-m.node"), 8, 1);
    let (code, _, stderr) = run_in(dir.path(), &["-Q", "--", "-m.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(dir.path().join("-m.1.ele").exists());
    // Without `--` it is a switch string: refused, naming the letters.
    let (code, _, stderr) = run_in(dir.path(), &["-Q", "-m.node", "other.node"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("-m (mesh sizing function)"), "{stderr}");
}

#[test]
fn quiet_and_verbose() {
    let dir = tempfile::tempdir().unwrap();
    write_points(&dir.path().join("p.node"), 10, 1);
    let (code, stdout, stderr) = run_in(dir.path(), &["-Q", "p.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(stdout, "");
    assert_eq!(stderr, "");
    let (code, stdout, stderr) = run_in(dir.path(), &["-VO0", "p.node"]);
    assert_eq!(code, 0, "{stderr}");
    for want in [
        "Statistics:",
        "Input points: 10",
        "Mesh points: 10",
        "Mesh tetrahedra:",
        "Convex hull faces:",
    ] {
        assert!(stdout.contains(want), "stdout lacks {want:?}:\n{stdout}");
    }
}

#[test]
fn no_iteration_and_output_prefix() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_points(&d.join("p.node"), 9, 0);
    fs::create_dir(d.join("in")).unwrap();
    write_points(&d.join("in/y.node"), 9, 1);

    // -I on y.node would write y.node over the input: refused, input untouched.
    let before = fs::read(d.join("in/y.node")).unwrap();
    let (code, _, stderr) = run_in(d, &["-I", "in/y.node"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("would overwrite the input file"),
        "{stderr}"
    );
    assert_eq!(fs::read(d.join("in/y.node")).unwrap(), before);
    assert_eq!(listing(&d.join("in")), ["y.node"]);

    // -I with -o elsewhere is fine; -o alone too; both keep the input's numbering.
    let (code, _, stderr) = run_in(d, &["-QIe", "-o", "in/mesh", "p.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(
        listing(&d.join("in")),
        ["mesh.edge", "mesh.ele", "mesh.face", "mesh.node", "y.node"]
    );
    assert_eq!(read_back(&d.join("in/mesh")).first, 0);
    let (code, _, stderr) = run_in(d, &["p.node", "--output", "out.v2", "-Qn"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(d.join("out.v2.node").exists() && d.join("out.v2.neigh").exists());
    assert!(!d.join("out.v2.edge").exists());

    // -o naming the input itself is refused like -I.
    let (code, _, stderr) = run_in(d, &["-Q", "-o", "p", "p.node"]);
    assert_eq!(code, 2, "{stderr}");

    // w.1.node: -I would write w.1.node again (refused); without -I the outputs are w.2.*.
    fs::create_dir(d.join("z")).unwrap();
    write_points(&d.join("z/w.1.node"), 9, 1);
    let (code, _, stderr) = run_in(d, &["-QI", "z/w.1.node"]);
    assert_eq!(code, 2, "w.1.node with -I writes w.1.node: {stderr}");
    let (code, _, stderr) = run_in(d, &["-Qz", "z/w.1.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(
        listing(&d.join("z")),
        ["w.1.node", "w.2.ele", "w.2.face", "w.2.node"]
    );
    assert_eq!(read_back(&d.join("z/w.2")).first, 0, "-z numbers from 0");
}

#[test]
fn switch_files_edges_neighbors_all_faces() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_points(&d.join("p.node"), 14, 1);
    let (code, _, stderr) = run_in(d, &["-fenQ", "p.node"]);
    assert_eq!(code, 0, "{stderr}");
    let rb = read_back(&d.join("p.1"));
    let counts = face_counts(&rb.tets);
    // .face: every face once, marker 1 on the hull, 0 inside.
    let face = data_lines(&d.join("p.1.face"));
    assert_eq!(face[0], [counts.len().to_string(), "1".into()]);
    for l in &face[1..] {
        let mut f: Vec<usize> = l[1..4]
            .iter()
            .map(|s| s.parse::<usize>().unwrap() - 1)
            .collect();
        f.sort_unstable();
        let want = if counts[&[f[0], f[1], f[2]]] == 1 {
            "1"
        } else {
            "0"
        };
        assert_eq!(l[4], want, "{l:?}");
    }
    // .edge: every edge once, marker 1 on the hull.
    let mut edges = std::collections::BTreeSet::new();
    for t in &rb.tets {
        for i in 0..4 {
            for j in i + 1..4 {
                edges.insert((t[i].min(t[j]), t[i].max(t[j])));
            }
        }
    }
    let edge = data_lines(&d.join("p.1.edge"));
    assert_eq!(edge[0], [edges.len().to_string(), "1".into()]);
    let mut listed = std::collections::BTreeSet::new();
    for l in &edge[1..] {
        let (a, b) = (
            l[1].parse::<usize>().unwrap() - 1,
            l[2].parse::<usize>().unwrap() - 1,
        );
        assert!(listed.insert((a.min(b), a.max(b))), "edge {l:?} twice");
        let on_hull = counts
            .iter()
            .any(|(f, &c)| c == 1 && f.contains(&a) && f.contains(&b));
        assert_eq!(l[3], if on_hull { "1" } else { "0" }, "{l:?}");
    }
    assert_eq!(listed, edges);
    // .neigh: symmetric, -1 exactly on hull faces.
    let neigh = data_lines(&d.join("p.1.neigh"));
    assert_eq!(neigh[0], [rb.tets.len().to_string(), "4".into()]);
    for (i, l) in neigh[1..].iter().enumerate() {
        for j in 0..4 {
            let n: i64 = l[1 + j].parse().unwrap();
            let t = rb.tets[i];
            let mut f: Vec<usize> = (0..4).filter(|&k| k != j).map(|k| t[k]).collect();
            f.sort_unstable();
            if n == -1 {
                assert_eq!(counts[&[f[0], f[1], f[2]]], 1);
            } else {
                let o = &rb.tets[(n - 1) as usize];
                assert!(
                    f.iter().all(|x| o.contains(x)),
                    "tet {i} neighbour {n} shares no face"
                );
            }
        }
    }
}

#[test]
fn failures_leave_no_partial_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_points(&d.join("p.node"), 8, 1);

    // Output directory missing: refused before meshing, nothing created.
    let (code, stdout, stderr) = run_in(d, &["-o", "no/such/dir/m", "p.node"]);
    assert_eq!(code, 4, "{stderr}");
    assert!(stderr.contains("no/such/dir/m.node"), "{stderr}");
    assert!(!stdout.contains("Writing"), "{stdout}");
    assert_eq!(listing(d), ["p.node"]);

    // An earlier run's outputs, then a run whose .face is blocked by a directory:
    // it fails with exit 4, keeps the earlier files intact and leaves no temporaries.
    let (code, _, stderr) = run_in(d, &["-Q", "p.node"]);
    assert_eq!(code, 0, "{stderr}");
    let node_before = fs::read(d.join("p.1.node")).unwrap();
    fs::remove_file(d.join("p.1.face")).unwrap();
    fs::create_dir(d.join("p.1.face")).unwrap();
    write_points(&d.join("p.node"), 9, 1);
    let (code, _, stderr) = run_in(d, &["-Q", "p.node"]);
    assert_eq!(code, 4, "{stderr}");
    assert!(stderr.contains("p.1.face"), "{stderr}");
    assert_eq!(fs::read(d.join("p.1.node")).unwrap(), node_before);
    assert_eq!(listing(d), ["p.1.ele", "p.1.face", "p.1.node", "p.node"]);

    // -o prefix in a directory that is a file.
    fs::write(d.join("plain"), "").unwrap();
    let (code, _, stderr) = run_in(d, &["-Q", "-o", "plain/m", "p.node"]);
    assert_eq!(code, 4, "{stderr}");
    assert_eq!(
        listing(d),
        ["p.1.ele", "p.1.face", "p.1.node", "p.node", "plain"]
    );
}

#[test]
fn warnings_go_to_stderr_unless_quiet() {
    let dir = tempfile::tempdir().unwrap();
    let text = "6 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 0 0\n6 0.2 0.2 0.2\n";
    fs::write(dir.path().join("dup.node"), text).unwrap();
    let (code, stdout, stderr) = run_in(dir.path(), &["dup.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.starts_with("Warning: "), "{stderr}");
    assert!(stderr.contains("duplicate"), "{stderr}");
    assert!(!stdout.contains("Warning"), "{stdout}");
    let (code, stdout, stderr) = run_in(dir.path(), &["-Q", "dup.node"]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!((stdout.as_str(), stderr.as_str()), ("", ""));
}

#[test]
fn degenerate_input_is_an_input_error() {
    let dir = tempfile::tempdir().unwrap();
    // Coplanar points: no tetrahedron exists.
    fs::write(
        dir.path().join("flat.node"),
        "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 1 1 0\n",
    )
    .unwrap();
    let (code, _, stderr) = run_in(dir.path(), &["-Q", "flat.node"]);
    assert_eq!(code, 3, "{stderr}");
    assert!(stderr.starts_with("tetcdt: "), "{stderr}");
    assert_eq!(listing(dir.path()), ["flat.node"]);
}

/// Meshes every example point set shipped in `data/examples/` and reads the files back.
#[test]
fn examples_mesh_and_read_back() {
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples");
    let Ok(entries) = fs::read_dir(&examples) else {
        return;
    };
    let mut nodes: Vec<PathBuf> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "node"))
        .collect();
    nodes.sort();
    let out = tempfile::tempdir().unwrap();
    for input in nodes {
        let Ok(plc) = tetcdt::io::read_plc(&input) else {
            continue;
        };
        let stem = input.file_stem().unwrap().to_string_lossy().into_owned();
        let prefix = out.path().join(&stem);
        let cmd = tetcdt()
            .args(["-Qfen", "-o"])
            .arg(&prefix)
            .arg(&input)
            .output()
            .unwrap();
        assert_eq!(
            cmd.status.code(),
            Some(0),
            "{}: {}",
            input.display(),
            stderr_of(&cmd)
        );
        let rb = read_back(&prefix);
        assert_eq!(rb.first, plc.first_index, "{stem}");
        assert_eq!(
            rb.points, plc.points,
            "{stem}: coordinates must read back exactly"
        );
        for f in ["face", "edge", "neigh"] {
            assert!(
                out.path().join(format!("{stem}.{f}")).exists(),
                "{stem}.{f}"
            );
        }
    }
}

/// The writers' exact text on a hand-made mesh of two tets, through the public API.
#[test]
fn writer_formats_on_two_tets() {
    let mesh = MeshOut {
        points: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.25, 0.25, 1.0],
            [0.25, 0.25, -0.1],
        ],
        num_point_attrs: 1,
        point_attrs: vec![0.5, 1.0, 2.0, 1e-7, 0.1],
        point_markers: Some(vec![1, 2, 3, 0, -1]),
        tets: vec![[0, 1, 2, 3], [1, 0, 2, 4]],
        neighbors: vec![[-1, -1, -1, 1], [-1, -1, -1, 0]],
        first_index: 1,
        ..Default::default()
    };
    let w = WriteOptions {
        write_edges: true,
        write_neighbors: true,
        comment: Some("Generated by test".into()),
        ..Default::default()
    };
    let render = |kind, w: &WriteOptions| {
        let mut out = Vec::new();
        write::write_kind(&mut out, kind, &mesh, w).unwrap();
        String::from_utf8(out).unwrap()
    };
    assert_eq!(
        render(FileKind::Node, &w),
        "5  3  1  1\n\
         \u{20}  1    0  0  0  0.5    1\n\
         \u{20}  2    1  0  0  1    2\n\
         \u{20}  3    0  1  0  2    3\n\
         \u{20}  4    0.25  0.25  1  1e-7    0\n\
         \u{20}  5    0.25  0.25  -0.1  0.1    -1\n\
         # Generated by test\n"
    );
    assert_eq!(
        render(FileKind::Ele, &w),
        "2  4  0\n    1       1     2     3     4\n    2       2     1     3     5\n# Generated by test\n"
    );
    assert_eq!(
        render(FileKind::Face, &w),
        "6  0\n\
         \u{20}   1      2     3     4\n\
         \u{20}   2      1     4     3\n\
         \u{20}   3      1     2     4\n\
         \u{20}   4      1     3     5\n\
         \u{20}   5      2     5     3\n\
         \u{20}   6      2     1     5\n\
         # Generated by test\n"
    );
    assert_eq!(
        render(FileKind::Edge, &w),
        "9  1\n\
         \u{20}   1      1     2  1\n\
         \u{20}   2      1     3  1\n\
         \u{20}   3      1     4  1\n\
         \u{20}   4      2     3  1\n\
         \u{20}   5      2     4  1\n\
         \u{20}   6      3     4  1\n\
         \u{20}   7      2     5  1\n\
         \u{20}   8      1     5  1\n\
         \u{20}   9      3     5  1\n\
         # Generated by test\n"
    );
    assert_eq!(
        render(FileKind::Neigh, &w),
        "2  4\n   1      -1    -1    -1     2\n   2      -1    -1    -1     1\n# Generated by test\n"
    );
    let wz = WriteOptions {
        zero_based: true,
        all_faces: true,
        comment: None,
        ..w.clone()
    };
    assert_eq!(
        render(FileKind::Face, &wz),
        "7  1\n\
         \u{20}   0      1     3     2  1\n\
         \u{20}   1      0     2     3  1\n\
         \u{20}   2      0     3     1  1\n\
         \u{20}   3      0     1     2  0\n\
         \u{20}   4      0     4     2  1\n\
         \u{20}   5      1     2     4  1\n\
         \u{20}   6      1     4     0  1\n"
    );
    assert_eq!(
        write::file_kinds(false, &w),
        [
            FileKind::Node,
            FileKind::Ele,
            FileKind::Face,
            FileKind::Edge,
            FileKind::Neigh
        ]
    );
    assert_eq!(
        write::file_kinds(true, &WriteOptions::default()),
        [
            FileKind::Node,
            FileKind::Ele,
            FileKind::Face,
            FileKind::Edge
        ]
    );
}

#[test]
fn stats_json_matches_the_written_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let src =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples/box_with_hole.poly");
    fs::copy(&src, dir.path().join("b.poly")).unwrap();
    let (code, _, stderr) = run_in(dir.path(), &["-pQ", "--stats-json", "s.json", "b.poly"]);
    assert_eq!(code, 0, "{stderr}");
    let json = fs::read_to_string(dir.path().join("s.json")).unwrap();
    let ele = fs::read_to_string(dir.path().join("b.1.ele")).unwrap();
    let tets: usize = ele.split_whitespace().next().unwrap().parse().unwrap();
    assert!(json.contains(&format!("\"output_tets\": {tets}")), "{json}");
    assert!(
        json.contains("\"plc\": true") && json.contains("\"crossing_tets\""),
        "{json}"
    );
}

/// The number after `"key": ` in a flat JSON object.
fn json_number(json: &str, key: &str) -> f64 {
    let at = json
        .find(&format!("\"{key}\": "))
        .unwrap_or_else(|| panic!("no {key} in {json}"));
    let rest = &json[at + key.len() + 4..];
    let end = rest
        .find(|c: char| c == ',' || c == '}' || c.is_whitespace())
        .unwrap_or(rest.len());
    rest[..end].parse().unwrap()
}

/// `-F`'s stuck regions and fallbacks reach `-V` and `--stats-json`: the 19-gon of
/// `tests/flip.rs` (4 stuck regions, 2 of them given the cavity code's point, 1 fallback).
#[test]
fn flip_fallbacks_and_stuck_regions_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/flip/bent_19gon_60.poly");
    fs::copy(&src, dir.path().join("p.poly")).unwrap();
    let (code, stdout, stderr) = run_in(dir.path(), &["-pcFV", "--stats-json", "s.json", "p.poly"]);
    assert_eq!(code, 0, "{stderr}");
    let json = fs::read_to_string(dir.path().join("s.json")).unwrap();
    assert_eq!(json_number(&json, "flip_fallbacks"), 1.0, "{json}");
    assert_eq!(json_number(&json, "flip_not_flat_stuck"), 4.0, "{json}");
    assert_eq!(
        json_number(&json, "flip_not_flat_cavity_points"),
        2.0,
        "{json}"
    );
    let text = format!("{stdout}{stderr}");
    for (row, value) in [
        ("fallbacks to cavity retriangulation", "1"),
        ("stuck on polygons not flat: Steiner points", "4"),
        ("of which placed by the cavity code", "2"),
    ] {
        let line = text
            .lines()
            .find(|l| l.contains(row))
            .unwrap_or_else(|| panic!("no row {row:?} in {text}"));
        let after = &line[line.find(row).unwrap() + row.len()..];
        assert_eq!(after.split_whitespace().next(), Some(value), "{line}");
    }
}

#[test]
fn the_facets_triangulation_is_timed_apart_from_facet_recovery_as_tetgen_times_it() {
    // TetGen reports "Surface mesh seconds" apart from "Facet recovery seconds"; Figure 9
    // compares the latter, so ours must not include the facets' 2D triangulation.
    let dir = tempfile::tempdir().unwrap();
    let src =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples/box_with_hole.poly");
    fs::copy(&src, dir.path().join("b.poly")).unwrap();
    let (code, stdout, stderr) = run_in(dir.path(), &["-pV", "--stats-json", "s.json", "b.poly"]);
    assert_eq!(code, 0, "{stderr}");
    let json = fs::read_to_string(dir.path().join("s.json")).unwrap();
    let surface = json_number(&json, "surface_secs");
    let facet = json_number(&json, "facet_secs");
    let total = json_number(&json, "total_secs");
    assert!(surface > 0.0 && facet > 0.0, "{json}");
    assert!(surface + facet <= total, "{json}");
    let text = format!("{stdout}{stderr}");
    let row = text
        .find("surface triangulation seconds")
        .unwrap_or_else(|| panic!("no surface row in {text}"));
    assert!(
        row < text.find("(14) facet recovery seconds").unwrap(),
        "{text}"
    );
}

#[test]
fn an_open_surface_is_refused_before_meshing_naming_its_rim() {
    let dir = tempfile::tempdir().unwrap();
    // A box without its top: nothing is enclosed.
    let off = "OFF\n8 5 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n\
               4 0 2 3 1\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
    fs::write(dir.path().join("open.off"), off).unwrap();
    let (code, _, err) = run_in(dir.path(), &["-pQ", "open.off"]);
    assert_eq!(code, 3, "{err}");
    assert!(err.contains("the meshed domain would be empty"), "{err}");
    assert!(err.contains("4 boundary edge(s)"), "{err}");
    assert!(err.contains("4 (0, 0, 1) – 5 (1, 0, 1)"), "{err}");
    assert_eq!(listing(dir.path()), vec!["open.off"]);
    // With -c the convex hull is meshed instead.
    let (code, _, err) = run_in(dir.path(), &["-pcQ", "open.off"]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn a_fin_outside_a_closed_surface_is_refused_without_output() {
    let dir = tempfile::tempdir().unwrap();
    // A unit cube (triangulated) with a triangle fin on its edge 4-5, outside it.
    let off = "OFF\n9 13 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n0.5 -1 2\n\
               3 0 2 3\n3 0 3 1\n3 4 5 7\n3 4 7 6\n3 0 1 5\n3 0 5 4\n3 2 6 7\n3 2 7 3\n\
               3 0 4 6\n3 0 6 2\n3 1 3 7\n3 1 7 5\n3 4 5 8\n";
    fs::write(dir.path().join("fin.off"), off).unwrap();
    let (code, _, err) = run_in(dir.path(), &["-pe", "fin.off"]);
    assert_eq!(code, 3, "{err}");
    assert!(
        err.contains("2 polygon edge(s) lie outside the meshed domain")
            && err.contains("5 (1, 0, 1) – 8 (0.5, -1, 2) of facet 12"),
        "{err}"
    );
    assert_eq!(listing(dir.path()), vec!["fin.off"]);
    // With -c the fin is inside the hull, and kept as a constraint.
    let (code, _, err) = run_in(dir.path(), &["-pceQ", "--check", "fin.off"]);
    assert_eq!(code, 0, "{err}");
    let edges = fs::read_to_string(dir.path().join("fin.1.edge")).unwrap();
    assert!(edges.lines().any(|l| {
        let t: Vec<&str> = l.split_whitespace().collect();
        t.len() >= 3 && (t[1] == "8" || t[2] == "8")
    }));
}
