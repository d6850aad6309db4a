//! Fabric description files (JSON) and their validation into a [`Fabric`].
//!
//! Schema (every length in the same arbitrary unit; see `docs/fabric-format.md`):
//! ```json
//! { "name": "twill", "pattern": [[1,1,0],[0,1,1],[1,0,1]],
//!   "warp": { "radius": 1.5, "height": 0.0, "spacing": 3.1,
//!             "material": { "albedo": [0.4,0.4,0.4], "specular": 0.3, "exponent": 10 } },
//!   "weft": { "radius": 1.5, "spacing": 3.1, "segment_length": 3.2 } }
//! ```
//! `radius`, `height`, `spacing` and `segment_length` take one number for the whole group or
//! an array with one value per thread of the period.

use crate::weave::{Group, Weave};
use crate::wif::WifOptions;
use serde::Deserialize;
use serde_json::Value;
use std::fmt;
use std::path::Path;

/// Facet material defaults of thesis sec. 4.3.
pub const DEFAULT_ALBEDO: f64 = 0.4;
/// Default specular coefficient rho_s (sec. 4.3).
pub const DEFAULT_SPECULAR: f64 = 0.3;
/// Default specular exponent n (sec. 4.3).
pub const DEFAULT_EXPONENT: f64 = 10.0;

/// A bad fabric description: the file, the field, what is wrong and how to fix it.
#[derive(Debug, Clone, PartialEq)]
pub struct FabricError {
    /// The file (or `<inline>` for a string).
    pub file: String,
    /// Dotted path of the offending field, e.g. `warp.radius[2]`.
    pub field: String,
    /// What is wrong.
    pub problem: String,
    /// How to fix it.
    pub fix: String,
}

impl fmt::Display for FabricError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.field.is_empty() {
            write!(f, "{}: {}; {}", self.file, self.problem, self.fix)
        } else {
            write!(
                f,
                "{}: field `{}`: {}; {}",
                self.file, self.field, self.problem, self.fix
            )
        }
    }
}
impl std::error::Error for FabricError {}

/// Facet material of one yarn group.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Diffuse albedo rho_d per RGB channel, each in [0, 1].
    pub albedo: [f64; 3],
    /// Specular coefficient rho_s in [0, 1].
    pub specular: f64,
    /// Specular exponent n >= 0.
    pub exponent: f64,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            albedo: [DEFAULT_ALBEDO; 3],
            specular: DEFAULT_SPECULAR,
            exponent: DEFAULT_EXPONENT,
        }
    }
}

/// One thread of the period: its cylinder radius and axis height above the floor z = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Yarn {
    /// Cylinder radius (> 0).
    pub radius: f64,
    /// Height of the cylinder axis above the floor, in (-radius, radius); 0 is a half cylinder.
    pub height: f64,
    /// Centre-to-centre distance to the next thread of the same group (>= the two radii).
    pub spacing: f64,
    /// Explicit length of every float of this thread, or `None` to derive it (see `geometry`).
    pub segment_length: Option<f64>,
    /// This thread's own diffuse albedo rho_d (RGB), overriding the group material's albedo;
    /// `None` to use the group's (fabric files: `thread_albedo`).
    pub albedo: Option<[f64; 3]>,
}

/// A yarn group (warp or weft): its threads in the period and their facet material.
#[derive(Clone, Debug, PartialEq)]
pub struct YarnGroup {
    /// One entry per thread of the period.
    pub threads: Vec<Yarn>,
    /// Facet material of the whole group (a thread's own albedo overrides its `albedo`).
    pub material: Material,
}

impl YarnGroup {
    /// Diffuse albedo of thread `t` (index modulo the period): its own, else the group's.
    pub fn albedo(&self, t: usize) -> [f64; 3] {
        self.threads[t % self.threads.len()]
            .albedo
            .unwrap_or(self.material.albedo)
    }

