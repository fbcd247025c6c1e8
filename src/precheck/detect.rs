//! TetGen's `-d`: detect intersecting facets, report them, and write the input points and
//! the intersecting triangles (`<prefix>.node`, `<prefix>.face`), without meshing. As in
//! TetGen, nothing is written when no facets intersect, and both cases exit with 0.

use super::{
    check_elements, intersection_line, intersections, segment_line, stray_line, Intersection,
    SegmentHit, StrayVertex,
};
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
    /// Segments meeting facets.
    pub segments: Vec<SegmentHit>,
    /// Points lying on facets that do not list them.
    pub strays: Vec<StrayVertex>,
    /// Warnings (facets that could not be checked).
    pub warnings: Vec<String>,
}

impl Detected {
    /// The report, one line per pair, as printed by `-d`.
    pub fn report(&self, plc: &Plc) -> Vec<String> {
        let mut lines: Vec<String> = self
            .found
            .iter()
            .map(|x| format!("  {}", intersection_line(plc, x)))
            .chain(
                self.segments
                    .iter()
                    .map(|h| format!("  {}", segment_line(plc, h))),
            )
            .chain(
                self.strays
                    .iter()
                    .map(|s| format!("  {}", stray_line(plc, s))),
            )
            .collect();
        if self.found.is_empty() {
            lines.push("No faces are intersecting.".into());
        } else {
            lines.push(format!(
                "Found {} pair(s) of intersecting facets.",
                self.found.len()
            ));
        }
        if !self.segments.is_empty() {
            lines.push(format!(
                "Found {} segment(s) meeting facets.",
                self.segments.len()
            ));
        }
        if !self.strays.is_empty() {
            lines.push(format!(
                "Found {} point(s) on facets that do not list them.",
                self.strays.len()
            ));
        }
        lines
    }
}

/// Runs the detection; the element checks (ranges, finiteness, repeated or collinear
/// vertices) still fail with an error, since those facets cannot be tested.
pub fn detect(plc: &Plc) -> Result<Detected, InputError> {
    let rep = check_elements(plc)?;
    let mut warnings = Vec::new();
    let f = intersections(plc, &rep, &mut warnings);
    Ok(Detected {
        found: f.pairs,
        segments: f.segments,
        strays: f.strays,
        warnings,
    })
}

/// The intersecting triangles (and those with stray points), once each, by facet, with
/// their facet markers.
pub fn faces_of(plc: &Plc, d: &Detected) -> Vec<([u32; 3], i32)> {
    let mut faces: Vec<(usize, [u32; 3])> = d
        .found
        .iter()
        .flat_map(|x| [(x.facets[0], x.tris[0]), (x.facets[1], x.tris[1])])
        .chain(d.segments.iter().map(|h| (h.facet, h.tri)))
        .chain(d.strays.iter().map(|s| (s.facet, s.tri)))
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
/// Writes nothing when nothing was found. Returns the paths written.
pub fn write(
    plc: &Plc,
    d: &Detected,
    prefix: &Path,
    w: &WriteOptions,
    on_file: &mut dyn FnMut(&Path),
) -> Result<Vec<PathBuf>, Error> {
    if d.found.is_empty() && d.segments.is_empty() && d.strays.is_empty() {
        return Ok(Vec::new());
    }
    let mesh = MeshOut {
        points: plc.points.clone(),
        num_point_attrs: plc.num_point_attrs,
        point_attrs: plc.point_attrs.clone(),
        point_markers: plc.point_markers.clone(),
        subfaces: faces_of(plc, d),
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
