//! Patch form factors F_ij stored as sparse rows.
//!
//! One hemisphere of M rays reaches at most M patches, and in a room full of small patches it
//! reaches far fewer than the P of the scene, so a row of F holds what its patch's hemispheres
//! saw: column indices and values, sorted by column. A dense P × P matrix of f64 per channel was
//! 24·P² bytes (2.4 GB at 10⁴ patches, 60 GB at 5·10⁴); this grows with the non-zeros (12 bytes
//! each). The values stay f64: they are (4.3)'s sums, the very bits the dense matrix held, so
//! every pinned result and the boards' bit-for-bit agreement carry over unchanged.
//!
//! A row reads as its dense self where the code wants that (`row[j]`, `row.iter()` over all P
//! columns, the zeros included), and as its non-zeros where speed matters ([`Row::entries`]):
//! the solvers sweep non-zeros only.

use std::ops::Index;

/// F as sparse rows: `P` rows of `P` columns.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FormMatrix {
    rows: Vec<Row>,
}

/// One row of a [`FormMatrix`]: its non-zero columns, ascending, and their values.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Row {
    len: usize,
    cols: Vec<u32>,
    vals: Vec<f64>,
}

/// The zero that `row[j]` answers for a column the row does not hold.
static ZERO: f64 = 0.0;

impl Row {
    /// A row of `len` columns from its entries (`(column, value)`, any order, each column at
    /// most once, every column below `len`).
    pub fn from_entries(len: usize, mut entries: Vec<(u32, f64)>) -> Row {
        entries.sort_unstable_by_key(|e| e.0);
        debug_assert!(entries.windows(2).all(|w| w[0].0 < w[1].0));
        debug_assert!(entries.last().is_none_or(|e| (e.0 as usize) < len));
        let (cols, vals) = entries.into_iter().unzip();
        Row { len, cols, vals }
    }

    /// A row from its dense values, keeping the non-zeros.
    pub fn from_dense(dense: &[f64]) -> Row {
        let entries = dense
            .iter()
            .enumerate()
            .filter(|(_, v)| **v != 0.0)
            .map(|(j, v)| (j as u32, *v))
            .collect();
        Row::from_entries(dense.len(), entries)
    }

    /// Columns (P).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the row has no columns.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The non-zero entries, `(j, F_ij)` by ascending j.
    pub fn entries(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.cols
            .iter()
            .map(|&j| j as usize)
            .zip(self.vals.iter().copied())
    }

    /// Non-zero entries held.
    pub fn nonzeros(&self) -> usize {
        self.cols.len()
    }

    /// Every column's value in order, zeros included (P values): the dense view.
    pub fn iter(&self) -> impl Iterator<Item = f64> + '_ {
        let mut next = self.entries().peekable();
        (0..self.len).map(move |j| match next.peek() {
            Some(&(c, v)) if c == j => {
                next.next();
                v
            }
            _ => 0.0,
        })
    }

    /// Σ_j F_ij.
    pub fn sum(&self) -> f64 {
        self.vals.iter().sum()
    }

    /// The same row with every value mapped by `f` (zeros stay zero, not stored).
    pub fn map(&self, f: impl Fn(f64) -> f64) -> Row {
        Row {
            len: self.len,
            cols: self.cols.clone(),
            vals: self.vals.iter().map(|v| f(*v)).collect(),
        }
    }

    /// `a·self + b·other` over the union of their columns (the same length).
    pub fn combine(&self, a: f64, other: &Row, b: f64) -> Row {
        let mut entries: Vec<(u32, f64)> = Vec::with_capacity(self.nonzeros() + other.nonzeros());
        let (mut x, mut y) = (self.entries().peekable(), other.entries().peekable());
        loop {
            let e = match (x.peek().copied(), y.peek().copied()) {
                (Some((i, u)), Some((j, w))) if i == j => {
                    x.next();
                    y.next();
                    (i, a * u + b * w)
                }
                (Some((i, u)), Some((j, _))) if i < j => {
                    x.next();
                    (i, a * u)
                }
                (Some((i, u)), None) => {
                    x.next();
                    (i, a * u)
                }
                (_, Some((j, w))) => {
                    y.next();
                    (j, b * w)
                }
                (None, None) => break,
            };
            entries.push((e.0 as u32, e.1));
        }
        Row::from_entries(self.len, entries)
    }

    /// Bytes this row holds (its entries).
    pub fn bytes(&self) -> usize {
        self.cols.len() * (4 + 8)
    }
}

impl Index<usize> for Row {
    type Output = f64;
    /// F_ij, zero where the row holds nothing.
    fn index(&self, j: usize) -> &f64 {
        assert!(j < self.len, "column {j} of a row of {}", self.len);
        match self.cols.binary_search(&(j as u32)) {
            Ok(k) => &self.vals[k],
            Err(_) => &ZERO,
        }
    }
}

