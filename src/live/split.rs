//! Splits of subsegments and subfaces in place: where a point lands exactly on one, and
//! where a point encroaches upon one (Delaunay refinement's rule), with the split point
//! chosen by Ruppert's and Shewchuk's rules (middles, power-of-two shells around input
//! vertices, circumcentres of subfaces unless they encroach upon a subsegment).

use super::{Cdt, InsertError, Tets};
use crate::constrained::cdt::{edge_key, face_key};
use crate::constrained::free;
use crate::constrained::slivers::{DomainOf, FacetIndex, Search};
use crate::delaunay::Walled;
use crate::geom::encroach::{
    circumcenter, in_diametral_ball, in_equatorial_ball, near_segment, near_triangle,
};
use crate::geom::{norm, sub, Point};
use crate::mesh::{FaceRef, TetId, VertexId, EDGE_VERTS, FACE_VERTS, GHOST};

/// A constraint that a point lies on exactly.
#[derive(Clone, Copy)]
pub(super) enum On {
    /// Strictly inside subsegment `a`–`b`.
    Subsegment(VertexId, VertexId),
    /// Strictly inside this subface.
    Subface([VertexId; 3]),
}

impl On {
    /// Whether subface `k` (a sorted key) lies on this constraint: through the
    /// subsegment, or the subface itself. A cavity of a point on the constraint is open
    /// through these, so that both sides count whichever side the point is located on.
    pub(super) fn opens(&self, k: &[VertexId; 3]) -> bool {
        match *self {
            On::Subsegment(a, b) => k.contains(&a) && k.contains(&b),
            On::Subface(f) => *k == face_key(f),
        }
    }
}

/// The constraint of tet `t` (which holds `p`, possibly on its boundary) that `p` lies on,
/// exactly or within distance `tol` of it (see [`Cdt::build`]), if any.
pub(super) fn on_constraint(tets: &Tets, t: TetId, p: &Point, tol: f64) -> Option<On> {
    let v = tets.dt.mesh.verts(t);
    let pt = |x: VertexId| &tets.dt.points[x as usize];
    for &(i, j) in &EDGE_VERTS {
        let (a, b) = (v[i], v[j]);
        if a != GHOST
            && b != GHOST
            && tets.subsegs.contains_key(&edge_key(a, b))
            && near_segment(pt(a), pt(b), p, tol)
        {
            return Some(On::Subsegment(a, b));
        }
    }
    (0..4).find_map(|f| {
        let fv = FACE_VERTS[f].map(|k| v[k]);
        let is_sub = !fv.contains(&GHOST) && tets.subfaces.contains_key(&face_key(fv));
        (is_sub && near_triangle(pt(fv[0]), pt(fv[1]), pt(fv[2]), p, tol))
            .then_some(On::Subface(fv))
    })
}

/// What the walled cavity of a point shows (see [`encroached_constraints`]).
pub(super) struct Encroachment {
    /// A subsegment whose diametral ball holds the point.
    pub seg: Option<(VertexId, VertexId)>,
    /// A subface whose equatorial ball holds it.
    pub face: Option<[VertexId; 3]>,
    /// The distance to the cavity's nearest vertex: the shortest edge its insertion
    /// would make (0 if the point is a vertex).
    pub nearest: f64,
}

