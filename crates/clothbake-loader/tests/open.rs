//! `Brdf::open` reads an averaged half-float OpenEXR table from the file's lines straight into
//! the lookup's nodes (docs/reference/benchmarks.md, "Opening a table"). These tests hold it to the
//! path it replaced, the stored samples (`read_table_stored`) given to `Brdf::from_stored`:
//! the same lookups, pdfs and samples bit for bit, the same table read back, and the same
//! refusal, word for word, of damaged files and unphysical values.

mod common;

use std::fs;
use std::path::{Path, PathBuf};

use clothbake_loader::{
    read_table_stored, write_exr, Brdf, Grid, Memory, Metadata, Options, Precision, StoredTable,
    Table,
};
use common::Rng;

fn dir(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("loader-open-{name}"));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

fn meta(grid: Grid) -> Metadata {
    Metadata::new("clothbake test", grid, "{\"weave\":\"test\"}", "{}", "none")
}

/// Values over several decades with exact zeros and half subnormals, different per channel.
fn values(grid: Grid, seed: u64) -> Vec<f32> {
    let mut r = Rng(seed);
    (0..3 * grid.len())
        .map(|_| match (r.next() * 10.0) as u32 {
            0 => 0.0,
            1 => (r.next() * 6e-5) as f32,
            k => (r.next() * 10f64.powi(k as i32 - 5)) as f32,
        })
        .collect()
}

fn options(memory: Memory, reciprocal: bool) -> Options {
    Options {
        memory,
        reciprocal,
        ..Options::default()
    }
}

/// The lookup as it was built before: the stored samples through `from_stored`.
fn stored_path(p: &Path, o: Options) -> Result<Brdf, String> {
    read_table_stored(p)
        .and_then(|s| Brdf::from_stored(s, o))
        .map_err(|e| e.to_string())
}

fn direction(r: &mut Rng) -> [f32; 3] {
    // Some below the horizon and at the poles; most uniform over the hemisphere.
    let mu = match (r.next() * 20.0) as u32 {
        0 => -0.3,
        1 => 1.0,
        _ => r.next(),
    };
    let phi = std::f64::consts::TAU * r.next();
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    [(s * phi.cos()) as f32, (s * phi.sin()) as f32, mu as f32]
}

fn bits(v: [f32; 3]) -> [u32; 3] {
    v.map(f32::to_bits)
}

/// Every lookup of `a` is `b`'s to the bit: eval, eval_deg, eval_batch, pdf and sample.
fn same_lookups(a: &Brdf, b: &Brdf, pairs: usize, seed: u64) {
    let mut r = Rng(seed);
    let (wi, wo): (Vec<[f32; 3]>, Vec<[f32; 3]>) = (0..pairs)
        .map(|_| (direction(&mut r), direction(&mut r)))
        .unzip();
    for (i, o) in wi.iter().zip(&wo) {
        assert_eq!(bits(a.eval(*i, *o)), bits(b.eval(*i, *o)), "{i:?} {o:?}");
        assert_eq!(
            a.pdf(*i, *o).to_bits(),
            b.pdf(*i, *o).to_bits(),
            "{i:?} {o:?}"
        );
    }
    let (mut fa, mut fb) = (vec![[0f32; 3]; pairs], vec![[0f32; 3]; pairs]);
    a.eval_batch(&wi, &wo, &mut fa).unwrap();
    b.eval_batch(&wi, &wo, &mut fb).unwrap();
    assert!(fa.iter().zip(&fb).all(|(x, y)| bits(*x) == bits(*y)));
    for o in wo.iter().take(2000) {
        let (u1, u2) = (r.next() as f32, r.next() as f32);
        let (sa, sb) = (a.sample(*o, u1, u2), b.sample(*o, u1, u2));
        assert_eq!(
            (bits(sa.wi), bits(sa.weight), sa.pdf.to_bits()),
            (bits(sb.wi), bits(sb.weight), sb.pdf.to_bits())
        );
        let t = [r.next() * 89.9, r.next() * 720.0 - 360.0].map(|x| x as f32);
        assert_eq!(
            bits(a.eval_deg(t[0], t[1], 45.0, t[1] * 0.5)),
            bits(b.eval_deg(t[0], t[1], 45.0, t[1] * 0.5))
        );
    }
}

