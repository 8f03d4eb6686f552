//! The options of `rotorid identify` and the method they select (each option checked
//! against its method and its allowed range).

use rotorid::identify::algebraic::Quadrature;
use rotorid::identify::modulating::ModulatingConfig;
use rotorid::parameter::Parameter;
use rotorid::pipeline::{
    AlgebraicSettings, Method, ModelChoice, ModulatingSettings, RefineSettings,
};
use rotorid::refine::Unknowns;

// The defaults shown in `--help`, each written once (a test keeps them equal to the
// library's constants): the algebraic identifier's calibrated
// `rotorid::identify::algebraic::DEFAULT_ALGEBRAIC_RCOND_MIN`, the modulating identifier's
// `modulating::DEFAULT_MODULATING_RCOND_MIN` and `DEFAULT_WINDOW_S`, `rotorid::identify::algebraic::DEFAULT_TOLERANCE`,
// `Quadrature::default()` and `crate::io::DEFAULT_TIME_TOLERANCE`.
macro_rules! rcond_min_text {
    () => {
        "1e-5"
    };
}
macro_rules! modulating_rcond_min_text {
    () => {
        "1e-8"
    };
}
macro_rules! tol_text {
    () => {
        "0.01"
    };
}
macro_rules! window_text {
    () => {
        "0.02"
    };
}
macro_rules! quadrature_text {
    () => {
        "am5"
    };
}
#[cfg(test)]
const RCOND_MIN_TEXT: &str = rcond_min_text!();
#[cfg(test)]
const MODULATING_RCOND_MIN_TEXT: &str = modulating_rcond_min_text!();
#[cfg(test)]
const TOL_TEXT: &str = tol_text!();
#[cfg(test)]
const WINDOW_TEXT: &str = window_text!();
#[cfg(test)]
const QUADRATURE_TEXT: &str = quadrature_text!();
const TIME_TOLERANCE_TEXT: &str = "1e-6";

