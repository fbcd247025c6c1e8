//! Flip times of facet insertion by flips (paper §3.2), computed and compared exactly.
//!
//! Two tets `t1 = (x, y, z, v)` (positively oriented) and `t2` sharing the face `xyz`,
//! with apex `w`, are locally regular while `D(τ) = I + τ·J` is negative, where `I` is
//! [`insphere`](super::insphere)`(x, y, z, v, w)` and `J` is the same determinant with the
//! lift replaced by the vertices' heights above the polygon's plane (left vertices only).
//! The face flips at `τ = -I/J` if `J > 0` (Equation 1), and never otherwise.
//!
//! Comparing two flip times is the sign of `I₂·J₁ − I₁·J₂`: an interval-arithmetic filter
//! first, then floating-point expansions. A certificate's exact `I` and `J`, once computed,
//! also give it a tight interval, so that it rarely needs exact products again. Exact ties
//! are broken by TetGen's symbolic perturbation of the lift (lower index, larger
//! infinitesimal lowering), the same one that [`insphere_sos`](super::insphere_sos)
//! applies, so the flips keep the canonical triangulation and no two events are ever
//! simultaneous unless they are the same event.

use super::expansion::Expansion;
use super::Point;
use std::cell::OnceCell;
use std::cmp::Ordering;

/// A floating-point value with its permanent (the same expression evaluated on absolute
/// values). An expression tree of depth d evaluated from exact inputs is off by at most
/// γ_d times the permanent; all ours have depth at most 12 (hence the module's bound `ERR`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Approx {
    /// The value, rounded.
    pub v: f64,
    /// The permanent, rounded; for a value rounded from its exact expansion, its error
    /// bound divided by `ERR`.
    pub p: f64,
}

/// Bound on the relative (to the permanent) error of every evaluation here: γ_12 is
/// about 1.34e-15; the margin also covers the rounding of the permanent itself.
const ERR: f64 = 3.0e-15;
/// Outside this range of permanents, underflow or overflow could break the bounds.
const RANGE: (f64, f64) = (1e-120, 1e120);

impl Approx {
    /// The value of `x` rounded, with a permanent whose error bound (`ERR` times it)
    /// covers the rounding: the rest `x − v` is bounded by the sum of its components'
    /// magnitudes, rounded up.
    fn of_exact(x: &Expansion) -> Self {
        let v = x.estimate();
        let rest = x.sub(&Expansion::from_f64(v));
        let n = rest.components().len() as f64;
        let bound = rest.components().iter().map(|c| c.abs()).sum::<f64>()
            * (1.0 + 2.0 * (n + 1.0) * f64::EPSILON);
        Approx {
            v,
            p: bound / ERR * (1.0 + 1e-12),
        }
    }

    /// The error bound, or `None` when the value is outside the range of the analysis.
    #[inline]
    fn err(&self) -> Option<f64> {
        (self.p == 0.0 || (self.p > RANGE.0 && self.p < RANGE.1)).then_some(ERR * self.p)
    }

    /// The sign if the error bound settles it.
    pub fn sign(&self) -> Option<i32> {
        let e = self.err()?;
        if self.v > e {
            Some(1)
        } else if -self.v > e {
            Some(-1)
        } else if self.p == 0.0 {
            Some(0)
        } else {
            None
        }
    }
}

/// The arithmetic both evaluations of the determinants share.
pub trait Arith: Clone {
    /// `a - b` of two coordinates.
    fn diff(a: f64, b: f64) -> Self;
    /// A constant.
    fn constant(x: f64) -> Self;
    /// Sum.
    fn plus(&self, o: &Self) -> Self;
    /// Difference.
    fn minus(&self, o: &Self) -> Self;
    /// Product.
    fn times(&self, o: &Self) -> Self;
}

impl Arith for Approx {
    #[inline(always)]
    fn diff(a: f64, b: f64) -> Self {
        let v = a - b;
        Approx { v, p: v.abs() }
    }
    #[inline(always)]
    fn constant(x: f64) -> Self {
        Approx { v: x, p: x.abs() }
    }
    #[inline(always)]
    fn plus(&self, o: &Self) -> Self {
        Approx {
            v: self.v + o.v,
            p: self.p + o.p,
        }
    }
    #[inline(always)]
    fn minus(&self, o: &Self) -> Self {
        Approx {
            v: self.v - o.v,
            p: self.p + o.p,
        }
    }
    #[inline(always)]
    fn times(&self, o: &Self) -> Self {
        Approx {
            v: self.v * o.v,
            p: self.p * o.p,
        }
    }
}

impl Arith for Expansion {
    fn diff(a: f64, b: f64) -> Self {
        Expansion::diff(a, b)
    }
    fn constant(x: f64) -> Self {
        Expansion::from_f64(x)
    }
    fn plus(&self, o: &Self) -> Self {
        self.add(o)
    }
    fn minus(&self, o: &Self) -> Self {
        self.sub(o)
    }
    fn times(&self, o: &Self) -> Self {
        self.mul(o)
    }
}

