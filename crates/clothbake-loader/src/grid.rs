//! The 4-D grid of directions a table is tabulated on ([`Grid`]): four [`Axis`]es, the cell
//! order and the limits of its size.

use std::fmt;

use serde::{Deserialize, Serialize};

use crate::axis::{Axis, Span};
use crate::error::TableError;

/// Which light a table holds: reflection off the one face of the thesis's cloth over its
/// floor, or the two-faced cloth's reflection and transmission over the whole sphere
/// (docs/science/transmission.md, docs/reference/table-format.md).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[serde(rename_all = "lowercase")]
pub enum Faces {
    /// One face over an opaque floor: both polar axes cover the hemisphere (the default, and
    /// every table before two-faced ones; not written in a header).
    #[default]
    One,
    /// Two faces, no floor: both polar axes cover the sphere, 0 to 180 degrees from +Z, in an
    /// even number of cells (the horizon is a cell edge).
    Two,
}

impl Faces {
    /// Whether this is [`Faces::One`] (serde's test for leaving the field out).
    pub fn is_one(&self) -> bool {
        *self == Faces::One
    }

    /// The span of a polar axis.
    #[inline(always)]
    pub const fn polar_span(self) -> Span {
        match self {
            Faces::One => Span::Hemisphere,
            Faces::Two => Span::Sphere,
        }
    }
}

/// Largest number of cells a grid may have (2^31).
pub const MAX_CELLS: u64 = 1 << 31;

/// The 4-D grid of incident and outgoing directions, cell-centred, in degrees.
///
/// Four [`Axis`]es: the polar angles ([`Grid::theta_i`], [`Grid::theta_o`]) cover the
/// hemisphere, [0, 90] degrees from +Z (or, for a two-faced table, [`Faces::Two`], the sphere,
/// [0, 180] degrees), the azimuths ([`Grid::phi_i`], [`Grid::phi_o`]) a turn, [0, 360)
/// degrees from +X toward +Y. Cell `k` of an axis of `n` cells is centred on
/// `(k + 0.5) * span / n` degrees ([`Axis::centre_deg`]). Cells are ordered theta_i, phi_i,
/// theta_o, phi_o, the last varying fastest (see [`Grid::index`]).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub struct Grid {
    /// Number of cells of the incident polar angle.
    pub n_theta_i: u32,
    /// Number of cells of the incident azimuth.
    pub n_phi_i: u32,
    /// Number of cells of the outgoing polar angle.
    pub n_theta_o: u32,
    /// Number of cells of the outgoing azimuth.
    pub n_phi_o: u32,
    /// One face (polar axes over the hemisphere) or two (over the sphere); absent from the
    /// JSON of one-faced grids, whose headers are as before.
    #[serde(default, skip_serializing_if = "Faces::is_one")]
    pub faces: Faces,
}

impl Grid {
    /// The one-faced grid of `n_theta_i x n_phi_i x n_theta_o x n_phi_o` cells, unchecked (as
    /// a struct literal; [`Grid::validate`] checks).
    pub const fn new(n_theta_i: u32, n_phi_i: u32, n_theta_o: u32, n_phi_o: u32) -> Grid {
        Grid {
            n_theta_i,
            n_phi_i,
            n_theta_o,
            n_phi_o,
            faces: Faces::One,
        }
    }

    /// The two-faced grid with this grid's cells on each side: its polar counts doubled over
    /// the sphere, so that each side's hemisphere has the cells of `self` (saturating).
    pub const fn two_faced(self) -> Grid {
        Grid {
            n_theta_i: self.n_theta_i.saturating_mul(2),
            n_theta_o: self.n_theta_o.saturating_mul(2),
            faces: Faces::Two,
            ..self
        }
    }

    /// The one-faced grid of one side's hemisphere: a two-faced grid's polar counts halved
    /// (the grid of each of its blocks, `docs/reference/table-format.md`); a one-faced grid itself.
    pub const fn side(self) -> Grid {
        match self.faces {
            Faces::One => self,
            Faces::Two => Grid::new(
                self.n_theta_i / 2,
                self.n_phi_i,
                self.n_theta_o / 2,
                self.n_phi_o,
            ),
        }
    }

    /// Number of cells. Saturates at `usize::MAX` for absurd grids that [`Grid::validate`]
    /// rejects.
    pub fn len(&self) -> usize {
        usize::try_from(self.cells()).unwrap_or(usize::MAX)
    }

    /// True when the grid has no cells (an invalid grid).
    pub fn is_empty(&self) -> bool {
        self.cells() == 0
    }

    /// Number of cells as `u64`, saturating.
    fn cells(&self) -> u64 {
        [self.n_theta_i, self.n_phi_i, self.n_theta_o, self.n_phi_o]
            .iter()
            .fold(1u64, |acc, &n| acc.saturating_mul(u64::from(n)))
    }

