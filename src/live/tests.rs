//! Each kind of insertion on small CDTs, certified after every step.

use super::*;

fn model(name: &str) -> Plc {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    crate::io::read_plc(&path).unwrap()
}

/// Inserts `p`, certifies, and returns what the insertion did.
fn insert_certified(cdt: &mut Cdt, p: Point) -> Inserted {
    let done = cdt
        .insert_vertex(p)
        .unwrap_or_else(|e| panic!("{p:?}: {e}"));
    if let Err(e) = cdt.certify() {
        panic!("after {p:?}: {e}");
    }
    done
}

#[test]
fn a_point_inside_goes_in_without_splits() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let (segs, faces) = cdt.num_constraints();
    let done = insert_certified(&mut cdt, [0.4, 0.45, 0.5]);
    assert!(done.new);
    assert_eq!(done.splits, 0);
    assert_eq!(done.node, 8);
    assert_eq!(cdt.num_constraints(), (segs, faces));
    // Again: the same node, nothing new.
    let again = cdt.insert_vertex([0.4, 0.45, 0.5]).unwrap();
    assert_eq!((again.node, again.new), (8, false));
    assert_eq!(cdt.mesh().unwrap().points.len(), 9);
}

#[test]
fn a_point_on_a_subsegment_splits_it_and_its_subfaces() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let (segs, faces) = cdt.num_constraints();
    // Every edge of the cube is a segment; (0.5, 0, 0) lies on one, exactly.
    let done = insert_certified(&mut cdt, [0.5, 0.0, 0.0]);
    assert!(done.new);
    assert_eq!(cdt.num_constraints(), (segs + 1, faces + 2));
    let mesh = cdt.mesh().unwrap();
    let node = done.node as u32;
    let pieces = mesh
        .subsegments
        .iter()
        .filter(|(e, _)| e.contains(&node))
        .count();
    assert_eq!(pieces, 2);
}

#[test]
fn a_point_on_a_subface_splits_it_in_three() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let (segs, faces) = cdt.num_constraints();
    // On the face z = 0, inside one of its two triangles whatever the diagonal.
    let done = insert_certified(&mut cdt, [0.5, 0.25, 0.0]);
    let (s, f) = cdt.num_constraints();
    // It lies in the diametral ball of the edge y = 0, which is split first.
    assert!(s > segs);
    assert!(f >= faces + 2, "{f} subfaces from {faces}");
    assert!(done.new);
    let mesh = cdt.mesh().unwrap();
    let node = done.node as u32;
    assert!(
        mesh.subfaces
            .iter()
            .filter(|(t, _)| t.contains(&node))
            .count()
            >= 3
    );
}

#[test]
fn a_point_near_a_segment_splits_what_it_encroaches_upon_first() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let (segs, _) = cdt.num_constraints();
    // Inside the diametral ball of the edge from (0,0,0) to (1,0,0).
    let done = insert_certified(&mut cdt, [0.3, 0.05, 0.05]);
    assert!(done.splits >= 1);
    assert!(cdt.num_constraints().0 > segs);
    // The point itself went in, off the segments.
    assert!(done.new);
    let mesh = cdt.mesh().unwrap();
    assert_eq!(mesh.points[done.node], [0.3, 0.05, 0.05]);
}

#[test]
fn points_outside_the_hull_and_not_finite_are_refused_without_change() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let n = cdt.num_tets();
    assert_eq!(
        cdt.insert_vertex([2.0, 0.5, 0.5]),
        Err(InsertError::OutsideHull([2.0, 0.5, 0.5]))
    );
    assert!(matches!(
        cdt.insert_vertex([f64::NAN, 0.0, 0.0]),
        Err(InsertError::NotFinite(_))
    ));
    assert_eq!(cdt.num_tets(), n);
    cdt.certify().unwrap();
}

#[test]
fn the_steiner_budget_bounds_insertions() {
    let opts = PlcOptions {
        max_steiner: 1,
        ..Default::default()
    };
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &opts).unwrap();
    cdt.insert_vertex([0.5, 0.5, 0.5]).unwrap();
    assert_eq!(
        cdt.insert_vertex([0.25, 0.5, 0.5]),
        Err(InsertError::Budget(1))
    );
}

/// Points in the hole, on the hole's walls, near its edges, and in the solid: the
/// carved mesh stays a CDT after each, and the hole stays empty.
#[test]
fn a_box_with_a_hole_takes_points_everywhere() {
    let plc = model("data/examples/box_with_hole.poly");
    let mut cdt = Cdt::build(&plc, &Default::default()).unwrap();
    let mut lcg = 7u64;
    let [lo, hi] = crate::geom::bounding_box(&plc.points);
    for _ in 0..40 {
        let p: Point =
            std::array::from_fn(|k| lo[k] + (hi[k] - lo[k]) * crate::geom::lcg(&mut lcg));
        insert_certified(&mut cdt, p);
    }
    // Exactly on the boundary's vertices' grid: faces, edges.
    let corner = plc.points[0];
    let other = plc.points[1];
    let mid: Point = std::array::from_fn(|k| 0.5 * (corner[k] + other[k]));
    insert_certified(&mut cdt, mid);
    assert!(cdt.added_points() >= 41);
}

