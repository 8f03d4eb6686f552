//! A correction split into the holes a plane has.
//!
//! A correction U = |U| e^{i beta} \[kg m\] at radius R on a plane with holes at angles
//! theta_j (all at R) becomes masses m_a, m_b >= 0 in two holes a, b whose angles enclose
//! beta less than 180 deg apart:
//!
//! ```text
//! m_a R e^{i theta_a} + m_b R e^{i theta_b} = U
//! m_a = |U| sin(theta_b - beta) / (R sin(theta_b - theta_a)),
//! m_b = |U| sin(beta - theta_a) / (R sin(theta_b - theta_a))
//! ```
//!
//! exact, and a single mass when beta is on a hole. With equally spaced holes the pair is
//! the two adjacent to beta; with a list of angles, the pair of least total mass among
//! those enclosing beta; when no pair encloses it (the holes all lie in a half-turn away
//! from beta), the best single hole, m = |U| cos(beta - theta) / R if positive, with the
//! residual that leaves.
//!
//! With a set of available masses (a box of weights: any number of each value, at most
//! `per_hole` weights stacked in one hole) the masses are chosen among the combinations for
//! any two holes (or one), minimising the residual |sum m_j R e^{i theta_j} - U|, which is
//! reported: the split is then not exact, and the residual is the unbalance it leaves
//! \[kg m\]. A far hole can win with discrete weights (4 g at 0 deg and 1 g at 135 deg
//! come closer to 3.3 g at 10 deg than any pair of the neighbours of 10 deg can).

use nalgebra::Complex;

use super::error::BalanceError;
use crate::analysis::modes::C64;
use crate::analysis::response::wrap;

/// An angle below which beta counts as on a hole \[rad\] (1e-9 rad).
const ON_HOLE: f64 = 1e-9;

/// Most combinations of available masses tried per hole.
const MAX_COMBINATIONS: usize = 20_000;

/// The holes of a plane.
#[derive(Debug, Clone, PartialEq)]
pub enum Holes {
    /// `count` holes equally spaced, the first at `offset` \[rad\] from the keyphasor mark
    /// in the direction of rotation.
    Equal {
        /// Number of holes, >= 2.
        count: usize,
        /// Angle of the first hole \[rad\].
        offset: f64,
    },
    /// Holes at these angles \[rad\].
    Angles(Vec<f64>),
}

impl Holes {
    /// The hole angles \[rad\] in \[0, 2 pi), in the order given (equally spaced: from
    /// the offset on).
    pub fn angles(&self) -> Vec<f64> {
        match self {
            Holes::Equal { count, offset } => (0..*count)
                .map(|j| wrap(offset + std::f64::consts::TAU * j as f64 / *count as f64))
                .collect(),
            Holes::Angles(a) => a.iter().map(|&x| wrap(x)).collect(),
        }
    }
}

/// The weights available for a split.
#[derive(Debug, Clone, PartialEq)]
pub struct MassSet {
    /// Masses available \[kg\], each > 0, any number of each.
    pub masses: Vec<f64>,
    /// Most weights in one hole (>= 1).
    pub per_hole: usize,
}

/// One mass of a split.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitMass {
    /// Index of the hole (in the order of [`Holes::angles`]).
    pub hole: usize,
    /// Its angle \[rad\].
    pub angle: f64,
    /// The mass \[kg\].
    pub mass: f64,
    /// With a mass set: the weights stacked in the hole \[kg\].
    pub weights: Vec<f64>,
}

/// A correction split into holes (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Split {
    /// The hole angles \[rad\].
    pub holes: Vec<f64>,
    /// The masses placed (none, one or two).
    pub masses: Vec<SplitMass>,
    /// Radius of the holes \[m\].
    pub radius: f64,
    /// The unbalance left by the split, placed - wanted \[kg m\].
    pub residual: C64,
}

