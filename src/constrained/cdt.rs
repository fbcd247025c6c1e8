//! A constrained Delaunay tetrahedralization under construction: the Delaunay arena plus
//! side tables of its constraints (subsegments and subfaces), keyed by sorted vertex ids.

use crate::delaunay::Delaunay;
use crate::mesh::{FaceRef, TetId, VertexId, FACE_VERTS, GHOST};
use rustc_hash::{FxHashMap, FxHashSet};

/// Sorted key of an edge.
#[inline]
pub fn edge_key(a: VertexId, b: VertexId) -> (VertexId, VertexId) {
    (a.min(b), a.max(b))
}

/// The triangles of `tris` (by index) on each of their edges.
pub fn triangles_by_edge(tris: &[[VertexId; 3]]) -> FxHashMap<(VertexId, VertexId), Vec<usize>> {
    let mut by_edge: FxHashMap<(VertexId, VertexId), Vec<usize>> = FxHashMap::default();
    for (i, t) in tris.iter().enumerate() {
        for k in 0..3 {
            by_edge
                .entry(edge_key(t[k], t[(k + 1) % 3]))
                .or_default()
                .push(i);
        }
    }
    by_edge
}

/// Sorted key of a triangle.
#[inline]
pub fn face_key(f: [VertexId; 3]) -> [VertexId; 3] {
    // A three-comparison network: a general sort costs several times more, and keys are
    // made for every face a flip or a cavity touches.
    let [a, b, c] = f;
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    let (b, c) = if b <= c { (b, c) } else { (c, b) };
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    [a, b, c]
}

/// The mesh and its constraints.
#[derive(Clone, Debug)]
pub struct Cdt {
    /// The tetrahedralization (vertex ids are internal; `dt.orig` maps to output ids).
    pub dt: Delaunay,
    /// Subsegments, with the marker of their segment.
    pub subsegs: FxHashMap<(VertexId, VertexId), i32>,
    /// Subfaces present in the mesh, with the index of their (merged) facet.
    pub subfaces: FxHashMap<[VertexId; 3], u32>,
    /// Faces of the mesh when [`Cdt::index_faces`] ran, each with a tet that had it: a
    /// hint that [`Cdt::has_face`] confirms in constant time while that tet is unchanged.
    face_index: FxHashMap<[VertexId; 3], FaceRef>,
    scratch: Vec<TetId>,
    /// The work done so far, which bounds restarts: edge-triangle crossing tests (and
    /// their orientations that need adaptive arithmetic), and exact flip-time
    /// comparisons, in units of about the same cost.
    pub work: std::cell::Cell<u64>,
    /// The work past which the construction stops
    /// ([`crate::error::MeshError::WorkBound`]): a single region can cost more than all
    /// restarts may, around a vertex far out of scale.
    pub work_limit: u64,
    /// Per facet, how often its flips got stuck on a polygon that is not flat and asked
    /// for a Steiner point in this construction (see [`super::flip::insert_region`]).
    pub flips_stuck: FxHashMap<u32, u32>,
}

impl Cdt {
    /// Wraps a Delaunay tetrahedralization with empty constraint tables.
    pub fn new(dt: Delaunay) -> Self {
        Cdt {
            dt,
            subsegs: FxHashMap::default(),
            subfaces: FxHashMap::default(),
            face_index: FxHashMap::default(),
            scratch: Vec::new(),
            work: std::cell::Cell::new(0),
            work_limit: u64::MAX,
            flips_stuck: FxHashMap::default(),
        }
    }

    /// The face `(a, b, c)` of the mesh, as seen from one of its two tets, if present.
    pub fn find_face(&mut self, a: VertexId, b: VertexId, c: VertexId) -> Option<FaceRef> {
        let mut star = std::mem::take(&mut self.scratch);
        let t = self
            .dt
            .find_around(a, &mut star, |v| v.contains(&b) && v.contains(&c));
        self.scratch = star;
        let t = t?;
        let v = self.dt.mesh.verts(t);
        let i = (0..4).find(|&i| v[i] != a && v[i] != b && v[i] != c)?;
        Some(FaceRef::new(t, i))
    }

    /// Records every face of the mesh as it is now, for [`Cdt::has_face`].
    pub fn index_faces(&mut self) {
        self.face_index = self.dt.mesh.face_index();
    }

    /// Like [`Cdt::index_faces`], for the faces among `wanted` (sorted keys): the only
    /// ones [`Cdt::has_face`] will be asked about, such as the facets' triangles.
    pub fn index_faces_of(&mut self, wanted: &[[VertexId; 3]]) {
        self.face_index = self.dt.mesh.face_index_of(self.dt.points.len(), wanted);
    }