/// Arguments of `rotorid identify`.
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Examples:\n  rotorid simulate --scenario table1 --out - | rotorid identify - \
                  --scenario table1 --out estimates.csv --summary summary.json\n  \
                  rotorid identify measured.csv --scenario rig.toml --method refine --out -",
    after_long_help = concat!(
        "Input: CSV whose header names at least t,x,z; any column order; extra columns ignored;\n",
        "values in SI unless a column's header gives its unit (`x [um]`, `t (ms)`,\n",
        "`phi_dot [rpm]`): then they are converted to SI and a `note:` line says so; t in\n",
        "s, ms, us; x, z in m, mm, um, nm, mil, in; phi in rad, deg, rev; phi_dot in rad/s,\n",
        "rpm, Hz, deg/s; phi_ddot in rad/s^2, rpm/s, Hz/s, deg/s^2. An unknown unit is an error.\n",
        "  t [s]                 strictly increasing, uniformly sampled (see --time-tolerance;\n",
        "                        stamps rounded to their printed decimals are accepted)\n",
        "  x, z [m]              disk displacement, horizontal and vertical\n",
        "  phi [rad], phi_dot [rad/s], phi_ddot [rad/s^2]\n",
        "                        optional, all three or none; without them the scenario's\n",
        "                        [speed] profile gives angle, speed and acceleration at each t\n",
        "\n",
        "Methods:\n",
        "  algebraic   the paper's identifier: one estimate per sample, streaming in bounded\n",
        "              memory (a live pipe sees each estimate as soon as its sample arrived).\n",
        "              Accurate on clean data; under noise its estimate drifts after ~0.1 s.\n",
        "  modulating  least squares over sliding windows of modulating-function equations,\n",
        "              noise-bias compensated (noise sigma from 4th differences); reads the\n",
        "              input in bounded memory and writes ONE row, at the last sample's time.\n",
        "              Needs at least one window (--window) of data.\n",
        "  refine      maximum-likelihood (output-error) fit of the model to the whole record,\n",
        "              with standard errors, the Cramer-Rao bound and identifiability warnings.\n",
        "              Batch: holds the whole record in memory (O(samples): ~60 bytes per\n",
        "              sample at constant speed, ~250 with a variable speed) and writes ONE\n",
        "              row, at the last sample's time.\n",
        "              Start: the modulating estimate (m = mean of m_x and m_z); if the record\n",
        "              is shorter than one window or that estimate is unusable, the algebraic\n",
        "              estimate at t_first + 0.05 s (or its last well-conditioned instant\n",
        "              before); if neither is physical (m, kx, kz > 0), the scenario's m, cx,\n",
        "              kx, cz, kz when it states them, else an error. The summary's `start`\n",
        "              says which, and why.\n",
        "              Unknowns (--unknowns): m, cx, kx, cz, kz by default, plus a and/or\n",
        "              `unbalance` (m_u d and alpha); the initial state x0, z0, vx0, vz0 (at the\n",
        "              first sample) is always estimated. Known quantities come from the\n",
        "              scenario (which must then state them); a and the unbalance, when unknown,\n",
        "              start from the scenario's values.\n",
        "              Speed: the CSV's phi columns (interpolated per sample; when they describe\n",
        "              an exactly constant speed, that constant profile, fitted with the exact\n",
        "              discretisation) or the scenario's profile.\n",
        "              A record that cannot determine the unknowns is reported, not refused:\n",
        "              `warning:` lines on stderr, `identifiable: false` and huge or null\n",
        "              (infinite) standard errors in the summary, exit code 0.\n",
        "\n",
        "Output: CSV with the header t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z,window:\n",
        "  t [s]                 the input's time (batch methods: the last sample's)\n",
        "  m_x, m_z [kg]         mass identified from the x and from the z equation\n",
        "                        (refine: the single fitted m in both)\n",
        "  c_x, c_z [N s/m]      support damping\n",
        "  k_x, k_z [N/m]        support stiffness\n",
        "  rcond_x, rcond_z [1]  algebraic: reciprocal condition number of the scaled 3x3\n",
        "                        system; modulating: of the equilibrated normal matrix;\n",
        "                        refine: 1 / condition number of the scaled Fisher information\n",
        "  window                algebraic: the restart window of the estimate (--restart; 0,\n",
        "                        1, 2, ... as they start; 0 throughout without restarts);\n",
        "                        empty for the batch methods' one row\n",
        "With --model cross_coupled the header is\n",
        "  t,m_x,cxx,cxz,kxx,kxz,m_z,czx,czz,kzx,kzz,rcond_x,rcond_z,window\n",
        "  (per direction m and the four bearing coefficients of that row [N s/m, N/m]).\n",
        "m, c, k are left EMPTY where a direction is ill-conditioned (rcond < --rcond-min, or\n",
        "singular as at the first three samples) and, for refine, where a parameter is not\n",
        "determined (infinite standard error, standard error above its value, or unknowns\n",
        "the data cannot separate) or not estimated (known, see --unknowns).\n",
        "\n",
        "Examples:\n",
        "  rotorid simulate --scenario table1 --out - \\\n",
        "    | rotorid identify - --scenario table1 --out estimates.csv --summary summary.json\n",
        "  rotorid simulate --scenario table1 --snr-db 40 --out noisy.csv\n",
        "  rotorid identify noisy.csv --scenario table1 --method refine --out fit.csv \\\n",
        "    --summary fit.json\n",
        "  rotorid identify measured.csv --scenario rig.toml --method refine \\\n",
        "    --unknowns m,cx,kx,cz,kz,unbalance --out -"
    )
)]
pub struct IdentifyArgs {
    /// The record: a response CSV (streamed; `-` for stdin), or a .mat, .tdms, .uff/.unv/.58,
    /// .npy, .npz or .parquet file (read whole). With a scenario that has [acquisition], a
    /// raw acquisition (probe volts and keyphasor) conditioned before identification.
    #[arg(value_name = "INPUT|-")]
    pub input: String,

