//! Quality refinement (`-q`, `-a`): every bound is met by every tet but the ones counted
//! as left next to small input angles, per-region volume bounds hold with `-A`, and
//! refinement ends on PLCs with small input angles. Every run here exits 0, which means
//! its mesh passed the certifier (a constrained Delaunay tetrahedralization of the PLC).

use assert_cmd::Command;
use std::fs;
use std::path::{Path, PathBuf};
use std::time::Duration;
use tetcdt::geom::quality;

/// A refined mesh as read back from its files, with the run's figures.
struct Refined {
    points: Vec<[f64; 3]>,
    tets: Vec<[usize; 4]>,
    attributes: Vec<f64>,
    /// The faces on facets (`.face`), by their corners' coordinates.
    faces: Vec<[[f64; 3]; 3]>,
    /// `refine_left` from `--stats-json`.
    left: usize,
}

impl Refined {
    fn corners(&self, t: &[usize; 4]) -> [[f64; 3]; 4] {
        t.map(|v| self.points[v])
    }

    /// Tets over `ratio`.
    fn over_ratio(&self, ratio: f64) -> usize {
        let over = |t: &&[usize; 4]| quality::radius_edge_ratio(&self.corners(t)) > ratio;
        self.tets.iter().filter(over).count()
    }

    /// Tets with a dihedral angle under `angle` degrees.
    fn under_angle(&self, angle: f64) -> usize {
        let under = |t: &&[usize; 4]| quality::dihedral_range(&self.corners(t)).0 < angle;
        self.tets.iter().filter(under).count()
    }

    /// The largest tet volume.
    fn max_volume(&self) -> f64 {
        let vol = |t: &[usize; 4]| quality::volume(&self.corners(t));
        self.tets.iter().map(vol).fold(0.0, f64::max)
    }
}

fn numbers(path: &Path) -> Vec<Vec<f64>> {
    fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split('#').next().unwrap())
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|x| x.parse().unwrap()).collect())
        .collect()
}

/// Meshes `model` with `switches` in a fresh directory; the run must exit 0.
fn refine(model: &Path, switches: &str) -> Refined {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("out");
    let stats = dir.path().join("stats.json");
    Command::cargo_bin("tetcdt")
        .unwrap()
        .timeout(Duration::from_secs(120))
        .args([switches, "-Q", "-o"])
        .arg(&prefix)
        .arg("--stats-json")
        .arg(&stats)
        .arg(model)
        .assert()
        .success();
    let node = numbers(&prefix.with_extension("node"));
    let first = node[1][0] as usize;
    let points: Vec<[f64; 3]> = node[1..].iter().map(|r| [r[1], r[2], r[3]]).collect();
    let ele = numbers(&prefix.with_extension("ele"));
    let tets = ele[1..]
        .iter()
        .map(|r| std::array::from_fn(|k| r[k + 1] as usize - first))
        .collect();
    let attributes = ele[1..].iter().filter_map(|r| r.get(5).copied()).collect();
    let face = numbers(&prefix.with_extension("face"));
    let faces = face[1..]
        .iter()
        .map(|r| std::array::from_fn(|k| points[r[k + 1] as usize - first]))
        .collect();
    let json = fs::read_to_string(&stats).unwrap();
    let left = json
        .split("\"refine_left\": ")
        .nth(1)
        .and_then(|s| s.split([',', '}']).next())
        .and_then(|s| s.trim().parse().ok())
        .expect("refine_left in the figures");
    Refined {
        points,
        tets,
        attributes,
        faces,
        left,
    }
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data")
        .join(name)
}

/// Writes a `.poly` of `points` and polygon facets into `dir`.
fn poly(dir: &Path, name: &str, points: &[[f64; 3]], facets: &[&[usize]]) -> PathBuf {
    let mut s = format!("{} 3 0 0\n", points.len());
    for (i, p) in points.iter().enumerate() {
        s += &format!("{i} {} {} {}\n", p[0], p[1], p[2]);
    }
    s += &format!("{} 0\n", facets.len());
    for f in facets {
        let ids: Vec<String> = f.iter().map(|v| v.to_string()).collect();
        s += &format!("1\n{} {}\n", f.len(), ids.join(" "));
    }
    s += "0\n0\n";
    let path = dir.join(name);
    fs::write(&path, s).unwrap();
    path
}

