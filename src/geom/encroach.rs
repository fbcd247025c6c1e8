//! Exact tests of where a point lies against a segment or a triangle: on it, or inside
//! its diametral ball (the smallest ball through its ends), as Delaunay refinement's
//! encroachment needs them. Signs are exact (expansion arithmetic); only the split
//! points themselves are rounded.

use super::expansion::Expansion;
use super::{orient3d, Point};

/// `(p - a) · (q - b)`, exactly.
fn dot_diff(p: &Point, a: &Point, q: &Point, b: &Point) -> Expansion {
    (0..3).fold(Expansion::zero(), |acc, k| {
        acc.add(&Expansion::diff(p[k], a[k]).mul(&Expansion::diff(q[k], b[k])))
    })
}

/// True if `p` lies strictly inside the diametral ball of segment `a`–`b`: the angle
/// `a p b` is obtuse, `(a - p) · (b - p) < 0`.
pub fn in_diametral_ball(a: &Point, b: &Point, p: &Point) -> bool {
    // A floating-point filter first: the sum of three products of rounded differences
    // errs by less than 8 units in the last place of the sum of their magnitudes.
    let (mut s, mut perm) = (0.0f64, 0.0f64);
    for k in 0..3 {
        let t = (a[k] - p[k]) * (b[k] - p[k]);
        s += t;
        perm += t.abs();
    }
    if s.abs() > FILTER_2 * perm {
        return s < 0.0;
    }
    dot_diff(a, p, b, p).sign() < 0
}

/// The relative error bound of the filter of [`in_diametral_ball`]: 8 ulps.
const FILTER_2: f64 = 8.0 * f64::EPSILON;

/// The relative error bound of the filter of [`in_equatorial_ball`]: a degree-6
/// polynomial of rounded differences, about 40 rounded operations deep; 256 ulps covers
/// the error of every one of them.
const FILTER_6: f64 = 256.0 * f64::EPSILON;

/// True if `p` lies on segment `a`–`b`, strictly between its ends.
pub fn on_segment(a: &Point, b: &Point, p: &Point) -> bool {
    near_segment(a, b, p, 0.0)
}

/// True if `p` lies within distance `tol` of the line through `a` and `b` (exactly on it
/// when `tol` is 0) and strictly between the planes through its ends across it.
pub fn near_segment(a: &Point, b: &Point, p: &Point, tol: f64) -> bool {
    let proj = |x: &Point, i: usize, j: usize| [x[i], x[j]];
    let collinear = [(0, 1), (1, 2), (0, 2)]
        .iter()
        .all(|&(i, j)| robust_orient2d(proj(a, i, j), proj(b, i, j), proj(p, i, j)) == 0.0);
    let near = collinear || {
        let d = super::sub(b, a);
        let off = super::norm(&super::cross(&super::sub(p, a), &d));
        off <= tol * super::norm(&d)
    };
    near && dot_diff(p, a, b, a).sign() > 0 && dot_diff(p, b, a, b).sign() > 0
}

/// True if `p` lies in the plane of triangle `a b c` and strictly inside it.
pub fn on_triangle(a: &Point, b: &Point, c: &Point, p: &Point) -> bool {
    near_triangle(a, b, c, p, 0.0)
}

/// True if `p` lies within distance `tol` of the plane of triangle `a b c` (exactly in
/// it when `tol` is 0) and, seen along the plane's normal, strictly inside it.
pub fn near_triangle(a: &Point, b: &Point, c: &Point, p: &Point, tol: f64) -> bool {
    if orient3d(a, b, c, p) != 0.0 {
        let n = super::cross(&super::sub(b, a), &super::sub(c, a));
        let off = super::dot(&n, &super::sub(p, a)).abs();
        if off.is_nan() || off > tol * super::norm(&n) {
            return false;
        }
    }
    // The projection along the normal's largest component keeps the triangle's area.
    let proj =
        super::polygon::Projection::along(&super::cross(&super::sub(b, a), &super::sub(c, a)));
    let s = [
        proj.orient(a, b, p),
        proj.orient(b, c, p),
        proj.orient(c, a, p),
    ];
    s.iter().all(|&x| x > 0.0) || s.iter().all(|&x| x < 0.0)
}

