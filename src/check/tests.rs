//! The certifier on meshes it must accept, and on tampered ones it must reject: a tet
//! removed, a flip that breaks the Delaunay property, a subface flipped away across its
//! facet, a shim, overlapping tets, a segment that is no chain of edges.

use super::*;
use crate::mesh::FACE_VERTS;
use crate::options::Options;
use crate::plc::Facet;

fn cube_with_center() -> Plc {
    let mut pts: Vec<Point> = (0..8)
        .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
        .collect();
    pts.push([0.4, 0.45, 0.55]);
    pts.push([0.9, 0.2, 0.3]);
    Plc::from_points(pts, 0)
}

/// The unit cube's six quads (as facets of `plc`, whose first eight points are its
/// corners), with the markers 1 to 6.
fn with_cube_facets(mut plc: Plc) -> Plc {
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    plc.facets = quads
        .iter()
        .enumerate()
        .map(|(i, q)| Facet {
            polygons: vec![q.to_vec()],
            marker: i as i32 + 1,
            ..Default::default()
        })
        .collect();
    plc
}

/// A PLC of `points` with one facet for each polygon of `polygons`.
fn polygons_plc(points: Vec<Point>, polygons: &[&[u32]]) -> Plc {
    let mut plc = Plc::from_points(points, 0);
    plc.facets = polygons
        .iter()
        .map(|p| Facet {
            polygons: vec![p.to_vec()],
            ..Default::default()
        })
        .collect();
    plc
}

/// The shim test's verdict: whether tet 0 of `m` is listed as a shim of `plc`.
fn tet_0_is_a_shim(plc: &Plc, m: &MeshOut) -> bool {
    let e = check(plc, m).unwrap_err();
    e.listed
        .iter()
        .any(|l| l.starts_with("tet 0 ") && l.contains("is a shim"))
}

fn meshed(plc: &Plc, p: bool) -> MeshOut {
    let opts = Options {
        plc: p,
        ..Default::default()
    };
    crate::tetrahedralize(plc, &opts).unwrap().mesh
}

fn check(plc: &Plc, m: &MeshOut) -> Result<(), CheckFailure> {
    check_mesh(plc, m, &CertifyOptions::default()).map(|_| ())
}

/// The tet with vertices `t`, positively oriented.
fn oriented(points: &[Point], mut t: [u32; 4]) -> [u32; 4] {
    let p = t.map(|v| points[v as usize]);
    if orient3d(&p[0], &p[1], &p[2], &p[3]) < 0.0 {
        t.swap(0, 1);
    }
    t
}

/// Replaces the two tets of `m` sharing face `f` by the three around the edge between
/// their other vertices (a 2-3 flip; the caller makes sure the union is convex).
fn flip23(m: &mut MeshOut, f: [u32; 3]) {
    let has = |t: &[u32; 4]| f.iter().all(|v| t.contains(v));
    let two: Vec<usize> = (0..m.tets.len()).filter(|&i| has(&m.tets[i])).collect();
    assert_eq!(two.len(), 2, "face {f:?} is not between two tets");
    let apex = |t: &[u32; 4]| *t.iter().find(|v| !f.contains(v)).unwrap();
    let (d, e) = (apex(&m.tets[two[0]]), apex(&m.tets[two[1]]));
    m.tets.remove(two[1]);
    m.tets.remove(two[0]);
    for k in 0..3 {
        let t = [f[k], f[(k + 1) % 3], d, e];
        m.tets.push(oriented(&m.points, t));
    }
    m.neighbors.clear();
}

/// A face of `m` between two tets whose union is convex (the edge between their other
/// vertices crosses it), chosen by `pick` among the candidates.
fn flippable_face(m: &MeshOut, pick: impl Fn(&[u32; 3]) -> bool) -> Option<[u32; 3]> {
    let mut faces: std::collections::BTreeMap<[u32; 3], Vec<u32>> = Default::default();
    for t in &m.tets {
        for fv in FACE_VERTS {
            let mut k = [t[fv[0]], t[fv[1]], t[fv[2]]];
            k.sort_unstable();
            let apex = *t.iter().find(|v| !k.contains(v)).unwrap();
            faces.entry(k).or_default().push(apex);
        }
    }
    let p = |v: u32| &m.points[v as usize];
    faces.into_iter().find_map(|(f, apices)| {
        let [d, e] = apices[..] else { return None };
        // The segment d–e crosses the triangle's interior.
        let s = [
            orient3d(p(d), p(e), p(f[0]), p(f[1])),
            orient3d(p(d), p(e), p(f[1]), p(f[2])),
            orient3d(p(d), p(e), p(f[2]), p(f[0])),
        ];
        let convex = s.iter().all(|&x| x > 0.0) || s.iter().all(|&x| x < 0.0);
        (convex && pick(&f)).then_some(f)
    })
}

#[test]
fn a_delaunay_mesh_passes() {
    let plc = cube_with_center();
    check(&plc, &meshed(&plc, false)).unwrap();
}

