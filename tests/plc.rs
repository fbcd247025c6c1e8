//! Tests of the PLC pipeline (`tetcdt -p`) on the small models in `data/plc/`.
//!
//! - Every model meshes (exit 0) and passes our own `--check`.
//! - Where python3 with numpy and the shared referee `validate_mesh.py` are found
//!   (`$TETCDT_TOOLS`, else `../shared/tools` next to the repository), every mesh also
//!   passes the referee; otherwise that part is skipped with a note.
//! - Where TetGen adds no Steiner points and its mesh is valid, our tets are exactly
//!   TetGen's (`data/plc/ref/`, written by `scripts/gen-plc-reference.sh`), nodes matched
//!   by coordinates.
//! - Switches: `-M` keeps coplanar quads apart, `-A` writes region attributes, `-c` keeps
//!   the convex hull, and a hole point carves its cavity.
//!
//! The models are written by `scripts/gen-plc-models.py` (see `data/plc/README.md` and
//! `data/plc/LICENSES.md`).

use assert_cmd::Command;
use std::collections::{BTreeSet, HashMap};
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

fn tetcdt() -> Command {
    Command::cargo_bin("tetcdt").unwrap()
}

fn plc_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join("plc")
}

/// The model files in `data/plc/` (not in `ref/`), sorted.
fn models() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = fs::read_dir(plc_dir())
        .expect("data/plc/ is missing (python3 scripts/gen-plc-models.py)")
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.is_file()
                && matches!(
                    p.extension().and_then(|e| e.to_str()),
                    Some("off" | "poly" | "smesh" | "obj" | "stl" | "ply" | "mesh")
                )
        })
        .collect();
    v.sort();
    assert!(
        v.len() >= 20,
        "expected the PLC models in {}",
        plc_dir().display()
    );
    v
}

fn model(name: &str) -> PathBuf {
    let p = plc_dir().join(name);
    assert!(p.is_file(), "{} is missing", p.display());
    p
}

fn file_name(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

/// Runs `tetcdt ARGS -o PREFIX MODEL`; returns (exit code, stderr).
fn run(model: &Path, prefix: &Path, args: &[&str]) -> (i32, String) {
    let out = tetcdt()
        .args(args)
        .arg("-o")
        .arg(prefix)
        .arg(model)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).trim().to_owned(),
    )
}

/// Meshes `model` with `args`, panicking with tetcdt's message on failure; returns the
/// output prefix inside `dir`.
fn mesh(model: &Path, dir: &Path, tag: &str, args: &[&str]) -> PathBuf {
    let prefix = dir.join(tag);
    let (code, err) = run(model, &prefix, args);
    assert_eq!(
        code,
        0,
        "tetcdt {} {}: exit {code}: {err}",
        args.join(" "),
        file_name(model)
    );
    prefix
}

/// The data rows of a TetGen file: comments stripped, blank lines dropped.
fn rows(path: &Path) -> Vec<Vec<String>> {
    fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .map(|l| l.split_whitespace().map(str::to_owned).collect::<Vec<_>>())
        .filter(|r| !r.is_empty())
        .collect()
}

