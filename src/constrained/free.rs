//! Points put into a finished CDT (free Steiner points inside the domain, and Steiner
//! points on polygons that are not flat): a cavity walled in by the subfaces, then flips
//! of the faces that are not locally Delaunay, as TetGen does. A point that the flips
//! cannot settle, or that would remove a subsegment, is taken back, leaving the CDT
//! exactly as it was.

use super::bistellar;
use super::cdt::{edge_key, face_key, Cdt};
use super::slivers::Candidate;
use crate::delaunay::{Change, Walled};
use crate::error::MeshError;
use crate::geom::{insphere_sos, Point, Sign};
use crate::mesh::{FaceRef, TetId, VertexId, EDGE_VERTS, FACE_VERTS};

/// Flips per inserted point beyond which the point is taken back.
const MAX_FLIPS: usize = 20_000;

/// Inserts free points into the CDT, one from each list of candidates (the first that
/// fits, and that `accept` takes if it is to be checked), and returns how many it added
/// and the first candidates of the lists it left out because every candidate would
/// break the CDT (the CDT then stays as it was). Lists whose first candidate is to be
/// checked are left out silently.
pub(super) fn insert_free(
    cdt: &mut Cdt,
    free: &[Vec<Candidate>],
    next_pert: &mut u32,
    mut accept: impl FnMut(&Cdt, VertexId) -> bool,
) -> Result<(usize, Vec<Point>), MeshError> {
    let mut added = 0;
    let mut refused = Vec::new();
    'tets: for ws in free {
        for c in ws {
            let inserted = insert_point(cdt, c.at, *next_pert, false)?;
            match &inserted {
                &Inserted::Yes { vertex, .. } if c.checked && !accept(cdt, vertex) => {
                    if super::debug() {
                        eprintln!("point {:?}: a tet around it lies on a facet", c.at);
                    }
                    take_back(cdt, inserted);
                }
                Inserted::Yes { .. } => {
                    *next_pert += 1;
                    added += 1;
                    continue 'tets;
                }
                Inserted::Refused { .. } => {}
                Inserted::OnVertex => continue 'tets,
            }
        }
        refused.extend(ws.first().filter(|c| !c.checked).map(|c| c.at));
    }
    Ok((added, refused))
}

/// What [`insert_point`] did.
pub(crate) enum Inserted {
    /// The point is in as `vertex`; [`take_back`] undoes it while nothing else changed.
    Yes {
        vertex: VertexId,
        changes: Vec<Change>,
        last: TetId,
    },
    /// It would break the CDT: nothing changed. With the subsegment it would remove, or
    /// the subface its cavity would wrap around (or that a flip it needs would remove),
    /// when that is why.
    Refused {
        lost: Option<(VertexId, VertexId)>,
        wrapped: Option<[VertexId; 3]>,
    },
    /// It coincides with a vertex: nothing changed.
    OnVertex,
}

/// Inserts point `w` (perturbation index `pert`) into the CDT: a cavity walled in by the
/// subfaces, then flips until every face is locally Delaunay again. Refused, leaving
/// the CDT as it was, if the flips cannot get there or a subsegment would be lost.
/// `wrapped_asked`: whether a refusal should name the
/// subface in the way (a search, wasted where nobody asks).
pub(crate) fn insert_point(
    cdt: &mut Cdt,
    w: Point,
    pert: u32,
    wrapped_asked: bool,
) -> Result<Inserted, MeshError> {
    let subfaces = &cdt.subfaces;
    let blocked = |v: [VertexId; 4], f: usize| {
        let fv = FACE_VERTS[f];
        subfaces.contains_key(&face_key([v[fv[0]], v[fv[1]], v[fv[2]]]))
    };
    let (vertex, first, last) = match cdt.dt.insert_walled(w, pert, blocked)? {
        Walled::Inserted {
            vertex,
            change,
            last,
        } => (vertex, change, last),
        Walled::OnVertex => return Ok(Inserted::OnVertex),
        Walled::Refused => {
            if super::debug() {
                eprintln!("point {w:?}: its cavity wraps around a subface");
            }
            let subfaces = &cdt.subfaces;
            let wrapped = wrapped_asked
                .then(|| {
                    cdt.dt.wrapped_face(&w, |v: [VertexId; 4], f: usize| {
                        let fv = FACE_VERTS[f];
                        subfaces.contains_key(&face_key([v[fv[0]], v[fv[1]], v[fv[2]]]))
                    })
                })
                .flatten();
            return Ok(Inserted::Refused {
                lost: None,
                wrapped,
            });
        }
    };
    settle(cdt, w, (vertex, first, last), wrapped_asked)
}

