//! `rotorid plot INPUT --out FILE.png|FILE.svg [--scenario table1|FILE.toml]
//! [--from S --to S]`: draw a CSV written by `rotorid simulate`, `rotorid condition` or
//! `rotorid identify`, any record `rotorid identify` reads, or a raw acquisition.
//!
//! The kind is chosen from the header (names compared as the readers in [`crate::io`]
//! compare them: trimmed, lower-case, a unit suffix `[m]` or `(m)` split off; a response's
//! columns in other units are converted to SI as they are read, with a `note:` line each):
//!
//! - an estimates column (`m_x` ... `k_z`, `rcond_x`, `rcond_z`): identify output
//!   (`t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z`) -> three stacked panels m, c, k against
//!   time, both directions solid; with `--scenario`, the true values dashed. Ill-conditioned
//!   instants are empty in that file and show as gaps, and so do restarts (a change of
//!   `window`: the lines of two windows are not joined). y is scaled to what is visible and
//!   kept within +-50 % of a reference: the true value, else the median of the last quarter
//!   of the window's estimates.
//! - otherwise `t` with `x` or `z`: simulate output (`t,x,z[,phi,phi_dot,phi_ddot]`) ->
//!   x(t) and z(t), and the orbit z against x (equal scales), side by side; displacements
//!   in the SI prefix that suits their size (nm, um, ...). When the file has `phi`, the
//!   orbit carries the keyphasor dots (the convention engineers read: the shaft's position
//!   at each once-per-turn event): black dots where phi passes the keyphasor angle, which
//!   is `[acquisition.keyphasor] angle_deg` of `--scenario`, else 0 (mod 2 pi), the
//!   position interpolated linearly between the two samples around the crossing.
//! - a raw record (probe volts and keyphasor) with `--scenario` holding `[acquisition]`:
//!   conditioned first as `rotorid condition` does (any format `rotorid_io` reads; its
//!   notes and warnings printed), then drawn as a response with keyphasor dots. Any other
//!   non-CSV file is read whole and its t, x, z[, phi] channels drawn.
//!
//! `--from`/`--to` restrict the time window [s]. The files are read with the validating
//! readers of [`crate::io`] (line and column in every error), streaming: every curve is
//! thinned to the pixel grid as the rows arrive ([`crate::plot::thin`]), so memory stays
//! flat for any record length and an SVG stays small. The image is written atomically
//! ([`crate::io::output`]); it may not be the input or the scenario file.

use std::io::Read;
use std::path::Path;

use anyhow::bail;

use crate::io::columns::{csv_reader, io_error, next_record, normalise};
use crate::io::csv_error::abbreviate;
use crate::io::lines::LineReader;
use crate::io::number::readable;
use crate::io::tables;
use crate::io::LoadScenario as _;
use crate::io::{
    check_distinct_files, open_input, EstimatesReader, ResponseReader, ScenarioSpec, Truth,
    ESTIMATES_HEADER, ESTIMATES_REQUIRED,
};
use crate::plot::scale::si_prefix;
use crate::plot::thin::{ColumnThinner, PathThinner, Subsample};
use crate::plot::{palette, save, Figure, ImageFormat, Panel, Series};

/// Auto-scaled estimates never extend beyond reference * (1 -+ this).
const Y_BAND: f64 = 0.5;

/// Columns a curve against time is thinned to: more than any axis has pixels (a figure is
/// 1600 px wide at most, 3200 supersampled).
const COLUMNS: usize = 4096;

/// Most distinct segments an orbit keeps (about 20 bytes each).
const ORBIT_SEGMENTS: usize = 200_000;

/// Values kept for the late median of an estimate (exact up to this many rows).
const MEDIAN_VALUES: usize = 1 << 16;

/// Most keyphasor dots drawn on an orbit (beyond it every other one is dropped, evenly).
const KEYPHASOR_DOTS: usize = 4096;

/// Diameter of a keyphasor dot [px].
const KEYPHASOR_DOT_PX: u32 = 7;

