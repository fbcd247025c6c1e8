use super::*;
use crate::geom::insphere_sos;
use crate::mesh::Tet;

use crate::geom::lcg;

fn random_points(n: usize, seed: u64) -> Vec<Point> {
    let mut s = seed;
    (0..n)
        .map(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)])
        .collect()
}

fn grid(nx: usize, ny: usize, nz: usize) -> Vec<Point> {
    let mut pts = Vec::new();
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                pts.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    pts
}

fn sorted_tets(dt: &Delaunay) -> Vec<[u32; 4]> {
    let mut v: Vec<[u32; 4]> = dt
        .mesh
        .real_tets()
        .map(|t| {
            let mut x = dt.mesh.verts(t).map(|v| dt.orig[v as usize]);
            x.sort();
            x
        })
        .collect();
    v.sort();
    v
}

/// The canonical DT by definition: every non-flat 4-subset whose perturbed
/// circumsphere contains no other point.
fn brute_force(pts: &[Point]) -> Vec<[u32; 4]> {
    let n = pts.len() as u32;
    let mut out = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                for d in c + 1..n {
                    let p = |i: u32| &pts[i as usize];
                    let o = orient3d(p(a), p(b), p(c), p(d));
                    if o == 0.0 {
                        continue;
                    }
                    let t = if o > 0.0 { [a, b, c, d] } else { [b, a, c, d] };
                    let empty = (0..n).filter(|e| !t.contains(e)).all(|e| {
                        let q = [t[0], t[1], t[2], t[3], e];
                        insphere_sos(q.map(p), q) == Sign::Negative
                    });
                    if empty {
                        out.push([a, b, c, d]);
                    }
                }
            }
        }
    }
    out.sort();
    out
}

fn assert_valid(dt: &Delaunay) {
    dt.mesh.check_links().unwrap();
    for t in dt.mesh.real_tets() {
        let v = dt.mesh.verts(t);
        let p = |i: u32| &dt.points[i as usize];
        assert!(
            orient3d(p(v[0]), p(v[1]), p(v[2]), p(v[3])) > 0.0,
            "tet {v:?} not positive"
        );
    }
}

#[test]
fn random_points_match_brute_force() {
    for seed in 1..20 {
        let pts = random_points(14, seed);
        let built = Delaunay::build(&pts).unwrap();
        assert_valid(&built.dt);
        assert_eq!(sorted_tets(&built.dt), brute_force(&pts), "seed {seed}");
    }
}

#[test]
fn integer_grids_match_the_perturbed_brute_force() {
    for (nx, ny, nz) in [(2, 2, 2), (3, 2, 2), (3, 3, 2), (3, 3, 3)] {
        let pts = grid(nx, ny, nz);
        let built = Delaunay::build(&pts).unwrap();
        assert_valid(&built.dt);
        assert_eq!(
            sorted_tets(&built.dt),
            brute_force(&pts),
            "grid {nx}x{ny}x{nz}"
        );
    }
}

#[test]
fn shuffled_grid_depends_only_on_indices() {
    // Reversing the index order changes the perturbation, so the DT must follow it.
    let mut pts = grid(3, 3, 2);
    pts.reverse();
    let built = Delaunay::build(&pts).unwrap();
    assert_valid(&built.dt);
    assert_eq!(sorted_tets(&built.dt), brute_force(&pts));
}

#[test]
fn cospherical_points_match_brute_force() {
    // Points on a sphere with exactly representable coordinates (Pythagorean quadruples).
    let mut pts: Vec<Point> = Vec::new();
    for &(a, b, c) in &[
        (3.0, 4.0, 12.0),
        (4.0, 12.0, 3.0),
        (12.0, 3.0, 4.0),
        (0.0, 0.0, 13.0),
    ] {
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                pts.push([sx * a, sy * b, c]);
            }
        }
    }
    pts.push([0.0, 5.0, 12.0]);
    pts.push([5.0, 0.0, -12.0]);
    pts.push([0.0, 0.0, -13.0]);
    pts.push([1.0, 1.0, 1.0]);
    let built = Delaunay::build(&pts).unwrap();
    assert_valid(&built.dt);
    assert_eq!(sorted_tets(&built.dt), brute_force(&pts));
}

