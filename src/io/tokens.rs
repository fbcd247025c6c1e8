//! A line tokenizer shared by the readers of TetGen's text formats.
//!
//! TetGen's formats are line oriented: every record (a header, a point, a facet, a
//! polygon, a hole, a region) sits on one line. [`Lines`] hands out the non-blank lines
//! of a text with their 1-based numbers, with `#` comments removed; [`Line`] splits one
//! line into tokens (separated by white space or commas) and parses them as integers or
//! floats, with errors that name the file, the line and what was expected there, e.g.
//! `cube.node:14: expected the x coordinate of point 12, found `abc``.
//!
//! Descriptions of what is expected are passed as closures so that they cost nothing
//! unless an error is actually reported.

use crate::error::InputError;
use num_error::IntErr;
use std::path::Path;

/// Reads a whole input file as text.
///
/// Bytes that are not valid UTF-8 (say, Latin-1 characters in comments) are replaced by
/// U+FFFD rather than failing the whole file; if they sit where a number is expected, the
/// parse error names their line.
pub fn read_text(path: &Path) -> Result<String, InputError> {
    let bytes = std::fs::read(path).map_err(|e| InputError::io(path, e))?;
    Ok(match String::from_utf8(bytes) {
        Ok(text) => text,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    })
}

/// Removes a `#` comment from a line.
pub fn strip_comment(line: &str) -> &str {
    match line.find('#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// The non-blank, comment-free lines of a text, with their 1-based numbers.
#[derive(Clone, Debug)]
pub struct Lines<'a> {
    path: &'a Path,
    rest: &'a str,
    line_no: usize,
}

impl<'a> Lines<'a> {
    /// Starts reading `text`, which came from `path` (used in error messages).
    pub fn new(text: &'a str, path: &'a Path) -> Self {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        Lines {
            path,
            rest: text,
            line_no: 0,
        }
    }

    /// The file the text came from.
    pub fn path(&self) -> &'a Path {
        self.path
    }

    /// The number of the last line handed out or skipped (0 before the first one).
    pub fn line_number(&self) -> usize {
        self.line_no
    }

    /// Returns the next raw line (blank or not, comment included) and its number.
    pub fn next_raw(&mut self) -> Option<(usize, &'a str)> {
        if self.rest.is_empty() {
            return None;
        }
        let (line, rest) = match self.rest.find('\n') {
            Some(i) => (&self.rest[..i], &self.rest[i + 1..]),
            None => (self.rest, ""),
        };
        self.rest = rest;
        self.line_no += 1;
        Some((self.line_no, line.strip_suffix('\r').unwrap_or(line)))
    }

    /// Returns the next line that holds at least one token, or `None` at the end of the text.
    pub fn next_line(&mut self) -> Option<Line<'a>> {
        while let Some((number, raw)) = self.next_raw() {
            let line = Line::new(self.path, number, strip_comment(raw));
            if !line.at_end() {
                return Some(line);
            }
        }
        None
    }

    /// Returns the next non-blank line, or an error saying that the file ended where
    /// `what` was expected.
    pub fn expect_line(&mut self, what: impl FnOnce() -> String) -> Result<Line<'a>, InputError> {
        match self.next_line() {
            Some(line) => Ok(line),
            None => Err(self.eof_error(what())),
        }
    }

    /// An error saying that the file ended (at its last line) where `what` was expected.
    pub fn eof_error(&self, what: String) -> InputError {
        InputError::parse(
            self.path,
            self.line_no.max(1),
            format!("unexpected end of file: expected {what}"),
        )
    }

    /// The text after the last line handed out.
    pub fn remaining(&self) -> &'a str {
        self.rest
    }

    /// A safe capacity for a vector of `count` elements announced by a header: at most
    /// one element per 8 bytes of the rest of the text (about the shortest record, e.g.
    /// `1 0 0 0` and its line break), so that a lying header cannot make us allocate
    /// blindly. An underestimate only costs the vector some regrowth.
    pub fn capacity_for(&self, count: usize) -> usize {
        count.min(self.rest.len() / 8 + 1)
    }
}

/// The tokens of one line, consumed from left to right.
#[derive(Clone, Debug)]
pub struct Line<'a> {
    path: &'a Path,
    number: usize,
    rest: &'a str,
}