/// Arguments of `rotorid plot`.
#[derive(Debug, clap::Args)]
pub struct PlotArgs {
    /// A response CSV from `rotorid simulate` or `rotorid condition` (t,x,z,...), an
    /// estimates CSV from `rotorid identify` (t,m_x,...,rcond_z), a record in another
    /// format (MAT, TDMS, UFF58, NPY/NPZ, Parquet), or a raw acquisition with a
    /// `--scenario` that has `[acquisition]`; `-` reads stdin (CSV).
    #[arg(value_name = "INPUT")]
    pub input: String,
    /// The image to write: FILE.png or FILE.svg.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub out: std::path::PathBuf,
    /// Draw the true m, c, k of this scenario (dashed) on an estimates plot: `table1` or
    /// a scenario TOML file. Its `[acquisition]` conditions a raw record before drawing it
    /// and gives the keyphasor angle of the orbit's dots.
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: Option<String>,
    /// Start of the time window [s].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub from: Option<f64>,
    /// End of the time window [s].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub to: Option<f64>,
}

/// What a CSV holds, from its header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CsvKind {
    /// `rotorid simulate` output.
    Response,
    /// `rotorid identify` output.
    Estimates,
}

/// The time window of the flags, `(from, to)`, either optional.
type Window = (Option<f64>, Option<f64>);

/// Run `rotorid plot`.
pub fn run(args: PlotArgs) -> anyhow::Result<()> {
    ImageFormat::from_path(&args.out)?;
    for (flag, v) in [("--from", args.from), ("--to", args.to)] {
        if let Some(v) = v {
            if !v.is_finite() {
                bail!(
                    "{flag} {} is out of range: must be a finite time (s)",
                    readable(v)
                );
            }
        }
    }
    if let (Some(a), Some(b)) = (args.from, args.to) {
        if a >= b {
            bail!(
                "--from {} must be earlier than --to {} (s)",
                readable(a),
                readable(b)
            );
        }
    }
    let mut inputs = vec![("the input", args.input.as_str())];
    if let Some(s) = &args.scenario {
        inputs.push(("--scenario", s));
    }
    if let Some(out) = args.out.to_str() {
        check_distinct_files(&inputs, &[("--out", out)])?;
    }
    let spec = match &args.scenario {
        Some(s) => Some(ScenarioSpec::load(s)?),
        None => None,
    };
    let truth = match &spec {
        Some(spec) => Some(spec.identification()?.truth),
        None => None,
    };
    let acquisition = spec.as_ref().and_then(|s| s.acquisition());
    let keyphasor = acquisition.map_or(0.0, |a| a.keyphasor.angle);
    let window = (args.from, args.to);
    let title = Path::new(&args.input)
        .file_name()
        .map_or_else(|| args.input.clone(), |f| f.to_string_lossy().into_owned());
    if tables::is_tabular(&args.input, None) {
        let table = tables::read(&args.input)?;
        let figure = match (&spec, acquisition) {
            (Some(spec), Some(acq)) => {
                conditioned_figure(&title, &table, spec, acq, window, keyphasor)?
            }
            _ => {
                let c = tables::columns(table, None)?;
                let phi = c.speed.as_ref().map(|s| s[0].as_slice());
                let d = ResponseData::from_columns(&c.t, &c.x, &c.z, phi, window, keyphasor);
                response_figure(&format!("{title}: response"), &d, window)?
            }
        };
        return save(&figure, &args.out);
    }
    let (name, input) = open_input(&args.input)?;
    let (head, rest) = read_head(&name, input)?;
    let kind = match (detect(&name, &head), &spec, acquisition) {
        (Ok(kind), _, _) => kind,
        (Err(_), Some(spec), Some(acq)) if args.input != "-" => {
            let table = tables::read(&args.input)?;
            let figure = conditioned_figure(&title, &table, spec, acq, window, keyphasor)?;
            return save(&figure, &args.out);
        }
        (Err(e), _, _) => return Err(e),
    };
    let input = std::io::Cursor::new(head).chain(rest);
    let title = Path::new(&name)
        .file_name()
        .map_or_else(|| name.clone(), |f| f.to_string_lossy().into_owned());
    let figure = match kind {
        CsvKind::Response => {
            if truth.is_some() && acquisition.is_none() {
                eprintln!("note: --scenario only adds true values to an estimates plot; {name} is a response");
            }
            let data = read_response(&name, input, window, keyphasor)?;
            response_figure(&format!("{title}: response"), &data, window)?
        }
        CsvKind::Estimates => {
            let data = read_estimates(&name, input, window)?;
            estimates_figure(&title, &data, truth.as_ref(), window)?
        }
    };
    save(&figure, &args.out)
}

