//! Merging identical pieces into independent units (thesis eq. 4.11: m units with
//! multiplicities D_i). Two pieces are the same unit when their keys (everything a piece's
//! reflection depends on) have the same length and agree to within a tolerance in every
//! component; a piece joins the first unit, in order of creation, that it agrees with.
//!
//! A linear search over the units made preprocessing quadratic in the period's cells. Here the
//! keys are hashed on a grid of [`CELL`] per component: keys that agree to within `tol`
//! (`2 tol <= CELL`) lie in the same grid cell or, for a component within `2 tol` of a cell
//! border, in the neighbouring one. A look-up visits every such cell and keeps the earliest
//! unit that agrees, so the units, their order and their counts are exactly those of the linear
//! search. Below [`LINEAR`] units the search is linear (most periods stay below it).

use std::collections::HashMap;

/// Grid step of the hash, per key component.
const CELL: f64 = 1e-6;

/// Up to this many units a look-up scans the keys (cheaper than hashing them for the small
/// periods of most fabrics); the hash is built when the units reach this number.
const LINEAR: usize = 32;

/// Beyond this many grid cells to visit (a key with many components on cell borders), a
/// look-up scans every key instead: the same answer, found linearly.
const MAX_PROBES: usize = 64;

/// Keys of the units made so far, indexed for look-up to a tolerance.
#[derive(Debug)]
pub struct UnitIndex {
    tol: f64,
    keys: Vec<Vec<f64>>,
    cells: HashMap<Vec<i64>, Vec<usize>>,
}

fn cell(x: f64) -> i64 {
    // Monotone in x (saturating for huge values, 0 for NaN: such keys only share a cell).
    (x / CELL).round() as i64
}

impl UnitIndex {
    /// An empty index comparing components to within `tol` (at most `CELL / 2`).
    pub fn new(tol: f64) -> UnitIndex {
        assert!(
            tol > 0.0 && 2.0 * tol <= CELL,
            "tolerance {tol} out of range"
        );
        UnitIndex {
            tol,
            keys: Vec::new(),
            cells: HashMap::new(),
        }
    }

    fn same(&self, a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < self.tol)
    }

    /// The first unit whose key agrees with `key`, or `None` after adding `key` as a new unit
    /// (numbered in order of creation from 0). Only a new key is copied.
    pub fn find_or_insert(&mut self, key: &[f64]) -> Option<usize> {
        if self.keys.len() < LINEAR {
            let found = (0..self.keys.len()).find(|&i| self.same(&self.keys[i], key));
            if found.is_none() {
                self.keys.push(key.to_vec());
                if self.keys.len() == LINEAR {
                    // Every key in its home cell, ids in order of creation.
                    for (i, k) in self.keys.iter().enumerate() {
                        let home: Vec<i64> = k.iter().map(|&x| cell(x)).collect();
                        self.cells.entry(home).or_default().push(i);
                    }
                }
            }
            return found;
        }
        let home: Vec<i64> = key.iter().map(|&x| cell(x)).collect();
        // Every cell a key within `tol` of this one can lie in, per component: y in
        // (x - tol, x + tol) implies cell(x - 2 tol) <= cell(y) <= cell(x + 2 tol), rounding
        // being monotone.
        let d = 2.0 * self.tol;
        let ranges: Vec<(i64, i64)> = key.iter().map(|&x| (cell(x - d), cell(x + d))).collect();
        let probes = ranges.iter().try_fold(1usize, |acc, &(lo, hi)| {
            let span = usize::try_from(hi.saturating_sub(lo))
                .ok()?
                .checked_add(1)?;
            acc.checked_mul(span).filter(|&p| p <= MAX_PROBES)
        });
        let found = match probes {
            Some(1) => self
                .cells
                .get(&home)
                .and_then(|ids| ids.iter().copied().find(|&i| self.same(&self.keys[i], key))),
            Some(_) => {
                let mut best: Option<usize> = None;
                let mut probe = ranges.iter().map(|r| r.0).collect::<Vec<i64>>();
                loop {
                    if let Some(ids) = self.cells.get(&probe) {
                        // Ids within a cell are in order of creation.
                        if let Some(i) =
                            ids.iter().copied().find(|&i| self.same(&self.keys[i], key))
                        {
                            best = Some(best.map_or(i, |b| b.min(i)));
                        }
                    }
                    // Next cell of the box, odometer order.
                    let mut k = 0;
                    while k < probe.len() && probe[k] == ranges[k].1 {
                        probe[k] = ranges[k].0;
                        k += 1;
                    }
                    if k == probe.len() {
                        break;
                    }
                    probe[k] += 1;
                }
                best
            }
            None => (0..self.keys.len()).find(|&i| self.same(&self.keys[i], key)),
        };
        if found.is_none() {
            self.cells.entry(home).or_default().push(self.keys.len());
            self.keys.push(key.to_vec());
        }
        found
    }

    /// Number of units.
    #[cfg(test)]
    fn len(&self) -> usize {
        self.keys.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// The rule the index must reproduce: the first earlier key within `tol`, by linear search.
    fn linear(keys: &[Vec<f64>], key: &[f64], tol: f64) -> Option<usize> {
        keys.iter().position(|k| {
            k.len() == key.len() && k.iter().zip(key).all(|(x, y)| (x - y).abs() < tol)
        })
    }

    #[test]
    fn agrees_with_linear_search_on_keys_near_cell_borders() {
        // Components drawn from a few values placed on, just inside and just outside the grid's
        // borders, plus jitter below and above the tolerance: every branch of the look-up.
        let tol = 1e-9;
        let mut rng = Rng::new(7);
        let bases = [
            0.0,
            0.5e-6,
            0.5e-6 - 1.5e-9,
            1.5e-6 + 0.9e-9,
            3.1,
            -2.5e-6,
            1e13,
        ];
        let jitter = [0.0, 0.4e-9, -0.4e-9, 0.9e-9, -0.99e-9, 1.1e-9, -3e-9];
        let mut index = UnitIndex::new(tol);
        let mut keys: Vec<Vec<f64>> = Vec::new();
        let mut merged = 0;
        for _ in 0..20_000 {
            let len = 2 + (rng.next_u64() % 3) as usize;
            let key: Vec<f64> = (0..len)
                .map(|_| {
                    let b = bases[(rng.next_u64() % bases.len() as u64) as usize];
                    let j = jitter[(rng.next_u64() % jitter.len() as u64) as usize];
                    b + j
                })
                .collect();
            let want = linear(&keys, &key, tol);
            assert_eq!(index.find_or_insert(&key), want, "{key:?}");
            if want.is_none() {
                keys.push(key);
            } else {
                merged += 1;
            }
        }
        assert_eq!(index.len(), keys.len());
        assert!(merged > 1000 && keys.len() > 100, "{merged} {}", keys.len());
    }

    #[test]
    fn keys_with_many_border_components_fall_back_to_the_scan() {
        // 12 components on cell borders: 4096 cells to visit, more than MAX_PROBES. First
        // LINEAR other units, so that the hash is in use.
        let mut index = UnitIndex::new(1e-9);
        for k in 0..LINEAR {
            assert_eq!(index.find_or_insert(&[k as f64; 12]), None);
        }
        let a = vec![0.5e-6; 12];
        let b: Vec<f64> = a.iter().map(|x| x + 0.5e-9).collect();
        assert_eq!(index.find_or_insert(&a), None);
        assert_eq!(index.find_or_insert(&b), Some(LINEAR));
        assert_eq!(index.find_or_insert(&[0.5e-6; 11]), None);
        assert_eq!(index.find_or_insert(&[3.0; 12]), Some(3));
    }
}
