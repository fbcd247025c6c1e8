//! Reader of STL files, ASCII and binary.
//!
//! ASCII: `solid [name]`, then per triangle `facet normal nx ny nz`, `outer loop`, three
//! `vertex x y z`, `endloop`, `endfacet`, and `endsolid [name]`; several solids may
//! follow each other. Keywords are case-insensitive, line breaks are free. Binary: an
//! 80-byte header, a little-endian `u32` triangle count, then 50 bytes per triangle
//! (normal, three corners as `f32` triples, a 2-byte attribute).
//!
//! Binary or ASCII: a binary file's header may itself begin with `solid`, so the size
//! decides first: a file of exactly `84 + 50·n` bytes is binary unless it reads as ASCII
//! text (all bytes after the first line printable, and an `endsolid`; printable bytes
//! at 80..84 make `n` at least 0x20202020, so this needs a file of 27 GB). A file of
//! another size is ASCII if it begins with `solid` and is text, else a binary file whose
//! count does not match its length (an error).
//!
//! STL repeats the corners of every triangle: exactly coincident corners (bitwise equal
//! after turning -0.0 into 0.0) are welded into one vertex, numbered in order of first
//! appearance, from 1 as TetGen does. Each triangle becomes a one-polygon facet with
//! marker 0; the normals are ignored.

use super::token_stream::Tokens;
use crate::error::InputError;
use crate::plc::{Facet, Plc};
use rustc_hash::FxHashMap;
use std::path::Path;

/// Size of the binary header, the count included.
const HEADER: usize = 84;
/// Size of one binary triangle record.
const RECORD: usize = 50;

/// Reads an `.stl` file.
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(path, e))?;
    parse(&bytes, path)
}

/// Parses the bytes of an STL file; `path` is used in error messages and as the source.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Plc, InputError> {
    if bytes.iter().all(u8::is_ascii_whitespace) {
        return Err(InputError::parse(path, 1, "empty file: expected `solid`"));
    }
    if is_binary(bytes) {
        parse_binary(bytes, path)
    } else {
        let text = String::from_utf8_lossy(bytes);
        parse_ascii(&text, path)
    }
}

/// The triangle count of a binary header, if the file is long enough to hold one.
fn binary_count(bytes: &[u8]) -> Option<u32> {
    let b = bytes.get(80..HEADER)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
}

/// Whether the bytes look like ASCII STL: `solid` first (after white space), printable
/// text after the first line.
fn looks_ascii(bytes: &[u8]) -> bool {
    let start = bytes.iter().position(|b| !b.is_ascii_whitespace());
    let Some(start) = start else {
        return false;
    };
    if !bytes[start..]
        .get(..5)
        .is_some_and(|k| k.eq_ignore_ascii_case(b"solid"))
    {
        return false;
    }
    // The first line (the solid's name) may hold any text but NUL, which pads binary headers.
    let first_end = bytes[start..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |i| start + i);
    !bytes[start..first_end].contains(&0)
        && bytes[first_end..]
            .iter()
            .all(|&b| matches!(b, b'\t' | b'\n' | b'\r' | 0x0c | b' '..=b'~'))
}

/// Decides whether an STL file is binary (see the module documentation).
pub fn is_binary(bytes: &[u8]) -> bool {
    let ascii = looks_ascii(bytes);
    match binary_count(bytes) {
        Some(n) if (bytes.len() - HEADER) as u64 == u64::from(n) * RECORD as u64 => {
            // The size fits a binary file; only a real ASCII file says otherwise.
            !(ascii && contains_ignore_case(bytes, b"endsolid"))
        }
        _ => !ascii,
    }
}

fn contains_ignore_case(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len())
        .any(|w| w.eq_ignore_ascii_case(needle))
}

/// Merges exactly coincident points, numbering them in order of first appearance.
#[derive(Default, Debug)]
pub struct Welder {
    index: FxHashMap<[u64; 3], u32>,
    /// The distinct points, in order of first appearance.
    pub points: Vec<[f64; 3]>,
}

impl Welder {
    /// The index of `p`, adding it if new; `None` if there are more points than a `u32` numbers.
    pub fn weld(&mut self, p: [f64; 3]) -> Option<u32> {
        // -0.0 and 0.0 are the same point; every other equal pair has equal bits.
        let key = p.map(|c| if c == 0.0 { 0.0f64 } else { c }.to_bits());
        let next = u32::try_from(self.points.len()).ok()?;
        let points = &mut self.points;
        Some(*self.index.entry(key).or_insert_with(|| {
            points.push(p);
            next
        }))
    }
}

