//! When did the identifier converge? A streaming, bounded-memory answer.
//!
//! For each parameter (m_x, c_x, k_x, m_z, c_z, k_z), over the well-conditioned instants
//! only (rcond >= rcond_min, [`super::DirectionEstimate::well_conditioned`]):
//!
//! ```text
//! final                = v_last, the value at the last well-conditioned instant
//! band                 = [F - d, F + d],  F = final, d = tol |F|
//! identification_time  = min { t_k : F - d <= v_j <= F + d for every j >= k }
//! ```
//!
//! i.e. the earliest well-conditioned instant from which every later well-conditioned
//! estimate stays within `tol` (relative) of the final value.
//!
//! ## Algorithm
//!
//! Per parameter, two monotone stacks ("staircases") hold the suffix maxima and suffix
//! minima of the sequence: pushing v pops every entry <= v (resp. >= v), so the stack lists
//! the instants whose value exceeds everything after them. At the end, the last entry
//! above F + d (resp. below F - d) is found by scanning from the top; the answer is the
//! instant right after it. O(1) amortised per estimate; the answer costs O(stack).
//!
//! The values reach the staircases in blocks of 64 per parameter: within a block, one
//! backward scan keeps the values that exceed everything after them, the block's largest
//! value pops what it would have popped, and the survivors are pushed. The staircases are
//! bit for bit those of one-by-one pushes (when a stack could fill up during a block, its
//! values go one by one), without a hard-to-predict pop loop per value.
//!
//! ## Bounded memory and its price
//!
//! A stack is capped (default [`DEFAULT_STACK_CAPACITY`] entries; a steadily drifting
//! sequence would otherwise keep every sample). When full, adjacent entries are merged, the
//! pairs whose values are closest first: a merged entry keeps the larger value (for the
//! max stack; the smaller for the min stack) and the later time, so it claims "a value
//! this far out occurs this late" -- the reported time can only get LATER than the exact
//! one, never earlier. With Delta the largest value range ever merged
//! ([`ParameterConvergence::resolution`], same unit as the parameter, 0 when nothing was
//! merged):
//!
//! ```text
//! T_exact(band [F - d, F + d]) <= T_reported <= T_exact(band [F - d + Delta, F + d - Delta])
//! ```
//!
//! so the answer is exact for a tolerance somewhere between tol - Delta/|F| and tol.

use serde::Serialize;

use super::config::AlgebraicConfig;
use super::error::AlgebraicError;
use super::estimate::AlgebraicEstimate;
use crate::model::check;
use crate::parameter::Parameter;

/// Default relative tolerance of the convergence band (1 %).
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Default cap on each staircase (entries); 6 parameters x 2 stacks x 32 bytes x 4096 =
/// 1.5 MiB at most.
pub const DEFAULT_STACK_CAPACITY: usize = 4096;

/// The convergence summary of one parameter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ParameterConvergence {
    /// Which parameter.
    pub parameter: Parameter,
    /// Value at the last well-conditioned instant (unit of the parameter); None if there
    /// was none.
    pub final_value: Option<f64>,
    /// Time of that instant \[s\].
    pub final_t: Option<f64>,
    /// Earliest well-conditioned instant from which every well-conditioned estimate stays
    /// within the tolerance of the final value \[s\]; None if there was no well-conditioned
    /// instant.
    pub identification_time: Option<f64>,
    /// Number of well-conditioned instants seen.
    pub well_conditioned: u64,
    /// Largest value range merged when a staircase was full (unit of the parameter; 0 when
    /// the answer is exact). See the module docs for what it bounds.
    pub resolution: f64,
}

/// A staircase entry: the newest original instant it stands for (time `t`, followed by
/// the instant `t_next`), the extreme value `rep` of the instants merged into it and the
/// opposite extreme `lo`.
#[derive(Debug, Clone, Copy)]
struct Step {
    t: f64,
    t_next: f64,
    rep: f64,
    lo: f64,
}

/// Suffix maxima of a sequence, capped (module docs).
#[derive(Debug, Clone)]
struct Staircase {
    steps: Vec<Step>,
    cap: usize,
    resolution: f64,
    spans: Vec<f64>,
}