#[test]
fn duplicates_are_skipped_keeping_the_lowest_index() {
    let mut pts = random_points(30, 5);
    pts.push(pts[7]);
    pts.insert(0, pts[20]); // now point 0 equals point 21
    let built = Delaunay::build(&pts).unwrap();
    assert_eq!(built.duplicates, vec![(21, 0), (31, 8)]);
    let used: std::collections::HashSet<u32> =
        sorted_tets(&built.dt).into_iter().flatten().collect();
    assert!(used.contains(&0) && !used.contains(&21) && !used.contains(&31));
}

#[test]
fn degenerate_inputs_are_errors() {
    let coplanar: Vec<Point> = (0..10).map(|i| [i as f64, (i * i) as f64, 0.0]).collect();
    let e = Delaunay::build(&coplanar).unwrap_err().to_string();
    assert!(e.contains("coplanar"), "{e}");
    let collinear: Vec<Point> = (0..10).map(|i| [i as f64, 2.0 * i as f64, 3.0]).collect();
    let e = Delaunay::build(&collinear).unwrap_err().to_string();
    assert!(e.contains("collinear"), "{e}");
    let e = Delaunay::build(&[[0.0; 3]; 5]).unwrap_err().to_string();
    assert!(e.contains("only 1 distinct"), "{e}");
    let e = Delaunay::build(&[[0.0, f64::NAN, 0.0]; 5])
        .unwrap_err()
        .to_string();
    assert!(e.contains("non-finite"), "{e}");
}

#[test]
fn larger_random_set_is_valid() {
    let pts = random_points(3000, 99);
    let built = Delaunay::build(&pts).unwrap();
    assert_valid(&built.dt);
    let dt = &built.dt;
    for t in dt.mesh.real_tets() {
        let v = dt.mesh.verts(t);
        for f in 0..4 {
            let g = dt.mesh.adj(FaceRef::new(t, f));
            if dt.mesh.is_ghost(g.tet()) {
                continue;
            }
            let e = dt.mesh.verts(g.tet())[g.face()];
            let q = [v[0], v[1], v[2], v[3], e];
            let ids = q.map(|i| dt.orig[i as usize]);
            assert_eq!(
                insphere_sos(q.map(|i| &dt.points[i as usize]), ids),
                Sign::Negative
            );
        }
    }
}

#[test]
fn location_by_scan_agrees_with_the_walk() {
    let pts = random_points(300, 9);
    let mut dt = Delaunay::build(&pts).unwrap().dt;
    let mut s = 77u64;
    let (mut inside, mut outside) = (0, 0);
    for k in 0..400 {
        // Queries inside and around the unit cube, and the input points themselves.
        let p: Point = if k % 10 == 0 {
            pts[k % 300]
        } else {
            [0, 0, 0].map(|_| lcg(&mut s) * 1.6 - 0.3)
        };
        let walked = dt.locate(&p);
        // A bound of no steps goes straight to the scan.
        match (walked, dt.locate_within(&p, 0)) {
            (Location::Inside(a), Location::Inside(b)) => {
                assert_eq!(a, b, "{p:?}");
                inside += 1;
            }
            (Location::Outside(_), Location::Outside(g)) => {
                let f = dt.mesh.face_verts(g, 3);
                assert!(dt.mesh.is_ghost(g));
                assert!(orient3d(dt.pt(f[0]), dt.pt(f[1]), dt.pt(f[2]), &p) > 0.0);
                outside += 1;
            }
            (Location::Vertex(a), Location::Vertex(b)) => assert_eq!(a, b),
            (a, b) => panic!("{p:?}: walk {a:?}, scan {b:?}"),
        }
    }
    assert!(
        inside > 50 && outside > 50,
        "{inside} inside, {outside} outside"
    );
}

