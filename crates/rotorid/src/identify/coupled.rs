//! The cross-coupled rotor's unknowns per row, as both cross-coupled identifiers report
//! them (docs/method.md sections 3.10 and 4.8): m and the four bearing coefficients of the
//! row's equation, the x row's first.

/// Names of the ten per-row values of the cross-coupled identifiers, in the order of their
/// `values()`: the x row's (m_x, cxx, cxz, kxx, kxz), then the z row's
/// (m_z, czx, czz, kzx, kzz). kxz is the restoring force in x per unit displacement in z,
/// as kxx is per unit x (it stands on the left of the x equation); m is estimated per row.
pub const CROSS_NAMES: [&str; 10] = [
    "m_x", "cxx", "cxz", "kxx", "kxz", "m_z", "czx", "czz", "kzx", "kzz",
];

/// Units of [`CROSS_NAMES`], same order.
pub const CROSS_UNITS: [&str; 10] = [
    "kg", "N s/m", "N s/m", "N/m", "N/m", "kg", "N s/m", "N s/m", "N/m", "N/m",
];

/// The x row's five values then the z row's, in the order of [`CROSS_NAMES`].
#[inline]
pub(crate) fn ten(x: &[f64; 5], z: &[f64; 5]) -> [f64; 10] {
    std::array::from_fn(|i| if i < 5 { x[i] } else { z[i - 5] })
}
