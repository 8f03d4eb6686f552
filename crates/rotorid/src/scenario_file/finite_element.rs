//! `[rotor]` of a finite-element rotor (docs/formats.md):
//!
//! ```toml
//! [rotor]
//! model = "finite_element"
//! matrices = "rotor.npz"   # the matrices file, relative to this file (read by the caller)
//!
//! [[rotor.bearing]]        # bearing0, bearing1, ... in this order
//! node = 0                 # the node it stands at (its x and y rows carry it)
//! kxx = 1.0e6              # N/m, > 0 (kyy likewise); kxy, kyx any sign, default 0
//! kyy = 1.2e6
//! cxx = 300.0              # N s/m, default 0; cxx, cyy >= 0 and the damping matrix's
//! cyy = 300.0              # symmetric part positive semi-definite; cxy, cyx default 0
//!
//! [[rotor.unbalance]]      # unbalance0, unbalance1, ... in this order
//! node = 2
//! m_u = 1.0e-4             # kg, >= 0
//! d = 0.1                  # m, >= 0: m_u d is the unbalance's mud (kg m)
//! alpha_deg = 0.0          # deg: its angle at phi = 0, from +x towards +y
//! ```
//!
//! `node`, `kxx`, `kyy` of a bearing and every key of an unbalance are required; a node is
//! a TOML integer. The bearings are checked by the model's rules
//! ([`Bearing::validated`], named `rotor.bearing[i]`); whether each node has its x and y
//! degrees of freedom is known only with the matrices ([`FiniteElementSpec::rotor`]). A
//! key of the lumped models (m, kx, kxx, ...) directly under `[rotor]` is an error naming
//! the model it belongs to, as is `[[rotor.bearing]]` or `[[rotor.unbalance]]` under
//! another model, and `[initial]` (the lumped rotor's x, z, vx, vz): a finite-element
//! rotor's initial state is not given there.

use std::sync::Arc;

use toml_edit::{Item, Value};

use super::acquisition::{Entries, Node, Val};
use super::error::RotorModel;
use super::text::Parser;
use super::{rotor_keys, ScenarioFileError};
use crate::model::finite_element::{
    Bearing, DofKind, FeMatrices, FeUnbalance, FiniteElementError, FiniteElementRotor,
};
use crate::parameter::ModelKind;

/// `rotor.model`'s value for a finite-element rotor.
pub const FINITE_ELEMENT: &str = "finite_element";

/// The keys of `[rotor]` in a finite-element rotor.
const KEYS: [&str; 4] = ["model", "matrices", "bearing", "unbalance"];
/// The keys of `[rotor]` only a finite-element rotor has.
pub(super) const FINITE_ELEMENT_KEYS: [&str; 3] = ["matrices", "bearing", "unbalance"];
/// The keys of a `[[rotor.bearing]]`.
const BEARING_KEYS: [&str; 9] = [
    "node", "kxx", "kxy", "kyx", "kyy", "cxx", "cxy", "cyx", "cyy",
];
/// The keys of a `[[rotor.unbalance]]`.
const UNBALANCE_KEYS: [&str; 4] = ["node", "m_u", "d", "alpha_deg"];

/// The `[rotor]` of a finite-element rotor, parsed and checked key by key: the matrices
/// file's path as written (relative to the scenario file; the caller reads it), the
/// bearings and the unbalances. [`Self::rotor`] joins it with the matrices.
#[derive(Debug, Clone, PartialEq)]
pub struct FiniteElementSpec {
    /// `rotor.matrices` as written: the matrices file, relative to the scenario file.
    pub matrices: String,
    /// The bearings, in the order of `[[rotor.bearing]]` (bearing0, ...).
    pub bearings: Vec<Bearing>,
    /// The unbalances, in the order of `[[rotor.unbalance]]` (unbalance0, ...): mud = m_u
    /// d \[kg m\], alpha \[rad\] (from `alpha_deg`).
    pub unbalances: Vec<FeUnbalance>,
    /// The scenario file, for messages.
    origin: String,
    /// The line of `rotor.matrices`.
    matrices_line: Option<usize>,
    /// The line of each bearing's `node`.
    bearing_lines: Vec<Option<usize>>,
    /// The line of each unbalance's `node`.
    unbalance_lines: Vec<Option<usize>>,
}

impl FiniteElementSpec {
    /// The line of `rotor.matrices` in the scenario file (for a caller's message about
    /// the file it names).
    pub fn matrices_line(&self) -> Option<usize> {
        self.matrices_line
    }