/// True if `p` lies strictly inside the equatorial ball of triangle `a b c` (the
/// smallest ball through its corners, centred on its circumcentre). With `u = b - a`,
/// `v = c - a`, `n = u × v` and `q = p - a`, the circumcentre is
/// `a + (|u|² v × n + |v|² n × u) / (2|n|²)`, so `|p - o|² < r²` is
/// `|n|² |q|² < q · (|u|² v × n + |v|² n × u)`, a polynomial in exact differences.
pub fn in_equatorial_ball(a: &Point, b: &Point, c: &Point, p: &Point) -> bool {
    in_equatorial_ball_filtered(a, b, c, p).unwrap_or_else(|| in_equatorial_ball_exact(a, b, c, p))
}

/// [`in_equatorial_ball`] in expansion arithmetic.
fn in_equatorial_ball_exact(a: &Point, b: &Point, c: &Point, p: &Point) -> bool {
    let d = |x: &Point| -> [Expansion; 3] { std::array::from_fn(|k| Expansion::diff(x[k], a[k])) };
    let (u, v, q) = (d(b), d(c), d(p));
    let dot = |x: &[Expansion; 3], y: &[Expansion; 3]| {
        (0..3).fold(Expansion::zero(), |acc, k| acc.add(&x[k].mul(&y[k])))
    };
    let cross = |x: &[Expansion; 3], y: &[Expansion; 3]| -> [Expansion; 3] {
        std::array::from_fn(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            x[i].mul(&y[j]).sub(&x[j].mul(&y[i]))
        })
    };
    let n = cross(&u, &v);
    let (uu, vv) = (dot(&u, &u), dot(&v, &v));
    let lhs = dot(&n, &n).mul(&dot(&q, &q));
    let w1 = cross(&v, &n);
    let w2 = cross(&n, &u);
    let rhs = uu.mul(&dot(&q, &w1)).add(&vv.mul(&dot(&q, &w2)));
    lhs.sub(&rhs).sign() < 0
}

/// [`in_equatorial_ball`] in floating point, with the same polynomial evaluated on the
/// magnitudes as the error's scale: `None` where the rounded value may have the wrong
/// sign.
fn in_equatorial_ball_filtered(a: &Point, b: &Point, c: &Point, p: &Point) -> Option<bool> {
    let d = |x: &Point| -> Point { std::array::from_fn(|k| x[k] - a[k]) };
    let (u, v, q) = (d(b), d(c), d(p));
    let abs = |x: Point| x.map(f64::abs);
    let cross_abs = |x: &Point, y: &Point| -> Point {
        std::array::from_fn(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            (x[i] * y[j]).abs() + (x[j] * y[i]).abs()
        })
    };
    let n = super::cross(&u, &v);
    let na = cross_abs(&u, &v);
    let (uu, vv) = (super::dot(&u, &u), super::dot(&v, &v));
    let lhs = super::dot(&n, &n) * super::dot(&q, &q);
    let w1 = super::cross(&v, &n);
    let w2 = super::cross(&n, &u);
    let rhs = uu * super::dot(&q, &w1) + vv * super::dot(&q, &w2);
    let (ua, va, qa) = (abs(u), abs(v), abs(q));
    let perm = super::dot(&na, &na) * super::dot(&qa, &qa)
        + uu * super::dot(&qa, &cross_abs(&va, &na))
        + vv * super::dot(&qa, &cross_abs(&na, &ua));
    let diff = lhs - rhs;
    (diff.abs() > FILTER_6 * perm && perm.is_finite()).then_some(diff < 0.0)
}

/// The circumcentre of triangle `a b c` (rounded), in its plane; the centroid of a
/// triangle whose rounded normal vanishes. An inexact construction: it places points,
/// it never decides topology.
pub fn circumcenter(a: &Point, b: &Point, c: &Point) -> Point {
    let u = super::sub(b, a);
    let v = super::sub(c, a);
    let n = super::cross(&u, &v);
    let nn = super::dot(&n, &n);
    if nn == 0.0 {
        return std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0);
    }
    let w1 = super::cross(&v, &n);
    let w2 = super::cross(&n, &u);
    let (uu, vv) = (super::dot(&u, &u), super::dot(&v, &v));
    std::array::from_fn(|k| a[k] + (uu * w1[k] + vv * w2[k]) / (2.0 * nn))
}

