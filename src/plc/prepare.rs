//! PLC preparation: merging of exactly duplicate points, cleanup of the polygons, grouping
//! of polygons into (merged) facets and extraction of the segments (constraint edges).
//!
//! The rules follow `merge_coplanar` of the independent validator
//! (`/work/shared/tools/validate_mesh.py`):
//!
//! * Exactly duplicate points map to the lowest-indexed one; polygons are rewritten with
//!   these representatives and repeated consecutive vertices (also across the wrap) are
//!   dropped.
//! * All polygons of one input facet form one group. With `merge` (TetGen's default; `-M`
//!   turns it off), two polygons that are the only two users of an edge and whose Newell
//!   normals satisfy `|n1·n2| >= cos(0.1°)` and that lie on opposite sides of their
//!   common edge (bent, not folded onto each other) are merged too (TetGen's 179.9°
//!   tolerance on dihedral angles).
//! * Every polygon edge is a segment, except an edge used by exactly two polygons that are
//!   both rings (3 or more vertices) of the same group.

use crate::error::InputError;
use crate::geom::facet2d::triangulate_facet;
use crate::geom::norm;
use crate::geom::polygon::representatives;
pub(crate) use crate::geom::polygon::{all_collinear, dedup_ring, newell_normal};
use crate::geom::polygon::{Projection, RingSide};
use crate::plc::Plc;
use rustc_hash::{FxHashMap, FxHashSet};

/// The error type of [`prepare`]: an invalid PLC (exit code 3).
pub type PrepError = InputError;

/// Angle (degrees) under which two edge-adjacent polygons count as coplanar.
pub const MERGE_ANGLE_DEG: f64 = 0.1;

/// A PLC ready for meshing.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PreparedPlc {
    /// For each input point, its representative: the lowest-indexed point with exactly equal coordinates.
    pub rep: Vec<u32>,
    /// Pairs (duplicate, kept) for the warnings.
    pub duplicates: Vec<(u32, u32)>,
    /// Segments (constraint edges) as (a, b) representative input indices with a < b, deduplicated, sorted.
    pub segments: Vec<[u32; 2]>,
    /// Merged facets.
    pub facets: Vec<MergedFacet>,
    /// Input points referenced by no polygon (still meshed as vertices, like TetGen).
    /// Only representatives are listed.
    pub loose_points: Vec<u32>,
}

/// A group of polygons meshed together as one planar facet.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MergedFacet {
    /// Polygon rings with >= 3 distinct vertices (representatives, consecutive repeats dropped).
    pub rings: Vec<Vec<u32>>,
    /// 2-vertex polygons (segments floating in the facet), each as `[min, max]`.
    pub inner_segments: Vec<[u32; 2]>,
    /// 1-vertex polygons (isolated vertices).
    pub isolated: Vec<u32>,
    /// Hole points of the merged input facets.
    pub holes: Vec<[f64; 3]>,
    /// Boundary marker (of the first input facet in the group).
    pub marker: i32,
    /// Indices of the input facets merged into this one (0-based, increasing).
    pub source_facets: Vec<usize>,
    /// A unit normal (Newell's method on the largest ring) for projection; zero when the
    /// group has no ring (only segments and isolated vertices: nothing to triangulate).
    pub normal: [f64; 3],
}

/// One cleaned-up input polygon.
struct Poly {
    verts: Vec<u32>,
    facet: usize,
}

/// Whether two polygons (rings `ra`, `rb` with unit normals `na`, `nb`) that share edge
/// `e` lie on opposite sides of it, as a facet bent by a small angle does (a dihedral
/// angle near 180°), rather than folded onto each other (near 0°): TetGen merges only
/// the first. Each ring's interior lies to the left of its edges seen from its normal,
/// along `n × d` for the edge's direction `d` in that ring.
fn opposite_sides(
    pts: &[[f64; 3]],
    ra: &[u32],
    na: [f64; 3],
    rb: &[u32],
    nb: [f64; 3],
    e: (u32, u32),
) -> bool {
    let inward = |ring: &[u32], n: [f64; 3]| -> Option<[f64; 3]> {
        let m = ring.len();
        let k = (0..m).find(|&k| {
            let (x, y) = (ring[k], ring[(k + 1) % m]);
            (x.min(y), x.max(y)) == e
        })?;
        let (p, q) = (pts[ring[k] as usize], pts[ring[(k + 1) % m] as usize]);
        Some(crate::geom::cross(&n, &crate::geom::sub(&q, &p)))
    };
    match (inward(ra, na), inward(rb, nb)) {
        (Some(ua), Some(ub)) => crate::geom::dot(&ua, &ub) < 0.0,
        _ => true,
    }
}