fn is_separator(c: char) -> bool {
    c.is_whitespace() || c == ','
}

/// [`is_separator`] for an ASCII byte: the ASCII white space of `char::is_whitespace`, or a comma.
fn is_separator_byte(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c | b',')
}

/// The byte range of the next token of `s` (empty at the end of the line), found by
/// scanning bytes; `None` if a non-ASCII byte comes first, which the char-based scan
/// must judge. Files of a million points spent most of their parsing time splitting
/// tokens char by char.
#[inline]
fn ascii_token(s: &str) -> Option<(usize, usize)> {
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() && is_separator_byte(b[i]) {
        i += 1;
    }
    let start = i;
    while i < b.len() && !is_separator_byte(b[i]) {
        if !b[i].is_ascii() {
            return None;
        }
        i += 1;
    }
    Some((start, i))
}

impl<'a> Line<'a> {
    /// A line of `path` numbered `number` (1-based) with content `text` (comment already removed).
    pub fn new(path: &'a Path, number: usize, text: &'a str) -> Self {
        Line {
            path,
            number,
            rest: text,
        }
    }

    /// The 1-based number of the line in its file.
    pub fn number(&self) -> usize {
        self.number
    }

    /// The file the line belongs to.
    pub fn path(&self) -> &'a Path {
        self.path
    }

    /// Whether all tokens of the line have been consumed.
    pub fn at_end(&self) -> bool {
        self.peek_token().is_none()
    }

    /// The next token, without consuming it.
    pub fn peek_token(&self) -> Option<&'a str> {
        if let Some((start, end)) = ascii_token(self.rest) {
            return (start < end).then(|| &self.rest[start..end]);
        }
        let s = self.rest.trim_start_matches(is_separator);
        if s.is_empty() {
            return None;
        }
        let end = s.find(is_separator).unwrap_or(s.len());
        Some(&s[..end])
    }

    /// Consumes and returns the next token.
    pub fn next_token(&mut self) -> Option<&'a str> {
        if let Some((start, end)) = ascii_token(self.rest) {
            let tok = &self.rest[start..end];
            self.rest = &self.rest[end..];
            return (start < end).then_some(tok);
        }
        let s = self.rest.trim_start_matches(is_separator);
        if s.is_empty() {
            self.rest = s;
            return None;
        }
        let end = s.find(is_separator).unwrap_or(s.len());
        self.rest = &s[end..];
        Some(&s[..end])
    }

    /// The remaining text of the line (used to bound capacities).
    pub fn remaining_len(&self) -> usize {
        self.rest.len()
    }

    /// A parse error at this line.
    pub fn error(&self, msg: impl Into<String>) -> InputError {
        InputError::parse(self.path, self.number, msg)
    }

    /// Consumes the next token, or fails saying that `what` was expected.
    pub fn token(&mut self, what: impl FnOnce() -> String) -> Result<&'a str, InputError> {
        match self.next_token() {
            Some(t) => Ok(t),
            None => Err(self.error(format!("expected {}, but the line ends", what()))),
        }
    }

    fn parse_int(&self, tok: &str, what: impl FnOnce() -> String) -> Result<i64, InputError> {
        match num_error::parse_i64(tok) {
            Ok(v) => Ok(v),
            Err(IntErr::Range) => Err(self.error(format!("{} is out of range: `{tok}`", what()))),
            Err(IntErr::Invalid) => {
                Err(self.error(format!("expected {} (an integer), found `{tok}`", what())))
            }
        }
    }

    /// Consumes an integer.
    pub fn int(&mut self, what: impl FnOnce() -> String) -> Result<i64, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_int(tok, what),
            None => Err(self.error(format!("expected {}, but the line ends", what()))),
        }
    }

    /// Consumes an integer if the line has one more token.
    pub fn opt_int(&mut self, what: impl FnOnce() -> String) -> Result<Option<i64>, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_int(tok, what).map(Some),
            None => Ok(None),
        }
    }

    fn parse_count(&self, tok: &str, what: impl FnOnce() -> String) -> Result<usize, InputError> {
        match num_error::parse_i64(tok) {
            Ok(v) if v < 0 => {
                Err(self.error(format!("{} cannot be negative, found `{tok}`", what())))
            }
            Ok(v) => usize::try_from(v)
                .map_err(|_| self.error(format!("{} is too large: `{tok}`", what()))),
            Err(IntErr::Range) => Err(self.error(format!("{} is out of range: `{tok}`", what()))),
            Err(IntErr::Invalid) => Err(self.error(format!(
                "expected {} (a non-negative integer), found `{tok}`",
                what()
            ))),
        }
    }

    /// Consumes a non-negative integer (a count).
    pub fn count(&mut self, what: impl FnOnce() -> String) -> Result<usize, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_count(tok, what),
            None => Err(self.error(format!("expected {}, but the line ends", what()))),
        }
    }

    /// Consumes a non-negative integer if the line has one more token.
    pub fn opt_count(
        &mut self,
        what: impl FnOnce() -> String,
    ) -> Result<Option<usize>, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_count(tok, what).map(Some),
            None => Ok(None),
        }
    }

    /// Consumes a 0/1 flag if the line has one more token (absent means 0).
    pub fn opt_flag(&mut self, what: impl FnOnce() -> String) -> Result<bool, InputError> {
        match self.next_token() {
            None => Ok(false),
            Some(tok) => match num_error::parse_i64(tok) {
                Ok(0) => Ok(false),
                Ok(1) => Ok(true),
                _ => Err(self.error(format!("{} must be 0 or 1, found `{tok}`", what()))),
            },
        }
    }

    fn parse_marker(&self, tok: &str, what: impl FnOnce() -> String) -> Result<i32, InputError> {
        match num_error::parse_i64(tok) {
            Ok(v) => i32::try_from(v).map_err(|_| {
                self.error(format!(
                    "{} is out of range (it must fit in 32 bits): `{tok}`",
                    what()
                ))
            }),
            Err(IntErr::Range) => Err(self.error(format!(
                "{} is out of range (it must fit in 32 bits): `{tok}`",
                what()
            ))),
            Err(IntErr::Invalid) => {
                Err(self.error(format!("expected {} (an integer), found `{tok}`", what())))
            }
        }
    }

    /// Consumes a boundary marker (a 32-bit integer).
    pub fn marker(&mut self, what: impl FnOnce() -> String) -> Result<i32, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_marker(tok, what),
            None => Err(self.error(format!("expected {}, but the line ends", what()))),
        }
    }

    /// Consumes a boundary marker if the line has one more token.
    pub fn opt_marker(&mut self, what: impl FnOnce() -> String) -> Result<Option<i32>, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_marker(tok, what).map(Some),
            None => Ok(None),
        }
    }

    fn parse_float(&self, tok: &str, what: impl FnOnce() -> String) -> Result<f64, InputError> {
        match tok.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.error(format!("{} is not a finite number: `{tok}`", what()))),
            Err(_) => Err(self.error(format!("expected {}, found `{tok}`", what()))),
        }
    }

    /// Consumes a finite floating-point number (NaN, infinities and overflowing values
    /// such as `1e999` are rejected).
    pub fn float(&mut self, what: impl FnOnce() -> String) -> Result<f64, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_float(tok, what),
            None => Err(self.error(format!("expected {}, but the line ends", what()))),
        }
    }

    /// Consumes a finite floating-point number if the line has one more token.
    pub fn opt_float(&mut self, what: impl FnOnce() -> String) -> Result<Option<f64>, InputError> {
        match self.next_token() {
            Some(tok) => self.parse_float(tok, what).map(Some),
            None => Ok(None),
        }
    }

    /// Consumes three finite coordinates of `element` (e.g. "point 12"), failing with
    /// messages such as "expected the x coordinate of point 12, found `abc`".
    pub fn xyz(&mut self, element: &dyn Fn() -> String) -> Result<[f64; 3], InputError> {
        let x = self.float(|| format!("the x coordinate of {}", element()))?;
        let y = self.float(|| format!("the y coordinate of {}", element()))?;
        let z = self.float(|| format!("the z coordinate of {}", element()))?;
        Ok([x, y, z])
    }
}

