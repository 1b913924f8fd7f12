//! Two patches with the same vertices facing the same way: the one coplanar overlap that can be
//! found exactly. A ray cannot tell such patches apart, so one of them would receive no light
//! (a quad repeated over the emitter left the emitter at 0). Partial overlaps are the user's to
//! avoid (docs/scene-format.md, "Coplanar overlaps").

use super::{ScenePatch, Shape};
use std::collections::hash_map::{Entry, HashMap};

/// The first patch that repeats an earlier one's vertices (in any order) and its facing, with
/// the earlier one: `(earlier, later)` indices.
pub fn first_duplicate(patches: &[ScenePatch]) -> Option<(usize, usize)> {
    let mut seen: HashMap<Vec<u32>, usize> = HashMap::new();
    for (i, p) in patches.iter().enumerate() {
        let Shape::Polygon(poly) = &p.shape else {
            continue;
        };
        let mut corners: Vec<[u32; 3]> = poly
            .vertices()
            .iter()
            .map(|v| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()])
            .collect();
        corners.sort_unstable();
        corners.dedup();
        let mut key: Vec<u32> = corners.into_iter().flatten().collect();
        // the facing: opposite windings of one quad are a two-sided wall, and allowed
        let n = poly.normal;
        key.extend([n.x > 0.0, n.y > 0.0, n.z > 0.0].map(u32::from));
        match seen.entry(key) {
            Entry::Occupied(earlier) => return Some((*earlier.get(), i)),
            Entry::Vacant(slot) => {
                slot.insert(i);
            }
        }
    }
    None
}
