//! The figures of `rotorid transient`: Bode (each probe's compensated 1X amplitude and
//! phase lag against speed, +-2 standard deviation bands, the criticals marked), polar
//! (the same vectors as curves with speed labels) and, for DC-coupled XY probes, the
//! shaft centreline against speed. Built in memory first, so that an error leaves no file.

use std::path::Path;

use rotorid::acquisition::probes::inverse_projection;
use rotorid::transient::analysis::Analysis;
use rotorid::transient::order::C64;
use rotorid::transient::report::lag_deg;
use rotorid::transient::Cascade;

use crate::plot::bode::{unwrap_deg, BodeChannel, BodePlot};
use crate::plot::campbell::CriticalMark;
use crate::plot::canvas::save_drawing;
use crate::plot::cascade::CascadePlot;
use crate::plot::polar::{PolarChannel, PolarPlot};
use crate::plot::{palette, Figure, Panel, Rgb, Series};

/// Peak-to-peak micrometres per metre zero-to-peak.
const UM_PP: f64 = 2e6;

const COLOURS: [Rgb; 6] = [
    palette::BLUE,
    palette::VERMILLION,
    Rgb(0, 158, 115),
    Rgb(204, 121, 167),
    Rgb(230, 159, 0),
    palette::GREY,
];

/// Everything to draw.
pub struct Figures {
    bode: BodePlot,
    polar: PolarPlot,
    centreline: Option<Figure>,
    /// (stem, caption, plot) of each cascade.
    cascades: Vec<(String, String, CascadePlot)>,
}

/// Criticals closer than this fraction of their speed are one mark on the plots.
const SAME_MARK: f64 = 0.01;

/// The speeds of the plots (the union of the sensors', increasing) and each sensor's
/// compensated 1X interpolated on them (NaN outside its own range).
fn on_common_speeds(a: &Analysis) -> (Vec<f64>, Vec<Vec<(C64, f64)>>) {
    let mut rpm: Vec<f64> = a
        .sensors
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.rpm))
        .collect();
    rpm.sort_by(f64::total_cmp);
    rpm.dedup();
    let per = a
        .sensors
        .iter()
        .map(|s| {
            let Some(o) = s.orders.iter().position(|&n| n == 1) else {
                return vec![(C64::new(f64::NAN, f64::NAN), f64::NAN); rpm.len()];
            };
            let pts: Vec<(f64, C64, f64)> = s
                .points
                .iter()
                .map(|p| (p.rpm, p.comp[o], p.std[o]))
                .collect();
            interpolate(&rpm, pts)
        })
        .collect();
    (rpm, per)
}

/// `pts` (speed, vector, std) linearly interpolated on the increasing speeds `rpm` (NaN
/// outside their range).
fn interpolate(rpm: &[f64], mut pts: Vec<(f64, C64, f64)>) -> Vec<(C64, f64)> {
    pts.sort_by(|x, y| x.0.total_cmp(&y.0));
    rpm.iter()
        .map(|&r| {
            let k = pts.partition_point(|p| p.0 < r);
            match (pts.get(k), k.checked_sub(1).and_then(|j| pts.get(j))) {
                (Some(hi), _) if hi.0 == r => (hi.1, hi.2),
                (Some(hi), Some(lo)) => {
                    let f = (r - lo.0) / (hi.0 - lo.0);
                    (lo.1 + (hi.1 - lo.1) * f, lo.2 + (hi.2 - lo.2) * f)
                }
                _ => (C64::new(f64::NAN, f64::NAN), f64::NAN),
            }
        })
        .collect()
}

