//! Exact intersection tests between closed triangles, from the signs of `orient3d` and,
//! for coplanar configurations, of `orient2d` on a coordinate projection in which the
//! plane does not degenerate (an affine map, so every 2D sign is the true in-plane one).
//!
//! Triangles are given with their vertex ids (duplicate points already merged, so two
//! different ids never have equal coordinates). Sharing vertices is legitimate: two
//! triangles sharing one vertex may meet only there, two sharing an edge only along it.

use crate::geom::{orient3d, Point};

/// How two triangles meet, when they meet where they should not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Contact {
    /// An edge of one passes through the interior of the other.
    Crossing,
    /// They meet only on their boundaries (a vertex on the other, an edge touching), not
    /// at shared vertices or edges.
    Touching,
    /// They lie in one plane and overlap.
    Overlap,
    /// They have the same three vertices.
    Duplicate,
}

impl Contact {
    /// A short word for reports.
    pub fn name(self) -> &'static str {
        match self {
            Contact::Crossing => "crossing",
            Contact::Touching => "touching",
            Contact::Overlap => "coplanar overlap",
            Contact::Duplicate => "duplicate",
        }
    }
}

/// The sign of `orient3d` as -1, 0 or 1.
fn o3(a: &Point, b: &Point, c: &Point, d: &Point) -> i8 {
    // Four points in one axis-parallel plane (common in CAD models) are coplanar: a
    // shortcut past the exact stages, which an exactly zero determinant always reaches.
    if (0..3).any(|k| a[k] == b[k] && a[k] == c[k] && a[k] == d[k]) {
        return 0;
    }
    sign(orient3d(a, b, c, d))
}

fn sign(x: f64) -> i8 {
    (x > 0.0) as i8 - (x < 0.0) as i8
}

/// A coordinate projection: the two axes kept.
type Axes = (usize, usize);

/// The sign of `orient2d` of the projections of `a, b, c` on `ax`.
fn o2(a: &Point, b: &Point, c: &Point, ax: Axes) -> i8 {
    let p = |q: &Point| robust::Coord {
        x: q[ax.0],
        y: q[ax.1],
    };
    sign(robust::orient2d(p(a), p(b), p(c)))
}

/// A projection in which triangle `abc` keeps a nonzero area, if it is not degenerate.
fn axes_of(a: &Point, b: &Point, c: &Point) -> Option<Axes> {
    (0..3)
        .map(|k| ((k + 1) % 3, (k + 2) % 3))
        .find(|&ax| o2(a, b, c, ax) != 0)
}

/// Whether `r`, collinear with `p` and `q`, lies on the closed segment `pq`.
fn between(p: &Point, q: &Point, r: &Point) -> bool {
    (0..3).all(|k| p[k].min(q[k]) <= r[k] && r[k] <= p[k].max(q[k]))
}

/// Whether the closed segments `pq` and `rs`, in a plane that `ax` does not degenerate, meet.
fn seg_seg(p: &Point, q: &Point, r: &Point, s: &Point, ax: Axes) -> bool {
    let (d1, d2) = (o2(p, q, r, ax), o2(p, q, s, ax));
    let (d3, d4) = (o2(r, s, p, ax), o2(r, s, q, ax));
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    (d1 == 0 && between(p, q, r))
        || (d2 == 0 && between(p, q, s))
        || (d3 == 0 && between(r, s, p))
        || (d4 == 0 && between(r, s, q))
}

/// Whether `p`, in the plane of the non-degenerate triangle `t`, lies in the closed triangle.
fn point_in(p: &Point, t: &[Point; 3], ax: Axes) -> bool {
    let s = o2(&t[0], &t[1], &t[2], ax);
    (0..3).all(|k| o2(&t[k], &t[(k + 1) % 3], p, ax) * s >= 0)
}