/// The input up to and including its first line that is not blank (the header, for
/// [`detect`]), and the reader positioned after it. Lines are capped as everywhere
/// ([`crate::io::lines`]).
fn read_head<R: Read>(name: &str, input: R) -> anyhow::Result<(Vec<u8>, LineReader<R>)> {
    let mut lines = LineReader::new(input);
    let mut head = Vec::new();
    let mut buf = vec![0u8; 64 * 1024];
    let mut content = false;
    loop {
        let n = lines
            .read(&mut buf)
            .map_err(|e| io_error(name, &e, lines.line()))?;
        if n == 0 {
            return Ok((head, lines));
        }
        head.extend_from_slice(&buf[..n]);
        let chunk = &buf[..n];
        content |= chunk.iter().any(|b| !matches!(b, b'\n' | b'\r'));
        if content && matches!(chunk[n - 1], b'\n' | b'\r') {
            return Ok((head, lines));
        }
    }
}

/// The kind of CSV whose first line(s) `head` holds, from its header line (module doc).
pub fn detect(name: &str, head: &[u8]) -> anyhow::Result<CsvKind> {
    let mut csv = csv_reader(head);
    let Some(rec) = next_record(name, &mut csv)? else {
        bail!("{name}: the file is empty: expected a CSV header (t,x,z,... or t,m_x,...,rcond_z)");
    };
    let names: Vec<String> = rec.iter().map(normalise).collect();
    let has = |n: &str| names.iter().any(|h| h == n);
    if ESTIMATES_REQUIRED[1..].iter().any(|n| has(n)) {
        Ok(CsvKind::Estimates)
    } else if has("t") && (has("x") || has("z")) {
        Ok(CsvKind::Response)
    } else {
        bail!(
            "{name} line 1: unknown header `{}`: expected a response CSV from `rotorid simulate` \
             (t,x,z[,phi,phi_dot,phi_ddot]) or an estimates CSV from `rotorid identify` ({})",
            abbreviate(&names.join(","), 200),
            ESTIMATES_HEADER.join(",")
        )
    }
}

/// Where the samples of a file lie in time, and how many are in the window.
#[derive(Debug, Clone, Copy)]
struct Extent {
    first: f64,
    last: f64,
    inside: u64,
}

impl Extent {
    fn new() -> Self {
        Self {
            first: f64::NAN,
            last: f64::NAN,
            inside: 0,
        }
    }

    fn push(&mut self, t: f64, (from, to): Window) {
        if self.first.is_nan() {
            self.first = t;
        }
        self.last = t;
        if from.is_none_or(|a| t >= a) && to.is_none_or(|b| t <= b) {
            self.inside += 1;
        }
    }

    /// The time window: the flags, else the data's extent; an error if no sample is
    /// inside.
    fn window(&self, (from, to): Window) -> anyhow::Result<(f64, f64)> {
        let t0 = from.unwrap_or(self.first);
        let t1 = to.unwrap_or(self.last);
        if self.inside == 0 {
            bail!(
                "no sample in the window {} s to {} s: the file spans {} s to {} s",
                readable(t0),
                readable(t1),
                readable(self.first),
                readable(self.last)
            );
        }
        if t1 > t0 {
            Ok((t0, t1))
        } else {
            // a single sample: show a little around it
            Ok((t0 - 0.5, t1 + 0.5))
        }
    }
}

/// The keyphasor dots of an orbit: the shaft's position (x, z) [m] each time phi passes
/// `angle` + 2 pi k, either way round, interpolated linearly between the samples around
/// the crossing. At most [`KEYPHASOR_DOTS`]: when full, every other dot is dropped and
/// only every `stride`-th crossing is kept from then on, so the dots stay even in time.
#[derive(Debug, Clone)]
pub struct KeyphasorDots {
    angle: f64,
    /// The previous sample inside the window: (turn index of phi, phi, x, z).
    prev: Option<(f64, f64, f64, f64)>,
    crossings: u64,
    stride: u64,
    /// The dots kept, (x, z) [m].
    pub dots: Vec<(f64, f64)>,
}

impl KeyphasorDots {
    /// No dots yet; `angle` is the keyphasor angle [rad].
    pub fn new(angle: f64) -> Self {
        Self {
            angle,
            prev: None,
            crossings: 0,
            stride: 1,
            dots: Vec::new(),
        }
    }

