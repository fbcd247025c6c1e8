//! Reader of PLY files (Stanford polygon format): `ascii`, `binary_little_endian` and
//! `binary_big_endian`.
//!
//! The header (`ply`, `format ...`, `comment`/`obj_info` lines, `element NAME COUNT`
//! each followed by its `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE
//! NAME` lines, `end_header`) describes the data that follows. The model is taken from
//! two elements: `vertex`, whose scalar properties `x`, `y`, `z` (of any type) are the
//! coordinates, and `face`, whose list property `vertex_indices` (or `vertex_index`)
//! gives each polygon, of any size. Every other property and element (normals, colors,
//! `edge`, `material`, ...) is read past and ignored.
//!
//! Vertices are numbered from 0 as in TetGen; each face becomes a one-polygon facet
//! with marker 0. Every PLY scalar type (at most 32-bit integers, `double`) converts
//! exactly to `f64`, so values are read as `f64` and indices checked to be integers.

use super::token_stream::Tokens;
use super::tokens::Lines;
use crate::error::InputError;
use crate::plc::{Facet, Plc};
use std::path::Path;

/// Reads a `.ply` file.
pub fn read(path: &Path) -> Result<Plc, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(path, e))?;
    parse(&bytes, path)
}

/// The storage of the data section.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    LittleEndian,
    BigEndian,
}

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The PLY name of the type.
    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    /// Whether an integer fits the type (floats take any value).
    fn holds(self, v: i64) -> bool {
        let (lo, hi) = match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => return true,
        };
        (lo..=hi).contains(&v)
    }

    /// Decodes one value from exactly `size()` bytes.
    fn decode(self, b: &[u8], big: bool) -> f64 {
        macro_rules! num {
            ($t:ty, $n:literal) => {{
                let mut a = [0u8; $n];
                a.copy_from_slice(b);
                f64::from(if big {
                    <$t>::from_be_bytes(a)
                } else {
                    <$t>::from_le_bytes(a)
                })
            }};
        }
        match self {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => num!(i16, 2),
            Scalar::U16 => num!(u16, 2),
            Scalar::I32 => num!(i32, 4),
            Scalar::U32 => num!(u32, 4),
            Scalar::F32 => num!(f32, 4),
            Scalar::F64 => num!(f64, 8),
        }
    }
}

/// One property of an element.
#[derive(Clone, Debug)]
struct Property {
    name: String,
    /// `Some(count type)` for a list property.
    list: Option<Scalar>,
    /// The value type (of the items, for a list).
    value: Scalar,
}

/// One element declaration.
#[derive(Clone, Debug)]
struct Element {
    name: String,
    count: usize,
    props: Vec<Property>,
    /// The header line that declares it.
    line: usize,
}

impl Element {
    /// The fewest bytes one binary record can take (empty lists).
    fn min_size(&self) -> usize {
        self.props
            .iter()
            .map(|p| p.list.unwrap_or(p.value).size())
            .sum()
    }
}

/// What the header says.
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Number of header lines (the data starts on the next line).
    lines: usize,
    /// Byte offset of the data.
    data_start: usize,
}

/// What the model is built from: where in each record to find it.
#[derive(Clone, Copy)]
enum Role {
    /// A property of no use.
    Skip,
    /// Vertex coordinate 0, 1 or 2.
    Coord(usize),
    /// The corner list of a face.
    Corners,
}

/// Parses the bytes of a PLY file; `path` is used in error messages and as the source.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Plc, InputError> {
    let header = parse_header(bytes, path)?;
    let mut model = Model::new(path, &header)?;
    match header.format {
        Format::Ascii => {
            let text = String::from_utf8_lossy(bytes);
            let mut lines = Lines::new(&text, path);
            for _ in 0..header.lines {
                lines.next_raw();
            }
            let mut t = Tokens::from_lines(lines);
            read_ascii(&mut t, &header, &mut model)?;
            if let Some(tok) = t.peek() {
                return Err(t.error(format!(
                    "unexpected `{tok}` after the last element announced by the header"
                )));
            }
        }
        Format::LittleEndian | Format::BigEndian => {
            let big = header.format == Format::BigEndian;
            read_binary(
                &bytes[header.data_start..],
                header.data_start,
                big,
                &header,
                &mut model,
            )?;
        }
    }
    Ok(model.plc)
}

