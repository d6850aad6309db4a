//! The fixed sets of direction pairs the model is validated on (docs/results/validation.md):
//! the tests, the benchmarks and `cargo xtask validate` draw from these, so every comparison
//! with the ground truth (clothbake-tests' `validate`) is made on the same pairs.

use crate::vec3::UnitVec3;

/// A direction pair: toward the light, toward the eye.
pub type Pair = (UnitVec3, UnitVec3);

/// The fixed validation set: `n` (wi, wo) pairs with both polar angles at most `max_theta_deg`,
/// spread over the hemisphere by a low-discrepancy (golden-ratio) sequence. Deterministic.
pub fn direction_set(n: usize, max_theta_deg: f64) -> Vec<Pair> {
    let g = |k: usize, a: f64| ((k as f64 + 0.5) * a).fract();
    let cmax = (1.0 - max_theta_deg.to_radians().cos()).max(0.0);
    (0..n)
        .map(|k| {
            // Uniform in solid angle: cos(theta) uniform on [cos max, 1].
            let ti = (1.0 - g(k, 0.618_033_988_749_895) * cmax).acos();
            let pi = g(k, 0.754_877_666_246_693) * 360.0;
            let to = (1.0 - g(k, 0.569_840_290_998_053) * cmax).acos();
            let po = g(k, 0.412_454_033_640_107) * 360.0;
            (
                UnitVec3::from_spherical(ti, pi.to_radians()),
                UnitVec3::from_spherical(to, po.to_radians()),
            )
        })
        .collect()
}

/// Pairs on which the model's special branches are taken: normal incidence, the symmetry
/// planes (phi a multiple of 90 degrees: a projection's zero component), a diagonal and near
/// grazing (89.99 degrees), for tests that compare two evaluations of the model.
pub fn edge_pairs() -> Vec<Pair> {
    [
        (0.0, 0.0, 0.0, 0.0),
        (30.0, 0.0, 45.0, 180.0),
        (60.0, 90.0, 20.0, 270.0),
        (89.99, 0.0, 89.99, 90.0),
        (45.0, 45.0, 45.0, 225.0),
        (0.0, 0.0, 70.0, 180.0),
    ]
    .map(|(ti, pi, to, po)| {
        (
            UnitVec3::from_degrees(ti, pi),
            UnitVec3::from_degrees(to, po),
        )
    })
    .to_vec()
}

/// The direction set of the secondary-reflection accuracy table and benchmarks
/// (`cargo xtask ir-accuracy`, `cargo bench -p clothbake-core -- secondary`): 40 pairs of
/// [`direction_set`] up to 85 degrees, and 4 grazing pairs whose light and eye run along the
/// +Y threads (the axial lobes' hard case).
pub fn secondary_direction_set() -> Vec<Pair> {
    let mut v = direction_set(40, 85.0);
    for ((ti, pi), (to, po)) in [
        ((60.0, 90.0), (60.0, 270.0)),
        ((80.0, 85.0), (70.0, 275.0)),
        ((45.0, 80.0), (75.0, 260.0)),
        ((85.0, 90.0), (85.0, 90.0)),
    ] {
        v.push((
            UnitVec3::from_degrees(ti, pi),
            UnitVec3::from_degrees(to, po),
        ));
    }
    v
}