    /// The channels that play t, x, z (and phi, phi_dot, phi_ddot): `t,x,z` or six names,
    /// e.g. `rec.t,rec.x,rec.z` (MAT struct fields), `g/x` (TDMS), `0,1,2` (2-D NPY). A
    /// name alone finds a struct field or TDMS channel when it is unique. Default: the
    /// role names. Units come from the file (CSV header suffix, TDMS unit_string, UFF58).
    #[arg(long, value_name = "T,X,Z[,PHI,PHI_DOT,PHI_DDOT]")]
    pub columns: Option<String>,

    /// The scenario: `table1` (built in) or a TOML file. Needs the known a, m_u, d,
    /// alpha_deg; m, cx, cz, kx, kz are optional (truth, for the error report; refine:
    /// required for the parameters --unknowns leaves known); [speed] is needed only if the
    /// input has no phi columns.
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: String,

    /// Identification method (see the long help, `--help`). modulating and refine write one
    /// row at the end; refine holds the whole record in memory (O(samples)).
    #[arg(long, value_enum, default_value_t = IdentifyMethod::Algebraic)]
    pub method: IdentifyMethod,

    /// algebraic only: write every N-th estimate (the 1st, (N+1)-th, ...); all are computed
    /// and tracked [default: 1].
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub every: Option<u64>,

    #[command(flatten)]
    pub settings: MethodOptions,

    /// Allowed deviation of each time stamp from the uniform grid t0 + i dt fitted by least
    /// squares over the stamps, relative to that dt; stamps printed with few decimals
    /// (25.6 kHz to 6 decimals) may besides be off by one unit of their last decimal (at
    /// most dt/4), with a `note:` saying so.
    #[arg(long, value_name = "REL", default_value = TIME_TOLERANCE_TEXT, allow_hyphen_values = true)]
    pub time_tolerance: f64,

    /// The estimates CSV, or `-` for stdout. Written as it goes (a file can be followed
    /// while it grows); after an error it holds the whole rows written before it. A name
    /// ending in `.parquet` writes the same columns as Parquet (a withheld estimate is a
    /// null), whole at the end: nothing on error.
    #[arg(long, short, value_name = "ESTIMATES.csv|ESTIMATES.parquet|-")]
    pub out: String,

    /// Also write a JSON summary: final values, identification times, truth and relative
    /// errors, flagged counts; for modulating and refine also noise levels, standard
    /// errors, Cramer-Rao bounds, warnings (see the documentation of the summary format).
    #[arg(long, value_name = "SUMMARY.json")]
    pub summary: Option<String>,

    /// Do not print the summary on stderr (warnings are still printed).
    #[arg(long, short)]
    pub quiet: bool,

    /// Finite-element rotors only: `rest` when the record starts at rest (the initial
    /// state is known: zero), `estimated` to fit it with the parameters [default:
    /// estimated].
    #[arg(long, value_name = "rest|estimated")]
    pub initial: Option<String>,

    /// Finite-element rotors only: modes in the Ritz basis of the reduced model (with the
    /// static shapes at the bearing and unbalance nodes) [default: 6, at most the degrees
    /// of freedom].
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,

    /// Finite-element rotors only: fit one constant offset per channel with the parameters
    /// (data = response + offset + noise), for a response whose DC was removed (a mean or
    /// a gap voltage subtracted). Always on for a raw record (the scenario's
    /// [acquisition]), whose conditioning leaves the mean of the motion in each DC.
    #[arg(long)]
    pub offsets: bool,
}

/// The method's settings, shared by `rotorid identify` and `rotorid worker` (each checked
/// against the method and its range by [`method_of`]).
#[derive(Debug, Clone, clap::Args)]
pub struct MethodOptions {
    /// The rotor model: jeffcott (the paper's rotor: m, cx, kx, cz, kz), cross_coupled
    /// (bearings with all eight coefficients: m, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz),
    /// or, refine only, auto (fit both, keep those whose residuals pass the adequacy test,
    /// take the simplest by BIC; the summary's model_selection says why) [default: the
    /// scenario's rotor.model, else jeffcott]. Overrides the scenario's model key.
    #[arg(long, value_enum, value_name = "MODEL")]
    pub model: Option<ModelName>,

