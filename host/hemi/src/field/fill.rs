//! The elements buried under other bodies, filled from their visible neighbours.

use crate::radiosity::ElementIndex;
use crate::scene::Scene;

/// Replaces the value of every buried element (see `BURIED` in the field) from its patch's
/// unburied neighbours (8-neighbourhood on the k×k lattice, [`fill_lattice`]), growing inwards
/// from the edge of the buried region until it is filled; a patch buried whole keeps its values.
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

/// One patch's k×k lattice: every `open` value (v-major) filled from its known 8-neighbours,
/// in rounds, until none is open or no round fills one. A neighbour with a known cell beyond
/// it in the same direction gives the linear extrapolation of the two, `2·v₁ − v₂` (at least
/// 0): the light falls towards a body's footprint (the contact shadow), and the vertices on the
/// footprint's edge, half from buried cells, carry that fall on to the edge. Where no direction
/// has two known cells, the mean of the known neighbours.
fn fill_lattice(k: usize, values: &mut [[f64; 3]], open: &mut [bool]) {
    if open.iter().all(|o| *o) {
        return;
    }
    let known = |open: &[bool], x: isize, y: isize| -> Option<usize> {
        let inside = x >= 0 && y >= 0 && x < k as isize && y < k as isize;
        let r = (y * k as isize + x) as usize;
        (inside && !open[r]).then_some(r)
    };
    while open.iter().any(|o| *o) {
        let mut filled = Vec::new();
        for q in (0..k * k).filter(|&q| open[q]) {
            let (a, b) = ((q % k) as isize, (q / k) as isize);
            // (sum, count) of the extrapolations, then of the plain neighbours
            let mut lines = ([0.0f64; 3], 0.0);
            let mut near = ([0.0f64; 3], 0.0);
            for (da, db) in (-1..=1).flat_map(|x| (-1..=1).map(move |y| (x, y))) {
                let Some(r1) = known(open, a + da, b + db) else {
                    continue;
                };
                let (guess, into) = match known(open, a + 2 * da, b + 2 * db) {
                    Some(r2) => (
                        [0, 1, 2].map(|c| (2.0 * values[r1][c] - values[r2][c]).max(0.0)),
                        &mut lines,
                    ),
                    None => (values[r1], &mut near),
                };
                for (s, g) in into.0.iter_mut().zip(guess) {
                    *s += g;
                }
                into.1 += 1.0;
            }
            let (sum, count) = if lines.1 > 0.0 { lines } else { near };
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_buried_edge_continues_the_fall_of_the_light_towards_it() {
        // 4×4, the light falling linearly towards the last column, which is buried
        let k = 4;
        let mut values: Vec<[f64; 3]> = (0..k * k).map(|q| [4.0 - (q % k) as f64; 3]).collect();
        let mut open: Vec<bool> = (0..k * k).map(|q| q % k == 3).collect();
        fill_lattice(k, &mut values, &mut open);
        for b in 0..k {
            assert!(
                (values[b * k + 3][0] - 1.0).abs() < 1e-12,
                "{:?}",
                values[b * k + 3]
            );
        }
        assert!(open.iter().all(|o| !o));
    }

    #[test]
    fn a_patch_buried_whole_keeps_its_values() {
        let mut values = vec![[0.5; 3]; 9];
        let mut open = vec![true; 9];
        fill_lattice(3, &mut values, &mut open);
        assert!(values.iter().all(|v| *v == [0.5; 3]));
    }
}
