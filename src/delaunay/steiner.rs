//! Incremental updates after the initial build: inserting Steiner points, and queries on
//! the stars of vertices that the constrained stages need.

use super::Delaunay;
use crate::error::MeshError;
use crate::geom::Point;
use crate::mesh::{FaceRef, Tet, TetId, VertexId, GHOST};

/// Marks an old tet's slot while [`Delaunay::undo`] restores a change.
const RESTORED: u8 = 3;

/// What [`Delaunay::insert_walled`] did.
#[derive(Clone, Debug)]
pub enum Walled {
    /// The point is in.
    Inserted {
        /// Its vertex.
        vertex: VertexId,
        /// The tets it replaced, for [`Delaunay::undo`].
        change: Change,
        /// Where point location started before.
        last: TetId,
    },
    /// The point coincides with a vertex.
    OnVertex,
    /// The cavity would wrap around a blocked face: nothing changed.
    Refused,
}

/// One change to the tets, as [`Delaunay::undo`] takes it back: the tets removed, with
/// their slots and contents, and the slots of the tets that replaced them.
#[derive(Clone, Debug, Default)]
pub struct Change {
    /// The removed tets: slot and contents.
    pub old: Vec<(TetId, Tet)>,
    /// The slots of the new tets.
    pub new: Vec<TetId>,
}

impl Delaunay {
    /// Inserts a new point with perturbation (and output) index `pert`, which must exceed
    /// every index in use. Returns its vertex id, or `None` if it coincides with a vertex.
    pub fn insert_steiner(&mut self, p: Point, pert: u32) -> Result<Option<VertexId>, MeshError> {
        self.insert_steiner_noting(p, pert, None)
    }

