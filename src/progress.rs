//! Stages of a run, reported to an optional progress callback.
//!
//! The library only says which stage begins; drawing (progress bars, logs) is the
//! caller's business. Callers that want nothing use [`tetrahedralize`](crate::tetrahedralize),
//! which passes [`no_progress`].

use std::fmt;

/// A stage of a meshing run, in the order a run goes through them. The library reports
/// `Delaunay` to `Carve`; readers and writers are driven by the caller, which reports
/// `Read` and `Write` itself. A restart of `-p` meshing reports `Delaunay` again.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    /// Reading the input file.
    Read,
    /// Building the Delaunay tetrahedralization of the vertices.
    Delaunay,
    /// Recovering the segments (`-p`).
    Segments,
    /// Recovering the facets (`-p`).
    Facets,
    /// Quality refinement (`-q`, `-a`).
    Refine,
    /// Removing the exterior and the holes (`-p`).
    Carve,
    /// Writing the output files.
    Write,
}

impl Stage {
    /// The stage's name as shown to users.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Read => "read",
            Stage::Delaunay => "Delaunay",
            Stage::Segments => "segments",
            Stage::Facets => "facets",
            Stage::Refine => "refine",
            Stage::Carve => "carve",
            Stage::Write => "write",
        }
    }
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The callback told when a stage begins. It runs on the meshing thread, between the
/// stages, so it must be cheap.
pub type Progress<'a> = &'a dyn Fn(Stage);

/// The callback that ignores every stage.
pub fn no_progress(_: Stage) {}
