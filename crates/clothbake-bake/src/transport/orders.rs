//! Full light transport (`--bounces N`, `--bounces all`; docs/science/transport.md): the direct
//! reflection I_1 from the analytic model (thesis eqs 4.1-4.11, exact on its own terms and
//! smooth) plus every later bounce, orders 2 to N, estimated by the ground truth's path tracer
//! (`clothbake_truth::pathtracer`) on the explicit micro-geometry: every yarn, parallel and
//! perpendicular, with the floor (z = 0, which has no material in a fabric description) and the
//! sky absorbing. The multiple-bounce part uses the radiometric kernel (the rendering equation);
//! the thesis's printed kernel means nothing past the second bounce.
//!
//! `--bounces 2` keeps its meaning, the thesis's analytic second bounce between neighbouring
//! parallel segments (ch. 5); `--bounces all` is the direct analytic term plus the path-traced
//! orders 2 and up, which include the perpendicular pairs, the bounces between non-neighbours
//! and the orders the thesis leaves out.
//!
//! Deterministic: the path tracer's seed for a direction pair is hashed from the pair's bits
//! and a base seed ([`pair_seed`]), never from time or thread.

use clothbake_core::rng::mix64;
use clothbake_core::{Kernel, UnitVec3};
use clothbake_truth::{PathEstimate, PathOptions, RayTracer};

/// `--bounces all` as a bounce count.
pub const ALL_BOUNCES: u32 = u32::MAX;

/// The highest order `--bounces all` follows: Russian roulette ends nearly every path long
/// before it (the orders past 20 carry under 1e-6 of I_1 on every shipped fabric,
/// docs/science/transport.md).
pub const MAX_ORDER: usize = 64;

/// Default paths per direction pair of [`Transport::multiple`] on the command line.
pub const DEFAULT_PATHS: usize = 100_000;

/// Default base seed.
pub const DEFAULT_SEED: u64 = 1;

/// The highest order estimated for a bounce count (`ALL_BOUNCES`: [`MAX_ORDER`]).
pub fn max_order(bounces: u32) -> usize {
    if bounces == ALL_BOUNCES {
        MAX_ORDER
    } else {
        (bounces as usize).min(MAX_ORDER)
    }
}

/// The bounce count in words: `all` or the number.
pub fn bounces_name(bounces: u32) -> String {
    if bounces == ALL_BOUNCES {
        "all".into()
    } else {
        bounces.to_string()
    }
}

/// The seed of the direction pair (`wi`, `wo`) under the base seed `seed`: the pair's bits
/// hashed, so that the same pair always draws the same paths, in any order and on any thread.
pub fn pair_seed(seed: u64, wi: UnitVec3, wo: UnitVec3) -> u64 {
    [wi.x, wi.y, wi.z, wo.x, wo.y, wo.z]
        .iter()
        .fold(mix64(seed), |h, x| mix64(h ^ x.to_bits()))
}

/// The multiple-bounce estimator of a fabric: the path tracer from the second order on.
#[derive(Clone, Debug)]
pub struct Transport {
    tracer: RayTracer,
    bounces: u32,
    paths: usize,
    seed: u64,
}

impl Transport {
    /// The estimator of orders 2 to `bounces` (or [`ALL_BOUNCES`]) with `paths` primary rays
    /// per direction pair and base seed `seed`, over the tracer's micro-geometry.
    pub fn new(tracer: RayTracer, bounces: u32, paths: usize, seed: u64) -> Transport {
        Transport {
            tracer,
            bounces,
            paths: paths.max(1),
            seed,
        }
    }

    /// The path options: radiometric kernel, gathering from order 2 (`first_order` 1 with
    /// `with_direct`), roulette from order 4.
    pub fn options(&self, with_direct: bool) -> PathOptions {
        PathOptions {
            max_bounces: max_order(self.bounces).max(1),
            kernel: Kernel::Radiometric,
            roulette_from: 4,
            first_order: if with_direct { 1 } else { 2 },
        }
    }

    /// The micro-geometry's tracer.
    pub fn tracer(&self) -> &RayTracer {
        &self.tracer
    }

    /// Primary rays per direction pair.
    pub fn paths(&self) -> usize {
        self.paths
    }

    /// The base seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The bounce count.
    pub fn bounces(&self) -> u32 {
        self.bounces
    }

    /// Orders 2 to N for the pair (`orders[0]`, the direct term, is left zero); `multiple` is
    /// their sum with its standard error. Zero at or below the horizon.
    pub fn multiple(&self, wi: UnitVec3, wo: UnitVec3) -> PathEstimate {
        self.tracer.render_paths(
            wi,
            wo,
            self.paths,
            pair_seed(self.seed, wi, wo),
            self.options(false),
        )
    }

    /// As [`Transport::multiple`] with the independent paths of round `round` (round 0 is
    /// [`Transport::multiple`] itself): more samples for the same pair, still seeded by it.
    pub fn multiple_round(&self, wi: UnitVec3, wo: UnitVec3, round: u64) -> PathEstimate {
        let seed = pair_seed(self.seed, wi, wo);
        self.tracer.render_paths(
            wi,
            wo,
            self.paths,
            if round == 0 {
                seed
            } else {
                mix64(seed ^ round)
            },
            self.options(false),
        )
    }

    /// Every order 1 to N by the path tracer alone (the ground truth of the whole sum).
    pub fn all_orders(&self, wi: UnitVec3, wo: UnitVec3) -> PathEstimate {
        self.tracer.render_paths(
            wi,
            wo,
            self.paths,
            pair_seed(self.seed, wi, wo),
            self.options(true),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clothbake_core::fabric::Fabric;
    use clothbake_core::facet::FacetModel;

    fn twill() -> Fabric {
        clothbake_core::fabric::thesis_twill()
    }

    #[test]
    fn seeds_depend_on_the_pair_and_not_on_the_order_of_evaluation() {
        let a = UnitVec3::from_degrees(30.0, 10.0);
        let b = UnitVec3::from_degrees(40.0, 200.0);
        assert_eq!(pair_seed(1, a, b), pair_seed(1, a, b));
        assert_ne!(pair_seed(1, a, b), pair_seed(1, b, a));
        assert_ne!(pair_seed(1, a, b), pair_seed(2, a, b));
        let t = Transport::new(
            RayTracer::new(&twill(), FacetModel::Huo),
            ALL_BOUNCES,
            2000,
            7,
        );
        let first = t.multiple(a, b);
        let _ = t.multiple(b, a);
        assert_eq!(t.multiple(a, b), first);
        assert_eq!(first.orders[0], [0.0; 3]);
    }

    #[test]
    fn the_multiple_part_is_the_sum_of_its_orders_and_the_split_sums_to_i2() {
        let t = Transport::new(
            RayTracer::new(&twill(), FacetModel::Huo),
            ALL_BOUNCES,
            4000,
            3,
        );
        let (wi, wo) = (
            UnitVec3::from_degrees(40.0, 30.0),
            UnitVec3::from_degrees(50.0, 250.0),
        );
        let p = t.multiple(wi, wo);
        for c in 0..3 {
            let sum: f64 = p.orders[1..].iter().map(|o| o[c]).sum();
            assert!((sum - p.multiple[c]).abs() <= 1e-12 * sum.max(1e-30));
            let split = p.i2_split[0][c] + p.i2_split[1][c];
            assert!((split - p.orders[1][c]).abs() <= 1e-12 * split.max(1e-30));
        }
        assert!(
            p.i2_split[1][0] > 0.0,
            "the twill has perpendicular bounces"
        );
    }
}