fn with_ext(prefix: &Path, ext: &str) -> PathBuf {
    let mut s = prefix.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// A mesh read back from `PREFIX.node` / `PREFIX.ele`: 0-based tets, per-tet attributes.
struct Mesh {
    points: Vec<[f64; 3]>,
    tets: Vec<[usize; 4]>,
    attrs: Vec<Vec<f64>>,
    nattr: usize,
}

fn read_mesh(prefix: &Path) -> Mesh {
    let node = with_ext(prefix, "node");
    let r = rows(&node);
    let n: usize = r[0][0].parse().unwrap();
    let first: usize = if n > 0 { r[1][0].parse().unwrap() } else { 0 };
    let points = r[1..=n]
        .iter()
        .map(|x| {
            [
                x[1].parse().unwrap(),
                x[2].parse().unwrap(),
                x[3].parse().unwrap(),
            ]
        })
        .collect();
    let ele = with_ext(prefix, "ele");
    let r = rows(&ele);
    let m: usize = r[0][0].parse().unwrap();
    let nattr: usize = r[0].get(2).map_or(0, |s| s.parse().unwrap());
    let mut tets = Vec::with_capacity(m);
    let mut attrs = Vec::with_capacity(m);
    for x in &r[1..=m] {
        let mut t = [0usize; 4];
        for (j, slot) in t.iter_mut().enumerate() {
            *slot = x[1 + j].parse::<usize>().unwrap() - first;
        }
        tets.push(t);
        attrs.push(x[5..5 + nattr].iter().map(|s| s.parse().unwrap()).collect());
    }
    Mesh {
        points,
        tets,
        attrs,
        nattr,
    }
}

/// The number of rows a TetGen file announces in its header.
fn count(prefix: &Path, ext: &str) -> usize {
    rows(&with_ext(prefix, ext))[0][0].parse().unwrap()
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn signed_volume(m: &Mesh, t: &[usize; 4]) -> f64 {
    let [a, b, c, d] = t.map(|i| m.points[i]);
    let (u, v, w) = (sub(a, d), sub(b, d), sub(c, d));
    (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
        + u[2] * (v[0] * w[1] - v[1] * w[0]))
        / 6.0
}

fn volume(m: &Mesh) -> f64 {
    m.tets.iter().map(|t| signed_volume(m, t).abs()).sum()
}

fn centroid(m: &Mesh, t: &[usize; 4]) -> [f64; 3] {
    std::array::from_fn(|k| t.iter().map(|&i| m.points[i][k] / 4.0).sum())
}

/// A point's key: the bits of its coordinates (-0 taken as 0).
fn key(p: [f64; 3]) -> [u64; 3] {
    p.map(|x| (x + 0.0).to_bits())
}

/// The tets as sets of vertex coordinates.
fn tet_keys(m: &Mesh) -> BTreeSet<[[u64; 3]; 4]> {
    m.tets
        .iter()
        .map(|t| {
            let mut k = t.map(|i| key(m.points[i]));
            k.sort_unstable();
            k
        })
        .collect()
}

/// The shared referee and a python3 with numpy, if both are found.
fn validator() -> Option<PathBuf> {
    let candidates = [
        std::env::var_os("TETCDT_TOOLS").map(PathBuf::from),
        Some(Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/tools")),
    ];
    let script = candidates
        .into_iter()
        .flatten()
        .map(|d| d.join("validate_mesh.py"))
        .find(|p| p.is_file());
    let Some(script) = script else {
        eprintln!("note: validate_mesh.py not found (set TETCDT_TOOLS): skipping the referee");
        return None;
    };
    let numpy = std::process::Command::new("python3")
        .args(["-c", "import numpy"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !numpy {
        eprintln!("note: python3 with numpy not found: skipping the referee");
        return None;
    }
    Some(script)
}

/// Runs `f` on every item on two threads (the machine's cores are shared); returns the
/// failure messages, in the items' order.
/// Whether the shared referee reads the format of `p` (it does not read STL, PLY or OBJ;
/// the certifier, which every run goes through, judges those).
fn referee_reads(p: &Path) -> bool {
    matches!(
        p.extension().and_then(|e| e.to_str()),
        Some("off" | "poly" | "smesh" | "mesh" | "node")
    )
}

/// The referee's verdict on a mesh of `model` (`extra` adds its switches): its report
/// if it rejects the mesh.
fn referee(script: &Path, model: &Path, prefix: &Path, extra: &[&str]) -> Result<(), String> {
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(model)
        .arg(prefix)
        .args(extra)
        .output()
        .unwrap();
    if out.status.success() {
        Ok(())
    } else {
        // The report, then anything the referee itself complained of.
        Err(format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr).trim()
        ))
    }
}

fn for_each_parallel<T: Sync>(items: &[T], f: impl Fn(&T) -> Option<String> + Sync) -> Vec<String> {
    let next = Mutex::new(0usize);
    let found = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = {
                    let mut n = next.lock().unwrap();
                    *n += 1;
                    *n - 1
                };
                let Some(item) = items.get(i) else { break };
                if let Some(msg) = f(item) {
                    found.lock().unwrap().push((i, msg));
                }
            });
        }
    });
    let mut found = found.into_inner().unwrap();
    found.sort();
    found.into_iter().map(|(_, m)| m).collect()
}

#[test]
fn every_model_meshes_and_passes_check() {
    let dir = tempfile::tempdir().unwrap();
    let models = models();
    let failures = for_each_parallel(&models, |m| {
        let name = file_name(m);
        let prefix = dir.path().join(&name);
        let (code, err) = run(m, &prefix, &["-pQ", "--check"]);
        if code != 0 {
            return Some(format!("{name}: `tetcdt -pQ --check` exit {code}: {err}"));
        }
        if count(&prefix, "ele") == 0 {
            return Some(format!("{name}: no tets"));
        }
        None
    });
    assert!(
        failures.is_empty(),
        "{} of {} models fail:\n{}",
        failures.len(),
        models.len(),
        failures.join("\n")
    );
}

#[test]
fn every_model_passes_the_validator() {
    let Some(script) = validator() else { return };
    let dir = tempfile::tempdir().unwrap();
    let models = models();
    let failures = for_each_parallel(&models, |m| {
        let name = file_name(m);
        let prefix = dir.path().join(&name);
        if !referee_reads(m) {
            return None;
        }
        let (code, err) = run(m, &prefix, &["-pQ"]);
        if code != 0 {
            return Some(format!("{name}: `tetcdt -pQ` exit {code}: {err}"));
        }
        let Err(text) = referee(&script, m, &prefix, &[]) else {
            return None;
        };
        let problems: Vec<&str> = text
            .lines()
            .filter(|l| l.starts_with("problem:") || l.starts_with("steiner:"))
            .collect();
        Some(format!(
            "{name}: validate_mesh.py: {} [{}]",
            text.lines().last().unwrap_or(""),
            problems.join("; ")
        ))
    });
    assert!(
        failures.is_empty(),
        "{} of {} models fail the referee:\n{}",
        failures.len(),
        models.len(),
        failures.join("\n")
    );
}

