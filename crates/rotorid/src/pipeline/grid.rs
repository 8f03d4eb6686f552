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
//!
//! Each stamp must lie within `tolerance dt` of the fitted grid, plus the stamps'
//! rounding: stamps printed with d decimals (25.6 kHz written to 6 decimals, as acquisition
//! software does) are up to half a unit of the d-th decimal off the grid they were
//! rounded from, and the least-squares grid of rounded stamps is itself off that grid by
//! their mean rounding error (at most another half unit; 1/32 of a unit at 25.6 kHz), so
//! a stamp may be one unit of the stamps' last decimal, [`TimeGrid::resolution`], off the
//! fitted grid, at most a quarter of dt. The decimals are read from the values, whatever
//! the file format: the fewest d (up to [`MAX_STAMP_DECIMALS`]) with t 10^d a whole number
//! to rounding, the most over the stamps ([`stamp_decimals`]). Stamps whose values have
//! more decimals (computed as i dt, or binary) get no such allowance; jitter, gaps and
//! non-uniform sampling are refused as before.

use super::error::PipelineError;

/// Relative distance within which the fitted dt is replaced by the shortest decimal
/// (the fit of exact stamps is accurate to a few ulps: its sums are compensated).
pub const SNAP_DT: f64 = 4.0 * f64::EPSILON;
/// Distance, relative to dt, within which the fitted t0 is replaced by the first stamp.
pub const SNAP_T0: f64 = 1e-9;
/// Default allowed deviation of a stamp from the grid, relative to dt (besides the
/// stamps' rounding, module doc).
pub const DEFAULT_TIME_TOLERANCE: f64 = 1e-6;
/// Most decimals a stamp's value is read with (module doc): stamps with more count as
/// exact (no rounding allowance).
pub const MAX_STAMP_DECIMALS: u32 = 12;
/// Largest rounding allowance, relative to dt: coarser stamps cannot tell a gap or jitter
/// from rounding.
pub const MAX_ROUNDING_ALLOWANCE: f64 = 0.25;

/// 10^d, exact, d = 0 ..= [`MAX_STAMP_DECIMALS`].
const POW10: [f64; MAX_STAMP_DECIMALS as usize + 1] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12,
];

/// Whether `s` is a whole number to within 4 ulp, and small enough (|s| < 2^49) for that
/// to mean something.
#[inline(always)]
fn whole(s: f64) -> bool {
    s.abs() < (1u64 << 49) as f64 && (s - s.round()).abs() <= 4.0 * f64::EPSILON * s.abs()
}

/// The decimals the stamp `t` \[s\] is printed with, read from its value: the fewest
/// d <= [`MAX_STAMP_DECIMALS`] with t 10^d a whole number to within rounding (the value a
/// reader parses from `0.000313` gives 6); `None` when there is none (a stamp computed as
/// i dt, or a binary one).
pub fn stamp_decimals(t: f64) -> Option<u32> {
    (0..=MAX_STAMP_DECIMALS).find(|&d| whole(t * POW10[d as usize]))
}

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
    /// The stamps' resolution \[s\]: one unit of the last decimal they are printed with
    /// (module doc); 0 when they have more than [`MAX_STAMP_DECIMALS`] (or for a given
    /// grid).
    #[serde(default)]
    pub resolution: f64,
    /// Whether a stamp needed the rounding allowance: it was more than `tolerance dt` off
    /// the grid, and within the rounding of its resolution.
    #[serde(default)]
    pub rounded: bool,
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
            resolution: 0.0,
            rounded: false,
        })
    }

    /// The least-squares grid of the stamps `t` (module doc), checked: at least two
    /// stamps, finite, strictly increasing, each within `tolerance dt` of the grid (plus
    /// the rounding of the stamps' resolution).
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
        let (_, rounded) = grid.check_rounded(worst.1, t[worst.1], tolerance, grid.resolution)?;
        Ok(TimeGrid {
            max_deviation: worst.0,
            rounded,
            ..grid
        })
    }

    /// The note ([`Finding::TimeStampsRounded`](super::Finding::TimeStampsRounded)) of a
    /// grid whose stamps needed the rounding allowance (module doc), `None` otherwise.
    pub fn rounding_note(&self) -> Option<super::Diagnostic> {
        self.rounded
            .then(|| super::rounded_stamps_note(self.resolution, self.max_deviation, self.dt))
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
        within(i, t, self.time(i), self.dt, tolerance, 0.0, 0.0).map(|(d, _)| d)
    }

    /// [`check`](Self::check) with the rounding allowance of stamps of resolution
    /// `resolution` \[s\] (module doc): the deviation \[s\], and whether the allowance was
    /// needed.
    #[inline]
    pub fn check_rounded(
        &self,
        i: usize,
        t: f64,
        tolerance: f64,
        resolution: f64,
    ) -> Result<(f64, bool), PipelineError> {
        // a given grid is the one the stamps were rounded from: half a unit
        let rounding = if self.fitted_over == 0 {
            0.5 * rounding_allowance(resolution, self.dt)
        } else {
            rounding_allowance(resolution, self.dt)
        };
        within(i, t, self.time(i), self.dt, tolerance, resolution, rounding)
    }
}

