//! A bounding-volume hierarchy over boxes, for finding the pairs of boxes that overlap
//! in O(n log n + pairs) time instead of testing every pair.

/// An axis-aligned box `[lo, hi]` (closed: boxes that touch overlap).
pub type Aabb = [[f64; 3]; 2];

/// Whether two closed boxes overlap.
fn overlap(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|k| a[0][k] <= b[1][k] && b[0][k] <= a[1][k])
}

fn union(a: &Aabb, b: &Aabb) -> Aabb {
    [
        std::array::from_fn(|k| a[0][k].min(b[0][k])),
        std::array::from_fn(|k| a[1][k].max(b[1][k])),
    ]
}

/// Boxes in a leaf.
const LEAF: usize = 4;

/// One node: its box and either two children or a range of `order`.
struct Node {
    bbox: Aabb,
    /// Children (`left`, `right`) of an inner node, or the range `start..end` of a leaf.
    a: u32,
    b: u32,
    leaf: bool,
}

/// The hierarchy.
pub struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

impl Bvh {
    /// Builds the hierarchy of `boxes` (median splits along the longest axis of the centres).
    pub fn build(boxes: &[Aabb]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(2 * boxes.len() / LEAF + 1),
            order: (0..boxes.len() as u32).collect(),
        };
        if !boxes.is_empty() {
            let n = boxes.len();
            bvh.build_range(boxes, 0, n);
        }
        bvh
    }

    /// Builds the node of `order[start..end]` and returns its index.
    fn build_range(&mut self, boxes: &[Aabb], start: usize, end: usize) -> u32 {
        let bbox = self.order[start..end]
            .iter()
            .map(|&i| boxes[i as usize])
            .reduce(|a, b| union(&a, &b))
            .unwrap_or([[0.0; 3]; 2]);
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            bbox,
            a: start as u32,
            b: end as u32,
            leaf: true,
        });
        if end - start <= LEAF {
            return id;
        }
        let centre = |i: u32| -> [f64; 3] {
            let b = &boxes[i as usize];
            std::array::from_fn(|k| 0.5 * b[0][k] + 0.5 * b[1][k])
        };
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for &i in &self.order[start..end] {
            let c = centre(i);
            for k in 0..3 {
                lo[k] = lo[k].min(c[k]);
                hi[k] = hi[k].max(c[k]);
            }
        }
        let axis = (0..3)
            .max_by(|&x, &y| (hi[x] - lo[x]).total_cmp(&(hi[y] - lo[y])))
            .unwrap_or(0);
        let mid = (start + end) / 2;
        self.order[start..end].select_nth_unstable_by(mid - start, |&x, &y| {
            centre(x)[axis].total_cmp(&centre(y)[axis])
        });
        let left = self.build_range(boxes, start, mid);
        let right = self.build_range(boxes, mid, end);
        let node = &mut self.nodes[id as usize];
        node.a = left;
        node.b = right;
        node.leaf = false;
        id
    }

    /// Calls `f(i)` for every box `i` that overlaps `b`.
    pub fn query(&self, boxes: &[Aabb], b: &Aabb, mut f: impl FnMut(usize)) {
        let mut stack: Vec<u32> = if self.nodes.is_empty() {
            vec![]
        } else {
            vec![0]
        };
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n as usize];
            if !overlap(&node.bbox, b) {
                continue;
            }
            if node.leaf {
                for &i in &self.order[node.a as usize..node.b as usize] {
                    if overlap(&boxes[i as usize], b) {
                        f(i as usize);
                    }
                }
            } else {
                stack.push(node.a);
                stack.push(node.b);
            }
        }
    }

    /// Calls `f(i, j)` with `i < j` for every pair of boxes that overlap, once each: a
    /// simultaneous descent of the tree against itself, pruning node pairs whose boxes
    /// are apart.
    pub fn overlapping_pairs(&self, boxes: &[Aabb], mut f: impl FnMut(usize, usize)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack: Vec<(u32, u32)> = vec![(0, 0)];
        let mut emit = |i: u32, j: u32| {
            let (i, j) = (i.min(j) as usize, i.max(j) as usize);
            if overlap(&boxes[i], &boxes[j]) {
                f(i, j);
            }
        };
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
            if a == b {
                if na.leaf {
                    let items = &self.order[na.a as usize..na.b as usize];
                    for (k, &i) in items.iter().enumerate() {
                        for &j in &items[k + 1..] {
                            emit(i, j);
                        }
                    }
                } else {
                    stack.push((na.a, na.a));
                    stack.push((na.b, na.b));
                    stack.push((na.a, na.b));
                }
                continue;
            }
            if !overlap(&na.bbox, &nb.bbox) {
                continue;
            }
            match (na.leaf, nb.leaf) {
                (true, true) => {
                    for &i in &self.order[na.a as usize..na.b as usize] {
                        for &j in &self.order[nb.a as usize..nb.b as usize] {
                            emit(i, j);
                        }
                    }
                }
                // Descend the inner node, or the larger one when both are inner.
                (false, true) => {
                    stack.push((na.a, b));
                    stack.push((na.b, b));
                }
                (true, false) => {
                    stack.push((a, nb.a));
                    stack.push((a, nb.b));
                }
                (false, false) => {
                    if volume(&na.bbox) >= volume(&nb.bbox) {
                        stack.push((na.a, b));
                        stack.push((na.b, b));
                    } else {
                        stack.push((a, nb.a));
                        stack.push((a, nb.b));
                    }
                }
            }
        }
    }
}

/// A box's size for choosing which node to descend (the sum of its extents, which
/// unlike the volume does not vanish for flat boxes).
fn volume(b: &Aabb) -> f64 {
    (0..3).map(|k| b[1][k] - b[0][k]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_equal_brute_force() {
        // Boxes of a pseudo-random walk, some touching exactly.
        let mut s = 12345u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) % 64) as f64
        };
        let boxes: Vec<Aabb> = (0..300)
            .map(|_| {
                let lo = [next(), next(), next()];
                let d = [next() / 8.0, next() / 8.0, next() / 8.0];
                [lo, std::array::from_fn(|k| lo[k] + d[k])]
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let mut got = Vec::new();
        bvh.overlapping_pairs(&boxes, |i, j| got.push((i, j)));
        got.sort_unstable();
        let mut want = Vec::new();
        for i in 0..boxes.len() {
            for j in i + 1..boxes.len() {
                if overlap(&boxes[i], &boxes[j]) {
                    want.push((i, j));
                }
            }
        }
        assert!(!want.is_empty());
        assert_eq!(got, want);
        for (i, b) in boxes.iter().enumerate().step_by(7) {
            let mut got = Vec::new();
            bvh.query(&boxes, b, |j| got.push(j));
            got.sort_unstable();
            let want: Vec<usize> = (0..boxes.len())
                .filter(|&j| overlap(b, &boxes[j]))
                .collect();
            assert!(want.contains(&i));
            assert_eq!(got, want);
        }
    }
}
