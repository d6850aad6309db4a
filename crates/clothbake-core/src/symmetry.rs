//! Exact symmetries of a fabric's micro-geometry, which the BRDF inherits:
//! if the geometry is invariant under a map M of the plane (up to a translation), then
//! f(M wi, M wo) = f(wi, wo) for the model and the ground truth alike.

use crate::fabric::{Fabric, Yarn};
use crate::vec3::UnitVec3;
use crate::weave::Weave;

/// A symmetry of the plane that can map a weave onto itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Symmetry {
    /// x -> -x: azimuth phi -> pi - phi.
    MirrorX,
    /// y -> -y: azimuth phi -> -phi.
    MirrorY,
    /// (x, y) -> (-x, -y): azimuth phi -> phi + pi.
    Rotate180,
}

impl Symmetry {
    /// Human-readable name.
    pub fn name(self) -> &'static str {
        match self {
            Symmetry::MirrorX => "mirror x",
            Symmetry::MirrorY => "mirror y",
            Symmetry::Rotate180 => "rotate 180",
        }
    }

    /// The map applied to a direction.
    pub fn apply(self, v: UnitVec3) -> UnitVec3 {
        match self {
            Symmetry::MirrorX => v.mirror_x(),
            Symmetry::MirrorY => v.mirror_y(),
            Symmetry::Rotate180 => v.mirror_x().mirror_y(),
        }
    }

    /// The map on the indices of a cell-centred azimuth grid of `n` cells
    /// (phi_k = (k + 1/2) 2 pi / n); `None` where it does not map cells onto cells (odd `n`).
    pub fn phi_index(self, k: usize, n: usize) -> Option<usize> {
        match self {
            Symmetry::MirrorY => Some(n - 1 - k),
            _ if n % 2 == 1 => None,
            Symmetry::MirrorX => Some((n / 2 + n - 1 - k) % n),
            Symmetry::Rotate180 => Some((k + n / 2) % n),
        }
    }
}

/// One group's threads in order of position, with the spacing to the next one.
fn reversed(threads: &[Yarn]) -> Vec<Yarn> {
    let n = threads.len();
    (0..n)
        .map(|k| {
            let old = n - 1 - k;
            // The gap after new thread k is the gap before old thread `old`.
            let spacing = threads[(old + n - 1) % n].spacing;
            Yarn {
                spacing,
                ..threads[old]
            }
        })
        .collect()
}

fn shifted_equal(a: &[Yarn], b: &[Yarn], s: usize) -> bool {
    let n = a.len();
    (0..n).all(|k| a[(k + s) % n] == b[k])
}

fn weave_equal(w: &Weave, f: impl Fn(usize, usize) -> bool, sx: usize, sy: usize) -> bool {
    let (nx, ny) = (w.n_warp(), w.n_weft());
    (0..ny).all(|j| (0..nx).all(|i| f((i + sx) % nx, (j + sy) % ny) == w.warp_over(i, j)))
}

