//! RGB to spectrum, for the spectral flavour of the RGL `.bsdf` (pbrt-v4, Mitsuba 3's spectral
//! variants). The model's colours are linear sRGB (Rec. 709 primaries, D65 white); a renderer
//! that works in wavelengths needs a spectrum per channel value. This module upsamples linearly:
//!
//! s(lambda) = r B_r(lambda) + g B_g(lambda) + b B_b(lambda)
//!
//! with three fixed basis spectra B_c on the nodes [`WAVELENGTHS`] (piecewise linear between
//! them, as both readers interpolate). They are a smooth partition of unity (logistic steps at
//! 490 and 590 nm, 10 nm wide) made exact by the inverse of its own 3 x 3 projection matrix, so
//! that [`project`] of `B_c` is the unit vector e_c: every upsampled spectrum projects back to
//! the RGB it came from (to the quadrature's ~1e-6), and white (1, 1, 1) becomes the flat
//! spectrum 1 (to 1e-4). The projection is the one a spectral renderer uses to show a
//! reflectance under its white light: the CIE 1931 2-degree colour matching functions times the
//! D65 illuminant, integrated over 360-830 nm, normalised so that Y(1) = 1, then the XYZ to
//! linear sRGB matrix. Docs: `docs/guide/export.md` ("Spectral files").
//!
//! Because the upsampling is linear, upsampling a BRDF's RGB output equals evaluating the model
//! with the upsampled albedos wavelength by wavelength wherever the model is linear in its
//! colours (direct reflection; see the tests).

/// The spectral nodes written to a spectral `.bsdf` (`wavelengths`, nm): 360 to 840 in 20 nm
/// steps. Both readers sample 360-830 nm and interpolate linearly between nodes.
pub const WAVELENGTHS: [f64; 25] = {
    let mut w = [0.0; 25];
    let mut k = 0;
    while k < 25 {
        w[k] = 360.0 + 20.0 * k as f64;
        k += 1;
    }
    w
};

/// The range the renderers sample and the CIE tables cover, nm.
pub const VISIBLE_NM: (f64, f64) = (360.0, 830.0);

