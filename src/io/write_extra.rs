//! Writers of the mesh in other programs' formats: legacy VTK (`-k`) and Medit (`-g`).
//!
//! * `.vtk`: a legacy ASCII `UNSTRUCTURED_GRID`: `POINTS` (double), `CELLS` with one
//!   4-node cell per tet, `CELL_TYPES` all 10 (`VTK_TETRA`), and with `-A` the region
//!   attribute as `CELL_DATA` (`SCALARS region double`). VTK numbers points from 0
//!   whatever `-z` says. Our tets already have VTK's orientation (the fourth node lies
//!   on the side the counterclockwise first three face), so they are written as in `.ele`.
//! * `.mesh`: Medit ASCII, version 1: `Vertices` (`x y z ref`, the ref being the point
//!   marker or 0), `Triangles` (for a PLC the subfaces with their facet markers, i.e. the
//!   faces of the `.face` file without `-f`; for a point set the convex hull faces,
//!   normals outwards, ref 1), `Tetrahedra` (ref: the region attribute truncated to an
//!   integer with `-A`, else 0), `End`. Medit numbers from 1 whatever `-z` says.
//!
//! Coordinates and attributes are written in the shortest form that reads back to the
//! same `f64`, as in the `.node` file.

use super::write::{Derived, WriteOptions};
use crate::output::MeshOut;
use std::io::{self, Write};

/// Appends `x` in the shortest form that reads back to the same `f64` (`1.0` as `1`).
fn push_float(s: &mut String, buf: &mut ryu::Buffer, x: f64) {
    if x.is_finite() {
        let t = buf.format_finite(x);
        s.push_str(t.strip_suffix(".0").unwrap_or(t));
    } else {
        // Finite input gives finite nodes; this keeps a bug visible rather than hidden.
        s.push_str(if x.is_nan() {
            "nan"
        } else if x > 0.0 {
            "inf"
        } else {
            "-inf"
        });
    }
}

/// Writes `lines` lines built by `line` (into a reused string), flushing in chunks.
fn write_lines<W: Write>(
    out: &mut W,
    lines: usize,
    mut line: impl FnMut(&mut String, &mut ryu::Buffer, usize),
) -> io::Result<()> {
    let mut s = String::with_capacity(1 << 16);
    let mut buf = ryu::Buffer::new();
    for i in 0..lines {
        line(&mut s, &mut buf, i);
        s.push('\n');
        if s.len() >= 1 << 15 {
            out.write_all(s.as_bytes())?;
            s.clear();
        }
    }
    out.write_all(s.as_bytes())
}

/// The comment text on one line.
fn one_line(c: &str) -> String {
    c.chars()
        .map(|ch| if ch == '\n' || ch == '\r' { ' ' } else { ch })
        .collect()
}

/// Writes the legacy VTK file.
pub fn write_vtk<W: Write>(out: &mut W, mesh: &MeshOut, w: &WriteOptions) -> io::Result<()> {
    writeln!(out, "# vtk DataFile Version 2.0")?;
    // The title line holds at most 256 characters.
    let title = w
        .comment
        .as_deref()
        .map(one_line)
        .unwrap_or_else(|| "Tetrahedral mesh".into());
    let title: String = title.chars().take(255).collect();
    writeln!(out, "{title}")?;
    writeln!(out, "ASCII")?;
    writeln!(out, "DATASET UNSTRUCTURED_GRID")?;
    writeln!(out, "POINTS {} double", mesh.points.len())?;
    write_lines(out, mesh.points.len(), |s, buf, i| {
        for (k, &x) in mesh.points[i].iter().enumerate() {
            if k > 0 {
                s.push(' ');
            }
            push_float(s, buf, x);
        }
    })?;
    let n = mesh.tets.len();
    writeln!(out, "CELLS {n} {}", 5 * n)?;
    write_lines(out, n, |s, _, i| {
        let t = mesh.tets[i];
        s.push_str(&format!("4 {} {} {} {}", t[0], t[1], t[2], t[3]));
    })?;
    writeln!(out, "CELL_TYPES {n}")?;
    write_lines(out, n, |s, _, _| s.push_str("10"))?;
    let na = mesh.num_tet_attrs;
    if na > 0 {
        writeln!(out, "CELL_DATA {n}")?;
        writeln!(out, "SCALARS region double 1")?;
        writeln!(out, "LOOKUP_TABLE default")?;
        write_lines(out, n, |s, buf, i| {
            push_float(s, buf, mesh.tet_attrs.get(i * na).copied().unwrap_or(0.0));
        })?;
    }
    Ok(())
}

