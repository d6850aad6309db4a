//! The ground truth resolved over the weave period: [`RayTracer::render_cells`] sorts every
//! counted hit of the direct estimate into the crossing cell it belongs to (docs/science/spatial.md),
//! by rules of its own written from the docs, not from the model's code.
//!
//! A hit on the float of thread t (warp or weft) at coordinate y along the thread's axis
//! belongs to cell (t, k), k the crossing thread nearest y (the cell edges are midway between
//! neighbouring crossing threads); where that thread passes over thread t (the hit lies on the
//! float's end, beyond the midpoint before its first or after its last crossing), k moves one
//! thread toward the float's middle.

use super::estimate::{batch_ratio, BatchSums, BATCHES};
use super::raytracer::RayTracer;
use clothbake_bsdf::rng::Rng;
use clothbake_bsdf::vec3::UnitVec3;
use clothbake_fabric::weave::Group;
use clothbake_fabric::Reflection;

/// The truth over one crossing cell.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CellEstimate {
    /// The intensity averaged over the cell's counted yarn hits (zero without hits).
    pub reflection: Reflection,
    /// Standard error of the total intensity, per channel (infinite with fewer than two
    /// batches holding hits).
    pub std_err: [f64; 3],
    /// The cell's coverage: counted yarn hits per ray, over the cell's share of the period.
    pub coverage: f64,
    /// Standard error of the coverage (binomial).
    pub coverage_err: f64,
    /// Counted yarn hits in the cell.
    pub hits: usize,
}

/// Index along `pos` (increasing thread positions in [0, period)) of the thread nearest `y`
/// (wrapped), and that thread's unwrapped position nearest `y`.
fn nearest(pos: &[f64], period: f64, y: f64) -> (usize, f64) {
    let w = y.rem_euclid(period);
    let mut best = (0, f64::INFINITY, 0.0);
    for (k, &p) in pos.iter().enumerate() {
        for q in [p - period, p, p + period] {
            let d = (w - q).abs();
            if d < best.1 {
                best = (k, d, q + (y - w));
            }
        }
    }
    (best.0, best.2)
}

impl RayTracer {
    /// Row-major index (weft row, then warp column) of the cell a counted hit at `point` on
    /// segment `seg` belongs to (see the module docs).
    fn cell_of(&self, seg: u32, point: clothbake_bsdf::vec3::Vec3) -> usize {
        let c = &self.yarns.cylinders[seg as usize];
        let (wx, wy) = (&self.yarns.threads.0, &self.yarns.threads.1);
        let (px, py) = self.yarns.period;
        let (cross_pos, cross_period, y) = match c.group {
            Group::Warp => (wy, py, point.y),
            Group::Weft => (wx, px, point.x),
        };
        let n = cross_pos.len();
        let (mut k, p) = nearest(cross_pos, cross_period, y);
        if let Some((e0, e1)) = c.extent {
            // The float's copy holding y, and whether crossing k lies under it.
            let shift = ((y - e0) / cross_period).floor() * cross_period;
            let inside = |q: f64| e0 + shift < q && q < e1 + shift;
            if !inside(p) {
                k = if y > p { (k + 1) % n } else { (k + n - 1) % n };
            }
        }
        match c.group {
            Group::Warp => k * wx.len() + c.thread,
            Group::Weft => c.thread * wx.len() + k,
        }
    }

    /// The direct estimate of [`RayTracer::render`] (same rays for the same seed), resolved
    /// per crossing cell: row-major, weft row then warp column. Empty below the horizon.
    pub fn render_cells(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        samples: usize,
        seed: u64,
    ) -> Vec<CellEstimate> {
        let (nx, ny) = (self.yarns.threads.0.len(), self.yarns.threads.1.len());
        if !(wi.above_horizon() && wo.above_horizon()) {
            return Vec::new();
        }
        let mut sums = vec![[BatchSums::default(); BATCHES]; nx * ny];
        let mut rays = 0u64;
        for b in 0..BATCHES {
            let m = samples / BATCHES + usize::from(b < samples % BATCHES);
            let mut rng = Rng::stream(seed, b as u64);
            for cell in sums.iter_mut() {
                cell[b].rays = m as u64;
            }
            rays += m as u64;
            for o in self.origins(m, &mut rng) {
                let Some((s, c)) = self.shade(o, wi, wo) else {
                    continue;
                };
                let albedo = self.cylinder(&c).finish.albedo;
                let cell = &mut sums[self.cell_of(c.seg, c.point)][b];
                cell.hits += 1;
                for (d, a) in cell.diffuse.iter_mut().zip(albedo) {
                    *d += s.diffuse * a;
                }
                cell.specular += s.specular;
            }
        }
        let (wx, wy) = (&self.yarns.threads.0, &self.yarns.threads.1);
        let (px, py) = self.yarns.period;
        let width = |pos: &[f64], period: f64, k: usize| {
            let n = pos.len();
            let prev = if k == 0 {
                pos[n - 1] - period
            } else {
                pos[k - 1]
            };
            let next = if k + 1 == n {
                pos[0] + period
            } else {
                pos[k + 1]
            };
            0.5 * (next - prev)
        };
        sums.iter()
            .enumerate()
            .map(|(i, cell)| {
                let (kx, ky) = (i % nx, i / nx);
                let share = width(wx, px, kx) * width(wy, py, ky) / (px * py);
                let hits: u64 = cell.iter().map(|b| b.hits).sum();
                let f = hits as f64 / rays.max(1) as f64;
                let mut e = CellEstimate {
                    hits: hits as usize,
                    coverage: f / share,
                    coverage_err: (f * (1.0 - f) / rays.max(1) as f64).sqrt() / share,
                    ..CellEstimate::default()
                };
                let ratio = |g: &dyn Fn(&BatchSums) -> f64| {
                    let b: Vec<(f64, u64, u64)> =
                        cell.iter().map(|s| (g(s), s.hits, s.rays)).collect();
                    batch_ratio(&b)
                };
                for k in 0..3 {
                    e.reflection.i_d[k] = ratio(&|s| s.diffuse[k]).0;
                    e.std_err[k] = ratio(&|s| s.diffuse[k] + s.specular).1;
                }
                e.reflection.i_s = [ratio(&|s| s.specular).0; 3];
                e
            })
            .collect()
    }
}
