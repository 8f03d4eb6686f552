//! The descriptions against independent references: the 2-DOF equation written out as
//! docs/method.md sections 1.2 and 1.6 write it, the matrices and force `Rotor` computes,
//! the finite-element system `FeSystem` assembles (full and reduced), central finite
//! differences of every derivative, and the existing simulator's response against a
//! Runge-Kutta integration of the description's equation.

use std::sync::Arc;

use nalgebra::{Complex, DMatrix, DVector};

use super::*;
use crate::model::finite_element::{
    Bearing, Dof, FeMatrices, FeParameter, FeSystem, FeUnbalance, FiniteElementRotor, RitzBasis,
};
use crate::model::{Rotor, Scenario, SpeedState};
use crate::test_models;

/// A few rotor states: at rest, constant speed, accelerating, decelerating.
fn states() -> [SpeedState; 4] {
    let s = |phi, omega, omega_dot| SpeedState {
        phi,
        omega,
        omega_dot,
    };
    [
        s(0.0, 0.0, 0.0),
        s(1.3, 125.66, 0.0),
        s(-0.4, 210.0, 35.0),
        s(7.9, 80.0, -12.5),
    ]
}

/// Largest |entry| of the difference over the largest |entry| of `b` (1 when b is 0).
fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    (a - b).amax() / b.amax().max(f64::MIN_POSITIVE)
}

fn relv(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).amax() / b.amax().max(f64::MIN_POSITIVE)
}

// ---------------------------------------------------------------------------------------
// the 2-DOF rotor

/// M q'' + C(w) q' + K(w') q written out per direction as docs/method.md section 1.6 does
/// (section 1.2 with the cross terms 0).
fn method_md_left_side(
    p: &crate::model::RotorParams,
    s: &SpeedState,
    q: [f64; 2],
    v: [f64; 2],
    acc: [f64; 2],
) -> [f64; 2] {
    let c = p.cross();
    let (w, wd) = (s.omega, s.omega_dot);
    [
        p.m * acc[0] + p.cx * v[0] + c.cxz * v[1] - p.a * w * v[1] + p.kx * q[0] + c.kxz * q[1]
            - p.a * wd * q[1],
        p.m * acc[1] + c.czx * v[0] + p.cz * v[1] + p.a * w * v[0] + c.kzx * q[0] + p.kz * q[1],
    ]
}

/// The right side of section 1.2: m_u d (w^2 sin th - w' cos th, w' sin th + w^2 cos th).
fn method_md_force(p: &crate::model::RotorParams, s: &SpeedState) -> [f64; 2] {
    let th = s.phi + p.unbalance.alpha;
    let (w2, wd, mud) = (s.omega * s.omega, s.omega_dot, p.unbalance.mud());
    [
        mud * (w2 * th.sin() - wd * th.cos()),
        mud * (wd * th.sin() + w2 * th.cos()),
    ]
}

/// table1 (Jeffcott), the cross-coupled test rotor, and each with every value moved.
fn two_dof_rotors() -> Vec<Rotor> {
    let jeffcott = Rotor::table1();
    let cross = Rotor::new(test_models::cross_coupled_rotor()).unwrap();
    let mut out = vec![jeffcott, cross];
    for r in [jeffcott, cross] {
        let d = TwoDofRotor::new(&r);
        let theta = d
            .nominal()
            .map_with_location(|i, _, v| v * (1.0 + 0.013 * (i as f64 + 1.0)) + 0.1);
        out.push(Rotor::new(d.rotor_params(&theta).unwrap()).unwrap());
    }
    out
}

