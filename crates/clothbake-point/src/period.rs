//! One weave period's yarns as a renderer needs them: each yarn segment a horizontal circular
//! cylinder with its finish, cut by the floor z = 0, the period tiling the plane
//! (docs/science/geometry.md, thesis ch. 2). A [`Period`] is built by one checked constructor and is
//! serialisable, so that a table can carry it beside its values.

use crate::finish::{Facet, Finish};
use serde::{Deserialize, Serialize};
use std::fmt;

/// The direction a yarn segment's axis runs in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Along {
    /// Along +Y: a warp thread (across coordinate x).
    Y,
    /// Along +X: a weft thread (across coordinate y).
    X,
}

/// One yarn segment of the period: a cylinder of `radius` whose axis runs `along` at
/// `across` (x for [`Along::Y`], y for [`Along::X`]) and `height` above the floor, from
/// `extent.0` to `extent.1` along its axis (unwrapped coordinates), or endless.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Yarn {
    /// Direction of the axis.
    pub along: Along,
    /// Across coordinate of the axis, in [0, the period's size across).
    pub across: f64,
    /// Height of the axis above the floor; |height| < radius.
    pub height: f64,
    /// Cylinder radius, > 0.
    pub radius: f64,
    /// Extent along the axis (low < high, shorter than the period), `None` when endless.
    pub extent: Option<(f64, f64)>,
    /// Index of its finish in [`Period::finishes`].
    pub finish: u32,
}

/// Why a [`Period`] was refused: the field and what is wrong with it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PeriodError(pub String);

impl fmt::Display for PeriodError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for PeriodError {}

/// The most yarn segments a period may hold (a bound on what one look walks over).
pub const MAX_YARNS: usize = 1 << 16;

/// A weave period's micro-geometry and finishes: valid by construction ([`Period::new`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Raw", into = "Raw")]
pub struct Period {
    size: (f64, f64),
    yarns: Vec<Yarn>,
    finishes: Vec<Finish>,
    facet: Facet,
}

/// The serialised form, checked by [`Period::new`] when read.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    size: (f64, f64),
    yarns: Vec<Yarn>,
    finishes: Vec<Finish>,
    facet: Facet,
}

impl TryFrom<Raw> for Period {
    type Error = PeriodError;
    fn try_from(r: Raw) -> Result<Period, PeriodError> {
        Period::new(r.size, r.yarns, r.finishes, r.facet)
    }
}

impl From<Period> for Raw {
    fn from(p: Period) -> Raw {
        Raw {
            size: p.size,
            yarns: p.yarns,
            finishes: p.finishes,
            facet: p.facet,
        }
    }
}

fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

impl Period {
    /// A period of `size` (Px, Py) holding `yarns` shaded with `finishes` by `facet`. Refused:
    /// sizes not finite and positive, more than [`MAX_YARNS`] yarns, a yarn with a radius not
    /// finite and positive, |height| >= radius, an axis outside [0, size across), an extent
    /// empty, not finite or as long as the period, a finish index out of range, or a finish out
    /// of its ranges ([`Finish::check`]). Solids may touch but are assumed not to overlap.
    pub fn new(
        size: (f64, f64),
        yarns: Vec<Yarn>,
        finishes: Vec<Finish>,
        facet: Facet,
    ) -> Result<Period, PeriodError> {
        let err = |s: String| Err(PeriodError(s));
        if !(positive(size.0) && positive(size.1)) {
            return err(format!("size: {size:?} is not two finite positive lengths"));
        }
        if yarns.len() > MAX_YARNS {
            return err(format!(
                "yarns: {} segments, at most {MAX_YARNS}",
                yarns.len()
            ));
        }
        for (k, f) in finishes.iter().enumerate() {
            f.check()
                .map_err(|e| PeriodError(format!("finishes[{k}]: {e}")))?;
        }
        for (k, y) in yarns.iter().enumerate() {
            let (across_size, along_size) = match y.along {
                Along::Y => (size.0, size.1),
                Along::X => (size.1, size.0),
            };
            if !positive(y.radius) {
                return err(format!("yarns[{k}].radius: {} is not > 0", y.radius));
            }
            if 2.0 * y.radius > across_size {
                return err(format!(
                    "yarns[{k}].radius: {} is more than half the period across ({across_size}): the thread would overlap its own next copy",
                    y.radius
                ));
            }
            if !(y.height.is_finite() && y.height.abs() < y.radius) {
                return err(format!(
                    "yarns[{k}].height: {} is not within the radius {}",
                    y.height, y.radius
                ));
            }
            if !(y.across.is_finite() && (0.0..across_size).contains(&y.across)) {
                return err(format!(
                    "yarns[{k}].across: {} is outside [0, {across_size})",
                    y.across
                ));
            }
            if let Some((lo, hi)) = y.extent {
                if !(lo.is_finite() && hi.is_finite() && lo < hi && hi - lo < along_size) {
                    return err(format!(
                        "yarns[{k}].extent: ({lo}, {hi}) is not a range shorter than the period {along_size}"
                    ));
                }
            }
            if y.finish as usize >= finishes.len() {
                return err(format!(
                    "yarns[{k}].finish: {} but {} finishes",
                    y.finish,
                    finishes.len()
                ));
            }
        }
        // Solids that do not overlap lie in two layers at most (warp over weft): their shadows
        // on the floor cover the period at most about twice. A description far beyond that is
        // not cloth, and would make the tracing grid's work unbounded.
        let shadow: f64 = yarns
            .iter()
            .map(|y| {
                let along = match y.along {
                    Along::Y => size.1,
                    Along::X => size.0,
                };
                2.0 * y.radius * y.extent.map_or(along, |(lo, hi)| hi - lo)
            })
            .sum();
        if shadow > 4.0 * size.0 * size.1 {
            return err(format!(
                "yarns: their footprints cover the period {:.1} times; yarns that do not overlap cover it at most about twice",
                shadow / (size.0 * size.1)
            ));
        }
        Ok(Period {
            size,
            yarns,
            finishes,
            facet,
        })
    }

