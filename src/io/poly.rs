//! Reader of TetGen's `.poly` files (a piecewise linear complex).
//!
//! A `.poly` file has four parts:
//! 1. a node section as in a `.node` file; a point count of 0 means that the points are
//!    in the sibling `.node` file (same base name), whose errors are reported with its
//!    own path;
//! 2. facets: `<#facets> [boundary markers 0|1]`, then per facet a line
//!    `<#polygons> [#holes] [boundary marker]`, its polygons `<#corners> <v1> ... <vn>`
//!    (1 corner: an isolated vertex, 2: a segment), and its hole points `<hole #> x y z`;
//! 3. volume holes: `<#holes>` and `<hole #> x y z` (TetGen 1.5 also accepts a file that
//!    ends before this part; so do we);
//! 4. regions (optional): `<#regions>` and `<region #> x y z <attribute> [max volume]`
//!    (a missing volume bound is recorded as -1, i.e. none).
//!
//! Vertex numbers follow the numbering of the node section (from 0 or 1) and are stored
//! 0-based. Facets, holes and regions are named in messages by their position counted
//! from the same first number; polygons are counted from 1 within their facet.

use super::node;
use super::tokens::{corner_index, read_text, Line, Lines};
use crate::error::InputError;
use crate::plc::{Facet, Plc, Region};
use std::path::Path;

/// Reads a `.poly` file (and its sibling `.node` file if its node section is empty).
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let text = read_text(path)?;
    parse(&text, path)
}

/// Parses the text of a `.poly` file. `path` names the file in errors and locates the
/// sibling `.node` file when the node section is empty.
pub fn parse(text: &str, path: &Path) -> Result<Plc, InputError> {
    let mut lines = Lines::new(text, path);
    let (mut plc, section) = read_to_facets(&mut lines)?;
    let first = plc.first_index;
    let npoints = plc.points.len();

    for f in 0..section.nfacets {
        let (fnum, mut line) = section.facet_line(&mut lines, f, first)?;
        let npolygons = line.count(|| format!("the number of polygons of facet {fnum}"))?;
        if npolygons == 0 {
            return Err(line.error(format!("facet {fnum} has no polygons")));
        }
        let nholes = line
            .opt_count(|| format!("the number of holes of facet {fnum}"))?
            .unwrap_or(0);
        let marker = section.marker(&mut line, fnum)?;
        let facet_line = line.number();
        let mut facet = Facet {
            polygons: Vec::with_capacity(npolygons.min(16)),
            holes: Vec::new(),
            marker,
            line: facet_line,
        };
        for k in 1..=npolygons {
            let mut line = lines.expect_line(|| {
                format!("polygon {k} of facet {fnum} ({k} of {npolygons} announced on line {facet_line})")
            })?;
            let id = PolygonId {
                facet: fnum,
                polygon: Some(k),
            };
            facet
                .polygons
                .push(read_polygon(&mut line, id, first, npoints)?);
        }
        for h in 0..nholes {
            let hnum = first + h;
            let mut line = lines.expect_line(|| {
                format!(
                    "hole {hnum} of facet {fnum} ({} of {nholes} announced on line {facet_line})",
                    h + 1
                )
            })?;
            line.int(|| format!("the number of hole {hnum} of facet {fnum}"))?;
            facet
                .holes
                .push(line.xyz(&|| format!("hole {hnum} of facet {fnum}"))?);
        }
        plc.facets.push(facet);
    }

    read_holes_and_regions(&mut lines, &mut plc)?;
    Ok(plc)
}

/// The header of the facet section of a `.poly` or `.smesh` file.
pub(crate) struct FacetSection {
    /// The number of facets announced.
    pub nfacets: usize,
    has_markers: bool,
    header_line: usize,
}

