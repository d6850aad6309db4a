//! The table as it is baked: one buffer of values in the table's own layout, filled row by row.
//!
//! A sweep's rows land straight in their cells of the one buffer ([`Assembly::put`]);
//! checkpoints and shard files are written from it, gathering each row's canonical values
//! again ([`Assembly::write_part`]), and at the end the symmetry copies are made in place and
//! the buffer becomes the [`clothbake_loader::Table`]'s values ([`Assembly::into_values`]). So
//! a bake holds its table once (12 bytes a cell, RGB f32; a spatial one 4 (3 + 2 K)), not
//! rows, then a table assembled from them, then the writer's copies (docs/reference/limits-output.md).
//!
//! The buffer covers a range of rows (all of them for a table, a shard's for a shard), in the
//! table's layout restricted to those rows: cell `c` of the range's `m` cells holds its RGB at
//! `3 c` and class `k`'s diffuse and specular at `3 m + 2 (k m + c)` (the layout of
//! [`clothbake_loader::spatial::value_index`]). A row is written once, by the worker that
//! evaluated it; a finished row never changes, so a checkpoint may gather the rows finished
//! when it starts while others are being written.

use crate::directions::row_cell;
use crate::shard::{write_rows, Kind, ShardId};
use crate::sweep::{Orbits, Row};
use clothbake_loader::spatial::value_index;
use clothbake_loader::{Metadata, TableError};
use std::ops::Range;
use std::path::Path;
use std::sync::Mutex;

/// The values of a range of rows of a bake, in the table's layout, and which rows are done.
pub struct Assembly {
    orbits: Orbits,
    rows: Range<usize>,
    state: Mutex<State>,
}

struct State {
    values: Vec<f32>,
    /// One flag per row of the range.
    done: Vec<bool>,
}

impl Assembly {
    /// An empty buffer for `rows` of a bake with these orbits (zeroed: the operating system
    /// maps its pages as the rows arrive).
    pub fn new(orbits: &Orbits, rows: Range<usize>) -> Assembly {
        assert!(rows.end <= orbits.rows(), "rows within the grid");
        let cells = rows.len() * orbits.cells_per_row();
        Assembly {
            orbits: orbits.clone(),
            state: Mutex::new(State {
                values: vec![0.0; cells * (3 + orbits.class_values())],
                done: vec![false; rows.len()],
            }),
            rows,
        }
    }

    /// The rows the buffer covers.
    pub fn rows(&self) -> Range<usize> {
        self.rows.clone()
    }

    /// Cells of the range.
    fn cells(&self) -> usize {
        self.rows.len() * self.orbits.cells_per_row()
    }

    /// Calls `f` with each canonical cell of `row`, in cell order, as an index among the
    /// range's cells (plain loops: an iterator chain cost a merge half its time).
    fn each_canonical_cell(&self, row: usize, mut f: impl FnMut(usize)) {
        let g = self.orbits.grid();
        let (_, pi) = row_cell(g, row);
        let (nto, npo) = (g.n_theta_o as usize, g.n_phi_o as usize);
        let first = (row - self.rows.start) * nto * npo;
        let columns: Vec<usize> = (0..npo)
            .filter(|&po| self.orbits.is_canonical(pi as usize, po))
            .collect();
        for to in 0..nto {
            for &po in &columns {
                f(first + to * npo + po);
            }
        }
    }

    /// Stores `row`'s canonical values (its [`Row`], [`Orbits::row_evaluations`] entries) in
    /// their cells and marks it done.
    pub fn put(&self, row: usize, vals: &[[f32; 3]]) {
        assert!(
            self.rows.contains(&row),
            "row {row} outside {:?}",
            self.rows
        );
        assert_eq!(
            vals.len(),
            self.orbits.row_evaluations(row),
            "row {row}'s length"
        );
        let (m, class_values) = (self.cells(), self.orbits.class_values());
        let lanes = self.orbits.lanes();
        let mut s = self.state.lock().expect("no panics while held");
        let mut entries = vals.chunks_exact(self.orbits.stride());
        let values = &mut s.values;
        self.each_canonical_cell(row, |c| {
            let v = entries.next().expect("one entry per canonical cell");
            values[3 * c..][..3].copy_from_slice(&v[0]);
            for (k, x) in v[1..].iter().flatten().take(class_values).enumerate() {
                values[value_index(3 + k, c, m, lanes)] = *x;
            }
        });
        s.done[row - self.rows.start] = true;
    }

    /// `row`'s [`Row`] as the sweep gave it (the classes' values three to an entry, the last
    /// padded with 0), or `None` while it is not done.
    pub fn row(&self, row: usize) -> Option<Row> {
        if !self.rows.contains(&row) {
            return None;
        }
        let (m, class_values) = (self.cells(), self.orbits.class_values());
        let lanes = self.orbits.lanes();
        let s = self.state.lock().expect("no panics while held");
        if !s.done[row - self.rows.start] {
            return None;
        }
        let mut out = Vec::with_capacity(self.orbits.row_evaluations(row));
        self.each_canonical_cell(row, |c| {
            out.push([s.values[3 * c], s.values[3 * c + 1], s.values[3 * c + 2]]);
            let mut class = (0..class_values).map(|k| s.values[value_index(3 + k, c, m, lanes)]);
            while let Some(a) = class.next() {
                let b = class.next().unwrap_or(0.0);
                let c = class.next().unwrap_or(0.0);
                out.push([a, b, c]);
            }
        });
        Some(out)
    }

