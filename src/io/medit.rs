//! Reader of Medit `.mesh` files (ASCII; binary `.meshb` is refused by `read_plc`).
//!
//! A file is a sequence of keywords, each followed by its data, with free line breaks
//! and `#` comments: `MeshVersionFormatted <v>`, `Dimension <d>` (3 only), `Vertices
//! <n>` then `x y z ref` per vertex, `Triangles <n>` then `a b c ref`, `Quadrilaterals
//! <n>` then `a b c d ref`, and `End`. Triangles and quadrilaterals become one-polygon
//! facets whose marker is the `ref`; corners are numbered from 1. Every other section
//! Medit defines (`Edges`, `Tetrahedra`, `Corners`, `Ridges`, `RequiredVertices`,
//! `Normals`, ...) is skipped, entry by entry, so that its data is not taken for a
//! keyword. A volume mesh thus gives its vertices (interior ones included, as TetGen
//! reads them) and its surface triangles.
//!
//! Output numbering follows TetGen, which numbers a Medit model's nodes from 1.

use super::token_stream::Tokens;
use super::tokens::{corner_index, read_text};
use crate::error::InputError;
use crate::plc::{Facet, Plc};
use std::path::Path;

/// Reads a `.mesh` file.
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let text = read_text(path)?;
    parse(&text, path)
}

/// Sections that are read past: keyword and number of tokens per entry (in 3-D).
const SKIPPED: &[(&str, usize)] = &[
    ("Edges", 3),
    ("Tetrahedra", 5),
    ("Hexahedra", 9),
    ("Prisms", 7),
    ("Pyramids", 6),
    ("Corners", 1),
    ("Ridges", 1),
    ("RequiredVertices", 1),
    ("RequiredEdges", 1),
    ("RequiredTriangles", 1),
    ("RequiredQuadrilaterals", 1),
    ("RequiredTetrahedra", 1),
    ("Normals", 3),
    ("Tangents", 3),
    ("NormalAtVertices", 2),
    ("NormalAtTriangleVertices", 3),
    ("NormalAtQuadrilateralVertices", 3),
    ("TangentAtVertices", 2),
    ("TangentAtEdges", 3),
    ("EdgesP2", 4),
    ("TrianglesP2", 7),
    ("QuadrilateralsQ2", 10),
    ("TetrahedraP2", 11),
    ("HexahedraQ2", 28),
];

/// The most entries reserved in advance, whatever a count says.
const MAX_RESERVE: usize = 1 << 16;

/// Parses the text of a `.mesh` file; `path` is used in error messages and as the source.
pub fn parse(text: &str, path: &Path) -> Result<Plc, InputError> {
    let mut t = Tokens::new(text, path);
    let mut plc = Plc {
        source: path.to_path_buf(),
        first_index: 1,
        ..Default::default()
    };
    let mut have_vertices = false;
    let mut ended = false;
    while let Some(line) = t.line() {
        let key = line.token(String::new)?;
        let is = |k: &str| key.eq_ignore_ascii_case(k);
        if is("End") {
            ended = true;
            break;
        }
        if is("MeshVersionFormatted") {
            let what = || "the version after MeshVersionFormatted".to_string();
            let v = t.expect(what)?.int(what)?;
            if !(1..=4).contains(&v) {
                return Err(t.error(format!("unknown Medit version {v} (expected 1 to 4)")));
            }
        } else if is("Dimension") {
            let what = || "the dimension after Dimension".to_string();
            let d = t.expect(what)?.int(what)?;
            if d != 3 {
                return Err(t.error(format!(
                    "only 3-dimensional meshes are supported, found Dimension {d}"
                )));
            }
        } else if is("Vertices") {
            if have_vertices {
                return Err(t.error("a second Vertices section"));
            }
            have_vertices = true;
            let (n, line_no) = count(&mut t, "Vertices")?;
            if u32::try_from(n).is_err() {
                return Err(t.error(format!("too many vertices: {n}")));
            }
            plc.points.reserve(n.min(MAX_RESERVE));
            for i in 0..n {
                let mut p = [0.0; 3];
                for (k, x) in p.iter_mut().enumerate() {
                    let what = || {
                        format!(
                            "the {} coordinate of vertex {} ({} of {n} announced on line {line_no})",
                            ["x", "y", "z"][k],
                            i + 1,
                            i + 1
                        )
                    };
                    *x = t.expect(what)?.float(what)?;
                }
                let what = || format!("the reference of vertex {}", i + 1);
                t.expect(what)?.marker(what)?;
                plc.points.push(p);
            }
        } else if is("Triangles") || is("Quadrilaterals") {
            let (kind, corners) = if is("Triangles") {
                ("triangle", 3)
            } else {
                ("quadrilateral", 4)
            };
            let (n, line_no) = count(&mut t, key)?;
            plc.facets.reserve(n.min(MAX_RESERVE));
            let nv = plc.points.len();
            for i in 0..n {
                let mut polygon = Vec::with_capacity(corners);
                let mut first_line = 0;
                for c in 0..corners {
                    let what = || {
                        format!(
                            "corner {c} of {kind} {} ({} of {n} announced on line {line_no})",
                            i + 1,
                            i + 1
                        )
                    };
                    let line = t.expect(what)?;
                    let v = line.int(what)?;
                    if c == 0 {
                        first_line = line.number();
                    }
                    let index = corner_index(v, 1, nv, "vertex", "vertices")
                        .map_err(|msg| line.error(format!("{kind} {} {msg}", i + 1)))?;
                    polygon.push(index);
                }
                let what = || format!("the reference of {kind} {}", i + 1);
                let marker = t.expect(what)?.marker(what)?;
                plc.facets.push(Facet {
                    polygons: vec![polygon],
                    holes: Vec::new(),
                    marker,
                    line: first_line,
                });
            }
        } else if let Some(&(name, per)) = SKIPPED.iter().find(|(k, _)| is(k)) {
            let (n, line_no) = count(&mut t, name)?;
            for i in 0..n {
                for k in 0..per {
                    let what = || {
                        format!(
                            "value {} of entry {} of {name} ({} of {n} announced on line {line_no})",
                            k + 1,
                            i + 1,
                            i + 1
                        )
                    };
                    t.expect(what)?.token(what)?;
                }
            }
        } else {
            let hint = if key.parse::<f64>().is_ok() {
                " (more data than the last section announced?)"
            } else {
                ""
            };
            return Err(t.error(format!("unknown Medit keyword `{key}`{hint}")));
        }
    }
    if !ended && !have_vertices {
        return Err(t.error("no Vertices section and no End: is this a Medit .mesh file?"));
    }
    Ok(plc)
}

