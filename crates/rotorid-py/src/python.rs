//! The extension module `rotorid._rotorid`: thin wrappers that convert arrays, call the
//! pure functions of this crate with the GIL released, and hand back numpy arrays (moved,
//! not copied) and the summary as JSON text. The Python package (`python/rotorid`) builds
//! its DataFrames and result objects from these.
//!
//! Arrays: a contiguous float64 1-D array is read in place; anything else numpy can read
//! as float64 (other dtypes, strides, lists, pandas Series) is converted once. The GIL is
//! released while the library computes, so records identified from a thread pool run in
//! parallel; as with any extension that does so, the caller must not write to an array
//! while a call that reads it runs.

use std::sync::Mutex;
use std::time::Instant;

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyPermissionError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rotorid::parameter::ModelKind;
use rotorid::pipeline::DEFAULT_TIME_TOLERANCE;
use rotorid::scenario_file::SimulationOverrides;

use crate::columns::{Columns, Estimates, ESTIMATE_COLUMNS, SPEED_NAMES};
use crate::error::Error;
use crate::options::{self, Options};
use crate::scenario::{self, Scenario, ScenarioKeys};
use crate::stream::{self, Stream};

/// `OSError` (its subclass by kind) for files, `ValueError` for everything else.
fn py_err(e: Error) -> PyErr {
    let text = e.to_string();
    let by_kind = |kind: std::io::ErrorKind| match kind {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(text.clone()),
        std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(text.clone()),
        _ => PyOSError::new_err(text.clone()),
    };
    match e {
        Error::Io { source, .. } => by_kind(source.kind()),
        Error::Csv(c) if c.io_kind.is_some() => PyOSError::new_err(text),
        Error::Read(r) => match *r {
            rotorid_io::ReadError::Io { source, .. } => by_kind(source.kind()),
            _ => PyValueError::new_err(text),
        },
        Error::Raw(r) => match *r {
            rotorid_io::raw::RawError::Read(r) => match *r {
                rotorid_io::ReadError::Io { source, .. } => by_kind(source.kind()),
                _ => PyValueError::new_err(text),
            },
            _ => PyValueError::new_err(text),
        },
        _ => PyValueError::new_err(text),
    }
}

/// `obj` as a 1-D float64 array that can be read as a slice (module doc); `name` names it
/// in messages.
fn column<'py>(name: &str, obj: &Bound<'py, PyAny>) -> PyResult<PyReadonlyArray1<'py, f64>> {
    let borrowed = |a: &Bound<'py, PyArray1<f64>>| {
        a.try_readonly()
            .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
    };
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        if a.is_contiguous() {
            return borrowed(a);
        }
    }
    let np = obj.py().import("numpy")?;
    let kwargs = PyDict::new(obj.py());
    kwargs.set_item("dtype", "float64")?;
    let converted = np
        .call_method("asarray", (obj,), Some(&kwargs))
        .map_err(|e| {
            PyValueError::new_err(format!("{name}: cannot be read as float64 numbers: {e}"))
        })?;
    let untyped = converted.cast::<numpy::PyUntypedArray>()?;
    if untyped.ndim() != 1 {
        let dims: Vec<String> = untyped.shape().iter().map(usize::to_string).collect();
        return Err(PyValueError::new_err(format!(
            "{name}: expected a 1-D array (one value per sample), got shape ({})",
            dims.join(", ")
        )));
    }
    let contiguous = np.call_method1("ascontiguousarray", (converted,))?;
    borrowed(contiguous.cast::<PyArray1<f64>>()?)
}

/// An optional column.
fn optional<'py>(
    name: &str,
    obj: Option<&Bound<'py, PyAny>>,
) -> PyResult<Option<PyReadonlyArray1<'py, f64>>> {
    obj.filter(|o| !o.is_none())
        .map(|o| column(name, o))
        .transpose()
}

/// The slices of columns held by the caller.
struct Held<'py> {
    t: Option<PyReadonlyArray1<'py, f64>>,
    x: PyReadonlyArray1<'py, f64>,
    z: PyReadonlyArray1<'py, f64>,
    speed: [Option<PyReadonlyArray1<'py, f64>>; 3],
}