#[test]
fn opening_from_the_lines_gives_the_stored_lookup_value_for_value() {
    let d = dir("same");
    // The default grid (two threads, many blocks), and small odd grids whose rings straddle
    // the 16-line blocks.
    for (k, n) in [
        [32, 64, 32, 64],
        [5, 7, 4, 9],
        [3, 2, 2, 3],
        [1, 1, 1, 1],
        [9, 3, 7, 2],
    ]
    .into_iter()
    .enumerate()
    {
        let grid = Grid::new(n[0], n[1], n[2], n[3]);
        let table = Table::new(meta(grid), values(grid, k as u64)).unwrap();
        let p = d.join(format!("t{k}.exr"));
        write_exr(&p, &table, Precision::F16, true).unwrap();
        for (memory, reciprocal) in [
            (Memory::AsStored, false),
            (Memory::AsStored, true),
            (Memory::F32, false),
        ] {
            let o = options(memory, reciprocal);
            let new = Brdf::open(&p, o).unwrap();
            let old = stored_path(&p, o).unwrap();
            assert_eq!(new.precision(), old.precision());
            assert_eq!(new.memory_bytes(), old.memory_bytes());
            same_lookups(&new, &old, 20_000, 7 + k as u64);
            // The values read back from the nodes are the file's: the written values rounded
            // to half, as the generic decoder of the `exr` crate reads them too.
            let stored = read_table_stored(&p).unwrap();
            let want = StoredTable::from_table(table.clone(), Precision::F16).unwrap();
            assert_eq!(stored, want);
            let generic = exr_generic(&p, grid);
            assert_eq!(stored.samples.clone().into_f32(), generic);
            if memory == Memory::AsStored {
                assert_eq!(new.to_stored(), Some(stored), "{n:?}");
            } else {
                assert_eq!(new.to_stored(), Some(stored.into_table().into()), "{n:?}");
            }
        }
    }
}

/// The samples of a table file as the `exr` crate's own reader decodes them, widened, in the
/// table's order (the reference the block reader is held to).
fn exr_generic(p: &Path, grid: Grid) -> Vec<f32> {
    use exr::prelude::*;
    let image = read_all_flat_layers_from_file(p).unwrap();
    let layer = &image.layer_data[0];
    let plane = |name: &str| -> Vec<f32> {
        let c = layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name == *name)
            .unwrap();
        c.sample_data.values_as_f32().collect()
    };
    let rgb = [plane("R"), plane("G"), plane("B")];
    let (nto, npi, npo) = (
        grid.n_theta_o as usize,
        grid.n_phi_i as usize,
        grid.n_phi_o as usize,
    );
    let width = npi * npo;
    let mut out = vec![0f32; 3 * grid.len()];
    for (i, v) in out.iter_mut().enumerate() {
        let (cell, k) = (i / 3, i % 3);
        let (po, rest) = (cell % npo, cell / npo);
        let (to, rest) = (rest % nto, rest / nto);
        let (pi, ti) = (rest % npi, rest / npi);
        *v = rgb[k][(ti * nto + to) * width + pi * npo + po];
    }
    out
}