impl FacetSection {
    /// The line of facet `f` (counted from 0) and its number as the file counts
    /// (`first` the node numbering's first index).
    pub(crate) fn facet_line<'a>(
        &self,
        lines: &mut Lines<'a>,
        f: usize,
        first: usize,
    ) -> Result<(usize, Line<'a>), InputError> {
        let fnum = first + f;
        let line = lines.expect_line(|| {
            format!(
                "facet {fnum} ({} of {} announced on line {})",
                f + 1,
                self.nfacets,
                self.header_line
            )
        })?;
        Ok((fnum, line))
    }

    /// Facet `fnum`'s boundary marker, next on its line when the header says there are
    /// markers (a missing one counts as 0).
    pub(crate) fn marker(&self, line: &mut Line<'_>, fnum: usize) -> Result<i32, InputError> {
        if !self.has_markers {
            return Ok(0);
        }
        Ok(line
            .opt_marker(|| format!("the boundary marker of facet {fnum}"))?
            .unwrap_or(0))
    }
}

/// Reads a `.poly` or `.smesh` file up to its facets: part 1 (see [`read_node_part`]) and
/// the facet section's header, with room reserved for the facets.
pub(crate) fn read_to_facets(lines: &mut Lines<'_>) -> Result<(Plc, FacetSection), InputError> {
    let mut plc = read_node_part(lines)?;
    let mut header =
        lines.expect_line(|| "the facet section header `<#facets> <boundary markers>`".into())?;
    let nfacets = header.count(|| "the number of facets".into())?;
    let has_markers = header.opt_flag(|| "the number of facet boundary markers".into())?;
    plc.facets = Vec::with_capacity(lines.capacity_for(nfacets));
    let section = FacetSection {
        nfacets,
        has_markers,
        header_line: header.number(),
    };
    Ok((plc, section))
}

/// Reads part 1 of a `.poly` or `.smesh` file: the points, either from the file itself
/// or, when its point count is 0, from the sibling `.node` file. The returned model has
/// `source` set to the `.poly`/`.smesh` file.
pub(crate) fn read_node_part(lines: &mut Lines<'_>) -> Result<Plc, InputError> {
    let path = lines.path();
    let mut header = lines.expect_line(|| {
        "the node section header `<#points> <dimension> <#attributes> <#boundary markers>`".into()
    })?;
    let count = header.count(|| "the number of points".into())?;
    let mut plc = if count == 0 {
        let node_path = path.with_extension("node");
        let text = read_text(&node_path).map_err(|e| match e {
            InputError::Io { file, source } => InputError::Io {
                source: std::io::Error::new(
                    source.kind(),
                    format!(
                        "{source} (line {} of {} has no points, so they are read from this file)",
                        header.number(),
                        path.display()
                    ),
                ),
                file,
            },
            other => other,
        })?;
        node::parse(&text, &node_path)?
    } else {
        let mut plc = Plc::default();
        node::read_points(lines, header, count, &mut plc)?;
        plc
    };
    plc.source = path.to_path_buf();
    Ok(plc)
}

/// Names a polygon in messages: "facet 3: polygon 1" or, for `.smesh` facets, "facet 3".
#[derive(Clone, Copy, Debug)]
pub(crate) struct PolygonId {
    /// The facet's number (counted from the file's first index).
    pub facet: usize,
    /// The polygon's number within the facet (from 1), if the facet has several.
    pub polygon: Option<usize>,
}

impl PolygonId {
    /// "polygon K of facet N" or "facet N".
    fn name(self) -> String {
        match self.polygon {
            Some(k) => format!("polygon {k} of facet {}", self.facet),
            None => format!("facet {}", self.facet),
        }
    }

    /// "facet N: polygon K" or "facet N", as the subject of a sentence.
    fn subject(self) -> String {
        match self.polygon {
            Some(k) => format!("facet {}: polygon {k}", self.facet),
            None => format!("facet {}", self.facet),
        }
    }
}

