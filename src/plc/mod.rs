//! The piecewise linear complex (PLC) model that every reader produces, and its
//! preparation for meshing and certifying ([`prepare`]: merged facets and segments).

pub mod prepare;

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

impl Plc {
    /// Returns a PLC with only the given points, numbered from `first_index`.
    pub fn from_points(points: Vec<[f64; 3]>, first_index: usize) -> Self {
        Plc {
            points,
            first_index,
            ..Default::default()
        }
    }
}
