//! Random vertices into the live CDTs of PLCs: certified after every insertion.

use proptest::prelude::*;
use tetcdt::live::{Cdt, InsertError};

/// Flat facets, a hole, an internal facet. (Splits on facets that are not flat, such as
/// nearly flat grids and twisted prisms, are still refused at times: a known limit.)
const MODELS: [&str; 3] = [
    "data/examples/cube.poly",
    "data/examples/box_with_hole.poly",
    "data/plc/box_internal_facet.poly",
];

fn plc(name: &str) -> tetcdt::Plc {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(name);
    tetcdt::io::read_plc(&path).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Points inside the bounding box, on its vertices' midpoints (exactly on segments
    /// and facets of axis-aligned models) and on input vertices.
    #[test]
    fn every_insertion_leaves_a_certified_cdt(
        model in 0..MODELS.len(),
        picks in prop::collection::vec((0.01f64..0.99, 0.01f64..0.99, 0.01f64..0.99, 0u8..4), 1..12),
    ) {
        let plc = plc(MODELS[model]);
        let mut cdt = Cdt::build(&plc, &Default::default()).unwrap();
        let n = plc.points.len();
        let lo: [f64; 3] = std::array::from_fn(|k| plc.points.iter().map(|p| p[k]).fold(f64::MAX, f64::min));
        let hi: [f64; 3] = std::array::from_fn(|k| plc.points.iter().map(|p| p[k]).fold(f64::MIN, f64::max));
        for (x, y, z, kind) in picks {
            let p = match kind {
                // The middle of two input points: on a segment or facet when they share one.
                0 => {
                    let (a, b) = (plc.points[(x * n as f64) as usize % n], plc.points[(y * n as f64) as usize % n]);
                    std::array::from_fn(|k| 0.5 * (a[k] + b[k]))
                }
                1 => plc.points[(z * n as f64) as usize % n],
                _ => [lo[0] + x * (hi[0] - lo[0]), lo[1] + y * (hi[1] - lo[1]), lo[2] + z * (hi[2] - lo[2])],
            };
            match cdt.insert_vertex(p) {
                Ok(_) | Err(InsertError::OutsideHull(_)) => {}
                Err(e) => prop_assert!(false, "{}: {p:?}: {e}", MODELS[model]),
            }
            if let Err(e) = cdt.certify() {
                prop_assert!(false, "{} after {p:?}: {e}", MODELS[model]);
            }
        }
    }
}
