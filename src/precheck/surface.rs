//! The triangles of every input facet, for the intersection check: each facet is
//! triangulated on its own (no merging), by the same 2D CDT the mesher uses, so a
//! facet's triangles cover exactly its polygons minus its holes.

use crate::geom::facet2d::triangulate_facet;
use crate::geom::polygon::{clean_ring, newell_normal};
use crate::plc::Plc;

/// One triangle of an input facet, with representative vertex ids.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SurfaceTri {
    /// Vertices (0-based representatives: coincident points share one id).
    pub v: [u32; 3],
    /// The input facet (0-based).
    pub facet: u32,
}

/// The triangles, and the facets that could not be triangulated (with the reason).
#[derive(Clone, Debug, Default)]
pub struct Surface {
    /// Triangles of all facets, facet by facet.
    pub tris: Vec<SurfaceTri>,
    /// 2-vertex polygons (segments floating in a facet): vertices and facet.
    pub segments: Vec<([u32; 2], u32)>,
    /// Facets left out of the check: (0-based facet, why).
    pub skipped: Vec<(usize, String)>,
}

/// Triangulates every facet of `plc` (indices already checked against the points).
pub fn triangulate(plc: &Plc, rep: &[u32]) -> Surface {
    let mut s = Surface::default();
    // Perturbation indices are the input indices, as in the mesher.
    let mut pert: Vec<u32> = Vec::new();
    for (fi, f) in plc.facets.iter().enumerate() {
        let polys: Vec<Vec<u32>> = f
            .polygons
            .iter()
            .map(|p| clean_ring(p, rep))
            .filter(|p| !p.is_empty())
            .collect();
        for p in polys.iter().filter(|p| p.len() == 2) {
            s.segments.push(([p[0], p[1]], fi as u32));
        }
        let rings = polys.iter().filter(|p| p.len() >= 3).count();
        if rings == 0 {
            continue;
        }
        // The common case (triangle soups): one triangle is its own triangulation.
        if polys.len() == 1 && polys[0].len() == 3 && f.holes.is_empty() {
            let p = &polys[0];
            s.tris.push(SurfaceTri {
                v: [p[0], p[1], p[2]],
                facet: fi as u32,
            });
            continue;
        }
        if polys.len() == 1 && polys[0].len() == 4 && f.holes.is_empty() {
            if let Some(pair) = split_quad(&plc.points, &polys[0]) {
                s.tris.extend(pair.map(|v| SurfaceTri {
                    v,
                    facet: fi as u32,
                }));
                continue;
            }
        }
        if pert.is_empty() {
            pert = (0..plc.points.len() as u32).collect();
        }
        let mut verts = Vec::new();
        let mut cons = Vec::new();
        let mut normal = [0.0; 3];
        let mut best = 0.0f64;
        for p in &polys {
            verts.extend_from_slice(p);
            match p.len() {
                1 => {}
                2 => cons.push([p[0], p[1]]),
                m => {
                    cons.extend((0..m).map(|k| [p[k], p[(k + 1) % m]]));
                    let n = newell_normal(&plc.points, p);
                    let l = n.iter().map(|x| x * x).sum::<f64>();
                    if l > best {
                        best = l;
                        normal = n;
                    }
                }
            }
        }
        match triangulate_facet(&plc.points, &pert, &verts, &cons, &f.holes, normal) {
            Ok(tris) => s.tris.extend(tris.into_iter().map(|v| SurfaceTri {
                v,
                facet: fi as u32,
            })),
            Err(e) => s.skipped.push((fi, e)),
        }
    }
    s
}

/// The two triangles of a quad that is simple in the projection along its normal's
/// largest component (split at its reflex corner, if any); `None` for a bow tie or a
/// degenerate quad, which go to the general triangulation.
fn split_quad(points: &[[f64; 3]], q: &[u32]) -> Option<[[u32; 3]; 2]> {
    let n = newell_normal(points, q);
    let k = (0..3).max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs()))?;
    let (ax, ay) = ((k + 1) % 3, (k + 2) % 3);
    let c = |v: u32| robust::Coord {
        x: points[v as usize][ax],
        y: points[v as usize][ay],
    };
    let turn: Vec<f64> = (0..4)
        .map(|i| robust::orient2d(c(q[(i + 3) % 4]), c(q[i]), c(q[(i + 1) % 4])))
        .collect();
    let pos = turn.iter().filter(|&&t| t > 0.0).count();
    let neg = turn.iter().filter(|&&t| t < 0.0).count();
    // The corner to split from: any corner of a convex quad, the reflex one otherwise.
    let from = match (pos, neg) {
        (4, 0) | (0, 4) => 0,
        (3, 1) => turn.iter().position(|&t| t < 0.0)?,
        (1, 3) => turn.iter().position(|&t| t > 0.0)?,
        _ => return None,
    };
    let r = |i: usize| q[(from + i) % 4];
    Some([[r(0), r(1), r(2)], [r(0), r(2), r(3)]])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quads_split_at_their_reflex_corner() {
        let pts = [
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 0.5, 0.0], // reflex
            [0.0, 2.0, 0.0],
        ];
        assert_eq!(
            split_quad(&pts, &[0, 1, 2, 4]),
            Some([[0, 1, 2], [0, 2, 4]])
        );
        assert_eq!(
            split_quad(&pts, &[0, 1, 2, 3]).map(|t| t[0][0]),
            Some(3),
            "a dart is split from its reflex corner"
        );
        // A bow tie is left to the general triangulation (which rejects it).
        assert_eq!(split_quad(&pts, &[0, 2, 1, 4]), None);
    }
}
