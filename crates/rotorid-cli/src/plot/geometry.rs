//! Turning a data series into what is drawn: runs of finite points, min/max decimation to
//! the pixel grid, and clipping to the axes' rectangle.
//!
//! Plotters maps data to pixels without clipping, so a spike of an estimate near a
//! singular instant would be drawn across the margins and the legend. Every polyline is
//! therefore clipped to the visible rectangle [x0, x1] x [y0, y1] first, segment by
//! segment, with the Liang-Barsky parametric test (Y.-D. Liang, B. A. Barsky, "A new
//! concept and method for line clipping", ACM Trans. Graphics 3(1), 1984):
//!
//! ```text
//! P(t) = P0 + t (P1 - P0),  0 <= t <= 1,   inside  <=>  p_i t <= q_i  for i = 1..4
//! p = (-dx, dx, -dy, dy),   q = (x0 - X0, x1 - X0, y0 - Y0, y1 - Y0)
//! t_in = max(0, q_i/p_i : p_i < 0),  t_out = min(1, q_i/p_i : p_i > 0),  visible iff t_in <= t_out
//! ```
//!
//! Thick bitmap lines are outlined by plotters with unlimited miter joins, whose length
//! is w / (2 sin(theta / 2)) at an interior angle theta: at a spike (theta -> 0) the miter
//! shoots across the figure. [`split_at_sharp_turns`] cuts a polyline wherever it turns by
//! more than 90 degrees in pixel space (d_in . d_out < 0), bounding miters by w / sqrt(2).
//!
//! Decimation keeps, in each pixel column of a series whose x never decreases, the first,
//! lowest, highest and last point in their original order: the drawn envelope is the same
//! as with every sample, at a few thousand points per curve whatever the record length.

/// A point (x, y) in data units.
pub type Point = (f64, f64);

/// The visible rectangle in data units, `x0 < x1`, `y0 < y1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub x0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y0: f64,
    /// Top edge.
    pub y1: f64,
}

