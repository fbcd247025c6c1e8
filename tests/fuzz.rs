//! Fuzzing in bounded time: no input may make the mesher panic, abort or hang.
//!
//! * **Mutated files.** Every model under `data/` whose extension a reader knows is a
//!   seed (so a new format is fuzzed as soon as a sample of it is added). Proptest applies
//!   byte flips, truncations, random tokens (huge, negative, NaN, `#`), dropped and
//!   repeated lines; the result goes through the reader and, when it parses, through the
//!   checks, `-d` and the whole `-p` pipeline (or the point-set pipeline), with facet
//!   insertion by cavities (`-C`) or, every other PLC, by flips (`-F`).
//! * **Random PLCs.** Random points (on a small grid, so degeneracies are common) and
//!   random triangles; unit cubes with perturbed vertices (which must mesh and pass the
//!   checker), with facets dropped (which must be refused as invalid, not fail).
//!
//! Every run happens on a worker thread with a deadline: a panic or a hang fails the test
//! with the input that caused it. Errors must be of the right kind: never an I/O error
//! for a readable file, never an internal error. `TETCDT_FUZZ_CASES` sets the number of
//! cases per test (default 1000, a few seconds each).

use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};
use std::sync::mpsc;
use std::time::Duration;
use tetcdt::error::{Error, InputError, MeshError};
use tetcdt::options::FacetAlgo;
use tetcdt::plc::{Facet, Plc};
use tetcdt::Options;

/// Longest a single case may run before it counts as a hang.
const DEADLINE: Duration = Duration::from_secs(60);

fn cases() -> u32 {
    std::env::var("TETCDT_FUZZ_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000)
}

/// Runs `f` on a worker thread; a panic or a run past the deadline is an error naming `what`.
fn guarded<T: Send + 'static>(
    what: String,
    f: impl FnOnce() -> T + Send + 'static,
) -> Result<T, TestCaseError> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        let _ = tx.send(r);
    });
    match rx.recv_timeout(DEADLINE) {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(_)) => Err(TestCaseError::fail(format!("panic on {what}"))),
        Err(_) => Err(TestCaseError::fail(format!(
            "hang (over {DEADLINE:?}) on {what}"
        ))),
    }
}

/// An error that a bad model may legitimately cause.
fn acceptable(e: &Error) -> Result<(), String> {
    match e {
        Error::Input(InputError::Io { .. }) => Err(format!("I/O error on a readable file: {e}")),
        Error::Mesh(MeshError::Internal(_)) => Err(format!("internal error: {e}")),
        Error::Output { .. } => Err(format!("output error without output: {e}")),
        _ => Ok(()),
    }
}

/// Outcomes of [`mesh_any`]: meshed, refused.
static MESHED: AtomicUsize = AtomicUsize::new(0);
static REFUSED: AtomicUsize = AtomicUsize::new(0);

/// PLCs meshed so far: every other one goes by flips.
static PLCS: AtomicUsize = AtomicUsize::new(0);

/// Meshes `plc` (as a PLC when it has facets, by cavities or, every other PLC, by flips:
/// both in one case could pass the deadline where each alone does not) and runs `-d`;
/// checks the error kinds.
fn mesh_any(plc: &Plc) -> Result<Option<tetcdt::Meshed>, String> {
    let _ = tetcdt::precheck::detect::detect(plc);
    let is_plc = !plc.facets.is_empty();
    let flips = is_plc && PLCS.fetch_add(1, Relaxed) % 2 == 1;
    let opts = Options {
        plc: is_plc,
        quiet: true,
        max_steiner: Some(20_000),
        facet_algo: if flips {
            FacetAlgo::Flip
        } else {
            FacetAlgo::Cavity
        },
        ..Default::default()
    };
    match tetcdt::tetrahedralize(plc, &opts) {
        Ok(m) => {
            MESHED.fetch_add(1, Relaxed);
            // Exit 0 means a valid mesh: certified here too, point sets included.
            let copts = tetcdt::check::CertifyOptions::of(&opts);
            if let Err(p) = tetcdt::check::check_mesh(plc, &m.mesh, &copts) {
                return Err(format!("a mesh given as valid fails the certifier: {p}"));
            }
            Ok(Some(m))
        }
        Err(e) => {
            REFUSED.fetch_add(1, Relaxed);
            if std::env::var_os("TETCDT_FUZZ_VERBOSE").is_some() {
                eprintln!("refused: {e}");
            }
            acceptable(&e)
                .map(|()| None)
                .map_err(|m| if flips { format!("with -F: {m}") } else { m })
        }
    }
}

