//! Shared pieces of the text readers: numbered lines, comments, tokens and numbers.
//!
//! Lines are bytes, not strings: a Latin-1 byte in a comment or a name is no reason to refuse a
//! file. `\n`, `\r\n` and a lone `\r` all end a line.

use super::{Place, ReadError, Syntax};

/// The lines of `bytes` with their numbers (from 1), each without its end-of-line bytes, and the
/// offset just after its end of line.
pub(crate) fn raw_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8], usize)> {
    let mut offset = 0;
    let mut number = 0;
    std::iter::from_fn(move || {
        let rest = &bytes[offset..];
        if rest.is_empty() {
            return None;
        }
        number += 1;
        let end = rest
            .iter()
            .position(|&b| b == b'\n' || b == b'\r')
            .unwrap_or(rest.len());
        let next = match (rest.get(end), rest.get(end + 1)) {
            (Some(b'\r'), Some(b'\n')) => end + 2,
            (Some(_), _) => end + 1,
            (None, _) => end,
        };
        offset += next;
        Some((number, &rest[..end], offset))
    })
}

/// The lines of `bytes` with their numbers (from 1), each without its end-of-line bytes and
/// without a `#` comment.
pub(crate) fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    raw_lines(bytes).map(|(number, line, _)| {
        let line = match line.iter().position(|&b| b == b'#') {
            Some(hash) => &line[..hash],
            None => line,
        };
        (number, line)
    })
}

/// The whitespace-separated tokens of a line.
pub(crate) fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

/// A token as text for messages (at most 40 characters, non-UTF-8 bytes replaced).
pub(crate) fn show(token: &[u8]) -> String {
    let text = String::from_utf8_lossy(token);
    match text.char_indices().nth(40) {
        Some((cut, _)) => format!("{}...", &text[..cut]),
        None => text.into_owned(),
    }
}

/// A number as C and Fortran write it: `1`, `-.5`, `1e-3`, `1.0D+00`, `+2.`, `nan`, `inf`.
pub(crate) fn number(token: &[u8]) -> Result<f32, Syntax> {
    let bad = || Syntax::Number(show(token));
    let text = std::str::from_utf8(token).map_err(|_| bad())?;
    text.parse::<f32>().or_else(|_| {
        if text.contains(['d', 'D']) {
            text.replace(['d', 'D'], "e")
                .parse::<f32>()
                .map_err(|_| bad())
        } else {
            Err(bad())
        }
    })
}

/// A whole number, for counts and indices.
pub(crate) fn integer(token: &[u8]) -> Result<i64, Syntax> {
    std::str::from_utf8(token)
        .ok()
        .and_then(|t| t.strip_prefix('+').unwrap_or(t).parse::<i64>().ok())
        .ok_or_else(|| Syntax::Number(show(token)))
}

/// The first `N` tokens of `tokens` as numbers, or an error at `line`.
pub(crate) fn numbers<'a, const N: usize>(
    tokens: &mut impl Iterator<Item = &'a [u8]>,
    line: usize,
) -> Result<[f32; N], ReadError> {
    let mut out = [0.0; N];
    for (k, slot) in out.iter_mut().enumerate() {
        let token = tokens.next().ok_or(ReadError::at(
            Place::Line(line),
            Syntax::TooFewValues {
                needed: N,
                found: k,
            },
        ))?;
        *slot = number(token).map_err(|s| ReadError::at(Place::Line(line), s))?;
    }
    Ok(out)
}

/// A colour channel: a byte as written (0-255) or, written with a decimal point or exponent, a
/// fraction of 1.
pub(crate) fn channel(token: &[u8], value: f32) -> u8 {
    let fraction = token.iter().any(|b| matches!(b, b'.' | b'e' | b'E'));
    let scaled = if fraction { value * 255.0 } else { value };
    (scaled.clamp(0.0, 255.0) + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_line_ending_counts() {
        let text = b"a\nb\r\nc\rd # note \xe9\n\ne";
        let got: Vec<(usize, &[u8])> = lines(text).collect();
        assert_eq!(
            got,
            vec![
                (1, &b"a"[..]),
                (2, b"b"),
                (3, b"c"),
                (4, b"d "),
                (5, b""),
                (6, b"e")
            ]
        );
    }

    #[test]
    fn numbers_as_people_write_them() {
        for (text, value) in [
            ("1", 1.0),
            ("-.5", -0.5),
            ("+2.", 2.0),
            ("1e-3", 1e-3),
            ("1.0D+02", 100.0),
            ("1.55991e-008", 1.55991e-8),
        ] {
            assert_eq!(number(text.as_bytes()), Ok(value), "{text}");
        }
        assert!(number(b"nan").unwrap().is_nan());
        assert_eq!(number(b"1,5"), Err(Syntax::Number("1,5".into())));
        assert_eq!(integer(b"+7"), Ok(7));
        assert!(integer(b"7.0").is_err());
    }

    #[test]
    fn channels_are_bytes_or_fractions() {
        assert_eq!(channel(b"255", 255.0), 255);
        assert_eq!(channel(b"1.0", 1.0), 255);
        assert_eq!(channel(b"0.5", 0.5), 128);
        assert_eq!(channel(b"300", 300.0), 255);
    }
}
