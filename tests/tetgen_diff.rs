//! Compares our Delaunay tetrahedralizations with TetGen's, stored in `data/ref/`
//! (written by `scripts/gen-reference.sh` with `tetgen -O0`; see `data/ref/README.md`).
//!
//! For every reference set the tets must be the same (as sets of four node indices) and
//! have the same orientation (the same vertex order up to an even permutation). TetGen's
//! tets have a negative Shewchuk orient3d(a, b, c, d); this test checks that too, on
//! the reference itself, so a wrong convention shows up as "orientation flipped".

use std::collections::{HashMap, HashSet};
use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

/// How many differing tets a failure report lists.
const SHOW: usize = 8;

fn ref_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join("ref")
}

/// The data lines of a TetGen file: comments stripped, blank lines dropped.
fn data_lines(path: &Path) -> Vec<Vec<String>> {
    let text = fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e} (run scripts/gen-reference.sh)", path.display()));
    text.lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .map(|l| l.split_whitespace().map(str::to_owned).collect::<Vec<_>>())
        .filter(|t| !t.is_empty())
        .collect()
}

fn num<T: std::str::FromStr>(path: &Path, tok: &str) -> T {
    tok.parse()
        .unwrap_or_else(|_| panic!("{}: bad number {tok:?}", path.display()))
}

/// Reads a `.node` file on its own (independently of `tetcdt::io`): first index and points.
fn read_node(path: &Path) -> (usize, Vec<[f64; 3]>) {
    let lines = data_lines(path);
    let n: usize = num(path, &lines[0][0]);
    let rows = &lines[1..=n];
    let first: usize = num(path, &rows[0][0]);
    let mut pts = Vec::with_capacity(n);
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(
            num::<usize>(path, &r[0]),
            first + i,
            "{}: ids not consecutive",
            path.display()
        );
        pts.push([num(path, &r[1]), num(path, &r[2]), num(path, &r[3])]);
    }
    (first, pts)
}

/// Reads `k` node indices per row from a `.ele` (k = 4) or `.face` (k = 3) file, 0-based.
fn read_cells<const K: usize>(path: &Path, first: usize, npoints: usize) -> Vec<[u32; K]> {
    let lines = data_lines(path);
    let n: usize = num(path, &lines[0][0]);
    assert_eq!(
        lines.len() - 1,
        n,
        "{}: header says {n} rows",
        path.display()
    );
    let mut out = Vec::with_capacity(n);
    for (i, r) in lines[1..].iter().enumerate() {
        assert_eq!(
            num::<usize>(path, &r[0]),
            first + i,
            "{}: ids not consecutive",
            path.display()
        );
        let mut c = [0u32; K];
        for (j, slot) in c.iter_mut().enumerate() {
            let v: usize = num(path, &r[1 + j]);
            assert!(
                v >= first && v - first < npoints,
                "{}: row {i}: bad node {v}",
                path.display()
            );
            *slot = (v - first) as u32;
        }
        out.push(c);
    }
    out
}

/// The sorted vertex indices of a tet, and whether sorting took an even permutation.
fn canonical(t: [u32; 4]) -> ([u32; 4], bool) {
    let mut s = t;
    let mut swaps = 0;
    for i in 0..4 {
        for j in 0..3 - i {
            if s[j] > s[j + 1] {
                s.swap(j, j + 1);
                swaps += 1;
            }
        }
    }
    (s, swaps % 2 == 0)
}