/// A subsegment of the walled cavity of `p` whose diametral ball holds `p`, if any (the
/// one with the lowest key, so that the choice does not depend on hashing), and the
/// distance to the cavity's nearest vertex. `p` lies on constraint `on`, if given: that
/// subsegment is left out, and the cavity is open through the subfaces on it. With
/// `faces`, also a subface of it whose equatorial ball holds `p` (the lowest key).
pub(super) fn encroached_constraints(
    tets: &mut Tets,
    p: &Point,
    pert: u32,
    on: Option<On>,
    faces: bool,
) -> Encroachment {
    // A split point lies on the constraint `on`, which it does not encroach upon.
    let skip = match on {
        Some(On::Subsegment(a, b)) => Some(edge_key(a, b)),
        _ => None,
    };
    let open = |k: &[VertexId; 3]| on.is_some_and(|o| o.opens(k));
    let Ok(conflict) = tets.walled_conflict_open(*p, pert, open) else {
        return Encroachment {
            seg: None,
            face: None,
            nearest: 0.0,
        };
    };
    let pt = |x: VertexId| &tets.dt.points[x as usize];
    let mut seg: Option<(VertexId, VertexId)> = None;
    let mut face: Option<[VertexId; 3]> = None;
    // An empty cavity: the point coincides with a vertex.
    let mut nearest = if conflict.is_empty() {
        0.0
    } else {
        f64::INFINITY
    };
    for t in conflict {
        let v = tets.dt.mesh.verts(t);
        for &x in v.iter().filter(|&&x| x != GHOST) {
            nearest = nearest.min(norm(&sub(pt(x), p)));
        }
        for &(i, j) in &EDGE_VERTS {
            let e = edge_key(v[i], v[j]);
            if e.1 == GHOST || Some(e) == skip || !tets.subsegs.contains_key(&e) {
                continue;
            }
            if seg.is_none_or(|f| e < f) && in_diametral_ball(pt(e.0), pt(e.1), p) {
                seg = Some(e);
            }
        }
        if !faces {
            continue;
        }
        for fv in FACE_VERTS {
            let k = face_key(fv.map(|i| v[i]));
            if k.contains(&GHOST) || !tets.subfaces.contains_key(&k) {
                continue;
            }
            if face.is_none_or(|g| k < g) && in_equatorial_ball(pt(k[0]), pt(k[1]), pt(k[2]), p) {
                face = Some(k);
            }
        }
    }
    Encroachment { seg, face, nearest }
}

/// A subsegment that point `p` encroaches upon, if any (see [`encroached_constraints`]).
pub(super) fn encroached(cdt: &mut Cdt, p: &Point) -> Option<(VertexId, VertexId)> {
    let pert = cdt.next_pert;
    encroached_constraints(&mut cdt.tets, p, pert, None, false).seg
}

/// A split to make: of a subsegment, of an edge of a facet's triangulation (the
/// subfaces through it), or of a subface; at a given point, or at the rule's.
#[derive(Clone, Copy, PartialEq)]
enum Target {
    Edge(VertexId, VertexId, Option<Point>),
    Face([VertexId; 3], Option<Point>),
}

impl Cdt {
    /// Splits subsegment `a`–`b` at `p`, which lies on it, after the subsegments that
    /// `p` encroaches upon.
    pub(super) fn split_subsegment_at(
        &mut self,
        a: VertexId,
        b: VertexId,
        p: Point,
    ) -> Result<super::Step, InsertError> {
        self.run_splits(Target::Edge(a, b, Some(p)))
            .map(super::Step::Split)
    }

    /// Splits subface `f` at `p`, which lies in it, after the subsegments that `p`
    /// encroaches upon.
    pub(super) fn split_subface_at(
        &mut self,
        f: [VertexId; 3],
        p: Point,
    ) -> Result<super::Step, InsertError> {
        self.run_splits(Target::Face(f, Some(p)))
            .map(super::Step::Split)
    }

    /// Splits subsegment `a`–`b` (after those its split point encroaches upon); the
    /// number of points added.
    pub(super) fn split_subsegment(
        &mut self,
        a: VertexId,
        b: VertexId,
    ) -> Result<usize, InsertError> {
        self.run_splits(Target::Edge(a, b, None))
    }

    /// Splits subface `f` (or what its split point encroaches upon first); the number
    /// of points added.
    pub(super) fn split_subface(&mut self, f: [VertexId; 3]) -> Result<usize, InsertError> {
        self.run_splits(Target::Face(f, None))
    }

    /// Makes split `first`, with the splits its point needs first, queue-driven: a split
    /// point that encroaches upon a subsegment puts that subsegment's split in front of
    /// its own, and a subface's circumcentre that does is dropped for it (Shewchuk's
    /// rule). The number of points added.
    fn run_splits(&mut self, first: Target) -> Result<usize, InsertError> {
        let at = self.split_point(first);
        let r = self.run_split_stack(first);
        // A refused cascade is refused again from its start: the splits it needs wait on
        // each other (a subface in the way of a subsegment's split, whose split point
        // encroaches upon that subsegment), and many bad tets lead to the same start.
        if let (Err(InsertError::Refused(_) | InsertError::TooClose { .. }), Some(m), Some(set)) =
            (&r, at, &mut self.refused_splits)
        {
            set.insert(m.map(f64::to_bits));
        }
        r
    }

