//! The time grid of a record: t_i = t0 + i dt, fitted by least squares over every time
//! stamp (docs/method.md section 6.2), so stamps printed with few decimals (25.6 kHz
//! written to 6 decimals) give the true period, not the difference of the first two.
//!
//! With u_i = t_i - t_first and i = 0 .. n-1,
//!
//! ```text
//! dt = (n S_iu - S_i S_u) / (n S_ii - S_i^2),   t0 = t_first + (S_u - dt S_i) / n
//! ```
//!
//! (S_i, S_ii in closed form). The fit is then snapped to the value the stamps were written
//! from when it is that value to rounding: dt to the shortest decimal within 4 ulp, t0
//! to the first stamp when within [`SNAP_T0`] dt. Exact stamps t_i = i dt thus give dt
//! itself, bit for bit. [`RunningGrid`] is the same fit updated sample by sample, for
//! streams.

use super::error::PipelineError;

/// Relative distance within which the fitted dt is replaced by the shortest decimal
/// (the fit of exact stamps is accurate to a few ulps: its sums are compensated).
pub const SNAP_DT: f64 = 4.0 * f64::EPSILON;
/// Distance, relative to dt, within which the fitted t0 is replaced by the first stamp.
pub const SNAP_T0: f64 = 1e-9;
/// Default allowed deviation of a stamp from the grid, relative to dt.
pub const DEFAULT_TIME_TOLERANCE: f64 = 1e-6;

/// A uniform time grid t_i = t0 + i dt \[s\], and how well the stamps fit it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TimeGrid {
    /// Time of sample 0 \[s\].
    pub t0: f64,
    /// Sampling period \[s\], > 0.
    pub dt: f64,
    /// Stamps the grid was fitted over (0 when dt was given).
    pub fitted_over: usize,
    /// Largest |t_i - (t0 + i dt)| over those stamps \[s\].
    pub max_deviation: f64,
}

impl TimeGrid {
    /// A given grid (no stamps): `dt` finite and > 0, `t0` finite.
    pub fn given(t0: f64, dt: f64) -> Result<Self, PipelineError> {
        crate::model::check("dt", dt, "finite and > 0 (s)", |v| v > 0.0)?;
        crate::model::check("t0", t0, "finite (s)", |_| true)?;
        Ok(Self {
            t0,
            dt,
            fitted_over: 0,
            max_deviation: 0.0,
        })
    }

    /// The least-squares grid of the stamps `t` (module doc), checked: at least two
    /// stamps, finite, strictly increasing, each within `tolerance dt` of the grid.
    pub fn fit(t: &[f64], tolerance: f64) -> Result<Self, PipelineError> {
        check_tolerance(tolerance)?;
        let mut g = RunningGrid::default();
        for (i, &ti) in t.iter().enumerate() {
            g.push(i, ti)?;
        }
        let grid = g.grid().ok_or(PipelineError::TooFewSamples {
            samples: t.len(),
            needed: 2,
            method: "the time grid",
            why: "two stamps give the sampling period",
        })?;
        let mut worst = (0.0_f64, 0);
        for (i, &ti) in t.iter().enumerate() {
            let d = (ti - grid.time(i)).abs();
            if d > worst.0 {
                worst = (d, i);
            }
        }
        let grid = TimeGrid {
            max_deviation: worst.0,
            ..grid
        };
        grid.check(worst.1, t[worst.1], tolerance)?;
        Ok(grid)
    }

    /// t0 + i dt \[s\].
    #[inline]
    pub fn time(&self, i: usize) -> f64 {
        self.t0 + i as f64 * self.dt
    }

    /// Stamp `t` of sample `i` against the grid: its deviation \[s\] when within
    /// `tolerance dt` (plus 8 ulp of t) of t0 + i dt, else the error naming the sample.
    #[inline]
    pub fn check(&self, i: usize, t: f64, tolerance: f64) -> Result<f64, PipelineError> {
        within(i, t, self.time(i), self.dt, tolerance)
    }
}