/// The deviation |t - expected| \[s\] of stamp `t` of sample `index` when it is within
/// `tolerance dt` plus 8 ulp of the larger of t and `expected`, plus `rounding` \[s\] for
/// stamps of resolution `resolution` \[s\] (module doc), else the error naming the
/// sample; and whether the rounding allowance was needed. The one test of
/// [`TimeGrid::check`], [`TimeGrid::fit`] and [`RunningGrid::check_newest`].
#[inline(always)]
fn within(
    index: usize,
    t: f64,
    expected: f64,
    dt: f64,
    tolerance: f64,
    resolution: f64,
    rounding: f64,
) -> Result<(f64, bool), PipelineError> {
    let deviation = (t - expected).abs();
    let allowed = tolerance * dt + 8.0 * f64::EPSILON * t.abs().max(expected.abs());
    if deviation <= allowed {
        Ok((deviation, false))
    } else {
        rounded(
            index, t, deviation, allowed, dt, tolerance, resolution, rounding,
        )
    }
}

/// The stamp beyond `tolerance`: within the rounding allowance, or the error naming it.
#[cold]
#[allow(clippy::too_many_arguments)]
fn rounded(
    index: usize,
    t: f64,
    deviation: f64,
    allowed: f64,
    dt: f64,
    tolerance: f64,
    resolution: f64,
    rounding: f64,
) -> Result<(f64, bool), PipelineError> {
    if deviation <= allowed + rounding {
        Ok((deviation, true))
    } else {
        Err(PipelineError::NonUniformSampling {
            index,
            t,
            deviation,
            dt,
            tolerance,
            resolution,
            rounding,
        })
    }
}

/// How far a stamp of resolution `resolution` \[s\] may be off the least-squares grid of
/// period `dt` by rounding alone (module doc): one unit, at most
/// [`MAX_ROUNDING_ALLOWANCE`] dt (off a given grid, half that).
pub fn rounding_allowance(resolution: f64, dt: f64) -> f64 {
    resolution.min(MAX_ROUNDING_ALLOWANCE * dt)
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
    /// The most decimals of the stamps so far ([`stamp_decimals`]), or
    /// [`NO_DECIMALS`] when one has more than [`MAX_STAMP_DECIMALS`].
    decimals: u32,
}