/// A model with the welded points and one triangle facet per corner triple.
fn plc_of(path: &Path, welder: Welder, facets: Vec<Facet>) -> Plc {
    Plc {
        points: welder.points,
        facets,
        first_index: 1,
        source: path.to_path_buf(),
        ..Default::default()
    }
}

fn too_many(path: &Path) -> InputError {
    InputError::Invalid {
        file: path.to_path_buf(),
        msg: format!("more than {} distinct vertices", u32::MAX),
    }
}

/// For a file taken as binary although it begins with `solid`: where it stops being
/// text, so that a damaged ASCII file is not only reported as a bad binary one.
fn ascii_hint(bytes: &[u8]) -> String {
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(0);
    if !bytes[start..]
        .get(..5)
        .is_some_and(|k| k.eq_ignore_ascii_case(b"solid"))
    {
        return String::new();
    }
    let text = |b: u8| matches!(b, b'\t' | b'\n' | b'\r' | 0x0c | b' '..=b'~');
    let first_end = bytes[start..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |i| start + i);
    let bad = bytes[start..first_end]
        .iter()
        .position(|&b| b == 0)
        .map(|i| start + i)
        .or_else(|| {
            bytes[first_end..]
                .iter()
                .position(|&b| !text(b))
                .map(|i| first_end + i)
        });
    match bad {
        Some(i) => format!(
            " (the file begins with `solid` like an ASCII STL, but byte {i} is not text, so it was read as binary)"
        ),
        None => String::new(),
    }
}

/// Parses a binary STL file (its size already checked or to be checked here).
fn parse_binary(bytes: &[u8], path: &Path) -> Result<Plc, InputError> {
    let invalid = |msg: String| InputError::Invalid {
        file: path.to_path_buf(),
        msg: msg + &ascii_hint(bytes),
    };
    let Some(n) = binary_count(bytes) else {
        return Err(invalid(format!(
            "binary STL truncated: {} bytes, shorter than the {HEADER}-byte header",
            bytes.len()
        )));
    };
    let n = n as usize;
    let have = (bytes.len() - HEADER) / RECORD;
    let expected = HEADER as u64 + n as u64 * RECORD as u64;
    if have < n {
        let offset = HEADER + have * RECORD;
        return Err(invalid(format!(
            "binary STL truncated: the header announces {n} triangles ({expected} bytes), \
             but the file has {} bytes; triangle {have} (byte offset {offset}) is incomplete",
            bytes.len()
        )));
    }
    if bytes.len() as u64 != expected {
        return Err(invalid(format!(
            "binary STL has {} bytes, but the header announces {n} triangles ({expected} bytes)",
            bytes.len()
        )));
    }
    let mut welder = Welder::default();
    let mut facets = Vec::with_capacity(n);
    for t in 0..n {
        let offset = HEADER + t * RECORD;
        let rec = &bytes[offset..offset + RECORD];
        let mut polygon = Vec::with_capacity(3);
        for c in 0..3 {
            let mut p = [0.0; 3];
            for (k, x) in p.iter_mut().enumerate() {
                let at = 12 + 12 * c + 4 * k;
                let v = f32::from_le_bytes([rec[at], rec[at + 1], rec[at + 2], rec[at + 3]]);
                if !v.is_finite() {
                    return Err(invalid(format!(
                        "triangle {t} (byte offset {offset}): the {} coordinate of corner {c} \
                         is not a finite number: {v}",
                        ["x", "y", "z"][k]
                    )));
                }
                *x = f64::from(v);
            }
            polygon.push(welder.weld(p).ok_or_else(|| too_many(path))?);
        }
        facets.push(Facet {
            polygons: vec![polygon],
            ..Default::default()
        });
    }
    Ok(plc_of(path, welder, facets))
}

/// Consumes the keyword `word` (case-insensitively) or fails naming what was found.
fn keyword(t: &mut Tokens<'_>, word: &str, context: &dyn Fn() -> String) -> Result<(), InputError> {
    let line = t.expect(|| format!("`{word}` in {}", context()))?;
    let tok = line.token(|| word.to_string())?;
    if tok.eq_ignore_ascii_case(word) {
        Ok(())
    } else {
        Err(line.error(format!("expected `{word}` in {}, found `{tok}`", context())))
    }
}

