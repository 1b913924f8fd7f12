//! A compact build's plane unit, one a ray group (`rtl/group_plane.v`): the lanes test edges
//! only, and hand it each (ray, slot) pair they find inside, with the slot's h from the lane's
//! word and the ray's tag. It reads the slot's unit normal n from the group's normal memory,
//! forms n · d, divides, t = h / (n · d) (paper §6.1), and keeps each ray's running minimum by
//! its tag, since the pairs of the rays in flight arrive interleaved. A ray's answer is read
//! out once its lanes are done: the nearest t, of equal t the lowest slot (the order of the
//! wide datapath's single scan), or none.
//!
//! **Its clocks.** A pair a clock: the normal's read ([`super::NORMAL_READ`]), the operands, the
//! twelve 18 × 18 tiles of the three products, each product's two halves, the products, two
//! levels of their sum ([`DOT_CLOCKS`] after the read), then the divider's
//! [`DIVIDER_CLOCKS`]; the minimum reads the tag's entry as t leaves the divider and writes it
//! two clocks later (the block RAM's read takes most of a clock, so it is registered before
//! the compare; placed without that register, the unit ran at 67 MHz). A ray's answer is asked
//! for at most once a clock, in ray order within the group, once its lanes are done
//! ([`readout`]); its entry is read [`T_LATENCY`] + 2 clocks later (after the last write of a
//! pair taken before the readout) and the answer is out two clocks after that
//! ([`ANSWER_LATENCY`]). Until session 40 the model charged a compact ray the wide datapath's
//! min tree over the lanes and its divider ([`super::DIV_LATENCY`], 34 clocks; the RTL
//! divider itself takes [`DIVIDER_CLOCKS`]) plus the normal's read, from the clock its lanes
//! were done, whatever the other rays of its group. A tag is reused once its ray's answer is
//! out (the RTL needs four clocks after the readout).

use super::{DivideStage, EdgeStage, LocalPatch};
use crate::format::{Coord64, PlaneDist, Unit};

/// Clocks from the normal's read to n · d at the divider's input: the operands registered, the
/// tiles, each product's two halves, the products, and the sum in two levels.
pub const DOT_CLOCKS: u64 = 6;

/// Clocks of the restoring divider (`rtl/plane_divider.v`): the signs and the range, then a
/// quotient bit a clock.
pub const DIVIDER_CLOCKS: u64 = 32;

/// Clocks from the clock a pair is taken to the clock its t leaves the divider.
pub const T_LATENCY: u64 = super::NORMAL_READ + DOT_CLOCKS + DIVIDER_CLOCKS;

/// Clocks from a ray's readout to its answer: the entry is read [`T_LATENCY`] + 2 clocks after
/// the readout (a pair taken the clock before it has its entry written by then: the minimum
/// reads the entry, registers it and writes it back over three clocks), then a clock of block
/// RAM and a clock to the answer's register.
pub const ANSWER_LATENCY: u64 = T_LATENCY + 4;

/// The clock a ray whose lanes are done on `finish` has its answer asked for, given the clock
/// its group's unit can take the next readout (`free`, advanced): in ray order, one a clock.
pub fn readout(free: &mut u64, finish: u64) -> u64 {
    let at = finish.max(*free);
    *free = at + 1;
    at
}

/// The t of a pair found inside, h / (n · d) as the unit forms it (Q8.24), or `None` where the
/// divider finds no hit (t ≤ 0, n · d = 0, out of range).
pub fn pair_t(h: PlaneDist, n: [Unit; 3], d: [Unit; 3]) -> Option<Coord64> {
    let lp = LocalPatch {
        n,
        h,
        active: true,
        ..LocalPatch::default()
    };
    DivideStage.eval(EdgeStage.decided(&d, &lp, true))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readouts_are_one_a_clock_in_order() {
        let mut free = 0;
        assert_eq!(readout(&mut free, 10), 10);
        assert_eq!(readout(&mut free, 10), 11);
        assert_eq!(readout(&mut free, 5), 12);
        assert_eq!(readout(&mut free, 20), 20);
    }

    #[test]
    fn t_is_h_over_n_dot_d() {
        let n = [Unit::ZERO, Unit::ZERO, Unit::ONE.wrapping_neg()];
        let d = [Unit::ZERO, Unit::ZERO, Unit::ONE.wrapping_neg()];
        let h = PlaneDist::from_num(3);
        assert_eq!(pair_t(h, n, d), Some(Coord64::from_num(3)));
        // behind the origin, parallel
        assert_eq!(pair_t(-h, n, d), None);
        assert_eq!(
            pair_t(h, n, [Unit::ZERO, Unit::ONE.wrapping_neg(), Unit::ZERO]),
            None
        );
    }
}
