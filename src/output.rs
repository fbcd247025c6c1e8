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