#[test]
fn identical_to_tetgen_where_it_adds_no_steiner_points() {
    let ref_dir = plc_dir().join("ref");
    let mut refs: Vec<PathBuf> = fs::read_dir(&ref_dir)
        .expect("data/plc/ref/ is missing (scripts/gen-plc-reference.sh)")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("ele"))
        .collect();
    refs.sort();
    assert!(
        refs.len() >= 10,
        "expected TetGen references in {}",
        ref_dir.display()
    );
    let dir = tempfile::tempdir().unwrap();
    let failures = for_each_parallel(&refs, |ele| {
        // NAME.1.ele -> NAME.{off,poly,smesh,stl,ply}
        let stem = file_name(ele);
        let stem = stem.strip_suffix(".1.ele").unwrap();
        let Some(input) = ["off", "poly", "smesh", "stl", "ply"]
            .iter()
            .map(|e| plc_dir().join(format!("{stem}.{e}")))
            .find(|p| p.is_file())
        else {
            return Some(format!("{stem}: reference without a model"));
        };
        let theirs = read_mesh(&ref_dir.join(format!("{stem}.1")));
        let prefix = dir.path().join(stem);
        let (code, err) = run(&input, &prefix, &["-pQ"]);
        if code != 0 {
            return Some(format!("{stem}: `tetcdt -pQ` exit {code}: {err}"));
        }
        let ours = read_mesh(&prefix);
        let node_keys = |m: &Mesh| m.points.iter().map(|&p| key(p)).collect::<BTreeSet<_>>();
        if node_keys(&ours) != node_keys(&theirs) {
            return Some(format!(
                "{stem}: our {} nodes are not TetGen's {} (input vertices only): we add Steiner points",
                ours.points.len(),
                theirs.points.len()
            ));
        }
        let (a, b) = (tet_keys(&ours), tet_keys(&theirs));
        if a == b {
            return None;
        }
        let index: HashMap<[u64; 3], usize> = theirs
            .points
            .iter()
            .enumerate()
            .map(|(i, &p)| (key(p), i))
            .collect();
        let show = |k: &[[u64; 3]; 4]| {
            let mut ids = k.map(|p| index[&p]);
            ids.sort_unstable();
            format!("{ids:?}")
        };
        let extra: Vec<String> = a.difference(&b).take(4).map(show).collect();
        let missing: Vec<String> = b.difference(&a).take(4).map(show).collect();
        Some(format!(
            "{stem}: {} tets (TetGen {}); {} of ours not in TetGen's, e.g. {} ; {} of TetGen's missing, e.g. {} (TetGen's node numbers, 0-based)",
            a.len(),
            b.len(),
            a.difference(&b).count(),
            extra.join(" "),
            b.difference(&a).count(),
            missing.join(" ")
        ))
    });
    assert!(
        failures.is_empty(),
        "{} of {} models differ from TetGen:\n{}",
        failures.len(),
        refs.len(),
        failures.join("\n")
    );
}

/// The faces of gridbox_3 (a 3x3x3 box) are 3x3 grids of unit quads. Merged (the default),
/// each face is one facet and only the box's 12 edges (split at the grid vertices: 36
/// pieces) are segments; with -M every quad edge is one (108). The number of boundary
/// triangles is 2 per quad either way: without Steiner points a triangulation of the same
/// vertices has the same number of triangles. TetGen 1.5 gives the same counts.
#[test]
fn no_merge_keeps_every_quad_edge() {
    let dir = tempfile::tempdir().unwrap();
    let m = model("gridbox_3.smesh");
    let merged = mesh(&m, dir.path(), "merged", &["-pQ", "--check"]);
    let apart = mesh(&m, dir.path(), "apart", &["-pQM", "--check"]);
    let (e0, e1) = (count(&merged, "edge"), count(&apart, "edge"));
    let (f0, f1) = (count(&merged, "face"), count(&apart, "face"));
    assert!(e1 > e0, "-M: {e1} segments, not more than the merged {e0}");
    assert_eq!((e0, e1), (36, 108), "segments merged / -M");
    assert_eq!((f0, f1), (108, 108), "boundary faces merged / -M");
    assert_eq!(read_mesh(&merged).points.len(), 56, "no Steiner points");
    assert_eq!(
        read_mesh(&apart).points.len(),
        56,
        "no Steiner points with -M"
    );
}

#[test]
fn region_attributes_with_a() {
    let dir = tempfile::tempdir().unwrap();
    // box [0,2]x[0,1]x[0,1] cut at x = 1: attribute 10 for x < 1, 20 for x > 1
    let m = model("box_internal_facet.poly");
    let plain = read_mesh(&mesh(&m, dir.path(), "plain", &["-pQ"]));
    assert_eq!(plain.nattr, 0, "no attributes without -A");
    let a = read_mesh(&mesh(&m, dir.path(), "attr", &["-pQA", "--check"]));
    assert_eq!(a.nattr, 1, "one attribute per tet with -A");
    let mut seen = BTreeSet::new();
    for (t, attr) in a.tets.iter().zip(&a.attrs) {
        let c = centroid(&a, t);
        let want = if c[0] < 1.0 { 10.0 } else { 20.0 };
        assert_eq!(attr[0], want, "tet {t:?} with centroid {c:?}");
        seen.insert(attr[0] as i64);
    }
    assert_eq!(seen, BTreeSet::from([10, 20]));
    let vol = |which: f64| -> f64 {
        a.tets
            .iter()
            .zip(&a.attrs)
            .filter(|(_, x)| x[0] == which)
            .map(|(t, _)| signed_volume(&a, t).abs())
            .sum()
    };
    assert!((vol(10.0) - 1.0).abs() < 1e-12 && (vol(20.0) - 1.0).abs() < 1e-12);

    // the Figure 4 box cut by a nearly flat facet: 1 above, 2 below
    let m = model("fig4_split.poly");
    let a = read_mesh(&mesh(&m, dir.path(), "fig4", &["-pQA", "--check"]));
    assert_eq!(a.nattr, 1);
    for (t, attr) in a.tets.iter().zip(&a.attrs) {
        let c = centroid(&a, t);
        if c[2].abs() > 0.01 {
            let want = if c[2] > 0.0 { 1.0 } else { 2.0 };
            assert_eq!(attr[0], want, "fig4_split: tet {t:?} with centroid {c:?}");
        }
    }
}