    /// refine only: the quantities to estimate, comma-separated, from the model's m, cx,
    /// kx, cz, kz (Jeffcott) or m, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz (cross-coupled),
    /// and a, unbalance (m_u d and alpha) [default: m and the model's bearing
    /// coefficients]. The initial state is always estimated; the others are known (from
    /// the scenario). A finite-element rotor: bearing<i>.kxx .. bearing<i>.cyy,
    /// unbalance<j>.mud, unbalance<j>.alpha, or the groups bearings (direct
    /// coefficients), bearing<i> (its eight), unbalances, unbalance<j> [default: bearings,
    /// unbalances].
    #[arg(long, value_name = "NAMES", value_delimiter = ',')]
    pub unknowns: Option<Vec<String>>,

    #[arg(long, value_name = "RULE", help = concat!(
        "Running quadrature of the algebraic identifier's iterated integrals: trapezoid ",
        "(order 2, as the paper), am3, am4, am5 (Adams-Moulton, order 3-5) [default: ",
        quadrature_text!(), "]. algebraic, and refine's algebraic fallback start"))]
    pub quadrature: Option<Quadrature>,

    #[arg(long, value_name = "REL", allow_hyphen_values = true, help = concat!(
        "algebraic only: relative band defining the identification time: the earliest t ",
        "after which every well-conditioned estimate stays within tol of its final value ",
        "[default: ", tol_text!(), "]"))]
    pub tol: Option<f64>,

    /// algebraic only: restart the identifier's integrals on overlapping windows of this
    /// period [s] (two identifiers staggered by half a period; every estimate comes from one
    /// between half and one period old), so a record or stream of any length keeps
    /// producing local estimates. Without it one identifier integrates from the first sample
    #[arg(long, value_name = "S", allow_hyphen_values = true)]
    pub restart: Option<f64>,

    #[arg(long, value_name = "R", allow_hyphen_values = true, help = concat!(
        "Estimates whose reciprocal condition number is below this are flagged as ",
        "ill-conditioned (not written, never counted as converged) [default: ",
        rcond_min_text!(), " for algebraic (scaled 3x3 system), ", modulating_rcond_min_text!(),
        " for modulating (equilibrated normal matrix)]. refine: applies to the identifier ",
        "that gives its start"))]
    pub rcond_min: Option<f64>,

    #[arg(long, value_name = "S", allow_hyphen_values = true, help = concat!(
        "modulating and refine: window length of the modulating-function identifier [s] ",
        "(windows overlap: the hop is a fixed fraction of it, reported as modulating.hop_s in the summary) [default: ", window_text!(),
        "]"))]
    pub window: Option<f64>,
}

/// `--method` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IdentifyMethod {
    /// The paper's algebraic identifier (3x3 system per direction per sample), streaming.
    Algebraic,
    /// Modulating-function least squares over windows, noise-bias compensated; one row.
    Modulating,
    /// Maximum-likelihood output-error fit with standard errors and Cramer-Rao bounds;
    /// batch (memory O(samples)); one row.
    Refine,
}

impl IdentifyMethod {
    /// The name written in the summary.
    pub fn name(self) -> &'static str {
        match self {
            IdentifyMethod::Algebraic => "algebraic",
            IdentifyMethod::Modulating => "modulating",
            IdentifyMethod::Refine => "refine",
        }
    }
}

/// `--model` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ModelName {
    /// The paper's Jeffcott rotor: m, cx, kx, cz, kz.
    Jeffcott,
    /// The rotor on cross-coupled bearings: m, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz.
    #[value(name = "cross_coupled")]
    CrossCoupled,
    /// refine only: fit both, keep the adequate ones, take the simplest by BIC.
    Auto,
}

