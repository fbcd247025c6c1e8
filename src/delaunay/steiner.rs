//! Incremental updates after the initial build: inserting Steiner points, and queries on
//! the stars of vertices that the constrained stages need.

use super::Delaunay;
use crate::error::MeshError;
use crate::geom::Point;
use crate::mesh::{FaceRef, TetId, VertexId, GHOST};

impl Delaunay {
    /// Inserts a new point with perturbation (and output) index `pert`, which must exceed
    /// every index in use. Returns its vertex id, or `None` if it coincides with a vertex.
    pub fn insert_steiner(&mut self, p: Point, pert: u32) -> Result<Option<VertexId>, MeshError> {
        self.insert_steiner_blocked(p, pert, |_, _| false)
    }

    /// [`Delaunay::insert_steiner`] with a cavity that never crosses a `blocked` face (see
    /// [`Delaunay::insert_blocked`]).
    pub fn insert_steiner_blocked(
        &mut self,
        p: Point,
        pert: u32,
        blocked: impl Fn([VertexId; 4], usize) -> bool,
    ) -> Result<Option<VertexId>, MeshError> {
        if !p.iter().all(|c| c.is_finite()) {
            return Err(MeshError::Internal(format!(
                "Steiner point {p:?} is not finite"
            )));
        }
        let v = self.points.len() as VertexId;
        self.points.push(p);
        self.orig.push(pert);
        self.mesh.grow_vertices(self.points.len());
        if !self.insert_blocked(v, blocked)? {
            self.points.pop();
            self.orig.pop();
            return Ok(None);
        }
        // Vertices of deleted tets all lie on the cavity boundary, so pointing every vertex
        // of the new tets at one of them repairs the vertex-to-tet map.
        for i in 0..self.created.len() {
            let t = self.created[i].0;
            for &x in &self.mesh.verts(t) {
                if x != GHOST {
                    self.mesh.set_vertex_tet(x, t);
                }
            }
        }
        Ok(Some(v))
    }

    /// The vertices on the boundary of the cavity of the last insertion: the only
    /// vertices between which that insertion can have removed an edge.
    pub fn last_cavity_vertices(&self, out: &mut Vec<VertexId>) {
        out.clear();
        for &(t, _) in &self.created {
            out.extend(self.mesh.verts(t).iter().filter(|&&x| x != GHOST));
        }
        out.sort_unstable();
        out.dedup();
    }

    /// Whether every face of the tets made by the last insertion is locally Delaunay,
    /// except the `blocked` ones (constraints) and hull faces.
    pub fn last_cavity_is_delaunay(&self, blocked: impl Fn([VertexId; 4], usize) -> bool) -> bool {
        self.created.iter().all(|&(t, _)| {
            let v = self.mesh.verts(t);
            if v.contains(&GHOST) {
                return true;
            }
            (0..4).all(|i| {
                if blocked(v, i) {
                    return true;
                }
                let n = self.mesh.adj(FaceRef::new(t, i));
                let w = self.mesh.verts(n.tet())[n.face()];
                w == GHOST || !self.in_sphere(t, &self.points[w as usize], w)
            })
        })
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
