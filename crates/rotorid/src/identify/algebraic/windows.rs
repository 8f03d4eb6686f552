//! Overlapping restarts of the algebraic identifier, for records of any length
//! (docs/method.md section 3.9).
//!
//! The 3x3 system A(t) theta = b(t) is built from iterated integrals weighted by
//! tau^2 = (t - t_0)^2: as tau grows its entries grow like tau^6 .. tau^8, noise and
//! round-off accumulate, and its conditioning degrades (on a 100 s record of table1 about
//! half of all instants are ill-conditioned and c first settles at 4.6 s). The method
//! needs no initial conditions, so restarting the integrals costs nothing but the settling
//! time. With a restart period of P = 2H samples, two identifiers run staggered by H:
//!
//! ```text
//! window j starts at sample j H and runs 2H samples;  identifier j mod 2 runs it
//! sample i reports window 0 for i < 2H, else window floor(i / H) - 1
//! ```
//!
//! so every reported estimate (after the first H samples) comes from a window between H
//! and 2H samples old: settled when H exceeds the settling time, and never older than P.
//! The estimate says which window it comes from ([`WindowedEstimate::window`]).
//! Without a period ([`RestartingIdentifier::new`] with `None`) it is the paper's single
//! identifier, bit for bit.

use super::config::AlgebraicConfig;
use super::cross::CrossAlgebraicIdentifier;
use super::cross_estimate::CrossAlgebraicEstimate;
use super::error::AlgebraicError;
use super::estimate::AlgebraicEstimate;
use super::identifier::AlgebraicIdentifier;
use crate::identify::{Known, Measurement};

/// A streaming algebraic identifier that can start over: the Jeffcott rotor's
/// ([`AlgebraicIdentifier`]) or the cross-coupled rotor's ([`CrossAlgebraicIdentifier`]).
pub trait Restartable: Clone {
    /// Its estimate at one sample.
    type Estimate: Copy;
    /// Take the next measurement (on an error nothing changes).
    fn push(&mut self, m: &Measurement) -> Result<Self::Estimate, AlgebraicError>;
    /// Start over: the next measurement becomes t_0.
    fn reset(&mut self);
}

impl Restartable for AlgebraicIdentifier {
    type Estimate = AlgebraicEstimate;
    #[inline]
    fn push(&mut self, m: &Measurement) -> Result<AlgebraicEstimate, AlgebraicError> {
        AlgebraicIdentifier::push(self, m)
    }
    fn reset(&mut self) {
        AlgebraicIdentifier::reset(self)
    }
}

impl Restartable for CrossAlgebraicIdentifier {
    type Estimate = CrossAlgebraicEstimate;
    #[inline]
    fn push(&mut self, m: &Measurement) -> Result<CrossAlgebraicEstimate, AlgebraicError> {
        CrossAlgebraicIdentifier::push(self, m)
    }
    fn reset(&mut self) {
        CrossAlgebraicIdentifier::reset(self)
    }
}

/// Fewest samples in a restart period: each window must hold at least two half-periods of
/// two samples (an estimate needs tau > 0).
pub const MIN_RESTART_SAMPLES: u64 = 4;

/// One estimate and the window it comes from (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowedEstimate<E = AlgebraicEstimate> {
    /// The estimate.
    pub estimate: E,
    /// Index of the window (0 = the one started at the first sample); always 0 without
    /// restarts.
    pub window: u64,
    /// Samples the window had seen before this one (its age, in samples).
    pub age: u64,
}

/// The algebraic identifier restarted on a schedule (module doc): the Jeffcott rotor's by
/// default, the cross-coupled rotor's with [`RestartingIdentifier::cross`].
#[derive(Debug, Clone)]
pub struct RestartingIdentifier<I: Restartable = AlgebraicIdentifier> {
    ids: [I; 2],
    /// Half the restart period \[samples\]; `None`: never restart.
    half: Option<u64>,
    /// Samples accepted.
    i: u64,
}

impl RestartingIdentifier {
    /// An identifier restarted every `period` samples (even, >= [`MIN_RESTART_SAMPLES`];
    /// `None`: never), for data sampled every `dt` \[s\] with `known` and `config`.
    pub fn new(
        known: Known,
        dt: f64,
        config: AlgebraicConfig,
        period: Option<u64>,
    ) -> Result<Self, AlgebraicError> {
        Self::of(AlgebraicIdentifier::new(known, dt, config)?, period)
    }
}

impl RestartingIdentifier<CrossAlgebraicIdentifier> {
    /// The cross-coupled identifier restarted every `period` samples, as
    /// [`RestartingIdentifier::new`].
    pub fn cross(
        known: Known,
        dt: f64,
        config: AlgebraicConfig,
        period: Option<u64>,
    ) -> Result<Self, AlgebraicError> {
        Self::of(CrossAlgebraicIdentifier::new(known, dt, config)?, period)
    }
}

impl<I: Restartable> RestartingIdentifier<I> {
    /// `id` restarted every `period` samples.
    fn of(id: I, period: Option<u64>) -> Result<Self, AlgebraicError> {
        let half = match period {
            Some(p) if p < MIN_RESTART_SAMPLES || p % 2 != 0 => {
                return Err(AlgebraicError::RestartPeriod {
                    samples: p,
                    min: MIN_RESTART_SAMPLES,
                })
            }
            Some(p) => Some(p / 2),
            None => None,
        };
        Ok(Self {
            ids: [id.clone(), id],
            half,
            i: 0,
        })
    }

    /// The restart period \[samples\], if any.
    pub fn period(&self) -> Option<u64> {
        self.half.map(|h| 2 * h)
    }