    /// The rows done so far, in increasing order.
    pub fn done_rows(&self) -> Vec<usize> {
        let s = self.state.lock().expect("no panics while held");
        let start = self.rows.start;
        s.done
            .iter()
            .enumerate()
            .filter(|(_, d)| **d)
            .map(|(r, _)| start + r)
            .collect()
    }

    /// Writes the rows done so far as a shard or checkpoint file (see [`crate::shard`]),
    /// gathering one row at a time; returns the number of rows written.
    pub fn write_part(
        &self,
        path: &Path,
        kind: Kind,
        shard: Option<ShardId>,
        meta: &Metadata,
        overwrite: bool,
    ) -> Result<usize, TableError> {
        let rows = self.done_rows();
        let count: usize = rows.iter().map(|&r| self.orbits.row_evaluations(r)).sum();
        let chunks = rows.iter().map(|&r| self.row(r).expect("a done row"));
        let values = chunks.map(|row| row.into_flattened());
        write_rows(
            path,
            kind,
            shard,
            meta,
            &rows,
            3 * count as u64,
            values,
            overwrite,
        )?;
        Ok(rows.len())
    }

    /// The table's values (RGB interleaved, cell order, then a spatial table's classes): the
    /// buffer, with each non-canonical cell given its representative's value, which may lie in
    /// another row. Every row of the grid must be done.
    pub fn into_values(self) -> Vec<f32> {
        assert_eq!(self.rows, 0..self.orbits.rows(), "the whole grid");
        let state = self.state.into_inner().expect("no panics while held");
        assert!(state.done.iter().all(|d| *d), "every row done");
        let mut values = state.values;
        let o = &self.orbits;
        let g = *o.grid();
        for ti in 0..g.n_theta_i {
            for pi in 0..g.n_phi_i {
                for po in 0..g.n_phi_o {
                    let (ri, ro) = o.rep(pi as usize, po as usize);
                    if (ri, ro) == (pi as usize, po as usize) {
                        continue;
                    }
                    for to in 0..g.n_theta_o {
                        let src = 3 * g.index(ti, ri as u32, to, ro as u32);
                        let dst = 3 * g.index(ti, pi, to, po);
                        values.copy_within(src..src + 3, dst);
                    }
                }
            }
        }
        values
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_core::symmetry::Symmetry;
    use clothbake_loader::Grid;

    fn grid() -> Grid {
        Grid::new(2, 4, 3, 4)
    }

    /// Row `r`'s values: distinct numbers, so that every misplaced value shows.
    fn row_of(o: &Orbits, r: usize) -> Row {
        (0..o.row_evaluations(r))
            .map(|k| {
                let x = (1000 * r + 3 * k) as f32;
                [x, x + 1.0, x + 2.0]
            })
            .collect()
    }

    #[test]
    fn rows_come_back_as_they_were_put() {
        let syms = [Symmetry::MirrorX, Symmetry::MirrorY, Symmetry::Rotate180];
        for o in [
            Orbits::new(&grid(), &[]),
            Orbits::new(&grid(), &syms),
            Orbits::spatial(&grid(), 2, 2),
            Orbits::spatial(&grid(), 2, 6),
        ] {
            let a = Assembly::new(&o, 2..6);
            assert!(a.row(3).is_none());
            for r in [5, 2, 3] {
                a.put(r, &row_of(&o, r));
            }
            assert_eq!(a.done_rows(), [2, 3, 5]);
            for r in [2, 3, 5] {
                let mut want = row_of(&o, r);
                // The classes' padding comes back as 0 (2 K = 4 values in 2 entries; 6 K = 12
                // in 4, none).
                if o.classes() > 0 {
                    for e in want.chunks_exact_mut(o.stride()) {
                        for x in e[1..].iter_mut().flatten().skip(o.class_values()) {
                            *x = 0.0;
                        }
                    }
                }
                assert_eq!(a.row(r).unwrap(), want, "row {r}");
            }
            assert!(a.row(4).is_none() && a.row(7).is_none());
        }
    }

    #[test]
    fn the_values_are_the_table_layout_with_symmetry_copies() {
        // Against a straightforward assembly: every cell's value is its representative's,
        // found in the representative's row at its rank among the row's canonical cells.
        let g = grid();
        let o = Orbits::new(&g, &[Symmetry::MirrorY]);
        let a = Assembly::new(&o, 0..o.rows());
        let rows: Vec<Row> = (0..o.rows()).map(|r| row_of(&o, r)).collect();
        for (r, v) in rows.iter().enumerate().rev() {
            a.put(r, v);
        }
        let values = a.into_values();
        assert_eq!(values.len(), 3 * g.len());
        for ti in 0..g.n_theta_i {
            for pi in 0..g.n_phi_i {
                for to in 0..g.n_theta_o {
                    for po in 0..g.n_phi_o {
                        let (ri, ro) = o.rep(pi as usize, po as usize);
                        let row = (ti * g.n_phi_i) as usize + ri;
                        let rank = (0..g.n_phi_o as usize)
                            .filter(|&p| o.rep(ri, p) == (ri, p))
                            .collect::<Vec<_>>();
                        let k =
                            to as usize * rank.len() + rank.iter().position(|&p| p == ro).unwrap();
                        let c = g.index(ti, pi, to, po);
                        assert_eq!(values[3 * c..3 * c + 3], rows[row][k], "cell {c}");
                    }
                }
            }
        }
    }
}