    /// Index of a cell: `((ti * n_phi_i + pi) * n_theta_o + to) * n_phi_o + po`.
    pub fn index(&self, ti: u32, pi: u32, to: u32, po: u32) -> usize {
        debug_assert!(ti < self.n_theta_i && pi < self.n_phi_i);
        debug_assert!(to < self.n_theta_o && po < self.n_phi_o);
        let (ti, pi, to, po) = (ti as usize, pi as usize, to as usize, po as usize);
        ((ti * self.n_phi_i as usize + pi) * self.n_theta_o as usize + to) * self.n_phi_o as usize
            + po
    }

    /// The incident polar axis: `n_theta_i` cells over the hemisphere (the sphere with two
    /// faces).
    #[inline(always)]
    pub const fn theta_i(&self) -> Axis {
        Axis::new(self.faces.polar_span(), self.n_theta_i)
    }

    /// The incident azimuth axis: `n_phi_i` cells over a turn.
    #[inline(always)]
    pub const fn phi_i(&self) -> Axis {
        Axis::azimuth(self.n_phi_i)
    }

    /// The outgoing polar axis: `n_theta_o` cells over the hemisphere (the sphere with two
    /// faces).
    #[inline(always)]
    pub const fn theta_o(&self) -> Axis {
        Axis::new(self.faces.polar_span(), self.n_theta_o)
    }

    /// The outgoing azimuth axis: `n_phi_o` cells over a turn.
    #[inline(always)]
    pub const fn phi_o(&self) -> Axis {
        Axis::azimuth(self.n_phi_o)
    }

    /// The four axes in cell order: theta_i, phi_i, theta_o, phi_o.
    #[inline(always)]
    pub const fn axes(&self) -> [Axis; 4] {
        [self.theta_i(), self.phi_i(), self.theta_o(), self.phi_o()]
    }

    /// Centre of incident polar cell `k`, degrees from +Z.
    pub fn theta_i_deg(&self, k: u32) -> f64 {
        self.theta_i().centre_deg(k)
    }

    /// Centre of incident azimuth cell `k`, degrees from +X toward +Y.
    pub fn phi_i_deg(&self, k: u32) -> f64 {
        self.phi_i().centre_deg(k)
    }

    /// Centre of outgoing polar cell `k`, degrees from +Z.
    pub fn theta_o_deg(&self, k: u32) -> f64 {
        self.theta_o().centre_deg(k)
    }

    /// Centre of outgoing azimuth cell `k`, degrees from +X toward +Y.
    pub fn phi_o_deg(&self, k: u32) -> f64 {
        self.phi_o().centre_deg(k)
    }

    /// Width of the EXR image: `n_phi_i * n_phi_o`.
    pub fn exr_width(&self) -> u64 {
        u64::from(self.n_phi_i) * u64::from(self.n_phi_o)
    }

    /// Height of the EXR image: `n_theta_i * n_theta_o`.
    pub fn exr_height(&self) -> u64 {
        u64::from(self.n_theta_i) * u64::from(self.n_theta_o)
    }

    /// Checks that every axis has cells, that a two-faced grid's polar counts are even, and
    /// that the grid has at most [`MAX_CELLS`] cells.
    pub fn validate(&self) -> Result<(), TableError> {
        let axes = [
            ("n_theta_i", self.n_theta_i),
            ("n_phi_i", self.n_phi_i),
            ("n_theta_o", self.n_theta_o),
            ("n_phi_o", self.n_phi_o),
        ];
        for (name, n) in axes {
            if n == 0 {
                return Err(TableError::InvalidTable {
                    reason: format!("grid {self}: {name} is 0; every axis needs at least 1 cell"),
                });
            }
        }
        if self.faces == Faces::Two {
            for (name, n) in [("n_theta_i", self.n_theta_i), ("n_theta_o", self.n_theta_o)] {
                if n % 2 == 1 {
                    return Err(TableError::InvalidTable {
                        reason: format!(
                            "grid {self}: {name} is {n}, but a two-faced grid's polar axes cover \
                             0 to 180 degrees in an even number of cells (the horizon is a cell edge)"
                        ),
                    });
                }
            }
        }
        if self.cells() > MAX_CELLS {
            return Err(TableError::InvalidTable {
                reason: format!(
                    "grid {self}: {} cells is more than the limit of {MAX_CELLS} (2^31); use a coarser grid",
                    // The exact count (a u128 holds any product of four u32).
                    [self.n_theta_i, self.n_phi_i, self.n_theta_o, self.n_phi_o]
                        .iter()
                        .map(|&n| u128::from(n))
                        .product::<u128>()
                ),
            });
        }
        Ok(())
    }
}

impl fmt::Display for Grid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "theta_i {} phi_i {} theta_o {} phi_o {}",
            self.n_theta_i, self.n_phi_i, self.n_theta_o, self.n_phi_o
        )?;
        match self.faces {
            Faces::One => Ok(()),
            Faces::Two => f.write_str(" (two faces: theta 0 to 180)"),
        }
    }
}
