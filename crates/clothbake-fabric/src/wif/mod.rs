//! Weaving drafts in WIF (Weaving Information File, version 1.1) read into a [`Fabric`].
//!
//! A WIF is an INI-like text file: `[SECTION]` headers, `key=value` lines, `;` comment lines,
//! names case-insensitive. What is read (the full account is `docs/reference/wif.md`):
//!
//! * **Pattern.** Warp end e (1-based) is on the shafts of `[THREADING] e=`; pick p lifts the
//!   shafts of `[LIFTPLAN] p=`, or, without a liftplan, the union of the `[TIEUP]` shafts of the
//!   treadles of `[TREADLING] p=`. The end is *raised* at pick p when one of its shafts is among
//!   them. With `[WEAVING] Rising Shed=true` (the default) a raised end lies over the weft on
//!   the face; with `Rising Shed=false` the listed shafts sink, so a raised end lies under it.
//!   The face is the +Z side of clothbake's point paper: **column i = end i + 1, row j =
//!   pick j + 1**, a cell 1 where the warp is over.
//! * **Period.** The drawdown of all ends by all picks is taken as one repeat of the cloth and
//!   reduced to its smallest repeat in each direction that also repeats the threads' colours,
//!   spacings and thicknesses.
//! * **Colours.** `[COLOR TABLE]` entries `i=r,g,b` in the `[COLOR PALETTE]` range `lo,hi`
//!   (default 0,255), chosen per thread by `[WARP COLORS]` / `[WEFT COLORS]` or for a whole group
//!   by `[WARP] Color=`, become diffuse albedos: c = (v - lo) / (hi - lo), decoded from the sRGB
//!   transfer curve to linear ([`srgb_to_linear`]).
//! * **Sizes.** `[WARP]` / `[WEFT]` `Spacing=` and `Thickness=` (per thread: `[WARP SPACING]`,
//!   `[WARP THICKNESS]`, ...) in `Units=` (decipoints, inches or centimeters) become spacings and
//!   radii (thickness / 2) in millimetres; WIF gives each thread the width `Spacing`, so the
//!   centre-to-centre distance of threads i and i+1 is (s_i + s_{i+1}) / 2. Missing sizes come
//!   from [`WifOptions`] or the defaults of [`resolve_sizes`].

use crate::fabric::{check_period, Fabric, FabricError, Field, Naming, PlainNaming, MAX_THREADS};
use crate::weave::Group;
use crate::weave::Weave;
use crate::yarn::{packed_radii, Material, Yarn, YarnGroup};
use std::fmt;

/// Default spacing (mm) of a group when neither the draft nor the options give any size: the
/// thesis's samples' spacing-to-diameter ratio 3.1 : 3.0.
pub const DEFAULT_SPACING_MM: f64 = 0.31;
/// Default thickness (mm, the yarn diameter) paired with [`DEFAULT_SPACING_MM`].
pub const DEFAULT_THICKNESS_MM: f64 = 0.30;

/// Millimetres per WIF length unit (decipoint = 1/720 inch).
fn unit_mm(units: &str) -> Option<f64> {
    match units.trim().to_ascii_lowercase().as_str() {
        "decipoints" | "decipoint" => Some(25.4 / 720.0),
        "inches" | "inch" => Some(25.4),
        "centimeters" | "centimeter" | "centimetres" | "centimetre" => Some(10.0),
        _ => None,
    }
}

/// A bad draft: the file, the section and line, what is wrong and how to fix it.
#[derive(Clone, Debug, PartialEq)]
pub struct WifError {
    /// The file.
    pub file: String,
    /// The section, upper case without brackets (empty: the file as a whole).
    pub section: String,
    /// 1-based line number, where one line is at fault.
    pub line: Option<usize>,
    /// What is wrong.
    pub problem: String,
    /// How to fix it.
    pub fix: String,
}

impl WifError {
    /// Where: `[SECTION] line N`, `[SECTION]`, `line N` or nothing.
    pub fn location(&self) -> String {
        match (self.section.is_empty(), self.line) {
            (false, Some(l)) => format!("[{}] line {l}", self.section),
            (false, None) => format!("[{}]", self.section),
            (true, Some(l)) => format!("line {l}"),
            (true, None) => String::new(),
        }
    }
}

impl fmt::Display for WifError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let loc = self.location();
        if loc.is_empty() {
            write!(f, "{}: {}; {}", self.file, self.problem, self.fix)
        } else {
            write!(f, "{}: {loc}: {}; {}", self.file, self.problem, self.fix)
        }
    }
}
impl std::error::Error for WifError {}

impl From<WifError> for FabricError {
    fn from(e: WifError) -> FabricError {
        let loc = e.location();
        FabricError {
            file: e.file,
            field: String::new(),
            problem: if loc.is_empty() {
                e.problem
            } else {
                format!("{loc}: {}", e.problem)
            },
            fix: e.fix,
        }
    }
}

/// Sizes for a draft that does not give them (the command line's `--radius`, `--spacing`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WifOptions {
    /// Yarn radius in mm for a group whose draft gives no `Thickness`.
    pub radius: Option<f64>,
    /// Spacing in mm for a group whose draft gives no `Spacing`.
    pub spacing: Option<f64>,
}

/// Decodes an sRGB-encoded value in [0, 1] to linear light (IEC 61966-2-1).
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