    /// Facet material of thread `t` (index modulo the period).
    pub fn thread_material(&self, t: usize) -> Material {
        Material {
            albedo: self.albedo(t),
            ..self.material
        }
    }
}

/// A validated fabric: weave period, both yarn groups. Every invariant the model relies on holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Fabric {
    /// Display name.
    pub name: String,
    /// The weave period.
    pub weave: Weave,
    /// Warp yarns (pattern columns, running along +Y).
    pub warp: YarnGroup,
    /// Weft yarns (pattern rows, running along +X).
    pub weft: YarnGroup,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FabricFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: Option<String>,
    pattern: Vec<Vec<Value>>,
    warp: GroupFile,
    weft: GroupFile,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GroupFile {
    radius: Value,
    #[serde(default)]
    height: Option<Value>,
    spacing: Value,
    #[serde(default)]
    segment_length: Option<Value>,
    #[serde(default)]
    material: Option<MaterialFile>,
    #[serde(default)]
    thread_albedo: Option<Vec<Value>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialFile {
    #[serde(default)]
    albedo: Option<Value>,
    #[serde(default)]
    specular: Option<f64>,
    #[serde(default)]
    exponent: Option<f64>,
}

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn err(
        &self,
        field: impl Into<String>,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> FabricError {
        FabricError {
            file: self.file.to_string(),
            field: field.into(),
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    fn number(&self, field: &str, v: &Value) -> Result<f64, FabricError> {
        match v.as_f64() {
            Some(x) if x.is_finite() => Ok(x),
            Some(_) => Err(self.err(
                field,
                "is not a finite number",
                "give a finite decimal number",
            )),
            None => Err(self.err(
                field,
                format!("expected a number, found {v}"),
                "give a decimal number",
            )),
        }
    }

    /// A diffuse albedo: one number (grey) or `[r, g, b]`, each in [0, 1].
    fn albedo(&self, f: &str, a: &Value) -> Result<[f64; 3], FabricError> {
        let out = match a {
            Value::Array(v) if v.len() == 3 => {
                let mut c = [0.0; 3];
                for (k, x) in v.iter().enumerate() {
                    c[k] = self.number(&format!("{f}[{k}]"), x)?;
                }
                c
            }
            Value::Array(v) => {
                return Err(self.err(
                    f,
                    format!("has {} values", v.len()),
                    "give one number or three (R, G, B)",
                ))
            }
            v => [self.number(f, v)?; 3],
        };
        for (k, c) in out.iter().enumerate() {
            if !(0.0..=1.0).contains(c) {
                let field = if a.is_array() {
                    format!("{f}[{k}]")
                } else {
                    f.to_string()
                };
                return Err(self.err(
                    field,
                    format!("is {c}, outside [0, 1]"),
                    "give a diffuse albedo between 0 and 1",
                ));
            }
        }
        Ok(out)
    }

    /// One value for the group or one per thread.
    fn per_thread(&self, field: &str, v: &Value, n: usize) -> Result<Vec<f64>, FabricError> {
        match v {
            Value::Array(a) => {
                if a.len() != n {
                    return Err(self.err(
                        field,
                        format!(
                            "has {} values but the period has {} threads of this group",
                            a.len(),
                            n
                        ),
                        format!("give one number for all threads or exactly {n} values"),
                    ));
                }
                a.iter()
                    .enumerate()
                    .map(|(i, x)| self.number(&format!("{field}[{i}]"), x))
                    .collect()
            }
            _ => Ok(vec![self.number(field, v)?; n]),
        }
    }
}

impl Fabric {
    /// Reads and validates a fabric file: JSON, or a WIF weaving draft when the name ends in
    /// `.wif` (any case; see [`crate::wif`]) with the default [`WifOptions`].
    pub fn from_path(path: &Path) -> Result<Fabric, FabricError> {
        Fabric::from_path_with(path, &WifOptions::default())
    }

    /// As [`Fabric::from_path`], with the sizes a WIF draft may leave out.
    pub fn from_path_with(path: &Path, wif: &WifOptions) -> Result<Fabric, FabricError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| FabricError {
            file: file.clone(),
            field: String::new(),
            problem: format!("cannot read the fabric file: {e}"),
            fix: "check the path (e.g. tables/twill.json)".into(),
        })?;
        if is_wif(path) {
            // Drafts are often Latin-1 or Windows-1252; only their [TEXT] can hold non-ASCII.
            let text = String::from_utf8_lossy(&bytes);
            return Ok(crate::wif::parse(&text, &file, wif)?);
        }
        let text = String::from_utf8(bytes).map_err(|e| FabricError {
            file: file.clone(),
            field: String::new(),
            problem: format!("the fabric file is not UTF-8 text: {e}"),
            fix: "save it as UTF-8 JSON (see docs/fabric-format.md)".into(),
        })?;
        Fabric::from_json_str(&text, &file)
    }

    /// Parses and validates a fabric description; `file` names the source in error messages.
    pub fn from_json_str(text: &str, file: &str) -> Result<Fabric, FabricError> {
        let cx = Ctx { file };
        let de = &mut serde_json::Deserializer::from_str(text);
        let raw: FabricFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let fix = if inner.to_string().contains("unknown field") {
                "remove or rename the field (see docs/fabric-format.md)"
            } else if inner.to_string().contains("missing field") {
                "add the field (see docs/fabric-format.md)"
            } else {
                "fix the JSON syntax or the value's type"
            };
            let path = if path == "." || path == "?" {
                String::new()
            } else {
                path
            };
            cx.err(path, inner.to_string(), fix)
        })?;
        Fabric::from_raw(raw, &cx)
    }

    fn from_raw(raw: FabricFile, cx: &Ctx) -> Result<Fabric, FabricError> {
        let _ = raw.description;
        if raw.pattern.is_empty() || raw.pattern[0].is_empty() {
            return Err(cx.err(
                "pattern",
                "is empty",
                "give at least one row with at least one 0/1 cell",
            ));
        }
        let cols = raw.pattern[0].len();
        let mut rows = Vec::with_capacity(raw.pattern.len());
        for (r, row) in raw.pattern.iter().enumerate() {
            if row.len() != cols {
                return Err(cx.err(
                    format!("pattern[{r}]"),
                    format!(
                        "has {} cells but row 0 has {cols}: the pattern is not rectangular",
                        row.len()
                    ),
                    "give every row the same number of cells (one per warp thread)",
                ));
            }
            let mut out = Vec::with_capacity(cols);
            for (c, v) in row.iter().enumerate() {
                match v.as_u64() {
                    Some(0) => out.push(false),
                    Some(1) => out.push(true),
                    _ => return Err(cx.err(
                        format!("pattern[{r}][{c}]"),
                        format!("is {v}, not 0 or 1"),
                        "write 1 where the warp passes over the weft, 0 where the weft is on top",
                    )),
                }
            }
            rows.push(out);
        }
        let weave = Weave::new(rows).expect("checked rectangular and non-empty");
        let warp = group(cx, "warp", &raw.warp, weave.n_warp())?;
        let weft = group(cx, "weft", &raw.weft, weave.n_weft())?;
        let fabric = Fabric {
            name: raw.name.unwrap_or_else(|| "fabric".into()),
            weave,
            warp,
            weft,
        };
        fabric.check_segment_lengths(cx)?;
        Ok(fabric)
    }

    /// The fabric as a fabric file (canonical JSON, every field explicit): reading it back gives
    /// an equal `Fabric`. Baked tables store it, so a table is reproducible from itself.
    pub fn to_json(&self) -> Value {
        let group = |g: &YarnGroup| {
            let col =
                |f: fn(&Yarn) -> f64| Value::from(g.threads.iter().map(f).collect::<Vec<f64>>());
            let mut v = serde_json::json!({
                "radius": col(|y| y.radius),
                "height": col(|y| y.height),
                "spacing": col(|y| y.spacing),
                "material": {
                    "albedo": g.material.albedo,
                    "specular": g.material.specular,
                    "exponent": g.material.exponent,
                },
            });
            if g.threads.iter().all(|y| y.segment_length.is_some()) {
                v["segment_length"] = col(|y| y.segment_length.unwrap_or(0.0));
            }
            if g.threads.iter().any(|y| y.albedo.is_some()) {
                let per: Vec<[f64; 3]> = (0..g.threads.len()).map(|t| g.albedo(t)).collect();
                v["thread_albedo"] = serde_json::json!(per);
            }
            v
        };
        serde_json::json!({
            "name": self.name,
            "pattern": self.weave.to_rows(),
            "warp": group(&self.warp),
            "weft": group(&self.weft),
        })
    }

    /// The yarn group `g`.
    pub fn group(&self, g: Group) -> &YarnGroup {
        match g {
            Group::Warp => &self.warp,
            Group::Weft => &self.weft,
        }
    }

    /// A copy with every facet material replaced (CLI material overrides); per-thread albedos
    /// are dropped, so `m.albedo` holds for every thread.
    pub fn with_material(mut self, m: Material) -> Fabric {
        for g in [&mut self.warp, &mut self.weft] {
            g.material = m;
            g.threads.iter_mut().for_each(|y| y.albedo = None);
        }
        self
    }

    /// The facet material of thread `thread` of group `g`: the group's material with the
    /// thread's own albedo where it has one.
    pub fn thread_material(&self, g: Group, thread: usize) -> Material {
        self.group(g).thread_material(thread)
    }

    fn check_segment_lengths(&self, cx: &Ctx) -> Result<(), FabricError> {
        for g in [Group::Warp, Group::Weft] {
            for (t, yarn) in self.group(g).threads.iter().enumerate() {
                let Some(len) = yarn.segment_length else {
                    continue;
                };
                for fl in self.weave.floats(g, t) {
                    if fl.endless {
                        continue;
                    }
                    let room = crate::geometry::derived_float_extent(self, g, t, fl);
                    let room = room.1 - room.0;
                    if len > room + 1e-9 {
                        return Err(cx.err(
                            format!("{}.segment_length", g.name()),
                            format!(
                                "{len} is longer than the room between the crossing threads ({room:.4}) for the float of {} thread {t} over {} crossing(s)",
                                g.name(), fl.len
                            ),
                            "shorten segment_length or omit it to derive it from the spacing",
                        ));
                    }
                }
            }
        }
        Ok(())
    }
}

