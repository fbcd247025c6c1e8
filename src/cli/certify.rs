//! `--certify PREFIX INPUT`: whether the mesh in `PREFIX.node` and `PREFIX.ele` (ours,
//! TetGen's or any other mesher's) is a CDT of the PLC in INPUT, by the library's
//! certifier.

use crate::Failure;
use anyhow::anyhow;
use std::path::Path;
use tetcdt::check::{certify, CertifyError, CertifyOptions, MeshView};
use tetcdt::error::{EXIT_MESH_FAILED, EXIT_OK};
use tetcdt::io::write::{output_path, FileKind};
use tetcdt::options::Options;

/// Certifies the mesh `prefix` against `input`; prints the verdict (unless quiet).
pub fn run(prefix: &Path, input: &Path, opts: &Options) -> Result<i32, Failure> {
    let plc = tetcdt::io::read_plc(input).map_err(tetcdt::Error::from)?;
    let plc = if opts.plc || !plc.facets.is_empty() {
        tetcdt::precheck::check(&plc).map_err(tetcdt::Error::from)?;
        plc
    } else {
        plc
    };
    let nodes = tetcdt::io::node::read(&output_path(prefix, FileKind::Node))
        .map_err(tetcdt::Error::from)?;
    let tets = tetcdt::io::ele::read(
        &output_path(prefix, FileKind::Ele),
        nodes.first_index,
        nodes.points.len(),
    )
    .map_err(tetcdt::Error::from)?;
    let copts = CertifyOptions::of(opts);
    let view = MeshView {
        points: &nodes.points,
        tets: &tets,
        first_index: nodes.first_index,
    };
    let what = if plc.facets.is_empty() {
        "the Delaunay tetrahedralization of the points of"
    } else {
        "a CDT of"
    };
    match certify(&plc, view, &copts) {
        Ok(c) => {
            if !opts.quiet {
                println!(
                    "{} is {what} {}: {} tets, {} Steiner points, {} faces on facets, {} edges on segments.",
                    prefix.display(),
                    input.display(),
                    c.tets,
                    c.steiner_points,
                    c.subfaces,
                    c.subsegments
                );
            }
            Ok(EXIT_OK)
        }
        Err(CertifyError::Input(e)) => Err(tetcdt::Error::from(e).into()),
        Err(CertifyError::Failed(problems)) => {
            let mut msg = format!(
                "{} is not {what} {}: {} problem(s):",
                prefix.display(),
                input.display(),
                problems.total
            );
            for p in problems.to_string().lines() {
                msg.push_str("\n  ");
                msg.push_str(p);
            }
            Err(Failure::new(EXIT_MESH_FAILED, anyhow!(msg)))
        }
    }
}