impl Staircase {
    fn new(cap: usize) -> Self {
        Self {
            steps: Vec::new(),
            cap,
            resolution: 0.0,
            spans: Vec::new(),
        }
    }

    /// Push one value. The top is always the entry pushed last (pops happen only here,
    /// before the push), so its `t_next` is still unset.
    #[inline]
    fn push(&mut self, t: f64, v: f64) {
        if let Some(top) = self.steps.last_mut() {
            top.t_next = t;
        }
        while self.steps.last().is_some_and(|s| s.rep <= v) {
            self.steps.pop();
        }
        if self.steps.len() >= self.cap {
            self.compact();
        }
        self.steps.push(Step {
            t,
            t_next: f64::NAN,
            rep: v,
            lo: v,
        });
    }

    /// Push the values `sign * v[i]` at times `t[i]` (at most [`BLOCK`]), with the same
    /// result as pushing them one by one. Within the block, a value survives when it
    /// exceeds every later one (one backward scan, whose branch is rarely taken, instead
    /// of a pop loop per value whose exit is hard to predict); the block's largest value
    /// pops what it would have popped, and the survivors are pushed in order. When the
    /// stack could fill up during the block, the values go one by one, so that compaction
    /// happens exactly when it would have.
    fn push_block(&mut self, t: &[f64], v: &[f64], sign: f64) {
        let n = t.len();
        debug_assert!(n == v.len() && n <= BLOCK);
        if n == 0 {
            return;
        }
        if self.steps.len() + n >= self.cap {
            for (&t, &v) in t.iter().zip(v) {
                self.push(t, sign * v);
            }
            return;
        }
        // survivors, last first
        let mut survivors = [0u8; BLOCK];
        let mut k = 0;
        let mut later_max = f64::NEG_INFINITY;
        for i in (0..n).rev() {
            let x = sign * v[i];
            if x > later_max {
                survivors[k] = i as u8;
                k += 1;
                later_max = x;
            }
        }
        if let Some(top) = self.steps.last_mut() {
            top.t_next = t[0];
        }
        while self.steps.last().is_some_and(|s| s.rep <= later_max) {
            self.steps.pop();
        }
        self.steps.extend(survivors[..k].iter().rev().map(|&i| {
            let i = usize::from(i);
            let x = sign * v[i];
            Step {
                t: t[i],
                t_next: t.get(i + 1).copied().unwrap_or(f64::NAN),
                rep: x,
                lo: x,
            }
        }));
    }

    /// Merge adjacent pairs whose merged range is at most the median range (each entry in
    /// at most one merge): frees at least ~1/6 of the stack, O(cap).
    #[cold]
    fn compact(&mut self) {
        let n = self.steps.len();
        if n < 2 {
            return;
        }
        let span = |a: &Step, b: &Step| a.rep - a.lo.min(b.lo);
        self.spans.clear();
        self.spans
            .extend(self.steps.windows(2).map(|w| span(&w[0], &w[1])));
        let mid = self.spans.len() / 2;
        let threshold = *self.spans.select_nth_unstable_by(mid, f64::total_cmp).1;
        let mut write = 0;
        let mut i = 0;
        while i < n {
            let cur = self.steps[i];
            if i + 1 < n && span(&cur, &self.steps[i + 1]) <= threshold {
                let next = self.steps[i + 1];
                let merged = Step {
                    t: next.t,
                    t_next: next.t_next,
                    rep: cur.rep,
                    lo: cur.lo.min(next.lo),
                };
                self.resolution = self.resolution.max(merged.rep - merged.lo);
                self.steps[write] = merged;
                i += 2;
            } else {
                self.steps[write] = cur;
                i += 1;
            }
            write += 1;
        }
        self.steps.truncate(write);
    }

    /// The instant after the newest entry above `hi` (None when no entry is above `hi`).
    fn after_last_above(&self, hi: f64) -> Option<f64> {
        self.steps
            .iter()
            .rev()
            .find(|s| s.rep > hi)
            .map(|s| s.t_next)
    }
}

/// Values a track holds back before it pushes them to its staircases together.
const BLOCK: usize = 64;