/// The fitted modes' model of each sensor fitted, on the speeds `rpm`, as Bode channels
/// (black: the data's colours are the sensors').
fn model_channels(a: &Analysis, rpm: &[f64]) -> Vec<BodeChannel> {
    let Some(m) = &a.modes else {
        return Vec::new();
    };
    m.sensors
        .iter()
        .zip(&m.fit.model)
        .map(|(&k, model)| {
            let s = &a.sensors[k];
            let pts = s.points[m.fit.points.clone()]
                .iter()
                .zip(model)
                .map(|(p, v)| (p.rpm, *v, f64::NAN))
                .collect();
            let v = interpolate(rpm, pts);
            let lag: Vec<f64> = v
                .iter()
                .map(|(x, _)| {
                    if x.norm() > 0.0 {
                        lag_deg(*x)
                    } else {
                        f64::NAN
                    }
                })
                .collect();
            BodeChannel {
                label: format!("{}: fitted modes", s.name),
                color: MODEL_COLOUR,
                amplitude: v.iter().map(|(x, _)| UM_PP * x.norm()).collect(),
                std_amplitude: vec![None; rpm.len()],
                phase_lag_deg: unwrap_deg(&lag),
                std_phase_lag_deg: vec![None; rpm.len()],
            }
        })
        .collect()
}

/// The colour of the fitted model's curves.
const MODEL_COLOUR: Rgb = Rgb(0, 0, 0);

/// The figures of `a` (module doc).
pub fn render(a: &Analysis) -> anyhow::Result<Figures> {
    let source = a
        .sources
        .iter()
        .map(|s| {
            Path::new(s)
                .file_name()
                .map_or_else(|| s.clone(), |f| f.to_string_lossy().into_owned())
        })
        .collect::<Vec<_>>()
        .join(", ");
    let mut marks: Vec<CriticalMark> = Vec::new();
    let mut all: Vec<(f64, f64)> = a
        .sensors
        .iter()
        .flat_map(|s| {
            s.criticals
                .iter()
                .map(|c| (c.critical.rpm, c.critical.rpm_std))
        })
        .collect();
    all.sort_by(|x, y| x.0.total_cmp(&y.0));
    for (rpm, std) in all {
        if marks
            .last()
            .is_some_and(|m| (rpm - m.rpm).abs() <= SAME_MARK * rpm)
        {
            continue;
        }
        marks.push(CriticalMark {
            rpm,
            std_rpm: Some(std),
            whirl: None,
        });
    }
    let (rpm, per) = on_common_speeds(a);
    let mut bode_channels = Vec::new();
    let mut polar_channels = Vec::new();
    for (i, (s, v)) in a.sensors.iter().zip(&per).enumerate() {
        let color = COLOURS[i % COLOURS.len()];
        let label = match s.angle_deg {
            Some(d) => format!("{} ({d:.0}\u{b0})", s.name),
            None => s.name.clone(),
        };
        let amp: Vec<f64> = v.iter().map(|(x, _)| UM_PP * x.norm()).collect();
        let lag: Vec<f64> = v
            .iter()
            .map(|(x, _)| {
                if x.norm() > 0.0 {
                    lag_deg(*x)
                } else {
                    f64::NAN
                }
            })
            .collect();
        bode_channels.push(BodeChannel {
            label: label.clone(),
            color,
            amplitude: amp.clone(),
            std_amplitude: v
                .iter()
                .map(|(_, sd)| sd.is_finite().then_some(UM_PP * sd))
                .collect(),
            phase_lag_deg: unwrap_deg(&lag),
            std_phase_lag_deg: v
                .iter()
                .map(|(x, sd)| {
                    (sd.is_finite() && x.norm() > 0.0)
                        .then(|| (sd / x.norm()).min(1.0).to_degrees())
                })
                .collect(),
        });
        polar_channels.push(PolarChannel {
            label,
            color,
            amplitude: amp,
            phase_lag_deg: lag,
        });
    }
    bode_channels.extend(model_channels(a, &rpm));
    let unit = "\u{b5}m pk-pk".to_string();
    let what = if a.keyphasor.is_empty() {
        "1X table"
    } else {
        "compensated 1X"
    };
    let bode = BodePlot {
        title: format!("Bode ({what}) \u{2014} {source}"),
        rpm: rpm.clone(),
        unit: unit.clone(),
        channels: bode_channels,
        critical: marks.clone(),
    };
    let polar = PolarPlot {
        title: format!("Polar ({what}) \u{2014} {source}"),
        rpm,
        unit,
        channels: polar_channels,
        critical: marks,
    };
    Ok(Figures {
        bode,
        polar,
        centreline: centreline(a, &source)?,
        cascades: cascades(a, &source)?,
    })
}

