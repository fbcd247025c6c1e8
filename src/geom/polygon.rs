//! Polygons in space: Newell normals, ring clean-up, and exact tests in a polygon's
//! projection along its dominant normal axis. Shared by the PLC's preparation, the checks
//! before meshing and the certifier, so that all three see a polygon the same way.

use super::Point;
use rustc_hash::FxHashMap;

/// Drops repeated consecutive vertices, also across the wrap.
pub fn dedup_ring(poly: &[u32]) -> Vec<u32> {
    without_repeats(poly.iter().copied())
}

/// The ring `vs` without repeated consecutive vertices, also across the wrap.
fn without_repeats(vs: impl ExactSizeIterator<Item = u32>) -> Vec<u32> {
    let mut out: Vec<u32> = Vec::with_capacity(vs.len());
    for v in vs {
        if out.last() != Some(&v) {
            out.push(v);
        }
    }
    while out.len() > 1 && out[0] == out[out.len() - 1] {
        out.pop();
    }
    out
}

/// Newell's normal of a polygon (not normalized): twice its vector area.
pub fn newell_normal(points: &[Point], ring: &[u32]) -> Point {
    let mut n = [0.0f64; 3];
    for i in 0..ring.len() {
        let a = points[ring[i] as usize];
        let b = points[ring[(i + 1) % ring.len()] as usize];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    n
}

/// Exact test: are all vertices of the ring on one line? (All three axis projections
/// have zero orientation for every vertex against the first two distinct ones.)
pub fn all_collinear(points: &[Point], ring: &[u32]) -> bool {
    let p0 = points[ring[0] as usize];
    let Some(p1) = ring.iter().map(|&v| points[v as usize]).find(|p| *p != p0) else {
        return true;
    };
    ring.iter().all(|&v| {
        let q = points[v as usize];
        (0..3).all(|k| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let c = |p: Point| robust::Coord { x: p[i], y: p[j] };
            robust::orient2d(c(p0), c(p1), c(q)) == 0.0
        })
    })
}

/// The projection of a (nearly) planar polygon onto the coordinate plane of the two axes
/// other than its normal's largest component: the projection that keeps the polygon's
/// area largest, and in which every decision about it is made exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Projection {
    /// The first kept axis.
    pub u: usize,
    /// The second kept axis.
    pub w: usize,
    /// Whether the normal's largest component is negative: orientations are flipped so
    /// that counterclockwise always means counterclockwise seen from the normal's side.
    flip: bool,
}

impl Projection {
    /// The projection along `normal`'s largest component.
    pub fn along(normal: &Point) -> Self {
        let axis = (0..3)
            .max_by(|&a, &b| normal[a].abs().total_cmp(&normal[b].abs()))
            .unwrap_or(2);
        Projection {
            u: (axis + 1) % 3,
            w: (axis + 2) % 3,
            flip: normal[axis] < 0.0,
        }
    }

    /// The dropped axis.
    pub fn axis(&self) -> usize {
        3 - self.u - self.w
    }

    /// The projected point.
    #[inline]
    pub fn project(&self, p: &Point) -> [f64; 2] {
        [p[self.u], p[self.w]]
    }

    /// The exact orientation of the projections of `a`, `b`, `c`: positive when they turn
    /// counterclockwise seen from the normal's side.
    #[inline]
    pub fn orient(&self, a: &Point, b: &Point, c: &Point) -> f64 {
        let co = |q: &Point| robust::Coord {
            x: q[self.u],
            y: q[self.w],
        };
        let o = robust::orient2d(co(a), co(b), co(c));
        if self.flip {
            -o
        } else {
            o
        }
    }

