//! Fuzzing every reader of the project's files, on stable Rust, in the normal test suite: the
//! fabric file (JSON), the WIF draft, the table as OpenEXR, the binary table (version 2
//! container and version 1), each averaged and spatial (one bounce and two), and shard and
//! checkpoint files.
//!
//! Each target first replays every file of its corpus, `tests/fuzz-corpus/<target>/` (inputs
//! that once failed, kept as regressions, and hand-made ones), then mutates valid seed files
//! with a seeded generator (bit flips, random and "interesting" bytes and integers, insertions,
//! deletions, truncations, duplicated chunks, the reader's own tokens; for checksummed
//! containers the CRC is made right again half the time, so that the checks behind it are
//! reached) for a bounded time: `CLOTHBAKE_FUZZ_SECS` seconds a target (default 4), with a
//! seed from `CLOTHBAKE_FUZZ_SEED` (default fixed, so a run is reproducible up to its time
//! budget).
//!
//! Every input must give `Ok` or `Err`: never a panic (caught) and never one allocation above
//! 256 MiB (a counting allocator; above 1 GiB it refuses, which aborts). A failing input is
//! saved into the corpus as `crash-<hash>` and the test fails naming it. Each target runs in a
//! child process (this test binary again, `CLOTHBAKE_FUZZ_CHILD=<target>`), and writes each
//! input to `<target tmp>/fuzz/fuzz-<target>.current` before reading it, so that an input that
//! kills the process is saved too.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use clothbake_bake::job::{self, Hooks, Job, Target};
use clothbake_bake::shard::{read_part, ShardId};
use clothbake_bake::{bake, BakeBounces, BakeOptions};
use clothbake_core::Fabric;
use clothbake_loader::{
    read_table, write_binary, write_exr, Brdf, Grid, Metadata, Options, Precision, Table,
};

/// The largest single allocation a reader may make for any input.
const LIMIT: usize = 256 << 20;

/// Allocations above this are refused (the process aborts; the parent saves the input).
const REFUSED: usize = 1 << 30;

thread_local! {
    /// The largest allocation of this thread since it was last reset.
    static BIGGEST: Cell<usize> = const { Cell::new(0) };
}

/// The system allocator, noting the largest request of each thread.
struct Counting;

fn note(n: usize) {
    let _ = BIGGEST.try_with(|b| {
        if n > b.get() {
            b.set(n);
        }
    });
}

// SAFETY: forwards every call to the system allocator unchanged.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        note(l.size());
        if l.size() > REFUSED {
            return std::ptr::null_mut();
        }
        System.alloc(l)
    }
    unsafe fn alloc_zeroed(&self, l: Layout) -> *mut u8 {
        note(l.size());
        if l.size() > REFUSED {
            return std::ptr::null_mut();
        }
        System.alloc_zeroed(l)
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, new: usize) -> *mut u8 {
        note(new);
        if new > REFUSED {
            return std::ptr::null_mut();
        }
        System.realloc(p, l, new)
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        System.dealloc(p, l)
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// SplitMix64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Integers that break size and count fields.
const INTERESTING: [u64; 12] = [
    0,
    1,
    0x7f,
    0xff,
    0xffff,
    0x7fff_ffff,
    0x8000_0000,
    0xffff_ffff,
    1 << 32,
    (1 << 32) + 1,
    1 << 60,
    u64::MAX,
];

/// Applies 1 to 4 random mutations to `data`, with `tokens` of the reader's language.
fn mutate(rng: &mut Rng, data: &mut Vec<u8>, tokens: &[&[u8]]) {
    for _ in 0..1 + rng.below(4) {
        let len = data.len();
        let at = rng.below(len + 1);
        match rng.below(9) {
            0 if len > 0 => {
                let i = rng.below(len);
                data[i] ^= 1 << rng.below(8);
            }
            1 if len > 0 => {
                let i = rng.below(len);
                data[i] = rng.next() as u8;
            }
            2 => {
                let n = 1 + rng.below(16);
                let bytes: Vec<u8> = (0..n).map(|_| rng.next() as u8).collect();
                data.splice(at..at, bytes);
            }
            3 if len > 0 => {
                let n = 1 + rng.below(64.min(len - at.min(len - 1)));
                let from = at.min(len - 1);
                data.drain(from..(from + n).min(len));
            }
            4 => data.truncate(at),
            5 => {
                let v = INTERESTING[rng.below(INTERESTING.len())];
                let bytes = if rng.below(2) == 0 {
                    v.to_le_bytes().to_vec()
                } else {
                    (v as u32).to_le_bytes().to_vec()
                };
                let end = (at + bytes.len()).min(len);
                data.splice(at.min(end)..end, bytes);
            }
            6 if !tokens.is_empty() => {
                let t = tokens[rng.below(tokens.len())];
                data.splice(at..at, t.iter().copied());
            }
            7 if len > 1 => {
                let from = rng.below(len);
                let n = 1 + rng.below((len - from).min(256));
                let chunk = data[from..from + n].to_vec();
                data.splice(at..at, chunk);
            }
            _ => {
                // A digit string: numbers far beyond every type.
                let digits: Vec<u8> = (0..1 + rng.below(40))
                    .map(|_| b'0' + rng.below(10) as u8)
                    .collect();
                data.splice(at..at, digits);
            }
        }
    }
}

/// Makes the trailing CRC-32 of a binary container (of everything before it) right again.
fn fix_crc(data: &mut [u8]) {
    if data.len() >= 8 {
        let n = data.len();
        let crc = crc32fast::hash(&data[..n - 4]);
        data[n - 4..].copy_from_slice(&crc.to_le_bytes());
    }
}

/// A reader under test: its corpus folder name, the file extension it reads, its language's
/// tokens, whether its files end in a CRC, and the reader itself (`Err` text is ignored; a
/// panic or a too large allocation fails the input).
struct Reader<'a> {
    name: &'a str,
    ext: &'a str,
    tokens: &'a [&'a [u8]],
    crc: bool,
    read: &'a dyn Fn(&Path),
}

