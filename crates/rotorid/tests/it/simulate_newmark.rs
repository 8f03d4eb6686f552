//! The paper's Newmark integrator converges at order 2 to the exact reference: halving dt
//! divides the error by 4, at constant speed and on a ramp.

use rotorid::model::{Sampling, Scenario};
use rotorid::simulate::{simulate, Method, TimeResponse};

/// Largest |newmark - exact| over both channels at the times of the coarsest grid
/// (every `stride`-th sample), relative to the largest |exact|.
fn error_on_coarse_grid(nm: &TimeResponse, ex: &TimeResponse, stride: usize) -> f64 {
    assert_eq!(nm.len(), ex.len());
    let amp = ex.x.iter().chain(&ex.z).fold(0.0f64, |m, v| m.max(v.abs()));
    let mut err = 0.0f64;
    for i in (0..nm.len()).step_by(stride) {
        assert_eq!(nm.t[i], ex.t[i]);
        err = err
            .max((nm.x[i] - ex.x[i]).abs())
            .max((nm.z[i] - ex.z[i]).abs());
    }
    err / amp
}

/// Errors of Newmark at dt0, dt0/2, dt0/4 over `duration`, at the times of the dt0 grid.
fn errors(base: Scenario, dt0: f64, duration: f64) -> Vec<f64> {
    (0..3)
        .map(|k| {
            let stride = 1 << k;
            let sc = Scenario {
                sampling: Sampling::new(dt0 / stride as f64, duration).unwrap(),
                ..base
            };
            let nm = simulate(&sc, Method::Newmark).unwrap();
            let ex = simulate(&sc, Method::Exact).unwrap();
            error_on_coarse_grid(&nm, &ex, stride)
        })
        .collect()
}

fn assert_order_two(name: &str, e: &[f64]) {
    for w in e.windows(2) {
        let order = (w[0] / w[1]).log2();
        eprintln!(
            "{name}: error {:.3e} -> {:.3e}, observed order {order:.4}",
            w[0], w[1]
        );
        assert!(
            (order - 2.0).abs() < 0.1,
            "{name}: order {order} from {e:?}"
        );
    }
}

#[test]
fn newmark_is_second_order_at_constant_speed() {
    let e = errors(Scenario::table1(), 2e-4, 0.2);
    // at the paper's 0.1 ms the error is of order (w dt)^2 / 12 per radian of phase
    assert!(e[1] > 1e-5 && e[1] < 1e-2, "{e:?}");
    assert_order_two("constant 1200 rpm", &e);
}

#[test]
fn newmark_is_second_order_on_a_ramp() {
    let e = errors(Scenario::table1_ramp(600.0).unwrap(), 2e-4, 0.2);
    assert_order_two("ramp 10 rad/s^2 from 600 rpm", &e);
}