impl Split {
    /// The unbalance the split places \[kg m\].
    pub fn placed(&self) -> C64 {
        self.masses
            .iter()
            .map(|m| Complex::from_polar(m.mass * self.radius, m.angle))
            .sum()
    }
}

/// Check holes and a mass set.
fn check(plane: &str, angles: &[f64], set: Option<&MassSet>) -> Result<(), BalanceError> {
    let err = |message: String| BalanceError::Holes {
        plane: plane.to_owned(),
        message,
    };
    if angles.is_empty() {
        return Err(err("no hole: give at least one".into()));
    }
    if let Some(a) = angles.iter().find(|a| !a.is_finite()) {
        return Err(err(format!("angle {a} is not finite")));
    }
    for (i, a) in angles.iter().enumerate() {
        for (j, b) in angles.iter().enumerate().skip(i + 1) {
            let d = wrap(a - b);
            if !(1e-9..=std::f64::consts::TAU - 1e-9).contains(&d) {
                return Err(err(format!(
                    "holes {} and {} are both at {:.6} deg: every hole needs its own angle",
                    i + 1,
                    j + 1,
                    a.to_degrees()
                )));
            }
        }
    }
    if let Some(s) = set {
        if s.masses.is_empty() {
            return Err(err("the mass set is empty".into()));
        }
        if let Some(m) = s.masses.iter().find(|m| !(m.is_finite() && **m > 0.0)) {
            return Err(err(format!(
                "mass {m} kg of the mass set is out of range: must be finite and > 0 (kg)"
            )));
        }
        if s.per_hole == 0 {
            return Err(err("at most 0 weights per hole: must be >= 1".into()));
        }
    }
    Ok(())
}

/// Split the correction `u` \[kg m\] at `radius` \[m\] into the holes `angles` \[rad\]
/// (module doc).
pub fn split(
    plane: &str,
    u: C64,
    radius: f64,
    holes: &Holes,
    set: Option<&MassSet>,
) -> Result<Split, BalanceError> {
    let angles = holes.angles();
    check(plane, &angles, set)?;
    if !(radius.is_finite() && radius > 0.0) {
        return Err(BalanceError::Holes {
            plane: plane.to_owned(),
            message: format!("radius {radius} m is out of range: must be finite and > 0 (m)"),
        });
    }
    let masses = match set {
        None => continuous(u, radius, &angles),
        Some(s) => discrete(u, radius, &angles, s),
    };
    let mut out = Split {
        holes: angles,
        masses,
        radius,
        residual: Complex::new(0.0, 0.0),
    };
    out.residual = out.placed() - u;
    Ok(out)
}

fn mass(hole: usize, angle: f64, mass: f64) -> SplitMass {
    SplitMass {
        hole,
        angle,
        mass,
        weights: Vec::new(),
    }
}

/// The exact split with any masses (module doc).
fn continuous(u: C64, radius: f64, angles: &[f64]) -> Vec<SplitMass> {
    let size = u.norm() / radius;
    if size == 0.0 {
        return Vec::new();
    }
    let beta = wrap(u.arg());
    // on a hole
    for (j, &t) in angles.iter().enumerate() {
        let d = wrap(beta - t);
        if !(ON_HOLE..=std::f64::consts::TAU - ON_HOLE).contains(&d) {
            return vec![mass(j, t, size)];
        }
    }
    // pairs enclosing beta less than half a turn apart: a at or before beta, b after it
    let mut best: Option<(f64, Vec<SplitMass>)> = None;
    for (ia, &ta) in angles.iter().enumerate() {
        for (ib, &tb) in angles.iter().enumerate() {
            let gap = wrap(tb - ta);
            let into = wrap(beta - ta);
            if ia == ib || gap >= std::f64::consts::PI || into >= gap {
                continue;
            }
            let s = gap.sin();
            let ma = size * (gap - into).sin() / s;
            let mb = size * into.sin() / s;
            let total = ma + mb;
            if best.as_ref().is_none_or(|b| total < b.0) {
                best = Some((total, vec![mass(ia, ta, ma), mass(ib, tb, mb)]));
            }
        }
    }
    if let Some((_, m)) = best {
        return m;
    }
    // no pair encloses beta: the best single hole
    let (j, &t) = angles
        .iter()
        .enumerate()
        .max_by(|a, b| (beta - a.1).cos().total_cmp(&(beta - b.1).cos()))
        .expect("checked: at least one hole");
    let m = size * (beta - t).cos();
    if m > 0.0 {
        vec![mass(j, t, m)]
    } else {
        Vec::new()
    }
}

