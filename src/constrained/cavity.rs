//! Facet insertion by cavity retriangulation (Si & Gärtner; the paper's §3.1).
//!
//! A missing region R (triangles of one facet that are not mesh faces) is inserted by
//! removing the tets that cross it, splitting their union into the cavities above and
//! below R, and filling each with the Delaunay tetrahedralization of its vertices. A
//! cavity face missing from that tetrahedralization makes the cavity grow by the tet
//! outside that face, until every face is present. The mesh is only changed once both
//! sides have been triangulated, so a failure leaves it as it was.
//!
//! Polygons that are not exactly flat can make the two sides disagree on R, or leave a
//! shim tet (four vertices on R); then the region asks for a Steiner point on the
//! polygon instead.

use super::cdt::{face_key, Cdt};
use crate::delaunay::Delaunay;
use crate::error::MeshError;
use crate::geom::polygon::Projection;
use crate::geom::predicates::adaptive_orient3d_calls;
use crate::geom::{orient3d, Point};
use crate::mesh::{FaceRef, TetId, VertexId, EDGE_VERTS as EDGES, FACE_VERTS, GHOST};
use rustc_hash::{FxHashMap, FxHashSet};

/// Figures of one region insertion (rows of the paper's Table 1).
#[derive(Clone, Debug, Default)]
pub struct RegionStats {
    /// Subfaces (of other facets) that the retriangulation destroyed, with their facets,
    /// sorted: they must be inserted again.
    pub lost: Vec<([VertexId; 3], u32)>,
    /// Tets crossing the region, deleted.
    pub crossing_tets: usize,
    /// Tets added to the cavity because a cavity face was missing.
    pub enlarged_tets: usize,
    /// Subfaces recovered (triangles of the region).
    pub subfaces: usize,
}

/// What inserting a region did.
#[derive(Clone, Debug)]
pub enum Outcome {
    /// The region is now a union of mesh faces.
    Inserted(RegionStats),
    /// The polygon is not flat enough: a Steiner point on it, here, resolves the conflict.
    NeedsSteiner(Point),
    /// The retriangulation would lose this subsegment (not Delaunay among the cavity's
    /// vertices): splitting it protects it.
    SplitSubsegment(VertexId, VertexId),
}

/// The boundary faces of a cavity above and below its region.
type Sides = (Vec<CavFace>, Vec<CavFace>);

/// A face of the cavity boundary: the inward-oriented vertices and, for faces of the
/// mesh, the tet inside the cavity and its face index.
#[derive(Clone, Copy, Debug)]
struct CavFace {
    verts: [VertexId; 3],
    inner: Option<FaceRef>,
}

/// Inserts the region `tris` (counterclockwise seen from the facet's normal side) of
/// facet `facet` into the mesh.
pub fn insert_region(
    cdt: &mut Cdt,
    tris: &[[VertexId; 3]],
    facet: u32,
    normal: [f64; 3],
) -> Result<Outcome, MeshError> {
    let region = Region::new(cdt, tris);
    let mut cavity = crossing_tets(cdt, &region)?;
    if cavity.is_empty() {
        // No tet crosses the region, yet its triangles are missing: the mesh already
        // triangulates the (not exactly flat) region its own way, which is as good a
        // triangulation of the polygon as ours.
        return match adopt(cdt, &region, normal) {
            Some(faces) => {
                let n = faces.len();
                for f in faces {
                    cdt.subfaces.insert(face_key(f), facet);
                }
                Ok(Outcome::Inserted(RegionStats {
                    subfaces: n,
                    ..Default::default()
                }))
            }
            None => Ok(Outcome::NeedsSteiner(steiner_point(
                cdt, tris, tris[0], normal,
            ))),
        };
    }
    let crossing = cavity.len();
    let mut in_cav = SlotSet::new(cdt.dt.mesh.num_slots());
    for &t in &cavity {
        in_cav.insert(t);
    }
    let mut enlarged = 0;
    let mut bubbles = Vec::new();
    let mut widened = false;
    let (mut top, mut bottom) = loop {
        bubbles.clear();
        if let Some(sides) = split_sides(cdt, &region, &cavity, &in_cav, &mut bubbles)? {
            break sides;
        }
        if bubbles.is_empty() && !widened {
            // The region's boundary does not split the cavity: where part of the
            // region, a rounding off flat, is triangulated otherwise by faces that no
            // tet crosses, the sides join around it. The tets on both sides of those
            // faces join the cavity, which then covers the whole region.
            widened = true;
            let more = other_triangulation(cdt, &region, normal);
            let mut added = false;
            for t in more {
                if cdt.is_ghost(t) {
                    return Ok(Outcome::NeedsSteiner(largest_centroid(cdt, tris)));
                }
                if in_cav.insert(t) {
                    cavity.push(t);
                    enlarged += 1;
                    added = true;
                }
            }
            if added {
                if super::debug() {
                    eprintln!(
                        "facet {facet}: cavity widened over another triangulation of the region"
                    );
                }
                continue;
            }
        }
        if bubbles.is_empty() {
            return Ok(Outcome::NeedsSteiner(largest_centroid(cdt, tris)));
        }
        // Tets that cross nothing but are walled in by crossing tets: the sides are
        // triangulated afresh around them, so they join the cavity.
        let mut stack: Vec<TetId> = bubbles.iter().map(|&f| cdt.dt.mesh.adj(f).tet()).collect();
        while let Some(t) = stack.pop() {
            if in_cav.contains(&t) {
                continue;
            }
            if cdt.is_ghost(t) {
                return Ok(Outcome::NeedsSteiner(largest_centroid(cdt, tris)));
            }
            in_cav.insert(t);
            cavity.push(t);
            enlarged += 1;
            for i in 0..4 {
                let n = cdt.dt.mesh.adj(FaceRef::new(t, i)).tet();
                if !in_cav.contains(&n) {
                    stack.push(n);
                }
            }
        }
    };
    // Each side's faces (with the region's triangles) and their triangulation.
    let mut sides: [Option<(Vec<CavFace>, SideDt)>; 2] = [None, None];
    // Both sides' inner vertices, found again only after the cavity grows.
    let mut inner_verts: Option<[Vec<VertexId>; 2]> = None;
    // A large cavity's two sides are triangulated at once, on two threads, as they are
    // before any growth; a side's result is used only while the cavity has not grown.
    let mut ahead: [Option<Result<SideDone, MeshError>>; 2] = [None, None];
    if cavity.len() >= PARALLEL_SIDES {
        let inner =
            inner_verts.get_or_insert_with(|| inner_vertices(cdt, &cavity, &top, &bottom, &region));
        let (points, orig, tris) = (&cdt.dt.points[..], &cdt.dt.orig[..], &region.tris[..]);
        let (a, b) = rayon::join(
            || triangulate_side(points, orig, &top, tris, false, &inner[0]),
            || triangulate_side(points, orig, &bottom, tris, true, &inner[1]),
        );
        ahead = [Some(a), Some(b)];
    }
    #[allow(clippy::needless_range_loop)] // `side` also selects the face list and lid
    for side in 0..2 {
        loop {
            let (all, sdt, missing) = match ahead[side].take() {
                // Taken only while the cavity is as it was (growth empties `ahead`).
                Some(done) => done?,
                None => {
                    let faces = if side == 0 { &top } else { &bottom };
                    let inner = inner_verts.get_or_insert_with(|| {
                        inner_vertices(cdt, &cavity, &top, &bottom, &region)
                    });
                    let (points, orig) = (&cdt.dt.points, &cdt.dt.orig);
                    triangulate_side(points, orig, faces, &region.tris, side == 1, &inner[side])?
                }
            };
            if missing.is_empty() {
                sides[side] = Some((all, sdt));
                break;
            }
            for m in missing {
                let Some(inner) = all[m].inner else {
                    // A triangle of R is not a face: the sides disagree on R.
                    return Ok(Outcome::NeedsSteiner(steiner_point(
                        cdt,
                        tris,
                        all[m].verts,
                        normal,
                    )));
                };
                let outside = cdt.dt.mesh.adj(inner).tet();
                if in_cav.contains(&outside) {
                    continue;
                }
                if cdt.is_ghost(outside) {
                    return Err(MeshError::Internal(format!(
                        "facet {facet}: a hull face is missing from a cavity triangulation"
                    )));
                }
                if !grow(cdt, outside, side, &mut in_cav, &mut top, &mut bottom) {
                    // The polygon's sides cannot be told apart here: a point on it,
                    // near the trouble, separates them.
                    return Ok(Outcome::NeedsSteiner(steiner_point(
                        cdt,
                        tris,
                        all[m].verts,
                        normal,
                    )));
                }
                cavity.push(outside);
                enlarged += 1;
                inner_verts = None;
                ahead = [None, None];
            }
        }
    }
    // Growing the bottom side never touches the top side's faces (`grow` refuses to),
    // so the top side's faces and triangulation still hold.
    let [Some(top_side), Some(bottom_side)] = sides else {
        return Err(MeshError::Internal(
            "a cavity side was not triangulated".into(),
        ));
    };
    replace_cavity(
        cdt,
        &region,
        facet,
        normal,
        &cavity,
        [&top_side, &bottom_side],
        (crossing, enlarged),
    )
}

