//! Reader of TetGen's `.smesh` files (a simple PLC: one polygon per facet).
//!
//! Like a `.poly` file, except that each facet is a single line
//! `<#corners> <v1> ... <vn> [boundary marker]`, the marker being read when the facet
//! section header says there are boundary markers (a missing one counts as 0). Part 1
//! may have a point count of 0, meaning the points are in the sibling `.node` file; the
//! hole and region parts are as in `.poly` (and may be missing at the end of the file).

use super::poly::{read_holes_and_regions, read_polygon, read_to_facets, PolygonId};
use super::tokens::{read_text, Lines};
use crate::error::InputError;
use crate::plc::{Facet, Plc};
use std::path::Path;

/// Reads a `.smesh` file (and its sibling `.node` file if its node section is empty).
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let text = read_text(path)?;
    parse(&text, path)
}

/// Parses the text of a `.smesh` file. `path` names the file in errors and locates the
/// sibling `.node` file when the node section is empty.
pub fn parse(text: &str, path: &Path) -> Result<Plc, InputError> {
    let mut lines = Lines::new(text, path);
    let (mut plc, section) = read_to_facets(&mut lines)?;
    let first = plc.first_index;
    let npoints = plc.points.len();

    for f in 0..section.nfacets {
        let (fnum, mut line) = section.facet_line(&mut lines, f, first)?;
        let polygon = read_polygon(
            &mut line,
            PolygonId {
                facet: fnum,
                polygon: None,
            },
            first,
            npoints,
        )?;
        let marker = section.marker(&mut line, fnum)?;
        plc.facets.push(Facet {
            polygons: vec![polygon],
            holes: Vec::new(),
            marker,
            line: line.number(),
        });
    }

    read_holes_and_regions(&mut lines, &mut plc)?;
    Ok(plc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plc::Region;

    const NODES0: &str = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";

    fn parse_ok(text: &str) -> Plc {
        parse(text, Path::new("t.smesh")).unwrap()
    }

    fn parse_err(text: &str) -> String {
        parse(text, Path::new("t.smesh")).unwrap_err().to_string()
    }

    #[test]
    fn reads_a_tetrahedron_numbered_from_zero_with_markers() {
        let text = format!(
            "{NODES0}# facets\n4 1\n3 0 1 2 5\n3 0 1 3 6\n\n3 1 2 3 7\n3 0 2 3 # no marker\n0\n0\n"
        );
        let plc = parse_ok(&text);
        assert_eq!(plc.first_index, 0);
        assert_eq!(plc.facets.len(), 4);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2]]);
        assert_eq!(
            plc.facets.iter().map(|f| f.marker).collect::<Vec<_>>(),
            vec![5, 6, 7, 0]
        );
        assert_eq!(plc.facets[2].line, 11);
    }

    #[test]
    fn reads_a_file_numbered_from_one_without_markers() {
        let text = "3 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n3 0\n3 1 2 3 99\n1 1\n2 2 3\n";
        let plc = parse_ok(text);
        assert_eq!(plc.first_index, 1);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2]]);
        assert_eq!(
            plc.facets[0].marker, 0,
            "markers are ignored when the header has none"
        );
        assert_eq!(plc.facets[1].polygons, vec![vec![0]]);
        assert_eq!(plc.facets[2].polygons, vec![vec![1, 2]]);
    }

    #[test]
    fn holes_and_regions() {
        let text = format!(
            "{NODES0}1 0\n3 0 1 2\n1\n0 0.1 0.1 0.1\n2\n0 0.2 0.2 0.2 1 0.5\n1 0.3 0.3 0.3 2\n"
        );
        let plc = parse_ok(&text);
        assert_eq!(plc.holes, vec![[0.1; 3]]);
        assert_eq!(
            plc.regions,
            vec![
                Region {
                    point: [0.2; 3],
                    attribute: 1.0,
                    max_volume: 0.5
                },
                Region {
                    point: [0.3; 3],
                    attribute: 2.0,
                    max_volume: -1.0
                },
            ]
        );
    }

    #[test]
    fn reads_points_from_the_sibling_node_file() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("tet.node"), NODES0).unwrap();
        let path = dir.path().join("tet.smesh");
        std::fs::write(
            &path,
            "0 3 0 0\n4 0\n3 0 1 2\n3 0 1 3\n3 1 2 3\n3 0 2 3\n0\n",
        )
        .unwrap();
        let plc = read(&path).unwrap();
        assert_eq!(plc.points.len(), 4);
        assert_eq!(plc.facets.len(), 4);
        assert_eq!(plc.source, path);
    }

    #[test]
    fn errors() {
        assert_eq!(
            parse_err(&format!("{NODES0}2 0\n3 0 1 2\n3 0 1 4\n")),
            "t.smesh:8: facet 1 has corner 4, but there are only 4 points (numbered from 0)"
        );
        assert_eq!(
            parse_err(&format!("{NODES0}2 1\n3 0 1 2 x\n")),
            "t.smesh:7: expected the boundary marker of facet 0 (an integer), found `x`"
        );
        assert_eq!(
            parse_err(&format!("{NODES0}2 0\n3 0 1\n")),
            "t.smesh:7: expected corner 3 of facet 0, but the line ends"
        );
        assert_eq!(
            parse_err(&format!("{NODES0}2 0\n0\n")),
            "t.smesh:7: facet 0 has no corners"
        );
        assert_eq!(
            parse_err(&format!("{NODES0}3 0\n3 0 1 2\n")),
            "t.smesh:7: unexpected end of file: expected facet 1 (2 of 3 announced on line 6)"
        );
        assert_eq!(
            parse_err(&format!("{NODES0}1 0\n3 0 1 2\n1\n0 0 0 -inf\n")),
            "t.smesh:9: the z coordinate of hole 0 is not a finite number: `-inf`"
        );
        assert_eq!(
            parse_err("4 3 0 0\n0 0 0 0\n"),
            "t.smesh:2: unexpected end of file: expected point 1 (2 of 4 announced on line 1)"
        );
    }

    #[test]
    fn example_file_parses() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples/cube.smesh");
        let plc = read(&path).unwrap();
        assert_eq!((plc.points.len(), plc.facets.len()), (8, 12));
    }
}
