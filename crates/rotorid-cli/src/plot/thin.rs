//! Thinning a record to the pixel grid while it streams in, so that `rotorid plot` holds
//! a bounded number of points whatever the record's length, and draws the same picture as
//! with every sample.
//!
//! - [`ColumnThinner`], for a curve against time: the points fall into columns of equal
//!   width; each column keeps its first, lowest, highest and last point, in their order
//!   (as [`super::geometry::decimate`] does once the axes are known). The column width is
//!   not known in advance (the record's length is not): it starts at zero (every point
//!   its own column) and doubles whenever there are more than twice `columns` columns,
//!   adjacent columns merging exactly (the first of the left, the last of the right, the
//!   lower low, the higher high). So between `columns` and `2 columns` columns remain,
//!   each at most 1 / `columns` of the record wide. A gap (a NaN: an ill-conditioned
//!   estimate) splits a column into fragments, each kept as above; more than
//!   [`MAX_FRAGMENTS`] in one column keep the first, the last and the envelope of the
//!   others. Points outside an explicit time window are dropped, except the last one
//!   before it and the first one after it, so the clipped line still reaches its edges.
//! - [`PathThinner`], for an orbit (z against x): the points are snapped to a square grid
//!   of cells, [`PathThinner::CELLS`] across the larger extent of the data (finer than the
//!   pixels), and only the distinct segments between cells are kept, in their order. A
//!   rotor that turns thousands of times over one ellipse gives each segment once. The cell
//!   size is a power of two that doubles as the extent grows (cells nest, so the segments
//!   kept so far are re-snapped exactly), and also when more than `cap` segments would be
//!   kept (a noisy orbit that fills an area), which bounds memory.
//! - [`Subsample`]: every k-th value, k doubling as needed to keep at most `cap`; the
//!   reference level of an estimates panel is the median of a late part of the record,
//!   exact up to `cap` values and a close estimate beyond.

use std::collections::HashSet;

/// Most fragments one column keeps (module doc).
pub const MAX_FRAGMENTS: usize = 3;

/// A point and its position in the input, to keep kept points in their original order.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Pt {
    x: f64,
    y: f64,
    seq: u64,
}

/// A stretch of one column without a gap: its first, lowest, highest and last point.
#[derive(Debug, Clone, Copy)]
struct Fragment {
    first: Pt,
    lo: Pt,
    hi: Pt,
    last: Pt,
    /// The line comes into `first` from the previous fragment's last point.
    joined: bool,
}

impl Fragment {
    fn new(p: Pt, joined: bool) -> Self {
        Self {
            first: p,
            lo: p,
            hi: p,
            last: p,
            joined,
        }
    }

    /// Extend by the fragment `o` that follows it.
    fn absorb(&mut self, o: &Fragment) {
        if o.lo.y < self.lo.y {
            self.lo = o.lo;
        }
        if o.hi.y > self.hi.y {
            self.hi = o.hi;
        }
        self.last = o.last;
    }

    fn points(&self) -> impl Iterator<Item = Pt> {
        let mut v = [self.first, self.lo, self.hi, self.last];
        v.sort_by_key(|p| p.seq);
        let mut prev = None;
        v.into_iter().filter(move |p| {
            let new = prev != Some(p.seq);
            prev = Some(p.seq);
            new
        })
    }
}

#[derive(Debug, Clone)]
struct Column {
    /// Column index at the current width (`None` while the width is zero).
    index: Option<i64>,
    /// Inside the time window (columns never mix points inside and outside it, so the
    /// extent of what is visible stays exact).
    inside: bool,
    fragments: Vec<Fragment>,
}

impl Column {
    /// Append `o`, which follows this column.
    fn absorb(&mut self, o: Column) {
        let mut rest = o.fragments.into_iter();
        if let (Some(first), Some(last)) = (rest.next(), self.fragments.last_mut()) {
            if first.joined {
                last.absorb(&first);
            } else {
                self.fragments.push(first);
            }
        }
        self.fragments.extend(rest);
        self.compact();
    }

    fn push(&mut self, p: Pt, joined: bool) {
        match self.fragments.last_mut() {
            Some(last) if joined => last.absorb(&Fragment::new(p, true)),
            _ => {
                self.fragments.push(Fragment::new(p, joined));
                self.compact();
            }
        }
    }