struct Entry {
    key: String,
    value: String,
    line: usize,
}

impl Entry {
    /// `key=value` as messages quote it ([`clip`]ped).
    fn shown(&self) -> String {
        clip(&format!("{}={}", self.key, self.value)).into_owned()
    }
}

/// Text quoted in a message, cut to 60 characters: a message stays one readable line whatever
/// the draft holds.
fn clip(s: &str) -> std::borrow::Cow<'_, str> {
    const MAX: usize = 60;
    match s.char_indices().nth(MAX) {
        Some((i, _)) => format!("{}...", &s[..i]).into(),
        None => s.into(),
    }
}

struct Section {
    name: String,
    line: usize,
    entries: Vec<Entry>,
}

/// The parsed file: sections in order, with the file name for errors.
struct Draft<'a> {
    file: &'a str,
    sections: Vec<Section>,
}

fn split_ini(text: &str, file: &str) -> Result<Vec<Section>, WifError> {
    let err = |section: &str, line, problem: String, fix: &str| WifError {
        file: file.into(),
        section: section.into(),
        line: Some(line),
        problem,
        fix: fix.into(),
    };
    let mut sections: Vec<Section> = Vec::new();
    // Lines end in LF, CR LF or a lone CR (old Macintosh drafts).
    let text = text.replace("\r\n", "\n");
    for (n, raw) in text.split(['\n', '\r']).enumerate() {
        let line = n + 1;
        let s = raw.trim_start_matches('\u{feff}').trim();
        if s.is_empty() || s.starts_with(';') {
            continue;
        }
        if let Some(rest) = s.strip_prefix('[') {
            let Some(name) = rest.strip_suffix(']') else {
                return Err(err(
                    "",
                    line,
                    format!("`{}` opens a section name without closing it", clip(s)),
                    "write the section header as [NAME]",
                ));
            };
            let name = name.trim().to_ascii_uppercase();
            if let Some(first) = sections.iter().find(|x| x.name == name) {
                return Err(err(
                    &name,
                    line,
                    format!(
                        "the section appears a second time (first at line {})",
                        first.line
                    ),
                    "merge the two sections into one",
                ));
            }
            sections.push(Section {
                name,
                line,
                entries: Vec::new(),
            });
            continue;
        }
        let Some((key, value)) = s.split_once('=') else {
            let sec = sections.last().map_or("", |x| x.name.as_str());
            return Err(err(
                sec,
                line,
                format!(
                    "`{}` is neither a [SECTION] header nor a key=value line",
                    clip(s)
                ),
                "write key=value, or start the line with ; to make it a comment",
            ));
        };
        let Some(sec) = sections.last_mut() else {
            return Err(err(
                "",
                line,
                "a key=value line comes before any [SECTION] header".into(),
                "start the file with [WIF]",
            ));
        };
        let key = key.trim().to_string();
        if let Some(first) = sec
            .entries
            .iter()
            .find(|e| e.key.eq_ignore_ascii_case(&key))
        {
            let (name, first) = (sec.name.clone(), first.line);
            return Err(err(
                &name,
                line,
                format!(
                    "key `{}` appears a second time (first at line {first})",
                    clip(&key)
                ),
                "keep one entry per key",
            ));
        }
        sec.entries.push(Entry {
            key,
            value: value.trim().to_string(),
            line,
        });
    }
    Ok(sections)
}

/// Largest count, thread, shaft, treadle or colour number a draft may give: the most threads
/// of a group in a period ([`MAX_THREADS`]).
pub const MAX_COUNT: usize = MAX_THREADS;

/// Most cells (ends x picks) of a whole draft before it is reduced to its repeat.
pub const MAX_DRAFT_CELLS: usize = 1 << 24;

/// Why a text is not a whole number in `usize`.
enum Whole {
    /// Not digits.
    No,
    /// Digits, too many.
    TooLarge,
}

/// A whole number: ASCII digits only (a leading `+` allowed, as Rust's parser does).
fn whole(t: &str) -> Result<usize, Whole> {
    let digits = t.strip_prefix('+').unwrap_or(t);
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return Err(Whole::No);
    }
    digits.parse::<usize>().map_err(|_| Whole::TooLarge)
}

fn parse_bool(v: &str) -> Option<bool> {
    match v.trim().to_ascii_lowercase().as_str() {
        "true" | "yes" | "on" | "1" => Some(true),
        "false" | "no" | "off" | "0" => Some(false),
        _ => None,
    }
}

/// The value without a trailing `; comment`.
fn bare(v: &str) -> &str {
    v.split(';').next().unwrap_or("").trim()
}

impl<'a> Draft<'a> {
    fn err(
        &self,
        section: &str,
        line: Option<usize>,
        problem: impl Into<String>,
        fix: impl Into<String>,
    ) -> WifError {
        WifError {
            file: self.file.into(),
            section: section.into(),
            line,
            problem: problem.into(),
            fix: fix.into(),
        }
    }

    /// A section, unless missing or switched off in `[CONTENTS]`.
    fn section(&self, name: &str) -> Option<&Section> {
        let off = self
            .raw_section("CONTENTS")
            .and_then(|c| c.entries.iter().find(|e| e.key.eq_ignore_ascii_case(name)))
            .is_some_and(|e| parse_bool(&e.value) == Some(false));
        if off {
            None
        } else {
            self.raw_section(name)
        }
    }