    /// [`Cdt::run_splits`] without remembering its refusal.
    fn run_split_stack(&mut self, first: Target) -> Result<usize, InsertError> {
        if self.keep_boundary {
            let at = self.split_point(first).unwrap_or([f64::NAN; 3]);
            return Err(InsertError::BoundaryKept(at));
        }
        let bound = self.split_bound();
        let mut stack = vec![first];
        let mut made = 0;
        while let Some(&top) = stack.last() {
            if made + stack.len() > bound {
                return Err(InsertError::TooManySplits {
                    point: self.split_point(top).unwrap_or([f64::NAN; 3]),
                    bound,
                });
            }
            self.check_budget()?;
            // A target an earlier split removed is gone.
            let Some(m) = self.split_point(top) else {
                stack.pop();
                continue;
            };
            // A point refused before is refused again at once, before its walled
            // cavity is sought (many bad tets lead to the same split).
            if self.was_refused(&m) {
                return Err(InsertError::Refused(m));
            }
            let on = match top {
                Target::Edge(a, b, _) => On::Subsegment(a, b),
                Target::Face(f, _) => On::Subface(f),
            };
            let pert = self.next_pert;
            let mut m = m;
            let found = encroached_constraints(&mut self.tets, &m, pert, Some(on), false);
            let mut nearest = found.nearest;
            if let Some(e) = found.seg {
                let seg = Target::Edge(e.0, e.1, None);
                if !stack.contains(&seg) {
                    if let Target::Face(..) = top {
                        stack.pop();
                    }
                    stack.push(seg);
                    continue;
                }
                // Each is in the other's ball. From one vertex at an angle under 60
                // degrees, Ruppert's concentric shells end that: this one is split on a
                // power-of-two shell around their common vertex, scaled to the shorter
                // of the two. Apart (skew and close), it is split as it is, as Ruppert's
                // algorithm does, and the other next: each split halves the pieces, and
                // pieces shorter than the distance between the two encroach upon
                // nothing. The insertion itself refuses to lose a subsegment.
                let moved = match top {
                    Target::Edge(a, b, None) => self.shell_point_between(a, b, e).unwrap_or(m),
                    Target::Edge(..) => m,
                    Target::Face(..) => return Err(InsertError::Refused(m)),
                };
                if moved != m {
                    m = moved;
                    nearest =
                        encroached_constraints(&mut self.tets, &m, pert, Some(on), false).nearest;
                }
            }
            // While refining, no split comes nearer a vertex than the insertion floor,
            // whatever asked for it (the termination argument, ARCHITECTURE.md).
            // A subface whose circumcentre lies beyond an edge is split at that edge.
            let redirect = match top {
                Target::Face(f, _) => match self.face_split(f, m) {
                    FaceSplit::Edge(a, b) => Some(Target::Edge(a, b, None)),
                    FaceSplit::At => None,
                },
                Target::Edge(..) => None,
            };
            if nearest < self.split_floor && redirect.is_none() {
                return Err(InsertError::TooClose {
                    point: m,
                    floor: self.split_floor,
                });
            }
            if self.was_refused(&m) {
                return Err(InsertError::Refused(m));
            }
            if let Some(edge) = redirect {
                // That edge already waits below: the splits would go round in a cycle.
                if stack.contains(&edge) {
                    return Err(InsertError::Refused(m));
                }
                stack.pop();
                stack.push(edge);
                continue;
            }
            let in_way = match top {
                Target::Edge(a, b, _) => self.remember_refusal(m, |c| c.split_edge(a, b, m))?,
                Target::Face(f, _) => self.remember_refusal(m, |c| c.split_face(f, m))?,
            };
            if let Some(g) = in_way {
                let t = Target::Face(g, None);
                if stack.contains(&t) {
                    return Err(InsertError::Refused(m));
                }
                stack.push(t);
                continue;
            }
            stack.pop();
            made += 1;
        }
        Ok(made)
    }

    /// Whether split point `m` was refused while refusals are remembered
    /// ([`Cdt::refused_splits`]).
    pub(super) fn was_refused(&self, m: &Point) -> bool {
        self.refused_splits
            .as_ref()
            .is_some_and(|r| r.contains(&m.map(f64::to_bits)))
    }

