//! Constrained Delaunay tetrahedralization of a PLC: preparation of the PLC, segment
//! recovery with Steiner points, and facet insertion.

pub mod facet2d;
pub mod prepare;
pub mod segments;