    /// Keep at most [`MAX_FRAGMENTS`]: the first, the envelope of the middle ones, the last.
    fn compact(&mut self) {
        let n = self.fragments.len();
        if n <= MAX_FRAGMENTS {
            return;
        }
        let last = self.fragments[n - 1];
        let mut middle = self.fragments[1];
        for f in &self.fragments[2..n - 1] {
            middle.absorb(f);
        }
        self.fragments.truncate(1);
        self.fragments.push(middle);
        self.fragments.push(last);
    }
}

/// Streaming min/max thinning of a curve against time (module doc).
#[derive(Debug, Clone)]
pub struct ColumnThinner {
    window: (Option<f64>, Option<f64>),
    columns: usize,
    origin: Option<f64>,
    /// Column width (0: every point its own column).
    width: f64,
    kept: Vec<Column>,
    seq: u64,
    /// The last point pushed was finite: the next one continues the line.
    connected: bool,
    /// The last point pushed was inside the window and kept.
    after_inside: bool,
    /// The latest point before the window (or between windows), kept only if the window
    /// follows.
    held: Option<Pt>,
    x_last: f64,
}

impl ColumnThinner {
    /// Thin to about `columns` columns (at least the pixel width of the axes); points with
    /// x outside `window` (either bound optional) are dropped as the module doc says.
    pub fn new(columns: usize, window: (Option<f64>, Option<f64>)) -> Self {
        Self {
            window,
            columns: columns.max(1),
            origin: None,
            width: 0.0,
            kept: Vec::new(),
            seq: 0,
            connected: false,
            after_inside: false,
            held: None,
            x_last: f64::NAN,
        }
    }

    fn inside(&self, x: f64) -> bool {
        self.window.0.is_none_or(|a| x >= a) && self.window.1.is_none_or(|b| x <= b)
    }

    /// The next point; a non-finite `x` or `y` breaks the line.
    pub fn push(&mut self, x: f64, y: f64) {
        if !(x.is_finite() && y.is_finite()) {
            self.connected = false;
            self.held = None;
            self.after_inside = false;
            return;
        }
        let p = Pt {
            x,
            y,
            seq: self.seq,
        };
        self.seq += 1;
        if self.inside(x) {
            if let Some(h) = self.held.take() {
                self.add(h, false, false);
                self.connected = true;
            }
            self.add(p, self.connected, true);
            self.after_inside = true;
        } else if self.after_inside && self.connected {
            // the first point after the window
            self.add(p, true, false);
            self.after_inside = false;
        } else {
            self.held = Some(p);
            self.after_inside = false;
        }
        self.connected = true;
    }

    fn index(&self, x: f64) -> Option<i64> {
        let origin = self.origin?;
        (self.width > 0.0).then(|| ((x - origin) / self.width).floor() as i64)
    }

    fn add(&mut self, p: Pt, joined: bool, inside: bool) {
        self.origin.get_or_insert(p.x);
        self.x_last = p.x;
        let index = self.index(p.x);
        match self.kept.last_mut() {
            Some(c) if index.is_some() && c.index == index && c.inside == inside => {
                c.push(p, joined);
            }
            _ => self.kept.push(Column {
                index,
                inside,
                fragments: vec![Fragment::new(p, joined)],
            }),
        }
        if self.kept.len() > 2 * self.columns {
            self.coarsen();
        }
    }

    /// Double the column width (or set it, the first time) until at most twice
    /// `columns` columns remain.
    fn coarsen(&mut self) {
        let origin = self.origin.unwrap_or(0.0);
        let mut rounds = 0;
        while self.kept.len() > 2 * self.columns {
            rounds += 1;
            if rounds > 64 {
                // x that does not advance (a zigzag in time): merge neighbours regardless
                self.merge_where(|_, _| true);
                continue;
            }
            if self.width > 0.0 {
                self.width *= 2.0;
            } else {
                let span = (self.x_last - origin).abs();
                self.width = if span > 0.0 {
                    span / self.columns as f64
                } else {
                    f64::MIN_POSITIVE
                };
            }
            let width = self.width;
            for c in &mut self.kept {
                let x = c.fragments[0].first.x;
                c.index = Some(((x - origin) / width).floor() as i64);
            }
            self.merge_where(|a, b| a.index == b.index && a.inside == b.inside);
        }
    }

    fn merge_where(&mut self, same: impl Fn(&Column, &Column) -> bool) {
        let mut merged: Vec<Column> = Vec::with_capacity(self.kept.len());
        for c in self.kept.drain(..) {
            match merged.last_mut() {
                Some(prev) if same(prev, &c) => prev.absorb(c),
                _ => merged.push(c),
            }
        }
        self.kept = merged;
    }

