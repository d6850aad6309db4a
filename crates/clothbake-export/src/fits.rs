//! Both families fitted to one source as their files hold them: the glTF fit, the OpenPBR fit
//! and its conversion for Blender, each with its residual against the averaged reflectance
//! under the rules it is rendered by. Above `fitted` and the writers (`gltf`, `openpbr`),
//! which say what their files hold.

use crate::fitted::fit::Residual;
use crate::fitted::material::{Fitted, Source};
use crate::fitted::microfacet::Albedos;
use crate::fitted::{Convention, Family};

/// Both families fitted to one source, as their files hold them, with the residual of each
/// against the averaged reflectance under the rules it is rendered by: glTF under its
/// specification, OpenPBR under OpenPBR's, and the same fit converted for Blender under
/// Cycles' ([`crate::fitted::cycles_params`]).
pub struct Fits {
    /// The glTF fit.
    pub gltf: Fitted,
    /// As the `.glb` holds it.
    pub gltf_held: Fitted,
    /// Its residual.
    pub gltf_residual: Residual,
    /// The OpenPBR fit.
    pub openpbr: Fitted,
    /// As the MaterialX and USD files (and their maps) hold it.
    pub openpbr_held: Fitted,
    /// Its residual.
    pub openpbr_residual: Residual,
    /// The Blender module's parameters (f32 Principled inputs).
    pub blender_held: Fitted,
    /// Their residual under Cycles' rules.
    pub blender_residual: Residual,
}

impl Fits {
    /// Fits the families `want` asks for (glTF, OpenPBR) to `src`; the other's fields hold
    /// the one fitted (with zero residuals) when only one is asked for.
    pub fn new(src: &Source<'_>, t: &Albedos, want_gltf: bool, want_openpbr: bool) -> Fits {
        let fam = |f: Family| Fitted::new(f, src, t);
        let gltf = if want_gltf {
            Some(fam(Family::Gltf))
        } else {
            None
        };
        let openpbr = if want_openpbr {
            Some(fam(Family::OpenPbr))
        } else {
            None
        };
        let any = gltf
            .clone()
            .or_else(|| openpbr.clone())
            .expect("one family asked for");
        let gltf = gltf.unwrap_or_else(|| any.clone());
        let openpbr = openpbr.unwrap_or(any);
        let zero = Residual {
            l2: 0.0,
            albedo_mean: 0.0,
            albedo_max: 0.0,
        };
        let gltf_held = crate::gltf::held(&gltf);
        let gltf_residual = if want_gltf {
            gltf_held.residual_against(src.average, Convention::GltfSpec, t)
        } else {
            zero
        };
        let openpbr_held = crate::openpbr::held(&openpbr);
        let blender_held = crate::openpbr::blender_held(&openpbr);
        let (openpbr_residual, blender_residual) = if want_openpbr {
            (
                openpbr_held.residual_against(src.average, Convention::OpenPbr, t),
                blender_held.residual_against(src.average, Convention::Cycles, t),
            )
        } else {
            (zero, zero)
        };
        Fits {
            gltf,
            gltf_held,
            gltf_residual,
            openpbr,
            openpbr_held,
            openpbr_residual,
            blender_held,
            blender_residual,
        }
    }
}
