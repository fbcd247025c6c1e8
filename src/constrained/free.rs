//! Free Steiner points (inside the domain, on no constraint) put into a finished CDT: a
//! cavity walled in by the subfaces, then flips of the faces that are not locally
//! Delaunay, as TetGen does. A point that the flips cannot settle, or that would remove
//! a subsegment, is taken back, leaving the CDT exactly as it was.

use super::bistellar;
use super::cdt::{edge_key, face_key, Cdt};
use crate::delaunay::{Change, Walled};
use crate::error::MeshError;
use crate::geom::{insphere_sos, Point, Sign};
use crate::mesh::{FaceRef, TetId, VertexId, FACE_VERTS};
use rustc_hash::FxHashMap;

/// Flips per inserted point beyond which the point is taken back.
const MAX_FLIPS: usize = 20_000;

/// Inserts free points into the CDT, one from each list of candidates (the first that
/// fits), and returns how many it added and the first candidates of the lists it left
/// out (whose every candidate would break the CDT; the CDT then stays as it was).
pub(super) fn insert_free(
    cdt: &mut Cdt,
    free: &[Vec<Point>],
    next_pert: &mut u32,
) -> Result<(usize, Vec<Point>), MeshError> {
    let mut at: FxHashMap<VertexId, Vec<VertexId>> = FxHashMap::default();
    for &(a, b) in cdt.subsegs.keys() {
        at.entry(a).or_default().push(b);
        at.entry(b).or_default().push(a);
    }
    let mut added = 0;
    let mut refused = Vec::new();
    'tets: for ws in free {
        for &w in ws {
            match insert_one(cdt, w, *next_pert, &at)? {
                Some(true) => {
                    *next_pert += 1;
                    added += 1;
                    continue 'tets;
                }
                Some(false) => {}
                None => continue 'tets,
            }
        }
        refused.extend(ws.first());
    }
    Ok((added, refused))
}

/// Inserts one free point: `Some(true)` if in, `Some(false)` if taken back or refused,
/// `None` if it coincides with a vertex.
fn insert_one(
    cdt: &mut Cdt,
    w: Point,
    pert: u32,
    at: &FxHashMap<VertexId, Vec<VertexId>>,
) -> Result<Option<bool>, MeshError> {
    let subfaces = &cdt.subfaces;
    let blocked = |v: [VertexId; 4], f: usize| {
        let fv = FACE_VERTS[f];
        subfaces.contains_key(&face_key([v[fv[0]], v[fv[1]], v[fv[2]]]))
    };
    let (v, first, last) = match cdt.dt.insert_walled(w, pert, blocked)? {
        Walled::Inserted {
            vertex,
            change,
            last,
        } => (vertex, change, last),
        Walled::OnVertex => return Ok(None),
        Walled::Refused => return Ok(Some(false)),
    };
    let mut changes = vec![first];
    let settled = flip_to_delaunay(cdt, &mut changes)?;
    if settled && keeps_subsegments(cdt, &changes, at) {
        return Ok(Some(true));
    }
    cdt.dt.undo(v, &changes, last);
    Ok(Some(false))
}

/// Flips the faces of the tets made so far (`changes`) that are not locally Delaunay
/// until none is left, recording each flip; false if some face cannot be flipped (it
/// would remove a subface or a subsegment, or the tets around it do not allow a flip).
fn flip_to_delaunay(cdt: &mut Cdt, changes: &mut Vec<Change>) -> Result<bool, MeshError> {
    let mut queue: Vec<FaceRef> = changes[0]
        .new
        .iter()
        .flat_map(|&t| (0..4).map(move |i| FaceRef::new(t, i)))
        .collect();
    let mut stuck: Vec<FaceRef> = Vec::new();
    let mut flips = 0;
    while let Some(f) = queue.pop() {
        if !not_delaunay(cdt, f) {
            continue;
        }
        let Some(sh) = bistellar::shape(&cdt.dt.mesh, &cdt.dt.points, f) else {
            // Other flips may make it flippable: looked at again at the end.
            stuck.push(f);
            continue;
        };
        let constrained = match &sh.edge {
            None => false,
            Some(([e0, e1], apices)) => {
                cdt.subsegs.contains_key(&edge_key(*e0, *e1))
                    || apices
                        .iter()
                        .any(|&x| cdt.subfaces.contains_key(&face_key([*e0, *e1, x])))
            }
        };
        if constrained || sh.old.iter().any(|&t| cdt.dt.mesh.is_ghost(t)) {
            stuck.push(f);
            continue;
        }
        flips += 1;
        if flips > MAX_FLIPS {
            return Ok(false);
        }
        let old: Vec<(TetId, crate::mesh::Tet)> =
            sh.old.iter().map(|&t| (t, *cdt.dt.mesh.tet(t))).collect();
        let made = bistellar::replace(&mut cdt.dt.mesh, &sh.old, &sh.new, |_| {})?;
        queue.extend(
            made.iter()
                .flat_map(|&t| (0..4).map(move |i| FaceRef::new(t, i))),
        );
        queue.append(&mut stuck);
        changes.push(Change { old, new: made });
    }
    Ok(stuck.iter().all(|&f| !not_delaunay(cdt, f)))
}

/// Is face `f` of a live real tet, between two real tets, not a subface, and not
/// locally Delaunay?
fn not_delaunay(cdt: &Cdt, f: FaceRef) -> bool {
    let mesh = &cdt.dt.mesh;
    let t = f.tet();
    if !mesh.is_alive(t) || mesh.is_ghost(t) {
        return false;
    }
    let g = mesh.adj(f);
    if mesh.is_ghost(g.tet()) || cdt.is_subface(t, f.face()) {
        return false;
    }
    let tv = mesh.verts(t);
    let ids = [tv[0], tv[1], tv[2], tv[3], mesh.verts(g.tet())[g.face()]];
    let p = ids.map(|x| &cdt.dt.points[x as usize]);
    let orig = ids.map(|x| cdt.dt.orig[x as usize]);
    insphere_sos(p, orig) == Sign::Positive
}

/// Are the subsegments between vertices of the changed tets still mesh edges? Only
/// those can have gone.
fn keeps_subsegments(
    cdt: &mut Cdt,
    changes: &[Change],
    at: &FxHashMap<VertexId, Vec<VertexId>>,
) -> bool {
    let mut verts: Vec<VertexId> = changes
        .iter()
        .flat_map(|c| c.old.iter().flat_map(|(_, tet)| tet.v))
        .collect();
    verts.sort_unstable();
    verts.dedup();
    verts.iter().all(|&x| {
        at.get(&x)
            .map(|v| v.as_slice())
            .unwrap_or(&[])
            .iter()
            .all(|&y| x > y || verts.binary_search(&y).is_err() || cdt.has_edge(x, y))
    })
}
