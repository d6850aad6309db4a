//! The ground truth: an exact ray tracer (and a many-bounce path tracer) of woven cloth's
//! micro-geometry, against which every approximation of the crate is measured.
//!
//! It is written independently of the analytic model so that a bug in the model's geometry or
//! facet terms shows up as a disagreement instead of being shared: it builds its own
//! micro-geometry from the fabric's *description* and shades with its own facet terms.
//!
//! * [`description`]: the one file that reads a [`Fabric`](clothbake_fabric::fabric::Fabric) (and the
//!   model's facet selector), copying it into the plain [`Description`];
//! * [`yarns`]: segment placement and extents (thesis ch. 2, `docs/science/geometry.md`);
//! * [`facets`]: Huo's terms (eqs 4.6, 4.8) and Lewis's modified Phong;
//! * [`intersect`]: cylinder, cap-slab and floor intervals of one segment;
//! * [`cells`]: the acceleration cells over one period and the walk over the tiling;
//! * [`estimate`]: the batch ratio estimator and its standard error;
//! * [`raytracer`]: [`RayTracer`], the direct reflection (eq. 4.11's average);
//! * [`patches`]: the same estimate resolved per crossing cell of the period;
//! * [`pathtracer`]: [`PathOptions`], [`PathEstimate`], every bounce order;
//! * [`transmission`]: the two-faced cloth (no floor, translucent yarns): openness, where the
//!   light goes ([`Scattering`]) and f over the whole sphere.
//!
//! Imports from the rest of the crate are limited to `crate::vec3`, `crate::rng`,
//! `crate::weave` (the pattern type), and the plain output types `clothbake_fabric::Reflection`
//! and `clothbake_fabric::{Kernel, Secondary}` (the path tracer's bounce weight and I_2
//! split); `description` alone also names `crate::fabric` and `clothbake_fabric::FacetModel`.
//! A unit test below enforces this.

pub mod cells;
pub mod description;
pub mod estimate;
pub mod facets;
pub mod intersect;
pub mod patches;
pub mod pathtracer;
pub mod raytracer;
pub mod transmission;
pub mod yarns;

pub use description::{Description, Finish, Thread};
pub use estimate::{Estimate, BATCHES};
pub use facets::{Shading, Terms};
pub use patches::CellEstimate;
pub use pathtracer::{PathEstimate, PathOptions};
pub use raytracer::{Caps, RayTracer};
pub use transmission::Scattering;
pub use yarns::{Cylinder, Face, Yarns};

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// The code of a source file up to its test module, without comments.
    fn code(text: &str) -> String {
        let mut out = String::new();
        for line in text.lines() {
            let t = line.trim_start();
            if t.starts_with("#[cfg(test)]") {
                break;
            }
            if t.starts_with("//") {
                continue;
            }
            out.push_str(line.split(" //").next().unwrap_or(""));
            out.push('\n');
        }
        out
    }

    /// The words of `code` that read the fabric or the facet selector outside `description.rs`.
    fn readers(file: &str, code: &str) -> Vec<String> {
        if file == "description.rs" {
            return Vec::new();
        }
        ["Fabric", "FacetModel"]
            .iter()
            .filter(|w| code.contains(*w))
            .map(|w| format!("{file}: names {w}"))
            .collect()
    }

    #[test]
    fn only_the_description_reads_the_fabric() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut files = 0;
        let mut bad = Vec::new();
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            bad.extend(readers(&name, &code(&std::fs::read_to_string(&p).unwrap())));
            files += 1;
        }
        assert!(files >= 8, "{files} files in {}", dir.display());
        assert!(
            bad.is_empty(),
            "the fabric read outside description.rs:\n{}",
            bad.join("\n")
        );
        // The scanner itself: a reader elsewhere is caught, comments and description.rs are not.
        assert_eq!(readers("x.rs", &code("let f: &Fabric;\n")).len(), 1);
        assert!(readers("x.rs", &code("// Fabric\nlet x = 1;\n")).is_empty());
        assert!(readers("description.rs", "use clothbake_fabric::Fabric;").is_empty());
    }
}