    /// The rotor of these bearings and unbalances on `matrices`, read from the file
    /// `matrices_file` (named in messages): each bearing's and unbalance's node must have
    /// its x and y degrees of freedom.
    pub fn rotor(
        &self,
        matrices: Arc<FeMatrices>,
        matrices_file: &str,
    ) -> Result<FiniteElementRotor, ScenarioFileError> {
        let nodes = self
            .bearings
            .iter()
            .map(|b| b.node)
            .zip(&self.bearing_lines)
            .enumerate()
            .map(|(i, (n, l))| (format!("rotor.bearing[{i}]"), "a bearing", n, *l))
            .chain(
                self.unbalances
                    .iter()
                    .map(|u| u.node)
                    .zip(&self.unbalance_lines)
                    .enumerate()
                    .map(|(j, (n, l))| (format!("rotor.unbalance[{j}]"), "an unbalance", n, *l)),
            );
        for (what, kind, node, line) in nodes {
            for dof in [DofKind::X, DofKind::Y] {
                let d = crate::model::finite_element::Dof::new(node, dof);
                if matrices.index(d).is_none() {
                    return Err(ScenarioFileError::Inconsistent {
                        origin: self.origin.clone(),
                        line,
                        message: format!(
                            "{what}.node = {node}: the matrices file {matrices_file} has no \
                             degree of freedom {d} in dofs ({kind} needs {node}.x and {node}.y)"
                        ),
                    });
                }
            }
        }
        FiniteElementRotor::new(matrices, self.bearings.clone(), self.unbalances.clone()).map_err(
            |e| ScenarioFileError::Inconsistent {
                origin: self.origin.clone(),
                line: None,
                message: e.to_string(),
            },
        )
    }
}

/// A model error about `rotor.bearing[i]` as the scenario's error: an out-of-range value at
/// its key's line, anything else at the table's.
fn bearing_error(origin: &str, e: &Entries<'_>, err: FiniteElementError) -> ScenarioFileError {
    match err {
        FiniteElementError::OutOfRange {
            what,
            field,
            value,
            allowed,
        } => ScenarioFileError::OutOfRange {
            origin: origin.to_owned(),
            line: e.get(field).and_then(|(l, _)| l).or(e.line),
            key: format!("{what}.{field}"),
            value,
            allowed: allowed.to_owned(),
        },
        other => ScenarioFileError::Inconsistent {
            origin: origin.to_owned(),
            line: e.line,
            message: other.to_string(),
        },
    }
}