/// A walled insertion is the plain one where nothing is blocked, refuses a cavity that
/// would reach both sides of a blocked face, and `undo` restores the mesh slot for slot.
#[test]
fn walled_insertions_are_undone_exactly() {
    let pts = random_points(300, 11);
    let mut s = 77u64;
    for k in 0..40 {
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let before: Vec<Tet> = (0..dt.mesh.num_slots() as TetId)
            .map(|t| *dt.mesh.tet(t))
            .collect();
        let tets_before = sorted_tets(&dt);
        let p: Point = [0, 0, 0].map(|_| 0.1 + 0.8 * lcg(&mut s));
        // Every other round, the faces of the tet holding the point are walls.
        let holder = match dt.locate(&p) {
            Location::Inside(t) => dt.mesh.verts(t),
            other => panic!("{other:?}"),
        };
        let walls = k % 2 == 1;
        let blocked = |v: [VertexId; 4], f: usize| {
            walls && {
                let mut a = v;
                a.sort_unstable();
                let mut b = holder;
                b.sort_unstable();
                a == b && v[f] != GHOST
            }
        };
        let n = dt.points.len();
        match dt.insert_walled(p, n as u32, blocked).unwrap() {
            Walled::Inserted {
                vertex,
                change,
                last,
            } => {
                dt.mesh.check_links().unwrap();
                // Walls around the holder keep every other tet: only it is replaced.
                if walls {
                    assert_eq!(change.old.len(), 1, "round {k}");
                } else {
                    let mut plain = Delaunay::build(&pts).unwrap().dt;
                    let id = plain.points.len() as u32;
                    plain.insert_steiner(p, id).unwrap();
                    assert_eq!(sorted_tets(&dt), sorted_tets(&plain), "round {k}");
                }
                dt.undo(vertex, &[change], last);
            }
            other => panic!("round {k}: {other:?}"),
        }
        dt.mesh.check_links().unwrap();
        assert_eq!(dt.points.len(), n);
        assert_eq!(sorted_tets(&dt), tets_before, "round {k}");
        for (t, tet) in before.iter().enumerate() {
            if tet.is_real() || tet.v[3] == GHOST {
                assert_eq!(dt.mesh.tet(t as TetId), tet, "round {k}, slot {t}");
            }
        }
    }
}

/// In a tetrahedralization that is not Delaunay (as a CDT is not, near its constraints)
/// a cavity grown by the insphere test need not be seen whole from the new point, even
/// with no wall met: such an insertion is refused, leaving the mesh as it was, and every
/// accepted one makes positive tets. The mesh here is a Delaunay one with a vertex moved
/// (its tets staying positive), and the points go near that vertex.
#[test]
fn cavities_not_seen_whole_from_the_point_are_refused() {
    let pts = random_points(200, 5);
    let mut s = 91u64;
    let (mut refused, mut inserted) = (0, 0);
    for k in 0..2000 {
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let v = (lcg(&mut s) * pts.len() as f64) as usize % pts.len();
        let on_hull = dt
            .mesh
            .live_tets()
            .any(|t| dt.mesh.is_ghost(t) && dt.mesh.verts(t).contains(&(v as VertexId)));
        if on_hull {
            continue;
        }
        let step = 10f64.powf(-1.5 - 1.5 * lcg(&mut s));
        let at = dt.points[v];
        let moved: Point = std::array::from_fn(|d| at[d] + step * (lcg(&mut s) - 0.5));
        dt.points[v] = moved;
        let positive = |dt: &Delaunay| {
            dt.mesh.real_tets().all(|t| {
                let q = dt.mesh.verts(t).map(|x| dt.pt(x));
                orient3d(q[0], q[1], q[2], q[3]) > 0.0
            })
        };
        if !positive(&dt) {
            continue;
        }
        let tets_before = sorted_tets(&dt);
        let p: Point = std::array::from_fn(|d| moved[d] + 2.0 * step * (lcg(&mut s) - 0.5));
        let n = dt.points.len();
        match dt.insert_walled(p, n as u32, |_, _| false).unwrap() {
            Walled::Inserted { .. } => {
                inserted += 1;
                dt.mesh.check_links().unwrap();
                assert!(positive(&dt), "round {k}");
            }
            Walled::Refused => {
                refused += 1;
                dt.mesh.check_links().unwrap();
                assert_eq!(dt.points.len(), n);
                assert_eq!(sorted_tets(&dt), tets_before, "round {k}");
            }
            Walled::OnVertex => panic!("round {k}"),
        }
    }
    assert!(
        refused > 5 && inserted > 5,
        "{refused} refused, {inserted} inserted"
    );
}

