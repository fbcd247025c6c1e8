//! The constraints of a PLC in a mesh, found from the geometry alone: which mesh nodes lie
//! on which facet, the segments as chains of mesh edges, the faces that lie on each facet
//! and whether they cover it exactly once, and shim tets.
//!
//! * A node lies on a (merged) facet when it is a vertex of one of its polygons, a node
//!   of the chain of one of its segments, or, for another Steiner point, when it lies
//!   within the facet's slab (four times the facet's own deviation from its plane, at
//!   least 1e-10 of the model's size, as the shared referee measures it) and inside or on
//!   the facet in its projection along its normal's largest component; where several
//!   facets' slabs hold it, on the one whose plane is nearest.
//! * A face is a candidate for a facet when its three nodes lie on it and its projected
//!   centroid lies in it. The faces on the facet are the surface of candidates spanning
//!   its boundary: from each piece of the boundary, the candidate on its inner side, then
//!   across each edge of a face taken, the candidate beyond it; where several candidates
//!   lie on one side of an edge (faces of tets rising from the facet, with nodes inside
//!   its slab near its boundary), the one nearest to the facet's plane.
//! * They cover the facet exactly once when, in the projection, each of their edges has
//!   one of them on each side or is a piece of the boundary with the facet on the face's
//!   side, and every piece of the boundary is such an edge: their boundary is then the
//!   facet's, so every point of the facet is covered by exactly one face (the winding
//!   number of that boundary).

use super::{name, Problems};
use crate::geom::bvh::{Aabb, Bvh};
use crate::geom::polygon::{Projection, RingSide};
use crate::geom::{cross, diagonal, dot, longest_edge2, norm, orient3d, sub, Point};
use crate::plc::prepare::{MergedFacet, PreparedPlc};
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// A tet is flat when its volume is at most this fraction of its longest edge cubed (the
/// shared referee's measure of a shim).
const FLAT: f64 = 1e-3;

/// Steiner points on a segment lie within this fraction of the model's size of its line
/// (they are rounded to the nearest doubles; the shared referee's tolerance).
const ON_SEGMENT: f64 = 1e-9;

/// The slab of a facet is at least this fraction of the model's size thick (exactly flat
/// facets have Steiner points rounded off their plane).
const MIN_SLAB: f64 = 1e-10;

/// Facets with more rings than this find the rings around a point through a hierarchy of
/// their boxes; smaller ones test every ring.
const RING_BVH: usize = 8;

/// One merged facet as the certifier sees it.
pub(super) struct Facet<'a> {
    pub src: &'a MergedFacet,
    proj: Projection,
    slab: Slab,
    /// The rings as mesh nodes, whether each bounds a hole, whether each turns
    /// counterclockwise in the projection, and their projected boxes.
    rings: Vec<Vec<u32>>,
    hole: Vec<bool>,
    ccw: Vec<bool>,
    ring_boxes: Vec<Aabb>,
    ring_bvh: Option<Bvh>,
}

impl Facet<'_> {
    /// Where `q` lies relative to the facet in its projection: inside one of its rings
    /// that bounds no hole and not inside a hole, or on an edge, or outside.
    fn locate(&self, points: &[Point], q: &Point) -> RingSide {
        let (mut inside, mut in_hole, mut boundary) = (false, false, false);
        let mut test = |k: usize| match self.proj.locate_in_ring(points, &self.rings[k], q) {
            RingSide::Boundary => boundary = true,
            RingSide::Inside if self.hole[k] => in_hole = true,
            RingSide::Inside => inside = true,
            RingSide::Outside => {}
        };
        match &self.ring_bvh {
            Some(bvh) => bvh.query(&self.ring_boxes, &[*q, *q], test),
            None => {
                for (k, b) in self.ring_boxes.iter().enumerate() {
                    if (0..3).all(|a| b[0][a] <= q[a] && q[a] <= b[1][a]) {
                        test(k);
                    }
                }
            }
        }
        if boundary {
            RingSide::Boundary
        } else if inside && !in_hole {
            RingSide::Inside
        } else {
            RingSide::Outside
        }
    }

    /// A point strictly inside the facet, on one of its rings: the centroid of the first
    /// triangle of a ring's fan that lies inside the facet in projection.
    pub fn sample(&self, points: &[Point]) -> Option<Point> {
        for (k, r) in self.rings.iter().enumerate() {
            if self.hole[k] {
                continue;
            }
            for i in 1..r.len().saturating_sub(1) {
                let t = [r[0], r[i], r[i + 1]].map(|v| points[v as usize]);
                let c: Point = std::array::from_fn(|a| (t[0][a] + t[1][a] + t[2][a]) / 3.0);
                if self.locate(points, &c) == RingSide::Inside {
                    return Some(c);
                }
            }
        }
        None
    }
}

