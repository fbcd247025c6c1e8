//! Segment recovery: every segment missing from the Delaunay tetrahedralization is split
//! with Steiner points until each of its subsegments is a mesh edge.
//!
//! Split points avoid needlessly short edges where segments meet at acute angles: next to
//! an acute vertex a subsegment is split on a sphere centred at that vertex whose radius
//! is a power of two (concentric shells, as Si & Gärtner and Shewchuk do), so the
//! subsegments around the vertex shrink together and protect it; elsewhere the vertex
//! that encroaches most upon the piece decides (its projection, or its distance from an
//! end the piece's segment shares with the vertex's own), else the midpoint is used.
//! Steiner points are computed from the segment's original endpoints, so they lie on the
//! segment up to rounding.

use crate::constrained::cdt::edge_key;
use crate::delaunay::Delaunay;
use crate::error::MeshError;
use crate::geom::{norm, sub, Point};
use crate::mesh::VertexId;

/// The recovered segments.
#[derive(Clone, Debug, Default)]
pub struct Subsegments {
    /// For each input segment, its vertices (internal ids) from one end to the other.
    pub chains: Vec<Vec<VertexId>>,
    /// Number of Steiner points inserted.
    pub steiner_points: usize,
}

/// One piece of a segment, between parameters `s0 < s1` along it.
#[derive(Clone, Copy, Debug)]
struct Piece {
    seg: usize,
    s0: f64,
    u: VertexId,
    s1: f64,
    v: VertexId,
}

