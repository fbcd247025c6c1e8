//! Readers of TetGen's input formats and writers of its output files.

pub mod ele;
pub mod medit;
pub mod node;
pub mod obj;
pub mod off;
pub mod ply;
pub mod poly;
pub mod smesh;
pub mod stl;
pub mod token_stream;
pub mod tokens;
pub mod write;
pub mod write_extra;

use crate::error::InputError;
use crate::plc::Plc;
use std::path::Path;

/// Reads a model, choosing the reader by the file's extension.
pub fn read_plc(path: &Path) -> Result<Plc, InputError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    // Surface meshes (triangle soups from CAD and scanning tools) often hold triangles
    // that exact welding collapses; those add nothing to the surface and are dropped.
    let surface = |plc: Result<Plc, InputError>| {
        plc.map(|mut p| {
            p.drop_degenerate_polygons();
            p
        })
    };
    match ext.as_str() {
        "node" => node::read(path),
        "poly" => poly::read(path),
        "smesh" => smesh::read(path),
        "off" => surface(off::read(path)),
        "obj" => surface(obj::read(path)),
        "stl" => surface(stl::read(path)),
        "ply" => surface(ply::read(path)),
        "mesh" => surface(medit::read(path)),
        "meshb" => Err(InputError::Invalid {
            file: path.to_path_buf(),
            msg: "binary Medit files (.meshb) are not supported; convert to ASCII .mesh".into(),
        }),
        _ => Err(InputError::UnknownFormat {
            file: path.to_path_buf(),
        }),
    }
}