    /// Runs split `f` at `m`, and remembers `m` if the CDT refuses it while refusals
    /// are remembered ([`Cdt::refused_splits`]).
    fn remember_refusal<T>(
        &mut self,
        m: Point,
        f: impl FnOnce(&mut Self) -> Result<T, InsertError>,
    ) -> Result<T, InsertError> {
        let r = f(self);
        if let (Err(InsertError::Refused(_)), Some(set)) = (&r, &mut self.refused_splits) {
            set.insert(m.map(f64::to_bits));
        }
        r
    }

    /// The point a target is split at, or `None` if it is no longer in the CDT.
    fn split_point(&mut self, t: Target) -> Option<Point> {
        match t {
            Target::Edge(a, b, at) => {
                let e = edge_key(a, b);
                let present = self.tets.subsegs.contains_key(&e)
                    || (self.tets.has_edge(a, b) && !self.subfaces_around(a, b).is_empty());
                present.then(|| at.unwrap_or_else(|| self.edge_split_point(a, b)))
            }
            Target::Face(f, at) => {
                let present = self.tets.subfaces.contains_key(&face_key(f));
                present.then(|| {
                    at.unwrap_or_else(|| {
                        let [a, b, c] = f.map(|x| self.tets.dt.points[x as usize]);
                        circumcenter(&a, &b, &c)
                    })
                })
            }
        }
    }

    /// Where edge `a`–`b` is split: on the power-of-two shell around its end that is an
    /// input vertex, if only one is (Ruppert's concentric shells: pieces of segments that
    /// meet at a small angle are then split at equal distances from their common vertex,
    /// and never encroach upon each other), else at its middle. A shell radius `2^k` in
    /// `[L/3, 2L/3]` always exists, so no piece is shorter than a third.
    pub(super) fn edge_split_point(&self, a: VertexId, b: VertexId) -> Point {
        let n_input = self.plc.points.len() as u32;
        let input =
            |x: VertexId| self.tets.dt.orig[x as usize] < n_input || self.corners.contains(&x);
        let (pa, pb) = (
            self.tets.dt.points[a as usize],
            self.tets.dt.points[b as usize],
        );
        let (from, to) = match (input(a), input(b)) {
            (true, false) => (pa, pb),
            (false, true) => (pb, pa),
            _ => return std::array::from_fn(|k| 0.5 * (pa[k] + pb[k])),
        };
        let len = crate::geom::norm(&crate::geom::sub(&to, &from));
        let r = (len / 3.0).log2().ceil().exp2();
        let s = if r > 0.0 && r < len { r / len } else { 0.5 };
        std::array::from_fn(|k| from[k] + s * (to[k] - from[k]))
    }

    /// The point splitting `a`–`b` on the power-of-two shell around its end shared with
    /// subsegment `e`, with a radius in `[L/3, 2L/3]` of the shorter one's length `L`
    /// (`None` if they share no end).
    fn shell_point_between(
        &self,
        a: VertexId,
        b: VertexId,
        e: (VertexId, VertexId),
    ) -> Option<Point> {
        let (c, far) = if a == e.0 || a == e.1 {
            (a, b)
        } else if b == e.0 || b == e.1 {
            (b, a)
        } else {
            return None;
        };
        let other = if e.0 == c { e.1 } else { e.0 };
        let pt = |x: VertexId| self.tets.dt.points[x as usize];
        let len = |x: VertexId| crate::geom::norm(&crate::geom::sub(&pt(x), &pt(c)));
        let (l, shorter) = (len(far), len(far).min(len(other)));
        let r = (shorter / 3.0).log2().ceil().exp2();
        let s = if r > 0.0 && r < l { r / l } else { 0.5 };
        let (from, to) = (pt(c), pt(far));
        Some(std::array::from_fn(|k| from[k] + s * (to[k] - from[k])))
    }

