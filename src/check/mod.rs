//! The mesh validator behind `--check`: an independent check of a finished mesh against
//! its input, working on the flat output arrays rather than on the arena.
//!
//! For a point set it verifies that the tets are positively oriented, that faces are
//! shared by at most two tets lying on opposite sides, that the neighbour table agrees,
//! that the boundary is a closed locally convex surface enclosing the tets' volume with
//! every input point used (so the tets tile the convex hull), and that every face is
//! locally Delaunay under the symbolic perturbation. For a PLC it verifies instead that
//! every unconstrained face is locally Delaunay, that the constraints are in the mesh and
//! the boundary lies on them, that no input point is lost inside the mesh, and that no
//! shim tet survives (`shims.rs`: a flat tet with all four vertices on one facet, as the
//! shared referee counts them).

mod shims;

use crate::geom::{insphere_sos, orient3d, Point, Sign};
use crate::mesh::{EDGE_VERTS, FACE_VERTS};
use crate::output::MeshOut;
use crate::plc::Plc;

/// Stop collecting after this many problems; the count of the rest is reported.
const MAX_REPORTED: usize = 20;

struct Problems {
    list: Vec<String>,
    more: usize,
}

impl Problems {
    fn push(&mut self, msg: String) {
        if self.list.len() < MAX_REPORTED {
            self.list.push(msg);
        } else {
            self.more += 1;
        }
    }
    fn finish(self) -> Result<(), CheckFailure> {
        if self.list.is_empty() {
            Ok(())
        } else {
            Err(CheckFailure {
                total: self.list.len() + self.more,
                listed: self.list,
            })
        }
    }
}

/// What a failed check found: the first problems, a line each, and how many there are.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CheckFailure {
    /// The first problems found, at most twenty.
    pub listed: Vec<String>,
    /// How many problems there are in all, listed or not.
    pub total: usize,
}

impl std::fmt::Display for CheckFailure {
    /// The listed problems, one per line, and a last line counting the others.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.listed.join("\n"))?;
        if self.total > self.listed.len() {
            write!(
                f,
                "\n... and {} more problems",
                self.total - self.listed.len()
            )?;
        }
        Ok(())
    }
}

/// A face of a tet: sorted vertex key, the tet, and the local face index.
#[derive(Copy, Clone, PartialEq, Eq, PartialOrd, Ord)]
struct FaceEntry {
    key: [u32; 3],
    tet: u32,
    face: u8,
}

/// Checks `mesh` against `plc`; returns the problems found (empty means valid).
pub fn check_mesh(plc: &Plc, mesh: &MeshOut) -> Result<(), CheckFailure> {
    let mut pr = Problems {
        list: Vec::new(),
        more: 0,
    };
    let pts = &mesh.points;
    let n = pts.len();
    let base = mesh.first_index;
    for (i, t) in mesh.tets.iter().enumerate() {
        let bad_index = t.iter().any(|&v| v as usize >= n);
        let repeated = (0..4).any(|a| (a + 1..4).any(|b| t[a] == t[b]));
        if bad_index || repeated {
            pr.push(format!("tet {} has invalid vertices {:?}", i + base, t));
        }
    }
    if !pr.list.is_empty() {
        return pr.finish();
    }
    let p = |v: u32| -> &Point { &pts[v as usize] };
    let vol6 = |t: &[u32; 4]| orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3]));
    for (i, t) in mesh.tets.iter().enumerate() {
        if vol6(t) <= 0.0 {
            pr.push(format!(
                "tet {} {:?} is not positively oriented",
                i + base,
                shift(t, base)
            ));
        }
    }

    // Pair the faces by sorting; every face must have one or two tets.
    let mut faces: Vec<FaceEntry> = Vec::with_capacity(mesh.tets.len() * 4);
    for (i, t) in mesh.tets.iter().enumerate() {
        for (f, fv) in FACE_VERTS.iter().enumerate() {
            let mut key = [t[fv[0]], t[fv[1]], t[fv[2]]];
            key.sort_unstable();
            faces.push(FaceEntry {
                key,
                tet: i as u32,
                face: f as u8,
            });
        }
    }
    faces.sort_unstable();
    let subfaces: rustc_hash::FxHashSet<[u32; 3]> = mesh
        .subfaces
        .iter()
        .map(|(f, _)| {
            let mut k = *f;
            k.sort_unstable();
            k
        })
        .collect();
    let mut boundary: Vec<(u32, u8)> = Vec::new();
    let mut k = 0;
    while k < faces.len() {
        let mut j = k + 1;
        while j < faces.len() && faces[j].key == faces[k].key {
            j += 1;
        }
        match j - k {
            1 => boundary.push((faces[k].tet, faces[k].face)),
            2 => {
                let constrained = subfaces.contains(&faces[k].key);
                check_interior_face(mesh, faces[k], faces[k + 1], constrained, &mut pr)
            }
            m => pr.push(format!(
                "face {:?} is shared by {m} tets",
                faces[k].key.map(|v| v as usize + base)
            )),
        }
        k = j;
    }
    drop(faces);
    check_hull_faces(mesh, &mut boundary, &mut pr);
    check_boundary(mesh, &boundary, &mut pr);
    if mesh.plc_mode {
        // Each input point's first copy, which stands for its duplicates in the mesh.
        let rep = crate::precheck::representatives(&plc.points);
        check_constraints(plc, mesh, &rep, &subfaces, &boundary, &mut pr);
        check_points_kept(plc, mesh, &rep, &mut pr);
        check_shims(plc, mesh, &rep, &mut pr);
    } else {
        check_vertices_used(plc, mesh, &mut pr);
    }
    pr.finish()
}