/// Whether the closed segment `pq` meets the closed triangle `t`.
fn seg_tri(p: &Point, q: &Point, t: &[Point; 3]) -> bool {
    let (sp, sq) = (o3(&t[0], &t[1], &t[2], p), o3(&t[0], &t[1], &t[2], q));
    if sp * sq > 0 {
        return false;
    }
    let Some(ax) = axes_of(&t[0], &t[1], &t[2]) else {
        return false;
    };
    match (sp, sq) {
        (0, 0) => {
            point_in(p, t, ax)
                || point_in(q, t, ax)
                || (0..3).any(|k| seg_seg(p, q, &t[k], &t[(k + 1) % 3], ax))
        }
        (0, _) => point_in(p, t, ax),
        (_, 0) => point_in(q, t, ax),
        _ => {
            let s: [i8; 3] = std::array::from_fn(|k| o3(p, q, &t[k], &t[(k + 1) % 3]));
            !(s.contains(&1) && s.contains(&-1))
        }
    }
}

/// Whether the closed segment `pq` passes through the interior of `t`, crossing its plane.
fn seg_crosses_tri(p: &Point, q: &Point, t: &[Point; 3]) -> bool {
    let (sp, sq) = (o3(&t[0], &t[1], &t[2], p), o3(&t[0], &t[1], &t[2], q));
    if sp * sq >= 0 {
        return false;
    }
    let s: [i8; 3] = std::array::from_fn(|k| o3(p, q, &t[k], &t[(k + 1) % 3]));
    s == [1; 3] || s == [-1; 3]
}

/// Whether two coplanar closed triangles meet (`ax` keeps their plane non-degenerate).
fn coplanar_meet(t: &[Point; 3], u: &[Point; 3], ax: Axes) -> bool {
    (0..3).any(|i| (0..3).any(|j| seg_seg(&t[i], &t[(i + 1) % 3], &u[j], &u[(j + 1) % 3], ax)))
        || point_in(&u[0], t, ax)
        || point_in(&t[0], u, ax)
}

/// Whether the closed segment `pq` meets the closed triangle `t`, all in one plane.
fn seg_tri_2d(p: &Point, q: &Point, t: &[Point; 3], ax: Axes) -> bool {
    point_in(p, t, ax)
        || point_in(q, t, ax)
        || (0..3).any(|k| seg_seg(p, q, &t[k], &t[(k + 1) % 3], ax))
}

/// Whether `b`, in the plane of triangle `(v, e, f)`, lies in its closed angle at `v`.
fn in_angle(v: &Point, b: &Point, e: &Point, f: &Point, ax: Axes) -> bool {
    let s = o2(v, e, f, ax);
    o2(v, e, b, ax) * s >= 0 && o2(v, b, f, ax) * s >= 0
}

/// Whether ray `v → b` (without `v`) enters the closed triangle `(v, e, f)`: `b` is in its
/// plane and inside its angle at `v`.
fn ray_enters(v: &Point, b: &Point, e: &Point, f: &Point) -> bool {
    if o3(v, e, f, b) != 0 {
        return false;
    }
    axes_of(v, e, f).is_some_and(|ax| in_angle(v, b, e, f, ax))
}

/// Tests a segment (2-vertex polygon) against a triangle, by vertex ids and coordinates;
/// `None` when they meet only at a shared vertex, or the segment is an edge of it.
pub fn seg_contact(si: [u32; 2], s: [Point; 2], ti: [u32; 3], t: [Point; 3]) -> Option<Contact> {
    let at = |v: u32| ti.iter().position(|&x| x == v);
    match (at(si[0]), at(si[1])) {
        (Some(_), Some(_)) => None,
        (Some(i), None) | (None, Some(i)) => {
            let q = if at(si[0]).is_some() { s[1] } else { s[0] };
            let r = [t[i], t[(i + 1) % 3], t[(i + 2) % 3]];
            if !ray_enters(&r[0], &q, &r[1], &r[2]) {
                return None;
            }
            Some(Contact::Overlap)
        }
        (None, None) => {
            if !seg_tri(&s[0], &s[1], &t) {
                return None;
            }
            let coplanar = (0..2).all(|k| o3(&t[0], &t[1], &t[2], &s[k]) == 0);
            Some(if coplanar {
                Contact::Overlap
            } else if seg_crosses_tri(&s[0], &s[1], &t) {
                Contact::Crossing
            } else {
                Contact::Touching
            })
        }
    }
}

