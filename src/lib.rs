//! tetcdt: constrained Delaunay tetrahedralizations of piecewise linear complexes,
//! with exact predicates and TetGen-compatible files.
//!
//! Data flows one way: [`io`] reads a [`plc::Plc`], [`delaunay`] builds the canonical
//! Delaunay tetrahedralization in a [`mesh::Mesh`], and [`io::write`] writes the
//! resulting [`output::MeshOut`]. [`check`] validates a mesh independently.
//!
//! [`live::Cdt`] keeps a PLC's CDT live: vertices go in one at a time, on segments and
//! facets or anywhere inside, and polygons as new facets, each insertion leaving a CDT
//! that [`live::Cdt::certify`] checks (see `examples/incremental.rs`):
//!
//! ```
//! use tetcdt::live::Cdt;
//! let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples/cube.poly");
//! let plc = tetcdt::io::read_plc(&path).unwrap();
//! let mut cdt = Cdt::build(&plc, &Default::default()).unwrap();
//! let on_edge = cdt.insert_vertex([0.5, 0.0, 0.0]).unwrap();
//! assert!(on_edge.new);
//! cdt.certify().unwrap();
//! let square = [[0.2, 0.2, 0.5], [0.8, 0.2, 0.5], [0.8, 0.8, 0.5], [0.2, 0.8, 0.5]];
//! let inside = cdt.insert_polygon(&square, 3).unwrap();
//! assert!(inside.subfaces >= 2);
//! cdt.certify().unwrap();
//! let mesh = cdt.mesh().unwrap();
//! assert!(mesh.subfaces.iter().any(|&(_, marker)| marker == 3));
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod carve;
pub mod check;
pub mod constrained;
pub mod delaunay;
pub mod error;
pub mod geom;
pub mod io;
pub mod live;
pub mod mesh;
pub mod options;
pub mod output;
pub mod plc;
pub mod precheck;
pub mod progress;

pub use error::{Error, InputError, MeshError};
pub use options::Options;
pub use output::MeshOut;
pub use plc::Plc;
pub mod stats;

pub use stats::Stats;

/// The result of a meshing run: the mesh, its statistics and any warnings for the user.
#[derive(Clone, Debug, Default)]
pub struct Meshed {
    /// The finished mesh.
    pub mesh: MeshOut,
    /// Counts and timings.
    pub stats: Stats,
    /// Warnings to show the user (duplicate points and the like), one per line.
    pub warnings: Vec<String>,
}

/// Meshes a model: the Delaunay tetrahedralization of its points (and, with `-p`, its CDT).
pub fn tetrahedralize(plc: &Plc, opts: &Options) -> Result<Meshed, Error> {
    pipeline::run(plc, opts, &progress::no_progress)
}

/// Like [`tetrahedralize`], telling `progress` when each stage begins.
pub fn tetrahedralize_with_progress(
    plc: &Plc,
    opts: &Options,
    progress: progress::Progress<'_>,
) -> Result<Meshed, Error> {
    pipeline::run(plc, opts, progress)
}

pub mod pipeline;

/// The number of cores this process may use, read once: each reading costs a dozen
/// system calls (cgroup files), a noticeable share of a small model's run.
pub fn cores() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}
