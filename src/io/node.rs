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
use std::fs::File;
use std::io::Read;
use std::path::Path;
use std::sync::mpsc;

/// Reads a `.node` file.
pub fn read(path: &Path) -> Result<Plc, InputError> {
    if let Some(plc) = fast::read(path) {
        return Ok(plc);
    }
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

    /// Large files take the two-thread block reader; it must read exactly what the
    /// exact reader reads, and leave every error to it.
    #[test]
    fn large_files_read_the_same_both_ways() {
        let dir = tempfile::tempdir().unwrap();
        let exact = |path: &Path| parse(&read_text(path).unwrap(), path);
        let two_cores = std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2);
        // `ok`: the file is valid; `fast`: the block reader reads it (else it gives up).
        let check = |name: &str, text: String, ok: bool, fast: bool| {
            let path = dir.path().join(name);
            std::fs::write(&path, &text).unwrap();
            assert!(text.len() as u64 > fast::MIN_SIZE, "{name} is too small");
            if two_cores {
                assert_eq!(fast::read(&path).is_some(), fast, "{name}");
            }
            match (read(&path), exact(&path)) {
                (Ok(a), Ok(b)) => {
                    assert!(ok, "{name} should fail");
                    assert_eq!(a.points, b.points, "{name}");
                    assert_eq!(a.point_attrs, b.point_attrs, "{name}");
                    assert_eq!(a.point_markers, b.point_markers, "{name}");
                    assert_eq!(
                        (a.first_index, a.num_point_attrs, &a.source),
                        (b.first_index, b.num_point_attrs, &b.source)
                    );
                }
                (Err(a), Err(b)) => {
                    assert!(!ok, "{name}: {a}");
                    assert_eq!(a.to_string(), b.to_string());
                }
                (a, b) => panic!("{name}: {:?} vs {:?}", a.is_ok(), b.is_ok()),
            }
        };
        let n = 120_000;
        let lines = |from: usize, extra: &dyn Fn(usize) -> String| -> String {
            (0..n)
                .map(|i| {
                    let x = i as f64 / 7.0;
                    format!("{} {x} {} -{x}e-3{}\n", i + from, i % 97, extra(i))
                })
                .collect()
        };
        check(
            "plain.node",
            format!("{n} 3 0 0\n{}", lines(1, &|_| String::new())),
            true,
            true,
        );
        check(
            "attrs.node",
            format!(
                "# c\n\n{n}  3  2  1\n{}",
                lines(0, &|i| format!(" {i}.5 -2 {} # x", i % 5))
            ),
            true,
            true,
        );
        let crlf = lines(1, &|_| String::new()).replace('\n', "\r\n");
        check(
            "crlf.node",
            format!("{n} 3 0 0\r\n{crlf}# trailing\n"),
            true,
            true,
        );
        let mut more = lines(1, &|_| String::new());
        more.push_str("junk that the reader ignores\n");
        check("trailing.node", format!("{n} 3 0 0\n{more}"), true, false);
        check(
            "short.node",
            format!("{} 3 0 0\n{}", n + 1, lines(1, &|_| String::new())),
            false,
            false,
        );
        let mut bad = lines(1, &|_| String::new());
        bad.replace_range(3_000_000..3_000_001, "x");
        check("bad.node", format!("{n} 3 0 0\n{bad}"), false, false);
        let skip = lines(1, &|_| String::new()).replacen("\n5000 ", "\n5001 ", 1);
        check("skip.node", format!("{n} 3 0 0\n{skip}"), false, false);
        check(
            "from2.node",
            format!("{n} 3 0 0\n{}", lines(2, &|_| String::new())),
            false,
            false,
        );
    }

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

/// The reader of large, well-formed `.node` files: the file is read a block of lines at
/// a time into reused buffers, and two threads parse alternate blocks.
///
/// A million points are 70 MB of text, which need not sit in fresh memory all at once,
/// and parsing them is easily split: this halved the time to read a million points.
/// Anything unusual (an error, a stray line, a file that is not UTF-8) makes it give
/// up, and the exact reader then reads the file and reports the problem.
mod fast {
    use super::*;

    /// Files smaller than this are left to the exact reader.
    pub(super) const MIN_SIZE: u64 = 1 << 22;
    /// Bytes per block (a block ends at a line end, so it may be longer).
    const BLOCK: usize = 1 << 20;

    /// The points parsed from one block.
    #[derive(Default)]
    struct Points {
        xyz: Vec<[f64; 3]>,
        attrs: Vec<f64>,
        markers: Vec<i32>,
        /// The number written on the block's first point line.
        first_number: i64,
    }

    /// The layout of the point lines, from the header.
    #[derive(Clone, Copy)]
    struct Layout {
        attrs: usize,
        markers: bool,
    }

    /// Parses every line of `text` as a point line with consecutive numbers into `out`;
    /// false if any line does not fit.
    fn parse_block(text: &[u8], layout: Layout, out: &mut Points) -> bool {
        let Ok(text) = std::str::from_utf8(text) else {
            return false;
        };
        out.xyz.clear();
        out.attrs.clear();
        out.markers.clear();
        let mut lines = Lines::new(text, Path::new(""));
        while let Some(mut line) = lines.next_line() {
            let Ok(number) = line.int(String::new) else {
                return false;
            };
            if out.xyz.is_empty() {
                out.first_number = number;
            } else if number != out.first_number + out.xyz.len() as i64 {
                return false;
            }
            let Ok(p) = line.xyz(&String::new) else {
                return false;
            };
            out.xyz.push(p);
            for _ in 0..layout.attrs {
                let Ok(a) = line.float(String::new) else {
                    return false;
                };
                out.attrs.push(a);
            }
            if layout.markers {
                let Ok(m) = line.marker(String::new) else {
                    return false;
                };
                out.markers.push(m);
            }
        }
        true
    }