fn group(cx: &Ctx, name: &str, g: &GroupFile, n: usize) -> Result<YarnGroup, FabricError> {
    let radius = cx.per_thread(&format!("{name}.radius"), &g.radius, n)?;
    let height = match &g.height {
        Some(v) => cx.per_thread(&format!("{name}.height"), v, n)?,
        None => vec![0.0; n],
    };
    let spacing = cx.per_thread(&format!("{name}.spacing"), &g.spacing, n)?;
    let seg = match &g.segment_length {
        Some(v) => Some(cx.per_thread(&format!("{name}.segment_length"), v, n)?),
        None => None,
    };
    for i in 0..n {
        // Name the element only where the file gave an array for that field.
        let field = |f: &str| {
            let arr = match f {
                "radius" => g.radius.is_array(),
                "height" => g.height.as_ref().is_some_and(Value::is_array),
                "spacing" => g.spacing.is_array(),
                _ => g.segment_length.as_ref().is_some_and(Value::is_array),
            };
            if arr {
                format!("{name}.{f}[{i}]")
            } else {
                format!("{name}.{f}")
            }
        };
        if radius[i] <= 0.0 {
            return Err(cx.err(
                field("radius"),
                format!("is {}, must be > 0", radius[i]),
                "give a positive yarn radius",
            ));
        }
        if height[i].abs() >= radius[i] {
            return Err(cx.err(
                field("height"),
                format!(
                    "is {}, must lie strictly between -radius and +radius ({})",
                    height[i], radius[i]
                ),
                "give the height of the cylinder axis above the floor; 0 is a half cylinder",
            ));
        }
        let next = radius[(i + 1) % n];
        if spacing[i] < radius[i] + next - 1e-12 {
            return Err(cx.err(
                field("spacing"),
                format!(
                    "is {}, smaller than the two radii it separates ({} + {}): neighbouring threads would overlap",
                    spacing[i], radius[i], next
                ),
                format!("make the centre-to-centre spacing at least {}", radius[i] + next),
            ));
        }
        if let Some(s) = &seg {
            if s[i] <= 0.0 {
                return Err(cx.err(
                    field("segment_length"),
                    format!("is {}, must be > 0", s[i]),
                    "give a positive length or omit it",
                ));
            }
        }
    }
    let material = material(cx, name, g.material.as_ref())?;
    let albedo = match &g.thread_albedo {
        Some(list) => {
            let f = format!("{name}.thread_albedo");
            if list.len() != n {
                return Err(cx.err(
                    &f,
                    format!(
                        "has {} values but the period has {n} threads of this group",
                        list.len()
                    ),
                    format!(
                        "give exactly {n} albedos (each one number or [r, g, b]), one per thread"
                    ),
                ));
            }
            let per = list
                .iter()
                .enumerate()
                .map(|(i, v)| cx.albedo(&format!("{f}[{i}]"), v).map(Some))
                .collect::<Result<Vec<_>, _>>()?;
            per
        }
        None => vec![None; n],
    };
    Ok(YarnGroup {
        threads: (0..n)
            .map(|i| Yarn {
                radius: radius[i],
                height: height[i],
                spacing: spacing[i],
                segment_length: seg.as_ref().map(|s| s[i]),
                albedo: albedo[i],
            })
            .collect(),
        material,
    })
}

