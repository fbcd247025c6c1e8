//! The finished mesh in flat, arena-free form: what the writers and the checker consume.

/// A finished tetrahedral mesh, numbered from 0, with tets in TetGen's orientation.
#[derive(Clone, Debug, Default)]
pub struct MeshOut {
    /// Node coordinates: the input points in input order, then Steiner points.
    pub points: Vec<[f64; 3]>,
    /// Number of attributes per node.
    pub num_point_attrs: usize,
    /// Node attributes, `num_point_attrs` per node (Steiner points get zeros).
    pub point_attrs: Vec<f64>,
    /// Node boundary markers, when the input had them.
    pub point_markers: Option<Vec<i32>>,
    /// Tets as 0-based node indices. TetGen's orientation: the Shewchuk orient3d of
    /// (a, b, c, d) is negative, i.e. d lies above the counterclockwise triangle a, b, c.
    pub tets: Vec<[u32; 4]>,
    /// For tet `i`, `neighbors[i][j]` is the tet opposite node `j`, or -1 on the boundary.
    /// May be empty (a point set meshed without `-n`, `-f` or `-e` skips it): consumers
    /// that need it derive it from `tets` (see `io::write::Derived`).
    pub neighbors: Vec<[i64; 4]>,
    /// Point sets: the convex hull faces, oriented with their normals pointing out of the
    /// mesh (counterclockwise seen from outside), in the order of their tets and, within
    /// a tet, of the node opposite them: the `.face` file's order. When empty, the
    /// writer derives the hull from the neighbours instead.
    pub hull_faces: Vec<[u32; 3]>,
    /// Number of attributes per tet (1 with `-A`, else 0).
    pub num_tet_attrs: usize,
    /// Tet attributes, `num_tet_attrs` per tet.
    pub tet_attrs: Vec<f64>,
    /// Constrained faces (subpolygons) with their facet markers; empty for point sets.
    pub subfaces: Vec<([u32; 3], i32)>,
    /// Constrained edges (subsegments) with their markers; empty for point sets.
    pub subsegments: Vec<([u32; 2], i32)>,
    /// True when the mesh came from a PLC (`-p`), which changes what `.face` and `.edge` hold.
    pub plc_mode: bool,
    /// True when each subface is already as seen from its lower-numbered tet (as the
    /// mesher writes them), so the `.face` writer need not find their tets again.
    pub subfaces_oriented: bool,
    /// Number of the first node in the input (0 or 1); output follows it unless `-z`.
    pub first_index: usize,
    /// True when the exterior was kept (`-c`), so the boundary need not lie on polygons.
    pub convex_hull_kept: bool,
}

impl MeshOut {
    /// The mesh as written when it differs from this one: [`MeshOut::jettisoned`]
    /// unless `keep_unused` (`-J`).
    pub fn written(&self, keep_unused: bool) -> Option<MeshOut> {
        if keep_unused {
            None
        } else {
            self.jettisoned()
        }
    }

