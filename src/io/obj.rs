//! Reader of Wavefront `.obj` files (a polygonal surface).
//!
//! Only geometry is read: `v x y z [w]` lines (a fourth value is the homogeneous
//! coordinate `w` and divides x, y and z; six or seven values are positions followed by a
//! vertex color, which is ignored) and `f` lines, whose corners may be written `v`,
//! `v/vt`, `v//vn` or `v/vt/vn`; only the position index `v` is used. Positive indices
//! count from 1; negative ones are relative to the vertices defined so far (`-1` is the
//! last one). Faces are not triangulated: each `f` line becomes one facet with one polygon
//! (of any size; 1 or 2 corners are accepted too, as isolated vertices and segments) and
//! marker 0. Groups and objects (`g`, `o`) are merged into one model; every other
//! statement (`vt`, `vn`, `l`, `p`, `s`, `usemtl`, `mtllib`, ...) is ignored. A line ending
//! with a backslash continues on the next line; `#` starts a comment.
//!
//! This is a small hand-written parser rather than the `tobj` crate: tobj stores
//! positions as `f32` unless its `use_f64` feature is enabled, its errors carry no line
//! numbers, and it renumbers vertices per model (dropping the unreferenced ones), so the
//! points would neither keep the file's order nor match its numbering.
//!
//! OBJ numbers vertices from 1, so `first_index` is 1: output files number points from 1,
//! as the input does, and messages name vertices and faces counted from 1.

use super::tokens::{read_text, strip_comment, Line, Lines};
use crate::error::InputError;
use crate::plc::{Facet, Plc};
use std::path::Path;

/// Reads an `.obj` file.
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let text = read_text(path)?;
    parse(&text, path)
}

/// Parses the text of an `.obj` file; `path` is used in error messages and as the source.
pub fn parse(text: &str, path: &Path) -> Result<Plc, InputError> {
    let mut lines = Lines::new(text, path);
    let mut plc = Plc {
        source: path.to_path_buf(),
        first_index: 1,
        ..Default::default()
    };
    let mut joined = String::new();

    while let Some((number, raw)) = lines.next_raw() {
        // Join continuation lines (ending with a backslash); errors name the first line.
        let content: &str = if strip_comment(raw).trim_end().ends_with('\\') {
            joined.clear();
            let mut part = strip_comment(raw).trim_end();
            loop {
                match part.strip_suffix('\\') {
                    Some(head) => {
                        joined.push_str(head);
                        joined.push(' ');
                        match lines.next_raw() {
                            Some((_, next)) => part = strip_comment(next).trim_end(),
                            None => break,
                        }
                    }
                    None => {
                        joined.push_str(part);
                        break;
                    }
                }
            }
            &joined
        } else {
            strip_comment(raw)
        };
        let mut line = Line::new(path, number, content);
        match line.next_token() {
            Some("v") => {
                let n = plc.points.len() + 1;
                if u32::try_from(n).is_err() {
                    return Err(line.error(format!(
                        "too many vertices (at most {} are supported)",
                        u32::MAX
                    )));
                }
                plc.points.push(read_vertex(&mut line, n)?);
            }
            Some("f") => {
                let f = plc.facets.len() + 1;
                let polygon = read_face(&mut line, f, plc.points.len())?;
                plc.facets.push(Facet {
                    polygons: vec![polygon],
                    holes: Vec::new(),
                    marker: 0,
                    line: number,
                });
            }
            _ => {}
        }
    }

    // Positive indices may refer to vertices defined further down; check them now.
    let count = plc.points.len();
    for (f, facet) in plc.facets.iter().enumerate() {
        for polygon in &facet.polygons {
            if let Some(&bad) = polygon.iter().find(|&&v| v as usize >= count) {
                let written = u64::from(bad) + 1;
                let msg = if count == 1 {
                    format!(
                        "face {} has corner {written}, but there is only 1 vertex",
                        f + 1
                    )
                } else {
                    format!(
                        "face {} has corner {written}, but there are only {count} vertices (numbered from 1)",
                        f + 1
                    )
                };
                return Err(InputError::parse(path, facet.line, msg));
            }
        }
    }
    Ok(plc)
}

/// Reads `x y z [w]` (or `x y z r g b [a]`) after `v`.
fn read_vertex(line: &mut Line<'_>, n: usize) -> Result<[f64; 3], InputError> {
    let [x, y, z] = line.xyz(&|| format!("vertex {n}"))?;
    let mut extra = line.clone();
    let mut count = 0usize;
    while extra.next_token().is_some() {
        count += 1;
    }
    if count == 1 {
        let w = line.float(|| format!("the w coordinate of vertex {n}"))?;
        if w == 0.0 {
            return Err(line.error(format!("the w coordinate of vertex {n} is 0")));
        }
        let p = [x / w, y / w, z / w];
        if p.iter().any(|c| !c.is_finite()) {
            return Err(line.error(format!(
                "vertex {n} divided by its w coordinate is not finite"
            )));
        }
        return Ok(p);
    }
    Ok([x, y, z])
}

