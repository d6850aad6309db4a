//! `clothbake.Fabric`: a validated fabric description and its BRDF from the analytic model
//! (thesis ch. 3-4, ch. 5 with two bounces) or the ray-traced ground truth.

use crate::args::{bounces_arg, facet_model};
use crate::vectors::{
    check_footprint, check_unit, period_rows, same_len, to_array, to_array1, unit_rows, widths,
};
use clothbake_bake::transport::Transport;
use clothbake_core::{
    intensity_to_brdf, AnalyticBsdf, AnalyticModel, Bsdf, Component, Fabric, FacetModel, Footprint,
    Local, PeriodPoint, Reflection, SecondaryOptions, UnitVec3, Vec3,
};
use clothbake_truth::RayTracer;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use rayon::prelude::*;
use std::sync::OnceLock;

/// A woven fabric (weave pattern, yarn geometry, facet materials), validated.
#[pyclass(name = "Fabric", module = "clothbake", frozen)]
pub struct PyFabric {
    pub(crate) fabric: Fabric,
    /// The file it was read from (`None` for a dict): a bake's output may not replace it.
    pub(crate) path: Option<std::path::PathBuf>,
    /// Analytic models, built on first use: Huo's facets, Lewis's.
    models: [OnceLock<AnalyticModel>; 2],
    /// The one-bounce model with the fabric's yarns (every level of detail), built on first
    /// use: Huo's facets, Lewis's.
    levels: [OnceLock<AnalyticBsdf>; 2],
}

impl PyFabric {
    /// The analytic model of this fabric with `facet` (built once).
    pub fn model(&self, facet: FacetModel) -> &AnalyticModel {
        let k = match facet {
            FacetModel::Huo => 0,
            FacetModel::Lewis => 1,
        };
        self.models[k].get_or_init(|| AnalyticModel::new(&self.fabric, facet))
    }

    /// The one-bounce model with the fabric's yarns: every level of detail (built once).
    pub fn levels(&self, facet: FacetModel) -> &AnalyticBsdf {
        let k = match facet {
            FacetModel::Huo => 0,
            FacetModel::Lewis => 1,
        };
        self.levels[k].get_or_init(|| {
            let b = AnalyticBsdf::new(self.model(facet).clone(), None);
            match clothbake_core::point::yarns(&self.fabric, facet) {
                Some(y) => b.with_yarns(y),
                None => b,
            }
        })
    }
}

fn unit(w: [f64; 3]) -> UnitVec3 {
    UnitVec3::new(Vec3::new(w[0], w[1], w[2])).unwrap_or(UnitVec3::Z)
}

/// f_r of the parts of a reflection: total, diffuse, specular, secondary.
fn parts(r: &Reflection, wi: UnitVec3) -> [[f64; 3]; 4] {
    let i2 = r.secondary.map_or([0.0; 3], |s| s.total());
    [
        r.brdf(wi),
        intensity_to_brdf(r.i_d, wi),
        intensity_to_brdf(r.i_s, wi),
        intensity_to_brdf(i2, wi),
    ]
}

#[pymethods]
impl PyFabric {
    /// Reads a fabric from a file path or from a dict of the fabric-file schema
    /// (docs/reference/fabric-format.md). Raises ValueError naming the file (or `<dict>`) and the field.
    #[new]
    fn new(source: &Bound<'_, PyAny>) -> PyResult<Self> {
        let py = source.py();
        let mut path = None;
        let fabric = if source.is_instance_of::<PyDict>() {
            let text: String = py
                .import("json")?
                .call_method1("dumps", (source,))
                .map_err(|e| PyValueError::new_err(format!("<dict>: not JSON-serialisable: {e}")))?
                .extract()?;
            Fabric::from_json_str(&text, "<dict>")
        } else {
            let p: std::path::PathBuf = source.extract().map_err(|_| {
                PyValueError::new_err(
                    "Fabric: pass a path to a fabric file (e.g. tables/twill.json) or a dict",
                )
            })?;
            let fabric = Fabric::from_path(&p);
            path = Some(p);
            fabric
        }
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(PyFabric {
            fabric,
            path,
            models: [OnceLock::new(), OnceLock::new()],
            levels: [OnceLock::new(), OnceLock::new()],
        })
    }

