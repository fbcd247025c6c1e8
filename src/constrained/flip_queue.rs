//! The priority queue of the flips' events: a radix heap on the lower ends of the
//! events' time intervals, in front of a small binary heap that orders the events near
//! the current time exactly.
//!
//! Flip times only grow as the flips go on, so a monotone queue fits: an event is filed
//! by the highest 4-bit digit in which its key (the interval's lower end, as ordered
//! bits) differs from the last minimum, and by its value of that digit, which is one
//! append; events move towards the front in sweeps over one bucket at a time, which
//! read memory in order, a level down each time: at most 6 times per entry (with digits
//! of one bit, the textbook radix heap, up to 24, and the flips took 5% longer). Only the
//! events whose intervals reach the earliest upper end go into the binary heap, where
//! the caller's exact comparison orders them; so the queue pops exactly the event that
//! one binary heap of all events would. On each sweep the caller may drop entries that
//! no longer matter (events made stale by a flip), which then cost no more moves.

/// An entry with an interval `[lo, hi]` that holds its priority (no NaN).
pub(super) trait Interval: Copy {
    /// The interval's lower end.
    fn lo(&self) -> f64;
    /// The interval's upper end.
    fn hi(&self) -> f64;
}

/// The caller's side of the queue: the exact order, and which entries still matter.
pub(super) trait Order<T> {
    /// Whether `a` comes strictly before `b`.
    fn earlier(&mut self, a: &T, b: &T) -> bool;
    /// Whether a far entry on its way to the front still matters: one that does not is
    /// dropped there, before it costs a refiling or a place in the binary heap.
    fn keep(&mut self, x: &T) -> bool;
}

/// Low bits of the ordered bits dropped from the keys: keys then tell values apart to
/// about one part in 4,096 (sign, exponent and 12 bits of mantissa), which bounds how
/// often an entry is refiled; entries closer than that meet in the binary heap.
const SHIFT: u32 = 40;

/// The order of `x` as an unsigned integer, coarsened (no NaN): `x < y` if
/// `key(x) < key(y)`.
#[inline]
fn key(x: f64) -> u64 {
    let b = x.to_bits();
    let ordered = if b >> 63 == 1 { !b } else { b | 1 << 63 };
    ordered >> SHIFT
}

/// Bits of a key per level of buckets: an entry is refiled at most once per level.
const DIGIT: u32 = 4;
/// Levels of buckets: the keys' bits, a digit per level.
const LEVELS: usize = ((64 - SHIFT) / DIGIT) as usize;
/// Buckets: one for keys equal to the last minimum, then `2^DIGIT` per level.
const BUCKETS: usize = 1 + (LEVELS << DIGIT);
// Every bit of a key falls in a level, and every bucket has a bit in the mask.
const _: () = assert!((64 - SHIFT).is_multiple_of(DIGIT) && BUCKETS <= 128);

/// The bucket of key `k` against the last minimum `last` (`k >= last`): 0 if equal, else
/// by the highest digit in which they differ and `k`'s value of that digit, so that
/// buckets in increasing order hold increasing keys.
#[inline]
fn bucket(k: u64, last: u64) -> usize {
    let diff = k ^ last;
    if diff == 0 {
        return 0;
    }
    let level = (63 - diff.leading_zeros()) / DIGIT;
    let digit = (k >> (level * DIGIT)) & ((1 << DIGIT) - 1);
    1 + ((level as usize) << DIGIT) + digit as usize
}

/// The smallest key bucket `b` can hold against the last minimum `last`.
#[inline]
fn bucket_floor(b: usize, last: u64) -> u64 {
    if b == 0 {
        return last;
    }
    let level = ((b - 1) >> DIGIT) as u32;
    let digit = ((b - 1) & ((1 << DIGIT) - 1)) as u64;
    let above = (level + 1) * DIGIT;
    let prefix = if above >= 64 {
        0
    } else {
        (last >> above) << above
    };
    prefix | digit << (level * DIGIT)
}

