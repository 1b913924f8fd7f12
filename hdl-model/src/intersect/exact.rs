//! The compact datapath's shared exact edge unit (`rtl/exact_edge.v`): the pairs a lane's
//! coarse test cannot decide ([`super::coarse`]) have their undecided edges tested exactly,
//! d · e_k ≥ 0, with e_k = a_k × a_{k+1} formed again from the patch's corners as the set-up
//! pass forms it (the side's sign and the origin-wide truncation). The edge normals are not
//! stored: they would take as much block RAM as the lanes' words, and few pairs need them
//! (`hemi bench lanes`: 0.002 undecided edges a ray on the Cornell box, where a ray has 2.8
//! candidates; 0.022 on its 1,154-patch subdivision).
//!
//! **Its clocks.** One multiplier (34 × 64 bits, five clocks: operands, eight 18 × 18 tiles,
//! three levels of their sum) forms an edge's nine products in a nine-clock window of a grid
//! ([`Schedule`]): the cross product's six in the window's first six clocks, a component's two
//! on consecutive clocks, the dot product's three in the next window's last three, once each
//! component of the normal is through the difference with the side and the truncation's bias
//! (two clocks; its shift as the dot product takes it), summed as they come out. So edges follow
//! one another every nine clocks, a pair's after the last pair's, and a pair takes nine clocks
//! an edge. A pair is taken on the grid's [`GRID_START`] clock; its first edge's two corners are
//! read on the next two (a corner a clock, as the set-up units read them; each later edge's in
//! the window before it), each less the origin a clock later, and its first window begins eight
//! clocks after it was taken. Its verdict is out [`LATENCY`] clocks after the clock the next
//! pair could be taken. Until session 39 the model charged 5 clocks an edge and 2 for the first
//! reads, with the verdict at once: the RTL showed the multipliers' and the normal's clocks, and
//! the grid. Until session 43 two multipliers, a five-clock window: eight DSP tiles more for a
//! unit that sees 0.002 (Cornell box) to 0.022 (its 1,154-patch subdivision) undecided edges a
//! ray, while the default build's set-up units had their products in LUT arrays for want of
//! tiles (docs/PERFORMANCE.md, "Session 43").
//!
//! **The grid restarts when the unit is idle.** Kept from reset (session 39), a pair's wait
//! for the grid depended on every clock since reset, so the model's clock counts moved with the
//! number of engines the host split a run over. Now a unit with no edge in its windows holds
//! its grid on the clock that takes a pair, and a pair offered to an idle unit is taken at
//! once: the wait depends on the unit's own last pair alone.

/// Clocks an edge takes of the unit: a window of the grid, a product a clock.
pub const WINDOW: u64 = 9;

/// The clock of a window on which a pair may be taken, the clock before its first corner's
/// read (counted modulo [`WINDOW`] from the clock the unit last took a pair when idle, or from
/// reset): the first clock after reset an idle unit takes a pair on.
pub const GRID_START: u64 = 1;

/// Clocks from the clock the next pair could be taken to a pair's verdict. That clock is the
/// one after its last window's first; the dot product's last product is issued on that
/// window's eighteenth clock (the next window's ninth), takes five clocks of multiplier, then
/// its sum with the first two and its sign are registered, so the verdict register is read on
/// the last window's 24th clock (its 23rd after the window's first).
pub const LATENCY: u64 = 22;

/// Clocks from the clock the next pair could be taken to the first clock the unit is idle: its
/// last edge's cross products take one more window, their dot products the next.
pub const IDLE_AFTER: u64 = 2 * WINDOW;

/// Clocks of the unit for a pair with `edges` undecided edges.
pub fn pair_clocks(edges: u8) -> u64 {
    WINDOW * edges as u64
}

/// The unit's grid: when it takes its next pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Schedule {
    /// the clock the next pair could be taken (a clock of the grid)
    free: u64,
    /// the first clock of the idle unit, whose grid holds on the clock that takes a pair
    idle: u64,
}

impl Default for Schedule {
    /// As from reset: idle from the grid's first clock.
    fn default() -> Self {
        Schedule {
            free: GRID_START,
            idle: GRID_START,
        }
    }
}

impl Schedule {
    /// The clock a pair offered on `at` is taken: at once by an idle unit, else on the first
    /// clock of the grid at or after both `at` and the last pair's windows.
    pub fn begin(&self, at: u64) -> u64 {
        if at >= self.idle {
            return at;
        }
        let wait = at.saturating_sub(self.free);
        self.free + wait.div_ceil(WINDOW) * WINDOW
    }