/// The 3×3 determinant of `r`.
fn det3<T: Arith>(r: [&[T; 3]; 3]) -> T {
    let m0 = r[1][1].times(&r[2][2]).minus(&r[1][2].times(&r[2][1]));
    let m1 = r[1][0].times(&r[2][2]).minus(&r[1][2].times(&r[2][0]));
    let m2 = r[1][0].times(&r[2][1]).minus(&r[1][1].times(&r[2][0]));
    r[0][0]
        .times(&m0)
        .minus(&r[0][1].times(&m1))
        .plus(&r[0][2].times(&m2))
}

/// Shewchuk's orient3d of `a, b, c, d`: `det[a−d; b−d; c−d]` (the paper's Orient3D;
/// the negation of [`orient3d`](super::orient3d)).
pub fn orient<T: Arith>(a: &Point, b: &Point, c: &Point, d: &Point) -> T {
    let row = |p: &Point| -> [T; 3] { std::array::from_fn(|k| T::diff(p[k], d[k])) };
    let (ra, rb, rc) = (row(a), row(b), row(c));
    det3([&ra, &rb, &rc])
}

/// The 4×4 determinant with rows `(p_i − p_4, l_i)` for `i < 4`, given the rows'
/// coordinate differences and lifts already relative to `p_4`. With `l_i = |p_i − p_4|²`
/// this is Shewchuk's insphere.
fn lifted_det<T: Arith>(d: &[[T; 3]; 4], l: &[T; 4]) -> T {
    with_minors(&minors(d), l)
}

/// The four 3×3 minors of the coordinate columns, `m[i]` without row `i`.
fn minors<T: Arith>(d: &[[T; 3]; 4]) -> [T; 4] {
    let m = |a: usize, b: usize, c: usize| det3([&d[a], &d[b], &d[c]]);
    [m(1, 2, 3), m(0, 2, 3), m(0, 1, 3), m(0, 1, 2)]
}

/// [`lifted_det`] from precomputed minors (`I` and `J` share them).
fn with_minors<T: Arith>(m: &[T; 4], l: &[T; 4]) -> T {
    l[3].times(&m[3])
        .minus(&l[2].times(&m[2]))
        .plus(&l[1].times(&m[1]))
        .minus(&l[0].times(&m[0]))
}

/// Coordinate differences of the first four points from the fifth.
fn rows<T: Arith>(p: &[Point; 5]) -> [[T; 3]; 4] {
    std::array::from_fn(|i| std::array::from_fn(|k| T::diff(p[i][k], p[4][k])))
}

/// `I`: our insphere (positive inside) of the tet `p[0..4]` and the query `p[4]`.
fn insphere_value<T: Arith>(d: &[[T; 3]; 4]) -> T {
    insphere_with(d, &minors(d))
}

fn insphere_with<T: Arith>(d: &[[T; 3]; 4], m: &[T; 4]) -> T {
    let l: [T; 4] = std::array::from_fn(|i| {
        d[i][0]
            .times(&d[i][0])
            .plus(&d[i][1].times(&d[i][1]))
            .plus(&d[i][2].times(&d[i][2]))
    });
    T::constant(0.0).minus(&with_minors(m, &l))
}

/// `J`: the insphere determinant with the lift replaced by the heights `h`.
fn height_with<T: Arith>(m: &[T; 4], h: &[T; 5]) -> T {
    let l: [T; 4] = std::array::from_fn(|i| h[i].minus(&h[4]));
    T::constant(0.0).minus(&with_minors(m, &l))
}

/// `I` and `J` together, sharing the minors.
fn both_values<T: Arith>(d: &[[T; 3]; 4], h: &[T; 5]) -> (T, T) {
    let m = minors(d);
    (insphere_with(d, &m), height_with(&m, h))
}

/// The coefficient of the perturbation weight of point `k` in `D`: the determinant with
/// lift 1 at point `k` and 0 elsewhere (lowering a lift by ε adds ε times this to `D`).
fn perturbation_coefficient(d: &[[Expansion; 3]; 4], k: usize) -> Expansion {
    let l: [Expansion; 4] = std::array::from_fn(|i| {
        if k == 4 {
            Expansion::from_f64(-1.0)
        } else if i == k {
            Expansion::from_f64(1.0)
        } else {
            Expansion::zero()
        }
    });
    lifted_det(d, &l)
}

/// The plane of a polygon, through three of its vertices: heights are Shewchuk's
/// orient3d of `(a, b, c, v)`, positive for left vertices.
#[derive(Clone, Copy, Debug)]
pub struct Lifting {
    /// Three vertices of the polygon, approximately of largest area.
    pub abc: [Point; 3],
}

