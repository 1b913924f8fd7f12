//! The elements buried under other bodies, filled from their visible neighbours.

use crate::radiosity::ElementIndex;
use crate::scene::Scene;

/// Replaces the value of every buried element (see [`BURIED`]) by the mean of its patch's
/// unburied neighbours (8-neighbourhood on the k×k lattice), growing inwards from the edge of
/// the buried region until it is filled; a patch buried whole keeps its values.
pub fn fill_buried(scene: &Scene, index: &ElementIndex, values: &mut [[f64; 3]], buried: &[bool]) {
    for i in 0..scene.patches.len() {
        let range = index.range(i);
        if range.is_empty() {
            continue;
        }
        let k = (range.len() as f64).sqrt().round() as usize;
        let mut open: Vec<bool> = buried[range.clone()].to_vec();
        fill_lattice(k, &mut values[range], &mut open);
    }
}

/// One patch's k×k lattice: every `open` value (v-major) replaced by the mean of its known
/// 8-neighbours, in rounds, until none is open or no round fills one.
fn fill_lattice(k: usize, values: &mut [[f64; 3]], open: &mut [bool]) {
    if open.iter().all(|o| *o) {
        return;
    }
    while open.iter().any(|o| *o) {
        let mut filled = Vec::new();
        for q in (0..k * k).filter(|&q| open[q]) {
            let (a, b) = ((q % k) as isize, (q / k) as isize);
            let (mut sum, mut count) = ([0.0f64; 3], 0.0);
            for (da, db) in (-1..=1).flat_map(|x| (-1..=1).map(move |y| (x, y))) {
                let (x, y) = (a + da, b + db);
                if x < 0 || y < 0 || x >= k as isize || y >= k as isize {
                    continue;
                }
                let r = y as usize * k + x as usize;
                if !open[r] {
                    for c in 0..3 {
                        sum[c] += values[r][c];
                    }
                    count += 1.0;
                }
            }
            if count > 0.0 {
                filled.push((q, sum.map(|s| s / count)));
            }
        }
        if filled.is_empty() {
            return;
        }
        for (q, v) in filled {
            values[q] = v;
            open[q] = false;
        }
    }
}