fn corpus(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz-corpus")
        .join(name)
}

fn scratch() -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz");
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn budget() -> Duration {
    let secs = std::env::var("CLOTHBAKE_FUZZ_SECS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or(4.0);
    Duration::from_secs_f64(secs.max(0.0))
}

fn base_seed() -> u64 {
    std::env::var("CLOTHBAKE_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x636c_6f74_6862_616b)
}

/// FNV-1a, for crash file names.
fn hash(data: &[u8]) -> u64 {
    data.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// Runs the reader on `data`; `Some(why)` when it panicked or allocated too much.
fn check(t: &Reader<'_>, data: &[u8], file: &Path, current: &Path) -> Option<String> {
    std::fs::write(current, data).unwrap();
    std::fs::write(file, data).unwrap();
    BIGGEST.with(|b| b.set(0));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| (t.read)(file)));
    let biggest = BIGGEST.with(Cell::get);
    let _ = std::fs::remove_file(current);
    match r {
        Err(p) => Some(format!(
            "panicked: {}",
            p.downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default()
        )),
        Ok(()) if biggest > LIMIT => Some(format!("allocated {biggest} bytes at once")),
        Ok(()) => None,
    }
}

/// Saves `data` into the target's corpus; returns the file.
fn save(t: &Reader<'_>, data: &[u8]) -> PathBuf {
    let dir = corpus(t.name);
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(format!("crash-{:016x}.{}", hash(data), t.ext));
    std::fs::write(&p, data).unwrap();
    p
}

/// Replays the corpus, then fuzzes from `seeds` for the time budget; panics naming the saved
/// inputs that failed.
fn fuzz(t: &Reader<'_>, seeds: &[Vec<u8>]) {
    let dir = scratch();
    let file = dir.join(format!("{}-input.{}", t.name, t.ext));
    let current = dir.join(format!("fuzz-{}.current", t.name));
    let mut failures = Vec::new();
    // The corpus, always.
    let mut replayed = 0;
    if let Ok(entries) = std::fs::read_dir(corpus(t.name)) {
        let mut paths: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
        paths.sort();
        for p in paths {
            let data = std::fs::read(&p).unwrap();
            replayed += 1;
            if let Some(why) = check(t, &data, &file, &current) {
                failures.push(format!("{}: {why}", p.display()));
            }
        }
    }
    for s in seeds {
        if let Some(why) = check(t, s, &file, &current) {
            failures.push(format!("a seed of {}: {why}", t.name));
        }
    }
    let mut rng = Rng(base_seed() ^ hash(t.name.as_bytes()));
    let (start, limit) = (Instant::now(), budget());
    let mut runs = 0u64;
    while start.elapsed() < limit && failures.len() < 5 {
        let mut data = seeds[rng.below(seeds.len())].clone();
        mutate(&mut rng, &mut data, t.tokens);
        if t.crc && rng.below(2) == 0 {
            fix_crc(&mut data);
        }
        runs += 1;
        if let Some(why) = check(t, &data, &file, &current) {
            let p = save(t, &data);
            failures.push(format!("{}: {why}", p.display()));
        }
    }
    eprintln!(
        "fuzz {}: {replayed} corpus inputs replayed, {runs} mutated inputs in {:.1} s",
        t.name,
        start.elapsed().as_secs_f64()
    );
    assert!(
        failures.is_empty(),
        "{} input(s) of {} failed (saved in the corpus):\n{}",
        failures.len(),
        t.name,
        failures.join("\n")
    );
}

/// Runs `body` (the fuzzing of target `name`, the test function `test`) in a child process,
/// so that an input that aborts the process is saved and named like any other failure.
fn isolated(name: &str, ext: &str, test: &str, body: impl FnOnce()) {
    if std::env::var("CLOTHBAKE_FUZZ_CHILD").as_deref() == Ok(name) {
        body();
        return;
    }
    let current = scratch().join(format!("fuzz-{name}.current"));
    let _ = std::fs::remove_file(&current);
    let out = std::process::Command::new(std::env::current_exe().unwrap())
        .args([test, "--exact", "--nocapture", "--test-threads", "1"])
        .env("CLOTHBAKE_FUZZ_CHILD", name)
        .output()
        .expect("run the fuzz child");
    let err = String::from_utf8_lossy(&out.stderr);
    // What went wrong and where: the abort or panic line, the frames in clothbake's crates.
    let lines: Vec<&str> = err.lines().collect();
    let tail: Vec<&str> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| {
            l.contains("memory allocation")
                || l.contains("panicked")
                || l.contains("failed")
                || (l.contains("clothbake_") && !l.contains("fuzz::"))
        })
        .flat_map(|(k, _)| lines[k..(k + 2).min(lines.len())].iter().copied())
        .take(16)
        .collect();
    if out.status.success() {
        if let Some(line) = err.lines().find(|l| l.starts_with("fuzz ")) {
            eprintln!("{line}");
        }
        return;
    }
    if let Ok(data) = std::fs::read(&current) {
        let dir = corpus(name);
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(format!("crash-{:016x}.{ext}", hash(&data)));
        std::fs::write(&p, &data).unwrap();
        let _ = std::fs::remove_file(&current);
        panic!(
            "{name}: the reader ended the process ({}) on {} (saved in the corpus):\n{}",
            out.status,
            p.display(),
            tail.join("\n")
        );
    }
    panic!("{name} failed ({}):\n{}", out.status, tail.join("\n"));
}