impl ModelName {
    fn choice(self) -> ModelChoice {
        match self {
            ModelName::Jeffcott => ModelChoice::Jeffcott,
            ModelName::CrossCoupled => ModelChoice::CrossCoupled,
            ModelName::Auto => ModelChoice::Auto,
        }
    }
}

/// `--unknowns` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum UnknownName {
    /// Mass m [kg].
    M,
    /// Damping cx [N s/m].
    Cx,
    /// Stiffness kx [N/m].
    Kx,
    /// Damping cz [N s/m].
    Cz,
    /// Stiffness kz [N/m].
    Kz,
    /// Gyroscopic coefficient a [N s^2/m].
    A,
    /// Unbalance m_u d [kg m] and its angle alpha [rad].
    Unbalance,
    /// Cross-coupled model: direct damping in x [N s/m].
    Cxx,
    /// Cross-coupled model: damping force in x per velocity in z [N s/m].
    Cxz,
    /// Cross-coupled model: damping force in z per velocity in x [N s/m].
    Czx,
    /// Cross-coupled model: direct damping in z [N s/m].
    Czz,
    /// Cross-coupled model: direct stiffness in x [N/m].
    Kxx,
    /// Cross-coupled model: restoring force in x per displacement in z [N/m].
    Kxz,
    /// Cross-coupled model: restoring force in z per displacement in x [N/m].
    Kzx,
    /// Cross-coupled model: direct stiffness in z [N/m].
    Kzz,
}

impl UnknownName {
    /// The parameters it selects.
    fn parameters(self) -> &'static [Parameter] {
        use Parameter as P;
        match self {
            UnknownName::M => &[P::M],
            UnknownName::Cx => &[P::Cx],
            UnknownName::Kx => &[P::Kx],
            UnknownName::Cz => &[P::Cz],
            UnknownName::Kz => &[P::Kz],
            UnknownName::A => &[P::A],
            UnknownName::Unbalance => &[P::Mud, P::Alpha],
            UnknownName::Cxx => &[P::Cxx],
            UnknownName::Cxz => &[P::Cxz],
            UnknownName::Czx => &[P::Czx],
            UnknownName::Czz => &[P::Czz],
            UnknownName::Kxx => &[P::Kxx],
            UnknownName::Kxz => &[P::Kxz],
            UnknownName::Kzx => &[P::Kzx],
            UnknownName::Kzz => &[P::Kzz],
        }
    }
}