/// Union-find with path halving.
pub(crate) struct Dsu(pub(crate) Vec<usize>);

/// One use of an edge (sorted vertex pair) by a polygon (its index).
type EdgeUse = ((u32, u32), u32);

impl Dsu {
    pub(crate) fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }
    pub(crate) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            // Keep the lower index as the root: deterministic and order-friendly.
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi] = lo;
        }
    }
}

/// The input facets of the merged groups of `prep` (prepared from `plc`) that cannot be
/// triangulated in one plane: their polygons, bent, overlap in its projection or cross
/// their segments there. They are to be kept apart ([`prepare_except`]).
pub fn unflat_groups(plc: &Plc, prep: &PreparedPlc) -> Vec<usize> {
    let groups: Vec<&MergedFacet> = prep
        .facets
        .iter()
        .filter(|f| f.source_facets.len() > 1 && !f.rings.is_empty())
        .collect();
    if groups.is_empty() {
        return Vec::new();
    }
    let segments: FxHashSet<[u32; 2]> = prep.segments.iter().copied().collect();
    // Input indices are the perturbation indices, as in meshing.
    let pert: Vec<u32> = (0..plc.points.len() as u32).collect();
    let mut out = Vec::new();
    for f in groups {
        let mut verts: Vec<u32> = f.isolated.clone();
        let mut constraints: Vec<[u32; 2]> = f.inner_segments.clone();
        for ring in &f.rings {
            for k in 0..ring.len() {
                let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                verts.push(a);
                let e = [a.min(b), a.max(b)];
                if segments.contains(&e) {
                    constraints.push(e);
                }
            }
        }
        verts.extend(f.inner_segments.iter().flatten());
        verts.sort_unstable();
        verts.dedup();
        let tris = triangulate_facet(&plc.points, &pert, &verts, &constraints, &f.holes, f.normal);
        if tris.is_err() {
            out.extend(&f.source_facets);
        }
    }
    out
}

/// Prepares a PLC for meshing: duplicate points, cleaned polygons, merged facets, segments.
pub fn prepare(plc: &Plc, merge: bool) -> Result<PreparedPlc, PrepError> {
    prepare_except(plc, merge, &[])
}

