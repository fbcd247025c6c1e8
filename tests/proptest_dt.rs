//! Property tests: any point set that is not degenerate gets a valid Delaunay
//! tetrahedralization (checked by the library's independent validator), and the result
//! does not depend on the order of equal-coordinate duplicates being present.

use proptest::prelude::*;
use tetcdt::check::check_mesh;
use tetcdt::{tetrahedralize, Options, Plc};

fn mesh_and_check(points: Vec<[f64; 3]>) -> Result<(), TestCaseError> {
    let plc = Plc::from_points(points, 1);
    match tetrahedralize(&plc, &Options::default()) {
        Ok(m) => {
            if let Err(problems) = check_mesh(&plc, &m.mesh) {
                return Err(TestCaseError::fail(problems.to_string()));
            }
            Ok(())
        }
        // Coplanar, collinear or too few distinct points: a clear error is the right answer.
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(
                msg.contains("coplanar") || msg.contains("collinear") || msg.contains("distinct"),
                "unexpected error: {msg}"
            );
            Ok(())
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random floating-point coordinates: generic position.
    #[test]
    fn random_points_give_valid_dts(pts in prop::collection::vec(prop::array::uniform3(-1.0e3f64..1.0e3), 4..120)) {
        mesh_and_check(pts)?;
    }

    /// Points on a small integer grid: many exact coplanar and cospherical ties, and
    /// duplicates, all resolved by the symbolic perturbation.
    #[test]
    fn integer_grid_points_give_valid_dts(pts in prop::collection::vec(prop::array::uniform3(0i32..4), 4..80)) {
        mesh_and_check(pts.into_iter().map(|p| p.map(f64::from)).collect())?;
    }

    /// Points clustered at wildly different scales.
    #[test]
    fn multiscale_points_give_valid_dts(
        pts in prop::collection::vec((prop::array::uniform3(-1.0f64..1.0), 0u32..4), 4..80)
    ) {
        let scale = [1.0, 1e-6, 1e6, 1e-12];
        mesh_and_check(pts.into_iter().map(|(p, s)| p.map(|c| c * scale[s as usize])).collect())?;
    }
}
