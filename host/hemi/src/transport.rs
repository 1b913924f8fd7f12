//! The element transport, recorded once: what each element's hemisphere gathers from each
//! vertex of the radiosity grids.
//!
//! A gather sweep of the element field ([`crate::field`]) sums, over the rays of an element's
//! hemisphere, `w_k · B_side(u_k, v_k)`, and `B(u, v)` is bilinear in the four vertices around
//! the hit ([`crate::grid::Cuts::blend`]). So the sum is linear in the vertex values,
//!
//! ```text
//!     H_e = Σ_k w_k Σ_corners c_k,v B_v = Σ_v T_ev B_v,    T_ev = Σ_k w_k c_k,v,
//! ```
//!
//! and the rays decide only T: the same for every sweep. Casting the hemispheres once and
//! keeping T's row per element (the vertices it sees, a few thousand at most, however many
//! rays) turns each sweep from a pass of rays into a sparse product, so the sweeps can run to
//! convergence for less than one pass of rays costs. T needs memory in proportion to elements
//! times the vertices each sees; [`Layout`] numbers the vertices and the field falls back to
//! re-casting when T would not fit its budget.

use crate::grid::{Cuts, Grid};

/// Every vertex of every patch grid, numbered: patch `side`'s (K+1)² vertices from
/// `first[side]`, v-major as [`Grid::vertex`].
#[derive(Clone, Debug)]
pub struct Layout {
    first: Vec<u32>,
    k: Vec<usize>,
    /// Each grid's lines not to blend across.
    cuts: Vec<Cuts>,
    len: usize,
}

impl Layout {
    /// The layout of `grids` (one per scene patch), or an error if it has more vertices than
    /// 32-bit indices number.
    pub fn of(grids: &[Grid]) -> anyhow::Result<Layout> {
        let (mut first, mut k, mut len) = (Vec::new(), Vec::new(), 0usize);
        let cuts = grids.iter().map(|g| g.cuts().clone()).collect();
        for g in grids {
            first.push(u32::try_from(len)?);
            k.push(g.k());
            len += (g.k() + 1) * (g.k() + 1);
        }
        anyhow::ensure!(
            u32::try_from(len).is_ok(),
            "{len} grid vertices: more than the element transport numbers"
        );
        Ok(Layout {
            first,
            k,
            cuts,
            len,
        })
    }

    /// Vertices in all.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Adds what one ray gathers, weight `w` on side `side` at (u, v), to `row`; a side the
    /// layout does not know is an error.
    pub fn add(
        &self,
        row: &mut Accumulator,
        side: usize,
        (u, v): (f32, f32),
        w: [f32; 3],
    ) -> anyhow::Result<()> {
        let (Some(&first), Some(&k)) = (self.first.get(side), self.k.get(side)) else {
            anyhow::bail!("a backend reported a hit on unknown patch {side}");
        };
        for ((i, j), c) in self.cuts[side].blend(k, u, v) {
            let vertex = first + (j * (k + 1) + i) as u32;
            row.add(vertex, w, c);
        }
        Ok(())
    }

    /// The vertex values of `grids` in this layout's order.
    pub fn values(&self, grids: &[Grid]) -> Vec<[f64; 3]> {
        let mut out = Vec::with_capacity(self.len);
        for (g, &k) in grids.iter().zip(&self.k) {
            for j in 0..=k {
                for i in 0..=k {
                    out.push(g.vertex(i, j));
                }
            }
        }
        out
    }
}

/// One element's row of T while its rays come in: dense over the layout (so adding is one
/// index), with the vertices touched listed so that taking the row costs only them.
///
/// Rows are grey (one weight for all channels) unless a ray came through a coloured specular
/// surface (a mirror or a sheet of glass), so the accumulator keeps one weight a vertex until
/// the first ray whose channels differ and only then moves to three: a ray then adds to four
/// numbers instead of twelve, in the same order and with the same roundings, so the row's bits
/// are those of adding per channel.
#[derive(Clone, Debug)]
pub struct Accumulator {
    grey: Vec<f32>,
    tinted: Vec<[f32; 3]>,
    is_tinted: bool,
    touched: Vec<u32>,
}

