//! `tetcdt --certify PREFIX INPUT` on meshes it must accept (ours, and TetGen's plain
//! CDTs in `data/plc/ref/`) and on meshes it must reject (TetGen's plain CDTs that leave
//! shim tets, and an optimized mesh that is no CDT, in `data/certify/`), its usage and
//! input errors, and its agreement with the shared referee where that is found.

use assert_cmd::Command;
use std::fs;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `tetcdt ARGS`; (exit code, stdout, stderr).
fn tetcdt(args: &[&std::ffi::OsStr]) -> (i32, String, String) {
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .args(args)
        .timeout(std::time::Duration::from_secs(120))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn certify(prefix: &Path, input: &Path, extra: &[&str]) -> (i32, String, String) {
    let mut args: Vec<&std::ffi::OsStr> = extra.iter().map(|s| s.as_ref()).collect();
    args.push("--certify".as_ref());
    args.push(prefix.as_os_str());
    args.push(input.as_os_str());
    tetcdt(&args)
}

#[test]
fn tetgens_shim_meshes_are_rejected() {
    for (m, why) in [
        ("anchor", "is a shim"),
        ("fandisk", "is a shim"),
        ("mpi", "facet 34:"),
    ] {
        let prefix = root().join("data/certify").join(format!("{m}.pO0"));
        let input = root().join("data/nonflat").join(format!("{m}.off"));
        let (code, _, err) = certify(&prefix, &input, &[]);
        assert_eq!(code, 1, "{m}: {err}");
        assert!(err.contains("is not a CDT of"), "{m}: {err}");
        assert!(err.contains(why), "{m}: {err}");
    }
}

#[test]
fn tetgens_optimized_mesh_is_no_cdt() {
    let prefix = root().join("data/certify/rotor_small.p");
    let input = root().join("data/nonflat/rotor_small.off");
    let (code, _, err) = certify(&prefix, &input, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("lies on no facet and is not locally Delaunay"),
        "{err}"
    );
}

#[test]
fn tetgens_plain_cdts_and_ours_are_accepted() {
    let refs = root().join("data/plc/ref");
    let mut n = 0;
    for e in fs::read_dir(&refs).unwrap() {
        let path = e.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix(".1.ele") else {
            continue;
        };
        let input = ["off", "poly", "smesh", "stl", "ply"]
            .iter()
            .map(|x| root().join("data/plc").join(format!("{stem}.{x}")))
            .find(|p| p.is_file())
            .unwrap();
        let (code, out, err) = certify(&refs.join(format!("{stem}.1")), &input, &[]);
        assert_eq!(code, 0, "TetGen's {stem}: {err}");
        assert!(out.contains("is a CDT of"), "{stem}: {out}");
        n += 1;
    }
    assert!(n >= 15, "{n} references");
    // Ours, with Steiner points on polygons and free points, and with -M.
    let dir = tempfile::tempdir().unwrap();
    for (m, sw) in [("anchor", "-pQ"), ("fandisk", "-pQF"), ("mpi", "-pQM")] {
        let input = root().join("data/nonflat").join(format!("{m}.off"));
        let prefix = dir.path().join(m);
        let (code, _, err) = tetcdt(&[
            sw.as_ref(),
            "-o".as_ref(),
            prefix.as_os_str(),
            input.as_os_str(),
        ]);
        assert_eq!(code, 0, "{m}: {err}");
        let extra: &[&str] = if sw.contains('M') { &["-pM"] } else { &[] };
        let (code, out, err) = certify(&prefix, &input, extra);
        assert_eq!(code, 0, "{m} {sw}: {err}");
        assert!(out.contains("Steiner points"), "{out}");
    }
}

#[test]
fn a_tampered_file_is_caught() {
    let dir = tempfile::tempdir().unwrap();
    let input = root().join("data/examples/box_with_hole.poly");
    let prefix = dir.path().join("b");
    let (code, _, err) = tetcdt(&[
        "-pQ".as_ref(),
        "-o".as_ref(),
        prefix.as_os_str(),
        input.as_os_str(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(certify(&prefix, &input, &[]).0, 0);
    // The last tet dropped from the file: the mesh has a hole inside.
    let ele = prefix.with_extension("ele");
    let text = fs::read_to_string(&ele).unwrap();
    let mut lines: Vec<&str> = text.lines().filter(|l| !l.starts_with('#')).collect();
    let n: usize = lines[0].split_whitespace().next().unwrap().parse().unwrap();
    lines.truncate(n);
    let header = lines[0].replacen(&n.to_string(), &(n - 1).to_string(), 1);
    lines[0] = &header;
    fs::write(&ele, lines.join("\n") + "\n").unwrap();
    let (code, _, err) = certify(&prefix, &input, &[]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("lies on no facet"), "{err}");
}

#[test]
fn usage_and_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    let input = root().join("data/examples/cube.poly");
    // Two inputs, or a meshing option: usage errors.
    let (code, _, err) = tetcdt(&[
        "--certify".as_ref(),
        dir.path().join("x").as_os_str(),
        input.as_os_str(),
        input.as_os_str(),
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = certify(&dir.path().join("x"), &input, &["--check"]);
    assert_eq!(code, 2, "{err}");
    // No mesh files: an I/O error naming the file.
    let (code, _, err) = certify(&dir.path().join("x"), &input, &[]);
    assert_eq!(code, 4, "{err}");
    assert!(err.contains("x.node"), "{err}");
    // A malformed .ele: an invalid input naming the line.
    let prefix = dir.path().join("m");
    fs::write(
        prefix.with_extension("node"),
        "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n",
    )
    .unwrap();
    fs::write(prefix.with_extension("ele"), "1 4 0\n0 0 1 2 9\n").unwrap();
    let (code, _, err) = certify(&prefix, &input, &[]);
    assert_eq!(code, 3, "{err}");
    assert!(
        err.contains("m.ele:2: tet 0: node 9 does not exist"),
        "{err}"
    );
}

/// The shared referee and a python3 with numpy, if both are found.
fn referee() -> Option<PathBuf> {
    let script = [
        std::env::var_os("TETCDT_TOOLS").map(PathBuf::from),
        Some(root().join("../shared/tools")),
    ]
    .into_iter()
    .flatten()
    .map(|d| d.join("validate_mesh.py"))
    .find(|p| p.is_file())?;
    let numpy = std::process::Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    numpy.then_some(script)
}

#[test]
fn the_referee_agrees() {
    let Some(script) = referee() else {
        eprintln!("note: validate_mesh.py or numpy not found: skipping the referee");
        return;
    };
    let cases = [
        ("data/certify/anchor.pO0", "data/nonflat/anchor.off"),
        ("data/certify/mpi.pO0", "data/nonflat/mpi.off"),
        ("data/certify/rotor_small.p", "data/nonflat/rotor_small.off"),
        ("data/plc/ref/windows.1", "data/plc/windows.poly"),
        ("data/plc/ref/cosph_cube.1", "data/plc/cosph_cube.poly"),
    ];
    for (prefix, input) in cases {
        let (prefix, input) = (root().join(prefix), root().join(input));
        let ours = certify(&prefix, &input, &[]).0 == 0;
        let theirs = std::process::Command::new("python3")
            .arg(&script)
            .arg(&input)
            .arg(&prefix)
            .output()
            .unwrap()
            .status
            .success();
        assert_eq!(ours, theirs, "{}", prefix.display());
    }
}
