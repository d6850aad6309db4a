//! The two-faced cloth (docs/science/transmission.md) end to end: the model's datasheet figures, the
//! ones a fabric-shade maker publishes, against the ground truth's light paths.

use clothbake_bake::two_faced::{TwoFaced, MAX_BOUNCES};
use clothbake_core::{Fabric, FacetModel, UnitVec3, Variant};
use clothbake_export::klems::Datasheet;
use clothbake_truth::RayTracer;

fn open_plain(tau: f64, h: f64) -> Fabric {
    let m = format!(
        r#""material": {{"albedo": [0.5, 0.4, 0.3], "specular": 0.1, "exponent": 8, "translucency": {tau}}}"#
    );
    Fabric::from_json_str(
        &format!(
            r#"{{"pattern": [[1,0],[0,1]], "warp": {{"radius": 0.5, "spacing": 2, "height": {h}, {m}}},
                "weft": {{"radius": 0.5, "spacing": 2, "height": {h}, {m}}}}}"#
        ),
        "open plain",
    )
    .unwrap()
}

#[test]
fn the_datasheet_agrees_with_the_light_paths() {
    for (tau, h) in [(0.0, 0.0), (0.8, 0.2)] {
        let fabric = open_plain(tau, h);
        let tf = TwoFaced::new(&fabric, FacetModel::Lewis, Variant::default()).unwrap();
        tf.prepare();
        let sheet = Datasheet::of(&tf);
        let truth = RayTracer::two_faced(&fabric, FacetModel::Lewis);
        let front = truth.scatter(UnitVec3::Z, 100_000, 1, MAX_BOUNCES);
        let back = truth.scatter(UnitVec3::Z.reverse(), 100_000, 2, MAX_BOUNCES);
        let solar = |c: [f64; 3]| (c[0] + c[1] + c[2]) / 3.0;
        // Openness: the geometric open area (1 - 2 r / s)^2, exactly, and the truth's.
        assert!((sheet.openness - 0.25).abs() < 1e-12, "{sheet:?}");
        assert!((front.through - 0.25).abs() < 4.0 * front.std_err.2 + 1e-3);
        // Transmittance: openness plus the diffuse part. The model's diffuse part is the
        // path-traced rest at coarse nodes, interpolated; its error at normal incidence is a
        // few per cent of the diffuse part (docs/science/transmission.md).
        let t_truth = front.through + solar(front.transmitted);
        let t_err = front.std_err.2 + solar(front.std_err.1);
        let t_diffuse = solar(front.transmitted);
        eprintln!(
            "tau {tau}: T {} vs {t_truth} +- {t_err}; R front {} vs {}, back {} vs {}",
            sheet.solar_transmittance,
            sheet.solar_reflectance_front,
            solar(front.reflected),
            sheet.solar_reflectance_back,
            solar(back.reflected)
        );
        assert!(
            (sheet.solar_transmittance - t_truth).abs() < 4.0 * t_err + 0.05 * t_diffuse + 1e-3,
            "tau {tau}: transmittance {} vs {t_truth} +- {t_err}",
            sheet.solar_transmittance
        );
        // Reflectance: the analytic direct part carries the model's own error on this open
        // weave (a few per cent of it).
        for (got, s) in [
            (sheet.solar_reflectance_front, &front),
            (sheet.solar_reflectance_back, &back),
        ] {
            let want = solar(s.reflected);
            assert!(
                (got - want).abs() < 4.0 * solar(s.std_err.0) + 0.06 * want,
                "tau {tau}: reflectance {got} vs {want}"
            );
        }
    }
}

