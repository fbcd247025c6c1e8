//! Constrained Delaunay triangulation of one (nearly) planar facet.
//!
//! The facet's vertices are triangulated incrementally (BRIO + Hilbert order, Lawson
//! flips, inside a far "super triangle"), the constraint edges are recovered by flipping
//! the edges they cross (Sloan's method) and the Delaunay property is restored by flipping
//! the non-constrained edges that are not locally Delaunay. Finally the triangles reachable
//! from the super triangle or from a hole point without crossing a constraint are removed.
//!
//! All predicates are exact and cocircular ties are broken by the same symbolic
//! perturbation as [`crate::geom::insphere_sos`] (lifted weights, the lowest perturbation
//! index dominant), so the result on a flat facet is unique: the canonical CDT, whatever
//! the insertion order. The predicates depend on the facet:
//!
//! * **Axis-parallel** facets (the coordinate dropped by the projection, the one of the
//!   largest `|normal|` component, is the same for every vertex) use `orient2d` and
//!   `incircle` on the projected coordinates, with the perturbation of [`incircle_sos`].
//!   Projected circles are the true in-plane circles here.
//! * **Tilted flat** facets (exactly coplanar, or within `PLANAR_TOL` of the plane
//!   relative to their extent, e.g. with rounded Steiner points) use 3D predicates relative
//!   to an apex `e` above the facet on the side of `normal`: `orient3d(a, b, c, e)` and
//!   `insphere_sos(a, b, c, e, d)`. For coplanar vertices the sphere through `a, b, c, e`
//!   cuts the plane in the circumcircle of `abc`, so this is the exact in-plane in-circle
//!   test, and its ties are broken exactly like the 3D Delaunay tetrahedralization's (the
//!   apex's weight multiplies `orient3d(a, b, c, d) = 0`). Projecting onto a coordinate
//!   plane instead would turn circles into ellipses and give triangles that the 3D
//!   Delaunay tetrahedralization does not contain. The two predicates stay consistent
//!   for vertices slightly off the plane (they describe the regular triangulation of the
//!   vertices centrally projected from `e`), so flipping always terminates.
//! * **Other** (not flat) facets are projected orthogonally onto their plane (rounded
//!   in-plane coordinates) and triangulated with the exact 2D predicates.
//!
//! Triangles are returned counterclockwise as seen from the side `normal` points to (in
//! the projection used).

use crate::geom::{insphere_sos, orient3d, Point, Sign};
use rustc_hash::{FxHashMap, FxHashSet};
use std::collections::VecDeque;

/// No triangle (across the super triangle's outer edges).
const NONE: u32 = u32::MAX;
/// Perturbation index of the first super-triangle vertex (the next two follow); the apex
/// gets `u32::MAX`. They are higher than any vertex's, so they have the weakest weights.
const SUPER_PERT: u32 = u32::MAX - 3;

#[inline(always)]
fn c2(p: &[f64; 2]) -> robust::Coord<f64> {
    robust::Coord { x: p[0], y: p[1] }
}

/// Exact 2D in-circle test with the symbolic perturbation of [`crate::geom::insphere_sos`].
///
/// Follows Shewchuk's convention: for counterclockwise `a, b, c`, positive iff `d` lies
/// inside their circumcircle. On an exact tie each point's lifted height `x² + y²` is
/// lowered by an infinitesimal weight that is larger for lower `ids` (so the query with
/// the lowest id counts as inside). Returns `Zero` only if the points are not in general
/// position even under the perturbation (e.g. all collinear or repeated).
pub fn incircle_sos(p: [&[f64; 2]; 4], ids: [u32; 4]) -> Sign {
    let det = robust::incircle(c2(p[0]), c2(p[1]), c2(p[2]), c2(p[3]));
    if det != 0.0 {
        return Sign::of(det);
    }
    // The determinant |x y x²+y²−w 1| of the sorted rows loses w_k times the cofactor
    // (−1)^k · orient2d(others) of its lift entry; the lowest index dominates.
    crate::geom::predicates::perturbed_sign(p, ids, |r: &[&[f64; 2]; 3]| {
        Sign::of(robust::orient2d(c2(r[0]), c2(r[1]), c2(r[2]))).flip()
    })
}

/// The predicates of one mode, on local vertex numbers.
trait Geometry {
    /// Positive iff `a, b, c` are counterclockwise (seen from the normal's side); the sign
    /// is exact.
    fn orient(&self, a: u32, b: u32, c: u32) -> f64;
    /// For counterclockwise `a, b, c`: is `d` strictly inside the perturbed circumcircle?
    fn incircle(&self, a: u32, b: u32, c: u32, d: u32) -> bool;
}

/// Axis-parallel facets: exact 2D predicates on projected coordinates.
struct Flat {
    xy: Vec<[f64; 2]>,
    ids: Vec<u32>,
}

impl Geometry for Flat {
    #[inline]
    fn orient(&self, a: u32, b: u32, c: u32) -> f64 {
        let x = &self.xy;
        robust::orient2d(c2(&x[a as usize]), c2(&x[b as usize]), c2(&x[c as usize]))
    }

    #[inline]
    fn incircle(&self, a: u32, b: u32, c: u32, d: u32) -> bool {
        let x = &self.xy;
        let i = &self.ids;
        let p = [a, b, c, d].map(|v| &x[v as usize]);
        let ids = [a, b, c, d].map(|v| i[v as usize]);
        incircle_sos(p, ids) == Sign::Positive
    }
}

/// Other facets: exact 3D predicates relative to an apex above the facet.
struct Apex {
    p: Vec<Point>,
    ids: Vec<u32>,
    e: Point,
}

impl Geometry for Apex {
    #[inline]
    fn orient(&self, a: u32, b: u32, c: u32) -> f64 {
        let p = &self.p;
        orient3d(&p[a as usize], &p[b as usize], &p[c as usize], &self.e)
    }

    #[inline]
    fn incircle(&self, a: u32, b: u32, c: u32, d: u32) -> bool {
        let p = &self.p;
        let i = &self.ids;
        let pts = [
            &p[a as usize],
            &p[b as usize],
            &p[c as usize],
            &self.e,
            &p[d as usize],
        ];
        let ids = [
            i[a as usize],
            i[b as usize],
            i[c as usize],
            u32::MAX,
            i[d as usize],
        ];
        insphere_sos(pts, ids) == Sign::Positive
    }
}

/// Where a point lies in the triangulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Loc {
    /// Strictly inside triangle `t`.
    Inside(u32),
    /// In the interior of the edge of `t` opposite its vertex `i`.
    OnEdge(u32, usize),
    /// On a vertex.
    OnVertex(u32),
    /// Outside the super triangle.
    Outside,
}

/// How a constraint leaves its first endpoint.
enum Trace {
    /// Through a vertex on the constraint, joined to the start by an edge.
    Collinear(u32),
    /// Across these edges, up to this vertex (the far endpoint or a vertex on the way).
    Cross(Vec<(u32, u32)>, u32),
}

#[inline(always)]
fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

#[inline(always)]
fn nx(i: usize) -> usize {
    if i == 2 {
        0
    } else {
        i + 1
    }
}

#[inline(always)]
fn pv(i: usize) -> usize {
    if i == 0 {
        2
    } else {
        i - 1
    }
}

/// A triangulation of local vertices `0..n` inside the super triangle `n, n+1, n+2`.
struct Tri<G: Geometry> {
    g: G,
    /// Number of facet vertices.
    n: u32,
    /// Vertices of each triangle, counterclockwise.
    v: Vec<[u32; 3]>,
    /// `nb[t][i]`: the triangle across the edge opposite `v[t][i]`, or `NONE`.
    nb: Vec<[u32; 3]>,
    /// A triangle incident to each vertex (`NONE` before insertion).
    vtri: Vec<u32>,
    /// Where the next point location starts.
    last: u32,
    rng: u64,
}

impl<G: Geometry> Tri<G> {
    /// A triangulation holding only the super triangle (`n, n+1, n+2` counterclockwise).
    fn new(g: G, n: u32, total: usize) -> Self {
        let s = [n, n + 1, n + 2];
        let mut vtri = vec![NONE; total];
        for &x in &s {
            vtri[x as usize] = 0;
        }
        Tri {
            g,
            n,
            v: vec![s],
            nb: vec![[NONE; 3]],
            vtri,
            last: 0,
            rng: 0x9E37_79B9_7F4A_7C15,
        }
    }

    #[inline]
    fn rand3(&mut self) -> usize {
        self.rng ^= self.rng << 13;
        self.rng ^= self.rng >> 7;
        self.rng ^= self.rng << 17;
        (self.rng % 3) as usize
    }

    #[inline]
    fn idx(&self, t: u32, x: u32) -> usize {
        let v = &self.v[t as usize];
        if v[0] == x {
            0
        } else if v[1] == x {
            1
        } else {
            debug_assert_eq!(v[2], x);
            2
        }
    }

    #[inline]
    fn set(&mut self, t: u32, v: [u32; 3], nb: [u32; 3]) {
        self.v[t as usize] = v;
        self.nb[t as usize] = nb;
        for x in v {
            self.vtri[x as usize] = t;
        }
    }

    fn alloc(&mut self) -> u32 {
        self.v.push([NONE; 3]);
        self.nb.push([NONE; 3]);
        (self.v.len() - 1) as u32
    }

    /// In triangle `t` (if any), makes the link that pointed to `old` point to `new`.
    #[inline]
    fn relink(&mut self, t: u32, old: u32, new: u32) {
        if t != NONE {
            let nb = &mut self.nb[t as usize];
            for x in nb.iter_mut() {
                if *x == old {
                    *x = new;
                    return;
                }
            }
            debug_assert!(false, "relink: {t} is not adjacent to {old}");
        }
    }