impl<'py> Held<'py> {
    fn new(
        t: Option<&Bound<'py, PyAny>>,
        x: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        speed: [Option<&Bound<'py, PyAny>>; 3],
    ) -> PyResult<Self> {
        Ok(Self {
            t: optional("t", t)?,
            x: column("x", x)?,
            z: column("z", z)?,
            speed: [
                optional(SPEED_NAMES[0], speed[0])?,
                optional(SPEED_NAMES[1], speed[1])?,
                optional(SPEED_NAMES[2], speed[2])?,
            ],
        })
    }

    fn columns(&self) -> PyResult<Columns<'_>> {
        Columns::new(
            opt(&self.t)?,
            slice(&self.x)?,
            slice(&self.z)?,
            [
                opt(&self.speed[0])?,
                opt(&self.speed[1])?,
                opt(&self.speed[2])?,
            ],
        )
        .map_err(py_err)
    }
}

/// The values of an optional contiguous array.
fn opt<'a>(a: &'a Option<PyReadonlyArray1<'_, f64>>) -> PyResult<Option<&'a [f64]>> {
    a.as_ref().map(slice).transpose()
}

/// The values of a contiguous array.
fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice()
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The estimates as a dict of numpy arrays (moved into numpy, not copied).
fn estimates_dict(py: Python<'_>, e: Estimates) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    for (name, c) in e.names().into_iter().zip(e.columns) {
        d.set_item(name, PyArray1::from_vec(py, c))?;
    }
    Ok(d)
}

/// A scenario: `table1`, a TOML file, or keyword arguments named as the file's keys.
#[pyclass(module = "rotorid._rotorid", name = "Scenario", frozen)]
pub struct PyScenario {
    inner: Scenario,
}

#[pymethods]
impl PyScenario {
    #[new]
    #[pyo3(signature = (*, model=None, m=None, cx=None, kx=None, cz=None, kz=None, kxx=None,
        kxz=None, kzx=None, kzz=None, cxx=None, cxz=None, czx=None, czz=None, a=None, m_u=None,
        d=None, alpha_deg=None, rpm=None, rpm0=None, accel=None, phi0_deg=None, dt=None,
        duration=None, x0=None, z0=None, vx0=None, vz0=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        model: Option<String>,
        m: Option<f64>,
        cx: Option<f64>,
        kx: Option<f64>,
        cz: Option<f64>,
        kz: Option<f64>,
        kxx: Option<f64>,
        kxz: Option<f64>,
        kzx: Option<f64>,
        kzz: Option<f64>,
        cxx: Option<f64>,
        cxz: Option<f64>,
        czx: Option<f64>,
        czz: Option<f64>,
        a: Option<f64>,
        m_u: Option<f64>,
        d: Option<f64>,
        alpha_deg: Option<f64>,
        rpm: Option<f64>,
        rpm0: Option<f64>,
        accel: Option<f64>,
        phi0_deg: Option<f64>,
        dt: Option<f64>,
        duration: Option<f64>,
        x0: Option<f64>,
        z0: Option<f64>,
        vx0: Option<f64>,
        vz0: Option<f64>,
    ) -> PyResult<Self> {
        let keys = ScenarioKeys {
            model,
            m,
            cx,
            cz,
            kx,
            kz,
            kxx,
            kxz,
            kzx,
            kzz,
            cxx,
            cxz,
            czx,
            czz,
            a,
            m_u,
            d,
            alpha_deg,
            rpm,
            rpm0,
            accel,
            phi0_deg,
            dt,
            duration,
            x0,
            z0,
            vx0,
            vz0,
        };
        let inner = Scenario::from_keys(&keys).map_err(py_err)?;
        Ok(Self { inner })
    }

    #[staticmethod]
    fn table1() -> Self {
        Self {
            inner: Scenario::table1(),
        }
    }

    #[staticmethod]
    fn from_toml(path: std::path::PathBuf) -> PyResult<Self> {
        let path = path.to_string_lossy();
        let inner = Scenario::from_toml_file(&path).map_err(py_err)?;
        Ok(Self { inner })
    }

    #[staticmethod]
    fn load(arg: &str) -> PyResult<Self> {
        let inner = Scenario::load(arg).map_err(py_err)?;
        Ok(Self { inner })
    }

    #[getter]
    fn origin(&self) -> &str {
        self.inner.origin()
    }

    /// The keys it states, its model first (the keyword arguments of an equal scenario).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let k = self.inner.keys().map_err(py_err)?;
        let d = PyDict::new(py);
        if let Some(model) = &k.model {
            d.set_item("model", model)?;
        }
        for (name, v) in key_values(&k) {
            if let Some(v) = v {
                d.set_item(name, v)?;
            }
        }
        Ok(d)
    }

    fn __repr__(&self) -> String {
        let origin = self.inner.origin();
        if origin == rotorid::scenario_file::BUILTIN_TABLE1 {
            return "Scenario.table1()".to_owned();
        }
        if !self.inner.from_keywords() {
            return format!("Scenario.from_toml({origin:?})");
        }
        let k = self.inner.keys().unwrap_or_default();
        // the model when it is not the default
        let model = k
            .model
            .as_deref()
            .filter(|m| *m != ModelKind::Jeffcott.name())
            .map(|m| format!("model={m:?}"));
        let given: Vec<String> = model
            .into_iter()
            .chain(
                key_values(&k)
                    .into_iter()
                    .filter_map(|(name, v)| Some(format!("{name}={:?}", v?))),
            )
            .collect();
        format!("Scenario({})", given.join(", "))
    }
}

