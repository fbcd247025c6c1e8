//! Does the PLC enclose any volume? A cheap topological answer before meshing.
//!
//! The bounded components of the complement of a 2-complex in space correspond to its
//! 2-cycles (mod 2, by Alexander duality). A facet with an edge that no other facet
//! shares cannot belong to any 2-cycle, so peeling such facets until none is left
//! proves the meshed domain empty: an open surface, which TetGen carves away entirely.
//! The answer is only "certainly empty" or "maybe not"; the second case is decided by
//! meshing and carving.

use crate::plc::prepare::PreparedPlc;
use crate::plc::Plc;
use rustc_hash::FxHashMap;

/// The boundary edges (input indices) of a PLC that certainly encloses no volume, or
/// `None` if it may enclose some.
pub fn open_boundary(plc: &Plc, prep: &PreparedPlc) -> Option<Vec<[u32; 2]>> {
    // The mod-2 boundary of each merged facet: its rings tile it when every input facet
    // in it is a single polygon. A facet with several rings of one input facet may nest
    // them (a polygon drawn inside another), so it is never peeled.
    let mut boundary: Vec<Vec<(u32, u32)>> = Vec::with_capacity(prep.facets.len());
    let mut peelable = Vec::with_capacity(prep.facets.len());
    for f in &prep.facets {
        let single = f.source_facets.iter().all(|&s| {
            plc.facets[s]
                .polygons
                .iter()
                .filter(|p| p.len() >= 3)
                .count()
                <= 1
        });
        let mut odd: FxHashMap<(u32, u32), bool> = FxHashMap::default();
        for ring in &f.rings {
            for k in 0..ring.len() {
                let (a, b) = (ring[k], ring[(k + 1) % ring.len()]);
                let e = (a.min(b), a.max(b));
                let slot = odd.entry(e).or_insert(false);
                *slot = !*slot;
            }
        }
        let mut edges: Vec<(u32, u32)> = odd.into_iter().filter(|e| e.1).map(|e| e.0).collect();
        edges.sort_unstable();
        boundary.push(edges);
        peelable.push(single && !f.rings.is_empty());
    }
    let mut degree: FxHashMap<(u32, u32), u32> = FxHashMap::default();
    let mut alive = 0usize;
    for (i, edges) in boundary.iter().enumerate() {
        if f_alive(&prep.facets[i]) {
            alive += 1;
            for &e in edges {
                *degree.entry(e).or_default() += 1;
            }
        }
    }
    if alive == 0 {
        return None; // a point set or segments only: not a surface question
    }
    let mut open: Vec<[u32; 2]> = degree
        .iter()
        .filter(|(_, &d)| d == 1)
        .map(|(&(a, b), _)| [a, b])
        .collect();
    if open.is_empty() {
        return None;
    }
    open.sort_unstable();
    let mut by_edge: FxHashMap<(u32, u32), Vec<usize>> = FxHashMap::default();
    for (i, edges) in boundary.iter().enumerate() {
        for &e in edges {
            by_edge.entry(e).or_default().push(i);
        }
    }
    let mut live: Vec<bool> = prep.facets.iter().map(f_alive).collect();
    let mut stack: Vec<(u32, u32)> = degree
        .iter()
        .filter(|(_, &d)| d == 1)
        .map(|(&e, _)| e)
        .collect();
    while let Some(e) = stack.pop() {
        let Some(&f) = by_edge[&e].iter().find(|&&f| live[f]) else {
            continue;
        };
        if !peelable[f] {
            return None;
        }
        live[f] = false;
        alive -= 1;
        for &g in &boundary[f] {
            let d = degree
                .get_mut(&g)
                .expect("every boundary edge has a degree");
            *d -= 1;
            if *d == 1 {
                stack.push(g);
            }
        }
    }
    (alive == 0).then_some(open)
}

/// Facets that take part: those with at least one ring.
fn f_alive(f: &crate::plc::prepare::MergedFacet) -> bool {
    !f.rings.is_empty()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plc::prepare::prepare;
    use crate::plc::Facet;

    fn cube(drop_top: bool, inner_polygon: bool) -> Plc {
        let points: Vec<[f64; 3]> = (0..8)
            .map(|i| [(i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64])
            .chain([[0.25, 0.25, 1.0], [0.75, 0.25, 1.0], [0.5, 0.75, 1.0]])
            .collect();
        let quads = [
            vec![0, 2, 3, 1],
            vec![4, 5, 7, 6],
            vec![0, 1, 5, 4],
            vec![2, 6, 7, 3],
            vec![0, 4, 6, 2],
            vec![1, 3, 7, 5],
        ];
        let facets = quads
            .iter()
            .enumerate()
            .filter(|(i, _)| !(drop_top && *i == 1))
            .map(|(i, q)| {
                let mut polygons = vec![q.clone()];
                if inner_polygon && i == 1 {
                    polygons.push(vec![8, 9, 10]);
                }
                Facet {
                    polygons,
                    ..Default::default()
                }
            })
            .collect();
        Plc {
            points,
            facets,
            ..Default::default()
        }
    }

    #[test]
    fn a_closed_cube_may_enclose_volume() {
        let plc = cube(false, false);
        assert_eq!(open_boundary(&plc, &prepare(&plc, true).unwrap()), None);
    }

    #[test]
    fn an_open_box_encloses_nothing_and_its_rim_is_reported() {
        let plc = cube(true, false);
        let rim = open_boundary(&plc, &prepare(&plc, true).unwrap()).unwrap();
        assert_eq!(rim, vec![[4, 5], [4, 6], [5, 7], [6, 7]]);
    }

    #[test]
    fn a_polygon_drawn_inside_a_facet_is_not_a_hole() {
        // The top facet's inner triangle has edges no other facet shares, yet the cube
        // is closed: such facets are never peeled.
        let plc = cube(false, true);
        assert_eq!(open_boundary(&plc, &prepare(&plc, true).unwrap()), None);
    }

    #[test]
    fn a_fin_on_a_closed_cube_is_peeled_but_the_cube_stays() {
        let mut plc = cube(false, false);
        plc.points.push([0.5, 0.5, 2.0]);
        plc.facets.push(Facet {
            polygons: vec![vec![4, 5, 11]],
            ..Default::default()
        });
        assert_eq!(open_boundary(&plc, &prepare(&plc, true).unwrap()), None);
    }
}
