//! The MERL BRDF database's binary (Matusik et al. 2003): an isotropic BRDF on 90 x 90 x 180
//! cells of (theta_h, theta_d, phi_d), Rusinkiewicz's half/difference angles.
//!
//! File: three little-endian i32 dimensions (90, 90, 180), then 3 x 1 458 000 doubles: the red,
//! green and blue blocks, each indexed `phi_d + 180 (theta_d + 90 theta_h)`; a stored value times
//! the channel's scale (1/1500, 1.15/1500, 1.66/1500) is f_r in 1/sr. Readers find the cell by
//! truncation: theta_h index = floor(90 sqrt(theta_h / (pi/2))), theta_d index = floor(90 theta_d
//! / (pi/2)), phi_d index = floor(180 phi_d / pi) after phi_d < 0 is moved up by pi (reciprocity).
//!
//! The format is isotropic; cloth is not. Each cell holds f_r averaged over rotations about the
//! normal (phi_h, `phi_samples` equally spaced angles) and symmetrised over swapping light and
//! eye (phi_d and phi_d + pi share a cell). It is evaluated at the cell's centre in the readers'
//! index space. What the average loses is reported as [`Anisotropy`].

use super::{luminance, Bsdf};
use clothbake_core::{UnitVec3, Vec3};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Cells in theta_h.
pub const N_THETA_H: usize = 90;
/// Cells in theta_d.
pub const N_THETA_D: usize = 90;
/// Cells in phi_d (over [0, pi)).
pub const N_PHI_D: usize = 180;
/// Cells per channel.
pub const N_CELLS: usize = N_THETA_H * N_THETA_D * N_PHI_D;
/// Stored value times this is f_r (red, green, blue).
pub const SCALE: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];

/// The (theta_h, theta_d, phi_d) of cell (ih, id, ip): the centre of the cell in the readers'
/// index space (theta_h = ((ih + 1/2) / 90)^2 pi/2: the square-root mapping).
pub fn cell_angles(ih: usize, id: usize, ip: usize) -> (f64, f64, f64) {
    let uh = (ih as f64 + 0.5) / N_THETA_H as f64;
    (
        uh * uh * PI / 2.0,
        (id as f64 + 0.5) / N_THETA_D as f64 * PI / 2.0,
        (ip as f64 + 0.5) / N_PHI_D as f64 * PI,
    )
}

/// The (light, eye) pair of half/difference angles: the half vector h at (theta_h, phi_h); the
/// light is the difference vector (theta_d, phi_d) turned from +Z to h (by theta_h about +Y,
/// then phi_h about +Z); the eye is its mirror image about h.
pub fn half_diff_to_pair(theta_h: f64, phi_h: f64, theta_d: f64, phi_d: f64) -> (Vec3, Vec3) {
    let (sd, cd) = theta_d.sin_cos();
    let d = Vec3::new(sd * phi_d.cos(), sd * phi_d.sin(), cd);
    let (sh, ch) = theta_h.sin_cos();
    let y = Vec3::new(d.x * ch + d.z * sh, d.y, -d.x * sh + d.z * ch);
    let (sp, cp) = phi_h.sin_cos();
    let wi = Vec3::new(y.x * cp - y.y * sp, y.x * sp + y.y * cp, y.z);
    let h = Vec3::new(sh * cp, sh * sp, ch);
    let wo = h * (2.0 * wi.dot(h)) - wi;
    (wi, wo)
}

