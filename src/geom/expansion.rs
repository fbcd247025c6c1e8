//! Exact arithmetic on floating-point expansions (Shewchuk, "Adaptive precision
//! floating-point arithmetic"): a number is the exact sum of nonoverlapping doubles.
//!
//! Used where a sign must be exact but no adaptive predicate exists: the flip times of
//! facet insertion by flips are quotients of degree-5 and degree-6 polynomials, and
//! comparing two of them needs the sign of a degree-11 polynomial. Every operation is
//! exact as long as no intermediate product underflows or overflows, which holds for
//! coordinates within about 1e±25 of each other's scale (the callers filter first, so this
//! runs only on near-ties).

/// An exact sum of doubles, stored in increasing magnitude, without zeros.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Expansion(Vec<f64>);

/// `a + b` as an exact pair (sum, roundoff).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    let bv = x - a;
    let av = x - bv;
    (x, (a - av) + (b - bv))
}

/// `a + b` as an exact pair, given `|a| >= |b|`.
#[inline(always)]
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let x = a + b;
    (x, b - (x - a))
}

/// `a * b` as an exact pair (product, roundoff), using a fused multiply-add.
#[inline(always)]
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let x = a * b;
    (x, a.mul_add(b, -x))
}

impl Expansion {
    /// Zero.
    pub fn zero() -> Self {
        Expansion(Vec::new())
    }

    /// The double `x`, exactly.
    pub fn from_f64(x: f64) -> Self {
        if x == 0.0 {
            Expansion(Vec::new())
        } else {
            Expansion(vec![x])
        }
    }

    /// `a - b`, exactly.
    pub fn diff(a: f64, b: f64) -> Self {
        let (x, y) = two_sum(a, -b);
        Expansion([y, x].into_iter().filter(|&c| c != 0.0).collect())
    }

    /// The components, smallest first.
    pub fn components(&self) -> &[f64] {
        &self.0
    }

    /// The sign: -1, 0 or 1 (the largest component decides).
    pub fn sign(&self) -> i32 {
        match self.0.last() {
            Some(&x) if x > 0.0 => 1,
            Some(&x) if x < 0.0 => -1,
            _ => 0,
        }
    }

    /// An approximation of the value.
    pub fn estimate(&self) -> f64 {
        self.0.iter().sum()
    }

    /// `-self`.
    pub fn neg(&self) -> Self {
        Expansion(self.0.iter().map(|x| -x).collect())
    }

    /// `self + b` for one double (Shewchuk's grow-expansion, eliminating zeros).
    fn grow_into(e: &[f64], b: f64, out: &mut Vec<f64>) {
        out.clear();
        let mut q = b;
        for &x in e {
            let (s, h) = two_sum(q, x);
            if h != 0.0 {
                out.push(h);
            }
            q = s;
        }
        if q != 0.0 {
            out.push(q);
        }
    }

    /// `self + other`.
    pub fn add(&self, other: &Expansion) -> Expansion {
        let (small, big) = if self.0.len() < other.0.len() {
            (self, other)
        } else {
            (other, self)
        };
        let mut acc = big.0.clone();
        let mut tmp = Vec::with_capacity(acc.len() + small.0.len());
        for &x in &small.0 {
            Self::grow_into(&acc, x, &mut tmp);
            std::mem::swap(&mut acc, &mut tmp);
        }
        Expansion(acc)
    }

    /// `self - other`.
    pub fn sub(&self, other: &Expansion) -> Expansion {
        self.add(&other.neg())
    }

    /// `self * b` for one double (Shewchuk's scale-expansion, eliminating zeros).
    pub fn scale(&self, b: f64) -> Expansion {
        let e = &self.0;
        let mut out = Vec::with_capacity(2 * e.len());
        if e.is_empty() || b == 0.0 {
            return Expansion(out);
        }
        let (mut q, h) = two_product(e[0], b);
        if h != 0.0 {
            out.push(h);
        }
        for &x in &e[1..] {
            let (p1, p0) = two_product(x, b);
            let (s, h) = two_sum(q, p0);
            if h != 0.0 {
                out.push(h);
            }
            let (s2, h2) = fast_two_sum(p1, s);
            if h2 != 0.0 {
                out.push(h2);
            }
            q = s2;
        }
        if q != 0.0 {
            out.push(q);
        }
        Expansion(out)
    }

    /// `self * other`.
    pub fn mul(&self, other: &Expansion) -> Expansion {
        let (small, big) = if self.0.len() < other.0.len() {
            (self, other)
        } else {
            (other, self)
        };
        let mut acc = Expansion::zero();
        for &x in &small.0 {
            acc = acc.add(&big.scale(x));
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_and_products_are_exact() {
        let a = Expansion::from_f64(1.0);
        let tiny = Expansion::from_f64(1e-30);
        let s = a.add(&tiny).sub(&a);
        assert_eq!(s.sign(), 1);
        assert_eq!(s.estimate(), 1e-30);
        // (1 + 2^-60)^2 - 1 - 2^-59 = 2^-120, invisible to doubles.
        let x = Expansion::from_f64(1.0).add(&Expansion::from_f64(2f64.powi(-60)));
        let y = x
            .mul(&x)
            .sub(&Expansion::from_f64(1.0))
            .sub(&Expansion::from_f64(2f64.powi(-59)));
        assert_eq!(y.estimate(), 2f64.powi(-120));
        assert_eq!(Expansion::diff(0.1, 0.1).sign(), 0);
        assert_eq!(Expansion::diff(0.1, 0.3).neg().sign(), 1);
    }
}
