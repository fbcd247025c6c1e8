//! Incremental Delaunay tetrahedralization (Bowyer–Watson) with exact predicates and
//! TetGen's symbolic perturbation, so the result is the canonical Delaunay
//! tetrahedralization that TetGen computes.

use crate::error::MeshError;
use crate::geom::hilbert::insertion_order;
use crate::geom::{insphere_sos, orient3d, Point, Sign, StaticFilter};
use crate::mesh::{FaceRef, Mesh, TetId, VertexId, FACE_VERTS, GHOST};

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
    /// Per tet slot, the walk that last visited it (see [`Delaunay::find_around`]), and
    /// the current walk's stamp: a star walk then tests membership in O(1).
    visit: std::cell::RefCell<(Vec<u32>, u32)>,
    /// Where the next point location starts.
    last: TetId,
    rng: u64,
    conflict: Vec<TetId>,
    /// The cavity's boundary faces, as the new tets that will rest on them.
    boundary: Vec<NewTet>,
    /// The tets made by the last insertion, each with its face opposite the new vertex.
    created: Vec<(TetId, usize)>,
    edges: EdgeTable,
    /// A box holding every vertex, and the predicates' static error bounds for it.
    bbox: [Point; 2],
    filter: StaticFilter,
    /// Steps taken by point-location walks so far (work that callers may bound).
    walk_steps: u64,
}

/// What [`Delaunay::blocked_cavity`] found.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Cavity {
    /// The point coincides with a vertex.
    OnVertex,
    /// The cavity wraps around a blocked face: filling it would break the mesh.
    Wraps,
    /// The cavity is ready to be filled.
    Ready,
}

