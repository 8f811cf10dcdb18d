//! The two things about a text file's bytes that are not its text: a
//! UTF-8 byte-order mark, and CRLF line endings. A saved file keeps them
//! as found.

const BOM: &str = "\u{feff}";

/// A text file's byte-order mark and line endings.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TextStyle {
    /// The text starts with a UTF-8 byte-order mark.
    pub bom: bool,
    /// Lines end in CRLF (as the first line of the text does).
    pub crlf: bool,
}

impl TextStyle {
    /// The style of a file's bytes (or text): its first line decides the
    /// line endings.
    #[must_use]
    pub fn of(bytes: &[u8]) -> Self {
        Self {
            bom: bytes.starts_with(BOM.as_bytes()),
            crlf: bytes
                .iter()
                .position(|&b| b == b'\n')
                .is_some_and(|i| i > 0 && bytes[i - 1] == b'\r'),
        }
    }

    /// `text` in this style: its own byte-order mark dropped and every
    /// line ending made LF, then the mark and CRLF put back as this style
    /// has them. (A TOML text holds a CR only before a LF, so no CR of
    /// the text is lost.)
    #[must_use]
    pub fn apply(self, text: &str) -> String {
        let body = text.strip_prefix(BOM).unwrap_or(text);
        let mut out = String::with_capacity(body.len() + body.len() / 32 + 3);
        if self.bom {
            out.push_str(BOM);
        }
        let mut lines = body.split_inclusive('\n');
        for line in lines.by_ref() {
            match line.strip_suffix('\n') {
                Some(l) => {
                    out.push_str(l.strip_suffix('\r').unwrap_or(l));
                    out.push_str(if self.crlf { "\r\n" } else { "\n" });
                }
                None => out.push_str(line),
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_style_is_read_from_the_mark_and_the_first_line() {
        assert_eq!(TextStyle::of(b"a\nb\r\n"), TextStyle::default());
        let crlf = TextStyle::of(b"a\r\nb\n");
        assert_eq!((crlf.bom, crlf.crlf), (false, true));
        let both = TextStyle::of("\u{feff}a\r\n".as_bytes());
        assert_eq!((both.bom, both.crlf), (true, true));
        assert!(TextStyle::of(b"\r\n").crlf, "an empty first line");
        assert!(!TextStyle::of(b"\n").crlf);
        assert_eq!(TextStyle::of(b"no newline"), TextStyle::default());
    }

    #[test]
    fn applying_a_style_normalises_then_converts() {
        let mixed = "\u{feff}a = 1\r\nb = 2\nc = 3";
        let lf = TextStyle::default();
        let crlf = TextStyle {
            bom: false,
            crlf: true,
        };
        let both = TextStyle {
            bom: true,
            crlf: true,
        };
        assert_eq!(lf.apply(mixed), "a = 1\nb = 2\nc = 3");
        assert_eq!(crlf.apply(mixed), "a = 1\r\nb = 2\r\nc = 3");
        assert_eq!(both.apply(mixed), "\u{feff}a = 1\r\nb = 2\r\nc = 3");
        assert_eq!(both.apply(&both.apply(mixed)), both.apply(mixed));
        assert_eq!(lf.apply(""), "");
        assert_eq!(both.apply("\n"), "\u{feff}\r\n");
    }
}
