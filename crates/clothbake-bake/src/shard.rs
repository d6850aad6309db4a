//! Shards and checkpoints: part of a bake's rows, in a file of their own.
//!
//! A bake's (theta_i, phi_i) rows are independent (see [`crate::sweep::Baker`]). A **shard** is
//! shard K of N of a [`split`] of the rows, baked by one process (`clothbake bake --shard K/N`),
//! and `clothbake merge` assembles the shards into the table. A **checkpoint** holds the rows a
//! bake (or a shard's bake) has finished so far, for `--resume`. Both are a [`Part`], stored
//! in the loader's binary container (`clothbake_loader::container`, docs/reference/table-format.md) of
//! kind `shard` or `checkpoint`.
//!
//! The JSON header holds the shard index and count (`"shard"`; `null` for a checkpoint of a
//! whole-table bake), the rows as half-open ranges (`"rows"`) and the table's full
//! [`Metadata`] (`"metadata"`). The values are the canonical cells of each row
//! (rows in increasing order, each [`Row`] in cell order, RGB): exactly the f32 values the
//! single-process bake computes, so a merge is bit-identical to it.

use crate::directions::row_cell;
use crate::settings::Naming;
use crate::sweep::{Orbits, Row};
use clothbake_loader::container::{read_container, write_container_counted, ContainerKind};
use clothbake_loader::{Grid, Metadata, TableError};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// What a [`Part`] file is.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Kind {
    /// A finished shard: every row of shard K of N.
    Shard,
    /// The rows an unfinished bake has done so far.
    Checkpoint,
}

/// Shard `index` of `count`, 0-based: `0 <= index < count`.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardId {
    /// 0-based index.
    pub index: u32,
    /// Number of shards.
    pub count: u32,
}

impl std::fmt::Display for ShardId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Some rows of a bake, with the table's metadata.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// Shard or checkpoint.
    pub kind: Kind,
    /// The shard this is (or, for a checkpoint, belongs to); `None`: a whole-table bake.
    pub shard: Option<ShardId>,
    /// The metadata of the table the bake makes.
    pub meta: Metadata,
    /// Finished rows: row number -> its canonical values.
    pub rows: BTreeMap<usize, Row>,
}

/// Why shards cannot be merged: names the file, the cause and the fix.
#[derive(Debug)]
pub struct PartError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong.
    pub problem: String,
    /// What to do.
    pub fix: String,
}

impl std::fmt::Display for PartError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}; {}", self.path.display(), self.problem, self.fix)
    }
}

impl std::error::Error for PartError {}

/// The header of a shard or checkpoint container file (its kind is the container's).
#[derive(Serialize, Deserialize)]
struct Header {
    shard: Option<ShardId>,
    rows: Vec<[usize; 2]>,
    metadata: Metadata,
}

/// Parses `K/N` (0-based K, 0 <= K < N); the message says what is wrong and the fix, in the
/// command line's words.
pub fn parse_shard_id(s: &str) -> Result<ShardId, String> {
    parse_shard_id_as(s, Naming::Cli)
}

/// [`parse_shard_id`] with the fix spelled as `n` spells options (`--shard 0/4`,
/// `shard="0/4"`).
pub fn parse_shard_id_as(s: &str, naming: Naming) -> Result<ShardId, String> {
    let fix = match naming {
        Naming::Cli => {
            "give --shard K/N with K from 0 to N-1 (0-based), e.g. --shard 0/4, or --shard auto"
        }
        Naming::Python => "give shard=\"K/N\" with K from 0 to N-1 (0-based), e.g. shard=\"0/4\"",
    };
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| format!("shard `{s}` is not K/N; {fix}"))?;
    let num = |t: &str, what: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("shard {what} `{}` is not a whole number; {fix}", t.trim()))
    };
    let (index, count) = (num(k, "index K")?, num(n, "count N")?);
    if count == 0 {
        return Err(format!("shard count N is 0; {fix}"));
    }
    if index >= count {
        return Err(format!(
            "shard index {index} is not below the count {count} (K is 0-based); {fix}"
        ));
    }
    Ok(ShardId { index, count })
}

