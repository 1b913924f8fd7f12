//! Runtime SIMD dispatch for the host's hot loops: the same scalar Rust, compiled once for the
//! baseline and once for each wider instruction set, and run as the widest one the CPU has.
//!
//! The release build targets baseline x86-64 (SSE2) so that one binary runs everywhere; the
//! ring scan (`soft::scan_in_lanes`) tests groups of eight rays, branch-free so that they
//! vectorise: with AVX2 or AVX-512 a group is one instruction a step instead of two. (Groups
//! of sixteen, which AVX-512 could take at once, measured slower: most runs are a few rays.)
//! pulp's `Arch` detects the extensions once and calls the closure through a
//! `#[target_feature]` copy of it; the arithmetic is the same IEEE operations in the same order
//! (Rust never contracts `a * b + c` into a fused multiply-add by itself), so every width gives
//! the same bits. Without the kernel's `std` feature (the firmware) the closure runs as
//! compiled.
//!
//! A loop to dispatch is a [`SimdLoop`]: a struct holding what the loop works on, whose `run`
//! is `#[inline(always)]` so that its body is compiled into each `#[target_feature]` copy (a
//! closure would be called, not inlined, and keep the baseline).
//!
//! ```
//! use hemi_kernel::accel::simd::{SimdLoop, Vectorizer};
//! struct Double<'a>(&'a mut [f32]);
//! impl SimdLoop for Double<'_> {
//!     type Output = ();
//!     #[inline(always)]
//!     fn run(self) {
//!         self.0.iter_mut().for_each(|x| *x *= 2.0);
//!     }
//! }
//! let mut xs = [1.0f32, 2.0, 3.0];
//! Vectorizer::detect().run(Double(&mut xs));
//! assert_eq!(xs, [2.0, 4.0, 6.0]);
//! ```

use core::fmt;

/// The instruction set a host's hot loops run with, detected once.
#[derive(Clone, Copy)]
pub struct Vectorizer {
    #[cfg(feature = "std")]
    arch: pulp::Arch,
}

impl Vectorizer {
    /// Detects what this CPU can run (pulp's `Arch::new`: AVX-512 or AVX2 on x86-64, NEON on
    /// aarch64, else the baseline).
    pub fn detect() -> Vectorizer {
        Vectorizer {
            #[cfg(feature = "std")]
            arch: pulp::Arch::new(),
        }
    }

    /// Runs `job` compiled for the detected instruction set.
    #[inline(always)]
    pub fn run<L: SimdLoop>(self, job: L) -> L::Output {
        #[cfg(feature = "std")]
        {
            self.arch.dispatch(Dispatched(job))
        }
        #[cfg(not(feature = "std"))]
        {
            job.run()
        }
    }
}

/// A loop [`Vectorizer::run`] compiles once per instruction set. Implement `run` with
/// `#[inline(always)]`, and mark what it calls so too where the SIMD should reach.
pub trait SimdLoop {
    /// What the loop returns.
    type Output;
    /// The loop.
    fn run(self) -> Self::Output;
}

/// pulp's view of a [`SimdLoop`].
#[cfg(feature = "std")]
struct Dispatched<L>(L);

#[cfg(feature = "std")]
impl<L: SimdLoop> pulp::WithSimd for Dispatched<L> {
    type Output = L::Output;
    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> L::Output {
        self.0.run()
    }
}

impl fmt::Debug for Vectorizer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Vectorizer")
    }
}