fn robust_orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let c2 = |x: [f64; 2]| robust::Coord { x: x[0], y: x[1] };
    robust::orient2d(c2(a), c2(b), c2(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn diametral_balls_are_exact_at_their_boundary() {
        let (a, b) = ([0.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
        assert!(in_diametral_ball(&a, &b, &[1.0, 0.5, 0.3]));
        // On the sphere (a right angle at p) is not inside.
        assert!(!in_diametral_ball(&a, &b, &[1.0, 1.0, 0.0]));
        assert!(in_diametral_ball(&a, &b, &[1.0, 1.0 - 1e-16, 0.0]));
        assert!(!in_diametral_ball(&a, &b, &[3.0, 0.0, 0.0]));
    }

    #[test]
    fn points_on_segments_and_triangles_are_found_exactly() {
        let (a, b) = ([0.0, 0.0, 0.0], [3.0, 3.0, 3.0]);
        assert!(on_segment(&a, &b, &[1.0, 1.0, 1.0]));
        assert!(!on_segment(&a, &b, &[1.0, 1.0, 1.0 + 1e-15]));
        assert!(!on_segment(&a, &b, &[4.0, 4.0, 4.0]));
        assert!(!on_segment(&a, &b, &a));
        let c = [0.0, 3.0, 0.0];
        let (a, b) = ([0.0, 0.0, 0.0], [3.0, 0.0, 0.0]);
        assert!(on_triangle(&a, &b, &c, &[1.0, 1.0, 0.0]));
        assert!(!on_triangle(&a, &b, &c, &[1.0, 1.0, 1e-300]));
        assert!(!on_triangle(&a, &b, &c, &[1.5, 0.0, 0.0]));
        assert!(!on_triangle(&a, &b, &c, &[2.0, 2.0, 0.0]));
    }

    #[test]
    fn equatorial_balls_agree_with_the_circumcentre() {
        let (a, b, c) = ([0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [0.0, 4.0, 0.0]);
        let o = circumcenter(&a, &b, &c);
        assert_eq!(o, [2.0, 2.0, 0.0]);
        // Radius sqrt(8): (2, 2, 2.8) is inside, (2, 2, 2.9) outside.
        assert!(in_equatorial_ball(&a, &b, &c, &[2.0, 2.0, 2.8]));
        assert!(!in_equatorial_ball(&a, &b, &c, &[2.0, 2.0, 2.9]));
        // On the sphere: (4, 4, 0) is at distance sqrt(8) from o.
        assert!(!in_equatorial_ball(&a, &b, &c, &[4.0, 4.0, 0.0]));
        assert!(in_equatorial_ball(&a, &b, &c, &[4.0 - 1e-15, 4.0, 0.0]));
    }

    #[test]
    fn the_filters_agree_with_exact_arithmetic() {
        let mut seed = 7u64;
        let mut r = || crate::geom::lcg(&mut seed) * 2.0 - 1.0;
        for _ in 0..20_000 {
            let (a, b, c) = ([r(), r(), r()], [r(), r(), r()], [r(), r(), r()]);
            // Points near the balls' spheres too: on them, rounded.
            let o = circumcenter(&a, &b, &c);
            let rad = crate::geom::norm(&crate::geom::sub(&a, &o));
            let dir = [r(), r(), r()];
            let len = crate::geom::norm(&dir).max(1e-300);
            let s = 1.0 + 1e-15 * r();
            let p: Point = std::array::from_fn(|k| o[k] + dir[k] / len * rad * s);
            for q in [p, [r(), r(), r()]] {
                if let Some(x) = in_equatorial_ball_filtered(&a, &b, &c, &q) {
                    assert_eq!(
                        x,
                        in_equatorial_ball_exact(&a, &b, &c, &q),
                        "{a:?} {b:?} {c:?} {q:?}"
                    );
                }
                let m: Point = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
                let h = 0.5 * crate::geom::norm(&crate::geom::sub(&a, &b));
                let q2: Point = std::array::from_fn(|k| m[k] + dir[k] / len * h * s);
                assert_eq!(
                    in_diametral_ball(&a, &b, &q2),
                    dot_diff(&a, &q2, &b, &q2).sign() < 0
                );
            }
        }
    }
}