/// If the mesh lists its hull faces, they must be the boundary faces, reversed (normals
/// pointing out), in the order of their tets and faces. Sorts `boundary` that way.
fn check_hull_faces(mesh: &MeshOut, boundary: &mut [(u32, u8)], pr: &mut Problems) {
    boundary.sort_unstable();
    if mesh.hull_faces.is_empty() || mesh.plc_mode {
        return;
    }
    let base = mesh.first_index;
    if mesh.hull_faces.len() != boundary.len() {
        pr.push(format!(
            "the mesh lists {} hull faces but has {} boundary faces",
            mesh.hull_faces.len(),
            boundary.len()
        ));
        return;
    }
    for (k, (&(t, f), h)) in boundary.iter().zip(&mesh.hull_faces).enumerate() {
        let o = oriented_face(&mesh.tets[t as usize], f as usize);
        if *h != [o[0], o[2], o[1]] {
            pr.push(format!(
                "hull face {} {:?} should be {:?} (face {f} of tet {})",
                k + base,
                shift(h, base),
                shift(&[o[0], o[2], o[1]], base),
                t as usize + base
            ));
        }
    }
}

/// PLC meshes: every subsegment and subface is in the mesh, every input segment is a
/// chain of subsegments, every polygon vertex is a mesh vertex, and the boundary of the
/// mesh lies on polygons (unless the convex hull was kept).
fn check_constraints(
    plc: &Plc,
    mesh: &MeshOut,
    rep: &[u32],
    subfaces: &rustc_hash::FxHashSet<[u32; 3]>,
    boundary: &[(u32, u8)],
    pr: &mut Problems,
) {
    use rustc_hash::{FxHashMap, FxHashSet};
    let base = mesh.first_index;
    let mut edges: FxHashSet<(u32, u32)> = FxHashSet::default();
    let mut faces: FxHashSet<[u32; 3]> = FxHashSet::default();
    for t in &mesh.tets {
        for (a, b) in EDGE_VERTS {
            edges.insert((t[a].min(t[b]), t[a].max(t[b])));
        }
        for fv in FACE_VERTS {
            let mut k = [t[fv[0]], t[fv[1]], t[fv[2]]];
            k.sort_unstable();
            faces.insert(k);
        }
    }
    for &([a, b], _) in &mesh.subsegments {
        if !edges.contains(&(a.min(b), a.max(b))) {
            pr.push(format!(
                "subsegment ({}, {}) is not a mesh edge",
                a as usize + base,
                b as usize + base
            ));
        }
    }
    for f in subfaces {
        if !faces.contains(f) {
            pr.push(format!("subface {:?} is not a mesh face", shift(f, base)));
        }
    }
    if !mesh.convex_hull_kept {
        for &(t, f) in boundary {
            let mut k = oriented_face(&mesh.tets[t as usize], f as usize);
            k.sort_unstable();
            if !subfaces.contains(&k) {
                pr.push(format!(
                    "boundary face {:?} lies on no polygon",
                    shift(&k, base)
                ));
            }
        }
    }
    // Each polygon edge must be joined up by subsegments running along it.
    let mut adj: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for &([a, b], _) in &mesh.subsegments {
        adj.entry(a).or_default().push(b);
        adj.entry(b).or_default().push(a);
    }
    let mut seen_edges: FxHashSet<(u32, u32)> = FxHashSet::default();
    for (fi, facet) in plc.facets.iter().enumerate() {
        for poly in &facet.polygons {
            let ring: Vec<u32> = poly.iter().map(|&v| rep[v as usize]).collect();
            let n = ring.len();
            if n < 2 {
                continue;
            }
            let count = if n == 2 { 1 } else { n };
            for k in 0..count {
                let (a, b) = (ring[k], ring[(k + 1) % n]);
                if a == b || !seen_edges.insert((a.min(b), a.max(b))) {
                    continue;
                }
                if !joined_along(mesh, &adj, a, b) {
                    // Edges between merged coplanar polygons are not constraints: they
                    // need no subsegments, but their facets still cover them. (A polygon
                    // that carving would drop is refused by the mesher, so every
                    // constraint edge must be here.)
                    if !edges.contains(&(a.min(b), a.max(b))) && is_segment(plc, rep, a, b) {
                        pr.push(format!(
                            "facet {}: edge ({}, {}) is not covered by subsegments",
                            fi + base,
                            a as usize + base,
                            b as usize + base
                        ));
                    }
                }
            }
        }
    }
}

