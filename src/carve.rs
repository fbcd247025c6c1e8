//! Carving: removing the tets outside the domain and in holes, and giving each remaining
//! tet its region attribute. Floods never cross subfaces.

use crate::constrained::cdt::Cdt;
use crate::delaunay::Location;
use crate::geom::Point;
use crate::mesh::{FaceRef, TetId};
use crate::plc::Region;

/// The tets that remain after carving, with their region attributes.
#[derive(Clone, Debug, Default)]
pub struct Carved {
    /// The kept real tets.
    pub tets: Vec<TetId>,
    /// The region attribute of each kept tet (0 where no region point reaches).
    pub attributes: Vec<f64>,
}

/// Carves the exterior (unless `keep_hull`), then the holes, and floods the regions.
pub fn carve(cdt: &mut Cdt, holes: &[Point], regions: &[Region], keep_hull: bool) -> Carved {
    let slots = cdt.dt.mesh.num_slots();
    let mut removed = vec![false; slots];
    let mut stack: Vec<TetId> = Vec::new();
    for t in cdt.dt.mesh.live_tets().collect::<Vec<_>>() {
        if cdt.is_ghost(t) {
            removed[t as usize] = true;
            if !keep_hull && !cdt.is_subface(t, 3) {
                stack.push(cdt.dt.mesh.adj(FaceRef::new(t, 3)).tet());
            }
        }
    }
    flood(cdt, &mut stack, &mut removed);
    for h in holes {
        if let Some(t) = containing_tet(cdt, h) {
            if !removed[t as usize] {
                stack.push(t);
                flood(cdt, &mut stack, &mut removed);
            }
        }
    }
    let mut attr = vec![0.0f64; slots];
    let mut seen = vec![false; slots];
    for r in regions {
        let Some(t) = containing_tet(cdt, &r.point) else {
            continue;
        };
        if removed[t as usize] {
            continue;
        }
        // Each region floods from scratch, so a later region point inside an earlier
        // region's tets takes them over, as TetGen does.
        seen.iter_mut().for_each(|s| *s = false);
        stack.push(t);
        seen[t as usize] = true;
        while let Some(t) = stack.pop() {
            attr[t as usize] = r.attribute;
            for i in 0..4 {
                if cdt.is_subface(t, i) {
                    continue;
                }
                let n = cdt.dt.mesh.adj(FaceRef::new(t, i)).tet();
                if !removed[n as usize] && !seen[n as usize] {
                    seen[n as usize] = true;
                    stack.push(n);
                }
            }
        }
    }
    let tets: Vec<TetId> = cdt
        .dt
        .mesh
        .real_tets()
        .filter(|&t| !removed[t as usize])
        .collect();
    let attributes = tets.iter().map(|&t| attr[t as usize]).collect();
    Carved { tets, attributes }
}

/// Marks as removed everything reachable from `stack` without crossing a subface.
fn flood(cdt: &Cdt, stack: &mut Vec<TetId>, removed: &mut [bool]) {
    while let Some(t) = stack.pop() {
        if removed[t as usize] {
            continue;
        }
        removed[t as usize] = true;
        for i in 0..4 {
            if cdt.is_subface(t, i) {
                continue;
            }
            let n = cdt.dt.mesh.adj(FaceRef::new(t, i)).tet();
            if !removed[n as usize] {
                stack.push(n);
            }
        }
    }
}

/// The real tet containing point `p`, if it lies inside the hull.
fn containing_tet(cdt: &mut Cdt, p: &Point) -> Option<TetId> {
    match cdt.dt.locate(p) {
        Location::Inside(t) => Some(t),
        Location::Vertex(v) => cdt.dt.mesh.vertex_tet(v).filter(|&t| !cdt.is_ghost(t)),
        Location::Outside(_) => None,
    }
}
