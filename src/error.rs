//! Typed errors of the library; `main.rs` maps them to exit codes.

use std::path::{Path, PathBuf};
use thiserror::Error;

/// A problem with an input file: it cannot be read, or its text is malformed.
#[derive(Debug, Error)]
pub enum InputError {
    /// The file could not be opened or read.
    #[error("{}: {source}", file.display())]
    Io {
        /// The file concerned.
        file: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The text of the file is malformed at a given line (1-based).
    #[error("{}:{line}: {msg}", file.display())]
    Parse {
        /// The file concerned.
        file: PathBuf,
        /// The 1-based line number, or 0 when the problem is the end of the file.
        line: usize,
        /// What is wrong, naming the element.
        msg: String,
    },
    /// The file parsed, but describes an invalid model (not tied to one line).
    #[error("{}: {msg}", file.display())]
    Invalid {
        /// The file concerned.
        file: PathBuf,
        /// What is wrong, naming the elements.
        msg: String,
    },
    /// The file's extension names no format we read.
    #[error("{}: unknown input format (expected .node, .poly, .smesh, .off, .obj, .stl, .ply or .mesh)", file.display())]
    UnknownFormat {
        /// The file concerned.
        file: PathBuf,
    },
}

impl InputError {
    /// Builds a parse error at `line` of `file`.
    pub fn parse(file: &Path, line: usize, msg: impl Into<String>) -> Self {
        InputError::Parse {
            file: file.to_path_buf(),
            line,
            msg: msg.into(),
        }
    }

    /// Builds an I/O error for `file`.
    pub fn io(file: &Path, source: std::io::Error) -> Self {
        InputError::Io {
            file: file.to_path_buf(),
            source,
        }
    }
}

/// A failure of the meshing algorithms on an input that parsed.
#[derive(Debug, Error)]
pub enum MeshError {
    /// All input points are coplanar, collinear or coincident: no tetrahedron exists.
    #[error("{0}")]
    Degenerate(String),
    /// The PLC is invalid in a way found while meshing (e.g. a vertex on a segment).
    #[error("invalid PLC: {0}")]
    InvalidPlc(String),
    /// Meshing could not finish (e.g. the Steiner point limit was reached).
    #[error("{0}")]
    Failed(String),
    /// The input asks for something the mesher cannot do.
    #[error("{0}")]
    Unsupported(String),
    /// An internal consistency check failed; this is a bug.
    #[error("internal error: {0}")]
    Internal(String),
    /// The finished mesh failed the certifier: it is not a CDT of the PLC, so no mesh is
    /// given (a bug, or a PLC the mesher does not handle).
    #[error("the mesh made is not a valid CDT of the PLC, so none is written: {}", .0.report())]
    NotCertified(crate::check::CheckFailure),
    /// A group of merged input facets (`sources`, 0-based) could not be triangulated in
    /// one plane: the group is too far from flat. The `-p` driver meshes it again with
    /// those facets kept apart; the error reaches the user only when they already were.
    #[error("facet {facet}: {reason}")]
    UnflatGroup {
        /// The input facets of the group.
        sources: Vec<usize>,
        /// The group's name for messages.
        facet: String,
        /// Why its triangulation failed.
        reason: String,
    },
    /// `-Y`: the CDT made has Steiner points on the PLC's segments or facets.
    #[error(
        "-Y: the boundary cannot be kept as given: recovering the segments and facets put \
         {points} Steiner point(s) on them, the first at ({}, {}, {}); without -Y they are \
         kept",
        first[0], first[1], first[2]
    )]
    BoundaryChanged {
        /// How many Steiner points lie on segments and facets.
        points: usize,
        /// The first of them (in node order).
        first: [f64; 3],
    },
    /// A construction passed its bound on work ([`crate::constrained::cdt::Cdt::work_limit`]):
    /// the restarts end as if it had finished over the bound.
    #[error("the construction passed its bound on work")]
    WorkBound,
}

/// Any error of the library.
#[derive(Debug, Error)]
pub enum Error {
    /// Bad input file.
    #[error(transparent)]
    Input(#[from] InputError),
    /// Meshing failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Writing an output file failed.
    #[error("{}: {source}", file.display())]
    Output {
        /// The file being written.
        file: PathBuf,
        /// The underlying I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// Exit code of a successful run.
pub const EXIT_OK: i32 = 0;
/// Exit code when meshing failed.
pub const EXIT_MESH_FAILED: i32 = 1;
/// Exit code of a usage error (bad or unimplemented switch).
pub const EXIT_USAGE: i32 = 2;
/// Exit code of an invalid input model.
pub const EXIT_INVALID_INPUT: i32 = 3;
/// Exit code of an I/O error.
pub const EXIT_IO: i32 = 4;

impl Error {
    /// The process exit code for this error, as documented in the README.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Input(InputError::Io { .. }) | Error::Output { .. } => EXIT_IO,
            Error::Input(_) => EXIT_INVALID_INPUT,
            Error::Mesh(MeshError::Degenerate(_) | MeshError::InvalidPlc(_)) => EXIT_INVALID_INPUT,
            Error::Mesh(_) => EXIT_MESH_FAILED,
        }
    }
}
