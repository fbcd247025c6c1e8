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

    /// `e + f` (`e − f` if `negate`): the components of both merged by increasing
    /// magnitude, then summed from the smallest with exact two-sums, each roundoff left
    /// behind as a component (Shewchuk's fast expansion sum, zeros eliminated). Linear
    /// in the lengths, where adding one component at a time was quadratic.
    fn sum(e: &[f64], f: &[f64], negate: bool) -> Expansion {
        let sf = if negate { -1.0 } else { 1.0 };
        let mut out = Vec::with_capacity(e.len() + f.len());
        let (mut i, mut j) = (0, 0);
        let mut next = || -> Option<f64> {
            let g = match (e.get(i), f.get(j)) {
                (Some(&x), Some(&y)) if x.abs() <= y.abs() => {
                    i += 1;
                    x
                }
                (_, Some(&y)) => {
                    j += 1;
                    sf * y
                }
                (Some(&x), None) => {
                    i += 1;
                    x
                }
                (None, None) => return None,
            };
            Some(g)
        };
        let Some(mut q) = next() else {
            return Expansion(out);
        };
        while let Some(g) = next() {
            let (s, h) = two_sum(q, g);
            if h != 0.0 {
                out.push(h);
            }
            q = s;
        }
        if q != 0.0 {
            out.push(q);
        }
        Expansion(out)
    }

    /// `self + other`.
    pub fn add(&self, other: &Expansion) -> Expansion {
        Self::sum(&self.0, &other.0, false)
    }

    /// `self - other`.
    pub fn sub(&self, other: &Expansion) -> Expansion {
        Self::sum(&self.0, &other.0, true)
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

    /// `self * other`: the partial products (one per component of the shorter factor)
    /// summed pairwise, then compressed. Summing them one after another made the running
    /// sum, and so the cost, grow with every term; without compression a product of
    /// factors of very different scales kept every roundoff as a component, and degree-11
    /// comparisons of coordinates 1e19 apart ran to thousands of components.
    pub fn mul(&self, other: &Expansion) -> Expansion {
        let (small, big) = if self.0.len() < other.0.len() {
            (self, other)
        } else {
            (other, self)
        };
        let mut terms: Vec<Expansion> = small.0.iter().map(|&x| big.scale(x)).collect();
        while terms.len() > 1 {
            let mut next = Vec::with_capacity(terms.len().div_ceil(2));
            let mut it = terms.into_iter();
            while let Some(a) = it.next() {
                next.push(match it.next() {
                    Some(b) => a.add(&b),
                    None => a,
                });
            }
            terms = next;
        }
        terms.pop().unwrap_or_default().compress()
    }

    /// The same value in as few components as two sweeps of exact two-sums find
    /// (Shewchuk's compression): a downward sweep gathers each run of components that
    /// fit in one double, an upward one renormalizes what is left.
    pub fn compress(self) -> Expansion {
        let mut e = self.0;
        let Some(&top) = e.last() else {
            return Expansion(e);
        };
        let n = e.len();
        let mut q = top;
        let mut bottom = n - 1;
        for k in (0..n - 1).rev() {
            let (s, r) = fast_two_sum(q, e[k]);
            if r != 0.0 {
                e[bottom] = s;
                bottom -= 1;
                q = r;
            } else {
                q = s;
            }
        }
        let mut out = Vec::with_capacity(n - bottom);
        for &g in &e[bottom + 1..] {
            let (s, r) = fast_two_sum(g, q);
            if r != 0.0 {
                out.push(r);
            }
            q = s;
        }
        if q != 0.0 {
            out.push(q);
        }
        Expansion(out)
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

    /// The exact value of an expansion whose components are integer multiples of
    /// 2^-40 below 2^40 in magnitude, as an integer count of 2^-40 (fits in i128).
    fn fixed(e: &Expansion) -> i128 {
        e.components()
            .iter()
            .map(|&c| {
                let n = c * 2f64.powi(40);
                assert_eq!(n.fract(), 0.0, "component {c} off the 2^-40 grid");
                n as i128
            })
            .sum()
    }

    /// Components strictly increasing in magnitude, nonzero, and each smaller than the
    /// next one's unit in the last place: what `sign` relies on.
    fn nonoverlapping(e: &Expansion) -> bool {
        e.components().windows(2).all(|w| {
            let (a, b) = (w[0].abs(), w[1].abs());
            a != 0.0 && a < b && a <= 2f64.powi(b.log2().floor() as i32 - 52)
        }) && e.components().iter().all(|&c| c != 0.0)
    }

    #[test]
    fn merged_sums_and_products_match_integer_arithmetic() {
        let mut seed = 7u64;
        // Dyadic numbers of mixed scales, so that components cancel and interleave.
        let num = |seed: &mut u64| {
            let m = (crate::geom::lcg(seed) * 2f64.powi(20)).floor();
            let e = (crate::geom::lcg(seed) * 30.0).floor() as i32 - 20;
            let s = if crate::geom::lcg(seed) < 0.5 {
                -1.0
            } else {
                1.0
            };
            s * m * 2f64.powi(e)
        };
        for _ in 0..2000 {
            let (a, b, c, d) = (
                num(&mut seed),
                num(&mut seed),
                num(&mut seed),
                num(&mut seed),
            );
            let x = Expansion::diff(a, b).add(&Expansion::from_f64(c));
            let y = Expansion::diff(c, d).sub(&Expansion::diff(a, d));
            let (fx, fy) = (fixed(&x), fixed(&y));
            for (e, want) in [(x.add(&y), fx + fy), (x.sub(&y), fx - fy), (y.sub(&y), 0)] {
                assert!(nonoverlapping(&e), "{e:?}");
                assert_eq!(fixed(&e), want);
                assert_eq!(e.sign(), want.signum() as i32);
                let c = e.clone().compress();
                assert!(nonoverlapping(&c), "{c:?}");
                assert!(c.components().len() <= e.components().len());
                assert_eq!(fixed(&c), want);
            }
            // Products leave the 2^-40 grid: compare at a scale where they stay on it.
            let k = 2f64.powi(-20);
            let xs = x.scale(k);
            let p = xs.mul(&y.scale(k));
            assert!(nonoverlapping(&p), "{p:?}");
            assert_eq!(p.sign(), (fx.signum() * fy.signum()) as i32);
            assert_eq!(p.sub(&y.scale(k).mul(&xs)).sign(), 0);
        }
    }

    /// The 11th power of a value whose two parts are 2^66 apart in scale stays short (219
    /// components when every roundoff was kept).
    #[test]
    fn products_of_spread_out_values_stay_short() {
        let x = Expansion::diff(1.8e19, 0.29389262614623657);
        let mut p = Expansion::from_f64(1.0);
        for _ in 0..11 {
            p = p.mul(&x);
        }
        assert!(
            p.components().len() <= 40,
            "{} components",
            p.components().len()
        );
        // x^11 multiplied in the other order is exactly the same number.
        let mut q = x.clone();
        for _ in 0..10 {
            q = x.mul(&q);
        }
        assert_eq!(p.sub(&q).sign(), 0);
        assert!(nonoverlapping(&p), "{p:?}");
    }
}