    /// The period's size (Px, Py).
    pub fn size(&self) -> (f64, f64) {
        self.size
    }

    /// The yarn segments.
    pub fn yarns(&self) -> &[Yarn] {
        &self.yarns
    }

    /// The finishes the yarns index.
    pub fn finishes(&self) -> &[Finish] {
        &self.finishes
    }

    /// The facet terms the yarns are shaded with.
    pub fn facet(&self) -> Facet {
        self.facet
    }

    /// The highest point of any yarn above the floor (0 without yarns).
    pub fn top(&self) -> f64 {
        self.yarns
            .iter()
            .map(|y| y.height + y.radius)
            .fold(0.0, f64::max)
    }

    /// The height of the reference plane, the plane a renderer's mesh of the cloth stands for:
    /// halfway between the floor and the top of the highest yarn (docs/science/spatial.md, "The
    /// reference plane").
    pub fn reference_height(&self) -> f64 {
        0.5 * self.top()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finish() -> Finish {
        Finish {
            albedo: [0.5; 3],
            specular: 0.1,
            exponent: 10.0,
        }
    }

    fn yarn() -> Yarn {
        Yarn {
            along: Along::Y,
            across: 1.0,
            height: 0.0,
            radius: 0.5,
            extent: Some((0.5, 2.5)),
            finish: 0,
        }
    }

    #[test]
    fn the_constructor_refuses_what_cannot_be_traced() {
        let ok = |y: Yarn| Period::new((2.0, 3.0), vec![y], vec![finish()], Facet::Huo);
        assert!(ok(yarn()).is_ok());
        for (bad, field) in [
            (
                Yarn {
                    radius: 0.0,
                    ..yarn()
                },
                "radius",
            ),
            (
                Yarn {
                    radius: f64::NAN,
                    ..yarn()
                },
                "radius",
            ),
            (
                Yarn {
                    height: 0.5,
                    ..yarn()
                },
                "height",
            ),
            (
                Yarn {
                    across: 2.0,
                    ..yarn()
                },
                "across",
            ),
            (
                Yarn {
                    across: -0.1,
                    ..yarn()
                },
                "across",
            ),
            (
                Yarn {
                    extent: Some((1.0, 1.0)),
                    ..yarn()
                },
                "extent",
            ),
            (
                Yarn {
                    extent: Some((0.0, 3.0)),
                    ..yarn()
                },
                "extent",
            ),
            (
                Yarn {
                    extent: Some((0.0, f64::INFINITY)),
                    ..yarn()
                },
                "extent",
            ),
            (
                Yarn {
                    finish: 1,
                    ..yarn()
                },
                "finish",
            ),
        ] {
            let e = ok(bad).unwrap_err().0;
            assert!(e.contains(field), "{e}");
        }
        assert!(Period::new((0.0, 1.0), vec![], vec![], Facet::Huo).is_err());
        // A radius wider than the period, and yarns piled on one another, are not cloth.
        let fat = Yarn {
            radius: 1.5,
            height: 0.0,
            ..yarn()
        };
        assert!(ok(fat).unwrap_err().0.contains("half the period"));
        let pile = vec![
            Yarn {
                extent: None,
                ..yarn()
            };
            40
        ];
        let e = Period::new((2.0, 3.0), pile, vec![finish()], Facet::Huo).unwrap_err();
        assert!(e.0.contains("cover the period"), "{e}");
        let bad_finish = Finish {
            specular: 2.0,
            ..finish()
        };
        assert!(Period::new((1.0, 1.0), vec![], vec![bad_finish], Facet::Huo).is_err());
    }

    #[test]
    fn it_reads_back_what_it_writes_and_checks_what_it_reads() {
        let p = Period::new((2.0, 3.0), vec![yarn()], vec![finish()], Facet::Lewis).unwrap();
        let s = serde_json::to_string(&p).unwrap();
        assert_eq!(serde_json::from_str::<Period>(&s).unwrap(), p);
        let bad = s.replace("\"radius\":0.5", "\"radius\":-0.5");
        assert_ne!(bad, s);
        let e = serde_json::from_str::<Period>(&bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("radius"), "{e}");
        assert_eq!(p.reference_height(), 0.25);
    }
}