/// CIE 1931 2-degree colour matching functions x, y, z and the CIE standard illuminant D65
/// (relative, 100 at 560 nm), every 5 nm from 360 to 830 nm. Sources: the CIE's tables as
/// published by the Colour & Vision Research Laboratory (cvrl.org, `ciexyz31`, 5 nm rows of the
/// 1 nm table) and CIE S 014-2 (D65).
const CIE_XYZ_D65: [[f64; 4]; 95] = [
    [0.0001299, 3.917e-06, 0.0006061, 46.6383],   // 360
    [0.0002321, 6.965e-06, 0.001086, 49.3637],    // 365
    [0.0004149, 1.239e-05, 0.001946, 52.0891],    // 370
    [0.0007416, 2.202e-05, 0.003486, 51.0323],    // 375
    [0.001368, 3.9e-05, 0.006450001, 49.9755],    // 380
    [0.002236, 6.4e-05, 0.01054999, 52.3118],     // 385
    [0.004243, 0.00012, 0.02005001, 54.6482],     // 390
    [0.00765, 0.000217, 0.03621, 68.7015],        // 395
    [0.01431, 0.000396, 0.06785001, 82.7549],     // 400
    [0.02319, 0.00064, 0.1102, 87.1204],          // 405
    [0.04351, 0.00121, 0.2074, 91.486],           // 410
    [0.07763, 0.00218, 0.3713, 92.4589],          // 415
    [0.13438, 0.004, 0.6456, 93.4318],            // 420
    [0.21477, 0.0073, 1.0390501, 90.057],         // 425
    [0.2839, 0.0116, 1.3856, 86.6823],            // 430
    [0.3285, 0.01684, 1.62296, 95.7736],          // 435
    [0.34828, 0.023, 1.74706, 104.865],           // 440
    [0.34806, 0.0298, 1.7826, 110.936],           // 445
    [0.3362, 0.038, 1.77211, 117.008],            // 450
    [0.3187, 0.048, 1.7441, 117.41],              // 455
    [0.2908, 0.06, 1.6692, 117.812],              // 460
    [0.2511, 0.0739, 1.5281, 116.336],            // 465
    [0.19536, 0.09098, 1.28764, 114.861],         // 470
    [0.1421, 0.1126, 1.0419, 115.392],            // 475
    [0.09564, 0.13902, 0.8129501, 115.923],       // 480
    [0.05795001, 0.1693, 0.6162, 112.367],        // 485
    [0.03201, 0.20802, 0.46518, 108.811],         // 490
    [0.0147, 0.2586, 0.3533, 109.082],            // 495
    [0.0049, 0.323, 0.272, 109.354],              // 500
    [0.0024, 0.4073, 0.2123, 108.578],            // 505
    [0.0093, 0.503, 0.1582, 107.802],             // 510
    [0.0291, 0.6082, 0.1117, 106.296],            // 515
    [0.06327, 0.71, 0.07824999, 104.79],          // 520
    [0.1096, 0.7932, 0.05725001, 106.239],        // 525
    [0.1655, 0.862, 0.04216, 107.689],            // 530
    [0.2257499, 0.9148501, 0.02984, 106.047],     // 535
    [0.2904, 0.954, 0.0203, 104.405],             // 540
    [0.3597, 0.9803, 0.0134, 104.225],            // 545
    [0.4334499, 0.9949501, 0.008749999, 104.046], // 550
    [0.5120501, 1.0, 0.005749999, 102.023],       // 555
    [0.5945, 0.995, 0.0039, 100.0],               // 560
    [0.6784, 0.9786, 0.002749999, 98.1671],       // 565
    [0.7621, 0.952, 0.0021, 96.3342],             // 570
    [0.8425, 0.9154, 0.0018, 96.0611],            // 575
    [0.9163, 0.87, 0.001650001, 95.788],          // 580
    [0.9786, 0.8163, 0.0014, 92.2368],            // 585
    [1.0263, 0.757, 0.0011, 88.6856],             // 590
    [1.0567, 0.6949, 0.001, 89.3459],             // 595
    [1.0622, 0.631, 0.0008, 90.0062],             // 600
    [1.0456, 0.5668, 0.0006, 89.8026],            // 605
    [1.0026, 0.503, 0.00034, 89.5991],            // 610
    [0.9384, 0.4412, 0.00024, 88.6489],           // 615
    [0.8544499, 0.381, 0.00019, 87.6987],         // 620
    [0.7514, 0.321, 0.0001, 85.4936],             // 625
    [0.6424, 0.265, 4.999999e-05, 83.2886],       // 630
    [0.5419, 0.217, 3e-05, 83.4939],              // 635
    [0.4479, 0.175, 2e-05, 83.6992],              // 640
    [0.3608, 0.1382, 1e-05, 81.863],              // 645
    [0.2835, 0.107, 0.0, 80.0268],                // 650
    [0.2187, 0.0816, 0.0, 80.1207],               // 655
    [0.1649, 0.061, 0.0, 80.2146],                // 660
    [0.1212, 0.04458, 0.0, 81.2462],              // 665
    [0.0874, 0.032, 0.0, 82.2778],                // 670
    [0.0636, 0.0232, 0.0, 80.281],                // 675
    [0.04677, 0.017, 0.0, 78.2842],               // 680
    [0.0329, 0.01192, 0.0, 74.0027],              // 685
    [0.0227, 0.00821, 0.0, 69.7213],              // 690
    [0.01584, 0.005723, 0.0, 70.6652],            // 695
    [0.01135916, 0.004102, 0.0, 71.6091],         // 700
    [0.008110916, 0.002929, 0.0, 72.979],         // 705
    [0.005790346, 0.002091, 0.0, 74.349],         // 710
    [0.004109457, 0.001484, 0.0, 67.9765],        // 715
    [0.002899327, 0.001047, 0.0, 61.604],         // 720
    [0.00204919, 0.00074, 0.0, 65.7448],          // 725
    [0.001439971, 0.00052, 0.0, 69.8856],         // 730
    [0.0009999493, 0.0003611, 0.0, 72.4863],      // 735
    [0.0006900786, 0.0002492, 0.0, 75.087],       // 740
    [0.0004760213, 0.0001719, 0.0, 69.3398],      // 745
    [0.0003323011, 0.00012, 0.0, 63.5927],        // 750
    [0.0002348261, 8.48e-05, 0.0, 55.0054],       // 755
    [0.0001661505, 6e-05, 0.0, 46.4182],          // 760
    [0.000117413, 4.24e-05, 0.0, 56.6118],        // 765
    [8.307527e-05, 3e-05, 0.0, 66.8054],          // 770
    [5.870652e-05, 2.12e-05, 0.0, 65.0941],       // 775
    [4.150994e-05, 1.499e-05, 0.0, 63.3828],      // 780
    [2.935326e-05, 1.06e-05, 0.0, 63.8434],       // 785
    [2.067383e-05, 7.4657e-06, 0.0, 64.304],      // 790
    [1.455977e-05, 5.2578e-06, 0.0, 61.8779],     // 795
    [1.025398e-05, 3.7029e-06, 0.0, 59.4519],     // 800
    [7.221456e-06, 2.6078e-06, 0.0, 55.7054],     // 805
    [5.085868e-06, 1.8366e-06, 0.0, 51.959],      // 810
    [3.581652e-06, 1.2934e-06, 0.0, 54.6998],     // 815
    [2.522525e-06, 9.1093e-07, 0.0, 57.4406],     // 820
    [1.776509e-06, 6.4153e-07, 0.0, 58.8765],     // 825
    [1.251141e-06, 4.5181e-07, 0.0, 60.3125],     // 830
];