/// The symmetries (among mirror x, mirror y, rotation by 180 degrees) under which the fabric's
/// micro-geometry is invariant up to a translation by whole threads. Materials are per group,
/// except per-thread albedos, which are part of each [`Yarn`] and so must map onto each other too.
pub fn symmetries(fabric: &Fabric) -> Vec<Symmetry> {
    let w = &fabric.weave();
    let (nx, ny) = (w.n_warp(), w.n_weft());
    let (warp, weft) = (&fabric.warp().threads, &fabric.weft().threads);
    let (rwarp, rweft) = (reversed(warp), reversed(weft));
    let mut out = Vec::new();
    for sym in [Symmetry::MirrorX, Symmetry::MirrorY, Symmetry::Rotate180] {
        let (fx, fy) = match sym {
            Symmetry::MirrorX => (true, false),
            Symmetry::MirrorY => (false, true),
            Symmetry::Rotate180 => (true, true),
        };
        let (wx, wy) = (
            if fx { &rwarp } else { warp },
            if fy { &rweft } else { weft },
        );
        // Transformed weave: cell (i, j) of the image comes from (i', j') of the original.
        let image = |i: usize, j: usize| {
            let i0 = if fx { nx - 1 - i } else { i };
            let j0 = if fy { ny - 1 - j } else { j };
            w.warp_over(i0, j0)
        };
        let found = (0..nx).any(|sx| {
            shifted_equal(wx, warp, sx)
                && (0..ny).any(|sy| shifted_equal(wy, weft, sy) && weave_equal(w, image, sx, sy))
        });
        if found {
            out.push(sym);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::AnalyticModel;
    use crate::facet::FacetModel;

    fn fabric(pattern: &str, warp_r: &str) -> Fabric {
        Fabric::from_json_str(
            &format!(
                r#"{{"pattern": {pattern}, "warp": {{"radius": {warp_r}, "spacing": 3.1}},
                    "weft": {{"radius": 1.5, "spacing": 3.1}}}}"#
            ),
            "t",
        )
        .unwrap()
    }

    #[test]
    fn known_weaves() {
        let plain = fabric("[[1,0],[0,1]]", "1.5");
        assert_eq!(
            symmetries(&plain),
            vec![Symmetry::MirrorX, Symmetry::MirrorY, Symmetry::Rotate180]
        );
        let twill = fabric("[[1,1,0],[0,1,1],[1,0,1]]", "1.5");
        assert_eq!(symmetries(&twill), vec![Symmetry::Rotate180]);
        // Unequal warp radii in a non-palindromic order break the mirror in x.
        let odd = fabric("[[1,1,1],[1,1,1]]", "[1.0, 1.2, 1.4]");
        assert_eq!(symmetries(&odd), vec![Symmetry::MirrorY]);
        // So do unequal per-thread colours: they are part of each thread.
        let striped = fabric("[[1,1,1],[1,1,1]]", "1.5")
            .with_groups(
                |g, yarns| {
                    if g == crate::Group::Warp {
                        for (y, a) in yarns.threads.iter_mut().zip([0.1, 0.2, 0.3]) {
                            y.albedo = Some([a; 3]);
                        }
                    }
                },
                &crate::PlainNaming("striped"),
            )
            .unwrap();
        assert_eq!(symmetries(&striped), vec![Symmetry::MirrorY]);
    }

    #[test]
    fn detected_symmetries_hold_for_the_model() {
        let twill = fabric("[[1,1,0],[0,1,1],[1,0,1]]", "1.5");
        let m = AnalyticModel::new(&twill, FacetModel::Huo);
        let (wi, wo) = (
            UnitVec3::from_degrees(50.0, 20.0),
            UnitVec3::from_degrees(35.0, 200.0),
        );
        let a = m.intensity(wi, wo).total();
        let s = Symmetry::Rotate180;
        let b = m.intensity(s.apply(wi), s.apply(wo)).total();
        assert!((a[0] - b[0]).abs() < 1e-12);
        // ... and a mirror it does not have really changes the result somewhere.
        let worst = (0..40)
            .map(|k| {
                let wi = UnitVec3::from_degrees(10.0 + k as f64 * 1.7, k as f64 * 37.0);
                let wo = UnitVec3::from_degrees(60.0 - k as f64 * 1.1, 90.0 + k as f64 * 53.0);
                let x = m.intensity(wi, wo).total()[0];
                let y = m.intensity(wi.mirror_x(), wo.mirror_x()).total()[0];
                (x - y).abs() / x
            })
            .fold(0.0, f64::max);
        assert!(worst > 1e-2, "{worst}");
    }

    #[test]
    fn phi_index_maps_cell_centres() {
        let n = 8;
        for s in [Symmetry::MirrorX, Symmetry::MirrorY, Symmetry::Rotate180] {
            for k in 0..n {
                let phi = (k as f64 + 0.5) * 360.0 / n as f64;
                let v = s.apply(UnitVec3::from_degrees(45.0, phi));
                let (_, p) = v.to_spherical();
                let want =
                    (p.to_degrees().rem_euclid(360.0) / (360.0 / n as f64) - 0.5).round() as usize;
                assert_eq!(s.phi_index(k, n), Some(want % n), "{s:?} {k}");
            }
        }
        assert_eq!(Symmetry::MirrorX.phi_index(0, 7), None);
    }
}
