//! The benchmarks' random numbers: xorshift64, fixed seeds, so that every run of a benchmark
//! (and the tests that share its workloads) sees the same rays and configurations.

/// A xorshift64 generator (Marsaglia 2003).
#[derive(Clone, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// A generator from `seed` (not 0).
    pub fn new(seed: u64) -> XorShift {
        XorShift(seed.max(1))
    }
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 >> 11
    }
    /// The next number in [0, 1), with 53 bits.
    pub fn f64(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 53) as f64
    }
    /// The next number in [0, 1], rounded to f32.
    pub fn f32(&mut self) -> f32 {
        self.next() as f32 / (1u64 << 53) as f32
    }
}
