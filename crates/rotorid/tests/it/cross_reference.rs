//! The cross-coupled test reference (`cross_common`) against itself and the library: the
//! matrix exponential against RK4 at constant speed, RK4 on a ramp against the library's
//! DoPri8 reference on the Jeffcott rotor and against itself at twice the sub-steps, the
//! test rotors' stability, the sense of whirl the cross-coupling feeds, and the
//! finite-difference Cramer-Rao bound against refine's on the Jeffcott rotor.

use crate::cross_common::*;
use rotorid::refine::{crb_at_snr, Unknowns};
use rotorid::simulate::{simulate, Method};
use rotorid::{Sampling, Scenario};

/// Largest |a - b| over both channels relative to the larger RMS amplitude of `b`.
fn deviation(a: &rotorid::simulate::TimeResponse, b: &rotorid::simulate::TimeResponse) -> f64 {
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let scale = rms(&b.x).max(rms(&b.z));
    a.x.iter()
        .zip(&b.x)
        .chain(a.z.iter().zip(&b.z))
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
        / scale
}

#[test]
fn matrix_exponential_and_rk4_agree_at_constant_speed() {
    for rotor in [
        CrossRotor::cross(),
        CrossRotor::asymmetric(),
        CrossRotor::table1(),
    ] {
        let case = Case::new(rotor, Speed::rpm1200(), 1.0).with_initial_state();
        let (exact, rk) = (exact_constant(&case), rk4(&case, 64));
        let d = deviation(&rk, &exact);
        println!("{rotor:?}: RK4 (64 sub-steps) vs exp(A dt): {d:.1e} of the RMS amplitude");
        // measured 1e-11 .. 3e-11; a wrong sign of any term is ~1e-1
        assert!(d < 1e-9, "{d:e}");
        assert_eq!(exact.len(), 10_001);
        assert_eq!(exact.t[10_000], 1.0);
    }
}

#[test]
fn rk4_on_a_ramp_matches_the_library_reference_and_converges() {
    // the Jeffcott rotor: the library's DoPri8 reference is an independent integrator
    let mut sc = Scenario::table1_ramp(600.0).unwrap();
    sc.sampling = Sampling::new(1e-4, 1.0).unwrap();
    let lib = simulate(&sc, Method::Exact).unwrap();
    let case = Case::new(CrossRotor::table1(), Speed::ramp(600.0), 1.0);
    let mine = case.simulate();
    let d = deviation(&mine, &lib);
    println!("RK4 ramp vs the library's DoPri8: {d:.1e}");
    assert!(d < 1e-9, "{d:e}");
    // the cross-coupled rotor: halving the sub-step changes nothing that matters
    let case = Case::new(CrossRotor::cross(), Speed::ramp(0.0), 1.0).with_initial_state();
    let d = deviation(&rk4(&case, 64), &rk4(&case, 128));
    println!("cross ramp, RK4 64 vs 128 sub-steps: {d:.1e}");
    assert!(d < 1e-10, "{d:e}");
}

#[test]
fn the_test_rotors_are_stable_and_the_cross_coupling_feeds_forward_whirl() {
    // every test rotor decays at every speed of the tests (0 .. 1300 rpm: the ramps
    // reach 1200 rpm + 10 rad/s)
    for rotor in [
        CrossRotor::table1(),
        CrossRotor::cross(),
        CrossRotor::weak_cross_damping(),
        CrossRotor::anisotropic(),
        CrossRotor::asymmetric(),
    ] {
        let worst = (0..=13)
            .map(|i| rotor.growth_rate(i as f64 * 100.0 * std::f64::consts::PI / 30.0))
            .fold(f64::NEG_INFINITY, f64::max);
        println!("{rotor:?}: largest real part {worst:.2} 1/s");
        assert!(worst < -0.3, "{worst}");
    }
    // with the direct damping of table1's order (200 N s/m) the cross rotor is unstable,
    // and the mode that grows whirls forward: (x, z) = r (sin, cos) turns from +z to +x,
    // i.e. its shape has X / Z = -i for an eigenvalue of positive imaginary part
    let weak = CrossRotor {
        cxx: 200.0,
        czz: 200.0,
        ..CrossRotor::cross()
    };
    let w = 1200.0 * std::f64::consts::PI / 30.0;
    assert!(weak.growth_rate(w) > 5.0, "{}", weak.growth_rate(w));
    let eig = weak.state_matrix(w, 0.0).complex_eigenvalues();
    let lambda = eig
        .iter()
        .filter(|l| l.im > 0.0)
        .max_by(|a, b| a.re.total_cmp(&b.re))
        .unwrap();
    let a = weak
        .state_matrix(w, 0.0)
        .map(|v| nalgebra::Complex::new(v, 0.0))
        - nalgebra::Matrix4::<nalgebra::Complex<f64>>::identity() * *lambda;
    // the null vector: the last column of V of the SVD
    let svd = a.svd(true, true);
    let (imin, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|p, q| p.1.total_cmp(q.1))
        .unwrap();
    let v = svd.v_t.unwrap().row(imin).map(|c| c.conj());
    let ratio = v[0] / v[1];
    println!("growing mode {lambda}: X/Z = {ratio}");
    assert!(
        lambda.re > 0.0 && (ratio - nalgebra::Complex::new(0.0, -1.0)).norm() < 0.2,
        "{ratio}"
    );
    // and with the signs swapped it is backward whirl that the cross terms feed
    let swapped = CrossRotor {
        kxz: -weak.kxz,
        kzx: -weak.kzx,
        ..weak
    };
    let eig = swapped.state_matrix(w, 0.0).complex_eigenvalues();
    let grows = eig.iter().filter(|l| l.re > 0.0 && l.im > 0.0).count();
    assert_eq!(grows, 1);
}

#[test]
fn the_finite_difference_bound_is_refines_cramer_rao_bound() {
    // the Jeffcott rotor, m, cx, cz, kx, kz and the initial state unknown, 40 dB
    let case = Case::new(CrossRotor::table1(), Speed::rpm1200(), 1.0);
    let (_, sigma) = noisy(&case.simulate(), 40.0, 1);
    let mine = crb(&case, sigma, Some(&[0, 1, 4, 5, 8]));
    let mut sc = Scenario::table1();
    sc.sampling = Sampling::new(1e-4, 1.0).unwrap();
    let theirs = crb_at_snr(&sc, 40.0, &Unknowns::default()).unwrap();
    for ((i, sd), name) in mine.iter().zip(["m", "cx", "cz", "kx", "kz"]) {
        let want = theirs.get(name).unwrap().std_dev;
        println!("{}: {sd:.5e} vs refine {want:.5e}", PARAMS[*i]);
        // measured within 7e-5
        assert!((sd / want - 1.0).abs() < 1e-3, "{name}: {sd} vs {want}");
    }
}