impl Lifting {
    /// The exact sign of `v`'s height (1 for left vertices).
    pub fn side(&self, v: &Point) -> i32 {
        let [a, b, c] = &self.abc;
        let s = robust::orient3d(co(a), co(b), co(c), co(v));
        if s > 0.0 {
            1
        } else if s < 0.0 {
            -1
        } else {
            0
        }
    }

    /// The height of `v` in floating point, with its permanent (zero unless left).
    pub fn height_approx(&self, v: &Point, left: bool) -> Approx {
        self.height(v, left)
    }

    fn height<T: Arith>(&self, v: &Point, left: bool) -> T {
        if left {
            let [a, b, c] = &self.abc;
            orient(a, b, c, v)
        } else {
            T::constant(0.0)
        }
    }
}

fn co(p: &Point) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p[0],
        y: p[1],
        z: p[2],
    }
}

/// The flip certificate of one face: the five points, the interval values of `I` and `J`,
/// and (on demand) their exact values.
#[derive(Clone, Debug)]
pub struct FlipTime {
    /// `x, y, z, v, w`: the face and the two apices (`xyzv` positively oriented).
    pub pts: [Point; 5],
    /// The points' perturbation indices.
    pub ids: [u32; 5],
    /// Which points are left vertices (weighted).
    pub left: [bool; 5],
    i: Approx,
    j: Approx,
    exact: OnceCell<Box<Exact>>,
}

/// The exact values of a certificate: `I`, `J`, and the minors, whose signed values are
/// the perturbation coefficients (computed once: a tie may ask for all five).
#[derive(Clone, Debug)]
struct Exact {
    i: Expansion,
    j: Expansion,
    minors: [Expansion; 4],
    /// `i` and `j` rounded, with bounds as tight as the rounding: an interval or a key made
    /// from these settles nearly every later comparison without the products.
    rounded: (Approx, Approx),
}

/// Counts of how the comparisons were decided (for tuning and tests).
#[derive(Clone, Copy, Debug, Default)]
pub struct CompareCounts {
    /// Decided by the interval filter.
    pub filtered: usize,
    /// Needed exact arithmetic.
    pub exact: usize,
    /// Exact ties broken by the symbolic perturbation.
    pub perturbed: usize,
    /// The size of the exact comparisons: for each, the product of the two sides'
    /// component counts, which the cost of its multiplications follows.
    pub exact_work: u64,
}

impl FlipTime {
    /// The certificate of the face `pts[0..3]` between apices `pts[3]` and `pts[4]`,
    /// given the points' heights ([`Lifting::height_approx`], zero unless left).
    pub fn new(pts: [Point; 5], ids: [u32; 5], left: [bool; 5], h: [Approx; 5]) -> Self {
        let d: [[Approx; 3]; 4] = rows(&pts);
        let (i, j) = both_values(&d, &h);
        FlipTime {
            pts,
            ids,
            left,
            i,
            j,
            exact: OnceCell::new(),
        }
    }

    /// The certificate if the face ever flips (`J > 0`), else `None`; cheaper than
    /// [`FlipTime::new`] followed by [`FlipTime::flips`] when `J` is surely not positive,
    /// since `I` is then never computed.
    pub fn if_flips(
        lift: &Lifting,
        pts: [Point; 5],
        ids: [u32; 5],
        left: [bool; 5],
        h: [Approx; 5],
    ) -> Option<Self> {
        let d: [[Approx; 3]; 4] = rows(&pts);
        let m = minors(&d);
        let j = height_with(&m, &h);
        if matches!(j.sign(), Some(s) if s <= 0) {
            return None;
        }
        let t = FlipTime {
            pts,
            ids,
            left,
            i: insphere_with(&d, &m),
            j,
            exact: OnceCell::new(),
        };
        t.flips(lift).then_some(t)
    }

    /// [`FlipTime::if_flips`] followed by [`FlipTime::interval`], without making the
    /// certificate unless `J`'s sign needs exact arithmetic: queueing a face needs only
    /// the interval (a certificate is 200 bytes, copied three times on its way).
    ///
    /// `ids_and_left` gives the points' perturbation indices and which are left; it is
    /// asked only then. Always inlined: as a call from the flips' `certify`, their hottest
    /// caller, it cost 3% more instructions.
    #[inline(always)]
    pub fn interval_if_flips(
        lift: &Lifting,
        pts: &[Point; 5],
        h: &[Approx; 5],
        ids_and_left: impl FnOnce() -> ([u32; 5], [bool; 5]),
    ) -> Option<(f64, f64)> {
        let d: [[Approx; 3]; 4] = rows(pts);
        let m = minors(&d);
        let j = height_with(&m, h);
        match j.sign() {
            Some(s) if s <= 0 => return None,
            Some(_) => {}
            None => {
                let (ids, left) = ids_and_left();
                let t = FlipTime::if_flips(lift, *pts, ids, left, *h)?;
                return Some(t.interval());
            }
        }
        Some(interval_of(&insphere_with(&d, &m), &j))
    }

