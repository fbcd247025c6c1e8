//! Shim tets in a finished PLC mesh: flat tets whose four vertices all lie on one facet,
//! which the paper rules out (§3.1). Facets are merged as TetGen merges them (the
//! polygons of one input facet, and edge-adjacent polygons whose planes differ by less
//! than 0.1°), and a Steiner point counts as lying on a merged facet when it is inside
//! the facet's box and slab, four times as thick as the facet's own deviation from flat:
//! the shared referee's measure, kept apart from the mesher's own search so that the
//! two check each other.

use crate::constrained::prepare::{dedup_ring, newell_normal, Dsu};
use crate::geom::{diagonal, dot, longest_edge2, norm, orient3d, sub, Point};
use crate::output::MeshOut;
use crate::plc::Plc;
use crate::precheck::bvh::{Aabb, Bvh};
use rustc_hash::FxHashMap;

/// A tet is flat when its volume is at most this fraction of its longest edge cubed.
const FLAT: f64 = 1e-3;

/// Edge-adjacent polygons whose planes differ by less than this many degrees are merged.
const MERGE_DEGREES: f64 = 0.1;

/// A merged facet: its plane, the half-thickness of its slab, and its box.
struct Group {
    normal: Point,
    mean: Point,
    tol: f64,
    lo: Point,
    hi: Point,
    /// An input facet it comes from, to name it.
    facet: usize,
}

impl Group {
    fn holds(&self, p: &Point) -> bool {
        dot(&sub(p, &self.mean), &self.normal).abs() <= self.tol
            && (0..3).all(|k| p[k] >= self.lo[k] && p[k] <= self.hi[k])
    }
}

/// The tets of `mesh` (indices) that are shims, each with an input facet of its merged
/// facet. `rep` maps each input point to its representative (the first of its copies).
pub(super) fn shims(plc: &Plc, mesh: &MeshOut, rep: &[u32]) -> Vec<(usize, usize)> {
    let pts = &mesh.points;
    let n_input = plc.points.len();
    // The polygons, as rings of representatives without repeats, with their facets.
    let polys: Vec<(usize, Vec<u32>)> = plc
        .facets
        .iter()
        .enumerate()
        .flat_map(|(fi, f)| {
            f.polygons.iter().map(move |poly| {
                let reps: Vec<u32> = poly.iter().map(|&v| rep[v as usize]).collect();
                (fi, dedup_ring(&reps))
            })
        })
        .collect();
    let groups_of = merge_coplanar(pts, &polys);
    let diag = diagonal(pts);
    let mut groups: Vec<Group> = Vec::new();
    // For each mesh vertex, the merged facets it lies on (increasing): input vertices by
    // their polygons, Steiner points below by the facets' slabs and boxes.
    let mut on: Vec<Vec<u32>> = vec![Vec::new(); pts.len()];
    for members in groups_of {
        let rings: Vec<&(usize, Vec<u32>)> = members
            .iter()
            .map(|&i| &polys[i])
            .filter(|(_, r)| r.len() >= 3)
            .collect();
        let Some(largest) = rings
            .iter()
            .map(|(_, r)| newell_normal(pts, r))
            .max_by(|a, b| norm(a).total_cmp(&norm(b)))
        else {
            continue;
        };
        let len = norm(&largest);
        if len.is_nan() || len <= 0.0 {
            continue;
        }
        let normal = largest.map(|x| x / len);
        let mut verts: Vec<u32> = rings.iter().flat_map(|(_, r)| r.iter().copied()).collect();
        verts.sort_unstable();
        verts.dedup();
        let k = verts.len() as f64;
        let mean: Point =
            std::array::from_fn(|a| verts.iter().map(|&v| pts[v as usize][a]).sum::<f64>() / k);
        let height = |p: &Point| dot(&sub(p, &mean), &normal);
        let dev = verts
            .iter()
            .map(|&v| height(&pts[v as usize]).abs())
            .fold(0.0, f64::max);
        let tol = (1e-10 * diag).max(4.0 * dev);
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for &v in &verts {
            for a in 0..3 {
                lo[a] = lo[a].min(pts[v as usize][a] - tol);
                hi[a] = hi[a].max(pts[v as usize][a] + tol);
            }
        }
        let g = groups.len() as u32;
        for &v in &verts {
            on[v as usize].push(g);
        }
        groups.push(Group {
            normal,
            mean,
            tol,
            lo,
            hi,
            facet: rings[0].0,
        });
    }
    if groups.is_empty() {
        return Vec::new();
    }
    // Steiner points: the merged facets whose box and slab hold them, found by a
    // bounding-volume hierarchy (a fan of long needles has many boxes across the model).
    let boxes: Vec<Aabb> = groups.iter().map(|g| [g.lo, g.hi]).collect();
    let bvh = Bvh::build(&boxes);
    for (v, p) in pts.iter().enumerate().skip(n_input) {
        bvh.query(&boxes, &[*p, *p], |g| {
            if groups[g].holds(p) {
                on[v].push(g as u32);
            }
        });
        on[v].sort_unstable();
    }
    let mut found = Vec::new();
    let mut common = Vec::new();
    for (t, tv) in mesh.tets.iter().enumerate() {
        common.clear();
        common.extend_from_slice(&on[tv[0] as usize]);
        for &v in &tv[1..] {
            let here = &on[v as usize];
            common.retain(|g| here.binary_search(g).is_ok());
        }
        let Some(&g) = common.first() else {
            continue;
        };
        let p = tv.map(|v| pts[v as usize]);
        if is_flat(&p) {
            found.push((t, groups[g as usize].facet));
        }
    }
    found
}

