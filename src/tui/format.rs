//! Number and text formatting for narrow columns. Every number on screen
//! goes through here: non-finite values print as `—`, never `NaN` or `inf`,
//! and the output is deterministic (fixed precision), so snapshots are stable.

/// What a non-finite number prints as.
pub const NOT_A_NUMBER: &str = "—";

/// `v` in at most `width` characters with as many significant digits as fit
/// (up to 4): fixed notation for moderate magnitudes, scientific otherwise.
/// Non-finite values give `—`. If nothing fits, the shortest form is
/// returned (the caller's column clips it).
pub fn num(v: f64, width: usize) -> String {
    if !v.is_finite() {
        return NOT_A_NUMBER.to_string();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let mag = v.abs().log10().floor() as i32;
    // Fixed notation while it keeps at least two significant digits.
    if (-3..6).contains(&mag) {
        let want = (3 - mag).clamp(0, 6);
        let least = (1 - mag).clamp(0, 6);
        for decimals in (least..=want).rev() {
            let s = tidy(format!("{v:.prec$}", prec = decimals as usize));
            if s.chars().count() <= width {
                return s;
            }
        }
    }
    let mut shortest = String::new();
    for digits in (0..=3).rev() {
        let s = tidy(format!("{v:.digits$e}"));
        if s.chars().count() <= width {
            return s;
        }
        shortest = s;
    }
    shortest
}

/// Control values below this fraction of their scale are round-off of the
/// solver's steps (a rotation axis that should stay 0 reads `2e-18`) and
/// print as `0`; the report and the saved file keep the exact value.
pub const CONTROL_RESOLUTION: f64 = 1e-12;

/// `v` with round-off below [`CONTROL_RESOLUTION`] of `scale` shown as 0.
pub fn resolved(v: f64, scale: f64) -> f64 {
    let unit = if scale.is_finite() && scale > 0.0 {
        scale
    } else {
        1.0
    };
    if v.abs() < CONTROL_RESOLUTION * unit {
        0.0
    } else {
        v
    }
}

/// Like [`num`] with an explicit `+` on positive values (for deltas).
pub fn signed(v: f64, width: usize) -> String {
    if v.is_finite() && v > 0.0 {
        let s = num(v, width.saturating_sub(1));
        if s != "0" {
            return format!("+{s}");
        }
        return s;
    }
    num(v, width)
}

/// Drop trailing zeros of the fraction (`1.500` → `1.5`, `1.000e-5` →
/// `1e-5`) and the sign of a value that printed as zero.
fn tidy(s: String) -> String {
    let (mantissa, exponent) = match s.split_once('e') {
        Some((m, e)) => (m, Some(e)),
        None => (s.as_str(), None),
    };
    let mantissa = if mantissa.contains('.') {
        mantissa.trim_end_matches('0').trim_end_matches('.')
    } else {
        mantissa
    };
    let mantissa = match mantissa.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0') => rest,
        _ => mantissa,
    };
    match exponent {
        Some(e) => format!("{mantissa}e{e}"),
        None => mantissa.to_string(),
    }
}