/// Reads the entry count after a section keyword; returns it with its line.
fn count(t: &mut Tokens<'_>, section: &str) -> Result<(usize, usize), InputError> {
    let what = || format!("the number of entries of {section}");
    let line = t.expect(what)?;
    Ok((line.count(what)?, line.number()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_ok(text: &str) -> Plc {
        parse(text, Path::new("t.mesh")).unwrap()
    }

    fn parse_err(text: &str) -> String {
        parse(text, Path::new("t.mesh")).unwrap_err().to_string()
    }

    const HEAD: &str = "MeshVersionFormatted 1\n# a comment\nDimension\n3\nVertices\n4\n\
        0 0 0 1\n1 0 0 1\n0 1 0 1\n0 0 1 2\n";

    #[test]
    fn reads_facets_and_skips_other_sections() {
        let text = format!(
            "{HEAD}Edges 1\n1 2 0\nTriangles 2\n1 2 3 7\n1 2 4 8\nCorners\n2 1 2\n\
             Quadrilaterals 1\n1 2 3 4 9\nTetrahedra 1\n1 2 3 4 0\n NormalAtVertices 1 1 1\n End\n"
        );
        let plc = parse_ok(&text);
        assert_eq!(plc.first_index, 1);
        assert_eq!(plc.points.len(), 4);
        assert_eq!(plc.points[3], [0.0, 0.0, 1.0]);
        let facets: Vec<_> = plc
            .facets
            .iter()
            .map(|f| (f.polygons.clone(), f.marker, f.line))
            .collect();
        assert_eq!(
            facets,
            vec![
                (vec![vec![0, 1, 2]], 7, 14),
                (vec![vec![0, 1, 3]], 8, 15),
                (vec![vec![0, 1, 2, 3]], 9, 19),
            ]
        );
    }

    #[test]
    fn errors() {
        assert_eq!(
            parse_err(&format!("{HEAD}Triangles 1\n1 2 5 0\nEnd\n")),
            "t.mesh:12: triangle 1 has corner 5, but there are only 4 vertices (numbered from 1)"
        );
        assert_eq!(
            parse_err(&format!("{HEAD}Triangles 1\n0 2 3 0\nEnd\n")),
            "t.mesh:12: triangle 1 has corner 0, but the vertices are numbered from 1"
        );
        assert_eq!(
            parse_err("Dimension 2\n"),
            "t.mesh:1: only 3-dimensional meshes are supported, found Dimension 2"
        );
        assert_eq!(
            parse_err("Vertices 2\n0 0 0 0\n0 inf 0 0\n"),
            "t.mesh:3: the y coordinate of vertex 2 (2 of 2 announced on line 1) is not a finite number: `inf`"
        );
        assert_eq!(
            parse_err("Vertices 2\n0 0 0 0\n0 0 0\n"),
            "t.mesh:3: unexpected end of file: expected the reference of vertex 2"
        );
        assert_eq!(
            parse_err(&format!("{HEAD}Tetrahedra 2\n1 2 3 4 0\nEnd\n")),
            "t.mesh:13: unexpected end of file: expected value 2 of entry 2 of Tetrahedra (2 of 2 announced on line 11)"
        );
        assert_eq!(
            parse_err(&format!("{HEAD}Triangle 1\n1 2 3 0\n")),
            "t.mesh:11: unknown Medit keyword `Triangle`"
        );
        assert_eq!(
            parse_err(&format!("{HEAD}Triangles 1\n1 2 3 0 4\n")),
            "t.mesh:12: unknown Medit keyword `4` (more data than the last section announced?)"
        );
        assert_eq!(
            parse_err("Vertices -1\n"),
            "t.mesh:1: the number of entries of Vertices cannot be negative, found `-1`"
        );
        assert_eq!(
            parse_err("hello\n"),
            "t.mesh:1: unknown Medit keyword `hello`"
        );
        assert_eq!(
            parse_err("# nothing\n"),
            "t.mesh:1: no Vertices section and no End: is this a Medit .mesh file?"
        );
    }
}
