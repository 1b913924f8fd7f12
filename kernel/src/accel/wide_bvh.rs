//! The [`Bvh`] collapsed to four children a node, for rays that walk it one by one.
//!
//! A binary tree visits about 25 nodes, two box tests each, for a ray across a room of
//! 5,000 patches; the walk, not the patches, was most of a ray's time. Collapsing every
//! node with its children's children into one node of four boxes halves the nodes a ray
//! visits, and the four boxes are tested side by side (four lanes of the same operations,
//! which the compiler turns into one SSE instruction each on baseline x86-64).
//!
//! **Same answers as the binary tree.** The boxes are the binary tree's (padded) boxes and a
//! child is entered while its entry distance is ≤ the best t, so every patch the binary walk
//! could report is still tested; the nearest hit, ties to the lowest id, does not depend on the
//! order in which patches are tested.

use super::bvh::{area, test_leaf, Bvh, Node, SlabRay, MAX_DEPTH};

/// Children a wide node holds.
pub const WIDTH: usize = 4;

/// `count` of a child slot that holds nothing.
const EMPTY: u32 = u32::MAX;

/// One node of four children, their boxes side by side (axis-major, a lane per child).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WideNode {
    min: [[f32; WIDTH]; 3],
    max: [[f32; WIDTH]; 3],
    /// An inner child's wide node, or a leaf child's first index into the leaf order.
    first: [u32; WIDTH],
    /// 0 for an inner child, the patch count of a leaf child, [`EMPTY`] for no child.
    count: [u32; WIDTH],
}

impl Default for WideNode {
    fn default() -> WideNode {
        WideNode {
            min: [[0.0; WIDTH]; 3],
            max: [[0.0; WIDTH]; 3],
            first: [0; WIDTH],
            count: [EMPTY; WIDTH],
        }
    }
}

/// Wide nodes a tree over `patches` patches may need (one per inner node of the binary tree
/// at most).
pub const fn nodes_for(patches: usize) -> usize {
    if patches == 0 {
        1
    } else {
        patches
    }
}

/// Why a tree could not be widened.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WidenError {
    /// `out` holds fewer than [`nodes_for`] nodes.
    StorageTooSmall,
}

/// Collapses `tree` into `out` (at least [`nodes_for`] its patch count) and returns the wide
/// nodes used; node 0 is the root.
pub fn widen(tree: &Bvh<'_>, out: &mut [WideNode]) -> Result<usize, WidenError> {
    let nodes = tree.nodes();
    if out.len() < nodes_for(tree.patch_count()) {
        return Err(WidenError::StorageTooSmall);
    }
    // (binary node, wide node to fill) still to do: at most three more a level
    let mut todo = [(0usize, 0usize); 3 * MAX_DEPTH + 8];
    let mut pending = 1;
    let mut used = 1;
    while pending > 0 {
        pending -= 1;
        let (binary, wide) = todo[pending];
        let (kids, len) = gather(nodes, binary);
        let mut node = WideNode::default();
        for (slot, &c) in kids[..len].iter().enumerate() {
            let Some(n) = nodes.get(c) else {
                continue;
            };
            for k in 0..3 {
                node.min[k][slot] = n.bounds.min[k];
                node.max[k][slot] = n.bounds.max[k];
            }
            if n.count > 0 {
                (node.first[slot], node.count[slot]) = (n.first, n.count);
                continue;
            }
            if used >= out.len() || pending >= todo.len() {
                return Err(WidenError::StorageTooSmall);
            }
            (node.first[slot], node.count[slot]) = (used as u32, 0);
            todo[pending] = (c, used);
            pending += 1;
            used += 1;
        }
        out[wide] = node;
    }
    Ok(used)
}