fn material(cx: &Ctx, name: &str, m: Option<&MaterialFile>) -> Result<Material, FabricError> {
    let mut out = Material::default();
    let Some(m) = m else { return Ok(out) };
    if let Some(a) = &m.albedo {
        out.albedo = cx.albedo(&format!("{name}.material.albedo"), a)?;
    }
    if let Some(s) = m.specular {
        if !(0.0..=1.0).contains(&s) {
            return Err(cx.err(
                format!("{name}.material.specular"),
                format!("is {s}, outside [0, 1]"),
                "give a specular coefficient rho_s between 0 and 1",
            ));
        }
        out.specular = s;
    }
    if let Some(n) = m.exponent {
        if !(n >= 0.0 && n.is_finite()) {
            return Err(cx.err(
                format!("{name}.material.exponent"),
                format!("is {n}, must be >= 0"),
                "give a non-negative specular exponent n (cloth: 6 to 15)",
            ));
        }
        out.exponent = n;
    }
    Ok(out)
}

/// True when `path` names a WIF draft (extension `.wif`, any case).
pub fn is_wif(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("wif"))
}

#[cfg(test)]
mod tests {
    use super::*;

    const OK: &str = r#"{"pattern": [[1,0],[0,1]],
        "warp": {"radius": 1.5, "spacing": 3.1},
        "weft": {"radius": [1.5, 1.2], "spacing": 3.1, "material": {"albedo": [0.5, 0.2, 0.1]}}}"#;

    fn err(s: &str) -> FabricError {
        Fabric::from_json_str(s, "t.json").unwrap_err()
    }

    #[test]
    fn parses_and_defaults() {
        let f = Fabric::from_json_str(OK, "t.json").unwrap();
        assert_eq!(f.weave.n_warp(), 2);
        assert_eq!(f.weft.threads[1].radius, 1.2);
        assert_eq!(f.warp.material, Material::default());
        assert_eq!(f.weft.material.albedo, [0.5, 0.2, 0.1]);
    }

    #[test]
    fn canonical_json_round_trips() {
        let f = Fabric::from_json_str(OK, "t.json").unwrap();
        let back = Fabric::from_json_str(&f.to_json().to_string(), "t.json").unwrap();
        assert_eq!(f.name, back.name);
        assert_eq!(
            f,
            Fabric {
                name: f.name.clone(),
                ..back
            }
        );
    }

    #[test]
    fn errors_name_file_and_field() {
        let e = err(&OK.replace("[[1,0],[0,1]]", "[[1,0],[0]]"));
        assert_eq!(e.field, "pattern[1]");
        assert!(
            e.to_string().starts_with("t.json: field `pattern[1]`"),
            "{e}"
        );
        assert_eq!(err(&OK.replace("[[1,0],[0,1]]", "[]")).field, "pattern");
        assert_eq!(
            err(&OK.replace("[[1,0],[0,1]]", "[[1,2],[0,1]]")).field,
            "pattern[0][1]"
        );
        assert_eq!(err(&OK.replace("[1.5, 1.2]", "[1.5]")).field, "weft.radius");
        assert_eq!(
            err(&OK.replace("[1.5, 1.2]", "[1.5, -1]")).field,
            "weft.radius[1]"
        );
        assert_eq!(
            err(&OK.replace("\"spacing\": 3.1}", "\"spacing\": 2.0}")).field,
            "warp.spacing"
        );
        assert_eq!(
            err(&OK.replace("[0.5, 0.2, 0.1]", "[0.5, 1.2, 0.1]")).field,
            "weft.material.albedo[1]"
        );
        let e = err(&OK.replace("\"albedo\"", "\"exponent\": -1, \"albedo\""));
        assert_eq!(e.field, "weft.material.exponent");
        let e = err(&OK.replace("\"radius\": 1.5,", "\"radius\": 1.5, \"colour\": 1,"));
        assert_eq!(e.field, "warp.colour");
        assert!(e.problem.contains("unknown field `colour`"), "{e}");
        let e = err(&OK.replace("\"radius\": 1.5,", "\"radius\": 1.5, \"height\": 1.5,"));
        assert_eq!(e.field, "warp.height");
        let e = err(&OK.replace(
            "\"radius\": 1.5,",
            "\"radius\": 1.5, \"segment_length\": 9,",
        ));
        assert_eq!(e.field, "warp.segment_length");
        assert!(err("{").problem.contains("EOF"));
    }

    #[test]
    fn thread_albedo_overrides_the_group_and_round_trips() {
        let t = OK.replace(
            r#""weft": {"radius""#,
            r#""weft": {"thread_albedo": [0.2, [0.9, 0.5, 0.1]], "radius""#,
        );
        let f = Fabric::from_json_str(&t, "t.json").unwrap();
        assert_eq!(f.weft.albedo(0), [0.2; 3]);
        assert_eq!(f.weft.albedo(1), [0.9, 0.5, 0.1]);
        // The rest of the material is the group's; the warp has no list and keeps its own.
        assert_eq!(f.thread_material(Group::Weft, 1).specular, DEFAULT_SPECULAR);
        assert_eq!(f.warp.albedo(1), [DEFAULT_ALBEDO; 3]);
        let back = Fabric::from_json_str(&f.to_json().to_string(), "t.json").unwrap();
        assert_eq!(back.weft, f.weft);
        // The material override drops the list.
        let m = Material::default();
        assert_eq!(f.clone().with_material(m).weft.albedo(1), m.albedo);
        let e = err(&t.replace("[0.2, [0.9, 0.5, 0.1]]", "[0.2]"));
        assert_eq!(e.field, "weft.thread_albedo");
        let e = err(&t.replace("[0.9, 0.5, 0.1]", "[0.9, 0.5, 1.5]"));
        assert_eq!(e.field, "weft.thread_albedo[1][2]");
        let e = err(&t.replace("[0.2,", "[-0.2,"));
        assert_eq!(e.field, "weft.thread_albedo[0]");
    }
}