/// After vertex `vertex` (at `w`) went in by change `first` (point location started at
/// `last` before), flips the faces that are not locally Delaunay; the point is in if
/// that settles and no subsegment is lost, else it is taken back.
pub(crate) fn settle(
    cdt: &mut Cdt,
    w: Point,
    (vertex, first, last): (VertexId, Change, TetId),
    wrapped_asked: bool,
) -> Result<Inserted, MeshError> {
    let mut changes = vec![first];
    let settled = flip_to_delaunay(cdt, &mut changes)?;
    let (lost, wrapped) = match settled {
        Ok(()) => (lost_subsegment(cdt, &changes), None),
        Err(in_way) => (None, in_way.filter(|_| wrapped_asked)),
    };
    let settled = settled.is_ok();
    if settled && lost.is_none() {
        return Ok(Inserted::Yes {
            vertex,
            changes,
            last,
        });
    }
    if super::debug() {
        eprintln!(
            "point {w:?}: {}",
            if settled {
                "a subsegment would be lost"
            } else {
                "the flips are stuck"
            }
        );
    }
    cdt.dt.undo(vertex, &changes, last);
    Ok(Inserted::Refused { lost, wrapped })
}

/// Takes back a point that [`insert_point`] put in, if nothing has changed since.
pub(crate) fn take_back(cdt: &mut Cdt, inserted: Inserted) {
    if let Inserted::Yes {
        vertex,
        changes,
        last,
    } = inserted
    {
        cdt.dt.undo(vertex, &changes, last);
    }
}

/// Flips the faces of the tets made so far (`changes`) that are not locally Delaunay
/// until none is left, recording each flip. Fails if some face cannot be flipped (it
/// would remove a subface or a subsegment, or the tets around it do not allow a flip),
/// naming a subface whose edge a wanted flip would remove, if there is one.
fn flip_to_delaunay(
    cdt: &mut Cdt,
    changes: &mut Vec<Change>,
) -> Result<Result<(), Option<[VertexId; 3]>>, MeshError> {
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
            return Ok(Err(None));
        }
        let old: Vec<(TetId, crate::mesh::Tet)> =
            sh.old.iter().map(|&t| (t, *cdt.dt.mesh.tet(t))).collect();
        let made = bistellar::flip(&mut cdt.dt.mesh, &sh, false, |_| {})?;
        queue.extend(
            made.iter()
                .flat_map(|&t| (0..4).map(move |i| FaceRef::new(t, i))),
        );
        queue.append(&mut stuck);
        changes.push(Change {
            old,
            new: made.to_vec(),
        });
    }
    let mut left = stuck
        .into_iter()
        .filter(|&f| not_delaunay(cdt, f))
        .peekable();
    if left.peek().is_none() {
        return Ok(Ok(()));
    }
    // A subface in the way of a flip: unrecovering its facet may let the point in.
    let in_way = left.find_map(|f| {
        let sh = bistellar::shape(&cdt.dt.mesh, &cdt.dt.points, f)?;
        let ([e0, e1], apices) = sh.edge.as_ref()?;
        apices
            .iter()
            .map(|&x| face_key([*e0, *e1, x]))
            .find(|k| cdt.subfaces.contains_key(k))
    });
    Ok(Err(in_way))
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

/// The first (in vertex order) subsegment that is an edge of a tet the changes removed
/// and no longer a mesh edge (only those can have gone), if any.
fn lost_subsegment(cdt: &mut Cdt, changes: &[Change]) -> Option<(VertexId, VertexId)> {
    let mut edges: Vec<(VertexId, VertexId)> = changes
        .iter()
        .flat_map(|c| c.old.iter())
        .flat_map(|(_, tet)| EDGE_VERTS.map(|(i, j)| edge_key(tet.v[i], tet.v[j])))
        .filter(|e| cdt.subsegs.contains_key(e))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges.into_iter().find(|&(x, y)| !cdt.has_edge(x, y))
}
