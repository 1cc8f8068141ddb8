//! Command-line values: each parser takes the text after an option and returns the value or a
//! message saying what was expected and what was found (clap names the option). An option
//! that takes a number accepts a leading hyphen (`allow_negative_numbers`, or
//! `allow_hyphen_values` for `WxH`), so that `-1` reaches its parser and is refused there
//! with the option named, not taken for an option of its own.

use std::ops::RangeInclusive;
use std::str::FromStr;

use vitreous_render::Reflection;

use vitreous_scene::effects::EffectSet;

/// `WIDTHxHEIGHT` (`1280x960`) in whole pixels.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT like 1280x960, got '{s}'"))?;
    let parse = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("expected WIDTHxHEIGHT with whole numbers, got '{s}'"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// A whole number of `unit` (`frames`; empty for a bare number) within `range`: below it, or
/// not a whole number, is refused saying what was expected; above it, saying it is too large
/// and what the most is.
pub fn whole_number(s: &str, range: RangeInclusive<u64>, unit: &str) -> Result<u64, String> {
    let text = s.trim();
    let (negative, digits) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text.strip_prefix('+').unwrap_or(text)),
    };
    let of = if unit.is_empty() {
        String::new()
    } else {
        format!(" of {unit}")
    };
    let (low, high) = (*range.start(), *range.end());
    let expected = if high == u64::MAX {
        format!("a whole number{of}, at least {low}")
    } else {
        format!("a whole number{of} from {low} to {high}")
    };
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!("expected {expected}, got '{s}'"));
    }
    if negative && digits.bytes().any(|b| b != b'0') {
        return Err(format!("expected {expected}, got {text}"));
    }
    match digits.parse::<u64>() {
        Ok(n) if range.contains(&n) => Ok(n),
        Ok(n) if n < low => Err(format!("expected {expected}, got {n}")),
        _ => Err(format!(
            "{} is too large: expected a whole number{of} from {low} to {high}",
            digits.trim_start_matches('0')
        )),
    }
}

/// A number (fractions allowed): what it may be is checked where it is used, which names the
/// option and its range.
pub fn number<T: FromStr>(s: &str) -> Result<T, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("expected a number, got '{s}'"))
}

/// A frame count for `--frames`: a whole number of at least 1 (0 would be an empty run).
pub fn parse_frame_count(s: &str) -> Result<u64, String> {
    whole_number(s, 1..=u64::MAX, "frames")
}

/// Which frames are saved, `--save-every K`: every K-th, 0 for none.
pub fn parse_save_every(s: &str) -> Result<u64, String> {
    whole_number(s, 0..=u64::MAX, "frames")
}

/// A random seed: any whole number from 0 to the largest 64-bit one.
pub fn parse_seed(s: &str) -> Result<u64, String> {
    whole_number(s, 0..=u64::MAX, "")
}

/// As [`parse_frame_count`], for counts held in `usize`.
pub fn parse_frame_count_usize(s: &str) -> Result<usize, String> {
    let n = parse_frame_count(s)?;
    usize::try_from(n).map_err(|_| format!("{n} frames is more than this machine can count"))
}

/// A pass count for `soak --passes`: at least the warm-up passes and the two compared after
/// them.
pub fn parse_pass_count(s: &str) -> Result<usize, String> {
    let least = vitreous_frames::soak::WARM_UP_PASSES + vitreous_frames::soak::COMPARED_PASSES;
    match s.trim().parse::<i128>() {
        Ok(n) if n >= least as i128 && n <= usize::MAX as i128 => Ok(n as usize),
        Ok(n) => Err(format!(
            "expected at least {least} passes ({} of warm-up, then {} compared), got {n}",
            vitreous_frames::soak::WARM_UP_PASSES,
            vitreous_frames::soak::COMPARED_PASSES
        )),
        Err(_) => Err(format!("expected a whole number of passes, got '{s}'")),
    }
}

/// A growth limit for `soak --max-growth`, percent: 0 or more.
pub fn parse_growth_percent(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(percent) if percent >= 0.0 && percent.is_finite() => Ok(percent),
        Ok(percent) => Err(format!(
            "expected a growth of 0 percent or more, got {percent}"
        )),
        Err(_) => Err(format!("expected a growth in percent, got '{s}'")),
    }
}

/// A pupil diameter for `--pupil-mm`, millimetres: 1 to 9 (the range eq. 13-14 accept),
/// refused here whether or not the run's effects use it.
pub fn parse_pupil_mm(s: &str) -> Result<f32, String> {
    let mm = s
        .trim()
        .parse::<f32>()
        .map_err(|_| format!("expected a pupil diameter in millimetres, got '{s}'"))?;
    vitreous_gaze::blur::check_pupil_diameter_m(mm / 1000.0)
        .map(|_| mm)
        .map_err(|e| e.to_string())
}