    fn raw_section(&self, name: &str) -> Option<&Section> {
        self.sections.iter().find(|s| s.name == name)
    }

    fn value(&self, section: &str, key: &str) -> Option<&Entry> {
        self.section(section)?
            .entries
            .iter()
            .find(|e| e.key.eq_ignore_ascii_case(key))
    }

    /// A whole number in 0..=[`MAX_COUNT`] (counts, colour numbers).
    fn int(&self, section: &str, e: &Entry, what: &str) -> Result<usize, WifError> {
        match whole(bare(&e.value)) {
            Ok(n) if n <= MAX_COUNT => Ok(n),
            Err(Whole::No) => Err(self.err(
                section,
                Some(e.line),
                format!("{}: {what} is not a whole number", e.shown()),
                format!("give {what} as a whole number"),
            )),
            _ => Err(self.too_large(section, e, what)),
        }
    }

    fn too_large(&self, section: &str, e: &Entry, what: &str) -> WifError {
        self.err(
            section,
            Some(e.line),
            format!("{}: {what} is too large, at most {MAX_COUNT}", e.shown()),
            format!(
                "give {what} up to {MAX_COUNT}: one repeat of the weave (docs/reference/limits.md)"
            ),
        )
    }

    fn number(&self, section: &str, e: &Entry, what: &str) -> Result<f64, WifError> {
        match bare(&e.value).parse::<f64>() {
            Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
            _ => Err(self.err(
                section,
                Some(e.line),
                format!("{}: {what} is not a positive number", e.shown()),
                format!("give {what} as a positive decimal number"),
            )),
        }
    }

    fn boolean(&self, section: &str, key: &str, default: bool) -> Result<bool, WifError> {
        let Some(e) = self.value(section, key) else {
            return Ok(default);
        };
        parse_bool(bare(&e.value)).ok_or_else(|| {
            self.err(
                section,
                Some(e.line),
                format!("{} is not a yes/no value", e.shown()),
                "write true or false (yes/no, on/off, 1/0)",
            )
        })
    }

    /// The entries of a numbered section (`n=...`, n >= 1), keyed by n, each at most `max`.
    fn numbered(
        &self,
        section: &str,
        what: &str,
        max: Option<(usize, &str)>,
    ) -> Result<Vec<(usize, &Entry)>, WifError> {
        let Some(s) = self.section(section) else {
            return Ok(Vec::new());
        };
        let mut out = Vec::with_capacity(s.entries.len());
        for e in &s.entries {
            let n = match whole(&e.key) {
                Ok(n) if (1..=MAX_COUNT).contains(&n) => n,
                Ok(0) | Err(Whole::No) => {
                    return Err(self.err(
                        section,
                        Some(e.line),
                        format!("key `{}` is not a {what} number (1, 2, ...)", clip(&e.key)),
                        format!("number each line by its {what}, from 1"),
                    ))
                }
                _ => return Err(self.too_large(section, e, &format!("the {what} number"))),
            };
            if let Some((m, source)) = max {
                if n > m {
                    return Err(self.err(
                        section,
                        Some(e.line),
                        format!("{what} {n} is beyond the {m} of {source}"),
                        format!("remove the line or raise {source}"),
                    ));
                }
            }
            out.push((n, e));
        }
        Ok(out)
    }

    /// A comma list of numbers, each in 1..=max (0 entries, meaning none, are dropped).
    fn list(
        &self,
        section: &str,
        e: &Entry,
        what: &str,
        max: Option<(usize, &str)>,
    ) -> Result<Vec<usize>, WifError> {
        let mut out = Vec::new();
        for tok in bare(&e.value).split(',').map(str::trim) {
            if tok.is_empty() {
                continue;
            }
            let n = match whole(tok) {
                Ok(n) if n <= MAX_COUNT => n,
                Err(Whole::No) => {
                    return Err(self.err(
                        section,
                        Some(e.line),
                        format!("{}: `{}` is not a {what} number", e.shown(), clip(tok)),
                        format!("list {what} numbers separated by commas, e.g. 1,3"),
                    ))
                }
                _ => return Err(self.too_large(section, e, &format!("a {what} number"))),
            };
            if n == 0 {
                continue;
            }
            if let Some((m, source)) = max {
                if n > m {
                    return Err(self.err(
                        section,
                        Some(e.line),
                        format!("{}: {what} {n} is beyond the {m} of {source}", e.shown()),
                        format!("use {what}s 1 to {m} or raise {source}"),
                    ));
                }
            }
            out.push(n);
        }
        Ok(out)
    }
}

/// Sizes (mm) of one group before the per-thread sections: spacing and thickness.
#[derive(Clone, Copy, Debug, PartialEq)]
struct GroupSizes {
    spacing: Option<f64>,
    thickness: Option<f64>,
    unit: f64,
}