/// Groups the polygons (by index) into merged facets.
fn merge_coplanar(pts: &[Point], polys: &[(usize, Vec<u32>)]) -> Vec<Vec<usize>> {
    let mut dsu = Dsu((0..polys.len()).collect());
    let mut first_of_facet: FxHashMap<usize, usize> = FxHashMap::default();
    let mut users: FxHashMap<(u32, u32), Vec<usize>> = FxHashMap::default();
    for (i, (fi, ring)) in polys.iter().enumerate() {
        let j = *first_of_facet.entry(*fi).or_insert(i);
        dsu.union(i, j);
        let n = ring.len();
        let edges = match n {
            0 | 1 => 0,
            2 => 1,
            _ => n,
        };
        for k in 0..edges {
            let (a, b) = (ring[k], ring[(k + 1) % n]);
            if a != b {
                users.entry((a.min(b), a.max(b))).or_default().push(i);
            }
        }
    }
    let unit = |i: usize| {
        let r = &polys[i].1;
        if r.len() < 3 {
            return None;
        }
        let n = newell_normal(pts, r);
        let l = norm(&n);
        (l > 0.0).then(|| n.map(|x| x / l))
    };
    let cos_tol = MERGE_DEGREES.to_radians().cos();
    let mut edges: Vec<_> = users.into_iter().collect();
    edges.sort_unstable();
    for (_, us) in edges {
        if let [a, b] = us[..] {
            if let (Some(x), Some(y)) = (unit(a), unit(b)) {
                if dot(&x, &y).abs() >= cos_tol {
                    dsu.union(a, b);
                }
            }
        }
    }
    let mut groups: FxHashMap<usize, Vec<usize>> = FxHashMap::default();
    for i in 0..polys.len() {
        groups.entry(dsu.find(i)).or_default().push(i);
    }
    let mut out: Vec<Vec<usize>> = groups.into_values().collect();
    out.sort_unstable();
    out
}

/// Whether the tet's volume is at most [`FLAT`] times its longest edge cubed.
fn is_flat(p: &[Point; 4]) -> bool {
    let l2 = longest_edge2(p);
    orient3d(&p[0], &p[1], &p[2], &p[3]).abs() / 6.0 <= FLAT * l2 * l2.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plc::Facet;

    /// Two triangles (0, 1, 2) and (1, 3, 2) of the unit square, point 3 raised by `h`.
    fn two_triangles(h: f64, more: &[Point]) -> (Plc, MeshOut) {
        let mut points = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, h],
        ];
        let plc = Plc {
            points: points.clone(),
            facets: [[0, 1, 2], [1, 3, 2]]
                .iter()
                .map(|t| Facet {
                    polygons: vec![t.to_vec()],
                    ..Default::default()
                })
                .collect(),
            ..Default::default()
        };
        points.extend_from_slice(more);
        let mesh = MeshOut {
            points,
            plc_mode: true,
            ..Default::default()
        };
        (plc, mesh)
    }

    fn found(plc: &Plc, mesh: &MeshOut) -> Vec<(usize, usize)> {
        let rep: Vec<u32> = (0..plc.points.len() as u32).collect();
        shims(plc, mesh, &rep)
    }

    #[test]
    fn a_flat_tet_on_coplanar_neighbours_is_a_shim() {
        // 0.08 degrees apart: merged, so the four corners lie on one facet.
        let (plc, mut mesh) = two_triangles(1e-3, &[]);
        mesh.tets = vec![[0, 1, 2, 3]];
        assert_eq!(found(&plc, &mesh), vec![(0, 0)]);
    }

    #[test]
    fn a_flat_tet_across_a_crease_is_not() {
        // 0.4 degrees apart: two facets, and no one of them holds all four corners.
        let (plc, mut mesh) = two_triangles(5e-3, &[]);
        mesh.tets = vec![[0, 1, 2, 3]];
        assert!(found(&plc, &mesh).is_empty());
    }

    #[test]
    fn a_steiner_point_counts_on_a_facet_only_inside_its_slab() {
        // The merged facet's slab is four times its own deviation from flat thick.
        let (plc, mut mesh) = two_triangles(1e-3, &[[0.5, 0.5, 4e-4], [0.5, 0.5, 2e-2]]);
        mesh.tets = vec![[0, 1, 3, 4], [0, 1, 3, 5]];
        assert_eq!(found(&plc, &mesh), vec![(0, 0)]);
    }

    #[test]
    fn a_thick_tet_on_a_facet_is_not() {
        let (plc, mut mesh) = two_triangles(1e-3, &[[0.3, 0.3, 4e-4]]);
        // Point 4 is on the facet, but the tet of 0, 1, 2 and a point well off it is
        // neither flat nor on it; one of 0, 1, 2 and 4 is both.
        mesh.points.push([0.3, 0.3, 0.5]);
        mesh.tets = vec![[0, 1, 2, 5], [0, 1, 2, 4]];
        assert_eq!(found(&plc, &mesh), vec![(1, 0)]);
    }
}
