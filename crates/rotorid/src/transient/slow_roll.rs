//! Slow-roll compensation (docs/transient.md section 3): the runout a probe reads at slow
//! roll (the shaft's surface and electrical runout, fixed to the shaft) is one vector per
//! order, the same at every speed; it is subtracted from every revolution's vector,
//! `V_comp = V - V_sr`, with variances added, `std_comp^2 = std^2 + std_sr^2`.
//!
//! The runout vector is the mean of the vectors of the slow-roll revolutions, weighted by
//! their inverse variances. Its standard deviation is the larger of that mean's (from
//! each revolution's noise) and the scatter of the revolutions' vectors over sqrt(count)
//! (speed jitter, or a small dynamic response that changes over the range, shows there).

use serde::Serialize;

use super::error::TransientError;
use super::order::{Revolution, Tracked, C64};
use crate::model::OutOfRange;

/// The fewest revolutions of an automatic slow-roll range.
pub const AUTO_MIN_REVOLUTIONS: usize = 8;
/// The automatic range reaches this fraction above the lowest speed ...
pub const AUTO_RELATIVE: f64 = 0.15;
/// ... or this fraction of the speed span, whichever is larger.
pub const AUTO_SPAN: f64 = 0.03;

/// Where the runout vector comes from.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum SlowRollSource {
    /// A slow-roll record (its file as given).
    Record {
        /// The file.
        file: String,
    },
    /// The revolutions of the record in a speed range given by the user \[rev/min\].
    Range {
        /// Lowest speed \[rev/min\].
        min_rpm: f64,
        /// Highest speed \[rev/min\].
        max_rpm: f64,
    },
    /// The revolutions of the record in a range picked by [`auto_range`] \[rev/min\].
    Auto {
        /// Lowest speed \[rev/min\].
        min_rpm: f64,
        /// Highest speed \[rev/min\].
        max_rpm: f64,
    },
}

/// The runout vectors of one signal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlowRoll {
    /// Where they come from.
    pub source: SlowRollSource,
    /// The orders, as in the [`Tracked`] they compensate.
    pub orders: Vec<u32>,
    /// The runout vector per order \[signal unit\], zero-to-peak.
    pub vectors: Vec<C64>,
    /// Standard deviation of Re and of Im per order \[signal unit\].
    pub std: Vec<f64>,
    /// Revolutions averaged.
    pub revolutions: usize,
    /// Their speed range \[rev/min\].
    pub speed_rpm: (f64, f64),
}

/// The speed range \[rev/min\] of an automatic slow roll: from the lowest revolution speed
/// s_min to `s_min + max(0.15 s_min, 0.03 (s_max - s_min))`, widened to the
/// [`AUTO_MIN_REVOLUTIONS`] slowest revolutions when it holds fewer. `None` with no
/// revolution.
pub fn auto_range(speeds_rpm: &[f64]) -> Option<(f64, f64)> {
    let mut s: Vec<f64> = speeds_rpm
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    s.sort_by(f64::total_cmp);
    let (&lo, &hi) = (s.first()?, s.last()?);
    let mut top = lo + (AUTO_RELATIVE * lo).max(AUTO_SPAN * (hi - lo));
    let k = AUTO_MIN_REVOLUTIONS.min(s.len());
    top = top.max(s[k - 1]);
    Some((lo, top))
}

/// The runout vectors of `tracked` from its revolutions with speeds in
/// \[`min_rpm`, `max_rpm`\] (module doc), reported as coming from `source`.
pub fn from_revolutions(
    tracked: &Tracked,
    min_rpm: f64,
    max_rpm: f64,
    source: SlowRollSource,
) -> Result<SlowRoll, TransientError> {
    if !(min_rpm.is_finite() && max_rpm.is_finite() && min_rpm >= 0.0 && max_rpm > min_rpm) {
        return Err(OutOfRange {
            field: "slow-roll",
            value: max_rpm,
            allowed: "a range RPM_MIN:RPM_MAX with 0 <= RPM_MIN < RPM_MAX (rev/min)",
        }
        .into());
    }
    let chosen: Vec<&Revolution> = tracked
        .revolutions
        .iter()
        .filter(|r| (min_rpm..=max_rpm).contains(&r.rpm()))
        .collect();
    average(tracked, &chosen, source)
}

/// The runout vectors of a slow-roll record's `tracked` revolutions (all of them).
pub fn from_record(tracked: &Tracked, file: &str) -> Result<SlowRoll, TransientError> {
    let all: Vec<&Revolution> = tracked.revolutions.iter().collect();
    average(
        tracked,
        &all,
        SlowRollSource::Record {
            file: file.to_owned(),
        },
    )
}

