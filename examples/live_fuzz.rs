//! Measures the live CDT on random PLCs: for each case, the convex hull of 6 to 25
//! random points (its triangles as facets, the inner points as loose vertices), 10
//! random points inside the hull, then 3 random planar polygons (3 to 5 corners); after
//! each step the CDT is certified. Prints how many steps of each outcome there were, and
//! how many left a CDT that fails certification (the case then stops).
//!
//! `cargo run --release --example live_fuzz -- [SEED] [CASES]` (`SHOW=1` prints each
//! failure). A measurement, not a test: the live CDT's known limits show up here.

use tetcdt::live::{Cdt, InsertError, PolygonError};
use tetcdt::plc::{Facet, Plc};
fn main() {
    let seed: u64 = std::env::args().nth(1).map_or(777, |s| s.parse().unwrap());
    let cases: usize = std::env::args().nth(2).map_or(100, |s| s.parse().unwrap());
    let mut s = seed;
    let mut r = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut counts = std::collections::BTreeMap::<String, usize>::new();
    for case in 0..cases {
        let n = 6 + (r() * 20.0) as usize;
        let pts: Vec<[f64; 3]> = (0..n).map(|_| [r(), r(), r()]).collect();
        let built = tetcdt::delaunay::Delaunay::build(&pts).unwrap();
        let hull = built.dt.export_with(false).hull_faces;
        let plc = Plc {
            points: pts.clone(),
            facets: hull
                .iter()
                .map(|t| Facet {
                    polygons: vec![t.to_vec()],
                    holes: vec![],
                    marker: 1,
                    line: 0,
                })
                .collect(),
            ..Default::default()
        };
        let mut cdt = match Cdt::build(&plc, &Default::default()) {
            Ok(c) => c,
            Err(e) => {
                *counts.entry(format!("build {e}")).or_default() += 1;
                continue;
            }
        };
        if cdt.certify().is_err() {
            *counts.entry("build not certified".into()).or_default() += 1;
            continue;
        }
        let mut broken = false;
        for _ in 0..10 {
            // A random convex combination of four input points: inside the hull.
            let w: [f64; 4] = std::array::from_fn(|_| r());
            let picks: [usize; 4] = std::array::from_fn(|_| (r() * n as f64) as usize % n);
            let total: f64 = w.iter().sum();
            let p: [f64; 3] = std::array::from_fn(|d| {
                (0..4).map(|j| w[j] * pts[picks[j]][d]).sum::<f64>() / total
            });
            let key: String = match cdt.insert_vertex(p) {
                Ok(_) => "point ok".to_string(),
                Err(InsertError::Refused(_)) => "point refused".into(),
                Err(InsertError::OutsideHull(_)) => "point outside".into(),
                Err(e) => format!(
                    "point {}",
                    e.to_string().chars().take(25).collect::<String>()
                ),
            };
            *counts.entry(key.clone()).or_default() += 1;
            if let Err(e) = cdt.certify() {
                *counts
                    .entry(format!("NOT CERTIFIED after {key}"))
                    .or_default() += 1;
                if std::env::var_os("SHOW").is_some() {
                    eprintln!(
                        "{key} {p:?}: {}",
                        e.to_string()
                            .lines()
                            .take(3)
                            .collect::<Vec<_>>()
                            .join(" | ")
                    );
                }
                broken = true;
                break;
            }
        }
        if broken {
            continue;
        }
        for _ in 0..3 {
            let c = [0.3 + 0.4 * r(), 0.3 + 0.4 * r(), 0.3 + 0.4 * r()];
            let nn = [r() - 0.5, r() - 0.5, r() - 0.5];
            let u = tetcdt::geom::cross(&nn, &[1.0, 0.0, 0.0]);
            let lu = tetcdt::geom::norm(&u);
            let u = u.map(|x| x / lu);
            let w = tetcdt::geom::cross(&nn, &u);
            let lw = tetcdt::geom::norm(&w);
            let w = w.map(|x| x / lw);
            let k = 3 + (r() * 3.0) as usize;
            let size = 0.05 + 0.2 * r();
            let ring: Vec<[f64; 3]> = (0..k)
                .map(|i| {
                    let a = std::f64::consts::TAU * (i as f64 + 0.6 * r()) / k as f64;
                    std::array::from_fn(|d| c[d] + size * (a.cos() * u[d] + a.sin() * w[d]))
                })
                .collect();
            let key: String = match cdt.insert_polygon(&ring, 5) {
                Ok(_) => "polygon ok".to_string(),
                Err(PolygonError::Invalid(_)) => "polygon invalid".into(),
                Err(PolygonError::Vertex(InsertError::OutsideHull(_))) => "polygon outside".into(),
                Err(PolygonError::Vertex(e)) => format!(
                    "polygon vertex {}",
                    e.to_string().chars().take(12).collect::<String>()
                ),
                Err(e) => format!(
                    "polygon {}",
                    e.to_string().chars().take(25).collect::<String>()
                ),
            };
            *counts.entry(key.clone()).or_default() += 1;
            if let Err(e) = cdt.certify() {
                *counts
                    .entry(format!("NOT CERTIFIED after {key}"))
                    .or_default() += 1;
                if std::env::var_os("SHOW").is_some() {
                    eprintln!(
                        "case {case} {key} {ring:?}: {}",
                        e.to_string()
                            .lines()
                            .take(3)
                            .collect::<Vec<_>>()
                            .join(" | ")
                    );
                }
                break;
            }
        }
    }
    println!("{counts:#?}");
}