/// [`RunningGrid`]'s mark of stamps with more decimals than it reads.
const NO_DECIMALS: u32 = u32::MAX;

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
        // one multiplication per stamp while they keep their decimals
        if self.decimals != NO_DECIMALS && !whole(t * POW10[self.decimals as usize]) {
            self.decimals = stamp_decimals(t).map_or(NO_DECIMALS, |d| d.max(self.decimals));
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

    /// The stamps' resolution so far \[s\] ([`TimeGrid::resolution`]): 0 before the first
    /// stamp and when one has more than [`MAX_STAMP_DECIMALS`] decimals.
    pub fn resolution(&self) -> f64 {
        if self.n == 0 || self.decimals == NO_DECIMALS {
            0.0
        } else {
            1.0 / POW10[self.decimals as usize]
        }
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
            resolution: self.resolution(),
            rounded: false,
        })
    }

    /// The newest stamp checked against the least-squares fit of every stamp so far
    /// (what a stream checks each stamp against): its deviation |t - (t0 + (n - 1) dt)|
    /// \[s\] when within `tolerance dt` (plus 8 ulp of t, plus the rounding of the stamps'
    /// resolution so far, module doc), `None` before two stamps.
    /// The fit is [`fit`](Self::fit)'s to rounding, written so that its two divisions do
    /// not wait for each other: `dt = (n S_iu - S_i S_u) / (n^2 (n^2 - 1) / 12)` (the
    /// denominator is n S_ii - S_i^2 in closed form) and, as S_i = n (n - 1) / 2,
    /// `t0 + (n - 1) dt = t_first + S_u / n + dt (n - 1) / 2`.
    #[inline(always)]
    pub fn check_newest(&self, tolerance: f64) -> Result<Option<f64>, PipelineError> {
        Ok(self.check_newest_rounded(tolerance)?.map(|(d, _)| d))
    }

    /// [`check_newest`](Self::check_newest), and whether the stamp needed the rounding
    /// allowance.
    #[inline(always)]
    pub fn check_newest_rounded(
        &self,
        tolerance: f64,
    ) -> Result<Option<(f64, bool)>, PipelineError> {
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
        let resolution = self.resolution();
        within(
            self.n - 1,
            self.last,
            expected,
            dt,
            tolerance,
            resolution,
            rounding_allowance(resolution, dt),
        )
        .map(Some)
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
            resolution: self.resolution(),
            rounded: false,
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
        // rounding exceeds 1e-6 dt: without the rounding allowance this is refused
        let bare = TimeGrid::fit(&t, 0.02).unwrap();
        assert_eq!((bare.resolution, bare.rounded), (1e-6, false));
        let g = TimeGrid::fit(&t, 1e-6).unwrap();
        assert_eq!((g.resolution, g.rounded), (1e-6, true));
        assert_eq!((g.dt, g.t0), (bare.dt, bare.t0));
        // the largest deviation from the fitted grid: half a unit and the mean rounding
        // error (1/32 of a unit here), more than half a unit
        assert!(g.max_deviation > 0.5e-6, "{}", g.max_deviation);
        // statistically: std = 0.29 us sqrt(12 / n^3) = 2.4e-13 s = 6e-9 dt
        assert!((g.dt - dt).abs() < 5e-8 * dt, "dt {} vs {dt}", g.dt);
        // rounding moves a stamp by <= 0.5 us; the fitted line is not the true one
        assert!(g.max_deviation <= 0.6e-6, "{}", g.max_deviation);
        // the first two stamps would have said 3.9e-5 s, 0.16 % off
        assert!(((t[1] - t[0]) - dt).abs() > 1e-3 * dt);
    }

    /// Deterministic jitter: a xorshift draw per stamp, uniform in [-1, 1).
    fn draws(n: usize) -> Vec<f64> {
        let mut s: u64 = 0x2545_F491_4F6C_DD1D;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    #[test]
    fn rounded_stamps_are_accepted_and_jitter_gaps_and_rate_changes_are_not() {
        let dt = 1.0 / 25600.0;
        let round6 = |t: f64| (t * 1e6).round() / 1e6;
        let n = 25600;
        let exact = |i: usize| i as f64 * dt;
        let check = |t: &[f64]| {
            let batch = TimeGrid::fit(t, DEFAULT_TIME_TOLERANCE);
            // the stream: every stamp against the fit of those before it
            let mut g = RunningGrid::default();
            let mut stream = Ok(());
            for (i, &ti) in t.iter().enumerate() {
                g.push(i, ti).unwrap();
                if let Err(e) = g.check_newest(DEFAULT_TIME_TOLERANCE) {
                    stream = Err(e);
                    break;
                }
            }
            assert_eq!(
                batch.is_ok(),
                stream.is_ok(),
                "batch {batch:?}, stream {stream:?}"
            );
            batch
        };
        // 6 decimals, and 7 at 102.4 kHz
        let g = check(&(0..n).map(|i| round6(exact(i))).collect::<Vec<_>>()).unwrap();
        assert!(g.rounded && g.resolution == 1e-6 && (g.dt - dt).abs() < 1e-8 * dt);
        let dt7 = 1.0 / 102_400.0;
        let t7: Vec<f64> = (0..n)
            .map(|i| (i as f64 * dt7 * 1e7).round() / 1e7)
            .collect();
        let g7 = check(&t7).unwrap();
        assert!(g7.rounded && g7.resolution == 1e-7, "{g7:?}");
        // exact stamps need no allowance
        let g0 = check(&(0..n).map(exact).collect::<Vec<_>>()).unwrap();
        assert!(!g0.rounded && g0.max_deviation < 1e-12);
        // 2 % jitter, uniform and (nearly) Gaussian, printed with 6 decimals: refused
        let u = draws(4 * n);
        let uniform: Vec<f64> = (0..n)
            .map(|i| round6(exact(i) + 0.02 * dt * u[i]))
            .collect();
        let gauss: Vec<f64> = (0..n)
            .map(|i| {
                // sum of 3 uniforms, scaled to unit variance
                let g = (u[n + i] + u[2 * n + i] + u[3 * n + i]) / 1.0;
                round6(exact(i) + 0.02 * dt * g)
            })
            .collect();
        for (name, t) in [("uniform", uniform), ("gaussian", gauss)] {
            match check(&t) {
                Err(PipelineError::NonUniformSampling {
                    tolerance,
                    resolution,
                    ..
                }) => assert_eq!((tolerance, resolution), (1e-6, 1e-6), "{name}"),
                other => panic!("{name}: {other:?}"),
            }
        }
        // a missing sample, and a rate that changes half-way
        let mut gap: Vec<f64> = (0..n).map(|i| round6(exact(i))).collect();
        gap.remove(n / 2);
        assert!(check(&gap).is_err());
        let change: Vec<f64> = (0..n)
            .map(|i| {
                round6(if i < n / 2 {
                    exact(i)
                } else {
                    exact(i) * 1.001
                })
            })
            .collect();
        assert!(check(&change).is_err());
        // the message says what was allowed
        let e = check(&gap).unwrap_err().to_string();
        assert!(
            e.contains("plus 1e-6 s for stamps printed to 1e-6 s"),
            "{e}"
        );
        // off a given grid, half a unit
        let given = TimeGrid::given(0.0, dt).unwrap();
        assert!(given
            .check_rounded(7, 7.0 * dt + 0.45e-6, 0.0, 1e-6)
            .is_ok());
        assert!(given
            .check_rounded(7, 7.0 * dt + 0.55e-6, 0.0, 1e-6)
            .is_err());
    }

    #[test]
    fn stamp_decimals_are_read_from_the_values() {
        for (t, d) in [
            (0.0, Some(0)),
            (0.000313, Some(6)),
            (1.5, Some(1)),
            (12.000001, Some(6)),
            (3.90625e-5, Some(10)),
            (1700000000.25, Some(2)),
            // 3 dt computed (0.00030000000000000003) is 0.0003 to within an ulp: exact
            // stamps of a decimal dt look printed with dt's decimals, which costs nothing,
            // as they lie on the grid
            (3.0 * 1e-4, Some(4)),
            (1.0 / 3.0, None),
            (0.123456789012345, None),
        ] {
            assert_eq!(stamp_decimals(t), d, "{t}");
        }
        let mut g = RunningGrid::default();
        for (i, t) in [0.0, 0.5, 0.500039, 0.500078].into_iter().enumerate() {
            g.push(i, t).unwrap();
        }
        assert_eq!(g.resolution(), 1e-6);
        g.push(4, 0.500_117_123_456_789).unwrap();
        assert_eq!(g.resolution(), 0.0);
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
