//! The tetrahedral mesh: a flat arena of tets, each with four vertices and four
//! neighbour links, and a ghost vertex closing the hull. Pure combinatorics: no
//! coordinates live here.
//!
//! Conventions:
//! - Face `i` of a tet is the face opposite its vertex `v[i]`.
//! - `adj[i]` is a [`FaceRef`]: the neighbour across face `i` *and* which of the
//!   neighbour's faces is glued to ours, so gluing and flipping need no search.
//! - Hull tets carry [`GHOST`] in slot 3; their face 3 is a hull face. So every face of
//!   every real tet has a neighbour, and insertion has no boundary cases.
//! - Ids are `u32`: a [`FaceRef`] packs `tet << 2 | face` and so addresses 2^32 face
//!   slots (2^30 tets); index arithmetic is done in `usize`, and growth past that
//!   limit is refused rather than wrapped.

/// A vertex id: an index into the point array, or [`GHOST`].
pub type VertexId = u32;
/// A tet id: an index into the arena.
pub type TetId = u32;

/// The ghost vertex, "at infinity", closing the hull.
pub const GHOST: VertexId = u32::MAX;
/// Marks a tet slot that is free (its `v[0]` is set to this).
const DEAD: VertexId = u32::MAX;
/// The largest number of tet slots a [`FaceRef`] can address.
pub const MAX_TETS: usize = 1 << 30;

/// For face `i`, three local indices `(a, b, c)` such that `(a, b, c, i)` is an even
/// permutation of `(0, 1, 2, 3)`: the face seen with `v[i]` on its positive side.
pub const FACE_VERTS: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];

/// The 6 edges of a tet as pairs of vertex slots.
pub const EDGE_VERTS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];

/// A reference to one face of one tet: `tet << 2 | face`.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FaceRef(pub u32);

impl FaceRef {
    /// The reference to face `face` of tet `tet`.
    #[inline(always)]
    pub fn new(tet: TetId, face: usize) -> Self {
        FaceRef((tet << 2) | face as u32)
    }
    /// The tet.
    #[inline(always)]
    pub fn tet(self) -> TetId {
        self.0 >> 2
    }
    /// The face index within the tet (0..4).
    #[inline(always)]
    pub fn face(self) -> usize {
        (self.0 & 3) as usize
    }
}

/// A tetrahedron: four vertices and, for each face, the glued face of the neighbour.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Tet {
    /// Vertices; positively oriented (see `geom::predicates`); `GHOST` only in slot 3.
    pub v: [VertexId; 4],
    /// `adj[i]` is the neighbour's face glued to our face `i`.
    pub adj: [FaceRef; 4],
}

impl Tet {
    /// True for a live tet that is not a ghost (false for ghosts and free slots).
    #[inline(always)]
    pub fn is_real(&self) -> bool {
        self.v[0] != DEAD && self.v[3] != GHOST
    }
}

/// Lists of items per vertex in one flat array (compressed rows): each vertex's items
/// are contiguous, in the order given. Cheaper than a map of lists when most vertices
/// have few items or none.
#[derive(Clone, Debug)]
pub struct VertexLists<T> {
    first: Vec<u32>,
    items: Vec<T>,
}

impl<T: Copy + Default> VertexLists<T> {
    /// The lists of vertices `0..num_vertices` from `(vertex, item)` pairs (pairs whose
    /// vertex is out of range are dropped).
    pub fn new(num_vertices: usize, pairs: impl Iterator<Item = (VertexId, T)> + Clone) -> Self {
        let mut first = vec![0u32; num_vertices + 1];
        for (v, _) in pairs.clone().filter(|p| (p.0 as usize) < num_vertices) {
            first[v as usize + 1] += 1;
        }
        for i in 0..num_vertices {
            first[i + 1] += first[i];
        }
        let mut items = vec![T::default(); first[num_vertices] as usize];
        let mut fill = first.clone();
        for (v, x) in pairs.filter(|p| (p.0 as usize) < num_vertices) {
            items[fill[v as usize] as usize] = x;
            fill[v as usize] += 1;
        }
        VertexLists { first, items }
    }

