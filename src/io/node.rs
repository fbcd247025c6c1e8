//! Reader of TetGen's `.node` files (a list of points).
//!
//! Format: a header `<#points> <dimension (3)> <#attributes> <#boundary markers (0 or 1)>`
//! (trailing fields may be omitted: they default to 3, 0 and 0), then one line per point
//! `<point #> <x> <y> <z> [attributes] [boundary marker]`. The number of the first point,
//! 0 or 1, fixes the numbering of the whole file; later points must be numbered consecutively.
//! Extra tokens after the expected fields of a line are ignored, as TetGen does.

use super::tokens::{read_text, Line, Lines};
use crate::error::InputError;
use crate::plc::Plc;
use std::path::Path;

/// Reads a `.node` file.
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let text = read_text(path)?;
    parse(&text, path)
}

/// Parses the text of a `.node` file; `path` is used in error messages and as the source.
pub fn parse(text: &str, path: &Path) -> Result<Plc, InputError> {
    let mut lines = Lines::new(text, path);
    let mut plc = Plc {
        source: path.to_path_buf(),
        ..Default::default()
    };
    let mut header = lines.expect_line(|| {
        "the node header `<#points> <dimension> <#attributes> <#boundary markers>`".into()
    })?;
    let count = header.count(|| "the number of points".into())?;
    read_points(&mut lines, header, count, &mut plc)?;
    Ok(plc)
}