/// Group spacing and thickness (mm): the options (`--spacing`, `--radius`) where given, else the
/// draft's, else each other (in the ratio 3.1 : 3.0 of the thesis's samples), else the other
/// group's, else [`DEFAULT_SPACING_MM`] and [`DEFAULT_THICKNESS_MM`].
pub fn resolve_sizes(
    draft: (Option<f64>, Option<f64>),
    other: (Option<f64>, Option<f64>),
    opts: &WifOptions,
) -> (f64, f64) {
    let one = |(s, d): (Option<f64>, Option<f64>)| {
        let s = opts.spacing.or(s);
        let d = opts.radius.map(|r| 2.0 * r).or(d);
        match (s, d) {
            (Some(s), Some(d)) => Some((s, d)),
            (Some(s), None) => Some((s, s * 3.0 / 3.1)),
            (None, Some(d)) => Some((d * 3.1 / 3.0, d)),
            (None, None) => None,
        }
    };
    one(draft)
        .or_else(|| one(other))
        .unwrap_or((DEFAULT_SPACING_MM, DEFAULT_THICKNESS_MM))
}

/// One thread as read: its colour and its own sizes (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Thread {
    albedo: Option<[f64; 3]>,
    spacing: f64,
    thickness: f64,
}

impl Thread {
    fn key(&self) -> [u64; 5] {
        let a = self.albedo.unwrap_or([-1.0; 3]);
        [
            a[0].to_bits(),
            a[1].to_bits(),
            a[2].to_bits(),
            self.spacing.to_bits(),
            self.thickness.to_bits(),
        ]
    }
}

/// The drawdown of a whole draft: ends x picks bits, 1 where the warp is over.
struct Drawdown {
    picks: usize,
    bits: Vec<u64>,
}

/// Row j = pick j + 1, column i = end i + 1: end i is raised at pick j when one of its shafts
/// is among those moved (`lift[j]`), and over the weft when raised on a rising shed or not
/// raised on a sinking one. Linear in the cells and the entries of threading and liftplan.
fn drawdown(threading: &[Vec<usize>], lift: &[Vec<usize>], rising: bool) -> Drawdown {
    let (ends, picks) = (threading.len(), lift.len());
    let top = lift.iter().flatten().copied().max().unwrap_or(0);
    let mut moved = vec![false; top + 1];
    let mut bits = vec![0u64; (ends * picks).div_ceil(64)];
    for (j, shafts) in lift.iter().enumerate() {
        shafts.iter().for_each(|&s| moved[s] = true);
        for (i, on) in threading.iter().enumerate() {
            let raised = on.iter().any(|&s| moved.get(s).copied().unwrap_or(false));
            if raised == rising {
                let k = i * picks + j;
                bits[k / 64] |= 1 << (k % 64);
            }
        }
        shafts.iter().for_each(|&s| moved[s] = false);
    }
    Drawdown { picks, bits }
}

impl Drawdown {
    fn over(&self, i: usize, j: usize) -> bool {
        let k = i * self.picks + j;
        self.bits[k / 64] >> (k % 64) & 1 == 1
    }

    /// FNV-1a of a sequence of cells: a filter before comparing columns or rows cell by cell.
    fn hash(&self, cells: impl Iterator<Item = bool>) -> u64 {
        cells.fold(0xcbf2_9ce4_8422_2325, |h, c| {
            (h ^ u64::from(c)).wrapping_mul(0x0100_0000_01b3)
        })
    }
}

/// The smallest p dividing `n` with `same(i, (i + p) % n)` for every i.
fn minimal_period(n: usize, same: impl Fn(usize, usize) -> bool) -> usize {
    (1..=n)
        .filter(|&p| n.is_multiple_of(p))
        .find(|&p| (0..n).all(|i| same(i, (i + p) % n)))
        .unwrap_or(n)
}