/// The numeric keys by keyword name, in the order of `Scenario(...)`'s arguments.
fn key_values(k: &ScenarioKeys) -> [(&'static str, Option<f64>); 27] {
    [
        ("m", k.m),
        ("cx", k.cx),
        ("kx", k.kx),
        ("cz", k.cz),
        ("kz", k.kz),
        ("kxx", k.kxx),
        ("kxz", k.kxz),
        ("kzx", k.kzx),
        ("kzz", k.kzz),
        ("cxx", k.cxx),
        ("cxz", k.cxz),
        ("czx", k.czx),
        ("czz", k.czz),
        ("a", k.a),
        ("m_u", k.m_u),
        ("d", k.d),
        ("alpha_deg", k.alpha_deg),
        ("rpm", k.rpm),
        ("rpm0", k.rpm0),
        ("accel", k.accel),
        ("phi0_deg", k.phi0_deg),
        ("dt", k.dt),
        ("duration", k.duration),
        ("x0", k.x0),
        ("z0", k.z0),
        ("vx0", k.vx0),
        ("vz0", k.vz0),
    ]
}

/// Simulate `scenario`: a dict of arrays t, x, z, phi, phi_dot, phi_ddot.
#[pyfunction]
#[pyo3(signature = (scenario, method="exact", snr_db=None, seed=0, *, dt=None, duration=None,
    x0=None, z0=None, vx0=None, vz0=None))]
#[allow(clippy::too_many_arguments)]
fn simulate<'py>(
    py: Python<'py>,
    scenario: &PyScenario,
    method: &str,
    snr_db: Option<f64>,
    seed: u64,
    dt: Option<f64>,
    duration: Option<f64>,
    x0: Option<f64>,
    z0: Option<f64>,
    vx0: Option<f64>,
    vz0: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let ov = SimulationOverrides {
        dt,
        duration,
        x: x0,
        z: z0,
        vx: vx0,
        vz: vz0,
    };
    let sc = &scenario.inner;
    let r = py
        .detach(|| scenario::simulate(sc, method, &ov, snr_db.map(|s| (s, seed))))
        .map_err(py_err)?;
    let d = PyDict::new(py);
    for (name, c) in [
        ("t", r.t),
        ("x", r.x),
        ("z", r.z),
        ("phi", r.phi),
        ("phi_dot", r.phi_dot),
        ("phi_ddot", r.phi_ddot),
    ] {
        d.set_item(name, PyArray1::from_vec(py, c))?;
    }
    Ok(d)
}