/// `--shard auto`: the shard from the scheduler's environment, and a sentence saying which
/// variables gave it.
///
/// * SLURM job array (`SLURM_ARRAY_TASK_ID` set): K = (ID - `SLURM_ARRAY_TASK_MIN`) /
///   `SLURM_ARRAY_TASK_STEP` (MIN 0 and STEP 1 when unset), so `--array=0-3`, `--array=1-4`
///   and `--array=0-6:2` all give K = 0..3; N = `SLURM_ARRAY_TASK_COUNT`. A `shards` count
///   must agree with it.
/// * Kubernetes Indexed Job (`JOB_COMPLETION_INDEX` set, 0-based): K = the index, N =
///   `shards` (required: Kubernetes does not tell the pod the number of completions).
pub fn shard_from_env(
    get: &dyn Fn(&str) -> Option<String>,
    shards: Option<u32>,
) -> Result<(ShardId, String), String> {
    let num = |var: &str| -> Result<Option<i64>, String> {
        match get(var) {
            None => Ok(None),
            Some(v) => v.trim().parse::<i64>().map(Some).map_err(|_| {
                format!("--shard auto: {var}={v:?} is not a whole number; check the job's environment or give --shard K/N")
            }),
        }
    };
    if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
        let count = num("SLURM_ARRAY_TASK_COUNT")?.ok_or(
            "--shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not; run under a SLURM job array (sbatch --array=0-3) or give --shard K/N",
        )?;
        let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
        let step = num("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
        let off = id - min;
        if count < 1 || count > u32::MAX as i64 || off < 0 || off % step != 0 || off / step >= count
        {
            return Err(format!(
                "--shard auto: SLURM_ARRAY_TASK_ID={id} with SLURM_ARRAY_TASK_MIN={min}, STEP={step}, COUNT={count} is not one of the array's tasks; use one contiguous array such as --array=0-{} (or give --shard K/N)",
                count.max(1) - 1
            ));
        }
        if let Some(n) = shards {
            if n as i64 != count {
                return Err(format!(
                    "--shards {n} but the SLURM job array has SLURM_ARRAY_TASK_COUNT={count} tasks; drop --shards (SLURM gives the count) or make the array {n} tasks"
                ));
            }
        }
        let sid = ShardId {
            index: (off / step) as u32,
            count: count as u32,
        };
        let how = format!(
            "shard {sid} from SLURM_ARRAY_TASK_ID={id} (SLURM_ARRAY_TASK_MIN={min}, SLURM_ARRAY_TASK_STEP={step}) and SLURM_ARRAY_TASK_COUNT={count}"
        );
        return Ok((sid, how));
    }
    if let Some(k) = num("JOB_COMPLETION_INDEX")? {
        let n = shards.ok_or(
            "--shard auto: JOB_COMPLETION_INDEX is set (Kubernetes Indexed Job) but the number of shards is not known; add --shards N with N the Job's completions",
        )?;
        if k < 0 || k >= n as i64 {
            return Err(format!(
                "--shard auto: JOB_COMPLETION_INDEX={k} is not below --shards {n}; make --shards equal to the Job's completions"
            ));
        }
        let sid = ShardId {
            index: k as u32,
            count: n,
        };
        return Ok((
            sid,
            format!("shard {sid} from JOB_COMPLETION_INDEX={k} and --shards {n}"),
        ));
    }
    Err("--shard auto found neither SLURM_ARRAY_TASK_ID (SLURM job array) nor JOB_COMPLETION_INDEX (Kubernetes Indexed Job); run it under one of them or give --shard K/N".into())
}