#[test]
fn damaged_half_tables_are_refused_as_the_stored_path_refuses_them() {
    let d = dir("damaged");
    let grid = Grid::new(4, 8, 5, 8);
    let table = Table::new(meta(grid), values(grid, 3)).unwrap();
    let p = d.join("t.exr");
    write_exr(&p, &table, Precision::F16, true).unwrap();
    let good = fs::read(&p).unwrap();
    let (mut refused, mut same) = (0, 0);
    let o = Options::default();
    for i in (0..good.len()).step_by(3) {
        let mut bad = good.clone();
        bad[i] ^= 0x5a;
        fs::write(&p, &bad).unwrap();
        match (Brdf::open(&p, o), stored_path(&p, o)) {
            (Err(a), Err(b)) => {
                assert_eq!(a.to_string(), b, "byte {i}");
                refused += 1;
            }
            (Ok(a), Ok(b)) => {
                same_lookups(&a, &b, 200, i as u64);
                same += 1;
            }
            (a, b) => panic!("byte {i}: open {:?}, stored {:?}", a.err(), b.err()),
        }
    }
    // Truncated anywhere.
    for cut in (0..good.len()).step_by(97) {
        fs::write(&p, &good[..cut]).unwrap();
        let a = Brdf::open(&p, o).map(|_| ()).map_err(|e| e.to_string());
        assert_eq!(a, stored_path(&p, o).map(|_| ()), "cut at {cut}");
    }
    assert!(
        refused > 0 && same > 0,
        "{refused} refused, {same} harmless"
    );
}

/// An OpenEXR table of half samples written around the writer's checks (which refuse
/// unphysical values), without a checksum: `bad` holds (sample index in the table's order,
/// half bits).
fn raw_half_exr(p: &Path, grid: Grid, bad: &[(usize, u16)]) {
    use exr::prelude::*;
    let mut v: Vec<f16> = values(grid, 11).into_iter().map(f16::from_f32).collect();
    for &(i, b) in bad {
        v[i] = f16::from_bits(b);
    }
    let (nto, npo) = (grid.n_theta_o as usize, grid.n_phi_o as usize);
    let npi = grid.n_phi_i as usize;
    let at = |x: usize, y: usize, k: usize| {
        let (ti, to, pi, po) = (y / nto, y % nto, x / npo, x % npo);
        v[3 * (((ti * npi + pi) * nto + to) * npo + po) + k]
    };
    let (w, h) = (grid.exr_width() as usize, grid.exr_height() as usize);
    let channels =
        SpecificChannels::rgb(|p: Vec2<usize>| (at(p.0, p.1, 0), at(p.0, p.1, 1), at(p.0, p.1, 2)));
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let mut attributes = LayerAttributes::default();
    let json = serde_json::to_string(&meta(grid)).unwrap();
    attributes.other.insert(
        Text::from("clothbake.metadata"),
        AttributeValue::Text(Text::from(json.as_str())),
    );
    let layer = Layer::new((w, h), attributes, encoding, channels);
    Image::from_layer(layer).write().to_file(p).unwrap();
}

#[test]
fn unphysical_half_values_are_refused_as_the_stored_path_refuses_them() {
    let d = dir("unphysical");
    let grid = Grid::new(32, 64, 32, 64);
    let last = 3 * grid.len() - 1;
    // Infinity, NaN, a negative value and a negative subnormal; alone, and two at once (in
    // the rings of both threads: the first in the table's order is named).
    let cases: [&[(usize, u16)]; 6] = [
        &[(3 * 5 + 1, 0x7c00)],
        &[(last, 0x7e00)],
        &[(3 * grid.len() / 2, 0xbc00)],
        &[(100, 0x8001)],
        &[(last - 4, 0xfc00), (3 * 70_000 + 2, 0xc000)],
        &[(3, 0x8000)], // -0 is zero: not refused
    ];
    for (k, bad) in cases.iter().enumerate() {
        let p = d.join(format!("t{k}.exr"));
        raw_half_exr(&p, grid, bad);
        let o = Options::default();
        match (Brdf::open(&p, o), stored_path(&p, o)) {
            (Err(a), Err(b)) => {
                let a = a.to_string();
                assert_eq!(a, b);
                assert!(
                    a.contains("bake it again")
                        && a.contains("t{k}.exr".replace("{k}", &k.to_string()).as_str()),
                    "{a}"
                );
            }
            (Ok(a), Ok(b)) => {
                assert_eq!(k, 5, "only -0 is physical");
                same_lookups(&a, &b, 2000, 1);
            }
            (a, b) => panic!("case {k}: open {:?}, stored {:?}", a.err(), b.err()),
        }
    }
}
