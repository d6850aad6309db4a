//! Fabric description files (JSON) and their validation into a [`Fabric`].
//!
//! Schema (every length in the same arbitrary unit; see `docs/reference/fabric-format.md`):
//! ```json
//! { "name": "twill", "pattern": [[1,1,0],[0,1,1],[1,0,1]],
//!   "warp": { "radius": 1.5, "height": 0.0, "spacing": 3.1,
//!             "material": { "albedo": [0.4,0.4,0.4], "specular": 0.3, "exponent": 10 } },
//!   "weft": { "radius": 1.5, "spacing": 3.1, "segment_length": 3.2 } }
//! ```
//! `radius`, `height`, `spacing` and `segment_length` take one number for the whole group or
//! an array with one value per thread of the period.

use crate::weave::{Group, Weave};
use crate::yarn::{float_room, spacing_fits};
pub use crate::yarn::{
    Material, Yarn, YarnGroup, DEFAULT_ALBEDO, DEFAULT_EXPONENT, DEFAULT_SPECULAR,
};
use serde::Deserialize;
use serde_json::Value;
use std::fmt;

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

/// Smallest length (radius, spacing, segment length) a fabric may give, in its own unit.
pub const MIN_LENGTH: f64 = 1e-9;
/// Largest length a fabric may give, in its own unit.
pub const MAX_LENGTH: f64 = 1e9;

/// Most threads of one group in a period (pattern columns or rows).
pub const MAX_THREADS: usize = 1 << 16;
/// Most cells of a period (columns x rows): preprocessing and memory grow in proportion (a
/// random 1024 x 1024 period takes about 10 s and 100 MB to preprocess; docs/reference/limits.md).
pub const MAX_CELLS: usize = 1 << 20;

/// A validated fabric: weave period, both yarn groups. Every invariant the model relies on holds:
/// the fields are private and [`Fabric::new`] is the one constructor (fabric files, WIF drafts,
/// Python dicts and material overrides all go through it).
#[derive(Clone, Debug, PartialEq)]
pub struct Fabric {
    name: String,
    weave: Weave,
    warp: YarnGroup,
    weft: YarnGroup,
    notes: Vec<String>,
}

/// A field of a fabric that [`Fabric::new`] checks, for naming it in errors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// The weave period as a whole (its size).
    Pattern,
    /// A thread's `radius`.
    Radius,
    /// A thread's `height`.
    Height,
    /// A thread's `spacing`.
    Spacing,
    /// A thread's `segment_length`.
    SegmentLength,
    /// A thread's own albedo (`thread_albedo`), with its channel.
    ThreadAlbedo(usize),
    /// The group material's albedo, with its channel.
    Albedo(usize),
    /// The group material's specular coefficient.
    Specular,
    /// The group material's specular exponent.
    Exponent,
    /// The group material's translucency.
    Translucency,
}

/// How a source names the fields of its fabric in error messages (each format its own way).
pub trait Naming {
    /// The file (or `<inline>`).
    fn file(&self) -> &str;
    /// The name of `field` of group `g`, thread `thread` where the field is per thread.
    fn field(&self, g: Group, field: Field, thread: usize) -> String;
}

/// Names fields as the fabric file format does, with every per-thread field indexed
/// (`warp.radius[2]`, `weft.material.albedo[0]`): for fabrics built in code.
pub struct PlainNaming<'a>(pub &'a str);

