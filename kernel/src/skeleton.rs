//! The skeleton stack of paper §6.2: the frustums still to be shot for one primary ray.
//!
//! Every primary ray (a hemisphere ray in pass 1, an eye ray in pass 2) that reaches a specular
//! surface may grow a tree of frustums. The paper walks it by backtracking: the frustum axes
//! (the rays of largest contribution) are followed first and stored as the tree's *skeleton*;
//! then the last frustum on the stack is shot, any of its rays may store a deeper frustum, and
//! so on back up until every frustum of the primary ray is shot.
//!
//! hemi keeps the stack and the depth-first order but shoots a frustum whole, as one batch
//! through the engine's ring path (see [`crate::specular::Walker::follow`]): frames waiting on
//! the stack are frustums not yet shot, the newest (deepest) on top, and a frame is popped
//! when it is shot. The sums are the paper's, since every frustum ray is shot exactly once
//! whatever the order; only which branch a full stack cuts depends on it.
//! A frame stores what §6.2 lists: the axis' origin and direction (as the rotation that turns
//! the hemisphere onto it) and the frustum size, with the weight it carries.
//!
//! The stack lives in caller storage of fixed size (static SRAM in the firmware). When it is
//! full the deeper branch is cut: the frame is not pushed and its weight is counted as lost,
//! never a panic.

use crate::geometry::Vec3;
use crate::optics::Lobe;
use crate::rotation::Rotation;

/// One frustum waiting on the skeleton stack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// Where the frustum's rays start (the hit on the specular patch).
    pub origin: Vec3,
    /// The rotation that turns the hemisphere's +z onto the frustum axis.
    pub rot: Rotation,
    /// Rays must leave towards this side (d · side > 0): the reflecting side for k_r, the far side
    /// for k_t. A ray of a wide lobe that would go through the surface is absorbed.
    pub side: Vec3,
    /// The patch the frustum starts on, which its own rays do not hit.
    pub from: u32,
    /// The frustum's rings and weights.
    pub lobe: Lobe,
    /// Weight per channel carried into the frustum: the primary ray's weight times every k and
    /// frustum weight on the way.
    pub weight: [f32; 3],
    /// Bounces so far (1 for a frustum spawned by the primary ray).
    pub depth: u16,
}

impl Frame {
    /// An empty frame (storage filler).
    pub const EMPTY: Frame = Frame {
        origin: Vec3::ZERO,
        rot: Rotation::IDENTITY,
        side: Vec3::Z,
        from: u32::MAX,
        lobe: Lobe { first: 0, size: 0 },
        weight: [0.0; 3],
        depth: 0,
    };
}

/// A bounded stack of [`Frame`]s over caller storage; remembers its high-water mark.
#[derive(Debug)]
pub struct Skeleton<'s> {
    frames: &'s mut [Frame],
    len: usize,
    high_water: usize,
}

impl<'s> Skeleton<'s> {
    /// An empty stack whose capacity is `storage.len()`.
    pub fn new(storage: &'s mut [Frame]) -> Self {
        Skeleton {
            frames: storage,
            len: 0,
            high_water: 0,
        }
    }
    /// How many frames fit.
    pub fn capacity(&self) -> usize {
        self.frames.len()
    }
    /// Frames on the stack now.
    pub fn len(&self) -> usize {
        self.len
    }
    /// Whether the stack is empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// The deepest the stack has been since it was made.
    pub fn high_water(&self) -> usize {
        self.high_water
    }
    /// Pushes `frame`, or hands it back when the stack is full.
    pub fn push(&mut self, frame: Frame) -> Result<(), Frame> {
        match self.frames.get_mut(self.len) {
            Some(slot) => {
                *slot = frame;
                self.len += 1;
                self.high_water = self.high_water.max(self.len);
                Ok(())
            }
            None => Err(frame),
        }
    }
    /// The frame on top.
    pub fn top_mut(&mut self) -> Option<&mut Frame> {
        self.len.checked_sub(1).and_then(|i| self.frames.get_mut(i))
    }
    /// Drops the frame on top.
    pub fn pop(&mut self) {
        self.len = self.len.saturating_sub(1);
    }
    /// Empties the stack (keeps the high-water mark).
    pub fn clear(&mut self) {
        self.len = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounded_and_remembers_its_depth() {
        let mut store = [Frame::EMPTY; 3];
        let mut s = Skeleton::new(&mut store);
        for d in 0..3 {
            let f = Frame {
                depth: d,
                ..Frame::EMPTY
            };
            assert!(s.push(f).is_ok());
        }
        let over = Frame {
            depth: 9,
            ..Frame::EMPTY
        };
        assert_eq!(s.push(over), Err(over));
        assert_eq!(s.top_mut().map(|f| f.depth), Some(2));
        s.pop();
        s.pop();
        assert_eq!(s.len(), 1);
        s.pop();
        s.pop();
        assert!(s.is_empty() && s.top_mut().is_none());
        assert_eq!(s.high_water(), 3);
    }

    #[test]
    fn a_frame_is_small_enough_for_sram() {
        // docs/PERFORMANCE.md: the default 64-frame stack in firmware SRAM
        let size = core::mem::size_of::<Frame>();
        std::println!("Frame: {size} bytes, 64 frames: {} bytes", 64 * size);
        assert!(size <= 72, "{size}");
    }
}
