//! Tokens that flow across line breaks, for the formats whose records are not tied to
//! lines (Medit `.mesh`, ASCII STL, ASCII PLY data).
//!
//! Built on [`Lines`]/[`Line`], so parse errors read as in the line-oriented readers
//! (`file:line: expected ...`), the line being the one where the offending token sits.

use super::tokens::{Line, Lines};
use crate::error::InputError;
use std::path::Path;

/// A cursor over the tokens of a text, line breaks being plain separators.
#[derive(Clone, Debug)]
pub struct Tokens<'a> {
    lines: Lines<'a>,
    cur: Option<Line<'a>>,
}

impl<'a> Tokens<'a> {
    /// Starts at the beginning of `text`, which came from `path`.
    pub fn new(text: &'a str, path: &'a Path) -> Self {
        Tokens::from_lines(Lines::new(text, path))
    }

    /// Continues from the line after the last one `lines` handed out.
    pub fn from_lines(lines: Lines<'a>) -> Self {
        Tokens { lines, cur: None }
    }

    /// The file the text came from.
    pub fn path(&self) -> &'a Path {
        self.lines.path()
    }

    /// The line holding the next token, or `None` at the end of the text. Parsing a
    /// token from it (`float`, `int`, ...) consumes that token.
    pub fn line(&mut self) -> Option<&mut Line<'a>> {
        while self.cur.as_ref().is_none_or(Line::at_end) {
            self.cur = Some(self.lines.next_line()?);
        }
        self.cur.as_mut()
    }

    /// Like [`Tokens::line`], but the end of the text is an error saying that `what`
    /// was expected.
    pub fn expect(&mut self, what: impl FnOnce() -> String) -> Result<&mut Line<'a>, InputError> {
        if self.line().is_none() {
            return Err(self.lines.eof_error(what()));
        }
        Ok(self.cur.as_mut().expect("line() found a token"))
    }

    /// The next token, without consuming it (`None` at the end of the text).
    pub fn peek(&mut self) -> Option<&'a str> {
        self.line().and_then(|l| l.peek_token())
    }

    /// Drops the rest of the current line (e.g. a name after a keyword).
    pub fn skip_rest_of_line(&mut self) {
        self.cur = None;
    }

    /// The number of the line of the last token consumed or peeked (0 before any).
    pub fn line_number(&self) -> usize {
        self.cur
            .as_ref()
            .map_or(self.lines.line_number(), Line::number)
    }

    /// An error at the current line.
    pub fn error(&self, msg: impl Into<String>) -> InputError {
        InputError::parse(self.path(), self.line_number().max(1), msg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_cross_lines_and_skip_comments() {
        let p = Path::new("t.mesh");
        let mut t = Tokens::new("Vertices # the points\n\n 2\n1 2\n3 end\n", p);
        assert_eq!(t.peek(), Some("Vertices"));
        assert_eq!(t.line_number(), 1);
        t.skip_rest_of_line();
        assert_eq!(
            t.expect(|| "n".into())
                .unwrap()
                .count(|| "n".into())
                .unwrap(),
            2
        );
        assert_eq!(t.line_number(), 3);
        let mut v = Vec::new();
        for _ in 0..3 {
            v.push(
                t.expect(|| "v".into())
                    .unwrap()
                    .float(|| "v".into())
                    .unwrap(),
            );
        }
        assert_eq!(v, [1.0, 2.0, 3.0]);
        assert_eq!(t.line_number(), 5);
        assert_eq!(t.peek(), Some("end"));
        t.skip_rest_of_line();
        assert!(t.peek().is_none());
        let e = t.expect(|| "vertex 3".into()).unwrap_err().to_string();
        assert_eq!(e, "t.mesh:5: unexpected end of file: expected vertex 3");
        let mut t = Tokens::new("1 x\n", p);
        t.expect(|| "a".into()).unwrap().int(|| "a".into()).unwrap();
        let e = t
            .expect(|| "b".into())
            .unwrap()
            .int(|| "b".into())
            .unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.mesh:1: expected b (an integer), found `x`"
        );
    }
}