    /// The subfaces through edge `a`–`b`.
    fn subfaces_around(&mut self, a: VertexId, b: VertexId) -> Vec<([VertexId; 3], u32)> {
        let mut star = Vec::new();
        self.tets.dt.star(a, &mut star);
        let mut out = Vec::new();
        for t in star {
            let v = self.tets.dt.mesh.verts(t);
            if !v.contains(&b) {
                continue;
            }
            for &c in &v {
                if c == a || c == b || c == GHOST {
                    continue;
                }
                let k = face_key([a, b, c]);
                if let Some(&f) = self.tets.subfaces.get(&k) {
                    if !out.iter().any(|&(x, _)| x == k) {
                        out.push((k, f));
                    }
                }
            }
        }
        out
    }

    /// How subface `f` is split at its circumcentre `m`: there, if `m` lies inside it (in
    /// its plane, seen along its normal); else at its edge facing `m`, whose diametral
    /// ball then holds `m` (the longest edge, opposite the obtuse corner).
    fn face_split(&self, f: [VertexId; 3], m: Point) -> FaceSplit {
        let p = f.map(|x| self.tets.dt.points[x as usize]);
        let n = crate::geom::cross(
            &crate::geom::sub(&p[1], &p[0]),
            &crate::geom::sub(&p[2], &p[0]),
        );
        for k in 0..3 {
            let (a, b) = (p[k], p[(k + 1) % 3]);
            let apex: Point = std::array::from_fn(|i| a[i] + n[i]);
            // `m` beyond edge a-b (the side away from the third corner).
            let side = crate::geom::orient3d(&a, &b, &apex, &m);
            let third = crate::geom::orient3d(&a, &b, &apex, &p[(k + 2) % 3]);
            if side == 0.0 || (side > 0.0) != (third > 0.0) {
                return FaceSplit::Edge(f[k], f[(k + 1) % 3]);
            }
        }
        FaceSplit::At
    }

    /// Splits edge `a`–`b` at `m` in place (see [`Cdt::split_in_facets`]); or names a
    /// subface of another facet in the way.
    fn split_edge(
        &mut self,
        a: VertexId,
        b: VertexId,
        m: Point,
    ) -> Result<Option<[VertexId; 3]>, InsertError> {
        let through = self.subfaces_around(a, b);
        self.split_in_facets(m, Some((a, b)), through)
    }

    /// Splits subface `f` at `m` (inside it) in place (see [`Cdt::split_in_facets`]);
    /// or names a subface of another facet in the way.
    fn split_face(
        &mut self,
        f: [VertexId; 3],
        m: Point,
    ) -> Result<Option<[VertexId; 3]>, InsertError> {
        let k = face_key(f);
        let Some(&facet) = self.tets.subfaces.get(&k) else {
            return Err(InsertError::Refused(m));
        };
        self.split_in_facets(m, None, vec![(k, facet)])
    }

    /// Puts split point `m` on edge `edge` (when it splits an edge) and in the subfaces
    /// `start` (those through the edge, or the one it splits) in place. In each facet,
    /// the subfaces whose equatorial balls hold `m` and that are reached from `start`
    /// without crossing a subsegment are replaced by a fan from `m` (a 2D Bowyer–Watson
    /// cavity: on a flat facet the facet's triangulation stays Delaunay). The 3D cavity
    /// grows from the tets on those subfaces (and around the edge), walled in by every
    /// other subface and by the hull, and is filled from `m`; flips then settle the faces
    /// that are not locally Delaunay.
    fn split_in_facets(
        &mut self,
        m: Point,
        edge: Option<(VertexId, VertexId)>,
        start: Vec<([VertexId; 3], u32)>,
    ) -> Result<Option<[VertexId; 3]>, InsertError> {
        if start.is_empty() && edge.is_none() {
            return Err(InsertError::Refused(m));
        }
        // Subfaces that the flips after a first try needed to move join the region, each
        // try adding one at least: the tries are bounded by the facets' subfaces.
        let mut forced: Vec<([VertexId; 3], u32)> = Vec::new();
        loop {
            let mut r = self.try_split_in_facets(m, edge, &start, &forced, true);
            if matches!(r, Err(InsertError::Refused(_))) {
                r = self.try_split_in_facets(m, edge, &start, &forced, false);
            }
            match r? {
                Ok(()) => return Ok(None),
                Err(g) if !forced.iter().any(|&(x, _)| x == g) => {
                    match self.tets.subfaces.get(&g) {
                        Some(&f) if start.iter().any(|&(_, sf)| sf == f) => forced.push((g, f)),
                        // Another facet's subface is in the way: it is split first.
                        Some(_) => return Ok(Some(g)),
                        None => return Err(InsertError::Refused(m)),
                    }
                }
                Err(_) => return Err(InsertError::Refused(m)),
            }
        }
    }