/// Events far ahead in radix buckets, events near the current time in a binary heap.
pub(super) struct FlipQueue<T> {
    /// Ordered by the caller's comparison: every entry whose key is at most `frontier`.
    front: Vec<T>,
    /// The keys above `frontier`, by [`bucket`] against `last`.
    buckets: Vec<Vec<T>>,
    /// Bit `b` set when bucket `b` is not empty.
    full: u128,
    /// The key the buckets are filed against (at most `frontier`).
    last: u64,
    /// Every key above it is in the buckets.
    frontier: u64,
    /// Entries in the buckets.
    far: usize,
}

impl<T: Interval> FlipQueue<T> {
    /// An empty queue.
    pub(super) fn new() -> Self {
        FlipQueue {
            front: Vec::new(),
            buckets: (0..BUCKETS).map(|_| Vec::new()).collect(),
            full: 0,
            last: 0,
            frontier: 0,
            far: 0,
        }
    }

    /// Entries queued.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.front.len() + self.far
    }

    /// Queues `x`.
    pub(super) fn push(&mut self, x: T, ord: &mut impl Order<T>) {
        let k = key(x.lo());
        if k <= self.frontier {
            self.front.push(x);
            self.sift_up(self.front.len() - 1, ord);
        } else {
            self.file(x, k);
            self.far += 1;
        }
    }

    #[inline]
    fn file(&mut self, x: T, k: u64) {
        let b = bucket(k, self.last);
        self.buckets[b].push(x);
        self.full |= 1 << b;
    }

    /// The smallest key the buckets can hold now.
    fn far_bound(&self) -> u64 {
        bucket_floor(self.full.trailing_zeros() as usize, self.last)
    }

    /// The entry at the front of the binary heap: likely, not surely, the next popped.
    #[inline]
    pub(super) fn peek(&self) -> Option<&T> {
        self.front.first()
    }

    /// Removes and returns the earliest entry (of those kept).
    pub(super) fn pop(&mut self, ord: &mut impl Order<T>) -> Option<T> {
        loop {
            match self.front.first() {
                // Every far entry starts after this one ends: it is the earliest.
                Some(top) if self.far == 0 || key(top.hi()) < self.far_bound() => {
                    return self.pop_front(ord);
                }
                None if self.far == 0 => return None,
                _ => self.pull(ord),
            }
        }
    }

    /// Moves the far entries with the smallest key to the front.
    fn pull(&mut self, ord: &mut impl Order<T>) {
        let b = self.full.trailing_zeros() as usize;
        if b > 0 {
            // Refile the first full bucket against its smallest key: all of it goes
            // to lower buckets, its smallest keys to bucket 0.
            let mut list = std::mem::take(&mut self.buckets[b]);
            self.full &= !(1 << b);
            let before = list.len();
            list.retain(|x| ord.keep(x));
            self.far -= before - list.len();
            self.last = list.iter().map(|x| key(x.lo())).min().unwrap_or(self.last);
            for &x in &list {
                self.file(x, key(x.lo()));
            }
            // Keep the allocation for the bucket's next use.
            list.clear();
            if self.buckets[b].is_empty() {
                self.buckets[b] = list;
            }
        }
        let list = std::mem::take(&mut self.buckets[0]);
        self.full &= !1;
        self.far -= list.len();
        self.frontier = self.last;
        for &x in &list {
            if ord.keep(&x) {
                self.front.push(x);
                self.sift_up(self.front.len() - 1, ord);
            }
        }
        let mut list = list;
        list.clear();
        self.buckets[0] = list;
    }

    fn sift_up(&mut self, mut k: usize, ord: &mut impl Order<T>) {
        let x = self.front[k];
        while k > 0 {
            let parent = (k - 1) / 2;
            if !ord.earlier(&x, &self.front[parent]) {
                break;
            }
            self.front[k] = self.front[parent];
            k = parent;
        }
        self.front[k] = x;
    }

    /// Removes the root of the binary heap: the hole goes down along the earlier
    /// children to a leaf, and the last entry comes up from there.
    fn pop_front(&mut self, ord: &mut impl Order<T>) -> Option<T> {
        let top = *self.front.first()?;
        let last = self.front.pop()?;
        let n = self.front.len();
        if n == 0 {
            return Some(top);
        }
        let mut k = 0;
        loop {
            let l = 2 * k + 1;
            if l >= n {
                break;
            }
            let m = if l + 1 < n && ord.earlier(&self.front[l + 1], &self.front[l]) {
                l + 1
            } else {
                l
            };
            self.front[k] = self.front[m];
            k = m;
        }
        self.front[k] = last;
        self.sift_up(k, ord);
        Some(top)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::lcg;

    #[derive(Clone, Copy, Debug, PartialEq)]
    struct E {
        lo: f64,
        hi: f64,
        /// The exact priority (inside the interval), then the id breaks ties.
        t: f64,
        id: u32,
    }

    impl Interval for E {
        fn lo(&self) -> f64 {
            self.lo
        }
        fn hi(&self) -> f64 {
            self.hi
        }
    }

    /// The exact order, dropping the entries whose ids are in the set.
    struct ByTime(std::collections::HashSet<u32>);

    impl Order<E> for ByTime {
        fn earlier(&mut self, a: &E, b: &E) -> bool {
            (a.t, a.id) < (b.t, b.id)
        }
        fn keep(&mut self, x: &E) -> bool {
            !self.0.contains(&x.id)
        }
    }

    #[test]
    fn pops_in_the_exact_order_of_one_binary_heap() {
        let mut seed = 3u64;
        for round in 0..200 {
            let mut q = FlipQueue::new();
            // Entries go stale at random, as flips make events stale: the queue may
            // drop them on their way or pop them, and the caller skips them.
            let mut ord = ByTime(Default::default());
            let mut live: Vec<E> = Vec::new();
            let mut now = if round % 2 == 0 { 0.0 } else { -5.0 };
            let mut id = 0;
            let mut popped = 0;
            let pop_live = |q: &mut FlipQueue<E>, ord: &mut ByTime| loop {
                let got = q.pop(ord)?;
                if !ord.0.contains(&got.id) {
                    return Some(got);
                }
            };
            for step in 0..400 {
                // Pushes at or after the current time (a few before it, and some with
                // wide or unbounded intervals, as the flips' queue gets them).
                let pushes = (lcg(&mut seed) * 4.0) as usize;
                for _ in 0..pushes {
                    let r = lcg(&mut seed);
                    let t = if r < 0.05 {
                        now // a tie with the current time
                    } else if r < 0.1 {
                        now - lcg(&mut seed) // behind the current time
                    } else {
                        now + lcg(&mut seed).powi(3) * 10.0
                    };
                    let w = match (lcg(&mut seed) * 10.0) as u32 {
                        0 => f64::INFINITY,
                        1 => 0.5,
                        _ => t.abs() * 1e-14,
                    };
                    let (lo, hi) = if w.is_infinite() {
                        (f64::NEG_INFINITY, f64::INFINITY)
                    } else {
                        (t - w * lcg(&mut seed), t + w * lcg(&mut seed))
                    };
                    let e = E { lo, hi, t, id };
                    id += 1;
                    q.push(e, &mut ord);
                    live.push(e);
                }
                if !live.is_empty() && lcg(&mut seed) < 0.5 {
                    let k = (lcg(&mut seed) * live.len() as f64) as usize % live.len();
                    ord.0.insert(live.swap_remove(k).id);
                }
                if step % 3 != 0 || live.is_empty() {
                    continue;
                }
                let want = *live
                    .iter()
                    .min_by(|a, b| (a.t, a.id).partial_cmp(&(b.t, b.id)).unwrap())
                    .unwrap();
                let got = pop_live(&mut q, &mut ord).unwrap();
                assert_eq!(got, want, "round {round}, pop {popped}");
                live.retain(|e| e.id != got.id);
                now = now.max(got.t);
                popped += 1;
                assert!(q.len() >= live.len());
            }
            while let Some(got) = pop_live(&mut q, &mut ord) {
                let want = *live
                    .iter()
                    .min_by(|a, b| (a.t, a.id).partial_cmp(&(b.t, b.id)).unwrap())
                    .unwrap();
                assert_eq!(got, want);
                live.retain(|e| e.id != got.id);
            }
            assert!(live.is_empty());
            assert_eq!(q.len(), 0);
        }
    }
}