/// Read a record: a dict of arrays t, x, z [, phi, phi_dot, phi_ddot] in SI, and a dict
/// of the channels the file gave in other units (role -> unit as given, e.g. `{"x": "um"}`),
/// whose values were converted. CSV is streamed by the command's reader; MAT, TDMS, UFF58,
/// NPY/NPZ and Parquet (or a CSV with `columns`) go through `rotorid_io::select`.
#[pyfunction]
#[pyo3(signature = (path, columns=None))]
fn read(
    py: Python<'_>,
    path: std::path::PathBuf,
    columns: Option<String>,
) -> PyResult<(Bound<'_, PyDict>, Bound<'_, PyDict>)> {
    let path = path.to_string_lossy().into_owned();
    let r = py
        .detach(|| crate::response::read_any(&path, columns.as_deref()))
        .map_err(py_err)?;
    let d = PyDict::new(py);
    d.set_item("t", PyArray1::from_vec(py, r.t))?;
    d.set_item("x", PyArray1::from_vec(py, r.x))?;
    d.set_item("z", PyArray1::from_vec(py, r.z))?;
    if let Some(speed) = r.speed {
        for (name, c) in SPEED_NAMES.iter().zip(speed) {
            d.set_item(name, PyArray1::from_vec(py, c))?;
        }
    }
    let units = PyDict::new(py);
    for (name, unit) in r.converted {
        units.set_item(name, unit)?;
    }
    warn_notes(py, &path, &r.notes)?;
    Ok((d, units))
}

/// `m` (n x n, SI) as a 2-D float64 array.
fn matrix<'py>(py: Python<'py>, n: usize, row_major: Vec<f64>) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, row_major)
        .reshape([n, n])?
        .into_any())
}

/// Identify a finite-element rotor (`crate::finite_element::identify`): the summary as
/// JSON text.
#[pyfunction]
#[pyo3(signature = (t, channels, scenario, unknowns=None, initial=None, modes=None, offsets=false))]
#[allow(clippy::too_many_arguments)]
fn identify_finite_element(
    py: Python<'_>,
    t: Vec<f64>,
    channels: Vec<(String, Vec<f64>)>,
    scenario: std::path::PathBuf,
    unknowns: Option<String>,
    initial: Option<String>,
    modes: Option<usize>,
    offsets: bool,
) -> PyResult<String> {
    let path = scenario.to_string_lossy().into_owned();
    py.detach(|| {
        crate::finite_element::identify(
            t,
            channels,
            &path,
            unknowns.as_deref(),
            initial.as_deref(),
            modes,
            offsets,
        )
    })
    .map_err(py_err)
}

/// The matrices file `path` as stored (`rotorid_io::fe_matrices`): a dict of `dofs` (list
/// of str) and `M`, `K`, `G`, `C`, `Ka` (n x n float64 arrays; `C`, `Ka` None when absent).
#[pyfunction]
fn read_fe_matrices(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let path = path.to_string_lossy().into_owned();
    let f = py
        .detach(|| crate::finite_element::read_matrices(&path))
        .map_err(py_err)?;
    let n = f.n();
    let d = PyDict::new(py);
    d.set_item("dofs", &f.dofs)?;
    d.set_item("M", matrix(py, n, f.m)?)?;
    d.set_item("K", matrix(py, n, f.k)?)?;
    d.set_item("G", matrix(py, n, f.g)?)?;
    d.set_item("C", f.c.map(|c| matrix(py, n, c)).transpose()?)?;
    d.set_item("Ka", f.ka.map(|ka| matrix(py, n, ka)).transpose()?)?;
    Ok(d)
}

