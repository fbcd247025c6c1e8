//! Meshes one PLC again and again in one process and prints the fastest facet recovery,
//! with `-C` or `-F`: the "in one process" times of the README, free of a fresh
//! process's first-run costs. Also the loop to run under `valgrind --tool=callgrind`.
//!
//! usage: cargo run --release --example warm_facets -- MODEL.poly C|F [RUNS]

use tetcdt::constrained::{mesh_plc, FacetInserter, PlcOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 || !matches!(args[2].as_str(), "C" | "F") {
        eprintln!("usage: warm_facets MODEL C|F [RUNS]");
        std::process::exit(2);
    }
    let plc = match tetcdt::io::read_plc(std::path::Path::new(&args[1])) {
        Ok(plc) => plc,
        Err(e) => {
            eprintln!("warm_facets: {e}");
            std::process::exit(3);
        }
    };
    let runs: usize = args.get(3).and_then(|r| r.parse().ok()).unwrap_or(20);
    let mut best = f64::INFINITY;
    for _ in 0..runs.max(1) {
        let opts = PlcOptions {
            merge: true,
            // One rectangle (Figure 9) encloses no volume: keep the hull, as `-c`.
            keep_hull: true,
            region_attributes: false,
            max_steiner: usize::MAX,
            inserter: if args[2] == "F" {
                FacetInserter::Flip
            } else {
                FacetInserter::Cavity
            },
            cancel: None,
            wake_when_prepared: None,
        };
        match mesh_plc(&plc, &opts) {
            Ok(m) => best = best.min(m.stats.facet_secs),
            Err(e) => {
                eprintln!("warm_facets: {e}");
                std::process::exit(1);
            }
        }
    }
    println!("facet recovery, fastest of {runs}: {:.3} ms", best * 1e3);
}