/// Maximal runs of consecutive points where both x and y are finite (a NaN or infinity
/// breaks the line instead of being drawn).
pub fn finite_runs(x: &[f64], y: &[f64]) -> Vec<Vec<Point>> {
    let mut runs = Vec::new();
    let mut cur = Vec::new();
    for (&xi, &yi) in x.iter().zip(y) {
        if xi.is_finite() && yi.is_finite() {
            cur.push((xi, yi));
        } else if !cur.is_empty() {
            runs.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        runs.push(cur);
    }
    runs
}

/// Min/max decimation of `points` onto `columns` equal columns spanning `x0..x1`.
/// Returns the points unchanged when x ever decreases (an orbit) or when they are few.
/// Points outside `x0..x1` are dropped except the last one before and the first one
/// after the window, so the clipped line still reaches the window's edges.
pub fn decimate(points: &[Point], x0: f64, x1: f64, columns: usize) -> Vec<Point> {
    let monotone = points.windows(2).all(|w| w[1].0 >= w[0].0);
    if !monotone || points.len() <= 4 * columns || columns == 0 || x1 <= x0 {
        return points.to_vec();
    }
    let first_in = points.partition_point(|p| p.0 < x0);
    let end_in = points.partition_point(|p| p.0 <= x1);
    let mut out = Vec::with_capacity(4 * columns + 2);
    if first_in > 0 {
        out.push(points[first_in - 1]);
    }
    let width = (x1 - x0) / columns as f64;
    let mut i = first_in;
    while i < end_in {
        let col = ((points[i].0 - x0) / width).floor();
        let mut j = i;
        let (mut lo, mut hi) = (i, i);
        while j < end_in && ((points[j].0 - x0) / width).floor() == col {
            if points[j].1 < points[lo].1 {
                lo = j;
            }
            if points[j].1 > points[hi].1 {
                hi = j;
            }
            j += 1;
        }
        let mut keep = [i, lo, hi, j - 1];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for k in keep {
            if k != last {
                out.push(points[k]);
                last = k;
            }
        }
        i = j;
    }
    if end_in < points.len() {
        out.push(points[end_in]);
    }
    out
}

/// Coordinates further than this many rectangle sizes outside it are pulled in to it
/// before clipping, so that values near f64::MAX cannot overflow the arithmetic (the
/// visible part moves by less than 1e-6 of the rectangle).
const FAR: f64 = 1e6;

/// The part of segment `a`-`b` inside `r`, with flags telling whether the start and the
/// end were moved (the segment enters or leaves the rectangle). `None` if invisible.
pub fn clip_segment(a: Point, b: Point, r: &Rect) -> Option<(Point, Point, bool, bool)> {
    let (a, b) = (pull_in(a, r), pull_in(b, r));
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let p = [-dx, dx, -dy, dy];
    let q = [a.0 - r.x0, r.x1 - a.0, a.1 - r.y0, r.y1 - a.1];
    let (mut t_in, mut t_out) = (0.0f64, 1.0f64);
    for (pi, qi) in p.into_iter().zip(q) {
        if pi == 0.0 {
            if qi < 0.0 {
                return None; // parallel to this edge and outside it
            }
        } else {
            let t = qi / pi;
            if pi < 0.0 {
                t_in = t_in.max(t);
            } else {
                t_out = t_out.min(t);
            }
        }
    }
    if t_in > t_out {
        return None;
    }
    let at = |t: f64| (a.0 + t * dx, a.1 + t * dy);
    let start = if t_in > 0.0 { at(t_in) } else { a };
    let end = if t_out < 1.0 { at(t_out) } else { b };
    Some((start, end, t_in > 0.0, t_out < 1.0))
}

/// `p` with each coordinate limited to [`FAR`] rectangle sizes beyond the rectangle.
fn pull_in(p: Point, r: &Rect) -> Point {
    let (w, h) = (r.x1 - r.x0, r.y1 - r.y0);
    (
        p.0.clamp(r.x0 - FAR * w, r.x1 + FAR * w),
        p.1.clamp(r.y0 - FAR * h, r.y1 + FAR * h),
    )
}

/// Clip a polyline to `r`: the visible pieces, each a polyline of at least two points.
pub fn clip_polyline(points: &[Point], r: &Rect) -> Vec<Vec<Point>> {
    let mut pieces = Vec::new();
    let mut cur: Vec<Point> = Vec::new();
    let flush = |cur: &mut Vec<Point>, pieces: &mut Vec<Vec<Point>>| {
        if cur.len() >= 2 {
            pieces.push(std::mem::take(cur));
        } else {
            cur.clear();
        }
    };
    for w in points.windows(2) {
        match clip_segment(w[0], w[1], r) {
            None => flush(&mut cur, &mut pieces),
            Some((s, e, entered, left)) => {
                if entered || cur.is_empty() {
                    flush(&mut cur, &mut pieces);
                    cur.push(s);
                }
                cur.push(e);
                if left {
                    flush(&mut cur, &mut pieces);
                }
            }
        }
    }
    flush(&mut cur, &mut pieces);
    pieces
}

/// Cut `points` into strokes at every vertex where the direction turns by more than 90
/// degrees in pixel space (`sx`, `sy`: pixels per data unit on x and y); consecutive
/// strokes share the vertex.
pub fn split_at_sharp_turns(points: &[Point], sx: f64, sy: f64) -> Vec<Vec<Point>> {
    let mut strokes = Vec::new();
    let mut cur: Vec<Point> = Vec::new();
    let dir = |a: Point, b: Point| ((b.0 - a.0) * sx, (b.1 - a.1) * sy);
    for &p in points {
        if cur.len() >= 2 {
            let n = cur.len();
            let (d_in, d_out) = (dir(cur[n - 2], cur[n - 1]), dir(cur[n - 1], p));
            if d_in.0 * d_out.0 + d_in.1 * d_out.1 < 0.0 {
                let last = cur[n - 1];
                strokes.push(std::mem::replace(&mut cur, vec![last]));
            }
        }
        cur.push(p);
    }
    if cur.len() >= 2 {
        strokes.push(cur);
    }
    strokes
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: Rect = Rect {
        x0: 0.0,
        x1: 10.0,
        y0: -1.0,
        y1: 1.0,
    };

    #[test]
    fn nan_breaks_the_line() {
        let x = [0.0, 1.0, 2.0, 3.0, 4.0];
        let y = [1.0, f64::NAN, 2.0, 3.0, f64::INFINITY];
        assert_eq!(
            finite_runs(&x, &y),
            vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]
        );
    }

    #[test]
    fn a_spike_is_cut_at_the_top_edge() {
        // 0 -> 4 -> 0 crosses y = 1 at x = 1.25 and x = 2.75
        let pts = [(1.0, 0.0), (2.0, 4.0), (3.0, 0.0)];
        let pieces = clip_polyline(&pts, &R);
        assert_eq!(pieces.len(), 2);
        assert_eq!(pieces[0], vec![(1.0, 0.0), (1.25, 1.0)]);
        assert_eq!(pieces[1], vec![(2.75, 1.0), (3.0, 0.0)]);
    }

    #[test]
    fn a_segment_through_the_whole_box_is_cut_at_both_ends() {
        let (s, e, entered, left) = clip_segment((-10.0, 0.0), (20.0, 0.0), &R).unwrap();
        assert_eq!((s, e, entered, left), ((0.0, 0.0), (10.0, 0.0), true, true));
        assert!(clip_segment((-1.0, 5.0), (11.0, 5.0), &R).is_none());
        assert!(clip_segment((-2.0, 0.0), (-1.0, 0.5), &R).is_none());
    }

    #[test]
    fn huge_values_are_clipped_not_overflowed() {
        let pts = [(1.0, 0.0), (2.0, -1e300), (3.0, 0.5), (4.0, f64::MAX)];
        let pieces = clip_polyline(&pts, &R);
        // out through the bottom; back in through the bottom and out through the top
        assert_eq!(pieces.len(), 2);
        assert_eq!(pieces[1].len(), 3);
        for piece in &pieces {
            for p in piece {
                assert!(
                    p.0 >= R.x0 && p.0 <= R.x1 && p.1 >= R.y0 && p.1 <= R.y1,
                    "{p:?}"
                );
            }
        }
        // the cut is where the straight line to the (pulled-in) far point leaves the box
        assert!((pieces[0][1].0 - 1.0).abs() < 1e-5 && (pieces[0][1].1 + 1.0).abs() < 1e-12);
    }

    #[test]
    fn inside_polyline_is_kept_whole() {
        let pts: Vec<Point> = (0..10).map(|i| (i as f64, 0.1 * (i % 3) as f64)).collect();
        assert_eq!(clip_polyline(&pts, &R), vec![pts.clone()]);
    }

    #[test]
    fn decimation_keeps_the_envelope_and_the_edges() {
        let n = 100_000;
        let pts: Vec<Point> = (0..n)
            .map(|i| {
                let t = i as f64 / (n - 1) as f64;
                (t, (t * 2000.0).sin() * if i == 54_321 { 3.0 } else { 1.0 })
            })
            .collect();
        let d = decimate(&pts, 0.25, 0.75, 500);
        assert!(d.len() <= 4 * 500 + 2, "{} points", d.len());
        assert!(d.windows(2).all(|w| w[1].0 >= w[0].0));
        // the spike at sample 54321 (inside the window) survives
        assert!(d.contains(&pts[54_321]));
        // one point either side of the window
        assert!(d[0].0 < 0.25 && d[d.len() - 1].0 > 0.75);
        let max_in = |v: &[Point]| {
            v.iter()
                .filter(|p| p.0 >= 0.25 && p.0 <= 0.75)
                .map(|p| p.1)
                .fold(f64::MIN, f64::max)
        };
        assert_eq!(max_in(&d), max_in(&pts));
    }

    #[test]
    fn spikes_are_cut_into_strokes_that_turn_gently() {
        // up, down (spike), then on to the right: cut at the spike's tip only
        let pts = [(0.0, 0.0), (1.0, 0.0), (1.1, 10.0), (1.2, 0.0), (2.0, 0.0)];
        let strokes = split_at_sharp_turns(&pts, 1.0, 1.0);
        assert_eq!(strokes, vec![pts[..3].to_vec(), pts[2..].to_vec()]);
        // a smooth curve stays whole
        let arc: Vec<Point> = (0..50)
            .map(|i| ((i as f64 * 0.05).cos(), (i as f64 * 0.05).sin()))
            .collect();
        assert_eq!(split_at_sharp_turns(&arc, 1.0, 1.0).len(), 1);
    }

    #[test]
    fn orbits_are_not_decimated() {
        let pts: Vec<Point> = (0..5000)
            .map(|i| ((i as f64 * 0.01).cos(), (i as f64 * 0.01).sin()))
            .collect();
        assert_eq!(decimate(&pts, -1.0, 1.0, 100).len(), 5000);
    }
}