/// ushape.poly has volume 2.5; its convex hull is the box [0,3]x[0,1]x[0,1].
#[test]
fn convex_hull_kept_with_c() {
    let dir = tempfile::tempdir().unwrap();
    let m = model("ushape.poly");
    let carved = read_mesh(&mesh(&m, dir.path(), "carved", &["-pQ", "--check"]));
    let hull_prefix = mesh(&m, dir.path(), "hull", &["-pQc", "--check"]);
    let hull = read_mesh(&hull_prefix);
    assert!(
        (volume(&carved) - 2.5).abs() < 1e-12,
        "volume {}",
        volume(&carved)
    );
    assert!(
        (volume(&hull) - 3.0).abs() < 1e-12,
        "volume with -c {}",
        volume(&hull)
    );
    assert!(hull.tets.len() > carved.tets.len());
    if let Some(script) = validator() {
        if let Err(report) = referee(&script, &m, &hull_prefix, &["--hull"]) {
            panic!("validate_mesh.py --hull: {report}");
        }
    }
}

/// box_cavity.poly: the box [0,4]^3 with the cavity [1,2.5]x[1,3]x[1.5,3] and a hole
/// point in it; 59.5 remains.
#[test]
fn hole_is_carved() {
    let dir = tempfile::tempdir().unwrap();
    let m = model("box_cavity.poly");
    let mesh = read_mesh(&mesh(&m, dir.path(), "cavity", &["-pQA", "--check"]));
    assert!(
        (volume(&mesh) - 59.5).abs() < 1e-9,
        "volume {}",
        volume(&mesh)
    );
    for t in &mesh.tets {
        let c = centroid(&mesh, t);
        let inside = (1.0..=2.5).contains(&c[0])
            && (1.0..=3.0).contains(&c[1])
            && (1.5..=3.0).contains(&c[2]);
        assert!(!inside, "tet {t:?} (centroid {c:?}) lies in the hole");
    }
    // the one region left has attribute 5
    assert_eq!(mesh.nattr, 1);
    assert!(
        mesh.attrs.iter().all(|a| a[0] == 5.0),
        "attributes other than 5"
    );
}

/// The number of shim tets `validate_mesh.py` reports on a mesh.
fn referee_shims(script: &Path, model: &Path, prefix: &Path) -> usize {
    let out = std::process::Command::new("python3")
        .arg(script)
        .arg(model)
        .arg(prefix)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    text.lines()
        .find_map(|l| {
            l.strip_prefix("problem: ")
                .and_then(|r| {
                    r.strip_suffix(" shim tets (all four vertices on one input facet) survive")
                })
                .and_then(|n| n.parse().ok())
        })
        .unwrap_or(0)
}

#[test]
fn merged_facets_far_from_flat_mesh_without_flat_shims() {
    // Merged groups of mpi.off are far from flat, with steps between near-duplicate
    // vertices: Steiner points on them used to never converge. At one corner a vertex
    // lies 0.0024 from a segment of the same merged facet: the flat tets there have
    // circumspheres within the facet's slab, and splitting their subsegments (not a free
    // vertex) removes them.
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/nonflat/mpi.off");
    let dir = tempfile::tempdir().unwrap();
    for (tag, args) in [("c", ["-pQ", "--check"]), ("f", ["-pQF", "--check"])] {
        let prefix = dir.path().join(tag);
        let (code, err) = run(&m, &prefix, &args);
        assert_eq!(code, 0, "{tag}: {err}");
        // Free vertices and subsegment splits remove the flat tets; TetGen leaves 11.
        if let Some(script) = validator() {
            let shims = referee_shims(&script, &m, &prefix);
            assert_eq!(shims, 0, "{tag}: {shims} shims");
        }
    }
}

#[test]
fn flat_tets_get_free_points_inserted_into_the_cdt() {
    // anchor.off needs free points after cavity insertions have added tets; TetGen leaves
    // shims on it.
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/nonflat/anchor.off");
    let dir = tempfile::tempdir().unwrap();
    for (tag, args) in [("c", ["-pV", "--check"]), ("f", ["-pVF", "--check"])] {
        let prefix = dir.path().join(tag);
        let (code, err) = run(&m, &prefix, &args);
        assert_eq!(code, 0, "{tag}: {err}");
        if let Some(script) = validator() {
            if let Err(report) = referee(&script, &m, &prefix, &[]) {
                panic!("{tag}: {report}");
            }
        }
    }
}

