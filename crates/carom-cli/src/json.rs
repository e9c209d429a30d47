//! JSON Lines output of `carom run`: one object per line, numbers in their shortest
//! round-trip form for the run's precision (`0.1` stays `0.1` in `f32`).

use std::fmt::Write as _;

use carom_math::{Real, Vector};

/// A float that writes itself in JSON: shortest round-trip digits, `null` for the
/// non-finite values JSON cannot hold (carom never produces them; `null` would show it).
pub(crate) trait JsonFloat: Real {
    fn write_json(self, out: &mut String);
}

impl JsonFloat for f64 {
    fn write_json(self, out: &mut String) {
        if self.is_finite() {
            out.push_str(ryu::Buffer::new().format_finite(self));
        } else {
            out.push_str("null");
        }
    }
}

impl JsonFloat for f32 {
    fn write_json(self, out: &mut String) {
        if self.is_finite() {
            out.push_str(ryu::Buffer::new().format_finite(self));
        } else {
            out.push_str("null");
        }
    }
}

/// `[x, y, ...]`.
pub(crate) fn vector<T: JsonFloat, const D: usize>(out: &mut String, v: &Vector<T, D>) {
    out.push('[');
    for (k, x) in v.iter().enumerate() {
        if k > 0 {
            out.push_str(", ");
        }
        x.write_json(out);
    }
    out.push(']');
}

/// `[[x, y], ...]`.
pub(crate) fn vectors<T: JsonFloat, const D: usize>(out: &mut String, vs: &[Vector<T, D>]) {
    out.push('[');
    for (k, v) in vs.iter().enumerate() {
        if k > 0 {
            out.push_str(", ");
        }
        vector(out, v);
    }
    out.push(']');
}

/// A JSON string literal.
pub(crate) fn string(out: &mut String, s: &str) {
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn floats_are_shortest_round_trip_in_their_precision() {
        let mut s = String::new();
        vector(&mut s, &Vector2::new(0.1_f32, -1e-30));
        assert_eq!(s, "[0.1, -1e-30]");
        let mut s = String::new();
        vector(&mut s, &Vector2::new(0.1_f64, 1.0));
        assert_eq!(s, "[0.1, 1.0]");
        let mut s = String::new();
        f64::NAN.write_json(&mut s);
        assert_eq!(s, "null");
    }

    #[test]
    fn strings_are_escaped() {
        let mut s = String::new();
        string(&mut s, "a\"b\\c\n");
        assert_eq!(s, r#""a\"b\\c\u000a""#);
    }
}
