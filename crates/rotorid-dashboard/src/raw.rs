//! What the pages show of a window's samples ([`Frame`] from `ROTORID_RAW`): the orbit and
//! x(t), z(t) of the newest window, thinned for drawing, with the keyphasor instants; and
//! each window's 1X vector of x and z.
//!
//! **Keyphasor.** The shaft angle phi \[rad\] (channel `phi`) passes the keyphasor mark at
//! phi = 2 pi k: the instant of each crossing is found by linear interpolation between the
//! two samples around it, and x, z there likewise, at full resolution (not from the thinned
//! samples).
//!
//! **1X.** Per window and probe, [`rotorid::analysis::one_x`]: least squares of
//! s_k = c + Re(V e^{i phi_k}) over the window's samples, the synchronous vector of the
//! signal against the shaft angle (an average over the window's revolutions), amplitude |V|
//! (zero-to-peak) and phase lag -arg V from the keyphasor to the positive peak, with the
//! standard errors of least squares. Without a `phi` channel there is no keyphasor and no
//! 1X (the worker then takes the speed from its scenario, which the dashboard does not read).

use rotorid::analysis::one_x;
use rotorid_fleet::Frame;
use serde::Serialize;

/// Most points per channel kept of the newest window (every k-th sample).
pub const MAX_DRAWN_SAMPLES: usize = 2048;
/// Most keyphasor instants kept of the newest window.
pub const MAX_KEYPHASORS: usize = 512;

/// Micrometres per metre.
const UM: f64 = 1e6;

/// The newest window of a machine, as drawn (module doc). Displacements in um.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Orbit {
    /// Window number.
    pub window: u64,
    /// Time of sample 0 \[s\].
    pub t0_s: f64,
    /// Sampling period of the window \[s\].
    pub dt_s: f64,
    /// Samples per channel in the window.
    pub samples: usize,
    /// Every `stride`-th sample is kept: point i is sample i stride, at t0 + i stride dt.
    pub stride: usize,
    /// x \[um\] at the kept samples.
    pub x_um: Vec<f64>,
    /// z \[um\] at the kept samples.
    pub z_um: Vec<f64>,
    /// The keyphasor instants (module doc), at most [`MAX_KEYPHASORS`].
    pub keyphasor: Vec<Keyphasor>,
    /// Mean shaft speed over the window \[rev/min\], from phi (first to last sample).
    pub speed_rpm: Option<f64>,
    /// Why there is no keyphasor or 1X, when there is none.
    pub note: Option<String>,
}

/// One pass of the keyphasor mark.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Keyphasor {
    /// Time \[s\].
    pub t_s: f64,
    /// x there \[um\].
    pub x_um: f64,
    /// z there \[um\].
    pub z_um: f64,
}

/// One probe's 1X vector in display units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Vector1x {
    /// Amplitude |V| \[um\], zero-to-peak.
    pub amplitude_um: f64,
    /// Its standard error \[um\].
    pub amplitude_se_um: f64,
    /// Phase lag \[deg\], 0 to 360, from the keyphasor to the positive peak.
    pub phase_deg: f64,
    /// Its standard error \[deg\] (none at zero amplitude).
    pub phase_se_deg: Option<f64>,
}

/// One window's 1X vectors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OneXPoint {
    /// Window number.
    pub window: u64,
    /// Time of its first sample \[s\].
    pub t0_s: f64,
    /// Mean speed \[rev/min\].
    pub speed_rpm: Option<f64>,
    /// The 1X vector of x.
    pub x: Option<Vector1x>,
    /// The 1X vector of z.
    pub z: Option<Vector1x>,
}

fn vector(signal: &[f64], phi: &[f64]) -> Option<Vector1x> {
    let v = one_x(signal, phi).ok()??;
    let (re, im) = (v.vector.re, v.vector.im);
    let amp = v.amplitude;
    let c = &v.covariance;
    let quad = |a: f64, b: f64| a * a * c[(0, 0)] + 2.0 * a * b * c[(0, 1)] + b * b * c[(1, 1)];
    let (amp_se, phase_se) = if amp > 0.0 {
        let (u0, u1) = (re / amp, im / amp);
        (
            quad(u0, u1).max(0.0).sqrt(),
            Some(quad(-u1, u0).max(0.0).sqrt() / amp),
        )
    } else {
        ((c[(0, 0)] + c[(1, 1)]).max(0.0).sqrt(), None)
    };
    let finite = amp.is_finite() && amp_se.is_finite() && v.phase_lag.is_finite();
    finite.then(|| Vector1x {
        amplitude_um: amp * UM,
        amplitude_se_um: amp_se * UM,
        phase_deg: v.phase_lag.to_degrees(),
        phase_se_deg: phase_se.filter(|s| s.is_finite()).map(f64::to_degrees),
    })
}

