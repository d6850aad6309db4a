//! `clothbake merge`: shards back into the table a single process would have baked.
//!
//! Every shard must come from the same fabric, options, grid and tool version (this one: the
//! symmetry copies are made here), and the shards must cover the rows exactly once: each index
//! 0..N-1 given once, each holding exactly the rows [`crate::shard::split`] assigns to it. The
//! assembly is the single bake's own ([`Assembly`]), so the table is bit-identical.

use crate::assembly::Assembly;
use crate::orbit::usable_symmetries;
use crate::shard::{describe_rows, shard_rows, Kind, Part, PartError, ShardId};
use crate::sweep::{symmetry_name, tool_name, Orbits};
use clothbake_core::Fabric;
use clothbake_loader::{Metadata, Table};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The orbits of the bake that `meta` describes: the fabric is parsed from `fabric_json`, and
/// its symmetry must be the one the metadata names.
pub fn orbits_of(meta: &Metadata) -> Result<Orbits, String> {
    let fabric = Fabric::from_json_str(&meta.fabric_json, "the stored fabric")
        .map_err(|e| format!("its fabric cannot be read: {e}"))?;
    meta.grid.validate().map_err(|e| e.to_string())?;
    if let Some(l) = &meta.spatial {
        // A spatial bake uses no symmetry (`Orbits::spatial`).
        l.validate(&meta.grid).map_err(|e| e.to_string())?;
        if meta.symmetry != "none" {
            return Err(format!(
                "it is a spatial bake, which uses no symmetry, but names symmetry \"{}\"",
                meta.symmetry
            ));
        }
        return Ok(Orbits::spatial(&meta.grid, l.classes as usize, l.lanes()));
    }
    let syms = usable_symmetries(&fabric, &meta.grid);
    if symmetry_name(&syms) != meta.symmetry {
        return Err(format!(
            "it was baked with symmetry \"{}\", but this clothbake finds \"{}\"",
            meta.symmetry,
            symmetry_name(&syms)
        ));
    }
    Ok(Orbits::new(&meta.grid, &syms))
}

fn fabric_name(json: &str) -> String {
    serde_json::from_str::<serde_json::Value>(json)
        .ok()
        .and_then(|v| v["name"].as_str().map(str::to_string))
        .unwrap_or_else(|| "?".into())
}

fn e(path: &Path, problem: impl Into<String>, fix: impl Into<String>) -> PartError {
    PartError {
        path: path.to_path_buf(),
        problem: problem.into(),
        fix: fix.into(),
    }
}

/// Why `b` (at `pb`) cannot be merged with `a` (at `pa`), if it cannot.
fn mismatch(pa: &Path, a: &Part, pb: &Path, b: &Part) -> Option<PartError> {
    let (ma, mb) = (&a.meta, &b.meta);
    let fix = "merge the shards of one bake (same fabric file, options and clothbake version)";
    let problem = if ma.tool != mb.tool {
        format!("baked by {}, but {} by {}", mb.tool, pa.display(), ma.tool)
    } else if ma.fabric_json != mb.fabric_json {
        let (na, nb) = (fabric_name(&ma.fabric_json), fabric_name(&mb.fabric_json));
        if na != nb {
            format!("from another fabric ({nb}) than {} ({na})", pa.display())
        } else {
            format!(
                "from another fabric than {} (both named {na}, but their parameters or materials differ)",
                pa.display()
            )
        }
    } else if ma.grid != mb.grid {
        format!(
            "grid {}, but {} has grid {}",
            mb.grid,
            pa.display(),
            ma.grid
        )
    } else if ma.options_json != mb.options_json {
        format!(
            "baked with other options ({}) than {} ({})",
            mb.options_json,
            pa.display(),
            ma.options_json
        )
    } else if ma != mb {
        format!("its metadata differs from {}'s", pa.display())
    } else {
        let (sa, sb) = (a.shard?, b.shard?);
        if sa.count == sb.count {
            return None;
        }
        format!(
            "shard {sb} (of {} shards), but {} is shard {sa} (of {})",
            sb.count,
            pa.display(),
            sa.count
        )
    };
    Some(e(pb, problem, fix))
}

/// Checks the shards and assembles the table. Errors name the shard file at fault (or, for a
/// missing shard, its index and rows) and what to do.
pub fn merge(parts: &[(PathBuf, Part)]) -> Result<Table, PartError> {
    let Some((p0, first)) = parts.first() else {
        return Err(e(
            Path::new("merge"),
            "no shard files given",
            "give every shard: clothbake merge -o TABLE SHARD...",
        ));
    };
    for (p, part) in parts {
        if part.kind == Kind::Checkpoint {
            return Err(e(
                p,
                "a checkpoint of an unfinished bake, not a shard",
                "finish that bake with --resume, then merge the shard it writes",
            ));
        }
        if part.shard.is_none() {
            return Err(e(
                p,
                "a shard file without a shard index",
                "bake it again with --shard K/N",
            ));
        }
        if let Some(err) = mismatch(p0, first, p, part) {
            return Err(err);
        }
    }
    if first.meta.tool != tool_name() {
        return Err(e(
            p0,
            format!("baked by {}, but this is {}", first.meta.tool, tool_name()),
            "merge with the clothbake version that baked the shards",
        ));
    }
    let orbits = orbits_of(&first.meta).map_err(|m| e(p0, m, "bake the shards again"))?;
    let g = *orbits.grid();
    let count = first.shard.expect("checked").count;
    let mut by_index: BTreeMap<u32, (&PathBuf, &Part)> = BTreeMap::new();
    for (p, part) in parts {
        let id = part.shard.expect("checked");
        if id.index >= id.count {
            return Err(e(
                p,
                format!(
                    "shard index {} is not below the count {}",
                    id.index, id.count
                ),
                "bake it again with --shard K/N, K from 0 to N-1",
            ));
        }
        if let Some((q, _)) = by_index.insert(id.index, (p, part)) {
            return Err(e(
                p,
                format!(
                    "shard {id} is given twice (also as {}): its {} would be covered twice",
                    q.display(),
                    describe_rows(&g, &shard_rows(&orbits, id))
                ),
                "give each shard once",
            ));
        }
    }
    let all = Assembly::new(&orbits, 0..orbits.rows());
    for index in 0..count {
        let id = ShardId { index, count };
        let expect = shard_rows(&orbits, id);
        let Some((p, part)) = by_index.get(&index) else {
            return Err(e(
                Path::new(&format!("shard {id}")),
                format!(
                    "missing: {} of the grid are not covered",
                    describe_rows(&g, &expect)
                ),
                format!("bake it with --shard {id} and give it to merge too"),
            ));
        };
        let have: Vec<usize> = part.rows.keys().copied().collect();
        if have != expect.clone().collect::<Vec<_>>() {
            return Err(e(
                p,
                format!(
                    "shard {id} should hold {} but holds {} rows from {} to {}",
                    describe_rows(&g, &expect),
                    have.len(),
                    have.first().map_or("-".into(), |r| r.to_string()),
                    have.last().map_or("-".into(), |r| r.to_string()),
                ),
                "bake it again with --shard K/N",
            ));
        }
        for (&r, vals) in &part.rows {
            all.put(r, vals);
        }
    }
    Table::new(first.meta.clone(), all.into_values())
        .map_err(|m| e(p0, m.to_string(), "bake the shards again"))
}