/// The sums of at most `per_hole` weights of `set` (with repetition), with their weights,
/// including the empty one.
fn combinations(set: &MassSet) -> Vec<(f64, Vec<f64>)> {
    let mut values: Vec<f64> = set.masses.clone();
    values.sort_by(f64::total_cmp);
    values.dedup();
    let mut out = vec![(0.0, Vec::new())];
    let mut frontier = vec![(0.0, Vec::<f64>::new(), 0usize)];
    for _ in 0..set.per_hole {
        let mut next = Vec::new();
        for (sum, ws, start) in &frontier {
            for (i, &v) in values.iter().enumerate().skip(*start) {
                let mut w = ws.clone();
                w.push(v);
                next.push((sum + v, w, i));
                if out.len() + next.len() > MAX_COMBINATIONS {
                    break;
                }
            }
        }
        out.extend(next.iter().map(|(s, w, _)| (*s, w.clone())));
        frontier = next;
        if out.len() >= MAX_COMBINATIONS {
            break;
        }
    }
    out
}

/// The best split with the weights of `set` (module doc): for every pair of holes and
/// every combination in the first hole, the best combination in the second is one of the
/// two around the continuous optimum (the residual is a convex quadratic in its mass).
fn discrete(u: C64, radius: f64, angles: &[f64], set: &MassSet) -> Vec<SplitMass> {
    let mut combos = combinations(set);
    combos.sort_by(|a, b| a.0.total_cmp(&b.0));
    combos.dedup_by(|a, b| a.0 == b.0);
    let sums: Vec<f64> = combos.iter().map(|c| c.0).collect();
    let placed = |j: usize, m: f64| Complex::from_polar(m * radius, angles[j]);
    let entry = |j: usize, c: usize| SplitMass {
        weights: combos[c].1.clone(),
        ..mass(j, angles[j], combos[c].0)
    };
    // (residual, hole a, combination a, hole b, combination b)
    let mut best = (u.norm(), None::<(usize, usize, usize, usize)>);
    let n = angles.len();
    for ja in 0..n {
        for jb in (ja + 1)..n.max(ja + 2) {
            // one hole alone when there is only one
            let jb = jb.min(n - 1);
            for (ca, &ma) in sums.iter().enumerate() {
                let rest = u - placed(ja, ma);
                let candidates: Vec<usize> = if jb == ja {
                    vec![0]
                } else {
                    let e = Complex::from_polar(radius, angles[jb]);
                    let m_star = (e.conj() * rest).re / (radius * radius);
                    let i = sums.partition_point(|&s| s < m_star);
                    [i.saturating_sub(1), i.min(sums.len() - 1)].to_vec()
                };
                for cb in candidates {
                    let e = (rest - placed(jb, sums[cb])).norm();
                    if e < best.0 - 1e-15 * u.norm() {
                        best = (e, Some((ja, ca, jb, cb)));
                    }
                }
            }
        }
    }
    let Some((ja, ca, jb, cb)) = best.1 else {
        return Vec::new();
    };
    [(ja, ca), (jb, cb)]
        .into_iter()
        .filter(|&(_, c)| sums[c] > 0.0)
        .map(|(j, c)| entry(j, c))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deg(d: f64) -> f64 {
        d.to_radians()
    }

    #[test]
    fn a_correction_on_a_hole_is_one_mass_and_between_holes_two_exact_ones() {
        let holes = Holes::Equal {
            count: 12,
            offset: deg(15.0),
        };
        // on the hole at 75 deg
        let u = Complex::from_polar(3e-4, deg(75.0));
        let s = split("A", u, 0.1, &holes, None).unwrap();
        assert_eq!(s.masses.len(), 1);
        assert_eq!(s.masses[0].hole, 2);
        assert!((s.masses[0].mass - 3e-3).abs() < 1e-15);
        assert!(s.residual.norm() < 1e-18, "{}", s.residual);
        // between 75 and 105 deg: two masses, exactly the correction
        let u = Complex::from_polar(3e-4, deg(83.0));
        let s = split("A", u, 0.1, &holes, None).unwrap();
        assert_eq!(
            s.masses.iter().map(|m| m.hole).collect::<Vec<_>>(),
            vec![2, 3]
        );
        assert!(s.residual.norm() < 1e-15 * u.norm());
        // the closer hole gets more
        assert!(s.masses[0].mass > s.masses[1].mass);
        // across 0 deg: holes at 345 and 15 deg
        let u = Complex::from_polar(1e-4, deg(359.0));
        let s = split("A", u, 0.1, &holes, None).unwrap();
        assert_eq!(
            s.masses.iter().map(|m| m.hole).collect::<Vec<_>>(),
            vec![11, 0]
        );
        assert!(s.residual.norm() < 1e-15 * u.norm());
    }

    #[test]
    fn holes_in_a_half_turn_away_leave_the_stated_residual() {
        let holes = Holes::Angles(vec![deg(0.0), deg(40.0)]);
        let u = Complex::from_polar(1e-4, deg(120.0));
        let s = split("B", u, 0.05, &holes, None).unwrap();
        assert_eq!(s.masses.len(), 1);
        assert_eq!(s.masses[0].hole, 1);
        assert!((s.placed() - u - s.residual).norm() < 1e-18);
        assert!((s.residual.norm() - 1e-4 * deg(80.0).sin()).abs() < 1e-12);
        let e = split("B", u, 0.05, &Holes::Angles(vec![0.0, deg(360.0)]), None).unwrap_err();
        assert!(
            e.to_string()
                .contains("holes 1 and 2 are both at 0.000000 deg"),
            "{e}"
        );
    }

    #[test]
    fn a_mass_set_gives_the_best_combination_found_by_brute_force() {
        let holes = Holes::Equal {
            count: 8,
            offset: 0.0,
        };
        let set = MassSet {
            masses: vec![1e-3, 2e-3, 5e-3],
            per_hole: 2,
        };
        let radius = 0.1;
        for (size, angle) in [
            (3.3e-4, 10.0),
            (7.7e-4, 100.0),
            (1.2e-4, 215.0),
            (9e-4, 359.0),
        ] {
            let u = Complex::from_polar(size, deg(angle));
            let s = split("C", u, radius, &holes, Some(&set)).unwrap();
            assert!((s.placed() - u - s.residual).norm() < 1e-18);
            // brute force over every pair of holes and every combination
            let combos = combinations(&set);
            let angles = holes.angles();
            let mut best = f64::INFINITY;
            for a in 0..8 {
                for b in (0..8).filter(|&b| b != a) {
                    for (ma, _) in &combos {
                        for (mb, _) in &combos {
                            let placed = Complex::from_polar(ma * radius, angles[a])
                                + Complex::from_polar(mb * radius, angles[b]);
                            best = best.min((placed - u).norm());
                        }
                    }
                }
            }
            assert!(
                s.residual.norm() <= best * (1.0 + 1e-12) + 1e-18,
                "{angle}: {} vs brute force {best}",
                s.residual.norm()
            );
            for m in &s.masses {
                assert!((m.weights.iter().sum::<f64>() - m.mass).abs() < 1e-15);
                assert!(m.weights.len() <= 2);
            }
        }
    }
}
