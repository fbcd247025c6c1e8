//! Figures about one meshing run, printed under `-V` and later written as JSON.

/// Counts and timings of one run.
#[derive(Clone, Debug, Default)]
pub struct Stats {
    /// Number of input points.
    pub input_points: usize,
    /// Input points skipped because they coincide with an earlier one.
    pub duplicate_points: usize,
    /// Number of tets in the output.
    pub output_tets: usize,
    /// Number of hull faces of the output.
    pub hull_faces: usize,
    /// Seconds spent sorting the points (BRIO and Hilbert order).
    pub sort_secs: f64,
    /// Seconds spent building the Delaunay tetrahedralization (including sorting).
    pub delaunay_secs: f64,
    /// Seconds of the whole meshing call.
    pub total_secs: f64,
    /// The figures of PLC meshing (`-p`), the rows of the paper's Table 1.
    pub plc: Option<crate::constrained::PlcStats>,
}
