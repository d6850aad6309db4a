//! Shards merged in-process equal the single-process bake, bit for bit, for fabrics with
//! every kind of symmetry (copies cross rows, and so shards) and any shard count.

use clothbake_bake::merge::{merge, orbits_of};
use clothbake_bake::shard::{read_part, shard_rows, write_part, Kind, Part, ShardId};
use clothbake_bake::{bake, BakeOptions, Baker, Row};
use clothbake_core::Fabric;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

mod common;
use common::{fabric, grid, options, scratch};

fn shard(f: &Fabric, o: &BakeOptions, id: ShardId) -> Part {
    let baker = Baker::new(f, o).unwrap();
    let rows: Vec<usize> = shard_rows(baker.orbits(), id).collect();
    let done = Mutex::new(BTreeMap::<usize, Row>::new());
    let none = AtomicBool::new(false);
    baker
        .sweep(&rows, &|_| {}, &none, &|r, v| {
            done.lock().unwrap().insert(r, v);
        })
        .unwrap();
    Part {
        kind: Kind::Shard,
        shard: Some(id),
        meta: baker.metadata().clone(),
        rows: done.into_inner().unwrap(),
    }
}

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn merged_shards_equal_the_single_bake() {
    let none = AtomicBool::new(false);
    for (name, cells) in [
        ("plain", [3, 8, 2, 8]),  // mirror x, mirror y, rotation: orbits of 4
        ("twill", [2, 6, 3, 4]),  // rotation
        ("satin5", [2, 5, 2, 7]), // odd azimuths: mirror y at most
    ] {
        let f = fabric(name);
        let o = options(grid(cells));
        let single = bake(&f, &o, &|_| {}, &none).unwrap().table;
        for n in [1, 3, 4, 7] {
            let parts: Vec<(PathBuf, Part)> = (0..n)
                .map(|k| {
                    let id = ShardId { index: k, count: n };
                    (PathBuf::from(format!("{k}.shard")), shard(&f, &o, id))
                })
                .collect();
            let merged = merge(&parts).unwrap();
            assert_eq!(merged.meta, single.meta, "{name} {n}");
            assert_eq!(bits(&merged.values), bits(&single.values), "{name} {n}");
        }
    }
}

#[test]
fn shard_files_round_trip_and_bad_sets_are_refused() {
    let f = fabric("twill");
    let o = options(grid([2, 4, 2, 4]));
    let dir = scratch("merge-round-trip");
    let mut parts = Vec::new();
    for k in 0..2 {
        let p = shard(&f, &o, ShardId { index: k, count: 2 });
        let path = dir.join(format!("{k}.shard"));
        write_part(&path, &p, false).unwrap();
        let back = read_part(&path, orbits_of).unwrap();
        assert_eq!(back, p);
        parts.push((path, back));
    }
    assert!(merge(&parts).is_ok());
    // A checkpoint is not a shard.
    let mut ck = parts.clone();
    ck[1].1.kind = Kind::Checkpoint;
    assert!(merge(&ck).unwrap_err().to_string().contains("checkpoint"));
    // A shard missing a row.
    let mut short = parts.clone();
    let first = *short[1].1.rows.keys().next().unwrap();
    short[1].1.rows.remove(&first);
    let e = merge(&short).unwrap_err().to_string();
    assert!(e.contains("1.shard") && e.contains("should hold"), "{e}");
    // A truncated file.
    let bytes = std::fs::read(&parts[0].0).unwrap();
    let cut = dir.join("cut.shard");
    std::fs::write(&cut, &bytes[..bytes.len() - 9]).unwrap();
    let e = read_part(&cut, orbits_of).unwrap_err().to_string();
    assert!(e.contains("cut.shard") && e.contains("truncated"), "{e}");
    // Not a shard at all.
    std::fs::write(dir.join("x.shard"), b"hello").unwrap();
    let e = read_part(&dir.join("x.shard"), orbits_of)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a clothbake shard"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