/// An angle kappa for `--kappa-deg`, degrees: -15 to 15 (measured adult values lie within
/// about -5 to 10: beyond 15 the number is more likely a typo than an eye).
pub fn parse_kappa_deg(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(deg) if (-15.0..=15.0).contains(&deg) => Ok(deg),
        Ok(deg) => Err(format!(
            "expected an angle kappa from -15 to 15 degrees, got {deg}"
        )),
        Err(_) => Err(format!("expected an angle kappa in degrees, got '{s}'")),
    }
}

/// An OpenXR environment blend mode by its command-line name.
pub fn parse_blend(s: &str) -> Result<vitreous_trace::Blend, String> {
    vitreous_trace::Blend::parse(s)
        .ok_or_else(|| format!("expected additive, alpha-blend or opaque, got '{s}'"))
}

/// A gaze source for `--gaze`: `auto`, `ml`, `fb`, `ext`, `trace` or `manual`.
pub fn parse_gaze(s: &str) -> Result<vitreous_xr::openxr::GazeChoice, String> {
    vitreous_xr::openxr::GazeChoice::parse(s)
        .ok_or_else(|| format!("expected auto, ml, fb, ext, trace or manual, got '{s}'"))
}

/// An effect set or condition (`O4`, `c`, `disparity,defocus`).
pub fn parse_effects(s: &str) -> Result<EffectSet, String> {
    EffectSet::parse(s).map_err(|e| e.to_string())
}

/// How the reflected image is drawn.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum ReflectionArg {
    /// Phong highlight of the scene's point light.
    Phong,
    /// Environment map in the mirror direction, weighted by the Fresnel term.
    Environment,
}

impl From<ReflectionArg> for Reflection {
    fn from(r: ReflectionArg) -> Reflection {
        match r {
            ReflectionArg::Phong => Reflection::Phong,
            ReflectionArg::Environment => Reflection::EnvironmentFresnel,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_counts_below_one_are_refused_with_the_reason() {
        assert_eq!(parse_frame_count("5"), Ok(5));
        assert!(parse_frame_count("0").unwrap_err().contains("at least 1"));
        assert!(parse_frame_count("-1").unwrap_err().contains("at least 1"));
        assert!(parse_frame_count("x").unwrap_err().contains("whole number"));
        assert!(parse_frame_count("-0").unwrap_err().contains("at least 1"));
        let large = parse_frame_count("99999999999999999999").unwrap_err();
        assert!(
            large.starts_with("99999999999999999999 is too large"),
            "{large}"
        );
        assert!(large.contains(&u64::MAX.to_string()), "{large}");
        assert_eq!(parse_frame_count(&u64::MAX.to_string()), Ok(u64::MAX));
    }

    #[test]
    fn whole_numbers_name_their_range_and_unit() {
        assert_eq!(whole_number("+7", 1..=10, "trials"), Ok(7));
        assert_eq!(
            whole_number("11", 1..=10, "trials"),
            Err("11 is too large: expected a whole number of trials from 1 to 10".into())
        );
        assert_eq!(
            whole_number("-3", 1..=10, "trials"),
            Err("expected a whole number of trials from 1 to 10, got -3".into())
        );
        assert_eq!(
            whole_number("2.5", 0..=u64::MAX, ""),
            Err("expected a whole number, at least 0, got '2.5'".into())
        );
        assert_eq!(parse_save_every("0"), Ok(0));
        assert_eq!(number::<f64>("-1.5"), Ok(-1.5));
        assert_eq!(
            number::<f32>("fast"),
            Err("expected a number, got 'fast'".into())
        );
    }

    #[test]
    fn kappa_angles_are_degrees_within_fifteen() {
        assert_eq!(parse_kappa_deg("5"), Ok(5.0));
        assert_eq!(parse_kappa_deg("-2.5"), Ok(-2.5));
        assert!(parse_kappa_deg("20").unwrap_err().contains("-15 to 15"));
        assert!(parse_kappa_deg("NaN").unwrap_err().contains("-15 to 15"));
        assert!(parse_kappa_deg("five").unwrap_err().contains("in degrees"));
    }

    #[test]
    fn sizes_are_width_x_height_in_whole_pixels() {
        assert_eq!(parse_size("1280x960"), Ok((1280, 960)));
        assert_eq!(parse_size("64X48"), Ok((64, 48)));
        assert!(parse_size("wide").unwrap_err().contains("WIDTHxHEIGHT"));
        assert!(parse_size("-1x5").is_err());
    }
}
