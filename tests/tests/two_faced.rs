//! The two-faced cloth (docs/transmission.md) end to end: the model's datasheet figures, the
//! ones a fabric-shade maker publishes, against the ground truth's light paths.

use clothbake_bake::two_faced::{TwoFaced, MAX_BOUNCES};
use clothbake_core::{Fabric, FacetModel, RayTracer, UnitVec3, Variant};
use clothbake_export::klems::Datasheet;

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
        // few per cent of the diffuse part (docs/transmission.md).
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