/// Parses the header, up to and including the `end_header` line.
fn parse_header(bytes: &[u8], path: &Path) -> Result<Header, InputError> {
    let err = |line: usize, msg: String| InputError::parse(path, line, msg);
    let mut pos = 0;
    let mut number = 0;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        if pos >= bytes.len() {
            return Err(err(
                number.max(1),
                "unexpected end of file: expected `end_header`".into(),
            ));
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        let raw = String::from_utf8_lossy(&bytes[pos..end]);
        pos = (end + 1).min(bytes.len());
        number += 1;
        let mut words = raw.split_ascii_whitespace();
        let Some(key) = words.next() else {
            if number == 1 {
                return Err(err(
                    1,
                    "not a PLY file: the first line must be `ply`".into(),
                ));
            }
            continue;
        };
        if number == 1 {
            if key != "ply" || words.next().is_some() {
                return Err(err(
                    1,
                    "not a PLY file: the first line must be `ply`".into(),
                ));
            }
            continue;
        }
        match key {
            "comment" | "obj_info" => {}
            "format" => {
                let f = match words.next() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::LittleEndian,
                    Some("binary_big_endian") => Format::BigEndian,
                    other => {
                        return Err(err(
                            number,
                            format!(
                                "expected the format ascii, binary_little_endian or \
                                 binary_big_endian, found `{}`",
                                other.unwrap_or("")
                            ),
                        ))
                    }
                };
                if words.next() != Some("1.0") {
                    return Err(err(number, "only PLY version 1.0 is supported".into()));
                }
                if format.replace(f).is_some() {
                    return Err(err(number, "a second `format` line".into()));
                }
            }
            "element" => {
                let (Some(name), Some(count), None) = (words.next(), words.next(), words.next())
                else {
                    return Err(err(number, "expected `element NAME COUNT`".into()));
                };
                let count = count.parse::<usize>().map_err(|_| {
                    err(
                        number,
                        format!("expected the number of `{name}` elements, found `{count}`"),
                    )
                })?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line: number,
                });
            }
            "property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(err(number, "`property` before any `element`".into()));
                };
                let ty = |w: Option<&str>| -> Result<Scalar, InputError> {
                    let w = w.unwrap_or("");
                    Scalar::from_name(w)
                        .ok_or_else(|| err(number, format!("unknown property type `{w}`")))
                };
                let first = words.next();
                let prop = if first == Some("list") {
                    let list = ty(words.next())?;
                    if list.is_float() {
                        return Err(err(number, "a list count cannot be a float type".into()));
                    }
                    let value = ty(words.next())?;
                    Property {
                        name: words.next().unwrap_or("").to_string(),
                        list: Some(list),
                        value,
                    }
                } else {
                    Property {
                        value: ty(first)?,
                        name: words.next().unwrap_or("").to_string(),
                        list: None,
                    }
                };
                if prop.name.is_empty() || words.next().is_some() {
                    return Err(err(
                        number,
                        "expected `property TYPE NAME` or `property list COUNT_TYPE TYPE NAME`"
                            .into(),
                    ));
                }
                element.props.push(prop);
            }
            "end_header" => break,
            _ => {
                return Err(err(number, format!("unknown header keyword `{key}`")));
            }
        }
    }
    let Some(format) = format else {
        return Err(err(number, "the header has no `format` line".into()));
    };
    Ok(Header {
        format,
        elements,
        lines: number,
        data_start: pos,
    })
}

/// The model being built, and where its parts sit in the records.
struct Model<'a> {
    path: &'a Path,
    plc: Plc,
    num_vertices: usize,
}

