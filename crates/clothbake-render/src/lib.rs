//! `clothbake render`: pictures of cloth shaded with the model or a baked table.
//!
//! A render is a pure function of its inputs: each pixel averages `aa x aa` stratified samples
//! (sub-pixel offsets `((a + 0.5) / aa, (b + 0.5) / aa)`), each a ray of the [`camera`] into
//! the [`scene`], shaded by [`shade::radiance`] (a sun and a sky) in the hit point's tangent frame; background
//! samples count 0. Rows are computed in parallel (rayon) and collected in order, so the image
//! is bit-identical for any number of threads. [`tonemap`] turns it into PNG bytes.

pub mod camera;
pub mod plot;
pub mod scene;
pub mod shade;
pub mod tonemap;
pub mod typeset;

use camera::Camera;
use clothbake_core::Footprint;
use rayon::prelude::*;
use scene::Scene;
use shade::{shade_at, Lighting, Shader};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use tonemap::Image;

/// Renders `scene` seen by `camera` with `aa x aa` samples per pixel. `progress` receives the
/// number of finished rows (in any order; it only grows); raising `cancel` stops the render
/// (returns `None`).
pub fn render(
    scene: &Scene,
    camera: &Camera,
    lighting: &Lighting,
    shader: &Shader,
    aa: u32,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Option<Image> {
    render_weave(scene, camera, lighting, shader, aa, None, progress, cancel)
}

/// As [`render`], with `periods` weave periods across the scene's width ([`Scene::width`]):
/// each sample looks f_r up at its point of the period through its footprint
/// ([`Weave::footprint`]).
#[allow(clippy::too_many_arguments)]
pub fn render_weave(
    scene: &Scene,
    camera: &Camera,
    lighting: &Lighting,
    shader: &Shader,
    aa: u32,
    periods: Option<f64>,
    progress: &(dyn Fn(u64) + Sync),
    cancel: &AtomicBool,
) -> Option<Image> {
    let aa = aa.max(1);
    let weave = periods.map(|n| Weave {
        per_length: n / scene.width(),
        // The angle one sample subtends: the image plane's width over its pixels and samples.
        sample_angle: 2.0 * camera.tan_half / f64::from(camera.width.max(1) * aa),
    });
    let done = AtomicU64::new(0);
    let rows: Vec<Option<Vec<[f32; 3]>>> = (0..camera.height)
        .into_par_iter()
        .map(|j| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let row = (0..camera.width)
                .map(|i| pixel(scene, camera, lighting, shader, aa, weave, i, j))
                .collect();
            progress(done.fetch_add(1, Ordering::Relaxed) + 1);
            Some(row)
        })
        .collect();
    let mut pixels = Vec::with_capacity((camera.width * camera.height) as usize);
    for r in rows {
        pixels.extend(r?);
    }
    Some(Image {
        width: camera.width,
        height: camera.height,
        pixels,
    })
}

/// How a render maps surface points to the weave period (`render --periods`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weave {
    /// Periods per scene length.
    pub per_length: f64,
    /// The angle one sample subtends at the eye, radians.
    pub sample_angle: f64,
}

impl Weave {
    /// The footprint of a sample that meets the surface at `hit`, at distance `t` from the eye,
    /// seen at cos(theta_o) `cos_o`: the point in period fractions and the side of the square
    /// of equal area to the sample's footprint on the surface (t angle / sqrt(cos theta_o)).
    pub fn footprint(&self, hit: &scene::Hit, t: f64, cos_o: f64) -> Footprint {
        let side = t * self.sample_angle / cos_o.max(1e-3).sqrt();
        Footprint {
            u: hit.surface.0 * self.per_length,
            v: hit.surface.1 * self.per_length,
            width: side * self.per_length,
        }
    }
}

/// The value of pixel (i, j): the mean of its samples. With `--gaps` each sample counts with
/// its coverage; without, samples that show a gap (coverage 0, the point level) are left out
/// of the mean of those that meet the cloth, which is then weighted by the share of the
/// pixel's samples that meet the surface.
#[allow(clippy::too_many_arguments)]
fn pixel(
    scene: &Scene,
    camera: &Camera,
    lighting: &Lighting,
    shader: &Shader,
    aa: u32,
    weave: Option<Weave>,
    i: u32,
    j: u32,
) -> [f32; 3] {
    let mut sum = [0.0f64; 3];
    let (mut surface, mut gaps) = (0u32, 0u32);
    for b in 0..aa {
        for a in 0..aa {
            let (sx, sy) = (
                (f64::from(a) + 0.5) / f64::from(aa),
                (f64::from(b) + 0.5) / f64::from(aa),
            );
            let ray = camera.ray(i, j, sx, sy);
            if let Some(hit) = scene.intersect(&ray) {
                let wi = hit.to_local(lighting.light);
                let wo = hit.to_local(-ray.dir);
                let at = weave.map(|w| {
                    let t = (hit.point - ray.origin).length();
                    w.footprint(&hit, t, wo.z)
                });
                let up = hit.to_local(clothbake_core::Vec3::new(0.0, 0.0, 1.0));
                let (v, c) = shade_at(shader, lighting, wi, wo, up, at);
                surface += 1;
                if shader.shows_gaps() {
                    for k in 0..3 {
                        sum[k] += v[k] * c;
                    }
                } else if c == 0.0 && at.is_some() && wo.z > 0.0 {
                    gaps += 1;
                } else {
                    for k in 0..3 {
                        sum[k] += v[k];
                    }
                }
            }
        }
    }
    let n = f64::from(aa * aa);
    if gaps == 0 {
        return sum.map(|s| (s / n) as f32);
    }
    let yarn = f64::from(surface - gaps);
    if yarn == 0.0 {
        return [0.0; 3];
    }
    let share = f64::from(surface) / n;
    sum.map(|s| (s / yarn * share) as f32)
}
