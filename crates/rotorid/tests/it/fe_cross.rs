//! A one-node finite-element rotor is the cross-coupled 2-DOF rotor written in ROSS's
//! frame (docs/finite_element.md section 2): the FE simulators against the existing
//! cross-coupled simulators (`rotorid::simulate`), which are independent code.
//!
//! The map (derived in docs/finite_element.md): ROSS/FE x = x, y = -z; phi is the same
//! angle (the 2-DOF shaft turns from +z towards +x, i.e. from +x towards -z = +y);
//! G = [[0, a], [-a, 0]], Ka = [[0, a], [0, 0]], M = m I, K = 0 (the bearing carries it);
//! kxx = kx, kxy = -kxz, kyx = -kzx, kyy = kz (c likewise); alpha_FE = alpha - pi/2.

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

use nalgebra::DMatrix;
use rotorid::model::finite_element::{
    Bearing, Dof, FeMatrices, FeSystem, FeUnbalance, FiniteElementRotor,
};
use rotorid::model::{
    CrossCoupling, InitialState, Rotor, RotorParams, Sampling, Scenario, SpeedProfile,
};
use rotorid::simulate::finite_element::{simulate_fe, FeMethod, FeResponse};
use rotorid::simulate::{simulate, Method, TimeResponse};

fn cross_rotor() -> Rotor {
    Rotor::new(RotorParams {
        cx: 40.0,
        cz: 25.0,
        kx: 1.0e6,
        kz: 1.4e6,
        coupling: Some(CrossCoupling {
            cxz: 6.0,
            czx: -3.0,
            kxz: -1.2e5,
            kzx: 0.9e5,
        }),
        ..Rotor::table1().params()
    })
    .unwrap()
}

/// The same rotor as a one-node finite-element rotor in ROSS's frame (module doc).
fn as_fe(r: &Rotor) -> FiniteElementRotor {
    let dofs: Vec<Dof> = vec!["0.x".parse().unwrap(), "0.y".parse().unwrap()];
    let (m, a) = (r.m(), r.a());
    let mats = FeMatrices::new(
        dofs,
        DMatrix::identity(2, 2) * m,
        DMatrix::zeros(2, 2),
        DMatrix::from_row_slice(2, 2, &[0.0, a, -a, 0.0]),
        None,
        Some(DMatrix::from_row_slice(2, 2, &[0.0, a, 0.0, 0.0])),
    )
    .unwrap();
    let c = r.cross();
    let b = Bearing {
        node: 0,
        kxx: r.kx(),
        kxy: -c.kxz,
        kyx: -c.kzx,
        kyy: r.kz(),
        cxx: r.cx(),
        cxy: -c.cxz,
        cyx: -c.czx,
        cyy: r.cz(),
    };
    let u = FeUnbalance {
        node: 0,
        mud: r.unbalance().mud(),
        alpha: r.unbalance().alpha - FRAC_PI_2,
    };
    FiniteElementRotor::new(Arc::new(mats), vec![b], vec![u]).unwrap()
}

/// max over samples of |(x, z) - (x_fe, -y_fe)| / max |(x, z)|.
fn compare(j: &TimeResponse, fe: &FeResponse) -> f64 {
    assert_eq!(j.len(), fe.len());
    let x = fe.column("0.x".parse().unwrap()).unwrap();
    let y = fe.column("0.y".parse().unwrap()).unwrap();
    let amp = j.x.iter().chain(&j.z).fold(0.0f64, |m, v| m.max(v.abs()));
    let err = (0..j.len()).fold(0.0f64, |m, i| {
        m.max((j.x[i] - x[i]).abs()).max((j.z[i] + y[i]).abs())
    });
    for i in 0..j.len() {
        assert_eq!(j.t[i], fe.t[i]);
        assert_eq!(j.phi[i], fe.phi[i]);
    }
    err / amp
}

fn scenario(speed: SpeedProfile, duration: f64) -> Scenario {
    Scenario {
        rotor: cross_rotor(),
        speed,
        sampling: Sampling::new(1e-4, duration).unwrap(),
        initial: InitialState::default(),
    }
}

#[test]
fn one_node_rotor_equals_the_cross_coupled_rotor_at_constant_speed() {
    for rpm in [1200.0, 3000.0] {
        let sc = scenario(SpeedProfile::constant_rpm(rpm, 0.3).unwrap(), 0.5);
        let reference = simulate(&sc, Method::Exact).unwrap();
        let sys = FeSystem::full(&as_fe(&sc.rotor));
        for method in [FeMethod::Exact, FeMethod::Magnus] {
            let fe = simulate_fe(&sys, &sc.speed, &sc.sampling, None, None, method).unwrap();
            let d = compare(&reference, &fe);
            eprintln!("{rpm} rpm, {method}: max rel diff {d:.1e}");
            assert!(d < 1e-10, "{rpm} rpm {method}: {d:e}");
        }
    }
}

#[test]
fn one_node_rotor_equals_the_cross_coupled_rotor_on_a_ramp() {
    // w' terms: the tangential unbalance force and Ka. Newmark is the same scheme in both
    // (to rounding); the FE Magnus against the 2-DOF DoPri8 reference at tight tolerance.
    let sc = scenario(SpeedProfile::ramp(600.0, 300.0, 0.3).unwrap(), 0.5);
    let sys = FeSystem::full(&as_fe(&sc.rotor));
    let nm = simulate(&sc, Method::Newmark).unwrap();
    let fe_nm = simulate_fe(&sys, &sc.speed, &sc.sampling, None, None, FeMethod::Newmark).unwrap();
    let d = compare(&nm, &fe_nm);
    eprintln!("ramp, newmark: max rel diff {d:.1e}");
    assert!(d < 1e-10, "{d:e}");
    let ex = simulate(&sc, Method::Exact).unwrap();
    let fe_mg = simulate_fe(&sys, &sc.speed, &sc.sampling, None, None, FeMethod::Magnus).unwrap();
    let d = compare(&ex, &fe_mg);
    eprintln!("ramp, magnus vs dopri8: max rel diff {d:.1e}");
    assert!(d < 1e-9, "{d:e}");
}