#[test]
fn two_dof_matrices_are_the_equation_of_method_md_and_the_rotors() {
    let mut worst: f64 = 0.0;
    for rotor in two_dof_rotors() {
        let p = rotor.params();
        for unbalance in [UnbalanceCoordinates::Polar, UnbalanceCoordinates::Cartesian] {
            let d = TwoDofRotor::with_unbalance(&rotor, unbalance);
            assert_eq!(d.model(), rotor.model());
            let theta = d.nominal().clone();
            let m = d.matrices(&theta).unwrap();
            for s in states() {
                // against Rotor's own matrices and force (bit for bit where the
                // arithmetic is the same, to rounding for the force)
                assert_eq!(m.mass.fixed_view::<2, 2>(0, 0), rotor.mass_matrix());
                assert_eq!(
                    m.damping_at(s.omega).fixed_view::<2, 2>(0, 0),
                    rotor.damping_matrix(s.omega)
                );
                assert_eq!(
                    m.stiffness_at(s.omega_dot).fixed_view::<2, 2>(0, 0),
                    rotor.stiffness_matrix(s.omega_dot)
                );
                let f = d.force(&theta, &s).unwrap();
                let fr = rotor.unbalance_force(&s);
                let scale = fr
                    .amax()
                    .max(p.unbalance.mud() * s.omega * s.omega)
                    .max(1e-300);
                let e = (f[0] - fr[0]).abs().max((f[1] - fr[1]).abs()) / scale;
                worst = worst.max(e);
                assert!(e < 1e-14, "{:?}: force {f} vs {fr}", rotor.model());
                // against the equation written out per direction (docs/method.md)
                let (q, v, acc) = ([1.1e-5, -7.3e-6], [2.2e-3, 3.1e-3], [-0.4, 0.9]);
                let lhs = &m.mass * DVector::from_row_slice(&acc)
                    + m.damping_at(s.omega) * DVector::from_row_slice(&v)
                    + m.stiffness_at(s.omega_dot) * DVector::from_row_slice(&q);
                let want = method_md_left_side(&p, &s, q, v, acc);
                for i in 0..2 {
                    assert!(
                        (lhs[i] - want[i]).abs() <= 1e-14 * want[i].abs().max(1.0),
                        "{i}: {lhs} vs {want:?}"
                    );
                }
                let want = method_md_force(&p, &s);
                for i in 0..2 {
                    assert!(
                        (f[i] - want[i]).abs() <= 1e-14 * scale,
                        "{i}: {f} vs {want:?}"
                    );
                }
            }
            // theta and rotor_params are each other's inverse
            let back = d.theta(&d.rotor_params(&theta).unwrap());
            assert!(relv(&back, &theta) < 1e-15, "{back} vs {theta}");
            assert_eq!(d.output_map(), &DMatrix::<f64>::identity(2, 2));
            assert_eq!(d.channels(), ["x", "z"]);
        }
    }
    println!("2-DOF force: largest relative difference from Rotor::unbalance_force {worst:.1e}");
}

#[test]
fn two_dof_parameters_are_the_models_names() {
    let j = TwoDofRotor::new(&Rotor::table1());
    let names: Vec<_> = j.parameters().iter().map(|p| p.name()).collect();
    assert_eq!(names, ["m", "cx", "kx", "cz", "kz", "a", "mud", "alpha"]);
    let c = TwoDofRotor::with_unbalance(
        &Rotor::new(test_models::cross_coupled_rotor()).unwrap(),
        UnbalanceCoordinates::Cartesian,
    );
    let names: Vec<_> = c.parameters().iter().map(|p| p.name()).collect();
    assert_eq!(
        names,
        [
            "m",
            "cxx",
            "cxz",
            "czx",
            "czz",
            "kxx",
            "kxz",
            "kzx",
            "kzz",
            "a",
            "mud_cos_alpha",
            "mud_sin_alpha"
        ]
    );
    assert_eq!(c.index_by_name("kzx"), Ok(7));
    match j.index_by_name("kxz") {
        Err(DescriptionError::NotInModel { name, allowed }) => {
            assert_eq!(name, "kxz");
            assert_eq!(allowed, "m, cx, kx, cz, kz, a, mud, alpha");
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        j.index_by_name("k_x"),
        Err(DescriptionError::UnknownName { .. })
    ));
    assert_eq!(
        j.matrices(&DVector::zeros(3)),
        Err(DescriptionError::ThetaLength {
            expected: 8,
            got: 3
        })
    );
    assert_eq!(
        j.derivative(j.nominal(), 8),
        Err(DescriptionError::ParameterIndex { index: 8, len: 8 })
    );
    let mut bad = j.nominal().clone();
    bad[2] = -1.0;
    assert_eq!(
        j.validate(&bad).unwrap_err().to_string(),
        "kx = -1 is out of range: must be finite and > 0 (N/m)"
    );
    assert!(j.validate(j.nominal()).is_ok());
}

// ---------------------------------------------------------------------------------------
// derivatives