fn tables() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables")
}

fn files_with(ext: &str) -> Vec<Vec<u8>> {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(tables())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    paths.sort();
    paths.iter().map(|p| std::fs::read(p).unwrap()).collect()
}

const GRID: Grid = Grid::new(2, 4, 2, 4);

fn small_table() -> Table {
    let fabric = std::fs::read_to_string(tables().join("plain.json")).unwrap();
    let values = (0..3 * GRID.len()).map(|k| 0.01 * k as f32 + 0.5).collect();
    Table::new(
        Metadata::new("clothbake 0.1.0", GRID, fabric, "{}", "none"),
        values,
    )
    .unwrap()
}

/// Small spatial tables (docs/science/spatial.md), baked: the gingham's colour map with one bounce,
/// the twill with the second bounce (side terms, mirror images held once).
fn spatial_tables() -> Vec<Table> {
    [("gingham.wif", 1), ("twill.json", 2)]
        .into_iter()
        .map(|(name, bounces)| {
            let fabric = Fabric::from_path(&tables().join(name)).unwrap();
            let opts = BakeOptions {
                grid: GRID,
                spatial: true,
                bounces: BakeBounces::of(bounces, Default::default()),
                ..BakeOptions::default()
            };
            bake(&fabric, &opts, &|_| {}, &AtomicBool::new(false))
                .unwrap()
                .table
        })
        .collect()
}

/// A table that was read is used as renderers use it: looked up and sampled and, when
/// spatial, looked up at points and footprints of the period (wrapped, not finite, wide).
fn use_table(t: Table) {
    if let Ok(b) = Brdf::from_table(t, Options::default()) {
        let ok = |f: [f32; 3]| f.iter().all(|v| v.is_finite() && *v >= 0.0);
        for (wo, u) in [([0.0f32, 0.0, 1.0], 0.3f32), ([0.6, 0.0, 0.8], 0.9)] {
            let wi = [0.0, 0.6, 0.8];
            let f = b.eval(wi, wo);
            assert!(ok(f), "{f:?}");
            let s = b.sample(wo, u, 1.0 - u);
            assert!(s.weight.iter().all(|v| v.is_finite()), "{s:?}");
            if b.spatial().is_none() {
                continue;
            }
            for (x, y) in [
                (0.1, 0.7),
                (-3.4, 12.9),
                (f64::NAN, 0.5),
                (f64::INFINITY, 0.0),
            ] {
                for width in [0.0, 0.3, 0.999, 2.0, f64::NAN] {
                    let f = b.eval_at(wi, wo, x, y, width);
                    assert!(ok(f), "{f:?} at {x}, {y}, {width}");
                    // Slightly above 1 is possible (docs/science/spatial.md): no upper bound here.
                    let c = b.coverage_at(wo, x, y, width);
                    assert!(c.is_finite() && c >= 0.0, "{c} at {x}, {y}, {width}");
                }
            }
        }
    }
}