/// Replaces the `cavity` of region `region` of `facet` by the new tets of its two sides
/// (their faces and triangulations), once they are checked: a shim (four vertices on the
/// polygon) asks for a Steiner point, a subsegment inside the cavity that the new tets
/// lack for its split, and losing a vertex is an error. The subfaces of other facets
/// that the new tets do not have are returned as lost. `counts`: the crossing tets and
/// those added by enlargement, for the figures.
fn replace_cavity(
    cdt: &mut Cdt,
    region: &Region,
    facet: u32,
    normal: [f64; 3],
    cavity: &[TetId],
    [top_side, bottom_side]: [&(Vec<CavFace>, SideDt); 2],
    (crossing, enlarged): (usize, usize),
) -> Result<Outcome, MeshError> {
    let tris = &region.tris[..];
    let mut new_tets = Vec::new();
    for (faces, sdt) in [top_side, bottom_side] {
        let Some(inside) = sdt.inside(faces)? else {
            // The sides were told apart wrongly around a polygon far from flat: a point
            // on it makes its pieces flatter.
            if super::debug() {
                eprintln!("facet {facet}: a cavity side is not closed");
            }
            return Ok(Outcome::NeedsSteiner(largest_centroid(cdt, tris)));
        };
        for v in inside {
            if v.iter().all(|x| region.verts.contains(x)) {
                // A shim tet: four vertices on the polygon.
                let f = [v[0], v[1], v[2]];
                return Ok(Outcome::NeedsSteiner(steiner_point(cdt, tris, f, normal)));
            }
            new_tets.push(v);
        }
    }
    // Every vertex of the deleted tets must be a vertex of the new ones.
    let mut kept_verts = vec![false; cdt.dt.points.len()];
    for &x in new_tets.iter().flatten() {
        kept_verts[x as usize] = true;
    }
    for &t in cavity {
        let lost = cdt
            .dt
            .mesh
            .verts(t)
            .into_iter()
            .find(|&x| x != GHOST && !kept_verts[x as usize]);
        if let Some(x) = lost {
            return Err(MeshError::Internal(format!(
                "facet {facet}: the cavity retriangulation would lose vertex {}",
                cdt.dt.orig[x as usize]
            )));
        }
    }
    // Subsegments inside the cavity must survive: the new tets have no constraints.
    // Only the few subsegments among the cavity's edges are looked up in the new tets.
    let mut stake_order: Vec<(VertexId, VertexId)> = Vec::new();
    let mut kept_edge: FxHashMap<(VertexId, VertexId), bool> = FxHashMap::default();
    for &t in cavity {
        let v = cdt.dt.mesh.verts(t);
        for &(i, j) in &EDGES {
            let e = (v[i].min(v[j]), v[i].max(v[j]));
            if cdt.subsegs.contains_key(&e) && kept_edge.insert(e, false).is_none() {
                stake_order.push(e);
            }
        }
    }
    if !stake_order.is_empty() {
        for v in &new_tets {
            for &(i, j) in &EDGES {
                if let Some(k) = kept_edge.get_mut(&(v[i].min(v[j]), v[i].max(v[j]))) {
                    *k = true;
                }
            }
        }
        if let Some(&(a, b)) = stake_order.iter().find(|e| !kept_edge[e]) {
            return Ok(Outcome::SplitSubsegment(a, b));
        }
    }
    // Subfaces among the faces of the deleted tets may not survive the new triangulation.
    let mut at_risk: Vec<[VertexId; 3]> = Vec::new();
    for &t in cavity {
        for i in 0..4 {
            let v = cdt.dt.mesh.face_verts(t, i);
            let key = face_key(v);
            if cdt.subfaces.contains_key(&key) {
                at_risk.push(key);
            }
        }
    }
    graft(cdt, cavity, &top_side.0, &bottom_side.0, &new_tets)?;
    let lost = cdt.take_lost_subfaces(&mut at_risk);
    for t in tris {
        cdt.subfaces.insert(face_key(*t), facet);
    }
    Ok(Outcome::Inserted(RegionStats {
        lost,
        crossing_tets: crossing,
        enlarged_tets: enlarged,
        subfaces: tris.len(),
    }))
}

/// Is `q` strictly inside one of the triangles `tris` (of the mesh's `points`) in the
/// projection `seen`?
fn inside_any(seen: &Projection, points: &[Point], tris: &[[VertexId; 3]], q: &Point) -> bool {
    tris.iter().any(|t| {
        let [x, y, z] = t.map(|v| &points[v as usize]);
        let s = [
            seen.orient(x, y, q),
            seen.orient(y, z, q),
            seen.orient(z, x, q),
        ];
        s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0)
    })
}