    /// Locates point `p` (a local vertex number) by a remembering stochastic walk from
    /// `start`, falling back to a scan if the walk takes too long.
    fn locate(&mut self, p: u32, start: u32) -> Loc {
        let mut t = start;
        let mut from = NONE;
        let cap = 64 + 4 * self.v.len();
        for _ in 0..cap {
            let r = self.rand3();
            let mut next = NONE;
            for k in 0..3 {
                let i = (r + k) % 3;
                let nb = self.nb[t as usize][i];
                if nb == from && from != NONE {
                    continue;
                }
                let v = self.v[t as usize];
                if self.g.orient(v[nx(i)], v[pv(i)], p) < 0.0 {
                    if nb == NONE {
                        return Loc::Outside;
                    }
                    next = nb;
                    break;
                }
            }
            if next == NONE {
                return self.classify(t, p);
            }
            from = t;
            t = next;
        }
        for t in 0..self.v.len() as u32 {
            let v = self.v[t as usize];
            if (0..3).all(|i| self.g.orient(v[nx(i)], v[pv(i)], p) >= 0.0) {
                return self.classify(t, p);
            }
        }
        Loc::Outside
    }

    /// Where `p`, known to be in the closed triangle `t`, lies.
    fn classify(&self, t: u32, p: u32) -> Loc {
        let v = self.v[t as usize];
        let o = [0, 1, 2].map(|i| self.g.orient(v[nx(i)], v[pv(i)], p));
        let zeros: Vec<usize> = (0..3).filter(|&i| o[i] == 0.0).collect();
        match zeros.len() {
            0 => Loc::Inside(t),
            1 => Loc::OnEdge(t, zeros[0]),
            _ => {
                let j = (0..3).find(|&i| o[i] != 0.0).unwrap_or(0);
                Loc::OnVertex(v[j])
            }
        }
    }

    /// Inserts local vertex `p`; `Err(v)` if it coincides with vertex `v` (`Err(NONE)` if
    /// it lies outside the super triangle).
    fn insert(&mut self, p: u32) -> Result<(), u32> {
        let mut stack = Vec::with_capacity(8);
        match self.locate(p, self.last) {
            Loc::Inside(t) => {
                let [a, b, c] = self.v[t as usize];
                let [nbc, nca, nab] = self.nb[t as usize];
                let t1 = self.alloc();
                let t2 = self.alloc();
                self.set(t, [a, b, p], [t1, t2, nab]);
                self.set(t1, [b, c, p], [t2, t, nbc]);
                self.set(t2, [c, a, p], [t, t1, nca]);
                self.relink(nbc, t, t1);
                self.relink(nca, t, t2);
                stack.extend([t, t1, t2]);
            }
            Loc::OnEdge(t, i) => {
                let tv = self.v[t as usize];
                let (c, a, b) = (tv[i], tv[nx(i)], tv[pv(i)]);
                let u = self.nb[t as usize][i];
                let nbc = self.nb[t as usize][nx(i)];
                let nca = self.nb[t as usize][pv(i)];
                let j = self.nb[u as usize].iter().position(|&x| x == t).unwrap();
                let d = self.v[u as usize][j];
                let nad = self.nb[u as usize][nx(j)];
                let ndb = self.nb[u as usize][pv(j)];
                let t1 = self.alloc();
                let u1 = self.alloc();
                self.set(t, [c, a, p], [u1, t1, nca]);
                self.set(t1, [c, p, b], [u, nbc, t]);
                self.set(u, [d, b, p], [t1, u1, ndb]);
                self.set(u1, [d, p, a], [t, nad, u]);
                self.relink(nbc, t, t1);
                self.relink(nad, u, u1);
                stack.extend([t, t1, u, u1]);
            }
            Loc::OnVertex(v) => return Err(v),
            // Cannot happen for finite coordinates: the super triangle holds every vertex.
            Loc::Outside => return Err(NONE),
        }
        self.last = stack[0];
        while let Some(t) = stack.pop() {
            let i = self.idx(t, p);
            if let Some((t, u)) = self.flip_if_not_delaunay(t, i) {
                stack.push(t);
                stack.push(u);
            }
        }
        self.last = self.vtri[p as usize];
        Ok(())
    }

    /// If the edge of `t` opposite its vertex `i` is not locally Delaunay (and its
    /// quadrilateral is strictly convex), flips it and returns the two new triangles, both
    /// containing `v[t][i]`.
    #[inline]
    fn flip_if_not_delaunay(&mut self, t: u32, i: usize) -> Option<(u32, u32)> {
        let u = self.nb[t as usize][i];
        if u == NONE {
            return None;
        }
        let tv = self.v[t as usize];
        let (p, a, b) = (tv[i], tv[nx(i)], tv[pv(i)]);
        let j = self.nb[u as usize].iter().position(|&x| x == t).unwrap();
        let q = self.v[u as usize][j];
        if !self.g.incircle(p, a, b, q) {
            return None;
        }
        if self.g.orient(p, a, q) <= 0.0 || self.g.orient(p, q, b) <= 0.0 {
            return None;
        }
        Some(self.flip(t, i))
    }

    /// Flips the edge of `t` opposite its vertex `i`: `t = (p, a, b)` and its neighbour
    /// `(q, b, a)` become `t = (p, a, q)` and `u = (p, q, b)`, returned as `(t, u)`.
    fn flip(&mut self, t: u32, i: usize) -> (u32, u32) {
        let tv = self.v[t as usize];
        let (p, a, b) = (tv[i], tv[nx(i)], tv[pv(i)]);
        let u = self.nb[t as usize][i];
        let npa = self.nb[t as usize][pv(i)];
        let nbp = self.nb[t as usize][nx(i)];
        let j = self.nb[u as usize].iter().position(|&x| x == t).unwrap();
        let q = self.v[u as usize][j];
        let nqb = self.nb[u as usize][pv(j)];
        let naq = self.nb[u as usize][nx(j)];
        self.set(t, [p, a, q], [naq, u, npa]);
        self.set(u, [p, q, b], [nqb, nbp, t]);
        self.relink(naq, u, t);
        self.relink(nbp, t, u);
        (t, u)
    }

    /// The triangle holding edge `a–b` and the index of its vertex opposite the edge.
    fn find_edge(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        let (c, o) = if a < self.n { (a, b) } else { (b, a) };
        if c >= self.n {
            return None;
        }
        let start = self.vtri[c as usize];
        let mut t = start;
        for _ in 0..self.v.len() {
            let i = self.idx(t, c);
            let v = self.v[t as usize];
            if v[nx(i)] == o {
                return Some((t, pv(i)));
            }
            if v[pv(i)] == o {
                return Some((t, nx(i)));
            }
            // Counterclockwise around c: across the edge (c, v[pv(i)]).
            t = self.nb[t as usize][nx(i)];
            if t == start || t == NONE {
                return None;
            }
        }
        None
    }

    /// Finds how the constraint `a → b` (no edge yet) leaves `a`, then walks to `b`.
    fn trace(
        &self,
        a: u32,
        b: u32,
        constrained: &FxHashSet<(u32, u32)>,
        ids: &[u32],
    ) -> Result<Trace, String> {
        let start = self.vtri[a as usize];
        let mut t = start;
        let mut found = None;
        for _ in 0..self.v.len() {
            let i = self.idx(t, a);
            let v = self.v[t as usize];
            let (u, w) = (v[nx(i)], v[pv(i)]);
            let o1 = self.g.orient(a, u, b);
            let o2 = self.g.orient(a, w, b);
            if o1 == 0.0 && o2 < 0.0 {
                return Ok(Trace::Collinear(u));
            }
            if o2 == 0.0 && o1 > 0.0 {
                return Ok(Trace::Collinear(w));
            }
            if o1 > 0.0 && o2 < 0.0 {
                found = Some((t, i));
                break;
            }
            t = self.nb[t as usize][nx(i)];
            if t == start || t == NONE {
                break;
            }
        }
        let (t0, i0) = found.ok_or_else(|| "lost the constraint's first triangle".to_string())?;
        let v = self.v[t0 as usize];
        // u is right of a→b, w left.
        let (mut u, mut w) = (v[nx(i0)], v[pv(i0)]);
        let mut crossed = Vec::new();
        let mut t = self.nb[t0 as usize][i0];
        loop {
            if constrained.contains(&key(u, w)) {
                return Err(format!(
                    "crosses the constraint edge ({}, {})",
                    ids[u as usize], ids[w as usize]
                ));
            }
            crossed.push((u, w));
            if t == NONE {
                return Err("leaves the triangulation".into());
            }
            let tv = self.v[t as usize];
            let k = (0..3)
                .find(|&k| tv[k] != u && tv[k] != w)
                .ok_or_else(|| "corrupt triangulation".to_string())?;
            let x = tv[k];
            if x == b {
                return Ok(Trace::Cross(crossed, b));
            }
            let o = self.g.orient(a, b, x);
            if o == 0.0 {
                return Ok(Trace::Cross(crossed, x));
            }
            if o < 0.0 {
                u = x;
            } else {
                w = x;
            }
            // Leave t across the new crossed edge: it is opposite the vertex left behind.
            let opp = (0..3)
                .find(|&m| tv[m] != u && tv[m] != w)
                .ok_or_else(|| "corrupt triangulation".to_string())?;
            t = self.nb[t as usize][opp];
        }
    }