impl<'a> Model<'a> {
    /// Checks that the header describes the vertices and faces as needed.
    fn new(path: &'a Path, header: &Header) -> Result<Self, InputError> {
        let err = |line: usize, msg: String| InputError::parse(path, line, msg);
        let mut num_vertices = None;
        for e in &header.elements {
            if e.name == "vertex" {
                if num_vertices.is_some() {
                    return Err(err(e.line, "a second `vertex` element".into()));
                }
                for axis in ["x", "y", "z"] {
                    match e.props.iter().find(|p| p.name == axis) {
                        None => {
                            return Err(err(
                                e.line,
                                format!("the `vertex` element has no `{axis}` property"),
                            ))
                        }
                        Some(p) if p.list.is_some() => {
                            return Err(err(
                                e.line,
                                format!("the `{axis}` property of `vertex` is a list"),
                            ))
                        }
                        Some(_) => {}
                    }
                }
                if u32::try_from(e.count).is_err() {
                    return Err(err(e.line, format!("too many vertices: {}", e.count)));
                }
                num_vertices = Some(e.count);
            }
            if e.name == "face" && corner_prop(e).is_none() {
                return Err(err(
                    e.line,
                    "the `face` element has no list property `vertex_indices` (or `vertex_index`)"
                        .into(),
                ));
            }
        }
        let Some(num_vertices) = num_vertices else {
            return Err(err(
                header.lines,
                "the header declares no `vertex` element".into(),
            ));
        };
        Ok(Model {
            path,
            plc: Plc {
                source: path.to_path_buf(),
                first_index: 0,
                ..Default::default()
            },
            num_vertices,
        })
    }

    /// The roles of the properties of `e`.
    fn roles(e: &Element) -> Vec<Role> {
        let corners = if e.name == "face" {
            corner_prop(e)
        } else {
            None
        };
        e.props
            .iter()
            .enumerate()
            .map(|(i, p)| match (e.name.as_str(), p.name.as_str()) {
                ("vertex", "x") => Role::Coord(0),
                ("vertex", "y") => Role::Coord(1),
                ("vertex", "z") => Role::Coord(2),
                _ if corners == Some(i) => Role::Corners,
                _ => Role::Skip,
            })
            .collect()
    }

    /// Checks a corner value and converts it to an index, or says what is wrong.
    fn corner(&self, v: f64, c: usize, f: usize) -> Result<u32, String> {
        if v.fract() != 0.0 {
            return Err(format!("corner {c} of face {f} is not an integer: {v}"));
        }
        if v < 0.0 || v >= self.num_vertices as f64 {
            return Err(format!(
                "face {f} has corner {v}, but there are only {} vertices (numbered from 0)",
                self.num_vertices
            ));
        }
        Ok(v as u32)
    }
}

/// The index of the corner list property of a face element.
fn corner_prop(e: &Element) -> Option<usize> {
    ["vertex_indices", "vertex_index"].iter().find_map(|name| {
        e.props
            .iter()
            .position(|p| p.name == *name && p.list.is_some())
    })
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// Reads the ASCII data section: the tokens of each element in turn.
fn read_ascii(
    t: &mut Tokens<'_>,
    header: &Header,
    model: &mut Model<'_>,
) -> Result<(), InputError> {
    for e in header.elements.iter().filter(|e| !e.props.is_empty()) {
        let roles = Model::roles(e);
        let is_vertex = e.name == "vertex";
        let is_face = e.name == "face";
        let value = |t: &mut Tokens<'_>, ty: Scalar, what: &dyn Fn() -> String| {
            let line = t.expect(what)?;
            if ty.is_float() {
                return line.float(what);
            }
            let v = line.int(what)?;
            if !ty.holds(v) {
                return Err(line.error(format!(
                    "{} is out of range for its type {}: {v}",
                    what(),
                    ty.name()
                )));
            }
            Ok(v as f64)
        };
        // Reserve no more than a lying header could cost us.
        let cap = e.count.min(1 << 16);
        if is_vertex {
            model.plc.points.reserve(cap);
        } else if is_face {
            model.plc.facets.reserve(cap);
        }
        for i in 0..e.count {
            let name = &e.name;
            let mut p = [0.0; 3];
            let mut polygon = Vec::new();
            let mut line = 0;
            for (prop, role) in e.props.iter().zip(&roles) {
                let pname = &prop.name;
                match prop.list {
                    None => {
                        let what = || match role {
                            Role::Coord(k) => format!("the {} coordinate of vertex {i}", AXES[*k]),
                            _ => format!("property `{pname}` of {name} {i}"),
                        };
                        if let Role::Coord(k) = role {
                            p[*k] = value(t, prop.value, &what)?;
                        } else if prop.value.is_float() {
                            // Unused: any number will do, NaN included (say, an unknown normal).
                            let line = t.expect(what)?;
                            let tok = line.token(what)?;
                            if tok.parse::<f64>().is_err() {
                                return Err(
                                    line.error(format!("expected {}, found `{tok}`", what()))
                                );
                            }
                        } else {
                            value(t, prop.value, &what)?;
                        }
                    }
                    Some(count_ty) => {
                        let what = || format!("the length of list `{pname}` of {name} {i}");
                        let n = value(t, count_ty, &what)?;
                        if n < 0.0 {
                            return Err(t.error(format!(
                                "the length of list `{pname}` of {name} {i} is negative: {n}"
                            )));
                        }
                        let corners = matches!(role, Role::Corners);
                        if corners {
                            line = t.line_number();
                        }
                        if corners && n == 0.0 {
                            return Err(t.error(format!("face {i} has no corners")));
                        }
                        for c in 0..n as usize {
                            let what = || format!("item {c} of list `{pname}` of {name} {i}");
                            let v = value(t, prop.value, &what)?;
                            if corners {
                                polygon.push(model.corner(v, c, i).map_err(|m| t.error(m))?);
                            }
                        }
                    }
                }
            }
            if is_vertex {
                model.plc.points.push(p);
            } else if is_face {
                model.plc.facets.push(Facet {
                    polygons: vec![polygon],
                    line,
                    ..Default::default()
                });
            }
        }
    }
    Ok(())
}

