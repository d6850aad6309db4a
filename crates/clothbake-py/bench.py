"""One million table lookups from Python (numpy in, numpy out) against the loader's Rust
batch loop (Brdf::eval_batch over the same number of pairs, timed in Rust).

    python3 crates/clothbake-py/bench.py [tables/twill.json]

Prints the medians of 7 runs and their ratio.
"""

import statistics
import sys
import time

import numpy as np

import clothbake

N = 1_000_000
REPEATS = 7


def hemisphere(n, rng):
    z = rng.uniform(0.0, 1.0, n)
    phi = rng.uniform(0.0, 2 * np.pi, n)
    r = np.sqrt(1 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def main():
    fabric = clothbake.Fabric(sys.argv[1] if len(sys.argv) > 1 else "tables/twill.json")
    table = clothbake.bake(fabric, res=(32, 64, 32, 64))
    rng = np.random.default_rng(1)
    wi, wo = hemisphere(N, rng), hemisphere(N, rng)
    results = {}
    for dtype in (np.float64, np.float32):
        a, b = wi.astype(dtype), wo.astype(dtype)
        table.eval(a, b)  # warm-up
        t = []
        for _ in range(REPEATS):
            start = time.perf_counter()
            table.eval(a, b)
            t.append(time.perf_counter() - start)
        results[np.dtype(dtype).name] = statistics.median(t)
    rust = table._rust_batch_seconds(N, REPEATS)
    print(f"{N} lookups, twill, 32x64x32x64 f32 table, medians of {REPEATS}:")
    print(f"  Rust batch loop (Brdf::eval_batch): {rust * 1e3:8.1f} ms")
    for name, t in results.items():
        print(f"  Python Table.eval, {name} arrays:  {t * 1e3:8.1f} ms  ratio {t / rust:.2f}")


if __name__ == "__main__":
    main()
