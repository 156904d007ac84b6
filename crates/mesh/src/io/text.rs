//! The text of PLY, STL and OFF files: UTF-8 checked once, then read as lines or as
//! whitespace-separated words, each with its 1-based line number for error messages.

/// `bytes` as text, or the 1-based line of the first byte that is not UTF-8.
pub(crate) fn as_text(bytes: &[u8]) -> Result<&str, usize> {
    std::str::from_utf8(bytes).map_err(|e| {
        1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
    })
}

/// The lines of a text that hold something, each as `(line number, content)`: the content
/// stops before `comment` (when given) and the line is skipped when nothing but
/// whitespace is left.
pub(crate) struct Lines<'a> {
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    comment: Option<char>,
    first_line: usize,
}

impl<'a> Lines<'a> {
    /// The lines of `text`, whose first line is line `first_line` of the file.
    pub(crate) fn new(text: &'a str, comment: Option<char>, first_line: usize) -> Self {
        Self {
            lines: text.lines().enumerate(),
            comment,
            first_line,
        }
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, &'a str);

    fn next(&mut self) -> Option<Self::Item> {
        for (i, line) in self.lines.by_ref() {
            let content = match self.comment.and_then(|c| line.find(c)) {
                Some(end) => &line[..end],
                None => line,
            };
            if !content.trim_ascii().is_empty() {
                return Some((self.first_line + i, content));
            }
        }
        None
    }
}

/// The whitespace-separated words of a text, each as `(line number, word)`.
pub(crate) struct Words<'a> {
    lines: Lines<'a>,
    line: usize,
    words: std::str::SplitAsciiWhitespace<'a>,
}

impl<'a> Words<'a> {
    /// The words of `text`, whose first line is line `first_line` of the file.
    pub(crate) fn new(text: &'a str, first_line: usize) -> Self {
        Self {
            lines: Lines::new(text, None, first_line),
            line: first_line,
            words: "".split_ascii_whitespace(),
        }
    }

    /// The line of the last word returned (or of the start, before any).
    pub(crate) fn line(&self) -> usize {
        self.line
    }
}

impl<'a> Iterator for Words<'a> {
    type Item = (usize, &'a str);

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(word) = self.words.next() {
                return Some((self.line, word));
            }
            let (line, content) = self.lines.next()?;
            self.line = line;
            self.words = content.split_ascii_whitespace();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_skip_blanks_and_comments_and_keep_numbers() {
        let text = "OFF # header\n\n  # only a comment\n3 1 0\r\n0 0 0";
        let lines: Vec<_> = Lines::new(text, Some('#'), 1).collect();
        assert_eq!(lines, [(1, "OFF "), (4, "3 1 0"), (5, "0 0 0")]);
    }

    #[test]
    fn words_carry_their_line() {
        let words: Vec<_> = Words::new("a b\n\n c\n", 10).collect();
        assert_eq!(words, [(10, "a"), (10, "b"), (12, "c")]);
    }

    #[test]
    fn the_first_byte_that_is_not_utf8_is_named_by_its_line() {
        assert_eq!(as_text(b"ok\nok\n\xff"), Err(3));
        assert_eq!(as_text(b"ok"), Ok("ok"));
    }
}