impl Accumulator {
    /// An empty row over `vertices` vertices.
    pub fn new(vertices: usize) -> Accumulator {
        Accumulator {
            grey: vec![0.0; vertices],
            tinted: Vec::new(),
            is_tinted: false,
            touched: Vec::new(),
        }
    }

    fn add(&mut self, vertex: u32, w: [f32; 3], c: f64) {
        if !self.is_tinted && w[0] == w[1] && w[1] == w[2] {
            let d = &mut self.grey[vertex as usize];
            if *d == 0.0 {
                self.touched.push(vertex);
            }
            *d += (w[0] as f64 * c) as f32;
            return;
        }
        if !self.is_tinted {
            self.switch_to_tinted();
        }
        let d = &mut self.tinted[vertex as usize];
        if *d == [0.0; 3] {
            self.touched.push(vertex);
        }
        for ch in 0..3 {
            d[ch] += (w[ch] as f64 * c) as f32;
        }
    }

    /// Moves the grey weights gathered so far to three channels, for a ray whose differ.
    fn switch_to_tinted(&mut self) {
        if self.tinted.len() != self.grey.len() {
            self.tinted = vec![[0.0; 3]; self.grey.len()];
        }
        for &v in &self.touched {
            // a vertex is listed again when a zero weight came first: only its first listing
            // moves its weight, and the others must not overwrite it with the zero left behind
            let g = std::mem::take(&mut self.grey[v as usize]);
            if g != 0.0 {
                self.tinted[v as usize] = [g; 3];
            }
        }
        self.is_tinted = true;
    }

    /// The row gathered so far, vertices in ascending order, and the accumulator emptied.
    pub fn take(&mut self, blocked: f32) -> TransportRow {
        self.touched.sort_unstable();
        self.touched.dedup();
        // sized for the touched vertices: the records are what bounds the field's element
        // count, and a collect through a filter would grow by doubling
        let n = self.touched.len();
        let weights = match self.is_tinted {
            false => {
                let mut grey = Vec::with_capacity(n);
                for v in self.touched.drain(..) {
                    let w = std::mem::take(&mut self.grey[v as usize]);
                    if w != 0.0 {
                        grey.push((v, w));
                    }
                }
                Weights::Grey(grey)
            }
            true => {
                let mut entries = Vec::with_capacity(n);
                for v in self.touched.drain(..) {
                    let w = std::mem::take(&mut self.tinted[v as usize]);
                    if w != [0.0; 3] {
                        entries.push((v, w));
                    }
                }
                self.is_tinted = false;
                match entries.iter().all(|(_, w)| w[0] == w[1] && w[1] == w[2]) {
                    true => Weights::Grey(entries.iter().map(|&(v, w)| (v, w[0])).collect()),
                    false => Weights::Tinted(entries),
                }
            }
        };
        TransportRow { weights, blocked }
    }
}

/// One element's row of T.
#[derive(Clone, Debug, PartialEq)]
pub struct TransportRow {
    weights: Weights,
    /// The fraction of the element's rays that met the back of an opaque patch first
    /// ([`crate::backend::Gathered::blocked`]).
    pub blocked: f32,
}

/// A row's (vertex, weight) entries, vertices ascending: one weight for all channels unless a
/// coloured specular surface on some ray's way made them differ, which halves the memory of
/// the common row (the record is what bounds the field's element count, `--field-mib`).
#[derive(Clone, Debug, PartialEq)]
enum Weights {
    Grey(Vec<(u32, f32)>),
    Tinted(Vec<(u32, [f32; 3])>),
}

impl TransportRow {
    /// `H = Σ_v T_v B_v` per channel over the vertex values `vertices` ([`Layout::values`]).
    pub fn gather(&self, vertices: &[[f64; 3]]) -> [f64; 3] {
        let mut h = [0.0f64; 3];
        match &self.weights {
            Weights::Grey(entries) => {
                for &(v, w) in entries {
                    let b = vertices[v as usize];
                    for c in 0..3 {
                        h[c] += w as f64 * b[c];
                    }
                }
            }
            Weights::Tinted(entries) => {
                for &(v, w) in entries {
                    let b = vertices[v as usize];
                    for c in 0..3 {
                        h[c] += w[c] as f64 * b[c];
                    }
                }
            }
        }
        h
    }