/// The mesh faces that triangulate the region when no tet crosses it: a flood over mesh
/// faces with all vertices on the region, from its boundary edges inward (sides told
/// apart in the facet's projection). `None` if they do not make up a triangulation of it.
///
/// Where the polygon is not flat, tets with all four vertices on it (shims) can lie in
/// layers against it: the faces between a layer and the tets beside it then triangulate
/// the polygon twice, once above the layer and once below. Either is a triangulation of
/// the polygon; the faces above are tried first, then those below. The layer is left on
/// the other side, where carving removes it if that side is outside the domain, and the
/// shims' repairs see it otherwise.
fn adopt(cdt: &mut Cdt, region: &Region, normal: [f64; 3]) -> Option<Vec<[VertexId; 3]>> {
    let on_region = |v: &[VertexId]| v.iter().all(|x| region.verts.contains(x));
    // A shim lies within the region's slab: four times its vertices' deviation from their
    // mean plane (its vertices need not be the region's: the layer against the hull
    // reaches the polygon's other vertices).
    let height = |v: VertexId| crate::geom::dot(&cdt.dt.points[v as usize], &normal);
    let hs: Vec<f64> = region.verts.iter().map(|&v| height(v)).collect();
    let mean = hs.iter().sum::<f64>() / hs.len().max(1) as f64;
    let dev = hs.iter().map(|h| (h - mean).abs()).fold(0.0, f64::max);
    let slab = 4.0 * dev + f64::EPSILON * mean.abs();
    let in_slab = |v: &[VertexId; 4]| {
        v.iter()
            .all(|&x| x != GHOST && (height(x) - mean).abs() <= slab)
    };
    // Each face with all vertices on the region, with whether the tets on its two sides
    // (seen along the normal: above, below) are shims.
    let mut faces: FxHashMap<[VertexId; 3], [bool; 2]> = FxHashMap::default();
    let mut star = Vec::new();
    let p = |v: VertexId| cdt.dt.points[v as usize];
    for &v in &region.verts {
        cdt.dt.star(v, &mut star);
        for &t in &star {
            let tv = cdt.dt.mesh.verts(t);
            if cdt.is_ghost(t) {
                continue;
            }
            let shim = in_slab(&tv);
            for (i, fv) in FACE_VERTS.iter().enumerate() {
                let f = [tv[fv[0]], tv[fv[1]], tv[fv[2]]];
                if !on_region(&f) {
                    continue;
                }
                // Which side of the face tet `t` lies on: the side of its fourth vertex,
                // along the normal.
                let n = crate::geom::cross(
                    &crate::geom::sub(&p(f[1]), &p(f[0])),
                    &crate::geom::sub(&p(f[2]), &p(f[0])),
                );
                let up = crate::geom::dot(&n, &normal)
                    * orient3d(&p(f[0]), &p(f[1]), &p(f[2]), &p(tv[i]));
                let side = usize::from(up < 0.0);
                faces.entry(face_key(f)).or_insert([false; 2])[side] |= shim;
            }
        }
    }
    let shims = faces.values().any(|s| s[0] || s[1]);
    let envelopes: &[usize] = if shims { &[0, 1] } else { &[0] };
    for &keep in envelopes {
        // A face is taken only if the tet on the `keep` side is no shim (so never one
        // inside a layer).
        let cand: FxHashSet<[VertexId; 3]> = faces
            .iter()
            .filter(|(_, s)| !s[keep])
            .map(|(f, _)| *f)
            .collect();
        if let Some(found) = flood(cdt, region, normal, &cand) {
            return Some(found);
        }
    }
    None
}

/// The candidate faces `cand` that triangulate the region, flooded from its boundary edges
/// inward, or `None` if they do not make up a triangulation of it.
fn flood(
    cdt: &Cdt,
    region: &Region,
    normal: [f64; 3],
    cand: &FxHashSet<[VertexId; 3]>,
) -> Option<Vec<[VertexId; 3]>> {
    let seen = Projection::along(&normal);
    let o2 = |a: VertexId, b: VertexId, c: VertexId| {
        let p = |v: VertexId| &cdt.dt.points[v as usize];
        seen.orient(p(a), p(b), p(c))
    };
    let mut by_edge: FxHashMap<(VertexId, VertexId), Vec<[VertexId; 3]>> = FxHashMap::default();
    for f in cand {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            by_edge.entry((a.min(b), a.max(b))).or_default().push(*f);
        }
    }
    // The candidate through edge ab on the side of c (or away from it).
    let pick = |a: VertexId, b: VertexId, c: VertexId, same: bool| -> Option<[VertexId; 3]> {
        let sc = o2(a, b, c);
        let list = by_edge.get(&(a.min(b), a.max(b)))?;
        let mut found = None;
        for f in list {
            let x = *f.iter().find(|&&x| x != a && x != b)?;
            let sx = o2(a, b, x);
            let ok = if same { sx * sc > 0.0 } else { sx * sc < 0.0 };
            if ok {
                if found.is_some() {
                    return None; // two faces on one side: not a surface
                }
                found = Some(*f);
            }
        }
        found
    };
    let mut chosen: FxHashSet<[VertexId; 3]> = FxHashSet::default();
    let mut stack = Vec::new();
    for t in &region.tris {
        for k in 0..3 {
            let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
            if region.boundary.contains(&(a.min(b), a.max(b))) {
                let f = pick(a, b, c, true)?;
                if chosen.insert(f) {
                    stack.push(f);
                }
            }
        }
    }
    while let Some(f) = stack.pop() {
        for k in 0..3 {
            let (a, b, c) = (f[k], f[(k + 1) % 3], f[(k + 2) % 3]);
            if region.boundary.contains(&(a.min(b), a.max(b))) {
                continue;
            }
            let g = pick(a, b, c, false)?;
            if chosen.insert(g) {
                stack.push(g);
                if chosen.len() > region.tris.len() {
                    return None;
                }
            }
        }
    }
    (chosen.len() == region.tris.len()).then(|| chosen.into_iter().collect())
}

/// The region's triangles, vertices and boundary edges.
pub(crate) struct Region {
    pub(crate) tris: Vec<[VertexId; 3]>,
    pub(crate) verts: FxHashSet<VertexId>,
    boundary: FxHashSet<(VertexId, VertexId)>,
    boxes: Vec<[[f64; 3]; 2]>,
    /// Each vertex's side of each triangle's plane once computed: neighbouring tets
    /// share vertices (a vertex is met again through every edge of every tet around
    /// it), and a region of thousands of sliver triangles fanned from a far vertex
    /// (found by fuzzing), whose boxes all overlap, cost a minute of exact orientations
    /// without it.
    sides: std::cell::RefCell<SideCache>,
}

/// Sides of triangles' planes per vertex, for one region: a row of one entry per
/// triangle ([`UNKNOWN`] until computed) for each vertex met, in one buffer, found
/// through a per-vertex index that is kept from one region to the next and stamped, so
/// that starting a region costs nothing.
struct SideCache {
    /// Per vertex id: the stamp of the region that gave it a row, and the row's start.
    rows: Vec<(u32, u32)>,
    stamp: u32,
    buf: Vec<i8>,
}