    /// One try of [`Cdt::split_in_facets`] with the subfaces `forced` in the region too:
    /// `Err(g)` (nothing changed) when the flips need subface `g` moved.
    fn try_split_in_facets(
        &mut self,
        m: Point,
        edge: Option<(VertexId, VertexId)>,
        start: &[([VertexId; 3], u32)],
        forced: &[([VertexId; 3], u32)],
        grow: bool,
    ) -> Result<Result<(), [VertexId; 3]>, InsertError> {
        let split_edge = edge.map(|(a, b)| edge_key(a, b));
        let mut region = start.to_vec();
        region.extend_from_slice(forced);
        let mut k = if grow { 0 } else { usize::MAX };
        while k < region.len() {
            let (g, facet) = region[k];
            k += 1;
            for i in 0..3 {
                let e = edge_key(g[i], g[(i + 1) % 3]);
                if Some(e) == split_edge || self.tets.subsegs.contains_key(&e) {
                    continue;
                }
                for (h, hf) in self.subfaces_around(e.0, e.1) {
                    if hf != facet || region.iter().any(|&(x, _)| x == h) {
                        continue;
                    }
                    let [x, y, z] = h.map(|v| self.tets.dt.points[v as usize]);
                    if crate::geom::encroach::in_equatorial_ball(&x, &y, &z, &m) {
                        region.push((h, hf));
                    }
                }
            }
        }
        // Edges of the region: inside it (two of its subfaces share them) or on its rim.
        let mut uses: rustc_hash::FxHashMap<(VertexId, VertexId), (usize, u32)> =
            Default::default();
        for &(g, facet) in &region {
            for i in 0..3 {
                let e = edge_key(g[i], g[(i + 1) % 3]);
                uses.entry(e).or_insert((0, facet)).0 += 1;
            }
        }
        let open: rustc_hash::FxHashSet<[VertexId; 3]> = region.iter().map(|&(g, _)| g).collect();
        let mut seeds: Vec<TetId> = Vec::new();
        if let Some((a, b)) = edge {
            let mut star = Vec::new();
            self.tets.dt.star(a, &mut star);
            seeds.extend(
                star.into_iter()
                    .filter(|&t| self.tets.dt.mesh.verts(t).contains(&b)),
            );
        }
        for &(g, _) in &region {
            let Some(side) = self.tets.face_ref(g[0], g[1], g[2]) else {
                return Err(InsertError::Refused(m));
            };
            seeds.push(side.tet());
            seeds.push(self.tets.dt.mesh.adj(side).tet());
        }
        seeds.sort_unstable();
        seeds.dedup();
        let subfaces = &self.tets.subfaces;
        let blocked = |v: [VertexId; 4], f: usize| {
            let fv = face_key(FACE_VERTS[f].map(|k| v[k]));
            !open.contains(&fv) && subfaces.contains_key(&fv)
        };
        // A subface of a facet being split, outside the region, would make a flat tet
        // (a shim) with `m`, which lies on that facet: the cavity stays off it.
        let facets: Vec<u32> = region.iter().map(|&(_, f)| f).collect();
        let unfillable = |fv: [VertexId; 3]| {
            let k = face_key(fv);
            !open.contains(&k) && subfaces.get(&k).is_some_and(|f| facets.contains(f))
        };
        let walled = self
            .tets
            .dt
            .insert_seeded(m, self.next_pert, &seeds, blocked, unfillable)
            .map_err(|_| InsertError::Refused(m))?;
        let Walled::Inserted {
            vertex,
            change,
            last,
        } = walled
        else {
            // A subface the cavity wraps around is in the way.
            return match self.tets.dt.wrapped_face(&m, blocked) {
                Some(g) if !g.contains(&GHOST) => Ok(Err(face_key(g))),
                _ => Err(InsertError::Refused(m)),
            };
        };
        let marker = split_edge.and_then(|e| self.tets.subsegs.remove(&e));
        if let (Some(k), Some((a, b))) = (marker, edge) {
            self.tets.subsegs.insert(edge_key(a, vertex), k);
            self.tets.subsegs.insert(edge_key(vertex, b), k);
        }
        for &(g, _) in &region {
            self.tets.subfaces.remove(&g);
        }
        let mut made = Vec::new();
        for (&e, &(n, facet)) in &uses {
            if n == 1 && Some(e) != split_edge {
                let s = face_key([e.0, e.1, vertex]);
                self.tets.subfaces.insert(s, facet);
                made.push(s);
            }
        }
        made.sort_unstable();
        let undo_tables = |cdt: &mut Tets| {
            for s in &made {
                cdt.subfaces.remove(s);
            }
            cdt.subfaces.extend(region.iter().copied());
            if let (Some(k), Some((a, b))) = (marker, edge) {
                cdt.subsegs.remove(&edge_key(a, vertex));
                cdt.subsegs.remove(&edge_key(vertex, b));
                cdt.subsegs.insert(edge_key(a, b), k);
            }
        };
        let settled = self.settle_split(m, (vertex, change, last), &made, &facets, undo_tables)?;
        if let (Ok(()), Some(_), Some((a, b)), Some(log)) =
            (&settled, marker, edge, &mut self.split_log)
        {
            log.push((edge_key(a, b), vertex));
        }
        Ok(settled)
    }

