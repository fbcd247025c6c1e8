//! Geometry: exact predicates with symbolic perturbation, and the Hilbert/BRIO ordering.

pub mod bvh;
pub mod encroach;
pub mod expansion;
pub mod facet2d;
pub mod fixed;
pub mod hilbert;
pub mod lifted;
pub mod polygon;
pub mod predicates;
pub mod quality;

pub use predicates::{insphere, insphere_sos, orient3d, Point, Sign, StaticFilter};

/// `a - b`.
#[inline]
pub fn sub(a: &Point, b: &Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The cross product `a × b`.
#[inline]
pub fn cross(a: &Point, b: &Point) -> Point {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// The dot product `a · b`.
#[inline]
pub fn dot(a: &Point, b: &Point) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `2^e`, exactly: built from its bits in the normal range, where `powi` would call a
/// runtime routine (hot in the fixed-point predicates); `powi` elsewhere.
#[inline]
pub fn pow2(e: i32) -> f64 {
    if (-1022..=1023).contains(&e) {
        f64::from_bits(((e + 1023) as u64) << 52)
    } else {
        2f64.powi(e)
    }
}

/// A deterministic pseudo-random number in [0, 1) (an LCG), for tests.
#[cfg(test)]
pub(crate) fn lcg(s: &mut u64) -> f64 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*s >> 11) as f64 / (1u64 << 53) as f64
}

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

/// The length of `v`.
pub fn norm(v: &Point) -> f64 {
    dot(v, v).sqrt()
}

/// The length of the diagonal of the points' bounding box, or 1 where it is zero (a
/// single point, or none): a scale for tolerances relative to the model.
pub fn diagonal(points: &[Point]) -> f64 {
    let [lo, hi] = bounding_box(points);
    let d = norm(&sub(&hi, &lo));
    if d > 0.0 {
        d
    } else {
        1.0
    }
}

/// The square of the tet's longest edge.
pub fn longest_edge2(p: &[Point; 4]) -> f64 {
    let mut l2 = 0.0f64;
    for i in 0..4 {
        for j in i + 1..4 {
            let e = sub(&p[i], &p[j]);
            l2 = l2.max(dot(&e, &e));
        }
    }
    l2
}

#[cfg(test)]
mod tests {
    #[test]
    fn pow2_is_powi_bit_for_bit() {
        for e in -1100..=1100 {
            assert_eq!(super::pow2(e).to_bits(), 2f64.powi(e).to_bits(), "2^{e}");
        }
    }
}