/// The rotation-averaged, reciprocity-symmetrised f_r of one cell, and the relative standard
/// deviation of the luminance over phi_h (0 where the mean is 0). The average is over
/// `phi_samples` angles phi_h = 2 pi s / phi_samples; with `half_turn` (the BRDF is unchanged by
/// a rotation by pi about the normal, e.g. `Symmetry::Rotate180` of the fabric) and an even
/// count only the first half is evaluated: the second repeats it.
pub fn cell_value(
    brdf: &dyn Bsdf,
    angles: (f64, f64, f64),
    phi_samples: usize,
    half_turn: bool,
) -> ([f64; 3], f64) {
    let (th, td, pd) = angles;
    let (a, b) = half_diff_to_pair(th, 0.0, td, pd);
    if a.z <= clothbake_core::vec3::HORIZON_COS || b.z <= clothbake_core::vec3::HORIZON_COS {
        return ([0.0; 3], 0.0);
    }
    let evaluated = if half_turn && phi_samples.is_multiple_of(2) {
        phi_samples / 2
    } else {
        phi_samples
    };
    // Both orders of every rotation's pair, evaluated in one batch: (a, b), (b, a), ...
    let mut pairs = Vec::with_capacity(2 * evaluated);
    for s in 0..evaluated {
        let ph = 2.0 * PI * s as f64 / phi_samples as f64;
        let (a, b) = half_diff_to_pair(th, ph, td, pd);
        let (Some(a), Some(b)) = (UnitVec3::new(a), UnitVec3::new(b)) else {
            continue;
        };
        pairs.extend([(a, b), (b, a)]);
    }
    let mut fs = vec![[0.0; 3]; pairs.len()];
    brdf.f_batch(&pairs, &mut fs);
    let mut sum = [0.0; 3];
    let (mut s1, mut s2) = (0.0, 0.0);
    for fg in fs.chunks_exact(2) {
        let (f, g) = (fg[0], fg[1]);
        let v: [f64; 3] = std::array::from_fn(|c| 0.5 * (f[c] + g[c]));
        for c in 0..3 {
            sum[c] += v[c];
        }
        let y = luminance(v);
        s1 += y;
        s2 += y * y;
    }
    let n = evaluated as f64;
    let mean = s1 / n;
    let rel_std = if mean > 0.0 {
        ((s2 / n - mean * mean).max(0.0)).sqrt() / mean
    } else {
        0.0
    };
    (sum.map(|x| x / n), rel_std)
}

/// What averaging over rotations about the normal loses: the relative standard deviation of
/// the luminance over phi_h, per cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anisotropy {
    /// Sum over cells of the standard deviation / sum of the means (the luminance-weighted
    /// relative spread).
    pub weighted: f64,
    /// Largest relative spread of a cell whose mean is at least 1% of the largest mean.
    pub max: f64,
}

/// An upper bound on the memory a MERL export takes besides the program, in bytes, with
/// `threads` workers averaging `phi_samples` rotations: the cells' values and spreads as the
/// rows are collected (32 bytes a cell), the table (24 bytes a cell), the file's bytes (24 bytes
/// a cell) and each worker's pairs of one cell (72 bytes a pair, two pairs a rotation).
pub fn peak_bytes(phi_samples: usize, threads: usize) -> u64 {
    let cells = N_CELLS as u64;
    let workers = (threads.max(1) as u64).min(N_THETA_H as u64);
    80 * cells + 12 + workers * 2 * 72 * phi_samples as u64
}

/// A MERL table: f_r per cell and channel (index `c * N_CELLS + cell`) and the anisotropy lost.
#[derive(Clone, Debug)]
pub struct MerlTable {
    /// f_r in 1/sr: red block, green block, blue block, each in the file's cell order.
    pub values: Vec<f64>,
    /// The spread over phi_h that the isotropic table cannot hold.
    pub anisotropy: Anisotropy,
}

/// Tabulates `brdf` (rows of theta_h in parallel on the current rayon pool, collected in order:
/// deterministic). `phi_samples` >= 1 rotations are averaged per cell; `half_turn` as in
/// [`cell_value`].
pub fn merl_table(brdf: &dyn Bsdf, phi_samples: usize, half_turn: bool) -> MerlTable {
    assert!(phi_samples >= 1);
    let rows: Vec<Vec<([f64; 3], f64)>> = (0..N_THETA_H)
        .into_par_iter()
        .map(|ih| {
            let mut row = Vec::with_capacity(N_THETA_D * N_PHI_D);
            for id in 0..N_THETA_D {
                for ip in 0..N_PHI_D {
                    row.push(cell_value(
                        brdf,
                        cell_angles(ih, id, ip),
                        phi_samples,
                        half_turn,
                    ));
                }
            }
            row
        })
        .collect();
    let mut values = vec![0.0; 3 * N_CELLS];
    let (mut sum_std, mut sum_mean, mut peak) = (0.0, 0.0, 0.0f64);
    for (i, &(v, _)) in rows.iter().flatten().enumerate() {
        for c in 0..3 {
            values[c * N_CELLS + i] = v[c];
        }
        peak = peak.max(luminance(v));
    }
    let mut max: f64 = 0.0;
    for &(v, rel) in rows.iter().flatten() {
        let y = luminance(v);
        sum_std += rel * y;
        sum_mean += y;
        if y >= 0.01 * peak && y > 0.0 {
            max = max.max(rel);
        }
    }
    MerlTable {
        values,
        anisotropy: Anisotropy {
            weighted: if sum_mean > 0.0 {
                sum_std / sum_mean
            } else {
                0.0
            },
            max,
        },
    }
}

