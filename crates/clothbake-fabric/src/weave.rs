//! The weave period (thesis sec. 2.2-2.3): a binary point-paper matrix.
//!
//! Row index = weft thread (increasing +Y), column index = warp thread (increasing +X);
//! a 1 (`true`) means the warp passes over the weft at that crossing.

/// Which of the two perpendicular thread groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Group {
    /// Lengthwise yarns, running along +Y, one per pattern column.
    Warp,
    /// Widthwise yarns, running along +X, one per pattern row.
    Weft,
}

impl Group {
    /// The other group.
    pub fn other(self) -> Group {
        match self {
            Group::Warp => Group::Weft,
            Group::Weft => Group::Warp,
        }
    }
    /// Lower-case name as used in fabric files.
    pub fn name(self) -> &'static str {
        match self {
            Group::Warp => "warp",
            Group::Weft => "weft",
        }
    }
}

/// A validated weave period: rectangular, non-empty, cells 0/1 (invariant held by construction).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Weave {
    rows: usize,
    cols: usize,
    warp_over: Vec<bool>,
}

/// A float: a maximal run of consecutive crossings along one thread where that thread is on top.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Float {
    /// Index (within the period) of the first crossing thread it passes over.
    pub start: usize,
    /// Number of crossing threads it passes over (>= 1).
    pub len: usize,
    /// True when the thread never goes under: the float is endless (a straight cylinder).
    pub endless: bool,
}

impl Weave {
    /// Builds a weave from rows of booleans; `None` if empty or ragged.
    pub fn new(rows: Vec<Vec<bool>>) -> Option<Weave> {
        let cols = rows.first()?.len();
        if cols == 0 || rows.iter().any(|r| r.len() != cols) {
            return None;
        }
        Some(Weave {
            rows: rows.len(),
            cols,
            warp_over: rows.into_iter().flatten().collect(),
        })
    }

    /// The weave seen from the back: every crossing flipped (the back of a 2/1 twill is a
    /// 1/2 twill, of a warp-faced satin a weft-faced one).
    pub fn inverted(&self) -> Weave {
        Weave {
            rows: self.rows,
            cols: self.cols,
            warp_over: self.warp_over.iter().map(|&o| !o).collect(),
        }
    }

    /// Number of weft threads (rows) in the period.
    pub fn n_weft(&self) -> usize {
        self.rows
    }
    /// Number of warp threads (columns) in the period.
    pub fn n_warp(&self) -> usize {
        self.cols
    }
    /// Number of threads of `group` in the period.
    pub fn n(&self, group: Group) -> usize {
        match group {
            Group::Warp => self.cols,
            Group::Weft => self.rows,
        }
    }

    /// True when warp `warp` passes over weft `weft` (indices taken modulo the period).
    pub fn warp_over(&self, warp: usize, weft: usize) -> bool {
        self.warp_over[(weft % self.rows) * self.cols + warp % self.cols]
    }

    /// The group on top where thread `thread` of `group` crosses thread `cross` of the other group.
    pub fn on_top(&self, group: Group, thread: usize, cross: usize) -> bool {
        match group {
            Group::Warp => self.warp_over(thread, cross),
            Group::Weft => !self.warp_over(cross, thread),
        }
    }

    /// The floats of thread `thread` of `group`, in order of their start.
    pub fn floats(&self, group: Group, thread: usize) -> Vec<Float> {
        let n = self.n(group.other());
        let top: Vec<bool> = (0..n).map(|k| self.on_top(group, thread, k)).collect();
        if top.iter().all(|&t| t) {
            return vec![Float {
                start: 0,
                len: n,
                endless: true,
            }];
        }
        let mut out = Vec::new();
        for start in 0..n {
            // A float starts where this thread comes up after being under.
            if top[start] && !top[(start + n - 1) % n] {
                let len = (0..n).take_while(|&k| top[(start + k) % n]).count();
                out.push(Float {
                    start,
                    len,
                    endless: false,
                });
            }
        }
        out
    }

    /// The weave as rows of 0/1, as written in fabric files.
    pub fn to_rows(&self) -> Vec<Vec<u8>> {
        (0..self.rows)
            .map(|r| (0..self.cols).map(|c| self.warp_over(c, r) as u8).collect())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(rows: &[&[u8]]) -> Weave {
        Weave::new(
            rows.iter()
                .map(|r| r.iter().map(|&v| v == 1).collect())
                .collect(),
        )
        .unwrap()
    }

    #[test]
    fn twill_floats_wrap_around() {
        // 2/1 twill: each warp floats over two wefts, each weft over one warp.
        let t = w(&[&[1, 1, 0], &[0, 1, 1], &[1, 0, 1]]);
        let f = t.floats(Group::Warp, 0);
        assert_eq!(
            f,
            vec![Float {
                start: 2,
                len: 2,
                endless: false
            }]
        );
        for weft in 0..3 {
            let f = t.floats(Group::Weft, weft);
            assert_eq!(f.len(), 1);
            assert_eq!(f[0].len, 1);
        }
    }

    #[test]
    fn all_ones_is_endless_warp_and_no_weft() {
        let pf = w(&[&[1]]);
        assert!(pf.floats(Group::Warp, 0)[0].endless);
        assert!(pf.floats(Group::Weft, 0).is_empty());
    }

    #[test]
    fn ragged_or_empty_is_rejected() {
        assert!(Weave::new(vec![]).is_none());
        assert!(Weave::new(vec![vec![true], vec![true, false]]).is_none());
    }
}
