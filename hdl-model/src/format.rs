//! The fixed-point formats of the datapath and the one rule for word width.
//!
//! Every register of the CORDIC datapath is a 32-bit container whose binary point never moves;
//! the configured word width W (12..=32) keeps only the top W bits. Masking the low `32 − W` bits
//! after every add and shift is exactly what a W-bit datapath with the same binary point computes
//! (arithmetic shifts truncate towards −∞ in both), so one model covers every width at run time
//! instead of one monomorphised copy per width.

use fixed::types::extra::{LeEqU128, U24, U29, U30, U32, U54, U60};
use fixed::{FixedI128, FixedI32, FixedI64};

/// A component of a direction or of a CORDIC vector: Q2.30, range [−2, 2). Two integer bits hold
/// the CORDIC gain growth (|v|·K ≤ 1.65) of a unit vector.
pub type Unit = FixedI32<U30>;
/// An angle in radians: Q3.29, range [−4, 4), enough for ±π.
pub type Angle = FixedI32<U29>;
/// A scene coordinate after the driver's power-of-two normalisation: Q8.24. The loaded patches
/// fit in [−1, 1]; the range out to ±128 is for ray origins outside the scene (cameras).
pub type Coord = FixedI32<U24>;
/// A difference of two coordinates (33 bits significant), kept in 64; also a distance t or a
/// box corner in the Bezier unit's 64-bit registers.
pub type Coord64 = FixedI64<U24>;
/// A direction component, or a fraction of a Bezier leaf (s, r ∈ [0, 1]), in a 64-bit register:
/// Q.30.
pub type Unit64 = FixedI64<U30>;
/// A reciprocal 1/d of a direction component: Q32.32 (the slab test's multiplier).
pub type Recip = FixedI64<U32>;
/// A plane distance h = n · (v₀ − O): Q2.30 × Q8.24, so Q.54, exact in 128 bits.
pub type PlaneDist = FixedI128<U54>;
/// A ray's denominator n · d: Q2.30 × Q2.30, so Q.60, exact in 128 bits.
pub type PlaneDen = FixedI128<U60>;

/// The divider: n / d truncated towards zero, with `F` fraction bits. The numerator's bits are
/// shifted by F + frac(d) − frac(n), the one alignment the two formats call for, so no divider
/// writes its shift by hand. `None` for d = 0.
#[inline]
pub fn quotient<F: LeEqU128, N: LeEqU128, D: LeEqU128>(
    n: FixedI128<N>,
    d: FixedI128<D>,
) -> Option<FixedI128<F>> {
    let shift = F::U32 + D::U32 - N::U32;
    n.to_bits()
        .checked_shl(shift)
        .and_then(|bits| bits.checked_div(d.to_bits()))
        .map(FixedI128::from_bits)
}

/// The low-bit mask that reduces a 32-bit container to a `width`-bit word.
#[inline]
pub const fn width_mask(width: u32) -> i32 {
    if width >= 32 {
        -1
    } else {
        !((1i32 << (32 - width)) - 1)
    }
}

/// Rounds a Q0.62 ROM constant to a W-bit word with `frac` fraction bits in a container with
/// `container_frac` fraction bits (the ROM of a W-bit design is rounded, not truncated).
#[inline]
pub const fn rom_round(q62: u64, frac: u32, container_frac: u32) -> i32 {
    let shift = 62 - frac;
    let rounded = (q62 + (1u64 << (shift - 1))) >> shift;
    (rounded << (container_frac - frac)) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_keep_the_top_bits() {
        assert_eq!(width_mask(32), -1);
        assert_eq!(width_mask(16) as u32, 0xFFFF_0000);
        // atan(1) = 0.785398... in Q3.29 rounded to 16 bits (13 fraction bits)
        let v = rom_round(0x3243_f6a8_885a_3000, 13, 29);
        assert_eq!(v & !width_mask(16), 0);
        assert!(
            ((v as f64) / (1u64 << 29) as f64 - core::f64::consts::FRAC_PI_4).abs() < 1.0 / 8192.0
        );
    }
}
