//! The reduced model (Ritz basis of modes plus static shapes) against the full model on the
//! ROSS two-disk rotor (44 DOF): its error in the response at the probes (x, y at both
//! bearings) and at the disks, at constant speed and on a run-up through the first two
//! critical speeds (122 and 316 rad/s). The figures printed here are the ones in
//! docs/finite_element.md section 4 (`cargo test -p rotorid --test it fe_reduction --
//! --nocapture`).

use nalgebra::DMatrix;
use rotorid::model::finite_element::{
    Dof, FeDerivative, FeParameter, FeSystem, FiniteElementRotor, RitzBasis,
};
use rotorid::model::{Sampling, SpeedProfile};
use rotorid::simulate::finite_element::{simulate_fe, FeMethod, FeResponse};

use crate::fe_common::{probes, rms_rel, ross_rotor};

fn stations() -> Vec<Dof> {
    let mut d = probes();
    d.extend(["3.x", "3.y", "7.x", "7.y"].map(|s| s.parse::<Dof>().unwrap()));
    d
}

fn response(sys: &FeSystem, speed: &SpeedProfile, duration: f64, method: FeMethod) -> FeResponse {
    simulate_fe(
        sys,
        speed,
        &Sampling::new(1e-4, duration).unwrap(),
        None,
        Some(&stations()),
        method,
    )
    .unwrap()
}

/// Relative RMS error of the reduced response (probes and disks) for each basis.
fn errors(
    rotor: &FiniteElementRotor,
    full: &FeResponse,
    speed: &SpeedProfile,
    duration: f64,
    method: FeMethod,
    bases: &[(&str, RitzBasis)],
) -> Vec<f64> {
    bases
        .iter()
        .map(|(name, b)| {
            let r = response(&b.system(rotor).unwrap(), speed, duration, method);
            let e = rms_rel(full, &r);
            eprintln!(
                "  {name:>22} (r = {:2}): relative RMS error {e:.2e}",
                b.len()
            );
            e
        })
        .collect()
}

fn bases(rotor: &FiniteElementRotor) -> Vec<(&'static str, RitzBasis)> {
    vec![
        ("4 modes", RitzBasis::modes_only(rotor, 4).unwrap()),
        ("8 modes", RitzBasis::modes_only(rotor, 8).unwrap()),
        ("4 modes + statics", RitzBasis::new(rotor, 4).unwrap()),
        ("8 modes + statics", RitzBasis::new(rotor, 8).unwrap()),
        ("12 modes + statics", RitzBasis::new(rotor, 12).unwrap()),
    ]
}

#[test]
fn reduced_model_converges_to_the_full_one_at_constant_speed() {
    let rotor = ross_rotor();
    let speed = SpeedProfile::Constant {
        omega: 300.0,
        phi0: 0.0,
    };
    let full = response(&FeSystem::full(&rotor), &speed, 1.0, FeMethod::Exact);
    eprintln!("constant 300 rad/s, 1 s from rest at 10 kHz:");
    let e = errors(&rotor, &full, &speed, 1.0, FeMethod::Exact, &bases(&rotor));
    // static shapes beat twice the modes by orders of magnitude; more modes help
    // (measured: 2.2e-2, 1.0e-2, 1.6e-5, 9.6e-7, 5.5e-8)
    assert!(e[2] < 1e-2 * e[1] && e[3] < e[2] && e[4] < e[3], "{e:?}");
    assert!(e[3] < 2e-6, "{e:?}");
}

#[test]
fn reduced_model_converges_to_the_full_one_on_a_run_up_through_two_criticals() {
    let rotor = ross_rotor();
    // 0 -> 450 rad/s in 2 s, through 122 and 316 rad/s
    let speed = SpeedProfile::Ramp {
        omega0: 0.0,
        accel: 225.0,
        phi0: 0.0,
    };
    let full = response(&FeSystem::full(&rotor), &speed, 2.0, FeMethod::Magnus);
    eprintln!("run-up 0 -> 450 rad/s in 2 s from rest at 10 kHz:");
    let e = errors(&rotor, &full, &speed, 2.0, FeMethod::Magnus, &bases(&rotor));
    // (measured: 3.3e-2, 1.2e-2, 2.6e-6, 5.6e-9, 4.9e-9: at 12 modes the reduction error
    // is below the integrators' own differences)
    assert!(
        e[2] < 1e-3 * e[1] && e[3] < 1e-2 * e[2] && e[4] < 2.0 * e[3],
        "{e:?}"
    );
    assert!(e[3] < 2e-8, "{e:?}");
}

#[test]
fn reduced_derivatives_are_the_projected_full_ones() {
    let rotor = ross_rotor();
    let basis = RitzBasis::new(&rotor, 6).unwrap();
    let t = basis.matrix();
    let full = FeSystem::full(&rotor);
    let red = basis.system(&rotor).unwrap();
    // the bearings are exact in the reduced matrices: T^T (K + K_b) T
    let k = t.transpose() * full.stiffness0() * t;
    assert!((&k - red.stiffness0()).amax() < 1e-12 * k.amax());
    for p in FeParameter::all(&rotor) {
        let (a, b) = (full.derivative(p).unwrap(), red.derivative(p).unwrap());
        let proj = |m: &DMatrix<f64>| t.transpose() * m * t;
        match (a, b) {
            (FeDerivative::Stiffness(a), FeDerivative::Stiffness(b))
            | (FeDerivative::Damping(a), FeDerivative::Damping(b)) => {
                assert!((proj(&a) - &b).amax() < 1e-13 * b.amax().max(1e-300), "{p}")
            }
            (FeDerivative::Load(a), FeDerivative::Load(b)) => {
                let pa = t.transpose().map(nalgebra::Complex::from) * a;
                assert!((pa - &b).camax() < 1e-13 * b.camax(), "{p}")
            }
            other => panic!("{p}: {other:?}"),
        }
    }
}