/// Every analytic derivative of `d` at `theta` against the central difference
/// (X(th + h e_j) - X(th - h e_j)) / 2h of each matrix and of the force at `states()`;
/// returns the largest relative difference. A derivative the description calls zero
/// must have a central difference of rounding size (below 1e-6 of what a unit change of
/// th_j times the matrix's size would give).
fn check_derivatives(d: &dyn RotorDescription, theta: &DVector<f64>) -> f64 {
    let mut worst: f64 = 0.0;
    let n = d.coordinates();
    let base = d.matrices(theta).unwrap();
    for (j, p) in d.parameters().iter().enumerate() {
        let analytic = d.derivative(theta, j).unwrap();
        let h = 1e-6 * theta[j].abs().max(1e-3 * theta.amax().min(1.0)).max(1e-9);
        let (mut tp, mut tm) = (theta.clone(), theta.clone());
        tp[j] += h;
        tm[j] -= h;
        let (mp, mm) = (d.matrices(&tp).unwrap(), d.matrices(&tm).unwrap());
        type Pick = fn(&Matrices) -> &DMatrix<f64>;
        type PickD = fn(&Derivative) -> &Option<DMatrix<f64>>;
        let parts: [(&str, Pick, PickD); 5] = [
            ("M", |m| &m.mass, |d| &d.mass),
            ("C", |m| &m.damping, |d| &d.damping),
            ("G", |m| &m.gyroscopic, |d| &d.gyroscopic),
            ("K", |m| &m.stiffness, |d| &d.stiffness),
            ("Ka", |m| &m.acceleration, |d| &d.acceleration),
        ];
        for (name, pick, pick_d) in parts {
            let fd = (pick(&mp) - pick(&mm)) / (2.0 * h);
            match pick_d(&analytic) {
                Some(a) => {
                    let e = rel(&fd, a);
                    worst = worst.max(e);
                    assert!(e < 1e-6, "{p}: d{name} {fd} vs {a}");
                }
                None => {
                    let size = pick(&base).amax() / theta[j].abs().max(h);
                    assert!(
                        fd.amax() <= 1e-6 * size,
                        "{p}: d{name} = {fd}, said to be zero"
                    );
                }
            }
            assert_eq!(fd.shape(), (n, n));
        }
        for s in states() {
            let fd = (d.force(&tp, &s).unwrap() - d.force(&tm, &s).unwrap()) / (2.0 * h);
            let a = analytic
                .load
                .as_ref()
                .map_or_else(|| DVector::zeros(n), |l| unbalance_force(l, &s));
            if analytic.load.is_some() && s.omega != 0.0 {
                let e = relv(&fd, &a);
                worst = worst.max(e);
                assert!(e < 1e-6, "{p} at {s:?}: df {fd} vs {a}");
            } else {
                let size = d.force(theta, &s).unwrap().amax() / theta[j].abs().max(h);
                assert!(
                    (&fd - &a).amax() <= 1e-6 * size.max(1e-300),
                    "{p}: df {fd} vs {a}"
                );
            }
        }
    }
    worst
}

#[test]
fn two_dof_derivatives_equal_central_differences() {
    let mut worst: f64 = 0.0;
    for rotor in two_dof_rotors() {
        for unbalance in [UnbalanceCoordinates::Polar, UnbalanceCoordinates::Cartesian] {
            let d = TwoDofRotor::with_unbalance(&rotor, unbalance);
            worst = worst.max(check_derivatives(&d, d.nominal()));
        }
    }
    println!("2-DOF derivatives: largest relative difference from central differences {worst:.1e}");
}

// ---------------------------------------------------------------------------------------
// the finite-element rotor