/// The finite-element rotor of the scenario TOML `path` (`rotor.model =
/// "finite_element"`) joined with its matrices file, every check the library's: a dict of
/// `matrices` (the path read), `dofs`, `M`, `K`, `G`, `C`, `Ka` (as checked), `bearings`
/// (dicts of node, kxx .. cyy) and `unbalances` (dicts of node, mud [kg m], alpha [rad]).
#[pyfunction]
fn load_finite_element(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let path = path.to_string_lossy().into_owned();
    let (r, matrices) = py
        .detach(|| crate::finite_element::load(&path))
        .map_err(py_err)?;
    let m = &r.matrices;
    let n = m.n();
    let rows = |a: &nalgebra::DMatrix<f64>| a.transpose().as_slice().to_vec();
    let d = PyDict::new(py);
    d.set_item("matrices", matrices)?;
    d.set_item(
        "dofs",
        m.dofs().iter().map(|x| x.to_string()).collect::<Vec<_>>(),
    )?;
    d.set_item("M", matrix(py, n, rows(m.m()))?)?;
    d.set_item("K", matrix(py, n, rows(m.k()))?)?;
    d.set_item("G", matrix(py, n, rows(m.g()))?)?;
    d.set_item("C", m.c().map(|c| matrix(py, n, rows(c))).transpose()?)?;
    d.set_item("Ka", m.ka().map(|c| matrix(py, n, rows(c))).transpose()?)?;
    let bearings = r
        .bearings
        .iter()
        .map(|b| {
            let e = PyDict::new(py);
            e.set_item("node", b.node)?;
            for (k, v) in [
                ("kxx", b.kxx),
                ("kxy", b.kxy),
                ("kyx", b.kyx),
                ("kyy", b.kyy),
                ("cxx", b.cxx),
                ("cxy", b.cxy),
                ("cyx", b.cyx),
                ("cyy", b.cyy),
            ] {
                e.set_item(k, v)?;
            }
            Ok(e)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("bearings", bearings)?;
    let unbalances = r
        .unbalances
        .iter()
        .map(|u| {
            let e = PyDict::new(py);
            e.set_item("node", u.node)?;
            e.set_item("mud", u.mud)?;
            e.set_item("alpha", u.alpha)?;
            Ok(e)
        })
        .collect::<PyResult<Vec<_>>>()?;
    d.set_item("unbalances", unbalances)?;
    Ok(d)
}

/// What the reader noted about the file at `path` (an interrupted recording's unfinished
/// chunk), each as a `UserWarning`.
fn warn_notes(py: Python<'_>, path: &str, notes: &[String]) -> PyResult<()> {
    for n in notes {
        let category = py.get_type::<pyo3::exceptions::PyUserWarning>();
        PyErr::warn(
            py,
            &category,
            &std::ffi::CString::new(format!("{path}: {n}"))?,
            1,
        )?;
    }
    Ok(())
}

/// The record at `path` read `rows` rows at a time (`rotorid.read_blocks`): an iterator of
/// `(first row, {t, x, z[, phi, phi_dot, phi_ddot]: float64 array})`, in SI, bit for bit
/// the numbers of `read`; `units` as `read`'s second value. TDMS and Parquet are streamed
/// (memory holds a block, whatever the record's length); the other formats are read whole,
/// then handed out. The GIL is released while a block is read.
#[pyfunction]
#[pyo3(signature = (path, columns=None, rows=65536))]
fn read_blocks(
    py: Python<'_>,
    path: std::path::PathBuf,
    columns: Option<String>,
    rows: usize,
) -> PyResult<PyBlocks> {
    let path = path.to_string_lossy().into_owned();
    let r = py
        .detach(|| crate::response::open_blocks(&path, columns.as_deref(), rows))
        .map_err(py_err)?;
    warn_notes(py, &path, &r.notes)?;
    Ok(PyBlocks {
        units: r.converted.clone(),
        inner: Mutex::new(r),
    })
}

/// The iterator [`read_blocks`] returns.
#[pyclass(module = "rotorid._rotorid", name = "Blocks")]
pub struct PyBlocks {
    inner: Mutex<crate::response::BlockReader>,
    units: Vec<(String, String)>,
}

#[pymethods]
impl PyBlocks {
    /// Each role whose channel the file gives in another unit than SI, with that unit.
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let units = PyDict::new(py);
        for (name, unit) in &self.units {
            units.set_item(name, unit)?;
        }
        Ok(units)
    }

    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&self, py: Python<'py>) -> PyResult<Option<(usize, Bound<'py, PyDict>)>> {
        let next = py
            .detach(|| {
                let mut r = self.inner.lock().unwrap_or_else(|p| p.into_inner());
                r.next_block()
            })
            .map_err(py_err)?;
        let Some(b) = next else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("t", PyArray1::from_vec(py, b.t))?;
        d.set_item("x", PyArray1::from_vec(py, b.x))?;
        d.set_item("z", PyArray1::from_vec(py, b.z))?;
        if let Some(speed) = b.speed {
            for (name, c) in SPEED_NAMES.iter().zip(speed) {
                d.set_item(name, PyArray1::from_vec(py, c))?;
            }
        }
        Ok(Some((b.first, d)))
    }
}

/// The options of a call.
fn options_of(
    model: Option<String>,
    unknowns: Option<Vec<String>>,
    quadrature: Option<String>,
    rcond_min: Option<f64>,
    tol: Option<f64>,
    window: Option<f64>,
    restart: Option<f64>,
) -> Options {
    Options {
        model,
        unknowns,
        quadrature,
        rcond_min,
        tol,
        window,
        restart,
    }
}