/// The deviation |t - expected| \[s\] of stamp `t` of sample `index` when it is within
/// `tolerance dt` plus 8 ulp of the larger of t and `expected`, else the error naming the
/// sample: the one test of both [`TimeGrid::check`] and [`RunningGrid::check_newest`].
#[inline(always)]
fn within(
    index: usize,
    t: f64,
    expected: f64,
    dt: f64,
    tolerance: f64,
) -> Result<f64, PipelineError> {
    let deviation = (t - expected).abs();
    let allowed = tolerance * dt + 8.0 * f64::EPSILON * t.abs().max(expected.abs());
    if deviation <= allowed {
        Ok(deviation)
    } else {
        Err(off_grid(index, t, deviation, dt, tolerance))
    }
}

/// The error of stamp `t` of sample `index`, `deviation` \[s\] off a grid of period `dt`.
#[cold]
fn off_grid(index: usize, t: f64, deviation: f64, dt: f64, tolerance: f64) -> PipelineError {
    PipelineError::NonUniformSampling {
        index,
        t,
        deviation,
        dt,
        tolerance,
    }
}

/// The tolerance must be finite and >= 0.
pub(crate) fn check_tolerance(tolerance: f64) -> Result<(), PipelineError> {
    crate::model::check(
        "time_tolerance",
        tolerance,
        "finite and >= 0 (relative to dt)",
        |v| v >= 0.0,
    )?;
    Ok(())
}

/// The least-squares grid of the stamps pushed so far (module doc), in O(1) memory.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RunningGrid {
    n: usize,
    first: f64,
    last: f64,
    /// sum of u_i = t_i - t_first (compensated)
    s_u: Compensated,
    /// sum of i u_i (compensated)
    s_iu: Compensated,
}

/// A sum with Neumaier's compensation: accurate to a few ulps whatever the number of
/// terms.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Compensated {
    sum: f64,
    c: f64,
}

impl Compensated {
    fn add(&mut self, v: f64) {
        let t = self.sum + v;
        if self.sum.abs() >= v.abs() {
            self.c += (self.sum - t) + v;
        } else {
            self.c += (v - t) + self.sum;
        }
        self.sum = t;
    }

    fn value(&self) -> f64 {
        self.sum + self.c
    }
}

impl RunningGrid {
    /// Add stamp `t` of sample `index` (= the number pushed before): finite and after the
    /// previous one.
    pub fn push(&mut self, index: usize, t: f64) -> Result<(), PipelineError> {
        if !t.is_finite() {
            return Err(PipelineError::NotFinite {
                index,
                field: "t",
                value: t,
            });
        }
        if self.n > 0 && t.partial_cmp(&self.last) != Some(std::cmp::Ordering::Greater) {
            return Err(PipelineError::NotIncreasing {
                index,
                t,
                previous: self.last,
            });
        }
        if self.n == 0 {
            self.first = t;
        }
        let u = t - self.first;
        self.s_u.add(u);
        self.s_iu.add(self.n as f64 * u);
        self.last = t;
        self.n += 1;
        if !(self.s_u.value().is_finite() && self.s_iu.value().is_finite()) {
            return Err(PipelineError::NotFinite {
                index,
                field: "t",
                value: t,
            });
        }
        Ok(())
    }

    /// Stamps pushed.
    pub fn len(&self) -> usize {
        self.n
    }

    /// True before the first stamp.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The least-squares fit as it stands, not snapped: (t0, dt) \[s\]; cheap enough to
    /// check every stamp of a stream against.
    pub fn fit(&self) -> Option<TimeGrid> {
        if self.n < 2 {
            return None;
        }
        let n = self.n as f64;
        let s_i = n * (n - 1.0) / 2.0;
        let s_ii = (n - 1.0) * n * (2.0 * n - 1.0) / 6.0;
        let (s_u, s_iu) = (self.s_u.value(), self.s_iu.value());
        // centred: sum (i - mean i)(u_i - mean u) / sum (i - mean i)^2
        let dt = (s_iu - s_i * s_u / n) / (s_ii - s_i * s_i / n);
        self.grid_with(dt, s_i, s_u)
    }