/// Splits the missing segments of `dt` until all are chains of mesh edges.
///
/// `segments` are pairs of input indices; `next_pert` is the perturbation (and output)
/// index of the next Steiner point and is advanced; at most `max_steiner` points are added.
pub fn recover_segments(
    dt: &mut Delaunay,
    segments: &[[u32; 2]],
    n_input: usize,
    next_pert: &mut u32,
    max_steiner: usize,
    presplits: &[(usize, f64)],
    cancel: &std::sync::atomic::AtomicBool,
) -> Result<Subsegments, MeshError> {
    let inv = dt.internal_ids(n_input);
    let mut ends = Vec::with_capacity(segments.len());
    for &[a, b] in segments {
        let (ia, ib) = (inv[a as usize], inv[b as usize]);
        if ia == u32::MAX || ib == u32::MAX {
            return Err(MeshError::Internal(format!(
                "segment ({a}, {b}) has no vertex"
            )));
        }
        ends.push([ia, ib]);
    }
    let acute = acute_vertices(dt, &ends);
    // The segment each Steiner point lies on, for the split rule at shared ends.
    let mut seg_of: Vec<u32> = vec![u32::MAX; dt.points.len()];
    let mut splits: Vec<Vec<(f64, VertexId)>> = vec![Vec::new(); segments.len()];
    let mut steiner = 0usize;
    // Split points asked for by an earlier attempt (to protect a subsegment that a cavity
    // retriangulation would lose) go in first.
    for &(seg, s) in presplits {
        let [a, b] = ends[seg];
        let (pa, pb) = (dt.points[a as usize], dt.points[b as usize]);
        let x: Point = std::array::from_fn(|k| pa[k] + (pb[k] - pa[k]) * s);
        if let Some(w) = dt.insert_steiner(x, *next_pert)? {
            *next_pert += 1;
            steiner += 1;
            splits[seg].push((s, w));
            note_segment(&mut seg_of, w, seg);
        }
    }
    let mut queue: Vec<Piece> = Vec::new();
    for (seg, &[u, v]) in ends.iter().enumerate() {
        splits[seg].sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut prev = (0.0, u);
        for &(s, w) in splits[seg].iter().chain(std::iter::once(&(1.0, v))) {
            queue.push(Piece {
                seg,
                s0: prev.0,
                u: prev.1,
                s1: s,
                v: w,
            });
            prev = (s, w);
        }
    }
    // The pieces that are edges at the start, found in one pass over the tets (a walk
    // around each would cost much more).
    let mut present =
        crate::mesh::ListedEdges::new(dt.points.len(), queue.iter().map(|pc| edge_key(pc.u, pc.v)));
    present.mark(dt.mesh.real_tets().map(|t| dt.mesh.verts(t)));
    let was_present = |u: VertexId, v: VertexId| present.found(u, v);
    let mut done = Recovered::default();
    // Longest segments first (the queue is a stack): their split points are the
    // coarsest, and the shorter segments around them often need fewer points after.
    // Each segment's pieces are then finished depth first, which keeps the splits of
    // one segment consistent (processing all pieces by length costs 20% more points).
    let sq = |pc: &Piece| {
        let (a, b) = (dt.points[pc.u as usize], dt.points[pc.v as usize]);
        (0..3).map(|k| (a[k] - b[k]) * (a[k] - b[k])).sum::<f64>()
    };
    queue.sort_by(|x, y| sq(x).total_cmp(&sq(y)));
    // Recovered pieces are indexed by both endpoints: an insertion can only remove
    // edges between vertices of its cavity, so only those pieces are checked again.
    let mut scratch = Vec::new();
    // The last insertion's cavity: its vertices, and a stamp per vertex for membership.
    let mut cavity = Cavity::new();
    // Vertices of some insertion's cavity: an edge between two untouched vertices that
    // was in the mesh at the start still is.
    let mut touched = vec![false; dt.points.len()];
    loop {
        while let Some(pc) = queue.pop() {
            let hit = |v: VertexId| touched.get(v as usize).copied().unwrap_or(true);
            let untouched = !(hit(pc.u) && hit(pc.v));
            if (untouched && was_present(pc.u, pc.v)) || edge_between(dt, pc.u, pc.v, &mut scratch)
            {
                done.push(pc);
                continue;
            }
            if cancel.load(std::sync::atomic::Ordering::Relaxed) {
                return Err(MeshError::Failed(super::CANCELLED.into()));
            }
            if steiner >= max_steiner {
                return Err(MeshError::Failed(format!(
                    "segment recovery needs more than {max_steiner} Steiner points \
                     (raise the limit with -S)"
                )));
            }
            let [a, b] = ends[pc.seg];
            let owners = Owners {
                seg_of: &seg_of,
                ends: &ends,
            };
            let s = split_parameter(dt, pc, [a, b], &acute, &owners, &mut scratch);
            let pa = dt.points[a as usize];
            let pb = dt.points[b as usize];
            let x: Point = std::array::from_fn(|k| pa[k] + (pb[k] - pa[k]) * s);
            if x == dt.points[pc.u as usize] || x == dt.points[pc.v as usize] {
                return Err(MeshError::Failed(format!(
                    "segment ({}, {}) cannot be split finely enough in floating point",
                    dt.orig[a as usize], dt.orig[b as usize]
                )));
            }
            // The point lies on the piece: the walk to it starts at the piece's end.
            dt.start_walk_at(pc.u);
            let Some(w) = dt.insert_steiner_noting(x, *next_pert, Some(&mut cavity.removed))?
            else {
                return Err(MeshError::InvalidPlc(format!(
                    "segment ({}, {}) passes through another vertex or segment near {:?}",
                    dt.orig[a as usize], dt.orig[b as usize], x
                )));
            };
            *next_pert += 1;
            steiner += 1;
            splits[pc.seg].push((s, w));
            note_segment(&mut seg_of, w, pc.seg);
            cavity.of_last_insertion(dt, w);
            for &x in &cavity.verts {
                if let Some(t) = touched.get_mut(x as usize) {
                    *t = true;
                }
            }
            done.recheck(dt, &cavity, w, &mut queue);
            // Every cavity vertex is joined to the new one: a half whose other end is
            // one is an edge now, and is recovered without a look at the mesh.
            let halves = [
                Piece {
                    seg: pc.seg,
                    s0: pc.s0,
                    u: pc.u,
                    s1: s,
                    v: w,
                },
                Piece {
                    seg: pc.seg,
                    s0: s,
                    u: w,
                    s1: pc.s1,
                    v: pc.v,
                },
            ];
            for (half, end) in halves.into_iter().zip([pc.u, pc.v]) {
                if cavity.holds(end) {
                    done.push(half);
                } else {
                    queue.push(half);
                }
            }
        }
        // A last full check, in case a piece was lost without a recorded cavity (none
        // can be if nothing was inserted).
        if steiner > 0 {
            done.recheck_all(dt, &mut queue);
        }
        if queue.is_empty() {
            break;
        }
    }
    let chains = ends
        .iter()
        .zip(splits.iter_mut())
        .map(|(&[a, b], sp)| {
            sp.sort_by(|x, y| x.0.total_cmp(&y.0));
            let mut chain = Vec::with_capacity(sp.len() + 2);
            chain.push(a);
            chain.extend(sp.iter().map(|&(_, w)| w));
            chain.push(b);
            chain
        })
        .collect();
    Ok(Subsegments {
        chains,
        steiner_points: steiner,
    })
}