/// Parses an ASCII STL file.
fn parse_ascii(text: &str, path: &Path) -> Result<Plc, InputError> {
    let mut t = Tokens::new(text, path);
    let mut welder = Welder::default();
    let mut facets = Vec::new();
    let mut solids = 0usize;
    loop {
        let Some(line) = t.line() else {
            if solids == 0 {
                return Err(t.error("empty file: expected `solid`"));
            }
            break;
        };
        let tok = line.token(String::new)?;
        if !tok.eq_ignore_ascii_case("solid") {
            let what = if solids == 0 {
                "`solid`"
            } else {
                "`solid` or the end of the file"
            };
            return Err(line.error(format!("expected {what}, found `{tok}`")));
        }
        solids += 1;
        // The rest of the line is the solid's name.
        t.skip_rest_of_line();
        loop {
            let f = facets.len();
            let line = t.expect(|| format!("`facet` or `endsolid` (after triangle {f})"))?;
            let tok = line.token(String::new)?;
            let facet_line = line.number();
            if tok.eq_ignore_ascii_case("endsolid") {
                t.skip_rest_of_line();
                break;
            }
            if !tok.eq_ignore_ascii_case("facet") {
                return Err(line.error(format!(
                    "expected `facet` or `endsolid` (after triangle {f}), found `{tok}`"
                )));
            }
            let ctx = || format!("triangle {f}");
            keyword(&mut t, "normal", &ctx)?;
            for k in 0..3 {
                // The normal is not used, but must be a number.
                let line = t.expect(|| format!("the normal of triangle {f}"))?;
                let tok = line.token(String::new)?;
                if tok.parse::<f64>().is_err() {
                    return Err(line.error(format!(
                        "expected the {} component of the normal of triangle {f}, found `{tok}`",
                        ["x", "y", "z"][k]
                    )));
                }
            }
            keyword(&mut t, "outer", &ctx)?;
            keyword(&mut t, "loop", &ctx)?;
            let mut polygon = Vec::with_capacity(3);
            for c in 0..3 {
                let corner = || format!("corner {c} of triangle {f}");
                keyword(&mut t, "vertex", &corner)?;
                let mut p = [0.0; 3];
                for (k, x) in p.iter_mut().enumerate() {
                    let axis = ["x", "y", "z"][k];
                    let what = || format!("the {axis} coordinate of corner {c} of triangle {f}");
                    *x = t.expect(what)?.float(what)?;
                }
                polygon.push(welder.weld(p).ok_or_else(|| too_many(path))?);
            }
            let line = t.expect(|| format!("`endloop` in triangle {f}"))?;
            let tok = line.token(String::new)?;
            if tok.eq_ignore_ascii_case("vertex") {
                return Err(line.error(format!(
                    "triangle {f} has more than 3 corners; STL facets are triangles"
                )));
            }
            if !tok.eq_ignore_ascii_case("endloop") {
                return Err(
                    line.error(format!("expected `endloop` in triangle {f}, found `{tok}`"))
                );
            }
            keyword(&mut t, "endfacet", &ctx)?;
            facets.push(Facet {
                polygons: vec![polygon],
                line: facet_line,
                ..Default::default()
            });
        }
    }
    Ok(plc_of(path, welder, facets))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.stl")
    }

    /// A binary STL of the given triangles, with the given header text.
    fn binary(header: &str, tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = vec![b' '; 80];
        b[..header.len()].copy_from_slice(header.as_bytes());
        b.extend((tris.len() as u32).to_le_bytes());
        for tri in tris {
            b.extend([0u8; 12]);
            for c in tri {
                for x in c {
                    b.extend(x.to_le_bytes());
                }
            }
            b.extend([0u8; 2]);
        }
        b
    }

    const TRIS: [[[f32; 3]; 3]; 2] = [
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, -0.0], [0.0, 0.0, 1.0]],
    ];

    #[test]
    fn welding_merges_exact_copies_only() {
        let mut w = Welder::default();
        assert_eq!(w.weld([0.0, 0.0, 1.0]), Some(0));
        assert_eq!(w.weld([1.0, 0.0, 0.0]), Some(1));
        assert_eq!(w.weld([-0.0, 0.0, 1.0]), Some(0));
        assert_eq!(w.weld([1.0, 0.0, 0.0]), Some(1));
        // One ulp away is another point.
        assert_eq!(
            w.weld([f64::from_bits(1.0f64.to_bits() + 1), 0.0, 0.0]),
            Some(2)
        );
        assert_eq!(w.points.len(), 3);
        assert_eq!(w.points[0], [0.0, 0.0, 1.0]);
    }

    #[test]
    fn binary_with_solid_header_is_binary() {
        let b = binary("solid made by a CAD program", &TRIS);
        assert!(is_binary(&b));
        let plc = parse(&b, p()).unwrap();
        assert_eq!(plc.points.len(), 4);
        assert_eq!(plc.first_index, 1);
        assert_eq!(plc.facets.len(), 2);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2]]);
        assert_eq!(plc.facets[1].polygons, vec![vec![1, 2, 3]]);
        // The same triangles as ASCII.
        let ascii = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n\
            FACET NORMAL 0 0 0 OUTER LOOP VERTEX 1 0 0 VERTEX 0 1 -0 VERTEX 0 0 1 ENDLOOP ENDFACET\nendsolid t\n";
        assert!(!is_binary(ascii.as_bytes()));
        let a = parse(ascii.as_bytes(), p()).unwrap();
        assert_eq!(a.points, plc.points);
        assert_eq!(a.facets[1].polygons, plc.facets[1].polygons);
        assert_eq!((a.facets[0].line, a.facets[1].line), (2, 9));
    }

    #[test]
    fn binary_errors() {
        let mut b = binary("x", &TRIS);
        b.truncate(b.len() - 10);
        assert_eq!(
            parse(&b, p()).unwrap_err().to_string(),
            "t.stl: binary STL truncated: the header announces 2 triangles (184 bytes), \
             but the file has 174 bytes; triangle 1 (byte offset 134) is incomplete"
        );
        let mut b = binary("solid x", &TRIS);
        b.extend([0u8; 3]);
        assert_eq!(
            parse(&b, p()).unwrap_err().to_string(),
            "t.stl: binary STL has 187 bytes, but the header announces 2 triangles (184 bytes) \
             (the file begins with `solid` like an ASCII STL, but byte 81 is not text, so it was read as binary)"
        );
        let mut b = binary("x", &TRIS);
        b.extend([0u8; 3]);
        assert_eq!(
            parse(&b, p()).unwrap_err().to_string(),
            "t.stl: binary STL has 187 bytes, but the header announces 2 triangles (184 bytes)"
        );
        // An ASCII file damaged by a NUL byte.
        let text = b"solid t\nfacet normal 0 0 1\nouter loop\0\n";
        assert!(parse(text, p())
            .unwrap_err()
            .to_string()
            .ends_with("but byte 37 is not text, so it was read as binary)"));
        let mut tris = TRIS;
        tris[1][2][1] = f32::INFINITY;
        assert_eq!(
            parse(&binary("", &tris), p()).unwrap_err().to_string(),
            "t.stl: triangle 1 (byte offset 134): the y coordinate of corner 2 is not a finite number: inf"
        );
        assert_eq!(
            parse(&[0u8; 30], p()).unwrap_err().to_string(),
            "t.stl: binary STL truncated: 30 bytes, shorter than the 84-byte header"
        );
        // A lying count allocates nothing.
        let mut b = binary("", &TRIS);
        b[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(parse(&b, p())
            .unwrap_err()
            .to_string()
            .contains("4294967295 triangles"));
    }

    #[test]
    fn ascii_errors() {
        let err = |s: &str| parse(s.as_bytes(), p()).unwrap_err().to_string();
        let head = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n";
        assert_eq!(
            err(&format!(
                "{head}vertex 0 nan 0\nendloop\nendfacet\nendsolid\n"
            )),
            "t.stl:6: the y coordinate of corner 2 of triangle 0 is not a finite number: `nan`"
        );
        assert_eq!(
            err(head),
            "t.stl:5: unexpected end of file: expected `vertex` in corner 2 of triangle 0"
        );
        assert_eq!(
            err(&format!("{head}vertex 0 1 0\nendlop\n")),
            "t.stl:7: expected `endloop` in triangle 0, found `endlop`"
        );
        assert_eq!(
            err(&format!("{head}vertex 0 1 0\nvertex 1 1 0\nendloop\n")),
            "t.stl:7: triangle 0 has more than 3 corners; STL facets are triangles"
        );
        assert_eq!(
            err("solid t\nfacet normal 0 0 x\n"),
            "t.stl:2: expected the z component of the normal of triangle 0, found `x`"
        );
        assert_eq!(
            err("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0 0\n"),
            "t.stl:4: expected `vertex` in corner 1 of triangle 0, found `0`"
        );
        assert_eq!(
            err("solid t\nendsolid t\nfoo\n"),
            "t.stl:3: expected `solid` or the end of the file, found `foo`"
        );
        assert_eq!(err(""), "t.stl:1: empty file: expected `solid`");
    }
}