/// The method and its settings from `--every` (identify only) and the options (each option
/// checked against its method and its range).
pub fn method_of(
    method: IdentifyMethod,
    args: &MethodOptions,
    every: Option<u64>,
) -> anyhow::Result<Method> {
    let ok = |v: f64| v.is_finite() && v >= 0.0;
    let only = |flag: &str, given: bool, allowed: &[IdentifyMethod]| -> anyhow::Result<()> {
        if given && !allowed.contains(&method) {
            let names: Vec<&str> = allowed.iter().map(|m| m.name()).collect();
            anyhow::bail!(
                "{flag} applies to --method {} only, not to --method {}",
                names.join(" and "),
                method.name()
            );
        }
        Ok(())
    };
    use IdentifyMethod::{Algebraic, Modulating, Refine};
    only("--every", every.is_some(), &[Algebraic])?;
    only("--tol", args.tol.is_some(), &[Algebraic])?;
    only("--restart", args.restart.is_some(), &[Algebraic])?;
    only(
        "--quadrature",
        args.quadrature.is_some(),
        &[Algebraic, Refine],
    )?;
    only("--window", args.window.is_some(), &[Modulating, Refine])?;
    only("--unknowns", args.unknowns.is_some(), &[Refine])?;
    let model = args.model.map(ModelName::choice);
    if model == Some(ModelChoice::Auto) && method != Refine {
        anyhow::bail!(
            "--model auto applies to --method refine only, not to --method {}: choose \
             jeffcott or cross_coupled",
            method.name()
        );
    }
    let fixed = model.and_then(ModelChoice::fixed);
    let mut algebraic = AlgebraicSettings {
        quadrature: args.quadrature.unwrap_or_default(),
        model: fixed,
        ..AlgebraicSettings::default()
    };
    if let Some(tol) = args.tol {
        if !ok(tol) {
            anyhow::bail!("--tol = {tol} is out of range: must be finite and >= 0 (relative)");
        }
        algebraic.tol = tol;
    }
    if let Some(p) = args.restart {
        if !(p.is_finite() && p > 0.0) {
            anyhow::bail!(
                "--restart = {p} is out of range: must be finite and > 0 (s; at least 4 \
                 sampling periods)"
            );
        }
        algebraic.restart_s = Some(p);
    }
    let window_s = args
        .window
        .unwrap_or(rotorid::identify::modulating::DEFAULT_WINDOW_S);
    if !(window_s.is_finite() && window_s > 0.0) {
        anyhow::bail!("--window = {window_s} is out of range: must be finite and > 0 (s)");
    }
    let mut modulating = ModulatingSettings {
        config: ModulatingConfig::with_window(window_s),
        model: fixed,
    };
    if let Some(r) = args.rcond_min {
        if !(ok(r) && r <= 1.0) {
            anyhow::bail!("--rcond-min = {r} is out of range: must be in [0, 1]");
        }
        algebraic.rcond_min = r;
        modulating.config.rcond_min = r;
    }
    Ok(match method {
        Algebraic => Method::Algebraic(algebraic),
        Modulating => Method::Modulating(modulating),
        Refine => Method::Refine(RefineSettings {
            model,
            unknowns: unknowns_of(args.unknowns.as_deref())?,
            algebraic,
            modulating,
            ..RefineSettings::default()
        }),
    })
}

/// The unknowns `--unknowns` selects (`None`: the model's default); the initial state is
/// always estimated. A name that is not one of [`UnknownName`] is refused with the list.
fn unknowns_of(names: Option<&[String]>) -> anyhow::Result<Option<Unknowns>> {
    use clap::ValueEnum as _;
    let Some(names) = names else {
        return Ok(None);
    };
    let mut ps: Vec<Parameter> = Vec::new();
    for n in names {
        let Ok(u) = UnknownName::from_str(n, false) else {
            let allowed: Vec<String> = UnknownName::value_variants()
                .iter()
                .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_owned()))
                .collect();
            anyhow::bail!(
                "invalid value '{n}' for '--unknowns <NAMES>' [possible values: {}] (the \
                 names of a finite-element rotor, bearing<i>.kxx ..., apply to a scenario \
                 with rotor.model = \"finite_element\")",
                allowed.join(", ")
            );
        };
        ps.extend(u.parameters().iter().copied());
    }
    Ok(Some(Unknowns::from_parameters(&ps, true)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotorid::pipeline::DEFAULT_TIME_TOLERANCE;

    #[test]
    fn help_defaults_are_the_library_defaults() {
        use rotorid::identify::modulating;
        assert_eq!(
            RCOND_MIN_TEXT.parse::<f64>().unwrap(),
            rotorid::identify::algebraic::DEFAULT_ALGEBRAIC_RCOND_MIN
        );
        assert_eq!(
            MODULATING_RCOND_MIN_TEXT.parse::<f64>().unwrap(),
            modulating::DEFAULT_MODULATING_RCOND_MIN
        );
        assert_eq!(
            TIME_TOLERANCE_TEXT.parse::<f64>().unwrap(),
            DEFAULT_TIME_TOLERANCE
        );
        assert_eq!(
            TOL_TEXT.parse::<f64>().unwrap(),
            rotorid::identify::algebraic::DEFAULT_TOLERANCE
        );
        assert_eq!(
            WINDOW_TEXT.parse::<f64>().unwrap(),
            modulating::DEFAULT_WINDOW_S
        );
        assert_eq!(Quadrature::default().to_string(), QUADRATURE_TEXT);
    }
}