/// The pieces recovered so far, with the pieces at each vertex (indexed from the first
/// [`Recovered::recheck`] on: most segments need no Steiner point, and then no index).
#[derive(Default)]
struct Recovered {
    pieces: Vec<Option<Piece>>,
    /// Indexed by vertex: every cavity vertex is looked up after every insertion, and
    /// a hash map's lookups cost more than the rest of the check.
    at: Option<Vec<Vec<usize>>>,
}

/// Notes piece `i` at its two ends.
fn note_at(at: &mut Vec<Vec<usize>>, pc: &Piece, i: usize) {
    let top = pc.u.max(pc.v) as usize;
    if at.len() <= top {
        at.resize_with(top + 1, Vec::new);
    }
    at[pc.u as usize].push(i);
    at[pc.v as usize].push(i);
}

impl Recovered {
    fn push(&mut self, pc: Piece) {
        let i = self.pieces.len();
        self.pieces.push(Some(pc));
        if let Some(at) = &mut self.at {
            note_at(at, &pc, i);
        }
    }

    /// Sends back to `queue` the pieces between two `cavity` vertices that are no
    /// longer edges (`new` is the vertex just inserted, which no recovered piece has).
    fn recheck(&mut self, dt: &Delaunay, cavity: &Cavity, new: VertexId, queue: &mut Vec<Piece>) {
        let at = self.at.get_or_insert_with(|| {
            let mut at: Vec<Vec<usize>> = Vec::new();
            at.resize_with(dt.points.len(), Vec::new);
            for (i, pc) in self.pieces.iter().enumerate() {
                if let Some(pc) = pc {
                    note_at(&mut at, pc, i);
                }
            }
            at
        });
        for k in 0..cavity.verts.len() {
            let x = cavity.verts[k];
            if x == new {
                continue;
            }
            let Some(list) = at.get_mut(x as usize).filter(|l| !l.is_empty()) else {
                continue;
            };
            list.retain(|&i| self.pieces[i].is_some());
            for &i in list.iter() {
                let Some(pc) = self.pieces[i] else { continue };
                let other = if pc.u == x { pc.v } else { pc.u };
                // Each piece is seen from both ends; check it from the lower one.
                if other < x && cavity.holds(other) {
                    continue;
                }
                if cavity.holds(other) && !cavity.keeps_edge(dt, pc.u, pc.v) {
                    self.pieces[i] = None;
                    queue.push(pc);
                }
            }
        }
    }

    /// Sends back to `queue` every piece that is no longer an edge (one pass over the
    /// tets).
    fn recheck_all(&mut self, dt: &Delaunay, queue: &mut Vec<Piece>) {
        let live = self.pieces.iter().flatten();
        let mut present =
            crate::mesh::ListedEdges::new(dt.points.len(), live.map(|pc| edge_key(pc.u, pc.v)));
        present.mark(dt.mesh.real_tets().map(|t| dt.mesh.verts(t)));
        for slot in &mut self.pieces {
            if let Some(pc) = *slot {
                if !present.found(pc.u, pc.v) {
                    *slot = None;
                    queue.push(pc);
                }
            }
        }
    }
}

/// The vertices of the last insertion's cavity, each once, with a stamped set for
/// membership (sorting them cost more than the insertion's other bookkeeping).
struct Cavity {
    verts: Vec<VertexId>,
    members: super::cavity::SlotSet,
    /// The vertex the insertion added.
    new: VertexId,
    /// The vertices of the tets the insertion replaced.
    removed: Vec<[VertexId; 4]>,
}

impl Cavity {
    fn new() -> Self {
        Cavity {
            verts: Vec::new(),
            members: super::cavity::SlotSet::new(0),
            new: crate::mesh::GHOST,
            removed: Vec::new(),
        }
    }

    /// Takes the cavity of `dt`'s last insertion, that of vertex `new`.
    fn of_last_insertion(&mut self, dt: &Delaunay, new: VertexId) {
        self.members.clear(dt.points.len());
        self.verts.clear();
        self.new = new;
        for &(t, _) in dt.last_created() {
            for x in dt.mesh.verts(t) {
                if x != crate::mesh::GHOST && self.members.insert(x) {
                    self.verts.push(x);
                }
            }
        }
    }