#[test]
fn a_cdt_passes_and_is_certified_from_its_nodes_and_tets_alone() {
    let plc = with_cube_facets(cube_with_center());
    let m = meshed(&plc, true);
    check(&plc, &m).unwrap();
    let view = MeshView {
        points: &m.points,
        tets: &m.tets,
        first_index: 0,
    };
    let cert = certify(&plc, view, &CertifyOptions::default()).unwrap();
    // Two triangles on each of the six quads, no Steiner point.
    assert_eq!(cert.subfaces, 12);
    assert_eq!(cert.steiner_points, 0);
}

#[test]
fn wrong_hull_faces_fail() {
    let plc = cube_with_center();
    let mut m = meshed(&plc, false);
    assert!(!m.hull_faces.is_empty());
    m.hull_faces[0].swap(1, 2);
    let e = check(&plc, &m).unwrap_err().to_string();
    assert!(e.contains("hull face 0"), "{e}");
    m.hull_faces.pop();
    let e = check(&plc, &m).unwrap_err().to_string();
    assert!(e.contains("hull faces but has"), "{e}");
}

#[test]
fn an_inverted_tet_fails() {
    let plc = cube_with_center();
    let mut m = meshed(&plc, false);
    m.tets[0].swap(0, 1);
    let e = check(&plc, &m).unwrap_err().to_string();
    assert!(e.contains("not positively oriented"), "{e}");
}

#[test]
fn a_removed_tet_fails() {
    let plc = with_cube_facets(cube_with_center());
    let mut m = meshed(&plc, true);
    // A tet at the inner point: its removal opens the mesh inside.
    let k = m.tets.iter().position(|t| t.contains(&8)).unwrap();
    m.tets.remove(k);
    m.neighbors.clear();
    let e = check(&plc, &m).unwrap_err().to_string();
    assert!(e.contains("lies on no facet"), "{e}");
}

#[test]
fn a_flip_that_breaks_the_delaunay_property_fails() {
    let mut s = 7u64;
    let pts: Vec<Point> = (0..30)
        .map(|_| std::array::from_fn(|_| crate::geom::lcg(&mut s)))
        .collect();
    let plc = Plc::from_points(pts, 0);
    let mut m = meshed(&plc, false);
    let f = flippable_face(&m, |_| true).expect("a flippable face");
    flip23(&mut m, f);
    m.hull_faces.clear();
    let e = check(&plc, &m).unwrap_err().to_string();
    assert!(e.contains("not locally Delaunay"), "{e}");
}

#[test]
fn a_subface_flipped_across_its_facet_fails() {
    // The box [0,2]x[0,1]x[0,1] cut by the internal facet x = 1, with points near it on
    // both sides so that its triangles are faces between two tets.
    let mut pts: Vec<Point> = Vec::new();
    for x in [0.0, 1.0, 2.0] {
        for y in [0.0, 1.0] {
            for z in [0.0, 1.0] {
                pts.push([x, y, z]);
            }
        }
    }
    pts.push([0.8, 0.4, 0.45]);
    pts.push([1.2, 0.55, 0.6]);
    let g = |x: usize, y: usize, z: usize| (x * 4 + y * 2 + z) as u32;
    let quad = |q: [u32; 4]| Facet {
        polygons: vec![q.to_vec()],
        marker: 1,
        ..Default::default()
    };
    let mut facets = vec![
        quad([g(0, 0, 0), g(0, 0, 1), g(0, 1, 1), g(0, 1, 0)]),
        quad([g(2, 0, 0), g(2, 1, 0), g(2, 1, 1), g(2, 0, 1)]),
        quad([g(1, 0, 0), g(1, 1, 0), g(1, 1, 1), g(1, 0, 1)]),
    ];
    for (a, b) in [(0, 1), (1, 2)] {
        facets.push(quad([g(a, 0, 0), g(a, 1, 0), g(b, 1, 0), g(b, 0, 0)]));
        facets.push(quad([g(a, 0, 1), g(b, 0, 1), g(b, 1, 1), g(a, 1, 1)]));
        facets.push(quad([g(a, 0, 0), g(b, 0, 0), g(b, 0, 1), g(a, 0, 1)]));
        facets.push(quad([g(a, 1, 0), g(a, 1, 1), g(b, 1, 1), g(b, 1, 0)]));
    }
    let plc = Plc {
        points: pts,
        facets,
        ..Default::default()
    };
    let mut m = meshed(&plc, true);
    check(&plc, &m).unwrap();
    let on_wall = |f: &[u32; 3]| f.iter().all(|&v| (4..8).contains(&v));
    let f = flippable_face(&m, on_wall).expect("a subface between two tets");
    flip23(&mut m, f);
    let e = check(&plc, &m).unwrap_err().to_string();
    assert!(e.contains("facet 2:"), "{e}");
}

#[test]
fn an_unused_point_fails_but_a_duplicate_does_not() {
    let mut plc = cube_with_center();
    plc.points.push(plc.points[3]);
    let m = meshed(&plc, false);
    check(&plc, &m).unwrap();
    let mut m2 = m.clone();
    // Pretend point 9 was never inserted: drop every tet that uses it.
    m2.tets.retain(|t| !t.contains(&9));
    m2.neighbors.clear();
    m2.hull_faces.clear();
    assert!(check(&plc, &m2).is_err());
}