/// Reads and validates a WIF draft; `file` names it in errors (and, without a `[TEXT] Title`,
/// gives the fabric its name).
pub fn parse(text: &str, file: &str, opts: &WifOptions) -> Result<Fabric, WifError> {
    let d = Draft {
        file,
        sections: split_ini(text, file)?,
    };
    if d.raw_section("WIF").is_none() {
        return Err(d.err(
            "",
            None,
            "this is not a WIF draft: it has no [WIF] section",
            "give a Weaving Information File (version 1.1), or a JSON fabric file (docs/reference/fabric-format.md)",
        ));
    }
    let rising = d.boolean("WEAVING", "Rising Shed", true)?;
    let count = |section: &str, key: &str, what: &str| -> Result<Option<usize>, WifError> {
        match d.value(section, key) {
            Some(e) => d.int(section, e, what).map(Some),
            None => Ok(None),
        }
    };
    let shafts = count("WEAVING", "Shafts", "the number of shafts")?;
    let treadles = count("WEAVING", "Treadles", "the number of treadles")?;
    let shaft_max = shafts.map(|m| (m, "[WEAVING] Shafts"));
    let treadle_max = treadles.map(|m| (m, "[WEAVING] Treadles"));

    // Threading: the shafts of each end.
    let ends_given = count("WARP", "Threads", "the number of warp ends")?;
    let ends_max = ends_given.map(|m| (m, "[WARP] Threads"));
    if d.section("THREADING").is_none() {
        return Err(d.err(
            "THREADING",
            None,
            "the draft has no [THREADING] section",
            "add [THREADING] with a line end=shaft for every warp end",
        ));
    }
    let th = d.numbered("THREADING", "end", ends_max)?;
    let ends = ends_given.unwrap_or_else(|| th.iter().map(|(n, _)| *n).max().unwrap_or(0));
    let mut threading = vec![None; ends];
    for &(n, e) in &th {
        let shafts = d.list("THREADING", e, "shaft", shaft_max)?;
        if shafts.is_empty() {
            return Err(d.err(
                "THREADING",
                Some(e.line),
                format!("end {n} is on no shaft"),
                "put every warp end on a shaft (clothbake weaves every end), or remove the end and renumber",
            ));
        }
        threading[n - 1] = Some(shafts);
    }
    if ends == 0 {
        return Err(d.err(
            "THREADING",
            d.section("THREADING").map(|s| s.line),
            "the draft has no warp ends",
            "give [THREADING] a line end=shaft for each end",
        ));
    }
    let threading: Vec<Vec<usize>> = threading
        .into_iter()
        .enumerate()
        .map(|(i, t)| {
            t.ok_or_else(|| {
                d.err(
                    "THREADING",
                    d.section("THREADING").map(|s| s.line),
                    format!("end {} of {ends} has no entry", i + 1),
                    format!(
                        "add the line {}=shaft (every end 1..{ends} needs one)",
                        i + 1
                    ),
                )
            })
        })
        .collect::<Result<_, _>>()?;

    // The shafts lifted (or sunk) at each pick.
    let picks_given = count("WEFT", "Threads", "the number of picks")?;
    let picks_max = picks_given.map(|m| (m, "[WEFT] Threads"));
    let (plan_section, plan) = if d.section("LIFTPLAN").is_some() {
        let lp = d.numbered("LIFTPLAN", "pick", picks_max)?;
        let mut rows = Vec::with_capacity(lp.len());
        for &(n, e) in &lp {
            rows.push((n, d.list("LIFTPLAN", e, "shaft", shaft_max)?));
        }
        ("LIFTPLAN", rows)
    } else if d.section("TREADLING").is_some() {
        if d.section("TIEUP").is_none() {
            return Err(d.err(
                "TIEUP",
                None,
                "the draft has a [TREADLING] but no [TIEUP]",
                "add [TIEUP] with a line treadle=shafts for each treadle, or give a [LIFTPLAN]",
            ));
        }
        // Tie-up by treadle number (each at most MAX_COUNT).
        let tied = d.numbered("TIEUP", "treadle", treadle_max)?;
        let mut tieup: Vec<Vec<usize>> =
            vec![Vec::new(); tied.iter().map(|t| t.0 + 1).max().unwrap_or(0)];
        for &(n, e) in &tied {
            tieup[n] = d.list("TIEUP", e, "shaft", shaft_max)?;
        }
        let mut rows = Vec::new();
        for &(n, e) in &d.numbered("TREADLING", "pick", picks_max)? {
            let mut lifted = Vec::new();
            for t in d.list("TREADLING", e, "treadle", treadle_max)? {
                if let Some(s) = tieup.get(t) {
                    lifted.extend(s);
                }
            }
            rows.push((n, lifted));
        }
        ("TREADLING", rows)
    } else {
        return Err(d.err(
            "TREADLING",
            None,
            "the draft has neither a [TREADLING] nor a [LIFTPLAN] section",
            "add [TREADLING] (with [TIEUP]) or [LIFTPLAN]: a line pick=treadles or pick=shafts for every pick",
        ));
    };
    let picks = picks_given.unwrap_or_else(|| plan.iter().map(|(n, _)| *n).max().unwrap_or(0));
    let plan_line = d.section(plan_section).map(|s| s.line);
    if picks == 0 {
        return Err(d.err(
            plan_section,
            plan_line,
            "the draft has no picks",
            format!("give [{plan_section}] a line for each pick"),
        ));
    }
    let mut lift: Vec<Option<Vec<usize>>> = vec![None; picks];
    for (n, s) in plan {
        lift[n - 1] = Some(s);
    }
    let lift: Vec<Vec<usize>> = lift
        .into_iter()
        .enumerate()
        .map(|(j, l)| {
            l.ok_or_else(|| {
                d.err(
                    plan_section,
                    plan_line,
                    format!("pick {} of {picks} has no entry", j + 1),
                    format!(
                        "add the line {}=... (every pick 1..{picks} needs one; 0 lifts nothing)",
                        j + 1
                    ),
                )
            })
        })
        .collect::<Result<_, _>>()?;

    if ends.saturating_mul(picks) > MAX_DRAFT_CELLS {
        return Err(d.err(
            "WARP",
            d.section("WARP").map(|s| s.line),
            format!(
                "the draft has {ends} ends x {picks} picks = {} cells, more than the {MAX_DRAFT_CELLS} clothbake reads",
                ends * picks
            ),
            "give one repeat of the weave (docs/reference/limits.md)",
        ));
    }
    let dd = drawdown(&threading, &lift, rising);
    let over = |i: usize, j: usize| dd.over(i, j);

    let warp = threads(&d, "WARP", ends, "end", opts, "WEFT")?;
    let weft = threads(&d, "WEFT", picks, "pick", opts, "WARP")?;

    // The smallest repeat of pattern and threads: columns (rows) compared by hash first.
    let column: Vec<u64> = (0..ends)
        .map(|i| dd.hash((0..picks).map(|j| over(i, j))))
        .collect();
    let px = minimal_period(ends, |a, b| {
        warp[a].key() == warp[b].key()
            && column[a] == column[b]
            && (0..picks).all(|j| over(a, j) == over(b, j))
    });
    let row: Vec<u64> = (0..picks)
        .map(|j| dd.hash((0..px).map(|i| over(i, j))))
        .collect();
    let py = minimal_period(picks, |a, b| {
        weft[a].key() == weft[b].key()
            && row[a] == row[b]
            && (0..px).all(|i| over(i, a) == over(i, b))
    });
    check_period(px, py).map_err(|e| {
        d.err(
            "WARP",
            d.section("WARP").map(|s| s.line),
            format!("the draft's repeat is {px} ends x {py} picks: {e}"),
            e.fix(),
        )
    })?;
    let rows: Vec<Vec<bool>> = (0..py)
        .map(|j| (0..px).map(|i| over(i, j)).collect())
        .collect();
    let weave = Weave::new(rows).expect("non-empty and rectangular by construction");

    let name = d
        .value("TEXT", "Title")
        .map(|e| e.value.clone())
        .filter(|t| !t.is_empty())
        .unwrap_or_else(|| {
            std::path::Path::new(file)
                .file_stem()
                .map_or("draft".into(), |s| s.to_string_lossy().into_owned())
        });
    // Sizes in notes: in the group's units where it gives its sizes, in mm where the options
    // set them or they come from the other group or the defaults.
    let unit = |g: &str| {
        if opts.radius.is_some() || opts.spacing.is_some() {
            return Ok((1.0, "mm, from --radius/--spacing".to_string()));
        }
        let own = group_sizes(&d, g)?;
        if own.spacing.is_some() || own.thickness.is_some() {
            draft_unit(&d, g)
        } else {
            Ok((1.0, "mm".to_string()))
        }
    };
    let facets = facet_material(&d)?;
    let (mut warp, warp_note) = group("WARP", &warp[..px], &unit("WARP")?);
    let (mut weft, weft_note) = group("WEFT", &weft[..py], &unit("WEFT")?);
    facets.apply("WARP", &mut warp.material);
    facets.apply("WEFT", &mut weft.material);
    let fabric = Fabric::new(name, weave, warp, weft, &WifNaming(file)).map_err(|e| WifError {
        file: e.file,
        section: String::new(),
        line: None,
        problem: format!("{}: {}", e.field, e.problem),
        fix: e.fix,
    })?;
    Ok(fabric.with_notes(warp_note.into_iter().chain(weft_note).collect()))
}

