//! The bistellar flips of a face (2-3, 3-2 and 4-4): which tets a flip replaces and by
//! what, and the replacement itself. Shared by facet insertion by flips ([`super::flip`])
//! and by free points, which are flipped into the CDT ([`super::free`]); each adds its
//! own rules on which flips are allowed.

use crate::error::MeshError;
use crate::geom::{orient3d, Point};
use crate::mesh::{FaceRef, Mesh, TetId, VertexId, FACE_VERTS, GHOST};

use super::cdt::face_key;

/// The kind of a flip.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// Two tets sharing a face become three around a new edge.
    T23,
    /// Three tets around an edge become two sharing a new face.
    T32,
    /// Four tets around an edge whose four other vertices are coplanar become four
    /// around the other diagonal.
    T44,
}

/// At most four items, in place: a flip's lists are that short, and allocating them
/// cost a few percent of every flip.
#[derive(Clone, Copy, Debug)]
pub(super) struct Few<T: Copy + Default> {
    items: [T; 4],
    len: u8,
}

impl<T: Copy + Default> Few<T> {
    /// The items of `list` (at most four).
    fn of(list: &[T]) -> Self {
        let mut items = [T::default(); 4];
        items[..list.len()].copy_from_slice(list);
        Few {
            items,
            len: list.len() as u8,
        }
    }

    /// Appends `x` (there must be room).
    fn push(&mut self, x: T) {
        self.items[self.len as usize] = x;
        self.len += 1;
    }
}

impl<T: Copy + Default> std::ops::Deref for Few<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.items[..self.len as usize]
    }
}

/// What flipping a face would do.
pub(super) struct Shape {
    /// The kind of flip.
    pub kind: Kind,
    /// The tets it removes.
    pub old: Few<TetId>,
    /// The positively oriented tets that replace them, filling the same volume.
    pub new: Few<[VertexId; 4]>,
    /// The face flipped away (2-3), or the edge removed (3-2, 4-4) with the vertices
    /// around it: the faces `(edge, apex)` go with it.
    pub face: [VertexId; 3],
    pub edge: Option<([VertexId; 2], Few<VertexId>)>,
    /// The face flipped away, as seen from `old[0]`.
    pub at: FaceRef,
}