/// Reads `<#corners> <v1> ... <vn>` from `line`, converting the vertex numbers (counted
/// from `first`) to 0-based indices below `npoints`. Leaves any further tokens unread.
pub(crate) fn read_polygon(
    line: &mut Line<'_>,
    id: PolygonId,
    first: usize,
    npoints: usize,
) -> Result<Vec<u32>, InputError> {
    let ncorners = line.count(|| format!("the number of corners of {}", id.name()))?;
    if ncorners == 0 {
        return Err(line.error(format!("{} has no corners", id.subject())));
    }
    let mut corners = Vec::with_capacity(ncorners.min(line.remaining_len() / 2 + 1));
    for c in 1..=ncorners {
        let v = line.int(|| format!("corner {c} of {}", id.name()))?;
        let index = corner_index(v, first, npoints, "point", "points")
            .map_err(|msg| line.error(format!("{} {msg}", id.subject())))?;
        corners.push(index);
    }
    Ok(corners)
}

/// Reads parts 3 and 4 of a `.poly` or `.smesh` file: the volume holes and the regions.
/// Either part may be missing at the end of the file.
pub(crate) fn read_holes_and_regions(
    lines: &mut Lines<'_>,
    plc: &mut Plc,
) -> Result<(), InputError> {
    let first = plc.first_index;
    let Some(mut header) = lines.next_line() else {
        return Ok(());
    };
    let nholes = header.count(|| "the number of holes".into())?;
    let header_line = header.number();
    plc.holes = Vec::with_capacity(lines.capacity_for(nholes));
    for h in 0..nholes {
        let hnum = first + h;
        let mut line = lines.expect_line(|| {
            format!(
                "hole {hnum} ({} of {nholes} announced on line {header_line})",
                h + 1
            )
        })?;
        line.int(|| format!("the number of hole {hnum}"))?;
        plc.holes.push(line.xyz(&|| format!("hole {hnum}"))?);
    }

    let Some(mut header) = lines.next_line() else {
        return Ok(());
    };
    let nregions = header.count(|| "the number of regions".into())?;
    let header_line = header.number();
    plc.regions = Vec::with_capacity(lines.capacity_for(nregions));
    for r in 0..nregions {
        let rnum = first + r;
        let mut line = lines.expect_line(|| {
            format!(
                "region {rnum} ({} of {nregions} announced on line {header_line})",
                r + 1
            )
        })?;
        line.int(|| format!("the number of region {rnum}"))?;
        let point = line.xyz(&|| format!("region {rnum}"))?;
        let attribute = line.float(|| format!("the attribute of region {rnum}"))?;
        let max_volume = line
            .opt_float(|| format!("the maximum volume of region {rnum}"))?
            .unwrap_or(-1.0);
        plc.regions.push(Region {
            point,
            attribute,
            max_volume,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE_NODES: &str =
        "8 3 0 0\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 0 0 1\n6 1 0 1\n7 1 1 1\n8 0 1 1\n";
    const CUBE_FACETS: &str = "6 1\n1 0 1\n4 1 2 3 4\n1 0 2\n4 5 6 7 8\n1 0 3\n4 1 2 6 5\n1 0 4\n4 2 3 7 6\n1 0 5\n4 3 4 8 7\n1 0 6\n4 4 1 5 8\n";

    fn parse_ok(text: &str) -> Plc {
        parse(text, Path::new("cube.poly")).unwrap()
    }

    fn parse_err(text: &str) -> String {
        parse(text, Path::new("cube.poly")).unwrap_err().to_string()
    }

    #[test]
    fn reads_a_cube_numbered_from_one() {
        let plc = parse_ok(&format!("{CUBE_NODES}{CUBE_FACETS}0\n0\n"));
        assert_eq!(plc.first_index, 1);
        assert_eq!(plc.points.len(), 8);
        assert_eq!(plc.facets.len(), 6);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2, 3]]);
        assert_eq!(plc.facets[5].polygons, vec![vec![3, 0, 4, 7]]);
        assert_eq!(
            plc.facets.iter().map(|f| f.marker).collect::<Vec<_>>(),
            vec![1, 2, 3, 4, 5, 6]
        );
        assert_eq!(plc.facets[0].line, 11);
        assert_eq!(plc.facets[1].line, 13);
        assert!(plc.holes.is_empty() && plc.regions.is_empty());
        assert_eq!(plc.source, Path::new("cube.poly"));
    }

    #[test]
    fn reads_a_file_numbered_from_zero_without_markers() {
        let text = "# tet\n4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n\n4 0\n1\n3 0 1 2\n1\n3 0 1 3\n1 # c\n3 1 2 3\n1\n3 0 2 3\n0\n";
        let plc = parse_ok(text);
        assert_eq!(plc.first_index, 0);
        assert_eq!(plc.facets[2].polygons, vec![vec![1, 2, 3]]);
        assert!(plc.facets.iter().all(|f| f.marker == 0));
    }

    #[test]
    fn missing_marker_and_hole_count_default_to_zero() {
        let text = "3 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n1 1\n1\n3 1 2 3\n";
        let plc = parse_ok(text);
        assert_eq!(plc.facets[0].marker, 0);
        assert!(plc.facets[0].holes.is_empty());
        assert!(
            plc.holes.is_empty(),
            "a file may end before its hole section"
        );
    }

    #[test]
    fn multiple_polygons_with_points_segments_and_facet_holes() {
        let text = format!(
            "{CUBE_NODES}1 1\n4 2 9 # 4 polygons, 2 holes, marker 9\n4 1 2 3 4\n3 1 2 3\n2 5 6\n1 7\n1 0.5 0.5 0\n2 0.25 0.25 0\n0\n"
        );
        let plc = parse_ok(&text);
        let f = &plc.facets[0];
        assert_eq!(
            f.polygons,
            vec![vec![0, 1, 2, 3], vec![0, 1, 2], vec![4, 5], vec![6]]
        );
        assert_eq!(f.holes, vec![[0.5, 0.5, 0.0], [0.25, 0.25, 0.0]]);
        assert_eq!(f.marker, 9);
    }

    #[test]
    fn hole_and_region_lists() {
        let text = format!(
            "{CUBE_NODES}{CUBE_FACETS}2\n1 0.5 0.5 0.5\n2 0.1 0.2 0.3\n3\n1 0.5 0.5 0.5 10 0.01\n2 0.1 0.1 0.1 -2\n3 0.2 0.2 0.2 3.5 -1\n"
        );
        let plc = parse_ok(&text);
        assert_eq!(plc.holes, vec![[0.5; 3], [0.1, 0.2, 0.3]]);
        assert_eq!(
            plc.regions,
            vec![
                Region {
                    point: [0.5; 3],
                    attribute: 10.0,
                    max_volume: 0.01
                },
                Region {
                    point: [0.1; 3],
                    attribute: -2.0,
                    max_volume: -1.0
                },
                Region {
                    point: [0.2; 3],
                    attribute: 3.5,
                    max_volume: -1.0
                },
            ]
        );
    }

    #[test]
    fn point_attributes_and_markers_in_the_node_section() {
        let text = "3 3 1 1\n0 0 0 0 5 1\n1 1 0 0 6 2\n2 0 1 0 7 3\n1 0\n1\n3 0 1 2\n0\n";
        let plc = parse_ok(text);
        assert_eq!(plc.point_attrs, vec![5.0, 6.0, 7.0]);
        assert_eq!(plc.point_markers, Some(vec![1, 2, 3]));
    }

    #[test]
    fn reads_points_from_the_sibling_node_file() {
        let dir = tempfile::tempdir().unwrap();
        let node = dir.path().join("cube.node");
        let poly = dir.path().join("cube.poly");
        std::fs::write(&node, CUBE_NODES).unwrap();
        std::fs::write(&poly, format!("0 3 0 0\n{CUBE_FACETS}0\n")).unwrap();
        let plc = read(&poly).unwrap();
        assert_eq!(plc.points.len(), 8);
        assert_eq!(plc.first_index, 1);
        assert_eq!(plc.facets.len(), 6);
        assert_eq!(plc.source, poly);

        // Errors in the .node file name the .node file.
        std::fs::write(&node, "2 3 0 0\n1 0 0 0\n2 0 zz 0\n").unwrap();
        let e = read(&poly).unwrap_err().to_string();
        assert_eq!(
            e,
            format!(
                "{}:3: expected the y coordinate of point 2, found `zz`",
                node.display()
            )
        );

        // A missing .node file is an I/O error naming it.
        std::fs::remove_file(&node).unwrap();
        let e = read(&poly).unwrap_err();
        assert!(matches!(e, InputError::Io { .. }));
        let msg = e.to_string();
        assert!(msg.starts_with(&node.display().to_string()), "{msg}");
        assert!(msg.contains("line 1 of"), "{msg}");
    }

    #[test]
    fn corner_out_of_range() {
        let text = format!("{CUBE_NODES}6 0\n1\n4 1 2 3 4\n1\n4 5 6 7 8\n1\n4 1 2 6 9\n");
        assert_eq!(
            parse_err(&text),
            "cube.poly:16: facet 3: polygon 1 has corner 9, but there are only 8 points (numbered from 1)"
        );
        let text = format!("{CUBE_NODES}1 0\n2\n3 1 2 3\n3 0 2 3\n");
        assert_eq!(
            parse_err(&text),
            "cube.poly:13: facet 1: polygon 2 has corner 0, but the points are numbered from 1"
        );
        let text = "1 3 0 0\n0 0 0 0\n1 0\n1\n1 -1\n";
        assert_eq!(
            parse_err(text),
            "cube.poly:5: facet 0: polygon 1 has corner -1, but the points are numbered from 0"
        );
    }

    #[test]
    fn malformed_facets() {
        let base = CUBE_NODES;
        assert_eq!(
            parse_err(&format!("{base}1 0\n1\n4 1 2 3\n")),
            "cube.poly:12: expected corner 4 of polygon 1 of facet 1, but the line ends"
        );
        assert_eq!(
            parse_err(&format!("{base}1 0\n1\n4 1 2 x 4\n")),
            "cube.poly:12: expected corner 3 of polygon 1 of facet 1 (an integer), found `x`"
        );
        assert_eq!(
            parse_err(&format!("{base}1 0\n0\n")),
            "cube.poly:11: facet 1 has no polygons"
        );
        assert_eq!(
            parse_err(&format!("{base}1 0\n1\n0\n")),
            "cube.poly:12: facet 1: polygon 1 has no corners"
        );
        assert_eq!(
            parse_err(&format!("{base}1 0\n-1\n")),
            "cube.poly:11: the number of polygons of facet 1 cannot be negative, found `-1`"
        );
        assert_eq!(
            parse_err(&format!("{base}-6 0\n")),
            "cube.poly:10: the number of facets cannot be negative, found `-6`"
        );
        assert_eq!(
            parse_err(&format!("{base}1 2\n")),
            "cube.poly:10: the number of facet boundary markers must be 0 or 1, found `2`"
        );
        assert_eq!(
            parse_err(&format!("{base}1 1\n1 0 x\n")),
            "cube.poly:11: expected the boundary marker of facet 1 (an integer), found `x`"
        );
        assert_eq!(
            parse_err(&format!("{base}1 0\n1 1\n3 1 2 3\n1 0.5 nan 0\n")),
            "cube.poly:13: the y coordinate of hole 1 of facet 1 is not a finite number: `nan`"
        );
    }

    #[test]
    fn truncated_files() {
        assert_eq!(
            parse_err(&format!("{CUBE_NODES}6 0\n1\n4 1 2 3 4\n")),
            "cube.poly:12: unexpected end of file: expected facet 2 (2 of 6 announced on line 10)"
        );
        assert_eq!(
            parse_err(&format!("{CUBE_NODES}6 0\n2\n4 1 2 3 4\n\n")),
            "cube.poly:13: unexpected end of file: expected polygon 2 of facet 1 (2 of 2 announced on line 11)"
        );
        assert_eq!(
            parse_err(&format!("{CUBE_NODES}1 0\n1 2\n3 1 2 3\n1 0 0 0\n")),
            "cube.poly:13: unexpected end of file: expected hole 2 of facet 1 (2 of 2 announced on line 11)"
        );
        assert_eq!(
            parse_err(CUBE_NODES),
            "cube.poly:9: unexpected end of file: expected the facet section header `<#facets> <boundary markers>`"
        );
        assert_eq!(
            parse_err("8 3 0 0\n1 0 0 0\n"),
            "cube.poly:2: unexpected end of file: expected point 2 (2 of 8 announced on line 1)"
        );
        assert_eq!(
            parse_err(&format!("{CUBE_NODES}0\n3\n1 0 0 0\n")),
            "cube.poly:12: unexpected end of file: expected hole 2 (2 of 3 announced on line 11)"
        );
        assert_eq!(
            parse_err(&format!("{CUBE_NODES}0\n0\n1000000000000\n1 0 0 0 1\n")),
            "cube.poly:13: unexpected end of file: expected region 2 (2 of 1000000000000 announced on line 12)"
        );
        assert_eq!(
            parse_err(&format!(
                "{CUBE_NODES}1000000000000 0\n1 1000000000000\n1000000000000 1\n"
            )),
            "cube.poly:12: expected corner 2 of polygon 1 of facet 1, but the line ends"
        );
    }

    #[test]
    fn bad_holes_and_regions() {
        let base = format!("{CUBE_NODES}{CUBE_FACETS}");
        assert_eq!(
            parse_err(&format!("{base}1\n1 0.5 0.5 1e999\n")),
            "cube.poly:24: the z coordinate of hole 1 is not a finite number: `1e999`"
        );
        assert_eq!(
            parse_err(&format!("{base}-1\n")),
            "cube.poly:23: the number of holes cannot be negative, found `-1`"
        );
        assert_eq!(
            parse_err(&format!("{base}0\n1\n1 0.5 0.5 0.5\n")),
            "cube.poly:25: expected the attribute of region 1, but the line ends"
        );
        assert_eq!(
            parse_err(&format!("{base}0\n1\n1 inf 0.5 0.5 1 2\n")),
            "cube.poly:25: the x coordinate of region 1 is not a finite number: `inf`"
        );
        assert_eq!(
            parse_err(&format!("{base}0\n1\n1 0.5 0.5 0.5 1 nan\n")),
            "cube.poly:25: the maximum volume of region 1 is not a finite number: `nan`"
        );
        assert_eq!(
            parse_err(&format!("{base}0\n2.5\n")),
            "cube.poly:24: expected the number of regions (a non-negative integer), found `2.5`"
        );
    }

    #[test]
    fn example_files_parse() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples");
        let cube = read(&dir.join("cube.poly")).unwrap();
        assert_eq!((cube.points.len(), cube.facets.len()), (8, 6));
        let hole = read(&dir.join("box_with_hole.poly")).unwrap();
        assert_eq!(hole.points.len(), 16);
        assert_eq!(hole.facets.len(), 12);
        assert_eq!(hole.holes.len(), 1);
        assert_eq!(hole.regions.len(), 1);
        let facet_hole = read(&dir.join("square_with_facet_hole.poly")).unwrap();
        assert_eq!(facet_hole.facets[0].polygons.len(), 4);
        assert_eq!(facet_hole.facets[0].holes.len(), 1);
        let split = read(&dir.join("points8.poly")).unwrap();
        assert_eq!(split.points.len(), 8);
    }
}