/// The spectra of every record joined (records of one event: the same sampling, so the
/// same lines); `None` when they differ (then the first record's alone).
fn joined(parts: Vec<Cascade>) -> Option<Cascade> {
    let mut it = parts.into_iter();
    let mut all = it.next()?;
    for c in it {
        if c.freq_hz != all.freq_hz {
            return Some(all);
        }
        all.rpm.extend(c.rpm);
        all.t.extend(c.t);
        all.amplitude.extend(c.amplitude);
    }
    Some(all)
}

/// The cascade of each probe and, with an XY pair, the full-spectrum cascade (raw
/// records only; the signals as measured, runout included): the analysis computed them
/// as each record was added (`Analysis::spectra`).
fn cascades(a: &Analysis, source: &str) -> anyhow::Result<Vec<(String, String, CascadePlot)>> {
    if a.spectra.is_empty() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    for (k, s) in a.sensors.iter().enumerate() {
        let parts = a
            .spectra
            .iter()
            .map(|r| r.probes[k].clone())
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(c) = joined(parts) {
            let mut plot =
                CascadePlot::new(format!("Cascade \u{2014} {} \u{2014} {source}", s.name), c);
            plot.orders.retain(|&o| o <= 10.0);
            out.push((
                format!("cascade_{}", file_stem_of(&s.name)),
                format!("Cascade of {}: its spectra (\u{b5}m pk, colour) against speed, the orders as dashed lines (the signal as measured, runout included)", s.name),
                plot,
            ));
        }
    }
    if let (Some(_), 2) = (a.pair_angles, a.sensors.len()) {
        let parts = a
            .spectra
            .iter()
            .filter_map(|r| r.full.clone())
            .collect::<Result<Vec<_>, _>>()?;
        if let Some(c) = joined(parts) {
            out.push((
                "full_spectrum".to_string(),
                format!("Full-spectrum cascade of the pair {} and {}: forward whirl (in the direction of rotation) at positive frequencies, backward at negative", a.sensors[0].name, a.sensors[1].name),
                CascadePlot::new(format!("Full spectrum \u{2014} {source}"), c),
            ));
        }
    }
    Ok(out)
}

/// `name` with every character that is not a letter, digit, `-` or `_` replaced by `_`.
fn file_stem_of(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// The shaft centreline: x, z from the two probes' gaps (DC) through the inverse of the
/// probe projection, relative to the first point, in um; `None` without an XY pair of
/// DC-coupled probes.
fn centreline(a: &Analysis, source: &str) -> anyhow::Result<Option<Figure>> {
    let (Some(angles), true) = (a.pair_angles, a.dc_coupled) else {
        return Ok(None);
    };
    if a.sensors.len() != 2 {
        return Ok(None);
    }
    let inv = inverse_projection(angles)?;
    let pts: Vec<(f64, f64, f64)> = a.sensors[0]
        .points
        .iter()
        .zip(&a.sensors[1].points)
        .filter_map(|(p, q)| {
            let (d1, d2) = (p.dc?, q.dc?);
            let xz = inv * nalgebra::Vector2::new(d1, d2);
            Some((p.rpm, xz[0], xz[1]))
        })
        .collect();
    let Some(&(_, x0, z0)) = pts.first() else {
        return Ok(None);
    };
    let rpm: Vec<f64> = pts.iter().map(|p| p.0).collect();
    // a running median over 21 revolutions: a revolution's gap carries a little of its
    // vibration when that changes within the revolution (near a resonance on a sweep),
    // which is no movement of the centre
    let x = running_median(
        &pts.iter().map(|p| (p.1 - x0) * 1e6).collect::<Vec<_>>(),
        10,
    );
    let z = running_median(
        &pts.iter().map(|p| (p.2 - z0) * 1e6).collect::<Vec<_>>(),
        10,
    );
    // speed labels: dots at a few speeds along the path
    let (lo, hi) = rpm
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let step = nice_step((hi - lo) / 6.0);
    let mut dots = (Vec::new(), Vec::new());
    let mut next = (lo / step).ceil() * step;
    let order: Vec<usize> = {
        let mut o: Vec<usize> = (0..rpm.len()).collect();
        o.sort_by(|&i, &j| rpm[i].total_cmp(&rpm[j]));
        o
    };
    for &i in &order {
        if rpm[i] >= next {
            dots.0.push(x[i]);
            dots.1.push(z[i]);
            next += step;
        }
    }
    let path = Panel::new(
        "centreline (from the first revolution; median of 21 revolutions; dots at equal speed steps)",
        "x, horizontal (\u{b5}m)",
        "z, vertical up (\u{b5}m)",
    )
    .with_series(vec![
        Series::solid("centreline", x.clone(), z.clone(), palette::BLUE),
        Series::dots(
            format!("every {step} rpm"),
            dots.0,
            dots.1,
            palette::VERMILLION,
            8,
        ),
    ])
    .with_equal_aspect();
    let against = Panel::new("", "speed (rpm)", "position (\u{b5}m)").with_series(vec![
        Series::solid("x", rpm.clone(), x, palette::BLUE),
        Series::solid("z", rpm, z, palette::VERMILLION),
    ]);
    Ok(Some(
        Figure::new(
            format!("Shaft centreline \u{2014} {source}"),
            vec![path, against],
        )
        .side_by_side(),
    ))
}

/// The median of `v` over `2 half + 1` points around each (fewer at the ends).
fn running_median(v: &[f64], half: usize) -> Vec<f64> {
    let n = v.len();
    (0..n)
        .map(|i| {
            let mut w: Vec<f64> = v[i.saturating_sub(half)..(i + half + 1).min(n)].to_vec();
            w.sort_by(f64::total_cmp);
            w[w.len() / 2]
        })
        .collect()
}

/// The step of 1, 2 or 5 times a power of ten nearest above `raw` (> 0).
fn nice_step(raw: f64) -> f64 {
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * p)
        .find(|&v| v >= raw)
        .unwrap_or(10.0 * p)
}