/// The flip that removes face `f` (between two real tets), if the tets around it allow
/// one: a 2-3 flip when the segment between the two apices crosses the face, a 3-2 flip
/// when it passes beside one edge held by exactly three tets, a 4-4 flip when it meets
/// such an edge held by four.
pub(super) fn shape(mesh: &Mesh, pts: &[Point], f: FaceRef) -> Option<Shape> {
    let (t1, i) = (f.tet(), f.face());
    let g = mesh.adj(f);
    let t2 = g.tet();
    // A flip never removes a hull tet (the hull is not the flips' to change).
    if mesh.is_ghost(t1) || mesh.is_ghost(t2) {
        return None;
    }
    let v = mesh.verts(t1)[i];
    let w = mesh.verts(t2)[g.face()];
    let s = mesh.face_verts(t1, i);
    let base = [s[0], s[1], s[2], v];
    let rep = |k: usize| {
        let mut b = base;
        b[k] = w;
        b
    };
    let orient = |t: &[VertexId; 4]| {
        let p = t.map(|x| &pts[x as usize]);
        orient3d(p[0], p[1], p[2], p[3])
    };
    let o: [f64; 3] = std::array::from_fn(|k| orient(&rep(k)));
    let negs = o.iter().filter(|&&x| x < 0.0).count();
    let zeros = o.iter().filter(|&&x| x == 0.0).count();
    // The face of `t` opposite vertex `x`.
    let opposite = |t: TetId, x: VertexId| mesh.verts(t).iter().position(|&y| y == x);
    if negs == 0 && zeros == 0 {
        return Some(Shape {
            kind: Kind::T23,
            old: Few::of(&[t1, t2]),
            new: Few::of(&[rep(0), rep(1), rep(2)]),
            face: s,
            edge: None,
            at: f,
        });
    }
    if negs == 1 && zeros == 0 {
        let k = (0..3).find(|&k| o[k] < 0.0)?;
        let (e0, e1) = (s[(k + 1) % 3], s[(k + 2) % 3]);
        let t3 = mesh.adj(FaceRef::new(t1, opposite(t1, s[k])?)).tet();
        if mesh.is_ghost(t3) || !mesh.verts(t3).contains(&w) {
            return None;
        }
        return Some(Shape {
            kind: Kind::T32,
            old: Few::of(&[t1, t2, t3]),
            new: Few::of(&[rep((k + 1) % 3), rep((k + 2) % 3)]),
            face: s,
            edge: Some(([e0, e1], Few::of(&[s[k], v, w]))),
            at: f,
        });
    }
    if zeros == 1 && negs == 0 {
        let k = (0..3).find(|&k| o[k] == 0.0)?;
        let (e0, e1) = (s[(k + 1) % 3], s[(k + 2) % 3]);
        let t3 = mesh.adj(FaceRef::new(t1, opposite(t1, s[k])?)).tet();
        let t4 = mesh.adj(FaceRef::new(t2, opposite(t2, s[k])?)).tet();
        if mesh.is_ghost(t3) || mesh.is_ghost(t4) {
            return None;
        }
        let (t3v, t4v) = (mesh.verts(t3), mesh.verts(t4));
        let &u = t3v.iter().find(|&&x| x != e0 && x != e1 && x != v)?;
        if u == w || !t4v.contains(&u) || !t4v.contains(&w) {
            return None;
        }
        // On u's side: t3 with e0 (then e1) replaced by w.
        let mut on_u = [t3v; 2];
        for (t, e) in on_u.iter_mut().zip([e0, e1]) {
            if let Some(p) = t.iter().position(|&x| x == e) {
                t[p] = w;
            }
            if orient(t) <= 0.0 {
                return None;
            }
        }
        return Some(Shape {
            kind: Kind::T44,
            old: Few::of(&[t1, t2, t3, t4]),
            new: Few::of(&[rep((k + 1) % 3), rep((k + 2) % 3), on_u[0], on_u[1]]),
            face: s,
            edge: Some(([e0, e1], Few::of(&[s[k], v, w, u]))),
            at: f,
        });
    }
    None
}