/// Fuzzes the fabric reader (`Fabric::from_path`) on the shipped `*.<ext>` files: the campaign
/// `name`, with `tokens` spliced in; no checksum guards these files.
fn fuzz_fabric_reader(name: &str, ext: &str, tokens: &[&[u8]]) {
    fuzz(
        &Reader {
            name,
            ext,
            tokens,
            crc: false,
            read: &|p| {
                let _ = Fabric::from_path(p);
            },
        },
        &files_with(ext),
    );
}

#[test]
fn fuzz_fabric_json() {
    isolated("fabric-json", "json", "fuzz_fabric_json", run_fabric_json);
}

fn run_fabric_json() {
    let tokens: &[&[u8]] = &[
        b"\"radius\":",
        b"\"spacing\":",
        b"\"pattern\":",
        b"1e300",
        b"1e-300",
        b"-1",
        b"NaN",
        b"[[",
        b"]]",
        b"{",
        b"}",
        b"\"",
        b"\xef\xbb\xbf",
        b"null",
    ];
    fuzz_fabric_reader("fabric-json", "json", tokens);
}

#[test]
fn fuzz_wif() {
    isolated("wif", "wif", "fuzz_wif", run_wif);
}

fn run_wif() {
    let tokens: &[&[u8]] = &[
        b"\n[WARP]\n",
        b"\n[WEFT]\n",
        b"\n[THREADING]\n",
        b"\n[TREADLING]\n",
        b"\n[TIEUP]\n",
        b"\n[LIFTPLAN]\n",
        b"Threads=",
        b"Thickness=",
        b"Spacing=",
        b"Units=",
        b"1=1,2\n",
        b",",
        b"=",
        b"\r\n",
        b"\xff\xfe",
    ];
    fuzz_fabric_reader("wif", "wif", tokens);
}

#[test]
fn fuzz_table_exr() {
    isolated("table-exr", "exr", "fuzz_table_exr", run_table_exr);
}

fn run_table_exr() {
    let d = scratch();
    let mut seeds = Vec::new();
    for (k, precision) in [Precision::F16, Precision::F32].into_iter().enumerate() {
        let p = d.join(format!("seed-{k}.exr"));
        write_exr(&p, &small_table(), precision, true).unwrap();
        seeds.push(std::fs::read(&p).unwrap());
    }
    for (k, t) in spatial_tables().iter().enumerate() {
        let p = d.join(format!("seed-spatial-{k}.exr"));
        write_exr(&p, t, Precision::F16, true).unwrap();
        seeds.push(std::fs::read(&p).unwrap());
    }
    let tokens: &[&[u8]] = &[
        b"clothbake:metadata\0",
        b"string\0",
        b"half\0",
        b"float\0",
        b"dataWindow\0",
        b"box2i\0",
        b"channels\0",
        b"chlist\0",
        b"\0",
        b"class1.diffuse\0",
        b"class0.plus_both\0",
        b"\"u_edges\":",
        b"\"cell_class\":",
        b"\"classes\":",
        b"\"secondary\":true",
    ];
    fuzz(
        &Reader {
            name: "table-exr",
            ext: "exr",
            tokens,
            crc: false,
            read: &|p| {
                if let Ok(t) = read_table(p) {
                    use_table(t);
                }
            },
        },
        &seeds,
    );
}

/// A version-1 binary table (bincode header), by `docs/reference/table-format.md`.
fn v1_table(t: &Table) -> Vec<u8> {
    fn string(out: &mut Vec<u8>, s: &str) {
        out.extend_from_slice(&(s.len() as u64).to_le_bytes());
        out.extend_from_slice(s.as_bytes());
    }
    let m = &t.meta;
    let mut h = m.format_version.to_le_bytes().to_vec();
    string(&mut h, &m.tool);
    for n in [
        m.grid.n_theta_i,
        m.grid.n_phi_i,
        m.grid.n_theta_o,
        m.grid.n_phi_o,
    ] {
        h.extend_from_slice(&n.to_le_bytes());
    }
    for s in [
        &m.centring,
        &m.quantity,
        &m.units,
        &m.fabric_json,
        &m.options_json,
        &m.symmetry,
    ] {
        string(&mut h, s);
    }
    let mut f = b"CLTHBAKE".to_vec();
    f.extend_from_slice(&1u32.to_le_bytes());
    f.extend_from_slice(&(h.len() as u64).to_le_bytes());
    f.extend_from_slice(&h);
    f.extend_from_slice(&(t.values.len() as u64).to_le_bytes());
    for v in &t.values {
        f.extend_from_slice(&v.to_le_bytes());
    }
    f.extend_from_slice(&[0; 4]);
    fix_crc(&mut f);
    f
}