#[test]
fn flat_tets_left_on_a_facet_fail_the_run() {
    // anchor.off's flat tets need a free point. With -S leaving no room for one, the flat
    // tet stays, and the certifier fails the run; with room, nothing is left and nothing
    // is said.
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/nonflat/anchor.off");
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("s.json");
    let json_arg = json.to_str().unwrap();
    let prefix = dir.path().join("a");
    let (code, err) = run(&m, &prefix, &["-p", "--stats-json", json_arg]);
    assert_eq!(code, 0, "{err}");
    let stats = std::fs::read_to_string(&json).unwrap();
    assert_eq!(json_number(&stats, "flat_tets_left"), 0, "{stats}");
    assert_eq!(json_number(&stats, "thick_tets_left"), 0, "{stats}");
    assert_eq!(json_number(&stats, "free_searches_cut"), 0, "{stats}");
    assert!(!err.contains("flat tet"), "{err}");
    let all = json_number(&stats, "steiner_points");
    let free = json_number(&stats, "free_steiner_points");
    assert!(free >= 1, "{stats}");
    // Fewer Steiner points allowed: a limit that leaves no room for the free points
    // leaves a flat tet, and the run fails (exit 1) naming it as a shim rather than
    // writing a mesh that is no CDT (a limit too low for the segments fails earlier).
    let mut seen = false;
    let prefix = dir.path().join("limited");
    for limit in (all.saturating_sub(free + 4)..all).rev() {
        let _ = fs::remove_file(with_ext(&prefix, "ele"));
        let (code, err) = run(&m, &prefix, &["-p", &format!("-S{limit}")]);
        if code == 0 {
            continue;
        }
        assert_eq!(code, 1, "-S{limit}: {err}");
        if err.contains("is a shim") {
            assert!(err.contains("is not a valid CDT"), "-S{limit}: {err}");
            assert!(
                !with_ext(&prefix, "ele").exists(),
                "-S{limit}: a mesh was written"
            );
            seen = true;
            break;
        }
    }
    assert!(seen, "no limit below {all} left a flat tet");
}

/// The number after `"key":` in a one-line JSON object.
fn json_number(json: &str, key: &str) -> usize {
    let at = json
        .find(&format!("\"{key}\":"))
        .unwrap_or_else(|| panic!("{key} in {json}"));
    json[at + key.len() + 3..]
        .trim_start()
        .chars()
        .take_while(|c| c.is_ascii_digit())
        .collect::<String>()
        .parse()
        .unwrap()
}

#[test]
fn free_points_go_into_the_cdt_without_a_restart() {
    // fandisk.off has flat tets (TetGen leaves shims) that need free points; one of them
    // used to be refused by the CDT (its cavity left faces that were not locally
    // Delaunay), which restarted the construction. Flips now settle it in place.
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/nonflat/fandisk.off");
    let dir = tempfile::tempdir().unwrap();
    for (tag, flag) in [("c", "-pQ"), ("f", "-pQF")] {
        let stats = checked_stats(&m, dir.path(), tag, flag);
        assert!(
            json_number(&stats, "free_steiner_points") >= 1,
            "{tag}: {stats}"
        );
        assert_eq!(json_number(&stats, "restarts"), 0, "{tag}: {stats}");
    }
}

/// Meshes `model` with `switch`, `--check` and `--stats-json` (outputs in `dir`, named
/// by `tag`); requires exit 0 and, where the referee is at hand, a mesh it accepts.
/// The statistics, as JSON.
fn checked_stats(model: &Path, dir: &Path, tag: &str, switch: &str) -> String {
    let prefix = dir.join(tag);
    let json = dir.join(format!("{tag}.json"));
    let (code, err) = run(
        model,
        &prefix,
        &[switch, "--check", "--stats-json", json.to_str().unwrap()],
    );
    assert_eq!(code, 0, "{tag}: {err}");
    if let Some(script) = validator() {
        if let Err(report) = referee(&script, model, &prefix, &[]) {
            panic!("{tag}: {report}");
        }
    }
    std::fs::read_to_string(&json).unwrap()
}

#[test]
fn a_steiner_point_on_a_polygon_goes_into_the_cdt_without_a_restart() {
    // One polygon of fine_star_point is not flat enough: its two sides disagree, and a
    // Steiner point on it settles them. The point is put into the CDT by a walled cavity
    // and flips, and the polygon is triangulated again with it; the construction used to
    // start again from the Delaunay stage.
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/nonflat/fine_star_point.poly");
    let dir = tempfile::tempdir().unwrap();
    for (tag, flag) in [("c", "-pQ"), ("f", "-pQF")] {
        let stats = checked_stats(&m, dir.path(), tag, flag);
        assert_eq!(
            json_number(&stats, "facet_steiner_points"),
            1,
            "{tag}: {stats}"
        );
        assert_eq!(json_number(&stats, "restarts"), 0, "{tag}: {stats}");
    }
}

#[test]
fn refused_steiner_points_split_subsegments_in_place_instead_of_restarting() {
    // Free points for mpi's flat tets encroach upon subsegments: the CDT refuses them,
    // and the whole construction used to start again with them. The subsegments are now
    // split in place, the facets through them triangulated and recovered again, and a
    // point refused for its own facet's subfaces goes in with them taken out (anchor.off
    // has such a point).
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/nonflat");
    let dir = tempfile::tempdir().unwrap();
    for (model, most_restarts) in [("mpi.off", 0), ("anchor.off", 0)] {
        let m = data.join(model);
        for (tag, flag) in [("c", "-pQ"), ("f", "-pQF")] {
            let tag = format!("{model}-{tag}");
            let stats = checked_stats(&m, dir.path(), &tag, flag);
            assert!(
                json_number(&stats, "in_place_splits") >= 1,
                "{tag}: {stats}"
            );
            assert!(
                json_number(&stats, "restarts") <= most_restarts,
                "{tag}: {stats}"
            );
        }
    }
}

