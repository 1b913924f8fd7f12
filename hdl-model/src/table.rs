//! The model's large memories (patch memory, local memory, candidate bitmaps), sized by the build
//! parameters when the model is built.
//!
//! With the `alloc` feature (hosts) a table is allocated at its size, so a build of thousands of
//! patch slots costs its memory once, on the heap, and the model stays small enough to move. Without
//! it (the firmware, which has no allocator) a table is an array of `N` entries, the most the
//! static model holds, and a build asking for more gets `N` (reported in CAPS).

#[cfg(feature = "alloc")]
extern crate alloc;

/// A table of up to `len` entries of `T` (at most `N` without an allocator).
#[derive(Clone, Debug)]
pub struct Table<T: Copy, const N: usize> {
    #[cfg(feature = "alloc")]
    data: alloc::boxed::Box<[T]>,
    #[cfg(not(feature = "alloc"))]
    data: [T; N],
    len: usize,
}

impl<T: Copy, const N: usize> Table<T, N> {
    /// The most entries a table can have in this build.
    pub const fn max_len() -> usize {
        if cfg!(feature = "alloc") {
            usize::MAX
        } else {
            N
        }
    }

    /// `len` entries of `fill` (at most [`Table::max_len`]).
    pub fn new(fill: T, len: usize) -> Self {
        let len = len.min(Self::max_len());
        Table {
            #[cfg(feature = "alloc")]
            data: alloc::vec![fill; len].into_boxed_slice(),
            #[cfg(not(feature = "alloc"))]
            data: [fill; N],
            len,
        }
    }

    /// Entries.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether it has no entries.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl<T: Copy, const N: usize> core::ops::Deref for Table<T, N> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.data[..self.len]
    }
}

impl<T: Copy, const N: usize> core::ops::DerefMut for Table<T, N> {
    fn deref_mut(&mut self) -> &mut [T] {
        &mut self.data[..self.len]
    }
}