    /// The kept points as (x, y), a NaN pair wherever the line breaks.
    pub fn points(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for c in &self.kept {
            for f in &c.fragments {
                if !f.joined && !xs.is_empty() {
                    xs.push(f64::NAN);
                    ys.push(f64::NAN);
                }
                for p in f.points() {
                    xs.push(p.x);
                    ys.push(p.y);
                }
            }
        }
        (xs, ys)
    }

    /// Number of points kept.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.kept
            .iter()
            .flat_map(|c| &c.fragments)
            .map(|f| f.points().count())
            .sum()
    }
}

/// A grid cell.
type Cell = (i32, i32);

/// Streaming thinning of a path to its distinct segments between grid cells (module doc).
#[derive(Debug, Clone)]
pub struct PathThinner {
    cap: usize,
    anchor: Option<(f64, f64)>,
    /// min x, max x, min y, max y.
    extent: [f64; 4],
    /// Cell size, a power of two (0 while every point is the anchor).
    h: f64,
    last: Option<Cell>,
    segments: Vec<(Cell, Cell)>,
    seen: HashSet<(Cell, Cell)>,
}

impl PathThinner {
    /// Cells across the larger extent of the data.
    pub const CELLS: f64 = 1024.0;

    /// Keep at most `cap` segments (the cells grow coarser beyond).
    pub fn new(cap: usize) -> Self {
        Self {
            cap: cap.max(16),
            anchor: None,
            extent: [
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            ],
            h: 0.0,
            last: None,
            segments: Vec::new(),
            seen: HashSet::new(),
        }
    }

    /// Break the path: the next point starts a new line.
    pub fn break_line(&mut self) {
        self.last = None;
    }

    /// The next point of the path (non-finite: a break).
    pub fn push(&mut self, x: f64, y: f64) {
        if !(x.is_finite() && y.is_finite()) {
            self.break_line();
            return;
        }
        let (ax, ay) = *self.anchor.get_or_insert((x, y));
        let e = &mut self.extent;
        (e[0], e[1], e[2], e[3]) = (e[0].min(x), e[1].max(x), e[2].min(y), e[3].max(y));
        let span = (e[1] - e[0]).max(e[3] - e[2]);
        if span > 0.0 && (self.h == 0.0 || span / self.h > Self::CELLS) {
            let mut h = if self.h > 0.0 {
                self.h
            } else {
                f64::MIN_POSITIVE
            };
            while span / h > Self::CELLS {
                h *= 2.0;
            }
            self.regrid(h);
        }
        let cell = if self.h > 0.0 {
            (
                ((x - ax) / self.h).floor() as i32,
                ((y - ay) / self.h).floor() as i32,
            )
        } else {
            (0, 0)
        };
        if let Some(prev) = self.last {
            if prev != cell {
                let key = if prev < cell {
                    (prev, cell)
                } else {
                    (cell, prev)
                };
                if self.seen.insert(key) {
                    self.segments.push((prev, cell));
                }
            }
        }
        self.last = Some(cell);
        while self.segments.len() > self.cap {
            self.regrid(self.h * 2.0);
        }
    }

    /// Snap to cells of size `h` (a power-of-two multiple of the current size).
    fn regrid(&mut self, h: f64) {
        if self.h > 0.0 {
            let k = (h / self.h).round().max(1.0) as i64;
            let snap = |c: Cell| {
                (
                    i64::from(c.0).div_euclid(k) as i32,
                    i64::from(c.1).div_euclid(k) as i32,
                )
            };
            let old = std::mem::take(&mut self.segments);
            self.seen.clear();
            for (a, b) in old {
                let (a, b) = (snap(a), snap(b));
                let key = if a < b { (a, b) } else { (b, a) };
                if a != b && self.seen.insert(key) {
                    self.segments.push((a, b));
                }
            }
            self.last = self.last.map(snap);
        }
        self.h = h;
    }

