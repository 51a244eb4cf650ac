//! Text encoding shared by the writers: numbers that read back exactly,
//! XML escaping, and the finiteness check.

use std::borrow::Cow;
use std::fmt::Write as _;

use crate::OutputError;

/// Appends `x` to `out` in the shortest form that parses back to the same
/// `f64`: plain decimals for moderate magnitudes, exponent form otherwise
/// (plain `Display` would print `1e-300` with three hundred digits).
///
/// The caller guarantees `x` is finite.
pub(crate) fn push_f64(out: &mut String, x: f64) {
    let a = x.abs();
    // Writing into a String cannot fail.
    let _ = if a == 0.0 || (1e-5..1e16).contains(&a) {
        write!(out, "{x}")
    } else {
        write!(out, "{x:e}")
    };
}

/// `x` formatted by [`push_f64`].
pub(crate) fn format_f64(x: f64) -> String {
    let mut s = String::new();
    push_f64(&mut s, x);
    s
}

/// Escapes the five XML special characters for use in an attribute value
/// or text node.
pub(crate) fn xml_escape(s: &str) -> Cow<'_, str> {
    if !s.contains(['&', '<', '>', '"', '\'']) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// Fails on the first non-finite entry of `data`, a flattened array of
/// `components` values per tuple, naming the array and the tuple index.
pub(crate) fn check_finite(name: &str, data: &[f64], components: usize) -> Result<(), OutputError> {
    match data.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(OutputError::NonFinite {
            array: name.to_owned(),
            index: i / components.max(1),
            value: data[i],
        }),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    #[test]
    fn numbers_round_trip_exactly() {
        for x in [
            0.0,
            -0.0,
            1.0,
            -2.5,
            0.1,
            1.0 / 3.0,
            1e-300,
            -4.9e-324,
            1e16,
            123_456_789.123,
            f64::MAX,
            f64::MIN_POSITIVE,
        ] {
            let s = format_f64(x);
            assert_eq!(
                s.parse::<f64>().unwrap().to_bits(),
                x.to_bits(),
                "{x} -> {s}"
            );
        }
        assert_eq!(format_f64(0.5), "0.5");
        assert_eq!(format_f64(1e-300), "1e-300");
    }

    #[test]
    fn xml_special_characters_are_escaped() {
        assert_eq!(xml_escape("plain"), "plain");
        assert_eq!(
            xml_escape(r#"a<b&"c">'"#),
            "a&lt;b&amp;&quot;c&quot;&gt;&apos;"
        );
    }

    #[test]
    fn non_finite_reports_tuple_index() {
        let data = [0.0, 1.0, 2.0, 3.0, f64::NAN, 5.0];
        match check_finite("v", &data, 3) {
            Err(OutputError::NonFinite {
                array,
                index,
                value,
            }) => {
                assert_eq!(array, "v");
                assert_eq!(index, 1);
                assert!(value.is_nan());
            }
            other => panic!("expected NonFinite, got {other:?}"),
        }
        assert!(check_finite("v", &data[..3], 3).is_ok());
    }
}
