//! What numbers and names a scene may hold, decided where each enters (the TOML, an OBJ/MTL or
//! `.bpt` file): finite, inside f32's range, and far enough inside it that the kernel's f32
//! arithmetic keeps them apart.
//!
//! The kernel is f32 throughout, and it multiplies lengths: areas are squares, and the
//! point-to-point form factor divides by r⁴. With every coordinate within ±[`COORD_LIMIT`]
//! (1e9) and every patch at least [`MIN_SIZE`] (1e-9) across, fourth powers of lengths stay
//! within f32's normal numbers (1.2e-38 … 3.4e38), so no overflow or underflow is mistaken for a
//! degenerate patch. A patch must also be large against the spacing of f32 numbers where it
//! lies ([`RELATIVE_SIZE`]), or its vertices round onto each other.
//!
//! Text errors say what is wrong with the number (NaN, infinite, beyond f32, beyond the limit);
//! the caller adds the file, line and key.

use super::Scene;
use hemi_kernel::geometry::Vec3;

/// The largest coordinate magnitude a scene may use.
pub const COORD_LIMIT: f64 = 1e9;
/// The smallest size (bounding-box diagonal) a patch may have.
pub const MIN_SIZE: f64 = 1e-9;
/// The smallest size a patch may have against its largest coordinate magnitude: f32 numbers are
/// 1.2e-7 apart relative to their size, so this leaves a patch about ten of them across.
pub const RELATIVE_SIZE: f64 = 1e-6;
/// The largest emission component (W/m²), about 10⁴ times the sun's surface: radiosities are
/// sums of E × area over the scene and pass through f32 on their way to the pixels.
pub const EMISSION_LIMIT: f64 = 1e12;

/// How far from the scene's box, in scene sizes, a ray may start: beyond it the f32 spacing of
/// the origin's coordinates (1.2e-7 of their size) exceeds the scene's ray offset (1e-5 of its
/// size), and hits can no longer tell the surfaces apart (a ray from 1e12 away "hits" a floor
/// through its ceiling).
pub const REACH: f32 = 100.0;

/// The region points given to a scene (rays, queries) must lie in: its box, widened by
/// [`REACH`] times its size.
#[derive(Clone, Copy, Debug)]
pub struct Reach {
    lo: Vec3,
    hi: Vec3,
    margin: f32,
}

impl Reach {
    /// The reach of `scene`.
    pub fn of(scene: &Scene) -> Reach {
        let (lo, hi) = scene.bounding_box();
        let size = (hi - lo).length();
        // a flat or point-like scene still has the precision of its coordinates' size
        let far = [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z]
            .iter()
            .fold(0.0f32, |m, c| m.max(c.abs()));
        let scale = size.max(far * 1e-3).max(1e-6);
        Reach {
            lo,
            hi,
            margin: REACH * scale,
        }
    }
    /// Why `p` is too far away for f32, if it is.
    pub fn check(&self, p: Vec3) -> Option<String> {
        let out = (self.lo - p).max(p - self.hi).max(Vec3::ZERO).length();
        (out > self.margin).then(|| {
            format!(
                "the point ({}, {}, {}) is {:.3e} from the scene's box, beyond the {:.3e} ({REACH} \
                 scene sizes) within which f32 can tell its surfaces apart",
                p.x, p.y, p.z, out, self.margin
            )
        })
    }
}

/// Why `x` is not a number f32 can hold, if it is not.
pub fn not_f32(x: f64) -> Option<String> {
    if x.is_nan() {
        Some("is NaN".into())
    } else if x.is_infinite() {
        Some("is infinite".into())
    } else if x.abs() > f64::from(f32::MAX) {
        Some("is beyond f32's range (±3.4e38)".into())
    } else {
        None
    }
}

