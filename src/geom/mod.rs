//! Geometry: exact predicates with symbolic perturbation, and the Hilbert/BRIO ordering.

pub mod expansion;
pub mod hilbert;
pub mod lifted;
pub mod predicates;

pub use predicates::{insphere, insphere_sos, orient3d, Point, Sign, StaticFilter};

/// The smallest box holding `points`, as `[lo, hi]` (an empty box for no points).
pub fn bounding_box(points: &[Point]) -> [Point; 2] {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    [lo, hi]
}