    /// The items of vertex `v` (none for a vertex out of range).
    #[inline]
    pub fn of(&self, v: VertexId) -> &[T] {
        let v = v as usize;
        match (self.first.get(v), self.first.get(v + 1)) {
            (Some(&a), Some(&b)) => &self.items[a as usize..b as usize],
            _ => &[],
        }
    }

    /// Where the items of vertex `v` start in the flat order of all items (for side
    /// arrays indexed like them).
    #[inline]
    pub fn start(&self, v: VertexId) -> usize {
        self.first
            .get(v as usize)
            .map_or(self.items.len(), |&a| a as usize)
    }

    /// The number of items over all vertices.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True if no vertex has an item.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}

/// Edges, each listed under its lower vertex, with whether the tets shown to
/// [`ListedEdges::mark`] have it: one pass over the tets and no hashing, cheaper than a
/// set of edges when most vertices have few listed edges or none.
pub struct ListedEdges {
    lists: VertexLists<VertexId>,
    found: Vec<bool>,
}

impl ListedEdges {
    /// The edges `(lower, higher)` among vertices `0..num_vertices`, none found yet.
    pub fn new(
        num_vertices: usize,
        edges: impl Iterator<Item = (VertexId, VertexId)> + Clone,
    ) -> Self {
        let lists = VertexLists::new(num_vertices, edges);
        let found = vec![false; lists.len()];
        ListedEdges { lists, found }
    }

    /// Where edge `a`–`b` (`a < b`) is in the flat order of the lists.
    #[inline]
    fn index(&self, a: VertexId, b: VertexId) -> Option<usize> {
        let k = self.lists.of(a).iter().position(|&x| x == b)?;
        Some(self.lists.start(a) + k)
    }

    /// Marks the listed edges that are edges of `tets`.
    pub fn mark(&mut self, tets: impl IntoIterator<Item = [VertexId; 4]>) {
        for t in tets {
            for (i, j) in EDGE_VERTS {
                let (a, b) = (t[i].min(t[j]), t[i].max(t[j]));
                if let Some(k) = self.index(a, b) {
                    self.found[k] = true;
                }
            }
        }
    }

    /// Was edge `u`–`v` listed and marked?
    pub fn found(&self, u: VertexId, v: VertexId) -> bool {
        self.index(u.min(v), u.max(v))
            .is_some_and(|k| self.found[k])
    }

    /// Whether each listed edge was marked, vertex by vertex in the order given.
    pub fn flags(&self) -> &[bool] {
        &self.found
    }
}

/// The tet arena with a free list and a vertex-to-tet map.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    tets: Vec<Tet>,
    free: Vec<TetId>,
    /// For each vertex, some live tet incident to it (or `u32::MAX`).
    vert_tet: Vec<TetId>,
}

/// Error when the arena would exceed [`MAX_TETS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TooManyTets;

impl Mesh {
    /// An empty mesh for `num_vertices` vertices.
    pub fn new(num_vertices: usize) -> Self {
        Mesh {
            tets: Vec::new(),
            free: Vec::new(),
            vert_tet: vec![u32::MAX; num_vertices],
        }
    }

    /// Reserves room for about `n` tets.
    pub fn reserve(&mut self, n: usize) {
        self.tets.reserve(n.min(MAX_TETS));
    }

    /// Makes room for vertices up to `num_vertices` (for Steiner points).
    pub fn grow_vertices(&mut self, num_vertices: usize) {
        if self.vert_tet.len() < num_vertices {
            self.vert_tet.resize(num_vertices, u32::MAX);
        }
    }

    /// A word of slot `t` (0 past the end): reading it early brings the tet into the
    /// cache while other work goes on.
    #[inline(always)]
    pub fn touch(&self, t: TetId) -> u32 {
        self.tets.get(t as usize).map_or(0, |x| x.v[0])
    }

    /// The tet `t`.
    #[inline(always)]
    pub fn tet(&self, t: TetId) -> &Tet {
        &self.tets[t as usize]
    }

    /// The vertices of tet `t`.
    #[inline(always)]
    pub fn verts(&self, t: TetId) -> [VertexId; 4] {
        self.tets[t as usize].v
    }

    /// The face glued to face `f`.
    #[inline(always)]
    pub fn adj(&self, f: FaceRef) -> FaceRef {
        self.tets[f.tet() as usize].adj[f.face()]
    }