    /// The mesh without the nodes that no tet uses (duplicates of other points, points
    /// outside the domain or in holes), renumbered in order, as TetGen writes its output
    /// unless given `-J`; `None` if every node is used, or if there are no tets.
    pub fn jettisoned(&self) -> Option<MeshOut> {
        if self.tets.is_empty() {
            return None;
        }
        let mut used = vec![false; self.points.len()];
        let tets = self.tets.iter().flatten();
        // Constrained faces and edges lie on tets; kept in case one ever does not.
        let faces = self.subfaces.iter().flat_map(|(f, _)| f);
        let edges = self.subsegments.iter().flat_map(|(e, _)| e);
        for &v in tets.chain(faces).chain(edges) {
            // A node that does not exist leaves the mesh as it is (the checker names it).
            *used.get_mut(v as usize)? = true;
        }
        if used.iter().all(|&u| u) {
            return None;
        }
        let kept: Vec<usize> = (0..self.points.len()).filter(|&i| used[i]).collect();
        let mut new_index = vec![u32::MAX; self.points.len()];
        for (n, &i) in kept.iter().enumerate() {
            new_index[i] = n as u32;
        }
        let map = |v: u32| new_index[v as usize];
        let k = self.num_point_attrs;
        Some(MeshOut {
            points: kept.iter().map(|&i| self.points[i]).collect(),
            point_attrs: kept
                .iter()
                .flat_map(|&i| {
                    let row = self.point_attrs.get(i * k..(i + 1) * k);
                    row.unwrap_or_default().iter().copied()
                })
                .collect(),
            point_markers: self.point_markers.as_ref().map(|m| {
                kept.iter()
                    .map(|&i| m.get(i).copied().unwrap_or(0))
                    .collect()
            }),
            tets: self.tets.iter().map(|t| t.map(map)).collect(),
            hull_faces: self.hull_faces.iter().map(|f| f.map(map)).collect(),
            subfaces: self
                .subfaces
                .iter()
                .map(|(f, m)| (f.map(map), *m))
                .collect(),
            subsegments: self
                .subsegments
                .iter()
                .map(|(e, m)| (e.map(map), *m))
                .collect(),
            neighbors: self.neighbors.clone(),
            tet_attrs: self.tet_attrs.clone(),
            ..*self
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tets on five points, with an unused point before, between and after them.
    fn with_unused() -> MeshOut {
        let p = |x: f64| [x, x * x, 1.0 - x];
        MeshOut {
            points: vec![
                p(9.0),
                p(0.0),
                p(1.0),
                p(8.0),
                p(2.0),
                p(3.0),
                p(4.0),
                p(7.0),
            ],
            num_point_attrs: 1,
            point_attrs: vec![90.0, 0.0, 10.0, 80.0, 20.0, 30.0, 40.0, 70.0],
            point_markers: Some(vec![9, 0, 1, 8, 2, 3, 4, 7]),
            tets: vec![[1, 2, 4, 5], [2, 4, 5, 6]],
            neighbors: vec![[1, -1, -1, -1], [-1, -1, -1, 0]],
            hull_faces: vec![[1, 2, 4]],
            num_tet_attrs: 1,
            tet_attrs: vec![1.0, 2.0],
            subfaces: vec![([1, 2, 4], 5)],
            subsegments: vec![([2, 6], 6)],
            plc_mode: true,
            first_index: 1,
            ..Default::default()
        }
    }

    #[test]
    fn unused_nodes_are_dropped_and_the_rest_renumbered_in_order() {
        let m = with_unused();
        let j = m.jettisoned().expect("three nodes are unused");
        let p = |x: f64| [x, x * x, 1.0 - x];
        assert_eq!(j.points, vec![p(0.0), p(1.0), p(2.0), p(3.0), p(4.0)]);
        assert_eq!(j.point_attrs, vec![0.0, 10.0, 20.0, 30.0, 40.0]);
        assert_eq!(j.point_markers, Some(vec![0, 1, 2, 3, 4]));
        assert_eq!(j.tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
        assert_eq!(j.hull_faces, vec![[0, 1, 2]]);
        assert_eq!(j.subfaces, vec![([0, 1, 2], 5)]);
        assert_eq!(j.subsegments, vec![([1, 4], 6)]);
        assert_eq!(j.neighbors, m.neighbors);
        assert_eq!(j.tet_attrs, m.tet_attrs);
        assert_eq!((j.first_index, j.plc_mode), (1, true));
    }

    #[test]
    fn a_mesh_that_uses_every_node_is_left_alone() {
        let mut m = with_unused();
        m.points.truncate(7);
        m.tets.push([0, 3, 2, 4]);
        assert!(m.jettisoned().is_none());
        m.tets.clear();
        assert!(m.jettisoned().is_none());
    }

    #[test]
    fn the_written_mesh_keeps_unused_nodes_only_with_keep_unused() {
        let m = with_unused();
        assert!(m.written(true).is_none());
        let (w, j) = (m.written(false).unwrap(), m.jettisoned().unwrap());
        assert_eq!((w.points, w.tets), (j.points, j.tets));
    }

    #[test]
    fn a_node_out_of_range_leaves_the_mesh_alone() {
        let mut m = with_unused();
        m.tets.push([0, 1, 2, 99]);
        assert!(m.jettisoned().is_none());
    }
}