/// A facet's slab: its plane (through the mean of its vertices), half the slab's
/// thickness, and the box of its vertices grown by that.
#[derive(Clone, Copy)]
struct Slab {
    normal: Point,
    mean: Point,
    tol: f64,
    bbox: Aabb,
}

impl Slab {
    /// The slab of facet `f` (`node` maps its vertices to mesh nodes): empty if some of
    /// them are missing from the mesh (reported apart: nothing lies on it).
    fn of(f: &MergedFacet, node: &[u32], points: &[Point], diag: f64) -> Slab {
        let mut verts: Vec<u32> = f
            .rings
            .iter()
            .flatten()
            .map(|&v| node[v as usize])
            .collect();
        if verts.is_empty() || verts.contains(&u32::MAX) {
            return Slab {
                normal: f.normal,
                mean: [0.0; 3],
                tol: -1.0,
                bbox: [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]],
            };
        }
        verts.sort_unstable();
        verts.dedup();
        let k = verts.len() as f64;
        let mean: Point =
            std::array::from_fn(|a| verts.iter().map(|&v| points[v as usize][a]).sum::<f64>() / k);
        let dev = verts
            .iter()
            .map(|&v| dot(&sub(&points[v as usize], &mean), &f.normal).abs())
            .fold(0.0, f64::max);
        let tol = (MIN_SLAB * diag).max(4.0 * dev);
        Slab {
            normal: f.normal,
            mean,
            tol,
            bbox: slab_box(&verts, points, tol),
        }
    }

    /// The signed distance of `q` from the plane.
    fn height(&self, q: &Point) -> f64 {
        dot(&sub(q, &self.mean), &self.normal)
    }

    /// Whether `q` lies within the slab and its box.
    fn holds(&self, q: &Point) -> bool {
        (0..3).all(|k| q[k] >= self.bbox[0][k] && q[k] <= self.bbox[1][k])
            && self.height(q).abs() <= self.tol
    }
}

/// The constraints found in a mesh.
pub(super) struct Constraints {
    /// For each segment of the prepared PLC, its chain of nodes (empty if it is none).
    pub chains: Vec<Vec<u32>>,
    /// The faces (sorted keys) that lie on facets, with their facet (an index into the
    /// prepared PLC's facets).
    pub subfaces: FxHashMap<[u32; 3], u32>,
    /// For each facet with rings but no faces on it, a point strictly inside it: it must
    /// lie outside the domain.
    pub bare: Vec<(u32, Point)>,
}

/// The node of each input point (found by its coordinates), `u32::MAX` for none.
pub(super) fn nodes_of_inputs(input: &[Point], points: &[Point]) -> Vec<u32> {
    let key = |p: &Point| p.map(|c| (c + 0.0).to_bits());
    let mut at: FxHashMap<[u64; 3], u32> = FxHashMap::default();
    at.reserve(points.len());
    for (i, p) in points.iter().enumerate() {
        at.entry(key(p)).or_insert(i as u32);
    }
    input
        .iter()
        .map(|p| at.get(&key(p)).copied().unwrap_or(u32::MAX))
        .collect()
}