#[test]
fn fuzz_table_bin() {
    isolated("table-bin", "bin", "fuzz_table_bin", run_table_bin);
}

fn run_table_bin() {
    let d = scratch();
    let t = small_table();
    let p = d.join("seed.bin");
    write_binary(&p, &t, true).unwrap();
    let v1 = v1_table(&t);
    // The version-1 seed is what the loader reads (the layout is right).
    std::fs::write(d.join("seed-v1.bin"), &v1).unwrap();
    assert_eq!(read_table(&d.join("seed-v1.bin")).unwrap(), t);
    let mut seeds = vec![std::fs::read(&p).unwrap(), v1];
    for (k, t) in spatial_tables().iter().enumerate() {
        let p = d.join(format!("seed-spatial-{k}.bin"));
        write_binary(&p, t, true).unwrap();
        seeds.push(std::fs::read(&p).unwrap());
    }
    let tokens: &[&[u8]] = &[
        b"CLTHBAKE",
        b"\"grid\":",
        b"\"n_phi_o\":",
        b"\"format_version\":",
        b"\"u_edges\":",
        b"\"v_edges\":",
        b"\"cell_class\":",
        b"\"cell_neighbours\":",
        b"\"classes\":",
        b"\"secondary\":true",
        b"\"visible\":",
        b"4294967297",
        b"1e39",
        b"-0",
        b"\x7f\x7f\xff\xff",
        b"\x00\x00\xc0\x7f",
        b"\x00\x00\x80\xff",
    ];
    fuzz(
        &Reader {
            name: "table-bin",
            ext: "bin",
            tokens,
            crc: true,
            read: &|p| {
                if let Ok(t) = read_table(p) {
                    use_table(t);
                }
            },
        },
        &seeds,
    );
}

#[test]
fn fuzz_shard_and_checkpoint() {
    isolated(
        "shard",
        "shard",
        "fuzz_shard_and_checkpoint",
        run_shard_and_checkpoint,
    );
}

fn run_shard_and_checkpoint() {
    let d = scratch();
    let fabric = Fabric::from_path(&tables().join("twill.json")).unwrap();
    let options = BakeOptions {
        grid: GRID,
        ..Default::default()
    };
    let no = |_: u64, _: u64| {};
    let quiet = |_: &str| {};
    let cancel = AtomicBool::new(false);
    let hooks = Hooks {
        progress: &no,
        note: &quiet,
        warn: &quiet,
        cancel: &cancel,
    };
    let mut seeds = Vec::new();
    for k in 1..=2 {
        let p = d.join(format!("seed-{k}.shard"));
        let mut j = Job::new(&fabric, options);
        j.target = Target::Shard {
            path: p.clone(),
            id: ShardId {
                index: k - 1,
                count: 2,
            },
        };
        j.overwrite = true;
        job::run(&j, &hooks).unwrap();
        seeds.push(std::fs::read(&p).unwrap());
    }
    // A checkpoint: the first shard's rows in a container of kind "checkpoint".
    let part = read_part(&d.join("seed-1.shard"), clothbake_bake::merge::orbits_of).unwrap();
    let ckp = d.join("seed.checkpoint");
    let part = clothbake_bake::shard::Part {
        kind: clothbake_bake::shard::Kind::Checkpoint,
        ..part
    };
    clothbake_bake::shard::write_part(&ckp, &part, true).unwrap();
    seeds.push(std::fs::read(&ckp).unwrap());
    let tokens: &[&[u8]] = &[
        b"\"rows\":",
        b"\"shard\":",
        b"\"index\":",
        b"\"count\":",
        b"[[0,4]]",
        b"checkpoint",
        b"shard",
        b"4294967297",
    ];
    fuzz(
        &Reader {
            name: "shard",
            ext: "shard",
            tokens,
            crc: true,
            read: &|p| {
                let _ = read_part(p, clothbake_bake::merge::orbits_of);
            },
        },
        &seeds,
    );
}