thread_local! {
    static SIDE_CACHE: std::cell::RefCell<Option<SideCache>> =
        const { std::cell::RefCell::new(None) };
}

impl SideCache {
    const EMPTY: SideCache = SideCache {
        rows: Vec::new(),
        stamp: 0,
        buf: Vec::new(),
    };

    /// The thread's cache, emptied for a new region.
    fn take() -> Self {
        let mut c = SIDE_CACHE
            .with(|c| c.borrow_mut().take())
            .unwrap_or(SideCache::EMPTY);
        c.stamp = next_stamp(c.stamp, &mut c.rows, |r| &mut r.0);
        c.buf.clear();
        c
    }
}

impl Drop for Region {
    fn drop(&mut self) {
        let cache = std::mem::replace(self.sides.get_mut(), SideCache::EMPTY);
        SIDE_CACHE.with(|c| *c.borrow_mut() = Some(cache));
    }
}

/// A side not computed yet.
const UNKNOWN: i8 = 2;
/// The most side entries cached per region (bytes); past it, sides are recomputed.
const MAX_SIDES: usize = 1 << 26;

impl Region {
    /// The region of triangles `tris`.
    pub(crate) fn new(cdt: &Cdt, tris: &[[VertexId; 3]]) -> Self {
        let mut count: FxHashMap<(VertexId, VertexId), u32> = FxHashMap::default();
        let mut verts = FxHashSet::default();
        for t in tris {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                verts.insert(a);
            }
        }
        let boundary = count
            .into_iter()
            .filter(|&(_, c)| c == 1)
            .map(|(e, _)| e)
            .collect();
        let boxes = tris
            .iter()
            .map(|t| {
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for &v in t {
                    let p = cdt.dt.points[v as usize];
                    for k in 0..3 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
                [lo, hi]
            })
            .collect();
        Region {
            tris: tris.to_vec(),
            verts,
            boundary,
            boxes,
            sides: std::cell::RefCell::new(SideCache::take()),
        }
    }

    /// The sign of `orient3d` of triangle `k` and vertex `v`.
    fn side_of(&self, pts: &[Point], k: usize, v: VertexId) -> i8 {
        let tri = self.tris[k];
        // A vertex of the triangle lies on its plane.
        if tri.contains(&v) {
            return 0;
        }
        let [a, b, c] = tri.map(|y| &pts[y as usize]);
        let o = orient3d(a, b, c, &pts[v as usize]);
        (o > 0.0) as i8 - (o < 0.0) as i8
    }

    /// Does the open segment `pq`, whose ends lie strictly on opposite sides of triangle
    /// `k`'s plane, pass through the triangle (its boundary included)?
    fn pierces(&self, pts: &[Point], k: usize, p: VertexId, q: VertexId) -> bool {
        let (pp, pq) = (&pts[p as usize], &pts[q as usize]);
        let [a, b, c] = self.tris[k].map(|v| &pts[v as usize]);
        let s = [
            orient3d(pp, pq, a, b),
            orient3d(pp, pq, b, c),
            orient3d(pp, pq, c, a),
        ];
        !(s.iter().any(|&x| x > 0.0) && s.iter().any(|&x| x < 0.0))
    }

    /// Does an edge of the tet with vertices `v` cross the region's interior? The
    /// vertices' sides of the triangles' planes come from the region's cache, computed
    /// when first needed.
    fn crossed_by_tet(&self, pts: &[Point], v: [VertexId; 4]) -> bool {
        let n = self.tris.len();
        let mut cache = self.sides.borrow_mut();
        let SideCache { rows, stamp, buf } = &mut *cache;
        let top = v.iter().max().map_or(0, |&m| m as usize);
        if top >= rows.len() {
            rows.resize(top + 1, (0, 0));
        }
        // Each vertex's row in the buffer, found (or made) when first needed: a tet whose
        // box misses every triangle's needs none. `None` once the buffer is full: then
        // the vertex's sides are computed each time.
        let mut start: [Option<Option<usize>>; 4] = [None; 4];
        let mut side = |i: usize, k: usize| {
            let s = *start[i].get_or_insert_with(|| {
                let row = &mut rows[v[i] as usize];
                if row.0 == *stamp {
                    Some(row.1 as usize)
                } else if buf.len() + n <= MAX_SIDES {
                    let s = buf.len();
                    buf.resize(s + n, UNKNOWN);
                    *row = (*stamp, s as u32);
                    Some(s)
                } else {
                    None
                }
            });
            match s {
                Some(s) => {
                    if buf[s + k] == UNKNOWN {
                        buf[s + k] = self.side_of(pts, k, v[i]);
                    }
                    buf[s + k]
                }
                None => self.side_of(pts, k, v[i]),
            }
        };
        let q = v.map(|x| &pts[x as usize]);
        for &(i, j) in &EDGES {
            let (p, r) = (q[i], q[j]);
            for (k, bx) in self.boxes.iter().enumerate() {
                // Both ends beyond one side of the triangle's box (coordinates are finite).
                if (0..3).any(|a| {
                    (p[a] < bx[0][a] && r[a] < bx[0][a]) || (p[a] > bx[1][a] && r[a] > bx[1][a])
                }) {
                    continue;
                }
                if side(i, k) * side(j, k) < 0 && self.pierces(pts, k, v[i], v[j]) {
                    return true;
                }
            }
        }
        false
    }
}

/// Does tet `t` have an edge crossing the region?
fn crosses(cdt: &Cdt, region: &Region, t: TetId) -> bool {
    let v = cdt.dt.mesh.verts(t);
    if v[3] == GHOST {
        return false;
    }
    let work = &cdt.work;
    work.set(work.get() + region.tris.len() as u64);
    region.crossed_by_tet(&cdt.dt.points, v)
}

/// Cavities of at least this many tets have their two sides triangulated on two threads
/// (below it, starting a thread costs more than it saves).
const PARALLEL_SIDES: usize = 4096;

/// Work units ([`Cdt::work`], a crossing test each) per orientation test that needed
/// adaptive arithmetic.
const ADAPTIVE_WORK_UNITS: u64 = 32;

/// The stamp after `now` for arrays whose entries are valid where they carry the current
/// stamp: when the numbers wrap, every entry's stamp (`stamp_of`) is cleared first, so
/// that no old entry carries the new one.
pub(crate) fn next_stamp<T>(
    now: u32,
    items: &mut [T],
    stamp_of: impl Fn(&mut T) -> &mut u32,
) -> u32 {
    match now.wrapping_add(1) {
        0 => {
            items.iter_mut().for_each(|x| *stamp_of(x) = 0);
            1
        }
        next => next,
    }
}

/// A set of tets (or of other dense ids, such as vertices) as a stamp per slot, in
/// arrays kept from one use to the next: a hash set per region cost more than the
/// region's own cavity work.
pub(crate) struct SlotSet {
    stamp: Vec<u32>,
    now: u32,
}

