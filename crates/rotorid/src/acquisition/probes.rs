//! Probes -> x, z \[m\] (docs/acquisition.md section 4).
//!
//! A probe mounted at angle theta (from +x towards +z, the direction from the shaft centre
//! to the probe) reads the shaft's displacement towards it,
//!
//! ```text
//! d = x cos(theta) + z sin(theta)                                           [m]
//! V = V_dc + s d       (s the sensitivity [V/m], signed as given)           [V]
//! ```
//!
//! so `V - V_dc = s d` is the contract of `[[acquisition.probe]]`: a usual proximity probe,
//! whose output grows more negative with the gap, has s > 0 (7874 V/m = 200 mV/mil) since
//! a displacement towards it closes the gap; a probe wired the other way has s < 0. With
//! two probes,
//!
//! ```text
//! [d1]   [cos t1  sin t1] [x]          [x]     1      [ sin t2  -sin t1] [d1]
//! [d2] = [cos t2  sin t2] [z],         [z] = -----    [-cos t2   cos t1] [d2]
//!                                            sin(t2 - t1)
//! ```
//!
//! which needs |sin(t2 - t1)| >= sin 30 deg = 0.5 (lines of sight at least 30 deg apart;
//! otherwise the noise of x, z grows by 1 / |sin(t2 - t1)| > 2 and an error says so).

use nalgebra::Matrix2;

use super::error::AcquisitionError;

/// The smallest angle between the two probes' lines of sight \[deg\].
pub const MIN_PROBE_SEPARATION_DEG: f64 = 30.0;

/// The angle between two lines of sight at `a1`, `a2` \[rad\], in \[0, 90\] deg.
pub fn separation_deg(a1: f64, a2: f64) -> f64 {
    let d = (a2 - a1).rem_euclid(std::f64::consts::PI).to_degrees();
    d.min(180.0 - d)
}

/// The 2x2 projection P (rows (cos t_i, sin t_i)): d = P (x, z).
pub fn projection(angles: [f64; 2]) -> Matrix2<f64> {
    let [(s1, c1), (s2, c2)] = angles.map(f64::sin_cos);
    Matrix2::new(c1, s1, c2, s2)
}

/// P^-1, or [`AcquisitionError::ProbesTooClose`] when the lines of sight are less than
/// [`MIN_PROBE_SEPARATION_DEG`] apart.
pub fn inverse_projection(angles: [f64; 2]) -> Result<Matrix2<f64>, AcquisitionError> {
    let sep = separation_deg(angles[0], angles[1]);
    if sep.is_nan() || sep < MIN_PROBE_SEPARATION_DEG - 1e-9 {
        return Err(AcquisitionError::ProbesTooClose {
            angle1_deg: angles[0].to_degrees(),
            angle2_deg: angles[1].to_degrees(),
            separation_deg: sep,
        });
    }
    Ok(projection(angles)
        .try_inverse()
        .expect("separation >= 30 deg makes P invertible"))
}

/// The correlation of the conditioned x and z noises when the two probes at `angles`
/// \[rad\] carry independent noises of equal level: the off-diagonal of
/// P^-1 P^-T over the root of its diagonal (0 for probes at right angles, cos of the
/// separation in magnitude otherwise).
pub fn noise_correlation(angles: [f64; 2]) -> Result<f64, AcquisitionError> {
    let inv = inverse_projection(angles)?;
    let c = inv * inv.transpose();
    Ok(c[(0, 1)] / (c[(0, 0)] * c[(1, 1)]).sqrt())
}

/// Displacement towards a probe at `angle` \[rad\] for shaft displacement (x, z) \[m\].
#[inline]
pub fn toward(angle: f64, x: f64, z: f64) -> f64 {
    let (s, c) = angle.sin_cos();
    x * c + z * s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_correlation_is_the_closed_form_of_the_normal_matrix() {
        // Cov(x, z) = sigma^2 (P^T P)^-1 with P^T P = [[c1^2 + c2^2, c1 s1 + c2 s2], [.,
        // s1^2 + s2^2]], so r = -(c1 s1 + c2 s2) / sqrt((c1^2 + c2^2)(s1^2 + s2^2))
        for (a1, a2) in [
            (45.0f64, 135.0f64),
            (0.0, 90.0),
            (60.0, 120.0),
            (0.0, 30.0),
            (10.0, 140.0),
            (200.0, 250.0),
        ] {
            let (s1, c1) = a1.to_radians().sin_cos();
            let (s2, c2) = a2.to_radians().sin_cos();
            let r = -(c1 * s1 + c2 * s2) / ((c1 * c1 + c2 * c2) * (s1 * s1 + s2 * s2)).sqrt();
            let got = noise_correlation([a1.to_radians(), a2.to_radians()]).unwrap();
            assert!((got - r).abs() < 1e-12, "{a1} {a2}: {got} vs {r}");
        }
        // at right angles, whatever the orientation, none
        assert!(
            noise_correlation([0.3, 0.3 + std::f64::consts::FRAC_PI_2])
                .unwrap()
                .abs()
                < 1e-12
        );
        assert!((noise_correlation([0.0, 30f64.to_radians()]).unwrap() + 0.6547).abs() < 1e-4);
    }

    #[test]
    fn inversion_recovers_x_and_z_for_any_admissible_pair() {
        for (a1, a2) in [(0.0, 90.0), (135.0, 45.0), (10.0, 40.0), (-20.0, 200.0)] {
            let ang = [f64::to_radians(a1), f64::to_radians(a2)];
            let inv = inverse_projection(ang).unwrap();
            let (x, z) = (3.0e-6, -7.0e-6);
            let d = nalgebra::Vector2::new(toward(ang[0], x, z), toward(ang[1], x, z));
            let q = inv * d;
            assert!(
                (q[0] - x).abs() < 1e-20 && (q[1] - z).abs() < 1e-20,
                "{a1} {a2}"
            );
        }
    }

    #[test]
    fn probes_on_nearly_the_same_line_are_rejected() {
        for (a1, a2) in [(0.0, 29.0), (45.0, 45.0), (0.0, 180.0), (10.0, 200.0)] {
            match inverse_projection([f64::to_radians(a1), f64::to_radians(a2)]) {
                Err(AcquisitionError::ProbesTooClose { separation_deg, .. }) => {
                    assert!(separation_deg < 30.0)
                }
                other => panic!("{a1} {a2}: {other:?}"),
            }
        }
    }
}