/// The seed files: every file under `data/` that a reader accepts as it is.
fn seeds() -> Vec<(PathBuf, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("data");
    let mut out = Vec::new();
    let mut dirs = vec![root];
    while let Some(d) = dirs.pop() {
        let Ok(rd) = std::fs::read_dir(&d) else {
            continue;
        };
        let mut entries: Vec<PathBuf> = rd.filter_map(|e| e.ok().map(|e| e.path())).collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                // The reference outputs are large and not inputs.
                if p.file_name().is_some_and(|n| n != "ref") {
                    dirs.push(p);
                }
                continue;
            }
            let small = std::fs::metadata(&p)
                .map(|m| m.len() < 64 << 10)
                .unwrap_or(false);
            // A .poly with an empty node section reads a sibling .node: not self-contained.
            if small && tetcdt::io::read_plc(&p).is_ok() {
                if let Ok(bytes) = std::fs::read(&p) {
                    out.push((p, bytes));
                }
            }
        }
    }
    out
}

/// One change to a file's bytes; positions are taken modulo the current length.
#[derive(Clone, Debug)]
enum Mutation {
    Flip(usize, u8),
    Truncate(usize),
    Insert(usize, &'static str),
    DropLine(usize),
    RepeatLine(usize),
    ReplaceNumber(usize, &'static str),
}

const TOKENS: &[&str] = &[
    "-1",
    "0",
    "1",
    "3",
    "-0",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "99999999999999999999",
    "#",
    "\n",
    " ",
    "x",
    "1.5",
    "2.",
    "\u{0}",
    "é",
    "0x10",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    let tok = proptest::sample::select(TOKENS);
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Flip(p, b)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), tok.clone()).prop_map(|(p, t)| Mutation::Insert(p, t)),
        any::<usize>().prop_map(Mutation::DropLine),
        any::<usize>().prop_map(Mutation::RepeatLine),
        (any::<usize>(), tok).prop_map(|(p, t)| Mutation::ReplaceNumber(p, t)),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let n = bytes.len().max(1);
    let lines = |b: &[u8]| -> Vec<(usize, usize)> {
        let mut v = Vec::new();
        let mut s = 0;
        for (i, &c) in b.iter().enumerate() {
            if c == b'\n' {
                v.push((s, i + 1));
                s = i + 1;
            }
        }
        if s < b.len() {
            v.push((s, b.len()));
        }
        v
    };
    match *m {
        Mutation::Flip(p, b) => {
            if !bytes.is_empty() {
                bytes[p % n] ^= b.max(1);
            }
        }
        Mutation::Truncate(p) => bytes.truncate(p % n),
        Mutation::Insert(p, t) => {
            let at = p % (bytes.len() + 1);
            bytes.splice(at..at, t.bytes());
        }
        Mutation::DropLine(k) => {
            let ls = lines(bytes);
            if !ls.is_empty() {
                let (s, e) = ls[k % ls.len()];
                bytes.drain(s..e);
            }
        }
        Mutation::RepeatLine(k) => {
            let ls = lines(bytes);
            if !ls.is_empty() {
                let (s, e) = ls[k % ls.len()];
                let copy = bytes[s..e].to_vec();
                bytes.splice(e..e, copy);
            }
        }
        Mutation::ReplaceNumber(k, t) => {
            // The spans of maximal runs of digit-like characters.
            let mut spans = Vec::new();
            let mut i = 0;
            while i < bytes.len() {
                if bytes[i].is_ascii_digit() {
                    let s = i;
                    while i < bytes.len()
                        && (bytes[i].is_ascii_alphanumeric() || b".-+".contains(&bytes[i]))
                    {
                        i += 1;
                    }
                    spans.push((s, i));
                } else {
                    i += 1;
                }
            }
            if !spans.is_empty() {
                let (s, e) = spans[k % spans.len()];
                bytes.splice(s..e, t.bytes());
            }
        }
    }
}

/// Reads a mutated file and meshes what parses; only size-bounded models are meshed so
/// that a case stays fast (a mutated header can declare huge counts, never allocated).
fn run_file(path: PathBuf) -> Result<(), String> {
    match tetcdt::io::read_plc(&path) {
        // A .poly without points names a sibling .node, which may be missing.
        Err(InputError::Io { file, .. }) if file == path => {
            Err("I/O error reading a file that exists".into())
        }
        Err(_) => Ok(()),
        Ok(plc) if plc.points.len() <= 2000 && plc.facets.len() <= 4000 => {
            mesh_any(&plc).map(|_| ())
        }
        Ok(_) => Ok(()),
    }
}