/// A tet to be made by an insertion: its vertices (the new vertex in slot `face`) and
/// the outside face it is glued to across face `face`.
#[derive(Copy, Clone, Debug)]
struct NewTet {
    v: [VertexId; 4],
    face: usize,
    outside: FaceRef,
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
        Self::build_until(points, &std::sync::atomic::AtomicBool::new(false))
    }

    /// [`Delaunay::build`], giving up (with a failure whose reason is never shown) once
    /// `stop` is set by another thread that found the run pointless.
    pub fn build_until(
        points: &[Point],
        stop: &std::sync::atomic::AtomicBool,
    ) -> Result<Built, MeshError> {
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
            visit: Default::default(),
            last: 0,
            rng: 0x2545_F491_4F6C_DD1D,
            conflict: Vec::new(),
            boundary: Vec::new(),
            created: Vec::new(),
            edges: EdgeTable::default(),
            bbox: [[0.0; 3]; 2],
            filter: StaticFilter::new(&[0.0; 3], &[0.0; 3]),
            walk_steps: 0,
        };
        dt.set_bbox(crate::geom::bounding_box(&dt.points));
        // A DT of n random points has about 6.5 n tets; reserve to avoid regrowth.
        let expected = n * 7 + 16;
        dt.mesh.reserve(expected);
        dt.mark.reserve(expected);
        let first = dt.initial_tet()?;
        for v in 0..n as u32 {
            if first.contains(&v) {
                continue;
            }
            if v % 4096 == 0 && stop.load(std::sync::atomic::Ordering::Relaxed) {
                return Err(MeshError::Failed("stopped".into()));
            }
            dt.insert(v)?;
        }
        dt.mesh.rebuild_vertex_map();
        Ok(Built {
            dt,
            duplicates: order.duplicates,
        })
    }

    /// Sets the box holding every vertex, and the static filter bounds that go with it.
    fn set_bbox(&mut self, bbox: [Point; 2]) {
        self.bbox = bbox;
        self.filter = StaticFilter::new(&bbox[0], &bbox[1]);
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

    /// Makes the next point location start at tet `t` (if alive): a caller that knows a
    /// tet near the next point saves the walk.
    pub fn start_walks_at(&mut self, t: TetId) {
        if self.mesh.is_alive(t) && !self.mesh.is_ghost(t) {
            self.last = t;
        }
    }

    /// Locates point `p` by a visibility walk from the last tet created.
    pub fn locate(&mut self, p: &Point) -> Location {
        self.locate_within(p, usize::MAX)
    }

    /// [`Delaunay::locate`] in a tetrahedralization that need not be Delaunay (a
    /// constrained one), where the walk can cycle: past a bound on its steps, every tet
    /// is tested instead. (In a Delaunay tetrahedralization the walk ends, though around
    /// far-off vertices only after many steps.)
    pub fn locate_anywhere(&mut self, p: &Point) -> Location {
        self.locate_within(p, 4 * self.mesh.num_slots() + 1000)
    }

    /// [`Delaunay::locate_anywhere`], walking from tet `start` (a tet near `p` keeps the
    /// walk short).
    pub fn locate_anywhere_from(&mut self, start: TetId, p: &Point) -> Location {
        if self.mesh.is_alive(start) {
            self.last = start;
        }
        self.locate_anywhere(p)
    }

    /// The walk of [`Delaunay::locate`], giving up after `max_steps` for a scan.
    fn locate_within(&mut self, p: &Point, max_steps: usize) -> Location {
        let mut t = self.last;
        if !self.mesh.is_alive(t) {
            t = self.mesh.real_tets().next().unwrap_or(0);
        }
        if self.mesh.is_ghost(t) {
            t = self.mesh.adj(FaceRef::new(t, 3)).tet();
        }
        let mut from = 4usize;
        let mut steps = 0usize;
        loop {
            steps += 1;
            if steps > max_steps {
                self.walk_steps += steps as u64;
                return self.locate_by_scan(p);
            }
            let start = (self.next_rand() & 3) as usize;
            let mut next = None;
            let mut on_boundary = false;
            for r in 0..4 {
                let i = (start + r) & 3;
                if i == from {
                    continue;
                }
                let f = self.mesh.face_verts(t, i);
                let o = self
                    .filter
                    .orient3d(self.pt(f[0]), self.pt(f[1]), self.pt(f[2]), p);
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
                    self.walk_steps += steps as u64;
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
                        self.walk_steps += steps as u64;
                        return Location::Outside(t);
                    }
                }
            }
        }
    }

    /// Steps taken by point-location walks so far (a scan past a walk's bound counts as
    /// the walk's steps).
    pub fn walk_steps(&self) -> u64 {
        self.walk_steps
    }

    /// [`Delaunay::locate`] by testing every live tet: a real tet holding `p`, else a
    /// ghost tet whose hull face `p` lies beyond.
    #[cold]
    fn locate_by_scan(&self, p: &Point) -> Location {
        let sees = |t: TetId, i: usize| {
            let f = self.mesh.face_verts(t, i);
            self.filter
                .orient3d(self.pt(f[0]), self.pt(f[1]), self.pt(f[2]), p)
        };
        let mut outside = None;
        for t in self.mesh.live_tets() {
            if self.mesh.is_ghost(t) {
                if outside.is_none() && sees(t, 3) > 0.0 {
                    outside = Some(t);
                }
                continue;
            }
            let o = [0, 1, 2, 3].map(|i| sees(t, i));
            if o.iter().all(|&x| x >= 0.0) {
                if o.contains(&0.0) {
                    if let Some(&v) = self.mesh.verts(t).iter().find(|&&v| self.pt(v) == p) {
                        return Location::Vertex(v);
                    }
                }
                return Location::Inside(t);
            }
        }
        match outside {
            Some(t) => Location::Outside(t),
            None => Location::Inside(self.mesh.real_tets().next().unwrap_or(0)),
        }
    }

    /// The sign of the orientation of a real tet (0 when flat).
    fn orientation(&self, v: [VertexId; 4]) -> i8 {
        let o = self
            .filter
            .orient3d(self.pt(v[0]), self.pt(v[1]), self.pt(v[2]), self.pt(v[3]));
        (o > 0.0) as i8 - (o < 0.0) as i8
    }

    /// Is tet `t` in conflict with point `p` (vertex id `pv`)?
    fn in_conflict(&self, t: TetId, p: &Point, pv: VertexId) -> bool {
        self.in_conflict_with(t, self.mesh.verts(t), p, pv)
    }

    /// [`Self::in_conflict`] given the vertices `v` of tet `t`.
    #[inline]
    fn in_conflict_with(&self, t: TetId, v: [VertexId; 4], p: &Point, pv: VertexId) -> bool {
        if v[3] == GHOST {
            let o = self
                .filter
                .orient3d(self.pt(v[0]), self.pt(v[1]), self.pt(v[2]), p);
            if o != 0.0 {
                return o > 0.0;
            }
            // p lies in the plane of the hull face: the ghost's "sphere" is then the
            // face's circumcircle, which the adjacent real tet's circumsphere cuts out of
            // that plane; testing that tet keeps the perturbation consistent.
            let r = self.mesh.adj(FaceRef::new(t, 3)).tet();
            return self.in_sphere(r, p, pv);
        }
        self.in_sphere_with(v, p, pv)
    }

    #[inline]
    fn in_sphere(&self, t: TetId, p: &Point, pv: VertexId) -> bool {
        self.in_sphere_with(self.mesh.verts(t), p, pv)
    }

    #[inline]
    fn in_sphere_with(&self, v: [VertexId; 4], p: &Point, pv: VertexId) -> bool {
        let s = self.filter.insphere(
            self.pt(v[0]),
            self.pt(v[1]),
            self.pt(v[2]),
            self.pt(v[3]),
            p,
        );
        if s != 0.0 {
            return s > 0.0;
        }
        self.in_sphere_tie(v, p, pv)
    }

    /// [`Self::in_sphere`] when the five points are cospherical: the perturbation decides.
    #[cold]
    #[inline(never)]
    fn in_sphere_tie(&self, v: [VertexId; 4], p: &Point, pv: VertexId) -> bool {
        let pts = [
            self.pt(v[0]),
            self.pt(v[1]),
            self.pt(v[2]),
            self.pt(v[3]),
            p,
        ];
        let ids = [v[0], v[1], v[2], v[3], pv].map(|x| self.orig[x as usize]);
        insphere_sos(pts, ids) == Sign::Positive
    }

    /// Inserts vertex `pv` (already in `points`). Returns `Ok(false)` if it coincides with
    /// an existing vertex and was skipped.
    pub fn insert(&mut self, pv: VertexId) -> Result<bool, MeshError> {
        self.insert_noting(pv, None)
    }

    /// [`Delaunay::insert`], also listing in `removed` (when given) the vertices of the
    /// tets the insertion replaced.
    fn insert_noting(
        &mut self,
        pv: VertexId,
        removed: Option<&mut Vec<[VertexId; 4]>>,
    ) -> Result<bool, MeshError> {
        match self.blocked_cavity(pv, |_, _| false)? {
            Cavity::OnVertex => Ok(false),
            // Nothing is blocked, so the cavity cannot wrap around anything.
            Cavity::Wraps => Err(MeshError::Internal(
                "the cavity of a vertex wraps around a constraint".into(),
            )),
            Cavity::Ready => {
                if let Some(removed) = removed {
                    removed.clear();
                    removed.extend(self.conflict.iter().map(|&t| self.mesh.verts(t)));
                }
                self.fill_cavity()
            }
        }
    }

    /// Widens the box of the static filter to cover Steiner point `p`.
    pub(crate) fn widen_box(&mut self, p: &Point) {
        let [lo, hi] = self.bbox;
        if (0..3).any(|k| !(lo[k] <= p[k] && p[k] <= hi[k])) {
            self.set_bbox([
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            ]);
        }
    }

    /// Finds the cavity of vertex `pv` walled in by the `blocked` faces (in `conflict`
    /// and `boundary`), without changing the mesh.
    fn blocked_cavity(
        &mut self,
        pv: VertexId,
        blocked: impl Fn([VertexId; 4], usize) -> bool,
    ) -> Result<Cavity, MeshError> {
        let p = *self.pt(pv);
        self.widen_box(&p);
        let start = match self.locate(&p) {
            Location::Vertex(_) => return Ok(Cavity::OnVertex),
            Location::Inside(t) | Location::Outside(t) => t,
        };
        if !self.in_conflict(start, &p, pv) {
            return Err(MeshError::Internal(format!(
                "point {pv} lies in tet {start} but not in its circumsphere"
            )));
        }
        Ok(self.grow_cavity(pv, &[start], blocked))
    }

    /// Grows the cavity of vertex `pv` from the tets `seeds` (taken whole), walled in by
    /// the `blocked` faces, into `conflict` and `boundary`, without changing the mesh.
    pub(crate) fn grow_cavity(
        &mut self,
        pv: VertexId,
        seeds: &[TetId],
        blocked: impl Fn([VertexId; 4], usize) -> bool,
    ) -> Cavity {
        let p = *self.pt(pv);
        // The constrained stages add tets behind this struct's back.
        if self.mark.len() < self.mesh.num_slots() {
            self.mark.resize(self.mesh.num_slots(), 0);
        }
        self.conflict.clear();
        self.boundary.clear();
        for &t in seeds {
            if self.mark[t as usize] != IN_CONFLICT {
                self.mark[t as usize] = IN_CONFLICT;
                self.conflict.push(t);
            }
        }
        let mut walled = false;
        let mut wraps = false;
        let mut k = 0;
        while k < self.conflict.len() {
            let t = self.conflict[k];
            k += 1;
            // One copy of the tet: its vertices and links are all read below.
            let tet = *self.mesh.tet(t);
            // The four neighbours read up front, so that their cache misses overlap
            // instead of each waiting behind the previous neighbour's test.
            let nb = |f: usize| self.mesh.verts(tet.adj[f].tet());
            let around = [nb(0), nb(1), nb(2), nb(3)];
            for (f, &outside) in tet.adj.iter().enumerate() {
                let n = outside.tet();
                let state = self.mark[n as usize];
                if blocked(tet.v, f) {
                    // A wall: the tet behind it is left unmarked, since the cavity may
                    // still reach it around the wall, which is then destroyed (below).
                    walled = true;
                    wraps |= state == IN_CONFLICT;
                } else if state == IN_CONFLICT {
                    continue;
                } else if state != OUTSIDE {
                    if self.in_conflict_with(n, around[f], &p, pv) {
                        self.mark[n as usize] = IN_CONFLICT;
                        self.conflict.push(n);
                        continue;
                    }
                    self.mark[n as usize] = OUTSIDE;
                }
                let mut v = tet.v;
                v[f] = pv;
                self.boundary.push(NewTet {
                    v,
                    face: f,
                    outside,
                });
            }
        }
        // A cavity that reached both sides of a blocked face would destroy it. (One that
        // wrapped around a blocked face into tets hidden from the new vertex would make
        // inverted tets: `fill_is_positive` refuses it.)
        if walled
            && (wraps
                || self
                    .boundary
                    .iter()
                    .any(|b| self.mark[b.outside.tet() as usize] == IN_CONFLICT))
        {
            self.abandon_cavity();
            return Cavity::Wraps;
        }
        Cavity::Ready
    }

    /// Shrinks a grown cavity of vertex `pv` until it is seen whole from the vertex
    /// (every boundary face makes a positive tet with it), as a cavity in a constrained
    /// tetrahedralization must be: a tet with a boundary face the vertex does not see
    /// strictly leaves, with the tets it alone connected to `seeds`, and the boundary is
    /// made again. A boundary face that is `unfillable` (its three vertices and the
    /// vertex would make a flat tet on a constraint) counts as one it does not see,
    /// unless a seed holds it.
    /// False, with the marks cleared, if a seed would have to leave; the faces made by
    /// filling are then not all locally Delaunay, and flips settle them.
    pub(crate) fn shrink_to_star(
        &mut self,
        pv: VertexId,
        seeds: &[TetId],
        blocked: impl Fn([VertexId; 4], usize) -> bool,
        unfillable: impl Fn([VertexId; 3]) -> bool,
    ) -> bool {
        // Every tet marked outside during growth is the outside of a boundary face.
        for i in 0..self.boundary.len() {
            let n = self.boundary[i].outside.tet() as usize;
            if self.mark[n] == OUTSIDE {
                self.mark[n] = 0;
            }
        }
        loop {
            let bad: Vec<TetId> = self
                .boundary
                .iter()
                .filter(|b| {
                    !b.v.contains(&GHOST)
                        && (self.orientation(b.v) <= 0
                            || (unfillable(FACE_VERTS[b.face].map(|k| b.v[k]))
                                && !seeds.contains(&self.mesh.adj(b.outside).tet())))
                })
                .map(|b| self.mesh.adj(b.outside).tet())
                .collect();
            if bad.is_empty() {
                return true;
            }
            if bad.iter().any(|t| seeds.contains(t)) {
                self.abandon_cavity();
                return false;
            }
            for &t in &bad {
                self.mark[t as usize] = 0;
            }
            // What stays is what the seeds still reach through faces that are not walls.
            let kept: Vec<TetId> = std::mem::take(&mut self.conflict);
            for &t in &kept {
                if self.mark[t as usize] == IN_CONFLICT {
                    self.mark[t as usize] = OUTSIDE;
                }
            }
            for &t in seeds {
                self.mark[t as usize] = IN_CONFLICT;
                self.conflict.push(t);
            }
            let mut k = 0;
            while k < self.conflict.len() {
                let t = self.conflict[k];
                k += 1;
                let tet = *self.mesh.tet(t);
                for (f, n) in tet.adj.iter().enumerate() {
                    let n = n.tet() as usize;
                    if self.mark[n] == OUTSIDE && !blocked(tet.v, f) {
                        self.mark[n] = IN_CONFLICT;
                        self.conflict.push(n as TetId);
                    }
                }
            }
            for &t in &kept {
                if self.mark[t as usize] == OUTSIDE {
                    self.mark[t as usize] = 0;
                }
            }
            self.boundary.clear();
            for i in 0..self.conflict.len() {
                let t = self.conflict[i];
                let tet = *self.mesh.tet(t);
                for (f, &outside) in tet.adj.iter().enumerate() {
                    if blocked(tet.v, f) || self.mark[outside.tet() as usize] != IN_CONFLICT {
                        let mut v = tet.v;
                        v[f] = pv;
                        self.boundary.push(NewTet {
                            v,
                            face: f,
                            outside,
                        });
                    }
                }
            }
        }
    }

    /// Clears the marks of a cavity that will not be filled.
    pub(crate) fn abandon_cavity(&mut self) {
        for i in 0..self.conflict.len() {
            self.mark[self.conflict[i] as usize] = 0;
        }
        for i in 0..self.boundary.len() {
            self.mark[self.boundary[i].outside.tet() as usize] = 0;
        }
    }

    /// Whether the cavity's boundary is a closed surface in which every edge joins
    /// exactly two faces, seen in opposite directions: true of every cavity in a
    /// Delaunay tetrahedralization, but in a constrained one (not Delaunay near its
    /// constraints) the tets in conflict can pinch, meeting along an edge only, and
    /// filling such a cavity would glue the new tets wrongly.
    pub(crate) fn boundary_is_a_sphere(&self) -> bool {
        let mut directed: rustc_hash::FxHashSet<(VertexId, VertexId)> =
            rustc_hash::FxHashSet::with_capacity_and_hasher(
                3 * self.boundary.len(),
                Default::default(),
            );
        for b in &self.boundary {
            for (_, (x, y)) in FAN_EDGES[b.face] {
                if !directed.insert((b.v[x], b.v[y])) {
                    return false;
                }
            }
        }
        directed.iter().all(|&(a, c)| directed.contains(&(c, a)))
    }

    /// Whether every vertex of the cavity's tets lies on its boundary. A Delaunay cavity
    /// never holds a vertex inside, but a seeded or walled one can take every tet around
    /// a vertex (a split point near a corner of the domain): filling it would drop that
    /// vertex, and the constraints at it, from the mesh.
    pub(crate) fn encloses_no_vertex(&self) -> bool {
        let on: rustc_hash::FxHashSet<VertexId> = self.boundary.iter().flat_map(|b| b.v).collect();
        self.conflict.iter().all(|&t| {
            self.mesh
                .verts(t)
                .iter()
                .all(|v| *v == GHOST || on.contains(v))
        })
    }

    /// Whether every real tet the cavity's fill would make is positively oriented. True of
    /// every Delaunay cavity, but in a constrained tetrahedralization a cavity need not be
    /// seen whole from the new point: it may wrap around a wall, or (found by fuzzing
    /// `-F`, with no wall met) grow through tets that are not Delaunay. Filling it would
    /// make inverted tets that overlap others.
    pub(crate) fn fill_is_positive(&self) -> bool {
        self.boundary
            .iter()
            .all(|b| b.v[3] == GHOST || self.orientation(b.v) > 0)
    }

    /// Replaces the conflict tets by the fan of new tets from the new vertex to the cavity
    /// boundary (`self.boundary`, which already holds everything read from the old tets).
    ///
    /// The new tets reuse the conflict tets' slots first: those are hot in cache. Two new
    /// tets are neighbours across a face through the new vertex exactly when their
    /// boundary faces share an edge, which the two faces see in opposite directions; so
    /// every face first files its directed edge in a small hash table, then looks up the
    /// reversed edge. (This replaced turning around each edge through the old tets, which
    /// cost a quarter of the build; two passes keep the branches predictable.)
    fn fill_cavity(&mut self) -> Result<bool, MeshError> {
        self.created.clear();
        let stamp = self.edges.start(self.boundary.len());
        let mut real = None;
        for i in 0..self.boundary.len() {
            let nt = self.boundary[i];
            let n = match self.conflict.get(i) {
                Some(&t) => {
                    self.mesh.reset_tet(t, nt.v);
                    t
                }
                None => self.add_tet(nt.v)?,
            };
            self.mark[n as usize] = 0;
            self.mesh.glue(FaceRef::new(n, nt.face), nt.outside);
            self.mark[nt.outside.tet() as usize] = 0;
            self.created.push((n, nt.face));
            if nt.v[3] != GHOST {
                real = Some(n);
            }
            for (k, (a, b)) in FAN_EDGES[nt.face] {
                self.edges
                    .insert(stamp, nt.v[a], nt.v[b], FaceRef::new(n, k));
            }
        }
        for i in 0..self.boundary.len() {
            let (n, f) = self.created[i];
            let v = self.boundary[i].v;
            for (k, (a, b)) in FAN_EDGES[f] {
                // Every edge of a closed cavity boundary is filed from both sides.
                let there = self.edges.find(stamp, v[b], v[a]).ok_or_else(|| {
                    MeshError::Internal(format!("cavity edge ({}, {}) has no twin", v[b], v[a]))
                })?;
                self.mesh.set_link(FaceRef::new(n, k), there);
            }
        }
        for i in self.boundary.len()..self.conflict.len() {
            let t = self.conflict[i];
            self.mark[t as usize] = 0;
            self.mesh.kill_tet(t);
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

/// `FAN_EDGES[j]`: for a new tet whose new vertex sits in slot `j`, its three faces `k`
/// through that vertex, each with the slots `(a, b)` such that the face, seen as in
/// [`FACE_VERTS`], is the cyclic order `(j, a, b)`. The neighbour across face `k` sees
/// the same face reversed, as `(new vertex, v[b], v[a])`.
const FAN_EDGES: [[(usize, (usize, usize)); 3]; 4] = {
    let mut t = [[(0, (0, 0)); 3]; 4];
    let mut j = 0;
    while j < 4 {
        let mut n = 0;
        let mut k = 0;
        while k < 4 {
            if k != j {
                let f = FACE_VERTS[k];
                let p = if f[0] == j {
                    0
                } else if f[1] == j {
                    1
                } else {
                    2
                };
                t[j][n] = (k, (f[(p + 1) % 3], f[(p + 2) % 3]));
                n += 1;
            }
            k += 1;
        }
        j += 1;
    }
    t
};

/// Marks of tets during one insertion.
const IN_CONFLICT: u8 = 1;
const OUTSIDE: u8 = 2;

/// The directed edges of one insertion's cavity boundary, each with the new face that
/// holds it: open addressing with every slot stamped with the insertion it belongs to,
/// so the table is never cleared.
#[derive(Clone, Debug, Default)]
struct EdgeTable {
    slots: Vec<EdgeSlot>,
    stamp: u32,
    shift: u32,
}

#[derive(Copy, Clone, Debug)]
struct EdgeSlot {
    key: u64,
    stamp: u32,
    face: FaceRef,
}

impl EdgeTable {
    /// Starts a new insertion with `faces` boundary faces; returns its stamp.
    fn start(&mut self, faces: usize) -> u32 {
        // Three directed edges per face; 32 slots per face keep the load under 3/32, so
        // that most probes hit at once (measured faster than 16 or 8 slots per face).
        let want = (faces * 32).next_power_of_two().max(256);
        if want > self.slots.len() || self.stamp == u32::MAX {
            let empty = EdgeSlot {
                key: 0,
                stamp: 0,
                face: FaceRef(0),
            };
            self.slots = vec![empty; want.max(self.slots.len())];
            self.shift = 64 - self.slots.len().trailing_zeros();
            self.stamp = 0;
        }
        self.stamp += 1;
        self.stamp
    }

    #[inline(always)]
    fn home(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> self.shift) as usize
    }

    /// Files the directed edge `(a, b)` as held by face `face`.
    #[inline]
    fn insert(&mut self, stamp: u32, a: VertexId, b: VertexId, face: FaceRef) {
        let key = u64::from(a) << 32 | u64::from(b);
        let mask = self.slots.len() - 1;
        let mut h = self.home(key);
        while self.slots[h].stamp == stamp {
            h = (h + 1) & mask;
        }
        self.slots[h] = EdgeSlot { key, stamp, face };
    }

    /// The face filed with the directed edge `(a, b)`, if any.
    #[inline]
    fn find(&self, stamp: u32, a: VertexId, b: VertexId) -> Option<FaceRef> {
        let key = u64::from(a) << 32 | u64::from(b);
        let mask = self.slots.len() - 1;
        let mut h = self.home(key);
        loop {
            let s = &self.slots[h];
            if s.stamp != stamp {
                return None;
            }
            if s.key == key {
                return Some(s.face);
            }
            h = (h + 1) & mask;
        }
    }
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

mod steiner;
pub use steiner::{Change, Walled};

/// A finished triangulation in output form (see [`Delaunay::export_with`]).
#[derive(Clone, Debug, Default)]
pub struct Exported {
    /// The live real tets as quadruples of input indices, numbered compactly in slot order.
    pub tets: Vec<[u32; 4]>,
    /// For each tet, its neighbours across faces 0..4 (-1 across hull faces); empty
    /// unless asked for.
    pub neighbors: Vec<[i64; 4]>,
    /// The hull faces as input indices, oriented outwards (seen from outside, counter-
    /// clockwise), in the order of their tets and, within a tet, of their faces.
    pub hull_faces: Vec<[u32; 3]>,
}

impl Delaunay {
    /// The live real tets as quadruples of input indices (compactly numbered) and, for
    /// each, the numbers of its neighbours across faces 0..4 (-1 across hull faces).
    /// Consumes the triangulation so that its memory can be reused for the numbering.
    pub fn export(self) -> (Vec<[u32; 4]>, Vec<[i64; 4]>) {
        let e = self.export_with(true);
        (e.tets, e.neighbors)
    }

    /// The triangulation in output form, with the neighbour table only if `neighbors`.
    ///
    /// Without neighbours the tet arena is turned into the tet list in place (Rust's
    /// in-place collect reuses the allocation), so no memory is touched for the first
    /// time: on a million points that saves a quarter of a gigabyte of page faults.
    pub fn export_with(self, neighbors: bool) -> Exported {
        if neighbors {
            return self.export_with_neighbors();
        }
        let Delaunay {
            mesh,
            orig,
            mut mark,
            ..
        } = self;
        // Bit f of mark[t]: face f of real tet t is on the hull (faces a ghost).
        mark.clear();
        mark.resize(mesh.num_slots(), 0);
        for t in mesh.live_tets() {
            if mesh.is_ghost(t) {
                let f = mesh.adj(FaceRef::new(t, 3));
                mark[f.tet() as usize] |= 1 << f.face();
            }
        }
        let mut hull_faces = Vec::new();
        let mut tets: Vec<[u32; 4]> = mesh
            .into_tets()
            .into_iter()
            .enumerate()
            .filter(|(_, t)| t.is_real())
            .map(|(i, t)| {
                let v = t.v.map(|x| orig[x as usize]);
                let m = mark[i];
                if m != 0 {
                    for (f, fv) in FACE_VERTS.iter().enumerate() {
                        if m & (1 << f) != 0 {
                            hull_faces.push([v[fv[0]], v[fv[2]], v[fv[1]]]);
                        }
                    }
                }
                v
            })
            .collect();
        // Gives the arena's unused tail back (a remap, not a copy).
        tets.shrink_to_fit();
        Exported {
            tets,
            neighbors: Vec::new(),
            hull_faces,
        }
    }

    fn export_with_neighbors(mut self) -> Exported {
        self.mark = Vec::new();
        let mut number = vec![0u32; self.mesh.num_slots()];
        let mut count = 0u32;
        for t in self.mesh.real_tets() {
            number[t as usize] = count;
            count += 1;
        }
        let mut tets = Vec::with_capacity(count as usize);
        let mut neighbors = Vec::with_capacity(count as usize);
        let mut hull_faces = Vec::new();
        for t in self.mesh.real_tets() {
            let v = self.mesh.verts(t).map(|v| self.orig[v as usize]);
            tets.push(v);
            let mut nb = [-1i64; 4];
            for (i, slot) in nb.iter_mut().enumerate() {
                let n = self.mesh.adj(FaceRef::new(t, i)).tet();
                if self.mesh.is_ghost(n) {
                    let fv = FACE_VERTS[i];
                    hull_faces.push([v[fv[0]], v[fv[2]], v[fv[1]]]);
                } else {
                    *slot = i64::from(number[n as usize]);
                }
            }
            neighbors.push(nb);
        }
        Exported {
            tets,
            neighbors,
            hull_faces,
        }
    }
}