/// The nearly flat grids: their polygons are not flat, and points on and near them go
/// in with their facets' triangulations split in place.
#[test]
fn points_go_into_a_nearly_flat_grid() {
    let plc = model("data/plc/flat_grid_6.poly");
    let mut cdt = Cdt::build(&plc, &Default::default()).unwrap();
    let mut lcg = 3u64;
    let [lo, hi] = crate::geom::bounding_box(&plc.points);
    for _ in 0..30 {
        let p: Point =
            std::array::from_fn(|k| lo[k] + (hi[k] - lo[k]) * crate::geom::lcg(&mut lcg));
        insert_certified(&mut cdt, p);
    }
}

/// Inserts polygon `ring`, certifies, and returns what the insertion did.
fn polygon_certified(cdt: &mut Cdt, ring: &[Point], marker: i32) -> PolygonInserted {
    let done = cdt
        .insert_polygon(ring, marker)
        .unwrap_or_else(|e| panic!("{ring:?}: {e}"));
    if let Err(e) = cdt.certify() {
        panic!("after {ring:?}: {e}");
    }
    done
}

#[test]
fn a_square_inside_a_cube_becomes_a_facet() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let (segs, faces) = cdt.num_constraints();
    let sq = [
        [0.2, 0.2, 0.5],
        [0.8, 0.2, 0.5],
        [0.8, 0.8, 0.5],
        [0.2, 0.8, 0.5],
    ];
    let done = polygon_certified(&mut cdt, &sq, 7);
    // The corners encroach upon the cube's vertical edges, which are split first.
    let mesh = cdt.mesh().unwrap();
    let at: Vec<Point> = done.corners.iter().map(|&c| mesh.points[c]).collect();
    assert_eq!(at, sq);
    assert!(done.added >= 4);
    assert!(done.subfaces >= 2);
    let (s, f) = cdt.num_constraints();
    assert!(s >= segs + 4);
    assert!(f >= faces + done.subfaces);
    let mesh = cdt.mesh().unwrap();
    assert_eq!(
        mesh.subfaces.iter().filter(|(_, m)| *m == 7).count(),
        done.subfaces
    );
    // A point just above the square, inside its equatorial balls, goes in too.
    insert_certified(&mut cdt, [0.5, 0.45, 0.52]);
}

#[test]
fn a_tilted_triangle_and_a_polygon_sharing_its_edge_go_in() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let a = [0.2, 0.3, 0.3];
    let b = [0.7, 0.2, 0.4];
    let c = [0.6, 0.8, 0.7];
    polygon_certified(&mut cdt, &[a, b, c], 1);
    // Another polygon on the edge a–b, folded away from the first.
    polygon_certified(&mut cdt, &[b, a, [0.4, 0.1, 0.8]], 2);
    for p in [[0.45, 0.3, 0.45], [0.5, 0.5, 0.5], [0.35, 0.25, 0.35]] {
        insert_certified(&mut cdt, p);
    }
}

#[test]
fn polygons_that_break_the_plc_are_refused_without_change() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let (n, segs) = (cdt.num_vertices(), cdt.num_constraints());
    // Through the cube's side x = 1.
    let through = [[0.5, 0.5, 0.5], [1.5, 0.5, 0.5], [1.5, 0.6, 0.6]];
    assert!(matches!(
        cdt.insert_polygon(&through, 1),
        Err(PolygonError::Invalid(_)) | Err(PolygonError::Vertex(InsertError::OutsideHull(_)))
    ));
    let sq = [[0.2, 0.2, 0.5], [0.8, 0.2, 0.5], [0.8, 0.8, 0.5]];
    polygon_certified(&mut cdt, &sq, 1);
    // Crossing the first.
    let crossing = [[0.5, 0.4, 0.2], [0.6, 0.4, 0.8], [0.5, 0.5, 0.8]];
    assert!(matches!(
        cdt.insert_polygon(&crossing, 1),
        Err(PolygonError::Invalid(_))
    ));
    assert!(matches!(
        cdt.insert_polygon(&[[0.1, 0.1, 0.1], [0.2, 0.2, 0.2], [0.3, 0.3, 0.3]], 1),
        Err(PolygonError::Degenerate(_))
    ));
    assert!(matches!(
        cdt.insert_polygon(&[[0.1, 0.1, 0.1], [0.2, 0.2, 0.2]], 1),
        Err(PolygonError::Degenerate(_))
    ));
    assert!(cdt.num_vertices() >= n + 3);
    assert!(cdt.num_constraints().0 > segs.0);
    cdt.certify().unwrap();
}