    /// Makes `a–b` an edge by flipping the edges crossing it (Sloan's method); every
    /// edge touched is pushed on `dirty` for the later Delaunay restoration.
    fn flip_in(
        &mut self,
        a: u32,
        b: u32,
        crossed: Vec<(u32, u32)>,
        dirty: &mut Vec<(u32, u32)>,
    ) -> Result<(), String> {
        let k = crossed.len();
        let cap = 1000 + 50 * k * k;
        let mut queue: VecDeque<(u32, u32)> = crossed.into();
        let mut steps = 0usize;
        while let Some((u, w)) = queue.pop_front() {
            steps += 1;
            if steps > cap {
                return Err("edge flipping does not converge".into());
            }
            let (t, i) = self
                .find_edge(u, w)
                .ok_or_else(|| "lost a crossing edge".to_string())?;
            let tv = self.v[t as usize];
            let (p, x, y) = (tv[i], tv[nx(i)], tv[pv(i)]);
            let nb = self.nb[t as usize][i];
            if nb == NONE {
                return Err("crossing edge on the boundary".into());
            }
            let j = self.nb[nb as usize].iter().position(|&z| z == t).unwrap();
            let q = self.v[nb as usize][j];
            if self.g.orient(p, x, q) > 0.0 && self.g.orient(p, q, y) > 0.0 {
                self.flip(t, i);
                dirty.extend([(p, q), (p, x), (x, q), (q, y), (y, p)]);
                if p != a && p != b && q != a && q != b {
                    let (op, oq) = (self.g.orient(a, b, p), self.g.orient(a, b, q));
                    if (op > 0.0) != (oq > 0.0) {
                        queue.push_back((p, q));
                    }
                }
            } else {
                queue.push_back((u, w));
            }
        }
        if self.find_edge(a, b).is_none() {
            return Err("edge flipping did not produce the edge".into());
        }
        Ok(())
    }

    /// Flips non-constrained edges that are not locally Delaunay, starting from `dirty`,
    /// until every edge is locally Delaunay or constrained.
    fn restore_delaunay(
        &mut self,
        mut dirty: Vec<(u32, u32)>,
        constrained: &FxHashSet<(u32, u32)>,
    ) {
        while let Some((a, b)) = dirty.pop() {
            if constrained.contains(&key(a, b)) {
                continue;
            }
            let Some((t, i)) = self.find_edge(a, b) else {
                continue;
            };
            if let Some((t, u)) = self.flip_if_not_delaunay(t, i) {
                let tv = self.v[t as usize];
                let uv = self.v[u as usize];
                // t = (p, a', q), u = (p, q, b'): the four outer edges.
                dirty.extend([
                    (tv[0], tv[1]),
                    (tv[1], tv[2]),
                    (uv[1], uv[2]),
                    (uv[2], uv[0]),
                ]);
            }
        }
    }
}

/// Triangulates a (nearly) planar facet: the 2D constrained Delaunay triangulation of `verts`
/// with `constraints` as edges, with the exterior and holes removed.
///
/// * `points`: all mesh points, indexed by vertex id; `pert`: the perturbation index of
///   each vertex id (ties are broken like [`crate::geom::insphere_sos`]).
/// * `verts`: the facet's vertex ids (ring vertices, Steiner points on its segments,
///   isolated vertices); repeats are ignored.
/// * `constraints`: constraint edges (subsegments of the rings and of inner segments);
///   every vertex of them must be in `verts`. A constraint passing exactly through a
///   vertex is split there.
/// * `holes`: hole points (3D, near the facet plane; projected onto it).
/// * `normal`: the facet normal (any length), which chooses the projection (see the
///   module documentation) and the orientation of the output.
///
/// Returns the triangles counterclockwise as seen from the side `normal` points to, each
/// rotated to start at its lowest vertex id, sorted. For a flat facet they are the
/// canonical CDT: the restriction of the 3D Delaunay tetrahedralization's perturbation
/// to the facet's plane, independent of the order of `verts` and `constraints`. Triangles are those reachable from no
/// hole point and not from outside without crossing a constraint; a facet without closed
/// rings of constraints (or with collinear vertices only) has none. Errors: constraints
/// that cross each other, vertices that coincide (in projection), bad input.
pub fn triangulate_facet(
    points: &[Point],
    pert: &[u32],
    verts: &[u32],
    constraints: &[[u32; 2]],
    holes: &[Point],
    normal: [f64; 3],
) -> Result<Vec<[u32; 3]>, String> {
    // Local numbering.
    let mut local: FxHashMap<u32, u32> = FxHashMap::default();
    let mut ids: Vec<u32> = Vec::with_capacity(verts.len());
    for &v in verts {
        if v as usize >= points.len() || v as usize >= pert.len() {
            return Err(format!("vertex {v} is out of range"));
        }
        if points[v as usize].iter().any(|c| !c.is_finite()) {
            return Err(format!("vertex {v} has a non-finite coordinate"));
        }
        if let std::collections::hash_map::Entry::Vacant(e) = local.entry(v) {
            e.insert(ids.len() as u32);
            ids.push(v);
        }
    }
    let n = ids.len();
    let mut cons: Vec<(u32, u32)> = Vec::with_capacity(constraints.len());
    for &[a, b] in constraints {
        let (Some(&la), Some(&lb)) = (local.get(&a), local.get(&b)) else {
            return Err(format!(
                "constraint ({a}, {b}) has a vertex not in the facet"
            ));
        };
        if la != lb {
            cons.push((la, lb));
        }
    }
    if n < 3 {
        return Ok(Vec::new());
    }
    let nlen = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
    if !(nlen > 0.0 && nlen.is_finite()) {
        return Err("the facet normal is zero".into());
    }
    let (k, ax, ay) = projection(normal);
    let pts3: Vec<Point> = ids.iter().map(|&v| points[v as usize]).collect();
    let xy: Vec<[f64; 2]> = pts3.iter().map(|p| [p[ax], p[ay]]).collect();
    let mut lids: Vec<u32> = ids.iter().map(|&v| pert[v as usize]).collect();
    lids.extend([SUPER_PERT, SUPER_PERT + 1, SUPER_PERT + 2]);
    // Insertion order: BRIO + Hilbert on the projected coordinates; points equal in
    // projection go last (they are then reported as coinciding, unless the 3D mode tells
    // them apart).
    let order = {
        let flat: Vec<Point> = xy.iter().map(|p| [p[0], p[1], 0.0]).collect();
        let io = crate::geom::hilbert::insertion_order(&flat);
        let mut o = io.order;
        o.extend(io.duplicates.iter().map(|&(d, _)| d));
        o
    };
    let axis_parallel = pts3.iter().all(|p| p[k] == pts3[0][k]);
    if axis_parallel {
        return run_flat(
            xy,
            lids,
            holes.iter().map(|h| [h[ax], h[ay]]),
            n,
            &order,
            &cons,
            &ids,
        );
    }
    let nn = normal.map(|x| x / nlen);
    let (lo, hi) = bbox(pts3.iter().copied());
    let m = (0..3)
        .map(|i| hi[i] - lo[i])
        .fold(0.0f64, f64::max)
        .max(f64::MIN_POSITIVE);
    let mut c = [0.0; 3];
    for p in &pts3 {
        for (ci, pi) in c.iter_mut().zip(p) {
            *ci += pi / n as f64;
        }
    }
    // An orthonormal basis (t1, t2) of the plane, with t1 × t2 = normal.
    let s = (0..3)
        .min_by(|&i, &j| nn[i].abs().total_cmp(&nn[j].abs()))
        .unwrap_or(0);
    let mut axis = [0.0; 3];
    axis[s] = 1.0;
    let t1 = unit(cross(nn, axis));
    let t2 = cross(nn, t1);
    let dot = |a: Point, b: Point| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let rel = |p: &Point| -> Point { std::array::from_fn(|i| p[i] - c[i]) };
    let max_dev = pts3
        .iter()
        .map(|p| dot(rel(p), nn).abs())
        .fold(0.0f64, f64::max);
    if max_dev > PLANAR_TOL * m && !exactly_coplanar(&pts3) {
        // Not flat: the exact 2D CDT of the vertices projected on the plane.
        let uv: Vec<[f64; 2]> = pts3
            .iter()
            .map(|p| [dot(rel(p), t1), dot(rel(p), t2)])
            .collect();
        let hv = holes.iter().map(|h| [dot(rel(h), t1), dot(rel(h), t2)]);
        return run_flat(uv, lids, hv, n, &order, &cons, &ids);
    }
    // Flat (up to rounding) but tilted: in-circle tests relative to an apex.
    let r = 100.0 * m;
    let e = std::array::from_fn(|i| c[i] + 2.0 * m * nn[i]);
    let mut all = pts3.clone();
    for deg in [90.0f64, 210.0, 330.0] {
        let (sn, cs) = deg.to_radians().sin_cos();
        all.push(std::array::from_fn(|i| {
            c[i] + r * (cs * t1[i] + sn * t2[i])
        }));
    }
    for h in holes {
        let d = dot(rel(h), nn);
        all.push(std::array::from_fn(|i| h[i] - d * nn[i]));
    }
    let mut g = Apex {
        p: all,
        ids: lids,
        e,
    };
    if g.orient(n as u32, n as u32 + 1, n as u32 + 2) < 0.0 {
        g.p.swap(n + 1, n + 2);
    }
    run(g, n, &order, &cons, holes.len(), &ids)
}

/// The axis `k` along which `normal` is largest, and the two others `(ax, ay)` in the
/// order that keeps counterclockwise (seen from `normal`'s side) counterclockwise in the
/// projection.
fn projection(normal: [f64; 3]) -> (usize, usize, usize) {
    let k = (0..3)
        .max_by(|&i, &j| normal[i].abs().total_cmp(&normal[j].abs()))
        .unwrap_or(2);
    let (ax, ay) = ((k + 1) % 3, (k + 2) % 3);
    if normal[k] < 0.0 {
        (k, ay, ax)
    } else {
        (k, ax, ay)
    }
}