/// Like [`prepare`], but the input facets listed in `keep_apart` (sorted) are never merged
/// with their neighbours: the fallback for a merged group that is too far from flat to be
/// triangulated in one plane.
pub fn prepare_except(
    plc: &Plc,
    merge: bool,
    keep_apart: &[usize],
) -> Result<PreparedPlc, PrepError> {
    let pts = &plc.points;
    let n = pts.len();
    let invalid = |msg: String| InputError::Invalid {
        file: plc.source.clone(),
        msg,
    };
    let where_ = |fi: usize, pi: usize| {
        let f = &plc.facets[fi];
        let line = if f.line > 0 {
            format!(" (line {})", f.line)
        } else {
            String::new()
        };
        format!("facet {}{line}, polygon {}", fi + plc.first_index, pi + 1)
    };

    // Representatives of exactly equal points.
    let rep = representatives(pts);
    let duplicates: Vec<(u32, u32)> = rep
        .iter()
        .enumerate()
        .filter(|&(i, &r)| r != i as u32)
        .map(|(i, &r)| (i as u32, r))
        .collect();

    // Cleaned polygons, in input order.
    let mut polys: Vec<Poly> = Vec::new();
    for (fi, f) in plc.facets.iter().enumerate() {
        for (pi, poly) in f.polygons.iter().enumerate() {
            let mut mapped = Vec::with_capacity(poly.len());
            for &v in poly {
                if v as usize >= n {
                    return Err(invalid(format!(
                        "{}: vertex {} is out of range ({} points)",
                        where_(fi, pi),
                        v as usize + plc.first_index,
                        n
                    )));
                }
                mapped.push(rep[v as usize]);
            }
            let verts = dedup_ring(&mapped);
            if verts.is_empty() {
                continue;
            }
            if verts.len() >= 3 && all_collinear(pts, &verts) {
                return Err(invalid(format!(
                    "{}: its {} vertices are collinear",
                    where_(fi, pi),
                    poly.len()
                )));
            }
            polys.push(Poly { verts, facet: fi });
        }
    }

    // Groups: the polygons of one facet, plus coplanar edge-adjacent polygons.
    let mut dsu = Dsu((0..polys.len()).collect());
    {
        let mut first_of_facet: FxHashMap<usize, usize> = FxHashMap::default();
        for (i, p) in polys.iter().enumerate() {
            let j = *first_of_facet.entry(p.facet).or_insert(i);
            dsu.union(i, j);
        }
    }
    // Edge users, one entry per occurrence, sorted by edge then polygon: runs of one
    // edge (sorting beats a map of lists: no allocation per edge).
    let mut occurrences: Vec<EdgeUse> = Vec::new();
    for (i, p) in polys.iter().enumerate() {
        let v = &p.verts;
        let mut add = |a: u32, b: u32| occurrences.push(((a.min(b), a.max(b)), i as u32));
        match v.len() {
            1 => {}
            2 => add(v[0], v[1]),
            m => {
                for k in 0..m {
                    add(v[k], v[(k + 1) % m]);
                }
            }
        }
    }
    occurrences.sort_unstable();
    let edges: Vec<((u32, u32), &[EdgeUse])> = occurrences
        .chunk_by(|x, y| x.0 == y.0)
        .map(|run| (run[0].0, run))
        .collect();
    let unit: Vec<Option<[f64; 3]>> = polys
        .iter()
        .map(|p| {
            if p.verts.len() < 3 {
                return None;
            }
            let nn = newell_normal(pts, &p.verts);
            let l = norm(&nn);
            (l > 0.0).then(|| nn.map(|x| x / l))
        })
        .collect();
    if merge {
        let cos_tol = MERGE_ANGLE_DEG.to_radians().cos();
        for (e, us) in &edges {
            if us.len() != 2 {
                continue;
            }
            let (a, b) = (us[0].1 as usize, us[1].1 as usize);
            let apart = |i: usize| keep_apart.binary_search(&polys[i].facet).is_ok();
            if apart(a) || apart(b) {
                continue;
            }
            // Facets with different markers stay apart, as in TetGen: their common edges
            // stay segments, and each keeps its marker.
            let marker = |i: usize| plc.facets[polys[i].facet].marker;
            if marker(a) != marker(b) {
                continue;
            }
            if let (Some(n1), Some(n2)) = (unit[a], unit[b]) {
                let d = n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2];
                if d.abs() >= cos_tol
                    && opposite_sides(pts, &polys[a].verts, n1, &polys[b].verts, n2, *e)
                {
                    dsu.union(a, b);
                }
            }
        }
    }

    // Segments.
    let mut segments: Vec<[u32; 2]> = Vec::new();
    for (k, us) in &edges {
        let interior = us.len() == 2
            && polys[us[0].1 as usize].verts.len() > 2
            && polys[us[1].1 as usize].verts.len() > 2
            && dsu.find(us[0].1 as usize) == dsu.find(us[1].1 as usize);
        if !interior {
            segments.push([k.0, k.1]);
        }
    }
    segments.sort_unstable();
    segments.dedup();

    // Merged facets, in order of their first polygon (hence of their first source facet,
    // since roots are the lowest polygon index of each group).
    let mut group_of_root: FxHashMap<usize, usize> = FxHashMap::default();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for i in 0..polys.len() {
        let r = dsu.find(i);
        let g = *group_of_root.entry(r).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(i);
    }
    let mut facets = Vec::with_capacity(groups.len());
    for g in &groups {
        let mut mf = MergedFacet::default();
        let mut best = 0.0f64;
        let mut seen_iso: FxHashSet<u32> = FxHashSet::default();
        let mut seen_seg: FxHashSet<[u32; 2]> = FxHashSet::default();
        for &i in g {
            let p = &polys[i];
            // Polygons come in input order, so source facets arrive sorted.
            if mf.source_facets.last() != Some(&p.facet) {
                mf.source_facets.push(p.facet);
            }
            match p.verts.len() {
                1 => {
                    if seen_iso.insert(p.verts[0]) {
                        mf.isolated.push(p.verts[0]);
                    }
                }
                2 => {
                    let s = [p.verts[0].min(p.verts[1]), p.verts[0].max(p.verts[1])];
                    if seen_seg.insert(s) {
                        mf.inner_segments.push(s);
                    }
                }
                _ => {
                    let nn = newell_normal(pts, &p.verts);
                    let l = norm(&nn);
                    if l > best {
                        best = l;
                        mf.normal = nn.map(|x| x / l);
                    }
                    mf.rings.push(p.verts.clone());
                }
            }
        }
        mf.source_facets.sort_unstable();
        mf.marker = plc.facets[mf.source_facets[0]].marker;
        mf.holes = open_holes(plc, &polys, g, mf.normal);
        facets.push(mf);
    }
    facets.sort_by_key(|f| f.source_facets[0]);

    // Loose points: representatives that no polygon uses.
    let mut used = vec![false; n];
    for p in &polys {
        for &v in &p.verts {
            used[v as usize] = true;
        }
    }
    let loose_points = (0..n as u32)
        .filter(|&i| rep[i as usize] == i && !used[i as usize])
        .collect();

    Ok(PreparedPlc {
        rep,
        duplicates,
        segments,
        facets,
        loose_points,
    })
}