/// XYZ (D65 white) to linear sRGB: the Rec. 709 primaries' matrix, to the 7 digits Mitsuba 3
/// uses (its `xyz_to_srgb`).
pub const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.240479, -1.537150, -0.498535],
    [-0.969256, 1.875991, 0.041556],
    [0.055648, -0.204043, 1.057311],
];

/// x, y, z and D65 at `lambda` nm: linear interpolation of the 5 nm tables, zero outside
/// 360-830 nm.
pub fn cie_xyz_d65(lambda: f64) -> [f64; 4] {
    let t = (lambda - VISIBLE_NM.0) / 5.0;
    if !(0.0..=94.0).contains(&t) {
        return [0.0; 4];
    }
    let i = (t.floor() as usize).min(93);
    let f = t - i as f64;
    std::array::from_fn(|k| CIE_XYZ_D65[i][k] * (1.0 - f) + CIE_XYZ_D65[i + 1][k] * f)
}

/// A spectrum given at increasing `nodes` (nm) read the way the `.bsdf` readers read it:
/// linear between nodes, the end values held beyond them.
pub fn interpolate(nodes: &[f64], values: &[f64], lambda: f64) -> f64 {
    debug_assert_eq!(nodes.len(), values.len());
    let n = nodes.len();
    if lambda <= nodes[0] {
        return values[0];
    }
    if lambda >= nodes[n - 1] {
        return values[n - 1];
    }
    let j = nodes.partition_point(|&x| x <= lambda).clamp(1, n - 1) - 1;
    let f = (lambda - nodes[j]) / (nodes[j + 1] - nodes[j]);
    values[j] * (1.0 - f) + values[j + 1] * f
}

/// Quadrature step of [`project`], nm (trapezoid rule over 360-830 nm).
const STEP_NM: f64 = 0.5;

/// The linear sRGB colour of a reflectance spectrum (given at `nodes`, read as
/// [`interpolate`] reads it) under D65: XYZ_TO_SRGB . (integral of (x, y, z) D65 s) / (integral
/// of y D65). A flat spectrum 1 gives (1, 1, 1) to 1e-4.
pub fn project(nodes: &[f64], values: &[f64]) -> [f64; 3] {
    let n = ((VISIBLE_NM.1 - VISIBLE_NM.0) / STEP_NM).round() as usize;
    let (mut xyz, mut y_white) = ([0.0; 3], 0.0);
    for i in 0..=n {
        let lambda = VISIBLE_NM.0 + i as f64 * STEP_NM;
        let w = if i == 0 || i == n { 0.5 } else { 1.0 };
        let c = cie_xyz_d65(lambda);
        let s = interpolate(nodes, values, lambda);
        for k in 0..3 {
            xyz[k] += w * c[k] * c[3] * s;
        }
        y_white += w * c[1] * c[3];
    }
    std::array::from_fn(|r| (0..3).map(|k| XYZ_TO_SRGB[r][k] * xyz[k]).sum::<f64>() / y_white)
}

/// The linear RGB-to-spectrum map on [`WAVELENGTHS`] (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Upsampling {
    /// Per node, the basis spectra's values (B_r, B_g, B_b).
    basis: Vec<[f64; 3]>,
}

/// Where the smooth partition of unity steps from blue to green and from green to red, and the
/// logistic width, nm.
const STEPS_NM: (f64, f64, f64) = (490.0, 590.0, 10.0);

impl Default for Upsampling {
    fn default() -> Self {
        Self::new()
    }
}