/// The private section a draft may carry its facet material in (docs/reference/wif.md): WIF has no
/// field for rho_s and n, and other programs ignore `PRIVATE` sections.
pub const MATERIAL_SECTION: &str = "PRIVATE CLOTHBAKE MATERIAL";

/// The keys of [`MATERIAL_SECTION`]: both groups, then the warp, then the weft (a group's own
/// key wins over the key for both).
const MATERIAL_KEYS: [&str; 6] = [
    "Specular",
    "Exponent",
    "Warp Specular",
    "Warp Exponent",
    "Weft Specular",
    "Weft Exponent",
];

/// What a draft's [`MATERIAL_SECTION`] gives, in [`MATERIAL_KEYS`] order.
#[derive(Default)]
struct FacetMaterial([Option<f64>; 6]);

impl FacetMaterial {
    /// Sets rho_s and n of group `g` (`WARP`, `WEFT`) where the section gives them.
    fn apply(&self, g: &str, m: &mut Material) {
        let own = if g == "WARP" { 2 } else { 4 };
        if let Some(x) = self.0[own].or(self.0[0]) {
            m.specular = x;
        }
        if let Some(x) = self.0[own + 1].or(self.0[1]) {
            m.exponent = x;
        }
    }
}

/// Reads [`MATERIAL_SECTION`]: rho_s in [0, 1], n >= 0, no other key (a misspelt key would
/// otherwise be silently ignored).
fn facet_material(d: &Draft<'_>) -> Result<FacetMaterial, WifError> {
    let mut out = FacetMaterial::default();
    let Some(s) = d.section(MATERIAL_SECTION) else {
        return Ok(out);
    };
    for e in &s.entries {
        let Some(k) = MATERIAL_KEYS
            .iter()
            .position(|k| k.eq_ignore_ascii_case(e.key.trim()))
        else {
            return Err(d.err(
                MATERIAL_SECTION,
                Some(e.line),
                format!("key `{}` is not one clothbake reads", clip(&e.key)),
                format!("use {} (docs/reference/wif.md)", MATERIAL_KEYS.join(", ")),
            ));
        };
        let x = bare(&e.value).parse::<f64>().ok().filter(|x| x.is_finite());
        let (ok, what, fix) = if k % 2 == 0 {
            (
                x.filter(|x| (0.0..=1.0).contains(x)),
                "outside [0, 1]",
                "give the specular coefficient rho_s between 0 and 1, e.g. 0.05",
            )
        } else {
            (
                x.filter(|x| *x >= 0.0),
                "not a number >= 0",
                "give a non-negative specular exponent n, e.g. 10",
            )
        };
        out.0[k] = Some(ok.ok_or_else(|| {
            d.err(
                MATERIAL_SECTION,
                Some(e.line),
                format!("{} is {what}", e.shown()),
                fix,
            )
        })?);
    }
    Ok(out)
}

/// Names a draft's fields by the WIF section and key they come from.
struct WifNaming<'a>(&'a str);