    /// [`Delaunay::insert_steiner`], also listing in `removed` (when given) the vertices of
    /// the tets the insertion replaced.
    pub fn insert_steiner_noting(
        &mut self,
        p: Point,
        pert: u32,
        removed: Option<&mut Vec<[VertexId; 4]>>,
    ) -> Result<Option<VertexId>, MeshError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(MeshError::Internal(format!(
                "Steiner point {p:?} is not finite"
            )));
        }
        let v = self.push_point(p, pert);
        if !self.insert_noting(v, removed)? {
            self.points.pop();
            self.orig.pop();
            return Ok(None);
        }
        self.point_at_created();
        Ok(Some(v))
    }

    /// Makes the next point location walk from a tet of vertex `v` (a real one), for a
    /// point known to lie near `v`.
    pub fn start_walk_at(&mut self, v: VertexId) {
        if let Some(t) = self.mesh.vertex_tet(v) {
            if self.mesh.is_alive(t) && !self.mesh.is_ghost(t) {
                self.last = t;
            }
        }
    }

    /// Appends point `p` with perturbation index `pert`; its vertex id.
    fn push_point(&mut self, p: Point, pert: u32) -> VertexId {
        let v = self.points.len() as VertexId;
        self.points.push(p);
        self.orig.push(pert);
        self.mesh.grow_vertices(self.points.len());
        v
    }

    /// Points every vertex of the last insertion's new tets at one of them. Vertices of
    /// deleted tets all lie on the cavity boundary, so this repairs the vertex-to-tet map.
    fn point_at_created(&mut self) {
        for i in 0..self.created.len() {
            let t = self.created[i].0;
            for &x in &self.mesh.verts(t) {
                if x != GHOST {
                    self.mesh.set_vertex_tet(x, t);
                }
            }
        }
    }

    /// Inserts a Steiner point into a constrained tetrahedralization with a cavity walled
    /// in by the `blocked` faces, unless the cavity would wrap around one of them, pinch,
    /// or not be seen whole from the point. The change is recorded so that
    /// [`Delaunay::undo`] can take it back.
    pub fn insert_walled(
        &mut self,
        p: Point,
        pert: u32,
        blocked: impl Fn([VertexId; 4], usize) -> bool,
    ) -> Result<Walled, MeshError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Ok(Walled::Refused);
        }
        let v = self.push_point(p, pert);
        let mut found = self.blocked_cavity(v, &blocked);
        let ready = matches!(found, Ok(super::Cavity::Ready));
        if ready
            && !(self.boundary_is_a_sphere()
                && self.encloses_no_vertex()
                && self.fill_is_positive())
        {
            self.abandon_cavity();
            found = Ok(super::Cavity::Wraps);
        }
        if !matches!(found, Ok(super::Cavity::Ready)) {
            self.points.pop();
            self.orig.pop();
            return match found? {
                super::Cavity::OnVertex => Ok(Walled::OnVertex),
                _ => Ok(Walled::Refused),
            };
        }
        self.fill_recorded(v)
    }

    /// Fills the ready cavity of vertex `v`, recording the change for
    /// [`Delaunay::undo`].
    fn fill_recorded(&mut self, v: VertexId) -> Result<Walled, MeshError> {
        // What filling overwrites: the cavity's tets, whose slots the new tets reuse.
        let old: Vec<(TetId, Tet)> = self
            .conflict
            .iter()
            .map(|&t| (t, *self.mesh.tet(t)))
            .collect();
        let last = self.last;
        self.fill_cavity()?;
        self.point_at_created();
        let created: Vec<TetId> = self.created.iter().map(|&(t, _)| t).collect();
        Ok(Walled::Inserted {
            vertex: v,
            change: Change { old, new: created },
            last,
        })
    }

    /// The tets of the cavity that point `p` would have walled in by the `blocked` faces
    /// (as far as it grew before a wall stopped it), without changing the mesh; empty
    /// if `p` coincides with a vertex. `pert` is its perturbation index, as for
    /// [`Delaunay::insert_walled`].
    pub fn walled_conflict(
        &mut self,
        p: Point,
        pert: u32,
        blocked: impl Fn([VertexId; 4], usize) -> bool,
    ) -> Result<Vec<TetId>, MeshError> {
        let v = self.push_point(p, pert);
        let found = self.blocked_cavity(v, &blocked);
        if matches!(found, Ok(super::Cavity::Ready)) {
            self.abandon_cavity();
        }
        self.points.pop();
        self.orig.pop();
        Ok(match found? {
            super::Cavity::OnVertex => Vec::new(),
            _ => self.conflict.clone(),
        })
    }

    /// Inserts a Steiner point that splits a constraint: its cavity is the tets `seeds`
    /// (those around the split edge, or the two on the split face, which hold the point on
    /// their boundary) grown through the faces that are not `blocked`, and refused, with
    /// nothing changed, if it wraps around a blocked face, pinches, or is not seen whole
    /// from the point. The faces through the split constraint must not be `blocked`.
    pub fn insert_seeded(
        &mut self,
        p: Point,
        pert: u32,
        seeds: &[TetId],
        blocked: impl Fn([VertexId; 4], usize) -> bool,
        unfillable: impl Fn([VertexId; 3]) -> bool,
    ) -> Result<Walled, MeshError> {
        if !p.iter().all(|c| c.is_finite()) || seeds.is_empty() {
            return Ok(Walled::Refused);
        }
        self.widen_box(&p);
        let v = self.push_point(p, pert);
        let grown = self.grow_cavity(v, seeds, &blocked);
        let ready = matches!(grown, super::Cavity::Ready)
            && self.shrink_to_star(v, seeds, &blocked, unfillable);
        if !(ready
            && self.boundary_is_a_sphere()
            && self.encloses_no_vertex()
            && self.fill_is_positive())
        {
            if ready {
                self.abandon_cavity();
            }
            self.points.pop();
            self.orig.pop();
            return Ok(Walled::Refused);
        }
        self.fill_recorded(v)
    }

    /// After [`Delaunay::insert_walled`] refused point `p`, a blocked face that its cavity
    /// reached from both sides, or else one walling it in that `p` does not see from the
    /// cavity's side (the cavity wraps around its edge), if that is why.
    pub fn wrapped_face(
        &self,
        p: &Point,
        blocked: impl Fn([VertexId; 4], usize) -> bool,
    ) -> Option<[VertexId; 3]> {
        let inside: rustc_hash::FxHashSet<TetId> = self.conflict.iter().copied().collect();
        let both_sides = self.conflict.iter().find_map(|&t| {
            let tet = self.mesh.tet(t);
            (0..4)
                .find(|&f| blocked(tet.v, f) && inside.contains(&tet.adj[f].tet()))
                .map(|f| self.mesh.face_verts(t, f))
        });
        both_sides.or_else(|| {
            self.conflict.iter().find_map(|&t| {
                let tet = self.mesh.tet(t);
                (0..4)
                    .find(|&f| {
                        if !blocked(tet.v, f) || inside.contains(&tet.adj[f].tet()) {
                            return false;
                        }
                        // The tet the fill would make on this wall: not positive.
                        let mut v = tet.v.map(|x| (x != GHOST).then(|| *self.pt(x)));
                        v[f] = Some(*p);
                        let [Some(a), Some(b), Some(c), Some(d)] = v else {
                            return false;
                        };
                        self.filter.orient3d(&a, &b, &c, &d) <= 0.0
                    })
                    .map(|f| self.mesh.face_verts(t, f))
            })
        })
    }

    /// Takes back the insertion of the last vertex `v` and the changes made since (in
    /// `changes`, oldest first, the insertion's own first), restoring the mesh exactly;
    /// `last` is where point location started before.
    pub fn undo(&mut self, v: VertexId, changes: &[Change], last: TetId) {
        self.undo_changes(changes);
        self.created.clear();
        self.last = last;
        if self.points.len() == v as usize + 1 {
            self.points.pop();
            self.orig.pop();
        }
    }

    /// Takes back `changes` (oldest first) and nothing else, restoring the tets exactly
    /// as they were before the first: the vertices stay.
    pub fn undo_changes(&mut self, changes: &[Change]) {
        if self.mark.len() < self.mesh.num_slots() {
            self.mark.resize(self.mesh.num_slots(), 0);
        }
        for c in changes.iter().rev() {
            // The new tets' slots go first: some are the old tets' own slots.
            for &t in &c.new {
                self.mesh.kill_tet(t);
            }
            // The old tets' slots are marked (the marks are clear between operations):
            // a link to one of them needs no rewiring from the other side.
            for &(t, tet) in &c.old {
                self.mesh.restore_tet(t, tet);
                self.mark[t as usize] = RESTORED;
            }
            for &(t, tet) in &c.old {
                for (f, &n) in tet.adj.iter().enumerate() {
                    if self.mark[n.tet() as usize] != RESTORED {
                        self.mesh.set_link(n, FaceRef::new(t, f));
                    }
                }
                for &x in &tet.v {
                    if x != GHOST {
                        self.mesh.set_vertex_tet(x, t);
                    }
                }
            }
            for &(t, _) in &c.old {
                self.mark[t as usize] = 0;
            }
        }
    }

    /// The tets made by the last insertion, each with its face opposite the new vertex
    /// (a face of the cavity's boundary).
    pub fn last_created(&self) -> &[(TetId, usize)] {
        &self.created
    }

    /// The internal vertex id of each of the first `n` input indices (`u32::MAX` for
    /// points that are not vertices, such as duplicates).
    pub fn internal_ids(&self, n: usize) -> Vec<VertexId> {
        let mut inv = vec![u32::MAX; n];
        for (v, &o) in self.orig.iter().enumerate() {
            if (o as usize) < n {
                inv[o as usize] = v as VertexId;
            }
        }
        inv
    }

    /// Collects the live tets (ghosts included) incident to vertex `v` into `out`.
    pub fn star(&self, v: VertexId, out: &mut Vec<TetId>) {
        // A walk that never stops early visits the whole star and leaves it in `out`.
        let _ = self.find_around(v, out, |_| false);
    }

    /// The first tet around vertex `u` (in a walk over its star) for which `hit` holds.
    pub fn find_around(
        &self,
        u: VertexId,
        scratch: &mut Vec<TetId>,
        mut hit: impl FnMut([VertexId; 4]) -> bool,
    ) -> Option<TetId> {
        scratch.clear();
        let start = self.mesh.vertex_tet(u)?;
        let mut visit = self.visit.borrow_mut();
        let (stamp, walk) = &mut *visit;
        *walk = walk.wrapping_add(1);
        if *walk == 0 {
            stamp.fill(0);
            *walk = 1;
        }
        let walk = *walk;
        if stamp.len() < self.mesh.num_slots() {
            stamp.resize(self.mesh.num_slots(), 0);
        }
        stamp[start as usize] = walk;
        scratch.push(start);
        let mut k = 0;
        while k < scratch.len() {
            let t = scratch[k];
            k += 1;
            let tv = self.mesh.verts(t);
            if hit(tv) {
                return Some(t);
            }
            for (i, &x) in tv.iter().enumerate() {
                if x == u {
                    continue;
                }
                let n = self.mesh.adj(FaceRef::new(t, i)).tet();
                if stamp[n as usize] != walk {
                    stamp[n as usize] = walk;
                    scratch.push(n);
                }
            }
        }
        None
    }

    /// True if `u`–`v` is an edge of the mesh.
    pub fn has_edge(&self, u: VertexId, v: VertexId, scratch: &mut Vec<TetId>) -> bool {
        self.find_around(u, scratch, |tv| tv.contains(&v)).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steiner_points_keep_the_dt_valid_and_the_vertex_map_current() {
        let pts: Vec<Point> = (0..27)
            .map(|i| [(i % 3) as f64, ((i / 3) % 3) as f64, (i / 9) as f64])
            .collect();
        let mut dt = Delaunay::build(&pts).unwrap().dt;
        let mut scratch = Vec::new();
        for (k, p) in [[0.5, 0.5, 0.5], [1.25, 0.0, 0.0], [3.0, 3.0, 3.0]]
            .iter()
            .enumerate()
        {
            let v = dt.insert_steiner(*p, 27 + k as u32).unwrap().unwrap();
            dt.mesh.check_links().unwrap();
            dt.star(v, &mut scratch);
            assert!(scratch.iter().all(|&t| dt.mesh.verts(t).contains(&v)));
            for x in 0..dt.points.len() as u32 {
                let t = dt.mesh.vertex_tet(x).unwrap();
                assert!(
                    dt.mesh.is_alive(t) && dt.mesh.verts(t).contains(&x),
                    "vertex {x}"
                );
            }
        }
        // A point equal to a vertex is refused.
        assert_eq!(dt.insert_steiner([1.0, 1.0, 1.0], 40).unwrap(), None);
        let inv = dt.internal_ids(27);
        assert!(inv.iter().all(|&v| v != u32::MAX));
        let a = inv[0];
        let b = inv[1];
        assert!(dt.has_edge(a, b, &mut scratch));
    }
}