    /// One sample inside the window: shaft angle `phi` [rad] and position `x`, `z` [m]. A
    /// non-finite phi breaks the sequence (no dot across it).
    pub fn push(&mut self, phi: f64, x: f64, z: f64) {
        if !phi.is_finite() {
            self.prev = None;
            return;
        }
        let turn = ((phi - self.angle) / std::f64::consts::TAU).floor();
        if let Some((turn0, phi0, x0, z0)) = self.prev {
            if turn != turn0 {
                // the crossing nearest the previous sample, in the direction of travel
                let k = if turn > turn0 { turn } else { turn0 };
                let at = self.angle + std::f64::consts::TAU * k;
                let s = ((at - phi0) / (phi - phi0)).clamp(0.0, 1.0);
                if self.crossings.is_multiple_of(self.stride) {
                    self.dots.push((x0 + s * (x - x0), z0 + s * (z - z0)));
                    if self.dots.len() >= KEYPHASOR_DOTS {
                        let kept: Vec<_> = self.dots.iter().copied().step_by(2).collect();
                        self.dots = kept;
                        self.stride *= 2;
                    }
                }
                self.crossings += 1;
            }
        }
        self.prev = Some((turn, phi, x, z));
    }
}

/// A response, thinned.
struct ResponseData {
    extent: Extent,
    x: ColumnThinner,
    z: ColumnThinner,
    orbit: PathThinner,
    /// Largest |x| or |z| in the window.
    peak: f64,
    /// Keyphasor dots, when the response has phi.
    keyphasor: Option<KeyphasorDots>,
}

impl ResponseData {
    fn new(window: Window) -> Self {
        Self {
            extent: Extent::new(),
            x: ColumnThinner::new(COLUMNS, window),
            z: ColumnThinner::new(COLUMNS, window),
            orbit: PathThinner::new(ORBIT_SEGMENTS),
            peak: 0.0,
            keyphasor: None,
        }
    }

    /// One sample: t [s], x, z [m], phi [rad] when known.
    fn push(&mut self, window: Window, t: f64, x: f64, z: f64, phi: Option<f64>) {
        let before = self.extent.inside;
        self.extent.push(t, window);
        self.x.push(t, x);
        self.z.push(t, z);
        if self.extent.inside > before {
            self.orbit.push(x, z);
            self.peak = self.peak.max(x.abs()).max(z.abs());
            if let (Some(k), Some(phi)) = (&mut self.keyphasor, phi) {
                k.push(phi, x, z);
            }
        }
    }

    /// A response held in memory (SI); `phi` gives keyphasor dots at `keyphasor` [rad].
    fn from_columns(
        t: &[f64],
        x: &[f64],
        z: &[f64],
        phi: Option<&[f64]>,
        window: Window,
        keyphasor: f64,
    ) -> Self {
        let mut d = Self::new(window);
        if phi.is_some() {
            d.keyphasor = Some(KeyphasorDots::new(keyphasor));
        }
        for i in 0..t.len() {
            d.push(window, t[i], x[i], z[i], phi.map(|p| p[i]));
        }
        d
    }
}

fn read_response<R: Read>(
    name: &str,
    input: R,
    window: Window,
    keyphasor: f64,
) -> anyhow::Result<ResponseData> {
    let mut r = ResponseReader::new(name, input)?;
    r.print_conversions();
    let mut d = ResponseData::new(window);
    if r.has_phi() {
        d.keyphasor = Some(KeyphasorDots::new(keyphasor));
    }
    while let Some(row) = r.next_row()? {
        d.push(window, row.t, row.x, row.z, row.speed.map(|s| s.phi));
    }
    if d.extent.first.is_nan() {
        bail!("{name}: the file has a header but no data rows");
    }
    Ok(d)
}

/// A raw record conditioned for `acq` (as `rotorid condition` does), as a response figure.
fn conditioned_figure(
    title: &str,
    table: &rotorid_io::Table,
    spec: &ScenarioSpec,
    acq: &rotorid::acquisition::Acquisition,
    window: Window,
    keyphasor: f64,
) -> anyhow::Result<Figure> {
    let raw = tables::raw_record(table, acq)?;
    let slow = tables::slow_roll(spec, acq)?;
    let c = tables::condition_for(&raw, acq, slow.as_ref(), spec, &spec.knowledge()?, None)?;
    tables::print_report(&c);
    let d = ResponseData::from_columns(&c.t, &c.x, &c.z, Some(&c.phi), window, keyphasor);
    if d.extent.first.is_nan() {
        bail!("{}: the conditioned record is empty", table.file);
    }
    response_figure(&format!("{title}: conditioned response"), &d, window)
}