impl Naming for WifNaming<'_> {
    fn file(&self) -> &str {
        self.0
    }

    fn field(&self, g: Group, field: Field, thread: usize) -> String {
        let s = match g {
            Group::Warp => "WARP",
            Group::Weft => "WEFT",
        };
        let t = thread + 1;
        match field {
            Field::Pattern => "[WARP] Threads / [WEFT] Threads".into(),
            Field::Radius => format!("[{s}] Thickness (thread {t})"),
            Field::Spacing => format!("[{s}] Spacing (thread {t})"),
            Field::Height
            | Field::SegmentLength
            | Field::Specular
            | Field::Exponent
            | Field::Translucency => PlainNaming(self.0).field(g, field, thread),
            Field::ThreadAlbedo(_) | Field::Albedo(_) => format!("[{s} COLORS] (thread {t})"),
        }
    }
}

/// The threads of one group: colours and sizes, per thread of the whole draft.
fn threads(
    d: &Draft<'_>,
    g: &str,
    n: usize,
    what: &str,
    opts: &WifOptions,
    other: &str,
) -> Result<Vec<Thread>, WifError> {
    let sizes = group_sizes(d, g)?;
    let theirs = group_sizes(d, other)?;
    let (s, t) = resolve_sizes(
        (sizes.spacing, sizes.thickness),
        (theirs.spacing, theirs.thickness),
        opts,
    );
    let colour = colours(d)?;
    let lookup = |section: &str, e: &Entry, idx: usize| {
        colour
            .iter()
            .find(|(k, _)| *k == idx)
            .map(|(_, c)| *c)
            .ok_or_else(|| {
                d.err(
                    section,
                    Some(e.line),
                    format!("{}: colour {idx} is not in the [COLOR TABLE]", e.shown()),
                    "add the colour to [COLOR TABLE] or use one of its entries",
                )
            })
    };
    let default = match d.value(g, "Color") {
        Some(e) => {
            let v: Vec<&str> = bare(&e.value).split(',').map(str::trim).collect();
            let idx = v[0].parse::<usize>().map_err(|_| {
                d.err(
                    g,
                    Some(e.line),
                    format!("{}: `{}` is not a colour number", e.shown(), clip(v[0])),
                    "give the number of a [COLOR TABLE] entry, e.g. Color=1",
                )
            })?;
            Some(lookup(g, e, idx)?)
        }
        None => None,
    };
    let per_section = format!("{g} COLORS");
    let mut albedo = vec![default; n];
    let max = Some((
        n,
        if g == "WARP" {
            "[WARP] Threads"
        } else {
            "[WEFT] Threads"
        },
    ));
    for (k, e) in d.numbered(&per_section, what, max)? {
        if k > n {
            return Err(d.err(
                &per_section,
                Some(e.line),
                format!("{what} {k} is beyond the {n} {what}s of the draft"),
                "remove the line",
            ));
        }
        let idx = d.int(&per_section, e, "a colour number")?;
        albedo[k - 1] = Some(lookup(&per_section, e, idx)?);
    }
    let per = |suffix: &str, base: f64| -> Result<Vec<f64>, WifError> {
        let section = format!("{g} {suffix}");
        let mut v = vec![base; n];
        for (k, e) in d.numbered(&section, what, None)? {
            if k > n {
                return Err(d.err(
                    &section,
                    Some(e.line),
                    format!("{what} {k} is beyond the {n} {what}s of the draft"),
                    "remove the line",
                ));
            }
            v[k - 1] = d.number(&section, e, suffix.to_ascii_lowercase().as_str())? * sizes.unit;
        }
        Ok(v)
    };
    // The options replace the draft's sizes, its per-thread ones too (still checked).
    let mut spacing = per("SPACING", s)?;
    let mut thickness = per("THICKNESS", t)?;
    if opts.spacing.is_some() {
        spacing.fill(s);
    }
    if opts.radius.is_some() {
        thickness.fill(t);
    }
    Ok((0..n)
        .map(|k| Thread {
            albedo: albedo[k],
            spacing: spacing[k],
            thickness: thickness[k],
        })
        .collect())
}

/// `[G] Units`, `Spacing`, `Thickness`, in mm.
fn group_sizes(d: &Draft<'_>, g: &str) -> Result<GroupSizes, WifError> {
    let unit = match d.value(g, "Units") {
        Some(e) => unit_mm(&e.value).ok_or_else(|| {
            d.err(
                g,
                Some(e.line),
                format!("{} is not a WIF unit", e.shown()),
                "write Units=Decipoints, Units=Inches or Units=Centimeters",
            )
        })?,
        None => unit_mm("decipoints").expect("known unit"),
    };
    let get = |key: &str| -> Result<Option<f64>, WifError> {
        match d.value(g, key) {
            Some(e) => Ok(Some(d.number(g, e, &key.to_ascii_lowercase())? * unit)),
            None => Ok(None),
        }
    };
    Ok(GroupSizes {
        spacing: get("Spacing")?,
        thickness: get("Thickness")?,
        unit,
    })
}