/// Reads the corners of an `f` line as 0-based indices. Negative indices are resolved
/// against the `defined` vertices so far; positive ones are checked by the caller.
fn read_face(line: &mut Line<'_>, f: usize, defined: usize) -> Result<Vec<u32>, InputError> {
    let mut polygon = Vec::new();
    let mut c = 0usize;
    while let Some(tok) = line.next_token() {
        c += 1;
        let v = tok.split('/').next().unwrap_or(tok);
        if v.is_empty() {
            return Err(line.error(format!(
                "face {f}: corner {c} (`{tok}`) has no vertex index"
            )));
        }
        let mut single = Line::new(line.path(), line.number(), v);
        let index = single.int(|| format!("the vertex of corner {c} of face {f}"))?;
        let resolved = match index {
            0 => {
                return Err(line.error(format!(
                    "face {f}: corner {c} has vertex index 0 (OBJ numbers vertices from 1)"
                )))
            }
            i if i > 0 => u64::try_from(i - 1).ok(),
            // -1 is the last vertex defined so far.
            i => u64::try_from(defined)
                .ok()
                .and_then(|d| i.checked_add(i64::try_from(d).ok()?))
                .and_then(|r| u64::try_from(r).ok()),
        };
        let Some(resolved) = resolved else {
            return Err(line.error(format!(
                "face {f}: corner {c} is vertex {index}, but only {defined} vertices are defined before this line"
            )));
        };
        let Ok(resolved) = u32::try_from(resolved) else {
            return Err(line.error(format!(
                "face {f}: corner {c} is vertex {index}, which is too large"
            )));
        };
        polygon.push(resolved);
    }
    if polygon.is_empty() {
        return Err(line.error(format!("face {f} has no corners")));
    }
    Ok(polygon)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

    fn parse_ok(text: &str) -> Plc {
        parse(text, Path::new("t.obj")).unwrap()
    }

    fn parse_err(text: &str) -> String {
        parse(text, Path::new("t.obj")).unwrap_err().to_string()
    }

    #[test]
    fn quad_face_with_slashes_is_not_triangulated() {
        let text = format!("# square\nmtllib a.mtl\no sq\n{SQUARE}vt 0 0\nvn 0 0 1\nusemtl x\nf 1/1/1 2/2/1 3//1 4/3\n");
        let plc = parse_ok(&text);
        assert_eq!(plc.first_index, 1);
        assert_eq!(plc.points.len(), 4);
        assert_eq!(plc.facets.len(), 1);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2, 3]]);
        assert_eq!(plc.facets[0].line, 11);
        assert_eq!(plc.facets[0].marker, 0);
    }

    #[test]
    fn negative_indices_are_relative() {
        let text = format!("{SQUARE}f -4 -3 -2 -1\nv 0 0 1\nf -5/1 -4 -1\ng other\nf 5 1 2\n");
        let plc = parse_ok(&text);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2, 3]]);
        assert_eq!(plc.facets[1].polygons, vec![vec![0, 1, 4]]);
        assert_eq!(plc.facets[2].polygons, vec![vec![4, 0, 1]]);
    }

    #[test]
    fn homogeneous_coordinates_colors_and_continuations() {
        let text = "v 2 4 6 2\nv 1 2 3 0.5 0.5 0.5\nv 1 \\\n 1 1\nf 1 2 \\\n3\n";
        let plc = parse_ok(text);
        assert_eq!(
            plc.points,
            vec![[1.0, 2.0, 3.0], [1.0, 2.0, 3.0], [1.0, 1.0, 1.0]]
        );
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2]]);
        assert_eq!(plc.facets[0].line, 5);
    }

    #[test]
    fn forward_references_and_short_faces() {
        let plc = parse_ok("f 1 2\nf 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1]]);
        assert_eq!(plc.facets[1].polygons, vec![vec![2]]);
    }

    #[test]
    fn errors() {
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 2 3\nf 1 2 9\n")),
            "t.obj:6: face 2 has corner 9, but there are only 4 vertices (numbered from 1)"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 0 3\n")),
            "t.obj:5: face 1: corner 2 has vertex index 0 (OBJ numbers vertices from 1)"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 2 -5\n")),
            "t.obj:5: face 1: corner 3 is vertex -5, but only 4 vertices are defined before this line"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 x/2 3\n")),
            "t.obj:5: expected the vertex of corner 2 of face 1 (an integer), found `x`"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f\n")),
            "t.obj:5: face 1 has no corners"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 2 /3/4\n")),
            "t.obj:5: face 1: corner 3 (`/3/4`) has no vertex index"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 2 99999999999999999999\n")),
            "t.obj:5: the vertex of corner 3 of face 1 is out of range: `99999999999999999999`"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 2 -9223372036854775808\n")),
            "t.obj:5: face 1: corner 3 is vertex -9223372036854775808, but only 4 vertices are defined before this line"
        );
        assert_eq!(
            parse_err(&format!("{SQUARE}f 1 2 99999999999\n")),
            "t.obj:5: face 1: corner 3 is vertex 99999999999, which is too large"
        );
        assert_eq!(
            parse_err("v 0 0\n"),
            "t.obj:1: expected the z coordinate of vertex 1, but the line ends"
        );
        assert_eq!(
            parse_err("v 0 0 0\nv 1 nan 0\n"),
            "t.obj:2: the y coordinate of vertex 2 is not a finite number: `nan`"
        );
        assert_eq!(
            parse_err("v 1e308 0 0 1e-308\n"),
            "t.obj:1: vertex 1 divided by its w coordinate is not finite"
        );
        assert_eq!(
            parse_err("v 1 0 0 0\n"),
            "t.obj:1: the w coordinate of vertex 1 is 0"
        );
        assert_eq!(
            parse_err("v 1 0 0\nf 1 2 3\n"),
            "t.obj:2: face 1 has corner 2, but there is only 1 vertex"
        );
    }

    #[test]
    fn example_file_parses() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples/tet.obj");
        let plc = read(&path).unwrap();
        assert_eq!((plc.points.len(), plc.facets.len()), (4, 4));
    }
}
