//! Incremental Delaunay tetrahedralization (Bowyer–Watson) with exact predicates and
//! TetGen's symbolic perturbation, so the result is the canonical Delaunay
//! tetrahedralization that TetGen computes.

use crate::error::MeshError;
use crate::geom::hilbert::insertion_order;
use crate::geom::{insphere, insphere_sos, orient3d, Point, Sign};
use crate::mesh::{FaceRef, Mesh, TetId, VertexId, GHOST};

/// Where a point lies relative to the current triangulation.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// Inside or on the boundary of this real tet.
    Inside(TetId),
    /// Outside the hull, beyond the hull face of this ghost tet.
    Outside(TetId),
    /// Coincides with this vertex.
    Vertex(VertexId),
}

/// A Delaunay tetrahedralization under construction: points, the tet arena and scratch.
///
/// Vertices are numbered internally in insertion order, so that tets made together
/// reference points stored together; `orig` maps them back to input indices, which are
/// also the perturbation indices.
#[derive(Clone, Debug)]
pub struct Delaunay {
    /// Points by internal vertex id.
    pub points: Vec<Point>,
    /// The input index (and perturbation index) of each internal vertex.
    pub orig: Vec<u32>,
    /// The tets.
    pub mesh: Mesh,
    /// Per tet slot, what the current insertion knows of it (`IN_CONFLICT`, ...); reset
    /// after every insertion. One byte a slot keeps the array in cache.
    mark: Vec<u8>,
    /// Where the next point location starts.
    last: TetId,
    rng: u64,
    conflict: Vec<TetId>,
    boundary: Vec<(TetId, usize)>,
    created: Vec<(TetId, usize)>,
}

/// The outcome of building a Delaunay tetrahedralization of a point set.
#[derive(Clone, Debug)]
pub struct Built {
    /// The tetrahedralization.
    pub dt: Delaunay,
    /// Points skipped as `(duplicate, kept)`: each equals the lower-indexed kept point.
    pub duplicates: Vec<(u32, u32)>,
}

impl Delaunay {
    /// Builds the Delaunay tetrahedralization of `points` (BRIO + Hilbert insertion order).
    pub fn build(points: &[Point]) -> Result<Built, MeshError> {
        if let Some((i, _)) = points
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
        {
            return Err(MeshError::Degenerate(format!(
                "point {i} has a non-finite coordinate"
            )));
        }
        if points.len() >= GHOST as usize {
            return Err(MeshError::Unsupported(format!(
                "{} points is more than this mesher can index",
                points.len()
            )));
        }
        let order = insertion_order(points);
        let n = order.order.len();
        let mut dt = Delaunay {
            mesh: Mesh::new(n),
            points: order.order.iter().map(|&i| points[i as usize]).collect(),
            orig: order.order,
            mark: Vec::new(),
            last: 0,
            rng: 0x2545_F491_4F6C_DD1D,
            conflict: Vec::new(),
            boundary: Vec::new(),
            created: Vec::new(),
        };
        // A DT of n random points has about 6.5 n tets; reserve to avoid regrowth.
        let expected = n * 7 + 16;
        dt.mesh.reserve(expected);
        dt.mark.reserve(expected);
        let first = dt.initial_tet()?;
        for v in 0..n as u32 {
            if first.contains(&v) {
                continue;
            }
            dt.insert(v)?;
        }
        dt.mesh.rebuild_vertex_map();
        Ok(Built {
            dt,
            duplicates: order.duplicates,
        })
    }