/// The convex hull of random points, its triangles as facets: sharp angles between
/// facets and between segments everywhere.
fn random_hull(seed: u64, n: usize) -> (Plc, Vec<Point>) {
    let mut lcg = seed;
    let pts: Vec<Point> = (0..n)
        .map(|_| std::array::from_fn(|_| crate::geom::lcg(&mut lcg)))
        .collect();
    let hull = crate::delaunay::Delaunay::build(&pts)
        .unwrap()
        .dt
        .export_with(false)
        .hull_faces;
    let plc = Plc {
        points: pts.clone(),
        facets: hull
            .iter()
            .map(|t| crate::plc::Facet {
                polygons: vec![t.to_vec()],
                holes: Vec::new(),
                marker: 1,
                line: 0,
            })
            .collect(),
        ..Default::default()
    };
    // Points inside: convex combinations of four input points.
    let inside = (0..12)
        .map(|_| {
            let w: [f64; 4] = std::array::from_fn(|_| 0.05 + crate::geom::lcg(&mut lcg));
            let k: [usize; 4] =
                std::array::from_fn(|_| (crate::geom::lcg(&mut lcg) * n as f64) as usize % n);
            let total: f64 = w.iter().sum();
            std::array::from_fn(|d| (0..4).map(|j| w[j] * pts[k[j]][d]).sum::<f64>() / total)
        })
        .collect();
    (plc, inside)
}

/// Points into the CDTs of random convex hulls (sharp angles between facets and between
/// segments everywhere): every step leaves a certified CDT, refused or not (splits keep
/// their cavities off the split facets' other subfaces, and a split that still makes a
/// shim is taken back), and in most runs every point goes in: 32 of these 40, none
/// before those rules.
#[test]
fn points_go_into_random_convex_hulls() {
    let mut clean = 0;
    for seed in 1..=40u64 {
        let (plc, inside) = random_hull(seed, 12);
        let mut cdt = Cdt::build(&plc, &Default::default()).unwrap();
        let mut refused = false;
        for p in inside {
            match cdt.insert_vertex(p) {
                // Points exactly on a hull facet may round to outside the hull.
                Ok(_) | Err(InsertError::OutsideHull(_)) => {}
                Err(InsertError::Refused(_)) => refused = true,
                Err(e) => panic!("hull {seed}, {p:?}: {e}"),
            }
            if let Err(e) = cdt.certify() {
                panic!("hull {seed}, after {p:?}: {e}");
            }
        }
        clean += usize::from(!refused);
    }
    assert!(clean >= 30, "{clean} of 40 runs clean");
}

/// Points computed on a facet are rounded off its plane: within the certifier's
/// thinnest slab they are on it, and split it, rather than making shims beside it.
#[test]
fn points_rounded_off_a_facet_split_it() {
    let mut cdt = Cdt::build(&model("data/examples/cube.poly"), &Default::default()).unwrap();
    let (a, b, c) = ([0.2, 0.3, 0.3], [0.7, 0.2, 0.4], [0.6, 0.8, 0.7]);
    polygon_certified(&mut cdt, &[a, b, c], 4);
    let mut off_plane = 0;
    for (u, v) in [(0.3, 0.3), (0.2, 0.5), (0.45, 0.15), (0.3, 0.6)] {
        let p: Point = std::array::from_fn(|k| a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]));
        off_plane += usize::from(crate::geom::orient3d(&a, &b, &c, &p) != 0.0);
        let done = insert_certified(&mut cdt, p);
        let mesh = cdt.mesh().unwrap();
        let node = done.node as u32;
        assert!(
            mesh.subfaces
                .iter()
                .any(|(t, m)| *m == 4 && t.contains(&node)),
            "{p:?} is not on the triangle"
        );
    }
    assert!(off_plane > 0, "no point was rounded off the plane");
}

#[test]
fn refinement_meets_its_bounds_and_stays_a_cdt() {
    let plc = model("data/examples/box_with_hole.poly");
    let mut cdt = Cdt::build(&plc, &Default::default()).unwrap();
    let before = cdt.num_vertices();
    let params = RefineParameters {
        max_ratio: Some(1.3),
        max_volume: Some(0.05),
        ..Default::default()
    };
    let r = cdt.refine(&params);
    assert_eq!(r.left, 0);
    assert!(!r.budget_spent);
    assert_eq!(cdt.num_vertices(), before + r.points);
    cdt.certify().unwrap();
    let mesh = cdt.mesh().unwrap();
    for t in &mesh.tets {
        let p = t.map(|v| mesh.points[v as usize]);
        assert!(crate::geom::quality::radius_edge_ratio(&p) <= 1.3);
        assert!(crate::geom::quality::volume(&p) <= 0.05);
    }
    // Nothing asked, nothing done.
    let again = cdt.refine(&RefineParameters::default());
    assert_eq!(again, RefineResult::default());
}

#[test]
fn refinement_stops_at_the_steiner_budget() {
    let plc = model("data/examples/cube.poly");
    let mut cdt = Cdt::build(&plc, &Default::default()).unwrap();
    cdt.set_steiner_budget(10);
    let r = cdt.refine(&RefineParameters {
        max_volume: Some(1e-4),
        ..Default::default()
    });
    assert!(r.budget_spent && r.left > 0 && r.points <= 10);
    cdt.certify().unwrap();
}
