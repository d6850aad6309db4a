//! `clothbake render`: pictures of cloth shaded with the model or a baked table.
//!
//! A render is a pure function of its inputs: each pixel averages `aa x aa` stratified samples
//! (sub-pixel offsets `((a + 0.5) / aa, (b + 0.5) / aa)`), each a ray of the [`camera`] into
//! the [`scene`], shaded by [`shade::radiance`] in the hit point's tangent frame; background
//! samples count 0. Rows are computed in parallel (rayon) and collected in order, so the image
//! is bit-identical for any number of threads. [`tonemap`] turns it into PNG bytes.

pub mod camera;
pub mod plot;
pub mod scene;
pub mod shade;
pub mod tonemap;

use camera::Camera;
use rayon::prelude::*;
use scene::Scene;
use shade::{radiance, Lighting, Shader};
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
    let aa = aa.max(1);
    let done = AtomicU64::new(0);
    let rows: Vec<Option<Vec<[f32; 3]>>> = (0..camera.height)
        .into_par_iter()
        .map(|j| {
            if cancel.load(Ordering::Relaxed) {
                return None;
            }
            let row = (0..camera.width)
                .map(|i| pixel(scene, camera, lighting, shader, aa, i, j))
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

/// The value of pixel (i, j): the mean of its samples.
fn pixel(
    scene: &Scene,
    camera: &Camera,
    lighting: &Lighting,
    shader: &Shader,
    aa: u32,
    i: u32,
    j: u32,
) -> [f32; 3] {
    let mut sum = [0.0f64; 3];
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
                let v = radiance(shader, lighting, wi, wo);
                for k in 0..3 {
                    sum[k] += v[k];
                }
            }
        }
    }
    let n = f64::from(aa * aa);
    sum.map(|s| (s / n) as f32)
}