    /// Creates the first tet from four affinely independent points (the earliest in
    /// insertion order) and the four ghost tets around it.
    fn initial_tet(&mut self) -> Result<[u32; 4], MeshError> {
        let n = self.points.len();
        let order: Vec<u32> = (0..n as u32).collect();
        if n < 4 {
            return Err(MeshError::Degenerate(format!(
                "only {n} distinct point(s): a tetrahedralization needs 4 points not all coplanar"
            )));
        }
        let p = |i: u32| self.points[i as usize];
        let a = order[0];
        let b = order[1];
        let c = order[2..]
            .iter()
            .copied()
            .find(|&c| !collinear(&p(a), &p(b), &p(c)))
            .ok_or_else(|| {
                MeshError::Degenerate(format!("all {n} distinct points are collinear"))
            })?;
        let d = order[2..]
            .iter()
            .copied()
            .find(|&d| orient3d(&p(a), &p(b), &p(c), &p(d)) != 0.0)
            .ok_or_else(|| {
                MeshError::Degenerate(format!("all {n} distinct points are coplanar"))
            })?;
        let v = if orient3d(&p(a), &p(b), &p(c), &p(d)) > 0.0 {
            [a, b, c, d]
        } else {
            [b, a, c, d]
        };
        let t = self.add_tet(v)?;
        let mut ghosts = [0; 4];
        for (i, g) in ghosts.iter_mut().enumerate() {
            let f = self.mesh.face_verts(t, i);
            *g = self.add_tet([f[0], f[2], f[1], GHOST])?;
            self.mesh.glue(FaceRef::new(t, i), FaceRef::new(*g, 3));
        }
        self.glue_small(&ghosts);
        self.last = t;
        Ok(v)
    }

    fn add_tet(&mut self, v: [VertexId; 4]) -> Result<TetId, MeshError> {
        let t = self
            .mesh
            .add_tet(v)
            .map_err(|_| MeshError::Unsupported("the mesh exceeds 2^30 tets".into()))?;
        if t as usize >= self.mark.len() {
            self.mark.resize(t as usize + 1, 0);
        }
        Ok(t)
    }

    #[inline(always)]
    fn pt(&self, v: VertexId) -> &Point {
        &self.points[v as usize]
    }

    #[inline]
    fn next_rand(&mut self) -> u64 {
        // xorshift64: only used to vary the face order of the walk.
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.rng = x;
        x
    }

    /// Locates point `p` by a visibility walk from the last tet created.
    pub fn locate(&mut self, p: &Point) -> Location {
        let mut t = self.last;
        if !self.mesh.is_alive(t) {
            t = self.mesh.real_tets().next().unwrap_or(0);
        }
        if self.mesh.is_ghost(t) {
            t = self.mesh.adj(FaceRef::new(t, 3)).tet();
        }
        let mut from = 4usize;
        loop {
            let start = (self.next_rand() & 3) as usize;
            let mut next = None;
            let mut on_boundary = false;
            for r in 0..4 {
                let i = (start + r) & 3;
                if i == from {
                    continue;
                }
                let f = self.mesh.face_verts(t, i);
                let o = orient3d(self.pt(f[0]), self.pt(f[1]), self.pt(f[2]), p);
                if o < 0.0 {
                    next = Some(self.mesh.adj(FaceRef::new(t, i)));
                    break;
                }
                if o == 0.0 {
                    on_boundary = true;
                }
            }
            match next {
                None => {
                    if on_boundary {
                        if let Some(&v) = self.mesh.verts(t).iter().find(|&&v| self.pt(v) == p) {
                            return Location::Vertex(v);
                        }
                    }
                    return Location::Inside(t);
                }
                Some(f) => {
                    t = f.tet();
                    from = f.face();
                    if self.mesh.is_ghost(t) {
                        return Location::Outside(t);
                    }
                }
            }
        }
    }

    /// Is tet `t` in conflict with point `p` (vertex id `pv`)?
    fn in_conflict(&self, t: TetId, p: &Point, pv: VertexId) -> bool {
        let v = self.mesh.verts(t);
        if v[3] == GHOST {
            let o = orient3d(self.pt(v[0]), self.pt(v[1]), self.pt(v[2]), p);
            if o != 0.0 {
                return o > 0.0;
            }
            // p lies in the plane of the hull face: the ghost's "sphere" is then the
            // face's circumcircle, which the adjacent real tet's circumsphere cuts out of
            // that plane; testing that tet keeps the perturbation consistent.
            let r = self.mesh.adj(FaceRef::new(t, 3)).tet();
            return self.in_sphere(r, p, pv);
        }
        self.in_sphere(t, p, pv)
    }