fn average(
    tracked: &Tracked,
    revs: &[&Revolution],
    source: SlowRollSource,
) -> Result<SlowRoll, TransientError> {
    if revs.len() < 2 {
        return Err(TransientError::TooFew {
            what: format!("slow-roll revolutions ({})", describe(&source)),
            found: revs.len(),
            needed: 2,
        });
    }
    let k = revs.len() as f64;
    let mut vectors = Vec::new();
    let mut std = Vec::new();
    for o in 0..tracked.orders.len() {
        let (mut sw, mut sv) = (0.0, C64::new(0.0, 0.0));
        for r in revs {
            let w = 1.0 / r.std[o].max(f64::MIN_POSITIVE).powi(2);
            sw += w;
            sv += r.vectors[o] * w;
        }
        let mean = sv / sw;
        let scatter = revs
            .iter()
            .map(|r| (r.vectors[o] - mean).norm_sqr() / 2.0)
            .sum::<f64>()
            / (k - 1.0);
        vectors.push(mean);
        std.push((1.0 / sw).max(scatter / k).sqrt());
    }
    let lo = revs.iter().map(|r| r.rpm()).fold(f64::INFINITY, f64::min);
    let hi = revs
        .iter()
        .map(|r| r.rpm())
        .fold(f64::NEG_INFINITY, f64::max);
    Ok(SlowRoll {
        source,
        orders: tracked.orders.clone(),
        vectors,
        std,
        revolutions: revs.len(),
        speed_rpm: (lo, hi),
    })
}

/// Where a slow roll comes from, in words.
pub fn describe(source: &SlowRollSource) -> String {
    match source {
        SlowRollSource::Record { file } => format!("the slow-roll record {file}"),
        SlowRollSource::Range { min_rpm, max_rpm } => {
            format!("the revolutions from {min_rpm} to {max_rpm} rpm")
        }
        SlowRollSource::Auto { min_rpm, max_rpm } => {
            format!("the revolutions from {min_rpm:.1} to {max_rpm:.1} rpm (picked automatically)")
        }
    }
}

/// `tracked` with the runout `sr` subtracted from every revolution (module doc). The
/// orders must be the same.
pub fn compensate(tracked: &Tracked, sr: &SlowRoll) -> Tracked {
    debug_assert_eq!(tracked.orders, sr.orders);
    let revolutions = tracked
        .revolutions
        .iter()
        .map(|r| {
            let mut c = r.clone();
            for o in 0..c.vectors.len() {
                c.vectors[o] -= sr.vectors[o];
                c.std[o] = c.std[o].hypot(sr.std[o]);
            }
            c
        })
        .collect();
    Tracked {
        orders: tracked.orders.clone(),
        revolutions,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rev(rpm: f64, v: C64, std: f64) -> Revolution {
        let w = rpm * std::f64::consts::TAU / 60.0;
        Revolution {
            t_start: 0.0,
            t_end: std::f64::consts::TAU / w,
            speed: w,
            dc: 0.0,
            noise: 0.0,
            vectors: vec![v],
            std: vec![std],
            count: 1,
        }
    }

    #[test]
    fn the_runout_is_the_weighted_mean_and_is_subtracted() {
        let tr = Tracked {
            orders: vec![1],
            revolutions: vec![
                rev(300.0, C64::new(1.0, 0.0), 1.0),
                rev(310.0, C64::new(3.0, 0.0), 2.0),
                rev(2000.0, C64::new(10.0, 5.0), 0.5),
            ],
        };
        let sr = from_revolutions(
            &tr,
            290.0,
            320.0,
            SlowRollSource::Range {
                min_rpm: 290.0,
                max_rpm: 320.0,
            },
        )
        .unwrap();
        // weights 1 and 1/4: (1 + 3/4) / (5/4) = 1.4
        assert!((sr.vectors[0] - C64::new(1.4, 0.0)).norm() < 1e-12);
        assert_eq!(sr.revolutions, 2);
        // scatter: ((0.4^2 + 1.6^2) / 2) / 1 / 2 = 0.68 > 1 / 1.25 = 0.8? no: 0.8 wins
        assert!((sr.std[0] - 0.8f64.sqrt()).abs() < 1e-12, "{}", sr.std[0]);
        let c = compensate(&tr, &sr);
        assert!((c.revolutions[2].vectors[0] - C64::new(8.6, 5.0)).norm() < 1e-12);
        assert!((c.revolutions[2].std[0] - (0.25f64 + 0.8).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn auto_range_takes_the_lowest_speeds() {
        let speeds: Vec<f64> = (0..1000).map(|i| 500.0 + 5.0 * f64::from(i)).collect();
        let (lo, hi) = auto_range(&speeds).unwrap();
        assert_eq!(lo, 500.0);
        // 0.15 * 500 = 75 > 0.03 * 4995 = 149.85? no: 149.85
        assert!((hi - 649.85).abs() < 1e-9);
        // widened to eight revolutions
        let (_, hi) = auto_range(&[
            100.0, 1000.0, 1001.0, 1002.0, 1003.0, 1004.0, 1005.0, 1006.0, 1007.0,
        ])
        .unwrap();
        assert_eq!(hi, 1006.0);
        assert!(auto_range(&[]).is_none());
    }

    #[test]
    fn an_empty_range_is_refused_with_what_it_held() {
        let tr = Tracked {
            orders: vec![1],
            revolutions: vec![rev(300.0, C64::new(1.0, 0.0), 1.0)],
        };
        let e = from_revolutions(
            &tr,
            100.0,
            200.0,
            SlowRollSource::Range {
                min_rpm: 100.0,
                max_rpm: 200.0,
            },
        )
        .unwrap_err();
        assert!(e.to_string().contains("100 to 200 rpm"), "{e}");
        assert!(from_revolutions(
            &tr,
            200.0,
            100.0,
            SlowRollSource::Range {
                min_rpm: 200.0,
                max_rpm: 100.0
            }
        )
        .is_err());
    }
}