#[derive(Debug, Clone)]
struct Track {
    /// Suffix maxima of v.
    max: Staircase,
    /// Suffix maxima of -v (suffix minima of v).
    min: Staircase,
    first_t: f64,
    last_t: f64,
    last_v: f64,
    count: u64,
    /// Values not yet in the staircases: (t, v) of the last `held` well-conditioned
    /// instants.
    held_t: [f64; BLOCK],
    held_v: [f64; BLOCK],
    held: usize,
}

impl Track {
    fn new(cap: usize) -> Self {
        Self {
            max: Staircase::new(cap),
            min: Staircase::new(cap),
            first_t: f64::NAN,
            last_t: f64::NAN,
            last_v: f64::NAN,
            count: 0,
            held_t: [0.0; BLOCK],
            held_v: [0.0; BLOCK],
            held: 0,
        }
    }

    /// Take (t, v) when `keep`, else nothing; written without a branch on `keep` (whether
    /// an instant is well conditioned can change from sample to sample).
    #[inline]
    fn push_if(&mut self, t: f64, v: f64, keep: bool) {
        let first = keep && self.count == 0;
        self.first_t = if first { t } else { self.first_t };
        self.held_t[self.held] = t;
        self.held_v[self.held] = v;
        self.held += usize::from(keep);
        self.last_t = if keep { t } else { self.last_t };
        self.last_v = if keep { v } else { self.last_v };
        self.count += u64::from(keep);
        if self.held == BLOCK {
            self.flush();
        }
    }

    /// The held values into the staircases.
    fn flush(&mut self) {
        let n = self.held;
        self.max
            .push_block(&self.held_t[..n], &self.held_v[..n], 1.0);
        self.min
            .push_block(&self.held_t[..n], &self.held_v[..n], -1.0);
        self.held = 0;
    }

    /// This track with every value in its staircases.
    fn flushed(&self) -> Self {
        let mut t = self.clone();
        t.flush();
        t
    }

    /// The summary; the held values must have been flushed.
    fn result(&self, parameter: Parameter, tol: f64) -> ParameterConvergence {
        debug_assert_eq!(self.held, 0);
        let resolution = self.max.resolution.max(self.min.resolution);
        if self.count == 0 {
            return ParameterConvergence {
                parameter,
                final_value: None,
                final_t: None,
                identification_time: None,
                well_conditioned: 0,
                resolution,
            };
        }
        let f = self.last_v;
        let d = tol * f.abs();
        let (hi, lo) = (f + d, f - d);
        let after_max = self.max.after_last_above(hi);
        let after_min = self.min.after_last_above(-lo);
        let start = match (after_max, after_min) {
            (None, None) => Some(self.first_t),
            (a, b) => {
                let t = a
                    .unwrap_or(f64::NEG_INFINITY)
                    .max(b.unwrap_or(f64::NEG_INFINITY));
                // t_next is always set for an entry below the top; NaN would be a bug.
                t.is_finite().then_some(t)
            }
        };
        ParameterConvergence {
            parameter,
            final_value: Some(f),
            final_t: Some(self.last_t),
            identification_time: start,
            well_conditioned: self.count,
            resolution,
        }
    }
}

/// Streaming convergence summary of the six parameters (module docs). Memory is bounded by
/// the stack capacity whatever the record length.
#[derive(Debug, Clone)]
pub struct ConvergenceTracker {
    tol: f64,
    rcond_min: f64,
    tracks: [Track; 6],
    estimates: u64,
}

impl ConvergenceTracker {
    /// A tracker with relative band `tol` (finite, >= 0) that ignores instants with
    /// rcond < `rcond_min` (in [0, 1]), with the default stack capacity.
    pub fn new(tol: f64, rcond_min: f64) -> Result<Self, AlgebraicError> {
        Self::with_capacity(tol, rcond_min, DEFAULT_STACK_CAPACITY)
    }

    /// As [`new`](Self::new) with each of the 12 stacks capped at `capacity` entries
    /// (>= 2).
    pub fn with_capacity(
        tol: f64,
        rcond_min: f64,
        capacity: usize,
    ) -> Result<Self, AlgebraicError> {
        check("tol", tol, "finite and >= 0 (relative)", |v| v >= 0.0)?;
        check("rcond_min", rcond_min, "finite and in [0, 1]", |v| {
            (0.0..=1.0).contains(&v)
        })?;
        check("capacity", capacity as f64, ">= 2 (entries)", |v| v >= 2.0)?;
        Ok(Self {
            tol,
            rcond_min,
            tracks: std::array::from_fn(|_| Track::new(capacity)),
            estimates: 0,
        })
    }