    #[inline]
    fn in_sphere(&self, t: TetId, p: &Point, pv: VertexId) -> bool {
        let v = self.mesh.verts(t);
        let pts = [
            self.pt(v[0]),
            self.pt(v[1]),
            self.pt(v[2]),
            self.pt(v[3]),
            p,
        ];
        let s = insphere(pts[0], pts[1], pts[2], pts[3], pts[4]);
        if s != 0.0 {
            return s > 0.0;
        }
        let ids = [v[0], v[1], v[2], v[3], pv].map(|x| self.orig[x as usize]);
        insphere_sos(pts, ids) == Sign::Positive
    }

    /// Inserts vertex `pv` (already in `points`). Returns `Ok(false)` if it coincides with
    /// an existing vertex and was skipped.
    pub fn insert(&mut self, pv: VertexId) -> Result<bool, MeshError> {
        let p = *self.pt(pv);
        let start = match self.locate(&p) {
            Location::Vertex(_) => return Ok(false),
            Location::Inside(t) | Location::Outside(t) => t,
        };
        self.conflict.clear();
        self.boundary.clear();
        if !self.in_conflict(start, &p, pv) {
            return Err(MeshError::Internal(format!(
                "point {pv} lies in tet {start} but not in its circumsphere"
            )));
        }
        self.mark[start as usize] = IN_CONFLICT;
        self.conflict.push(start);
        let mut k = 0;
        while k < self.conflict.len() {
            let t = self.conflict[k];
            k += 1;
            for f in 0..4 {
                let n = self.mesh.adj(FaceRef::new(t, f)).tet();
                match self.mark[n as usize] {
                    IN_CONFLICT => {}
                    OUTSIDE => self.boundary.push((t, f)),
                    _ => {
                        if self.in_conflict(n, &p, pv) {
                            self.mark[n as usize] = IN_CONFLICT;
                            self.conflict.push(n);
                        } else {
                            self.mark[n as usize] = OUTSIDE;
                            self.boundary.push((t, f));
                        }
                    }
                }
            }
        }
        self.fill_cavity(pv)
    }

    /// Replaces the conflict tets by the fan of new tets from `pv` to the cavity boundary.
    ///
    /// The new tets take fresh slots, so the conflict tets can still be read while the new
    /// ones are glued: each boundary face's link is redirected to its new tet, and the
    /// neighbour of a new tet across a face through `pv` is found by turning around the
    /// cavity edge in that face, through the old tets, until a redirected link is met.
    fn fill_cavity(&mut self, pv: VertexId) -> Result<bool, MeshError> {
        self.created.clear();
        let mut real = None;
        for bi in 0..self.boundary.len() {
            let (t, f) = self.boundary[bi];
            let mut v = self.mesh.verts(t);
            v[f] = pv;
            let outside = self.mesh.adj(FaceRef::new(t, f));
            let n = self.add_tet(v)?;
            self.mesh.glue(FaceRef::new(n, f), outside);
            self.mesh.set_link(FaceRef::new(t, f), FaceRef::new(n, f));
            self.mark[n as usize] = NEW;
            self.created.push((n, f));
            if v[3] != GHOST {
                real = Some(n);
            }
        }
        for bi in 0..self.boundary.len() {
            let (t, f) = self.boundary[bi];
            let (n, _) = self.created[bi];
            for k in 0..4 {
                if k == f || self.mesh.tet(n).adj[k].0 != u32::MAX {
                    continue;
                }
                let tv = self.mesh.verts(t);
                let (a, b) = other_two(f, k);
                let (ea, eb) = (tv[a], tv[b]);
                let (mut cur, mut face) = (t, k);
                loop {
                    let next = self.mesh.adj(FaceRef::new(cur, face));
                    let nt = next.tet();
                    let cv = self.mesh.verts(cur);
                    if self.mark[nt as usize] == NEW {
                        let w = third_slot(&cv, face, ea, eb);
                        self.mesh.glue(FaceRef::new(n, k), FaceRef::new(nt, w));
                        break;
                    }
                    face = third_slot(&self.mesh.verts(nt), next.face(), ea, eb);
                    cur = nt;
                }
            }
        }
        for i in 0..self.conflict.len() {
            let t = self.conflict[i];
            self.mark[t as usize] = 0;
            self.mesh.kill_tet(t);
        }
        for &(n, f) in &self.created {
            self.mark[n as usize] = 0;
            let outside = self.mesh.adj(FaceRef::new(n, f)).tet();
            self.mark[outside as usize] = 0;
        }
        if let Some(t) = real {
            self.last = t;
        }
        Ok(true)
    }