/// Up to four descendants of binary node `i` that cover it, and how many: its children, then
/// the largest inner one among them replaced by its own two, while there is room. A leaf is
/// its own single child.
fn gather(nodes: &[Node], i: usize) -> ([usize; WIDTH], usize) {
    let mut kids = [i; WIDTH];
    match nodes.get(i) {
        Some(n) if n.count == 0 => (kids[0], kids[1]) = (i + 1, n.first as usize),
        _ => return (kids, 1),
    }
    let mut len = 2;
    let inner = |c: usize| nodes.get(c).filter(|n| n.count == 0);
    while len < WIDTH {
        let largest = (0..len)
            .filter_map(|s| inner(kids[s]).map(|n| (s, area(&n.bounds))))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((s, _)) = largest else {
            break;
        };
        let c = kids[s];
        (kids[s], kids[len]) = (c + 1, nodes[c].first as usize);
        len += 1;
    }
    (kids, len)
}

impl WideNode {
    /// Each child's entry distance if the ray enters its box at or before `t_max` (the binary
    /// tree's slab test, four lanes at once), else infinity.
    #[inline(always)]
    fn enter(&self, ray: &SlabRay, t_max: f32) -> [f32; WIDTH] {
        let mut enter = [0.0f32; WIDTH];
        let mut exit = [t_max; WIDTH];
        let mut inside = [true; WIDTH];
        for k in 0..3 {
            let o = ray.origin[k];
            if ray.parallel[k] {
                for ((inside, lo), hi) in inside.iter_mut().zip(self.min[k]).zip(self.max[k]) {
                    *inside &= o >= lo && o <= hi;
                }
                continue;
            }
            let inv = ray.inv[k];
            for i in 0..WIDTH {
                let a = (self.min[k][i] - o) * inv;
                let c = (self.max[k][i] - o) * inv;
                let (a, c) = if a < c { (a, c) } else { (c, a) };
                // `f32::max`/`min` as one instruction each (their NaN handling cost a sixth
                // of a ray's time): the same values, since `enter` and `exit` are never NaN
                // and a NaN `a` or `c` leaves them as they were either way
                enter[i] = if a > enter[i] { a } else { enter[i] };
                exit[i] = if c < exit[i] { c } else { exit[i] };
            }
        }
        let mut out = [f32::INFINITY; WIDTH];
        for i in 0..WIDTH {
            if inside[i] && enter[i] <= exit[i] && self.count[i] != EMPTY {
                out[i] = enter[i];
            }
        }
        out
    }
}

/// [`Bvh::nearest`] over the wide nodes `wide` of `tree`.
pub(super) fn nearest<T: Copy>(
    tree: &Bvh<'_>,
    wide: &[WideNode],
    ray: &SlabRay,
    t_max: f32,
    mut test: impl FnMut(u32, f32) -> Option<(f32, T)>,
) -> Option<(f32, u32, T)> {
    let mut best: Option<(f32, u32, T)> = None;
    let mut best_t = t_max;
    // children still to visit, with their entry distances: (first, count, entry) as the
    // node's slots hold them
    let mut stack = [(0u32, 0u32, 0.0f32); (WIDTH - 1) * (MAX_DEPTH + 2) + 1];
    let mut top = 0usize;
    let mut cur = (0u32, 0u32, 0.0f32);
    loop {
        let (first, count, _) = cur;
        if count > 0 {
            test_leaf(tree.leaf(first, count), &mut test, &mut best, &mut best_t);
        } else if let Some(node) = wide.get(first as usize) {
            let t = node.enter(ray, best_t);
            // the entered children nearest first: the first is visited next, the rest wait
            let mut near = [(0u32, 0u32, 0.0f32); WIDTH];
            let mut m = 0;
            for (s, &ts) in t.iter().enumerate() {
                if ts < f32::INFINITY {
                    let mut at = m;
                    while at > 0 && near[at - 1].2 > ts {
                        near[at] = near[at - 1];
                        at -= 1;
                    }
                    near[at] = (node.first[s], node.count[s], ts);
                    m += 1;
                }
            }
            if m > 0 {
                for &child in near[1..m].iter().rev() {
                    if top < stack.len() {
                        stack[top] = child;
                        top += 1;
                    }
                }
                cur = near[0];
                continue;
            }
        }
        // the next waiting child still worth entering
        loop {
            if top == 0 {
                return best;
            }
            top -= 1;
            if stack[top].2 <= best_t {
                cur = stack[top];
                break;
            }
        }
    }
}