/// x(t), z(t) and the orbit, side by side.
fn response_figure(title: &str, d: &ResponseData, window: Window) -> anyhow::Result<Figure> {
    let (t0, t1) = d.extent.window(window)?;
    let (f, prefix) = si_prefix(d.peak);
    let unit = format!("{prefix}m");
    let scaled = |v: Vec<f64>| v.into_iter().map(|y| y * f).collect::<Vec<f64>>();
    let (tx, x) = d.x.points();
    let (tz, z) = d.z.points();
    let time = Panel::new(
        "(a) displacement against time",
        "time t (s)",
        format!("displacement ({unit})"),
    )
    .with_series(vec![
        Series::solid("x (horizontal)", tx, scaled(x), palette::BLUE),
        Series::solid("z (vertical)", tz, scaled(z), palette::VERMILLION),
    ])
    .with_x_range(t0, t1);
    let (ox, oz) = d.orbit.points();
    let mut series = vec![Series::solid("", scaled(ox), scaled(oz), palette::BLUE).with_width(1)];
    if let Some(k) = &d.keyphasor {
        let (kx, kz): (Vec<f64>, Vec<f64>) = k.dots.iter().copied().unzip();
        series.push(Series::dots(
            format!(
                "keyphasor (phi = {} deg)",
                readable(k.angle.to_degrees().rem_euclid(360.0))
            ),
            scaled(kx),
            scaled(kz),
            palette::BLACK,
            KEYPHASOR_DOT_PX,
        ));
    }
    let orbit = Panel::new(
        format!("(b) orbit, t = {}-{} s", readable(t0), readable(t1)),
        format!("horizontal x ({unit})"),
        format!("vertical z ({unit})"),
    )
    .with_series(series)
    .with_equal_aspect();
    Ok(Figure::new(title.to_owned(), vec![time, orbit])
        .side_by_side()
        .with_size(1600, 800))
}

/// Estimates, thinned: m, c, k of x then of z, as in `ParameterSet::to_array`.
struct EstimatesData {
    extent: Extent,
    curves: Vec<ColumnThinner>,
    late: Vec<Subsample>,
}

fn read_estimates<R: Read>(name: &str, input: R, window: Window) -> anyhow::Result<EstimatesData> {
    let mut r = EstimatesReader::new(name, input)?;
    if r.model() != rotorid::parameter::ModelKind::Jeffcott {
        anyhow::bail!(
            "{name}: an estimates file of the {} model (columns {}); plot draws the Jeffcott \
             model's m, c, k per direction: read this file with pandas to plot its columns",
            r.model(),
            crate::io::estimates_csv::estimates_header(r.model()).join(",")
        );
    }
    let mut d = EstimatesData {
        extent: Extent::new(),
        curves: vec![ColumnThinner::new(COLUMNS, window); 6],
        late: vec![Subsample::new(MEDIAN_VALUES); 6],
    };
    let mut last_window = None;
    while let Some(row) = r.next_row()? {
        let before = d.extent.inside;
        d.extent.push(row.t, window);
        let inside = d.extent.inside > before;
        // a restart (--restart): the estimates of the new window are not joined to the
        // last of the old one
        if row.window.is_some() && last_window.is_some() && row.window != last_window {
            for c in &mut d.curves {
                c.push(row.t, f64::NAN);
            }
        }
        last_window = row.window;
        let Some(values) = row.jeffcott() else {
            unreachable!("the reader's model was checked")
        };
        for (i, v) in values.to_array().into_iter().enumerate() {
            let v = v.unwrap_or(f64::NAN);
            d.curves[i].push(row.t, v);
            if inside && v.is_finite() {
                d.late[i].push(row.t, v);
            }
        }
    }
    if d.extent.first.is_nan() {
        bail!("{name}: the file has a header but no data rows");
    }
    Ok(d)
}