    /// The grid of slope `dt` through the stamps' centroid, `None` unless `dt` is finite
    /// and > 0.
    #[inline]
    fn grid_with(&self, dt: f64, s_i: f64, s_u: f64) -> Option<TimeGrid> {
        if !(dt.is_finite() && dt > 0.0) {
            return None;
        }
        Some(TimeGrid {
            t0: self.first + (s_u - dt * s_i) / self.n as f64,
            dt,
            fitted_over: self.n,
            max_deviation: 0.0,
        })
    }

    /// The newest stamp checked against the least-squares fit of every stamp so far
    /// (what a stream checks each stamp against): its deviation |t - (t0 + (n - 1) dt)|
    /// \[s\] when within `tolerance dt` (plus 8 ulp of t), `None` before two stamps.
    /// The fit is [`fit`](Self::fit)'s to rounding, written so that its two divisions do
    /// not wait for each other: `dt = (n S_iu - S_i S_u) / (n^2 (n^2 - 1) / 12)` (the
    /// denominator is n S_ii - S_i^2 in closed form) and, as S_i = n (n - 1) / 2,
    /// `t0 + (n - 1) dt = t_first + S_u / n + dt (n - 1) / 2`.
    #[inline(always)]
    pub fn check_newest(&self, tolerance: f64) -> Result<Option<f64>, PipelineError> {
        if self.n < 2 {
            return Ok(None);
        }
        let n = self.n as f64;
        let s_i = n * (n - 1.0) * 0.5;
        let (s_u, s_iu) = (self.s_u.value(), self.s_iu.value());
        let n2 = n * n;
        let dt = (n * s_iu - s_i * s_u) / (n2 * (n2 - 1.0) * (1.0 / 12.0));
        if !(dt.is_finite() && dt > 0.0) {
            return Ok(None);
        }
        let expected = self.first + (s_u / n + dt * ((n - 1.0) * 0.5));
        within(self.n - 1, self.last, expected, dt, tolerance).map(Some)
    }

    /// The fitted grid (snapped, module doc), `None` before two stamps; `max_deviation`
    /// is 0 (a stream cannot revisit its stamps).
    pub fn grid(&self) -> Option<TimeGrid> {
        let raw = self.fit()?;
        let n = self.n as f64;
        let s_i = n * (n - 1.0) / 2.0;
        let s_u = self.s_u.value();
        let dt = snap_dt(raw.dt);
        let offset = (s_u - dt * s_i) / n;
        let t0 = if offset.abs() <= SNAP_T0 * dt {
            self.first
        } else {
            self.first + offset
        };
        Some(TimeGrid {
            t0,
            dt,
            fitted_over: self.n,
            max_deviation: 0.0,
        })
    }
}

