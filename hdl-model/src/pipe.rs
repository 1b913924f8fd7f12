//! Pipeline registers with a valid bit per stage.
//!
//! A pipeline of L stages is L registers; on each clock every valid register moves through the
//! next stage's combinational logic into the following register. [`Pipe::tick`] does exactly
//! that; [`Pipe::shift`] moves the registers and leaves the stage logic to be applied, in stage
//! order, as a value leaves the pipe, which gives the same values at the same clocks for pipes
//! whose stages depend only on their own register and never stall (the CORDIC pipes, the
//! rotator, the (u,v) pipe), at a cost per clock that does not grow with the valid stages:
//! simulation speed is a requirement (≥ 20 M cycles/s, `docs/PERFORMANCE.md`).

/// The default register count of a [`Pipe`]: the longest single pipe (CORDIC: 30 iterations +
/// quadrant + gain). The rotator's chain of three pipes names its own.
pub const MAX_STAGES: usize = 34;

/// L pipeline registers holding `S`, with their valid bits.
///
/// The registers are kept as a ring: register k is `regs[(base + k) % len]`, and a clock moves
/// `base` back by one instead of copying every register into the next. Each stage's logic
/// updates its register in place, so a clock touches only the fields a stage changes.
#[derive(Clone, Debug)]
pub struct Pipe<S: Copy + Default, const N: usize = MAX_STAGES> {
    regs: [S; N],
    valid: u128,
    /// the valid bits of `len` registers
    mask: u128,
    len: usize,
    base: usize,
}

impl<S: Copy + Default, const N: usize> Pipe<S, N> {
    /// An empty pipe of `len` stages (1..=N, N ≤ 128).
    pub fn new(len: usize) -> Self {
        assert!(N <= 128 && (1..=N).contains(&len), "pipe length {len}");
        Pipe {
            regs: [S::default(); N],
            valid: 0,
            mask: u128::MAX >> (128 - len),
            len,
            base: 0,
        }
    }

    /// Number of stages (the latency in clocks from `tick` input to output).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no stage holds data.
    pub fn is_empty(&self) -> bool {
        self.valid == 0
    }

    /// Number of valid stages.
    pub fn occupancy(&self) -> u32 {
        self.valid.count_ones()
    }

    /// Drops everything in flight (reset).
    pub fn flush(&mut self) {
        self.valid = 0;
    }

    /// Loads register 0 after this clock's `tick(None, ..)` has moved its old content on: for
    /// a unit whose input is produced later in the same clock than the pipe's own update.
    pub fn load_first(&mut self, s: S) {
        debug_assert!(self.valid & 1 == 0, "register 0 still occupied");
        self.regs[self.base] = s;
        self.valid |= 1;
    }

    /// One clock. `input` is the value entering register 0 (already through stage 0's logic);
    /// `stage(k, s)` is the logic between register k and register k+1, applied in place to the
    /// content of register k (which then becomes register k+1). Returns what left the last
    /// register.
    #[inline]
    pub fn tick(&mut self, input: Option<S>, mut stage: impl FnMut(usize, &mut S)) -> Option<S> {
        let len = self.len;
        let last = len - 1;
        let phys = |base: usize, k: usize| {
            if base + k >= len {
                base + k - len
            } else {
                base + k
            }
        };
        let out = if self.valid & (1u128 << last) != 0 {
            Some(self.regs[phys(self.base, last)])
        } else {
            None
        };
        let mut moving = self.valid & !(1u128 << last);
        while moving != 0 {
            let k = moving.trailing_zeros() as usize;
            stage(k, &mut self.regs[phys(self.base, k)]);
            moving &= moving - 1;
        }
        // register k's content is register k+1's now; the last register's slot is register 0
        self.base = if self.base == 0 { last } else { self.base - 1 };
        self.valid = (self.valid << 1) & self.mask;
        if let Some(s) = input {
            self.regs[self.base] = s;
            self.valid |= 1;
        }
        out
    }
}