    /// Is `a`–`b`, a mesh edge before the insertion between two vertices of its cavity,
    /// still one? Edges of the boundary faces are: those at `a` are found by turning
    /// once around the edge from `a` to the new vertex, whose tets are all new (cheaper
    /// than filing every boundary edge in a hash set, which cost 7% of segment recovery
    /// on CAD models). Any other edge of a removed tet went with it, and an edge of none
    /// is untouched.
    fn keeps_edge(&self, dt: &Delaunay, a: VertexId, b: VertexId) -> bool {
        on_rim(dt, a, self.new, b)
            || !self
                .removed
                .iter()
                .any(|t| t.contains(&a) && t.contains(&b))
    }

    /// Is `v` a vertex of the cavity?
    fn holds(&self, v: VertexId) -> bool {
        self.members.contains(&v)
    }
}

/// Is `b` a vertex of the tets around edge `a`–`w`, turning once around it from the tet
/// that `a` points at? Right after `w` was inserted, that tet is one of the new ones
/// (so it holds `w`), and the tets around the edge are the new tets on `a`'s boundary
/// faces. False, never wrongly true, when the walk finds anything else: `keeps_edge`
/// then asks the removed tets, which at worst sends a kept piece back to be looked at.
fn on_rim(dt: &Delaunay, a: VertexId, w: VertexId, b: VertexId) -> bool {
    let Some(start) = dt.mesh.vertex_tet(a) else {
        return false;
    };
    let mut t = start;
    let mut prev = None;
    // A ring longer than this is left to the removed tets' test (see `keeps_edge`).
    for _ in 0..64 {
        let v = dt.mesh.verts(t);
        if !v.contains(&a) || !v.contains(&w) {
            return false;
        }
        if v.contains(&b) {
            return true;
        }
        // Across one of the two faces through the edge, not back where the walk came from.
        let mut next = None;
        for (i, &x) in v.iter().enumerate() {
            if x == a || x == w {
                continue;
            }
            let n = dt.mesh.adj(crate::mesh::FaceRef::new(t, i)).tet();
            if Some(n) != prev {
                next = Some(n);
                break;
            }
        }
        let Some(n) = next else {
            return false;
        };
        prev = Some(t);
        t = n;
        if t == start {
            return false;
        }
    }
    false
}

/// True if `a`–`b` is a mesh edge, walking around the newer vertex: Steiner points have
/// small stars, while input vertices of CAD models can have huge fans.
fn edge_between(
    dt: &Delaunay,
    a: VertexId,
    b: VertexId,
    scratch: &mut Vec<crate::mesh::TetId>,
) -> bool {
    dt.has_edge(a.max(b), a.min(b), scratch)
}

/// Vertices where two segments meet at less than 90 degrees.
fn acute_vertices(dt: &Delaunay, ends: &[[VertexId; 2]]) -> Vec<bool> {
    let mut incident: Vec<(VertexId, VertexId)> = Vec::with_capacity(ends.len() * 2);
    for &[a, b] in ends {
        incident.push((a, b));
        incident.push((b, a));
    }
    incident.sort_unstable();
    let mut acute = vec![false; dt.points.len()];
    let p = |v: VertexId| dt.points[v as usize];
    let mut i = 0;
    while i < incident.len() {
        let mut j = i + 1;
        while j < incident.len() && incident[j].0 == incident[i].0 {
            j += 1;
        }
        let c = p(incident[i].0);
        let dir = |v: VertexId| {
            let q = p(v);
            [q[0] - c[0], q[1] - c[1], q[2] - c[2]]
        };
        'pairs: for x in i..j {
            for y in x + 1..j {
                let (d1, d2) = (dir(incident[x].1), dir(incident[y].1));
                if d1[0] * d2[0] + d1[1] * d2[1] + d1[2] * d2[2] > 0.0 {
                    acute[incident[i].0 as usize] = true;
                    break 'pairs;
                }
            }
        }
        i = j;
    }
    acute
}

/// Which segment each Steiner point lies on (`u32::MAX` for other vertices), and the
/// segments' ends.
struct Owners<'a> {
    seg_of: &'a [u32],
    ends: &'a [[VertexId; 2]],
}

