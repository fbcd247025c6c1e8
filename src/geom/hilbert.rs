//! Insertion order for incremental Delaunay: biased randomized insertion order (BRIO)
//! with each round sorted along a 3D Hilbert curve, and detection of exact duplicates.

use super::Point;

/// Bits per axis of the Hilbert grid (3 × 21 = 63 bits fit a `u64` key).
const BITS: u32 = 21;
/// Fraction of the remaining points that go to earlier rounds (TetGen uses 1/8 too).
const ROUND_RATIO: u64 = 8;
/// Cells whose Hilbert keys are computed side by side.
const LANES: usize = 8;
/// Rounds smaller than this are not split further.
const MIN_ROUND: usize = 64;

/// Maps grid coordinates to their distance along the Hilbert curve (Skilling's transform).
pub fn hilbert_key(x: [u32; 3]) -> u64 {
    hilbert_keys([x])[0]
}

/// [`hilbert_key`] of `L` cells at once.
///
/// The transform is a long chain of dependent bit operations per cell; running cells
/// side by side lets the CPU overlap the chains and the compiler vectorize them, and
/// writing it without data-dependent branches (random bits mispredict half of them)
/// and interleaving the bits with masks made the keys of a million points about ten
/// times cheaper.
pub fn hilbert_keys<const L: usize>(cells: [[u32; 3]; L]) -> [u64; L] {
    let mut x: [[u32; L]; 3] = std::array::from_fn(|i| cells.map(|c| c[i]));
    // Skilling's "inverse undo": for each level from the top, either invert the low
    // bits of x[0] (the level's bit is set in x[i]) or exchange them with those of x[i].
    for level in (1..BITS).rev() {
        let p = (1u32 << level) - 1;
        let [x0, x1, x2] = &mut x;
        // For x[0] itself the exchange is a no-op, leaving only the inversion.
        for u in x0.iter_mut() {
            *u ^= p & 0u32.wrapping_sub((*u >> level) & 1);
        }
        for xi in [x1, x2] {
            for (u, w) in x0.iter_mut().zip(xi.iter_mut()) {
                let set = 0u32.wrapping_sub((*w >> level) & 1);
                let t = (*u ^ *w) & p & !set;
                *u ^= (p & set) ^ t;
                *w ^= t;
            }
        }
    }
    std::array::from_fn(|l| {
        // Gray encode.
        let mut v = [x[0][l], x[1][l], x[2][l]];
        v[1] ^= v[0];
        v[2] ^= v[1];
        let mut t = 0;
        for level in (1..BITS).rev() {
            t ^= ((1u32 << level) - 1) & 0u32.wrapping_sub((v[2] >> level) & 1);
        }
        // Interleave: bit b of v[0], v[1], v[2] goes to bits 3b + 2, 3b + 1, 3b.
        (spread3(v[0] ^ t) << 2) | (spread3(v[1] ^ t) << 1) | spread3(v[2] ^ t)
    })
}

