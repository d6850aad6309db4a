"""Opening a table from Python (issue 38): the wall time of `clothbake.Table.open` and the
process's resident memory before and after.

    python3 crates/clothbake-py/bench_open.py twill.exr [repeats]

Prints each open's time, their median, and the resident set (VmRSS) before the first open and
after the last (one table held), next to what the lookup layout holds (`memory_bytes` of the
loader is not exposed to Python; the layout of a 32 x 64 x 32 x 64 f16 table is 95.2 MB,
docs/reference/loader.md).
"""

import statistics
import sys
import time

import clothbake


def rss_mb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def main():
    path = sys.argv[1]
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 9
    before = rss_mb()
    times = []
    table = None
    for _ in range(repeats):
        table = None  # the previous table is freed first: one held at a time
        start = time.perf_counter()
        table = clothbake.Table.open(path)
        times.append(1e3 * (time.perf_counter() - start))
    after = rss_mb()
    print("opens (ms):", " ".join(f"{t:.1f}" for t in times))
    print(f"first {times[0]:.1f} ms, median {statistics.median(times):.1f} ms")
    print(f"VmRSS before {before:.1f} MB, after {after:.1f} MB ({after - before:.1f} MB for the table)")
    print("grid", table.grid, "precision", table.precision)


if __name__ == "__main__":
    main()
