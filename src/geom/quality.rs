//! Shape measures of a tet: circumcentre, radius-edge ratio, dihedral angles, volume.
//! Inexact (rounded) constructions: they place refinement points and judge shapes, they
//! never decide topology.

use super::{cross, dot, norm, sub, Point};

/// The circumcentre of tet `p` (rounded); `None` for a flat tet.
pub fn circumcenter(p: &[Point; 4]) -> Option<Point> {
    let (b, c, d) = (sub(&p[1], &p[0]), sub(&p[2], &p[0]), sub(&p[3], &p[0]));
    let (cd, db, bc) = (cross(&c, &d), cross(&d, &b), cross(&b, &c));
    let den = 2.0 * dot(&b, &cd);
    if den == 0.0 || !den.is_finite() {
        return None;
    }
    let (bb, cc, dd) = (dot(&b, &b), dot(&c, &c), dot(&d, &d));
    let o: Point = std::array::from_fn(|k| p[0][k] + (bb * cd[k] + cc * db[k] + dd * bc[k]) / den);
    o.iter().all(|x| x.is_finite()).then_some(o)
}

/// The length of the shortest edge of tet `p`.
pub fn shortest_edge(p: &[Point; 4]) -> f64 {
    let mut l = f64::INFINITY;
    for i in 0..4 {
        for j in i + 1..4 {
            l = l.min(norm(&sub(&p[i], &p[j])));
        }
    }
    l
}

/// The volume of tet `p` (positive when `p[3]` lies on the negative side of `p[0..3]`,
/// as the orientation of the mesh's tets has it; the absolute value is the volume).
pub fn volume(p: &[Point; 4]) -> f64 {
    let (b, c, d) = (sub(&p[1], &p[0]), sub(&p[2], &p[0]), sub(&p[3], &p[0]));
    dot(&b, &cross(&c, &d)).abs() / 6.0
}

/// The circumradius of tet `p` over its shortest edge (infinite for a flat tet); a
/// regular tet has the smallest, `sqrt(6)/4`.
pub fn radius_edge_ratio(p: &[Point; 4]) -> f64 {
    match circumcenter(p) {
        Some(o) => norm(&sub(&o, &p[0])) / shortest_edge(p),
        None => f64::INFINITY,
    }
}

/// The six dihedral angles of tet `p`, in degrees, at edges 01, 02, 03, 12, 13, 23
/// (0 or 180 for a flat tet).
pub fn dihedral_angles(p: &[Point; 4]) -> [f64; 6] {
    // The normal of the face opposite vertex k, pointing away from vertex k.
    let normal = |k: usize| {
        let f: Vec<usize> = (0..4).filter(|&i| i != k).collect();
        let n = cross(&sub(&p[f[1]], &p[f[0]]), &sub(&p[f[2]], &p[f[0]]));
        if dot(&n, &sub(&p[k], &p[f[0]])) > 0.0 {
            n.map(|x| -x)
        } else {
            n
        }
    };
    let n: [Point; 4] = std::array::from_fn(normal);
    let mut out = [0.0; 6];
    let mut e = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            // The faces through edge i-j are those opposite the other two vertices.
            let (k, l) = match (0..4).filter(|&x| x != i && x != j).collect::<Vec<_>>()[..] {
                [k, l] => (k, l),
                _ => unreachable!(),
            };
            let den = norm(&n[k]) * norm(&n[l]);
            let cos = if den > 0.0 {
                (-dot(&n[k], &n[l]) / den).clamp(-1.0, 1.0)
            } else {
                1.0
            };
            out[e] = cos.acos().to_degrees();
            e += 1;
        }
    }
    out
}

/// The smallest and the largest dihedral angle of tet `p`, in degrees.
pub fn dihedral_range(p: &[Point; 4]) -> (f64, f64) {
    dihedral_angles(p)
        .iter()
        .fold((180.0f64, 0.0f64), |(lo, hi), &a| (lo.min(a), hi.max(a)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn regular() -> [Point; 4] {
        [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ]
    }

    #[test]
    fn a_regular_tet_has_the_known_measures() {
        let p = regular();
        let o = circumcenter(&p).unwrap();
        assert!(o.iter().all(|x| x.abs() < 1e-15));
        assert!((radius_edge_ratio(&p) - 6f64.sqrt() / 4.0).abs() < 1e-12);
        let want = (1.0f64 / 3.0).acos().to_degrees();
        for a in dihedral_angles(&p) {
            assert!((a - want).abs() < 1e-9, "{a}");
        }
        // Edge length 2*sqrt(2): volume a^3 / (6 sqrt 2).
        let a = 8f64.sqrt();
        assert!((volume(&p) - a.powi(3) / (6.0 * 2f64.sqrt())).abs() < 1e-12);
    }

    #[test]
    fn a_corner_tet_has_right_angles_and_a_sliver_small_ones() {
        let p = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let d = dihedral_angles(&p);
        // At the edges through the corner: 90 degrees.
        assert!(d[..3].iter().all(|a| (a - 90.0).abs() < 1e-9), "{d:?}");
        // Four points almost on a circle: a sliver, near 0 and 180 degrees.
        let s = [
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.01],
            [0.0, -1.0, 0.01],
        ];
        let (lo, hi) = dihedral_range(&s);
        assert!(lo < 2.0 && hi > 178.0, "{lo} {hi}");
        assert!(radius_edge_ratio(&s) < 1.0);
        assert_eq!(circumcenter(&[[0.0; 3]; 4]), None);
        assert_eq!(radius_edge_ratio(&[[0.0; 3]; 4]), f64::INFINITY);
    }
}