#[test]
fn the_radius_edge_bound_is_met() {
    for (model, ratio) in [
        ("examples/box_with_hole.poly", 1.414),
        ("examples/box_with_hole.poly", 1.05),
        ("plc/gridbox_3.smesh", 1.414),
    ] {
        let m = refine(&example(model), &format!("-pq{ratio}"));
        let over = m.over_ratio(ratio);
        assert!(
            over <= m.left,
            "{model}: {over} tets over {ratio}, {} left",
            m.left
        );
        assert_eq!(m.left, 0, "{model}: no small input angle, nothing is left");
        // It did refine: the unrefined meshes have tets over these bounds.
        let plain = refine(&example(model), "-p");
        assert!(plain.over_ratio(ratio) > 0 && m.points.len() > plain.points.len());
    }
}

#[test]
fn the_dihedral_bound_is_met() {
    let m = refine(&example("examples/box_with_hole.poly"), "-pq1.5/35");
    assert_eq!(m.left, 0);
    assert_eq!(m.over_ratio(1.5) + m.under_angle(35.0), 0);
    let plain = refine(&example("examples/box_with_hole.poly"), "-pq1.5");
    assert!(
        plain.under_angle(35.0) > 0,
        "the angle bound is what refines further"
    );
}

#[test]
fn the_volume_bound_is_met() {
    for bound in [0.05, 0.002] {
        let m = refine(
            &example("examples/box_with_hole.poly"),
            &format!("-pa{bound}"),
        );
        assert!(m.max_volume() <= bound, "{} over {bound}", m.max_volume());
        let total: f64 = m.tets.iter().map(|t| quality::volume(&m.corners(t))).sum();
        assert!(total > 0.0);
    }
}

#[test]
fn regions_keep_their_own_volume_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let text = fs::read_to_string(example("plc/box_internal_facet.poly")).unwrap();
    // Region 10 (x < 1) at most 0.01, region 20 (x > 1) at most 0.001.
    let text = text
        .replace("0 0.5 0.5 0.5 10 -1", "0 0.5 0.5 0.5 10 0.01")
        .replace("1 1.5 0.5 0.5 20 -1", "1 1.5 0.5 0.5 20 0.001");
    let model = dir.path().join("regions.poly");
    fs::write(&model, text).unwrap();
    let m = refine(&model, "-paA");
    assert_eq!(m.attributes.len(), m.tets.len());
    let mut seen = [false; 2];
    for (t, &a) in m.tets.iter().zip(&m.attributes) {
        let bound = if a == 10.0 { 0.01 } else { 0.001 };
        seen[(a == 20.0) as usize] = true;
        let v = quality::volume(&m.corners(t));
        assert!(v <= bound, "a tet of region {a} has volume {v}");
    }
    assert_eq!(seen, [true, true]);
    // A global bound below both wins everywhere.
    let m = refine(&model, "-pa0.0005aA");
    assert!(m.max_volume() <= 0.0005);
}