impl Upsampling {
    /// The basis: the partition of unity S = (red, green, blue) (logistic steps, `STEPS_NM`),
    /// times the inverse of P, P's column c being the projection of S_c.
    pub fn new() -> Upsampling {
        let (l1, l2, w) = STEPS_NM;
        let logistic = |x: f64| 1.0 / (1.0 + (-x).exp());
        let s: Vec<[f64; 3]> = WAVELENGTHS
            .iter()
            .map(|&l| {
                let (b, r) = (1.0 - logistic((l - l1) / w), logistic((l - l2) / w));
                [r, 1.0 - r - b, b]
            })
            .collect();
        let cols: Vec<[f64; 3]> = (0..3)
            .map(|c| project(&WAVELENGTHS, &s.iter().map(|v| v[c]).collect::<Vec<_>>()))
            .collect();
        let p: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| cols[c][r]));
        let q = inverse(p);
        let basis = s
            .iter()
            .map(|v| std::array::from_fn(|d| (0..3).map(|c| v[c] * q[c][d]).sum()))
            .collect();
        Upsampling { basis }
    }

    /// Per node of [`WAVELENGTHS`], (B_r, B_g, B_b).
    pub fn basis(&self) -> &[[f64; 3]] {
        &self.basis
    }

    /// The spectrum of `rgb` on [`WAVELENGTHS`].
    pub fn spectrum(&self, rgb: [f64; 3]) -> Vec<f64> {
        self.basis
            .iter()
            .map(|b| b[0] * rgb[0] + b[1] * rgb[1] + b[2] * rgb[2])
            .collect()
    }
}