    fn exact(&self, lift: &Lifting) -> &Exact {
        self.exact.get_or_init(|| {
            let d: [[Expansion; 3]; 4] = rows(&self.pts);
            let h: [Expansion; 5] =
                std::array::from_fn(|k| lift.height(&self.pts[k], self.left[k]));
            let minors = minors(&d);
            let (i, j) = (insphere_with(&d, &minors), height_with(&minors, &h));
            let rounded = (Approx::of_exact(&i), Approx::of_exact(&j));
            Box::new(Exact {
                i,
                j,
                minors,
                rounded,
            })
        })
    }

    /// True if the face ever stops being locally regular: `J > 0`.
    pub fn flips(&self, lift: &Lifting) -> bool {
        match self.j.sign() {
            Some(s) => s > 0,
            None => self.exact(lift).j.sign() > 0,
        }
    }

    /// The approximate flip time (for reports; the order uses [`compare`]).
    pub fn approx(&self) -> f64 {
        -self.i.v / self.j.v
    }

    /// The perturbation coefficient of vertex index `id` (zero if not one of the points):
    /// [`perturbation_coefficient`], from the kept minors.
    fn coefficient(&self, id: u32, lift: &Lifting) -> Expansion {
        let Some(k) = self.ids.iter().position(|&x| x == id) else {
            return Expansion::zero();
        };
        // The determinant with lifts (l0, l1, l2, l3) is l3·m3 − l2·m2 + l1·m1 − l0·m0: a
        // single lift of 1 picks one signed minor; the fifth point's lowers all four.
        let m = &self.exact(lift).minors;
        match k {
            0 => Expansion::zero().sub(&m[0]),
            1 => m[1].clone(),
            2 => Expansion::zero().sub(&m[2]),
            3 => m[3].clone(),
            _ => m[0].sub(&m[1]).add(&m[2]).sub(&m[3]),
        }
    }
}

/// The sign of `(I_b + δ_b)·J_a − (I_a + δ_a)·J_b`, where δ are the symbolic perturbation
/// terms. With `J_a > 0` and `J_b > 0` it is negative iff `a` flips before `b`; with
/// `J_a > 0` it is positive iff `b`'s face is not locally regular at `a`'s flip time.
pub fn cross_sign(a: &FlipTime, b: &FlipTime, lift: &Lifting, counts: &mut CompareCounts) -> i32 {
    if let Some(s) = filtered_cross(a, b) {
        counts.filtered += 1;
        return s;
    }
    if a.ids
        .iter()
        .all(|&id| b.ids.contains(&id) && left_of(a, id) == left_of(b, id))
    {
        // The same five lifted points: the same hyperplane, the same event.
        return 0;
    }
    let (ea, eb) = (a.exact(lift), b.exact(lift));
    // The filter again, on the exact values rounded: the floating-point evaluation of a
    // nearly flat certificate (four vertices of the polygon in one minor) may not even
    // have J's sign, while the two flip times are far apart.
    if let Some(s) = key_cross(&a.key(), &b.key()) {
        counts.filtered += 1;
        return s;
    }
    counts.exact += 1;
    let (ia, ja, ib, jb) = (&ea.i, &ea.j, &eb.i, &eb.j);
    let len = |x: &Expansion, y: &Expansion| (x.components().len() + y.components().len()) as u64;
    counts.exact_work += len(ia, ja) * len(ib, jb);
    let s = ib.mul(ja).sub(&ia.mul(jb)).sign();
    if s != 0 {
        return s;
    }
    counts.perturbed += 1;
    let mut ids: Vec<u32> = a.ids.iter().chain(&b.ids).copied().collect();
    ids.sort_unstable();
    ids.dedup();
    for id in ids {
        let c = b
            .coefficient(id, lift)
            .mul(ja)
            .sub(&a.coefficient(id, lift).mul(jb));
        let s = c.sign();
        if s != 0 {
            return s;
        }
    }
    0
}

/// The floating-point part of a flip time, compact enough to keep in a heap entry:
/// `I` and `J` with their error bounds (NaN bounds when outside the analysed range).
#[derive(Copy, Clone, Debug)]
struct TimeKey {
    i: f64,
    j: f64,
    ei: f64,
    ej: f64,
}

impl FlipTime {
    /// The compact key of this flip time.
    fn key(&self) -> TimeKey {
        let (i, j) = self.values();
        TimeKey {
            i: i.v,
            j: j.v,
            ei: i.err().unwrap_or(f64::NAN),
            ej: j.err().unwrap_or(f64::NAN),
        }
    }