impl Figures {
    /// The file names the figures are written to.
    pub fn names(&self) -> Vec<String> {
        let mut v = Vec::new();
        for stem in self
            .stems()
            .into_iter()
            .map(str::to_owned)
            .chain(self.cascades.iter().map(|c| c.0.clone()))
        {
            for ext in ["png", "svg"] {
                v.push(format!("{stem}.{ext}"));
            }
        }
        v
    }

    fn stems(&self) -> Vec<&'static str> {
        let mut v = vec!["bode", "polar"];
        if self.centreline.is_some() {
            v.push("centreline");
        }
        v
    }

    /// (stem, caption) of each figure, for the report.
    pub fn report_figures(&self) -> Vec<(String, String)> {
        let mut v: Vec<(String, String)> = self
            .stems()
            .into_iter()
            .map(|s| {
                let caption = match s {
                    "bode" => "Bode: 1X amplitude (\u{b5}m pk-pk, bands \u{b1}2 standard deviations) and phase lag against speed; the critical speeds numbered",
                    "polar" => "Polar: the 1X vectors as one curve per probe (amplitude as radius, phase lag as angle, 0\u{b0} at the top, lag against the rotation), speeds labelled",
                    _ => "Shaft centreline from the probes' gap voltages (DC-coupled probes), relative to the first revolution",
                };
                (s.to_string(), caption.to_string())
            })
            .collect();
        v.extend(self.cascades.iter().map(|(s, c, _)| (s.clone(), c.clone())));
        v
    }

    /// Write every figure into `dir` as PNG and SVG; the names written.
    pub fn save(&self, dir: &Path) -> anyhow::Result<Vec<String>> {
        for ext in ["png", "svg"] {
            save_drawing(&self.bode, (1400, 1000), &dir.join(format!("bode.{ext}")))?;
            save_drawing(&self.polar, (1400, 1000), &dir.join(format!("polar.{ext}")))?;
            if let Some(f) = &self.centreline {
                crate::plot::save(f, &dir.join(format!("centreline.{ext}")))?;
            }
            for (stem, _, plot) in &self.cascades {
                plot.save(&dir.join(format!("{stem}.{ext}")))?;
            }
        }
        Ok(self.names())
    }
}