/// The inverse of a well-conditioned 3 x 3 matrix (adjugate over determinant).
fn inverse(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let c = |r: usize, k: usize| {
        let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
        let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
        m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
    };
    let det: f64 = (0..3).map(|k| m[0][k] * c(0, k)).sum();
    std::array::from_fn(|r| std::array::from_fn(|k| c(k, r) / det))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_under_d65_is_white() {
        // The tables and the matrix together: D65's own chromaticity maps to (1, 1, 1).
        let w = project(&WAVELENGTHS, &[1.0; 25]);
        for c in w {
            assert!((c - 1.0).abs() < 2e-4, "{w:?}");
        }
    }

    #[test]
    fn the_d65_white_point_is_the_cie_one() {
        // x, y chromaticity of D65 from the 5 nm tables: CIE 015 gives (0.31272, 0.32903) for
        // the 1931 observer.
        let (mut x, mut y, mut z) = (0.0, 0.0, 0.0);
        for l in 0..=470 {
            let c = cie_xyz_d65(360.0 + l as f64);
            x += c[0] * c[3];
            y += c[1] * c[3];
            z += c[2] * c[3];
        }
        let (cx, cy) = (x / (x + y + z), y / (x + y + z));
        assert!(
            (cx - 0.31272).abs() < 2e-4 && (cy - 0.32903).abs() < 2e-4,
            "{cx} {cy}"
        );
    }

    #[test]
    fn upsampled_spectra_project_back_and_white_is_flat() {
        let up = Upsampling::new();
        for rgb in [
            [0.6, 0.3, 0.12],
            [0.05, 0.1, 0.4],
            [1.0, 1.0, 1.0],
            [0.2, 0.8, 0.1],
        ] {
            let back = project(&WAVELENGTHS, &up.spectrum(rgb));
            for c in 0..3 {
                assert!((back[c] - rgb[c]).abs() < 1e-9, "{rgb:?} -> {back:?}");
            }
        }
        for b in up.basis() {
            assert!((b.iter().sum::<f64>() - 1.0).abs() < 2e-4, "{b:?}");
        }
    }

    #[test]
    fn the_basis_is_nearly_non_negative_and_puts_each_channel_where_it_belongs() {
        // Each B_c is at most 4% negative, and peaks in its own band (red > 600 nm, green
        // 500-580 nm, blue < 480 nm).
        let up = Upsampling::new();
        let b = up.basis();
        let min = b.iter().flatten().fold(f64::INFINITY, |m, &v| m.min(v));
        assert!(min > -0.04, "{min}");
        let at = |l: f64| &b[((l - 360.0) / 20.0) as usize];
        assert!(at(640.0)[0] > 0.95 && at(540.0)[1] > 0.95 && at(420.0)[2] > 0.95);
    }

    /// `f` with every albedo (groups and single threads) replaced by its spectrum's value at
    /// node `w`, the same in all three channels; `None` where a spectrum dips below 0 there (not
    /// a valid albedo).
    fn at_wavelength(
        f: &clothbake_core::Fabric,
        up: &Upsampling,
        w: usize,
    ) -> Option<clothbake_core::Fabric> {
        let grey = |a: [f64; 3]| [up.spectrum(a)[w]; 3];
        f.with_groups(
            |_, g| {
                g.material.albedo = grey(g.material.albedo);
                for t in &mut g.threads {
                    t.albedo = t.albedo.map(grey);
                }
            },
            &clothbake_core::PlainNaming(f.name()),
        )
        .ok()
    }

    #[test]
    fn upsampling_the_model_output_is_the_model_at_each_wavelength() {
        // Direct reflection is linear in the albedos (and the specular term is grey), so the
        // upsampled RGB output equals the model evaluated with the upsampled albedos, node by
        // node, up to the basis' 1e-4 departure from a partition of unity (which scales the
        // specular part). Gingham has per-thread colours; the twill a coloured group albedo.
        use clothbake_core::{AnalyticModel, Fabric, FacetModel, UnitVec3};
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let twill = Fabric::from_path(&dir.join("twill.json"))
            .unwrap()
            .with_groups(
                |_, g| g.material.albedo = [0.6, 0.3, 0.12],
                &clothbake_core::PlainNaming("twill"),
            )
            .unwrap();
        let gingham = Fabric::from_path(&dir.join("gingham.wif")).unwrap();
        let up = Upsampling::new();
        let pairs = [
            ((30.0, 0.0), (45.0, 180.0)),
            ((60.0, 90.0), (20.0, 250.0)),
            ((10.0, 45.0), (70.0, 300.0)),
        ];
        let (mut checked, mut skipped) = (0, 0);
        for (fabric, facet) in [(&twill, FacetModel::Huo), (&gingham, FacetModel::Lewis)] {
            let rgb_model = AnalyticModel::new(fabric, facet);
            for w in (0..WAVELENGTHS.len()).step_by(3) {
                let Some(grey) = at_wavelength(fabric, &up, w) else {
                    skipped += 1;
                    continue;
                };
                let grey_model = AnalyticModel::new(&grey, facet);
                for &((ti, pi), (to, po)) in &pairs {
                    let (wi, wo) = (
                        UnitVec3::from_degrees(ti, pi),
                        UnitVec3::from_degrees(to, po),
                    );
                    let f = rgb_model.intensity(wi, wo).brdf(wi);
                    let want = up.spectrum(f)[w];
                    let got = grey_model.intensity(wi, wo).brdf(wi);
                    assert!((got[0] - got[2]).abs() <= 1e-12 * got[0].abs());
                    assert!(
                        (got[0] - want).abs()
                            <= 2e-4 * f.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
                        "{} node {w}: {got:?} vs {want}",
                        fabric.name()
                    );
                    checked += 1;
                }
            }
        }
        // Gingham's red thread dips below 0 near 510 nm (see the next test): that node alone is
        // not a valid fabric.
        assert_eq!((checked, skipped), ((2 * 9 - 1) * 3, 1));
    }

    #[test]
    fn the_shipped_fabrics_colours_lose_little_where_negative_parts_are_clamped() {
        // Saturated colours give spectra with small negative parts (gingham's red thread,
        // sRGB (800, 80, 80)/999, dips to -1.8% of its red near 510 nm). pbrt-v4 clamps them
        // to 0: the colour it then sees, projected back, stays within 1% of the largest channel
        // for every albedo of the shipped fabrics and drafts (groups and single threads; 0.95%
        // measured, gingham's red). Mitsuba does not clamp: its round trip stays exact.
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let up = Upsampling::new();
        let (mut seen, mut worst, mut dip) = (0, 0.0f64, 0.0f64);
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            if !matches!(p.extension().and_then(|x| x.to_str()), Some("json" | "wif")) {
                continue;
            }
            let f = clothbake_core::Fabric::from_path(&p).unwrap();
            for g in [&f.warp(), &f.weft()] {
                for t in 0..g.threads.len() {
                    let a = g.albedo(t);
                    let s = up.spectrum(a);
                    let top = a.iter().fold(0.0f64, |m, &v| m.max(v));
                    dip = dip.max(-s.iter().fold(0.0f64, |m, &v| m.min(v)) / top);
                    let clamped: Vec<f64> = s.iter().map(|v| v.max(0.0)).collect();
                    let back = project(&WAVELENGTHS, &clamped);
                    for c in 0..3 {
                        worst = worst.max((back[c] - a[c]).abs() / top);
                    }
                    seen += 1;
                }
            }
        }
        eprintln!(
            "deepest dip {:.2}% of the top channel, clamped colour off by {:.3}%",
            100.0 * dip,
            100.0 * worst
        );
        assert!(seen > 20, "{seen}");
        assert!(worst < 1e-2, "{worst}");
    }

    #[test]
    fn interpolation_holds_the_ends() {
        let (n, v) = ([400.0, 500.0, 600.0], [1.0, 3.0, 2.0]);
        assert_eq!(interpolate(&n, &v, 300.0), 1.0);
        assert_eq!(interpolate(&n, &v, 450.0), 2.0);
        assert_eq!(interpolate(&n, &v, 550.0), 2.5);
        assert_eq!(interpolate(&n, &v, 700.0), 2.0);
    }
}