    /// Takes a pair of `edges` undecided edges offered on `at`: the clock it is taken. A pair
    /// has an undecided edge, or the coarse test decided it (the RTL would fall idle a window
    /// early on an empty mask).
    pub fn take(&mut self, at: u64, edges: u8) -> u64 {
        debug_assert!(
            edges > 0,
            "a pair the exact unit is handed has an undecided edge"
        );
        let begin = self.begin(at);
        self.advance(begin, pair_clocks(edges));
        begin
    }

    /// Takes, from clock `begin` (of [`Schedule::begin`]), pairs whose windows take `clocks`.
    pub fn advance(&mut self, begin: u64, clocks: u64) {
        self.free = begin + clocks;
        self.idle = self.free + IDLE_AFTER;
    }

    /// The clock the next pair could be taken.
    pub fn free(&self) -> u64 {
        self.free
    }

    /// The clock of the last verdict.
    pub fn verdict(&self) -> u64 {
        self.free + LATENCY
    }
}

/// The edge normal of the edge from corner a_k to a_{k+1} (both v − O, 33-bit values) as the
/// set-up pass forms it: the cross product, its sign flipped when the origin is behind the
/// patch (`negate`), truncated towards zero by the origin-wide `shift` and kept to 64 bits (the
/// hardware's width; the model's and the RTL's products of it agree bit for bit).
pub fn edge_normal(u: &[i64; 3], v: &[i64; 3], negate: bool, shift: u32) -> [i64; 3] {
    let s: i128 = if negate { -1 } else { 1 };
    let cross = [
        u[1] as i128 * v[2] as i128 - u[2] as i128 * v[1] as i128,
        u[2] as i128 * v[0] as i128 - u[0] as i128 * v[2] as i128,
        u[0] as i128 * v[1] as i128 - u[1] as i128 * v[0] as i128,
    ];
    cross.map(|c| super::shift_toward_zero(c * s, shift) as i64)
}

/// Whether direction `d` (Q2.30 words) is on the inner side of edge normal `e`: d · e ≥ 0,
/// exactly (98 bits).
pub fn inside_edge(d: &[i32; 3], e: &[i64; 3]) -> bool {
    (0..3).map(|c| d[c] as i128 * e[c] as i128).sum::<i128>() >= 0
}

/// Whether `d` is inside every edge of `mask` (bit k the edge from corner k to the next) among
/// `sides`, edge k's normal being `normal(k)`: what the unit decides of a pair.
pub fn inside_masked(
    d: &[i32; 3],
    mask: u8,
    sides: usize,
    normal: impl Fn(usize) -> [i64; 3],
) -> bool {
    (0..sides)
        .filter(|k| mask >> k & 1 == 1)
        .all(|k| inside_edge(d, &normal(k)))
}

/// The exact unit's verdict on a pair from its corners (`a`, less the origin), the normals
/// formed as the unit forms them.
pub fn verdict(a: &[[i64; 3]], mask: u8, negate: bool, shift: u32, d: &[i32; 3]) -> bool {
    inside_masked(d, mask, a.len(), |k| {
        edge_normal(&a[k], &a[(k + 1) % a.len()], negate, shift)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pair_begins_on_the_grid_or_at_once() {
        let mut s = Schedule::default();
        // idle from reset: the grid's first clock, then any clock
        assert_eq!(s.begin(0), 1);
        assert_eq!(s.begin(7), 7);
        assert_eq!(s.take(7, 2), 7);
        // busy: back to back (two edges, two windows), or the grid's next clock
        assert_eq!(s.begin(9), 25);
        assert_eq!(s.begin(26), 34);
        assert_eq!(s.begin(35), 43);
        // idle two windows after the last pair's
        assert_eq!(s.begin(43), 43);
        assert_eq!(s.take(50, 1), 50);
        assert_eq!(s.verdict(), 59 + LATENCY);
    }

    #[test]
    fn shared_edges_hold_opposite_normals() {
        let (u, v) = (
            [5i64 << 30, -3 << 29, 7],
            [-(1i64 << 32), 9 << 28, -(5 << 31)],
        );
        for shift in 0..5 {
            for negate in [false, true] {
                let e = edge_normal(&u, &v, negate, shift);
                let back = edge_normal(&v, &u, negate, shift);
                assert_eq!(e.map(|c| c.wrapping_neg()), back);
            }
        }
    }
}