/// The split of rows into `n` shards: contiguous ranges of row numbers, balanced by `costs`
/// (the estimated cost of each row). Boundary k (0 < k < n) is the first row at which the
/// cost of the rows before it reaches k/n of the total, so every shard costs at most
/// total/n plus one row. Deterministic: integers only. Shards may be empty when n is close to
/// the number of rows.
pub fn split(costs: &[u64], n: u32) -> Vec<Range<usize>> {
    assert!(n >= 1, "at least one shard");
    let total: u128 = costs.iter().map(|&c| c as u128).sum();
    let mut bounds = vec![0usize];
    let mut prefix: u128 = 0;
    let mut row = 0;
    for k in 1..n as u128 {
        // Smallest row r with prefix(r) * n >= k * total.
        while row < costs.len() && prefix * (n as u128) < k * total {
            prefix += costs[row] as u128;
            row += 1;
        }
        bounds.push(row);
    }
    bounds.push(costs.len());
    bounds.windows(2).map(|w| w[0]..w[1]).collect()
}

/// The estimated cost of each row: the cells it evaluates (after symmetry). The cost of a cell
/// is taken as the same for every direction.
pub fn row_costs(orbits: &Orbits) -> Vec<u64> {
    (0..orbits.rows())
        .map(|r| orbits.row_evaluations(r) as u64)
        .collect()
}

/// The rows of shard `id` of a bake with these orbits.
pub fn shard_rows(orbits: &Orbits, id: ShardId) -> Range<usize> {
    split(&row_costs(orbits), id.count)[id.index as usize].clone()
}

/// A range of rows in words: `rows 8-15 (theta_i cell 1 phi_i cell 0 to theta_i cell 1 phi_i
/// cell 7)`, or `no rows`.
pub fn describe_rows(g: &Grid, r: &Range<usize>) -> String {
    if r.is_empty() {
        return "no rows".into();
    }
    let (a, b) = (row_cell(g, r.start), row_cell(g, r.end - 1));
    format!(
        "rows {}-{} (theta_i cell {} phi_i cell {} to theta_i cell {} phi_i cell {})",
        r.start,
        r.end - 1,
        a.0,
        a.1,
        b.0,
        b.1
    )
}

/// Row numbers as half-open ranges.
fn ranges(rows: impl Iterator<Item = usize>) -> Vec<[usize; 2]> {
    let mut out: Vec<[usize; 2]> = Vec::new();
    for r in rows {
        match out.last_mut() {
            Some(last) if last[1] == r => last[1] = r + 1,
            _ => out.push([r, r + 1]),
        }
    }
    out
}

/// Writes `part` to `path` atomically (temp file, fsync, rename) as a container file of kind
/// `shard` or `checkpoint`, refusing an existing file unless `overwrite`.
pub fn write_part(path: &Path, part: &Part, overwrite: bool) -> Result<(), TableError> {
    let rows: Vec<usize> = part.rows.keys().copied().collect();
    let count: usize = part.rows.values().map(|r| 3 * r.len()).sum();
    let chunks = part.rows.values().map(|r| r.as_flattened());
    write_rows(
        path,
        part.kind,
        part.shard,
        &part.meta,
        &rows,
        count as u64,
        chunks,
        overwrite,
    )
}

/// Writes a shard or checkpoint file of `rows` (increasing) whose values, `count` in all,
/// `chunks` gives row by row (see [`write_part`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_rows(
    path: &Path,
    kind: Kind,
    shard: Option<ShardId>,
    meta: &Metadata,
    rows: &[usize],
    count: u64,
    chunks: impl IntoIterator<Item = impl AsRef<[f32]>>,
    overwrite: bool,
) -> Result<(), TableError> {
    let header = Header {
        shard,
        rows: ranges(rows.iter().copied()),
        metadata: meta.clone(),
    };
    let header = serde_json::to_value(&header).map_err(|e| TableError::Unwritable {
        path: path.to_path_buf(),
        what: container_kind(kind).tag().into(),
        reason: format!("the header cannot be written as JSON ({e})"),
    })?;
    write_container_counted(
        path,
        container_kind(kind),
        &header,
        count,
        chunks,
        overwrite,
    )
}

fn container_kind(kind: Kind) -> ContainerKind {
    match kind {
        Kind::Shard => ContainerKind::Shard,
        Kind::Checkpoint => ContainerKind::Checkpoint,
    }
}