    /// Glues a handful of new tets to each other by comparing their faces pairwise.
    fn glue_small(&mut self, tets: &[TetId]) {
        for (x, &t) in tets.iter().enumerate() {
            for &u in &tets[x + 1..] {
                for i in 0..4 {
                    let mut fi = self.mesh.face_verts(t, i);
                    fi.sort_unstable();
                    for j in 0..4 {
                        let mut fj = self.mesh.face_verts(u, j);
                        fj.sort_unstable();
                        if fi == fj {
                            self.mesh.glue(FaceRef::new(t, i), FaceRef::new(u, j));
                        }
                    }
                }
            }
        }
    }

    /// Number of live non-ghost tets.
    pub fn num_tets(&self) -> usize {
        self.mesh.real_tets().count()
    }
}

/// The two slots of a tet other than `j` and `k`.
#[inline(always)]
fn other_two(j: usize, k: usize) -> (usize, usize) {
    let mut r = [0usize; 2];
    let mut n = 0;
    for s in 0..4 {
        if s != j && s != k {
            r[n] = s;
            n += 1;
        }
    }
    (r[0], r[1])
}

/// Marks of tets during one insertion.
const IN_CONFLICT: u8 = 1;
const OUTSIDE: u8 = 2;
const NEW: u8 = 3;

/// The slot of `v` other than `skip` holding neither `a` nor `b`.
#[inline(always)]
fn third_slot(v: &[VertexId; 4], skip: usize, a: VertexId, b: VertexId) -> usize {
    // Branch-free: the four slots sum to 6, and `a`, `b` are in `v` exactly once.
    let slot = |x: VertexId| {
        usize::from(v[1] == x) + 2 * usize::from(v[2] == x) + 3 * usize::from(v[3] == x)
    };
    6 - skip - slot(a) - slot(b)
}

/// Exact collinearity: all three axis-aligned projections have zero area.
fn collinear(a: &Point, b: &Point, c: &Point) -> bool {
    let proj = |i: usize, j: usize| {
        robust::orient2d(
            robust::Coord { x: a[i], y: a[j] },
            robust::Coord { x: b[i], y: b[j] },
            robust::Coord { x: c[i], y: c[j] },
        )
    };
    proj(0, 1) == 0.0 && proj(1, 2) == 0.0 && proj(0, 2) == 0.0
}

#[cfg(test)]
mod tests;

impl Delaunay {
    /// The live real tets as quadruples of input indices (compactly numbered) and, for
    /// each, the numbers of its neighbours across faces 0..4 (-1 across hull faces).
    /// Consumes the triangulation so that its memory can be reused for the numbering.
    pub fn export(mut self) -> (Vec<[u32; 4]>, Vec<[i64; 4]>) {
        self.mark = Vec::new();
        let mut number = vec![0u32; self.mesh.num_slots()];
        let mut count = 0u32;
        for t in self.mesh.real_tets() {
            number[t as usize] = count;
            count += 1;
        }
        let mut tets = Vec::with_capacity(count as usize);
        let mut neighbors = Vec::with_capacity(count as usize);
        for t in self.mesh.real_tets() {
            tets.push(self.mesh.verts(t).map(|v| self.orig[v as usize]));
            let mut nb = [-1i64; 4];
            for (i, slot) in nb.iter_mut().enumerate() {
                let n = self.mesh.adj(FaceRef::new(t, i)).tet();
                if !self.mesh.is_ghost(n) {
                    *slot = i64::from(number[n as usize]);
                }
            }
            neighbors.push(nb);
        }
        (tets, neighbors)
    }
}