/// Three nodes with x, y, rx, ry; a shaft damping C and a Ka; two bearings with every
/// coefficient non-zero and two unbalances; distinct entries so a wrong index shows.
fn fe_rotor() -> FiniteElementRotor {
    let dofs: Vec<Dof> = (0..3)
        .flat_map(|n| ["x", "y", "rx", "ry"].map(|k| format!("{n}.{k}").parse().unwrap()))
        .collect();
    let n = dofs.len();
    let a = DMatrix::from_fn(n, n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0);
    let m = &a * a.transpose() + DMatrix::identity(n, n) * 2.0;
    let k = DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            4e5 + 1e4 * i as f64
        } else {
            1e4 * ((i + 2 * j) % 3) as f64
        }
    });
    let k = (&k + k.transpose()) * 0.5;
    let g = DMatrix::from_fn(n, n, |i, j| (i as f64 - j as f64) * 0.01);
    let c = DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            3.0
        } else {
            0.1 * ((i + j) % 2) as f64
        }
    });
    let ka = DMatrix::from_fn(n, n, |i, j| if i < j { 0.02 } else { 0.0 });
    let mats = FeMatrices::new(dofs, m, k, g, Some(c), Some(ka)).unwrap();
    let b = Bearing {
        node: 0,
        kxx: 1e6,
        kxy: -2e5,
        kyx: 3e5,
        kyy: 1.2e6,
        cxx: 300.0,
        cxy: 10.0,
        cyx: -20.0,
        cyy: 400.0,
    };
    let b2 = Bearing {
        node: 2,
        kxx: 8e5,
        kxy: 5e4,
        kyx: -4e4,
        kyy: 9e5,
        cxx: 250.0,
        cxy: -5.0,
        cyx: 7.0,
        cyy: 260.0,
    };
    let u = FeUnbalance {
        node: 1,
        mud: 1e-4,
        alpha: 0.7,
    };
    let u2 = FeUnbalance {
        node: 2,
        mud: 3e-5,
        alpha: -2.1,
    };
    FiniteElementRotor::new(Arc::new(mats), vec![b, b2], vec![u, u2]).unwrap()
}

fn fe_outputs() -> Vec<Dof> {
    ["0.x", "2.y", "1.rx", "1.x"]
        .map(|s| s.parse().unwrap())
        .to_vec()
}

/// The rotor with every bearing coefficient and unbalance moved (still valid).
fn fe_moved(r: &FiniteElementRotor) -> FiniteElementRotor {
    let mut moved = r.clone();
    for (i, p) in FeParameter::all(r).into_iter().enumerate() {
        let v = p.get(r).unwrap();
        p.set(
            &mut moved,
            v * (1.0 + 0.01 * i as f64) + if v == 0.0 { 1.0 } else { 0.0 },
        );
    }
    moved
}

/// The description's matrices, load, force and output map against `FeSystem`'s.
fn compare_with_system(d: &FiniteElementDescription, theta: &DVector<f64>, s: &FeSystem) -> f64 {
    let m = d.matrices(theta).unwrap();
    let mut worst: f64 = 0.0;
    let mut check = |what: &str, e: f64| {
        worst = worst.max(e);
        assert!(e < 1e-13, "{what}: {e:e}");
    };
    check("M", rel(&m.mass, s.mass()));
    check("C", rel(&m.damping, s.damping0()));
    check("G", rel(&m.gyroscopic, s.gyroscopic()));
    check("K", rel(&m.stiffness, s.stiffness0()));
    check("Ka", rel(&m.acceleration, s.ka().unwrap()));
    for st in states() {
        check("C(w)", rel(&m.damping_at(st.omega), &s.damping(st.omega)));
        check(
            "K(w')",
            rel(&m.stiffness_at(st.omega_dot), &s.stiffness(st.omega_dot)),
        );
        if st.omega != 0.0 {
            check("f", relv(&d.force(theta, &st).unwrap(), &s.force(&st)));
        }
    }
    let p = d.load(theta).unwrap();
    let e = (&p - s.load()).map(|z| z.norm()).amax() / s.load().map(|z| z.norm()).amax();
    check("P", e);
    check(
        "H",
        rel(d.output_map(), &s.output_map(&fe_outputs()).unwrap()),
    );
    worst
}