#[test]
fn a_region_triangulated_otherwise_above_a_layer_of_shims_is_adopted() {
    // In rotor_small, regions of nearly flat facets that no tet crosses are triangulated
    // by the mesh otherwise, twice: above and below a layer of flat tets with all four
    // vertices in the facet's slab. Either triangulation is adopted as the polygon's,
    // where such regions used to ask for Steiner points, and then for updates in place
    // (subsegment splits, facets recovered again) or a restart.
    for (sw, stats) in updated_in_place_without_restart("rotor_small.off", [0, 0]) {
        assert!(json_number(&stats, "steiner_points") <= 569, "{sw} {stats}");
    }
}

#[test]
fn subsegments_that_encroach_upon_each_other_in_a_group_split_in_place_together() {
    // In fine_star_group, five subsegments near a pole need splits in place whose points
    // would each remove another of them: all five are split in place at once, where the
    // construction used to restart.
    updated_in_place_without_restart("fine_star_group.poly", [1, 1]);
}

#[test]
fn a_cavity_the_region_does_not_split_widens_over_the_meshs_other_triangulation() {
    // In rotor_small, a region of a facet split by rounded Steiner points on its edges
    // is partly triangulated otherwise by mesh faces that no tet crosses: its crossing
    // tets' boundary is one piece, which the region's boundary does not split. The tets
    // on both sides of those faces now join the cavity, where a Steiner point on the
    // polygon (refused by the CDT, and put in by updates in place) was asked for: 3
    // points on polygons instead of 4, 572 Steiner points instead of 579.
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/nonflat/rotor_small.off");
    let dir = tempfile::tempdir().unwrap();
    let stats = checked_stats(&m, dir.path(), "rotor_small", "-pQ");
    assert!(json_number(&stats, "facet_steiner_points") <= 3, "{stats}");
    assert!(json_number(&stats, "steiner_points") <= 572, "{stats}");
}

#[test]
fn subsegments_at_a_sharp_corner_that_encroach_upon_each_other_split_in_place_together() {
    // In fine_star, a refused Steiner point on a polygon encroaches upon a subsegment
    // whose middle would remove a subsegment of a neighbouring segment, and that one's
    // middle the first: both are split at one distance from the segments' shared end,
    // in place, where the construction used to restart.
    for (sw, stats) in updated_in_place_without_restart("fine_star.poly", [1, 1]) {
        assert_eq!(
            json_number(&stats, "facet_steiner_points"),
            0,
            "{sw} {stats}"
        );
    }
}

/// Meshes `data/nonflat/MODEL` with `-pQ` and `-pQF` (checked, and refereed where the
/// referee is at hand), asserting no restart and `in_place` updates in place; the
/// switches with their statistics.
#[test]
fn a_refused_free_point_goes_in_with_the_facets_its_cavity_wraps_around_recovered_again() {
    // In anchor.off, the free point for a flat tet on a facet has a cavity that wraps
    // around subfaces of that facet: the CDT refuses it, and the construction used to
    // start again with it as an input vertex. It now goes in with that facet taken out,
    // and the facet is recovered again around it (one update), where the referee finds
    // no face of the new tets lying on a facet beside its triangles.
    for (sw, stats) in updated_in_place_without_restart("anchor.off", [1, 1]) {
        assert_eq!(
            json_number(&stats, "free_steiner_points"),
            1,
            "{sw} {stats}"
        );
        assert_eq!(json_number(&stats, "flat_tets_left"), 0, "{sw} {stats}");
        assert_eq!(json_number(&stats, "thick_tets_left"), 0, "{sw} {stats}");
    }
}

#[test]
fn a_free_point_that_would_remove_a_subsegment_gives_way_to_its_split_in_place() {
    // In mpi.off, free points for flat tets on facets would remove subsegments (after
    // the facets their cavities wrap around are taken out): the subsegments are split in
    // place instead, the facets through them recovered again, and the next round's free
    // points go in, where the construction used to restart with the refused points.
    for (sw, stats) in updated_in_place_without_restart("mpi.off", [3, 3]) {
        assert!(
            json_number(&stats, "free_steiner_points") >= 1,
            "{sw} {stats}"
        );
        assert_eq!(json_number(&stats, "flat_tets_left"), 0, "{sw} {stats}");
        assert_eq!(json_number(&stats, "thick_tets_left"), 0, "{sw} {stats}");
    }
}

#[test]
fn a_group_of_more_than_eight_subsegments_at_a_sharp_corner_splits_in_place() {
    // In fine_star_wide_group, one group of subsegments split in place grows to eleven
    // (each split point would remove another subsegment nearby): all are split in place
    // at once, where groups of at most eight made the construction restart.
    updated_in_place_without_restart("fine_star_wide_group.poly", [4, 5]);
}

/// Meshes `model` with `-pQ` and `-pQF`, requiring no restart and `in_place` updates in
/// place (for each switch); the statistics of both runs.
fn updated_in_place_without_restart(
    model: &str,
    in_place: [usize; 2],
) -> Vec<(&'static str, String)> {
    let m = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/nonflat")
        .join(model);
    let dir = tempfile::tempdir().unwrap();
    let mut out = Vec::new();
    for (sw, in_place) in ["-pQ", "-pQF"].into_iter().zip(in_place) {
        let stats = checked_stats(&m, dir.path(), model, sw);
        assert_eq!(json_number(&stats, "restarts"), 0, "{model} {sw} {stats}");
        assert_eq!(
            json_number(&stats, "in_place_splits"),
            in_place,
            "{model} {sw} {stats}"
        );
        out.push((sw, stats));
    }
    out
}

