//! Where a hemisphere's form factors are summed: an element row F_iq,j per diffuse column.
//!
//! A board sums into a dense row it sends whole (`jobs::shoot`). The host's scenes reach 10⁵
//! patches, where clearing and scanning a dense row of every column for each hemisphere costs
//! more than the rays: its row also notes the columns it touched. Both are the same sums in the
//! same order, so the bits do not depend on the row.
//!
//! ```
//! use hemi_kernel::form_row::FormRow;
//! let mut row = [[0.0f32; 3]; 4];
//! row[..].add(2, [0.5; 3]);
//! row[..].add(9, [1.0; 3]); // beyond the row: no column, ignored
//! assert_eq!(row[2], [0.5; 3]);
//! ```

/// A row of per-channel form factors, one entry per diffuse column.
pub trait FormRow {
    /// Adds `w` to column `column`; a column beyond the row is ignored.
    fn add(&mut self, column: usize, w: [f32; 3]);
}

impl FormRow for [[f32; 3]] {
    fn add(&mut self, column: usize, w: [f32; 3]) {
        if let Some(slot) = self.get_mut(column) {
            for (s, w) in slot.iter_mut().zip(w) {
                *s += w;
            }
        }
    }
}