    /// The fabric's name.
    #[getter]
    fn name(&self) -> &str {
        self.fabric.name()
    }

    /// The fabric as a dict of the fabric-file schema, every field explicit.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?
            .call_method1("loads", (self.fabric.to_json().to_string(),))
    }

    fn __repr__(&self) -> String {
        format!("clothbake.Fabric({:?})", self.fabric.name())
    }

    /// f_r(wi, wo) in 1/sr, RGB, for unit vectors in the fabric's frame (+X weft, +Y warp,
    /// +Z normal; `wi` toward the light, `wo` toward the eye), arrays of shape (N, 3) or (3,).
    /// Zero when either direction is at or below the horizon.
    ///
    /// method: "analytic" (the thesis's model) or "raytrace" (the exact ray tracer of the same
    /// micro-geometry, `samples` rays per pair, seeded `seed + row`: ground truth, slow).
    /// bounces: 1 (default), or 2 to add the secondary reflection (thesis ch. 5; analytic
    /// only), or N from 3 to 64 or "all": the analytic direct term plus orders 2 to N
    /// path-traced on the micro-geometry, `samples` paths a pair, seeded from `seed` and the
    /// pair (docs/science/transport.md); "secondary" of `split=True` is then that multiple-bounce part.
    /// facet: "huo" (default, eqs 4.6 and 4.8) or "lewis" (energy conserving).
    /// split: also return the diffuse, specular and secondary parts, each as f_r in 1/sr.
    /// uv: points of the weave period, (N, 2) or (2,), in period fractions (u along the weft
    /// +X, v along the warp +Y, any finite numbers, wrapped; analytic only): f_r seen through
    /// a footprint there instead of the period's average, through the model's BSDF
    /// (`Bsdf::local`, docs/science/spatial.md). width: the footprint's side in periods, one number
    /// or one a row (default 0, the point itself; 1 or more, the period). level: "auto" (default), the footprint's level of
    /// detail: with one bounce the yarns traced up close (the point level), the crossing cells
    /// from two cells wide, the period from a period; or "cells", the crossing cells as a
    /// spatial table holds them. With `split=True` the dict holds "brdf", "coverage" (the
    /// footprint's c per row) and, with bounces=2, "secondary"; a footprint's reflection is not
    /// split into diffuse and specular parts.
    /// Returns an (N, 3) float64 array, or a dict of them with `split=True`.
    #[pyo3(signature = (wi, wo, method="analytic", bounces=None, facet="huo", split=false, samples=100_000, seed=1, uv=None, width=None, level="auto"))]
    #[allow(clippy::too_many_arguments)]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        wi: &Bound<'py, PyAny>,
        wo: &Bound<'py, PyAny>,
        method: &str,
        bounces: Option<&Bound<'py, PyAny>>,
        facet: &str,
        split: bool,
        samples: usize,
        seed: u64,
        uv: Option<&Bound<'py, PyAny>>,
        width: Option<&Bound<'py, PyAny>>,
        level: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let facet = facet_model(facet)?;
        let most = clothbake_bake::settings::MAX_SAMPLES;
        if samples == 0 || samples > most {
            return Err(PyValueError::new_err(format!(
                "samples: {samples}; give a whole number of rays from 1 to {most} (2^24)"
            )));
        }
        let point_level = match level {
            "auto" => true,
            "cells" => false,
            other => {
                return Err(PyValueError::new_err(format!(
                    "level: {other:?}; use \"auto\" (the footprint's level of detail) or \"cells\" (the crossing cells)"
                )))
            }
        };
        let bounces = bounces_arg(bounces)?;
        if bounces > 2 && (method != "analytic" || uv.is_some()) {
            return Err(PyValueError::new_err(
                "bounces: more than 2 adds path-traced orders to the analytic model's period average; use method=\"analytic\" without uv",
            ));
        }
        let wi = unit_rows("wi", wi)?;
        let wo = unit_rows("wo", wo)?;
        same_len(("wi", wi.rows.len()), ("wo", wo.rows.len()))?;
        let at = match uv {
            None => None,
            Some(obj) => {
                if method != "analytic" {
                    return Err(PyValueError::new_err(
                        "uv: points of the period are evaluated by the analytic model only; drop uv or use method=\"analytic\"",
                    ));
                }
                let r = period_rows(obj, wi.rows.len())?;
                let pts = r
                    .rows
                    .iter()
                    .map(|&[u, v]| PeriodPoint::new(u, v).expect("period_rows: finite"))
                    .collect::<Vec<_>>();
                Some(pts)
            }
        };
        let secondary = (bounces == 2).then(SecondaryOptions::default);
        let pairs: Vec<(UnitVec3, UnitVec3)> = wi
            .rows
            .iter()
            .zip(&wo.rows)
            .map(|(&a, &b)| (unit(a), unit(b)))
            .collect();
        let mut coverage = Vec::new();
        let out: Vec<[[f64; 3]; 4]> = match (method, &at) {
            ("analytic", Some(at)) => {
                let w = match width {
                    Some(w) => widths(w, pairs.len())?,
                    None => vec![0.0; pairs.len()],
                };
                let m = self.model(facet);
                let cells;
                let bsdf = if point_level && secondary.is_none() {
                    self.levels(facet)
                } else {
                    cells = AnalyticBsdf::new(m.clone(), secondary);
                    &cells
                };
                let i2 = secondary.and_then(|_| {
                    AnalyticBsdf::new(m.clone(), secondary).with_component(Component::Secondary)
                });
                let local: Vec<(Local, [f64; 3])> = py.detach(|| {
                    pairs
                        .par_iter()
                        .zip(at)
                        .zip(&w)
                        .map(|((&(a, b), p), &width)| {
                            let fp = Footprint {
                                u: p.u(),
                                v: p.v(),
                                width,
                            };
                            let s = i2.as_ref().map_or([0.0; 3], |s| s.f_at(fp, a, b));
                            (bsdf.local(fp, a, b), s)
                        })
                        .collect()
                });
                coverage = local.iter().map(|l| l.0.coverage).collect();
                local
                    .iter()
                    .map(|(l, s)| [l.f, [f64::NAN; 3], [f64::NAN; 3], *s])
                    .collect()
            }
            ("analytic", None) if bounces > 2 => {
                let m = self.model(facet);
                let t = Transport::new(RayTracer::new(&self.fabric, facet), bounces, samples, seed);
                py.detach(|| {
                    pairs
                        .par_iter()
                        .map(|&(a, b)| {
                            let mut p = parts(&m.intensity(a, b), a);
                            if a.above_horizon() && b.above_horizon() {
                                let i = t.multiple(a, b).multiple;
                                p[3] = intensity_to_brdf(i, a);
                                p[0] = std::array::from_fn(|k| p[0][k] + p[3][k]);
                            }
                            p
                        })
                        .collect()
                })
            }
            ("analytic", None) if secondary.is_none() => {
                // One bounce: four pairs at a time (AnalyticModel::intensity_batch, the same
                // bits as intensity).
                let m = self.model(facet);
                py.detach(|| {
                    let mut r = vec![Reflection::default(); pairs.len()];
                    r.par_chunks_mut(256)
                        .zip(pairs.par_chunks(256))
                        .for_each(|(r, p)| m.intensity_batch(p, r));
                    r.iter()
                        .zip(&pairs)
                        .map(|(r, &(a, _))| parts(r, a))
                        .collect()
                })
            }
            ("analytic", None) => {
                let m = self.model(facet);
                py.detach(|| {
                    pairs
                        .par_iter()
                        .map(|&(a, b)| parts(&m.intensity_with(a, b, secondary.as_ref()), a))
                        .collect()
                })
            }
            ("raytrace", _) => {
                if bounces != 1 {
                    return Err(PyValueError::new_err(
                        "bounces: the ray tracer here gives the direct reflection only; use bounces=1 with method=\"raytrace\"",
                    ));
                }
                let rt = RayTracer::new(&self.fabric, facet);
                py.detach(|| {
                    pairs
                        .par_iter()
                        .enumerate()
                        .map(|(k, &(a, b))| {
                            let r = rt.render(a, b, samples, seed.wrapping_add(k as u64));
                            parts(&r.reflection, a)
                        })
                        .collect()
                })
            }
            (other, _) => {
                return Err(PyValueError::new_err(format!(
                    "method: {other:?}; use \"analytic\" or \"raytrace\""
                )))
            }
        };
        let single = wi.single && wo.single;
        let part = |k: usize| -> Vec<[f64; 3]> { out.iter().map(|p| p[k]).collect() };
        if !split {
            return to_array(py, &part(0), single);
        }
        let d = PyDict::new(py);
        for (k, name) in ["brdf", "diffuse", "specular", "secondary"]
            .iter()
            .enumerate()
        {
            // A footprint's reflection comes whole (and its I_2 only with two bounces).
            let unsplit = at.is_some() && (k == 1 || k == 2 || (k == 3 && bounces != 2));
            if !unsplit {
                d.set_item(PyString::new(py, name), to_array(py, &part(k), single)?)?;
            }
        }
        if at.is_some() {
            d.set_item(
                PyString::new(py, "coverage"),
                to_array1(py, coverage, single)?,
            )?;
        }
        Ok(d.into_any())
    }

    /// f_r and coverage at point (u, v) of the weave period through a footprint of side
    /// `width` periods, for one pair of unit vectors given as 3 floats each (fabric frame,
    /// analytic model, direct reflection, every level of detail: the yarns traced up close):
    /// the scalar path of the Mitsuba plugin. Returns ((r, g, b), coverage).
    #[pyo3(signature = (wi, wo, u, v, width=0.0, facet="huo"))]
    fn eval1_at(
        &self,
        wi: [f64; 3],
        wo: [f64; 3],
        u: f64,
        v: f64,
        width: f64,
        facet: &str,
    ) -> PyResult<((f64, f64, f64), f64)> {
        check_unit("wi", 0, wi)?;
        check_unit("wo", 0, wo)?;
        check_footprint(u, v, width)?;
        let l =
            self.levels(facet_model(facet)?)
                .local(Footprint { u, v, width }, unit(wi), unit(wo));
        Ok(((l.f[0], l.f[1], l.f[2]), l.coverage))
    }

    /// The fabric's two-faced cloth (docs/science/transmission.md): no floor, light through the gaps
    /// and through translucent yarns (the materials' `translucency`), the back the inverted
    /// weave (facet "huo" by default, as everywhere; "lewis" conserves energy, which light
    /// through the cloth makes worth having); its model's coarse grid is path-traced here (about 25 s on two cores at the
    /// default `nodes=(5, 8)` polar angles by azimuths a direction and `paths=8192` eye rays a
    /// node; fewer for a quick look). Refused before any work where the grid's nodes would not
    /// fit in memory; Ctrl-C stops the path tracing (KeyboardInterrupt).
    #[pyo3(signature = (facet="huo", variant="refined", nodes=(5, 8), paths=8192))]
    fn two_faced(
        &self,
        py: Python<'_>,
        facet: &str,
        variant: &str,
        nodes: (i64, i64),
        paths: i64,
    ) -> PyResult<crate::two_faced::PyTwoFaced> {
        crate::two_faced::PyTwoFaced::build(py, &self.fabric, facet, variant, nodes, paths)
    }

    /// f_r(wi, wo) in 1/sr for one pair of unit vectors given as 3 floats each (fabric frame,
    /// analytic model, direct reflection): the scalar path renderers call per sample.
    #[pyo3(signature = (wi, wo, facet="huo"))]
    fn eval1(&self, wi: [f64; 3], wo: [f64; 3], facet: &str) -> PyResult<(f64, f64, f64)> {
        check_unit("wi", 0, wi)?;
        check_unit("wo", 0, wo)?;
        let (a, b) = (unit(wi), unit(wo));
        let f = self.model(facet_model(facet)?).intensity(a, b).brdf(a);
        Ok((f[0], f[1], f[2]))
    }
}
