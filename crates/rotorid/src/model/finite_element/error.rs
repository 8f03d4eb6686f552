//! What is wrong with a finite-element rotor's description.

/// A finite-element rotor that cannot be built; every variant names the offending part and
/// value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FiniteElementError {
    /// A degree of freedom's name is not `<node>.<dof>`.
    #[error(
        "degree of freedom {name:?} is not <node>.<dof>: allowed a node number (0, 1, ...) \
         and one of x, y, rx, ry, e.g. \"3.x\""
    )]
    BadDof {
        /// The name as given.
        name: String,
    },
    /// The same degree of freedom twice.
    #[error("degree of freedom {name} appears twice in dofs (at {first} and {second})")]
    DuplicateDof {
        /// Its name.
        name: String,
        /// Its first index.
        first: usize,
        /// Its second index.
        second: usize,
    },
    /// A matrix is not n x n with n the number of degrees of freedom.
    #[error("matrix {matrix} is {rows} x {cols}: must be {n} x {n} (one row and column per entry of dofs)")]
    Shape {
        /// M, K, G, C or Ka.
        matrix: &'static str,
        /// Its rows.
        rows: usize,
        /// Its columns.
        cols: usize,
        /// The number of degrees of freedom.
        n: usize,
    },
    /// A matrix entry is NaN or infinite.
    #[error("matrix {matrix} has {value} at row {row}, column {col} ({row_dof}, {col_dof}): every entry must be finite")]
    NotFinite {
        /// M, K, G, C or Ka.
        matrix: &'static str,
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// The row's degree of freedom.
        row_dof: String,
        /// The column's degree of freedom.
        col_dof: String,
        /// The entry.
        value: f64,
    },
    /// The mass matrix is not symmetric.
    #[error(
        "mass matrix M is not symmetric: M[{row}, {col}] = {value} but M[{col}, {row}] = \
         {transposed} ({row_dof}, {col_dof}); allowed a difference up to 1e-9 of the largest entry"
    )]
    MassNotSymmetric {
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// The row's degree of freedom.
        row_dof: String,
        /// The column's degree of freedom.
        col_dof: String,
        /// M\[row, col\] (kg or kg m or kg m^2).
        value: f64,
        /// M\[col, row\].
        transposed: f64,
    },
    /// The mass matrix is not positive definite.
    #[error("mass matrix M is not positive definite (its Cholesky factorisation fails): every degree of freedom must carry mass or inertia")]
    MassNotPositiveDefinite,
    /// A bearing or unbalance stands at a node without both lateral degrees of freedom.
    #[error("{what} is at node {node}, which has no {dof} degree of freedom in dofs (a bearing or unbalance needs {node}.x and {node}.y)")]
    NodeWithoutDof {
        /// `bearing <i>` or `unbalance <j>`.
        what: String,
        /// The node.
        node: u32,
        /// The missing one: `x` or `y`.
        dof: &'static str,
    },
    /// A bearing or unbalance value is out of its range.
    #[error("{what}.{field} = {value} is out of range: must be {allowed}")]
    OutOfRange {
        /// `bearing0`, `unbalance1`, ...
        what: String,
        /// The key: kxx, ..., cyy, m_u, d, mud, alpha.
        field: &'static str,
        /// The value.
        value: f64,
        /// The allowed range, with its unit.
        allowed: &'static str,
    },
    /// A bearing's damping matrix feeds energy in some direction.
    #[error(
        "{what}: the damping matrix [[cxx, cxy], [cyx, cyy]] = [[{cxx}, {cxy}], [{cyx}, {cyy}]] \
         N s/m is not dissipative: its symmetric part must be positive semi-definite, cxx >= 0, \
         cyy >= 0 and cxx cyy >= ((cxy + cyx) / 2)^2"
    )]
    DampingNotDissipative {
        /// `bearing<i>`.
        what: String,
        /// cxx \[N s/m\].
        cxx: f64,
        /// cxy \[N s/m\].
        cxy: f64,
        /// cyx \[N s/m\].
        cyx: f64,
        /// cyy \[N s/m\].
        cyy: f64,
    },
    /// A parameter name that is not one of the rotor's.
    #[error("unknown parameter {name:?}: {allowed}")]
    UnknownParameter {
        /// The name as given.
        name: String,
        /// What the rotor has, in words.
        allowed: String,
    },
    /// A degree of freedom asked for that the rotor does not have.
    #[error("degree of freedom {name} is not one of the rotor's {n} (see its dofs)")]
    UnknownDof {
        /// The name asked for.
        name: String,
        /// How many the rotor has.
        n: usize,
    },
    /// Parts that do not fit together (e.g. a system updated with a rotor of other
    /// bearings).
    #[error("inconsistent finite-element model: {what}")]
    Inconsistent {
        /// What does not fit, in words.
        what: String,
    },
    /// The steady-state system K0 - w^2 M + i w (C0 + w G) is singular at this speed.
    #[error(
        "the steady-state 1X response at w = {omega} rad/s does not exist: K0 - w^2 M + i w \
         (C0 + w G) is singular there (an undamped rotor at a critical speed)"
    )]
    SingularSteadyState {
        /// The speed w \[rad/s\].
        omega: f64,
    },
    /// The stiffness K + K_b is singular: no static shape (the rotor is not held by its
    /// bearings).
    #[error("K + K_b is singular: the static shapes of the reduction need a rotor held by its bearings (every rigid-body motion restrained)")]
    SingularStiffness,
    /// A reduction asked for more modes than the rotor has, or for none.
    #[error(
        "modes = {modes} is out of range: must be 1 ..= {n} (the number of degrees of freedom)"
    )]
    ModeCount {
        /// Asked for.
        modes: usize,
        /// Degrees of freedom.
        n: usize,
    },
}