/// Reads the binary data section `data`, which starts at byte `base` of the file.
fn read_binary(
    data: &[u8],
    base: usize,
    big: bool,
    header: &Header,
    model: &mut Model<'_>,
) -> Result<(), InputError> {
    let path = model.path;
    let invalid = |msg: String| InputError::Invalid {
        file: path.to_path_buf(),
        msg,
    };
    let mut pos = 0usize;
    for e in header.elements.iter().filter(|e| !e.props.is_empty()) {
        let roles = Model::roles(e);
        // A lying count cannot make us allocate: each record takes at least min_size bytes.
        let min = e.min_size();
        if min > 0 && e.count > (data.len() - pos) / min {
            return Err(invalid(format!(
                "the header announces {} `{}` elements of at least {min} bytes each, \
                 but only {} bytes of data remain (at byte offset {})",
                e.count,
                e.name,
                data.len() - pos,
                base + pos
            )));
        }
        let is_vertex = e.name == "vertex";
        let is_face = e.name == "face";
        if is_vertex {
            model.plc.points.reserve(e.count);
        } else if is_face {
            model.plc.facets.reserve(e.count);
        }
        for i in 0..e.count {
            let start = pos;
            let take = |ty: Scalar, pos: &mut usize| -> Result<f64, InputError> {
                let end = *pos + ty.size();
                let Some(b) = data.get(*pos..end) else {
                    return Err(invalid(format!(
                        "the file ends inside {} {i} (at byte offset {})",
                        e.name,
                        base + start
                    )));
                };
                *pos = end;
                Ok(ty.decode(b, big))
            };
            let mut p = [0.0; 3];
            let mut polygon = Vec::new();
            for (prop, role) in e.props.iter().zip(&roles) {
                match prop.list {
                    None => {
                        let v = take(prop.value, &mut pos)?;
                        if let Role::Coord(k) = role {
                            if !v.is_finite() {
                                return Err(invalid(format!(
                                    "vertex {i} (at byte offset {}): the {} coordinate is not a finite number: {v}",
                                    base + start,
                                    AXES[*k]
                                )));
                            }
                            p[*k] = v;
                        }
                    }
                    Some(count_ty) => {
                        let n = take(count_ty, &mut pos)?;
                        if n < 0.0 {
                            return Err(invalid(format!(
                                "{} {i} (at byte offset {}): the length of list `{}` is negative: {n}",
                                e.name,
                                base + start,
                                prop.name
                            )));
                        }
                        let corners = matches!(role, Role::Corners);
                        if !corners {
                            let skip = n as usize * prop.value.size();
                            if data.len() - pos < skip {
                                return Err(invalid(format!(
                                    "the file ends inside {} {i} (at byte offset {})",
                                    e.name,
                                    base + start
                                )));
                            }
                            pos += skip;
                            continue;
                        }
                        if n == 0.0 {
                            return Err(invalid(format!(
                                "face {i} (at byte offset {}) has no corners",
                                base + start
                            )));
                        }
                        for c in 0..n as usize {
                            let v = take(prop.value, &mut pos)?;
                            polygon.push(model.corner(v, c, i).map_err(|m| {
                                invalid(format!("{m} (at byte offset {})", base + start))
                            })?);
                        }
                    }
                }
            }
            if is_vertex {
                model.plc.points.push(p);
            } else if is_face {
                model.plc.facets.push(Facet {
                    polygons: vec![polygon],
                    ..Default::default()
                });
            }
        }
    }
    if pos != data.len() {
        return Err(invalid(format!(
            "{} bytes after the last element announced by the header (at byte offset {})",
            data.len() - pos,
            base + pos
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.ply")
    }

    const HEAD: &str = "ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\n\
        property uchar red\nproperty double y\nproperty int z\nelement edge 1\n\
        property list uchar int vertex_indices\nproperty float w\nelement face 2\n\
        property list uint8 uint vertex_index\nproperty float q\nend_header\n";

    #[test]
    fn ascii_skips_other_properties_and_elements() {
        let text = format!(
            "{HEAD}0 1 0 0\n1 2 0 0\n0 3 1 0\n0 4 0 1\n3 0 1 2 0.5\n3 0 1 2 9\n4 0 1 2 3 1e3\n"
        );
        // NaN is refused in a coordinate, accepted in an unused float property.
        let nan_y = text.replace("\n1 2 0 0\n", "\n1 2 nan 0\n");
        let e = parse(nan_y.as_bytes(), p()).unwrap_err().to_string();
        assert_eq!(
            e,
            "t.ply:17: the y coordinate of vertex 1 is not a finite number: `nan`"
        );
        let nan_w = text.replace("3 0 1 2 0.5", "3 0 1 2 nan");
        assert_eq!(parse(nan_w.as_bytes(), p()).unwrap().facets.len(), 2);
        let plc = parse(text.as_bytes(), p()).unwrap();
        assert_eq!(
            plc.points,
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0]
            ]
        );
        assert_eq!(plc.facets.len(), 2);
        assert_eq!(plc.facets[0].polygons, vec![vec![0, 1, 2]]);
        assert_eq!(plc.facets[1].polygons, vec![vec![0, 1, 2, 3]]);
        assert_eq!(plc.facets[1].line, 22);
        assert_eq!(plc.first_index, 0);
    }

    #[test]
    fn elements_without_properties_take_no_time_whatever_their_count() {
        // Their records hold nothing, so a huge count must not be counted through.
        let huge = "element edge 18446744073709551615\nelement face 2\n";
        let text = format!(
            "{HEAD}0 1 0 0\n1 2 0 0\n0 3 1 0\n0 4 0 1\n3 0 1 2 0.5\n3 0 1 2 9\n4 0 1 2 3 1e3\n"
        )
        .replacen("element face 2\n", huge, 1);
        assert_eq!(parse(text.as_bytes(), p()).unwrap().facets.len(), 2);
        let b = binary_file(false, 1.0, 2.0);
        let at = b.windows(10).position(|w| w == b"end_header").unwrap();
        let mut with_empty = b[..at].to_vec();
        with_empty.extend_from_slice(b"element nothing 18446744073709551615\n");
        with_empty.extend_from_slice(&b[at..]);
        assert_eq!(parse(&with_empty, p()).unwrap().facets.len(), 2);
    }

    /// Encodes values of the given types in one byte order.
    fn bin(vals: &[(Scalar, f64)], big: bool) -> Vec<u8> {
        let mut b = Vec::new();
        for &(t, v) in vals {
            macro_rules! put {
                ($x:expr) => {
                    b.extend(
                        if big {
                            $x.to_be_bytes()
                        } else {
                            $x.to_le_bytes()
                        }
                        .iter(),
                    )
                };
            }
            match t {
                Scalar::I8 => put!(v as i8),
                Scalar::U8 => put!(v as u8),
                Scalar::I16 => put!(v as i16),
                Scalar::U16 => put!(v as u16),
                Scalar::I32 => put!(v as i32),
                Scalar::U32 => put!(v as u32),
                Scalar::F32 => put!(v as f32),
                Scalar::F64 => put!(v),
            }
        }
        b
    }

    fn binary_file(big: bool, z: f64, corner: f64) -> Vec<u8> {
        use Scalar::*;
        let fmt = if big {
            "binary_big_endian"
        } else {
            "binary_little_endian"
        };
        let head = HEAD.replace("format ascii", &format!("format {fmt}"));
        let mut b = head.into_bytes();
        let mut vals = Vec::new();
        for (i, pt) in [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, z],
        ]
        .iter()
        .enumerate()
        {
            vals.extend([(F32, pt[0]), (U8, i as f64), (F64, pt[1]), (I32, pt[2])]);
        }
        vals.extend([(U8, 3.0), (I32, 0.0), (I32, 1.0), (I32, 2.0), (F32, 0.5)]);
        vals.extend([(U8, 3.0), (U32, 0.0), (U32, 1.0), (U32, corner), (F32, 9.0)]);
        vals.extend([
            (U8, 4.0),
            (U32, 0.0),
            (U32, 1.0),
            (U32, 2.0),
            (U32, 3.0),
            (F32, 1e3),
        ]);
        b.extend(bin(&vals, big));
        b
    }

    #[test]
    fn binary_both_byte_orders() {
        for big in [false, true] {
            let plc = parse(&binary_file(big, 1.0, 2.0), p()).unwrap();
            assert_eq!(plc.points[3], [0.0, 0.0, 1.0]);
            assert_eq!(plc.facets[1].polygons, vec![vec![0, 1, 2, 3]]);
        }
    }

    #[test]
    fn errors() {
        let err = |b: &[u8]| parse(b, p()).unwrap_err().to_string();
        let mut b = binary_file(false, 1.0, 2.0);
        b.truncate(b.len() - 3);
        assert!(
            err(&b).starts_with("t.ply: the file ends inside face 1 (at byte offset "),
            "{}",
            err(&b)
        );
        assert!(err(&binary_file(true, 1.0, 7.0)).starts_with(
            "t.ply: face 0 has corner 7, but there are only 4 vertices (numbered from 0) (at byte offset"
        ));
        let mut b = binary_file(false, 1.0, 2.0);
        b.push(0);
        assert!(err(&b).starts_with("t.ply: 1 bytes after the last element"));
        assert_eq!(
            err(b"plyx\n"),
            "t.ply:1: not a PLY file: the first line must be `ply`"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n"),
            "t.ply:3: the `vertex` element has no `z` property"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\n"),
            "t.ply:4: unknown property type `flot`"
        );
        assert_eq!(
            err(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"),
            "t.ply:4: unexpected end of file: expected `end_header`"
        );
        let text = format!("{HEAD}0 1 0 0\n1 256 0 0\n");
        assert_eq!(
            err(text.as_bytes()),
            "t.ply:17: property `red` of vertex 1 is out of range for its type uchar: 256"
        );
        let text = format!("{HEAD}0 1 0 0\n1 2 0 0\n0 3 1 0\n0 4 inf 1\n");
        assert_eq!(
            err(text.as_bytes()),
            "t.ply:19: the y coordinate of vertex 3 is not a finite number: `inf`"
        );
        let text = format!("{HEAD}0 1 0 0\n1 2 0 0\n0 3 1 0\n0 4 0 1\n3 0 1 2 0.5\n3 0 1 4 9\n");
        assert_eq!(
            err(text.as_bytes()),
            "t.ply:21: face 0 has corner 4, but there are only 4 vertices (numbered from 0)"
        );
        let text = format!("{HEAD}0 1 0 0\n1 2 0 0\n0 3 1 0\n0 4 0 1\n3 0 1 2 0.5\n3 0 1 2 9\n");
        assert_eq!(
            err(text.as_bytes()),
            "t.ply:21: unexpected end of file: expected the length of list `vertex_index` of face 1"
        );
        // A lying count allocates nothing.
        let b = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty double x\nproperty double y\nproperty double z\nend_header\n";
        assert!(
            err(b).contains("announces 4000000000 `vertex` elements"),
            "{}",
            err(b)
        );
    }
}
