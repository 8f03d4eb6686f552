//! Shared by the fe_*.rs tests: the two-disk rotor exported from ROSS itself
//! (`fe_fixture/ross_two_disk.py`, ross-rotordynamics 3.1.0: 11 nodes x (x, y, rx, ry) =
//! 44 degrees of freedom, Timoshenko shaft elements, two disks, two anisotropic bearings
//! with cross-coupling, proportional shaft damping C, K and C without the bearings) and comparison helpers.

use std::sync::Arc;

use nalgebra::{Complex, DMatrix, DVector};
use rotorid::model::finite_element::FeSystem;
use rotorid::model::finite_element::{Bearing, Dof, FeMatrices, FeUnbalance, FiniteElementRotor};
use rotorid::model::{Sampling, SpeedProfile};
use rotorid::simulate::add_noise_to;
use rotorid::simulate::finite_element::{simulate_fe, FeMethod, FeResponse};
use serde_json::Value;

pub const ROSS_TWO_DISK: &str = include_str!("../fe_fixture/ross_two_disk.json");

fn matrix(v: &Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).unwrap();
    DMatrix::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j])
}

pub fn fixture() -> Value {
    serde_json::from_str(ROSS_TWO_DISK).unwrap()
}

/// The ROSS two-disk rotor with its bearings and unbalances.
pub fn ross_rotor() -> FiniteElementRotor {
    let f = fixture();
    let dofs: Vec<Dof> = f["dofs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().parse().unwrap())
        .collect();
    let mats = FeMatrices::new(
        dofs,
        matrix(&f["M"]),
        matrix(&f["K"]),
        matrix(&f["G"]),
        Some(matrix(&f["C"])),
        Some(matrix(&f["Ksdt"])),
    )
    .unwrap();
    let num = |b: &Value, k: &str| b[k].as_f64().unwrap();
    let bearings = f["bearings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| Bearing {
            node: b["node"].as_u64().unwrap() as u32,
            kxx: num(b, "kxx"),
            kxy: num(b, "kxy"),
            kyx: num(b, "kyx"),
            kyy: num(b, "kyy"),
            cxx: num(b, "cxx"),
            cxy: num(b, "cxy"),
            cyx: num(b, "cyx"),
            cyy: num(b, "cyy"),
        })
        .collect();
    let unbalances = f["unbalances"]
        .as_array()
        .unwrap()
        .iter()
        .map(|u| FeUnbalance {
            node: u["node"].as_u64().unwrap() as u32,
            mud: num(u, "mud"),
            alpha: num(u, "alpha"),
        })
        .collect();
    FiniteElementRotor::new(Arc::new(mats), bearings, unbalances).unwrap()
}

/// ROSS's steady-state unbalance response: (speed [rad/s], X) with q = Re(X e^{i w t}).
pub fn ross_steady_state() -> Vec<(f64, DVector<Complex<f64>>)> {
    let f = fixture();
    let ss = &f["steady_state"];
    let speeds: Vec<f64> = serde_json::from_value(ss["speeds"].clone()).unwrap();
    let re: Vec<Vec<f64>> = serde_json::from_value(ss["re"].clone()).unwrap();
    let im: Vec<Vec<f64>> = serde_json::from_value(ss["im"].clone()).unwrap();
    speeds
        .iter()
        .enumerate()
        .map(|(k, &w)| {
            (
                w,
                DVector::from_fn(re[k].len(), |i, _| Complex::new(re[k][i], im[k][i])),
            )
        })
        .collect()
}

/// max |a - b| over every column and sample, over max |a|.
pub fn max_rel(a: &FeResponse, b: &FeResponse) -> f64 {
    assert_eq!(a.dofs, b.dofs);
    assert_eq!(a.len(), b.len());
    let mut amp = 0.0f64;
    let mut err = 0.0f64;
    for (ca, cb) in a.q.iter().zip(&b.q) {
        for (x, y) in ca.iter().zip(cb) {
            amp = amp.max(x.abs());
            err = err.max((x - y).abs());
        }
    }
    err / amp
}

/// RMS of a - b over every column and sample, over the RMS of a.
pub fn rms_rel(a: &FeResponse, b: &FeResponse) -> f64 {
    assert_eq!(a.dofs, b.dofs);
    let (mut e, mut s) = (0.0, 0.0);
    for (ca, cb) in a.q.iter().zip(&b.q) {
        for (x, y) in ca.iter().zip(cb) {
            e += (x - y) * (x - y);
            s += x * x;
        }
    }
    (e / s).sqrt()
}

/// The probes of the tests: x and y at both bearings (nodes 0 and 10).
pub fn probes() -> Vec<Dof> {
    ["0.x", "0.y", "10.x", "10.y"]
        .iter()
        .map(|s| s.parse().unwrap())
        .collect()
}

/// The truth's response at the probes from rest, with noise at `snr_db` (seed).
pub fn record(
    rotor: &FiniteElementRotor,
    speed: &SpeedProfile,
    duration: f64,
    snr_db: f64,
    seed: u64,
) -> (FeResponse, Vec<f64>) {
    let method = if speed.is_constant() {
        FeMethod::Exact
    } else {
        FeMethod::Magnus
    };
    let mut r = simulate_fe(
        &FeSystem::full(rotor),
        speed,
        &Sampling::new(1e-4, duration).unwrap(),
        None,
        Some(&probes()),
        method,
    )
    .unwrap();
    let names = ["0.x", "0.y", "10.x", "10.y"];
    let mut chans: Vec<(&'static str, &mut [f64])> = names
        .iter()
        .zip(r.q.iter_mut())
        .map(|(n, c)| (*n, c.as_mut_slice()))
        .collect();
    let sigma = add_noise_to(&mut chans, snr_db, seed).unwrap();
    (r, sigma)
}

/// An engineering guess: direct coefficients 30-70 % off, angles 40 deg off, mud 50 % off.
pub fn guess(truth: &FiniteElementRotor) -> FiniteElementRotor {
    let mut g = truth.clone();
    let f = [1.5, 0.6, 1.4, 0.7];
    for (i, b) in g.bearings.iter_mut().enumerate() {
        b.kxx *= f[i % 4];
        b.kyy *= f[(i + 1) % 4];
        b.cxx *= f[(i + 2) % 4];
        b.cyy *= f[(i + 3) % 4];
    }
    for (j, u) in g.unbalances.iter_mut().enumerate() {
        u.mud *= if j == 0 { 1.5 } else { 0.6 };
        u.alpha += 40f64.to_radians() * if j == 0 { 1.0 } else { -1.0 };
    }
    g
}
