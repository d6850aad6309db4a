//! Tables kept at their stored precision: half-float EXR tables stay half in memory.
//!
//! [`read_table_stored`](crate::read_table_stored) returns a [`StoredTable`], whose
//! [`Samples`] are `f16` for half-float EXR files and `f32` otherwise; the lookup
//! ([`crate::Brdf`]) interpolates either directly. [`crate::Table`] (always `f32`) remains the
//! type the baker builds and writes.

use half::f16;

use crate::error::TableError;
#[cfg(test)]
use crate::table::is_physical;
use crate::table::{check_values, Metadata, Precision, Table};

/// The RGB values of a table, interleaved as in [`Table::values`], at one precision.
#[derive(Clone, Debug, PartialEq)]
pub enum Samples {
    /// Half floats, as stored in a half-float EXR table (2 bytes a value).
    F16(Vec<f16>),
    /// 32-bit floats (4 bytes a value): binary tables, float EXR tables, or on request.
    F32(Vec<f32>),
}

impl Samples {
    /// Number of values (three per cell).
    pub fn len(&self) -> usize {
        match self {
            Samples::F16(v) => v.len(),
            Samples::F32(v) => v.len(),
        }
    }

    /// True when there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `i` widened to `f32` (exact for both precisions).
    pub fn get(&self, i: usize) -> f32 {
        match self {
            Samples::F16(v) => f16_to_f32(v[i].to_bits()),
            Samples::F32(v) => v[i],
        }
    }

    /// Splits off the values from `at` on (as [`Vec::split_off`]).
    pub fn split_off(&mut self, at: usize) -> Samples {
        match self {
            Samples::F16(v) => Samples::F16(v.split_off(at)),
            Samples::F32(v) => Samples::F32(v.split_off(at)),
        }
    }

    /// The precision of the values.
    pub fn precision(&self) -> Precision {
        match self {
            Samples::F16(_) => Precision::F16,
            Samples::F32(_) => Precision::F32,
        }
    }

    /// All values widened to `f32` (exact).
    pub fn into_f32(self) -> Vec<f32> {
        match self {
            Samples::F16(v) => v.into_iter().map(|h| f16_to_f32(h.to_bits())).collect(),
            Samples::F32(v) => v,
        }
    }

    /// Index and widened value of the first value that is not physical (not finite,
    /// negative, or above [`crate::table::MAX_VALUE`]), if any.
    fn first_unphysical(&self) -> Option<(usize, f32)> {
        match self {
            Samples::F16(v) => {
                // Blocks checked whole on the bits (no early exit inside one, so the check
                // vectorises), the block that fails searched again.
                const BLOCK: usize = 1024;
                let physical = |h: &f16| half_is_physical(h.to_bits());
                v.chunks(BLOCK)
                    .position(|b| !b.iter().fold(true, |ok, h| ok & physical(h)))
                    .map(|k| {
                        let at = k * BLOCK;
                        let i = at
                            + v[at..]
                                .iter()
                                .position(|h| !physical(h))
                                .expect("the failing block holds the value");
                        (i, v[i].to_f32())
                    })
            }
            Samples::F32(v) => crate::table::first_unphysical(v).map(|i| (i, v[i])),
        }
    }
}

/// A table whose values keep the precision they were stored with.
#[derive(Clone, Debug, PartialEq)]
pub struct StoredTable {
    /// What the table holds.
    pub meta: Metadata,
    /// RGB values, interleaved: value `3 * cell + channel`, see [`crate::Grid::index`].
    pub samples: Samples,
}

impl StoredTable {
    /// A table, after the checks of [`Table::new`] (metadata, number of values, all physical).
    pub fn new(meta: Metadata, samples: Samples) -> Result<StoredTable, TableError> {
        check_values(&meta, samples.len(), samples.first_unphysical())?;
        Ok(StoredTable { meta, samples })
    }

    /// A table at `precision`: `f32` keeps the values; `f16` rounds them to the nearest half
    /// float (as [`crate::write_exr`] does), an error beyond the half range (65504).
    pub fn from_table(table: Table, precision: Precision) -> Result<StoredTable, TableError> {
        let samples = match precision {
            Precision::F32 => Samples::F32(table.values),
            Precision::F16 => {
                let max = f16::MAX.to_f32();
                if let Some(v) = table.values.iter().find(|v| v.abs() > max) {
                    return Err(TableError::InvalidTable {
                        reason: format!(
                            "value {v} exceeds the half-float range (65504); keep the table in f32"
                        ),
                    });
                }
                Samples::F16(table.values.iter().map(|&v| f16::from_f32(v)).collect())
            }
        };
        StoredTable::new(table.meta, samples)
    }

    /// The table with its values widened to `f32` (exact).
    pub fn into_table(self) -> Table {
        Table {
            meta: self.meta,
            values: self.samples.into_f32(),
        }
    }
}

impl From<Table> for StoredTable {
    /// Keeps the `f32` values (a [`Table`] is valid by construction or checked by its writer).
    fn from(table: Table) -> StoredTable {
        StoredTable {
            meta: table.meta,
            samples: Samples::F32(table.values),
        }
    }
}

/// [`is_physical`] of a half float from its bits: finite (exponent bits not all ones) and not
/// negative (sign clear, or -0); every finite half is below [`crate::MAX_VALUE`].
#[inline(always)]
pub(crate) fn half_is_physical(bits: u16) -> bool {
    (bits & 0x7c00 != 0x7c00) & ((bits & 0x8000 == 0) | (bits == 0x8000))
}

/// Widens the bits of a finite IEEE half float to `f32`, branch-free: the exponent and
/// mantissa bits, shifted into an `f32` of exponent bias 127 - 15 less than a half's, times
/// 2^112 (which also normalises half subnormals exactly), and the sign. Not for infinities and
/// NaNs, which tables never hold.
#[inline(always)]
pub fn f16_to_f32(bits: u16) -> f32 {
    const TWO_POW_112: f32 = 5.192_297e33; // 2^112, exactly representable
    let magnitude = f32::from_bits(u32::from(bits & 0x7fff) << 13) * TWO_POW_112;
    f32::from_bits(magnitude.to_bits() | (u32::from(bits & 0x8000) << 16))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widening_matches_the_half_crate_for_every_finite_half() {
        for bits in 0..=u16::MAX {
            let h = f16::from_bits(bits);
            if h.is_finite() {
                assert_eq!(
                    f16_to_f32(bits).to_bits(),
                    h.to_f32().to_bits(),
                    "bits {bits:#06x}"
                );
            }
        }
    }

    #[test]
    fn the_bits_test_is_the_value_test_for_every_half() {
        for bits in 0..=u16::MAX {
            let h = f16::from_bits(bits);
            assert_eq!(
                half_is_physical(bits),
                is_physical(h.to_f32()),
                "bits {bits:#06x}"
            );
        }
    }

    #[test]
    fn two_pow_112_is_exact() {
        assert_eq!(5.192_297e33_f32, 2f32.powi(112));
    }
}
