//! The piecewise linear complex (PLC) model that every reader produces, and its
//! preparation for meshing and certifying ([`prepare`]: merged facets and segments).

pub mod prepare;

use crate::geom::polygon::{clean_ring, representatives};
use std::path::PathBuf;

/// One facet: a set of polygons (possibly 1- or 2-vertex ones) lying in a common plane,
/// with optional hole points inside it and a boundary marker.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Facet {
    /// Polygons as lists of 0-based point indices. Polygons with one or two vertices
    /// are isolated vertices and segments floating in the facet.
    pub polygons: Vec<Vec<u32>>,
    /// Points that lie in holes of the facet.
    pub holes: Vec<[f64; 3]>,
    /// The facet's boundary marker (0 when the file gives none).
    pub marker: i32,
    /// The 1-based line of the input file where the facet is declared (0 if unknown).
    pub line: usize,
}

/// A region seed: a point inside a region, its attribute and its volume bound.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// A point strictly inside the region.
    pub point: [f64; 3],
    /// The regional attribute given to every tet of the region (with `-A`).
    pub attribute: f64,
    /// The maximum tet volume in the region, if given (negative means none).
    pub max_volume: f64,
}

/// A PLC as read from an input file: points, facets, holes and regions.
#[derive(Clone, Debug, Default)]
pub struct Plc {
    /// Point coordinates, in input order.
    pub points: Vec<[f64; 3]>,
    /// Number of attributes per point.
    pub num_point_attrs: usize,
    /// Point attributes, `num_point_attrs` per point, point-major.
    pub point_attrs: Vec<f64>,
    /// Point boundary markers, when the input has them.
    pub point_markers: Option<Vec<i32>>,
    /// Facets, in input order.
    pub facets: Vec<Facet>,
    /// Volume hole points.
    pub holes: Vec<[f64; 3]>,
    /// Region seeds.
    pub regions: Vec<Region>,
    /// Number of the first point in the input (0 or 1); output numbering follows it unless `-z`.
    pub first_index: usize,
    /// The file the model was read from (the `.node` file for a `.poly` with an empty node section is not recorded here).
    pub source: PathBuf,
    /// Warnings from reading it (such as the degenerate triangles of a surface mesh that
    /// were dropped), for the caller to show.
    pub warnings: Vec<String>,
}

/// How many offending elements a message lists before "and N more".
pub(crate) const SHOWN: usize = 5;

/// "; and N more" when a list was cut.
pub(crate) fn more(total: usize) -> String {
    if total > SHOWN {
        format!("; and {} more", total - SHOWN)
    } else {
        String::new()
    }
}

impl Plc {
    /// Returns a PLC with only the given points, numbered from `first_index`.
    pub fn from_points(points: Vec<[f64; 3]>, first_index: usize) -> Self {
        Plc {
            points,
            first_index,
            ..Default::default()
        }
    }

    /// A facet's name in messages: its number as in the file, and its line when known.
    pub fn facet_name(&self, fi: usize) -> String {
        match self.facets.get(fi).map(|f| f.line).unwrap_or(0) {
            0 => format!("facet {}", fi + self.first_index),
            line => format!("facet {} (line {line})", fi + self.first_index),
        }
    }

    /// Drops the polygons of a surface mesh that have fewer than three distinct corners once
    /// exactly equal points are welded (two corners at one point): they add nothing to the
    /// surface. One warning counts them and names the first few. Polygons with an index out
    /// of range are left for [`crate::precheck::check_elements`] to report.
    pub fn drop_degenerate_polygons(&mut self) {
        let rep = representatives(&self.points);
        let n = self.points.len();
        let mut dropped: Vec<usize> = Vec::new();
        for (fi, f) in self.facets.iter_mut().enumerate() {
            let before = f.polygons.len();
            f.polygons.retain(|poly| {
                poly.len() < 3
                    || poly.iter().any(|&v| v as usize >= n)
                    || clean_ring(poly, &rep).len() >= 3
            });
            if f.polygons.len() < before {
                dropped.push(fi);
            }
        }
        if dropped.is_empty() {
            return;
        }
        let list: Vec<String> = dropped
            .iter()
            .take(SHOWN)
            .map(|&fi| self.facet_name(fi))
            .collect();
        self.warnings.push(format!(
            "{} facet(s) with a repeated corner (two corners at the same point) add nothing to \
             the surface and were dropped: {}{}",
            dropped.len(),
            list.join(", "),
            more(dropped.len())
        ));
    }
}