    /// Number of segments kept.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.segments.len()
    }

    /// The kept path as (x, y) at cell centres, a NaN pair wherever it breaks, followed by
    /// the two corners of the data's extent as single points (which draw nothing but give
    /// the axes the same range as every sample would).
    pub fn points(&self) -> (Vec<f64>, Vec<f64>) {
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        let Some((ax, ay)) = self.anchor else {
            return (xs, ys);
        };
        let at = |c: Cell| {
            (
                ax + (f64::from(c.0) + 0.5) * self.h,
                ay + (f64::from(c.1) + 0.5) * self.h,
            )
        };
        let mut end = None;
        for &(a, b) in &self.segments {
            if end != Some(a) {
                if !xs.is_empty() {
                    xs.push(f64::NAN);
                    ys.push(f64::NAN);
                }
                let (x, y) = at(a);
                xs.push(x);
                ys.push(y);
            }
            let (x, y) = at(b);
            xs.push(x);
            ys.push(y);
            end = Some(b);
        }
        let e = self.extent;
        for (x, y) in [(e[0], e[2]), (e[1], e[3])] {
            if !xs.is_empty() {
                xs.push(f64::NAN);
                ys.push(f64::NAN);
            }
            xs.push(x);
            ys.push(y);
        }
        (xs, ys)
    }
}

/// Every k-th of a stream of (t, v), at most `cap` kept (module doc).
#[derive(Debug, Clone)]
pub struct Subsample {
    cap: usize,
    stride: u64,
    count: u64,
    kept: Vec<(f64, f64)>,
}

impl Subsample {
    /// Keep at most `cap` (at least 2) values.
    pub fn new(cap: usize) -> Self {
        Self {
            cap: cap.max(2),
            stride: 1,
            count: 0,
            kept: Vec::new(),
        }
    }

    /// The next value `v` at time `t`.
    pub fn push(&mut self, t: f64, v: f64) {
        if self.count.is_multiple_of(self.stride) {
            self.kept.push((t, v));
            if self.kept.len() >= self.cap {
                let mut i = 0;
                self.kept.retain(|_| {
                    i += 1;
                    i % 2 == 1
                });
                self.stride *= 2;
            }
        }
        self.count += 1;
    }