#[test]
fn refinement_ends_at_small_input_angles() {
    let dir = tempfile::tempdir().unwrap();
    // An acute cone: a square pyramid 40 times taller than wide (an apex angle near 1.4
    // degrees).
    let cone = poly(
        dir.path(),
        "cone.poly",
        &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.5, 40.0],
        ],
        &[
            &[0, 3, 2, 1],
            &[0, 1, 4],
            &[1, 2, 4],
            &[2, 3, 4],
            &[3, 0, 4],
        ],
    );
    // A thin slit: a wedge whose two large faces meet at an edge at 2 degrees.
    let t = 2f64.to_radians().tan();
    let slit = poly(
        dir.path(),
        "slit.poly",
        &[
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 1.0, 0.0],
            [4.0, 0.0, 4.0 * t],
            [4.0, 1.0, 4.0 * t],
        ],
        &[
            &[0, 2, 3, 1],
            &[0, 1, 5, 4],
            &[2, 4, 5, 3],
            &[0, 4, 2],
            &[1, 3, 5],
        ],
    );
    // A needle: a triangular prism 100 times longer than its side.
    let needle = poly(
        dir.path(),
        "needle.poly",
        &[
            [0.0, 0.0, 0.0],
            [0.1, 0.0, 0.0],
            [0.05, 0.08, 0.0],
            [0.0, 0.0, 10.0],
            [0.1, 0.0, 10.0],
            [0.05, 0.08, 10.0],
        ],
        &[
            &[0, 2, 1],
            &[3, 4, 5],
            &[0, 1, 4, 3],
            &[1, 2, 5, 4],
            &[2, 0, 3, 5],
        ],
    );
    for model in [&cone, &slit, &needle] {
        for switches in ["-pq1.414", "-pq1.2/10", "-pq1.414a0.001"] {
            let m = refine(model, switches);
            let over = m.over_ratio(1.414);
            assert!(
                over <= m.left,
                "{}: {over} tets over the bound, {} counted",
                model.display(),
                m.left
            );
        }
    }
}

/// Triangles as sorted lists of sorted corners, for comparing boundaries.
fn triangle_set(faces: &[[[f64; 3]; 3]]) -> Vec<[[u64; 3]; 3]> {
    let mut set: Vec<[[u64; 3]; 3]> = faces
        .iter()
        .map(|f| {
            let mut t = f.map(|p| p.map(f64::to_bits));
            t.sort();
            t
        })
        .collect();
    set.sort();
    set
}

/// A regular tetrahedron's surface, each face cut into 16 triangles (a triangulated
/// input whose triangles are no Delaunay accident: no four points are cospherical on a
/// face), as the points and triangles of an `.off` file written to `path`.
fn subdivided_tetrahedron(path: &Path) -> Vec<[[f64; 3]; 3]> {
    let corners = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.5, 0.75f64.sqrt(), 0.0],
        [0.5, 0.75f64.sqrt() / 3.0, (2.0f64 / 3.0).sqrt()],
    ];
    let mut tris: Vec<[[f64; 3]; 3]> = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]]
        .iter()
        .map(|f| f.map(|i| corners[i]))
        .collect();
    let mid = |a: [f64; 3], b: [f64; 3]| std::array::from_fn(|k| (a[k] + b[k]) / 2.0);
    for _ in 0..2 {
        tris = tris
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b), mid(b, c), mid(c, a));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    let mut points: Vec<[f64; 3]> = Vec::new();
    let mut index = |p: [f64; 3]| match points.iter().position(|&q| q == p) {
        Some(i) => i,
        None => {
            points.push(p);
            points.len() - 1
        }
    };
    let faces: Vec<[usize; 3]> = tris.iter().map(|t| t.map(&mut index)).collect();
    let mut off = format!("OFF\n{} {} 0\n", points.len(), faces.len());
    for p in &points {
        off += &format!("{} {} {}\n", p[0], p[1], p[2]);
    }
    for f in &faces {
        off += &format!("3 {} {} {}\n", f[0], f[1], f[2]);
    }
    fs::write(path, off).unwrap();
    tris
}

#[test]
fn keep_boundary_leaves_the_input_triangles_as_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("tet16.off");
    let input = triangle_set(&subdivided_tetrahedron(&model));
    assert_eq!(input.len(), 64);

    let kept = refine(&model, "-pq1.2/10a0.0001Y");
    assert!(kept.points.len() > 34, "refinement added interior points");
    assert_eq!(
        triangle_set(&kept.faces),
        input,
        "-Y keeps every input triangle"
    );
    // The tets -Y leaves (their circumcentres encroach upon the boundary) are counted.
    assert!(kept.left > 0 && kept.over_ratio(1.2) <= kept.left);
    // Without -Y the same bounds split the boundary (so the test tells the two apart).
    let free = refine(&model, "-pq1.2/10a0.0001");
    assert_ne!(triangle_set(&free.faces), input);
}

