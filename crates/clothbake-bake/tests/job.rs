//! The bake job: a job cancelled half way and resumed from its checkpoint, and shards written
//! by jobs and merged, give the in-memory bake (`clothbake_bake::bake`, which shares no
//! checkpoint or file code with the job) bit for bit.

use clothbake_bake::job::{run, Hooks, Job, JobError, Target};
use clothbake_bake::merge::{merge, orbits_of};
use clothbake_bake::output::Format;
use clothbake_bake::shard::{read_part, ShardId};
use clothbake_bake::{bake, BakeOptions};
use clothbake_core::Fabric;
use clothbake_loader::read_table;
use std::sync::atomic::{AtomicBool, Ordering};

mod common;
use common::scratch;

fn twill() -> Fabric {
    common::fabric("twill")
}

fn options() -> BakeOptions {
    common::options(common::small())
}

fn hooks<'a>(
    progress: &'a (dyn Fn(u64, u64) + Sync),
    notes: &'a (dyn Fn(&str) + Sync),
    cancel: &'a AtomicBool,
) -> Hooks<'a> {
    Hooks {
        progress,
        note: notes,
        warn: &|m| panic!("unexpected warning: {m}"),
        cancel,
    }
}

#[test]
fn cancelled_then_resumed_equals_the_uninterrupted_bake() {
    let dir = scratch("job-resume");
    let f = twill();
    let out = dir.join("t.bin");
    let mut job = Job::new(&f, options());
    job.target = Target::Table {
        path: out.clone(),
        format: Format::Binary,
    };
    let cancel = AtomicBool::new(false);
    let stop = |done: u64, total: u64| {
        if done >= total / 2 && done > 0 {
            cancel.store(true, Ordering::SeqCst);
        }
    };
    let e = run(&job, &hooks(&stop, &|_| {}, &cancel)).unwrap_err();
    let JobError::Interrupted(i) = e else {
        panic!("{e}")
    };
    assert!(i.saved > 0 && i.saved < i.rows, "{i}");
    assert!(!out.exists());
    // Not asked to resume: the checkpoint is an error.
    let never = AtomicBool::new(false);
    let e = run(&job, &hooks(&|_, _| {}, &|_| {}, &never)).unwrap_err();
    assert!(e.to_string().contains("--resume"), "{e}");
    // Python's spelling, for the same refusal.
    job.naming = clothbake_bake::settings::Naming::Python;
    let e = run(&job, &hooks(&|_, _| {}, &|_| {}, &never)).unwrap_err();
    assert!(
        e.to_string().contains("call bake() again with resume=True")
            && !e.to_string().contains("--"),
        "{e}"
    );
    job.resume = true;
    let notes = std::sync::Mutex::new(Vec::new());
    let note = |m: &str| notes.lock().unwrap().push(m.to_string());
    let done = run(&job, &hooks(&|_, _| {}, &note, &never)).unwrap();
    assert!(notes.lock().unwrap()[0].contains("resuming from"));
    let whole = bake(&f, &options(), &|_| {}, &never).unwrap().table;
    assert_eq!(done.table.as_ref().unwrap().values, whole.values);
    assert_eq!(read_table(&out).unwrap().values, whole.values);
    assert!(!dir.join("t.bin.checkpoint").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn shards_of_jobs_merge_into_the_bake() {
    let dir = scratch("job-shards");
    let f = twill();
    let never = AtomicBool::new(false);
    let mut parts = Vec::new();
    for index in 0..3 {
        let path = dir.join(format!("{index}.shard"));
        let mut job = Job::new(&f, options());
        job.target = Target::Shard {
            path: path.clone(),
            id: ShardId { index, count: 3 },
        };
        let done = run(&job, &hooks(&|_, _| {}, &|_| {}, &never)).unwrap();
        assert!(done.table.is_none());
        parts.push((path.clone(), read_part(&path, orbits_of).unwrap()));
    }
    let whole = bake(&f, &options(), &|_| {}, &never).unwrap().table;
    assert_eq!(merge(&parts).unwrap().values, whole.values);
    // Resuming needs an output file.
    let mut job = Job::new(&f, options());
    job.resume = true;
    let e = run(&job, &hooks(&|_, _| {}, &|_| {}, &never)).unwrap_err();
    assert!(e.to_string().contains("output file"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
