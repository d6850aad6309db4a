//! The table in memory: its [`Metadata`] (with its [`Grid`] of directions) and its values
//! ([`Table`]), and the rules every table obeys ([`Table::new`]).

use serde::{Deserialize, Serialize};

use crate::error::TableError;
use crate::grid::Grid;
use crate::spatial::Spatial;

/// Version of the table description: the [`Metadata`] record, the grid layout and the OpenEXR
/// format (`docs/reference/table-format.md`), of one-faced tables. Readers reject versions they do not
/// know. The binary container has a version of its own, [`crate::CONTAINER_VERSION`].
pub const FORMAT_VERSION: u32 = 1;

/// Version of two-faced tables ([`crate::Faces::Two`]): the same description with a sphere
/// grid and the openness, numbered apart so that a reader of version 1 alone refuses one
/// instead of reading its sphere as a hemisphere.
pub const TWO_FACED_VERSION: u32 = 2;

/// The version of a table with `faces`.
pub const fn version_for(faces: crate::Faces) -> u32 {
    match faces {
        crate::Faces::One => FORMAT_VERSION,
        crate::Faces::Two => TWO_FACED_VERSION,
    }
}

/// Whether this build reads table description version `v`.
pub(crate) fn reads_version(v: u64) -> bool {
    v == u64::from(FORMAT_VERSION) || v == u64::from(TWO_FACED_VERSION)
}

/// Largest value a table may hold, in 1/sr (10^30). Far beyond any physical BRDF (a mirror
/// tabulated in cells of 0.01 degrees stays below 10^8), and small enough that every sum and
/// weight the loader forms stays finite in f32: the importance sampling's density is at least
/// [`crate::sampling::DEFENSIVE`] / (2 pi) per steradian, so its weights f_r cos(theta) / pdf
/// are at most about 630 f_r (f32 overflows at 3.4 10^38).
pub const MAX_VALUE: f32 = 1e30;

/// Whether `v` may be a table's value: finite, not negative, at most [`MAX_VALUE`].
pub(crate) fn is_physical(v: f32) -> bool {
    (0.0..=MAX_VALUE).contains(&v)
}

/// The index of the first value of `values` that is not [`is_physical`], if any. Blocks are
/// checked whole (no early exit inside one, so the check vectorises), the block that fails
/// searched again.
pub(crate) fn first_unphysical(values: &[f32]) -> Option<usize> {
    const BLOCK: usize = 1024;
    values
        .chunks(BLOCK)
        .position(|b| !b.iter().fold(true, |ok, &v| ok & is_physical(v)))
        .map(|k| {
            let at = k * BLOCK;
            at + values[at..]
                .iter()
                .position(|&v| !is_physical(v))
                .expect("the failing block holds the value")
        })
}

/// What a table holds and how it was made. Stored in both formats.
///
/// The field order is part of the version-1 binary format, which the loader still reads (see
/// `docs/reference/table-format.md`): do not reorder.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq)]
pub struct Metadata {
    /// Version of the table description: [`FORMAT_VERSION`], or [`TWO_FACED_VERSION`] for a
    /// two-faced table ([`version_for`]).
    pub format_version: u32,
    /// The tool that wrote the table, e.g. `"clothbake 0.1.0"`.
    pub tool: String,
    /// The grid of directions.
    pub grid: Grid,
    /// Where samples sit in their cells: always `"cell"` (cell centres).
    pub centring: String,
    /// The tabulated quantity: `"f_r"`, the BRDF.
    pub quantity: String,
    /// Units of the values: `"1/sr"`.
    pub units: String,
    /// The full fabric file, as JSON text.
    pub fabric_json: String,
    /// The bake options, as JSON text.
    pub options_json: String,
    /// The symmetry the baker exploited, in words, e.g. `"mirror x, mirror y"` or `"none"`.
    pub symmetry: String,
    /// For a spatially varying table, the period's cells and classes (`crate::spatial`);
    /// absent from averaged tables, whose headers are as before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spatial: Option<Spatial>,
    /// For a spatial table of one bounce, the period's yarns (`clothbake_point::Period`,
    /// checked on reading by its one constructor): with them the loader answers footprints
    /// under two crossing cells at the point level (docs/science/spatial.md). Absent elsewhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yarns: Option<clothbake_point::Period>,
    /// For a two-faced table ([`crate::Faces::Two`]), the openness at each incident cell
    /// centre of the sphere grid, `ti * n_phi_i + pi`: the share of the light from there that
    /// passes straight through the gaps (docs/science/transmission.md), each in [0, 1]. Absent from
    /// one-faced tables.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub openness: Option<Vec<f32>>,
}

impl Metadata {
    /// Values per class and grid cell of a spatial table ([`crate::spatial::lanes`]; that of
    /// the direct reflection for an averaged table, which has no classes).
    pub fn class_lanes(&self) -> usize {
        self.spatial
            .as_ref()
            .map_or(crate::spatial::lanes(false), Spatial::lanes)
    }

