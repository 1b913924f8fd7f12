//! The random numbers of hemi's benchmarks and tests: one xorshift64 generator (Marsaglia 2003),
//! always from a fixed seed, so that every run sees the same rays, configurations and faults.
//! (The kernel's own unit tests, which cannot depend on a host crate, keep a private one.)
//!
//! ```
//! use hemi_bench::rng::XorShift;
//! let mut a = XorShift::new(0x2545_f491_4f6c_dd1d);
//! let mut b = XorShift::new(0x2545_f491_4f6c_dd1d);
//! let x = a.f64();
//! assert!((0.0..1.0).contains(&x));
//! assert_eq!(x, b.f64(), "the same seed gives the same stream");
//! ```

/// A xorshift64 generator.
#[derive(Clone, Debug)]
pub struct XorShift(u64);

impl XorShift {
    /// A generator from `seed` (0, which xorshift cannot leave, is taken as 1). Give it a
    /// well-mixed 64-bit constant: from a small seed such as 1 the first few dozen numbers are
    /// tiny (xorshift only spreads the bits it has).
    pub fn new(seed: u64) -> XorShift {
        XorShift(seed.max(1))
    }

    /// The next 64 raw bits.
    pub fn bits(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// The next number in [0, 1), with 53 bits.
    pub fn f64(&mut self) -> f64 {
        (self.bits() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The next number in [0, 1], rounded to f32.
    pub fn f32(&mut self) -> f32 {
        (self.bits() >> 11) as f32 / (1u64 << 53) as f32
    }

    /// An f32 of any bit pattern: NaN, infinities and subnormals included (hostile input).
    pub fn any_f32(&mut self) -> f32 {
        f32::from_bits(self.bits() as u32)
    }

    /// True with probability `p`.
    pub fn chance(&mut self, p: f64) -> bool {
        self.f64() < p
    }
}