/// Identify a record: (summary JSON, estimates dict, seconds spent in the library).
#[pyfunction]
#[pyo3(signature = (scenario, method, t, x, z, phi=None, phi_dot=None, phi_ddot=None, *,
    model=None, unknowns=None, quadrature=None, rcond_min=None, tol=None, window=None,
    restart=None, time_tolerance=DEFAULT_TIME_TOLERANCE, input=None, scenario_name=None))]
#[allow(clippy::too_many_arguments)]
fn identify<'py>(
    py: Python<'py>,
    scenario: &PyScenario,
    method: &str,
    t: &Bound<'py, PyAny>,
    x: &Bound<'py, PyAny>,
    z: &Bound<'py, PyAny>,
    phi: Option<&Bound<'py, PyAny>>,
    phi_dot: Option<&Bound<'py, PyAny>>,
    phi_ddot: Option<&Bound<'py, PyAny>>,
    model: Option<String>,
    unknowns: Option<Vec<String>>,
    quadrature: Option<String>,
    rcond_min: Option<f64>,
    tol: Option<f64>,
    window: Option<f64>,
    restart: Option<f64>,
    time_tolerance: f64,
    input: Option<String>,
    scenario_name: Option<String>,
) -> PyResult<(String, Bound<'py, PyDict>, f64)> {
    let o = options_of(model, unknowns, quadrature, rcond_min, tol, window, restart);
    let method = options::method(method, &o).map_err(py_err)?;
    let held = Held::new(Some(t), x, z, [phi, phi_dot, phi_ddot])?;
    let columns = held.columns()?;
    let sc = &scenario.inner;
    let (result, seconds) = py.detach(|| {
        let start = Instant::now();
        let r = stream::identify(&columns, sc, &method, time_tolerance);
        (r, start.elapsed().as_secs_f64())
    });
    let done = result.map_err(py_err)?;
    let summary = stream::summary_json(done.identification, input, scenario_name);
    Ok((summary, estimates_dict(py, done.estimates)?, seconds))
}

/// A live identification: chunks pushed as they arrive.
#[pyclass(module = "rotorid._rotorid", name = "Session")]
pub struct PySession {
    inner: Mutex<Option<Stream>>,
}

impl PySession {
    fn with<T>(&self, f: impl FnOnce(&mut Stream) -> Result<T, Error>) -> PyResult<T> {
        let mut guard = self
            .inner
            .lock()
            .map_err(|_| PyValueError::new_err("the session failed in another thread"))?;
        let s = guard
            .as_mut()
            .ok_or_else(|| PyValueError::new_err("the session is finished"))?;
        f(s).map_err(py_err)
    }
}