/// The file's bytes: the three i32 dimensions, then the doubles f_r / scale per channel.
pub fn merl_bytes(t: &MerlTable) -> Vec<u8> {
    let mut out = Vec::with_capacity(12 + 8 * t.values.len());
    for d in [N_THETA_H, N_THETA_D, N_PHI_D] {
        out.extend_from_slice(&(d as i32).to_le_bytes());
    }
    for (i, v) in t.values.iter().enumerate() {
        out.extend_from_slice(&(v / SCALE[i / N_CELLS]).to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_diff_round_trip() {
        // The pair's half vector is at (theta_h, phi_h) and the light makes theta_d with it.
        let (th, ph, td, pd) = (0.4, 1.1, 0.3, 2.0);
        let (wi, wo) = half_diff_to_pair(th, ph, td, pd);
        let h = wi + wo;
        let h = h * (1.0 / h.length());
        assert!((h.z.acos() - th).abs() < 1e-12);
        assert!((h.y.atan2(h.x) - ph).abs() < 1e-12);
        assert!((wi.dot(h).acos() - td).abs() < 1e-12);
        assert!((wi.length() - 1.0).abs() < 1e-12 && (wo.length() - 1.0).abs() < 1e-12);
        // theta_h = 0: the difference vector is the light itself.
        let (wi, _) = half_diff_to_pair(0.0, 0.0, td, pd);
        assert!((wi.x - td.sin() * pd.cos()).abs() < 1e-12);
    }

    #[test]
    fn isotropic_brdf_has_no_spread() {
        let brdf = clothbake_core::FromFn(|wi: UnitVec3, wo: UnitVec3| {
            let c = wi.cos_theta() * wo.cos_theta();
            [c, 2.0 * c, 0.5]
        });
        let (v, rel) = cell_value(&brdf, cell_angles(30, 20, 50), 12, false);
        assert!(rel < 1e-12, "{rel}");
        let (a, b) = half_diff_to_pair(
            cell_angles(30, 20, 50).0,
            0.0,
            cell_angles(30, 20, 50).1,
            cell_angles(30, 20, 50).2,
        );
        assert!((v[0] - a.z * b.z).abs() < 1e-12);
    }

    #[test]
    fn half_turn_symmetry_halves_the_work_not_the_result() {
        // Invariant under (x, y) -> (-x, -y), anisotropic otherwise.
        let brdf = clothbake_core::FromFn(|wi: UnitVec3, wo: UnitVec3| {
            let v = (wi.x + wo.x).powi(2) + 0.3 * wi.x * wo.y;
            [1.0 + v, 2.0, 0.5 + wi.y * wo.y]
        });
        for cell in [(10, 5, 7), (40, 30, 100), (70, 10, 179)] {
            let a = cell_angles(cell.0, cell.1, cell.2);
            let (full, rf) = cell_value(&brdf, a, 16, false);
            let (half, rh) = cell_value(&brdf, a, 16, true);
            // The test BRDF is anisotropic in every cell (less so near theta_h = 0), so the
            // comparison below is not between two constants.
            assert!(rf > 1e-4, "{rf}");
            assert!((rf - rh).abs() < 1e-12);
            for c in 0..3 {
                assert!((full[c] - half[c]).abs() < 1e-12 * full[c].abs().max(1.0));
            }
        }
    }
}