thread_local! {
    static SLOT_SETS: std::cell::RefCell<Vec<(Vec<u32>, u32)>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

impl SlotSet {
    /// An empty set for a mesh of `slots` tet slots (more may be added).
    pub(crate) fn new(slots: usize) -> Self {
        let (stamp, now) = SLOT_SETS.with(|p| p.borrow_mut().pop()).unwrap_or_default();
        let mut set = SlotSet { stamp, now };
        set.clear(slots);
        set
    }

    /// Empties the set, for `slots` slots (more may be added).
    pub(crate) fn clear(&mut self, slots: usize) {
        self.now = next_stamp(self.now, &mut self.stamp, |x| x);
        if self.stamp.len() < slots {
            self.stamp.resize(slots, 0);
        }
    }

    /// Is tet `t` in the set?
    #[inline]
    pub(crate) fn contains(&self, t: &TetId) -> bool {
        self.stamp.get(*t as usize) == Some(&self.now)
    }

    /// Adds tet `t`; false if it was there already.
    #[inline]
    pub(crate) fn insert(&mut self, t: TetId) -> bool {
        let i = t as usize;
        if i >= self.stamp.len() {
            self.stamp.resize(i + 1, 0);
        }
        let fresh = self.stamp[i] != self.now;
        self.stamp[i] = self.now;
        fresh
    }
}

impl Drop for SlotSet {
    fn drop(&mut self) {
        let stamp = std::mem::take(&mut self.stamp);
        let now = self.now;
        SLOT_SETS.with(|p| p.borrow_mut().push((stamp, now)));
    }
}

/// The tets whose interiors meet the region: those with an edge crossing it. They are
/// face-connected, and each touches the region near a region vertex or is reached from one.
/// Stops with [`MeshError::WorkBound`] once the tests pass [`Cdt::work_limit`].
pub(crate) fn crossing_tets(cdt: &mut Cdt, region: &Region) -> Result<Vec<TetId>, MeshError> {
    let mut adaptive = adaptive_orient3d_calls();
    let mut seen = SlotSet::new(cdt.dt.mesh.num_slots());
    let mut out = Vec::new();
    let mut star = Vec::new();
    let mut verts: Vec<VertexId> = region.verts.iter().copied().collect();
    verts.sort_unstable();
    for v in verts {
        cdt.dt.star(v, &mut star);
        for &t in &star {
            if seen.insert(t) && crosses(cdt, region, t) {
                out.push(t);
            }
        }
        over_work(cdt, &mut adaptive)?;
    }
    let mut k = 0;
    while k < out.len() {
        let t = out[k];
        k += 1;
        for i in 0..4 {
            let n = cdt.dt.mesh.adj(FaceRef::new(t, i)).tet();
            if seen.insert(n) && crosses(cdt, region, n) {
                out.push(n);
            }
        }
        over_work(cdt, &mut adaptive)?;
    }
    Ok(out)
}

/// Charges the crossing tests' orientations since `adaptive` (a count of
/// [`adaptive_orient3d_calls`]) that needed adaptive arithmetic, then fails with
/// [`MeshError::WorkBound`] once the work done passes the construction's bound. A test is
/// cheap unless its orientations need adaptive arithmetic: around a vertex far out of
/// the model's scale they all do, and those count as the time they take.
fn over_work(cdt: &Cdt, adaptive: &mut u64) -> Result<(), MeshError> {
    let now = adaptive_orient3d_calls();
    let work = &cdt.work;
    work.set(work.get() + ADAPTIVE_WORK_UNITS * (now - *adaptive));
    *adaptive = now;
    if work.get() > cdt.work_limit {
        return Err(MeshError::WorkBound);
    }
    Ok(())
}

/// Splits the cavity's boundary faces into those above and those below the region, by a
/// flood fill over the cavity surface that stops at the region's boundary edges; `None`
/// if they do not split it in two.
fn split_sides(
    cdt: &Cdt,
    region: &Region,
    cavity: &[TetId],
    in_cav: &SlotSet,
    bubbles: &mut Vec<FaceRef>,
) -> Result<Option<Sides>, MeshError> {
    let mesh = &cdt.dt.mesh;
    let mut faces: Vec<FaceRef> = Vec::new();
    // Sized up front (a cavity has about two boundary faces per tet): growing maps
    // rehash, which cost more than the lookups in small cavities.
    let mut index: FxHashMap<FaceRef, usize> =
        FxHashMap::with_capacity_and_hasher(2 * cavity.len(), Default::default());
    let mut cav: Vec<TetId> = cavity.to_vec();
    cav.sort_unstable();
    for &t in &cav {
        for i in 0..4 {
            if !in_cav.contains(&mesh.adj(FaceRef::new(t, i)).tet()) {
                index.insert(FaceRef::new(t, i), faces.len());
                faces.push(FaceRef::new(t, i));
            }
        }
    }
    let mut comp = vec![usize::MAX; faces.len()];
    let mut ncomp = 0;
    // Whether each component reaches the region's boundary: the two sides do; any
    // other is a bubble around tets enclosed by the cavity.
    let mut rim: Vec<bool> = Vec::new();
    for start in 0..faces.len() {
        if comp[start] != usize::MAX {
            continue;
        }
        comp[start] = ncomp;
        rim.push(false);
        let mut stack = vec![start];
        while let Some(fi) = stack.pop() {
            let f = faces[fi];
            let v = mesh.face_verts(f.tet(), f.face());
            for k in 0..3 {
                let (a, b) = (v[k], v[(k + 1) % 3]);
                if region.boundary.contains(&(a.min(b), a.max(b))) {
                    rim[ncomp] = true;
                    continue;
                }
                let g = surface_neighbor(cdt, f, a, b, in_cav)?;
                // The turn around edge (a, b) ends on a face that is not on the
                // cavity's boundary: the cavity is pinched there (seen around needle
                // polygons far out of proportion), and its surface has no two sides.
                let Some(&gi) = index.get(&g) else {
                    return Ok(None);
                };
                if comp[gi] == usize::MAX {
                    comp[gi] = ncomp;
                    stack.push(gi);
                }
            }
        }
        ncomp += 1;
    }
    if ncomp > 2 && rim.iter().filter(|&&r| r).count() == 2 {
        bubbles.extend(
            faces
                .iter()
                .zip(&comp)
                .filter(|(_, &c)| !rim[c])
                .map(|(&f, _)| f),
        );
        return Ok(None);
    }
    if ncomp != 2 {
        // The region's boundary does not split the cavity: part of the (not exactly
        // flat) region is already triangulated differently by faces no tet crosses.
        return Ok(None);
    }
    // Which component lies above: look at a face through a boundary edge of R.
    let mut top_comp = None;
    'search: for t in &region.tris {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if !region.boundary.contains(&(a.min(b), a.max(b))) {
                continue;
            }
            for (fi, f) in faces.iter().enumerate() {
                let v = mesh.face_verts(f.tet(), f.face());
                if v.contains(&a) && v.contains(&b) {
                    let x = *v.iter().find(|&&x| x != a && x != b).unwrap_or(&a);
                    let p = |i: VertexId| &cdt.dt.points[i as usize];
                    let o = orient3d(p(t[0]), p(t[1]), p(t[2]), p(x));
                    if o > 0.0 {
                        top_comp = Some(comp[fi]);
                        break 'search;
                    } else if o < 0.0 {
                        top_comp = Some(1 - comp[fi]);
                        break 'search;
                    }
                }
            }
        }
    }
    let Some(top_comp) = top_comp else {
        return Ok(None);
    };
    let mut top = Vec::new();
    let mut bottom = Vec::new();
    for (fi, f) in faces.iter().enumerate() {
        let cf = CavFace {
            verts: mesh.face_verts(f.tet(), f.face()),
            inner: Some(*f),
        };
        if comp[fi] == top_comp {
            top.push(cf);
        } else {
            bottom.push(cf);
        }
    }
    Ok(Some((top, bottom)))
}

