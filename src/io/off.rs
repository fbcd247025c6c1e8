//! Reader of Geomview `.off` files (a polygonal surface).
//!
//! Accepted: a header keyword `OFF`, `COFF`, `NOFF`, `CNOFF` (more generally
//! `[ST][C][N]OFF`; 4-dimensional, n-dimensional and binary variants are rejected), the
//! counts `<#vertices> <#faces> [#edges]` on the header line or on the next one (a file
//! starting directly with the counts is accepted too), then one vertex per line (`x y z`,
//! further columns such as normals, colors or texture coordinates are ignored), then one
//! face per line `<n> <v0> ... <v(n-1)> [color...]` with any `n >= 1` (1: an isolated
//! vertex, 2: a segment); a face whose line ends before its corners goes on over the next
//! lines, since Geomview reads OFF token by token. `#` starts a comment. The edge section
//! is ignored.
//!
//! Vertices are numbered from 0 (`first_index = 0`); each face becomes one facet with one
//! polygon and marker 0. (TetGen 1.5, given an `.off` file with `-p`, writes boundary
//! marker 1 on the hull faces of its `.face` output, exactly as it does for a `.poly`
//! file whose facet section has no markers; so the input marker is 0, and the 1 is an
//! output convention for inputs without facet markers.)

use super::tokens::{corner_index, read_text, Line, Lines};
use crate::error::InputError;
use crate::plc::{Facet, Plc};
use std::path::Path;

/// Reads an `.off` file.
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let text = read_text(path)?;
    parse(&text, path)
}

/// Checks an OFF header keyword: `[ST][C][N]OFF`.
fn check_keyword(keyword: &str, line: &Line<'_>) -> Result<(), InputError> {
    if keyword == "off" {
        return Ok(());
    }
    let rest = keyword.strip_prefix("ST").unwrap_or(keyword);
    let rest = rest.strip_prefix('C').unwrap_or(rest);
    let rest = rest.strip_prefix('N').unwrap_or(rest);
    match rest {
        "OFF" => Ok(()),
        "4OFF" | "n4OFF" | "4nOFF" | "nOFF" => Err(line.error(format!(
            "`{keyword}` files have vertices of another dimension; only 3-dimensional OFF files are supported"
        ))),
        _ => Err(line.error(format!(
            "expected the OFF header (OFF, COFF, NOFF, CNOFF...), found `{keyword}`"
        ))),
    }
}