/// `s` with every word that spells a non-finite number (`NaN`, `inf`,
/// `infinity`, any case) replaced by `—`: for labels the core formats
/// itself, such as the accuracy setting.
pub fn scrub(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        let bad = ["nan", "inf", "infinity"]
            .iter()
            .any(|b| word.eq_ignore_ascii_case(b));
        out.push_str(if bad { NOT_A_NUMBER } else { word });
        word.clear();
    };
    for c in s.chars() {
        if c.is_alphanumeric() {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            out.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

/// Milliseconds, compactly: `0.42`, `12.3`, `1530`.
pub fn ms(v: f64) -> String {
    num(v, 5)
}

/// `s` cut to `width` characters, ending in `…` when cut.
pub fn truncate(s: &str, width: usize) -> String {
    if s.chars().count() <= width {
        return s.to_string();
    }
    if width == 0 {
        return String::new();
    }
    let mut out: String = s.chars().take(width - 1).collect();
    out.push('…');
    out
}

/// `s` padded with spaces (or cut) to exactly `width` characters, left aligned.
pub fn pad_left_aligned(s: &str, width: usize) -> String {
    let s = truncate(s, width);
    let n = s.chars().count();
    format!("{s}{}", " ".repeat(width - n))
}

/// `s` padded with spaces (or cut) to exactly `width` characters, right aligned.
pub fn pad_right_aligned(s: &str, width: usize) -> String {
    let s = truncate(s, width);
    let n = s.chars().count();
    format!("{}{s}", " ".repeat(width - n))
}

/// Short names of control-name segments, used when a full name does not fit.
const SHORT: &[(&str, &str)] = &[
    ("position", "pos"),
    ("orientation", "rot"),
    ("velocity", "vel"),
    ("angular_velocity", "ω"),
    ("mass", "m"),
    ("inertia", "I"),
    ("normal", "n"),
    ("restitution", "e"),
];

/// `name` within `width` characters: as is; else the body, a space and
/// the short quantity (`egg1.velocity.x` → `egg1 vel.x`, `plank ω.y`);
/// else with the body cut so the quantity stays whole.
pub fn short_control_name(name: &str, width: usize) -> String {
    if name.chars().count() <= width {
        return name.to_string();
    }
    let parts: Vec<&str> = name.split('.').collect();
    let short: Vec<&str> = parts
        .iter()
        .map(|p| {
            SHORT
                .iter()
                .find(|(long, _)| long == p)
                .map_or(*p, |(_, s)| *s)
        })
        .collect();
    if short.len() < 2 {
        return truncate(name, width);
    }
    let (body, quantity) = (short[0], short[1..].join("."));
    let joined = format!("{body} {quantity}");
    if joined.chars().count() <= width {
        return joined;
    }
    // Cut the body so the quantity and component stay.
    let room = width.saturating_sub(quantity.chars().count() + 1);
    if room >= 2 {
        format!("{} {quantity}", truncate(body, room))
    } else {
        truncate(&joined, width)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_is_a_dash() {
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(num(v, 8), "—");
            assert_eq!(signed(v, 8), "—");
        }
    }

    #[test]
    fn round_off_relative_to_the_scale_reads_zero() {
        assert_eq!(resolved(2e-18, 1.0), 0.0);
        assert_eq!(resolved(-5e-17, 1.0), 0.0);
        assert_eq!(resolved(3e-12, 1.0), 3e-12);
        // A smaller scale resolves smaller values.
        assert_eq!(resolved(2e-15, 1e-3), 2e-15);
        assert_eq!(resolved(2e-16, 1e-3), 0.0);
        // A scale that is not a positive number counts as 1.
        assert_eq!(resolved(1e-13, f64::NAN), 0.0);
        assert_eq!(resolved(1e-13, 0.0), 0.0);
        assert!(resolved(f64::NAN, 1.0).is_nan());
    }

    #[test]
    fn keeps_four_significant_digits_when_room() {
        assert_eq!(num(1.23456, 8), "1.235");
        assert_eq!(num(-12.3456, 8), "-12.35");
        assert_eq!(num(0.0123456, 8), "0.01235");
        assert_eq!(num(12345.6, 8), "12346");
        assert_eq!(num(0.0, 3), "0");
        assert_eq!(num(1.5, 8), "1.5");
        assert_eq!(num(999.99, 5), "1000");
    }

    #[test]
    fn falls_back_to_scientific_in_narrow_columns() {
        assert_eq!(num(0.000012346, 8), "1.235e-5");
        assert_eq!(num(0.000012346, 6), "1.2e-5");
        assert_eq!(num(-0.000012346, 6), "-1e-5");
        assert_eq!(num(1e300, 6), "1e300");
        assert_eq!(num(1e-300, 4), "1e-300");
        assert_eq!(num(123456789.0, 6), "1.23e8");
        assert_eq!(num(-0.0123456, 6), "-0.012");
    }

    #[test]
    fn every_output_fits_or_is_the_shortest() {
        let values = [
            1.0, -1.0, 1e-30, -1e-30, 1e30, 0.5, 999.99, 99999.9, 1e5, 1.5e-3, 9.9999e-4, -7.77e-7,
        ];
        for v in values {
            for w in 6..12 {
                let s = num(v, w);
                assert!(s.chars().count() <= w, "{v} in {w}: {s}");
                let back: f64 = s.parse().expect("parses back");
                assert!((back - v).abs() <= v.abs() * 0.5, "{v} in {w}: {s}");
            }
        }
    }

    #[test]
    fn no_negative_zero() {
        assert_eq!(num(-0.0000001, 6), "-1e-7");
        assert_eq!(num(-0.0, 6), "0");
        assert_eq!(tidy("-0.000".into()), "0");
        assert_eq!(tidy("-0e0".into()), "0e0");
    }

    #[test]
    fn scrub_replaces_non_finite_words_only() {
        assert_eq!(scrub("rk4 h=NaN"), "rk4 h=—");
        assert_eq!(scrub("dopri5 tol=inf, -Infinity"), "dopri5 tol=—, -—");
        assert_eq!(scrub("info nano t=1.250"), "info nano t=1.250");
    }

    #[test]
    fn deltas_carry_a_sign() {
        assert_eq!(signed(0.5, 6), "+0.5");
        assert_eq!(signed(-0.5, 6), "-0.5");
        assert_eq!(signed(0.0, 6), "0");
    }

    #[test]
    fn truncation_marks_the_cut() {
        assert_eq!(truncate("egg1.velocity", 6), "egg1.…");
        assert_eq!(truncate("egg", 6), "egg");
        assert_eq!(truncate("egg", 0), "");
        assert_eq!(pad_left_aligned("ab", 4), "ab  ");
        assert_eq!(pad_right_aligned("ab", 4), "  ab");
    }
}