#[test]
fn finite_element_matrices_are_the_systems_full_and_reduced() {
    let r = fe_rotor();
    let moved = fe_moved(&r);
    let basis = RitzBasis::new(&r, 3).unwrap();
    let t = basis.matrix();
    let mut worst: f64 = 0.0;
    for reduced in [false, true] {
        let d = if reduced {
            FiniteElementDescription::reduced(&r, t, &fe_outputs()).unwrap()
        } else {
            FiniteElementDescription::full(&r, &fe_outputs()).unwrap()
        };
        let system = |rotor: &FiniteElementRotor| {
            if reduced {
                FeSystem::reduced(rotor, t).unwrap()
            } else {
                FeSystem::full(rotor)
            }
        };
        assert_eq!(d.coordinates(), if reduced { t.ncols() } else { 12 });
        assert_eq!(d.basis().is_some(), reduced);
        assert_eq!(d.channels(), ["0.x", "2.y", "1.rx", "1.x"]);
        // the parameters are FeParameter::all's, by name, at the rotor's values
        let names: Vec<String> = FeParameter::all(&r).iter().map(|p| p.to_string()).collect();
        let ours: Vec<String> = d.parameters().iter().map(|p| p.to_string()).collect();
        assert_eq!(ours, names);
        assert_eq!(d.parameters().len(), 20);
        worst = worst.max(compare_with_system(&d, d.nominal(), &system(&r)));
        // at other values: th of the moved rotor against the system assembled from it
        let theta = DVector::from_iterator(
            20,
            FeParameter::all(&r).iter().map(|p| p.get(&moved).unwrap()),
        );
        worst = worst.max(compare_with_system(&d, &theta, &system(&moved)));
    }
    println!("finite element: largest relative difference from FeSystem {worst:.1e}");
}

#[test]
fn finite_element_derivatives_equal_central_differences() {
    let r = fe_rotor();
    let basis = RitzBasis::new(&r, 3).unwrap();
    let full = FiniteElementDescription::full(&r, &fe_outputs()).unwrap();
    let reduced = FiniteElementDescription::reduced(&r, basis.matrix(), &fe_outputs()).unwrap();
    let w1 = check_derivatives(&full, full.nominal());
    let w2 = check_derivatives(&reduced, reduced.nominal());
    println!(
        "finite element derivatives: largest relative difference {:.1e}",
        w1.max(w2)
    );
}

#[test]
fn finite_element_errors_carry_the_offending_values() {
    let r = fe_rotor();
    let e = FiniteElementDescription::full(&r, &["3.x".parse().unwrap()]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "degree of freedom 3.x is not one of the rotor's 12 (see its dofs)"
    );
    let e = FiniteElementDescription::reduced(&r, &DMatrix::identity(7, 3), &[]).unwrap_err();
    assert_eq!(
        e,
        DescriptionError::Basis {
            rows: 7,
            cols: 3,
            n: 12
        }
    );
    let t = RitzBasis::new(&r, 2).unwrap();
    let c0 = t.matrix().column(0).into_owned();
    let dependent = DMatrix::from_columns(&[c0.clone(), c0.clone() * 2.0]);
    // and a basis whose columns are nearly dependent: T^T M T = [[1, 1], [1, 1 + 1e-14]]
    // (c0, c1 M-orthonormal) is positive definite to Cholesky (its factor's last diagonal
    // entry 1e-7, far above rounding) with condition number 4e14
    let c1 = t.matrix().column(1).into_owned();
    let nearly = DMatrix::from_columns(&[c0.clone(), c0 + c1 * 1e-7]);
    for t in [dependent, nearly] {
        assert!(matches!(
            FiniteElementDescription::reduced(&r, &t, &[]),
            Err(DescriptionError::Basis {
                rows: 12,
                cols: 2,
                ..
            })
        ));
    }
    let d = FiniteElementDescription::full(&r, &[]).unwrap();
    assert_eq!(d.output_map().shape(), (0, 12));
    assert_eq!(d.index_by_name("unbalance1.alpha"), Ok(19));
    let e = d.index_by_name("bearing2.kxx").unwrap_err().to_string();
    assert!(
        e.contains("bearing2.kxx is not a parameter") && e.contains("bearing1.cyy"),
        "{e}"
    );
    let mut bad = d.nominal().clone();
    bad[8 + 3] = 0.0;
    assert_eq!(
        d.validate(&bad).unwrap_err().to_string(),
        "bearing1.kyy = 0 is out of range: must be finite and > 0 (N/m)"
    );
}

// ---------------------------------------------------------------------------------------
// a simulation of the description's equation against the existing simulator