    /// The kept (t, v).
    pub fn values(&self) -> &[(f64, f64)] {
        &self.kept
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::geometry::{decimate, finite_runs};

    /// The envelope per pixel column, as [`decimate`] draws it.
    fn envelope(x: &[f64], y: &[f64], x0: f64, x1: f64, cols: usize) -> Vec<(f64, f64)> {
        let mut env = vec![(f64::INFINITY, f64::NEG_INFINITY); cols];
        for run in finite_runs(x, y) {
            for (px, py) in decimate(&run, x0, x1, cols) {
                if px >= x0 && px <= x1 {
                    let c = (((px - x0) / (x1 - x0) * cols as f64) as usize).min(cols - 1);
                    env[c].0 = env[c].0.min(py);
                    env[c].1 = env[c].1.max(py);
                }
            }
        }
        env
    }

    #[test]
    fn a_long_curve_keeps_its_envelope_in_bounded_points() {
        let n = 1_000_000;
        let mut th = ColumnThinner::new(1000, (None, None));
        let (mut xs, mut ys) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for i in 0..n {
            let t = i as f64 * 1e-4;
            let y = (t * 377.0).sin() * (1.0 + t) + if i == 654_321 { 50.0 } else { 0.0 };
            th.push(t, y);
            xs.push(t);
            ys.push(y);
        }
        assert!(th.len() <= 4 * 2 * 1000 + 8, "{} points", th.len());
        let (tx, ty) = th.points();
        assert!(ty.iter().any(|&v| v > 40.0), "the spike is kept");
        // per pixel column, the drawn envelope is that of every sample, give or take a
        // column of thinning (here 2 to 4 per pixel)
        let (x0, x1) = (0.0, xs[n - 1]);
        let (thin, full) = (
            envelope(&tx, &ty, x0, x1, 500),
            envelope(&xs, &ys, x0, x1, 500),
        );
        for j in 0..500usize {
            let near = &thin[j.saturating_sub(1)..(j + 2).min(500)];
            let lo = near.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
            let hi = near.iter().map(|e| e.1).fold(f64::NEG_INFINITY, f64::max);
            assert!(lo <= full[j].0 && hi >= full[j].1, "column {j}");
        }
        let kept: HashSet<u64> = tx.iter().map(|v| v.to_bits()).collect();
        assert!(xs.iter().filter(|v| kept.contains(&v.to_bits())).count() >= tx.len() / 2);
        assert_eq!(
            ty.iter().cloned().fold(f64::MIN, f64::max),
            ys.iter().cloned().fold(f64::MIN, f64::max)
        );
    }

    #[test]
    fn gaps_survive_and_windows_keep_one_point_either_side() {
        let mut th = ColumnThinner::new(4, (Some(10.0), Some(20.0)));
        for i in 0..40 {
            let y = if i == 15 { f64::NAN } else { i as f64 };
            th.push(i as f64, y);
        }
        let (x, y) = th.points();
        let finite: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
        assert_eq!(finite.first(), Some(&9.0));
        assert_eq!(finite.last(), Some(&21.0));
        let gap = x.iter().position(|v| v.is_nan()).expect("a gap");
        assert!(x[gap - 1] <= 14.0 && x[gap + 1] >= 16.0, "{x:?}");
        assert_eq!(y.iter().filter(|v| v.is_nan()).count(), 1);
    }

    #[test]
    fn many_gaps_in_a_column_stay_bounded() {
        let mut th = ColumnThinner::new(10, (None, None));
        for i in 0..100_000 {
            let y = if i % 3 == 0 { f64::NAN } else { (i % 7) as f64 };
            th.push(i as f64, y);
        }
        assert!(th.len() <= 2 * 10 * MAX_FRAGMENTS * 4, "{}", th.len());
        let (_, y) = th.points();
        let finite: Vec<f64> = y.iter().copied().filter(|v| v.is_finite()).collect();
        assert_eq!(finite.iter().cloned().fold(f64::MIN, f64::max), 6.0);
        assert_eq!(finite.iter().cloned().fold(f64::MAX, f64::min), 0.0);
    }

    #[test]
    fn zigzag_time_is_still_bounded() {
        let mut th = ColumnThinner::new(8, (None, None));
        for i in 0..10_000 {
            th.push(if i % 2 == 0 { -1.0 } else { 1.0 }, i as f64);
        }
        assert!(th.len() <= 2 * 8 * 4 * MAX_FRAGMENTS);
    }

    #[test]
    fn an_orbit_turning_many_times_is_kept_once() {
        // ~500 samples per turn: a spiral of ~100 turns out to a steady ellipse
        let mut th = PathThinner::new(200_000);
        let push = |th: &mut PathThinner, from: u32, to: u32| {
            for i in from..to {
                let a = f64::from(i) * 0.0126;
                let r = 1e-6 * (1.0 - (-f64::from(i) / 50_000.0).exp());
                th.push(r * a.cos(), 0.5 * r * a.sin());
            }
        };
        push(&mut th, 0, 1_000_000);
        let half = th.len();
        push(&mut th, 1_000_000, 2_000_000);
        // the second million samples (2000 turns over the ellipse) add next to nothing
        assert!(th.len() < half + half / 20, "{half} then {}", th.len());
        let (x, y) = th.points();
        let max = x
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(f64::MIN, f64::max);
        let min_y = y
            .iter()
            .copied()
            .filter(|v| v.is_finite())
            .fold(f64::MAX, f64::min);
        assert!(
            (max - 1e-6).abs() < 4e-9 && (min_y + 0.5e-6).abs() < 4e-9,
            "{max} {min_y}"
        );
        // every kept point (but the extent's corners, last) is within a cell of the
        // ellipse or inside it
        let path = x.len() - 4;
        for (&px, &py) in x[..path].iter().zip(&y[..path]) {
            if px.is_finite() {
                assert!(
                    (px / 1e-6).powi(2) + (py / 0.5e-6).powi(2) < 1.02,
                    "{px} {py}"
                );
            }
        }
    }

    #[test]
    fn a_noisy_orbit_is_capped() {
        let mut th = PathThinner::new(5_000);
        let mut s: u64 = 1;
        for _ in 0..200_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            let u = (s % 10_000) as f64 / 10_000.0;
            let v = ((s >> 20) % 10_000) as f64 / 10_000.0;
            th.push(u, v);
        }
        assert!(th.len() <= 5_000);
        let mut still = PathThinner::new(16);
        for _ in 0..10 {
            still.push(3.0, 4.0);
        }
        assert_eq!(still.len(), 0);
        let (x, y) = still.points();
        assert_eq!(x.len(), 3, "only the extent's corners");
        assert!(x[0] == 3.0 && x[1].is_nan() && x[2] == 3.0 && y[2] == 4.0);
    }

    #[test]
    fn subsamples_are_exact_up_to_the_cap_then_strided() {
        let mut s = Subsample::new(8);
        for i in 0..7 {
            s.push(i as f64, i as f64);
        }
        assert_eq!(s.values().len(), 7);
        for i in 7..100 {
            s.push(i as f64, i as f64);
        }
        assert!(s.values().len() < 8);
        let ts: Vec<f64> = s.values().iter().map(|p| p.0).collect();
        let step = ts[1] - ts[0];
        assert!(ts.windows(2).all(|w| w[1] - w[0] == step), "{ts:?}");
    }
}