/// The sign of Shewchuk's orient3d(a, b, c, d) when floating point can certify it
/// (his stage-A error bound), else `None`. Positive: d lies below the plane of the
/// counterclockwise triangle a, b, c.
fn orient3d_sign(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Option<i8> {
    let (adx, ady, adz) = (a[0] - d[0], a[1] - d[1], a[2] - d[2]);
    let (bdx, bdy, bdz) = (b[0] - d[0], b[1] - d[1], b[2] - d[2]);
    let (cdx, cdy, cdz) = (c[0] - d[0], c[1] - d[1], c[2] - d[2]);
    let (bdxcdy, cdxbdy) = (bdx * cdy, cdx * bdy);
    let (cdxady, adxcdy) = (cdx * ady, adx * cdy);
    let (adxbdy, bdxady) = (adx * bdy, bdx * ady);
    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    let eps = f64::EPSILON / 2.0;
    let bound = (7.0 + 56.0 * eps) * eps * permanent;
    if det > bound {
        Some(1)
    } else if -det > bound {
        Some(-1)
    } else if permanent == 0.0 {
        Some(0)
    } else {
        None
    }
}

/// The faces that belong to exactly one tet (the convex hull), each sorted.
fn hull_faces(tets: &[[u32; 4]]) -> HashSet<[u32; 3]> {
    let mut count: HashMap<[u32; 3], u32> = HashMap::new();
    for t in tets {
        for skip in 0..4 {
            let mut f = [0u32; 3];
            let mut k = 0;
            for (j, &v) in t.iter().enumerate() {
                if j != skip {
                    f[k] = v;
                    k += 1;
                }
            }
            f.sort_unstable();
            *count.entry(f).or_insert(0) += 1;
        }
    }
    count
        .into_iter()
        .filter(|&(_, c)| c == 1)
        .map(|(f, _)| f)
        .collect()
}

fn describe(points: &[[f64; 3]], t: &[u32]) -> String {
    let coords: Vec<String> = t
        .iter()
        .map(|&v| format!("{:?}", points[v as usize]))
        .collect();
    format!("{t:?} at {}", coords.join(" "))
}

fn check_set(name: &str) {
    let dir = ref_dir();
    let node = dir.join(format!("{name}.node"));
    let (first, points) = read_node(&node);
    let n = points.len();
    let ref_tets = read_cells::<4>(&dir.join(format!("{name}.1.ele")), first, n);
    let ref_hull = read_cells::<3>(&dir.join(format!("{name}.1.face")), first, n);

    // The reference itself: TetGen's orientation convention, and a sane hull.
    let mut uncertain = 0;
    for t in &ref_tets {
        let p = t.map(|v| points[v as usize]);
        match orient3d_sign(p[0], p[1], p[2], p[3]) {
            Some(s) => assert!(
                s < 0,
                "{name}: TetGen tet {t:?} has orient3d sign {s}, expected < 0"
            ),
            None => uncertain += 1,
        }
    }
    assert!(
        uncertain * 100 <= ref_tets.len(),
        "{name}: {uncertain} tets with uncertain orientation"
    );
    let ref_hull: HashSet<[u32; 3]> = ref_hull
        .into_iter()
        .map(|mut f| {
            f.sort_unstable();
            f
        })
        .collect();
    assert_eq!(
        hull_faces(&ref_tets),
        ref_hull,
        "{name}: reference .ele and .face disagree"
    );

    // Our mesh.
    let plc = tetcdt::io::read_plc(&node).unwrap_or_else(|e| panic!("{name}: read_plc: {e}"));
    assert_eq!(plc.points.len(), n, "{name}: read_plc point count");
    assert_eq!(plc.first_index, first, "{name}: read_plc first_index");
    let meshed = tetcdt::tetrahedralize(&plc, &tetcdt::Options::default())
        .unwrap_or_else(|e| panic!("{name}: tetrahedralize: {e}"));
    let mesh = &meshed.mesh;
    assert_eq!(
        mesh.points.len(),
        n,
        "{name}: output has Steiner points or lost input points"
    );
    assert!(
        mesh.points == points,
        "{name}: output points differ from the input points"
    );
    assert_eq!(mesh.first_index, first, "{name}: MeshOut.first_index");

    let ours_map: HashMap<[u32; 4], bool> = mesh.tets.iter().map(|&t| canonical(t)).collect();
    let ref_map: HashMap<[u32; 4], bool> = ref_tets.iter().map(|&t| canonical(t)).collect();
    assert_eq!(
        ref_map.len(),
        ref_tets.len(),
        "{name}: duplicate tets in the reference"
    );

    let mut only_ours: Vec<&[u32; 4]> = ours_map
        .keys()
        .filter(|k| !ref_map.contains_key(*k))
        .collect();
    let mut only_ref: Vec<&[u32; 4]> = ref_map
        .keys()
        .filter(|k| !ours_map.contains_key(*k))
        .collect();
    let mut flipped: Vec<&[u32; 4]> = ours_map
        .iter()
        .filter(|(k, p)| ref_map.get(*k).is_some_and(|q| q != *p))
        .map(|(k, _)| k)
        .collect();
    let duplicates = mesh.tets.len() - ours_map.len();
    let hull = hull_faces(&mesh.tets);

    if only_ours.is_empty() && only_ref.is_empty() && flipped.is_empty() && duplicates == 0 {
        return;
    }
    only_ours.sort_unstable();
    only_ref.sort_unstable();
    flipped.sort_unstable();
    let mut msg = String::new();
    let _ = writeln!(
        msg,
        "{name}: our Delaunay tetrahedralization differs from TetGen's (data/ref/{name}.1.ele)\n  \
         {n} points, first index {first} (indices below are 0-based; add {first} for the files)\n  \
         tets: ours {} ({} distinct), TetGen {}\n  \
         only ours: {}, only TetGen: {}, orientation flipped: {}\n  \
         hull faces: ours {}, TetGen {}, only ours {}, only TetGen {}",
        mesh.tets.len(),
        ours_map.len(),
        ref_tets.len(),
        only_ours.len(),
        only_ref.len(),
        flipped.len(),
        hull.len(),
        ref_hull.len(),
        hull.difference(&ref_hull).count(),
        ref_hull.difference(&hull).count(),
    );
    for (label, list) in [
        ("only ours", &only_ours),
        ("only TetGen", &only_ref),
        ("flipped", &flipped),
    ] {
        for t in list.iter().take(SHOW) {
            let _ = writeln!(msg, "  {label}: {}", describe(&points, &t[..]));
        }
        if list.len() > SHOW {
            let _ = writeln!(msg, "  {label}: ... {} more", list.len() - SHOW);
        }
    }
    panic!("{msg}");
}

/// One test per reference set, and `SETS`, the list of their names.
macro_rules! reference_tests {
    ($($name:ident),* $(,)?) => {
        /// The reference sets, by the name of their `.node` file in `data/ref/`.
        const SETS: &[&str] = &[$(stringify!($name)),*];
        $(
            #[test]
            fn $name() {
                check_set(stringify!($name));
            }
        )*
    };
}

reference_tests!(
    cube_center,
    grid3,
    grid4,
    grid4_shuffled,
    grid543_shuffled,
    lattice300,
    rand1k,
    rand10k
);

/// Every input in `data/ref` has a test above, and every test has its files.
#[test]
fn every_reference_set_is_tested() {
    let mut found: Vec<String> = fs::read_dir(ref_dir())
        .expect("data/ref")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter_map(|f| f.strip_suffix(".node").map(str::to_owned))
        .filter(|f| !f.ends_with(".1"))
        .collect();
    found.sort();
    let mut want: Vec<String> = SETS.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(
        found, want,
        "data/ref inputs vs SETS in tests/tetgen_diff.rs"
    );
    for s in SETS {
        for ext in ["1.ele", "1.face"] {
            assert!(
                ref_dir().join(format!("{s}.{ext}")).is_file(),
                "missing data/ref/{s}.{ext}"
            );
        }
    }
}
