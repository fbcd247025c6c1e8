//! Builds the CDT of a PLC, inserts a polygon (a new facet across the middle of the
//! model) and vertices (inside, exactly on a segment, exactly on a facet, near a
//! segment) into it one at a time, certifies it after each step, and writes the carved
//! mesh.
//!
//! `cargo run --release --example incremental -- data/examples/box_with_hole.poly /tmp/out`

use tetcdt::live::Cdt;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let input = args
        .get(1)
        .map_or("data/examples/box_with_hole.poly", String::as_str);
    let prefix = args.get(2).map_or("incremental.1", String::as_str);
    let plc = tetcdt::io::read_plc(std::path::Path::new(input))?;
    let mut cdt = Cdt::build(&plc, &Default::default())?;
    cdt.certify()?;
    println!(
        "built: {} vertices, {} tets",
        cdt.num_vertices(),
        cdt.num_tets()
    );
    let [lo, hi] = tetcdt::geom::bounding_box(&plc.points);
    let at = |s: [f64; 3]| -> [f64; 3] { std::array::from_fn(|k| lo[k] + s[k] * (hi[k] - lo[k])) };
    let polygon = [
        at([0.1, 0.1, 0.15]),
        at([0.9, 0.12, 0.18]),
        at([0.85, 0.9, 0.15]),
        at([0.15, 0.85, 0.12]),
    ];
    match cdt.insert_polygon(&polygon, 9) {
        Ok(done) => {
            let cert = cdt.certify()?;
            println!(
                "polygon: corners {:?}, {} subfaces, {} points added; certified: {} tets",
                done.corners, done.subfaces, done.added, cert.tets
            );
        }
        Err(e) => println!("polygon not inserted: {e}"),
    }
    let a = plc.points[0];
    let b = plc.points[1];
    let points = [
        at([0.2, 0.3, 0.4]),
        // The middle of the first two input points: on a segment when they share one.
        std::array::from_fn(|k| 0.5 * (a[k] + b[k])),
        at([0.5, 0.5, 0.0]),
        at([0.3, 0.02, 0.02]),
    ];
    for p in points {
        match cdt.insert_vertex(p) {
            Ok(done) => {
                let cert = cdt.certify()?;
                println!(
                    "{p:?}: node {} ({}), {} splits first; certified: {} tets",
                    done.node,
                    if done.new { "new" } else { "already there" },
                    done.splits,
                    cert.tets
                );
            }
            Err(e) => println!("{p:?}: not inserted: {e}"),
        }
    }
    let mesh = cdt.mesh()?;
    let written = tetcdt::io::write::write_files(
        &mesh,
        std::path::Path::new(prefix),
        &Default::default(),
        &mut |_| {},
    )?;
    for f in written {
        println!("wrote {}", f.display());
    }
    Ok(())
}