/// Classical RK4 on q'' = M^-1 (f - (C + w G) q' - (K + w' Ka) q), `sub` steps per
/// sample, from the scenario's initial state; the x and z of the first `samples`.
fn rk4_response(d: &TwoDofRotor, scenario: &Scenario, samples: usize, sub: usize) -> Vec<[f64; 2]> {
    let theta = d.nominal();
    let m = d.matrices(theta).unwrap();
    let load = d.load(theta).unwrap();
    let minv = m.mass.clone().try_inverse().unwrap();
    let accel = |t: f64, q: &DVector<f64>, v: &DVector<f64>| {
        let s = scenario.speed.at(t);
        &minv
            * (unbalance_force(&load, &s)
                - m.damping_at(s.omega) * v
                - m.stiffness_at(s.omega_dot) * q)
    };
    let i0 = scenario.initial;
    let (mut q, mut v) = (
        DVector::from_vec(vec![i0.x, i0.z]),
        DVector::from_vec(vec![i0.vx, i0.vz]),
    );
    let dt = scenario.sampling.dt();
    let h = dt / sub as f64;
    let mut out = vec![[q[0], q[1]]];
    for k in 0..samples - 1 {
        for j in 0..sub {
            let t = k as f64 * dt + j as f64 * h;
            let (k1q, k1v) = (v.clone(), accel(t, &q, &v));
            let (q2, v2) = (&q + &k1q * (h / 2.0), &v + &k1v * (h / 2.0));
            let (k2q, k2v) = (v2.clone(), accel(t + h / 2.0, &q2, &v2));
            let (q3, v3) = (&q + &k2q * (h / 2.0), &v + &k2v * (h / 2.0));
            let (k3q, k3v) = (v3.clone(), accel(t + h / 2.0, &q3, &v3));
            let (q4, v4) = (&q + &k3q * h, &v + &k3v * h);
            let (k4q, k4v) = (v4.clone(), accel(t + h, &q4, &v4));
            q += (k1q + k2q * 2.0 + k3q * 2.0 + k4q) * (h / 6.0);
            v += (k1v + k2v * 2.0 + k3v * 2.0 + k4v) * (h / 6.0);
        }
        out.push([q[0], q[1]]);
    }
    out
}

/// The tolerance, relative to the largest |x|, |z| of the record. The RK4 error over
/// n steps of h on an oscillation of frequency w is about n (w h)^5 / 120 of its
/// amplitude (the local error of the stability function, Hairer-Norsett-Wanner II.2);
/// with w = max(sqrt(k/m), forcing) ~ 290 rad/s, h = 1e-5 s and n = 2e4 steps it is
/// 3e-11, and the references are accurate to 1e-10 of the amplitude (docs/method.md
/// sections 2.2 and 2.3): 1e-9 leaves a factor of ten over both together.
const SIMULATION_TOLERANCE: f64 = 1e-9;

#[test]
fn rk4_of_the_two_dof_description_matches_the_simulator() {
    let samples = 2001; // 0.2 s at 10 kHz: the response builds up through ~9 periods
    for model in [
        test_models::table1(),
        test_models::cross_coupled(),
        test_models::table1_ramp(600.0),
    ] {
        let d = TwoDofRotor::new(&model.scenario.rotor);
        let ours = rk4_response(&d, &model.scenario, samples, 10);
        let r = &model.clean;
        let scale = r.x[..samples]
            .iter()
            .chain(&r.z[..samples])
            .fold(0.0f64, |a, v| a.max(v.abs()));
        let err = ours
            .iter()
            .enumerate()
            .map(|(i, q)| (q[0] - r.x[i]).abs().max((q[1] - r.z[i]).abs()))
            .fold(0.0, f64::max);
        println!(
            "{}: RK4 of the description vs the simulator: {:.2e} of the amplitude {scale:.3e} m",
            model.name,
            err / scale
        );
        assert!(
            scale > 0.0 && err <= SIMULATION_TOLERANCE * scale,
            "{}: {err:e} of {scale:e}",
            model.name
        );
    }
}

/// The load of a unit unbalance at angle 0 is (-i, 1): the force of section 1.2 at
/// phi = 0 is (0, w^2) per unit m_u d, the centrifugal force along +z.
#[test]
fn the_two_dof_load_points_along_z_at_phi_zero() {
    let mut p = Rotor::table1().params();
    p.unbalance.alpha = 0.0;
    let d = TwoDofRotor::new(&Rotor::new(p).unwrap());
    let load = d.load(d.nominal()).unwrap() / Complex::from(p.unbalance.mud());
    assert_eq!(
        load,
        DVector::from_vec(vec![Complex::new(0.0, -1.0), Complex::new(1.0, 0.0)])
    );
}