    /// Reads the next block of whole lines into `buf`, keeping a partial last line in
    /// `carry` for the next block; an empty block means the end of the file. Fails on a
    /// line longer than a block.
    fn next_block(file: &mut File, carry: &mut Vec<u8>, buf: &mut Vec<u8>) -> std::io::Result<()> {
        buf.clear();
        buf.append(carry);
        while buf.len() < BLOCK {
            let start = buf.len();
            buf.resize(start + BLOCK, 0);
            let n = file.read(&mut buf[start..])?;
            buf.truncate(start + n);
            if n == 0 {
                return Ok(());
            }
        }
        match buf.iter().rposition(|&b| b == b'\n') {
            Some(end) => {
                carry.extend_from_slice(&buf[end + 1..]);
                buf.truncate(end + 1);
                Ok(())
            }
            // A line longer than a block: not worth handling here.
            None => Err(std::io::Error::other("line too long")),
        }
    }

    /// The points of a large `.node` file, or `None` to leave it to the exact reader.
    pub(super) fn read(path: &Path) -> Option<Plc> {
        let workers = crate::cores().min(2);
        let mut file = File::open(path).ok()?;
        let size = file.metadata().ok()?.len();
        if size < MIN_SIZE || workers < 2 {
            return None;
        }
        let mut carry = Vec::new();
        let mut first = Vec::new();
        next_block(&mut file, &mut carry, &mut first).ok()?;
        let text = std::str::from_utf8(&first).ok()?;
        let mut lines = Lines::new(text, path);
        let mut header = lines.next_line()?;
        let count = header.count(String::new).ok()?;
        let dim = header.opt_count(String::new).ok()?.unwrap_or(3);
        let attrs = header.opt_count(String::new).ok()?.unwrap_or(0);
        let markers = header.opt_flag(String::new).ok()?;
        if dim != 3 || u32::try_from(count).is_err() {
            return None;
        }
        let layout = Layout { attrs, markers };
        // The lines after the header are the first block of points.
        let skip = text.len() - lines.remaining().len();
        first.drain(..skip);

        // Bounded by the file size, as the exact reader bounds it by the text.
        let cap = count.min((size / 8) as usize + 1);
        let mut plc = Plc {
            source: path.to_path_buf(),
            points: Vec::with_capacity(cap),
            num_point_attrs: attrs,
            point_attrs: Vec::with_capacity(cap.saturating_mul(attrs).min(size as usize / 2)),
            point_markers: markers.then(|| Vec::with_capacity(cap)),
            ..Default::default()
        };
        let ok = std::thread::scope(|scope| {
            // Per worker: blocks to parse in, parsed blocks (with their buffers) out.
            let mut lanes = Vec::with_capacity(workers);
            for _ in 0..workers {
                let (todo_tx, todo_rx) = mpsc::sync_channel::<(Vec<u8>, Points)>(1);
                let (done_tx, done_rx) = mpsc::sync_channel::<(Vec<u8>, Points, bool)>(1);
                scope.spawn(move || {
                    for (text, mut pts) in todo_rx {
                        let ok = parse_block(&text, layout, &mut pts);
                        if done_tx.send((text, pts, ok)).is_err() {
                            return;
                        }
                    }
                });
                lanes.push((todo_tx, done_rx));
            }
            // Keeps every worker one block ahead of the merge.
            let mut spare: Vec<(Vec<u8>, Points)> = Vec::new();
            let mut next = Some(first);
            let (mut sent, mut merged) = (0usize, 0usize);
            loop {
                while sent < merged + workers {
                    let Some(block) = next.take() else { break };
                    let pts = spare.pop().map(|(_, p)| p).unwrap_or_default();
                    if lanes[sent % workers].0.send((block, pts)).is_err() {
                        return false;
                    }
                    sent += 1;
                    let mut buf = spare.pop().map(|(b, _)| b).unwrap_or_default();
                    if next_block(&mut file, &mut carry, &mut buf).is_err() {
                        return false;
                    }
                    next = (!buf.is_empty()).then_some(buf);
                }
                if merged == sent {
                    return true;
                }
                let Ok((text, pts, ok)) = lanes[merged % workers].1.recv() else {
                    return false;
                };
                merged += 1;
                if !ok || !merge(&mut plc, &pts, count) {
                    return false;
                }
                spare.push((text, pts));
            }
        });
        (ok && plc.points.len() == count).then_some(plc)
    }

    /// Appends a parsed block to `plc`, checking its numbering against the points before
    /// it; points beyond `count` are left out, as the exact reader ignores those lines.
    fn merge(plc: &mut Plc, pts: &Points, count: usize) -> bool {
        let have = plc.points.len();
        if pts.xyz.is_empty() || have == count {
            return true;
        }
        let first = if have == 0 {
            match pts.first_number {
                0 => 0,
                1 => 1,
                _ => return false,
            }
        } else {
            plc.first_index
        };
        if pts.first_number != (first + have) as i64 {
            return false;
        }
        plc.first_index = first;
        let take = pts.xyz.len().min(count - have);
        plc.points.extend_from_slice(&pts.xyz[..take]);
        plc.point_attrs
            .extend_from_slice(&pts.attrs[..take * plc.num_point_attrs]);
        if let Some(m) = plc.point_markers.as_mut() {
            m.extend_from_slice(&pts.markers[..take]);
        }
        true
    }
}