/// No shim tet may survive: a flat tet whose four vertices lie on one (merged) facet.
fn check_shims(plc: &Plc, mesh: &MeshOut, rep: &[u32], pr: &mut Problems) {
    let found = shims::shims(plc, mesh, rep);
    let base = mesh.first_index;
    for &(t, facet) in &found {
        pr.push(format!(
            "tet {} {:?} is a shim: flat, with all four vertices on facet {} (as merged)",
            t + base,
            shift(&mesh.tets[t], base),
            facet + base
        ));
    }
}

/// True if `q` lies in tet `t` (boundary included): exact orientations.
fn in_tet(mesh: &MeshOut, t: &[u32; 4], q: &Point) -> bool {
    let w = t.map(|v| mesh.points[v as usize]);
    let o = orient3d(&w[0], &w[1], &w[2], &w[3]);
    (0..4).all(|i| {
        let mut x = w;
        x[i] = *q;
        orient3d(&x[0], &x[1], &x[2], &x[3]) * o >= 0.0
    })
}

/// PLC meshes: an input point that is no mesh vertex must lie outside the mesh (carved
/// away with the exterior or a hole), and never inside a tet.
fn check_points_kept(plc: &Plc, mesh: &MeshOut, rep: &[u32], pr: &mut Problems) {
    let mut used = vec![false; mesh.points.len()];
    for t in &mesh.tets {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let unused: Vec<u32> = (0..plc.points.len() as u32)
        .filter(|&i| rep[i as usize] == i && !used.get(i as usize).copied().unwrap_or(false))
        .collect();
    if unused.is_empty() {
        return;
    }
    let p = |v: u32| mesh.points[v as usize];
    for t in &mesh.tets {
        let (mut lo, mut hi) = (p(t[0]), p(t[0]));
        for &v in &t[1..] {
            for k in 0..3 {
                lo[k] = lo[k].min(p(v)[k]);
                hi[k] = hi[k].max(p(v)[k]);
            }
        }
        for &x in &unused {
            let q = plc.points[x as usize];
            if (0..3).any(|k| q[k] < lo[k] || q[k] > hi[k]) {
                continue;
            }
            if in_tet(mesh, t, &q) {
                pr.push(format!(
                    "input point {} lies in tet {:?} but is not a mesh vertex",
                    x as usize + mesh.first_index,
                    shift(t, mesh.first_index)
                ));
                return;
            }
        }
    }
}

/// Is edge `ab` used by a single polygon, or by polygons that are not coplanar? (Then it
/// is a segment; TetGen drops only edges between coplanar neighbours.)
fn is_segment(plc: &Plc, rep: &[u32], a: u32, b: u32) -> bool {
    let mut users = 0;
    for f in &plc.facets {
        for poly in &f.polygons {
            let ring: Vec<u32> = poly.iter().map(|&v| rep[v as usize]).collect();
            let n = ring.len();
            if n == 2 && ((ring[0] == a && ring[1] == b) || (ring[0] == b && ring[1] == a)) {
                return true;
            }
            if n >= 3
                && (0..n).any(|k| {
                    let (x, y) = (ring[k], ring[(k + 1) % n]);
                    (x == a && y == b) || (x == b && y == a)
                })
            {
                users += 1;
            }
        }
    }
    users != 2
}

/// Is there a path of subsegments from `a` to `b` whose vertices stay within rounding
/// distance of the line through them?
fn joined_along(
    mesh: &MeshOut,
    adj: &rustc_hash::FxHashMap<u32, Vec<u32>>,
    a: u32,
    b: u32,
) -> bool {
    let pa = mesh.points[a as usize];
    let pb = mesh.points[b as usize];
    let d: [f64; 3] = std::array::from_fn(|k| pb[k] - pa[k]);
    let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if len2 == 0.0 {
        return false;
    }
    // Steiner points are rounded to the nearest doubles: allow a few ulps of the
    // coordinates' magnitude.
    let scale = pa
        .iter()
        .chain(pb.iter())
        .fold(0.0f64, |m, c| m.max(c.abs()));
    let tol2 = 3.0 * (1e-14 * scale).powi(2) + 1e-300;
    let on_line = |v: u32| {
        let p = mesh.points[v as usize];
        let w: [f64; 3] = std::array::from_fn(|k| p[k] - pa[k]);
        let t = (w[0] * d[0] + w[1] * d[1] + w[2] * d[2]) / len2;
        let off: f64 = (0..3).map(|k| (w[k] - t * d[k]).powi(2)).sum();
        (-1e-9..=1.0 + 1e-9).contains(&t) && off <= tol2
    };
    let mut stack = vec![a];
    let mut seen = rustc_hash::FxHashSet::default();
    seen.insert(a);
    while let Some(v) = stack.pop() {
        if v == b {
            return true;
        }
        for &w in adj.get(&v).map(|x| x.as_slice()).unwrap_or(&[]) {
            if seen.insert(w) && on_line(w) {
                stack.push(w);
            }
        }
    }
    false
}

fn shift(t: &[u32], base: usize) -> Vec<usize> {
    t.iter().map(|&v| v as usize + base).collect()
}

/// The vertices of face `f` of `t`, oriented with `t[f]` on the positive side.
fn oriented_face(t: &[u32; 4], f: usize) -> [u32; 3] {
    let fv = FACE_VERTS[f];
    [t[fv[0]], t[fv[1]], t[fv[2]]]
}

fn check_interior_face(
    mesh: &MeshOut,
    a: FaceEntry,
    b: FaceEntry,
    constrained: bool,
    pr: &mut Problems,
) {
    let base = mesh.first_index;
    let ta = &mesh.tets[a.tet as usize];
    let tb = &mesh.tets[b.tet as usize];
    let (fa, fb) = (a.face as usize, b.face as usize);
    let pts = &mesh.points;
    // The opposite vertices must lie on opposite sides of the shared face.
    let f = oriented_face(ta, fa);
    let e = tb[fb];
    let side = orient3d(
        &pts[f[0] as usize],
        &pts[f[1] as usize],
        &pts[f[2] as usize],
        &pts[e as usize],
    );
    if side >= 0.0 {
        pr.push(format!(
            "tets {} and {} overlap across face {:?}",
            a.tet as usize + base,
            b.tet as usize + base,
            a.key.map(|v| v as usize + base)
        ));
        return;
    }
    if let Some(nb) = mesh.neighbors.get(a.tet as usize) {
        if nb[fa] != i64::from(b.tet) || mesh.neighbors[b.tet as usize][fb] != i64::from(a.tet) {
            pr.push(format!(
                "neighbour table disagrees at face {:?} of tets {} and {}",
                a.key.map(|v| v as usize + base),
                a.tet as usize + base,
                b.tet as usize + base
            ));
        }
    }
    // Only faces on polygons may fail to be locally Delaunay (the CDT property).
    if !constrained {
        let q = [ta[0], ta[1], ta[2], ta[3], e];
        let s = insphere_sos(q.map(|v| &pts[v as usize]), q);
        if s != Sign::Negative {
            pr.push(format!(
                "face {:?} between tets {} and {} is not locally Delaunay",
                a.key.map(|v| v as usize + base),
                a.tet as usize + base,
                b.tet as usize + base
            ));
        }
    }
}

/// The boundary must be a closed surface, each edge in two faces with opposite
/// directions, locally convex, and enclosing exactly the tets' volume.
fn check_boundary(mesh: &MeshOut, boundary: &[(u32, u8)], pr: &mut Problems) {
    let base = mesh.first_index;
    let pts = &mesh.points;
    let p = |v: u32| -> &Point { &pts[v as usize] };
    for &(t, f) in boundary {
        if let Some(nb) = mesh.neighbors.get(t as usize) {
            if nb[f as usize] != -1 {
                pr.push(format!(
                    "tet {} has a neighbour across its boundary face {}",
                    t as usize + base,
                    f
                ));
            }
        }
    }
    if boundary.is_empty() {
        if !mesh.tets.is_empty() {
            pr.push("the mesh has no boundary".into());
        }
        return;
    }
    // Directed edges (a, b) of the boundary faces, oriented inward, with the face index.
    let mut edges: Vec<(u32, u32, u32)> = Vec::with_capacity(boundary.len() * 3);
    for (idx, &(t, f)) in boundary.iter().enumerate() {
        let fv = oriented_face(&mesh.tets[t as usize], f as usize);
        for k in 0..3 {
            edges.push((fv[k], fv[(k + 1) % 3], idx as u32));
        }
    }
    let mut undirected: Vec<(u32, u32, u32, bool)> = edges
        .iter()
        .map(|&(a, b, i)| (a.min(b), a.max(b), i, a < b))
        .collect();
    undirected.sort_unstable();
    let mut k = 0;
    while k < undirected.len() {
        let mut j = k + 1;
        while j < undirected.len()
            && (undirected[j].0, undirected[j].1) == (undirected[k].0, undirected[k].1)
        {
            j += 1;
        }
        let (a, b) = (undirected[k].0, undirected[k].1);
        let forward = undirected[k..j].iter().filter(|e| e.3).count();
        // A PLC's boundary may be non-manifold at an edge (two solids touching along
        // it), but must still pair every face with one of opposite direction.
        let paired = if mesh.plc_mode {
            (j - k) % 2 == 0 && 2 * forward == j - k
        } else {
            j - k == 2 && forward == 1
        };
        if !paired {
            pr.push(format!(
                "boundary edge ({}, {}) is in {} boundary faces, not two of opposite sides",
                a as usize + base,
                b as usize + base,
                j - k
            ));
        } else if !mesh.plc_mode {
            let (f1, f2) = (undirected[k].2 as usize, undirected[k + 1].2 as usize);
            check_hull_edge(mesh, boundary[f1], boundary[f2], pr);
        }
        k = j;
    }
    // The enclosed volume (divergence theorem) must equal the tets' total volume. Faces
    // are oriented inward, so each contributes the signed volume of its cone to a centre.
    // Both sums are rounded, so they are compared within their summed error bounds.
    let centre = {
        let v0 = p(boundary_face(mesh, boundary[0])[0]);
        *v0
    };
    let (mut enclosed, mut err) = (0.0, 0.0);
    for &bf in boundary {
        let fv = boundary_face(mesh, bf);
        let (v, e) = volume6_with_error(p(fv[0]), p(fv[1]), p(fv[2]), &centre);
        enclosed += v;
        err += e;
    }
    let mut total = 0.0;
    for t in &mesh.tets {
        let (v, e) = volume6_with_error(p(t[0]), p(t[1]), p(t[2]), p(t[3]));
        total += v;
        err += e;
    }
    let tol = err + 1e-12 * (enclosed.abs() + total.abs()) + f64::MIN_POSITIVE;
    if (enclosed - total).abs() > tol {
        pr.push(format!(
            "the boundary encloses volume {} but the tets' volumes sum to {}",
            enclosed / 6.0,
            total / 6.0
        ));
    }
}

/// The inward-oriented vertices of a boundary face.
fn boundary_face(mesh: &MeshOut, (t, f): (u32, u8)) -> [u32; 3] {
    oriented_face(&mesh.tets[t as usize], f as usize)
}

/// Six times the signed volume of `abcd` in our orientation, in floating point, with a
/// bound on its rounding error (Shewchuk's first-stage bound on the permanent).
fn volume6_with_error(a: &Point, b: &Point, c: &Point, d: &Point) -> (f64, f64) {
    let u = [a[0] - d[0], a[1] - d[1], a[2] - d[2]];
    let v = [b[0] - d[0], b[1] - d[1], b[2] - d[2]];
    let w = [c[0] - d[0], c[1] - d[1], c[2] - d[2]];
    let det = u[2] * (v[0] * w[1] - w[0] * v[1])
        + v[2] * (w[0] * u[1] - u[0] * w[1])
        + w[2] * (u[0] * v[1] - v[0] * u[1]);
    let perm = u[2].abs() * ((v[0] * w[1]).abs() + (w[0] * v[1]).abs())
        + v[2].abs() * ((w[0] * u[1]).abs() + (u[0] * w[1]).abs())
        + w[2].abs() * ((u[0] * v[1]).abs() + (v[0] * u[1]).abs());
    (-det, 1e-15 * perm)
}

/// At a hull edge the two hull faces must meet convexly; when they are coplanar, the
/// hull triangulation there must be Delaunay under the perturbation (TetGen's rule).
fn check_hull_edge(mesh: &MeshOut, f1: (u32, u8), f2: (u32, u8), pr: &mut Problems) {
    let base = mesh.first_index;
    let pts = &mesh.points;
    let t1 = &mesh.tets[f1.0 as usize];
    let face1 = oriented_face(t1, f1.1 as usize);
    let face2 = oriented_face(&mesh.tets[f2.0 as usize], f2.1 as usize);
    let Some(&x) = face2.iter().find(|v| !face1.contains(v)) else {
        return;
    };
    let p = |v: u32| &pts[v as usize];
    let o = orient3d(p(face1[0]), p(face1[1]), p(face1[2]), p(x));
    if o < 0.0 {
        pr.push(format!(
            "the boundary is not convex at faces {:?} and {:?}",
            shift(&face1, base),
            shift(&face2, base)
        ));
    } else if o == 0.0 {
        let q = [t1[0], t1[1], t1[2], t1[3], x];
        if insphere_sos(q.map(p), q) != Sign::Negative {
            pr.push(format!(
                "coplanar hull faces {:?} and {:?} are not Delaunay",
                shift(&face1, base),
                shift(&face2, base)
            ));
        }
    }
}

/// Every input point must be a mesh vertex unless it duplicates an earlier point.
fn check_vertices_used(plc: &Plc, mesh: &MeshOut, pr: &mut Problems) {
    let base = mesh.first_index;
    let mut used = vec![false; mesh.points.len()];
    for t in &mesh.tets {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let mut unused: Vec<usize> = (0..plc.points.len().min(used.len()))
        .filter(|&i| !used[i])
        .collect();
    if unused.is_empty() {
        return;
    }
    // An unused point is fine only if an identical point is used.
    let mut by_coord: Vec<usize> = (0..plc.points.len()).collect();
    let key = |i: usize| plc.points[i].map(|c| (c + 0.0).to_bits());
    by_coord.sort_unstable_by_key(|&i| key(i));
    let mut has_used_twin = vec![false; plc.points.len()];
    let mut k = 0;
    while k < by_coord.len() {
        let mut j = k + 1;
        while j < by_coord.len() && key(by_coord[j]) == key(by_coord[k]) {
            j += 1;
        }
        let any_used = by_coord[k..j].iter().any(|&i| used[i]);
        for &i in &by_coord[k..j] {
            has_used_twin[i] = any_used && !used[i];
        }
        k = j;
    }
    unused.retain(|&i| !has_used_twin[i]);
    for i in unused {
        pr.push(format!(
            "input point {} is not a vertex of the mesh",
            i + base
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::options::Options;

    fn cube_with_center() -> Plc {
        let mut pts: Vec<Point> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        pts.push([0.4, 0.45, 0.55]);
        pts.push([0.9, 0.2, 0.3]);
        Plc::from_points(pts, 0)
    }

    fn meshed(plc: &Plc) -> MeshOut {
        crate::tetrahedralize(plc, &Options::default())
            .unwrap()
            .mesh
    }

    #[test]
    fn a_delaunay_mesh_passes() {
        let plc = cube_with_center();
        check_mesh(&plc, &meshed(&plc)).unwrap();
    }

    #[test]
    fn wrong_hull_faces_fail() {
        let plc = cube_with_center();
        let mut m = meshed(&plc);
        assert!(!m.hull_faces.is_empty());
        m.hull_faces[0].swap(1, 2);
        let e = check_mesh(&plc, &m).unwrap_err().to_string();
        assert!(e.contains("hull face 0"), "{e}");
        m.hull_faces.pop();
        let e = check_mesh(&plc, &m).unwrap_err().to_string();
        assert!(e.contains("hull faces but has"), "{e}");
    }

    #[test]
    fn an_inverted_tet_fails() {
        let plc = cube_with_center();
        let mut m = meshed(&plc);
        m.tets[0].swap(0, 1);
        let e = check_mesh(&plc, &m).unwrap_err().to_string();
        assert!(e.contains("not positively oriented"), "{e}");
    }

    #[test]
    fn a_missing_tet_fails() {
        let plc = cube_with_center();
        let mut m = meshed(&plc);
        let all_used_before = m.tets.len();
        m.tets.remove(all_used_before / 2);
        m.neighbors.clear();
        let e = check_mesh(&plc, &m).unwrap_err().to_string();
        assert!(e.contains("boundary"), "{e}");
    }

    #[test]
    fn a_non_delaunay_face_fails() {
        // Two tets sharing a face whose opposite vertices see each other inside
        // their circumspheres: a valid tiling of the hull, but not Delaunay.
        let pts = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.3, 0.3, 0.05],
            [0.3, 0.3, -0.05],
        ];
        let plc = Plc::from_points(pts.clone(), 0);
        let orient = |t: [u32; 4]| {
            let p = |v: u32| &pts[v as usize];
            if orient3d(p(t[0]), p(t[1]), p(t[2]), p(t[3])) > 0.0 {
                t
            } else {
                [t[1], t[0], t[2], t[3]]
            }
        };
        let m = MeshOut {
            points: pts.clone(),
            tets: vec![orient([0, 1, 2, 3]), orient([0, 1, 2, 4])],
            ..Default::default()
        };
        let e = check_mesh(&plc, &m).unwrap_err().to_string();
        assert!(
            e.contains("not locally Delaunay") || e.contains("not convex"),
            "{e}"
        );
    }

    #[test]
    fn an_unused_point_fails_but_a_duplicate_does_not() {
        let mut plc = cube_with_center();
        plc.points.push(plc.points[3]);
        let m = meshed(&plc);
        check_mesh(&plc, &m).unwrap();
        let mut m2 = m.clone();
        // Pretend point 9 was never inserted: drop every tet that uses it.
        m2.tets.retain(|t| !t.contains(&9));
        m2.neighbors.clear();
        assert!(check_mesh(&plc, &m2).is_err());
    }

    #[test]
    fn a_plc_point_inside_the_mesh_must_be_a_vertex() {
        let cube = |extra: bool| {
            let mut plc = cube_with_center();
            plc.points.truncate(8);
            if extra {
                plc.points.push([0.4, 0.45, 0.55]);
            }
            let quads = [
                [0, 2, 3, 1],
                [4, 5, 7, 6],
                [0, 1, 5, 4],
                [2, 6, 7, 3],
                [0, 4, 6, 2],
                [1, 3, 7, 5],
            ];
            plc.facets = quads
                .iter()
                .map(|q| crate::plc::Facet {
                    polygons: vec![q.to_vec()],
                    ..Default::default()
                })
                .collect();
            plc
        };
        let opts = Options {
            plc: true,
            ..Default::default()
        };
        let full = cube(true);
        let m = crate::tetrahedralize(&full, &opts).unwrap().mesh;
        check_mesh(&full, &m).unwrap();
        // The cube meshed without its inner point, checked against the model with it.
        let mut lost = crate::tetrahedralize(&cube(false), &opts).unwrap().mesh;
        lost.points.push(full.points[8]);
        let e = check_mesh(&full, &lost).unwrap_err().to_string();
        assert!(e.contains("input point 8 lies in tet"), "{e}");
    }

    #[test]
    fn a_shim_fails() {
        // A square pyramid whose base is bent by 1e-4: the mesher's mesh passes, and the
        // same domain with a flat tet of the four base corners beneath two others fails.
        let mut plc = Plc::from_points(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, -1e-4],
                [0.5, 0.5, 1.0],
            ],
            0,
        );
        let polygons = [
            vec![0, 1, 2, 3],
            vec![0, 1, 4],
            vec![1, 2, 4],
            vec![2, 3, 4],
            vec![3, 0, 4],
        ];
        plc.facets = polygons
            .into_iter()
            .map(|p| crate::plc::Facet {
                polygons: vec![p],
                ..Default::default()
            })
            .collect();
        let opts = Options {
            plc: true,
            ..Default::default()
        };
        let mut m = crate::tetrahedralize(&plc, &opts).unwrap().mesh;
        check_mesh(&plc, &m).unwrap();
        m.tets = [[0, 1, 2, 3], [0, 1, 2, 4], [0, 2, 3, 4]]
            .into_iter()
            .map(|mut t| {
                let p = t.map(|v| m.points[v as usize]);
                if orient3d(&p[0], &p[1], &p[2], &p[3]) < 0.0 {
                    t.swap(0, 1);
                }
                t
            })
            .collect();
        m.neighbors.clear();
        // The base's triangles are now the lower pair, under the flat tet.
        m.subfaces.retain(|(f, _)| f.contains(&4));
        m.subfaces.extend([([0, 1, 3], 0), ([1, 2, 3], 0)]);
        let e = check_mesh(&plc, &m).unwrap_err();
        assert_eq!(e.total, 1, "{e:?}");
        assert!(
            e.listed[0].starts_with("tet 0 ") && e.listed[0].contains("is a shim"),
            "{e:?}"
        );
    }

    #[test]
    fn problems_past_the_listed_ones_are_counted() {
        let plc = cube_with_center();
        let mut m = meshed(&plc);
        m.tets = vec![[0, 0, 1, 2]; 30];
        m.neighbors.clear();
        let e = check_mesh(&plc, &m).unwrap_err();
        assert_eq!((e.total, e.listed.len()), (30, 20), "{e:?}");
        assert!(e.to_string().ends_with("\n... and 10 more problems"), "{e}");
    }

    #[test]
    fn overlapping_tets_fail() {
        let plc = cube_with_center();
        let mut m = meshed(&plc);
        let t = m.tets[0];
        m.tets.push(t);
        m.neighbors.clear();
        let e = check_mesh(&plc, &m).unwrap_err().to_string();
        assert!(e.contains("shared by"), "{e}");
    }
}