/// The same with walls: the point in one tet near an edge of the face it shares with a
/// neighbour, every other face a wall. Where the two tets are not convex together, the
/// point does not see the neighbour's face at that edge.
#[test]
fn walled_cavities_not_seen_whole_from_the_point_are_refused() {
    let pts = random_points(200, 5);
    let mut s = 91u64;
    let (mut refused, mut inserted) = (0, 0);
    for k in 0..300 {
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let tets_before = sorted_tets(&dt);
        let real: Vec<TetId> = dt.mesh.real_tets().collect();
        let t = real[(lcg(&mut s) * real.len() as f64) as usize % real.len()];
        let i = (lcg(&mut s) * 4.0) as usize % 4;
        if dt.mesh.is_ghost(dt.mesh.adj(FaceRef::new(t, i)).tet()) {
            continue;
        }
        let f = dt.mesh.face_verts(t, i);
        let apex = *dt.pt(dt.mesh.verts(t)[i]);
        let e = (lcg(&mut s) * 3.0) as usize % 3;
        let c: Point = std::array::from_fn(|d| (dt.pt(f[e])[d] + dt.pt(f[(e + 1) % 3])[d]) / 2.0);
        let step = 10f64.powf(-1.0 - 3.0 * lcg(&mut s));
        let p: Point = std::array::from_fn(|d| c[d] + step * (apex[d] - c[d]));
        let mut shared = f;
        shared.sort_unstable();
        let blocked = |v: [VertexId; 4], j: usize| {
            let mut face = FACE_VERTS[j].map(|x| v[x]);
            face.sort_unstable();
            face != shared
        };
        let n = dt.points.len();
        match dt.insert_walled(p, n as u32, blocked).unwrap() {
            Walled::Inserted { .. } => {
                inserted += 1;
                dt.mesh.check_links().unwrap();
                for t in dt.mesh.real_tets() {
                    let v = dt.mesh.verts(t).map(|x| dt.pt(x));
                    assert!(orient3d(v[0], v[1], v[2], v[3]) > 0.0, "round {k}");
                }
            }
            Walled::Refused => {
                refused += 1;
                dt.mesh.check_links().unwrap();
                assert_eq!(dt.points.len(), n);
                assert_eq!(sorted_tets(&dt), tets_before, "round {k}");
            }
            Walled::OnVertex => panic!("round {k}"),
        }
    }
    assert!(
        refused > 10 && inserted > 10,
        "{refused} refused, {inserted} inserted"
    );
}

/// Where the walk starts changes how far it goes, never the tetrahedralization: Steiner
/// points inserted with the walk started at a vertex near each (as segment recovery
/// does) give the same tets as with the walk started wherever the last insertion ended.
#[test]
fn walks_started_at_a_vertex_insert_the_same_points() {
    let pts = random_points(400, 5);
    let mut plain = Delaunay::build(&pts).unwrap().dt;
    let mut hinted = Delaunay::build(&pts).unwrap().dt;
    let mut s = 99u64;
    for k in 0..200 {
        let v = (lcg(&mut s) * pts.len() as f64) as usize % pts.len();
        let w = (v + 1 + k) % pts.len();
        // A point on the way from one input point to another, as on a segment.
        let t = 0.1 + 0.8 * lcg(&mut s);
        let x: Point = std::array::from_fn(|d| pts[v][d] + t * (pts[w][d] - pts[v][d]));
        let pert = (pts.len() + k) as u32;
        let a = plain.insert_steiner(x, pert).unwrap();
        let iv = hinted.internal_ids(pts.len())[v];
        hinted.start_walk_at(iv);
        let b = hinted.insert_steiner(x, pert).unwrap();
        assert_eq!(a.is_some(), b.is_some(), "point {k}");
    }
    // A vertex the mesh does not have is ignored.
    hinted.start_walk_at(u32::MAX - 1);
    hinted.mesh.check_links().unwrap();
    let ids = |dt: &Delaunay| {
        let mut t: Vec<[u32; 4]> = sorted_tets(dt)
            .into_iter()
            .map(|x| x.map(|v| dt.orig[v as usize]))
            .map(|mut x| {
                x.sort_unstable();
                x
            })
            .collect();
        t.sort_unstable();
        t
    };
    assert_eq!(ids(&plain), ids(&hinted));
}