    /// `I` and `J` as tightly as they are known: rounded from the exact values once those
    /// were needed, else as evaluated in floating point.
    fn values(&self) -> (Approx, Approx) {
        match self.exact.get() {
            Some(e) => e.rounded,
            None => (self.i, self.j),
        }
    }
}

impl FlipTime {
    /// An interval holding the flip time `τ = −I/J` (everything when `J` may not be
    /// positive or the values leave the analysed range): most heap comparisons are
    /// settled by two of these, with two float comparisons.
    pub fn interval(&self) -> (f64, f64) {
        let (i, j) = self.values();
        interval_of(&i, &j)
    }
}

/// [`FlipTime::interval`] of the values `i` and `j`.
fn interval_of(i: &Approx, j: &Approx) -> (f64, f64) {
    let everything = (f64::NEG_INFINITY, f64::INFINITY);
    let (Some(ei), Some(ej)) = (i.err(), j.err()) else {
        return everything;
    };
    let (dlo, dhi) = (j.v - ej, j.v + ej);
    // Also false for NaN.
    if dlo.partial_cmp(&0.0) != Some(Ordering::Greater) {
        return everything;
    }
    let (nlo, nhi) = (-i.v - ei, -i.v + ei);
    let lo = nlo / if nlo >= 0.0 { dhi } else { dlo };
    let hi = nhi / if nhi >= 0.0 { dlo } else { dhi };
    // Each bound went through three roundings (of the numerator, the denominator
    // and the quotient), each relative to its result; the absolute term covers
    // subnormal results.
    let w = 8.0 * f64::EPSILON;
    let (lo, hi) = (
        lo - lo.abs() * w - f64::MIN_POSITIVE,
        hi + hi.abs() * w + f64::MIN_POSITIVE,
    );
    if lo.is_nan() || hi.is_nan() {
        everything
    } else {
        (lo, hi)
    }
}

/// The sign of `I_b·J_a − I_a·J_b` from two keys, if the error bounds settle it.
#[inline]
fn key_cross(a: &TimeKey, b: &TimeKey) -> Option<i32> {
    let (eia, eja, eib, ejb) = (a.ei, a.ej, b.ei, b.ej);
    let (x, y) = (b.i * a.j, a.i * b.j);
    let s = x - y;
    let bound = (eib * (a.j.abs() + eja)
        + b.i.abs() * eja
        + eia * (b.j.abs() + ejb)
        + a.i.abs() * ejb
        + 4.0 * f64::EPSILON * (x.abs() + y.abs()))
        * (1.0 + 1e-12);
    // NaN bounds (out of range) fail both tests below.
    // NaN (out of the analysed range), overflow, or possible underflow: undecided.
    if !(1e-290..f64::MAX).contains(&bound) {
        return None;
    }
    if s > bound {
        Some(1)
    } else if -s > bound {
        Some(-1)
    } else {
        None
    }
}

/// The sign of `I_b·J_a − I_a·J_b` if the floating-point values and their error bounds
/// settle it.
#[inline]
fn filtered_cross(a: &FlipTime, b: &FlipTime) -> Option<i32> {
    key_cross(&a.key(), &b.key())
}

fn left_of(f: &FlipTime, id: u32) -> bool {
    f.ids
        .iter()
        .position(|&x| x == id)
        .map(|k| f.left[k])
        .unwrap_or(false)
}

/// The order of the flip times of `a` and `b` (both with `J > 0`), ties perturbed.
pub fn compare(a: &FlipTime, b: &FlipTime, lift: &Lifting, counts: &mut CompareCounts) -> Ordering {
    cross_sign(a, b, lift, counts).cmp(&0)
}