/// Reads the points announced by a node section header, whose point count (`count`) has
/// already been consumed from `header`; fills the points, attributes, markers and
/// `first_index` of `plc`. Shared by the `.node`, `.poly` and `.smesh` readers.
pub(crate) fn read_points(
    lines: &mut Lines<'_>,
    mut header: Line<'_>,
    count: usize,
    plc: &mut Plc,
) -> Result<(), InputError> {
    let dim = header.opt_count(|| "the dimension".into())?.unwrap_or(3);
    if dim != 3 {
        return Err(header.error(format!("the dimension must be 3, found {dim}")));
    }
    let nattrs = header
        .opt_count(|| "the number of point attributes".into())?
        .unwrap_or(0);
    let has_markers = header.opt_flag(|| "the number of point boundary markers".into())?;
    if u32::try_from(count).is_err() {
        return Err(header.error(format!(
            "too many points: {count} (at most {} are supported)",
            u32::MAX
        )));
    }
    let header_line = header.number();

    let cap = lines.capacity_for(count);
    plc.points = Vec::with_capacity(cap);
    plc.num_point_attrs = nattrs;
    plc.point_attrs = Vec::with_capacity(
        cap.saturating_mul(nattrs)
            .min(lines.capacity_for(usize::MAX)),
    );
    let mut markers = if has_markers {
        Some(Vec::with_capacity(cap))
    } else {
        None
    };
    let mut first = 0usize;

    for i in 0..count {
        let mut line = lines.expect_line(|| {
            if i == 0 {
                format!("the first of {count} points announced on line {header_line}")
            } else {
                format!(
                    "point {} ({} of {count} announced on line {header_line})",
                    first + i,
                    i + 1
                )
            }
        })?;
        let number = line.int(|| {
            if i == 0 {
                "the number of the first point".into()
            } else {
                format!("the number of point {}", first + i)
            }
        })?;
        if i == 0 {
            first = match number {
                0 => 0,
                1 => 1,
                _ => {
                    return Err(line.error(format!(
                        "the first point must be numbered 0 or 1, found {number}"
                    )))
                }
            };
            plc.first_index = first;
        } else {
            // `first + i` < 2^32 + 1, so this conversion cannot fail in practice.
            let expected = i64::try_from(first + i).unwrap_or(i64::MAX);
            if number != expected {
                return Err(line.error(format!(
                    "points must be numbered consecutively: expected point {expected}, found {number}"
                )));
            }
        }
        let n = first + i;
        let p = line.xyz(&|| format!("point {n}"))?;
        plc.points.push(p);
        for a in 0..nattrs {
            let v = line.float(|| format!("attribute {} of point {n}", a + 1))?;
            plc.point_attrs.push(v);
        }
        if let Some(m) = markers.as_mut() {
            m.push(line.marker(|| format!("the boundary marker of point {n}"))?);
        }
    }
    plc.point_markers = markers;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_ok(text: &str) -> Plc {
        parse(text, Path::new("t.node")).unwrap()
    }

    fn parse_err(text: &str) -> String {
        parse(text, Path::new("t.node")).unwrap_err().to_string()
    }

    #[test]
    fn reads_points_numbered_from_one() {
        let plc = parse_ok("3 3 0 0\n1 0 0 0\n2 1.5 0 0\n3 0 -2e3 .5\n");
        assert_eq!(plc.first_index, 1);
        assert_eq!(
            plc.points,
            vec![[0.0, 0.0, 0.0], [1.5, 0.0, 0.0], [0.0, -2000.0, 0.5]]
        );
        assert_eq!(plc.num_point_attrs, 0);
        assert!(plc.point_attrs.is_empty());
        assert!(plc.point_markers.is_none());
        assert_eq!(plc.source, Path::new("t.node"));
    }

    #[test]
    fn reads_points_numbered_from_zero_with_comments_and_blank_lines() {
        let text = "# a comment\n\n2 3 # two points\n\n0 0 0 0 # origin\n  # nothing\n1\t1,1,1\n\n";
        let plc = parse_ok(text);
        assert_eq!(plc.first_index, 0);
        assert_eq!(plc.points, vec![[0.0; 3], [1.0; 3]]);
    }

    #[test]
    fn reads_attributes_and_markers() {
        let plc = parse_ok("2 3 2 1\n1 0 0 0 0.5 7 -3\n2 1 1 1 1.5 8 4 extra ignored\n");
        assert_eq!(plc.num_point_attrs, 2);
        assert_eq!(plc.point_attrs, vec![0.5, 7.0, 1.5, 8.0]);
        assert_eq!(plc.point_markers, Some(vec![-3, 4]));
    }

    #[test]
    fn empty_point_list() {
        let plc = parse_ok("0 3 0 0\n");
        assert!(plc.points.is_empty());
    }

    #[test]
    fn bad_numbering() {
        assert_eq!(
            parse_err("3 3 0 0\n1 0 0 0\n2 0 0 0\n4 0 0 0\n"),
            "t.node:4: points must be numbered consecutively: expected point 3, found 4"
        );
        assert_eq!(
            parse_err("1 3 0 0\n5 0 0 0\n"),
            "t.node:2: the first point must be numbered 0 or 1, found 5"
        );
        assert!(parse_err("1 3 0 0\nx 0 0 0\n")
            .starts_with("t.node:2: expected the number of the first point"));
    }

    #[test]
    fn bad_coordinates() {
        assert_eq!(
            parse_err("12 3 0 0\n1 0 0 0\n2 0 0 0\n3 0 0 0\n4 0 0 0\n5 0 0 0\n6 0 0 0\n7 0 0 0\n8 0 0 0\n9 0 0 0\n10 0 0 0\n11 0 0 0\n12 abc 0 0\n"),
            "t.node:13: expected the x coordinate of point 12, found `abc`"
        );
        assert_eq!(
            parse_err("2 3 0 0\n0 0 0 0\n1 0 nan 0\n"),
            "t.node:3: the y coordinate of point 1 is not a finite number: `nan`"
        );
        assert_eq!(
            parse_err("1 3 0 0\n1 0 0 1e999\n"),
            "t.node:2: the z coordinate of point 1 is not a finite number: `1e999`"
        );
        assert_eq!(
            parse_err("1 3 0 0\n1 0 0\n"),
            "t.node:2: expected the z coordinate of point 1, but the line ends"
        );
        assert_eq!(
            parse_err("1 3 1 1\n1 0 0 0 inf 1\n"),
            "t.node:2: attribute 1 of point 1 is not a finite number: `inf`"
        );
        assert_eq!(
            parse_err("1 3 1 1\n1 0 0 0 2\n"),
            "t.node:2: expected the boundary marker of point 1, but the line ends"
        );
        assert_eq!(
            parse_err("1 3 0 1\n1 0 0 0 1.5\n"),
            "t.node:2: expected the boundary marker of point 1 (an integer), found `1.5`"
        );
    }

    #[test]
    fn bad_headers() {
        assert_eq!(parse_err(""), "t.node:1: unexpected end of file: expected the node header `<#points> <dimension> <#attributes> <#boundary markers>`");
        assert_eq!(parse_err("# only a comment\n"), "t.node:1: unexpected end of file: expected the node header `<#points> <dimension> <#attributes> <#boundary markers>`");
        assert_eq!(
            parse_err("-4 3 0 0\n"),
            "t.node:1: the number of points cannot be negative, found `-4`"
        );
        assert_eq!(
            parse_err("4.5 3 0 0\n"),
            "t.node:1: expected the number of points (a non-negative integer), found `4.5`"
        );
        assert_eq!(
            parse_err("\n4 2 0 0\n"),
            "t.node:2: the dimension must be 3, found 2"
        );
        assert_eq!(
            parse_err("4 3 -1 0\n"),
            "t.node:1: the number of point attributes cannot be negative, found `-1`"
        );
        assert_eq!(
            parse_err("4 3 0 2\n"),
            "t.node:1: the number of point boundary markers must be 0 or 1, found `2`"
        );
        assert!(parse_err("99999999999999999999999 3 0 0\n")
            .contains("the number of points is out of range"));
        assert!(parse_err("99999999999 3 0 0\n").contains("too many points"));
    }

    #[test]
    fn truncated_file_does_not_allocate_blindly() {
        assert_eq!(
            parse_err("4000000000 3 1000000000 1\n1 0 0 0\n"),
            "t.node:2: expected attribute 1 of point 1, but the line ends"
        );
        assert_eq!(
            parse_err("4000000000 3 0 0\n1 0 0 0\n2 0 0 0\n"),
            "t.node:3: unexpected end of file: expected point 3 (3 of 4000000000 announced on line 1)"
        );
        assert_eq!(
            parse_err("3 3 0 0 # three\n\n"),
            "t.node:2: unexpected end of file: expected the first of 3 points announced on line 1"
        );
    }

    #[test]
    fn duplicate_points_are_accepted() {
        assert_eq!(parse_ok("2\n1 1 2 3\n2 1 2 3\n").points.len(), 2);
    }

    #[test]
    fn reads_a_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.node");
        std::fs::write(&path, "1 3 0 0\n0 1 2 3\n").unwrap();
        assert_eq!(read(&path).unwrap().points, vec![[1.0, 2.0, 3.0]]);
        let missing = dir.path().join("missing.node");
        let e = read(&missing).unwrap_err();
        assert!(matches!(e, InputError::Io { .. }));
        assert!(e.to_string().contains("missing.node"));
    }

    #[test]
    fn example_file_parses() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples/points8.node");
        let plc = read(&path).unwrap();
        assert_eq!(plc.points.len(), 8);
    }
}
