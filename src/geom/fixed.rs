//! Exact predicates in fixed-point integer arithmetic, for the tests the floating-point
//! filters cannot settle when the coordinates span few enough bits.
//!
//! CAD models put many vertices exactly on common spheres (the corners of boxes, points
//! on cylinders), so the insphere determinant is often exactly zero with coordinates whose
//! differences are not exact in floating point. The adaptive predicates then run their
//! costliest stage (full expansion arithmetic) every time. When all fifteen coordinates
//! are integer multiples of one power of two below 2^59 of it, the determinant is instead
//! computed exactly in 320-bit integers, several times faster.

use super::Point;
use std::ops::{Add, Mul, Sub};

/// Limbs of [`I320`].
const LIMBS: usize = 5;

/// A signed 320-bit integer, two's complement, little-endian 64-bit limbs. Arithmetic
/// wraps; callers keep every value far below 2^319 (see [`insphere`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct I320([u64; LIMBS]);

impl I320 {
    fn from_i128(x: i128) -> Self {
        let fill = if x < 0 { u64::MAX } else { 0 };
        let mut l = [fill; LIMBS];
        l[0] = x as u64;
        l[1] = (x >> 64) as u64;
        I320(l)
    }

    fn is_negative(&self) -> bool {
        (self.0[LIMBS - 1] as i64) < 0
    }

    fn neg(self) -> Self {
        let mut out = [0u64; LIMBS];
        let mut carry = 1u64;
        for (o, &x) in out.iter_mut().zip(&self.0) {
            let (s, c) = (!x).overflowing_add(carry);
            *o = s;
            carry = c as u64;
        }
        I320(out)
    }

    fn abs(self) -> Self {
        if self.is_negative() {
            self.neg()
        } else {
            self
        }
    }

    /// The nearest `f64` times `2^scale`, up to a few units in the last place, with the
    /// exact sign.
    fn to_f64_scaled(self, scale: i32) -> f64 {
        let negative = self.is_negative();
        let m = self.abs().0;
        let mut x = 0.0f64;
        for (i, &l) in m.iter().enumerate().rev() {
            x += l as f64 * super::pow2(64 * i as i32);
        }
        let y = times_pow2(x, scale);
        if negative {
            -y
        } else {
            y
        }
    }

    /// -1, 0 or 1.
    pub fn signum(&self) -> i32 {
        if self.is_negative() {
            -1
        } else if self.0.iter().any(|&x| x != 0) {
            1
        } else {
            0
        }
    }
}

impl Add for I320 {
    type Output = I320;
    fn add(self, o: I320) -> I320 {
        let mut out = [0u64; LIMBS];
        let mut carry = false;
        for ((r, &x), &y) in out.iter_mut().zip(&self.0).zip(&o.0) {
            let (s1, c1) = x.overflowing_add(y);
            let (s2, c2) = s1.overflowing_add(carry as u64);
            *r = s2;
            carry = c1 || c2;
        }
        I320(out)
    }
}

impl Sub for I320 {
    type Output = I320;
    fn sub(self, o: I320) -> I320 {
        let mut out = [0u64; LIMBS];
        let mut borrow = false;
        for ((r, &x), &y) in out.iter_mut().zip(&self.0).zip(&o.0) {
            let (d1, b1) = x.overflowing_sub(y);
            let (d2, b2) = d1.overflowing_sub(borrow as u64);
            *r = d2;
            borrow = b1 || b2;
        }
        I320(out)
    }
}

impl Mul for I320 {
    type Output = I320;
    fn mul(self, o: I320) -> I320 {
        let negative = self.is_negative() != o.is_negative();
        let (a, b) = (self.abs().0, o.abs().0);
        // Magnitudes are small: skip the zero high limbs.
        let len = |x: &[u64; LIMBS]| x.iter().rposition(|&l| l != 0).map_or(0, |i| i + 1);
        let (la, lb) = (len(&a), len(&b));
        let mut out = [0u64; LIMBS];
        for i in 0..la {
            let mut carry = 0u128;
            for j in 0..lb.min(LIMBS - i) {
                let t = a[i] as u128 * b[j] as u128 + out[i + j] as u128 + carry;
                out[i + j] = t as u64;
                carry = t >> 64;
            }
            if i + lb < LIMBS {
                out[i + lb] = carry as u64;
            }
        }
        let r = I320(out);
        if negative {
            r.neg()
        } else {
            r
        }
    }
}

/// The largest number of bits, from the lowest set bit of any coordinate to the highest
/// of any, for which the fixed-point path applies: differences then stay below 2^60,
/// and the determinant below 2^308.
const SPAN_BITS: i32 = 58;