/// Spreads the low 21 bits of `v` out to every third bit (bit b to bit 3b).
#[inline]
fn spread3(v: u32) -> u64 {
    let mut x = u64::from(v) & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// SplitMix64: a tiny deterministic hash, so the order is the same on every run.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The result of ordering a point set for insertion.
#[derive(Debug, Default)]
pub struct InsertionOrder {
    /// Indices of the distinct points, in insertion order.
    pub order: Vec<u32>,
    /// Pairs `(duplicate, kept)`: points equal to an earlier (lower-indexed) point.
    pub duplicates: Vec<(u32, u32)>,
}

/// Orders `points` for insertion: BRIO rounds, Hilbert-sorted within each round, with
/// exact duplicates removed (the lowest index of each group is kept).
pub fn insertion_order(points: &[Point]) -> InsertionOrder {
    let n = points.len();
    if n == 0 {
        return InsertionOrder::default();
    }
    let [lo, hi] = super::bounding_box(points);
    // Halved, so that the extent of coordinates near ±f64::MAX does not overflow.
    let span = (0..3)
        .map(|k| hi[k] * 0.5 - lo[k] * 0.5)
        .fold(0.0f64, f64::max);
    let scale = if span > 0.0 && span.is_finite() {
        ((1u64 << BITS) - 1) as f64 / span
    } else {
        0.0
    };
    let grid = |v: f64, k: usize| -> u32 {
        let g = ((v * 0.5 - lo[k] * 0.5) * scale) as u64;
        g.min((1u64 << BITS) - 1) as u32
    };
    let cell = |p: &Point| [grid(p[0], 0), grid(p[1], 1), grid(p[2], 2)];
    let mut keyed: Vec<(u64, u32)> = Vec::with_capacity(n);
    let mut chunks = points.chunks_exact(LANES);
    for chunk in &mut chunks {
        let keys = hilbert_keys::<LANES>(std::array::from_fn(|l| cell(&chunk[l])));
        let base = keyed.len() as u32;
        keyed.extend(keys.iter().zip(0..).map(|(&k, l)| (k, base + l)));
    }
    for p in chunks.remainder() {
        keyed.push((hilbert_key(cell(p)), keyed.len() as u32));
    }
    keyed.sort_unstable();

    // Equal points share a key, so duplicates lie within one run of equal keys; sorting
    // the run by coordinates, then index, puts each group together behind its lowest index.
    let mut duplicates = Vec::new();
    let mut is_dup = vec![false; n];
    let mut run: Vec<u32> = Vec::new();
    let mut i = 0;
    while i < keyed.len() {
        let mut j = i + 1;
        while j < keyed.len() && keyed[j].0 == keyed[i].0 {
            j += 1;
        }
        if j - i > 1 {
            run.clear();
            run.extend(keyed[i..j].iter().map(|&(_, idx)| idx));
            // Adding 0.0 turns -0.0 into 0.0, which equals it.
            let norm = |idx: u32| points[idx as usize].map(|v| v + 0.0);
            run.sort_unstable_by(|&a, &b| {
                let (pa, pb) = (norm(a), norm(b));
                pa[0]
                    .total_cmp(&pb[0])
                    .then(pa[1].total_cmp(&pb[1]))
                    .then(pa[2].total_cmp(&pb[2]))
                    .then(a.cmp(&b))
            });
            let mut first = run[0];
            for &idx in &run[1..] {
                if points[idx as usize] == points[first as usize] {
                    is_dup[idx as usize] = true;
                    duplicates.push((idx, first));
                } else {
                    first = idx;
                }
            }
        }
        i = j;
    }
    duplicates.sort_unstable();

    // Round r holds about a fraction (1 - 1/8) / 8^r of the points counted from the last
    // round; higher rounds are inserted first.
    let distinct = n - duplicates.len();
    let mut max_round = 0u32;
    let mut size = distinct;
    while size / ROUND_RATIO as usize >= MIN_ROUND {
        size /= ROUND_RATIO as usize;
        max_round += 1;
    }
    let round_of = |idx: u32| -> u32 {
        let mut h = mix(u64::from(idx) ^ 0x5EED_u64);
        let mut r = 0;
        while r < max_round && h.is_multiple_of(ROUND_RATIO) {
            r += 1;
            h = mix(h);
        }
        max_round - r
    };
    let mut counts = vec![0usize; max_round as usize + 2];
    let rounds: Vec<u32> = keyed.iter().map(|&(_, idx)| round_of(idx)).collect();
    for (&(_, idx), &r) in keyed.iter().zip(&rounds) {
        if !is_dup[idx as usize] {
            counts[r as usize + 1] += 1;
        }
    }
    for r in 1..counts.len() {
        counts[r] += counts[r - 1];
    }
    let mut order = vec![0u32; distinct];
    for (&(_, idx), &r) in keyed.iter().zip(&rounds) {
        if !is_dup[idx as usize] {
            order[counts[r as usize]] = idx;
            counts[r as usize] += 1;
        }
    }
    InsertionOrder { order, duplicates }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Skilling's transform as published, with branches and a bit-by-bit interleave.
    fn reference_key(mut x: [u32; 3]) -> u64 {
        let m = 1u32 << (BITS - 1);
        let mut q = m;
        while q > 1 {
            let p = q - 1;
            for i in 0..3 {
                if x[i] & q != 0 {
                    x[0] ^= p;
                } else {
                    let t = (x[0] ^ x[i]) & p;
                    x[0] ^= t;
                    x[i] ^= t;
                }
            }
            q >>= 1;
        }
        x[1] ^= x[0];
        x[2] ^= x[1];
        let mut t = 0;
        q = m;
        while q > 1 {
            if x[2] & q != 0 {
                t ^= q - 1;
            }
            q >>= 1;
        }
        for v in &mut x {
            *v ^= t;
        }
        let mut key = 0u64;
        for bit in (0..BITS).rev() {
            for v in &x {
                key = (key << 1) | u64::from((v >> bit) & 1);
            }
        }
        key
    }

    #[test]
    fn fast_keys_equal_the_reference_transform() {
        let top = (1u32 << BITS) - 1;
        for i in 0..200_000u64 {
            let h = mix(i);
            let x = [
                h as u32 & top,
                (h >> 21) as u32 & top,
                (h >> 42) as u32 & top,
            ];
            assert_eq!(hilbert_key(x), reference_key(x), "{x:?}");
        }
        for x in [
            [0, 0, 0],
            [top, top, top],
            [top, 0, 0],
            [0, top, 0],
            [0, 0, top],
        ] {
            assert_eq!(hilbert_key(x), reference_key(x), "{x:?}");
        }
    }

    #[test]
    fn hilbert_keys_are_a_bijection_on_a_small_grid_and_adjacent() {
        // On the full grid, consecutive keys must be grid neighbours; check at the coarse
        // level by comparing keys of the 2x2x2 corner cells.
        let mut seen = std::collections::HashSet::new();
        for x in 0..4u32 {
            for y in 0..4u32 {
                for z in 0..4u32 {
                    let s = 1 << (BITS - 2);
                    assert!(seen.insert(hilbert_key([x * s, y * s, z * s])));
                }
            }
        }
        let mut cells: Vec<(u64, [u32; 3])> = Vec::new();
        let s = 1 << (BITS - 3);
        for x in 0..8u32 {
            for y in 0..8u32 {
                for z in 0..8u32 {
                    cells.push((hilbert_key([x * s, y * s, z * s]), [x, y, z]));
                }
            }
        }
        cells.sort();
        for w in cells.windows(2) {
            let d: u32 = (0..3).map(|k| w[0].1[k].abs_diff(w[1].1[k])).sum();
            assert_eq!(
                d, 1,
                "cells {:?} and {:?} are not neighbours",
                w[0].1, w[1].1
            );
        }
    }

    #[test]
    fn order_is_a_permutation_without_duplicates() {
        let mut pts: Vec<Point> = (0..1000)
            .map(|i| {
                let h = mix(i);
                [
                    (h % 1000) as f64,
                    ((h >> 20) % 1000) as f64,
                    ((h >> 40) % 1000) as f64,
                ]
            })
            .collect();
        pts.push(pts[10]);
        pts.push(pts[3]);
        pts.push(pts[10]);
        let o = insertion_order(&pts);
        assert_eq!(o.duplicates, vec![(1000, 10), (1001, 3), (1002, 10)]);
        let mut sorted = o.order.clone();
        sorted.sort();
        assert_eq!(sorted, (0..1000).collect::<Vec<u32>>());
    }
}