impl<'a> IntoIterator for &'a Row {
    type Item = f64;
    type IntoIter = Box<dyn Iterator<Item = f64> + 'a>;
    fn into_iter(self) -> Self::IntoIter {
        Box::new(self.iter())
    }
}

impl FormMatrix {
    /// `n` rows of `n` zeros.
    pub fn zeros(n: usize) -> FormMatrix {
        FormMatrix {
            rows: vec![
                Row {
                    len: n,
                    ..Row::default()
                };
                n
            ],
        }
    }

    /// The matrix of these rows (each as long as there are rows).
    pub fn from_rows(rows: Vec<Row>) -> FormMatrix {
        debug_assert!(rows.iter().all(|r| r.len == rows.len()));
        FormMatrix { rows }
    }

    /// Rows (P).
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether there are no patches.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The rows in order.
    pub fn iter(&self) -> std::slice::Iter<'_, Row> {
        self.rows.iter()
    }

    /// Replaces row `i`.
    pub fn set_row(&mut self, i: usize, row: Row) {
        self.rows[i] = row;
    }

    /// Non-zero entries held.
    pub fn nonzeros(&self) -> usize {
        self.rows.iter().map(Row::nonzeros).sum()
    }

    /// Bytes the entries take.
    pub fn bytes(&self) -> usize {
        self.rows.iter().map(Row::bytes).sum()
    }

    /// The dense matrix (tests, small scenes, the dense LU).
    pub fn to_dense(&self) -> Vec<Vec<f64>> {
        self.rows.iter().map(|r| r.iter().collect()).collect()
    }

    /// Column `j` as (i, F_ij) over the rows that hold it: one pass over every entry.
    pub fn column(&self, j: usize) -> Vec<(usize, f64)> {
        self.rows
            .iter()
            .enumerate()
            .filter_map(|(i, r)| {
                r.cols
                    .binary_search(&(j as u32))
                    .ok()
                    .map(|k| (i, r.vals[k]))
            })
            .collect()
    }

    /// The transpose, so columns can be read as rows (progressive refinement shoots columns).
    pub fn transpose(&self) -> FormMatrix {
        let n = self.len();
        let mut entries: Vec<Vec<(u32, f64)>> = vec![Vec::new(); n];
        for (i, r) in self.rows.iter().enumerate() {
            for (j, v) in r.entries() {
                entries[j].push((i as u32, v));
            }
        }
        FormMatrix {
            rows: entries
                .into_iter()
                .map(|e| Row::from_entries(n, e))
                .collect(),
        }
    }
}

impl Index<usize> for FormMatrix {
    type Output = Row;
    fn index(&self, i: usize) -> &Row {
        &self.rows[i]
    }
}

impl<'a> IntoIterator for &'a FormMatrix {
    type Item = &'a Row;
    type IntoIter = std::slice::Iter<'a, Row>;
    fn into_iter(self) -> Self::IntoIter {
        self.rows.iter()
    }
}

impl From<Vec<Vec<f64>>> for FormMatrix {
    /// The sparse form of a dense matrix (square).
    fn from(dense: Vec<Vec<f64>>) -> FormMatrix {
        FormMatrix::from(&dense[..])
    }
}

impl From<&[Vec<f64>]> for FormMatrix {
    fn from(dense: &[Vec<f64>]) -> FormMatrix {
        FormMatrix {
            rows: dense.iter().map(|r| Row::from_dense(r)).collect(),
        }
    }
}

impl serde::Serialize for FormMatrix {
    /// Dense, as `[[F_00, F_01, …], …]`: the JSON of `hemi form-factors --json`, written row by
    /// row without forming the dense matrix.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.rows.iter())
    }
}

impl serde::Serialize for Row {
    /// Dense: every column's value, zeros included.
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_seq(self.iter())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_row_reads_as_its_dense_self() {
        let dense = vec![0.0, 0.25, 0.0, 0.5, 0.0];
        let r = Row::from_dense(&dense);
        assert_eq!(r.nonzeros(), 2);
        assert_eq!(r.iter().collect::<Vec<_>>(), dense);
        assert_eq!((0..5).map(|j| r[j]).collect::<Vec<_>>(), dense);
        assert_eq!(r.sum(), 0.75);
        assert_eq!(r.entries().collect::<Vec<_>>(), vec![(1, 0.25), (3, 0.5)]);
    }

    #[test]
    fn combine_and_transpose_agree_with_dense_arithmetic() {
        let a = vec![
            vec![0.0, 1.0, 2.0],
            vec![3.0, 0.0, 0.0],
            vec![0.0, 0.0, 4.0],
        ];
        let m = FormMatrix::from(a.clone());
        let t = m.transpose().to_dense();
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(t[i][j], a[j][i]);
            }
        }
        let c = m[0].combine(2.0, &m[1], 0.5).iter().collect::<Vec<_>>();
        assert_eq!(c, vec![1.5, 2.0, 4.0]);
        assert_eq!(m.column(2), vec![(0, 2.0), (2, 4.0)]);
    }
}