/// Compressed rows: for each of `n` keys, a list of values.
pub(super) struct Rows {
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Rows {
    /// The rows of `pairs` (key, value), values in the order given.
    fn new(n: usize, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Self {
        let mut start = vec![0u32; n + 1];
        for (k, _) in pairs.clone() {
            start[k as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut items = vec![0u32; start[n] as usize];
        for (k, v) in pairs {
            items[fill[k as usize] as usize] = v;
            fill[k as usize] += 1;
        }
        Rows { start, items }
    }

    /// For each node, the tets around it.
    pub fn stars(nodes: usize, tets: &[[u32; 4]]) -> Self {
        let pairs = tets
            .iter()
            .enumerate()
            .flat_map(|(i, t)| t.iter().map(move |&v| (v, i as u32)));
        Rows::new(nodes, pairs)
    }

    pub fn of(&self, k: u32) -> &[u32] {
        &self.items[self.start[k as usize] as usize..self.start[k as usize + 1] as usize]
    }
}

/// Finds the constraints of `prep` in the mesh (`node` maps input points to nodes) and
/// reports what is wrong with them: segments that are no chains of mesh edges, facets
/// not covered exactly once, shim tets.
///
/// Most facets of surface meshes are single triangles with no Steiner point on them:
/// their one face is looked up among the tets around a corner. The others get the whole
/// treatment of the module's documentation, with their geometry made when first needed.
#[allow(clippy::too_many_arguments)]
pub(super) fn find(
    prep: &PreparedPlc,
    node: &[u32],
    points: &[Point],
    tets: &[[u32; 4]],
    stars: &Rows,
    faces: &[[u32; 3]],
    n_inputs: usize,
    pr: &mut Problems,
) -> Constraints {
    let diag = diagonal(points);
    let chains: Vec<Vec<u32>> = prep
        .segments
        .par_iter()
        .map(|&[a, b]| {
            let (u, v) = (node[a as usize], node[b as usize]);
            if u == u32::MAX || v == u32::MAX {
                return Vec::new();
            }
            chain_along(points, tets, stars, u, v, ON_SEGMENT * diag)
        })
        .collect();
    for (&[a, b], chain) in prep.segments.iter().zip(&chains) {
        let (u, v) = (node[a as usize], node[b as usize]);
        if chain.is_empty() && u != u32::MAX && v != u32::MAX {
            pr.push(format!(
                "segment ({}, {}) is not a chain of mesh edges",
                name(pr, u),
                name(pr, v)
            ));
        }
    }
    let mut geo = Geometry {
        prep,
        node,
        points,
        diag,
        facets: (0..prep.facets.len()).map(|_| None).collect(),
    };
    let (on, simple, slab_rows) = nodes_on_facets(&mut geo, &chains, tets, n_inputs);
    let mut subfaces = FxHashMap::default();
    subfaces.reserve(faces.len() / 4);
    let mut has_faces = vec![false; prep.facets.len()];
    // Simple facets: their triangle must be a face of the mesh.
    let simple_faces: Vec<(usize, [u32; 3])> = (0..prep.facets.len())
        .into_par_iter()
        .filter(|&g| simple[g])
        .filter_map(|g| {
            let t = [0, 1, 2].map(|k| node[prep.facets[g].rings[0][k] as usize]);
            let is_face = stars
                .of(t[0])
                .iter()
                .any(|&x| t.iter().all(|v| tets[x as usize].contains(v)));
            is_face.then_some((g, t))
        })
        .collect();
    for (g, t) in simple_faces {
        subfaces.insert(face_key(t), g as u32);
        has_faces[g] = true;
    }
    let cands = candidates(&mut geo, &on, &simple, faces);
    let mut scratch = Scratch::default();
    let mut from = 0;
    while from < cands.len() {
        let g = cands[from].0;
        let to = from + cands[from..].partition_point(|c| c.0 == g);
        let fa = geo.facet(g as usize);
        boundary_pieces(fa, prep, node, &chains, &mut scratch.boundary);
        for f in surface(fa, &cands[from..to], &mut scratch, pr) {
            subfaces.insert(face_key(f), g);
            has_faces[g as usize] = true;
        }
        from = to;
    }
    let mut bare = Vec::new();
    for (g, f) in prep.facets.iter().enumerate() {
        if has_faces[g] || f.rings.is_empty() || norm(&f.normal) == 0.0 {
            continue;
        }
        if let Some(q) = geo.facet(g).sample(points) {
            bare.push((g as u32, q));
        }
    }
    shims(slab_rows.as_ref().unwrap_or(&on), points, tets, prep, pr);
    Constraints {
        chains,
        subfaces,
        bare,
    }
}

/// The facets' geometry, made when first needed.
struct Geometry<'a> {
    prep: &'a PreparedPlc,
    node: &'a [u32],
    points: &'a [Point],
    diag: f64,
    facets: Vec<Option<Facet<'a>>>,
}

impl<'a> Geometry<'a> {
    /// Facet `g` of the prepared PLC (it has rings).
    fn facet(&mut self, g: usize) -> &Facet<'a> {
        let (prep, node, points, diag) = (self.prep, self.node, self.points, self.diag);
        self.facets[g].get_or_insert_with(|| facet_geometry(&prep.facets[g], node, points, diag))
    }
}

/// Tets with all four nodes on one facet that are flat are shims; for this, as the
/// shared referee counts them, a Steiner point lies on every facet whose slab holds it
/// (`on`, from [`nodes_on_facets`]).
fn shims(on: &Rows, points: &[Point], tets: &[[u32; 4]], prep: &PreparedPlc, pr: &mut Problems) {
    let mut common: Vec<u32> = Vec::new();
    for (t, tv) in tets.iter().enumerate() {
        if tv.iter().any(|&v| on.of(v).is_empty()) {
            continue;
        }
        common.clear();
        common.extend_from_slice(on.of(tv[0]));
        for &v in &tv[1..] {
            let here = on.of(v);
            common.retain(|g| here.binary_search(g).is_ok());
        }
        let Some(&g) = common.first() else { continue };
        if is_flat(&tv.map(|v| points[v as usize])) {
            pr.push(format!(
                "tet {} is a shim: flat, with all four nodes on facet {}",
                t + pr.base,
                facet_label(&prep.facets[g as usize], pr)
            ));
        }
    }
}

/// An input facet of a merged facet, to name it.
pub(super) fn facet_label(f: &MergedFacet, pr: &Problems) -> String {
    (f.source_facets[0] + pr.facet_base).to_string()
}

/// The certifier's view of a merged facet with rings.
fn facet_geometry<'a>(f: &'a MergedFacet, node: &[u32], points: &[Point], diag: f64) -> Facet<'a> {
    let rings: Vec<Vec<u32>> = f
        .rings
        .iter()
        .map(|r| r.iter().map(|&v| node[v as usize]).collect())
        .collect();
    let proj = Projection::along(&f.normal);
    let slab = Slab::of(f, node, points, diag);
    if rings.iter().flatten().any(|&v| v == u32::MAX) {
        return Facet {
            src: f,
            proj,
            slab,
            rings: Vec::new(),
            hole: Vec::new(),
            ccw: Vec::new(),
            ring_boxes: Vec::new(),
            ring_bvh: None,
        };
    }
    // Projected boxes: queries ignore the dropped axis.
    let ax = proj.axis();
    let ring_boxes: Vec<Aabb> = rings
        .iter()
        .map(|r| {
            let mut b = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
            for &v in r {
                let p = points[v as usize];
                for a in 0..3 {
                    b[0][a] = b[0][a].min(p[a]);
                    b[1][a] = b[1][a].max(p[a]);
                }
            }
            b[0][ax] = f64::NEG_INFINITY;
            b[1][ax] = f64::INFINITY;
            b
        })
        .collect();
    let hole = crate::geom::polygon::hole_rings(points, &rings, &f.holes, &proj);
    let ccw = rings
        .iter()
        .map(|r| ring_is_ccw(r, &proj, points))
        .collect();
    let ring_bvh = (rings.len() > RING_BVH).then(|| Bvh::build(&ring_boxes));
    Facet {
        src: f,
        proj,
        slab,
        rings,
        hole,
        ccw,
        ring_boxes,
        ring_bvh,
    }
}