/// The cavity boundary face next to boundary face `f` across its edge `ab`: turn around
/// the edge through the tets outside the cavity until re-entering it.
fn surface_neighbor(
    cdt: &Cdt,
    f: FaceRef,
    a: VertexId,
    b: VertexId,
    in_cav: &SlotSet,
) -> Result<FaceRef, MeshError> {
    let mesh = &cdt.dt.mesh;
    let mut g = mesh.adj(f);
    for _ in 0..100_000 {
        let t = g.tet();
        if in_cav.contains(&t) {
            return Ok(g);
        }
        // Leave t through its other face containing a and b.
        let v = mesh.verts(t);
        let skip = g.face();
        let k = (0..4)
            .find(|&k| k != skip && v[k] != a && v[k] != b)
            .unwrap_or(skip);
        g = mesh.adj(FaceRef::new(t, k));
    }
    Err(MeshError::Internal(
        "turning around a cavity edge did not end".into(),
    ))
}

/// The tets on both sides of the mesh faces that join three of the region's vertices,
/// are no triangle of it, and lie within it (their centroid inside one of its triangles,
/// seen along `normal`): another triangulation of part of the region.
fn other_triangulation(cdt: &Cdt, region: &Region, normal: [f64; 3]) -> Vec<TetId> {
    let mesh = &cdt.dt.mesh;
    let p = |v: VertexId| cdt.dt.points[v as usize];
    let seen = Projection::along(&normal);
    let keys: FxHashSet<[VertexId; 3]> = region.tris.iter().map(|t| face_key(*t)).collect();
    let mut verts: Vec<VertexId> = region.verts.iter().copied().collect();
    verts.sort_unstable();
    let mut star = Vec::new();
    let mut out = Vec::new();
    for &v in &verts {
        cdt.dt.star(v, &mut star);
        for &t in &star {
            for i in 0..4 {
                let f = mesh.face_verts(t, i);
                let n = mesh.adj(FaceRef::new(t, i)).tet();
                // Each face once: from its least vertex, and the lower of its two tets.
                if f.iter().min() == Some(&v)
                    && t < n
                    && f.iter().all(|x| region.verts.contains(x))
                    && !keys.contains(&face_key(f))
                {
                    let c = [0, 1, 2].map(|k| (p(f[0])[k] + p(f[1])[k] + p(f[2])[k]) / 3.0);
                    if inside_any(&seen, &cdt.dt.points, &region.tris, &c) {
                        out.push(t);
                        out.push(n);
                    }
                }
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The vertices inside the cavity (on none of its boundary faces), above and below the
/// region: their whole star is deleted, so each side's triangulation must include its
/// own. The side is the one of the region triangle nearest the vertex, which is sound
/// for a region that is flat up to rounding.
fn inner_vertices(
    cdt: &Cdt,
    cavity: &[TetId],
    top: &[CavFace],
    bottom: &[CavFace],
    region: &Region,
) -> [Vec<VertexId>; 2] {
    // 0: not seen, 1: on the boundary, 2: inside (listed).
    let mut mark = vec![0u8; cdt.dt.points.len()];
    let boundary = top.iter().chain(bottom).flat_map(|f| f.verts);
    for x in region.verts.iter().copied().chain(boundary) {
        if x != GHOST {
            mark[x as usize] = 1;
        }
    }
    let mut inner: Vec<VertexId> = Vec::new();
    for &t in cavity {
        for x in cdt.dt.mesh.verts(t) {
            if x != GHOST && mark[x as usize] == 0 {
                mark[x as usize] = 2;
                inner.push(x);
            }
        }
    }
    let mut sides: [Vec<VertexId>; 2] = [Vec::new(), Vec::new()];
    let p = |i: VertexId| cdt.dt.points[i as usize];
    for x in inner {
        let q = p(x);
        let dist = |t: &[VertexId; 3]| -> f64 {
            (0..3)
                .map(|k| {
                    let c = (p(t[0])[k] + p(t[1])[k] + p(t[2])[k]) / 3.0;
                    (c - q[k]) * (c - q[k])
                })
                .sum()
        };
        let Some(t) = region
            .tris
            .iter()
            .min_by(|a, b| dist(a).total_cmp(&dist(b)))
        else {
            continue;
        };
        let o = orient3d(&p(t[0]), &p(t[1]), &p(t[2]), &q);
        sides[usize::from(o <= 0.0)].push(x);
    }
    for s in &mut sides {
        s.sort_unstable();
    }
    sides
}

/// One side's faces (with the region's triangles), its triangulation, and the indices
/// of the faces that the triangulation lacks.
type SideDone = (Vec<CavFace>, SideDt, Vec<usize>);

/// Triangulates one side of the cavity: its faces `faces`, the region's triangles `tris`
/// oriented so that the side lies on their positive side (`flip` for the bottom), and its
/// `inner` vertices. Needs only the mesh's points and perturbation indices, so that the
/// two sides can be triangulated on two threads.
fn triangulate_side(
    points: &[Point],
    orig: &[u32],
    faces: &[CavFace],
    tris: &[[VertexId; 3]],
    flip: bool,
    inner: &[VertexId],
) -> Result<SideDone, MeshError> {
    let mut all = faces.to_vec();
    for t in tris {
        let verts = if flip { [t[0], t[2], t[1]] } else { *t };
        all.push(CavFace { verts, inner: None });
    }
    let sdt = delaunay_of(points, orig, &all, inner)?;
    let missing = sdt.missing(&all);
    Ok((all, sdt, missing))
}

/// The Delaunay tetrahedralization of one side's vertices, with the map between its
/// vertex ids and the mesh's.
struct SideDt {
    dt: Delaunay,
    /// Mesh vertex id of each local internal vertex id.
    global: Vec<VertexId>,
    /// Local internal vertex id of each mesh vertex id of the side.
    local: FxHashMap<VertexId, VertexId>,
    /// Every face (sorted local ids) with a real tet that has it: lookups in constant
    /// time, where walking the stars cost a quarter of a large insertion.
    faces: FxHashMap<[VertexId; 3], FaceRef>,
}

/// The Delaunay tetrahedralization of the vertices of `faces` and `inner` (mesh
/// vertices, at `points`), numbered in global perturbation order (`orig`) so that its
/// ties are broken exactly as in the mesh.
fn delaunay_of(
    points: &[Point],
    orig: &[u32],
    faces: &[CavFace],
    inner: &[VertexId],
) -> Result<SideDt, MeshError> {
    let mut gv: Vec<VertexId> = faces.iter().flat_map(|f| f.verts).collect();
    gv.extend_from_slice(inner);
    gv.sort_unstable_by_key(|&v| orig[v as usize]);
    gv.dedup();
    let pts: Vec<Point> = gv.iter().map(|&v| points[v as usize]).collect();
    let dt = Delaunay::build(&pts)?.dt;
    let global: Vec<VertexId> = dt.orig.iter().map(|&i| gv[i as usize]).collect();
    let local = global
        .iter()
        .enumerate()
        .map(|(l, &g)| (g, l as VertexId))
        .collect();
    let faces = dt.mesh.face_index();
    Ok(SideDt {
        dt,
        global,
        local,
        faces,
    })
}

impl SideDt {
    /// The face `f` (mesh vertex ids) of this triangulation, seen from the tet on its
    /// positive side.
    fn face(&self, f: [VertexId; 3]) -> Option<FaceRef> {
        let [a, b, c] = [
            self.local.get(&f[0])?,
            self.local.get(&f[1])?,
            self.local.get(&f[2])?,
        ];
        let want = [*a, *b, *c];
        let fr = *self.faces.get(&face_key(want))?;
        let fv = self.dt.mesh.face_verts(fr.tet(), fr.face());
        let same = (0..3).any(|r| fv == [want[r], want[(r + 1) % 3], want[(r + 2) % 3]]);
        Some(if same { fr } else { self.dt.mesh.adj(fr) })
    }

    /// Indices of the faces that are not faces of this triangulation.
    fn missing(&self, faces: &[CavFace]) -> Vec<usize> {
        (0..faces.len())
            .filter(|&i| self.face(faces[i].verts).is_none())
            .collect()
    }

    /// The tets inside the side bounded by `faces` (each seen with the side on its
    /// positive side), as mesh vertex ids: a flood fill from the faces' inner tets that
    /// never crosses them. `None` if the faces do not close the side (the flood reaches
    /// the hull).
    fn inside(&self, faces: &[CavFace]) -> Result<Option<Vec<[VertexId; 4]>>, MeshError> {
        let mut wall: FxHashSet<FaceRef> =
            FxHashSet::with_capacity_and_hasher(2 * faces.len(), Default::default());
        let mut stack = Vec::new();
        let mut inside: FxHashSet<TetId> =
            FxHashSet::with_capacity_and_hasher(self.dt.mesh.num_slots(), Default::default());
        for f in faces {
            let inner = self
                .face(f.verts)
                .ok_or_else(|| MeshError::Internal("a cavity face vanished".into()))?;
            wall.insert(inner);
            wall.insert(self.dt.mesh.adj(inner));
            if inside.insert(inner.tet()) {
                stack.push(inner.tet());
            }
        }
        while let Some(t) = stack.pop() {
            if self.dt.mesh.is_ghost(t) {
                return Ok(None);
            }
            for i in 0..4 {
                let f = FaceRef::new(t, i);
                if wall.contains(&f) {
                    continue;
                }
                let n = self.dt.mesh.adj(f).tet();
                if inside.insert(n) {
                    stack.push(n);
                }
            }
        }
        let mut out: Vec<TetId> = inside.into_iter().collect();
        out.sort_unstable();
        Ok(Some(
            out.into_iter()
                .map(|t| self.dt.mesh.verts(t).map(|x| self.global[x as usize]))
                .collect(),
        ))
    }
}

/// Adds tet `t` (outside the cavity, next to side `side`) to the cavity, updating the
/// boundary faces of both sides. False, with the cavity left half grown, if `t` also
/// touches the other side's boundary: the cavity would wrap around its polygon (seen on
/// needle polygons billions of times longer than wide, whose sides rounding confuses).
fn grow(
    cdt: &Cdt,
    t: TetId,
    side: usize,
    in_cav: &mut SlotSet,
    top: &mut Vec<CavFace>,
    bottom: &mut Vec<CavFace>,
) -> bool {
    let mesh = &cdt.dt.mesh;
    for i in 0..4 {
        let f = FaceRef::new(t, i);
        let g = mesh.adj(f);
        if in_cav.contains(&g.tet()) {
            // The face between t and the cavity is no longer on the boundary.
            let in_top = top.iter().position(|c| c.inner == Some(g));
            let in_bot = bottom.iter().position(|c| c.inner == Some(g));
            match (in_top, in_bot) {
                (Some(k), _) => {
                    if side != 0 {
                        return false;
                    }
                    top.swap_remove(k);
                }
                (None, Some(k)) => {
                    if side != 1 {
                        return false;
                    }
                    bottom.swap_remove(k);
                }
                (None, None) => {}
            }
        } else {
            let cf = CavFace {
                verts: mesh.face_verts(t, i),
                inner: Some(f),
            };
            if side == 0 {
                top.push(cf);
            } else {
                bottom.push(cf);
            }
        }
    }
    in_cav.insert(t);
    true
}

/// Replaces the cavity's tets by `new_tets`, gluing them to each other and to the tets
/// outside the cavity.
fn graft(
    cdt: &mut Cdt,
    cavity: &[TetId],
    top: &[CavFace],
    bottom: &[CavFace],
    new_tets: &[[VertexId; 4]],
) -> Result<(), MeshError> {
    // The outside face behind each cavity face, read before the cavity is deleted.
    let mut outside: FxHashMap<[VertexId; 3], FaceRef> =
        FxHashMap::with_capacity_and_hasher(top.len() + bottom.len(), Default::default());
    for f in top.iter().chain(bottom) {
        if let Some(inner) = f.inner {
            outside.insert(face_key(f.verts), cdt.dt.mesh.adj(inner));
        }
    }
    for &t in cavity {
        cdt.dt.mesh.kill_tet(t);
    }
    let mut open: FxHashMap<[VertexId; 3], FaceRef> =
        FxHashMap::with_capacity_and_hasher(2 * new_tets.len(), Default::default());
    let mut made = Vec::with_capacity(new_tets.len());
    for &v in new_tets {
        let t = cdt
            .dt
            .mesh
            .add_tet(v)
            .map_err(|_| MeshError::Unsupported("the mesh exceeds 2^30 tets".into()))?;
        made.push(t);
        for (i, fv) in FACE_VERTS.iter().enumerate() {
            let key = face_key([v[fv[0]], v[fv[1]], v[fv[2]]]);
            match open.remove(&key) {
                Some(g) => cdt.dt.mesh.glue(FaceRef::new(t, i), g),
                None => {
                    open.insert(key, FaceRef::new(t, i));
                }
            }
        }
    }
    for (key, f) in open {
        let g = outside.get(&key).ok_or_else(|| {
            MeshError::Internal(format!("a new cavity tet face {key:?} has no neighbour"))
        })?;
        cdt.dt.mesh.glue(f, *g);
    }
    for t in made {
        for &x in &cdt.dt.mesh.verts(t) {
            if x != GHOST {
                cdt.dt.mesh.set_vertex_tet(x, t);
            }
        }
    }
    Ok(())
}

/// The centroid of the region's largest triangle: a point surely on the polygon.
fn largest_centroid(cdt: &Cdt, tris: &[[VertexId; 3]]) -> Point {
    let p = |v: VertexId| cdt.dt.points[v as usize];
    let area2 = |t: &[VertexId; 3]| {
        let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
        let n = crate::geom::cross(&crate::geom::sub(&b, &a), &crate::geom::sub(&c, &a));
        crate::geom::dot(&n, &n)
    };
    let t = tris
        .iter()
        .max_by(|a, b| area2(a).total_cmp(&area2(b)))
        .copied()
        .unwrap_or([0; 3]);
    let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
    std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0)
}

/// Where to put a Steiner point on the polygon for the offending face `f` (paper §3.1):
/// its circumcenter, brought onto the polygon's plane through `f`'s centroid (so it lies
/// no farther from the polygon than its vertices do), if that lands in one of the
/// region's triangles; else the centroid of the region's largest triangle.
pub(crate) fn steiner_point(
    cdt: &Cdt,
    tris: &[[VertexId; 3]],
    f: [VertexId; 3],
    normal: [f64; 3],
) -> Point {
    let p = |v: VertexId| cdt.dt.points[v as usize];
    let (a, b, c) = (p(f[0]), p(f[1]), p(f[2]));
    let centroid: Point = std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
    let nn = normal.iter().map(|x| x * x).sum::<f64>();
    let cc = circumcenter(cdt, f);
    if nn > 0.0 && cc.iter().all(|x| x.is_finite()) {
        let off = (0..3)
            .map(|k| (cc[k] - centroid[k]) * normal[k])
            .sum::<f64>()
            / nn;
        let q: Point = std::array::from_fn(|k| cc[k] - off * normal[k]);
        // Inside a region triangle, seen along the normal?
        if inside_any(&Projection::along(&normal), &cdt.dt.points, tris, &q) {
            return q;
        }
    }
    largest_centroid(cdt, tris)
}

/// The circumcenter of triangle `f` (see [`crate::geom::encroach::circumcenter`]).
fn circumcenter(cdt: &Cdt, f: [VertexId; 3]) -> Point {
    let [a, b, c] = f.map(|v| cdt.dt.points[v as usize]);
    crate::geom::encroach::circumcenter(&a, &b, &c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::Delaunay;
    use crate::geom::lcg;

    #[test]
    fn stamps_that_wrap_clear_the_entries_first() {
        let mut items = vec![(u32::MAX, 'a'), (7, 'b')];
        assert_eq!(next_stamp(7, &mut items, |x| &mut x.0), 8);
        assert_eq!(items[0].0, u32::MAX);
        assert_eq!(next_stamp(u32::MAX, &mut items, |x| &mut x.0), 1);
        assert!(items.iter().all(|x| x.0 == 0));
    }

    /// Regions that cache their vertices' sides (fans of slivers from a far vertex, as
    /// fuzzing made, small and large, one after the other on one cache) answer every
    /// tet as the plain exact test of its edges does, asked in any order and again.
    #[test]
    fn cached_sides_answer_as_the_plain_test() {
        for ring in [4, 128] {
            sides_match_the_plain_test(ring);
        }
    }

    fn sides_match_the_plain_test(ring: usize) {
        let mut s = 5u64;
        let mut pts: Vec<Point> = vec![[1e12, 0.3, 0.1]];
        for k in 0..ring {
            let a = k as f64 / ring as f64 * std::f64::consts::TAU;
            pts.push([a.cos(), a.sin(), 1e-3 * (lcg(&mut s) - 0.5)]);
        }
        while pts.len() < ring + 200 {
            pts.push([0, 0, 0].map(|_| 2.0 * lcg(&mut s) - 1.0));
        }
        let dt = Delaunay::build(&pts).unwrap().dt;
        let inv = dt.internal_ids(pts.len());
        let cdt = Cdt::new(dt);
        let tris: Vec<[VertexId; 3]> = (0..ring)
            .map(|k| [inv[0], inv[1 + k], inv[1 + (k + 1) % ring]])
            .collect();
        let region = Region::new(&cdt, &tris);
        let plain = |p: VertexId, q: VertexId| {
            let pt = |v: VertexId| &cdt.dt.points[v as usize];
            tris.iter().any(|t| {
                let [a, b, c] = t.map(pt);
                let (o1, o2) = (orient3d(a, b, c, pt(p)), orient3d(a, b, c, pt(q)));
                if !((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) {
                    return false;
                }
                let e = [
                    orient3d(pt(p), pt(q), a, b),
                    orient3d(pt(p), pt(q), b, c),
                    orient3d(pt(p), pt(q), c, a),
                ];
                !(e.iter().any(|&x| x > 0.0) && e.iter().any(|&x| x < 0.0))
            })
        };
        let n = pts.len() as f64;
        let mut crossing = 0;
        for _ in 0..2000 {
            let v: [VertexId; 4] =
                std::array::from_fn(|_| (lcg(&mut s) * n) as VertexId % pts.len() as VertexId);
            if (0..4).any(|i| (i + 1..4).any(|j| v[i] == v[j])) {
                continue;
            }
            let want = EDGES.iter().any(|&(i, j)| plain(v[i], v[j]));
            crossing += want as usize;
            assert_eq!(region.crossed_by_tet(&cdt.dt.points, v), want, "{v:?}");
        }
        assert!(crossing > 10 * ring.min(10), "{crossing}");
    }

    /// The crossing tets of a region are found in full under no bound, and the search
    /// stops with [`MeshError::WorkBound`] once its tests pass the CDT's bound.
    #[test]
    fn crossing_tets_stop_at_the_work_limit() {
        let mut s = 11u64;
        let pts: Vec<Point> = (0..300)
            .map(|_| [0, 0, 0].map(|_| 2.0 * lcg(&mut s) - 1.0))
            .chain([[-3.0, -3.0, 0.01], [3.0, -3.0, -0.01], [0.0, 3.0, 0.02]])
            .collect();
        let dt = Delaunay::build(&pts).unwrap().dt;
        let inv = dt.internal_ids(pts.len());
        let mut cdt = Cdt::new(dt);
        let tris = vec![[inv[300], inv[301], inv[302]]];
        let region = Region::new(&cdt, &tris);
        let all = crossing_tets(&mut cdt, &region).unwrap();
        let spent = cdt.work.get();
        assert!(
            all.len() > 50 && spent as usize >= all.len(),
            "{} {spent}",
            all.len()
        );
        cdt.work.set(0);
        cdt.work_limit = spent / 2;
        assert!(matches!(
            crossing_tets(&mut cdt, &region),
            Err(MeshError::WorkBound)
        ));
        assert!(cdt.work.get() < spent, "stopped early");
    }
}