/// STL models on which our CDT and TetGen's differ only by the numbering of the welded
/// points (`data/stl_numbering/README.md`): numbered as TetGen numbers them, our tets are
/// TetGen's; numbered by first appearance, as we read STL, the mesh is valid and has the
/// same points.
#[test]
fn stl_cdt_is_tetgens_with_tetgens_numbering() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join("stl_numbering");
    let out = tempfile::tempdir().unwrap();
    for name in ["cube", "bar"] {
        let theirs = read_mesh(&dir.join(format!("{name}.1")));
        let renumbered = dir.join(format!("{name}.tetgen_numbering.smesh"));
        let prefix = out.path().join(format!("{name}_tg"));
        let (code, err) = run(&renumbered, &prefix, &["-pQ"]);
        assert_eq!(code, 0, "{name}: {err}");
        let ours = read_mesh(&prefix);
        assert!(
            tet_keys(&ours) == tet_keys(&theirs),
            "{name}: with TetGen's numbering our tets differ from TetGen's"
        );
        let prefix = out.path().join(format!("{name}_stl"));
        let (code, err) = run(
            &dir.join(format!("{name}.stl")),
            &prefix,
            &["-pQ", "--check"],
        );
        assert_eq!(code, 0, "{name}.stl: {err}");
        let from_stl = read_mesh(&prefix);
        let points = |m: &Mesh| m.points.iter().map(|&p| key(p)).collect::<BTreeSet<_>>();
        assert_eq!(
            points(&from_stl),
            points(&theirs),
            "{name}.stl: other points"
        );
    }
}

/// The faces of `PREFIX.face` with their markers, as coordinates.
fn marked_faces(prefix: &Path) -> Vec<([[f64; 3]; 3], i32)> {
    let m = read_mesh(prefix);
    let r = rows(&with_ext(prefix, "face"));
    let n: usize = r[0][0].parse().unwrap();
    let first: usize = r[1][0].parse().unwrap();
    r[1..=n]
        .iter()
        .map(|row| {
            let v = |k: usize| m.points[row[k].parse::<usize>().unwrap() - first];
            ([v(1), v(2), v(3)], row[4].parse().unwrap())
        })
        .collect()
}

/// Windows (hole polygons with hole points that other facets fill) mesh as TetGen
/// meshes them (`identical_to_tetgen_where_it_adds_no_steiner_points` has their
/// references): each window's triangles carry the filling facet's marker, the walls'
/// carry the wall's, and a window filled by a facet of the wall's own marker is part of
/// the wall.
#[test]
fn windows_carry_the_markers_of_the_facets_that_fill_them() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = mesh(&model("windows.poly"), dir.path(), "w", &["-pQ"]);
    // Each window: the marker of its filling facet, the plane it lies in (axis, value)
    // and its rectangle in the other two coordinates.
    let windows: [(i32, usize, f64, [f64; 4]); 4] = [
        (5, 1, 0.0, [1.0, 2.0, 1.0, 2.0]),
        (6, 1, 0.0, [3.5, 5.0, 0.5, 2.5]),
        (7, 0, 6.0, [1.0, 3.0, 1.0, 2.0]),
        (8, 1, 4.0, [4.0, 5.0, 1.0, 2.0]),
    ];
    let faces = marked_faces(&prefix);
    let mut per_window = [0; 4];
    for (f, marker) in &faces {
        let c: [f64; 3] = std::array::from_fn(|k| (f[0][k] + f[1][k] + f[2][k]) / 3.0);
        let inside = windows.iter().position(|&(_, axis, at, r)| {
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let (a, b) = if axis == 1 {
                (c[w], c[u])
            } else {
                (c[u], c[w])
            };
            f.iter().all(|p| p[axis] == at) && r[0] <= a && a <= r[1] && r[2] <= b && b <= r[3]
        });
        match inside {
            Some(k) => {
                assert_eq!(*marker, windows[k].0, "face {f:?}");
                per_window[k] += 1;
            }
            None => assert_eq!(*marker, 1, "face {f:?}"),
        }
    }
    assert_eq!(per_window, [2, 2, 2, 2], "the windows' triangles");
}

/// Triangles whose corners repeat once exactly equal points are welded add nothing:
/// every format drops them with one warning naming them, and meshes the rest as the
/// same model without them (its tets are TetGen's: see `data/plc/ref/`).
#[test]
fn triangles_with_a_repeated_corner_are_dropped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let base = read_mesh(&mesh(
        &model("degenerate_tris.off"),
        dir.path(),
        "off",
        &["-p"],
    ));
    for (name, facets) in [
        (
            "degenerate_tris.off",
            "facet 5 (line 19), facet 11 (line 25)",
        ),
        (
            "degenerate_tris_obj.obj",
            "facet 6 (line 17), facet 12 (line 23)",
        ),
        (
            "degenerate_tris_ply.ply",
            "facet 5 (line 26), facet 11 (line 32)",
        ),
        (
            "degenerate_tris_ascii.stl",
            "facet 6 (line 37), facet 12 (line 79)",
        ),
        ("degenerate_tris_binary.stl", "facet 6, facet 12"),
    ] {
        let prefix = dir.path().join(name);
        let (code, err) = run(&model(name), &prefix, &["-p"]);
        assert_eq!(code, 0, "{name}: {err}");
        assert!(
            err.contains(&format!(
                "2 facet(s) with a repeated corner (two corners at the same point) add nothing to the surface and were dropped: {facets}"
            )),
            "{name}: {err}"
        );
        // The STL files hold the coordinates as floats: tets are compared at that
        // precision.
        let as_f32 = |m: &Mesh| -> BTreeSet<Vec<[u32; 3]>> {
            m.tets
                .iter()
                .map(|t| {
                    let mut k: Vec<[u32; 3]> = t
                        .iter()
                        .map(|&v| m.points[v].map(|c| (c as f32).to_bits()))
                        .collect();
                    k.sort_unstable();
                    k
                })
                .collect()
        };
        assert_eq!(as_f32(&read_mesh(&prefix)), as_f32(&base), "{name}");
    }
}

