//! How much memory a bake needs, and how much the machine has: a bake that would not fit is
//! refused before anything is allocated, in one line with the numbers and the fix.
//!
//! The estimate ([`peak_bytes`]) counts what grows with the grid, with no credit for
//! symmetry (an upper bound): the orbit map (8 bytes per (phi_i, phi_o) pair), the one buffer
//! the rows are written into and the table is made of ([`crate::assembly`]: 4 bytes per value
//! of each cell of the rows baked, 3 values of an averaged table, 3 + the lanes of every class
//! of a spatial one, and 64 bytes per row), with `--resume` the checkpoint's values while they
//! are read (as many bytes at most), and for an OpenEXR table the encoder's
//! block (16 lines of the image, or all of them when fewer, in the encoder's working copies:
//! measured at 51 bytes per pixel of the block in f32 and 22 in f16, counted as 56, and 4 MiB
//! for the rest of its state; binary tables stream from the buffer). A `sliced3d` bake adds
//! the open arcs it keeps for the grid's directions, counted at their budget
//! ([`crate::sweep::OPEN_ARCS_BUDGET`], 256 MiB; `job::check_memory`). [`available_bytes`] reads the operating system's
//! figure (Linux: `MemAvailable` of /proc/meminfo, lowered to the cgroup's limit where one is
//! set).

use clothbake_loader::Grid;
#[cfg(test)]
use clothbake_loader::Precision;

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
/// (theta_i, phi_i) rows (all of them for a table, the shard's for a shard), holds `values`
/// f32 values a cell (3 for an averaged table; a spatial one 3 + its classes' lanes), keeps
/// `kept` and, with `resume`, first reads a checkpoint (see the module documentation for what
/// is counted). Only what holds values grows with `values`: the fixed allowance does not.
pub fn peak_bytes(grid: &Grid, rows: u64, values: u64, kept: Kept, resume: bool) -> u64 {
    let pairs = u64::from(grid.n_phi_i) * u64::from(grid.n_phi_o);
    let orbits = 8 * pairs + 8 * u64::from(grid.n_phi_i);
    let cells = rows * u64::from(grid.n_theta_o) * u64::from(grid.n_phi_o);
    let cell_bytes = 4u64.saturating_mul(values);
    // The buffer, a flag and the rows in flight per row; the checkpoint read on resuming.
    let buffer = cell_bytes.saturating_mul(cells);
    let sweep = buffer
        .saturating_add(64 * rows)
        .saturating_add(if resume { buffer } else { 0 });
    // The encoder's block: 56 bytes a pixel of three channels, as many thirds as channels.
    let writer = match kept {
        Kept::Table(Some(Format::Exr(_))) => {
            let pixels = grid.exr_width() * grid.exr_height().min(16);
            (4 << 20) + (56 * pixels).saturating_mul(values) / 3
        }
        Kept::Table(_) | Kept::Shard => 0,
    };
    (BASE_BYTES + orbits)
        .saturating_add(sweep)
        .saturating_add(writer)
}

/// The most memory merging shards whose files hold `shard_bytes` in all needs, in bytes,
/// writing `format`: the shards' values (at most their files' size), the table's (at least
/// as many: copies by symmetry are not in the shards; counted as 4 times the files' size, the
/// most a symmetry group of 4 saves), and the OpenEXR encoder's block (at most the image
/// at 56 bytes a pixel, the image's width being unknown here).
pub fn merge_bytes(shard_bytes: u64, format: Format) -> u64 {
    // A cell is 12 bytes in a shard; the table may hold up to 4 times the shards' cells.
    let cells = shard_bytes / 12 * 4;
    // The encoder's block, uncompressed and compressed: 16 lines of the image, whose width
    // is not known here: at most the whole image.
    let writer = match format {
        Format::Exr(_) => 56 * cells,
        Format::Binary => 0,
    };
    BASE_BYTES + shard_bytes + 12 * cells + writer
}

