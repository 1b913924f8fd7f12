//! A bounded FIFO (a ring of N registers with read and write pointers): the ray FIFO and the
//! result FIFO of the register file.

/// `i` (below 2N) wrapped into the ring by a compare, for any depth (the intersection unit's is
/// 1,023).
#[inline(always)]
fn wrap<const N: usize>(i: usize) -> usize {
    debug_assert!(i < 2 * N, "a ring index past its second turn");
    if i >= N {
        i - N
    } else {
        i
    }
}

/// Up to `N` entries.
#[derive(Clone, Debug)]
pub struct Fifo<T: Copy + Default, const N: usize> {
    buf: [T; N],
    head: usize,
    len: usize,
}

impl<T: Copy + Default, const N: usize> Default for Fifo<T, N> {
    fn default() -> Self {
        Fifo {
            buf: [T::default(); N],
            head: 0,
            len: 0,
        }
    }
}

impl<T: Copy + Default, const N: usize> Fifo<T, N> {
    /// Entries held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Whether full.
    pub fn is_full(&self) -> bool {
        self.len == N
    }

    /// Appends; `Err(v)` when full (the caller reports overflow).
    pub fn push(&mut self, v: T) -> Result<(), T> {
        if self.is_full() {
            return Err(v);
        }
        self.buf[wrap::<N>(self.head + self.len)] = v;
        self.len += 1;
        Ok(())
    }

    /// The oldest entry.
    pub fn front(&self) -> Option<&T> {
        (self.len > 0).then(|| &self.buf[self.head])
    }

    /// Removes the oldest entry.
    pub fn pop(&mut self) -> Option<T> {
        let v = *self.front()?;
        self.head = wrap::<N>(self.head + 1);
        self.len -= 1;
        Some(v)
    }

    /// The entries, oldest first.
    pub fn iter(&self) -> impl Iterator<Item = &T> + '_ {
        (0..self.len).map(move |i| &self.buf[wrap::<N>(self.head + i)])
    }

    /// Empties it.
    pub fn clear(&mut self) {
        self.len = 0;
        self.head = 0;
    }
}