/// Nearly flat grids (`scripts/gen-flat-grids.py`: each side of a cube a grid of quads a
/// little off its plane, merged into one facet, with points inside near it) need no
/// Steiner point: where the mesh triangulates a side's region twice, above and below a
/// layer of flat tets against the hull, one of those triangulations is adopted and the
/// layer carved away. Their tets are TetGen's (`identical_to_tetgen_...`).
#[test]
fn nearly_flat_grids_need_no_steiner_point() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["flat_grid_6.poly", "flat_grid_8.poly"] {
        for sw in ["-pQ", "-pQF"] {
            let stats = checked_stats(&model(name), dir.path(), name, sw);
            assert_eq!(
                json_number(&stats, "steiner_points"),
                0,
                "{name} {sw} {stats}"
            );
            assert_eq!(json_number(&stats, "restarts"), 0, "{name} {sw} {stats}");
        }
    }
}

/// A solid wedge whose two large faces meet at 0.046° along its sharp edge: nearly
/// coplanar, but folded onto each other rather than bent, so they are two facets (TetGen
/// merges only polygons whose dihedral angle is within 0.1° of 180°). Merged, the wedge
/// had no interior; apart, its tets are TetGen's (`tetgen -pO0Q`: 0 3 4 2, 0 4 5 2,
/// 5 0 2 1).
#[test]
fn a_thin_wedge_keeps_its_folded_faces_apart_as_tetgen_does() {
    let dir = tempfile::tempdir().unwrap();
    let poly = dir.path().join("wedge.poly");
    fs::write(
        &poly,
        "6 3 0 0\n0 0 0 0\n1 1 0 0\n2 1 1 0\n3 0 1 0\n4 0 1 0.0008\n5 1 1 0.0008\n\
         5 0\n1\n4 0 1 2 3\n1\n4 0 4 5 1\n1\n4 3 2 5 4\n1\n3 0 3 4\n1\n3 1 5 2\n0\n0\n",
    )
    .unwrap();
    for args in [&["-pQ"][..], &["-pQF"][..]] {
        let prefix = mesh(&poly, dir.path(), "w", args);
        let mut tets: Vec<[usize; 4]> = rows(&with_ext(&prefix, "ele"))[1..]
            .iter()
            .map(|r| {
                let mut t: [usize; 4] = std::array::from_fn(|k| r[k + 1].parse().unwrap());
                t.sort_unstable();
                t
            })
            .collect();
        tets.sort_unstable();
        assert_eq!(
            tets,
            vec![[0, 1, 2, 5], [0, 2, 3, 4], [0, 2, 4, 5]],
            "{args:?}"
        );
    }
}

/// CSG parts rounded to 6 digits (`data/csg/`, from `scripts/gen-csg-parts.py`): both
/// insertion algorithms give certified meshes (`--check`) that the referee accepts.
#[test]
fn csg_parts_rounded_to_six_digits_mesh_validly() {
    let csg = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/csg");
    let jobs: Vec<(PathBuf, &str)> = ["bricks_9.off", "flange_7.off", "cheese_4.off"]
        .iter()
        .flat_map(|p| [(csg.join(p), "-pQ"), (csg.join(p), "-pQF")])
        .collect();
    let script = validator();
    let dir = tempfile::tempdir().unwrap();
    let failures = for_each_parallel(&jobs, |(m, sw)| {
        let name = file_name(m);
        let prefix = dir.path().join(format!("{name}{sw}"));
        let (code, err) = run(m, &prefix, &[sw, "--check"]);
        if code != 0 {
            return Some(format!("{name} {sw}: exit {code}: {err}"));
        }
        let script = script.as_ref()?;
        referee(script, m, &prefix, &[])
            .err()
            .map(|e| format!("{name} {sw}: the referee rejects the mesh: {e}"))
    });
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// With the convex hull kept (`-c`), the flat tets beside a merged facet that is not
/// exactly flat lie inside the domain: shims of the facet as merged, which is what the
/// mesh is judged against (the referee too). A CSG part rounded to 6 digits has such
/// facets, so `-pc` fails (exit 1, nothing written) instead of writing an invalid mesh.
#[test]
fn keep_hull_never_writes_shims_of_bent_merged_facets() {
    let dir = tempfile::tempdir().unwrap();
    let part = plc_dir().join("../csg/flange_7.off");
    let prefix = dir.path().join("flange");
    let (code, err) = run(&part, &prefix, &["-pcQ"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("not a valid CDT"), "{err}");
    assert!(!with_ext(&prefix, "ele").exists());
}