#[pymethods]
impl PySession {
    #[new]
    #[pyo3(signature = (scenario, method="algebraic", dt=None, t0=0.0, *, model=None,
        unknowns=None, quadrature=None, rcond_min=None, tol=None, window=None, restart=None,
        time_tolerance=DEFAULT_TIME_TOLERANCE))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        scenario: &PyScenario,
        method: &str,
        dt: Option<f64>,
        t0: f64,
        model: Option<String>,
        unknowns: Option<Vec<String>>,
        quadrature: Option<String>,
        rcond_min: Option<f64>,
        tol: Option<f64>,
        window: Option<f64>,
        restart: Option<f64>,
        time_tolerance: f64,
    ) -> PyResult<Self> {
        let o = options_of(model, unknowns, quadrature, rcond_min, tol, window, restart);
        let method = options::method(method, &o).map_err(py_err)?;
        let grid = dt.map(|dt| (t0, dt));
        let s = Stream::new(&scenario.inner, &method, grid, time_tolerance).map_err(py_err)?;
        Ok(Self {
            inner: Mutex::new(Some(s)),
        })
    }

    /// Push a chunk (phi alone: speed and acceleration from the scenario's profile);
    /// returns the estimates it completed.
    #[pyo3(signature = (x, z, t=None, phi=None, phi_dot=None, phi_ddot=None))]
    #[allow(clippy::too_many_arguments)]
    fn push<'py>(
        &self,
        py: Python<'py>,
        x: &Bound<'py, PyAny>,
        z: &Bound<'py, PyAny>,
        t: Option<&Bound<'py, PyAny>>,
        phi: Option<&Bound<'py, PyAny>>,
        phi_dot: Option<&Bound<'py, PyAny>>,
        phi_ddot: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let held = Held::new(t, x, z, [phi, phi_dot, phi_ddot])?;
        let (t, x, z) = (opt(&held.t)?, slice(&held.x)?, slice(&held.z)?);
        let speed = [
            opt(&held.speed[0])?,
            opt(&held.speed[1])?,
            opt(&held.speed[2])?,
        ];
        let e = py.detach(|| self.with(|s| s.push_angle(t, x, z, speed)))?;
        estimates_dict(py, e)
    }

    /// Start on the stamps held back so far (a paused acquisition).
    fn start_now<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let e = py.detach(|| self.with(Stream::start_now))?;
        estimates_dict(py, e)
    }

    #[getter]
    fn samples(&self) -> PyResult<usize> {
        self.with(|s| Ok(s.samples()))
    }

    /// The identification of every sample pushed: (summary JSON, remaining estimates).
    #[pyo3(signature = (*, input=None, scenario_name=None))]
    fn finish<'py>(
        &self,
        py: Python<'py>,
        input: Option<String>,
        scenario_name: Option<String>,
    ) -> PyResult<(String, Bound<'py, PyDict>)> {
        let taken = {
            let mut guard = self
                .inner
                .lock()
                .map_err(|_| PyValueError::new_err("the session failed in another thread"))?;
            guard
                .take()
                .ok_or_else(|| PyValueError::new_err("the session is finished"))?
        };
        let done = py.detach(|| taken.finish()).map_err(py_err)?;
        let summary = stream::summary_json(done.identification, input, scenario_name);
        Ok((summary, estimates_dict(py, done.estimates)?))
    }
}

/// Multi-plane balancing (`rotorid.balance`) or, with `plan`, trial planning
/// (`rotorid.plan_trials`): `balance.json` as text, from the CSV texts of the vectors and
/// the masses (crate::balance).
#[pyfunction]
#[pyo3(signature = (vectors, masses, current, *, vectors_name="vectors", masses_name="masses",
    method="ls", speeds=None, planes=None, limits=Vec::new(), weights=Vec::new(),
    radius=Vec::new(), default_radius=None, holes_equal=Vec::new(), holes_angles=Vec::new(),
    mass_set=None, per_hole=1, phase=None, unit=None, plan=None))]
#[allow(clippy::too_many_arguments)]
fn balance(
    py: Python<'_>,
    vectors: String,
    masses: String,
    current: String,
    vectors_name: &str,
    masses_name: &str,
    method: &str,
    speeds: Option<Vec<f64>>,
    planes: Option<Vec<String>>,
    limits: Vec<(String, f64)>,
    weights: Vec<(String, f64)>,
    radius: Vec<(String, f64)>,
    default_radius: Option<f64>,
    holes_equal: Vec<(String, (usize, f64))>,
    holes_angles: Vec<(String, Vec<f64>)>,
    mass_set: Option<Vec<f64>>,
    per_hole: usize,
    phase: Option<String>,
    unit: Option<String>,
    plan: Option<f64>,
) -> PyResult<String> {
    let r = crate::balance::Request {
        vectors: (vectors_name.to_owned(), vectors),
        masses: (masses_name.to_owned(), masses),
        current,
        method: method.to_owned(),
        speeds,
        planes,
        limits,
        weights,
        radius,
        default_radius,
        holes_equal,
        holes_angles,
        mass_set,
        per_hole,
        phase,
        unit,
    };
    py.detach(|| match plan {
        Some(fraction) => crate::balance::plan_json(&r, fraction),
        None => crate::balance::balance_json(&r),
    })
    .map_err(py_err)
}

