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

fn weave_equal(w: &Weave, f: impl Fn(usize, usize) -> bool, sx: usize, sy: usize) -> bool {
    let (nx, ny) = (w.n_warp(), w.n_weft());
    (0..ny).all(|j| (0..nx).all(|i| f((i + sx) % nx, (j + sy) % ny) == w.warp_over(i, j)))
}

/// Every rotation s of `text` that equals `pattern`: text[(k + s) % n] == pattern[k] for all
/// k (Knuth-Morris-Pratt on the doubled text; equal lengths n). Linear in n.
fn rotations<T: PartialEq>(text: &[T], pattern: &[T]) -> Vec<usize> {
    let n = pattern.len();
    assert_eq!(text.len(), n);
    // fail[k]: length of the longest proper border of pattern[..=k].
    let mut fail = vec![0usize; n];
    let mut b = 0;
    for k in 1..n {
        while b > 0 && pattern[k] != pattern[b] {
            b = fail[b - 1];
        }
        if pattern[k] == pattern[b] {
            b += 1;
        }
        fail[k] = b;
    }
    let mut out = Vec::new();
    let mut q = 0;
    for i in 0..2 * n - 1 {
        let c = &text[i % n];
        while q > 0 && *c != pattern[q] {
            q = fail[q - 1];
        }
        if *c == pattern[q] {
            q += 1;
        }
        if q == n {
            out.push(i + 1 - n);
            q = fail[q - 1];
        }
    }
    out
}

/// Polynomial hashes modulo the Mersenne prime 2^61 - 1 of rows of cells, and of their
/// rotations in O(1): a filter before the exact comparison.
mod row_hash {
    const P: u64 = (1 << 61) - 1;
    const BASE: u64 = 0x1d8e_4e27_c47d_124f % P;

    fn mul(a: u64, b: u64) -> u64 {
        let x = u128::from(a) * u128::from(b);
        let s = (x as u64 & P) + (x >> 61) as u64;
        if s >= P {
            s - P
        } else {
            s
        }
    }

    /// Hash of the sequence of cells (each 1 or 2 for false or true).
    pub fn of(cells: impl Iterator<Item = bool>) -> u64 {
        cells.fold(0, |h, c| {
            let v = mul(h, BASE) + 1 + u64::from(c);
            if v >= P {
                v - P
            } else {
                v
            }
        })
    }

    /// Prefix hashes of rows read twice over, for the hash of any rotation.
    pub struct Rotations {
        n: usize,
        base_n: u64,
        prefix: Vec<u64>,
    }

    impl Rotations {
        /// Rows given as `rows` of `n` cells each (cell(row, i)).
        pub fn new(rows: usize, n: usize, cell: impl Fn(usize, usize) -> bool) -> Rotations {
            let mut prefix = Vec::with_capacity(rows * (2 * n + 1));
            for r in 0..rows {
                let mut h = 0;
                prefix.push(h);
                for i in 0..2 * n {
                    h = mul(h, BASE) + 1 + u64::from(cell(r, i % n));
                    if h >= P {
                        h -= P;
                    }
                    prefix.push(h);
                }
            }
            let base_n = (0..n).fold(1, |acc, _| mul(acc, BASE));
            Rotations { n, base_n, prefix }
        }

        /// Hash of row `r` rotated by `s`: cells s, s+1, ..., s+n-1 (mod n), as [`of`] gives.
        pub fn get(&self, r: usize, s: usize) -> u64 {
            let p = &self.prefix[r * (2 * self.n + 1)..];
            let hi = p[s + self.n];
            let lo = mul(p[s], self.base_n);
            if hi >= lo {
                hi - lo
            } else {
                hi + P - lo
            }
        }
    }
}