/// Converts a vertex number as written in a file (numbered from `first`) to a 0-based
/// index below `count`, or explains (as "has corner ..., but ...") why it is out of range.
///
/// `one` and `many` name the things indexed ("point"/"points", "vertex"/"vertices").
pub fn corner_index(
    written: i64,
    first: usize,
    count: usize,
    one: &str,
    many: &str,
) -> Result<u32, String> {
    let index = i64::try_from(first)
        .ok()
        .and_then(|f| written.checked_sub(f));
    match index.and_then(|i| usize::try_from(i).ok()) {
        Some(i) if i < count => {
            u32::try_from(i).map_err(|_| format!("has corner {written}, which is too large"))
        }
        _ if count == 0 => Err(format!("has corner {written}, but there are no {many}")),
        Some(_) if count == 1 => Err(format!(
            "has corner {written}, but there is only 1 {one} (numbered from {first})"
        )),
        Some(_) => Err(format!(
            "has corner {written}, but there are only {count} {many} (numbered from {first})"
        )),
        None => Err(format!(
            "has corner {written}, but the {many} are numbered from {first}"
        )),
    }
}

/// Integer parsing that tells malformed tokens from out-of-range ones.
mod num_error {
    use std::num::IntErrorKind;

    /// Why a token is not an `i64`.
    pub enum IntErr {
        /// The token is an integer, but does not fit.
        Range,
        /// The token is not an integer.
        Invalid,
    }