/// `x · 2^e`, in steps that keep each factor representable.
fn times_pow2(x: f64, e: i32) -> f64 {
    let (mut y, mut e) = (x, e);
    while e > 1000 {
        y *= super::pow2(1000);
        e -= 1000;
    }
    while e < -1000 {
        y *= super::pow2(-1000);
        e += 1000;
    }
    y * super::pow2(e)
}

/// The coordinates as integers in units of their common lowest set bit `2^lo`, with
/// `lo`, or `None` when they span more than [`SPAN_BITS`] bits or one is subnormal or
/// not finite.
fn to_integers<const N: usize>(p: [&Point; N]) -> Option<([[i64; 3]; N], i32)> {
    let (mut lo, mut hi) = (i32::MAX, i32::MIN);
    for x in p.iter().flat_map(|q| q.iter()) {
        if *x == 0.0 {
            continue;
        }
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i32;
        if exp == 0 || exp == 0x7ff {
            return None;
        }
        let mant = (bits & ((1u64 << 52) - 1)) | (1u64 << 52);
        lo = lo.min(exp - 1075 + mant.trailing_zeros() as i32);
        hi = hi.max(exp - 1023);
    }
    if lo == i32::MAX {
        return Some(([[0; 3]; N], 0));
    }
    if hi - lo > SPAN_BITS {
        return None;
    }
    // Scaling by a power of two is exact (no overflow: the result is below 2^59).
    Some((p.map(|q| q.map(|x| times_pow2(x, -lo) as i64)), lo))
}

/// Shewchuk's orientation determinant of `a, b, c, d` (positive when `d` lies below the
/// plane of `a, b, c` seen counterclockwise from above), exact in sign and accurate in
/// magnitude, or `None` when the coordinates do not fit the fixed-point path.
pub fn orient3d(a: &Point, b: &Point, c: &Point, d: &Point) -> Option<f64> {
    let ([a, b, c, d], lo) = to_integers([a, b, c, d])?;
    let row = |p: [i64; 3]| std::array::from_fn::<i128, 3, _>(|k| (p[k] - d[k]) as i128);
    let (a, b, c) = (row(a), row(b), row(c));
    // Differences below 2^60; 2x2 minors below 2^121 fit in i128.
    let big = I320::from_i128;
    let det = big(a[2]) * big(b[0] * c[1] - c[0] * b[1])
        + big(b[2]) * big(c[0] * a[1] - a[0] * c[1])
        + big(c[2]) * big(a[0] * b[1] - b[0] * a[1]);
    Some(det.to_f64_scaled(3 * lo))
}