/// Parses the text of an `.off` file; `path` is used in error messages and as the source.
pub fn parse(text: &str, path: &Path) -> Result<Plc, InputError> {
    let mut lines = Lines::new(text, path);
    let mut line = lines.expect_line(|| "the OFF header".into())?;
    // Anything but an integer in first place is a header keyword (the counts line of a
    // file without a keyword starts with an integer).
    let has_keyword = line.peek_token().is_some_and(|t| t.parse::<i64>().is_err());
    if has_keyword {
        let keyword = line.next_token().unwrap_or_default();
        check_keyword(keyword, &line)?;
        if line
            .peek_token()
            .is_some_and(|t| t.eq_ignore_ascii_case("BINARY"))
        {
            return Err(line.error("binary OFF files are not supported"));
        }
        if line.at_end() {
            line = lines.expect_line(|| "the counts `<#vertices> <#faces> <#edges>`".into())?;
        }
    }
    let nv = line.count(|| "the number of vertices".into())?;
    let nf = line.count(|| "the number of faces".into())?;
    line.opt_count(|| "the number of edges".into())?;
    if u32::try_from(nv).is_err() {
        return Err(line.error(format!(
            "too many vertices: {nv} (at most {} are supported)",
            u32::MAX
        )));
    }
    let counts_line = line.number();

    let mut plc = Plc {
        source: path.to_path_buf(),
        first_index: 0,
        ..Default::default()
    };
    plc.points = Vec::with_capacity(lines.capacity_for(nv));
    for i in 0..nv {
        let mut line = lines.expect_line(|| {
            format!(
                "vertex {i} ({} of {nv} announced on line {counts_line})",
                i + 1
            )
        })?;
        plc.points.push(line.xyz(&|| format!("vertex {i}"))?);
    }

    plc.facets = Vec::with_capacity(lines.capacity_for(nf));
    for f in 0..nf {
        let mut line = lines.expect_line(|| {
            format!(
                "face {f} ({} of {nf} announced on line {counts_line})",
                f + 1
            )
        })?;
        let n = line.count(|| format!("the number of corners of face {f}"))?;
        if n == 0 {
            return Err(line.error(format!("face {f} has no corners")));
        }
        let first_line = line.number();
        let mut polygon = Vec::with_capacity(n.min(line.remaining_len() / 2 + 1));
        for c in 0..n {
            if line.at_end() {
                // Geomview reads OFF token by token: a face may go on over several lines.
                line = lines.expect_line(|| {
                    format!("corner {c} of face {f} (line {first_line} announces {n})")
                })?;
            }
            let v = line.int(|| format!("corner {c} of face {f}"))?;
            let index = corner_index(v, 0, nv, "vertex", "vertices")
                .map_err(|msg| line.error(format!("face {f} {msg}")))?;
            polygon.push(index);
        }
        plc.facets.push(Facet {
            polygons: vec![polygon],
            holes: Vec::new(),
            marker: 0,
            line: first_line,
        });
    }
    Ok(plc)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BODY: &str = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n";

    fn parse_ok(text: &str) -> Plc {
        parse(text, Path::new("t.off")).unwrap()
    }

    fn parse_err(text: &str) -> String {
        parse(text, Path::new("t.off")).unwrap_err().to_string()
    }

    #[test]
    fn reads_a_pyramid_with_polygons_of_any_size() {
        let text =
            format!("OFF\n5 6 0\n{BODY}4 0 1 2 3\n3 0 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n2 0 2\n");
        let plc = parse_ok(&text);
        assert_eq!(plc.first_index, 0);
        assert_eq!(plc.points.len(), 5);
        assert_eq!(plc.points[4], [0.0, 0.0, 1.0]);
        assert_eq!(plc.facets.len(), 6);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2, 3]]);
        assert_eq!(plc.facets[5].polygons, vec![vec![0, 2]]);
        assert!(plc
            .facets
            .iter()
            .all(|f| f.marker == 0 && f.holes.is_empty()));
        assert_eq!(plc.facets[0].line, 8);
        assert_eq!(plc.source, Path::new("t.off"));
    }

    #[test]
    fn header_variants() {
        let faces = "5 0 1 2 3 4\n1 4\n";
        for header in [
            "OFF\n5 2 0\n",
            "OFF 5 2 0\n",
            "OFF 5 2\n",
            "5 2 0\n",
            "off\n5 2 0\n",
        ] {
            let plc = parse_ok(&format!("{header}{BODY}{faces}"));
            assert_eq!(
                plc.facets[0].polygons,
                vec![vec![0, 1, 2, 3, 4]],
                "{header}"
            );
            assert_eq!(plc.facets[1].polygons, vec![vec![4]], "{header}");
        }
        // Extra columns of vertices (colors, normals) and faces (colors) are ignored.
        let coff = "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2 0.5 0.5 0.5 1\n";
        assert_eq!(parse_ok(coff).points[1], [1.0, 0.0, 0.0]);
        let noff = "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
        assert_eq!(parse_ok(noff).points[2], [0.0, 1.0, 0.0]);
        let cnoff = "CNOFF\n3 1 0\n0 0 0 0 0 1 1 1 1 1\n1 0 0 0 0 1 1 1 1 1\n0 1 0 0 0 1 1 1 1 1\n3 2 1 0\n";
        assert_eq!(parse_ok(cnoff).facets[0].polygons, vec![vec![2, 1, 0]]);
        assert_eq!(
            parse_ok("STCNOFF\n1 0 0\n1 2 3 0 0 0 0 1\n").points,
            vec![[1.0, 2.0, 3.0]]
        );
    }

    #[test]
    fn comments_and_blank_lines() {
        let text = "# made by hand\nOFF # keyword\n\n# counts\n3 1 0\n0 0 0 # v0\n\n1 0 0\n# between\n0 1 0\n3 0 1 2 # the face\n";
        let plc = parse_ok(text);
        assert_eq!(plc.points.len(), 3);
        assert_eq!(plc.facets[0].line, 11);
    }

    #[test]
    fn errors() {
        assert_eq!(parse_err("4OFF\n"), "t.off:1: `4OFF` files have vertices of another dimension; only 3-dimensional OFF files are supported");
        assert_eq!(
            parse_err("PLY\n"),
            "t.off:1: expected the OFF header (OFF, COFF, NOFF, CNOFF...), found `PLY`"
        );
        assert_eq!(
            parse_err("OFF BINARY\n"),
            "t.off:1: binary OFF files are not supported"
        );
        assert_eq!(
            parse_err(""),
            "t.off:1: unexpected end of file: expected the OFF header"
        );
        assert_eq!(
            parse_err("OFF\n"),
            "t.off:1: unexpected end of file: expected the counts `<#vertices> <#faces> <#edges>`"
        );
        assert_eq!(
            parse_err("OFF\n-5 2 0\n"),
            "t.off:2: the number of vertices cannot be negative, found `-5`"
        );
        assert_eq!(
            parse_err("OFF\n5 x 0\n"),
            "t.off:2: expected the number of faces (a non-negative integer), found `x`"
        );
        assert_eq!(
            parse_err("OFF\n5 1 0\n0 0 0\n1 0 0\n"),
            "t.off:4: unexpected end of file: expected vertex 2 (3 of 5 announced on line 2)"
        );
        assert_eq!(
            parse_err(&format!("OFF\n5 2 0\n{BODY}3 0 1 2\n")),
            "t.off:8: unexpected end of file: expected face 1 (2 of 2 announced on line 2)"
        );
        assert_eq!(
            parse_err(&format!("OFF\n5 1 0\n{BODY}3 0 1 5\n")),
            "t.off:8: face 0 has corner 5, but there are only 5 vertices (numbered from 0)"
        );
        assert_eq!(
            parse_err(&format!("OFF\n5 1 0\n{BODY}3 0 -1 2\n")),
            "t.off:8: face 0 has corner -1, but the vertices are numbered from 0"
        );
        assert_eq!(
            parse_err(&format!("OFF\n5 1 0\n{BODY}4 0 1 2\n")),
            "t.off:8: unexpected end of file: expected corner 3 of face 0 (line 8 announces 4)"
        );
        assert_eq!(
            parse_err(&format!("OFF\n5 1 0\n{BODY}4 0 1 2\nx\n")),
            "t.off:9: expected corner 3 of face 0 (an integer), found `x`"
        );
        assert_eq!(
            parse_err(&format!("OFF\n5 1 0\n{BODY}0\n")),
            "t.off:8: face 0 has no corners"
        );
        assert_eq!(
            parse_err("OFF\n2 0 0\n0 0 0\n0 nan 0\n"),
            "t.off:4: the y coordinate of vertex 1 is not a finite number: `nan`"
        );
        assert_eq!(
            parse_err("OFF\n1 0 0\n0 0 1e400\n"),
            "t.off:3: the z coordinate of vertex 0 is not a finite number: `1e400`"
        );
        assert_eq!(
            parse_err("OFF\n1 0 0\n0 0\n"),
            "t.off:3: expected the z coordinate of vertex 0, but the line ends"
        );
        assert_eq!(
            parse_err("OFF\n100000000000000 0 0\n0 0 0\n"),
            "t.off:2: too many vertices: 100000000000000 (at most 4294967295 are supported)"
        );
        assert_eq!(
            parse_err("OFF\n1 100000000000 0\n0 0 0\n"),
            "t.off:3: unexpected end of file: expected face 0 (1 of 100000000000 announced on line 2)"
        );
    }

    #[test]
    fn example_file_parses() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples/cube.off");
        let plc = read(&path).unwrap();
        assert_eq!((plc.points.len(), plc.facets.len()), (8, 6));
    }
}