    /// The names of the table's channels, in [`crate::spatial::channel_names`] order (as its
    /// OpenEXR file holds them).
    pub fn channel_names(&self) -> Vec<String> {
        let classes = self.spatial.as_ref().map_or(0, |s| s.classes);
        crate::spatial::channel_names(classes, self.class_lanes())
    }

    /// Metadata of the format version of `grid`'s faces ([`version_for`]) for a cell-centred table of `f_r` in `1/sr`.
    pub fn new(
        tool: impl Into<String>,
        grid: Grid,
        fabric_json: impl Into<String>,
        options_json: impl Into<String>,
        symmetry: impl Into<String>,
    ) -> Metadata {
        Metadata {
            format_version: version_for(grid.faces),
            tool: tool.into(),
            grid,
            centring: "cell".to_string(),
            quantity: "f_r".to_string(),
            units: "1/sr".to_string(),
            fabric_json: fabric_json.into(),
            options_json: options_json.into(),
            symmetry: symmetry.into(),
            spatial: None,
            yarns: None,
            openness: None,
        }
    }

    /// Number of values of a table with this metadata: 3 per grid cell (the averaged RGB), and
    /// for a spatial table [`Metadata::class_lanes`] per grid cell and class after them.
    /// Saturates.
    pub fn values_len(&self) -> usize {
        let extra = self
            .spatial
            .as_ref()
            .map_or(0, |s| s.values_len(&self.grid));
        self.grid.len().saturating_mul(3).saturating_add(extra)
    }

    /// Checks the format version, the grid and the centring.
    pub fn validate(&self) -> Result<(), TableError> {
        let want = version_for(self.grid.faces);
        if self.format_version != want {
            return Err(TableError::InvalidTable {
                reason: format!(
                    "metadata says format version {}, but a {}-faced table is version {want}",
                    self.format_version,
                    if self.grid.faces == crate::Faces::Two {
                        "two"
                    } else {
                        "one"
                    }
                ),
            });
        }
        self.grid.validate()?;
        if let Some(s) = &self.spatial {
            s.validate(&self.grid)?;
        }
        self.validate_faces()?;
        if self.centring != "cell" {
            return Err(TableError::InvalidTable {
                reason: format!(
                    "centring is {:?}, but only \"cell\" (cell-centred samples) is supported",
                    self.centring
                ),
            });
        }
        Ok(())
    }

    /// A two-faced table has its openness, one value in [0, 1] per incident cell, and no
    /// spatial layout or yarns; a one-faced table has no openness.
    fn validate_faces(&self) -> Result<(), TableError> {
        let invalid = |reason: String| Err(TableError::InvalidTable { reason });
        let g = &self.grid;
        match (g.faces, &self.openness) {
            (crate::Faces::One, None) => Ok(()),
            (crate::Faces::One, Some(_)) => invalid(
                "a one-faced table holds an openness; only two-faced tables have one".into(),
            ),
            (crate::Faces::Two, None) => invalid(format!(
                "the two-faced grid {g} needs the openness of each incident cell (field openness)"
            )),
            (crate::Faces::Two, Some(o)) => {
                let want = g.n_theta_i as usize * g.n_phi_i as usize;
                if o.len() != want {
                    return invalid(format!(
                        "openness has {} values, but the grid {g} has {want} incident cells",
                        o.len()
                    ));
                }
                if let Some(k) = o.iter().position(|v| !(0.0..=1.0).contains(v)) {
                    return invalid(format!(
                        "openness of incident cell {k} is {}; an openness lies in [0, 1]",
                        o[k]
                    ));
                }
                if self.spatial.is_some() || self.yarns.is_some() {
                    return invalid(
                        "a two-faced table has no spatial layout or yarns (it is averaged over \
                         the period)"
                            .into(),
                    );
                }
                Ok(())
            }
        }
    }

    /// The metadata as JSON text with every non-ASCII character escaped (`\uXXXX`), so that
    /// it survives any tool that treats EXR text attributes as bytes or as Latin-1.
    pub fn to_ascii_json(&self) -> String {
        let json = serde_json::to_string(self).expect("Metadata serialises to JSON");
        escape_non_ascii(&json)
    }
}

/// Replaces every non-ASCII character of a JSON text by `\uXXXX` escapes (UTF-16 surrogate
/// pairs above U+FFFF). Valid because non-ASCII characters only occur inside JSON strings.
fn escape_non_ascii(json: &str) -> String {
    if json.is_ascii() {
        return json.to_string();
    }
    let mut out = String::with_capacity(json.len() + 16);
    for c in json.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut units = [0u16; 2];
            for unit in c.encode_utf16(&mut units) {
                out.push_str(&format!("\\u{unit:04x}"));
            }
        }
    }
    out
}

