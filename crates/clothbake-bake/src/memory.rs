//! How much memory a bake needs, and how much the machine has: a bake that would not fit is
//! refused before anything is allocated, in one line with the numbers and the fix.
//!
//! The estimate ([`peak_bytes`]) counts what grows with the grid, with no credit for
//! symmetry (an upper bound): the orbit map (16 bytes per (phi_i, phi_o) pair), the finished
//! rows (12 bytes per cell, RGB f32) and their copy while a checkpoint is written, and for a
//! table the assembled values (12 bytes per cell) and the writer's buffers (OpenEXR: the
//! channels, the encoder's blocks and the encoded file, measured at 88 bytes per cell in f32
//! and 47 in f16 beyond the values, counted as 96 and 56; binary: none, it streams).
//! [`available_bytes`] reads the operating system's figure (Linux: `MemAvailable` of
//! /proc/meminfo, lowered to the cgroup's limit where one is set).

use clothbake_loader::{Grid, Precision};

use crate::output::Format;

/// Bytes of memory a bake needs besides the grid (the program, the model, thread stacks).
pub const BASE_BYTES: u64 = 64 << 20;

/// What a bake keeps in memory at the end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kept {
    /// A table, returned (Python) or written in `format`.
    Table(Option<Format>),
    /// The rows of a shard, written as a shard file.
    Shard,
}

/// The most memory a bake of `grid` needs, in bytes, when it evaluates `rows` of its
/// (theta_i, phi_i) rows (all of them for a table, the shard's for a shard) and keeps `kept`
/// (see the module documentation for what is counted).
pub fn peak_bytes(grid: &Grid, rows: u64, kept: Kept) -> u64 {
    let pairs = u64::from(grid.n_phi_i) * u64::from(grid.n_phi_o);
    let orbits = 16 * pairs + 8 * u64::from(grid.n_phi_i);
    let cells = rows * u64::from(grid.n_theta_o) * u64::from(grid.n_phi_o);
    // The rows and their copy while a checkpoint is written; a small header per row.
    let sweep = 24 * cells + 64 * rows;
    let all = grid.len() as u64;
    let end = match kept {
        Kept::Shard => 0,
        // The rows and the assembled values (the rows are dropped before writing).
        Kept::Table(format) => {
            let writer = match format {
                Some(Format::Exr(Precision::F32)) => 96 * all,
                Some(Format::Exr(Precision::F16)) => 56 * all,
                Some(Format::Binary) | None => 0,
            };
            (24 * all).max(12 * all + writer)
        }
    };
    BASE_BYTES + orbits + sweep.max(end)
}

/// The most memory merging shards whose files hold `shard_bytes` in all needs, in bytes,
/// writing `format`: the shards' values (at most their files' size), the table's (at least
/// as many: copies by symmetry are not in the shards; counted as 3 times the files' size, the
/// most a symmetry group of 4 saves, less the copy already counted), and the writer's buffers
/// (per cell, as for a bake).
pub fn merge_bytes(shard_bytes: u64, format: Format) -> u64 {
    // A cell is 12 bytes in a shard; the table may hold up to 4 times the shards' cells.
    let cells = shard_bytes / 12 * 4;
    let writer = match format {
        Format::Exr(Precision::F32) => 96 * cells,
        Format::Exr(Precision::F16) => 56 * cells,
        Format::Binary => 0,
    };
    BASE_BYTES + shard_bytes + 12 * cells + writer
}

/// The memory available to this process, in bytes, where the platform says (`None`
/// elsewhere: no check is made).
pub fn available_bytes() -> Option<u64> {
    #[cfg(target_os = "linux")]
    {
        let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
        let free = meminfo.as_deref().and_then(mem_available);
        match (free, cgroup_room()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
    #[cfg(not(target_os = "linux"))]
    None
}

/// `MemAvailable` of a /proc/meminfo text, in bytes.
pub fn mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let n: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") | None => n.checked_mul(1024),
        Some(_) => None,
    }
}