    /// The default tolerance ([`DEFAULT_TOLERANCE`]) and the identifier's `rcond_min`.
    pub fn for_config(config: &AlgebraicConfig) -> Result<Self, AlgebraicError> {
        Self::new(DEFAULT_TOLERANCE, config.rcond_min)
    }

    /// The relative tolerance.
    pub fn tolerance(&self) -> f64 {
        self.tol
    }

    /// The conditioning threshold.
    pub fn rcond_min(&self) -> f64 {
        self.rcond_min
    }

    /// Number of estimates pushed (flagged ones included).
    pub fn estimates(&self) -> u64 {
        self.estimates
    }

    /// Take the next estimate (in time order). Flagged directions are skipped.
    #[inline]
    pub fn push(&mut self, e: &AlgebraicEstimate) {
        self.estimates += 1;
        let ok = e.well_conditioned(self.rcond_min);
        let v = e.values();
        for (i, track) in self.tracks.iter_mut().enumerate() {
            track.push_if(e.t, v[i], ok[i / 3] && v[i].is_finite());
        }
    }

    /// Entries held in the 12 staircases now (each at most the capacity): the tracker's
    /// memory is about 32 bytes times this.
    pub fn stack_entries(&self) -> usize {
        self.tracks
            .iter()
            .map(|t| {
                let t = t.flushed();
                t.max.steps.len() + t.min.steps.len()
            })
            .sum()
    }

    /// The summary of one parameter so far; `None` for a parameter the per-direction
    /// identifier does not estimate (m, a, mud, alpha).
    pub fn result(&self, p: Parameter) -> Option<ParameterConvergence> {
        let i = p.direction_index()?;
        Some(self.tracks[i].flushed().result(p, self.tol))
    }

    /// The summaries of all six, in [`Parameter::PER_DIRECTION`] order.
    pub fn results(&self) -> [ParameterConvergence; 6] {
        std::array::from_fn(|i| {
            self.tracks[i]
                .flushed()
                .result(Parameter::PER_DIRECTION[i], self.tol)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn same(a: &Staircase, b: &Staircase) -> bool {
        let bits = |s: &Step| [s.t, s.t_next, s.rep, s.lo].map(f64::to_bits);
        a.steps.len() == b.steps.len()
            && a.steps
                .iter()
                .zip(&b.steps)
                .all(|(x, y)| bits(x) == bits(y))
            && a.resolution.to_bits() == b.resolution.to_bits()
    }

    /// Blocks give the staircases of one-by-one pushes bit for bit, whether or not the
    /// stack fills and is compacted during the run: drifting, noisy and flat sequences,
    /// capacities below, around and far above the block size, blocks cut short.
    #[test]
    fn blocks_are_one_by_one_pushes() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..300 {
            let cap = [2, 5, 63, 64, 65, 70, 130, 300, 4096][case % 9];
            let n = rng.gen_range(1..3000);
            let drift = [-1.0, 0.0, 1.0][case % 3] * 1e-3;
            let noise = [0.0, 1e-4, 1.0][(case / 3) % 3];
            let values: Vec<f64> = (0..n)
                .map(|i| {
                    let v: f64 = rng.gen_range(-1.0..1.0);
                    // a few repeated values, so that ties are exercised
                    let v = if rng.gen_range(0..8) == 0 { 0.5 } else { v };
                    drift * i as f64 + noise * v
                })
                .collect();
            let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
            for sign in [1.0, -1.0] {
                let mut one = Staircase::new(cap);
                for (&t, &v) in t.iter().zip(&values) {
                    one.push(t, sign * v);
                }
                let mut blocks = Staircase::new(cap);
                let mut at = 0;
                while at < n {
                    let len = rng.gen_range(1..=BLOCK).min(n - at);
                    blocks.push_block(&t[at..at + len], &values[at..at + len], sign);
                    at += len;
                }
                assert!(
                    same(&one, &blocks),
                    "case {case}: cap {cap}, n {n}, sign {sign}"
                );
            }
        }
    }
}