impl<S: Copy + Default, const N: usize> Pipe<S, N> {
    /// One clock of a pipe whose stage logic the owner applies at the output (see
    /// [`Pipe::tick`] for the eager form): every register moves on unchanged, `input` enters
    /// register 0, and what leaves the last register is returned, for the owner to put through
    /// the stages 0..len−1 in order.
    ///
    /// This is lazy evaluation, not a different circuit: a stage's logic depends only on its
    /// own register, nothing reads a register in between, and there are no stalls, so the value
    /// leaving the pipe and the clock it leaves on are those of the eager pipe. The cost of a
    /// clock no longer grows with the number of valid stages, which is what keeps the model
    /// fast (the CORDIC pipes and the (u,v) pipe hold a token for tens of clocks each).
    #[inline]
    pub fn shift(&mut self, input: Option<S>) -> Option<S> {
        let len = self.len;
        let last = len - 1;
        let out = if self.valid & (1u128 << last) != 0 {
            let k = self.base + last;
            Some(self.regs[if k >= len { k - len } else { k }])
        } else {
            None
        };
        self.base = if self.base == 0 { last } else { self.base - 1 };
        self.valid = (self.valid << 1) & self.mask;
        if let Some(s) = input {
            self.regs[self.base] = s;
            self.valid |= 1;
        }
        out
    }
}

/// A delay line of exactly `N` clocks (N ≤ 64) that does no work per stage (a ring of
/// registers with their valid bits): used where the model computes a multi-cycle unit in one
/// step and only its latency matters.
#[derive(Clone, Debug)]
pub struct Delay<S: Copy + Default, const N: usize> {
    regs: [S; N],
    /// valid bit of `regs[i]` is bit i
    valid: u64,
    head: usize,
}

impl<S: Copy + Default, const N: usize> Default for Delay<S, N> {
    fn default() -> Self {
        const { assert!(N >= 1 && N <= 64) };
        Delay {
            regs: [S::default(); N],
            valid: 0,
            head: 0,
        }
    }
}

impl<S: Copy + Default, const N: usize> Delay<S, N> {
    /// One clock: `input` enters, the value that entered N clocks ago leaves.
    #[inline]
    pub fn tick(&mut self, input: Option<S>) -> Option<S> {
        let bit = 1u64 << self.head;
        let out = (self.valid & bit != 0).then(|| self.regs[self.head]);
        match input {
            Some(s) => {
                self.regs[self.head] = s;
                self.valid |= bit;
            }
            None => self.valid &= !bit,
        }
        self.head = if self.head + 1 == N { 0 } else { self.head + 1 };
        out
    }

    /// Number of values in flight.
    pub fn occupancy(&self) -> u32 {
        self.valid.count_ones()
    }

    /// Drops everything in flight.
    pub fn flush(&mut self) {
        self.valid = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pipe_has_its_latency_and_throughput() {
        let mut p: Pipe<u32> = Pipe::new(5);
        let mut out = [None; 12];
        for (c, o) in out.iter_mut().enumerate() {
            let input = if c < 4 { Some(c as u32 * 10) } else { None };
            *o = p.tick(input, |k, s| *s += k as u32 + 1);
        }
        // entered at clock c, left at clock c + 5 having passed stages 1..=4 (sum 10)
        assert_eq!(&out[5..9], &[Some(10), Some(20), Some(30), Some(40)]);
        assert!(out[..5].iter().all(Option::is_none) && p.is_empty());
    }

    #[test]
    fn shift_then_stages_is_the_eager_pipe() {
        let mut eager: Pipe<u32> = Pipe::new(5);
        let mut lazy: Pipe<u32> = Pipe::new(5);
        for c in 0..40u32 {
            let input = (c % 3 != 1 && c < 30).then_some(c * 7);
            let a = eager.tick(input, |k, s| *s = s.wrapping_mul(3) ^ k as u32);
            let b = lazy.shift(input).map(|mut s| {
                for k in 0..4 {
                    s = s.wrapping_mul(3) ^ k;
                }
                s
            });
            assert_eq!(a, b, "clock {c}");
            assert_eq!(eager.occupancy(), lazy.occupancy());
        }
    }

    #[test]
    fn delay_has_its_latency() {
        let mut d: Delay<u8, 3> = Delay::default();
        let outs: [Option<u8>; 5] = core::array::from_fn(|c| d.tick(Some(c as u8)));
        assert_eq!(outs, [None, None, None, Some(0), Some(1)]);
        assert_eq!(d.occupancy(), 3);
    }
}