    /// The face `(a, b, c)` of the mesh from one of its tets, if present: the index's
    /// hint when still valid, else a walk.
    pub fn face_ref(&mut self, a: VertexId, b: VertexId, c: VertexId) -> Option<FaceRef> {
        if let Some(&f) = self.face_index.get(&face_key([a, b, c])) {
            let t = f.tet();
            // The tet may have been deleted or reused since; if it still has the three
            // vertices, the face is there.
            let mesh = &self.dt.mesh;
            if mesh.is_alive(t) {
                let v = mesh.verts(t);
                if v.contains(&a) && v.contains(&b) && v.contains(&c) {
                    let i = (0..4).find(|&i| v[i] != a && v[i] != b && v[i] != c)?;
                    return Some(FaceRef::new(t, i));
                }
            }
        }
        self.find_face(a, b, c)
    }

    /// Makes the triangles `tris` of facet `facet` that are mesh faces subfaces; the
    /// others, missing, in their order.
    pub fn keep_present(&mut self, tris: &[[VertexId; 3]], facet: u32) -> Vec<[VertexId; 3]> {
        let mut missing = Vec::new();
        for &t in tris {
            if self.has_face(t[0], t[1], t[2]) {
                self.subfaces.insert(face_key(t), facet);
            } else {
                missing.push(t);
            }
        }
        missing
    }

    /// Removes the subfaces among `at_risk` (drained) that are no longer mesh faces:
    /// they, with their facets, sorted.
    pub fn take_lost_subfaces(
        &mut self,
        at_risk: &mut Vec<[VertexId; 3]>,
    ) -> Vec<([VertexId; 3], u32)> {
        at_risk.sort_unstable();
        at_risk.dedup();
        let mut lost = Vec::new();
        for key in at_risk.drain(..) {
            if self.find_face(key[0], key[1], key[2]).is_none() {
                if let Some(f) = self.subfaces.remove(&key) {
                    lost.push((key, f));
                }
            }
        }
        lost
    }

    /// True if `(a, b, c)` is a face of the mesh.
    pub fn has_face(&mut self, a: VertexId, b: VertexId, c: VertexId) -> bool {
        self.face_ref(a, b, c).is_some()
    }

    /// True if `u`–`v` is a mesh edge.
    pub fn has_edge(&mut self, u: VertexId, v: VertexId) -> bool {
        let mut star = std::mem::take(&mut self.scratch);
        let r = self.dt.has_edge(u, v, &mut star);
        self.scratch = star;
        r
    }

    /// True if face `i` of tet `t` is a subface.
    #[inline]
    pub fn is_subface(&self, t: TetId, i: usize) -> bool {
        if self.subfaces.is_empty() {
            return false;
        }
        let v = self.dt.mesh.verts(t);
        let f = FACE_VERTS[i];
        self.subfaces
            .contains_key(&face_key([v[f[0]], v[f[1]], v[f[2]]]))
    }

    /// The subfaces that are no longer faces of the mesh, grouped by facet.
    pub fn lost_subfaces(&mut self) -> FxHashSet<u32> {
        let keys: Vec<([VertexId; 3], u32)> = self.subfaces.iter().map(|(k, &f)| (*k, f)).collect();
        let mut lost = FxHashSet::default();
        for (k, f) in keys {
            if self.find_face(k[0], k[1], k[2]).is_none() {
                lost.insert(f);
                self.subfaces.remove(&k);
            }
        }
        lost
    }

    /// The tets whose circumspheres hold point `p` (perturbation index `pert`) and that
    /// are reached from the tet holding it without crossing a subface; empty if `p` is
    /// a vertex.
    pub fn walled_conflict(
        &mut self,
        p: crate::geom::Point,
        pert: u32,
    ) -> Result<Vec<TetId>, crate::error::MeshError> {
        let subfaces = &self.subfaces;
        let blocked = |v: [VertexId; 4], f: usize| {
            subfaces.contains_key(&face_key(FACE_VERTS[f].map(|k| v[k])))
        };
        self.dt.walled_conflict(p, pert, blocked)
    }

    /// [`Cdt::walled_conflict`] with the subfaces that `open` accepts left open: for a
    /// point on a constraint, its own subfaces, so that its cavity reaches both sides
    /// whichever side the point is located on.
    pub fn walled_conflict_open(
        &mut self,
        p: crate::geom::Point,
        pert: u32,
        open: impl Fn(&[VertexId; 3]) -> bool,
    ) -> Result<Vec<TetId>, crate::error::MeshError> {
        let subfaces = &self.subfaces;
        let blocked = |v: [VertexId; 4], f: usize| {
            let k = face_key(FACE_VERTS[f].map(|k| v[k]));
            subfaces.contains_key(&k) && !open(&k)
        };
        self.dt.walled_conflict(p, pert, blocked)
    }

    /// Number of live real tets.
    pub fn num_tets(&self) -> usize {
        self.dt.mesh.real_tets().count()
    }

    /// True if tet `t` is a ghost.
    #[inline]
    pub fn is_ghost(&self, t: TetId) -> bool {
        self.dt.mesh.verts(t)[3] == GHOST
    }
}
