//! The domain of a CDT: the tets its subfaces enclose (not outside them, not in holes),
//! each with its region attribute. Floods never cross subfaces. The flat-tet search asks
//! for it while the CDT is built; carving keeps exactly these tets.

use super::cdt::Cdt;
use crate::delaunay::Location;
use crate::geom::Point;
use crate::mesh::{FaceRef, TetId};
use crate::plc::Region;

/// The tets of a CDT's domain, with their region attributes.
#[derive(Clone, Debug, Default)]
pub struct Domain {
    /// The kept real tets.
    pub tets: Vec<TetId>,
    /// The region attribute of each kept tet (0 where no region point reaches).
    pub attributes: Vec<f64>,
    /// The region (index in the PLC's list) of each kept tet, [`NO_REGION`] where no
    /// region point reaches.
    pub regions: Vec<u32>,
}

/// [`Domain::regions`] of a tet that no region point reaches.
pub const NO_REGION: u32 = u32::MAX;

impl Domain {
    /// Per tet slot (of `slots`), whether the tet is kept.
    pub fn kept_mask(&self, slots: usize) -> Vec<bool> {
        let mut kept = vec![false; slots];
        for &t in &self.tets {
            kept[t as usize] = true;
        }
        kept
    }
}

/// The domain: without the exterior (unless `keep_hull`) and the holes, with the regions
/// flooded.
pub fn domain(cdt: &mut Cdt, holes: &[Point], regions: &[Region], keep_hull: bool) -> Domain {
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
    let mut region = vec![NO_REGION; slots];
    let mut seen = vec![false; slots];
    for (ri, r) in regions.iter().enumerate() {
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
            region[t as usize] = ri as u32;
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
    let regions = tets.iter().map(|&t| region[t as usize]).collect();
    Domain {
        tets,
        attributes,
        regions,
    }
}

/// Marks as removed everything reachable from `stack` without crossing a subface.
fn flood(cdt: &Cdt, stack: &mut Vec<TetId>, removed: &mut [bool]) {
    while let Some(t) = stack.pop() {
        if removed[t as usize] {
            continue;
        }
        removed[t as usize] = true;
        for i in 0..4 {
            // The cheap test first: most faces of a flood lead back to removed tets.
            let n = cdt.dt.mesh.adj(FaceRef::new(t, i)).tet();
            if !removed[n as usize] && !cdt.is_subface(t, i) {
                stack.push(n);
            }
        }
    }
}

/// The real tet containing point `p`, if it lies inside the hull.
pub(crate) fn containing_tet(cdt: &mut Cdt, p: &Point) -> Option<TetId> {
    match cdt.dt.locate_anywhere(p) {
        Location::Inside(t) => Some(t),
        Location::Vertex(v) => cdt.dt.mesh.vertex_tet(v).filter(|&t| !cdt.is_ghost(t)),
        Location::Outside(_) => None,
    }
}

/// [`containing_tet`], searching from tet `near`.
pub(crate) fn containing_tet_near(cdt: &mut Cdt, near: TetId, p: &Point) -> Option<TetId> {
    match cdt.dt.locate_anywhere_from(near, p) {
        Location::Inside(t) => Some(t),
        Location::Vertex(v) => cdt.dt.mesh.vertex_tet(v).filter(|&t| !cdt.is_ghost(t)),
        Location::Outside(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constrained::cdt::face_key;
    use crate::delaunay::Delaunay;

    /// Two unit cubes side by side; the faces of the left cube are subfaces.
    fn two_cubes() -> Cdt {
        let mut pts = Vec::new();
        for x in 0..3 {
            for y in 0..2 {
                for z in 0..2 {
                    pts.push([x as f64, y as f64, z as f64]);
                }
            }
        }
        let mut cdt = Cdt::new(Delaunay::build(&pts).unwrap().dt);
        // Subfaces: every face of the mesh lying on the boundary of the left cube [0,1]^3.
        let p = cdt.dt.points.clone();
        let on_left_boundary = |f: [u32; 3]| {
            let q = f.map(|v| p[v as usize]);
            (0..3).any(|k| {
                (q.iter().all(|x| x[k] == 0.0) || q.iter().all(|x| x[k] == 1.0))
                    && q.iter().all(|x| x[0] <= 1.0)
            })
        };
        let tets: Vec<_> = cdt.dt.mesh.real_tets().collect();
        for t in tets {
            for i in 0..4 {
                let f = cdt.dt.mesh.face_verts(t, i);
                if on_left_boundary(f) {
                    cdt.subfaces.insert(face_key(f), 0);
                }
            }
        }
        cdt
    }

    fn volume(cdt: &Cdt, tets: &[TetId]) -> f64 {
        tets.iter()
            .map(|&t| {
                let v = cdt.dt.mesh.verts(t).map(|x| cdt.dt.points[x as usize]);
                crate::geom::orient3d(&v[0], &v[1], &v[2], &v[3]) / 6.0
            })
            .sum()
    }

    #[test]
    fn the_exterior_is_removed_up_to_subfaces() {
        let mut cdt = two_cubes();
        let c = domain(&mut cdt, &[], &[], false);
        assert!((volume(&cdt, &c.tets) - 1.0).abs() < 1e-12);
        // Every kept tet lies in the left cube.
        for &t in &c.tets {
            assert!(cdt
                .dt
                .mesh
                .verts(t)
                .iter()
                .all(|&v| cdt.dt.points[v as usize][0] <= 1.0));
        }
    }

    #[test]
    fn holes_regions_and_the_kept_hull() {
        let mut cdt = two_cubes();
        let c = domain(&mut cdt, &[], &[], true);
        assert!((volume(&cdt, &c.tets) - 2.0).abs() < 1e-12);
        let c = domain(&mut cdt, &[[0.5, 0.5, 0.5]], &[], true);
        assert!(
            (volume(&cdt, &c.tets) - 1.0).abs() < 1e-12,
            "the hole empties the left cube"
        );
        let region = |x: f64, a: f64| Region {
            point: [x, 0.5, 0.5],
            attribute: a,
            max_volume: -1.0,
        };
        let c = domain(&mut cdt, &[], &[region(0.5, 7.0), region(1.5, -2.0)], true);
        for ((&t, &a), &r) in c.tets.iter().zip(&c.attributes).zip(&c.regions) {
            assert_eq!(r, if a == 7.0 { 0 } else { 1 });
            let left = cdt
                .dt
                .mesh
                .verts(t)
                .iter()
                .all(|&v| cdt.dt.points[v as usize][0] <= 1.0);
            assert_eq!(a, if left { 7.0 } else { -2.0 });
        }
    }
}