/// m, c, k against time, both directions, the truth dashed when known.
fn estimates_figure(
    title: &str,
    d: &EstimatesData,
    truth: Option<&Truth>,
    window: Window,
) -> anyhow::Result<Figure> {
    let (t0, t1) = d.extent.window(window)?;
    let specs = [
        (
            "m",
            "mass m (kg)",
            0,
            3,
            truth.and_then(|tr| tr.m),
            truth.and_then(|tr| tr.m),
        ),
        (
            "c",
            "damping c (N s/m)",
            1,
            4,
            truth.and_then(|tr| tr.cx),
            truth.and_then(|tr| tr.cz),
        ),
        (
            "k",
            "stiffness k (N/m)",
            2,
            5,
            truth.and_then(|tr| tr.kx),
            truth.and_then(|tr| tr.kz),
        ),
    ];
    let mut panels = Vec::new();
    for (sym, label, ix, iz, tx, tz) in specs {
        let ((time_x, vx), (time_z, vz)) = (d.curves[ix].points(), d.curves[iz].points());
        let (lx, lz) = if sym == "m" {
            ("m from x".to_string(), "m from z".to_string())
        } else {
            (format!("{sym}x"), format!("{sym}z"))
        };
        let mut series = vec![
            Series::solid(lx, time_x, vx, palette::BLUE),
            Series::solid(lz, time_z, vz, palette::VERMILLION),
        ];
        match (tx, tz) {
            (Some(a), Some(b)) if a == b => {
                let l = if sym == "m" {
                    "true m".to_string()
                } else {
                    format!("true {sym}x = {sym}z")
                };
                series.push(Series::level(l, t0, t1, a, palette::BLACK));
            }
            _ => {
                if let Some(a) = tx {
                    series.push(Series::level(
                        format!("true {sym}x"),
                        t0,
                        t1,
                        a,
                        palette::BLACK,
                    ));
                }
                if let Some(b) = tz {
                    series.push(Series::level(
                        format!("true {sym}z"),
                        t0,
                        t1,
                        b,
                        palette::GREY,
                    ));
                }
            }
        }
        let mut panel = Panel::new("", "time t (s)", label)
            .with_series(series)
            .with_x_range(t0, t1);
        let refs: Vec<f64> = [tx, tz].into_iter().flatten().collect();
        let refs = if refs.is_empty() {
            [
                late_median(d.late[ix].values(), t0, t1),
                late_median(d.late[iz].values(), t0, t1),
            ]
            .into_iter()
            .flatten()
            .collect()
        } else {
            refs
        };
        if !refs.is_empty() {
            let lo = refs.iter().fold(f64::INFINITY, |m, v| m.min(*v));
            let hi = refs.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
            panel = panel
                .with_y_limits(lo - Y_BAND * lo.abs(), hi + Y_BAND * hi.abs())
                .with_min_y_span(1e-3 * lo.abs().max(hi.abs()));
        }
        panels.push(panel);
    }
    let what = if truth.is_some() {
        "identified m, c, k (solid) and true values (dashed)"
    } else {
        "identified m, c, k"
    };
    Ok(Figure::new(format!("{title}: {what}"), panels).with_size(1400, 1200))
}