#[test]
fn a_baked_table_holds_the_model_and_its_datasheet_agrees_with_the_light_paths() {
    use clothbake_bake::sweep::{bake, BakeOptions};
    use clothbake_loader::{Bsdf as _, Grid, Options, TwoFacedBrdf};
    use std::sync::atomic::AtomicBool;
    let fabric = open_plain(0.8, 0.2);
    // A quarter of the default rays a node (the transmittance integrates their noise away)
    // and a coarse grid, to keep the test short.
    let paths = 2048;
    let opts = BakeOptions {
        grid: Grid::new(12, 16, 12, 16).two_faced(),
        facet: FacetModel::Lewis,
        paths,
        ..BakeOptions::default()
    };
    let baked = bake(&fabric, &opts, &|_| {}, &AtomicBool::new(false)).unwrap();
    let g = baked.table.meta.grid;
    let values = baked.table.values.clone();
    let table = TwoFacedBrdf::from_table(baked.table, Options::default()).unwrap();
    // At every 7th cell centre the lookup returns the model's value at the cell's mirror orbit
    // representative (the bake evaluates one cell an orbit of the weave's symmetries and
    // copies it; the model of the same fabric, built apart: its nodes are pure functions of
    // their directions).
    let syms = clothbake_bake::sweep::usable_symmetries(&fabric, &g);
    assert!(!syms.is_empty(), "the open plain weave is symmetric");
    let model = TwoFaced::with_grid(
        &fabric,
        FacetModel::Lewis,
        Variant::default(),
        clothbake_bake::two_faced::NODES,
        paths,
    )
    .unwrap();
    let centre = |k: u32, polar: bool, n: u32| {
        if polar {
            (f64::from(k) + 0.5) * 180.0 / f64::from(n)
        } else {
            (f64::from(k) + 0.5) * 360.0 / f64::from(n)
        }
    };
    for c in (0..g.len()).step_by(7) {
        let po = (c % g.n_phi_o as usize) as u32;
        let to = (c / g.n_phi_o as usize % g.n_theta_o as usize) as u32;
        let pi = (c / (g.n_phi_o * g.n_theta_o) as usize % g.n_phi_i as usize) as u32;
        let ti = (c / (g.n_phi_o * g.n_theta_o * g.n_phi_i) as usize) as u32;
        let wi =
            UnitVec3::from_degrees(centre(ti, true, g.n_theta_i), centre(pi, false, g.n_phi_i));
        let wo =
            UnitVec3::from_degrees(centre(to, true, g.n_theta_o), centre(po, false, g.n_phi_o));
        let (ri, ro) = clothbake_bake::sweep::representative(pi as usize, po as usize, &syms, &g);
        let rep_i = UnitVec3::from_degrees(
            centre(ti, true, g.n_theta_i),
            centre(ri as u32, false, g.n_phi_i),
        );
        let rep_o = UnitVec3::from_degrees(
            centre(to, true, g.n_theta_o),
            centre(ro as u32, false, g.n_phi_o),
        );
        let (got, want) = (table.f(wi, wo), model.f(rep_i, rep_o));
        assert_eq!(values[3 * c + 1], want[1] as f32, "cell {c}");
        assert!(
            (got[1] - want[1]).abs() <= 1e-4 * want[1] + 1e-7,
            "cell {c} ({ti}, {pi}, {to}, {po}): table {got:?}, model {want:?}"
        );
    }
    // The datasheet of the table against the truth's light paths, as the model's above: the
    // openness at the normal is the first incident ring's (3.75 degrees from it; the closed
    // form falls from 0.25 there), the diffuse part interpolated on 7.5-degree cells.
    let sheet = Datasheet::of(&table);
    let truth = RayTracer::two_faced(&fabric, FacetModel::Lewis);
    let front = truth.scatter(UnitVec3::Z, 100_000, 1, MAX_BOUNCES);
    let solar = |c: [f64; 3]| (c[0] + c[1] + c[2]) / 3.0;
    let at_ring = clothbake_core::openness::openness(&fabric, UnitVec3::from_degrees(3.75, 11.25));
    eprintln!(
        "table: openness {} (closed form at normal 0.25, at the first ring {at_ring}), T {} vs {} +- {}",
        sheet.openness,
        sheet.solar_transmittance,
        front.through + solar(front.transmitted),
        front.std_err.2 + solar(front.std_err.1)
    );
    assert!(
        (sheet.openness - 0.25).abs() <= (0.25 - at_ring).abs() + 1e-6,
        "{sheet:?}"
    );
    let t_truth = front.through + solar(front.transmitted);
    let t_err = front.std_err.2 + solar(front.std_err.1);
    assert!(
        (sheet.solar_transmittance - t_truth).abs()
            < 4.0 * t_err + 0.05 * solar(front.transmitted) + (0.25 - at_ring).abs() + 1e-3,
        "transmittance {} vs {t_truth} +- {t_err}",
        sheet.solar_transmittance
    );
    let r_truth = solar(front.reflected);
    assert!(
        (sheet.solar_reflectance_front - r_truth).abs()
            < 4.0 * solar(front.std_err.0) + 0.08 * r_truth,
        "reflectance {} vs {r_truth}",
        sheet.solar_reflectance_front
    );
}
