//! The meshing pipeline: read model → Delaunay → (segments → facets → carve) → output.

use crate::delaunay::Delaunay;
use crate::error::{Error, MeshError};
use crate::options::Options;
use crate::output::MeshOut;
use crate::plc::Plc;
use crate::stats::Stats;
use crate::Meshed;
use std::time::Instant;

/// Runs the pipeline on `plc` as `opts` asks.
pub fn run(plc: &Plc, opts: &Options) -> Result<Meshed, Error> {
    if opts.plc {
        return Err(
            MeshError::Unsupported("PLC meshing (-p) is not implemented yet".into()).into(),
        );
    }
    let start = Instant::now();
    let mut stats = Stats {
        input_points: plc.points.len(),
        ..Default::default()
    };
    let built = Delaunay::build(&plc.points)?;
    stats.delaunay_secs = start.elapsed().as_secs_f64();
    let mut warnings = Vec::new();
    let base = plc.first_index;
    for &(dup, kept) in &built.duplicates {
        warnings.push(format!(
            "point {} is a duplicate of point {} and was skipped",
            dup as usize + base,
            kept as usize + base
        ));
    }
    stats.duplicate_points = built.duplicates.len();
    let (tets, neighbors) = built.dt.export();
    stats.output_tets = tets.len();
    stats.hull_faces = neighbors.iter().flatten().filter(|&&n| n < 0).count();
    let mesh = MeshOut {
        points: plc.points.clone(),
        num_point_attrs: plc.num_point_attrs,
        point_attrs: plc.point_attrs.clone(),
        point_markers: plc.point_markers.clone(),
        tets,
        neighbors,
        first_index: plc.first_index,
        ..Default::default()
    };
    stats.total_secs = start.elapsed().as_secs_f64();
    Ok(Meshed {
        mesh,
        stats,
        warnings,
    })
}
