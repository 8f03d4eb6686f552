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
//! The values reach the staircases in blocks of 64 instants: within a block, one backward
//! scan of all twelve staircases at once (six parameters, v and -v, side by side in vector
//! registers; an instant a parameter does not keep holds -inf there) marks the values that
//! exceed everything after them, the block's largest value pops what it would have popped,
//! and the survivors are pushed. The staircases are bit for bit those of one-by-one pushes
//! (when a stack could fill up during a block, its values go one by one), without a
//! hard-to-predict pop loop per value.
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
use super::cross_estimate::CrossAlgebraicEstimate;
use super::error::AlgebraicError;
use super::estimate::AlgebraicEstimate;
use crate::model::check;
use crate::parameter::{ModelKind, Parameter};

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

    /// Push a block's kept values with the same result as pushing them one by one:
    /// `kept` (bit i: instant i of the block is kept), their times `t[i]` and values
    /// `v(i)`, the block's survivors `survivors` (the kept instants whose value exceeds
    /// every later kept one, [`Block::scan`]) and its largest kept value `top`. The
    /// largest value pops what it would have popped and the survivors are pushed in
    /// order. When the stack could fill up during the block, the values go one by one, so
    /// that compaction happens exactly when it would have.
    fn push_survivors(
        &mut self,
        t: &[f64; BLOCK],
        v: impl Fn(usize) -> f64,
        kept: u64,
        survivors: u64,
        top: f64,
    ) {
        if kept == 0 {
            return;
        }
        if self.steps.len() + kept.count_ones() as usize >= self.cap {
            for i in bits(kept) {
                self.push(t[i], v(i));
            }
            return;
        }
        if let Some(last) = self.steps.last_mut() {
            last.t_next = t[kept.trailing_zeros() as usize];
        }
        while self.steps.last().is_some_and(|s| s.rep <= top) {
            self.steps.pop();
        }
        self.steps.extend(bits(survivors).map(|i| {
            // the next kept instant after i, if in this block
            let later = kept & (u64::MAX << i << 1);
            let x = v(i);
            Step {
                t: t[i],
                t_next: if later == 0 {
                    f64::NAN
                } else {
                    t[later.trailing_zeros() as usize]
                },
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

/// Instants the tracker holds back before it pushes them to its staircases together.
const BLOCK: usize = 64;

/// The positions of the set bits of `mask`, lowest first.
fn bits(mut mask: u64) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

/// The last `n` instants, not yet in the staircases. Lane 0 of `v[i][p]` holds parameter
/// p's value at instant i, lane 1 its negative (the minima staircase is the maxima one of
/// -v); -inf where the instant is not kept, which never survives a scan nor raises a
/// maximum.
#[derive(Debug, Clone)]
struct Block<const N: usize> {
    t: [f64; BLOCK],
    v: [[[f64; 2]; N]; BLOCK],
    /// Bit i of `kept[p]`: instant i is kept for parameter p.
    kept: [u64; N],
    n: usize,
}

impl<const N: usize> Block<N> {
    fn new() -> Self {
        Self {
            t: [0.0; BLOCK],
            v: [[[0.0; 2]; N]; BLOCK],
            kept: [0; N],
            n: 0,
        }
    }

    /// Per parameter and lane: the instants whose value exceeds every later one (bit i)
    /// and the largest value. One backward pass over the block for all 2N lanes at once
    /// (compare and select per lane, no branch: the compiler keeps the lanes in vector
    /// registers).
    #[inline]
    fn scan(&self) -> ([[u64; 2]; N], [[f64; 2]; N]) {
        let mut survivors = [[0u64; 2]; N];
        let mut later_max = [[f64::NEG_INFINITY; 2]; N];
        for i in (0..self.n).rev() {
            let row = &self.v[i];
            for p in 0..N {
                for l in 0..2 {
                    let above = row[p][l] > later_max[p][l];
                    survivors[p][l] |= u64::from(above) << i;
                    later_max[p][l] = if above { row[p][l] } else { later_max[p][l] };
                }
            }
        }
        (survivors, later_max)
    }
}

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
        }
    }

    /// Note (t, v) when `keep`, else nothing; written without a branch on `keep` (whether
    /// an instant is well conditioned can change from sample to sample).
    #[inline]
    fn note_if(&mut self, t: f64, v: f64, keep: bool) {
        let first = keep && self.count == 0;
        self.first_t = if first { t } else { self.first_t };
        self.last_t = if keep { t } else { self.last_t };
        self.last_v = if keep { v } else { self.last_v };
        self.count += u64::from(keep);
    }

    /// The summary; the held values must have been flushed.
    fn result(&self, parameter: Parameter, tol: f64) -> ParameterConvergence {
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

/// Streaming convergence summary of the N per-direction parameters of an algebraic
/// identifier (module docs): six for the Jeffcott rotor's ([`Parameter::PER_DIRECTION`]),
/// ten for the cross-coupled rotor's ([`ConvergenceTracker::cross`]), the x direction's
/// first half. Memory is bounded by the stack capacity whatever the record length.
#[derive(Debug, Clone)]
pub struct ConvergenceTracker<const N: usize = 6> {
    tol: f64,
    rcond_min: f64,
    parameters: [Parameter; N],
    tracks: [Track; N],
    block: Box<Block<N>>,
    estimates: u64,
}

impl ConvergenceTracker<6> {
    /// A tracker of the Jeffcott identifier's six values with relative band `tol` (finite
    /// and non-negative) that ignores instants with rcond < `rcond_min` (in [0, 1]), with
    /// the default stack capacity.
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
        Self::of(Parameter::PER_DIRECTION, tol, rcond_min, capacity)
    }

    /// The default tolerance ([`DEFAULT_TOLERANCE`]) and the identifier's `rcond_min`.
    pub fn for_config(config: &AlgebraicConfig) -> Result<Self, AlgebraicError> {
        Self::new(DEFAULT_TOLERANCE, config.rcond_min)
    }

    /// Take the next estimate (in time order). Flagged directions are skipped.
    #[inline]
    pub fn push(&mut self, e: &AlgebraicEstimate) {
        self.push_values(e.t, &e.values(), e.well_conditioned(self.rcond_min));
    }
}

impl ConvergenceTracker<10> {
    /// A tracker of the cross-coupled identifier's ten values (m_x, cxx, cxz, kxx, kxz,
    /// m_z, czx, czz, kzx, kzz), as [`ConvergenceTracker::new`].
    pub fn cross(tol: f64, rcond_min: f64) -> Result<Self, AlgebraicError> {
        let p = ModelKind::CrossCoupled.per_direction();
        Self::of(
            std::array::from_fn(|i| p[i]),
            tol,
            rcond_min,
            DEFAULT_STACK_CAPACITY,
        )
    }

    /// Take the next estimate (in time order). Flagged directions are skipped.
    #[inline]
    pub fn push_cross(&mut self, e: &CrossAlgebraicEstimate) {
        self.push_values(e.t, &e.values(), e.well_conditioned(self.rcond_min));
    }
}

impl<const N: usize> ConvergenceTracker<N> {
    fn of(
        parameters: [Parameter; N],
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
            parameters,
            tracks: std::array::from_fn(|_| Track::new(capacity)),
            block: Box::new(Block::new()),
            estimates: 0,
        })
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

    /// Take the values `v` at time `t` (in time order), the x direction's first half;
    /// `ok`: whether each direction is well conditioned (a flagged direction is skipped).
    #[inline]
    fn push_values(&mut self, t: f64, v: &[f64; N], ok: [bool; 2]) {
        self.estimates += 1;
        let b = &mut *self.block;
        let i = b.n;
        b.t[i] = t;
        for (p, track) in self.tracks.iter_mut().enumerate() {
            let keep = ok[p / (N / 2)] && v[p].is_finite();
            track.note_if(t, v[p], keep);
            b.v[i][p] = if keep {
                [v[p], -v[p]]
            } else {
                [f64::NEG_INFINITY; 2]
            };
            b.kept[p] |= u64::from(keep) << i;
        }
        b.n += 1;
        if b.n == BLOCK {
            self.flush();
        }
    }

    /// The held instants into the staircases.
    fn flush(&mut self) {
        let b = &mut *self.block;
        let (survivors, top) = b.scan();
        for (p, track) in self.tracks.iter_mut().enumerate() {
            for (stairs, l) in [(&mut track.max, 0), (&mut track.min, 1)] {
                stairs.push_survivors(
                    &b.t,
                    |i| b.v[i][p][l],
                    b.kept[p],
                    survivors[p][l],
                    top[p][l],
                );
            }
            b.kept[p] = 0;
        }
        b.n = 0;
    }

    /// This tracker with every instant in its staircases.
    fn flushed(&self) -> Self {
        let mut c = self.clone();
        c.flush();
        c
    }

    /// Entries held in the 2N staircases now (each at most the capacity): the tracker's
    /// memory is about 32 bytes times this.
    pub fn stack_entries(&self) -> usize {
        self.flushed()
            .tracks
            .iter()
            .map(|t| t.max.steps.len() + t.min.steps.len())
            .sum()
    }

    /// The summary of one parameter so far; `None` for a parameter the per-direction
    /// identifier does not estimate (m, a, mud, alpha).
    pub fn result(&self, p: Parameter) -> Option<ParameterConvergence> {
        let i = self.parameters.iter().position(|&q| q == p)?;
        Some(self.flushed().tracks[i].result(p, self.tol))
    }

    /// The summaries of all N, in the identifier's order ([`ModelKind::per_direction`]).
    pub fn results(&self) -> [ParameterConvergence; N] {
        let all = self.flushed();
        std::array::from_fn(|i| all.tracks[i].result(self.parameters[i], self.tol))
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

    /// The tracker's blocks give the staircases of one-by-one pushes of each parameter's
    /// kept values, bit for bit, whether or not a stack fills and is compacted during the
    /// run: drifting, noisy and flat sequences with ties, instants flagged per direction
    /// and non-finite values, capacities below, around and far above the block size, and
    /// blocks cut short by a summary taken mid-block.
    #[test]
    fn blocks_are_one_by_one_pushes() {
        use super::super::estimate::DirectionEstimate;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        for case in 0..200 {
            let cap = [2, 5, 63, 64, 65, 70, 130, 300, 4096][case % 9];
            let n = rng.gen_range(1..3000);
            let drift = [-1.0, 0.0, 1.0][case % 3] * 1e-3;
            let noise = [0.0, 1e-4, 1.0][(case / 3) % 3];
            let flagged = [0.0, 0.1, 0.9][(case / 9) % 3];
            let value = |i: usize, rng: &mut rand_chacha::ChaCha8Rng| {
                let v: f64 = rng.gen_range(-1.0..1.0);
                // a few repeated values, so that ties are exercised, and a few NaN
                match rng.gen_range(0..64) {
                    0..=7 => 0.5,
                    8 => f64::NAN,
                    _ => drift * i as f64 + noise * v,
                }
            };
            let mut tracker = ConvergenceTracker::with_capacity(0.01, 0.5, cap).unwrap();
            let mut one: [[Staircase; 2]; 6] =
                std::array::from_fn(|_| [Staircase::new(cap), Staircase::new(cap)]);
            for i in 0..n {
                let dir = |rng: &mut rand_chacha::ChaCha8Rng| DirectionEstimate {
                    m: value(i, rng),
                    c: value(i, rng),
                    k: value(i, rng),
                    rcond: if rng.gen_bool(flagged) { 0.1 } else { 0.9 },
                };
                let e = AlgebraicEstimate {
                    t: i as f64 * 1e-4,
                    x: dir(&mut rng),
                    z: dir(&mut rng),
                };
                tracker.push(&e);
                let ok = e.well_conditioned(0.5);
                for (p, v) in e.values().into_iter().enumerate() {
                    if ok[p / 3] && v.is_finite() {
                        one[p][0].push(e.t, v);
                        one[p][1].push(e.t, -v);
                    }
                }
                if rng.gen_range(0..500) == 0 || i == n - 1 {
                    let all = tracker.flushed();
                    for (p, [max, min]) in one.iter().enumerate() {
                        assert!(
                            same(max, &all.tracks[p].max) && same(min, &all.tracks[p].min),
                            "case {case}: cap {cap}, n {n}, parameter {p}, instant {i}"
                        );
                    }
                }
            }
        }
    }
}