impl Naming for PlainNaming<'_> {
    fn file(&self) -> &str {
        self.0
    }
    fn field(&self, g: Group, field: Field, thread: usize) -> String {
        let g = g.name();
        match field {
            Field::Pattern => "pattern".into(),
            Field::Radius => format!("{g}.radius[{thread}]"),
            Field::Height => format!("{g}.height[{thread}]"),
            Field::Spacing => format!("{g}.spacing[{thread}]"),
            Field::SegmentLength => format!("{g}.segment_length[{thread}]"),
            Field::ThreadAlbedo(k) => format!("{g}.thread_albedo[{thread}][{k}]"),
            Field::Albedo(k) => format!("{g}.material.albedo[{k}]"),
            Field::Specular => format!("{g}.material.specular"),
            Field::Exponent => format!("{g}.material.exponent"),
            Field::Translucency => format!("{g}.material.translucency"),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FabricFile {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    notes: Vec<String>,
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
    #[serde(default)]
    translucency: Option<f64>,
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

    /// A diffuse albedo: one number (grey) or `[r, g, b]` (the range is checked by [`Fabric::new`]).
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
    /// The one constructor: checks every invariant the model relies on and names the offending
    /// field through `naming`. Checked: a period of at most [`MAX_THREADS`] threads per group
    /// and [`MAX_CELLS`] cells; one thread per pattern column (warp) and row (weft);
    /// finite numbers; radius > 0; |height| < radius; neighbours that touch but do not overlap
    /// ([`crate::yarn::spacing_fits`]); segment lengths > 0 that fit their room
    /// ([`crate::yarn::float_room`]); albedos and rho_s in [0, 1]; exponent >= 0.
    pub fn new(
        name: String,
        weave: Weave,
        warp: YarnGroup,
        weft: YarnGroup,
        naming: &dyn Naming,
    ) -> Result<Fabric, FabricError> {
        check_period(weave.n_warp(), weave.n_weft()).map_err(|e| FabricError {
            file: naming.file().to_string(),
            field: naming.field(Group::Warp, Field::Pattern, 0),
            problem: e.to_string(),
            fix: e.fix(),
        })?;
        let fabric = Fabric {
            name,
            weave,
            warp,
            weft,
            notes: Vec::new(),
        };
        for g in [Group::Warp, Group::Weft] {
            fabric.check_group(g, naming)?;
        }
        for g in [Group::Warp, Group::Weft] {
            fabric.check_segment_lengths(g, naming)?;
        }
        Ok(fabric)
    }

    /// Parses and validates a fabric description; `file` names the source in error messages.
    pub fn from_json_str(text: &str, file: &str) -> Result<Fabric, FabricError> {
        let cx = Ctx { file };
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        // The top level must be an object: say so, rather than what serde makes of a sequence.
        let found = match text.trim_start().chars().next() {
            None => Some("is empty"),
            Some('{') => None,
            Some('[') => Some("is a JSON array"),
            Some('"') => Some("is a JSON string"),
            Some(_) => Some("does not start with a JSON object"),
        };
        if let Some(what) = found {
            return Err(cx.err(
                "",
                format!("the fabric file {what}; expected an object {{\"pattern\": ..., \"warp\": ..., \"weft\": ...}}"),
                "give a fabric file (docs/reference/fabric-format.md), e.g. tables/twill.json",
            ));
        }
        let de = &mut serde_json::Deserializer::from_str(text);
        let raw: FabricFile = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let fix = if inner.to_string().contains("unknown field") {
                "remove or rename the field (see docs/reference/fabric-format.md)"
            } else if inner.to_string().contains("missing field") {
                "add the field (see docs/reference/fabric-format.md)"
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

    fn from_raw(raw: FabricFile, cx: &Ctx<'_>) -> Result<Fabric, FabricError> {
        let _ = &raw.description;
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
        // Names and notes are shown on terminals (eval, info): no control characters (an
        // escape sequence such as \u001b would reach the terminal raw), as in WIF drafts.
        let texts = raw.name.iter().map(|n| ("name".to_string(), n)).chain(
            raw.notes
                .iter()
                .enumerate()
                .map(|(k, n)| (format!("notes[{k}]"), n)),
        );
        for (field, text) in texts {
            if let Some(c) = text.chars().find(|c| c.is_control()) {
                return Err(cx.err(
                    field,
                    format!("holds the control character U+{:04X}", u32::from(c)),
                    "remove it: names and notes are one line of printable text",
                ));
            }
        }
        let naming = JsonNaming {
            file: cx.file,
            warp: &raw.warp,
            weft: &raw.weft,
        };
        Ok(Fabric::new(
            raw.name.clone().unwrap_or_else(|| "fabric".into()),
            weave,
            warp,
            weft,
            &naming,
        )?
        .with_notes(raw.notes.clone()))
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
            // Written only when set, so that the tables of opaque yarns keep their headers.
            if g.material.translucency > 0.0 {
                v["material"]["translucency"] = g.material.translucency.into();
            }
            if g.threads.iter().all(|y| y.segment_length.is_some()) {
                v["segment_length"] = col(|y| y.segment_length.unwrap_or(0.0));
            }
            if g.threads.iter().any(|y| y.albedo.is_some()) {
                let per: Vec<[f64; 3]> = (0..g.threads.len()).map(|t| g.albedo(t)).collect();
                v["thread_albedo"] = serde_json::json!(per);
            }
            v
        };
        let mut v = serde_json::json!({
            "name": self.name,
            "pattern": self.weave.to_rows(),
            "warp": group(&self.warp),
            "weft": group(&self.weft),
        });
        if !self.notes.is_empty() {
            v["notes"] = serde_json::json!(self.notes);
        }
        v
    }

    /// What a source did to its description to make this fabric (a WIF draft's yarns capped
    /// where they pack, [`crate::wif`]), one line each, for reports; kept in [`Fabric::to_json`].
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The fabric with `notes` ([`Fabric::notes`]) in place of its own.
    pub fn with_notes(self, notes: Vec<String>) -> Fabric {
        Fabric { notes, ..self }
    }

    /// Display name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The weave period.
    pub fn weave(&self) -> &Weave {
        &self.weave
    }

    /// Warp yarns (pattern columns, running along +Y).
    pub fn warp(&self) -> &YarnGroup {
        &self.warp
    }

    /// Weft yarns (pattern rows, running along +X).
    pub fn weft(&self) -> &YarnGroup {
        &self.weft
    }

    /// The yarn group `g`.
    pub fn group(&self, g: Group) -> &YarnGroup {
        match g {
            Group::Warp => &self.warp,
            Group::Weft => &self.weft,
        }
    }

    /// A copy with each yarn group changed by `edit`, checked again by [`Fabric::new`] (errors
    /// named by `naming`).
    pub fn with_groups(
        &self,
        mut edit: impl FnMut(Group, &mut YarnGroup),
        naming: &dyn Naming,
    ) -> Result<Fabric, FabricError> {
        let (mut warp, mut weft) = (self.warp.clone(), self.weft.clone());
        edit(Group::Warp, &mut warp);
        edit(Group::Weft, &mut weft);
        Ok(
            Fabric::new(self.name.clone(), self.weave.clone(), warp, weft, naming)?
                .with_notes(self.notes.clone()),
        )
    }

    /// A copy with every facet material replaced (CLI material overrides), checked by
    /// [`Fabric::new`]; per-thread albedos are dropped, so `m.albedo` holds for every thread.
    pub fn with_material(&self, m: Material) -> Result<Fabric, FabricError> {
        self.with_groups(
            |_, g| {
                g.material = m;
                g.threads.iter_mut().for_each(|y| y.albedo = None);
            },
            &PlainNaming("the material options"),
        )
    }

    /// The fabric's back seen from below, as a fabric of its own: the weave inverted
    /// ([`Weave::inverted`]), the same threads (the two-faced cloth mirrors the back's floats
    /// below z = 0, so from below their axes stand at the threads' heights;
    /// docs/science/transmission.md). An error where the inverted weave's floats do not fit the
    /// threads' given segment lengths.
    pub fn back(&self) -> Result<Fabric, FabricError> {
        Fabric::new(
            format!("{} (back)", self.name),
            self.weave.inverted(),
            self.warp.clone(),
            self.weft.clone(),
            &PlainNaming("the fabric's back (its weave inverted; docs/science/transmission.md)"),
        )
        .map(|f| f.with_notes(self.notes.clone()))
    }

    /// The facet material of thread `thread` of group `g`: the group's material with the
    /// thread's own albedo where it has one.
    pub fn thread_material(&self, g: Group, thread: usize) -> Material {
        self.group(g).thread_material(thread)
    }

    fn check_group(&self, g: Group, naming: &dyn Naming) -> Result<(), FabricError> {
        let group = self.group(g);
        let threads = &group.threads;
        let n = self.weave.n(g);
        let err = |field: String, problem: String, fix: &str| FabricError {
            file: naming.file().to_string(),
            field,
            problem,
            fix: fix.to_string(),
        };
        if threads.len() != n {
            return Err(err(
                g.name().to_string(),
                format!(
                    "has {} threads but the pattern has {n} {}",
                    threads.len(),
                    if g == Group::Warp { "columns" } else { "rows" }
                ),
                "give one thread per pattern column (warp) or row (weft)",
            ));
        }
        let finite = |x: f64, f: Field, i: usize| {
            if x.is_finite() {
                Ok(())
            } else {
                Err(err(
                    naming.field(g, f, i),
                    format!("is {x}, not a finite number"),
                    "give a finite decimal number",
                ))
            }
        };
        // Only ratios of lengths matter, but squares and products of lengths must stay normal
        // f64 numbers: lengths outside [MIN_LENGTH, MAX_LENGTH] are refused, not computed wrong.
        let in_range = |x: f64, f: Field, i: usize| {
            if x > 0.0 && !(MIN_LENGTH..=MAX_LENGTH).contains(&x) {
                Err(err(
                    naming.field(g, f, i),
                    format!("is {x:e}, outside the lengths clothbake computes with ({MIN_LENGTH:e} to {MAX_LENGTH:e})"),
                    "give every length in one unit between 1e-9 and 1e9 (only their ratios matter: e.g. millimetres)",
                ))
            } else {
                Ok(())
            }
        };
        for (i, y) in threads.iter().enumerate() {
            finite(y.radius, Field::Radius, i)?;
            finite(y.height, Field::Height, i)?;
            finite(y.spacing, Field::Spacing, i)?;
            in_range(y.radius, Field::Radius, i)?;
            in_range(y.spacing, Field::Spacing, i)?;
            if let Some(s) = y.segment_length {
                in_range(s, Field::SegmentLength, i)?;
            }
            if y.radius <= 0.0 {
                return Err(err(
                    naming.field(g, Field::Radius, i),
                    format!("is {}, must be > 0", y.radius),
                    "give a positive yarn radius",
                ));
            }
            if y.height.abs() >= y.radius {
                return Err(err(
                    naming.field(g, Field::Height, i),
                    format!(
                        "is {}, must lie strictly between -radius and +radius ({})",
                        y.height, y.radius
                    ),
                    "give the height of the cylinder axis above the floor; 0 is a half cylinder",
                ));
            }
            let next = threads[(i + 1) % n].radius;
            if !spacing_fits(y.spacing, y.radius, next) {
                return Err(err(
                    naming.field(g, Field::Spacing, i),
                    format!(
                        "is {}, smaller than the two radii it separates ({} + {}): neighbouring threads would overlap",
                        y.spacing, y.radius, next
                    ),
                    &format!("make the centre-to-centre spacing at least {}", y.radius + next),
                ));
            }
            if let Some(s) = y.segment_length {
                finite(s, Field::SegmentLength, i)?;
                if s <= 0.0 {
                    return Err(err(
                        naming.field(g, Field::SegmentLength, i),
                        format!("is {s}, must be > 0"),
                        "give a positive length or omit it",
                    ));
                }
            }
            if let Some(a) = y.albedo {
                for (k, c) in a.iter().enumerate() {
                    if !(0.0..=1.0).contains(c) {
                        return Err(err(
                            naming.field(g, Field::ThreadAlbedo(k), i),
                            format!("is {c}, outside [0, 1]"),
                            "give a diffuse albedo between 0 and 1",
                        ));
                    }
                }
            }
        }
        let m = &group.material;
        for (k, c) in m.albedo.iter().enumerate() {
            if !(0.0..=1.0).contains(c) {
                return Err(err(
                    naming.field(g, Field::Albedo(k), 0),
                    format!("is {c}, outside [0, 1]"),
                    "give a diffuse albedo between 0 and 1",
                ));
            }
        }
        if !(0.0..=1.0).contains(&m.specular) {
            return Err(err(
                naming.field(g, Field::Specular, 0),
                format!("is {}, outside [0, 1]", m.specular),
                "give a specular coefficient rho_s between 0 and 1",
            ));
        }
        if !(m.exponent >= 0.0 && m.exponent.is_finite()) {
            return Err(err(
                naming.field(g, Field::Exponent, 0),
                format!("is {}, must be >= 0", m.exponent),
                "give a non-negative specular exponent n (cloth: 6 to 15)",
            ));
        }
        if !(0.0..=1.0).contains(&m.translucency) {
            return Err(err(
                naming.field(g, Field::Translucency, 0),
                format!("is {}, outside [0, 1]", m.translucency),
                "give a translucency between 0 (opaque yarn) and 1",
            ));
        }
        // What a translucent facet reflects and transmits: rho_d (1 + tau) + rho_s <= 1.
        if m.translucency > 0.0 {
            let darkest_fit = (1.0 - m.specular) / (1.0 + m.translucency);
            let brightest = (0..threads.len())
                .map(|t| group.albedo(t))
                .chain([m.albedo])
                .flatten()
                .fold(0.0f64, f64::max);
            if brightest > darkest_fit + 1e-12 {
                return Err(err(
                    naming.field(g, Field::Translucency, 0),
                    format!(
                        "is {} with an albedo up to {brightest} and specular {}: the yarn would \
                         give back more light than it gets (rho_d (1 + tau) + rho_s = {:.3} > 1)",
                        m.translucency,
                        m.specular,
                        brightest * (1.0 + m.translucency) + m.specular
                    ),
                    &format!(
                        "lower the translucency to at most {:.3}, or the albedo to at most {:.3}",
                        ((1.0 - m.specular) / brightest - 1.0).max(0.0),
                        darkest_fit
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check_segment_lengths(&self, g: Group, naming: &dyn Naming) -> Result<(), FabricError> {
        let (pos, period) = self.group(g.other()).positions();
        for (t, yarn) in self.group(g).threads.iter().enumerate() {
            let Some(len) = yarn.segment_length else {
                continue;
            };
            for fl in self.weave.floats(g, t) {
                if fl.endless {
                    continue;
                }
                let room = float_room(self.group(g.other()), &pos, period, fl);
                let room = room.1 - room.0;
                if len > room + 1e-9 {
                    return Err(FabricError {
                        file: naming.file().to_string(),
                        field: naming.field(g, Field::SegmentLength, t),
                        problem: format!(
                            "{len} is longer than the room between the crossing threads ({room:.4}) for the float of {} thread {t} over {} crossing(s)",
                            g.name(), fl.len
                        ),
                        fix: "shorten segment_length or omit it to derive it from the spacing"
                            .into(),
                    });
                }
            }
        }
        Ok(())
    }
}

/// A period larger than clothbake takes ([`check_period`]): the message says what, [`fix`]
/// what to do.
///
/// [`fix`]: PeriodTooLarge::fix
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PeriodTooLarge {
    /// More than [`MAX_THREADS`] threads of one group.
    Threads {
        /// The group with too many.
        group: Group,
        /// Its threads.
        count: usize,
    },
    /// More than [`MAX_CELLS`] crossings.
    Cells {
        /// Warp threads (columns).
        columns: usize,
        /// Weft threads (rows).
        rows: usize,
    },
}

impl fmt::Display for PeriodTooLarge {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            PeriodTooLarge::Threads { group, count } => {
                let what = match group {
                    Group::Warp => "warp threads (columns)",
                    Group::Weft => "weft threads (rows)",
                };
                write!(
                    f,
                    "the period has {count} {what}, more than the {MAX_THREADS} clothbake takes"
                )
            }
            PeriodTooLarge::Cells { columns, rows } => write!(
                f,
                "the period has {columns} x {rows} = {} cells, more than the {MAX_CELLS} clothbake \
                 takes",
                columns * rows
            ),
        }
    }
}

impl std::error::Error for PeriodTooLarge {}

impl PeriodTooLarge {
    /// What to do instead.
    pub fn fix(&self) -> String {
        format!(
            "give one repeat of the weave, at most {MAX_THREADS} threads per group and {MAX_CELLS} \
             cells (docs/reference/limits.md)"
        )
    }
}

/// Whether a period of `columns` warp threads by `rows` weft threads is within [`MAX_THREADS`]
/// and [`MAX_CELLS`].
pub fn check_period(columns: usize, rows: usize) -> Result<(), PeriodTooLarge> {
    if columns > MAX_THREADS {
        return Err(PeriodTooLarge::Threads {
            group: Group::Warp,
            count: columns,
        });
    }
    if rows > MAX_THREADS {
        return Err(PeriodTooLarge::Threads {
            group: Group::Weft,
            count: rows,
        });
    }
    if columns * rows > MAX_CELLS {
        return Err(PeriodTooLarge::Cells { columns, rows });
    }
    Ok(())
}

/// Names fields as the file gave them: an index only where the file gave an array.
struct JsonNaming<'a> {
    file: &'a str,
    warp: &'a GroupFile,
    weft: &'a GroupFile,
}

impl Naming for JsonNaming<'_> {
    fn file(&self) -> &str {
        self.file
    }

    fn field(&self, g: Group, field: Field, thread: usize) -> String {
        let raw = match g {
            Group::Warp => self.warp,
            Group::Weft => self.weft,
        };
        let name = g.name();
        if field == Field::Pattern {
            return "pattern".into();
        }
        let indexed = |f: &str, v: Option<&Value>| {
            if v.is_some_and(Value::is_array) {
                format!("{name}.{f}[{thread}]")
            } else {
                format!("{name}.{f}")
            }
        };
        match field {
            Field::Radius => indexed("radius", Some(&raw.radius)),
            Field::Height => indexed("height", raw.height.as_ref()),
            Field::Spacing => indexed("spacing", Some(&raw.spacing)),
            Field::SegmentLength => indexed("segment_length", raw.segment_length.as_ref()),
            Field::ThreadAlbedo(k) => {
                let entry = raw.thread_albedo.as_ref().and_then(|l| l.get(thread));
                let base = format!("{name}.thread_albedo[{thread}]");
                if entry.is_some_and(Value::is_array) {
                    format!("{base}[{k}]")
                } else {
                    base
                }
            }
            Field::Albedo(k) => {
                let v = raw.material.as_ref().and_then(|m| m.albedo.as_ref());
                if v.is_some_and(Value::is_array) {
                    format!("{name}.material.albedo[{k}]")
                } else {
                    format!("{name}.material.albedo")
                }
            }
            Field::Specular => format!("{name}.material.specular"),
            Field::Exponent => format!("{name}.material.exponent"),
            Field::Translucency => format!("{name}.material.translucency"),
            Field::Pattern => unreachable!("named above"),
        }
    }
}

/// Parses one group's fields (numbers and shapes); ranges are checked by [`Fabric::new`].
fn group(cx: &Ctx<'_>, name: &str, g: &GroupFile, n: usize) -> Result<YarnGroup, FabricError> {
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
            list.iter()
                .enumerate()
                .map(|(i, v)| cx.albedo(&format!("{f}[{i}]"), v).map(Some))
                .collect::<Result<Vec<_>, _>>()?
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

/// Parses a group's material; unset values keep the thesis's defaults.
fn material(cx: &Ctx<'_>, name: &str, m: Option<&MaterialFile>) -> Result<Material, FabricError> {
    let mut out = Material::default();
    let Some(m) = m else { return Ok(out) };
    if let Some(a) = &m.albedo {
        out.albedo = cx.albedo(&format!("{name}.material.albedo"), a)?;
    }
    if let Some(s) = m.specular {
        out.specular = s;
    }
    if let Some(n) = m.exponent {
        out.exponent = n;
    }
    if let Some(t) = m.translucency {
        out.translucency = t;
    }
    Ok(out)
}

/// The thesis's 2/1 twill (Fig. 4.7: radius 1.5, spacing 3.1, the default finish): the fabric
/// the unit tests of the model and the truth start from.
pub fn thesis_twill() -> Fabric {
    Fabric::from_json_str(
        r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]],
            "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#,
        "t",
    )
    .unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn periods_beyond_the_limits_are_refused() {
        assert!(check_period(1024, 1024).is_ok());
        assert!(check_period(MAX_THREADS, 16).is_ok());
        let e = check_period(MAX_THREADS + 1, 1).unwrap_err();
        assert_eq!(
            e,
            PeriodTooLarge::Threads {
                group: Group::Warp,
                count: MAX_THREADS + 1
            }
        );
        assert!(e.to_string().contains("65537 warp threads"), "{e}");
        assert!(e.fix().contains("docs/reference/limits.md"), "{}", e.fix());
        let e = check_period(16, MAX_THREADS + 1).unwrap_err();
        assert!(e.to_string().contains("65537 weft threads (rows)"), "{e}");
        let e = check_period(1025, 1024).unwrap_err();
        assert!(
            e.to_string()
                .contains(&format!("1049600 cells, more than the {MAX_CELLS}")),
            "{e}"
        );
        // The one constructor refuses such a period, naming the field, before any work on it.
        let rows = vec![vec![true, false]; MAX_CELLS / 2 + 1];
        let e = Fabric::from_json_str(
            &format!(
                r#"{{"pattern": {:?}, "warp": {{"radius": 1, "spacing": 2}}, "weft": {{"radius": 1, "spacing": 2}}}}"#,
                rows.iter().map(|r| r.iter().map(|&b| b as u8).collect::<Vec<_>>()).collect::<Vec<_>>()
            ),
            "big.json",
        )
        .unwrap_err();
        assert_eq!(e.field, "pattern");
        assert!(e.problem.contains("weft threads (rows)"), "{e}");
    }

    const OK: &str = r#"{"pattern": [[1,0],[0,1]],
        "warp": {"radius": 1.5, "spacing": 3.1},
        "weft": {"radius": [1.5, 1.2], "spacing": 3.1, "material": {"albedo": [0.5, 0.2, 0.1]}}}"#;

    fn err(s: &str) -> FabricError {
        Fabric::from_json_str(s, "t.json").unwrap_err()
    }

    #[test]
    fn parses_and_defaults() {
        let f = Fabric::from_json_str(OK, "t.json").unwrap();
        assert_eq!(f.weave().n_warp(), 2);
        assert_eq!(f.weft().threads[1].radius, 1.2);
        assert_eq!(f.warp().material, Material::default());
        assert_eq!(f.weft().material.albedo, [0.5, 0.2, 0.1]);
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
        // Translucent yarn may not give back more than it gets: weft albedo 0.5 and the
        // default specular 0.3 allow tau up to 0.4.
        let ok = OK.replace("\"albedo\"", "\"translucency\": 0.4, \"albedo\"");
        assert_eq!(
            Fabric::from_json_str(&ok, "t.json")
                .unwrap()
                .weft()
                .material
                .translucency,
            0.4
        );
        let e = err(&OK.replace("\"albedo\"", "\"translucency\": 0.5, \"albedo\""));
        assert_eq!(e.field, "weft.material.translucency");
        assert!(
            e.problem.contains("rho_d (1 + tau) + rho_s = 1.050 > 1"),
            "{e}"
        );
        assert!(e.fix.contains("at most 0.400"), "{e}");
        let e = err(&OK.replace("\"albedo\"", "\"translucency\": 1.5, \"albedo\""));
        assert!(e.problem.contains("outside [0, 1]"), "{e}");
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
    fn lengths_beyond_what_f64_squares_hold_are_refused_with_the_range() {
        // Radius 1e300 would overflow r^2 (NaN values), 1e-300 underflow it (all zeros).
        for (from, to) in [("1.5, 1.2", "1e300, 1.2"), ("1.5, 1.2", "1e-300, 1.2")] {
            let e = err(&OK.replace(from, to));
            assert_eq!(e.field, "weft.radius[0]", "{e}");
            assert!(e.problem.contains("1e-9 to 1e9"), "{e}");
        }
        let e = err(&OK.replace("\"spacing\": 3.1}", "\"spacing\": 3.1e300}"));
        assert_eq!(e.field, "warp.spacing", "{e}");
        // The same fabric scaled by 1e6 is accepted: the bound is not a unit.
        let big = OK
            .replace("1.5", "1.5e6")
            .replace("1.2", "1.2e6")
            .replace("3.1", "3.1e6");
        assert!(Fabric::from_json_str(&big, "t.json").is_ok());
    }

    #[test]
    fn thread_albedo_overrides_the_group_and_round_trips() {
        let t = OK.replace(
            r#""weft": {"radius""#,
            r#""weft": {"thread_albedo": [0.2, [0.9, 0.5, 0.1]], "radius""#,
        );
        let f = Fabric::from_json_str(&t, "t.json").unwrap();
        assert_eq!(f.weft().albedo(0), [0.2; 3]);
        assert_eq!(f.weft().albedo(1), [0.9, 0.5, 0.1]);
        // The rest of the material is the group's; the warp has no list and keeps its own.
        assert_eq!(f.thread_material(Group::Weft, 1).specular, DEFAULT_SPECULAR);
        assert_eq!(f.warp().albedo(1), [DEFAULT_ALBEDO; 3]);
        let back = Fabric::from_json_str(&f.to_json().to_string(), "t.json").unwrap();
        assert_eq!(back.weft(), f.weft());
        // The material override drops the list.
        let m = Material::default();
        assert_eq!(f.with_material(m).unwrap().weft.albedo(1), m.albedo);
        let e = err(&t.replace("[0.2, [0.9, 0.5, 0.1]]", "[0.2]"));
        assert_eq!(e.field, "weft.thread_albedo");
        let e = err(&t.replace("[0.9, 0.5, 0.1]", "[0.9, 0.5, 1.5]"));
        assert_eq!(e.field, "weft.thread_albedo[1][2]");
        let e = err(&t.replace("[0.2,", "[-0.2,"));
        assert_eq!(e.field, "weft.thread_albedo[0]");
    }
}