    /// Parses a decimal integer with an optional sign.
    pub fn parse_i64(tok: &str) -> Result<i64, IntErr> {
        tok.parse::<i64>().map_err(|e| match e.kind() {
            IntErrorKind::PosOverflow | IntErrorKind::NegOverflow => IntErr::Range,
            _ => IntErr::Invalid,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("t.node")
    }

    #[test]
    fn skips_comments_and_blank_lines_and_counts_lines() {
        let text = "# header comment\n\n  1 2 # trailing\r\n\t\n#only\n3,4\n";
        let mut lines = Lines::new(text, p());
        let mut a = lines.next_line().unwrap();
        assert_eq!(a.number(), 3);
        assert_eq!(a.next_token(), Some("1"));
        assert_eq!(a.next_token(), Some("2"));
        assert_eq!(a.next_token(), None);
        let mut b = lines.next_line().unwrap();
        assert_eq!(b.number(), 6);
        assert_eq!(b.count(|| "x".into()).unwrap(), 3);
        assert_eq!(b.count(|| "y".into()).unwrap(), 4);
        assert!(b.at_end());
        assert!(lines.next_line().is_none());
        let e = lines.eof_error("point 7".into()).to_string();
        assert_eq!(e, "t.node:6: unexpected end of file: expected point 7");
    }

    /// The byte scan splits tokens exactly as the char-based definition does, also
    /// around non-ASCII white space and letters.
    #[test]
    fn tokens_split_on_unicode_white_space_too() {
        for text in [
            "1 2\t3,4\r",
            " ,, 5 ,6",
            "1\u{a0}2\u{2003}3",
            "x\u{e9}y 7",
            "\u{e9} 8",
            "9\u{a0}",
            "",
            "\u{85}10",
        ] {
            let mut line = Line::new(p(), 1, text);
            let mut got = Vec::new();
            while let Some(peeked) = line.peek_token() {
                let t = line.next_token();
                assert_eq!(t, Some(peeked));
                got.push(peeked);
            }
            assert_eq!(line.next_token(), None);
            let want: Vec<&str> = text.split(is_separator).filter(|t| !t.is_empty()).collect();
            assert_eq!(got, want, "{text:?}");
        }
    }

    #[test]
    fn float_errors_name_the_element() {
        let mut line = Line::new(p(), 14, "abc nan 1e999 -inf 2.5");
        let e = line
            .float(|| "the x coordinate of point 12".into())
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.node:14: expected the x coordinate of point 12, found `abc`"
        );
        for bad in ["nan", "1e999", "-inf"] {
            let e = line
                .float(|| "the y coordinate of point 12".into())
                .unwrap_err();
            assert_eq!(
                e.to_string(),
                format!("t.node:14: the y coordinate of point 12 is not a finite number: `{bad}`")
            );
        }
        assert_eq!(line.float(|| "z".into()).unwrap(), 2.5);
        let e = line
            .float(|| "the z coordinate of point 12".into())
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.node:14: expected the z coordinate of point 12, but the line ends"
        );
    }

