//! A baked table as a [`Bsdf`]: f_r by [`Brdf::eval`], sampling and density by the table's own
//! importance sampling ([`Brdf::sample`], [`Brdf::pdf`]; the trait's cosine default where the
//! table was opened without sampling). Directions are rounded to f32 as the lookup takes them.

use crate::lookup::Brdf;
use clothbake_bsdf::{Bsdf, BsdfSample, Footprint, Local, Rgb, UnitVec3, Vec3};

/// A unit vector in the lookups' f32.
pub(crate) fn f32s(u: UnitVec3) -> [f32; 3] {
    [u.x as f32, u.y as f32, u.z as f32]
}

/// A lookup's [`crate::Sample`] as the interface's [`BsdfSample`] for `wo`: `None` without a
/// sample (pdf 0), f evaluated again at the sampled direction in f64.
pub(crate) fn bsdf_sample<B: Bsdf + ?Sized>(
    bsdf: &B,
    s: crate::Sample,
    wo: UnitVec3,
) -> Option<BsdfSample> {
    if s.pdf <= 0.0 {
        return None;
    }
    let [x, y, z] = s.wi.map(f64::from);
    let wi = UnitVec3::new(Vec3::new(x, y, z))?;
    Some(BsdfSample {
        wi,
        f: bsdf.f(wi, wo),
        pdf: f64::from(s.pdf),
    })
}

impl Bsdf for Brdf {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        self.eval(f32s(wi), f32s(wo)).map(f64::from)
    }

    /// Through [`Brdf::eval_batch`] (its misses overlapped; the same bits as `eval`).
    fn f_batch(&self, pairs: &[(UnitVec3, UnitVec3)], out: &mut [Rgb]) {
        assert_eq!(pairs.len(), out.len(), "one output per pair");
        let (wi, wo): (Vec<_>, Vec<_>) = pairs.iter().map(|&(a, b)| (f32s(a), f32s(b))).unzip();
        let mut f = vec![[0f32; 3]; pairs.len()];
        self.eval_batch(&wi, &wo, &mut f)
            .expect("slices of one length");
        for (o, f) in out.iter_mut().zip(&f) {
            *o = f.map(f64::from);
        }
    }

    fn f_at(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        self.eval_at(f32s(wi), f32s(wo), at.u, at.v, at.width)
            .map(f64::from)
    }

    fn coverage_at(&self, at: Footprint, wo: UnitVec3) -> f64 {
        f64::from(Brdf::coverage_at(self, f32s(wo), at.u, at.v, at.width))
    }

    /// Through [`Brdf::local_at`]: the point level traces once for both.
    fn local(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Local {
        let (f, c) = self.local_at(f32s(wi), f32s(wo), at.u, at.v, at.width);
        Local {
            f: f.map(f64::from),
            coverage: f64::from(c),
        }
    }

    fn sample(&self, wo: UnitVec3, u: [f64; 2]) -> Option<BsdfSample> {
        if !self.has_sampling() {
            return clothbake_bsdf::default_sample(self, wo, u);
        }
        bsdf_sample(self, self.sample(f32s(wo), u[0] as f32, u[1] as f32), wo)
    }

    fn pdf(&self, wi: UnitVec3, wo: UnitVec3) -> f64 {
        if !self.has_sampling() {
            return clothbake_bsdf::default_pdf(wi, wo);
        }
        f64::from(Brdf::pdf(self, f32s(wo), f32s(wi)))
    }
}
