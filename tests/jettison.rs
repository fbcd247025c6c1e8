//! Points that no tet uses (outside the domain, in a hole, or repeating another point)
//! are left out of the output and the rest numbered in order, as TetGen does; `-J` keeps
//! them, as TetGen's `-J` does. Compared with TetGen's files in `data/jettison/ref/`
//! (written by `scripts/gen-jettison-reference.sh`).

use assert_cmd::Command;
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join("jettison")
}

/// The data rows of a TetGen file (comments and blank lines dropped), header first.
fn rows(path: &Path) -> Vec<Vec<String>> {
    let text = fs::read_to_string(path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (run scripts/gen-jettison-reference.sh)",
            path.display()
        )
    });
    text.lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .map(|l| l.split_whitespace().map(str::to_owned).collect::<Vec<_>>())
        .filter(|t| !t.is_empty())
        .collect()
}

/// A point as exact bits, so that coordinates compare as read.
type Key = [u64; 3];

/// A `.node` file: its points (with the marker, if the file has markers), in order.
fn nodes(path: &Path) -> Vec<(Key, Option<i64>)> {
    let r = rows(path);
    let n: usize = r[0][0].parse().unwrap();
    let markers = r[0].get(3).is_some_and(|m| m == "1");
    let attrs: usize = r[0][2].parse().unwrap();
    r[1..=n]
        .iter()
        .map(|x| {
            let key = [1, 2, 3].map(|k| x[k].parse::<f64>().unwrap().to_bits());
            let marker = markers.then(|| x[4 + attrs].parse().unwrap());
            (key, marker)
        })
        .collect()
}

/// The cells of a `.ele` or `.face` file as sets of points, with the files' first index.
fn cells(path: &Path, k: usize, pts: &[(Key, Option<i64>)]) -> BTreeSet<Vec<Key>> {
    let r = rows(path);
    let n: usize = r[0][0].parse().unwrap();
    let first: usize = r[1][0].parse().unwrap();
    r[1..=n]
        .iter()
        .map(|x| {
            let mut c: Vec<Key> = (1..=k)
                .map(|j| pts[x[j].parse::<usize>().unwrap() - first].0)
                .collect();
            c.sort();
            c
        })
        .collect()
}

/// Meshes `data/jettison/NAME.EXT` with `switches` and compares the output with TetGen's
/// (`ref/NAME[.J].1.*`): the same nodes, in the same order where `same_order`, and the
/// same tets and faces.
fn compare(name: &str, ext: &str, switches: &str, same_order: bool) {
    let tmp = tempfile::tempdir().unwrap();
    let prefix = tmp.path().join("out");
    Command::cargo_bin("tetcdt")
        .unwrap()
        .args([switches, "-o"])
        .arg(&prefix)
        .arg(dir().join(format!("{name}.{ext}")))
        .assert()
        .success();
    let j = if switches.contains('J') { ".J" } else { "" };
    let theirs = |kind: &str| dir().join("ref").join(format!("{name}{j}.1.{kind}"));
    let ours = |kind: &str| prefix.with_extension(kind);
    let (tn, on) = (nodes(&theirs("node")), nodes(&ours("node")));
    assert_eq!(on.len(), tn.len(), "{name} {switches}: node count");
    if same_order {
        assert_eq!(on, tn, "{name} {switches}: nodes (and markers) in order");
    } else {
        let set = |v: &[(Key, Option<i64>)]| v.iter().map(|p| p.0).collect::<BTreeSet<_>>();
        assert_eq!(set(&on), set(&tn), "{name} {switches}: node coordinates");
    }
    assert_eq!(
        cells(&ours("ele"), 4, &on),
        cells(&theirs("ele"), 4, &tn),
        "{name} {switches}: tets"
    );
    if ext == "poly" {
        assert_eq!(
            cells(&ours("face"), 3, &on),
            cells(&theirs("face"), 3, &tn),
            "{name} {switches}: faces"
        );
    }
}

#[test]
fn points_outside_the_domain_are_left_out_as_tetgen_does() {
    compare("outside_points", "poly", "-pQ", true);
    compare("outside_points", "poly", "-pQF", true);
}

#[test]
fn a_point_in_a_hole_is_left_out_as_tetgen_does() {
    compare("box_hole", "poly", "-pQ", true);
}

#[test]
fn a_repeated_point_is_left_out_as_tetgen_does() {
    compare("dup_corner", "poly", "-pQ", true);
    // TetGen keeps another copy of one point here, so only the order differs.
    compare("dup_points", "node", "-Q", false);
}

#[test]
fn with_j_every_point_stays_as_with_tetgens_j() {
    compare("outside_points", "poly", "-pJQ", true);
    compare("box_hole", "poly", "-pJQ", true);
    compare("dup_corner", "poly", "-pJQ", true);
    compare("dup_points", "node", "-JQ", true);
}

#[test]
fn the_verbose_run_counts_the_points_left_out() {
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .args(["-pV", "-o"])
        .arg(tempfile::tempdir().unwrap().path().join("out"))
        .arg(dir().join("outside_points.poly"))
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("Points in no tet left out of the output: 2"),
        "{text}"
    );
    assert!(text.contains("Mesh points: 9"), "{text}");
}