/// Records that Steiner point `w` lies on segment `seg`.
fn note_segment(seg_of: &mut Vec<u32>, w: VertexId, seg: usize) {
    if seg_of.len() <= w as usize {
        seg_of.resize(w as usize + 1, u32::MAX);
    }
    seg_of[w as usize] = seg as u32;
}

/// Where to split a piece: on a power-of-two sphere around an acute segment endpoint,
/// else at the middle.
fn split_parameter(
    dt: &Delaunay,
    pc: Piece,
    [a, b]: [VertexId; 2],
    acute: &[bool],
    owners: &Owners,
    scratch: &mut Vec<crate::mesh::TetId>,
) -> f64 {
    let mid = 0.5 * (pc.s0 + pc.s1);
    let from_a = pc.u == a && acute[a as usize];
    let from_b = pc.v == b && acute[b as usize];
    if from_a == from_b {
        return reference_split(dt, pc, [a, b], owners, scratch).unwrap_or(mid);
    }
    let pa = dt.points[a as usize];
    let pb = dt.points[b as usize];
    let len = norm(&sub(&pb, &pa));
    let piece = len * (pc.s1 - pc.s0);
    if !(piece > 0.0 && piece.is_finite()) {
        return mid;
    }
    // The power of two nearest to half the piece lies within [piece/3, 2 piece/3].
    let r = 2f64.powi((piece * 0.5).log2().round() as i32);
    let t = r / len;
    let s = if from_a { pc.s0 + t } else { pc.s1 - t };
    if s > pc.s0 && s < pc.s1 {
        s
    } else {
        mid
    }
}

/// The scale of split points placed at a shared end's distance: the distance is
/// multiplied by `1 + SHARED_END_SCALE·(1 + f)`, `f` in [0, 1) distinct per segment (see
/// [`shared_end_split`]).
const SHARED_END_SCALE: f64 = 1e-9;

/// Where to split a piece whose reference point `r` is a Steiner point on a segment that
/// shares an end with this one (TetGen's rule): at `r`'s distance from that end. Split
/// at `r`'s projection instead, two segments meeting at a small angle chase each other's
/// split points towards their shared end, each new point encroaching upon the other's
/// piece a little nearer; at equal distances their points face each other and neither
/// encroaches. Equal distances on both segments would make the four points of two such
/// pairs an isosceles trapezoid, cocircular, whose diagonal in the facet rounding decides
/// (flip insertion then got stuck where the facet's triangulation chose the other one,
/// and shims formed in such folds): the distance is therefore scaled by a factor that
/// differs per segment by about 1e-9, far above rounding and far below the squared
/// angles between segments that the points must keep clear of each other's pieces.
fn shared_end_split(
    dt: &Delaunay,
    pc: Piece,
    [a, b]: [VertexId; 2],
    len: f64,
    owners: &Owners,
    r: VertexId,
) -> Option<f64> {
    let other = *owners.seg_of.get(r as usize)?;
    if other == u32::MAX || other as usize == pc.seg {
        return None;
    }
    let ends = owners.ends[other as usize];
    let dist = |v: VertexId| norm(&sub(&dt.points[r as usize], &dt.points[v as usize]));
    // The golden ratio's fractional multiples spread the segments' factors over [0, 1).
    let f = (pc.seg as f64 * 0.618_033_988_749_895).fract();
    let scale = 1.0 + SHARED_END_SCALE * (1.0 + f);
    if ends.contains(&a) {
        Some(dist(a) * scale / len)
    } else if ends.contains(&b) {
        Some(1.0 - dist(b) * scale / len)
    } else {
        None
    }
}

