//! The lookup's nodes of a table's values: the grid padded with a pole node on each polar axis
//! ([`crate::Axis::lookup_node`] says where a lookup reads them), whose value is the mean of
//! the first ring over the azimuths, so that a lookup is continuous at the pole and does not
//! depend on the azimuth there. The tiles that hold them are `crate::nodes`'.

use half::f16;

use crate::grid::Grid;
use crate::nodes::{self, Nodes, Values};
use crate::stored::Samples;

/// The padded node table ([`Nodes`]) of an averaged table's values, where polar row 0 is
/// the pole node (the mean over the azimuths of the first ring) and row `k + 1` is cell `k`;
/// half floats when `f16` and the samples are half. The same lanes as [`pad4`] of the
/// widened values (a half's bits are copied, which is what rounding its widened value gives),
/// filled a row at a time from the samples.
pub(crate) fn pad(g: &Grid, samples: &Samples, f16: bool) -> Nodes {
    let widen = |h: f16| crate::stored::f16_to_f32(h.to_bits());
    let values = match samples {
        Samples::F16(s) if f16 => Values::F16(pad_rows(g, s, widen, |h| h, f16::from_f32)),
        Samples::F16(s) => Values::F32(pad_rows(g, s, widen, widen, |x| x)),
        Samples::F32(s) => Values::F32(pad_rows(g, s, |x| x, |x| x, |x| x)),
    };
    Nodes::with_values(g, values)
}

/// The tiles of [`pad`] from samples `s` (interleaved RGB in cell order): `widen` gives a
/// sample's f32 value, `copy` its lane, `lane` the lane of an f32 (the pole means, 0).
fn pad_rows<S: Copy + Sync, V: Copy + Default + Send + Sync>(
    g: &Grid,
    s: &[S],
    widen: impl Fn(S) -> f32 + Sync,
    copy: impl Fn(S) -> V + Sync,
    lane: impl Fn(f32) -> V + Sync,
) -> nodes::Tiles<V> {
    let (npi, npo) = (g.n_phi_i as usize, g.n_phi_o as usize);
    let value = |ti: u32, pi: u32, to: u32, po: u32| -> [f32; 4] {
        let c = 3 * g.index(ti, pi, to, po);
        [widen(s[c]), widen(s[c + 1]), widen(s[c + 2]), 0.0]
    };
    let (pole_i, pole_o, pole_io) = poles(g, &value);
    let zero = lane(0.0);
    let pole_i: Vec<[V; 4]> = pole_i.iter().map(|x| x.map(&lane)).collect();
    let pole_o: Vec<[V; 4]> = pole_o.iter().map(|x| x.map(&lane)).collect();
    let pole_io = pole_io.map(&lane);
    nodes::Tiles::from_rows(g, &|ri, pi, ro, row: &mut [[V; 4]]| match (ri, ro) {
        (0, 0) => row.fill(pole_io),
        (0, _) => row.copy_from_slice(&pole_i[(ro as usize - 1) * npo..ro as usize * npo]),
        (_, 0) => row.fill(pole_o[(ri as usize - 1) * npi + pi as usize]),
        _ => {
            let c = 3 * g.index(ri - 1, pi, ro - 1, 0);
            for (x, v) in row.iter_mut().zip(s[c..c + 3 * npo].chunks_exact(3)) {
                *x = [copy(v[0]), copy(v[1]), copy(v[2]), zero];
            }
        }
    })
}

/// The pole nodes of `value` (cell `(ti, pi, to, po)`, four lanes): at the incident pole, per
/// outgoing cell `(to, po)`, the mean over `phi_i` of the first incident ring; at the
/// outgoing pole, per incident cell, the mean over `phi_o`; at both, the mean of both first
/// rings. Means in f64, in a fixed order.
#[allow(clippy::type_complexity)]
fn poles(
    g: &Grid,
    value: &dyn Fn(u32, u32, u32, u32) -> [f32; 4],
) -> (Vec<[f32; 4]>, Vec<[f32; 4]>, [f32; 4]) {
    let (nti, npi, nto, npo) = (g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o);
    // Mean of `value` over the listed azimuth pairs, in f64, in a fixed order.
    let mean = |pairs: &mut dyn Iterator<Item = [f32; 4]>| -> [f32; 4] {
        let (mut sum, mut n) = ([0f64; 4], 0f64);
        for x in pairs {
            for k in 0..4 {
                sum[k] += f64::from(x[k]);
            }
            n += 1.0;
        }
        sum.map(|s| (s / n) as f32)
    };
    let pole_i: Vec<[f32; 4]> = (0..nto)
        .flat_map(|to| (0..npo).map(move |po| (to, po)))
        .map(|(to, po)| mean(&mut (0..npi).map(|pi| value(0, pi, to, po))))
        .collect();
    let pole_o: Vec<[f32; 4]> = (0..nti)
        .flat_map(|ti| (0..npi).map(move |pi| (ti, pi)))
        .map(|(ti, pi)| mean(&mut (0..npo).map(|po| value(ti, pi, 0, po))))
        .collect();
    let pole_io = mean(&mut (0..npi).flat_map(|pi| (0..npo).map(move |po| value(0, pi, 0, po))));
    (pole_i, pole_o, pole_io)
}

/// [`pad`] of four lanes (a spatial table's two classes a node, `crate::spatial_lookup`).
pub(crate) fn pad4(
    g: &Grid,
    value: &(dyn Fn(u32, u32, u32, u32) -> [f32; 4] + Sync),
    f16: bool,
) -> Nodes {
    let npo = g.n_phi_o;
    let npi = g.n_phi_i;
    let (pole_i, pole_o, pole_io) = poles(g, value);
    let node = |ri: u32, pi: u32, ro: u32, po: u32| match (ri, ro) {
        (0, 0) => pole_io,
        (0, _) => pole_i[((ro - 1) * npo + po) as usize],
        (_, 0) => pole_o[((ri - 1) * npi + pi) as usize],
        _ => value(ri - 1, pi, ro - 1, po),
    };
    Nodes::new4(g, &node, f16)
}