/// The box of `verts` grown by `tol`.
fn slab_box(verts: &[u32], points: &[Point], tol: f64) -> Aabb {
    let mut bbox = [[f64::INFINITY; 3], [f64::NEG_INFINITY; 3]];
    for &v in verts {
        let p = points[v as usize];
        for a in 0..3 {
            bbox[0][a] = bbox[0][a].min(p[a] - tol);
            bbox[1][a] = bbox[1][a].max(p[a] + tol);
        }
    }
    bbox
}

/// Whether a ring turns counterclockwise in the projection: the exact orientation at its
/// lowest vertex (then leftmost), a convex corner of any simple polygon.
fn ring_is_ccw(ring: &[u32], proj: &Projection, points: &[Point]) -> bool {
    let n = ring.len();
    let key = |v: u32| {
        let q = proj.project(&points[v as usize]);
        (q[1], q[0])
    };
    let k = (0..n)
        .min_by(|&i, &j| {
            key(ring[i])
                .partial_cmp(&key(ring[j]))
                .unwrap_or(std::cmp::Ordering::Equal)
        })
        .unwrap_or(0);
    let p = |i: usize| &points[ring[i % n] as usize];
    proj.orient(p(k + n - 1), p(k), p(k + 1)) > 0.0
}

/// For each node, the facets it lies on (sorted), and which facets are simple: a single
/// triangle with no Steiner point on it. Input vertices lie on the facets of their
/// polygons, Steiner points on segments on the facets of their segments (rounded, they
/// may fall just off a facet's boundary in projection), and other Steiner points on the
/// facet whose slab and region hold them and whose plane is nearest. The lists leave out
/// simple facets, which need none.
///
/// Also, for the shim test, the facets each node lies on when a Steiner point lies on
/// every facet whose slab and box hold it (the rows then list simple facets too), if
/// they differ from the first rows.
fn nodes_on_facets(
    geo: &mut Geometry,
    chains: &[Vec<u32>],
    tets: &[[u32; 4]],
    n_inputs: usize,
) -> (Rows, Vec<bool>, Option<Rows>) {
    let (prep, node, points) = (geo.prep, geo.node, geo.points);
    let mut is_input = vec![false; points.len()];
    for &v in node.iter().take(n_inputs) {
        if v != u32::MAX {
            is_input[v as usize] = true;
        }
    }
    let mut placed = is_input.clone();
    let mut simple: Vec<bool> = prep
        .facets
        .iter()
        .map(|f| {
            matches!(&f.rings[..], [r] if r.len() == 3)
                && f.holes.is_empty()
                && f.inner_segments.is_empty()
                && f.isolated.is_empty()
                && f.rings[0].iter().all(|&v| node[v as usize] != u32::MAX)
                && norm(&f.normal) > 0.0
        })
        .collect();
    // Steiner points on the facets' segments: the few segments split by some are
    // looked up among every facet's edges.
    let split: FxHashMap<[u32; 2], usize> = prep
        .segments
        .iter()
        .enumerate()
        .filter(|(s, _)| chains[*s].len() > 2)
        .map(|(s, &e)| (e, s))
        .collect();
    let mut on_chain: Vec<(u32, u32)> = Vec::new();
    if !split.is_empty() {
        for (g, f) in prep.facets.iter().enumerate() {
            for_each_edge(f, |e| {
                if let Some(&s) = split.get(&e) {
                    for &x in &chains[s][1..chains[s].len() - 1] {
                        on_chain.push((x, g as u32));
                        placed[x as usize] = true;
                        simple[g] = false;
                    }
                }
            });
        }
    }
    // Other Steiner points.
    let loose: Vec<u32> = (0..points.len() as u32)
        .filter(|&v| !placed[v as usize])
        .collect();
    let mut in_slab: Vec<(u32, u32)> = Vec::new();
    // Every Steiner point with every facet whose slab and box hold it.
    let mut in_slabs: Vec<(u32, u32)> = Vec::new();
    // The slabs that hold Steiner points matter for loose points, and for shims: only
    // where a flat tet has a Steiner point.
    let flat_with_steiner = || {
        tets.par_iter().any(|tv| {
            tv.iter().any(|&v| !is_input[v as usize]) && is_flat(&tv.map(|v| points[v as usize]))
        })
    };
    if !loose.is_empty() || flat_with_steiner() {
        let with_rings: Vec<usize> = (0..prep.facets.len())
            .filter(|&g| !prep.facets[g].rings.is_empty() && norm(&prep.facets[g].normal) > 0.0)
            .collect();
        // The slabs alone: the facets' full geometry is made only for those whose slab
        // holds a loose point.
        let diag = geo.diag;
        let slabs: Vec<Slab> = with_rings
            .iter()
            .map(|&g| Slab::of(&prep.facets[g], node, points, diag))
            .collect();
        let boxes: Vec<Aabb> = slabs.iter().map(|s| s.bbox).collect();
        let bvh = Bvh::build(&boxes);
        let mut near: Vec<usize> = Vec::new();
        for v in (0..points.len() as u32).filter(|&v| !is_input[v as usize]) {
            let p = &points[v as usize];
            near.clear();
            bvh.query(&boxes, &[*p, *p], |i| near.push(i));
            let loose = !placed[v as usize];
            let mut best: Option<(f64, usize)> = None;
            for &i in &near {
                if !slabs[i].holds(p) {
                    continue;
                }
                let g = with_rings[i];
                in_slabs.push((v, g as u32));
                if loose && geo.facet(g).locate(points, p) != RingSide::Outside {
                    let d = slabs[i].height(p).abs();
                    if best.is_none_or(|(b, _)| d < b) {
                        best = Some((d, g));
                    }
                }
            }
            if let Some((_, g)) = best {
                in_slab.push((v, g as u32));
                simple[g] = false;
            }
        }
    }
    debug_assert!(loose.iter().all(|&v| !is_input[v as usize]));
    let mut pairs = on_chain;
    pairs.extend(in_slab);
    for (g, f) in prep.facets.iter().enumerate() {
        if simple[g] {
            continue;
        }
        let inputs = f
            .rings
            .iter()
            .flatten()
            .chain(f.inner_segments.iter().flatten())
            .chain(&f.isolated);
        for &v in inputs {
            let x = node[v as usize];
            if x != u32::MAX {
                pairs.push((x, g as u32));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    // For the shim test: the Steiner points in slabs of facets they are not on, and
    // then every node on those facets. Few or none: such a point lies near nearly
    // coplanar neighbouring facets.
    let mut extra: Vec<(u32, u32)> = in_slabs
        .into_iter()
        .filter(|e| pairs.binary_search(e).is_err())
        .collect();
    let shim_rows = (!extra.is_empty()).then(|| {
        let mut facets: Vec<u32> = extra.iter().map(|&(_, g)| g).collect();
        facets.sort_unstable();
        facets.dedup();
        for &g in &facets {
            let f = &prep.facets[g as usize];
            for &v in f.rings.iter().flatten().chain(&f.isolated) {
                let x = node[v as usize];
                if x != u32::MAX {
                    extra.push((x, g));
                }
            }
        }
        extra.extend(pairs.iter().copied());
        extra.sort_unstable();
        extra.dedup();
        Rows::new(points.len(), extra.into_iter())
    });
    (
        Rows::new(points.len(), pairs.into_iter()),
        simple,
        shim_rows,
    )
}

/// Calls `f` with every edge of the facet's rings and its inner segments, as sorted
/// pairs of input indices.
fn for_each_edge(src: &MergedFacet, mut f: impl FnMut([u32; 2])) {
    for r in &src.rings {
        for k in 0..r.len() {
            let (a, b) = (r[k], r[(k + 1) % r.len()]);
            f([a.min(b), a.max(b)]);
        }
    }
    for &e in &src.inner_segments {
        f(e);
    }
}

/// The chain of mesh edges from node `a` to node `b` through nodes within `tol` of the
/// segment between them (strictly between its ends), or empty if there is none.
fn chain_along(
    points: &[Point],
    tets: &[[u32; 4]],
    stars: &Rows,
    a: u32,
    b: u32,
    tol: f64,
) -> Vec<u32> {
    let (pa, pb) = (points[a as usize], points[b as usize]);
    let d = sub(&pb, &pa);
    let len2 = dot(&d, &d);
    if len2 == 0.0 {
        return Vec::new();
    }
    let on_line = |v: u32| {
        let w = sub(&points[v as usize], &pa);
        let t = dot(&w, &d) / len2;
        let off: Point = std::array::from_fn(|k| w[k] - t * d[k]);
        t > 0.0 && t < 1.0 && norm(&off) <= tol
    };
    // Depth first from `a`, nearest to `b` first: the chain is usually found at once.
    let mut prev: Vec<(u32, u32)> = vec![(a, a)];
    let mut stack = vec![a];
    let mut next: Vec<u32> = Vec::new();
    while let Some(u) = stack.pop() {
        next.clear();
        for &t in stars.of(u) {
            for &w in &tets[t as usize] {
                if w == b {
                    let mut chain = vec![b, u];
                    let mut x = u;
                    while x != a {
                        x = prev.iter().find(|p| p.0 == x).map_or(a, |p| p.1);
                        chain.push(x);
                    }
                    chain.reverse();
                    return chain;
                }
                if w != u && !prev.iter().any(|p| p.0 == w) && !next.contains(&w) && on_line(w) {
                    next.push(w);
                }
            }
        }
        for &w in &next {
            prev.push((w, u));
        }
        let dist = |v: &u32| norm(&sub(&points[*v as usize], &pb));
        next.sort_by(|x, y| dist(y).total_cmp(&dist(x)));
        stack.extend_from_slice(&next);
    }
    Vec::new()
}

/// A face that may lie on a facet: counterclockwise in the facet's projection, and how
/// far its plane is tilted from the facet's (one minus the cosine of the angle).
#[derive(Clone, Copy)]
struct Cand {
    f: [u32; 3],
    tilt: f64,
}

/// The candidate faces of every facet that is not simple, sorted by facet: faces whose
/// nodes all lie on the facet and whose projected centroid lies in it.
fn candidates(
    geo: &mut Geometry,
    on: &Rows,
    simple: &[bool],
    faces: &[[u32; 3]],
) -> Vec<(u32, Cand)> {
    let points = geo.points;
    let mut out: Vec<(u32, Cand)> = Vec::new();
    let mut common: Vec<u32> = Vec::new();
    for &f in faces {
        let (a, b, c) = (on.of(f[0]), on.of(f[1]), on.of(f[2]));
        if a.is_empty() || b.is_empty() || c.is_empty() {
            continue;
        }
        common.clear();
        common.extend(
            a.iter()
                .filter(|g| b.binary_search(g).is_ok() && c.binary_search(g).is_ok()),
        );
        for &g in &common {
            if simple[g as usize] {
                continue;
            }
            let fa = geo.facet(g as usize);
            let p = f.map(|v| &points[v as usize]);
            let o = fa.proj.orient(p[0], p[1], p[2]);
            if o == 0.0 {
                continue;
            }
            let centroid: Point = std::array::from_fn(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0);
            if fa.locate(points, &centroid) != RingSide::Outside {
                let n = cross(&sub(p[1], p[0]), &sub(p[2], p[0]));
                let tilt = 1.0 - (dot(&n, &fa.slab.normal) / norm(&n)).abs();
                let f = if o > 0.0 { f } else { [f[0], f[2], f[1]] };
                out.push((g, Cand { f, tilt }));
            }
        }
    }
    out.sort_by_key(|c| c.0);
    out
}

/// Sorted key of a face.
fn face_key(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// Buffers reused from one facet to the next.
#[derive(Default)]
struct Scratch {
    /// The facet's boundary pieces, sorted.
    boundary: Vec<(u32, u32)>,
    /// Each candidate's directed edges, sorted: (edge, candidate).
    left: Vec<((u32, u32), u32)>,
    taken: Vec<bool>,
    stack: Vec<usize>,
    sides: Vec<(u32, u32)>,
}

/// The faces on facet `fa` (see the module's documentation), from its candidates `cands`
/// and its boundary pieces (`scratch.boundary`). Problems: an edge of the surface with no
/// face beyond it, two faces of the surface on one side of an edge (the facet covered
/// twice), and pieces of the boundary that bound no face.
fn surface(
    fa: &Facet,
    cands: &[(u32, Cand)],
    scratch: &mut Scratch,
    pr: &mut Problems,
) -> Vec<[u32; 3]> {
    let Scratch {
        boundary,
        left,
        taken,
        stack,
        sides,
    } = scratch;
    left.clear();
    for (i, (_, c)) in cands.iter().enumerate() {
        for k in 0..3 {
            left.push(((c.f[k], c.f[(k + 1) % 3]), i as u32));
        }
    }
    left.sort_unstable();
    // The flattest candidate on the left of directed edge `e`.
    let flattest = |e: (u32, u32)| -> Option<usize> {
        let from = left.partition_point(|x| x.0 < e);
        left[from..]
            .iter()
            .take_while(|x| x.0 == e)
            .map(|x| x.1 as usize)
            .min_by(|&a, &b| cands[a].1.tilt.total_cmp(&cands[b].1.tilt))
    };
    let is_piece = |e: &(u32, u32)| boundary.binary_search(e).is_ok();
    taken.clear();
    taken.resize(cands.len(), false);
    stack.clear();
    for &e in boundary.iter() {
        if let Some(i) = flattest(e) {
            if !taken[i] {
                taken[i] = true;
                stack.push(i);
            }
        }
    }
    let label = facet_label(fa.src, pr);
    let mut open: Option<((u32, u32), usize)> = None;
    while let Some(i) = stack.pop() {
        let f = cands[i].1.f;
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            if is_piece(&(a, b)) {
                continue;
            }
            match flattest((b, a)) {
                Some(j) if !taken[j] => {
                    taken[j] = true;
                    stack.push(j);
                }
                Some(_) => {}
                None => match &mut open {
                    Some((_, n)) => *n += 1,
                    None => open = Some(((a, b), 1)),
                },
            }
        }
    }
    if let Some(((a, b), n)) = open {
        pr.push(format!(
            "facet {}: the faces on it end at {n} edge(s) that are no pieces of its boundary, the first ({}, {})",
            label,
            name(pr, a),
            name(pr, b)
        ));
    }
    // Exactly once: no edge with two faces of the surface on one side, and every piece
    // of the boundary used.
    sides.clear();
    for (i, (_, c)) in cands.iter().enumerate() {
        if taken[i] {
            for k in 0..3 {
                sides.push((c.f[k], c.f[(k + 1) % 3]));
            }
        }
    }
    sides.sort_unstable();
    let mut twice = sides.windows(2).filter(|w| w[0] == w[1]).map(|w| w[0]);
    if let Some((a, b)) = twice.next() {
        pr.push(format!(
            "facet {}: it is covered twice: {} edge(s) of the faces on it have two of them on one side, the first ({}, {})",
            label,
            1 + twice.count(),
            name(pr, a),
            name(pr, b)
        ));
    }
    let mut unused = boundary.iter().filter(|e| sides.binary_search(e).is_err());
    if let Some(&(u, v)) = unused.next() {
        pr.push(format!(
            "facet {}: {} piece(s) of its boundary bound no face on it, the first ({}, {})",
            label,
            1 + unused.count(),
            name(pr, u),
            name(pr, v)
        ));
    }
    cands
        .iter()
        .zip(taken.iter())
        .filter(|(_, &t)| t)
        .map(|(c, _)| c.1.f)
        .collect()
}

/// The boundary of facet `fa` as directed pieces of segment chains (sorted, into `out`),
/// with the facet's interior on their left in its projection: the ring edges used by one
/// ring of the facet, walked in ring order on rings turning counterclockwise that bound
/// no hole (or clockwise that bound one), in reverse otherwise.
fn boundary_pieces(
    fa: &Facet,
    prep: &PreparedPlc,
    node: &[u32],
    chains: &[Vec<u32>],
    out: &mut Vec<(u32, u32)>,
) {
    out.clear();
    let src = fa.src;
    let mut edges: Vec<[u32; 2]> = Vec::new();
    for r in &src.rings {
        for k in 0..r.len() {
            let (a, b) = (r[k], r[(k + 1) % r.len()]);
            edges.push([a.min(b), a.max(b)]);
        }
    }
    edges.sort_unstable();
    let used_once = |e: &[u32; 2]| {
        let from = edges.partition_point(|x| x < e);
        edges[from..].iter().take_while(|x| *x == e).count() == 1
    };
    for (ri, r) in src.rings.iter().enumerate() {
        let left =
            fa.ccw.get(ri).copied().unwrap_or(true) != fa.hole.get(ri).copied().unwrap_or(false);
        for k in 0..r.len() {
            let (a, b) = (r[k], r[(k + 1) % r.len()]);
            let e = [a.min(b), a.max(b)];
            if !used_once(&e) {
                continue;
            }
            let Ok(s) = prep.segments.binary_search(&e) else {
                continue;
            };
            let chain = &chains[s];
            if chain.is_empty() {
                continue; // reported with the segments
            }
            let forward = (chain[0] == node[a as usize]) == left;
            for w in chain.windows(2) {
                out.push(if forward { (w[0], w[1]) } else { (w[1], w[0]) });
            }
        }
    }
    out.sort_unstable();
    out.dedup();
}

/// Whether the tet's volume is at most [`FLAT`] times its longest edge cubed.
pub(super) fn is_flat(p: &[Point; 4]) -> bool {
    let l2 = longest_edge2(p);
    orient3d(&p[0], &p[1], &p[2], &p[3]).abs() / 6.0 <= FLAT * l2 * l2.sqrt()
}
