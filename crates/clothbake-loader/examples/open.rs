//! Opens a table file `n` times (default 1) and prints each open's wall time: a target for
//! `perf record` and `/usr/bin/time` (docs/reference/benchmarks.md, "Opening a table").
//!
//! `cargo run --release -p clothbake-loader --example open -- twill.exr [n]`

use std::time::Instant;

use clothbake_loader::{Brdf, Options};

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: open TABLE [N]");
        std::process::exit(2);
    };
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    for _ in 0..n {
        let t = Instant::now();
        match Brdf::open(path.as_ref(), Options::default()) {
            Ok(b) => {
                let dt = t.elapsed();
                let f = b.eval([0.3, 0.1, 0.9486833], [-0.4, 0.2, 0.8944272]);
                println!(
                    "{:.2} ms, {} bytes held, f {:?}",
                    dt.as_secs_f64() * 1e3,
                    b.memory_bytes(),
                    f
                );
            }
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(2);
            }
        }
    }
}