/// The shortest decimal within [`SNAP_DT`] of `dt`, else `dt`.
fn snap_dt(dt: f64) -> f64 {
    for digits in 0..17 {
        if let Ok(v) = format!("{dt:.digits$e}").parse::<f64>() {
            if (v - dt).abs() <= SNAP_DT * dt {
                return v;
            }
        }
    }
    dt
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_stamps_give_dt_bit_for_bit() {
        for dt in [1e-4, 3.90625e-5, 2e-5, 1.0 / 3.0e4] {
            let t: Vec<f64> = (0..5000).map(|i| i as f64 * dt).collect();
            let g = TimeGrid::fit(&t, 0.0).unwrap();
            assert_eq!(g.t0, 0.0);
            // 1/3e4 has no short decimal: within a few ulps, and every stamp on the grid
            // (tolerance 0 above)
            assert!(
                (g.dt - dt).abs() <= 8.0 * f64::EPSILON * dt,
                "{dt} -> {}",
                g.dt
            );
            if dt != 1.0 / 3.0e4 {
                assert_eq!(g.dt, dt);
            }
        }
    }

    #[test]
    fn rounded_stamps_give_the_true_period() {
        // 25.6 kHz written with 6 decimals: each stamp off by up to 0.5 us = 0.0128 dt.
        let dt = 1.0 / 25600.0;
        let t: Vec<f64> = (0..25600)
            .map(|i| (i as f64 * dt * 1e6).round() / 1e6)
            .collect();
        assert!(TimeGrid::fit(&t, 1e-6).is_err(), "rounding exceeds 1e-6 dt");
        let g = TimeGrid::fit(&t, 0.02).unwrap();
        // statistically: std = 0.29 us sqrt(12 / n^3) = 2.4e-13 s = 6e-9 dt
        assert!((g.dt - dt).abs() < 5e-8 * dt, "dt {} vs {dt}", g.dt);
        // rounding moves a stamp by <= 0.5 us; the fitted line is not the true one
        assert!(g.max_deviation <= 0.6e-6, "{}", g.max_deviation);
        // the first two stamps would have said 3.9e-5 s, 0.16 % off
        assert!(((t[1] - t[0]) - dt).abs() > 1e-3 * dt);
    }

    /// The stream's check of the newest stamp measures its deviation from the fit, to
    /// rounding, from two stamps to a million, with exact, jittered and offset stamps
    /// (a Unix time base among them).
    #[test]
    fn the_newest_stamp_is_checked_against_the_fit() {
        for (t0, dt, jitter) in [
            (0.0, 1e-4, 0.0),
            (1.7e9, 3.90625e-5, 0.0),
            (12.5, 2e-5, 0.3),
        ] {
            let mut g = RunningGrid::default();
            for i in 0..1_000_000usize {
                let wobble = jitter * dt * ((i as f64 * 0.37).sin());
                let t = t0 + i as f64 * dt + wobble;
                g.push(i, t).unwrap();
                if i >= 1 && (i.is_power_of_two() || i % 99_991 == 0) {
                    let fit = g.fit().unwrap();
                    let exact = (t - fit.time(i)).abs();
                    let d = g.check_newest(0.5).unwrap().unwrap();
                    // within rounding of the stamps' size (ulp(1.7e9) = 2.4e-7 s)
                    let ulp = 4.0 * f64::EPSILON * t.abs();
                    assert!((d - exact).abs() <= 1e-9 * dt + ulp, "{i}: {d} {exact}");
                }
            }
            // a stamp half a period off is refused, with its index and deviation
            let i = g.len();
            g.push(i, t0 + (i as f64 + 0.5) * dt).unwrap();
            match g.check_newest(1e-3) {
                Err(PipelineError::NonUniformSampling {
                    index, deviation, ..
                }) => {
                    assert_eq!(index, i);
                    assert!((deviation - 0.5 * dt).abs() < 1e-3 * dt, "{deviation}");
                }
                other => panic!("{other:?}"),
            }
        }
        assert_eq!(RunningGrid::default().check_newest(0.0).unwrap(), None);
    }

    #[test]
    fn bad_stamps_are_named() {
        assert!(matches!(
            TimeGrid::fit(&[0.0, 1.0, f64::INFINITY], 1e-6),
            Err(PipelineError::NotFinite { index: 2, .. })
        ));
        assert!(matches!(
            TimeGrid::fit(&[0.0, 1.0, 1.0], 1e-6),
            Err(PipelineError::NotIncreasing { index: 2, .. })
        ));
        assert!(matches!(
            TimeGrid::fit(&[0.0, 1.0, 2.0, 3.5, 4.0], 1e-6),
            Err(PipelineError::NonUniformSampling { index: 3, .. })
        ));
        assert!(matches!(
            TimeGrid::fit(&[0.0], 1e-6),
            Err(PipelineError::TooFewSamples { samples: 1, .. })
        ));
        // an infinite step: finite stamps whose difference overflows
        assert!(TimeGrid::fit(&[-1e308, 1e308, 1.7e308], 1e-6).is_err());
    }
}
