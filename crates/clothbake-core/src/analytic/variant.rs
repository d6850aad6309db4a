//! The analytic variants (thesis eq. 3.6 as printed, refined, sliced, sliced3d) and what each
//! takes: a [`Variant`] is checked against the fabric's period when the model is built
//! ([`Variant::check`]), so no caller can build a model its period would exhaust.

use super::*;

/// How the length a segment's end hides is taken (thesis eq. 3.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Variant {
    /// As printed: the hidden length on the flat top (height pi r / 4, eq. 3.1) of the
    /// segment's equal-area rectangle.
    Thesis,
    /// Eq. 3.6 evaluated at the true height r sin(theta) + h of every point of the arc and
    /// averaged over the arc with the projected-width weight N.E (closed form). The hidden length
    /// is clamped to [0, segment length] point by point, which the rectangle's single height
    /// cannot do: low points beside a crossing thread are hidden even when the rectangle's top
    /// is not. Default: it halves the model's error against the ray-traced ground truth.
    #[default]
    Refined,
    /// `refined`, with each piece's cross-section profile taken slice by slice along the piece
    /// instead of once for its crossing row (docs/science/model.md, "The sliced variant"): the
    /// neighbours' floats that reach into the piece from the next rows, seen end-on, and the
    /// crossing cylinder only where it is, at its true height there, in place of its
    /// equal-area rectangle along the whole piece. Slices where the profile is constant are
    /// exact; the slices under a crossing cylinder are split in [`SLICE_PARTS`] parts.
    Sliced,
    /// `sliced`, with what hides each slice's side taken in three dimensions (docs/science/model.md,
    /// "The sliced3d variant"): the rays that leave the slice's arc toward the light or the eye
    /// are followed through the floats around the piece, each a finite cylinder, in place of
    /// the slice's 2-D profile of its own row. Pieces are one unit only where their
    /// surroundings agree too; evaluated slice by slice, without the lanes: far slower than
    /// the others.
    Sliced3d,
}

/// Parts each slice of a piece under a crossing cylinder is split into by [`Variant::Sliced`]
/// (its profile taken at the middle of each part).
pub const SLICE_PARTS: usize = 4;

/// The most cells (warp x weft threads) a period may have for [`Variant::Sliced3d`], whose
/// preprocessing grows faster than the period (docs/reference/limits.md): about a minute and two
/// gigabytes at this size for a random period.
pub const SLICED3D_MAX_CELLS: usize = 16_384;

/// A variant asked of a fabric whose period it does not take: [`Variant::Sliced3d`] on a period
/// of more than [`SLICED3D_MAX_CELLS`] cells, whose preprocessing would take minutes and
/// gigabytes. The message says what; [`VariantError::fix`] what to do.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the variant {} takes a period of at most {max} cells, and this one has {warp} x {weft} = {}",
    variant.name(),
    warp * weft
)]
pub struct VariantError {
    /// The variant asked for.
    pub variant: Variant,
    /// Warp threads of the period.
    pub warp: usize,
    /// Weft threads of the period.
    pub weft: usize,
    /// The most cells the variant takes.
    pub max: usize,
}

impl VariantError {
    /// What to do instead.
    pub fn fix(&self) -> &'static str {
        "use the variant sliced or refined for it (docs/reference/limits.md)"
    }

    /// The one line a library error carries: what, then `; ` and the fix.
    pub fn line(&self) -> String {
        format!("{self}; {}", self.fix())
    }
}

impl Variant {
    /// Whether the variant takes `fabric`'s period: [`AnalyticModel::with_variant`] asks this
    /// before any work, and a command may ask it earlier (before reading its other inputs).
    pub fn check(self, fabric: &Fabric) -> Result<(), VariantError> {
        let w = fabric.weave();
        let (warp, weft) = (w.n_warp(), w.n_weft());
        if self == Variant::Sliced3d && warp * weft > SLICED3D_MAX_CELLS {
            return Err(VariantError {
                variant: self,
                warp,
                weft,
                max: SLICED3D_MAX_CELLS,
            });
        }
        Ok(())
    }
}

/// Parts each slice of a piece is split into by [`Variant::Sliced3d`]: under a crossing
/// cylinder, elsewhere (what hides the arc taken at the middle of each part).
pub const SLICE3D_PARTS: (usize, usize) = (8, 2);

impl Variant {
    /// Name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Thesis => "thesis",
            Variant::Refined => "refined",
            Variant::Sliced => "sliced",
            Variant::Sliced3d => "sliced3d",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A plain weave of `warp` x `weft` threads.
    fn period(warp: usize, weft: usize) -> Fabric {
        let rows: Vec<Vec<u8>> = (0..weft)
            .map(|j| (0..warp).map(|i| ((i + j) % 2) as u8).collect())
            .collect();
        Fabric::from_json_str(
            &format!(
                r#"{{"pattern": {rows:?}, "warp": {{"radius": 1, "spacing": 2.5}},
                    "weft": {{"radius": 1, "spacing": 2.5}}}}"#
            ),
            "big.json",
        )
        .unwrap()
    }

    #[test]
    fn the_constructor_refuses_a_period_the_variant_does_not_take() {
        // 130 x 128 = 16 640 cells, past sliced3d's 16 384; 128 x 128 is at the limit.
        let big = period(130, 128);
        let e = AnalyticModel::with_variant(&big, FacetModel::Huo, Variant::Sliced3d).unwrap_err();
        assert_eq!((e.warp, e.weft, e.max), (130, 128, SLICED3D_MAX_CELLS));
        let msg = e.to_string();
        assert!(
            msg.contains("sliced3d") && msg.contains("130 x 128 = 16640"),
            "{msg}"
        );
        assert!(e.fix().contains("sliced or refined"), "{}", e.fix());
        assert!(Variant::Sliced3d.check(&period(128, 128)).is_ok());
        // The other variants, the default among them, take any period the fabric format
        // takes: `AnalyticModel::new` relies on the default's.
        for v in [
            Variant::Thesis,
            Variant::Refined,
            Variant::Sliced,
            Variant::default(),
        ] {
            assert!(v.check(&big).is_ok(), "{v:?}");
        }
    }
}