/// The samples of channel `name` when its unit is `unit`.
fn channel<'a>(f: &'a Frame, name: &str, unit: &str) -> Option<&'a [f64]> {
    f.channel(name)
        .filter(|c| c.unit == unit)
        .map(|c| c.data.as_slice())
}

/// Mean speed over the window \[rev/min\] from the first and last phi.
fn speed_rpm(phi: &[f64], dt: f64) -> Option<f64> {
    let (first, last) = (phi.first()?, phi.last()?);
    let span = (phi.len() - 1) as f64 * dt;
    let w = (last - first) / span;
    (span > 0.0 && w.is_finite()).then(|| w * 60.0 / std::f64::consts::TAU)
}

/// The keyphasor instants of the window (module doc).
fn keyphasors(t0: f64, dt: f64, x: &[f64], z: &[f64], phi: &[f64]) -> Vec<Keyphasor> {
    let tau = std::f64::consts::TAU;
    let mut out = Vec::new();
    for k in 1..phi.len() {
        let (a, b) = (phi[k - 1], phi[k]);
        if !(a.is_finite() && b.is_finite()) || a == b {
            continue;
        }
        // a mark 2 pi n between a (excluded) and b (included), either direction of rotation
        let (lo, hi) = if b > a { (a, b) } else { (b, a) };
        let n = (hi / tau).floor();
        let mark = n * tau;
        let crossed = if b > a {
            mark > lo && mark <= hi
        } else {
            mark >= lo && mark < hi
        };
        if !crossed {
            continue;
        }
        let f = (mark - a) / (b - a);
        out.push(Keyphasor {
            t_s: t0 + (k as f64 - 1.0 + f) * dt,
            x_um: (x[k - 1] + f * (x[k] - x[k - 1])) * UM,
            z_um: (z[k - 1] + f * (z[k] - z[k - 1])) * UM,
        });
        if out.len() == MAX_KEYPHASORS {
            break;
        }
    }
    out
}