/// A run-up or coast-down analysed as `rotorid transient` analyses it
/// (`crate::transient`): `(transient.json text, {bode.csv column: array or list}, [(file,
/// note)])`. `scenario` is a `Scenario` or a path; `vectors` the CSV text of a 1X table
/// (`vectors_name` names it in messages); `slow_roll_kind` one of `default`, `auto`,
/// `none`, `file` (`slow_roll_file`) or `range` (`slow_roll_range`, rev/min).
#[pyfunction]
#[pyo3(signature = (records, *, scenario=None, vectors=None, vectors_name=None, amplitude="pk",
    unit=None, slow_roll_kind="default", slow_roll_file=None, slow_roll_range=None, orders=None,
    operating_rpm=None, bin_rpm=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn transient<'py>(
    py: Python<'py>,
    records: Vec<String>,
    scenario: Option<&Bound<'py, PyAny>>,
    vectors: Option<String>,
    vectors_name: Option<String>,
    amplitude: &str,
    unit: Option<String>,
    slow_roll_kind: &str,
    slow_roll_file: Option<String>,
    slow_roll_range: Option<(f64, f64)>,
    orders: Option<Vec<u32>>,
    operating_rpm: Option<(f64, f64)>,
    bin_rpm: Option<f64>,
) -> PyResult<(String, Bound<'py, PyDict>, Vec<(String, String)>)> {
    use crate::transient::{Request, SlowRollKw};
    let slow_roll = match (slow_roll_kind, slow_roll_file, slow_roll_range) {
        ("default", None, None) => SlowRollKw::Default,
        ("auto", None, None) => SlowRollKw::Auto,
        ("none", None, None) => SlowRollKw::None,
        ("file", Some(f), None) => SlowRollKw::File(f),
        ("range", None, Some((a, b))) => SlowRollKw::Range(a, b),
        (k, _, _) => {
            return Err(PyValueError::new_err(format!(
                "slow_roll_kind={k:?}: expected default, auto, none, file (with slow_roll_file) or range (with slow_roll_range)"
            )))
        }
    };
    let spec = match scenario {
        None => None,
        Some(s) => match s.cast::<PyScenario>() {
            Ok(sc) => Some(sc.get().inner.spec().clone()),
            Err(_) => {
                let path: std::path::PathBuf = s.extract()?;
                let sc = Scenario::from_toml_file(&path.to_string_lossy()).map_err(py_err)?;
                Some(sc.spec().clone())
            }
        },
    };
    let request = Request {
        records,
        vectors: vectors.map(|text| (vectors_name.unwrap_or_else(|| "vectors".into()), text)),
        amplitude: amplitude.to_owned(),
        unit,
        slow_roll,
        orders,
        operating_rpm,
        bin_rpm,
    };
    let out = py
        .detach(|| crate::transient::transient(spec.as_ref(), &request))
        .map_err(py_err)?;
    let b = out.bode;
    let d = PyDict::new(py);
    d.set_item("speed_rpm", PyArray1::from_vec(py, b.speed_rpm))?;
    d.set_item("sensor", b.sensor)?;
    d.set_item("order", PyArray1::from_vec(py, b.order))?;
    for (name, c) in [
        ("amplitude", b.amplitude),
        ("phase_lag_deg", b.phase_lag_deg),
        ("re", b.re),
        ("im", b.im),
        ("std", b.std),
        ("raw_re", b.raw_re),
        ("raw_im", b.raw_im),
    ] {
        d.set_item(name, PyArray1::from_vec(py, c))?;
    }
    Ok((out.json, d, out.read_notes))
}

/// The extension module.
#[pymodule]
#[pyo3(name = "_rotorid")]
fn rotorid_extension(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScenario>()?;
    m.add_class::<PySession>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(read_blocks, m)?)?;
    m.add_class::<PyBlocks>()?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(balance, m)?)?;
    m.add_function(wrap_pyfunction!(transient, m)?)?;
    m.add_function(wrap_pyfunction!(read_fe_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(load_finite_element, m)?)?;
    m.add_function(wrap_pyfunction!(identify_finite_element, m)?)?;
    m.add("METHODS", options::METHOD_NAMES.to_vec())?;
    m.add("UNKNOWNS", options::UNKNOWN_NAMES.to_vec())?;
    m.add("MODELS", options::MODEL_NAMES.to_vec())?;
    m.add("ESTIMATE_COLUMNS", ESTIMATE_COLUMNS.to_vec())?;
    let by_model = PyDict::new(m.py());
    for model in ModelKind::ALL {
        by_model.set_item(model.name(), crate::columns::estimate_columns(model))?;
    }
    m.add("ESTIMATE_COLUMNS_BY_MODEL", by_model)?;
    Ok(())
}