/// The memory available to this process, in bytes, where the platform says (`None`
/// elsewhere: no check is made): the least of the machine's free memory, the room under the
/// process's cgroup limit and the room under its address-space limit (`ulimit -v`).
pub fn available_bytes() -> Option<u64> {
    #[cfg(target_os = "linux")]
    {
        let meminfo = std::fs::read_to_string("/proc/meminfo").ok();
        let free = meminfo.as_deref().and_then(mem_available);
        [free, cgroup_room(), address_space_room()]
            .into_iter()
            .flatten()
            .min()
    }
    #[cfg(not(target_os = "linux"))]
    None
}

/// The room left under this process's address-space limit (RLIMIT_AS, `ulimit -v`), if one is
/// set: the limit less the address space already mapped (`VmSize` of /proc/self/status).
#[cfg(target_os = "linux")]
fn address_space_room() -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes one rlimit into the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0
        || limit.rlim_cur == libc::RLIM_INFINITY
    {
        return None;
    }
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let mapped: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(limit.rlim_cur.saturating_sub(mapped.saturating_mul(1024)))
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
        Grid::new(n[0], n[1], n[2], n[3])
    }

    #[test]
    fn the_issue_grid_needs_tens_of_gigabytes() {
        // 2^31 cells: the values alone are 2^31 * 12 bytes = 25.8 GB.
        let g = grid([32768, 65536, 1, 1]);
        let cells = 1u64 << 31;
        let p = peak_bytes(&g, cells, 3, Kept::Table(Some(Format::Binary)), false);
        assert!(p >= 12 * cells, "{p}");
        assert_eq!(describe(51_600_000_000), "51.6 GB");
        assert_eq!(describe(980_400_000), "980 MB");
        // A shard of a quarter of the rows needs about a quarter.
        let s = peak_bytes(&g, cells / 4, 3, Kept::Shard, false);
        assert!(s < p / 3, "{s} {p}");
        // Resuming reads the checkpoint besides the buffer.
        let r = peak_bytes(&g, cells, 3, Kept::Table(Some(Format::Binary)), true);
        assert!(r >= 24 * cells, "{r}");
    }

    #[test]
    fn exr_needs_more_than_binary() {
        let of = |g: &Grid, f| {
            peak_bytes(
                g,
                u64::from(g.n_theta_i * g.n_phi_i),
                3,
                Kept::Table(f),
                false,
            )
        };
        for n in [[32, 64, 32, 64], [2, 1024, 2, 1024]] {
            let g = grid(n);
            let c = g.len() as u64;
            let f32 = of(&g, Some(Format::Exr(Precision::F32)));
            let f16 = of(&g, Some(Format::Exr(Precision::F16)));
            let bin = of(&g, Some(Format::Binary));
            assert!(f32 >= f16 && f16 > bin, "{f32} {f16} {bin}");
            assert_eq!(of(&g, None), bin);
            // Peaks measured (maximum resident set of `clothbake bake`, twill, 4.2 M cells;
            // 6.4 MB for a 1-cell bake): on the default grid (50.3 MB of values, half of them
            // evaluated by symmetry) 61.1, 60.1 and 58.3 MB for f32 EXR, f16 EXR and binary;
            // on the 2,1024,2,1024 grid, whose 4 lines of 1 M pixels make one encoder block,
            // 267.4, 143.3 and 66.3 MB (8 MB of it the orbit map): the estimate is above each.
            let (exr32, exr16, binary) = if n[0] == 2 {
                (267.4e6, 143.3e6, 66.3e6)
            } else {
                (61.1e6, 60.1e6, 58.3e6)
            };
            assert!(f32 as f64 >= exr32, "{f32}");
            assert!(f16 as f64 >= exr16, "{f16}");
            assert!(bin as f64 >= binary, "{bin}");
            // The default grid: the buffer and a little more.
            if n[0] == 32 {
                assert!(f32 < BASE_BYTES + 14 * c, "{f32}");
            }
        }
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