#[test]
fn mutated_files_never_crash_or_hang() {
    let seeds = seeds();
    let exts: std::collections::BTreeSet<String> = seeds
        .iter()
        .filter_map(|(p, _)| p.extension().map(|e| e.to_string_lossy().into_owned()))
        .collect();
    // Every format we read must have a seed, so that none escapes the fuzzing.
    for ext in ["node", "poly", "smesh", "off", "obj"] {
        assert!(
            exts.contains(ext),
            "no seed file with extension .{ext} under data/"
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let dir_path = dir.path().to_path_buf();
    let n_seeds = seeds.len();
    let mut runner = TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (0..n_seeds, proptest::collection::vec(mutation(), 1..5));
    runner
        .run(&strategy, |(k, muts)| {
            let (seed, bytes) = &seeds[k];
            let mut b = bytes.clone();
            for m in &muts {
                apply(&mut b, m);
            }
            let name = seed.file_name().unwrap_or_default();
            let path = dir_path.join(name);
            std::fs::write(&path, &b).unwrap();
            let what = format!(
                "{} mutated by {muts:?}: {:?}",
                seed.display(),
                String::from_utf8_lossy(&b)
            );
            guarded(what.clone(), move || run_file(path))?
                .map_err(|e| TestCaseError::fail(format!("{e} on {what}")))
        })
        .unwrap();
    eprintln!(
        "mutated files: {} meshed, {} refused after parsing",
        MESHED.load(Relaxed),
        REFUSED.load(Relaxed)
    );
}

/// Random points on a 4×4×4 grid and random triangles on them.
fn random_plc() -> impl Strategy<Value = Plc> {
    (4usize..24).prop_flat_map(|n| {
        let pts = proptest::collection::vec((0u8..4, 0u8..4, 0u8..4), n);
        let tris = proptest::collection::vec((0..n as u32, 0..n as u32, 0..n as u32), 1..24);
        (pts, tris).prop_map(|(pts, tris)| Plc {
            points: pts
                .into_iter()
                .map(|(x, y, z)| [x as f64, y as f64, z as f64])
                .collect(),
            facets: tris
                .into_iter()
                .map(|(a, b, c)| Facet {
                    polygons: vec![vec![a, b, c]],
                    ..Default::default()
                })
                .collect(),
            source: "random.poly".into(),
            ..Default::default()
        })
    })
}

#[test]
fn random_plcs_never_crash_or_hang() {
    let mut runner = TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(&random_plc(), |plc| {
            let what = format!("points {:?} facets {:?}", plc.points, plc.facets);
            guarded(what.clone(), move || mesh_any(&plc).map(|_| ()))?
                .map_err(|e| TestCaseError::fail(format!("{e} on {what}")))
        })
        .unwrap();
}

/// The unit cube as 12 triangles, vertex `i` at the bits of `i`.
fn cube() -> Plc {
    let points = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let facets = quads
        .iter()
        .flat_map(|q| [vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]])
        .map(|p| Facet {
            polygons: vec![p],
            ..Default::default()
        })
        .collect();
    Plc {
        points,
        facets,
        source: "cube.poly".into(),
        ..Default::default()
    }
}

#[test]
fn perturbed_cubes_mesh_and_open_ones_are_refused() {
    let mut runner = TestRunner::new(Config {
        cases: cases(),
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (
        proptest::collection::vec((0usize..8, 0usize..3, -1000i32..1000, 3i32..13), 0..8),
        proptest::option::of(0usize..12),
    );
    runner
        .run(&strategy, |(moves, drop)| {
            let mut plc = cube();
            for &(v, k, m, e) in &moves {
                // Moves of at most 1e-3 keep the cube's faces from crossing each other.
                plc.points[v][k] += m as f64 * 10f64.powi(-e - 3);
            }
            if let Some(f) = drop {
                plc.facets.remove(f);
            }
            let what = format!("points {:?} without facet {drop:?}", plc.points);
            let p2 = plc.clone();
            let r = guarded(what.clone(), move || {
                let opts = Options {
                    plc: true,
                    quiet: true,
                    ..Default::default()
                };
                tetcdt::tetrahedralize(&p2, &opts)
            })?;
            match (drop, r) {
                (None, Ok(m)) => {
                    if let Err(p) = tetcdt::check::check_mesh(&plc, &m.mesh, &Default::default()) {
                        return Err(TestCaseError::fail(format!("invalid mesh {p:?} of {what}")));
                    }
                }
                (None, Err(e)) => {
                    return Err(TestCaseError::fail(format!("refused {what}: {e}")));
                }
                (Some(_), Ok(_)) => {
                    return Err(TestCaseError::fail(format!("meshed an open {what}")));
                }
                (Some(_), Err(e)) => {
                    let msg = e.to_string();
                    prop_assert_eq!(e.exit_code(), 3, "{}", msg);
                    // One triangle less leaves its three edges on the boundary.
                    prop_assert!(
                        msg.contains("not closed") && msg.contains("3 boundary edge(s)"),
                        "{}",
                        msg
                    );
                }
            }
            Ok(())
        })
        .unwrap();
}

/// The unit cube scaled by `s` and moved by `o`, its points numbered after `base`.
fn boxed(o: [f64; 3], s: f64, base: u32) -> (Vec<[f64; 3]>, Vec<Facet>) {
    let c = cube();
    let points = c
        .points
        .iter()
        .map(|p| std::array::from_fn(|k| o[k] + s * p[k]))
        .collect();
    let facets = c
        .facets
        .into_iter()
        .map(|mut f| {
            f.polygons[0].iter_mut().for_each(|v| *v += base);
            f
        })
        .collect();
    (points, facets)
}

/// Two boxes: the unit cube and one at odd multiples of 1/8 (so that no vertices, edges
/// or face planes coincide). Their surfaces meet exactly when the closed boxes meet and
/// neither lies inside the other: then the PLC must be refused as intersecting, else it
/// must mesh into a valid mesh.
#[test]
fn two_boxes_are_refused_exactly_when_they_intersect() {
    let meshed = std::sync::Arc::new(AtomicUsize::new(0));
    let refused = std::sync::Arc::new(AtomicUsize::new(0));
    let (m2, r2) = (meshed.clone(), refused.clone());
    let mut runner = TestRunner::new(Config {
        cases: cases() / 4,
        failure_persistence: None,
        ..Config::default()
    });
    let strategy = (proptest::array::uniform3(-6i32..6), 1i32..12);
    runner
        .run(&strategy, |(o, s)| {
            // Corner at odd multiples of 1/8, side a multiple of 1/4.
            let o = o.map(|k| (2 * k + 1) as f64 / 8.0);
            let s = s as f64 / 4.0;
            let (mut points, mut facets) = boxed([0.0; 3], 1.0, 0);
            let (p2, f2) = boxed(o, s, 8);
            points.extend(p2);
            facets.extend(f2);
            let plc = Plc {
                points,
                facets,
                source: "boxes.poly".into(),
                ..Default::default()
            };
            let (lo, hi) = (o, o.map(|x| x + s));
            let meet = (0..3).all(|k| lo[k] <= 1.0 && hi[k] >= 0.0);
            let b_in_a = (0..3).all(|k| lo[k] > 0.0 && hi[k] < 1.0);
            let a_in_b = (0..3).all(|k| lo[k] < 0.0 && hi[k] > 1.0);
            let crossing = meet && !b_in_a && !a_in_b;
            let what = format!("box at {o:?} side {s}");
            let p2 = plc.clone();
            let r = guarded(what.clone(), move || {
                let opts = Options {
                    plc: true,
                    quiet: true,
                    ..Default::default()
                };
                tetcdt::tetrahedralize(&p2, &opts)
            })?;
            match r {
                Ok(m) => {
                    m2.fetch_add(1, Relaxed);
                    prop_assert!(!crossing, "meshed crossing boxes: {}", what);
                    if let Err(p) = tetcdt::check::check_mesh(&plc, &m.mesh, &Default::default()) {
                        return Err(TestCaseError::fail(format!("invalid mesh {p:?} of {what}")));
                    }
                }
                Err(e) => {
                    r2.fetch_add(1, Relaxed);
                    let msg = e.to_string();
                    prop_assert!(crossing, "refused {}: {}", what, msg);
                    prop_assert!(msg.contains("pair(s) of facets intersect"), "{}", msg);
                    prop_assert_eq!(e.exit_code(), 3);
                }
            }
            Ok(())
        })
        .unwrap();
    // Both outcomes occurred (the proportions depend on the strategy's ranges).
    let (m, r) = (meshed.load(Relaxed), refused.load(Relaxed));
    eprintln!("two boxes: {m} meshed, {r} refused");
    assert!(m > 0 && r > 0, "{m} meshed, {r} refused");
}
