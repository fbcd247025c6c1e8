//! Geometry: exact predicates with symbolic perturbation, and the Hilbert/BRIO ordering.

pub mod hilbert;
pub mod predicates;

pub use predicates::{insphere, insphere_sos, orient3d, Point, Sign, StaticFilter};