/// The Medit reference of a tet: its region attribute as an integer (truncated, and
/// saturated to 32 bits), or 0.
fn tet_ref(mesh: &MeshOut, i: usize) -> i64 {
    let na = mesh.num_tet_attrs;
    if na == 0 {
        return 0;
    }
    let a = mesh.tet_attrs.get(i * na).copied().unwrap_or(0.0);
    // `as` truncates toward zero and saturates (NaN gives 0).
    i64::from(a as i32)
}

/// The faces written as Medit triangles, with their references (see the module doc).
fn medit_triangles(mesh: &MeshOut, d: &Derived<'_>) -> Vec<([u32; 3], i64)> {
    if mesh.plc_mode {
        return mesh
            .subfaces
            .iter()
            .map(|&(f, m)| (f, i64::from(m)))
            .collect();
    }
    if !mesh.hull_faces.is_empty() {
        return mesh.hull_faces.iter().map(|&f| (f, 1)).collect();
    }
    d.owned_faces()
        .filter(|&(i, j)| d.neighbor(i, j).is_none())
        .map(|(i, j)| {
            // Seen from inside the tet; reversed, the normal points out.
            let f = d.face_in(i, j);
            ([f[0], f[2], f[1]], 1)
        })
        .collect()
}

/// Writes the Medit `.mesh` file.
pub fn write_medit<W: Write>(
    out: &mut W,
    mesh: &MeshOut,
    w: &WriteOptions,
    d: &Derived<'_>,
) -> io::Result<()> {
    if let Some(c) = &w.comment {
        writeln!(out, "# {}", one_line(c))?;
    }
    writeln!(out, "MeshVersionFormatted 1")?;
    writeln!(out, "Dimension 3")?;
    writeln!(out, "Vertices")?;
    writeln!(out, "{}", mesh.points.len())?;
    write_lines(out, mesh.points.len(), |s, buf, i| {
        for &x in &mesh.points[i] {
            push_float(s, buf, x);
            s.push(' ');
        }
        let m = mesh.point_markers.as_ref().and_then(|m| m.get(i)).copied();
        s.push_str(&m.unwrap_or(0).to_string());
    })?;
    let tris = medit_triangles(mesh, d);
    writeln!(out, "Triangles")?;
    writeln!(out, "{}", tris.len())?;
    write_lines(out, tris.len(), |s, _, i| {
        let (f, m) = tris[i];
        s.push_str(&format!("{} {} {} {m}", f[0] + 1, f[1] + 1, f[2] + 1));
    })?;
    writeln!(out, "Tetrahedra")?;
    writeln!(out, "{}", mesh.tets.len())?;
    write_lines(out, mesh.tets.len(), |s, _, i| {
        let t = mesh.tets[i];
        s.push_str(&format!(
            "{} {} {} {} {}",
            t[0] + 1,
            t[1] + 1,
            t[2] + 1,
            t[3] + 1,
            tet_ref(mesh, i)
        ));
    })?;
    writeln!(out, "End")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two tets sharing a face, one with region 2.5 and one with region -1.
    fn mesh(plc: bool) -> MeshOut {
        MeshOut {
            points: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
                [0.0, 0.0, -0.5],
            ],
            tets: vec![[0, 1, 2, 3], [1, 0, 2, 4]],
            num_tet_attrs: 1,
            tet_attrs: vec![2.5, -1.0],
            subfaces: vec![([0, 1, 3], 5)],
            plc_mode: plc,
            point_markers: Some(vec![1, 0, 0, 0, 7]),
            ..Default::default()
        }
    }

    #[test]
    fn vtk_layout() {
        let mut out = Vec::new();
        write_vtk(&mut out, &mesh(true), &WriteOptions::default()).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "# vtk DataFile Version 2.0\nTetrahedral mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n\
             POINTS 5 double\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 0 -0.5\n\
             CELLS 2 10\n4 0 1 2 3\n4 1 0 2 4\nCELL_TYPES 2\n10\n10\n\
             CELL_DATA 2\nSCALARS region double 1\nLOOKUP_TABLE default\n2.5\n-1\n"
        );
    }

    #[test]
    fn medit_layout() {
        let m = mesh(true);
        let mut out = Vec::new();
        let w = WriteOptions {
            comment: Some("made\nby test".into()),
            ..Default::default()
        };
        write_medit(&mut out, &m, &w, &Derived::new(&m)).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "# made by test\nMeshVersionFormatted 1\nDimension 3\nVertices\n5\n\
             0 0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 -0.5 7\n\
             Triangles\n1\n1 2 4 5\nTetrahedra\n2\n1 2 3 4 2\n2 1 3 5 -1\nEnd\n"
        );
        // A point set: its hull faces, reference 1.
        let m = mesh(false);
        let mut out = Vec::new();
        write_medit(&mut out, &m, &w, &Derived::new(&m)).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(text.contains("Triangles\n6\n"), "{text}");
    }
}