impl Parser<'_> {
    /// The `[rotor]` of a finite-element rotor, from the section's item (a table in any
    /// TOML form) at `line`.
    pub(super) fn finite_element(
        &self,
        item: &Item,
        line: Option<usize>,
    ) -> Result<FiniteElementSpec, ScenarioFileError> {
        let node = self.table_of("rotor", line, Val::Item(item))?;
        // keys of the lumped models are named with the model they belong to
        for (k, key, _) in node.entries() {
            if !KEYS.contains(&k) {
                let other_model = ModelKind::ALL
                    .into_iter()
                    .find(|m| rotor_keys(*m).iter().any(|(kk, _)| *kk == k))
                    .map(RotorModel::Lumped);
                return Err(ScenarioFileError::UnknownKey {
                    origin: self.origin.to_owned(),
                    line: self.key_line(key),
                    section: "rotor".to_owned(),
                    key: k.to_owned(),
                    allowed: KEYS.join(", "),
                    other_model,
                });
            }
        }
        let top = self.entries("rotor", line, node, &KEYS)?;
        let (matrices, matrices_line) = self.string(&top, "matrices")?.ok_or_else(|| {
            self.missing(
                &top,
                "matrices",
                "the matrices file (NPZ of M, K, G, dofs), relative to this file",
            )
        })?;
        if matrices.trim().is_empty() {
            return Err(ScenarioFileError::WrongType {
                origin: self.origin.to_owned(),
                line: matrices_line,
                key: "rotor.matrices".to_owned(),
                value: format!("{matrices:?}"),
                expected: "the path of the matrices file (NPZ), relative to this file".to_owned(),
            });
        }
        let tables = |key: &str| match top.get(key) {
            None => Ok(Vec::new()),
            Some((l, v)) => self.array_of_tables(&format!("rotor.{key}"), l, v),
        };
        let mut bearings = Vec::new();
        let mut bearing_lines = Vec::new();
        for (i, (t, l)) in tables("bearing")?.into_iter().enumerate() {
            let (b, node_line) = self.bearing(i, t, l)?;
            bearings.push(b);
            bearing_lines.push(node_line);
        }
        let mut unbalances = Vec::new();
        let mut unbalance_lines = Vec::new();
        for (j, (t, l)) in tables("unbalance")?.into_iter().enumerate() {
            let (u, node_line) = self.unbalance(j, t, l)?;
            unbalances.push(u);
            unbalance_lines.push(node_line);
        }
        Ok(FiniteElementSpec {
            matrices,
            bearings,
            unbalances,
            origin: self.origin.to_owned(),
            matrices_line,
            bearing_lines,
            unbalance_lines,
        })
    }

    /// A node number: a TOML integer in 0 ..= 2^32 - 1; required.
    fn node_number(
        &self,
        e: &Entries<'_>,
        what: &str,
    ) -> Result<(u32, Option<usize>), ScenarioFileError> {
        let Some((line, v)) = e.get("node") else {
            return Err(self.missing(e, "node", what));
        };
        let key = format!("{}.node", e.path);
        match v.value() {
            Some(Value::Integer(i)) => {
                let n = *i.value();
                u32::try_from(n).map(|n| (n, line)).map_err(|_| {
                    self.range(line, &key, n as f64, "a node number 0, 1, ... (below 2^32)")
                })
            }
            _ => Err(self.err_type(line, &key, v, "an integer node number (0, 1, ...)")),
        }
    }

    /// `[[rotor.bearing]]` number `i`, and the line of its node.
    fn bearing(
        &self,
        i: usize,
        t: Node<'_>,
        line: Option<usize>,
    ) -> Result<(Bearing, Option<usize>), ScenarioFileError> {
        let path = format!("rotor.bearing[{i}]");
        let e = self.entries(&path, line, t, &BEARING_KEYS)?;
        let (node, node_line) =
            self.node_number(&e, "the node the bearing stands at (0, 1, ...)")?;
        // each value as written; ranges are the model's (Bearing::validated)
        let any = |_: f64| true;
        let value = |k: &str, unit: &str, required: bool| -> Result<f64, ScenarioFileError> {
            match self.num(&e, k, unit, any)? {
                Some((v, _)) => Ok(v),
                None if required => Err(self.missing(&e, k, unit)),
                None => Ok(0.0),
            }
        };
        let b = Bearing {
            node,
            kxx: value("kxx", "N/m, > 0", true)?,
            kxy: value("kxy", "N/m", false)?,
            kyx: value("kyx", "N/m", false)?,
            kyy: value("kyy", "N/m, > 0", true)?,
            cxx: value("cxx", "N s/m", false)?,
            cxy: value("cxy", "N s/m", false)?,
            cyx: value("cyx", "N s/m", false)?,
            cyy: value("cyy", "N s/m", false)?,
        };
        let b = b
            .validated(&path)
            .map_err(|err| bearing_error(self.origin, &e, err))?;
        Ok((b, node_line))
    }

    /// `[[rotor.unbalance]]` number `j`, and the line of its node.
    fn unbalance(
        &self,
        j: usize,
        t: Node<'_>,
        line: Option<usize>,
    ) -> Result<(FeUnbalance, Option<usize>), ScenarioFileError> {
        let path = format!("rotor.unbalance[{j}]");
        let e = self.entries(&path, line, t, &UNBALANCE_KEYS)?;
        let (node, node_line) = self.node_number(&e, "the node the unbalance is at (0, 1, ...)")?;
        let nonneg = |v: f64| v.is_finite() && v >= 0.0;
        let required = |k: &str, allowed: &str, ok: &dyn Fn(f64) -> bool| {
            self.num(&e, k, allowed, ok)?
                .map(|(v, _)| v)
                .ok_or_else(|| self.missing(&e, k, allowed))
        };
        let m_u = required("m_u", "finite and >= 0 (kg)", &nonneg)?;
        let d = required("d", "finite and >= 0 (m)", &nonneg)?;
        let alpha_deg = required(
            "alpha_deg",
            "finite (deg), the angle at phi = 0 from +x towards +y",
            &|v: f64| v.is_finite(),
        )?;
        let mud = m_u * d;
        if !mud.is_finite() {
            return Err(self.range(
                e.get("d").and_then(|(l, _)| l),
                &format!("{path}.d"),
                d,
                "such that m_u d is finite (kg m)",
            ));
        }
        Ok((
            FeUnbalance {
                node,
                mud,
                alpha: alpha_deg.to_radians(),
            },
            node_line,
        ))
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::DMatrix;

    use super::super::ScenarioSpec;
    use super::*;
    use crate::model::finite_element::Dof;

    /// The example of docs/formats.md, with a second bearing.
    const FE: &str = r#"[rotor]
model = "finite_element"
matrices = "rotor.npz"            # relative to this file
[[rotor.bearing]]
node = 0
kxx = 1.0e6
kyy = 1.2e6
cxx = 300.0
cyy = 300.0
[[rotor.bearing]]
node = 6
kxx = 2.0e6
kxy = -1.0e5
kyx = 2.0e5
kyy = 2.5e6
cxx = 400.0
cxy = 10.0
cyx = 12.0
cyy = 450.0
[[rotor.unbalance]]
node = 2
m_u = 1.0e-4                      # kg
d = 0.1                           # m
alpha_deg = 90.0
[speed]
kind = "ramp"
rpm0 = 0.0
accel = 100.0
[sampling]
dt = 1.0e-4
duration = 2.0
"#;

    fn err(text: &str) -> String {
        ScenarioSpec::parse("fe.toml", text)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn the_contract_example_parses_to_its_bearings_and_unbalance() {
        let s = ScenarioSpec::parse("fe.toml", FE).unwrap();
        let fe = s.finite_element().expect("a finite-element rotor");
        assert_eq!(fe.matrices, "rotor.npz");
        assert_eq!(fe.matrices_line(), Some(3));
        assert_eq!(fe.bearings.len(), 2);
        let b = fe.bearings[0];
        assert_eq!(
            (b.node, b.kxx, b.kxy, b.kyx, b.kyy, b.cxx, b.cxy, b.cyx, b.cyy),
            (0, 1.0e6, 0.0, 0.0, 1.2e6, 300.0, 0.0, 0.0, 300.0)
        );
        let b = fe.bearings[1];
        assert_eq!(
            (b.node, b.kxx, b.kxy, b.kyx, b.kyy, b.cxx, b.cxy, b.cyx, b.cyy),
            (6, 2.0e6, -1.0e5, 2.0e5, 2.5e6, 400.0, 10.0, 12.0, 450.0)
        );
        let u = fe.unbalances[0];
        assert_eq!(u.node, 2);
        assert_eq!(u.mud, 1.0e-4 * 0.1);
        assert_eq!(u.alpha, std::f64::consts::FRAC_PI_2);
        // the lumped rotor's views refuse it, naming the model
        let e = s.simulation(&Default::default()).unwrap_err().to_string();
        assert!(
            e.starts_with("fe.toml:1: rotor.model = \"finite_element\": simulate"),
            "{e}"
        );
        assert!(s.identification().is_err() && s.rotor("analyze").is_err());
        // the same rotor in inline tables
        let inline = "rotor = { model = \"finite_element\", matrices = \"rotor.npz\", \
                      bearing = [{ node = 0, kxx = 1.0e6, kyy = 1.2e6, cxx = 300.0, cyy = 300.0 }], \
                      unbalance = [{ node = 2, m_u = 1.0e-4, d = 0.1, alpha_deg = 90.0 }] }\n";
        let t = ScenarioSpec::parse("fe.toml", inline).unwrap();
        let t = t.finite_element().unwrap();
        assert_eq!(t.bearings[0], fe.bearings[0]);
        assert_eq!(t.unbalances, fe.unbalances);
    }

    #[test]
    fn errors_name_file_line_key_value_and_range() {
        // (text replaced, message expected)
        let cases: [(&str, &str, &str); 14] = [
            ("kyy = 1.2e6", "kyy = -1.2e6", "fe.toml:7: rotor.bearing[0].kyy = -1200000 is out of range: must be finite and > 0 (N/m)"),
            ("cxx = 400.0", "cxx = -4.0", "fe.toml:16: rotor.bearing[1].cxx = -4 is out of range: must be finite and >= 0 (N s/m)"),
            ("cxy = 10.0", "cxy = 1000.0", "fe.toml:10: rotor.bearing[1]: the damping matrix"),
            ("kxx = 2.0e6\n", "", "fe.toml:10: missing key rotor.bearing[1].kxx (N/m, > 0)"),
            ("node = 6", "node = -6", "fe.toml:11: rotor.bearing[1].node = -6 is out of range: must be a node number"),
            ("node = 6", "node = 6.0", "fe.toml:11: rotor.bearing[1].node = 6.0 has the wrong type: must be an integer node number"),
            ("kxy = -1.0e5", "kxz = -1.0e5", "fe.toml:13: unknown key rotor.bearing[1].kxz; allowed keys in [rotor.bearing[1]]: node, kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy"),
            ("kxx = 1.0e6", "kxx = \"stiff\"", "fe.toml:6: rotor.bearing[0].kxx = \"stiff\" has the wrong type: must be a number, N/m, > 0"),
            ("d = 0.1 ", "d = -0.1 ", "fe.toml:23: rotor.unbalance[0].d = -0.1 is out of range: must be finite and >= 0 (m)"),
            ("alpha_deg = 90.0\n", "", "fe.toml:20: missing key rotor.unbalance[0].alpha_deg"),
            ("matrices = \"rotor.npz\"", "matrices = 3", "fe.toml:3: rotor.matrices = 3 has the wrong type: must be a string"),
            ("matrices = \"rotor.npz\"", "", "fe.toml:1: missing key rotor.matrices (the matrices file"),
            ("matrices = \"rotor.npz\"", "matrices = \"rotor.npz\"\nkx = 1.0e6", "fe.toml:4: unknown key rotor.kx; allowed keys in [rotor]: model, matrices, bearing, unbalance (kx is a key of rotor.model = \"jeffcott\")"),
            ("[speed]", "[initial]\nx = 1.0e-5\n[speed]", "fe.toml:25: [initial] (x, z, vx, vz) is the initial state of a lumped rotor"),
        ];
        for (from, to, want) in cases {
            assert!(FE.contains(from), "{from}");
            let e = err(&FE.replacen(from, to, 1));
            assert!(e.starts_with(want), "{from} -> {to}:\n{e}\nwanted\n{want}");
        }
    }

    #[test]
    fn tables_of_the_finite_element_rotor_in_a_lumped_rotor_are_named() {
        let jeffcott = "[rotor]\nm = 14.29\na = 2.871\nm_u = 1e-4\nd = 0.15\nalpha_deg = 0.0\n\
                        [[rotor.bearing]]\nnode = 0\nkxx = 1.0e6\nkyy = 1.0e6\n";
        let e = err(jeffcott);
        assert!(
            e.starts_with("fe.toml:")
                && e.contains("unknown key rotor.bearing")
                && e.ends_with("(bearing is a key of rotor.model = \"finite_element\")"),
            "{e}"
        );
        let cross = "[rotor]\nmodel = \"cross_coupled\"\nmatrices = \"r.npz\"\n";
        let e = err(cross);
        assert!(
            e.starts_with("fe.toml:3: unknown key rotor.matrices")
                && e.ends_with("(matrices is a key of rotor.model = \"finite_element\")"),
            "{e}"
        );
        let e = err("[rotor]\nmodel = \"finite\"\n");
        assert!(
            e.ends_with("must be \"jeffcott\", \"cross_coupled\" or \"finite_element\""),
            "{e}"
        );
    }

    fn matrices(nodes: &[u32]) -> Arc<FeMatrices> {
        let dofs: Vec<Dof> = nodes
            .iter()
            .flat_map(|&n| [Dof::new(n, DofKind::X), Dof::new(n, DofKind::Y)])
            .collect();
        let n = dofs.len();
        let eye = DMatrix::<f64>::identity(n, n);
        Arc::new(FeMatrices::new(dofs, eye.clone(), eye, DMatrix::zeros(n, n), None, None).unwrap())
    }

    #[test]
    fn joined_with_matrices_each_node_must_have_x_and_y() {
        let s = ScenarioSpec::parse("fe.toml", FE).unwrap();
        let fe = s.finite_element().unwrap();
        let r = fe.rotor(matrices(&[0, 2, 6]), "rotor.npz").unwrap();
        assert_eq!(r.bearings, fe.bearings);
        assert_eq!(r.unbalances, fe.unbalances);
        let e = fe
            .rotor(matrices(&[0, 2]), "rotor.npz")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "fe.toml:11: rotor.bearing[1].node = 6: the matrices file rotor.npz has no degree \
             of freedom 6.x in dofs (a bearing needs 6.x and 6.y)"
        );
        let e = fe
            .rotor(matrices(&[0, 6]), "rotor.npz")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("fe.toml:21: rotor.unbalance[0].node = 2"),
            "{e}"
        );
    }
}