/// The output of [`triangulate_facet`] for a facet that is one triangle without holes,
/// computed directly (most facets of surface meshes are), or `None` when its projection
/// is degenerate and the general routine must decide.
pub fn single_triangle(points: &[Point], tri: [u32; 3], normal: [f64; 3]) -> Option<[u32; 3]> {
    let (_, ax, ay) = projection(normal);
    let p = |v: u32| {
        let q = points.get(v as usize)?;
        Some([q[ax], q[ay]])
    };
    let (a, b, c) = (p(tri[0])?, p(tri[1])?, p(tri[2])?);
    let s = robust::orient2d(c2(&a), c2(&b), c2(&c));
    let t = if s > 0.0 {
        tri
    } else if s < 0.0 {
        [tri[0], tri[2], tri[1]]
    } else {
        return None;
    };
    let m = (0..3).min_by_key(|&i| t[i]).unwrap_or(0);
    Some([t[m], t[nx(m)], t[pv(m)]])
}

/// Vertices farther than this (relative to the facet's extent) from the plane make the
/// facet "not flat": it is then triangulated in 2D after an orthogonal projection, since
/// the apex-relative in-circle test amplifies deviations from the plane.
const PLANAR_TOL: f64 = 1e-12;

/// Exact test: are all points in one plane?
fn exactly_coplanar(p: &[Point]) -> bool {
    let a = p[0];
    let d2 = |x: &Point, y: &Point| (0..3).map(|i| (x[i] - y[i]).powi(2)).sum::<f64>();
    let Some(b) = p.iter().max_by(|x, y| d2(x, &a).total_cmp(&d2(y, &a))) else {
        return true;
    };
    let ab: Point = std::array::from_fn(|i| b[i] - a[i]);
    let area = |x: &Point| {
        let ax: Point = std::array::from_fn(|i| x[i] - a[i]);
        let cr = cross(ab, ax);
        cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]
    };
    let Some(c) = p.iter().max_by(|x, y| area(x).total_cmp(&area(y))) else {
        return true;
    };
    // a, b, c must not be collinear; then every point must be in their plane.
    let cc = |u: &Point, i: usize, j: usize| robust::Coord { x: u[i], y: u[j] };
    if (0..3).all(|k| {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        robust::orient2d(cc(&a, i, j), cc(b, i, j), cc(c, i, j)) == 0.0
    }) {
        return true;
    }
    p.iter().all(|x| orient3d(&a, b, c, x) == 0.0)
}

/// The whole algorithm with exact 2D predicates on the coordinates `xy` of the vertices.
fn run_flat(
    mut xy: Vec<[f64; 2]>,
    lids: Vec<u32>,
    holes: impl Iterator<Item = [f64; 2]>,
    n: usize,
    order: &[u32],
    cons: &[(u32, u32)],
    ids: &[u32],
) -> Result<Vec<[u32; 3]>, String> {
    let (lo, hi) = bbox(xy.iter().map(|p| [p[0], p[1], 0.0]));
    let cx = [lo[0] * 0.5 + hi[0] * 0.5, lo[1] * 0.5 + hi[1] * 0.5];
    let m = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
    let r = 100.0 * m;
    xy.push([cx[0] - r, cx[1] - r]);
    xy.push([cx[0] + r, cx[1] - r]);
    xy.push([cx[0], cx[1] + r]);
    let before = xy.len();
    xy.extend(holes);
    let num_holes = xy.len() - before;
    run(Flat { xy, ids: lids }, n, order, cons, num_holes, ids)
}

fn bbox(it: impl Iterator<Item = Point>) -> (Point, Point) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in it {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    (lo, hi)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    crate::geom::cross(&a, &b)
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    a.map(|x| x / l)
}