/// The split point from the piece's reference point (Si & Gärtner): the neighbour of
/// its end `u` that sees the piece under the widest angle from inside its diametral
/// sphere, projected onto the segment (or, if it lies on a segment sharing an end with
/// this one, at its distance from that end: [`shared_end_split`]). Both halves then leave
/// that vertex on or outside their diametral spheres, so one split often suffices. A
/// projection close to an end would make a needlessly short edge: there the split goes on
/// the sphere centred at that end through the reference point instead, which also leaves
/// the reference point outside the short half's diametral sphere and no shorter than an
/// edge already there.
fn reference_split(
    dt: &Delaunay,
    pc: Piece,
    [a, b]: [VertexId; 2],
    owners: &Owners,
    scratch: &mut Vec<crate::mesh::TetId>,
) -> Option<f64> {
    let p = |v: VertexId| dt.points[v as usize];
    let (pu, pv) = (p(pc.u), p(pc.v));
    let (pa, pb) = (p(a), p(b));
    let d: [f64; 3] = std::array::from_fn(|k| pb[k] - pa[k]);
    let dd: f64 = d.iter().map(|x| x * x).sum();
    if !(dd > 0.0 && dd.is_finite()) {
        return None;
    }
    dt.star(pc.u, scratch);
    let mut best: Option<(f64, f64)> = None; // (cosine of the angle, parameter)
    let mut best_vertex = crate::mesh::GHOST;
    let mut dist = (0.0, 0.0); // the reference point's distances to u and v
    for &t in scratch.iter() {
        for &x in &dt.mesh.verts(t) {
            if x == crate::mesh::GHOST || x == pc.u || x == pc.v {
                continue;
            }
            let q = p(x);
            let e: [f64; 3] = std::array::from_fn(|k| pu[k] - q[k]);
            let f: [f64; 3] = std::array::from_fn(|k| pv[k] - q[k]);
            let dot: f64 = (0..3).map(|k| e[k] * f[k]).sum();
            if dot >= 0.0 {
                continue; // not inside the diametral sphere
            }
            let ne: f64 = e.iter().map(|x| x * x).sum::<f64>().sqrt();
            let nf: f64 = f.iter().map(|x| x * x).sum::<f64>().sqrt();
            let cos = dot / (ne * nf);
            let s = (0..3).map(|k| (q[k] - pa[k]) * d[k]).sum::<f64>() / dd;
            if best.is_none_or(|(c, _)| cos < c) {
                best = Some((cos, s));
                dist = (ne, nf);
                best_vertex = x;
            }
        }
    }
    let (_, s) = best?;
    let w = pc.s1 - pc.s0;
    let len = dd.sqrt();
    let s = shared_end_split(dt, pc, [a, b], len, owners, best_vertex).unwrap_or(s);
    let s = if s < pc.s0 + 0.1 * w {
        pc.s0 + dist.0 / len
    } else if s > pc.s1 - 0.1 * w {
        pc.s1 - dist.1 / len
    } else {
        s
    };
    Some(s.clamp(pc.s0 + 0.01 * w, pc.s1 - 0.01 * w))
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geom::lcg;

    #[test]
    fn long_segments_through_a_cloud_are_recovered() {
        let mut s = 3u64;
        let mut pts: Vec<Point> = (0..400)
            .map(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)])
            .collect();
        // Two long segments meeting at an acute angle at point 400.
        pts.push([-0.1, -0.1, -0.1]);
        pts.push([1.1, 1.1, 1.05]);
        pts.push([1.1, 1.0, 1.1]);
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let mut next = pts.len() as u32;
        let segs = [[400, 401], [400, 402]];
        let rec = recover_segments(
            &mut dt,
            &segs,
            pts.len(),
            &mut next,
            10_000,
            &[],
            &Default::default(),
        )
        .unwrap();
        assert!(rec.steiner_points > 0);
        dt.mesh.check_links().unwrap();
        let mut scratch = Vec::new();
        for chain in &rec.chains {
            for w in chain.windows(2) {
                assert!(dt.has_edge(w[0], w[1], &mut scratch));
            }
        }
        // Around the acute vertex, the first subsegments have power-of-two lengths.
        let apex = dt.points[rec.chains[0][0] as usize];
        for chain in &rec.chains {
            let q = dt.points[chain[1] as usize];
            let d =
                ((q[0] - apex[0]).powi(2) + (q[1] - apex[1]).powi(2) + (q[2] - apex[2]).powi(2))
                    .sqrt();
            let l = d.log2();
            assert!(
                (l - l.round()).abs() < 1e-9,
                "length {d} is not a power of two"
            );
        }
    }

    #[test]
    fn segments_at_a_small_angle_are_split_at_one_distance_from_their_shared_end() {
        // Two segments leave point 0 one degree apart, through a cloud that hides both;
        // two short segments make their far ends acute too, so that their first pieces
        // are split from reference points. A point on one segment is the reference of
        // the other's piece beside it: the split goes at its distance from point 0 (up
        // to the per-segment scale of about 1e-9), not at its projection (cos 1° nearer),
        // so that the two segments' split points face each other in pairs.
        let a = 1f64.to_radians();
        let mut pts: Vec<Point> = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [a.cos(), a.sin(), 0.0]];
        pts.push([1.0, -0.01, 0.0]);
        pts.push([a.cos(), a.sin() + 0.01, 0.0]);
        let mut s = 5u64;
        while pts.len() < 400 {
            let q = [lcg(&mut s), lcg(&mut s) - 0.5, 0.2 * (lcg(&mut s) - 0.5)];
            if q[2].abs() > 1e-3 {
                pts.push(q);
            }
        }
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let mut next = pts.len() as u32;
        let segs = [[0, 1], [0, 2], [1, 3], [2, 4]];
        let rec = recover_segments(
            &mut dt,
            &segs,
            pts.len(),
            &mut next,
            100_000,
            &[],
            &Default::default(),
        )
        .unwrap();
        assert!(
            rec.steiner_points < 100,
            "{} Steiner points",
            rec.steiner_points
        );
        let o = dt.points[rec.chains[0][0] as usize];
        let radii = |chain: &[VertexId]| -> Vec<f64> {
            chain[1..chain.len() - 1]
                .iter()
                .map(|&v| {
                    let q = dt.points[v as usize];
                    norm(&sub(&q, &o))
                })
                .collect()
        };
        let (r0, r1) = (radii(&rec.chains[0]), radii(&rec.chains[1]));
        // Those off the power-of-two shells around point 0 were placed from references.
        let off_shells = |r: f64| (r.log2() - r.log2().round()).abs() > 1e-9;
        let mut paired = 0;
        for &r in r1.iter().filter(|&&r| off_shells(r)) {
            let near = r0
                .iter()
                .map(|&q| (q - r).abs() / r)
                .fold(f64::INFINITY, f64::min);
            if near < 1e-8 {
                // Near, but not at the same distance: no isosceles trapezoids.
                assert!(near > 1e-12, "radius {r} repeated exactly");
                paired += 1;
            }
        }
        assert!(
            paired >= 5,
            "{paired} paired split points in {r0:?} and {r1:?}"
        );
    }

    #[test]
    fn the_rim_and_the_removed_tets_tell_which_edges_an_insertion_kept() {
        let mut s = 11u64;
        let pts: Vec<Point> = (0..300)
            .map(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)])
            .collect();
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let mut cavity = Cavity::new();
        let mut scratch = Vec::new();
        let (mut on, mut off) = (0, 0);
        for k in 0..40u32 {
            let p = [lcg(&mut s), lcg(&mut s), lcg(&mut s)];
            let had: rustc_hash::FxHashSet<(VertexId, VertexId)> = dt
                .mesh
                .real_tets()
                .flat_map(|t| {
                    let v = dt.mesh.verts(t);
                    crate::mesh::EDGE_VERTS.map(|(i, j)| edge_key(v[i], v[j]))
                })
                .collect();
            let w = dt
                .insert_steiner_noting(p, 300 + k, Some(&mut cavity.removed))
                .unwrap()
                .unwrap();
            cavity.of_last_insertion(&dt, w);
            let mut rim = rustc_hash::FxHashSet::default();
            for &(t, f) in dt.last_created() {
                let v = dt.mesh.face_verts(t, f);
                for i in 0..3 {
                    rim.insert(edge_key(v[i], v[(i + 1) % 3]));
                }
            }
            for &a in &cavity.verts {
                for &b in &cavity.verts {
                    if a == b || a == w || b == w {
                        continue;
                    }
                    let found = on_rim(&dt, a, w, b);
                    // Exactly the boundary edges: a Delaunay cavity is a ball.
                    assert_eq!(found, rim.contains(&edge_key(a, b)), "{a}-{b}");
                    if found {
                        assert!(dt.has_edge(a, b, &mut scratch));
                        on += 1;
                    } else {
                        off += 1;
                    }
                    // For an edge that was there, whether it still is.
                    if had.contains(&edge_key(a, b)) {
                        assert_eq!(
                            cavity.keeps_edge(&dt, a, b),
                            dt.has_edge(a, b, &mut scratch)
                        );
                    }
                }
            }
        }
        assert!(on > 0 && off > 0);
    }

    #[test]
    fn a_vertex_on_a_segment_is_an_invalid_plc() {
        let mut pts: Vec<Point> = vec![[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        pts.extend([
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
        ]);
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let mut next = pts.len() as u32;
        let e = recover_segments(
            &mut dt,
            &[[0, 1]],
            pts.len(),
            &mut next,
            100,
            &[],
            &Default::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("passes through"), "{e}");
    }
}