    /// Windows started so far.
    pub fn windows(&self) -> u64 {
        match self.half {
            Some(h) if self.i > 0 => (self.i - 1) / h + 1,
            _ => u64::from(self.i > 0),
        }
    }

    /// Take the next measurement; the estimate of the window that reports it (module doc).
    /// On an error (see [`AlgebraicIdentifier::push`]) nothing changes.
    pub fn push(
        &mut self,
        m: &Measurement,
    ) -> Result<WindowedEstimate<I::Estimate>, AlgebraicError> {
        let Some(h) = self.half else {
            let estimate = self.ids[0].push(m)?;
            self.i += 1;
            return Ok(WindowedEstimate {
                estimate,
                window: 0,
                age: self.i - 1,
            });
        };
        let i = self.i;
        // window `starting` begins at this sample (when i is a multiple of h)
        let starting = i.is_multiple_of(h).then_some(i / h);
        let reporting = if i < 2 * h { 0 } else { i / h - 1 };
        // the identifier that goes on (not restarted here) takes the sample first, so a
        // sample it refuses leaves both unchanged
        let fresh = starting.map(|j| (j % 2) as usize);
        let other = |k: usize| 1 - k;
        let mut out = None;
        match fresh {
            Some(k) => {
                if i > 0 {
                    let e = self.ids[other(k)].push(m)?;
                    if reporting % 2 == other(k) as u64 {
                        out = Some(e);
                    }
                }
                let mut restarted = self.ids[k].clone();
                restarted.reset();
                let e = restarted.push(m)?;
                self.ids[k] = restarted;
                if reporting % 2 == k as u64 || i == 0 {
                    out = out.or(Some(e));
                }
            }
            None => {
                // both run (after the first half-period), the reporting one first
                let r = (reporting % 2) as usize;
                let e = self.ids[r].push(m)?;
                if i > h {
                    // cannot fail where the reporting one accepted: same checks
                    self.ids[other(r)].push(m)?;
                }
                out = Some(e);
            }
        }
        self.i += 1;
        let estimate = out.expect("the reporting window took the sample");
        Ok(WindowedEstimate {
            estimate,
            window: reporting,
            age: i - reporting * h,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::algebraic::{Quadrature, SpeedModel};
    use crate::model::Scenario;
    use crate::simulate::{simulate, Method as SimMethod};

    fn config() -> AlgebraicConfig {
        AlgebraicConfig::new(Quadrature::default(), 1e-5, SpeedModel::General).unwrap()
    }

    fn measurements(duration: f64) -> (Known, f64, Vec<Measurement>) {
        let mut sc = Scenario::table1();
        sc.sampling = crate::model::Sampling::new(sc.sampling.dt(), duration).unwrap();
        let r = simulate(&sc, SimMethod::Exact).unwrap();
        let known = Known::from_rotor(&sc.rotor);
        let ms = (0..r.t.len())
            .map(|i| crate::identify::algebraic::measurement(&r, i))
            .collect();
        (known, sc.sampling.dt(), ms)
    }

    #[test]
    fn without_a_period_it_is_the_single_identifier() {
        let (known, dt, ms) = measurements(0.05);
        let mut a = RestartingIdentifier::new(known, dt, config(), None).unwrap();
        let mut b = AlgebraicIdentifier::new(known, dt, config()).unwrap();
        for m in &ms {
            let w = a.push(m).unwrap();
            let e = b.push(m).unwrap();
            assert_eq!(w.window, 0);
            assert_eq!(format!("{:?}", w.estimate), format!("{e:?}"));
        }
    }

    #[test]
    fn each_estimate_is_a_fresh_identifier_started_at_its_window() {
        // Reference: for every reported sample, an identifier started at the window's
        // first sample and fed up to it gives the same estimate bit for bit.
        let (known, dt, ms) = measurements(0.02);
        let period = 40;
        let h = period / 2;
        let mut w = RestartingIdentifier::new(known, dt, config(), Some(period)).unwrap();
        let got: Vec<WindowedEstimate> = ms.iter().map(|m| w.push(m).unwrap()).collect();
        for (i, g) in got.iter().enumerate() {
            let i = i as u64;
            let expected_window = if i < 2 * h { 0 } else { i / h - 1 };
            assert_eq!(g.window, expected_window, "sample {i}");
            let start = g.window * h;
            assert_eq!(g.age, i - start);
            let mut fresh = AlgebraicIdentifier::new(known, dt, config()).unwrap();
            let mut e = None;
            for m in &ms[start as usize..=i as usize] {
                e = Some(fresh.push(m).unwrap());
            }
            assert_eq!(
                format!("{:?}", e.unwrap()),
                format!("{:?}", g.estimate),
                "sample {i}"
            );
        }
        assert_eq!(w.windows(), (ms.len() as u64 - 1) / h + 1);
    }

    #[test]
    fn a_refused_sample_changes_nothing() {
        let (known, dt, ms) = measurements(0.01);
        let mut w = RestartingIdentifier::new(known, dt, config(), Some(8)).unwrap();
        let mut reference = w.clone();
        for (n, m) in ms.iter().enumerate() {
            let mut bad = *m;
            bad.x = f64::NAN;
            assert!(w.push(&bad).is_err(), "sample {n}");
            let a = w.push(m).unwrap();
            let b = reference.push(m).unwrap();
            assert_eq!(format!("{a:?}"), format!("{b:?}"));
        }
    }

    #[test]
    fn periods_too_short_or_odd_are_refused() {
        let (known, dt, _) = measurements(0.001);
        for p in [0, 2, 3, 7] {
            let e = RestartingIdentifier::new(known, dt, config(), Some(p)).unwrap_err();
            assert!(e.to_string().contains(&p.to_string()), "{e}");
        }
    }
}