    #[test]
    fn count_errors() {
        let mut line = Line::new(p(), 1, "-3 2.5 99999999999999999999999 x 7");
        let msg = |l: &mut Line| {
            l.count(|| "the number of points".into())
                .unwrap_err()
                .to_string()
        };
        assert_eq!(
            msg(&mut line),
            "t.node:1: the number of points cannot be negative, found `-3`"
        );
        assert_eq!(
            msg(&mut line),
            "t.node:1: expected the number of points (a non-negative integer), found `2.5`"
        );
        assert!(msg(&mut line).contains("out of range"));
        assert!(msg(&mut line).contains("found `x`"));
        assert_eq!(line.opt_count(|| "n".into()).unwrap(), Some(7));
        assert_eq!(line.opt_count(|| "n".into()).unwrap(), None);
    }

    #[test]
    fn markers_and_flags() {
        let mut line = Line::new(p(), 2, "-5 4294967296 2 1");
        assert_eq!(line.marker(|| "m".into()).unwrap(), -5);
        assert!(line
            .marker(|| "m".into())
            .unwrap_err()
            .to_string()
            .contains("32 bits"));
        assert!(line
            .opt_flag(|| "the flag".into())
            .unwrap_err()
            .to_string()
            .contains("must be 0 or 1"));
        assert!(line.opt_flag(|| "f".into()).unwrap());
        assert!(!line.opt_flag(|| "f".into()).unwrap());
    }

    #[test]
    fn corner_index_messages() {
        let ci = |w, first, n| corner_index(w, first, n, "point", "points");
        assert_eq!(ci(8, 1, 8), Ok(7));
        assert_eq!(ci(0, 0, 8), Ok(0));
        assert_eq!(
            ci(9, 1, 8).unwrap_err(),
            "has corner 9, but there are only 8 points (numbered from 1)"
        );
        assert_eq!(
            ci(0, 1, 8).unwrap_err(),
            "has corner 0, but the points are numbered from 1"
        );
        assert_eq!(
            ci(1, 0, 1).unwrap_err(),
            "has corner 1, but there is only 1 point (numbered from 0)"
        );
        assert!(ci(i64::MIN, 1, 8).is_err());
        assert!(ci(i64::MAX, 0, 8).is_err());
        assert_eq!(
            corner_index(3, 0, 0, "vertex", "vertices").unwrap_err(),
            "has corner 3, but there are no vertices"
        );
    }

    /// Feeds every reader with mutated versions of the example inputs: each must return
    /// (an error or a model) without panicking.
    #[test]
    fn readers_do_not_panic_on_mutated_inputs() {
        use crate::io::{node, obj, off, poly, smesh};
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/examples");
        type Parser = fn(&str, &Path) -> Result<crate::plc::Plc, InputError>;
        let cases: [(&str, Parser); 6] = [
            ("points8.node", node::parse),
            ("cube.poly", poly::parse),
            ("box_with_hole.poly", poly::parse),
            ("cube.smesh", smesh::parse),
            ("cube.off", off::parse),
            ("tet.obj", obj::parse),
        ];
        let pieces = [
            "-1",
            "0",
            "1",
            "9",
            "99999999999999999999",
            "4294967296",
            "nan",
            "1e999",
            "x",
            "#",
            "\n",
            " ",
            "\\",
            "/",
            "-9223372036854775808",
            "OFF",
            "2.5",
            ",",
        ];
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move |n: usize| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed % n as u64) as usize
        };
        for (name, parse) in cases {
            let text = std::fs::read_to_string(dir.join(name)).unwrap();
            let path = dir.join(name);
            for _ in 0..300 {
                let mut t = text.clone();
                for _ in 0..1 + next(3) {
                    // Pick a char boundary and replace a short span by a piece.
                    let mut at = next(t.len() + 1);
                    while !t.is_char_boundary(at) {
                        at -= 1;
                    }
                    let mut end = (at + next(4)).min(t.len());
                    while !t.is_char_boundary(end) {
                        end -= 1;
                    }
                    match next(3) {
                        0 => t.truncate(at),
                        _ => t.replace_range(at..end, pieces[next(pieces.len())]),
                    }
                }
                let _ = parse(&t, &path);
            }
        }
    }

    #[test]
    fn capacity_is_bounded_by_the_text() {
        let lines = Lines::new("1 2 3\n1 2 3\n", p());
        assert_eq!(lines.capacity_for(usize::MAX), 2);
        assert_eq!(lines.capacity_for(1), 1);
    }
}