/// Does flip `sh`: as [`replace`] of its old tets by its new ones (the same slots, links
/// and vertex map), with `on_face` called only if `faces`. 2-3 and 3-2 flips glue their
/// tets by their known layout, without matching faces (half the cost of a flip).
pub(super) fn flip(
    mesh: &mut Mesh,
    sh: &Shape,
    faces: bool,
    mut on_face: impl FnMut([VertexId; 3]),
) -> Result<Few<TetId>, MeshError> {
    let (t1, i) = (sh.at.tet(), sh.at.face());
    let t2 = sh.old[1];
    // `pos(t, x)`: the face of `t` opposite its vertex `x`.
    let pos = |mesh: &Mesh, t: TetId, x: VertexId| -> Result<usize, MeshError> {
        mesh.verts(t)
            .iter()
            .position(|&y| y == x)
            .ok_or_else(|| MeshError::Internal(format!("a flip's tet {t} lacks vertex {x}")))
    };
    let s = sh.face;
    // The new tets' links: `outer[a][j]` is the outside face at face `j` of new tet `a`,
    // or `None` for a face between new tets, glued below.
    let mut outer = [[None::<FaceRef>; 4]; 3];
    let m = sh.new.len();
    match sh.kind {
        Kind::T23 => {
            // New tet k is the old base (face, v) with s_k replaced by w, at slot k: its
            // face k (opposite w) was t1's opposite s_k, its face 3 (opposite v) t2's
            // opposite s_k; its faces k+1 and k+2 are shared with the other new tets.
            for k in 0..3 {
                outer[k][k] = Some(mesh.adj(FaceRef::new(t1, FACE_VERTS[i][k])));
                outer[k][3] = Some(mesh.adj(FaceRef::new(t2, pos(mesh, t2, s[k])?)));
            }
        }
        Kind::T32 => {
            // The edge e0 e1 = s_{k+1} s_{k+2} goes; new tet A has e0 replaced by w,
            // B has e1 replaced by w; they share the face (s_k, v, w).
            let t3 = sh.old[2];
            let k = (0..3)
                .find(|&k| sh.edge.as_ref().is_some_and(|(_, ap)| ap[0] == s[k]))
                .ok_or_else(|| MeshError::Internal("a 3-2 flip without its apex".into()))?;
            let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
            let (e0, e1) = (s[k1], s[k2]);
            // `w_slot`: where w took the place of the vertex that is gone.
            for (a, (gone, w_slot)) in [(e0, k1), (e1, k2)].into_iter().enumerate() {
                outer[a][k] = Some(mesh.adj(FaceRef::new(t3, pos(mesh, t3, gone)?)));
                outer[a][w_slot] = Some(mesh.adj(FaceRef::new(t1, FACE_VERTS[i][w_slot])));
                outer[a][3] = Some(mesh.adj(FaceRef::new(t2, pos(mesh, t2, gone)?)));
            }
        }
        Kind::T44 => {
            return replace(mesh, &sh.old, &sh.new, |key| {
                if faces {
                    on_face(key)
                }
            })
        }
    }
    for &t in sh.old.iter() {
        if faces {
            for j in 0..4 {
                on_face(face_key(mesh.face_verts(t, j)));
            }
        }
        mesh.kill_tet(t);
    }
    let mut made = Few::of(&[]);
    for &v in sh.new.iter() {
        let t = mesh
            .add_tet(v)
            .map_err(|_| MeshError::Unsupported("the mesh exceeds 2^30 tets".into()))?;
        made.push(t);
    }
    for (&t, links) in made.iter().zip(&outer[..m]) {
        for (j, n) in links.iter().enumerate() {
            if let Some(n) = *n {
                mesh.glue(FaceRef::new(t, j), n);
            }
        }
    }
    match sh.kind {
        Kind::T23 => {
            for k in 0..3 {
                let next = (k + 1) % 3;
                mesh.glue(FaceRef::new(made[k], next), FaceRef::new(made[next], k));
            }
        }
        _ => {
            // A's face opposite e1 (slot k+2) and B's opposite e0 (slot k+1).
            let k = (0..3)
                .find(|&j| outer[0][j].is_none())
                .ok_or_else(|| MeshError::Internal("a 3-2 flip without an inner face".into()))?;
            let kk = (0..3)
                .find(|&j| outer[1][j].is_none())
                .ok_or_else(|| MeshError::Internal("a 3-2 flip without an inner face".into()))?;
            mesh.glue(FaceRef::new(made[0], k), FaceRef::new(made[1], kk));
        }
    }
    for &t in made.iter() {
        for x in mesh.verts(t) {
            if x != GHOST {
                mesh.set_vertex_tet(x, t);
            }
        }
    }
    Ok(made)
}