    /// After a split point went in and the constraint tables were updated: flips to
    /// local Delaunayhood; the split stands if they settle, no subsegment is lost and
    /// every new subface is a face. Otherwise the tets and (by `undo_tables`) the tables
    /// are restored.
    fn settle_split(
        &mut self,
        m: Point,
        (vertex, change, last): (VertexId, crate::delaunay::Change, TetId),
        made: &[[VertexId; 3]],
        facets: &[u32],
        undo_tables: impl Fn(&mut Tets),
    ) -> Result<Result<(), [VertexId; 3]>, InsertError> {
        let settled = free::settle(&mut self.tets, m, (vertex, change, last), true)
            .map_err(|_| InsertError::Refused(m))?;
        let in_way = match &settled {
            free::Inserted::Refused {
                wrapped: Some(g), ..
            } => Some(*g),
            _ => None,
        };
        let ok = matches!(settled, free::Inserted::Yes { .. })
            && made.iter().all(|s| self.tets.has_face(s[0], s[1], s[2]))
            && !self.makes_shim(vertex, facets)
            && !self.breaks_facets(vertex);
        let close = ok && self.too_close(vertex);
        if !ok || close {
            free::take_back(&mut self.tets, settled);
            undo_tables(&mut self.tets);
            return match in_way {
                _ if close => Err(InsertError::TooClose {
                    point: m,
                    floor: self.split_floor,
                }),
                Some(g) => Ok(Err(g)),
                None => Err(InsertError::Refused(m)),
            };
        }
        self.next_pert += 1;
        self.added += 1;
        Ok(Ok(()))
    }

    /// While refining: whether new vertex `v` has a neighbour nearer than the split
    /// floor. The cavity's vertices are checked before a split, but the flips that
    /// settle it can join `v` to vertices beyond it.
    pub(super) fn too_close(&self, v: VertexId) -> bool {
        if self.split_floor == 0.0 {
            return false;
        }
        let mut star = Vec::new();
        self.tets.dt.star(v, &mut star);
        let p = &self.tets.dt.points[v as usize];
        star.iter().any(|&t| {
            self.tets.dt.mesh.verts(t).iter().any(|&x| {
                x != v
                    && x != GHOST
                    && norm(&sub(&self.tets.dt.points[x as usize], p)) < self.split_floor
            })
        })
    }
}