/// Reads a shard or checkpoint file (the container's checks: magic bytes, version, kind, sizes,
/// checksum), then checks that the rows are increasing ranges within the grid, that every row
/// holds the values its grid and symmetry call for, and that every value is finite.
pub fn read_part(
    path: &Path,
    orbits_of: impl Fn(&Metadata) -> Result<Orbits, String>,
) -> Result<Part, TableError> {
    let c = read_container(path, &[ContainerKind::Shard, ContainerKind::Checkpoint])?;
    let corrupt = |reason: String| TableError::Corrupted {
        path: path.to_path_buf(),
        reason,
    };
    let kind = match c.kind {
        ContainerKind::Shard => Kind::Shard,
        _ => Kind::Checkpoint,
    };
    let h: Header = serde_json::from_value(c.header).map_err(|e| {
        corrupt(format!(
            "the header does not describe a {} ({e})",
            c.kind.tag()
        ))
    })?;
    let orbits = orbits_of(&h.metadata).map_err(|m| {
        corrupt(format!(
            "{m} (baked by {}; bake it with this clothbake)",
            h.metadata.tool
        ))
    })?;
    if let Some(s) = h.shard {
        if s.count == 0 || s.index >= s.count {
            return Err(corrupt(format!(
                "shard {s} is not a shard index below the count"
            )));
        }
    }
    let mut rows = BTreeMap::new();
    let mut values = c.values.chunks_exact(3);
    let mut last: Option<usize> = None;
    for &[a, b] in &h.rows {
        if a >= b || b > orbits.rows() || last.is_some_and(|l| a < l) {
            return Err(corrupt(format!(
                "row range {a}..{b} is not in increasing order within the grid's {} rows",
                orbits.rows()
            )));
        }
        last = Some(b);
        for r in a..b {
            let k = orbits.row_evaluations(r);
            let mut row = Vec::with_capacity(k);
            for _ in 0..k {
                let v = values.next().ok_or_else(|| {
                    corrupt(format!(
                        "{} values, fewer than its rows need",
                        c.values.len()
                    ))
                })?;
                if let Some(x) = v
                    .iter()
                    .find(|x| !(x.is_finite() && **x >= 0.0 && **x <= clothbake_loader::MAX_VALUE))
                {
                    return Err(corrupt(format!(
                        "row {r} holds the value {x}, not a reflectance (finite, from 0 to {:e} \
                         1/sr)",
                        clothbake_loader::MAX_VALUE
                    )));
                }
                row.push([v[0], v[1], v[2]]);
            }
            rows.insert(r, row);
        }
    }
    if values.next().is_some() || !values.remainder().is_empty() {
        return Err(corrupt(format!(
            "{} values, more than its rows need",
            c.values.len()
        )));
    }
    Ok(Part {
        kind,
        shard: h.shard,
        meta: h.metadata,
        rows,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn split_covers_every_row_once_in_order() {
        for costs in [
            vec![1u64; 10],
            vec![0, 5, 0, 5, 0, 5, 0, 5],
            vec![7],
            vec![3, 1, 4, 1, 5, 9, 2, 6],
        ] {
            for n in 1..=12u32 {
                let s = split(&costs, n);
                assert_eq!(s.len(), n as usize);
                assert_eq!(s[0].start, 0);
                assert_eq!(s.last().unwrap().end, costs.len());
                assert!(s.windows(2).all(|w| w[0].end == w[1].start));
                // Balanced: each shard costs at most total/n plus its largest row.
                let total: u64 = costs.iter().sum();
                for r in &s {
                    let c: u64 = costs[r.clone()].iter().sum();
                    let max = costs[r.clone()].iter().max().copied().unwrap_or(0);
                    assert!(
                        c as f64 <= total as f64 / n as f64 + max as f64,
                        "{costs:?} {n} {s:?}"
                    );
                }
            }
        }
        // Equal rows split evenly.
        assert_eq!(split(&[2; 8], 4), [0..2, 2..4, 4..6, 6..8]);
        // Free rows (all copies) do not count: half the rows cost nothing.
        assert_eq!(split(&[1, 1, 0, 0, 1, 1, 0, 0], 2), [0..2, 2..8]);
    }

    fn env(vars: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
        let v: Vec<(String, String)> = vars
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect();
        move |k: &str| v.iter().find(|(a, _)| a == k).map(|(_, b)| b.clone())
    }

    #[test]
    fn shard_ids() {
        assert_eq!(
            parse_shard_id("0/4").unwrap(),
            ShardId { index: 0, count: 4 }
        );
        assert_eq!(
            parse_shard_id(" 3 / 4 ").unwrap(),
            ShardId { index: 3, count: 4 }
        );
        for (bad, needle) in [
            ("4/4", "0-based"),
            ("1/0", "N is 0"),
            ("x/4", "`x`"),
            ("3", "not K/N"),
            ("-1/4", "`-1`"),
        ] {
            let e = parse_shard_id(bad).unwrap_err();
            assert!(e.contains(needle), "{bad}: {e}");
            let e = parse_shard_id_as(bad, Naming::Python).unwrap_err();
            assert!(e.contains(needle), "{bad}: {e}");
            assert!(
                e.contains("shard=\"0/4\"") && !e.contains("--"),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn shard_from_the_environment() {
        let id = |i, n| ShardId { index: i, count: n };
        // SLURM arrays 0-3, 1-4 and 0-6:2 all give K = 0..3.
        let (s, how) = shard_from_env(
            &env(&[
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "4"),
            ]),
            None,
        )
        .unwrap();
        assert_eq!(s, id(2, 4));
        assert!(how.contains("SLURM_ARRAY_TASK_ID=2"), "{how}");
        let (count, min, step) = (
            ("SLURM_ARRAY_TASK_COUNT", "4"),
            "SLURM_ARRAY_TASK_MIN",
            ("SLURM_ARRAY_TASK_STEP", "2"),
        );
        for vars in [
            &[("SLURM_ARRAY_TASK_ID", "4"), count, (min, "1")][..],
            &[("SLURM_ARRAY_TASK_ID", "6"), count, (min, "0"), step],
        ] {
            assert_eq!(
                shard_from_env(&env(vars), None).unwrap().0,
                id(3, 4),
                "{vars:?}"
            );
        }
        // SLURM wins over Kubernetes; --shards must agree with SLURM.
        let e = env(&[
            ("SLURM_ARRAY_TASK_ID", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
            ("JOB_COMPLETION_INDEX", "0"),
        ]);
        assert_eq!(shard_from_env(&e, Some(4)).unwrap().0, id(1, 4));
        assert!(shard_from_env(&e, Some(3))
            .unwrap_err()
            .contains("SLURM_ARRAY_TASK_COUNT=4"));
        // Kubernetes needs --shards.
        let e = env(&[("JOB_COMPLETION_INDEX", "3")]);
        let (s, how) = shard_from_env(&e, Some(4)).unwrap();
        assert_eq!(s, id(3, 4));
        assert!(how.contains("JOB_COMPLETION_INDEX=3"), "{how}");
        assert!(shard_from_env(&e, None).unwrap_err().contains("--shards N"));
        assert!(shard_from_env(&e, Some(3))
            .unwrap_err()
            .contains("not below"));
        // Errors.
        for (vars, shards, needle) in [
            (&[][..], Some(4), "neither"),
            (
                &[("SLURM_ARRAY_TASK_ID", "1")],
                None,
                "SLURM_ARRAY_TASK_COUNT is not",
            ),
            (
                &[("SLURM_ARRAY_TASK_ID", "5"), count],
                None,
                "not one of the array's tasks",
            ),
            (
                &[("SLURM_ARRAY_TASK_ID", "x"), count],
                None,
                "not a whole number",
            ),
        ] {
            let e = shard_from_env(&env(vars), shards).unwrap_err();
            assert!(e.contains(needle), "{vars:?}: {e}");
        }
    }

    #[test]
    fn ranges_compress_rows() {
        assert_eq!(
            ranges([0, 1, 2, 5, 7, 8].into_iter()),
            [[0, 3], [5, 6], [7, 9]]
        );
        assert!(ranges(std::iter::empty()).is_empty());
    }
}