/// Replaces tets `old` by the positively oriented tets `new` (which fill the same
/// volume), gluing them to each other and to the outside; `on_face` sees every face of
/// the old tets first. Returns the new tets.
pub(super) fn replace(
    mesh: &mut Mesh,
    old: &[TetId],
    new: &[[VertexId; 4]],
    mut on_face: impl FnMut([VertexId; 3]),
) -> Result<Few<TetId>, MeshError> {
    // A flip replaces at most four tets by four: fixed arrays, and each face's sorted
    // vertices packed into one integer, so that matching faces is a comparison each.
    if old.len() > 4 || new.len() > 4 {
        return Err(MeshError::Internal(format!(
            "a flip of {} tets into {}",
            old.len(),
            new.len()
        )));
    }
    let pack = |k: [VertexId; 3]| (k[0] as u128) << 64 | (k[1] as u128) << 32 | k[2] as u128;
    let mut outer = [(0u128, FaceRef(0)); 16];
    let mut n_outer = 0;
    for &t in old {
        for j in 0..4 {
            let key = face_key(mesh.face_verts(t, j));
            let n = mesh.adj(FaceRef::new(t, j));
            if !old.contains(&n.tet()) {
                outer[n_outer] = (pack(key), n);
                n_outer += 1;
            }
            on_face(key);
        }
    }
    let outer = &outer[..n_outer];
    for &t in old {
        mesh.kill_tet(t);
    }
    let mut made = Few::of(&[]);
    for &v in new {
        let t = mesh
            .add_tet(v)
            .map_err(|_| MeshError::Unsupported("the mesh exceeds 2^30 tets".into()))?;
        made.push(t);
    }
    let mut keys = [[0u128; 4]; 4];
    for (k, v) in keys.iter_mut().zip(new) {
        *k = std::array::from_fn(|j| pack(face_key(FACE_VERTS[j].map(|x| v[x]))));
    }
    let m = new.len();
    // Faces already glued, as a bit per face of each new tet.
    let mut done = [0u8; 4];
    for a in 0..m {
        for j in 0..4 {
            if done[a] & (1 << j) != 0 {
                continue;
            }
            let key = keys[a][j];
            if let Some(&(_, n)) = outer.iter().find(|(k, _)| *k == key) {
                mesh.glue(FaceRef::new(made[a], j), n);
                continue;
            }
            // Not on the outside: shared with a later new tet (an earlier one would have
            // glued it already).
            let mut glued = false;
            for b in a + 1..m {
                if let Some(jj) = (0..4).find(|&jj| keys[b][jj] == key) {
                    mesh.glue(FaceRef::new(made[a], j), FaceRef::new(made[b], jj));
                    done[b] |= 1 << jj;
                    glued = true;
                    break;
                }
            }
            if !glued {
                return Err(MeshError::Internal(format!(
                    "a flip left face {:?} without a neighbour",
                    FACE_VERTS[j].map(|x| new[a][x])
                )));
            }
        }
    }
    for &t in made.iter() {
        for x in mesh.verts(t) {
            if x != GHOST {
                mesh.set_vertex_tet(x, t);
            }
        }
    }
    Ok(made)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::delaunay::Delaunay;
    use crate::geom::lcg;

    /// The 2-3 and 3-2 flips glued by their layout leave the very mesh that matching
    /// faces leaves: the same tets in the same slots, the same links, the same vertex
    /// map; checked along a chain of flips through random point sets.
    #[test]
    fn layout_flips_equal_face_matching_flips() {
        let mut kinds = [0usize; 2];
        for seed in 0..4u64 {
            let mut s = seed * 104_729 + 3;
            let pts: Vec<Point> = (0..60)
                .map(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)])
                .collect();
            let dt = Delaunay::build(&pts).unwrap().dt;
            let mut mesh = dt.mesh.clone();
            let mut done = 0;
            for round in 0..2000u64 {
                let slots = mesh.num_slots() as u64;
                let t = ((round * 7_919 + seed * 31) % slots) as TetId;
                if !mesh.is_alive(t) || mesh.is_ghost(t) {
                    continue;
                }
                let f = FaceRef::new(t, (round % 4) as usize);
                let Some(sh) = shape(&mesh, &dt.points, f) else {
                    continue;
                };
                if sh.kind == Kind::T44 {
                    continue;
                }
                kinds[(sh.kind == Kind::T32) as usize] += 1;
                let mut by_layout = mesh.clone();
                let a = flip(&mut by_layout, &sh, false, |_| {}).unwrap();
                let b = replace(&mut mesh, &sh.old, &sh.new, |_| {}).unwrap();
                assert_eq!(*a, *b);
                by_layout.check_links().unwrap();
                for v in 0..dt.points.len() as VertexId {
                    assert_eq!(by_layout.vertex_tet(v), mesh.vertex_tet(v));
                }
                assert_eq!(by_layout.into_tets(), mesh.clone().into_tets());
                done += 1;
                if done == 150 {
                    break;
                }
            }
        }
        assert!(kinds[0] > 50 && kinds[1] > 50, "{kinds:?}");
    }
}