/// The exact sign of Shewchuk's insphere determinant of `a, b, c, d, e` (positive when
/// `e` is inside the sphere of a tet that is positive in Shewchuk's orientation), or
/// `None` when the coordinates do not fit the fixed-point path.
pub fn insphere(a: &Point, b: &Point, c: &Point, d: &Point, e: &Point) -> Option<i32> {
    let ([a, b, c, d, e], _) = to_integers([a, b, c, d, e])?;
    let row = |p: [i64; 3]| std::array::from_fn::<i64, 3, _>(|k| p[k] - e[k]);
    let r = [row(a), row(b), row(c), row(d)];
    // 2x2 minors and lifts fit in i128 (below 2^122); the rest is done in I320.
    let m2 =
        |i: usize, j: usize| r[i][0] as i128 * r[j][1] as i128 - r[j][0] as i128 * r[i][1] as i128;
    let big = I320::from_i128;
    let z = |i: usize| big(r[i][2] as i128);
    let (ab, bc, cd, da, ac, bd) = (m2(0, 1), m2(1, 2), m2(2, 3), m2(3, 0), m2(0, 2), m2(1, 3));
    let abc = z(0) * big(bc) - z(1) * big(ac) + z(2) * big(ab);
    let bcd = z(1) * big(cd) - z(2) * big(bd) + z(3) * big(bc);
    let cda = z(2) * big(da) + z(3) * big(ac) + z(0) * big(cd);
    let dab = z(3) * big(ab) + z(0) * big(bd) + z(1) * big(da);
    let lift = |i: usize| big(r[i].iter().map(|&x| x as i128 * x as i128).sum::<i128>());
    let det = (lift(3) * abc - lift(2) * dab) + (lift(1) * cda - lift(0) * bcd);
    Some(det.signum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::lcg;

    fn sign(x: f64) -> i32 {
        (x > 0.0) as i32 - (x < 0.0) as i32
    }

    fn reference(p: &[Point; 5]) -> i32 {
        let c = |q: &Point| robust::Coord3D {
            x: q[0],
            y: q[1],
            z: q[2],
        };
        sign(robust::insphere(
            c(&p[0]),
            c(&p[1]),
            c(&p[2]),
            c(&p[3]),
            c(&p[4]),
        ))
    }

    #[test]
    fn i320_arithmetic_matches_i128() {
        let mut s = 3u64;
        for _ in 0..10_000 {
            let x = ((lcg(&mut s) - 0.5) * 2f64.powi(60)) as i128;
            let y = ((lcg(&mut s) - 0.5) * 2f64.powi(60)) as i128;
            let (a, b) = (I320::from_i128(x), I320::from_i128(y));
            assert_eq!(a * b, I320::from_i128(x * y));
            assert_eq!(a + b, I320::from_i128(x + y));
            assert_eq!(a - b, I320::from_i128(x - y));
            assert_eq!((a * b).signum(), (x * y).signum() as i32);
        }
        // Products beyond 128 bits: (2^100 + 1)^2 = 2^200 + 2^101 + 1, and its negative.
        let a = I320::from_i128((1i128 << 100) + 1);
        let mut want = [0u64; LIMBS];
        want[0] = 1;
        want[1] = 1 << 37;
        want[3] = 1 << 8;
        assert_eq!(a * a, I320(want));
        assert_eq!(a * a.neg(), I320(want).neg());
        assert_eq!((a * a.neg()).signum(), -1);
    }

    #[test]
    fn agrees_with_the_adaptive_insphere() {
        let mut s = 17u64;
        let (mut zeros, mut checked) = (0, 0);
        for round in 0..20_000 {
            // The corners of a box with arbitrary coordinates are exactly cospherical,
            // though their differences are not exact in floating point.
            let e0 = (round % 9) as i32 - 4;
            let coord = |s: &mut u64| (lcg(s) * 40.0 + 1.0) * 2f64.powi(e0);
            let x = [coord(&mut s), coord(&mut s)];
            let y = [coord(&mut s), coord(&mut s)];
            let z = [coord(&mut s), coord(&mut s)];
            let corner = |i: usize| [x[i & 1], y[(i >> 1) & 1], z[(i >> 2) & 1]];
            let mut pick: Vec<usize> = (0..8).collect();
            for i in (1..8).rev() {
                let j = ((lcg(&mut s) * (i + 1) as f64) as usize).min(i);
                pick.swap(i, j);
            }
            let mut p: [Point; 5] = std::array::from_fn(|i| corner(pick[i]));
            if round % 3 == 1 {
                // Off the sphere by one unit in the last place.
                p[4][round % 3] = f64::from_bits(p[4][round % 3].to_bits() + 1);
            } else if round % 3 == 2 {
                p[4] = [coord(&mut s), coord(&mut s), coord(&mut s)];
            }
            let want = reference(&p);
            if let Some(got) = insphere(&p[0], &p[1], &p[2], &p[3], &p[4]) {
                assert_eq!(got, want, "{p:?}");
                checked += 1;
                zeros += (want == 0) as usize;
            }
        }
        assert!(
            checked > 15_000 && zeros > 5_000,
            "{checked} checked, {zeros} zeros"
        );
    }

    #[test]
    fn orient3d_agrees_with_the_adaptive_one() {
        let mut s = 5u64;
        let mut zeros = 0;
        for round in 0..20_000 {
            let e0 = (round % 9) as i32 - 4;
            let coord = |s: &mut u64| (lcg(s) * 40.0 + 1.0) * 2f64.powi(e0);
            let mut p: [Point; 4] =
                std::array::from_fn(|_| [coord(&mut s), coord(&mut s), coord(&mut s)]);
            if round % 2 == 0 {
                // Four corners of a box face: exactly coplanar, inexact differences.
                let k = round % 3;
                p[1][k] = p[0][k];
                p[2][k] = p[0][k];
                p[3][k] = p[0][k];
                if round % 4 == 0 {
                    p[3][k] = f64::from_bits(p[3][k].to_bits() + 1);
                }
            }
            let c = |q: &Point| robust::Coord3D {
                x: q[0],
                y: q[1],
                z: q[2],
            };
            let want = robust::orient3d(c(&p[0]), c(&p[1]), c(&p[2]), c(&p[3]));
            let got = orient3d(&p[0], &p[1], &p[2], &p[3]).expect("fits");
            assert_eq!(sign(got), sign(want), "{p:?}");
            zeros += (want == 0.0) as usize;
            // The adaptive predicate's value is itself only an estimate when it stops
            // early: the magnitudes agree loosely, the signs exactly.
            if want != 0.0 {
                assert!(((got - want) / want).abs() < 1e-6, "{got} vs {want}");
            }
        }
        assert!(zeros > 3000, "{zeros} coplanar cases");
    }

    #[test]
    fn wide_spans_are_left_to_the_adaptive_predicates() {
        let p = [
            [1e-10, 0.0, 0.0],
            [1e10, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.3; 3],
        ];
        assert_eq!(insphere(&p[0], &p[1], &p[2], &p[3], &p[4]), None);
        let z = [[0.0; 3]; 5];
        assert_eq!(insphere(&z[0], &z[1], &z[2], &z[3], &z[4]), Some(0));
    }
}
