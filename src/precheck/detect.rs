//! TetGen's `-d`: detect intersecting facets, report them, and write the input points and
//! the intersecting triangles (`<prefix>.node`, `<prefix>.face`), without meshing. As in
//! TetGen, nothing is written when no facets intersect, and both cases exit with 0.

use super::{check_elements, intersection_line, intersections, Intersection};
use crate::error::{Error, InputError};
use crate::io::write::{output_path, write_kind, FileKind, WriteOptions};
use crate::output::MeshOut;
use crate::plc::Plc;
use std::fs::{self, File};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// What `-d` found.
#[derive(Clone, Debug, Default)]
pub struct Detected {
    /// The intersecting pairs of facets.
    pub found: Vec<Intersection>,
    /// Warnings (facets that could not be checked).
    pub warnings: Vec<String>,
}

impl Detected {
    /// The report, one line per pair, as printed by `-d`.
    pub fn report(&self, plc: &Plc) -> Vec<String> {
        if self.found.is_empty() {
            return vec!["No faces are intersecting.".into()];
        }
        let mut lines: Vec<String> = self
            .found
            .iter()
            .map(|x| format!("  {}", intersection_line(plc, x)))
            .collect();
        lines.push(format!(
            "Found {} pair(s) of intersecting facets.",
            self.found.len()
        ));
        lines
    }
}

/// Runs the detection; the element checks (ranges, finiteness, repeated or collinear
/// vertices) still fail with an error, since those facets cannot be tested.
pub fn detect(plc: &Plc) -> Result<Detected, InputError> {
    let rep = check_elements(plc)?;
    let mut warnings = Vec::new();
    let found = intersections(plc, &rep, &mut warnings);
    Ok(Detected { found, warnings })
}

/// The intersecting triangles, once each, by facet, with their facet markers.
pub fn faces_of(plc: &Plc, found: &[Intersection]) -> Vec<([u32; 3], i32)> {
    let mut faces: Vec<(usize, [u32; 3])> = found
        .iter()
        .flat_map(|x| [(x.facets[0], x.tris[0]), (x.facets[1], x.tris[1])])
        .collect();
    faces.sort_unstable();
    faces.dedup();
    faces
        .into_iter()
        .map(|(f, t)| (t, plc.facets[f].marker))
        .collect()
}

/// Writes `<prefix>.node` (the input points) and `<prefix>.face` (the intersecting
/// triangles) atomically: both go to temporary names first and are renamed when complete.
/// Writes nothing when `found` is empty. Returns the paths written.
pub fn write(
    plc: &Plc,
    found: &[Intersection],
    prefix: &Path,
    w: &WriteOptions,
    on_file: &mut dyn FnMut(&Path),
) -> Result<Vec<PathBuf>, Error> {
    if found.is_empty() {
        return Ok(Vec::new());
    }
    let mesh = MeshOut {
        points: plc.points.clone(),
        num_point_attrs: plc.num_point_attrs,
        point_attrs: plc.point_attrs.clone(),
        point_markers: plc.point_markers.clone(),
        subfaces: faces_of(plc, found),
        plc_mode: true,
        first_index: plc.first_index,
        ..Default::default()
    };
    let kinds = [FileKind::Node, FileKind::Face];
    let mut temps: Vec<PathBuf> = Vec::new();
    let mut finals: Vec<PathBuf> = Vec::new();
    let result = (|| -> Result<(), Error> {
        for kind in kinds {
            let fin = output_path(prefix, kind);
            on_file(&fin);
            let mut name = std::ffi::OsString::from(".");
            name.push(fin.file_name().unwrap_or_default());
            name.push(format!(".tmp-{}", std::process::id()));
            let tmp = fin.with_file_name(name);
            temps.push(tmp.clone());
            let err = |source| Error::Output {
                file: fin.clone(),
                source,
            };
            let mut out = BufWriter::new(File::create(&tmp).map_err(err)?);
            write_kind(&mut out, kind, &mesh, w).map_err(err)?;
            out.flush().map_err(err)?;
            finals.push(fin);
        }
        for (tmp, fin) in temps.iter().zip(&finals) {
            fs::rename(tmp, fin).map_err(|source| Error::Output {
                file: fin.clone(),
                source,
            })?;
        }
        Ok(())
    })();
    if result.is_err() {
        for tmp in &temps {
            let _ = fs::remove_file(tmp);
        }
    }
    result.map(|()| finals)
}