/// Whether point `p` lies on the closed triangle `t` (in its plane, inside or on its boundary).
pub fn point_on(p: &Point, t: &[Point; 3]) -> bool {
    o3(&t[0], &t[1], &t[2], p) == 0
        && axes_of(&t[0], &t[1], &t[2]).is_some_and(|ax| point_in(p, t, ax))
}

/// Tests two triangles given by vertex ids and coordinates; `None` when they meet only
/// at shared vertices or along a shared edge (or not at all).
pub fn contact(ti: [u32; 3], t: [Point; 3], ui: [u32; 3], u: [Point; 3]) -> Option<Contact> {
    // Shared vertices as (index in t, index in u); no allocation, this runs per pair.
    let mut shared = [None; 3];
    let mut n_shared = 0;
    for (i, a) in ti.iter().enumerate() {
        for (j, b) in ui.iter().enumerate() {
            if a == b && n_shared < 3 {
                shared[n_shared] = Some((i, j));
                n_shared += 1;
            }
        }
    }
    let meet = match n_shared {
        0 => {
            let s: [i8; 3] = std::array::from_fn(|k| o3(&t[0], &t[1], &t[2], &u[k]));
            if s == [1; 3] || s == [-1; 3] {
                return None;
            }
            let r: [i8; 3] = std::array::from_fn(|k| o3(&u[0], &u[1], &u[2], &t[k]));
            if r == [1; 3] || r == [-1; 3] {
                return None;
            }
            if s == [0; 3] {
                let ax = axes_of(&t[0], &t[1], &t[2])?;
                return coplanar_meet(&t, &u, ax).then_some(Contact::Overlap);
            }
            (0..3).any(|k| seg_tri(&t[k], &t[(k + 1) % 3], &u))
                || (0..3).any(|k| seg_tri(&u[k], &u[(k + 1) % 3], &t))
        }
        1 => {
            // Rotate both so that the shared vertex comes first.
            let (i, j) = shared[0].unwrap_or((0, 0));
            let t = [t[i], t[(i + 1) % 3], t[(i + 2) % 3]];
            let u = [u[j], u[(j + 1) % 3], u[(j + 2) % 3]];
            let v = t[0];
            // One triangle, but for the shared vertex, strictly on one side of the other's
            // plane: they meet only there. This settles most pairs with two tests.
            let (sb, sc) = (
                o3(&u[0], &u[1], &u[2], &t[1]),
                o3(&u[0], &u[1], &u[2], &t[2]),
            );
            if sb * sc > 0 {
                return None;
            }
            if sb == 0 && sc == 0 {
                // Coplanar: the same tests in 2D, without more exact 3D predicates.
                let ax = axes_of(&t[0], &t[1], &t[2])?;
                let meet = seg_tri_2d(&t[1], &t[2], &u, ax)
                    || seg_tri_2d(&u[1], &u[2], &t, ax)
                    || (1..3).any(|k| in_angle(&v, &t[k], &u[1], &u[2], ax))
                    || (1..3).any(|k| in_angle(&v, &u[k], &t[1], &t[2], ax));
                return meet.then_some(Contact::Overlap);
            }
            let (se, sf) = (
                o3(&t[0], &t[1], &t[2], &u[1]),
                o3(&t[0], &t[1], &t[2], &u[2]),
            );
            if se * sf > 0 {
                return None;
            }
            seg_tri(&t[1], &t[2], &u)
                || seg_tri(&u[1], &u[2], &t)
                || ray_enters(&v, &t[1], &u[1], &u[2])
                || ray_enters(&v, &t[2], &u[1], &u[2])
                || ray_enters(&v, &u[1], &t[1], &t[2])
                || ray_enters(&v, &u[2], &t[1], &t[2])
        }
        2 => {
            let (s0, s1) = (shared[0]?, shared[1]?);
            let c = t[(0..3).find(|&i| s0.0 != i && s1.0 != i)?];
            let f = u[(0..3).find(|&j| s0.1 != j && s1.1 != j)?];
            let (a, b) = (t[s0.0], t[s1.0]);
            if o3(&a, &b, &c, &f) != 0 {
                return None;
            }
            let ax = axes_of(&a, &b, &c)?;
            return (o2(&a, &b, &c, ax) * o2(&a, &b, &f, ax) > 0).then_some(Contact::Overlap);
        }
        _ => return Some(Contact::Duplicate),
    };
    if !meet {
        return None;
    }
    let coplanar = (0..3).all(|k| o3(&t[0], &t[1], &t[2], &u[k]) == 0);
    Some(if coplanar {
        Contact::Overlap
    } else if (0..3).any(|k| seg_crosses_tri(&t[k], &t[(k + 1) % 3], &u))
        || (0..3).any(|k| seg_crosses_tri(&u[k], &u[(k + 1) % 3], &t))
    {
        Contact::Crossing
    } else {
        Contact::Touching
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [u32; 3] = [0, 1, 2];
    const B: [u32; 3] = [3, 4, 5];
    /// The unit right triangle in the plane z = 0.
    const T: [Point; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    fn c(u: [Point; 3]) -> Option<Contact> {
        contact(A, T, B, u)
    }

    #[test]
    fn disjoint_and_crossing() {
        assert_eq!(c([[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]]), None);
        // A triangle through the interior of T.
        let x = [[0.2, 0.2, -1.0], [0.2, 0.2, 1.0], [3.0, 3.0, 0.5]];
        assert_eq!(c(x), Some(Contact::Crossing));
        // Passing beside T, through its plane.
        let y = [[2.0, 2.0, -1.0], [2.0, 2.0, 1.0], [3.0, 3.0, 0.5]];
        assert_eq!(c(y), None);
    }

    #[test]
    fn touching_at_a_point_or_edge() {
        // A vertex exactly on T's interior.
        let x = [[0.2, 0.2, 0.0], [0.2, 0.2, 1.0], [0.5, 0.0, 1.0]];
        assert_eq!(c(x), Some(Contact::Touching));
        // A vertex exactly on T's edge.
        let y = [[0.5, 0.0, 0.0], [0.5, -1.0, 1.0], [0.5, 1.0, 1.0]];
        assert_eq!(c(y), Some(Contact::Touching));
        // Exactly at T's vertex, but not sharing it by index.
        let z = [[1.0, 0.0, 0.0], [2.0, 0.0, 1.0], [2.0, 1.0, 1.0]];
        assert_eq!(c(z), Some(Contact::Touching));
    }

    #[test]
    fn coplanar_cases() {
        let over = [[0.2, 0.2, 0.0], [2.0, 0.2, 0.0], [0.2, 2.0, 0.0]];
        assert_eq!(c(over), Some(Contact::Overlap));
        let apart = [[2.0, 2.0, 0.0], [3.0, 2.0, 0.0], [2.0, 3.0, 0.0]];
        assert_eq!(c(apart), None);
        // T inside a big triangle: no edges meet, containment does.
        let big = [[-5.0, -5.0, 0.0], [10.0, -5.0, 0.0], [-5.0, 10.0, 0.0]];
        assert_eq!(c(big), Some(Contact::Overlap));
    }

    #[test]
    fn shared_vertex() {
        // Sharing vertex 0 only, the other one above: fine.
        let up = [T[0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]];
        assert_eq!(contact(A, T, [0, 4, 5], up), None);
        // Sharing vertex 0 and folding into T's plane, overlapping it.
        let fold = [T[0], [0.5, 0.1, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(contact(A, T, [0, 4, 5], fold), Some(Contact::Touching));
        // Sharing vertex 0 and piercing T elsewhere (camelhead's case).
        let pierce = [T[0], [0.4, 0.4, -1.0], [0.4, 0.4, 1.0]];
        assert_eq!(contact(A, T, [0, 4, 5], pierce), Some(Contact::Crossing));
        // Sharing vertex 0, coplanar, outside T's angle: fine.
        let beside = [T[0], [-1.0, 0.0, 0.0], [-1.0, -1.0, 0.0]];
        assert_eq!(contact(A, T, [0, 4, 5], beside), None);
    }

    /// On random triangles of a 3×3×3 grid (so that degenerate contacts abound), the
    /// verdict does not depend on the order of the two triangles, on the rotation or the
    /// orientation of either, and the kind is the same both ways.
    #[test]
    fn verdict_is_symmetric_and_order_free() {
        let mut s = 7u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 33) as u32 % 27
        };
        let pt = |i: u32| [(i % 3) as f64, (i / 3 % 3) as f64, (i / 9) as f64];
        let mut seen = [0usize; 5];
        for _ in 0..20000 {
            let t = [next(), next(), next()];
            let u = [next(), next(), next()];
            let tp = t.map(pt);
            let up = u.map(pt);
            if axes_of(&tp[0], &tp[1], &tp[2]).is_none()
                || axes_of(&up[0], &up[1], &up[2]).is_none()
            {
                continue;
            }
            let c = contact(t, tp, u, up);
            seen[c.map_or(4, |k| k as usize)] += 1;
            assert_eq!(contact(u, up, t, tp), c, "{t:?} {u:?}");
            let rot = |a: [u32; 3]| [a[1], a[2], a[0]];
            let rev = |a: [u32; 3]| [a[0], a[2], a[1]];
            for (t2, u2) in [(rot(t), u), (t, rev(u)), (rev(rot(t)), rot(rot(u)))] {
                assert_eq!(contact(t2, t2.map(pt), u2, u2.map(pt)), c, "{t:?} {u:?}");
            }
        }
        // Every kind of contact occurred, and so did no contact.
        assert!(seen.iter().all(|&k| k > 0), "{seen:?}");
    }

    #[test]
    fn segments_against_a_triangle() {
        let s = |a: [f64; 3], b: [f64; 3]| [a, b];
        // Through the interior, beside it, ending on it, lying in it.
        let through = s([0.2, 0.2, -1.0], [0.2, 0.2, 1.0]);
        assert_eq!(seg_contact([7, 8], through, A, T), Some(Contact::Crossing));
        let beside = s([2.0, 2.0, -1.0], [2.0, 2.0, 1.0]);
        assert_eq!(seg_contact([7, 8], beside, A, T), None);
        let ending = s([0.2, 0.2, 0.0], [0.2, 0.2, 1.0]);
        assert_eq!(seg_contact([7, 8], ending, A, T), Some(Contact::Touching));
        let inside = s([0.1, 0.1, 0.0], [0.3, 0.1, 0.0]);
        assert_eq!(seg_contact([7, 8], inside, A, T), Some(Contact::Overlap));
        // From a vertex of T: upwards is fine, along T's plane into T is not.
        assert_eq!(seg_contact([0, 8], s(T[0], [0.0, 0.0, 1.0]), A, T), None);
        assert_eq!(
            seg_contact([0, 8], s(T[0], [0.2, 0.2, 0.0]), A, T),
            Some(Contact::Overlap)
        );
        assert_eq!(seg_contact([0, 1], s(T[0], T[1]), A, T), None);
    }

    #[test]
    fn shared_edge() {
        let hinge = [T[0], T[1], [0.5, -1.0, 0.5]];
        assert_eq!(contact(A, T, [0, 1, 5], hinge), None);
        let flat_other_side = [T[1], T[0], [0.5, -1.0, 0.0]];
        assert_eq!(contact(A, T, [1, 0, 5], flat_other_side), None);
        let folded = [T[0], T[1], [0.5, 0.5, 0.0]];
        assert_eq!(contact(A, T, [0, 1, 5], folded), Some(Contact::Overlap));
        assert_eq!(
            contact(A, T, [2, 0, 1], [T[2], T[0], T[1]]),
            Some(Contact::Duplicate)
        );
    }
}