    /// The vertices the row has weights on, ascending.
    pub fn vertices(&self) -> Vec<u32> {
        match &self.weights {
            Weights::Grey(e) => e.iter().map(|&(v, _)| v).collect(),
            Weights::Tinted(e) => e.iter().map(|&(v, _)| v).collect(),
        }
    }

    /// The memory the row holds.
    pub fn bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + match &self.weights {
                Weights::Grey(e) => e.capacity() * std::mem::size_of::<(u32, f32)>(),
                Weights::Tinted(e) => e.capacity() * std::mem::size_of::<(u32, [f32; 3])>(),
            }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2×2 grid whose channels vary differently.
    fn coloured_2x2() -> Grid {
        Grid::from_samples(
            2,
            &[
                [1.0, 2.0, 3.0],
                [2.0, 1.0, 0.5],
                [0.0, 4.0, 1.0],
                [3.0, 3.0, 3.0],
            ],
        )
    }

    #[test]
    fn a_recorded_row_gathers_what_the_grids_interpolate() {
        // two grids, rays at a few (u, v): Σ w·B(u,v) read off the grids equals the row's
        // product with the vertex values
        let a = coloured_2x2();
        let b = Grid::from_samples(1, &[[0.25, 0.5, 0.75]]);
        let grids = [a, b];
        let layout = Layout::of(&grids).unwrap();
        assert_eq!(layout.len(), 9 + 4);
        let rays = [
            (0, (0.1, 0.9), [0.5, 0.5, 0.5]),
            (0, (0.6, 0.2), [0.25, 0.5, 1.0]),
            (1, (0.3, 0.3), [1.0, 1.0, 1.0]),
            (0, (0.1, 0.9), [0.5, 0.5, 0.5]),
        ];
        let mut acc = Accumulator::new(layout.len());
        let mut want = [0.0f64; 3];
        for &(side, uv, w) in &rays {
            layout.add(&mut acc, side, uv, w).unwrap();
            let b = grids[side].at(uv.0, uv.1);
            for c in 0..3 {
                want[c] += w[c] as f64 * b[c];
            }
        }
        let row = acc.take(0.0);
        assert!(row.vertices().windows(2).all(|w| w[0] < w[1]));
        assert!(
            matches!(row.weights, Weights::Tinted(_)),
            "the rays' weights differ by channel"
        );
        let got = row.gather(&layout.values(&grids));
        assert!(
            (0..3).all(|c| (got[c] - want[c]).abs() < 1e-6),
            "{got:?} vs {want:?}"
        );
        // the accumulator is empty again
        assert!(acc.take(0.0).vertices().is_empty());
        // grey rays make a grey row, which gathers the same
        for &(side, uv, _) in &rays {
            layout.add(&mut acc, side, uv, [0.5; 3]).unwrap();
        }
        let grey = acc.take(0.0);
        assert!(matches!(grey.weights, Weights::Grey(_)));
        let h = grey.gather(&layout.values(&grids));
        assert!(h[0] > 0.0 && h[0] != h[1]);
        assert!(layout.add(&mut acc, 2, (0.5, 0.5), [1.0; 3]).is_err());
    }

    #[test]
    fn a_tinted_ray_after_zero_weights_keeps_every_grey_weight() {
        // a hit on a grid line gives two of its corners weight 0, which lists them before any
        // weight arrives; a later grey ray lists them again, and the switch to three channels
        // for a tinted ray must move their weight once, not overwrite it with the zero
        let grid = coloured_2x2();
        let grids = [grid];
        let layout = Layout::of(&grids).unwrap();
        let rays = [
            ((0.5, 0.25), [0.5; 3]),
            ((0.75, 0.25), [0.25; 3]),
            ((0.6, 0.4), [1.0, 0.5, 0.25]),
        ];
        let mut acc = Accumulator::new(layout.len());
        let mut want = [0.0f64; 3];
        for &(uv, w) in &rays {
            layout.add(&mut acc, 0, uv, w).unwrap();
            let b = grids[0].at(uv.0, uv.1);
            for c in 0..3 {
                want[c] += w[c] as f64 * b[c];
            }
        }
        let got = acc.take(0.0).gather(&layout.values(&grids));
        assert!(
            (0..3).all(|c| (got[c] - want[c]).abs() < 1e-6),
            "{got:?} vs {want:?}"
        );
    }
}