/// `[COLOR TABLE]` as albedos, scaled by the `[COLOR PALETTE]` range.
fn colours(d: &Draft<'_>) -> Result<Vec<(usize, [f64; 3])>, WifError> {
    let (lo, hi) = match d.value("COLOR PALETTE", "Range") {
        Some(e) => {
            let v: Vec<Option<f64>> = bare(&e.value)
                .split(',')
                .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
                .collect();
            match v[..] {
                [Some(lo), Some(hi)] if hi > lo => (lo, hi),
                [Some(hi)] if hi > 0.0 => (0.0, hi),
                _ => {
                    return Err(d.err(
                        "COLOR PALETTE",
                        Some(e.line),
                        format!("{} is not a range low,high with low < high", e.shown()),
                        "write e.g. Range=0,255",
                    ))
                }
            }
        }
        None => (0.0, 255.0),
    };
    if let Some(e) = d.value("COLOR PALETTE", "Form") {
        if !bare(&e.value).eq_ignore_ascii_case("RGB") {
            return Err(d.err(
                "COLOR PALETTE",
                Some(e.line),
                format!("{}: only RGB colours are read", e.shown()),
                "give the palette as Form=RGB",
            ));
        }
    }
    let mut out = Vec::new();
    for (k, e) in d.numbered("COLOR TABLE", "colour", None)? {
        let v: Vec<Option<f64>> = bare(&e.value)
            .split(',')
            .map(|t| t.trim().parse::<f64>().ok())
            .collect();
        let rgb = match v[..] {
            [Some(r), Some(g), Some(b)] => [r, g, b],
            _ => {
                return Err(d.err(
                    "COLOR TABLE",
                    Some(e.line),
                    format!("{} is not three numbers r,g,b", e.shown()),
                    format!("write the colour as r,g,b, each from {lo} to {hi}"),
                ))
            }
        };
        if rgb.iter().any(|c| !(lo..=hi).contains(c)) {
            return Err(d.err(
                "COLOR TABLE",
                Some(e.line),
                format!(
                    "{}: a component lies outside the [COLOR PALETTE] range {lo},{hi}",
                    e.shown()
                ),
                "fix the colour or the palette's Range",
            ));
        }
        out.push((k, rgb.map(|c| srgb_to_linear((c - lo) / (hi - lo)))));
    }
    Ok(out)
}

/// The clothbake yarn group of one period of threads: radii, centre-to-centre spacings,
/// colours; and a note when yarns thicker than their spacing allows were packed
/// ([`packed_radii`]: round yarns capped where neighbours meet; docs/reference/wif.md).
fn group(g: &str, t: &[Thread], unit: &(f64, String)) -> (YarnGroup, Option<String>) {
    let n = t.len();
    let spacing: Vec<f64> = (0..n)
        .map(|i| 0.5 * (t[i].spacing + t[(i + 1) % n].spacing))
        .collect();
    let half: Vec<f64> = t.iter().map(|x| 0.5 * x.thickness).collect();
    let (radii, capped) = packed_radii(&half, &spacing);
    let note = (capped > 0).then(|| packing_note(g, t, &radii, capped, unit));
    let threads: Vec<Yarn> = (0..n)
        .map(|i| Yarn {
            radius: radii[i],
            height: 0.0,
            spacing: spacing[i],
            segment_length: None,
            albedo: t[i].albedo,
        })
        .collect();
    let mut threads = threads;
    let mut material = Material::default();
    // One colour for the whole group: the group material's; otherwise per thread, with the
    // default albedo for threads that have no colour.
    let first = threads[0].albedo;
    if threads.iter().all(|y| y.albedo == first) {
        if let Some(a) = first {
            material.albedo = a;
        }
        threads.iter_mut().for_each(|y| y.albedo = None);
    } else {
        for y in &mut threads {
            y.albedo.get_or_insert(material.albedo);
        }
    }
    (YarnGroup { threads, material }, note)
}

/// What packing did to a group, in one line for `eval` and `info`.
fn packing_note(
    g: &str,
    t: &[Thread],
    radii: &[f64],
    capped: usize,
    (per_unit, unit): &(f64, String),
) -> String {
    let (name, what) = if g == "WARP" {
        ("warp", "ends")
    } else {
        ("weft", "picks")
    };
    let n = t.len();
    let uniform = t
        .iter()
        .all(|x| x.thickness == t[0].thickness && x.spacing == t[0].spacing);
    if uniform {
        format!(
            "{name}: Thickness {} > Spacing {} ({unit}); radius capped to {} mm, half the spacing (round yarns that touch), instead of {} mm",
            mm(t[0].thickness / per_unit),
            mm(t[0].spacing / per_unit),
            mm(radii[0]),
            mm(0.5 * t[0].thickness)
        )
    } else {
        let lo = radii.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = radii.iter().copied().fold(0.0, f64::max);
        let thick = t.iter().map(|x| x.thickness).fold(0.0, f64::max);
        format!(
            "{name}: {capped} of {n} {what} thicker than their spacing allows; radii capped where neighbours meet, now {} to {} mm (Thickness up to {} mm)",
            mm(lo),
            mm(hi),
            mm(thick)
        )
    }
}

/// Millimetres per unit of group `g`'s sizes, and the unit's name as the draft writes it.
fn draft_unit(d: &Draft<'_>, g: &str) -> Result<(f64, String), WifError> {
    let name = d
        .value(g, "Units")
        .map_or("Decipoints".to_string(), |e| bare(&e.value).to_string());
    Ok((group_sizes(d, g)?.unit, name))
}

/// A length for a message: 4 significant digits.
fn mm(x: f64) -> String {
    let digits = (3 - x.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{x:.digits$}")
}

#[cfg(test)]
mod tests;
