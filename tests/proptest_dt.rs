//! Property tests: any point set that is not degenerate gets a valid Delaunay
//! tetrahedralization (checked by the library's independent validator), and the result
//! does not depend on the order of equal-coordinate duplicates being present.

use proptest::prelude::*;
use tetcdt::check::check_mesh;
use tetcdt::{tetrahedralize, Options, Plc};

/// Whether the points span no volume: all on one plane (exactly), which includes
/// collinear and coincident ones.
fn degenerate(points: &[[f64; 3]]) -> bool {
    let ids: Vec<u32> = (0..points.len() as u32).collect();
    let Some(k) =
        (2..points.len()).find(|&k| !tetcdt::geom::polygon::all_collinear(points, &ids[..=k]))
    else {
        return true;
    };
    // Points 0..=k span a plane: two of them and point k, not collinear.
    let a = points[0];
    let b = *points[..k].iter().find(|p| **p != a).unwrap_or(&a);
    let c = points[k];
    points
        .iter()
        .all(|q| tetcdt::geom::orient3d(&a, &b, &c, q) == 0.0)
}

fn mesh_and_check(points: Vec<[f64; 3]>) -> Result<(), TestCaseError> {
    let plc = Plc::from_points(points.clone(), 1);
    match tetrahedralize(&plc, &Options::default()) {
        Ok(m) => {
            if let Err(problems) = check_mesh(&plc, &m.mesh, &Default::default()) {
                return Err(TestCaseError::fail(problems.to_string()));
            }
            Ok(())
        }
        // Only a set that spans no volume may be refused, as an invalid input.
        Err(e) => {
            prop_assert!(
                degenerate(&points),
                "refused points that span a volume: {}",
                e
            );
            prop_assert_eq!(e.exit_code(), 3, "{}", e);
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
