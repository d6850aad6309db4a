use clothbake_core::arc::{Arc, Projected};
use clothbake_core::interreflection::*;
use clothbake_core::{FacetModel, Material, UnitVec3};
use std::f64::consts::PI;
fn main() {
    let m = Material {
        albedo: [0.4; 3],
        specular: 0.7,
        exponent: 10.0,
    };
    for kernel in [Kernel::Thesis, Kernel::Radiometric] {
        let pair = Pair {
            r1: 1.0,
            h1: 0.0,
            r2: 1.0,
            h2: 0.0,
            d: 2.0,
            m1: m,
            m2: m,
            facet: FacetModel::Huo,
            kernel,
        };
        let (l, e) = (
            UnitVec3::from_degrees(std::env::args().nth(1).unwrap().parse().unwrap(), 180.0),
            UnitVec3::from_degrees(std::env::args().nth(2).unwrap().parse().unwrap(), 20.0),
        );
        let half = Arc { lo: 0.0, hi: PI };
        let nb = clothbake_core::shadowing::Occluder {
            u: 2.0,
            z: 0.0,
            rho: 1.0,
        };
        let occ = |v: UnitVec3| {
            let mut a = Arc::facing(Projected { c: v.x, z: v.z }).meet(half);
            let th = v.z.atan2(v.x);
            if v.x > 0.0 {
                if let clothbake_core::shadowing::ArcOcclusion::UpTo(t) =
                    clothbake_core::shadowing::occluded_arc(1.0, 0.0, &nb, th)
                {
                    a.lo = a.lo.max(t);
                }
            } else if let clothbake_core::shadowing::ArcOcclusion::UpTo(t) =
                clothbake_core::shadowing::occluded_arc(1.0, 0.0, &nb, PI - th)
            {
                a.hi = a.hi.min(PI - t);
            }
            a
        };
        let s = Setting {
            l: l.get(),
            e: e.get(),
            vis1: occ(e),
            lit2: occ(l),
            axial: (f64::NEG_INFINITY, f64::INFINITY),
        };
        println!("vis1 {:?} lit2 {:?}", s.vis1, s.lit2);
        for o in [8, 16, 32, 48] {
            let a = analytic(
                &pair,
                &s,
                Ranges::Full,
                Orders {
                    theta: o,
                    beta: o,
                    axial: o,
                },
            );
            println!(
                "{kernel:?} analytic {o}: ss {:.5} sd {:.5} ds {:.5} dd {:.5} tot {:.5}",
                a.ss[0],
                a.sd[0],
                a.ds[0],
                a.dd[0],
                a.total()[0]
            );
        }
        for (n, da, dl, l0, ex) in [
            (100, 0.02, 0.04, 30.0, true),
            (200, 0.01, 0.02, 60.0, true),
            (200, 0.01, 0.02, 60.0, false),
            (400, 0.005, 0.01, 60.0, false),
        ] {
            let b = two_level_sampling(
                &pair,
                &s,
                Sampling {
                    first_level: n,
                    d_alpha: da,
                    d_l: dl,
                    l0,
                    exact_solid_angle: ex,
                },
            );
            println!("{kernel:?} sampling {n} {da} {dl} {l0} {ex}: ss {:.5} sd {:.5} ds {:.5} dd {:.5} tot {:.5}", b.ss[0], b.sd[0], b.ds[0], b.dd[0], b.total()[0]);
        }
    }
}
