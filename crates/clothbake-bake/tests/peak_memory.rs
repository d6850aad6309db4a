//! A bake's peak memory: the job holds the table's values once (issue 22: at most 1.5 times
//! the table's size in memory). Measured as the largest number of heap bytes allocated at once
//! during `job::run`, counted by this test binary's global allocator: deterministic (no
//! resident-set noise), and the one test in its binary, so nothing else allocates meanwhile.
//! Run with `--nocapture` to see the numbers (docs/results/performance.md quotes them).

use clothbake_bake::job::{run, Hooks, Job, Target};
use clothbake_bake::output::Format;
use clothbake_bake::shard::ShardId;
use clothbake_loader::Precision;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

mod common;

/// The system allocator, counting the bytes allocated now and the most at once.
struct Counting;

static NOW: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

fn grew(n: usize) {
    let now = NOW.fetch_add(n, Ordering::SeqCst) + n;
    PEAK.fetch_max(now, Ordering::SeqCst);
}

// SAFETY: every call is forwarded to `System` with the same arguments; the counters are
// atomics and allocate nothing.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        if !p.is_null() {
            grew(layout.size());
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout);
        NOW.fetch_sub(layout.size(), Ordering::SeqCst);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = System.realloc(ptr, layout, new_size);
        if !p.is_null() {
            // Counted as both blocks at once, as a moving realloc holds them.
            grew(new_size);
            NOW.fetch_sub(layout.size(), Ordering::SeqCst);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The most heap bytes `job` held at once beyond what was allocated before it started.
fn peak_of(job: &Job<'_>) -> usize {
    let cancel = AtomicBool::new(false);
    let hooks = Hooks {
        progress: &|_, _| {},
        note: &|_| {},
        warn: &|m| panic!("unexpected warning: {m}"),
        cancel: &cancel,
    };
    let before = NOW.load(Ordering::SeqCst);
    PEAK.store(before, Ordering::SeqCst);
    let done = run(job, &hooks).unwrap_or_else(|e| panic!("{e}"));
    drop(done);
    PEAK.load(Ordering::SeqCst) - before
}

#[test]
fn a_bake_holds_its_table_once() {
    let dir = common::scratch("peak-memory");
    let f = common::fabric("twill");
    // The default grid: 4.2 M cells, 50.3 MB of RGB f32.
    let opts = common::options(clothbake_bake::DEFAULT_GRID);
    let table = 12 * opts.grid.len();
    // Two workers, each with a row in flight.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let mut lines = Vec::new();
    let targets = [
        ("OpenEXR f16", "t16.exr", Format::Exr(Precision::F16)),
        ("OpenEXR f32", "t32.exr", Format::Exr(Precision::F32)),
        ("binary", "t.bin", Format::Binary),
    ];
    for (name, file, format) in targets {
        let mut job = Job::new(&f, opts);
        job.target = Target::Table {
            path: dir.join(file),
            format,
        };
        let peak = pool.install(|| peak_of(&job));
        let ratio = peak as f64 / table as f64;
        lines.push(format!(
            "{name}: peak heap {:.1} MB for a table of {:.1} MB in memory ({ratio:.3}x)",
            peak as f64 / 1e6,
            table as f64 / 1e6
        ));
        // The buffer, the model, the orbits and the encoder's block of 16 lines.
        assert!(ratio <= 1.5, "{}", lines.last().unwrap());
    }
    // A shard of a third of the rows holds a third of the table.
    let mut job = Job::new(&f, opts);
    job.target = Target::Shard {
        path: dir.join("s.part"),
        id: ShardId { index: 1, count: 3 },
    };
    let peak = pool.install(|| peak_of(&job));
    lines.push(format!(
        "shard 1/3: peak heap {:.1} MB ({:.3}x the table)",
        peak as f64 / 1e6,
        peak as f64 / table as f64
    ));
    assert!(
        (peak as f64) < 0.5 * table as f64,
        "{}",
        lines.last().unwrap()
    );
    println!("{}", lines.join("\n"));
}