/// Median of the finite values `(t, v)` in the last quarter of the window `t0..t1`.
fn late_median(values: &[(f64, f64)], t0: f64, t1: f64) -> Option<f64> {
    let from = t1 - 0.25 * (t1 - t0);
    let mut late: Vec<f64> = values
        .iter()
        .filter(|(ti, vi)| *ti >= from && *ti <= t1 && vi.is_finite())
        .map(|(_, vi)| *vi)
        .collect();
    if late.is_empty() {
        return None;
    }
    late.sort_by(f64::total_cmp);
    Some(late[late.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// A circular 1X orbit of radius 1 sampled `per_turn` times a turn, phi = w t + phi0:
    /// the keyphasor dots lie where phi = angle, i.e. at (cos angle, sin angle), one per
    /// crossing of angle + 2 pi k (closed form).
    fn circle(turns: f64, per_turn: usize, phi0: f64, sign: f64, angle: f64) -> KeyphasorDots {
        let mut k = KeyphasorDots::new(angle);
        let n = (turns * per_turn as f64) as usize;
        for i in 0..=n {
            let phi = phi0 + sign * TAU * i as f64 / per_turn as f64;
            k.push(phi, phi.cos(), phi.sin());
        }
        k
    }

    #[test]
    fn keyphasor_dots_sit_where_phi_passes_the_keyphasor_angle() {
        for (angle, phi0, sign) in [(0.0, 0.3, 1.0), (1.0, -7.0, 1.0), (2.5, 40.0, -1.0)] {
            let k = circle(10.0, 64, phi0, sign, angle);
            // 10 turns from phi0 cross angle + 2 pi k exactly 10 times (phi0 != angle)
            assert_eq!(k.dots.len(), 10, "angle {angle}, phi0 {phi0}, sign {sign}");
            // linear interpolation on a chord of 2 pi / 64: within the sagitta, 1.2e-3
            let sagitta = 1.0 - (TAU / 128.0).cos();
            for &(x, z) in &k.dots {
                let d = (x - angle.cos()).hypot(z - angle.sin());
                assert!(d <= sagitta + 1e-12, "dot ({x}, {z}) is {d} from the mark");
            }
        }
    }

    #[test]
    fn keyphasor_dots_skip_gaps_and_stay_even_when_thinned() {
        let mut k = KeyphasorDots::new(0.0);
        k.push(0.5, 0.0, 0.0);
        k.push(f64::NAN, 0.0, 0.0);
        k.push(TAU + 0.5, 0.0, 0.0);
        assert!(k.dots.is_empty(), "no dot across a gap in phi");
        // more crossings than are kept: every 2^j-th, evenly
        let turns = 3 * KEYPHASOR_DOTS;
        let mut k = KeyphasorDots::new(0.0);
        for i in 0..=(4 * turns) {
            let phi = 0.1 + TAU * i as f64 / 4.0;
            k.push(phi, i as f64, 0.0);
        }
        assert!(k.dots.len() < KEYPHASOR_DOTS && k.dots.len() >= KEYPHASOR_DOTS / 4);
        let steps: Vec<f64> = k.dots.windows(2).map(|w| w[1].0 - w[0].0).collect();
        assert!(
            steps.iter().all(|&s| (s - steps[0]).abs() < 1e-9),
            "uneven thinning"
        );
        assert_eq!(steps[0], 4.0 * k.stride as f64);
    }

    #[test]
    fn headers_pick_the_kind() {
        assert_eq!(
            detect("a.csv", b"t,x,z,phi,phi_dot,phi_ddot\n0,0,0,0,0,0\n").unwrap(),
            CsvKind::Response
        );
        assert_eq!(
            detect("a.csv", b"T [s], X [m], Z [m]\n").unwrap(),
            CsvKind::Response
        );
        assert_eq!(
            detect("a.csv", ESTIMATES_HEADER.join(",").as_bytes()).unwrap(),
            CsvKind::Estimates
        );
        let e = detect("a.csv", b"time,speed\n1,2\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("a.csv line 1: unknown header `time,speed`"),
            "{e}"
        );
        assert!(detect("a.csv", b"")
            .unwrap_err()
            .to_string()
            .contains("empty"));
    }

    #[test]
    fn a_restart_breaks_the_lines_between_windows() {
        let h = crate::io::ESTIMATES_HEADER.join(",");
        let text = format!(
            "{h}\n0.1,1,2,3,4,5,6,0.5,0.5,0\n0.2,1,2,3,4,5,6,0.5,0.5,0\n\
             0.3,9,9,9,9,9,9,0.5,0.5,1\n0.4,9,9,9,9,9,9,0.5,0.5,1\n"
        );
        let d = read_estimates("e.csv", text.as_bytes(), Window::default()).unwrap();
        for c in &d.curves {
            let (x, y) = c.points();
            assert_eq!(x.len(), 5, "{x:?}");
            assert!(y[2].is_nan() && x[1] == 0.2 && x[3] == 0.3, "{x:?} {y:?}");
        }
        // without the column (an older file), or within one window: no break
        let old = "t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z\n0.1,1,2,3,4,5,6,0.5,0.5\n\
                   0.2,9,9,9,9,9,9,0.5,0.5\n";
        let d = read_estimates("e.csv", old.as_bytes(), Window::default()).unwrap();
        assert!(d.curves[0].points().1.iter().all(|v| v.is_finite()));
    }

    #[test]
    fn late_median_ignores_gaps_and_early_transients() {
        let mut v: Vec<(f64, f64)> = (0..100)
            .map(f64::from)
            .map(|x| (x, if x < 50.0 { 1e6 } else { 14.29 }))
            .collect();
        v[90].1 = f64::NAN;
        assert_eq!(late_median(&v, 0.0, 99.0), Some(14.29));
    }
}