impl Cdt {
    /// Whether a tet around `v` (which lies on each of `facets`) has its other three
    /// vertices on one of them too: a shim, flat within the facet, inside the domain.
    fn makes_shim(&mut self, v: VertexId, facets: &[u32]) -> bool {
        let mut star = Vec::new();
        self.tets.dt.star(v, &mut star);
        let mut on: rustc_hash::FxHashMap<VertexId, Vec<u32>> = Default::default();
        let mut around = Vec::new();
        for &t in &star {
            for x in self.tets.dt.mesh.verts(t) {
                if x == v || x == GHOST || on.contains_key(&x) {
                    continue;
                }
                self.tets.dt.star(x, &mut around);
                let mut fs: Vec<u32> = Vec::new();
                for &u in &around {
                    let w = self.tets.dt.mesh.verts(u);
                    for fv in FACE_VERTS {
                        let f = fv.map(|k| w[k]);
                        if !f.contains(&x) || f.contains(&GHOST) {
                            continue;
                        }
                        if let Some(&g) = self.tets.subfaces.get(&face_key(f)) {
                            if facets.contains(&g) && !fs.contains(&g) {
                                fs.push(g);
                            }
                        }
                    }
                }
                on.insert(x, fs);
            }
        }
        star.iter().any(|&t| {
            let w = self.tets.dt.mesh.verts(t);
            !w.contains(&GHOST)
                && facets.iter().any(|g| {
                    w.iter()
                        .all(|x| *x == v || on.get(x).is_some_and(|fs| fs.contains(g)))
                })
                && !self.reaches_hull(t)
        })
    }

    /// Whether the tets around `v` break a facet as the certifier and the referee see
    /// it, a Steiner point counting as on every facet whose slab holds it: a tet inside
    /// the domain that is a shim (flat, with all four vertices on one facet), or a face
    /// through or opposite `v` that is no subface yet lies on a facet, covering it twice.
    /// A point within the slab of a facet that is not flat, beside it (on a segment of a
    /// nearly coplanar neighbour, or a circumcentre just off it), makes these with the
    /// facet's vertices though no facet it lies on is split.
    pub(super) fn breaks_facets(&self, v: VertexId) -> bool {
        let (plc, prep) = &self.judged;
        let index = self
            .facet_index
            .get_or_init(|| FacetIndex::new(prep, &plc.points, self.plc.points.len()));
        let search = Search {
            prep,
            input: &plc.points,
            domain: DomainOf {
                holes: &plc.holes,
                regions: &plc.regions,
                keep_hull: self.opts.keep_hull,
            },
            index: Default::default(),
            shared: Some(index),
        };
        let mut star = Vec::new();
        self.tets.dt.star(v, &mut star);
        // Faces of the exterior (a layer of flat tets between a facet that is not flat
        // and the hull) are carved away with it.
        let inside = |t: TetId| !self.reaches_hull(t);
        if search.covering_face_in(&self.tets, v, &star, true, inside)
            || search.covering_face_in(&self.tets, v, &star, false, inside)
        {
            return true;
        }
        let dt = &self.tets.dt;
        star.iter().any(|&t| {
            let w = dt.mesh.verts(t);
            !w.contains(&GHOST)
                && index
                    .shim_facet(
                        &w.map(|x| dt.points[x as usize]),
                        w.map(|x| dt.orig[x as usize]),
                    )
                    .is_some()
                && inside(t)
        })
    }

    /// Whether tet `t` reaches the hull through faces that are no subfaces, within
    /// [`EXTERIOR_SEARCH`] tets: then it lies outside the domain (a flat tet between a
    /// facet that is not flat and the hull), and carving removes it. Interior tets never
    /// do when the subfaces enclose the domain; the search stops early for them.
    fn reaches_hull(&self, t: TetId) -> bool {
        let mesh = &self.tets.dt.mesh;
        let mut seen = vec![t];
        let mut k = 0;
        while k < seen.len() && seen.len() <= EXTERIOR_SEARCH {
            let u = seen[k];
            k += 1;
            let w = mesh.verts(u);
            for (f, fv) in FACE_VERTS.iter().enumerate() {
                let face = face_key(fv.map(|i| w[i]));
                if self.tets.subfaces.contains_key(&face) {
                    continue;
                }
                let n = mesh.adj(FaceRef::new(u, f)).tet();
                if mesh.is_ghost(n) {
                    return true;
                }
                if !seen.contains(&n) {
                    seen.push(n);
                }
            }
        }
        false
    }
}

/// The most tets [`Cdt::reaches_hull`] visits: exterior flat tets lie in thin layers
/// against the hull, a few tets deep; an interior tet would lead it through the whole
/// domain.
const EXTERIOR_SEARCH: usize = 64;

/// Where a subface is split.
enum FaceSplit {
    /// At its circumcentre.
    At,
    /// At its edge `a`–`b`, which the circumcentre lies beyond or on.
    Edge(VertexId, VertexId),
}