/// A baked table: metadata and RGB values, interleaved, one triple per grid cell.
///
/// The value of cell `c` (see [`Grid::index`]) and channel `k` (0 = R, 1 = G, 2 = B) is
/// `values[3 * c + k]`. A spatially varying table ([`Metadata::spatial`]) continues with class
/// `k`'s diffuse and specular values of cell `c` at `3 N + 2 (k N + c)` and `+ 1`, `N` the
/// number of grid cells (`crate::spatial`).
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// What the table holds.
    pub meta: Metadata,
    /// RGB values, interleaved; `values.len() == 3 * meta.grid.len()`.
    pub values: Vec<f32>,
}

impl Table {
    /// A table, after checking the metadata, the number of values and that every value is
    /// physical: finite, not negative, at most [`MAX_VALUE`].
    pub fn new(meta: Metadata, values: Vec<f32>) -> Result<Table, TableError> {
        let table = Table { meta, values };
        table.validate()?;
        Ok(table)
    }

    /// Checks what [`Table::new`] checks; the writers call it, as the fields are public.
    pub fn validate(&self) -> Result<(), TableError> {
        let bad = first_unphysical(&self.values);
        check_values(
            &self.meta,
            self.values.len(),
            bad.map(|i| (i, self.values[i])),
        )
    }

    /// The grid of the table.
    pub fn grid(&self) -> &Grid {
        &self.meta.grid
    }

    /// The RGB value of a cell.
    pub fn rgb(&self, ti: u32, pi: u32, to: u32, po: u32) -> [f32; 3] {
        let c = self.meta.grid.index(ti, pi, to, po);
        [
            self.values[3 * c],
            self.values[3 * c + 1],
            self.values[3 * c + 2],
        ]
    }
}

/// Checks a table's metadata, its number of values (`len`) and the first value that is not
/// physical ([`is_physical`]), if any (its index and value): the rules of [`Table::new`], for
/// any sample type.
pub(crate) fn check_values(
    meta: &Metadata,
    len: usize,
    unphysical: Option<(usize, f32)>,
) -> Result<(), TableError> {
    meta.validate()?;
    let expected = meta.values_len();
    if len != expected {
        let what = if meta.spatial.is_some() {
            "RGB and the classes' values"
        } else {
            "RGB"
        };
        return Err(TableError::InvalidTable {
            reason: format!(
                "grid {} has {} cells and needs {expected} values ({what}), but there are {len}",
                meta.grid,
                meta.grid.len(),
            ),
        });
    }
    if let Some((i, v)) = unphysical {
        let rule = if !v.is_finite() {
            "every value must be finite".to_string()
        } else if v < 0.0 {
            "a BRDF is never negative".to_string()
        } else {
            format!(
                "the largest value a table may hold is {MAX_VALUE:e} 1/sr (beyond it albedos \
                 and sampling weights overflow)"
            )
        };
        return Err(TableError::InvalidTable {
            reason: if i < 3 * meta.grid.len() {
                format!(
                    "value {} of cell {} (channel {}) is {:e}; {rule}",
                    i,
                    i / 3,
                    ['R', 'G', 'B'][i % 3],
                    v
                )
            } else {
                format!("value {i} (a class's value) is {v:e}; {rule}")
            },
        });
    }
    Ok(())
}

/// Sample type of the EXR channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Precision {
    /// 16-bit half floats (the default): half the size, about 3 significant digits, at most
    /// 65504.
    #[default]
    F16,
    /// 32-bit floats: exact.
    F32,
}

/// Refuses a table whose metadata (`meta`, as JSON) names a version this build does not read
/// ([`FORMAT_VERSION`] and [`TWO_FACED_VERSION`]): checked
/// before the rest, so that a newer table says "update the loader" (both formats).
pub(crate) fn check_format_version(
    path: &std::path::Path,
    meta: &serde_json::Value,
) -> Result<(), TableError> {
    match meta.get("format_version").and_then(|v| v.as_u64()) {
        Some(found) if !reads_version(found) => Err(TableError::Version {
            path: path.to_path_buf(),
            what: "table",
            found: u32::try_from(found).unwrap_or(u32::MAX),
            reads: TWO_FACED_VERSION,
        }),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_unphysical_value_is_found_wherever_it_lies() {
        let n = 5000;
        let plain = |v: &[f32]| v.iter().position(|&x| !is_physical(x));
        assert_eq!(first_unphysical(&[]), None);
        assert_eq!(first_unphysical(&vec![0.5; n]), None);
        for at in [0, 1, 1023, 1024, 1025, 2047, 4095, 4096, n - 1] {
            for bad in [f32::NAN, -1e-30, f32::INFINITY, 2e30, -0.0 - 1.0] {
                let mut v = vec![0.5f32; n];
                v[at] = bad;
                // A second bad value later must not be the one found.
                v[n - 1] = f32::NAN;
                assert_eq!(first_unphysical(&v), plain(&v), "{bad} at {at}");
                assert_eq!(first_unphysical(&v), Some(at), "{bad} at {at}");
            }
        }
        // Edge values that are physical.
        assert_eq!(first_unphysical(&[0.0, -0.0, MAX_VALUE]), None);
    }
}
