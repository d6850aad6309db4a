//! The ground truth: an exact ray tracer (and a many-bounce path tracer) of woven cloth's
//! micro-geometry, against which every approximation of the crate is measured.
//!
//! It is written independently of the analytic model so that a bug in the model's geometry or
//! facet terms shows up as a disagreement instead of being shared: it builds its own
//! micro-geometry from the fabric's *description* and shades with its own facet terms.
//!
//! * [`description`]: the one file that reads a [`Fabric`](crate::fabric::Fabric) (and the
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
//! `crate::weave` (the pattern type), and the plain output types `crate::reflect::Reflection`
//! and `crate::interreflection::{Kernel, Secondary}` (the path tracer's bounce weight and I_2
//! split); `description` alone also names `crate::fabric` and `crate::facet::FacetModel`.
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

    /// What non-test code of each file may name with a `crate::` path: module prefixes allowed
    /// everywhere, and those allowed in `description.rs` alone.
    const ANYWHERE: [&str; 6] = [
        "crate::vec3::",
        "crate::rng::",
        "crate::weave::",
        "crate::reflect::Reflection",
        "crate::interreflection::{Kernel, Secondary}",
        "crate::truth::",
    ];
    const DESCRIPTION: [&str; 2] = ["crate::fabric::Fabric", "crate::facet::FacetModel"];

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

    /// The `crate::...` paths of `code` outside the allowed list for `file`, and any way out of
    /// the module that is not a `crate::` path.
    fn violations(file: &str, code: &str) -> Vec<String> {
        let mut bad = Vec::new();
        for (at, _) in code.match_indices("crate::") {
            // Skip `clothbake_crate::` style identifiers ending in `crate`.
            let before = code[..at].chars().next_back();
            if before.is_some_and(|c| c.is_alphanumeric() || c == '_') {
                continue;
            }
            let rest = &code[at..];
            // A module prefix (ending in `::`) or a whole item, not a longer name.
            let allowed = |p: &&str| {
                rest.starts_with(*p)
                    && (p.ends_with("::")
                        || !rest[p.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_'))
            };
            let ok = ANYWHERE.iter().any(allowed)
                || (file == "description.rs" && DESCRIPTION.iter().any(allowed));
            if !ok {
                let end = rest.find([';', '\n', ' ', ')']).unwrap_or(rest.len());
                bad.push(format!("{file}: {}", &rest[..end]));
            }
        }
        for word in ["super::super", "clothbake_core", "#[path"] {
            if code.contains(word) {
                bad.push(format!("{file}: {word}"));
            }
        }
        // The fabric and the model's facet selector are read in description.rs only.
        for word in ["Fabric", "FacetModel"] {
            if file != "description.rs" && code.contains(word) {
                bad.push(format!("{file}: names {word}"));
            }
        }
        bad
    }

    #[test]
    fn the_truth_imports_only_what_its_module_doc_lists() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/truth");
        let mut files = 0;
        let mut bad = Vec::new();
        for e in std::fs::read_dir(&dir).unwrap() {
            let p = e.unwrap().path();
            assert!(
                p.extension().is_some_and(|x| x == "rs"),
                "{}: the truth is one flat folder of .rs files",
                p.display()
            );
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            bad.extend(violations(
                &name,
                &code(&std::fs::read_to_string(&p).unwrap()),
            ));
            files += 1;
        }
        assert!(files >= 8, "{files} files in {}", dir.display());
        assert!(
            bad.is_empty(),
            "imports outside the truth's boundary:\n{}",
            bad.join("\n")
        );
    }

    #[test]
    fn the_boundary_check_catches_what_it_should() {
        // The scanner itself: a forbidden path is reported, an allowed one and comments are not.
        let code = code(
            "use crate::geometry::Geometry;\n// crate::facet::Facet\nuse crate::vec3::Vec3;\n",
        );
        assert_eq!(
            violations("cells.rs", &code),
            ["cells.rs: crate::geometry::Geometry"]
        );
        let grouped = "use crate::{vec3::Vec3, facet::Facet};\nuse crate::interreflection::Kernel;";
        assert_eq!(violations("x.rs", grouped).len(), 2);
        assert!(violations("x.rs", "let f: Fabric;").len() == 1);
        assert!(violations("description.rs", "use crate::fabric::Fabric;").is_empty());
        assert_eq!(violations("x.rs", "use crate::fabric::Fabric;").len(), 2);
        for longer in [
            "use crate::interreflection::{Kernel, Secondary, peak};",
            "use crate::reflect::Reflections;",
        ] {
            assert_eq!(violations("x.rs", longer).len(), 1, "{longer}");
        }
    }
}