#[test]
fn keep_boundary_refuses_a_plc_whose_cdt_needs_boundary_points() {
    // Schönhardt's twisted prism: its CDT needs Steiner points on its segments.
    let out = Command::cargo_bin("tetcdt")
        .unwrap()
        .args(["-pYQ", "-o"])
        .arg(tempfile::tempdir().unwrap().path().join("out"))
        .arg(example("plc/schonhardt.off"))
        .assert()
        .code(1);
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).to_string();
    assert!(
        stderr.contains("-Y: the boundary cannot be kept as given") && stderr.contains("Steiner"),
        "{stderr}"
    );
    // Without -Y it meshes, with those points.
    refine(&example("plc/schonhardt.off"), "-p");
}

#[test]
fn refinement_keeps_every_vertex_of_the_domain() {
    // Splits near the apex of a triangulated tetrahedron once took every tet around the
    // apex into their cavity and dropped it, with its segments (carving then refused
    // the mesh). Every input point must stay a node.
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("tet16.off");
    let triangles = subdivided_tetrahedron(&model);
    for switches in ["-pa0.001", "-pq1.2/10a0.001"] {
        let r = refine(&model, switches);
        for t in &triangles {
            for p in t {
                assert!(r.points.contains(p), "{switches}: {p:?} lost");
            }
        }
    }
}

#[test]
fn refinement_beside_facets_that_are_not_flat_leaves_no_shim() {
    // mpi.off merges polygons 0.1° apart into facets far from flat: split points on
    // the segments of one lie within the slab of its neighbour, and circumcentres fall
    // just off it. Each insertion is taken back when it would leave a tet of the domain
    // flat on one facet, or a face covering a facet twice; the run must be certified.
    let r = refine(&example("nonflat/mpi.off"), "-pq1.414");
    assert!(r.points.len() > 90, "refinement added no point");
    assert!(!r.tets.is_empty());
}

#[test]
fn refinement_ends_where_splits_cascade_toward_a_point() {
    // Splits that other splits ask for once ignored the insertion floor: on handle.off
    // subfaces of its facet x = -0.5 were split ever finer around one point (edges of
    // 1e-11, the floor about 3e-5) and -pq1.414 did not end in minutes. Every split
    // point now keeps a fraction of the floor, so refinement ends.
    let r = refine(&example("plc/handle.off"), "-pq1.414");
    assert!(r.points.len() > 1165, "refinement added no point");
    let shortest = r
        .tets
        .iter()
        .flat_map(|t| {
            let p = t.map(|v| r.points[v]);
            (0..4).flat_map(move |i| (i + 1..4).map(move |j| (p[i], p[j])))
        })
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt())
        .fold(f64::INFINITY, f64::min);
    // The input's shortest edge in its CDT is about 1.1e-4; the floor is a quarter of
    // it, and a cascade of splits keeps an eighth of the floor.
    assert!(shortest > 3e-6, "an edge of {shortest}");
}

#[test]
fn refinement_ends_where_splits_would_cycle_or_crowd() {
    // femur.off: a subface split moved to an edge already waiting below it, whose split
    // asked for that subface again, and the cascade went round until its bound.
    // boeing.off: the flips settling a split joined its point to vertices nearer than
    // the floor, and refinement crowded points around them. Both ran for minutes.
    for name in ["plc/femur.off", "plc/boeing.off"] {
        let input = fs::read_to_string(example(name)).unwrap();
        let vertices: usize = input.split_whitespace().nth(1).unwrap().parse().unwrap();
        let r = refine(&example(name), "-pq1.414");
        assert!(
            r.points.len() > vertices,
            "{name}: refinement added no point"
        );
    }
}