/// `D` at time 0 under the perturbation: positive iff `w` is inside the (perturbed)
/// circumsphere of `xyzv`; agrees with [`insphere_sos`](super::insphere_sos).
pub fn perturbed_insphere(pts: [Point; 5], ids: [u32; 5]) -> i32 {
    let d: [[Expansion; 3]; 4] = rows(&pts);
    let s = insphere_value(&d).sign();
    if s != 0 {
        return s;
    }
    let mut order: [usize; 5] = std::array::from_fn(|k| k);
    order.sort_unstable_by_key(|&k| ids[k]);
    for k in order {
        let s = perturbation_coefficient(&d, k).sign();
        if s != 0 {
            return s;
        }
    }
    0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{insphere, insphere_sos, orient3d, Sign};

    use crate::geom::lcg;

    #[test]
    fn values_agree_with_the_predicates() {
        let mut s = 3u64;
        for _ in 0..2000 {
            let p: [Point; 5] = std::array::from_fn(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)]);
            let d: [[Approx; 3]; 4] = rows(&p);
            let i = insphere_value(&d);
            let want = insphere(&p[0], &p[1], &p[2], &p[3], &p[4]);
            assert!(i.sign().is_none_or(|x| x as f64 * want > 0.0));
            let de: [[Expansion; 3]; 4] = rows(&p);
            assert_eq!(insphere_value(&de).sign() as f64 * want.signum(), 1.0);
            let o: Expansion = orient(&p[0], &p[1], &p[2], &p[3]);
            assert_eq!(
                o.sign() as f64,
                -orient3d(&p[0], &p[1], &p[2], &p[3]).signum()
            );
        }
    }

    /// The tie-breaking of `D` at time 0 is TetGen's, on the cospherical cube corners.
    #[test]
    fn perturbation_matches_insphere_sos() {
        let pts: Vec<Point> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64])
            .collect();
        let mut checked = 0;
        for a in 0..8u32 {
            for b in 0..8u32 {
                for c in 0..8u32 {
                    for d in 0..8u32 {
                        for e in 0..8u32 {
                            let ids = [a, b, c, d, e];
                            let mut u = ids.to_vec();
                            u.sort();
                            u.dedup();
                            if u.len() < 5 {
                                continue;
                            }
                            let p = ids.map(|i| pts[i as usize]);
                            if orient3d(&p[0], &p[1], &p[2], &p[3]) <= 0.0 {
                                continue;
                            }
                            let want = insphere_sos(p.each_ref(), ids);
                            let got = perturbed_insphere(p, ids);
                            let want = match want {
                                Sign::Positive => 1,
                                Sign::Negative => -1,
                                Sign::Zero => 0,
                            };
                            assert_eq!(got, want, "{ids:?}");
                            checked += 1;
                        }
                    }
                }
            }
        }
        assert!(checked > 500);
    }

    fn cert(lift: &Lifting, p: [Point; 5], ids: [u32; 5]) -> FlipTime {
        let left = p.map(|q| lift.side(&q) > 0);
        let h = std::array::from_fn(|k| lift.height_approx(&p[k], left[k]));
        FlipTime::new(p, ids, left, h)
    }

    /// The perturbation coefficients read from the kept minors are those of the
    /// determinant with one lift set (all five points, random values and ties).
    #[test]
    fn kept_minors_give_the_perturbation_coefficients() {
        let lift = Lifting {
            abc: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        };
        let mut s = 5u64;
        for round in 0..200 {
            let p: [Point; 5] = std::array::from_fn(|_| {
                std::array::from_fn(|_| {
                    let x = lcg(&mut s) * 6.0 - 3.0;
                    if round % 2 == 0 {
                        x.floor()
                    } else {
                        x
                    }
                })
            });
            let ids = [7, 3, 9, 1, 5];
            let t = cert(&lift, p, ids);
            let d: [[Expansion; 3]; 4] = rows(&p);
            for (k, &id) in ids.iter().enumerate() {
                let want = perturbation_coefficient(&d, k);
                assert_eq!(t.coefficient(id, &lift).sub(&want).sign(), 0, "{p:?} {k}");
            }
            assert_eq!(t.coefficient(2, &lift).sign(), 0);
        }
    }

    /// Integer reference: `I` and `J` exactly in i128 for small integer coordinates.
    fn reference(lift: &Lifting, p: &[Point; 5]) -> (i128, i128) {
        let q: Vec<[i128; 3]> = p.iter().map(|x| x.map(|c| c as i128)).collect();
        let d: Vec<[i128; 3]> = (0..4)
            .map(|i| std::array::from_fn(|k| q[i][k] - q[4][k]))
            .collect();
        let det3 = |a: &[i128; 3], b: &[i128; 3], c: &[i128; 3]| {
            a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])
        };
        let f = |l: [i128; 4]| {
            l[3] * det3(&d[0], &d[1], &d[2]) - l[2] * det3(&d[0], &d[1], &d[3])
                + l[1] * det3(&d[0], &d[2], &d[3])
                - l[0] * det3(&d[1], &d[2], &d[3])
        };
        let abc: Vec<[i128; 3]> = lift.abc.iter().map(|x| x.map(|c| c as i128)).collect();
        let h = |v: &[i128; 3]| {
            let r = |a: &[i128; 3]| std::array::from_fn::<i128, 3, _>(|k| a[k] - v[k]);
            det3(&r(&abc[0]), &r(&abc[1]), &r(&abc[2])).max(0)
        };
        let hs: Vec<i128> = q.iter().map(h).collect();
        let i = -f(std::array::from_fn(|k| d[k].iter().map(|x| x * x).sum()));
        let j = -f(std::array::from_fn(|k| hs[k] - hs[4]));
        (i, j)
    }

    /// Flip times are ordered exactly (checked against integer arithmetic, on
    /// configurations full of ties and near-ties), and exact ties between different
    /// events are broken antisymmetrically.
    #[test]
    fn flip_time_comparison_is_exact() {
        let lift = Lifting {
            abc: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        };
        let mut s = 11u64;
        let mut certs: Vec<(FlipTime, i128, i128)> = Vec::new();
        let mut next_id = 0u32;
        while certs.len() < 300 {
            let mut p: [Point; 5] =
                std::array::from_fn(|_| std::array::from_fn(|_| (lcg(&mut s) * 9.0).floor() - 4.0));
            let o = orient3d(&p[0], &p[1], &p[2], &p[3]);
            if o == 0.0 {
                continue;
            }
            if o < 0.0 {
                p.swap(0, 1);
            }
            let ids = std::array::from_fn(|k| next_id + k as u32);
            next_id += 5;
            let c = cert(&lift, p, ids);
            let (i, j) = reference(&lift, &p);
            assert_eq!(c.flips(&lift), j > 0);
            if j > 0 {
                certs.push((c, i, j));
            }
        }
        let mut counts = CompareCounts::default();
        let mut ties = 0;
        for (a, ia, ja) in &certs {
            for (b, ib, jb) in &certs {
                let want = (ib * ja - ia * jb).signum() as i32;
                assert_interval_agrees(a, b, want);
                let got = cross_sign(a, b, &lift, &mut counts);
                let back = cross_sign(b, a, &lift, &mut counts);
                assert_eq!(got, -back);
                if want != 0 {
                    assert_eq!(got, want);
                } else if a.ids != b.ids {
                    ties += 1;
                    assert_ne!(got, 0, "ties between different events are broken");
                }
            }
        }
        assert!(
            ties > 0 && counts.exact > 0 && counts.perturbed > 0,
            "{counts:?}"
        );
        // Nearby integer configurations (one coordinate moved by one), ordered exactly.
        let mut s = 5u64;
        for _ in 0..20000 {
            let mut p: [Point; 5] = std::array::from_fn(|_| {
                std::array::from_fn(|_| (lcg(&mut s) * 129.0).floor() - 64.0)
            });
            if orient3d(&p[0], &p[1], &p[2], &p[3]) < 0.0 {
                p.swap(0, 1);
            }
            let mut q = p;
            q[(lcg(&mut s) * 5.0) as usize][(lcg(&mut s) * 3.0) as usize] += 1.0;
            if orient3d(&q[0], &q[1], &q[2], &q[3]) <= 0.0 {
                continue;
            }
            let ((ia, ja), (ib, jb)) = (reference(&lift, &p), reference(&lift, &q));
            if ja <= 0 || jb <= 0 {
                continue;
            }
            let want = (ib * ja - ia * jb).signum() as i32;
            let (a, b) = (
                cert(&lift, p, [0, 1, 2, 3, 4]),
                cert(&lift, q, [0, 1, 2, 3, 5]),
            );
            assert_interval_agrees(&a, &b, want);
            let got = cross_sign(&a, &b, &lift, &mut counts);
            if want != 0 {
                assert_eq!(got, want);
            } else {
                assert_eq!(got, -cross_sign(&b, &a, &lift, &mut counts));
            }
        }
        assert!(decided_by_intervals() > 1000);
    }

    /// A flip time with J > 0 does not depend on the order of its five points: the
    /// flips keep one flip time, and one order against another event, per sorted five
    /// vertices on that ground. Checked against every other event, ties included.
    #[test]
    fn flip_times_with_positive_j_do_not_depend_on_the_order_of_the_five() {
        let lift = Lifting {
            abc: [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        };
        let mut s = 17u64;
        let mut events: Vec<([Point; 5], [u32; 5])> = Vec::new();
        let mut next_id = 0u32;
        while events.len() < 40 {
            let p: [Point; 5] =
                std::array::from_fn(|_| std::array::from_fn(|_| (lcg(&mut s) * 7.0).floor() - 3.0));
            let ids = std::array::from_fn(|k| next_id + k as u32);
            next_id += 5;
            if cert(&lift, p, ids).flips(&lift) {
                events.push((p, ids));
            }
        }
        let mut counts = CompareCounts::default();
        let mut reordered = 0;
        for (p, ids) in &events {
            let a = cert(&lift, *p, *ids);
            for _ in 0..6 {
                // A random order of the five points (odd ones make J negative: skipped).
                let mut order = [0usize, 1, 2, 3, 4];
                for k in (1..5).rev() {
                    order.swap(k, (lcg(&mut s) * (k + 1) as f64) as usize);
                }
                let a2 = cert(&lift, order.map(|k| p[k]), order.map(|k| ids[k]));
                if !a2.flips(&lift) {
                    continue;
                }
                reordered += 1;
                assert_eq!(cross_sign(&a, &a2, &lift, &mut counts), 0);
                for (q, qids) in &events {
                    let b = cert(&lift, *q, *qids);
                    assert_eq!(
                        cross_sign(&a, &b, &lift, &mut counts),
                        cross_sign(&a2, &b, &lift, &mut counts)
                    );
                }
            }
        }
        assert!(
            reordered > 40 && counts.perturbed > 0,
            "{reordered} {counts:?}"
        );
    }

    thread_local! {
        static DECIDED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
    }

    fn decided_by_intervals() -> usize {
        DECIDED.with(|d| d.get())
    }

    /// Where the intervals of two flip times are disjoint, they order them as the exact
    /// sign `want` of `I_b·J_a − I_a·J_b` does (negative: `a` first).
    fn assert_interval_agrees(a: &FlipTime, b: &FlipTime, want: i32) {
        let ((alo, ahi), (blo, bhi)) = (a.interval(), b.interval());
        assert!(alo <= ahi && blo <= bhi);
        if ahi < blo {
            assert_eq!(want, -1, "{:?} before {:?}", (alo, ahi), (blo, bhi));
        } else if bhi < alo {
            assert_eq!(want, 1, "{:?} after {:?}", (alo, ahi), (blo, bhi));
        } else {
            return;
        }
        DECIDED.with(|d| d.set(d.get() + 1));
    }

    /// The rounding of an exact value is within the error bound it claims, on products
    /// and sums of random values of many magnitudes (the rest is checked exactly).
    #[test]
    fn exact_values_round_within_their_bound() {
        let mut s = 11u64;
        for _ in 0..3000 {
            let mut x = Expansion::zero();
            for _ in 0..4 {
                let mag = 2f64.powi((lcg(&mut s) * 60.0) as i32 - 30);
                let a = Expansion::from_f64((lcg(&mut s) - 0.5) * mag);
                let b = Expansion::from_f64(lcg(&mut s) - 0.5 + f64::EPSILON * lcg(&mut s));
                x = x.add(&a.mul(&b));
            }
            let r = Approx::of_exact(&x);
            let e = r.err().unwrap();
            let rest = x.sub(&Expansion::from_f64(r.v));
            assert!(rest.sub(&Expansion::from_f64(e)).sign() <= 0, "{x:?}");
            assert!(rest.add(&Expansion::from_f64(e)).sign() >= 0, "{x:?}");
        }
    }

    /// Two certificates from a fine folded surface (`live-compare-plc.py --big`), each with
    /// one left vertex and four nearly coplanar points of the polygon: in floating point
    /// even the sign of `J` is lost. Once their exact values are known their intervals are
    /// tight, and comparing them (their times differ 26-fold) needs no exact products.
    #[test]
    fn nearly_flat_certificates_get_tight_intervals_from_their_exact_values() {
        let lift = Lifting {
            abc: [
                [
                    0.05546202341366163,
                    0.002944420733223551,
                    -1.0066807835160518,
                ],
                [
                    0.0305116708410871,
                    0.003476613126320699,
                    -1.0127440452905843,
                ],
                [
                    0.04625035864524529,
                    0.005269937683864016,
                    -1.0262795379483962,
                ],
            ],
        };
        let [p0, p1, p2] = lift.abc;
        let q: [Point; 5] = [
            [0.0553641751483994, 0.00732858427324465, -1.0126334118437166],
            [
                0.04885609164558194,
                -0.0033171022142907546,
                -1.018362479768785,
            ],
            [
                0.03443165256490832,
                -0.002337749646314077,
                -1.008956349467558,
            ],
            [
                0.05581077227503788,
                0.007051298445018789,
                -1.0199285048543425,
            ],
            p0,
        ];
        let certs = [
            (
                [q[0], p1, q[1], q[2], p2],
                [10644, 11673, 11159, 11672, 11161],
            ),
            (
                [q[0], p2, q[1], p1, q[3]],
                [10644, 11161, 11159, 11673, 14451],
            ),
        ]
        .map(|(p, ids)| {
            let left = p.map(|x| lift.side(&x) > 0);
            let h = std::array::from_fn(|k| lift.height_approx(&p[k], left[k]));
            assert!(FlipTime::new(p, ids, left, h).j.sign().is_none());
            FlipTime::if_flips(&lift, p, ids, left, h).expect("the face flips")
        });
        for t in &certs {
            let (lo, hi) = t.interval();
            let e = t.exact(&lift);
            let tau = -e.i.estimate() / e.j.estimate();
            assert!(
                lo <= tau && tau <= hi && hi - lo <= 1e-12 * tau,
                "{lo} {tau} {hi}"
            );
        }
        let [a, b] = &certs;
        let (ea, eb) = (a.exact(&lift), b.exact(&lift));
        let want = eb.i.mul(&ea.j).sub(&ea.i.mul(&eb.j)).sign();
        assert_eq!(want, -1);
        let mut counts = CompareCounts::default();
        assert_eq!(cross_sign(a, b, &lift, &mut counts), want);
        assert_eq!((counts.filtered, counts.exact), (1, 0), "{counts:?}");
    }
}