/// The room left under this process's cgroup memory limit (v2, or v1), if one is set.
#[cfg(target_os = "linux")]
fn cgroup_room() -> Option<u64> {
    let read = |p: &str| -> Option<u64> { std::fs::read_to_string(p).ok()?.trim().parse().ok() };
    // cgroup v2: the process's own group, from /proc/self/cgroup ("0::/path").
    let own = std::fs::read_to_string("/proc/self/cgroup")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("0::").map(|p| p.trim().to_string()))
        })
        .unwrap_or_default();
    for dir in [format!("/sys/fs/cgroup{own}"), "/sys/fs/cgroup".to_string()] {
        if let Some(max) = read(&format!("{dir}/memory.max")) {
            let used = read(&format!("{dir}/memory.current")).unwrap_or(0);
            return Some(max.saturating_sub(used));
        }
    }
    // cgroup v1 (no limit reads as a huge number).
    let max = read("/sys/fs/cgroup/memory/memory.limit_in_bytes")?;
    let used = read("/sys/fs/cgroup/memory/memory.usage_in_bytes").unwrap_or(0);
    (max < 1 << 60).then(|| max.saturating_sub(used))
}

/// Bytes in words: `51.5 GB`, `980 MB` (powers of 1000).
pub fn describe(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else {
        format!("{:.0} MB", (b / 1e6).max(1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: [u32; 4]) -> Grid {
        Grid {
            n_theta_i: n[0],
            n_phi_i: n[1],
            n_theta_o: n[2],
            n_phi_o: n[3],
        }
    }

    #[test]
    fn the_issue_grid_needs_tens_of_gigabytes() {
        // 2^31 cells: the values alone are 2^31 * 12 bytes = 25.8 GB, twice that at the end.
        let g = grid([32768, 65536, 1, 1]);
        let cells = 1u64 << 31;
        let p = peak_bytes(&g, cells, Kept::Table(Some(Format::Binary)));
        assert!(p >= 2 * 12 * cells, "{p}");
        assert_eq!(describe(51_600_000_000), "51.6 GB");
        assert_eq!(describe(980_400_000), "980 MB");
        // A shard of a quarter of the rows needs about a quarter.
        let s = peak_bytes(&g, cells / 4, Kept::Shard);
        assert!(s < p / 3, "{s} {p}");
    }

    #[test]
    fn exr_needs_more_than_binary_and_f32_more_than_f16() {
        let g = grid([32, 64, 32, 64]);
        let c = g.len() as u64;
        let of = |f| peak_bytes(&g, 32 * 64, Kept::Table(f));
        let f32 = of(Some(Format::Exr(Precision::F32)));
        let f16 = of(Some(Format::Exr(Precision::F16)));
        let bin = of(Some(Format::Binary));
        assert!(f32 > f16 && f16 >= bin, "{f32} {f16} {bin}");
        // Peaks measured (maximum resident set, `clothbake bake --res 2,1024,2,1024`, twill,
        // 4.2 M cells, 8 MB for a 1-cell bake): 419 MB beyond the program for an f32 EXR,
        // 249 MB for f16, 90 MB for binary (half the cells evaluated, by symmetry; all of
        // them would hold 24 bytes per cell): the estimate is above each.
        assert!(f32 >= BASE_BYTES + 100 * c, "{f32}");
        assert!(f16 >= BASE_BYTES + 60 * c, "{f16}");
        assert!(bin >= BASE_BYTES + 24 * c, "{bin}");
        assert_eq!(of(None), bin);
    }

    #[test]
    fn a_merge_holds_its_shards_and_the_table() {
        // 12 MB of shards: 1 M cells, up to 4 M in the table (a symmetry group of 4).
        let m = merge_bytes(12_000_000, Format::Binary);
        assert!(m >= BASE_BYTES + 12_000_000 + 48_000_000, "{m}");
        assert!(merge_bytes(12_000_000, Format::Exr(Precision::F32)) > m);
    }

    #[test]
    fn meminfo_is_read_in_kilobytes() {
        let text = "MemTotal:       24000000 kB\nMemFree:  1 kB\nMemAvailable:   22000000 kB\n";
        assert_eq!(mem_available(text), Some(22_000_000 * 1024));
        assert_eq!(mem_available("MemTotal: 5 kB\n"), None);
        assert_eq!(mem_available("MemAvailable: x kB\n"), None);
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn this_machine_has_some_memory() {
        let a = available_bytes().expect("Linux says");
        assert!(a > 1 << 20, "{a}");
    }
}