/// `x` as an error message shows it: in exponent form when large or small.
pub fn show(x: f64) -> String {
    if x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `x` as a scene coordinate, or why it cannot be one.
pub fn coordinate(x: f64) -> Result<f32, String> {
    if let Some(why) = not_f32(x) {
        return Err(format!("{} {why}", show(x)));
    }
    if x.abs() > COORD_LIMIT {
        return Err(format!(
            "{} is beyond the ±{COORD_LIMIT:e} coordinates hemi takes (its f32 geometry raises \
             lengths to the fourth power)",
            show(x)
        ));
    }
    Ok(x as f32)
}

/// Whether a patch `size` across, whose vertices reach `magnitude` from the origin, is too small
/// for f32; the reason if so.
pub fn too_small(size: f64, magnitude: f64) -> Option<String> {
    if size == 0.0 {
        Some("is degenerate: zero area (all its points coincide)".into())
    } else if size < MIN_SIZE {
        Some(format!(
            "is {size:.3e} across, below the {MIN_SIZE:e} hemi takes (its area and form factors \
             would underflow f32)"
        ))
    } else if size < RELATIVE_SIZE * magnitude {
        Some(format!(
            "is {size:.3e} across at {magnitude:.3e} from the origin: below a millionth of its \
             distance, where f32 cannot tell its vertices apart"
        ))
    } else {
        None
    }
}

/// Why `name` cannot name a patch or material given in a scene, if it cannot: names are printed
/// one to a line and in space-separated records (`hemi trace`), and `:` is kept for the names
/// hemi makes (`<name>:back`), so a user's name can never equal a generated one.
pub fn bad_name(name: &str) -> Option<String> {
    if name.is_empty() {
        return Some("is empty".into());
    }
    if let Some(c) = name
        .chars()
        .find(|c| c.is_whitespace() || c.is_control() || invisible(*c))
    {
        return Some(format!(
            "`{}` contains {:?}: names may not contain white space or control characters (they \
             are printed in line- and space-separated output)",
            name.escape_debug(),
            c
        ));
    }
    if name.contains(':') {
        return Some(format!(
            "`{name}` contains `:`, which is kept for the names hemi makes (`<name>:back`)"
        ));
    }
    None
}

/// Characters that print as nothing but move or join what is around them (zero-width spaces
/// and joiners, direction marks and overrides, the byte-order mark): a name holding one lines up
/// wrong and reads like another.
fn invisible(c: char) -> bool {
    matches!(c, '\u{200B}'..='\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2060}'..='\u{2064}' | '\u{FEFF}' | '\u{00AD}')
}

/// `name` (from an OBJ or MTL file) made a valid scene name: white space, control characters and
/// `:` become `_`, and an empty name becomes `_`.
pub fn safe_name(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_whitespace() || c.is_control() || c == ':' {
                '_'
            } else {
                c
            }
        })
        .collect();
    if s.is_empty() {
        "_".into()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_named_by_what_is_wrong() {
        assert_eq!(not_f32(f64::NAN).unwrap(), "is NaN");
        assert_eq!(show(1e39), "1e39");
        assert_eq!(show(0.25), "0.25");
        assert_eq!(not_f32(f64::NEG_INFINITY).unwrap(), "is infinite");
        assert!(not_f32(1e39).unwrap().contains("beyond f32's range"));
        assert!(coordinate(1e38)
            .unwrap_err()
            .starts_with("1e38 is beyond the ±1e9"));
        assert!(coordinate(1e39)
            .unwrap_err()
            .starts_with("1e39 is beyond f32's range"));
        assert_eq!(coordinate(-2.5), Ok(-2.5));
        assert!(too_small(1e-12, 1.0).unwrap().contains("underflow"));
        assert!(too_small(0.0, 1.0)
            .unwrap()
            .contains("degenerate: zero area"));
        assert!(too_small(1e-3, 1e4).unwrap().contains("millionth"));
        assert!(too_small(1.0, 1e4).is_none());
    }

    #[test]
    fn names_that_break_lines_or_look_generated_are_refused() {
        assert!(bad_name("floor:back").unwrap().contains("`:`"));
        assert!(bad_name("a b").unwrap().contains("white space"));
        assert!(bad_name("a\nb").unwrap().contains("\\n"));
        assert!(bad_name("").is_some());
        assert!(bad_name("teapot/3").is_none());
        assert_eq!(safe_name("my obj:1\n"), "my_obj_1_");
    }
}