    /// True if `t` is a hull (ghost) tet.
    #[inline(always)]
    pub fn is_ghost(&self, t: TetId) -> bool {
        self.tets[t as usize].v[3] == GHOST
    }

    /// True if slot `t` holds a live tet.
    #[inline(always)]
    pub fn is_alive(&self, t: TetId) -> bool {
        (t as usize) < self.tets.len() && self.tets[t as usize].v[0] != DEAD
    }

    /// The number of slots (live and free).
    pub fn num_slots(&self) -> usize {
        self.tets.len()
    }

    /// Some live tet incident to vertex `v`, if any.
    pub fn vertex_tet(&self, v: VertexId) -> Option<TetId> {
        self.vert_tet
            .get(v as usize)
            .copied()
            .filter(|&t| t != u32::MAX)
    }

    /// Creates a tet with vertices `v` and unset links; reuses a free slot if any.
    #[inline]
    pub fn add_tet(&mut self, v: [VertexId; 4]) -> Result<TetId, TooManyTets> {
        let tet = Tet {
            v,
            adj: [FaceRef(u32::MAX); 4],
        };
        let t = match self.free.pop() {
            Some(t) => {
                self.tets[t as usize] = tet;
                t
            }
            None => {
                if self.tets.len() >= MAX_TETS {
                    return Err(TooManyTets);
                }
                self.tets.push(tet);
                (self.tets.len() - 1) as TetId
            }
        };
        Ok(t)
    }

    /// Overwrites live tet `t` with a tet of vertices `v` and unset links, in place (an
    /// insertion reuses the slots of the tets it deletes, which are hot in cache).
    #[inline]
    pub fn reset_tet(&mut self, t: TetId, v: [VertexId; 4]) {
        self.tets[t as usize] = Tet {
            v,
            adj: [FaceRef(u32::MAX); 4],
        };
    }

    /// Points every vertex at one of its live tets. Bulk construction leaves the map
    /// stale because updating it per tet costs random writes; call this afterwards.
    pub fn rebuild_vertex_map(&mut self) {
        self.vert_tet.iter_mut().for_each(|x| *x = u32::MAX);
        for (i, t) in self.tets.iter().enumerate() {
            if t.v[0] != DEAD {
                for &x in &t.v {
                    if x != GHOST {
                        self.vert_tet[x as usize] = i as TetId;
                    }
                }
            }
        }
    }

    /// Sets the tet recorded for vertex `v`.
    #[inline]
    pub fn set_vertex_tet(&mut self, v: VertexId, t: TetId) {
        self.vert_tet[v as usize] = t;
    }

    /// Frees tet `t`. Its neighbours' links to it must be rewired by the caller.
    #[inline]
    pub fn kill_tet(&mut self, t: TetId) {
        let slot = &mut self.tets[t as usize];
        slot.v[0] = DEAD;
        // A free slot keeps its place in the free list, so that restoring it is O(1):
        // undoing a large cavity restores every one of its tets.
        slot.v[1] = self.free.len() as VertexId;
        self.free.push(t);
    }

    /// Puts `tet` back in slot `t` as it was, links included, taking the slot off the
    /// free list if it was freed (undoing an insertion).
    pub fn restore_tet(&mut self, t: TetId, tet: Tet) {
        if self.tets[t as usize].v[0] == DEAD {
            let k = self.tets[t as usize].v[1] as usize;
            let k = if self.free.get(k) == Some(&t) {
                Some(k)
            } else {
                self.free.iter().rposition(|&x| x == t)
            };
            if let Some(k) = k {
                self.free.swap_remove(k);
                if let Some(&moved) = self.free.get(k) {
                    self.tets[moved as usize].v[1] = k as VertexId;
                }
            }
        }
        self.tets[t as usize] = tet;
    }

    /// Glues face `a` to face `b` (both directions).
    #[inline(always)]
    pub fn glue(&mut self, a: FaceRef, b: FaceRef) {
        self.tets[a.tet() as usize].adj[a.face()] = b;
        self.tets[b.tet() as usize].adj[b.face()] = a;
    }

    /// Points face `a` at face `b` without touching `b`'s link (a one-way link, used
    /// while an old tet is about to be discarded).
    #[inline(always)]
    pub fn set_link(&mut self, a: FaceRef, b: FaceRef) {
        self.tets[a.tet() as usize].adj[a.face()] = b;
    }