/// The orbit view and the 1X point of `frame`, or `None` when it has no `x`, `z` in m.
pub fn analyse(frame: &Frame) -> Option<(Orbit, OneXPoint)> {
    let x = channel(frame, "x", "m")?;
    let z = channel(frame, "z", "m")?;
    let n = x.len();
    let stride = n.div_ceil(MAX_DRAWN_SAMPLES).max(1);
    let thin = |s: &[f64]| s.iter().step_by(stride).map(|v| v * UM).collect();
    let phi = channel(frame, "phi", "rad");
    let (keyphasor, speed, note, vx, vz) = match phi {
        Some(phi) => {
            let kp = keyphasors(frame.t0, frame.dt, x, z, phi);
            let speed = speed_rpm(phi, frame.dt);
            let (vx, vz) = (vector(x, phi), vector(z, phi));
            let note = (vx.is_none() || vz.is_none()).then(|| {
                "no 1X vector: the samples do not determine it (the shaft does not turn, or \
                 a value is not finite)"
                    .to_owned()
            });
            (kp, speed, note, vx, vz)
        }
        None => (
            Vec::new(),
            None,
            Some(
                "no keyphasor and no 1X: the window has no phi channel in rad (publish the \
                 recording with phi, or with --scenario)"
                    .to_owned(),
            ),
            None,
            None,
        ),
    };
    let orbit = Orbit {
        window: frame.window,
        t0_s: frame.t0,
        dt_s: frame.dt,
        samples: n,
        stride,
        x_um: thin(x),
        z_um: thin(z),
        keyphasor,
        speed_rpm: speed,
        note,
    };
    let point = OneXPoint {
        window: frame.window,
        t0_s: frame.t0,
        speed_rpm: speed,
        x: vx,
        z: vz,
    };
    Some((orbit, point))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotorid_fleet::Channel;

    fn frame(n: usize, w: f64, with_phi: bool) -> Frame {
        let dt = 1e-4;
        let t: Vec<f64> = (0..n).map(|i| 0.5 + i as f64 * dt).collect();
        let phi: Vec<f64> = t.iter().map(|t| w * t + 0.3).collect();
        // x = 2 um cos(phi - 1), z = 1 um sin(phi - 1) + 0.5 um
        let x = phi.iter().map(|p| 2e-6 * (p - 1.0).cos()).collect();
        let z = phi
            .iter()
            .map(|p| 1e-6 * (p - 1.0).sin() + 0.5e-6)
            .collect();
        let mut channels = vec![
            Channel {
                name: "x".into(),
                unit: "m".into(),
                data: x,
            },
            Channel {
                name: "z".into(),
                unit: "m".into(),
                data: z,
            },
        ];
        if with_phi {
            channels.push(Channel {
                name: "phi".into(),
                unit: "rad".into(),
                data: phi,
            });
        }
        Frame {
            machine: "m".into(),
            window: 7,
            t0: 0.5,
            dt,
            channels,
        }
    }

    #[test]
    fn keyphasors_orbit_and_1x_of_a_synthetic_window() {
        let w = 40.0 * std::f64::consts::PI; // 1200 rpm
        let f = frame(10_000, w, true);
        let (o, p) = analyse(&f).unwrap();
        assert_eq!(o.stride, 5);
        assert_eq!(o.x_um.len(), 2000);
        assert!((o.x_um[1] - f.channels[0].data[5] * 1e6).abs() < 1e-12);
        // phi from 0.3 + w 0.5 over 1 s at 20 rev/s: 20 marks
        assert_eq!(o.keyphasor.len(), 20);
        let tau = std::f64::consts::TAU;
        for k in &o.keyphasor {
            // at the mark phi = 2 pi n: x = 2 cos(-1), z = sin(-1) + 0.5, to interpolation error
            let phi = w * k.t_s + 0.3;
            assert!((phi / tau - (phi / tau).round()).abs() < 1e-9, "{k:?}");
            assert!((k.x_um - 2.0 * (-1.0f64).cos()).abs() < 1e-3, "{k:?}");
            assert!((k.z_um - ((-1.0f64).sin() + 0.5)).abs() < 1e-3, "{k:?}");
        }
        assert!((o.speed_rpm.unwrap() - 1200.0).abs() < 1e-6);
        let (vx, vz) = (p.x.unwrap(), p.z.unwrap());
        assert!((vx.amplitude_um - 2.0).abs() < 1e-9, "{vx:?}");
        assert!((vx.phase_deg - 1f64.to_degrees()).abs() < 1e-7, "{vx:?}");
        // sin(phi - 1) = cos(phi - 1 - pi/2): lag 1 + pi/2
        assert!((vz.amplitude_um - 1.0).abs() < 1e-9);
        assert!((vz.phase_deg - (1.0 + std::f64::consts::FRAC_PI_2).to_degrees()).abs() < 1e-7);
        assert!(vx.amplitude_se_um < 1e-9 && vx.phase_se_deg.unwrap() < 1e-7);
    }

    #[test]
    fn without_phi_there_is_an_orbit_and_a_note_but_no_keyphasor_or_1x() {
        let (o, p) = analyse(&frame(300, 100.0, false)).unwrap();
        assert_eq!((o.stride, o.x_um.len()), (1, 300));
        assert!(o.keyphasor.is_empty() && p.x.is_none() && p.z.is_none());
        assert!(o.note.unwrap().contains("no phi channel"));
    }

    #[test]
    fn reverse_rotation_and_missing_probes() {
        let (o, _) = analyse(&frame(10_000, -40.0 * std::f64::consts::PI, true)).unwrap();
        assert_eq!(o.keyphasor.len(), 20);
        assert!((o.speed_rpm.unwrap() + 1200.0).abs() < 1e-6);
        let mut f = frame(100, 1.0, true);
        f.channels[0].unit = "um".into();
        assert!(analyse(&f).is_none(), "x must be in m");
    }
}
