//! The tets' faces paired up: for every face of every tet (a slot, `4 × tet + face`),
//! the slot of the same face in the other tet that has it, or [`NONE`] on the boundary.
//! Each face is found among the tets around its lowest node, so the pairing needs no
//! sort of all faces (a million-point mesh has 27 million), and runs on every core.

use super::{names, Problems};
use crate::check::facets::Rows;
use crate::mesh::FACE_VERTS;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Faces of three tets or more, with how many.
type Crowded = Vec<([u32; 3], usize)>;

/// No tet beyond this face: it is on the boundary.
pub(super) const NONE: u32 = u32::MAX;

/// The face pairing of a mesh.
pub(super) struct Topology {
    /// For each slot, the slot of the same face in the other tet, or [`NONE`].
    pub adj: Vec<u32>,
    /// The boundary slots, in increasing order.
    pub boundary: Vec<u32>,
}

/// The nodes of face `f` of tet `t`, oriented with `t[f]` on the positive side.
pub(super) fn oriented_face(t: &[u32; 4], f: usize) -> [u32; 3] {
    let fv = FACE_VERTS[f];
    [t[fv[0]], t[fv[1]], t[fv[2]]]
}

/// The tet and face of a slot.
#[inline]
pub(super) fn split(s: u32) -> (usize, usize) {
    ((s >> 2) as usize, (s & 3) as usize)
}

/// The sorted nodes of the face in slot `s`.
pub(super) fn key(tets: &[[u32; 4]], s: u32) -> [u32; 3] {
    let (t, f) = split(s);
    let mut k = oriented_face(&tets[t], f);
    k.sort_unstable();
    k
}

impl Topology {
    /// Pairs the faces of `tets` (`stars`: the tets around each node); a face of three
    /// tets or more is a problem.
    pub fn build(tets: &[[u32; 4]], stars: &Rows, nodes: usize, pr: &mut Problems) -> Topology {
        let adj: Vec<AtomicU32> = (0..4 * tets.len()).map(|_| AtomicU32::new(NONE)).collect();
        // Nodes in the order the tets first name them: consecutive nodes then have their
        // tets near each other in memory (the tets come in a spatial order, node numbers
        // in the input's), which halves the time on large meshes.
        let mut order: Vec<u32> = Vec::with_capacity(nodes);
        let mut seen = vec![false; nodes];
        for t in tets {
            for &v in t {
                if !std::mem::replace(&mut seen[v as usize], true) {
                    order.push(v);
                }
            }
        }
        drop(seen);
        let crowded: Crowded = order
            .into_par_iter()
            .fold(
                || (Vec::new(), Vec::new()),
                |(mut buf, mut crowded): (Vec<(u32, u32, u32)>, Crowded), a| {
                    buf.clear();
                    for &t in stars.of(a) {
                        let tv = tets[t as usize];
                        let Some(j) = tv.iter().position(|&v| v == a) else {
                            continue;
                        };
                        // The faces through `a` are those opposite its three other nodes;
                        // each is paired around its lowest node.
                        for f in (0..4).filter(|&f| f != j) {
                            let mut o = (0..4).filter(|&i| i != j && i != f).map(|i| tv[i]);
                            let (b, c) = (o.next().unwrap_or(0), o.next().unwrap_or(0));
                            if b > a && c > a {
                                buf.push((b.min(c), b.max(c), 4 * t + f as u32));
                            }
                        }
                    }
                    buf.sort_unstable();
                    for run in buf.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
                        match run {
                            [_] => {}
                            [x, y] => {
                                adj[x.2 as usize].store(y.2, Relaxed);
                                adj[y.2 as usize].store(x.2, Relaxed);
                            }
                            _ => crowded.push(([a, run[0].0, run[0].1], run.len())),
                        }
                    }
                    (buf, crowded)
                },
            )
            .map(|(_, c)| c)
            .reduce(Vec::new, |mut a, b| {
                a.extend(b);
                a
            });
        for (k, count) in crowded {
            pr.push(format!("face {:?} belongs to {count} tets", names(pr, &k)));
        }
        let adj: Vec<u32> = adj.into_iter().map(AtomicU32::into_inner).collect();
        let boundary = (0..adj.len() as u32)
            .into_par_iter()
            .filter(|&s| adj[s as usize] == NONE)
            .collect();
        Topology { adj, boundary }
    }

    /// Every interior face once, as the slot with the lower number and its partner.
    pub fn pairs(&self) -> impl ParallelIterator<Item = (u32, u32)> + '_ {
        (0..self.adj.len() as u32).into_par_iter().filter_map(|s| {
            let o = self.adj[s as usize];
            (o != NONE && s < o).then_some((s, o))
        })
    }
}