    /// The vertices of face `i` of tet `t`, ordered so that `v[i]` is on its positive side.
    #[inline(always)]
    pub fn face_verts(&self, t: TetId, i: usize) -> [VertexId; 3] {
        let v = &self.tets[t as usize].v;
        let f = FACE_VERTS[i];
        [v[f[0]], v[f[1]], v[f[2]]]
    }

    /// The tet slots, free ones included (see [`Tet::is_real`]), consuming the mesh.
    pub fn into_tets(self) -> Vec<Tet> {
        self.tets
    }

    /// Iterates over the ids of live tets, ghosts included.
    pub fn live_tets(&self) -> impl Iterator<Item = TetId> + '_ {
        self.tets
            .iter()
            .enumerate()
            .filter(|(_, t)| t.v[0] != DEAD)
            .map(|(i, _)| i as TetId)
    }

    /// Iterates over the ids of live non-ghost tets.
    pub fn real_tets(&self) -> impl Iterator<Item = TetId> + '_ {
        self.tets
            .iter()
            .enumerate()
            .filter(|(_, t)| t.v[0] != DEAD && t.v[3] != GHOST)
            .map(|(i, _)| i as TetId)
    }

    /// Every face of the real tets, keyed by its sorted vertices, with one tet side of
    /// it: constant-time face lookups for as long as the mesh does not change.
    pub fn face_index(&self) -> rustc_hash::FxHashMap<[VertexId; 3], FaceRef> {
        // About two faces per tet: sized up front, as rehashing costs more than filling.
        let mut index = rustc_hash::FxHashMap::with_capacity_and_hasher(
            2 * self.num_slots() + 8,
            Default::default(),
        );
        for t in self.real_tets() {
            let v = self.verts(t);
            for (i, fv) in FACE_VERTS.iter().enumerate() {
                // Each face once: from the lower of its two real tets.
                let n = self.adj(FaceRef::new(t, i)).tet();
                if n < t && self.verts(n)[3] != GHOST {
                    continue;
                }
                let mut k = [v[fv[0]], v[fv[1]], v[fv[2]]];
                k.sort_unstable();
                index.insert(k, FaceRef::new(t, i));
            }
        }
        index
    }

    /// [`Mesh::face_index`] restricted to the faces among `wanted` (sorted vertex keys,
    /// vertex ids below `num_vertices`). One pass over the tets, where each face is
    /// compared with the few wanted faces at its lowest vertex: no hashing of every face.
    pub fn face_index_of(
        &self,
        num_vertices: usize,
        wanted: &[[VertexId; 3]],
    ) -> rustc_hash::FxHashMap<[VertexId; 3], FaceRef> {
        let rest = VertexLists::new(
            num_vertices,
            wanted
                .iter()
                .filter(|k| (k[2] as usize) < num_vertices)
                .map(|k| (k[0], [k[1], k[2]])),
        );
        let mut index = rustc_hash::FxHashMap::default();
        index.reserve(wanted.len());
        for t in self.real_tets() {
            let v = self.verts(t);
            for (i, fv) in FACE_VERTS.iter().enumerate() {
                let mut k = [v[fv[0]], v[fv[1]], v[fv[2]]];
                k.sort_unstable();
                if !rest.of(k[0]).contains(&[k[1], k[2]]) {
                    continue;
                }
                // Each face once, from the later of its two real tets: the one a pass
                // over both would have left in the index. (Asked only of wanted faces:
                // the neighbour is a cache miss, and few faces are wanted.)
                let n = self.adj(FaceRef::new(t, i)).tet();
                if n > t && !self.is_ghost(n) {
                    continue;
                }
                index.insert(k, FaceRef::new(t, i));
            }
        }
        index
    }

    /// Checks that every link is symmetric and glues faces with the same vertex set in
    /// opposite orientations. Returns a description of the first problem found.
    pub fn check_links(&self) -> Result<(), String> {
        for t in self.live_tets() {
            for i in 0..4 {
                let f = FaceRef::new(t, i);
                let g = self.adj(f);
                if !self.is_alive(g.tet()) {
                    return Err(format!("tet {t} face {i} links to a dead tet {}", g.tet()));
                }
                if self.adj(g) != f {
                    return Err(format!("tet {t} face {i}: link is not symmetric"));
                }
                let a = self.face_verts(t, i);
                let b = self.face_verts(g.tet(), g.face());
                // Opposite orientation: b is a cyclic rotation of a reversed.
                let r = [a[0], a[2], a[1]];
                let same = (0..3).any(|k| b == [r[k], r[(k + 1) % 3], r[(k + 2) % 3]]);
                if !same {
                    return Err(format!(
                        "tet {t} face {i} {a:?} is glued to tet {} face {} {b:?}",
                        g.tet(),
                        g.face()
                    ));
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_lists_keep_each_vertexs_items_in_order() {
        let l = VertexLists::new(4, [(2, 'a'), (0, 'b'), (2, 'c'), (9, 'x')].into_iter());
        assert_eq!(l.of(2), &['a', 'c']);
        assert_eq!(l.of(0), &['b']);
        assert!(l.of(1).is_empty() && l.of(3).is_empty() && l.of(9).is_empty());
        assert_eq!((l.len(), l.start(2)), (3, 1));
    }

    #[test]
    fn face_verts_are_even_permutations() {
        for (i, f) in FACE_VERTS.iter().enumerate() {
            let p = [f[0], f[1], f[2], i];
            let mut inversions = 0;
            for a in 0..4 {
                for b in a + 1..4 {
                    if p[a] > p[b] {
                        inversions += 1;
                    }
                }
            }
            assert_eq!(inversions % 2, 0, "face {i}");
        }
    }

    #[test]
    fn face_refs_address_more_than_2_pow_31_slots() {
        let t = (MAX_TETS - 1) as TetId;
        let f = FaceRef::new(t, 3);
        assert_eq!(f.tet(), t);
        assert_eq!(f.face(), 3);
        assert!(f.0 as usize > (1usize << 31));
    }

    /// Every free slot records its place in the free list.
    fn free_places_hold(m: &Mesh) {
        for (k, &t) in m.free.iter().enumerate() {
            assert_eq!(m.tets[t as usize].v[0], DEAD);
            assert_eq!(m.tets[t as usize].v[1] as usize, k, "slot {t}");
        }
    }

    #[test]
    fn restoring_slots_keeps_the_free_list_in_order() {
        let mut m = Mesh::new(8);
        let ts: Vec<TetId> = (0..6)
            .map(|i| m.add_tet([i, i + 1, i + 2, 7]).unwrap())
            .collect();
        let saved: Vec<Tet> = ts.iter().map(|&t| *m.tet(t)).collect();
        for &t in &ts {
            m.kill_tet(t);
        }
        free_places_hold(&m);
        // Restoring from the middle moves the last free slot into the gap, as a
        // swap_remove does; the moved slot's place is updated with it.
        for &k in &[1usize, 4, 0] {
            m.restore_tet(ts[k], saved[k]);
            assert!(m.is_alive(ts[k]));
            free_places_hold(&m);
        }
        assert_eq!(m.free, vec![ts[3], ts[5], ts[2]]);
        // Slots are reused from the end of the list.
        assert_eq!(m.add_tet([0, 1, 2, 3]).unwrap(), ts[2]);
        m.kill_tet(ts[2]);
        m.restore_tet(ts[2], saved[2]);
        free_places_hold(&m);
        assert_eq!(m.free, vec![ts[3], ts[5]]);
    }

    #[test]
    fn slots_are_reused_and_links_checked() {
        let mut m = Mesh::new(5);
        let a = m.add_tet([0, 1, 2, 3]).unwrap();
        let b = m.add_tet([1, 0, 2, 4]).unwrap();
        // Face 3 of a is (0,1,2); face 3 of b is (1,0,2): the same face, reversed.
        m.glue(FaceRef::new(a, 3), FaceRef::new(b, 3));
        m.kill_tet(b);
        let c = m.add_tet([1, 0, 2, 4]).unwrap();
        assert_eq!(b, c);
        m.rebuild_vertex_map();
        assert_eq!(m.vertex_tet(4), Some(c));
        assert!(m.check_links().is_err()); // the other faces are unset
    }
}