/// The hole points of the merged group `group` (polygon indices into `polys`, normal
/// `normal`) that stay holes: a hole point of one input facet that lies inside a polygon
/// of another facet of the group marks a window that the other facet fills (a wall with
/// a window given its own facet), so it removes nothing from the merged facet.
fn open_holes(plc: &Plc, polys: &[Poly], group: &[usize], normal: [f64; 3]) -> Vec<[f64; 3]> {
    let mut sources: Vec<usize> = group.iter().map(|&i| polys[i].facet).collect();
    sources.sort_unstable();
    sources.dedup();
    let proj = Projection::along(&normal);
    let mut holes = Vec::new();
    for &fi in &sources {
        for h in &plc.facets[fi].holes {
            let filled = group.iter().any(|&i| {
                polys[i].facet != fi
                    && polys[i].verts.len() >= 3
                    && proj.locate_in_ring(&plc.points, &polys[i].verts, h) == RingSide::Inside
            });
            if !filled {
                holes.push(*h);
            }
        }
    }
    holes
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plc::Facet;

    fn facet(polys: Vec<Vec<u32>>, marker: i32) -> Facet {
        Facet {
            polygons: polys,
            holes: vec![],
            marker,
            line: 0,
        }
    }

    fn cube_points() -> Vec<[f64; 3]> {
        (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect()
    }

    fn cube() -> Plc {
        let faces = vec![
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        Plc {
            points: cube_points(),
            facets: faces
                .into_iter()
                .enumerate()
                .map(|(i, f)| facet(vec![f], i as i32 + 1))
                .collect(),
            first_index: 1,
            ..Default::default()
        }
    }

    #[test]
    fn cube_has_six_facets_and_twelve_segments() {
        for merge in [true, false] {
            let p = prepare(&cube(), merge).unwrap();
            assert_eq!(p.facets.len(), 6);
            assert_eq!(p.segments.len(), 12);
            assert!(p.segments.windows(2).all(|w| w[0] < w[1]));
            assert!(p.segments.iter().all(|s| s[0] < s[1]));
            assert!(p.duplicates.is_empty());
            assert!(p.loose_points.is_empty());
            assert_eq!(p.rep, (0..8).collect::<Vec<u32>>());
            for (i, f) in p.facets.iter().enumerate() {
                assert_eq!(f.source_facets, vec![i]);
                assert_eq!(f.marker, i as i32 + 1);
                assert_eq!(f.rings.len(), 1);
                let l = norm(&f.normal);
                assert!((l - 1.0).abs() < 1e-12);
            }
            // Bottom face 0,2,3,1 is clockwise seen from +z: normal points down.
            assert!(p.facets[0].normal[2] < -0.99);
        }
    }

    /// A cube whose top is split into two coplanar quads by the edge 4–6 ... 5–7 midline.
    fn split_top_cube() -> Plc {
        let mut pts = cube_points();
        pts.push([0.5, 0.0, 1.0]); // 8
        pts.push([0.5, 1.0, 1.0]); // 9
        let faces = vec![
            vec![vec![0, 2, 3, 1]],
            vec![vec![4, 8, 9, 6]],
            vec![vec![8, 5, 7, 9]],
            vec![vec![0, 1, 5, 8, 4]],
            vec![vec![2, 6, 9, 7, 3]],
            vec![vec![0, 4, 6, 2]],
            vec![vec![1, 3, 7, 5]],
        ];
        Plc {
            points: pts,
            facets: faces
                .into_iter()
                .enumerate()
                // The two top quads share marker 2.
                .map(|(i, f)| facet(f, if i == 2 { 2 } else { i as i32 + 1 }))
                .collect(),
            ..Default::default()
        }
    }

    #[test]
    fn coplanar_neighbours_with_different_markers_stay_apart() {
        let mut plc = split_top_cube();
        plc.facets[2].marker = 7;
        let p = prepare(&plc, true).unwrap();
        assert_eq!(p.facets.len(), 7);
        assert!(p.segments.contains(&[8, 9]));
        assert_eq!(p.facets[1].marker, 2);
        assert_eq!(p.facets[2].marker, 7);
    }

    #[test]
    fn coplanar_neighbours_merge() {
        let plc = split_top_cube();
        let p = prepare(&plc, true).unwrap();
        // Top quads merge; the front and back pentagons are separate facets.
        assert_eq!(p.facets.len(), 6);
        // Edges: 12 cube edges split at 8 and 9 → 14 pieces; 8–9 is not a segment.
        // Counting input edges: 12 cube edges with 4–5 and 6–7 each split in two = 14.
        let has = |a: u32, b: u32| p.segments.contains(&[a.min(b), a.max(b)]);
        assert!(!has(8, 9));
        assert_eq!(p.segments.len(), 14);
        let top = &p.facets[1];
        assert_eq!(top.source_facets, vec![1, 2]);
        assert_eq!(top.rings.len(), 2);
        assert_eq!(top.marker, 2);
        assert!(top.normal[2] > 0.99);

        let q = prepare(&plc, false).unwrap();
        assert_eq!(q.facets.len(), 7);
        assert_eq!(q.segments.len(), 15);
        assert!(q.segments.contains(&[8, 9]));
    }

    /// The brief's case: the cube top split into two quads with the split edge's endpoints
    /// on the cube's vertical edges, so the cube keeps 12 segments when merged.
    #[test]
    fn split_top_gives_twelve_or_thirteen_segments() {
        let pts = cube_points();
        // Top quads 4,5,7,6 split along the diagonal-free way: use two rings sharing 4–7?
        // A quad split into two quads needs extra points; split into triangles instead.
        let faces = vec![
            vec![vec![0, 2, 3, 1]],
            vec![vec![4, 5, 7]],
            vec![vec![4, 7, 6]],
            vec![vec![0, 1, 5, 4]],
            vec![vec![2, 6, 7, 3]],
            vec![vec![0, 4, 6, 2]],
            vec![vec![1, 3, 7, 5]],
        ];
        let plc = Plc {
            points: pts,
            facets: faces.into_iter().map(|f| facet(f, 0)).collect(),
            ..Default::default()
        };
        let p = prepare(&plc, true).unwrap();
        assert_eq!(p.facets.len(), 6);
        assert_eq!(p.segments.len(), 12);
        let q = prepare(&plc, false).unwrap();
        assert_eq!(q.facets.len(), 7);
        assert_eq!(q.segments.len(), 13);
        assert!(q.segments.contains(&[4, 7]));
    }

    /// Two triangles sharing edge 0–1 with a dihedral angle of 180° − `dev` degrees.
    fn hinge(dev_deg: f64) -> Plc {
        let t = dev_deg.to_radians();
        let pts = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.5, -t.cos(), t.sin()],
        ];
        Plc {
            points: pts,
            facets: vec![facet(vec![vec![0, 1, 2]], 5), facet(vec![vec![1, 0, 3]], 5)],
            ..Default::default()
        }
    }

    #[test]
    fn merge_angle_tolerance() {
        let p = prepare(&hinge(0.05), true).unwrap();
        assert_eq!(p.facets.len(), 1);
        assert_eq!(p.facets[0].source_facets, vec![0, 1]);
        assert_eq!(p.facets[0].marker, 5);
        assert_eq!(p.segments.len(), 4);
        assert!(!p.segments.contains(&[0, 1]));

        let p = prepare(&hinge(0.5), true).unwrap();
        assert_eq!(p.facets.len(), 2);
        assert_eq!(p.segments.len(), 5);

        let p = prepare(&hinge(0.05), false).unwrap();
        assert_eq!(p.facets.len(), 2);
        assert_eq!(p.segments.len(), 5);
    }

    /// Two triangles sharing edge 0–1 at a dihedral angle of `deg` degrees (folded).
    fn fold(deg: f64) -> Plc {
        let t = deg.to_radians();
        let mut plc = hinge(0.0);
        plc.points[3] = [0.5, t.cos(), t.sin()];
        plc
    }

    #[test]
    fn folded_polygons_stay_apart_however_close() {
        for deg in [0.05, 0.001] {
            let p = prepare(&fold(deg), true).unwrap();
            assert_eq!(p.facets.len(), 2, "{deg}°");
            assert!(p.segments.contains(&[0, 1]));
        }
    }

    #[test]
    fn edge_with_three_users_stays_a_segment() {
        let mut plc = hinge(0.0);
        plc.points.push([0.5, 0.0, 1.0]);
        plc.facets.push(facet(vec![vec![0, 1, 4]], 7));
        let p = prepare(&plc, true).unwrap();
        assert_eq!(p.facets.len(), 3);
        assert!(p.segments.contains(&[0, 1]));
    }

    #[test]
    fn duplicates_map_to_lowest_index() {
        let mut plc = cube();
        // Points 8 and 9 duplicate 3 and 0; -0.0 equals 0.0.
        plc.points.push([1.0, 1.0, 0.0]);
        plc.points.push([-0.0, 0.0, -0.0]);
        plc.points.push([5.0, 5.0, 5.0]); // loose
        plc.facets[0].polygons[0] = vec![9, 2, 8, 3, 1];
        let p = prepare(&plc, true).unwrap();
        assert_eq!(p.rep[8], 3);
        assert_eq!(p.rep[9], 0);
        assert_eq!(p.duplicates, vec![(8, 3), (9, 0)]);
        // 8,3 became 3,3 and collapsed.
        assert_eq!(p.facets[0].rings, vec![vec![0, 2, 3, 1]]);
        assert_eq!(p.segments.len(), 12);
        assert_eq!(p.loose_points, vec![10]);
    }

    #[test]
    fn inner_segment_and_isolated_vertex() {
        let pts = vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 4.0, 0.0],
            [0.0, 4.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [3.0, 3.0, 0.0],
        ];
        let mut f = facet(vec![vec![0, 1, 2, 3], vec![5, 4], vec![6], vec![6, 6]], 2);
        f.holes = vec![[9.0, 9.0, 0.0]];
        let plc = Plc {
            points: pts,
            facets: vec![f],
            ..Default::default()
        };
        let p = prepare(&plc, true).unwrap();
        assert_eq!(p.facets.len(), 1);
        let mf = &p.facets[0];
        assert_eq!(mf.rings, vec![vec![0, 1, 2, 3]]);
        assert_eq!(mf.inner_segments, vec![[4, 5]]);
        assert_eq!(mf.isolated, vec![6]);
        assert_eq!(mf.holes, vec![[9.0, 9.0, 0.0]]);
        assert_eq!(mf.normal, [0.0, 0.0, 1.0]);
        assert_eq!(p.segments, vec![[0, 1], [0, 3], [1, 2], [2, 3], [4, 5]]);
        assert!(p.loose_points.is_empty());
    }

    #[test]
    fn degenerate_ring_becomes_segment() {
        let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let plc = Plc {
            points: pts,
            facets: vec![facet(vec![vec![0, 1, 2]], 0)],
            ..Default::default()
        };
        let p = prepare(&plc, true).unwrap();
        assert_eq!(p.facets[0].rings.len(), 0);
        assert_eq!(p.facets[0].inner_segments, vec![[0, 1]]);
        assert_eq!(p.facets[0].normal, [0.0; 3]);
        assert_eq!(p.segments, vec![[0, 1]]);
    }

    #[test]
    fn collinear_ring_is_an_error() {
        let pts = vec![
            [0.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
            [2.0, 2.0, 2.0],
            [0.0, 1.0, 0.0],
        ];
        let mut f = facet(vec![vec![0, 1, 3]], 0);
        let mut g = facet(vec![vec![0, 1, 2]], 0);
        g.line = 17;
        f.line = 16;
        let plc = Plc {
            points: pts,
            facets: vec![f, g],
            first_index: 1,
            source: "m.poly".into(),
            ..Default::default()
        };
        let e = prepare(&plc, true).unwrap_err();
        let msg = e.to_string();
        assert!(matches!(e, InputError::Invalid { .. }));
        assert!(msg.contains("facet 2 (line 17), polygon 1"), "{msg}");
        assert!(msg.contains("collinear"), "{msg}");
        assert!(msg.starts_with("m.poly"), "{msg}");
        let err: crate::Error = e.into();
        assert_eq!(err.exit_code(), crate::error::EXIT_INVALID_INPUT);
    }

    #[test]
    fn out_of_range_vertex_is_an_error() {
        let mut plc = cube();
        plc.facets[2].polygons[0][1] = 99;
        let e = prepare(&plc, true).unwrap_err().to_string();
        assert!(
            e.contains("facet 3, polygon 1: vertex 100 is out of range"),
            "{e}"
        );
    }

    /// A 150 × 150 grid of squares, each split into two triangles given as separate
    /// facets (like an OFF file): merged into one facet with only the border as segments.
    #[test]
    fn triangle_soup_merges_quickly() {
        let k = 150u32;
        let mut plc = Plc::default();
        for j in 0..=k {
            for i in 0..=k {
                plc.points.push([i as f64, j as f64, 3.0]);
            }
        }
        let id = |i: u32, j: u32| j * (k + 1) + i;
        for j in 0..k {
            for i in 0..k {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                plc.facets.push(facet(vec![vec![a, b, c]], 1));
                plc.facets.push(facet(vec![vec![a, c, d]], 1));
            }
        }
        let t0 = std::time::Instant::now();
        let p = prepare(&plc, true).unwrap();
        assert_eq!(p.facets.len(), 1);
        assert_eq!(p.facets[0].rings.len(), (2 * k * k) as usize);
        assert_eq!(p.facets[0].source_facets.len(), (2 * k * k) as usize);
        assert_eq!(p.segments.len(), (4 * k) as usize);
        let q = prepare(&plc, false).unwrap();
        assert_eq!(q.facets.len(), (2 * k * k) as usize);
        assert_eq!(q.segments.len(), (3 * k * k + 2 * k) as usize);
        assert!(t0.elapsed().as_secs_f64() < 10.0);
    }

    /// `mpi.off` merges facets 27, 48 and 49 (0-based), bent by under 0.1°, whose
    /// polygons overlap in their common plane: the group is found before meshing; the
    /// flat faces of a box of 3x3 quads each merge into a group that is none.
    #[test]
    fn groups_that_cannot_be_triangulated_in_one_plane_are_found() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/plc/mpi.off");
        let plc = crate::io::read_plc(&path).unwrap();
        let prep = prepare(&plc, true).unwrap();
        assert_eq!(unflat_groups(&plc, &prep), vec![27, 48, 49]);
        let apart = prepare_except(&plc, true, &[27, 48, 49]).unwrap();
        assert!(unflat_groups(&plc, &apart).is_empty());
        let path = path.with_file_name("gridbox_3.smesh");
        let grid = crate::io::read_plc(&path).unwrap();
        let prep = prepare(&grid, true).unwrap();
        assert!(prep.facets.iter().all(|f| f.source_facets.len() == 9));
        assert!(unflat_groups(&grid, &prep).is_empty());
    }
}