    /// Where `q`'s projection lies relative to the projection of `ring` (a closed
    /// polygon, any orientation), decided exactly.
    pub fn locate_in_ring(&self, points: &[Point], ring: &[u32], q: &Point) -> RingSide {
        let [qx, qy] = self.project(q);
        // Winding number by upward and downward crossings of the horizontal ray from q;
        // an edge through q puts it on the boundary.
        let mut winding = 0i32;
        for k in 0..ring.len() {
            let a = &points[ring[k] as usize];
            let b = &points[ring[(k + 1) % ring.len()] as usize];
            let (ay, by) = (a[self.w], b[self.w]);
            let o = {
                let co = |p: &Point| robust::Coord {
                    x: p[self.u],
                    y: p[self.w],
                };
                robust::orient2d(co(a), co(b), robust::Coord { x: qx, y: qy })
            };
            if o == 0.0 {
                let within = |lo: f64, hi: f64, x: f64| lo.min(hi) <= x && x <= lo.max(hi);
                if within(a[self.u], b[self.u], qx) && within(ay, by, qy) {
                    return RingSide::Boundary;
                }
            }
            if ay <= qy {
                if by > qy && o > 0.0 {
                    winding += 1;
                }
            } else if by <= qy && o < 0.0 {
                winding -= 1;
            }
        }
        if winding != 0 {
            RingSide::Inside
        } else {
            RingSide::Outside
        }
    }
}

/// Which of `rings` (one facet's polygons, seen in `proj`) bound holes: for each hole
/// point, the smallest ring (by area) that holds it strictly inside.
pub fn hole_rings(
    points: &[Point],
    rings: &[Vec<u32>],
    holes: &[Point],
    proj: &Projection,
) -> Vec<bool> {
    let mut hole = vec![false; rings.len()];
    let area = |r: &Vec<u32>| super::norm(&newell_normal(points, r));
    for h in holes {
        let smallest = rings
            .iter()
            .enumerate()
            .filter(|(_, r)| r.len() >= 3 && proj.locate_in_ring(points, r, h) == RingSide::Inside)
            .min_by(|a, b| area(a.1).total_cmp(&area(b.1)));
        if let Some((k, _)) = smallest {
            hole[k] = true;
        }
    }
    hole
}

/// Where a point lies relative to a polygon in projection.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RingSide {
    /// Strictly inside (a nonzero winding number).
    Inside,
    /// On one of its edges.
    Boundary,
    /// Strictly outside.
    Outside,
}

/// For each point, the lowest-indexed point with exactly equal coordinates.
pub fn representatives(points: &[Point]) -> Vec<u32> {
    let mut first: FxHashMap<[u64; 3], u32> = FxHashMap::default();
    first.reserve(points.len());
    points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            // Adding 0.0 turns -0.0 into 0.0, which compares equal to it.
            *first
                .entry(p.map(|v| (v + 0.0).to_bits()))
                .or_insert(i as u32)
        })
        .collect()
}

/// Polygon `poly` with its vertices replaced by their representatives `rep`, without
/// repeated consecutive vertices (also across the wrap).
pub fn clean_ring(poly: &[u32], rep: &[u32]) -> Vec<u32> {
    without_repeats(poly.iter().map(|&v| rep[v as usize]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_located_exactly_in_a_projected_ring() {
        // An L-shaped ring in the plane z = x (tilted), seen along its normal.
        let pts: Vec<Point> = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ]
        .iter()
        .map(|&[x, y]| [x, y, 0.5 * x])
        .collect();
        let ring: Vec<u32> = (0..6).collect();
        let proj = Projection::along(&newell_normal(&pts, &ring));
        assert_eq!(proj.axis(), 2);
        let at = |x: f64, y: f64| proj.locate_in_ring(&pts, &ring, &[x, y, 0.0]);
        assert_eq!(at(0.5, 0.5), RingSide::Inside);
        assert_eq!(at(1.5, 1.5), RingSide::Outside);
        assert_eq!(at(1.0, 1.5), RingSide::Boundary);
        assert_eq!(at(2.0, 0.0), RingSide::Boundary);
        assert_eq!(at(-1e-300, 1.0), RingSide::Outside);
        // Reversed, the ring gives the same answers.
        let rev: Vec<u32> = ring.iter().rev().copied().collect();
        assert_eq!(
            proj.locate_in_ring(&pts, &rev, &[0.5, 0.5, 0.0]),
            RingSide::Inside
        );
    }

    #[test]
    fn orientation_is_counterclockwise_seen_from_the_normal() {
        let pts: Vec<Point> = vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]];
        let ring = [0, 1, 2];
        let n = newell_normal(&pts, &ring);
        assert!(n[2] < 0.0);
        let proj = Projection::along(&n);
        assert!(proj.orient(&pts[0], &pts[1], &pts[2]) > 0.0);
    }
}