#[test]
fn a_plc_point_inside_the_mesh_must_be_a_vertex() {
    let cube = |extra: bool| {
        let mut plc = cube_with_center();
        plc.points.truncate(8);
        if extra {
            plc.points.push([0.4, 0.45, 0.55]);
        }
        with_cube_facets(plc)
    };
    let full = cube(true);
    check(&full, &meshed(&full, true)).unwrap();
    // The cube meshed without its inner point, checked against the model with it.
    let lost = meshed(&cube(false), true);
    let e = check(&full, &lost).unwrap_err().to_string();
    assert!(e.contains("input point 8 lies in tet"), "{e}");
}

#[test]
fn a_segment_that_is_no_chain_of_edges_fails() {
    let plc = with_cube_facets(cube_with_center());
    let m = meshed(&plc, true);
    // A segment floating in the cube between two corners that no edge joins.
    let joined = |a: u32, b: u32| m.tets.iter().any(|t| t.contains(&a) && t.contains(&b));
    let (a, b) = (0..8u32)
        .flat_map(|a| (a + 1..8).map(move |b| (a, b)))
        .find(|&(a, b)| !joined(a, b))
        .expect("two corners without an edge");
    let mut with_segment = plc.clone();
    with_segment.facets.push(Facet {
        polygons: vec![vec![a, b]],
        ..Default::default()
    });
    let e = check(&with_segment, &m).unwrap_err().to_string();
    assert!(e.contains("is not a chain of mesh edges"), "{e}");
}

#[test]
fn a_shim_fails() {
    // A square pyramid whose base is bent by 1e-4: the mesher's mesh passes, and the
    // same domain with a flat tet of the four base corners beneath two others fails.
    let plc = polygons_plc(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, -1e-4],
            [0.5, 0.5, 1.0],
        ],
        &[
            &[0, 1, 2, 3],
            &[0, 1, 4],
            &[1, 2, 4],
            &[2, 3, 4],
            &[3, 0, 4],
        ],
    );
    let mut m = meshed(&plc, true);
    check(&plc, &m).unwrap();
    m.tets = [[0, 1, 2, 3], [0, 1, 2, 4], [0, 2, 3, 4]]
        .into_iter()
        .map(|t| oriented(&m.points, t))
        .collect();
    m.neighbors.clear();
    assert!(tet_0_is_a_shim(&plc, &m));
}

#[test]
fn problems_past_the_listed_ones_are_counted() {
    let plc = cube_with_center();
    let mut m = meshed(&plc, false);
    m.tets = vec![[0, 0, 1, 2]; 30];
    m.neighbors.clear();
    let e = check(&plc, &m).unwrap_err();
    assert_eq!((e.total, e.listed.len()), (30, 20), "{e:?}");
    assert!(e.to_string().ends_with("\n... and 10 more problems"), "{e}");
}

#[test]
fn overlapping_tets_fail() {
    let plc = cube_with_center();
    let mut m = meshed(&plc, false);
    let t = m.tets[0];
    m.tets.push(t);
    m.neighbors.clear();
    m.hull_faces.clear();
    let e = check(&plc, &m).unwrap_err().to_string();
    assert!(e.contains("belongs to 3 tets"), "{e}");
}

#[test]
fn a_second_layer_of_tets_is_found_by_the_tiling_count() {
    // Two copies of the same mesh, the second with its own nodes at the same places: every
    // face pairs up within its copy, but each point is held by two tets.
    let plc = cube_with_center();
    let m = meshed(&plc, false);
    let n = m.points.len() as u32;
    let mut points = m.points.clone();
    points.extend_from_slice(&m.points);
    let mut tets = m.tets.clone();
    tets.extend(m.tets.iter().map(|t| t.map(|v| v + n)));
    let view = MeshView {
        points: &points,
        tets: &tets,
        first_index: 0,
    };
    let e = certify(&plc, view, &CertifyOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("tets overlap"), "{e}");
}

#[test]
fn a_shim_with_a_steiner_point_in_a_facets_slab_fails() {
    // A tetrahedron whose bottom facet is the triangle (0, 1, 2); a Steiner point in the
    // bottom's plane and box but outside the triangle lies on no facet by the nearest-
    // plane rule, yet in the bottom's slab, as the shared referee counts it: the flat
    // tet of the three bottom corners and that point is a shim.
    let plc = polygons_plc(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.2, 0.2, 1.0],
        ],
        &[&[0, 1, 2], &[0, 1, 3], &[1, 2, 3], &[2, 0, 3]],
    );
    let mut m = meshed(&plc, true);
    check(&plc, &m).unwrap();
    m.points.push([0.7, 0.7, 0.0]);
    m.tets.insert(0, oriented(&m.points, [0, 1, 2, 4]));
    m.neighbors.clear();
    assert!(tet_0_is_a_shim(&plc, &m));
}