/// The whole algorithm on local vertices `0..n` (super triangle `n..n+3`, holes after).
fn run<G: Geometry>(
    g: G,
    n: usize,
    order: &[u32],
    cons: &[(u32, u32)],
    num_holes: usize,
    ids: &[u32],
) -> Result<Vec<[u32; 3]>, String> {
    let total = n + 3 + num_holes;
    let mut tri = Tri::new(g, n as u32, total);
    tri.v.reserve(2 * n + 1);
    tri.nb.reserve(2 * n + 1);
    for &p in order {
        if let Err(q) = tri.insert(p) {
            if q == NONE {
                return Err(format!(
                    "vertex {} lies outside the facet's bounding triangle",
                    ids[p as usize]
                ));
            }
            return Err(format!(
                "vertices {} and {} coincide in the facet's plane",
                ids[q as usize], ids[p as usize]
            ));
        }
    }

    // Constraint recovery.
    let mut constrained: FxHashSet<(u32, u32)> = FxHashSet::default();
    let mut dirty: Vec<(u32, u32)> = Vec::new();
    for &(a0, b0) in cons {
        let mut work = vec![(a0, b0)];
        while let Some((a, b)) = work.pop() {
            if a == b {
                continue;
            }
            if tri.find_edge(a, b).is_some() {
                constrained.insert(key(a, b));
                continue;
            }
            let err = |m: String| {
                format!(
                    "constraint edge ({}, {}) {m}",
                    ids[a0 as usize], ids[b0 as usize]
                )
            };
            match tri.trace(a, b, &constrained, ids).map_err(err)? {
                Trace::Collinear(c) => {
                    constrained.insert(key(a, c));
                    work.push((c, b));
                }
                Trace::Cross(crossed, end) => {
                    tri.flip_in(a, end, crossed, &mut dirty).map_err(err)?;
                    constrained.insert(key(a, end));
                    if end != b {
                        work.push((end, b));
                    }
                }
            }
        }
    }
    tri.restore_delaunay(dirty, &constrained);

    // Remove the exterior and the holes.
    let nt = tri.v.len();
    let out_seed: Vec<bool> = tri
        .v
        .iter()
        .map(|v| v.iter().any(|&x| x as usize >= n))
        .collect();
    let mut stack: Vec<u32> = (0..nt as u32).filter(|&t| out_seed[t as usize]).collect();
    let mut out = out_seed;
    let flood = |tri: &Tri<G>, out: &mut Vec<bool>, stack: &mut Vec<u32>| {
        while let Some(t) = stack.pop() {
            let v = tri.v[t as usize];
            for i in 0..3 {
                let u = tri.nb[t as usize][i];
                if u == NONE || out[u as usize] {
                    continue;
                }
                if constrained.contains(&key(v[nx(i)], v[pv(i)])) {
                    continue;
                }
                out[u as usize] = true;
                stack.push(u);
            }
        }
    };
    flood(&tri, &mut out, &mut stack);
    for h in 0..num_holes {
        let hp = (n + 3 + h) as u32;
        let start = tri.last;
        let t = match tri.locate(hp, start) {
            Loc::Inside(t) | Loc::OnEdge(t, _) => t,
            Loc::OnVertex(v) => tri.vtri[v as usize],
            Loc::Outside => continue,
        };
        if !out[t as usize] {
            out[t as usize] = true;
            stack.push(t);
            flood(&tri, &mut out, &mut stack);
        }
    }

    let mut res: Vec<[u32; 3]> = Vec::new();
    for (v, _) in tri.v.iter().zip(&out).filter(|(_, &o)| !o) {
        let g = v.map(|x| ids[x as usize]);
        let m = (0..3).min_by_key(|&i| g[i]).unwrap_or(0);
        res.push([g[m], g[nx(m)], g[pv(m)]]);
    }
    res.sort_unstable();
    Ok(res)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::Delaunay;

    /// Rounds of a randomized test: `FACET2D_STRESS` multiplies the default.
    fn rounds(default: usize) -> usize {
        let k: usize = std::env::var("FACET2D_STRESS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(1);
        default * k.max(1)
    }

    use crate::geom::lcg;

    #[test]
    fn single_triangles_match_the_general_routine() {
        let mut s = 7u64;
        let mut checked = 0;
        for round in 0..rounds(2000) {
            let mut pts: Vec<Point> = (0..3)
                .map(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)])
                .collect();
            if round % 3 == 0 {
                // Axis-parallel facets take another path in the general routine.
                for p in &mut pts {
                    p[round % 2] = 0.5;
                }
            }
            let ids = [0u32, 1, 2];
            let pert = [5u32, 3, 9];
            let (u, v) = (
                crate::geom::sub(&pts[1], &pts[0]),
                crate::geom::sub(&pts[2], &pts[0]),
            );
            let mut n = cross(u, v);
            if round % 2 == 1 {
                n = n.map(|x| -x);
            }
            let cons = [[0u32, 1], [1, 2], [2, 0]];
            let want = triangulate_facet(&pts, &pert, &ids, &cons, &[], n);
            match single_triangle(&pts, [2, 0, 1], n) {
                Some(t) => {
                    assert_eq!(want.unwrap(), vec![t], "round {round}");
                    checked += 1;
                }
                None => assert!(want.map(|w| w.is_empty()).unwrap_or(true)),
            }
        }
        assert!(checked > 100);
    }

    fn shuffle<T>(v: &mut [T], s: &mut u64) {
        for i in (1..v.len()).rev() {
            let j = (lcg(s) * (i + 1) as f64) as usize;
            v.swap(i, j.min(i));
        }
    }

    fn o2(a: &[f64; 2], b: &[f64; 2], c: &[f64; 2]) -> f64 {
        robust::orient2d(c2(a), c2(b), c2(c))
    }

    /// Canonical form: rotated to the lowest id, sorted.
    fn canon(mut t: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
        for x in t.iter_mut() {
            let m = (0..3).min_by_key(|&i| x[i]).unwrap();
            *x = [x[m], x[nx(m)], x[pv(m)]];
        }
        t.sort_unstable();
        t
    }

    /// Brute force: every triangle (counterclockwise in `xy`) whose perturbed circumcircle
    /// holds no other point.
    fn brute_dt(xy: &[[f64; 2]], ids: &[u32]) -> Vec<[u32; 3]> {
        let n = xy.len() as u32;
        let mut res = Vec::new();
        for a in 0..n {
            for b in a + 1..n {
                for c in a + 1..n {
                    if b == c {
                        continue;
                    }
                    let (pa, pb, pc) = (&xy[a as usize], &xy[b as usize], &xy[c as usize]);
                    if o2(pa, pb, pc) <= 0.0 {
                        continue;
                    }
                    let empty = (0..n).filter(|&d| d != a && d != b && d != c).all(|d| {
                        let s = incircle_sos(
                            [pa, pb, pc, &xy[d as usize]],
                            [a, b, c, d].map(|v| ids[v as usize]),
                        );
                        assert_ne!(s, Sign::Zero);
                        s == Sign::Negative
                    });
                    if empty {
                        res.push([a, b, c]);
                    }
                }
            }
        }
        canon(res)
    }

    /// Strict convex hull (extreme points only), counterclockwise.
    fn hull(xy: &[[f64; 2]]) -> Vec<u32> {
        let mut idx: Vec<u32> = (0..xy.len() as u32).collect();
        idx.sort_by(|&a, &b| {
            let (p, q) = (xy[a as usize], xy[b as usize]);
            p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1]))
        });
        let mut h: Vec<u32> = Vec::new();
        for pass in 0..2 {
            let start = h.len();
            let it: Box<dyn Iterator<Item = &u32>> = if pass == 0 {
                Box::new(idx.iter())
            } else {
                Box::new(idx.iter().rev())
            };
            for &i in it {
                while h.len() >= start + 2
                    && o2(
                        &xy[h[h.len() - 2] as usize],
                        &xy[h[h.len() - 1] as usize],
                        &xy[i as usize],
                    ) <= 0.0
                {
                    h.pop();
                }
                h.push(i);
            }
            h.pop();
        }
        h
    }

    fn ring_edges(r: &[u32]) -> Vec<[u32; 2]> {
        (0..r.len()).map(|i| [r[i], r[(i + 1) % r.len()]]).collect()
    }

    fn area2(p: &[Point], t: &[u32; 3], ax: usize, ay: usize) -> f64 {
        let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
        (b[ax] - a[ax]) * (c[ay] - a[ay]) - (c[ax] - a[ax]) * (b[ay] - a[ay])
    }

    /// Checks that the triangles form a valid triangulation (each edge used once per
    /// direction), all counterclockwise seen from `normal`, with the constraints as
    /// edges; returns the edge → triangles map.
    fn check_valid(
        p: &[Point],
        tris: &[[u32; 3]],
        cons: &[[u32; 2]],
        normal: [f64; 3],
    ) -> FxHashMap<(u32, u32), Vec<usize>> {
        let mut dir: FxHashSet<(u32, u32)> = FxHashSet::default();
        let mut und: FxHashMap<(u32, u32), Vec<usize>> = FxHashMap::default();
        for (k, t) in tris.iter().enumerate() {
            let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
            let nrm = cross(
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let d: f64 = (0..3).map(|i| nrm[i] * normal[i]).sum();
            // Slivers of non-flat facets may flip in an orthogonal projection along
            // `normal` (the triangulation is valid in its own projection).
            let l2 = |u: Point, w: Point| (0..3).map(|i| (u[i] - w[i]).powi(2)).sum::<f64>();
            let scale = l2(a, b) + l2(a, c);
            assert!(
                d > 0.0 || -d <= 1e-9 * scale,
                "triangle {t:?} is not counterclockwise"
            );
            for i in 0..3 {
                let (u, w) = (t[i], t[(i + 1) % 3]);
                assert!(dir.insert((u, w)), "edge {u}->{w} used twice");
                und.entry(key(u, w)).or_default().push(k);
            }
        }
        for c in cons {
            assert!(
                und.contains_key(&key(c[0], c[1])),
                "constraint {c:?} missing"
            );
        }
        und
    }

    /// Every non-constrained edge between two triangles is locally Delaunay (2D mode).
    fn check_locally_delaunay(
        xy: &[[f64; 2]],
        ids: &[u32],
        tris: &[[u32; 3]],
        und: &FxHashMap<(u32, u32), Vec<usize>>,
        cons: &FxHashSet<(u32, u32)>,
    ) {
        for (e, ts) in und {
            if ts.len() != 2 || cons.contains(e) {
                continue;
            }
            let t = tris[ts[0]];
            let u = tris[ts[1]];
            let q = *u.iter().find(|&&x| x != e.0 && x != e.1).unwrap();
            let pt = t.map(|v| &xy[v as usize]);
            let s = incircle_sos(
                [pt[0], pt[1], pt[2], &xy[q as usize]],
                [t[0], t[1], t[2], q].map(|v| ids[v as usize]),
            );
            assert_eq!(s, Sign::Negative, "edge {e:?} is not locally Delaunay");
        }
    }

    #[test]
    fn incircle_sos_is_alternating_and_matches_insphere_sos() {
        // The 12 integer points on the circle of radius 5.
        let mut pts: Vec<[f64; 2]> = Vec::new();
        for x in -5i32..=5 {
            for y in -5i32..=5 {
                if x * x + y * y == 25 {
                    pts.push([x as f64, y as f64]);
                }
            }
        }
        pts.push([0.0, 0.0]);
        pts.push([1.0, 2.0]);
        assert_eq!(pts.len(), 14);
        let n = pts.len() as u32;
        let mut ties = 0;
        let perms: Vec<[usize; 4]> = {
            let mut v = Vec::new();
            for a in 0..4 {
                for b in 0..4 {
                    for c in 0..4 {
                        for d in 0..4 {
                            let mut s = [a, b, c, d];
                            s.sort();
                            if s == [0, 1, 2, 3] {
                                v.push([a, b, c, d]);
                            }
                        }
                    }
                }
            }
            v
        };
        let parity = |p: &[usize; 4]| {
            let mut inv = 0;
            for i in 0..4 {
                for j in i + 1..4 {
                    if p[i] > p[j] {
                        inv += 1;
                    }
                }
            }
            inv % 2
        };
        for a in 0..n {
            for b in 0..n {
                for c in 0..n {
                    for d in 0..n {
                        let q = [a, b, c, d];
                        let mut u = q.to_vec();
                        u.sort();
                        u.dedup();
                        if u.len() < 4 || !(a < b && b < c) {
                            continue;
                        }
                        let p = q.map(|i| &pts[i as usize]);
                        let o = o2(p[0], p[1], p[2]);
                        if o == 0.0 {
                            continue;
                        }
                        // Ids in a scrambled order.
                        let ids = q.map(|i| (i * 7 + 3) % 17);
                        let s = incircle_sos(p, ids);
                        assert_ne!(s, Sign::Zero);
                        if robust::incircle(c2(p[0]), c2(p[1]), c2(p[2]), c2(p[3])) == 0.0 {
                            ties += 1;
                        }
                        // Alternating: every permutation with three non-collinear leading points.
                        for perm in &perms {
                            let pp = perm.map(|k| p[k]);
                            let ii = perm.map(|k| ids[k]);
                            if o2(pp[0], pp[1], pp[2]) == 0.0 {
                                continue;
                            }
                            let sp = incircle_sos(pp, ii);
                            let want = if parity(perm) == 1 { s.flip() } else { s };
                            assert_eq!(sp, want);
                        }
                        // Agreement with the 3D perturbation: lift into z = 0 and add an
                        // apex above, with its id either lowest or highest.
                        let (ta, tb) = if o > 0.0 { (0, 1) } else { (1, 0) };
                        let s2 = if o > 0.0 { s } else { s.flip() };
                        let l = |k: usize| [p[k][0], p[k][1], 0.0];
                        for (e, eid) in [([0.3, 0.7, 40.0], 100u32), ([-0.2, 0.1, 1e3], 0)] {
                            let ids5 = [ids[ta] + 1, ids[tb] + 1, ids[2] + 1, eid, ids[3] + 1];
                            let (pa, pb, pc, pd) = (l(ta), l(tb), l(2), l(3));
                            assert!(orient3d(&pa, &pb, &pc, &e) > 0.0);
                            let s3 = insphere_sos([&pa, &pb, &pc, &e, &pd], ids5);
                            assert_eq!(s3, s2, "{q:?}");
                        }
                    }
                }
            }
        }
        assert!(ties > 100);
    }

    /// The lowest-indexed query on a tie counts as inside.
    #[test]
    fn incircle_sos_lowest_query_is_inside() {
        let p = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let r = [&p[0], &p[1], &p[2], &p[3]];
        assert_eq!(incircle_sos(r, [1, 2, 3, 0]), Sign::Positive);
        assert_eq!(incircle_sos(r, [0, 1, 2, 3]), Sign::Negative);
    }

    /// Random flat facets (often integer grids with many cocircular points), hull edges as
    /// constraints: the result must be the brute-force perturbed Delaunay triangulation,
    /// on every axis-parallel plane and for both normal directions, whatever the order.
    #[test]
    fn flat_facets_match_brute_force_oracle() {
        let mut s = 11u64;
        for round in 0..rounds(120) {
            let grid = round % 3 != 2;
            let m = 4 + round % 20;
            let mut xy: Vec<[f64; 2]> = Vec::new();
            while xy.len() < m {
                let p = if grid {
                    [(lcg(&mut s) * 6.0).floor(), (lcg(&mut s) * 6.0).floor()]
                } else {
                    [lcg(&mut s), lcg(&mut s)]
                };
                if !xy.contains(&p) {
                    xy.push(p);
                }
                if grid && xy.len() >= 36 {
                    break;
                }
            }
            let n = xy.len();
            let mut pert: Vec<u32> = (0..n as u32).collect();
            shuffle(&mut pert, &mut s);
            let h = hull(&xy);
            if h.len() < 3 {
                continue;
            }
            let oracle = brute_dt(&xy, &pert);
            let cons = ring_edges(&h);
            // Every axis-parallel plane, both normals.
            for k in 0..3 {
                for sign in [1.0, -1.0] {
                    let (ax, ay) = ((k + 1) % 3, (k + 2) % 3);
                    let (ax, ay) = if sign > 0.0 { (ax, ay) } else { (ay, ax) };
                    let mut pts = vec![[0.0; 3]; n];
                    for i in 0..n {
                        pts[i][ax] = xy[i][0];
                        pts[i][ay] = xy[i][1];
                        pts[i][k] = 2.5;
                    }
                    let mut normal = [0.0; 3];
                    normal[k] = sign;
                    let mut verts: Vec<u32> = (0..n as u32).collect();
                    shuffle(&mut verts, &mut s);
                    let got = triangulate_facet(&pts, &pert, &verts, &cons, &[], normal).unwrap();
                    assert_eq!(got, oracle, "round {round} k {k} sign {sign}");
                }
            }
        }
    }

    /// The faces of the 3D Delaunay tetrahedralization of a planar point set plus one apex
    /// that lie in the plane (TetGen's perturbation, ids = input indices).
    fn dt3_plane_faces(pts: &[Point], apex: Point) -> Vec<[u32; 3]> {
        let mut all = pts.to_vec();
        all.push(apex);
        let n = pts.len() as u32;
        let built = Delaunay::build(&all).unwrap();
        let (tets, _) = built.dt.export();
        let mut faces = Vec::new();
        for t in tets {
            let i = t
                .iter()
                .position(|&v| v == n)
                .expect("every tet has the apex");
            // Face opposite the apex, oriented counterclockwise seen from the apex.
            let f: Vec<u32> = (0..4).filter(|&k| k != i).map(|k| t[k]).collect();
            let (a, b, c) = (f[0], f[1], f[2]);
            if orient3d(&all[a as usize], &all[b as usize], &all[c as usize], &apex) > 0.0 {
                faces.push([a, b, c]);
            } else {
                faces.push([b, a, c]);
            }
        }
        canon(faces)
    }

    /// Tilted and axis-parallel planes with exactly coplanar (integer) points, including
    /// cocircular ties: the facet triangulation is the one of the 3D Delaunay
    /// tetrahedralization, as the 3D mesh needs.
    #[test]
    fn planar_facets_match_the_3d_delaunay() {
        let mut s = 5u64;
        // Planes z = αx + βy with small integer slopes keep integer points exact.
        let slopes = [
            (0.0, 0.0),
            (1.0, 0.0),
            (1.0, 2.0),
            (-3.0, 1.0),
            (0.5, -0.25),
        ];
        for round in 0..rounds(60) {
            let (al, be) = slopes[round % slopes.len()];
            let m = 5 + round % 25;
            let mut xy: Vec<[f64; 2]> = Vec::new();
            while xy.len() < m && xy.len() < 49 {
                let p = [(lcg(&mut s) * 7.0).floor(), (lcg(&mut s) * 7.0).floor()];
                if !xy.contains(&p) {
                    xy.push(p);
                }
            }
            let h = hull(&xy);
            if h.len() < 3 {
                continue;
            }
            let pts: Vec<Point> = xy
                .iter()
                .map(|p| [p[0], p[1], al * p[0] + be * p[1]])
                .collect();
            let normal = unit([-al, -be, 1.0]);
            let c = [3.0, 3.0, 3.0 * al + 3.0 * be];
            for up in [1.0, -1.0] {
                let nrm = normal.map(|x| x * up);
                let apex = std::array::from_fn(|i| c[i] + 20.0 * nrm[i]);
                let want = dt3_plane_faces(&pts, apex);
                let pert: Vec<u32> = (0..pts.len() as u32).collect();
                let mut verts = pert.clone();
                shuffle(&mut verts, &mut s);
                let hh: Vec<u32> = if up > 0.0 {
                    h.clone()
                } else {
                    h.iter().rev().copied().collect()
                };
                let got =
                    triangulate_facet(&pts, &pert, &verts, &ring_edges(&hh), &[], nrm).unwrap();
                assert_eq!(got, want, "round {round} slope {al},{be} up {up}");
            }
        }
    }

    fn square_pts() -> Vec<Point> {
        vec![
            [0.0, 0.0, 1.0],
            [10.0, 0.0, 1.0],
            [10.0, 10.0, 1.0],
            [0.0, 10.0, 1.0],
            [3.0, 3.0, 1.0],
            [7.0, 3.0, 1.0],
            [7.0, 7.0, 1.0],
            [3.0, 7.0, 1.0],
        ]
    }

    fn total_area(p: &[Point], t: &[[u32; 3]]) -> f64 {
        t.iter().map(|t| area2(p, t, 0, 1)).sum::<f64>() / 2.0
    }

    #[test]
    fn square_with_square_hole() {
        let p = square_pts();
        let pert: Vec<u32> = (0..8).collect();
        let verts: Vec<u32> = (0..8).collect();
        let mut cons = ring_edges(&[0, 1, 2, 3]);
        cons.extend(ring_edges(&[4, 5, 6, 7]));
        let n = [0.0, 0.0, 1.0];
        let t = triangulate_facet(&p, &pert, &verts, &cons, &[[5.0, 5.0, 1.0]], n).unwrap();
        assert_eq!(t.len(), 8);
        assert_eq!(total_area(&p, &t), 84.0);
        check_valid(&p, &t, &cons, n);
        // Without the hole point the inner square is kept.
        let t = triangulate_facet(&p, &pert, &verts, &cons, &[], n).unwrap();
        assert_eq!(t.len(), 10);
        assert_eq!(total_area(&p, &t), 100.0);
        // A hole point outside the facet changes nothing; one in the annulus removes it.
        let t2 = triangulate_facet(&p, &pert, &verts, &cons, &[[50.0, 5.0, 1.0]], n).unwrap();
        assert_eq!(t2, t);
        let t3 = triangulate_facet(&p, &pert, &verts, &cons, &[[1.0, 5.0, 1.2]], n).unwrap();
        assert_eq!(t3.len(), 2);
        assert_eq!(total_area(&p, &t3), 16.0);
    }

    #[test]
    fn tilted_square_with_hole() {
        // The same on the plane z = x + y, with the hole point slightly off the plane.
        let p: Vec<Point> = square_pts()
            .iter()
            .map(|q| [q[0], q[1], q[0] + q[1]])
            .collect();
        let pert: Vec<u32> = (0..8).collect();
        let mut cons = ring_edges(&[0, 1, 2, 3]);
        cons.extend(ring_edges(&[4, 5, 6, 7]));
        let n = unit([-1.0, -1.0, 1.0]);
        let t = triangulate_facet(&p, &pert, &pert, &cons, &[[5.0, 5.0, 10.01]], n).unwrap();
        assert_eq!(t.len(), 8);
        check_valid(&p, &t, &cons, n);
        let t = triangulate_facet(&p, &pert, &pert, &cons, &[], n).unwrap();
        assert_eq!(t.len(), 10);
    }

    #[test]
    fn non_convex_l_shape() {
        let xy = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let p: Vec<Point> = xy.iter().map(|q| [q[0], 0.5, q[1]]).collect();
        // Plane y = 0.5; counterclockwise in (x, z) is seen from -y.
        let n = [0.0, -1.0, 0.0];
        let ids: Vec<u32> = (0..6).collect();
        let cons = ring_edges(&ids);
        let t = triangulate_facet(&p, &ids, &ids, &cons, &[], n).unwrap();
        assert_eq!(t.len(), 4);
        assert_eq!(total_area(&p, &t).abs(), 0.0); // degenerate in (x, y)
        let a: f64 = t.iter().map(|t| area2(&p, t, 0, 2)).sum::<f64>() / 2.0;
        assert_eq!(a, 3.0);
        check_valid(&p, &t, &cons, n);
        // No triangle covers the notch at (1.5, 1.5).
        for tr in &t {
            let c: Vec<f64> = (0..3)
                .map(|k| tr.iter().map(|&v| p[v as usize][k]).sum::<f64>() / 3.0)
                .collect();
            assert!(!(c[0] > 1.0 && c[2] > 1.0));
        }
    }

    #[test]
    fn inner_segment_and_isolated_vertex() {
        let mut p = square_pts()[..4].to_vec();
        p.push([2.0, 5.0, 1.0]);
        p.push([8.0, 5.0, 1.0]);
        p.push([5.0, 8.0, 1.0]); // isolated
        p.push([5.0, 5.0, 1.0]); // on the inner segment: splits it
        let ids: Vec<u32> = (0..8).collect();
        let mut cons = ring_edges(&[0, 1, 2, 3]);
        cons.push([4, 5]);
        let n = [0.0, 0.0, 1.0];
        let t = triangulate_facet(&p, &ids, &ids, &cons, &[], n).unwrap();
        assert_eq!(total_area(&p, &t), 100.0);
        let und = check_valid(&p, &t, &[[4, 7], [7, 5]], n);
        assert!(!und.contains_key(&(4, 5)));
        // Euler: 8 vertices, 4 on the hull → 2·8 − 4 − 2 triangles.
        assert_eq!(t.len(), 10);
        assert!(t.iter().any(|tr| tr.contains(&6)));
    }

    #[test]
    fn steiner_points_on_ring_edges() {
        // Dyadic corners, so that the Steiner points on edge 0–1 are exactly on it.
        let mut p: Vec<Point> = vec![
            [0.125, 0.375, 2.0],
            [0.625, 0.875, 2.0],
            [-0.375, 1.75, 2.0],
            [-1.125, 0.8125, 2.0],
        ];
        let n = [0.0, 0.0, 1.0];
        let lerp = |a: Point, b: Point, t: f64| -> Point {
            std::array::from_fn(|i| a[i] + t * (b[i] - a[i]))
        };
        let mut ring: Vec<u32> = vec![0];
        for k in [1.0, 2.0, 3.0] {
            p.push(lerp(p[0], p[1], k / 4.0));
            ring.push(p.len() as u32 - 1);
        }
        // Rounded lerps at sevenths on the other edges: nearly collinear.
        let mut near = 0;
        for (a, b) in [(1usize, 2usize), (2, 3), (3, 0)] {
            ring.push(a as u32);
            for k in 1..7 {
                let q = lerp(p[a], p[b], k as f64 / 7.0);
                let (pa, pb) = ([p[a][0], p[a][1]], [p[b][0], p[b][1]]);
                if o2(&pa, &pb, &[q[0], q[1]]) != 0.0 {
                    near += 1;
                }
                p.push(q);
                ring.push(p.len() as u32 - 1);
            }
        }
        assert!(near > 5, "the test needs points off their edges");
        let xy: Vec<[f64; 2]> = p.iter().map(|v| [v[0], v[1]]).collect();
        for k in 4..7 {
            assert_eq!(o2(&xy[0], &xy[1], &xy[k]), 0.0);
        }
        let ids: Vec<u32> = (0..p.len() as u32).collect();
        let cons = ring_edges(&ring);
        let t = triangulate_facet(&p, &ids, &ids, &cons, &[], n).unwrap();
        check_valid(&p, &t, &cons, n);
        assert_eq!(t.len(), ring.len() - 2);
        // The exact edge 0–1 given whole: split at the vertices on it, same result.
        let mut cons2: Vec<[u32; 2]> = cons
            .iter()
            .copied()
            .filter(|c| !c.iter().any(|&v| (4..7).contains(&v)))
            .collect();
        cons2.push([1, 0]);
        assert_eq!(cons2.len(), cons.len() - 3);
        let t2 = triangulate_facet(&p, &ids, &ids, &cons2, &[], n).unwrap();
        assert_eq!(t2, t);
        // Non-constrained edges are locally Delaunay.
        let und = check_valid(&p, &t, &cons, n);
        let ck: FxHashSet<(u32, u32)> = cons.iter().map(|c| key(c[0], c[1])).collect();
        check_locally_delaunay(&xy, &ids, &t, &und, &ck);
        // Tilted copy (3D mode), with edge 0–1 given whole: its Steiner points are on it
        // exactly in 3D too.
        let q: Vec<Point> = p.iter().map(|v| [v[0], v[1], v[0] - v[1]]).collect();
        let nq = unit([-1.0, 1.0, 1.0]);
        let tq = triangulate_facet(&q, &ids, &ids, &cons2, &[], nq).unwrap();
        check_valid(&q, &tq, &cons, nq);
        assert_eq!(tq.len(), ring.len() - 2);
    }

    #[test]
    fn constraint_through_collinear_vertices_is_split() {
        let mut p: Vec<Point> = vec![
            [0.0, 0.0, 0.0],
            [4.0, 0.0, 0.0],
            [4.0, 4.0, 0.0],
            [0.0, 4.0, 0.0],
        ];
        for x in [1.0, 2.0, 3.0] {
            p.push([x, 0.0, 0.0]);
        }
        for y in [1.0, 3.0] {
            p.push([4.0, y, 0.0]);
        }
        p.push([2.0, 2.0, 0.0]);
        let ids: Vec<u32> = (0..p.len() as u32).collect();
        let n = [0.0, 0.0, 1.0];
        // Whole edges, the diagonal 0–2 through vertex 9 (2, 2).
        let cons = vec![[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]];
        let t = triangulate_facet(&p, &ids, &ids, &cons, &[], n).unwrap();
        assert_eq!(total_area(&p, &t), 16.0);
        let sub = [
            [0, 4],
            [4, 5],
            [5, 6],
            [6, 1],
            [1, 7],
            [7, 8],
            [8, 2],
            [0, 9],
            [9, 2],
        ];
        check_valid(&p, &t, &sub, n);
        // Same on a tilted plane (3D mode).
        let q: Vec<Point> = p.iter().map(|v| [v[0], v[1], 2.0 * v[0] - v[1]]).collect();
        let nq = unit([-2.0, 1.0, 1.0]);
        let tq = triangulate_facet(&q, &ids, &ids, &cons, &[], nq).unwrap();
        check_valid(&q, &tq, &sub, nq);
        assert_eq!(tq.len(), t.len());
    }

    #[test]
    fn forty_gon() {
        let m = 40;
        let p: Vec<Point> = (0..m)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / m as f64;
                [3.0 + 2.0 * a.cos(), -1.0 + 2.0 * a.sin(), 7.0]
            })
            .collect();
        let ids: Vec<u32> = (0..m as u32).collect();
        let cons = ring_edges(&ids);
        let n = [0.0, 0.0, 1.0];
        let t = triangulate_facet(&p, &ids, &ids, &cons, &[], n).unwrap();
        assert_eq!(t.len(), m - 2);
        check_valid(&p, &t, &cons, n);
        // Exactly cocircular polygon: the 12 integer points of the circle of radius 5.
        let mut q: Vec<(f64, Point)> = Vec::new();
        for x in -5i32..=5 {
            for y in -5i32..=5 {
                if x * x + y * y == 25 {
                    q.push(((y as f64).atan2(x as f64), [x as f64, y as f64, 0.0]));
                }
            }
        }
        q.sort_by(|a, b| a.0.total_cmp(&b.0));
        let q: Vec<Point> = q.into_iter().map(|x| x.1).collect();
        let ids: Vec<u32> = (0..12).collect();
        let t = triangulate_facet(&q, &ids, &ids, &ring_edges(&ids), &[], n).unwrap();
        assert_eq!(t.len(), 10);
        let xy: Vec<[f64; 2]> = q.iter().map(|v| [v[0], v[1]]).collect();
        assert_eq!(t, brute_dt(&xy, &ids));
    }

    /// Random constraints (edges of another triangulation of the points): the result
    /// contains them and every other interior edge is locally Delaunay, i.e. it is the CDT.
    #[test]
    fn random_constraints_give_the_cdt() {
        let mut s = 99u64;
        for round in 0..rounds(40) {
            let m = 10 + round % 30;
            let mut xy: Vec<[f64; 2]> = Vec::new();
            while xy.len() < m {
                let p = if round % 2 == 0 {
                    [(lcg(&mut s) * 8.0).floor(), (lcg(&mut s) * 8.0).floor()]
                } else {
                    [lcg(&mut s), lcg(&mut s)]
                };
                if !xy.contains(&p) {
                    xy.push(p);
                }
            }
            let n = xy.len();
            let pert: Vec<u32> = (0..n as u32).collect();
            // Another triangulation: the Delaunay triangulation of the points moved.
            let moved: Vec<[f64; 2]> = xy
                .iter()
                .map(|p| [p[0] + 0.9 * lcg(&mut s), p[1] + 0.9 * lcg(&mut s)])
                .collect();
            let h = hull(&xy);
            let other = brute_dt(&moved, &pert);
            let mut cons: Vec<[u32; 2]> = ring_edges(&h);
            for t in &other {
                for i in 0..3 {
                    let e = [t[i], t[(i + 1) % 3]];
                    // Keep some of them: those inside the hull that cross no kept
                    // constraint.
                    if lcg(&mut s) < 0.3 {
                        let (a, b) = (xy[e[0] as usize], xy[e[1] as usize]);
                        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
                        let inside = (0..h.len()).all(|k| {
                            o2(&xy[h[k] as usize], &xy[h[(k + 1) % h.len()] as usize], &mid) > 0.0
                        });
                        if inside && !crosses_any(&xy, e, &cons) {
                            cons.push(e);
                        }
                    }
                }
            }
            let pts: Vec<Point> = xy.iter().map(|p| [p[0], p[1], -1.0]).collect();
            let verts: Vec<u32> = (0..n as u32).collect();
            let nrm = [0.0, 0.0, 1.0];
            let t = triangulate_facet(&pts, &pert, &verts, &cons, &[], nrm).unwrap();
            // Constraints through vertices are split: check coverage via the chains.
            let und = check_valid_loose(&pts, &t, nrm);
            let mut ckeys: FxHashSet<(u32, u32)> = FxHashSet::default();
            for c in &cons {
                for e in chain(&xy, *c) {
                    assert!(und.contains_key(&key(e[0], e[1])), "round {round}: {c:?}");
                    ckeys.insert(key(e[0], e[1]));
                }
            }
            check_locally_delaunay(&xy, &pert, &t, &und, &ckeys);
            // Euler: the whole hull is covered.
            let hv = (0..n).filter(|&i| on_hull_boundary(&xy, &h, i)).count();
            assert_eq!(t.len(), 2 * n - hv - 2, "round {round}");
            // Same result whatever the order of the vertices and constraints.
            let mut v2 = verts.clone();
            shuffle(&mut v2, &mut s);
            let mut c2_ = cons.clone();
            shuffle(&mut c2_, &mut s);
            let t2 = triangulate_facet(&pts, &pert, &v2, &c2_, &[], nrm).unwrap();
            assert_eq!(t2, t);
        }
    }

    fn on_hull_boundary(xy: &[[f64; 2]], h: &[u32], i: usize) -> bool {
        (0..h.len()).any(|k| {
            let (a, b) = (xy[h[k] as usize], xy[h[(k + 1) % h.len()] as usize]);
            let p = xy[i];
            o2(&a, &b, &p) == 0.0
                && p[0] >= a[0].min(b[0])
                && p[0] <= a[0].max(b[0])
                && p[1] >= a[1].min(b[1])
                && p[1] <= a[1].max(b[1])
        })
    }

    /// The pieces of constraint `c` between the vertices lying exactly on it.
    fn chain(xy: &[[f64; 2]], c: [u32; 2]) -> Vec<[u32; 2]> {
        let (a, b) = (xy[c[0] as usize], xy[c[1] as usize]);
        let mut on: Vec<(f64, u32)> = (0..xy.len() as u32)
            .filter(|&i| {
                let p = xy[i as usize];
                o2(&a, &b, &p) == 0.0
                    && p[0] >= a[0].min(b[0])
                    && p[0] <= a[0].max(b[0])
                    && p[1] >= a[1].min(b[1])
                    && p[1] <= a[1].max(b[1])
            })
            .map(|i| {
                let p = xy[i as usize];
                (
                    (p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1]),
                    i,
                )
            })
            .collect();
        on.sort_by(|x, y| x.0.total_cmp(&y.0));
        on.windows(2).map(|w| [w[0].1, w[1].1]).collect()
    }

    fn crosses_any(xy: &[[f64; 2]], e: [u32; 2], cons: &[[u32; 2]]) -> bool {
        let (a, b) = (xy[e[0] as usize], xy[e[1] as usize]);
        cons.iter().any(|c| {
            if c.contains(&e[0]) || c.contains(&e[1]) {
                return key(c[0], c[1]) == key(e[0], e[1]);
            }
            let (p, q) = (xy[c[0] as usize], xy[c[1] as usize]);
            let s1 = o2(&a, &b, &p) * o2(&a, &b, &q);
            let s2 = o2(&p, &q, &a) * o2(&p, &q, &b);
            s1 <= 0.0 && s2 <= 0.0
        })
    }

    fn check_valid_loose(
        p: &[Point],
        tris: &[[u32; 3]],
        normal: [f64; 3],
    ) -> FxHashMap<(u32, u32), Vec<usize>> {
        check_valid(p, tris, &[], normal)
    }

    #[test]
    fn nearly_coplanar_facets_triangulate() {
        let mut s = 3u64;
        for round in 0..rounds(20) {
            let m = 30 + 10 * round;
            // A square ring with points inside, on a tilted plane (or z = const) with a
            // relative deviation of 1e-5.
            let tilt = if round % 2 == 0 {
                (0.3, -0.7)
            } else {
                (0.0, 0.0)
            };
            let f = |x: f64, y: f64, s: &mut u64| -> Point {
                [x, y, tilt.0 * x + tilt.1 * y + 1e-5 * (lcg(s) - 0.5)]
            };
            let mut p: Vec<Point> = vec![
                f(0.0, 0.0, &mut s),
                f(1.0, 0.0, &mut s),
                f(1.0, 1.0, &mut s),
                f(0.0, 1.0, &mut s),
            ];
            // Steiner points nearly on the edges.
            let mut ring: Vec<u32> = Vec::new();
            for k in 0..4 {
                ring.push(k);
                let (a, b) = (p[k as usize], p[((k + 1) % 4) as usize]);
                for j in 1..4 {
                    let t = j as f64 / 4.0 + 0.01 * (lcg(&mut s) - 0.5);
                    let mut q: Point = std::array::from_fn(|i| a[i] + t * (b[i] - a[i]));
                    q[2] += 1e-5 * (lcg(&mut s) - 0.5);
                    p.push(q);
                    ring.push(p.len() as u32 - 1);
                }
            }
            while p.len() < m {
                let q = f(0.02 + 0.96 * lcg(&mut s), 0.02 + 0.96 * lcg(&mut s), &mut s);
                p.push(q);
            }
            let nrm = unit([-tilt.0, -tilt.1, 1.0]);
            let ids: Vec<u32> = (0..p.len() as u32).collect();
            let cons = ring_edges(&ring);
            let t = triangulate_facet(&p, &ids, &ids, &cons, &[], nrm).unwrap();
            let und = check_valid(&p, &t, &cons, nrm);
            let boundary = und.values().filter(|v| v.len() == 1).count();
            assert_eq!(boundary, ring.len());
            assert_eq!(t.len(), 2 * p.len() - ring.len() - 2);
        }
    }

    #[test]
    fn errors_and_degenerate_inputs() {
        let p: Vec<Point> = vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [0.0, 2.0, 0.0],
            [0.0, 0.0, 0.0],
        ];
        let ids: Vec<u32> = (0..5).collect();
        let n = [0.0, 0.0, 1.0];
        // Crossing constraints.
        let mut cons = ring_edges(&[0, 1, 2, 3]);
        cons.push([0, 2]);
        cons.push([1, 3]);
        let e = triangulate_facet(&p, &ids, &[3, 2, 1, 0], &cons, &[], n).unwrap_err();
        assert!(e.contains("crosses"), "{e}");
        assert!(e.contains("(2, 0)") && e.contains("(1, 3)"), "{e}");
        // Coincident vertices.
        let e = triangulate_facet(&p, &ids, &ids, &[], &[], n).unwrap_err();
        assert!(e.contains("coincide"), "{e}");
        // Collinear vertices only: nothing to triangulate.
        let q: Vec<Point> = (0..5).map(|i| [i as f64, 2.0 * i as f64, 1.0]).collect();
        let t = triangulate_facet(&q, &ids, &ids, &[[0, 4]], &[], n).unwrap();
        assert!(t.is_empty());
        // A constraint vertex outside the facet.
        assert!(triangulate_facet(&p, &ids, &ids[..3], &[[0, 3]], &[], n).is_err());
        // No closed ring: nothing is kept.
        let t = triangulate_facet(&p, &ids, &ids[..4], &[[0, 2]], &[], n).unwrap();
        assert!(t.is_empty());
        // Repeated vertex ids and repeated constraints are fine.
        let mut v = ids[..4].to_vec();
        v.extend([2, 1]);
        let mut c = ring_edges(&[0, 1, 2, 3]);
        c.push([1, 0]);
        let t = triangulate_facet(&p, &ids, &v, &c, &[], n).unwrap();
        assert_eq!(t.len(), 2);
    }

    #[test]
    fn large_facet_is_fast() {
        let mut s = 17u64;
        let m = 30000;
        let mut p: Vec<Point> = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.5],
            [1.0, 1.0, 1.0],
            [0.0, 1.0, 0.5],
        ];
        for _ in 4..m {
            let (x, y) = (lcg(&mut s), lcg(&mut s));
            p.push([x, y, 0.5 * x + 0.5 * y]);
        }
        // Integer grid too (massively cocircular), on z = 0.
        let mut g: Vec<Point> = Vec::new();
        for i in 0..150 {
            for j in 0..150 {
                g.push([i as f64, j as f64, 0.0]);
            }
        }
        let t0 = std::time::Instant::now();
        let ids: Vec<u32> = (0..m as u32).collect();
        let t = triangulate_facet(
            &p,
            &ids,
            &ids,
            &ring_edges(&[0, 1, 2, 3]),
            &[],
            unit([-0.5, -0.5, 1.0]),
        )
        .unwrap();
        assert_eq!(t.len(), 2 * m - 4 - 2);
        let gi: Vec<u32> = (0..g.len() as u32).collect();
        let corners = [0, 149 * 150, 150 * 150 - 1, 149];
        let tg =
            triangulate_facet(&g, &gi, &gi, &ring_edges(&corners), &[], [0.0, 0.0, 1.0]).unwrap();
        assert_eq!(tg.len(), 2 * 149 * 149);
        // The grid on a tilted plane (exact ties through the 3D predicates).
        let gt: Vec<Point> = g.iter().map(|q| [q[0], q[1], q[0] + 2.0 * q[1]]).collect();
        let tt = triangulate_facet(
            &gt,
            &gi,
            &gi,
            &ring_edges(&corners),
            &[],
            unit([-1.0, -2.0, 1.0]),
        )
        .unwrap();
        assert_eq!(tt.len(), 2 * 149 * 149);
        let el = t0.elapsed().as_secs_f64();
        eprintln!("large facets: {el:.3} s");
        assert!(el < 20.0, "took {el} s");
    }

    /// A rotated integer grid: coordinates rounded off the plane by ~1e-16 (the apex mode
    /// within tolerance), with its boundary points as the ring. Valid, complete, and the
    /// same whatever the insertion order.
    #[test]
    fn rotated_grid_is_valid_and_order_independent() {
        let mut s = 23u64;
        for round in 0..rounds(6) {
            let (a, b) = (lcg(&mut s) * 6.0, lcg(&mut s) * 3.0);
            // Rotation: about z by a, then about x by b.
            let rot = |p: [f64; 3]| -> Point {
                let (sa, ca) = a.sin_cos();
                let (sb, cb) = b.sin_cos();
                let q = [ca * p[0] - sa * p[1], sa * p[0] + ca * p[1], p[2]];
                [q[0], cb * q[1] - sb * q[2], sb * q[1] + cb * q[2]]
            };
            let k = 12 + round;
            let mut p: Vec<Point> = Vec::new();
            for j in 0..k {
                for i in 0..k {
                    p.push(rot([i as f64, j as f64, 0.5]));
                }
            }
            let id = |i: usize, j: usize| (j * k + i) as u32;
            let mut ring: Vec<u32> = Vec::new();
            for i in 0..k - 1 {
                ring.push(id(i, 0));
            }
            for j in 0..k - 1 {
                ring.push(id(k - 1, j));
            }
            for i in (1..k).rev() {
                ring.push(id(i, k - 1));
            }
            for j in (1..k).rev() {
                ring.push(id(0, j));
            }
            let normal = rot([0.0, 0.0, 1.0]);
            let pert: Vec<u32> = (0..p.len() as u32).collect();
            let cons = ring_edges(&ring);
            let t = triangulate_facet(&p, &pert, &pert, &cons, &[], normal).unwrap();
            check_valid(&p, &t, &cons, normal);
            assert_eq!(t.len(), 2 * k * k - ring.len() - 2);
            let mut v = pert.clone();
            shuffle(&mut v, &mut s);
            let t2 = triangulate_facet(&p, &pert, &v, &cons, &[], normal).unwrap();
            assert_eq!(t2, t);
        }
    }
}
