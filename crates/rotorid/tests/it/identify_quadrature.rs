//! Observed order of every running quadrature rule on cascaded integrals of cos, from the
//! first sample (start-up included): halving h must divide the error by 2^order at every
//! level. A wrong coefficient breaks the order, so this fails.

use rotorid::identify::algebraic::{Quadrature, RunningIntegrals, LEVELS};

/// I1..I4 of cos from 0: sin t, 1 - cos t, t - sin t, t^2/2 - 1 + cos t.
fn exact(t: f64) -> [f64; LEVELS] {
    [
        t.sin(),
        1.0 - t.cos(),
        t - t.sin(),
        0.5 * t * t - 1.0 + t.cos(),
    ]
}

/// |error| of each level at t = `end` with step h.
fn errors(q: Quadrature, h: f64, end: f64) -> [f64; LEVELS] {
    let n = (end / h).round() as usize;
    let mut ri = RunningIntegrals::<1>::new(q, h).unwrap();
    for i in 0..=n {
        ri.push(&[(i as f64 * h).cos()]);
    }
    let want = exact(n as f64 * h);
    std::array::from_fn(|k| (ri.levels()[k + 1][0] - want[k]).abs())
}

#[test]
fn every_rule_shows_its_order_at_every_level() {
    for q in Quadrature::ALL {
        let p = q.order() as f64;
        for h in [0.05, 0.025] {
            let (e1, e2) = (errors(q, h, 2.0), errors(q, h / 2.0, 2.0));
            for k in 0..LEVELS {
                let observed = (e1[k] / e2[k]).log2();
                assert!(
                    (observed - p).abs() < 0.3,
                    "{q}: level {} observed order {observed:.2} (expected {p}) at h = {h}: {:e} -> {:e}",
                    k + 1,
                    e1[k],
                    e2[k]
                );
            }
        }
    }
}

#[test]
fn error_constants_are_those_of_the_rules() {
    // One running integral over [0, T] with many steps: global error ~ |C| h^p (f^(p-1)(T) -
    // f^(p-1)(0)) with C the rule's error constant (trapezoid -1/12, AM3 -1/24, AM4 -19/720,
    // AM5 -27/1440). f = cos: f^(p-1) = derivative p-1 of cos.
    let consts = [1.0 / 12.0, 1.0 / 24.0, 19.0 / 720.0, 27.0 / 1440.0];
    let t = 1.0;
    for (q, c) in Quadrature::ALL.into_iter().zip(consts) {
        let p = q.order();
        let h = 0.02;
        let e = errors(q, h, t)[0];
        // d^(p-1)/dt^(p-1) cos t: cos, -sin, -cos, sin, cos ...
        let deriv = |x: f64| match (p - 1) % 4 {
            0 => x.cos(),
            1 => -x.sin(),
            2 => -x.cos(),
            _ => x.sin(),
        };
        let predicted = c * h.powi(p as i32) * (deriv(t) - deriv(0.0)).abs();
        assert!(
            (e / predicted - 1.0).abs() < 0.1,
            "{q}: error {e:e}, predicted {predicted:e}"
        );
    }
}

#[test]
fn weights_are_the_documented_ones() {
    let table: [(&str, &[f64], f64); 4] = [
        ("trapezoid", &[1.0, 1.0], 2.0),
        ("am3", &[5.0, 8.0, -1.0], 12.0),
        ("am4", &[9.0, 19.0, -5.0, 1.0], 24.0),
        ("am5", &[251.0, 646.0, -264.0, 106.0, -19.0], 720.0),
    ];
    for (name, num, den) in table {
        let q: Quadrature = name.parse().unwrap();
        assert_eq!(q.name(), name);
        assert_eq!(q.order(), num.len());
        for (w, n) in q.weights().iter().zip(num) {
            assert!((w - n / den).abs() < 1e-16, "{name}");
        }
    }
    assert_eq!(Quadrature::default(), Quadrature::AdamsMoulton5);
}
