//! Meshes one PLC again and again in one process and prints the fastest facet recovery,
//! with `-C` or `-F`, or both in turns (`CF`, which also prints their ratio: turns keep
//! the machine's slow spells from falling on one side only): facet recovery times free of
//! a fresh process's first-run costs. Also the loop to run under `valgrind
//! --tool=callgrind`.
//!
//! usage: cargo run --release --example warm_facets -- MODEL.poly C|F|CF [RUNS]

use tetcdt::constrained::{FacetInserter, PlcOptions};
use tetcdt::pipeline::mesh_plc;
use tetcdt::plc::Plc;

/// The facet recovery time of one run, in seconds.
fn facet_secs(plc: &Plc, inserter: FacetInserter) -> f64 {
    let opts = PlcOptions {
        merge: true,
        // One rectangle (Figure 9) encloses no volume: keep the hull, as `-c`.
        keep_hull: true,
        region_attributes: false,
        max_steiner: usize::MAX,
        inserter,
        cancel: None,
        wake_when_prepared: None,
    };
    match mesh_plc(plc, &opts) {
        Ok(m) => m.stats.facet_secs,
        Err(e) => {
            eprintln!("warm_facets: {e}");
            std::process::exit(1);
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 || !matches!(args[2].as_str(), "C" | "F" | "CF") {
        eprintln!("usage: warm_facets MODEL C|F|CF [RUNS]");
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
    let inserters: &[FacetInserter] = match args[2].as_str() {
        "C" => &[FacetInserter::Cavity],
        "F" => &[FacetInserter::Flip],
        _ => &[FacetInserter::Cavity, FacetInserter::Flip],
    };
    let mut best = vec![f64::INFINITY; inserters.len()];
    for _ in 0..runs.max(1) {
        for (b, &inserter) in best.iter_mut().zip(inserters) {
            *b = b.min(facet_secs(&plc, inserter));
        }
    }
    if let [c, f] = best[..] {
        println!(
            "facet recovery, fastest of {runs}: -C {:.3} ms, -F {:.3} ms, -F/-C {:.3}",
            c * 1e3,
            f * 1e3,
            f / c
        );
    } else {
        println!("facet recovery, fastest of {runs}: {:.3} ms", best[0] * 1e3);
    }
}