/// The symmetries (among mirror x, mirror y, rotation by 180 degrees) under which the fabric's
/// micro-geometry is invariant up to a translation by whole threads. Materials are per group,
/// except per-thread albedos, which are part of each [`Yarn`] and so must map onto each other too.
///
/// Linear in the period's cells: the translations that map the threads onto each other are
/// found by string matching, those that map the point paper's rows by matching row hashes, and
/// each translation found is confirmed cell by cell.
pub fn symmetries(fabric: &Fabric) -> Vec<Symmetry> {
    let w = &fabric.weave();
    let (nx, ny) = (w.n_warp(), w.n_weft());
    let (warp, weft) = (&fabric.warp().threads, &fabric.weft().threads);
    let (rwarp, rweft) = (reversed(warp), reversed(weft));
    let want: Vec<u64> = (0..ny)
        .map(|j| row_hash::of((0..nx).map(|i| w.warp_over(i, j))))
        .collect();
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
        // Translations mapping the threads: wx[(k + s) % n] == warp[k].
        let sxs = rotations(wx, warp);
        let mut sy_ok = vec![false; ny];
        for sy in rotations(wy, weft) {
            sy_ok[sy] = true;
        }
        if sxs.is_empty() || !sy_ok.contains(&true) {
            continue;
        }
        // Row j of the image shifted by sx must be row (j - sy) of the weave: the row hashes
        // of the shifted image are a rotation by sy of the weave's.
        let rows = row_hash::Rotations::new(ny, nx, |r, i| image(i, r));
        let found = sxs.into_iter().any(|sx| {
            let shifted: Vec<u64> = (0..ny).map(|j| rows.get(j, sx)).collect();
            rotations(&shifted, &want)
                .into_iter()
                .any(|sy| sy_ok[sy] && weave_equal(w, image, sx, sy))
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

    /// The definition, by brute force over every translation.
    fn brute_force(fabric: &Fabric) -> Vec<Symmetry> {
        let w = fabric.weave();
        let (nx, ny) = (w.n_warp(), w.n_weft());
        let (warp, weft) = (&fabric.warp().threads, &fabric.weft().threads);
        let shifted_equal = |a: &[Yarn], b: &[Yarn], s: usize| {
            let n = a.len();
            (0..n).all(|k| a[(k + s) % n] == b[k])
        };
        [Symmetry::MirrorX, Symmetry::MirrorY, Symmetry::Rotate180]
            .into_iter()
            .filter(|&sym| {
                let (fx, fy) = match sym {
                    Symmetry::MirrorX => (true, false),
                    Symmetry::MirrorY => (false, true),
                    Symmetry::Rotate180 => (true, true),
                };
                let wx = if fx { reversed(warp) } else { warp.clone() };
                let wy = if fy { reversed(weft) } else { weft.clone() };
                let image = |i: usize, j: usize| {
                    w.warp_over(
                        if fx { nx - 1 - i } else { i },
                        if fy { ny - 1 - j } else { j },
                    )
                };
                (0..nx).any(|sx| {
                    (0..ny).any(|sy| {
                        shifted_equal(&wx, warp, sx)
                            && shifted_equal(&wy, weft, sy)
                            && weave_equal(w, image, sx, sy)
                    })
                })
            })
            .collect()
    }

    #[test]
    fn rotations_by_string_matching() {
        assert_eq!(rotations(&[1, 2, 1, 2], &[2, 1, 2, 1]), vec![1, 3]);
        assert_eq!(rotations(&[5, 5, 5], &[5, 5, 5]), vec![0, 1, 2]);
        assert_eq!(rotations(&[1, 2, 3], &[1, 3, 2]), Vec::<usize>::new());
        assert_eq!(rotations(&[7], &[7]), vec![0]);
    }

    #[test]
    fn agrees_with_brute_force_on_random_small_periods() {
        // Random point papers, symmetric ones made by construction, and per-thread radii drawn
        // from two values: every outcome of every test.
        let mut rng = crate::rng::Rng::new(11);
        let mut seen = [0usize; 8];
        for case in 0..3000 {
            let nx = 1 + (rng.next_u64() % 6) as usize;
            let ny = 1 + (rng.next_u64() % 6) as usize;
            let mut rows: Vec<Vec<u8>> = (0..ny)
                .map(|_| (0..nx).map(|_| (rng.next_u64() % 2) as u8).collect())
                .collect();
            if case % 3 == 0 {
                // Mirror symmetric in x about a random axis.
                for r in &mut rows {
                    let orig = r.clone();
                    let s = (rng.next_u64() % nx as u64) as usize;
                    for i in 0..nx {
                        r[i] = orig[(2 * nx + s - i) % nx].max(orig[i]);
                    }
                    let fixed = r.clone();
                    for i in 0..nx {
                        r[(2 * nx + s - i) % nx] = fixed[i];
                    }
                }
            }
            let radii: Vec<String> = (0..nx)
                .map(|_| {
                    if rng.next_u64().is_multiple_of(4) {
                        "1.2"
                    } else {
                        "1.5"
                    }
                    .to_string()
                })
                .collect();
            let f = fabric(&format!("{rows:?}"), &format!("[{}]", radii.join(",")));
            let got = symmetries(&f);
            assert_eq!(got, brute_force(&f), "{rows:?} {radii:?}");
            let mask = got.iter().fold(0, |m, s| m | 1 << (*s as usize));
            seen[mask] += 1;
        }
        assert!(seen.iter().filter(|&&c| c > 0).count() >= 4, "{seen:?}");
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
