//! The input-to-output plumbing of `rotorid identify`: rows of the response CSV go into a
//! `rotorid::pipeline::Session` as they are read, the algebraic estimates come out as
//! rows of the estimates CSV (every `--every`-th), the batch methods' one row is written
//! at the end. Memory stays bounded for the streaming methods whatever the input length.
//!
//! A live input (stdin, a pipe or FIFO) gets its estimates as soon as its samples arrive:
//! just before a read that may block, the output is flushed and the session starts on the
//! samples it holds (its time grid is then fitted over those; a regular file's over the
//! first `DEFAULT_GRID_HEAD` stamps).
//!
//! A regular file is read on a second thread: it splits and parses rows in batches of
//! [`BATCH_ROWS`] while this one identifies the previous batch (at most [`BATCHES_AHEAD`]
//! batches ahead, so memory stays bounded). Rows reach the session in file order, and a
//! bad row's error arrives after every row before it, as on one thread.

use std::cell::RefCell;
use std::io::{self, Read, Write};
use std::rc::Rc;

use anyhow::Context as _;
use rotorid::pipeline::{
    Identification, Method, PipelineError, Sample, SampleEstimate, Session, Timing,
    DEFAULT_GRID_HEAD,
};
use rotorid::SpeedProfile;

use crate::io::estimates_csv::estimates_parquet;
use crate::io::progress::{Progress, Unit};
use crate::io::{CsvError, EstimateRow, EstimatesWriter, Output, ResponseReader, ScenarioSpec};

/// Rows a reader thread parses before it hands them over.
const BATCH_ROWS: usize = 4096;

/// Rows of a block read from a file that streams (TDMS, Parquet): 2^14 rows of six
/// channels are 768 KiB.
const BLOCK_ROWS: usize = 1 << 14;

/// Batches the reader thread may run ahead of the identification.
const BATCHES_AHEAD: usize = 4;

/// Names and options of one run.
pub(crate) struct Io<'a> {
    /// The input's name in messages.
    pub name: &'a str,
    /// The output's name in messages.
    pub out_name: &'a str,
    /// Whether reads may block (stdin, pipe, FIFO).
    pub live: bool,
    /// Write the estimates as Parquet (at the end) rather than CSV (as they come).
    pub parquet: bool,
    /// Write every N-th algebraic estimate.
    pub every: u64,
    /// Show progress on stderr (`io::progress`) against this input size \[bytes\]: a
    /// regular CSV file, not under `-q`.
    pub progress_bytes: Option<u64>,
}

/// What the reader's pre-read hook and the row loop share.
struct State {
    session: Session,
    rows: Rows,
}

/// Where the algebraic estimates go: every `every`-th as a row of the estimates CSV.
struct Rows {
    /// The output until the first row is written (then inside `writer`): nothing, not even
    /// the header, is written for an input that gives no estimate.
    out: Option<Output>,
    writer: Option<EstimatesWriter<Output>>,
    /// For a Parquet output: the rows, written when the run ends (nothing on error).
    parquet: Option<Vec<EstimateRow>>,
    /// Estimates to skip before the next one written (the `--every` counter: a count down
    /// rather than a remainder, which is a division per estimate).
    skip: u64,
    every: u64,
    /// The first write error (a session's sink cannot return one).
    error: Option<io::Error>,
}

impl Rows {
    fn write(&mut self, e: &SampleEstimate) {
        if self.skip > 0 {
            self.skip -= 1;
            return;
        }
        self.skip = self.every.saturating_sub(1);
        if self.error.is_some() {
            return;
        }
        if let Some(rows) = self.parquet.as_mut() {
            rows.push(row_of(e));
            return;
        }
        if self.writer.is_none() {
            match self
                .out
                .take()
                .map(|o| EstimatesWriter::for_model(o, e.model))
            {
                Some(Ok(w)) => self.writer = Some(w),
                Some(Err(err)) => self.error = Some(err),
                None => {}
            }
        }
        if let Some(w) = self.writer.as_mut() {
            if let Err(err) = w.write(&row_of(e)) {
                self.error = Some(err);
            }
        }
    }

    /// The output back, with what was written.
    fn into_output(self) -> Option<Output> {
        self.writer.map(EstimatesWriter::into_inner).or(self.out)
    }
}

impl State {
    fn push(&mut self, s: &Sample) -> Result<(), PipelineError> {
        let rows = &mut self.rows;
        self.session.push(s, &mut |e| rows.write(e))
    }

    /// Flush, and on a live input start the session on what it holds.
    fn before_read(&mut self, live: bool) -> io::Result<()> {
        if live {
            let rows = &mut self.rows;
            // a grid error here surfaces again at the next push or at the end
            let _ = self.session.start_now(&mut |e| rows.write(e));
        }
        if let Some(e) = self.rows.error.take() {
            return Err(e);
        }
        match self.rows.writer.as_mut() {
            Some(w) => w.flush(),
            None => Ok(()),
        }
    }
}

/// An input that calls `State::before_read` before each read of the underlying input.
struct HookedInput<R> {
    inner: R,
    state: Rc<RefCell<State>>,
    live: bool,
}

impl<R: Read> Read for HookedInput<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if let Ok(mut s) = self.state.try_borrow_mut() {
            s.before_read(self.live)?;
        }
        self.inner.read(buf)
    }
}

/// Where the samples come from: a response CSV read as it streams, or columns already in
/// memory and in SI (a binary file, a CSV read whole for `--columns`, a conditioned raw
/// record).
pub(crate) enum Source {
    /// The response CSV (a file or a live pipe).
    Csv(Box<dyn Read + Send>),
    /// t \[s\], x, z \[m\] and optional phi \[rad\], phi_dot \[rad/s\], phi_ddot
    /// \[rad/s^2\].
    Columns(rotorid_io::SiColumns),
    /// The same, read a block of rows at a time from a file whose format streams.
    Blocks(rotorid_io::SiBlocks),
}

/// Read `input`, identify it by `method` with what `spec` knows, write the estimates CSV
/// to `out` (committed on success; complete rows on error) and return the result.
pub(crate) fn identify(
    io: &Io,
    input: Source,
    out: Output,
    spec: &ScenarioSpec,
    method: &Method,
    time_tolerance: f64,
) -> anyhow::Result<Identification> {
    let knowledge = spec.knowledge()?;
    let profile = spec.identification()?.speed;
    let timing = Timing::Fit {
        head: DEFAULT_GRID_HEAD,
        tolerance: time_tolerance,
    };
    let session = Session::new(&knowledge, method, profile, timing)
        .map_err(|e| CsvError::file(io.name, e.to_string()))?;
    // The algebraic method writes a row per estimate as it goes, the others one at the end.
    let algebraic = matches!(method, Method::Algebraic(_));
    let (out, held) = if algebraic {
        (Some(out), None)
    } else {
        (None, Some(out))
    };
    let state = Rc::new(RefCell::new(State {
        session,
        rows: Rows {
            out,
            writer: None,
            parquet: io.parquet.then(Vec::new),
            skip: 0,
            every: io.every,
            error: None,
        },
    }));
    let result = match input {
        Source::Csv(input) if !io.live => read_all_threaded(io, input, &state, profile),
        Source::Csv(input) => {
            let hooked = HookedInput {
                inner: input,
                state: Rc::clone(&state),
                live: io.live,
            };
            read_all(io, hooked, &state, profile)
        }
        Source::Columns(cols) => push_columns(io, &cols, &state, profile),
        Source::Blocks(blocks) => push_blocks_threaded(io, blocks, &state, profile),
    };
    let State { session, mut rows } = Rc::try_unwrap(state)
        .map_err(|_| anyhow::anyhow!("the input still holds the session"))?
        .into_inner();
    let finished = result.and_then(|()| {
        session
            .finish(&mut |e| rows.write(e))
            .map_err(|e| CsvError::file(io.name, finish_error(e, spec.origin())).into())
    });
    if let Some(e) = rows.error.take() {
        return Err(e).with_context(|| format!("cannot write {}", io.out_name));
    }
    // After an error, keep the whole rows written so far.
    let parquet = rows.parquet.take();
    let Some(mut out) = rows.into_output().or(held) else {
        anyhow::bail!("no output for {}", io.out_name);
    };
    let ident = match finished {
        Ok(i) => i,
        Err(e) => {
            let _ = out.flush();
            return Err(e);
        }
    };
    let last = ident
        .final_estimate()
        .map(|f| EstimateRow::new(f.t_s, f.model, &f.values, [f.rcond.x, f.rcond.z], None));
    if let Some(mut table) = parquet {
        table.extend(last);
        let bytes = estimates_parquet(io.out_name, ident.model, &table)?;
        out.write_all(&bytes)
            .with_context(|| format!("cannot write {}", io.out_name))?;
    } else if let Some(last) = last {
        let mut w = EstimatesWriter::for_model(&mut out, last.model)
            .with_context(|| format!("cannot write {}", io.out_name))?;
        w.write(&last)
            .with_context(|| format!("cannot write {}", io.out_name))?;
    }
    out.commit()?;
    Ok(ident)
}

/// Every row of `reader` into the session.
fn read_all<R: Read>(
    io: &Io,
    input: HookedInput<R>,
    state: &Rc<RefCell<State>>,
    profile: Option<SpeedProfile>,
) -> anyhow::Result<()> {
    let mut reader = open_rows(io, input, profile)?;
    while let Some(row) = reader.next_row()? {
        push_row(io, state, &row)?;
    }
    Ok(())
}

/// One row of the response CSV into the session (a refusal names its line).
fn push_row(
    io: &Io,
    state: &Rc<RefCell<State>>,
    row: &crate::io::response_csv::ResponseRow,
) -> anyhow::Result<()> {
    let s = Sample {
        t: Some(row.t),
        x: row.x,
        z: row.z,
        speed: row.speed,
    };
    push(io, state, &s, |m| {
        CsvError::line(io.name, row.line, m).into()
    })
}

/// The response CSV reader of `input`, its unit conversions noted on stderr; an error when
/// neither the file nor the scenario gives the speed.
fn open_rows<R: Read>(
    io: &Io,
    input: R,
    profile: Option<SpeedProfile>,
) -> anyhow::Result<ResponseReader<R>> {
    let reader = ResponseReader::new(io.name, input)?;
    reader.print_conversions();
    if !reader.has_phi() && profile.is_none() {
        return Err(CsvError::file(
            io.name,
            "has no phi, phi_dot, phi_ddot columns and the scenario has no [speed] section: \
             give the rotor angle in the data or the speed profile in the scenario"
                .to_owned(),
        )
        .into());
    }
    Ok(reader)
}

/// Every row of the regular file `input` into the session, parsed on a second thread
/// (module doc).
fn read_all_threaded(
    io: &Io,
    input: Box<dyn Read + Send>,
    state: &Rc<RefCell<State>>,
    profile: Option<SpeedProfile>,
) -> anyhow::Result<()> {
    let read = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let input = CountingReader {
        inner: input,
        read: std::sync::Arc::clone(&read),
    };
    let mut progress = io
        .progress_bytes
        .map(|total| Progress::counting(total, "identify", Unit::Bytes));
    let mut reader = open_rows(io, input, profile)?;
    type Batch = Result<Vec<crate::io::response_csv::ResponseRow>, CsvError>;
    let (tx, rx) = std::sync::mpsc::sync_channel::<Batch>(BATCHES_AHEAD);
    std::thread::scope(|scope| {
        scope.spawn(move || loop {
            let mut batch = Vec::with_capacity(BATCH_ROWS);
            let end = loop {
                match reader.next_row() {
                    Ok(Some(row)) => {
                        batch.push(row);
                        if batch.len() == BATCH_ROWS {
                            break None;
                        }
                    }
                    Ok(None) => break Some(Ok(())),
                    Err(e) => break Some(Err(e)),
                }
            };
            // a send fails only when the identification stopped: nothing more to do
            if !batch.is_empty() && tx.send(Ok(batch)).is_err() {
                return;
            }
            match end {
                None => {}
                Some(Ok(())) => return,
                Some(Err(e)) => {
                    let _ = tx.send(Err(e));
                    return;
                }
            }
        });
        // rx is dropped on the first error, which stops the reader at its next send
        for batch in rx {
            for row in batch? {
                push_row(io, state, &row)?;
            }
            if let Some(p) = &mut progress {
                p.update(read.load(std::sync::atomic::Ordering::Relaxed));
            }
        }
        if let Some(p) = progress {
            p.finish();
        }
        Ok(())
    })
}

/// A reader that counts the bytes read through it (for the progress of the reading
/// thread, seen from the identifying one).
struct CountingReader<R> {
    inner: R,
    read: std::sync::Arc<std::sync::atomic::AtomicU64>,
}

impl<R: Read> Read for CountingReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read
            .fetch_add(n as u64, std::sync::atomic::Ordering::Relaxed);
        Ok(n)
    }
}

/// One sample into the session; `at` locates a refused sample's message (its line or
/// index). A failed write of an estimate row is reported too.
fn push(
    io: &Io,
    state: &Rc<RefCell<State>>,
    s: &Sample,
    at: impl FnOnce(String) -> anyhow::Error,
) -> anyhow::Result<()> {
    let mut st = state.borrow_mut();
    st.push(s).map_err(|e| {
        let hint = match e {
            PipelineError::NonUniformSampling { .. } => " (--time-tolerance)",
            _ => "",
        };
        at(format!("{e}{hint}"))
    })?;
    if let Some(e) = st.rows.error.take() {
        return Err(e).with_context(|| format!("cannot write {}", io.out_name));
    }
    Ok(())
}

/// Every sample of `cols` into the session (sample i named as such in messages).
fn push_columns(
    io: &Io,
    cols: &rotorid_io::SiColumns,
    state: &Rc<RefCell<State>>,
    profile: Option<SpeedProfile>,
) -> anyhow::Result<()> {
    need_speed(io, cols.speed.is_some(), profile)?;
    push_rows(io, 0, &cols.t, &cols.x, &cols.z, cols.speed.as_ref(), state)
}

/// An error when neither the file nor the scenario gives the speed.
fn need_speed(io: &Io, has_speed: bool, profile: Option<SpeedProfile>) -> anyhow::Result<()> {
    if !has_speed && profile.is_none() {
        anyhow::bail!(
            "{}: has no phi, phi_dot, phi_ddot channels and the scenario has no [speed] \
             section: give the rotor angle in the data (--columns t,x,z,phi,phi_dot,phi_ddot) \
             or the speed profile in the scenario",
            io.name
        );
    }
    Ok(())
}

/// The rows of columns t, x, z and speed, the record's samples `first..`, into the session
/// (sample i named as such in messages).
fn push_rows(
    io: &Io,
    first: usize,
    t: &[f64],
    x: &[f64],
    z: &[f64],
    speed: Option<&[Vec<f64>; 3]>,
    state: &Rc<RefCell<State>>,
) -> anyhow::Result<()> {
    for j in 0..x.len() {
        let s = Sample {
            t: Some(t[j]),
            x: x[j],
            z: z[j],
            speed: speed.map(|[p, w, a]| rotorid::SpeedState {
                phi: p[j],
                omega: w[j],
                omega_dot: a[j],
            }),
        };
        push(io, state, &s, |m| {
            let i = first + j;
            anyhow::anyhow!("{}, sample {i} (t = {} s): {m}", io.name, t[j])
        })?;
    }
    Ok(())
}

/// Every sample of `blocks` into the session, read a block at a time on a second thread
/// while this one identifies the block before (at most [`BATCHES_AHEAD`] blocks ahead, so
/// memory holds a few blocks whatever the record's length); a read error arrives after
/// every sample before it, as on one thread.
fn push_blocks_threaded(
    io: &Io,
    mut blocks: rotorid_io::SiBlocks,
    state: &Rc<RefCell<State>>,
    profile: Option<SpeedProfile>,
) -> anyhow::Result<()> {
    need_speed(io, blocks.has_speed(), profile)?;
    type Block = Result<rotorid_io::SiBlock, rotorid_io::ReadError>;
    let (tx, rx) = std::sync::mpsc::sync_channel::<Block>(BATCHES_AHEAD);
    std::thread::scope(|scope| {
        scope.spawn(move || loop {
            let next = blocks.next_block(BLOCK_ROWS).transpose();
            let stop = !matches!(next, Some(Ok(_)));
            // a send fails only when the identification stopped: nothing more to do
            if let Some(b) = next {
                if tx.send(b).is_err() {
                    return;
                }
            }
            if stop {
                return;
            }
        });
        // rx is dropped on the first error, which stops the reader at its next send
        for b in rx {
            let b = b?;
            push_rows(io, b.first, &b.t, &b.x, &b.z, b.speed.as_ref(), state)?;
        }
        Ok(())
    })
}

/// The message of an error at the end of the input, in the command's terms (its options
/// and the scenario file `scenario`).
fn finish_error(e: PipelineError, scenario: &str) -> String {
    let rotor_keys = |names: &str| names.replace(", ", ", rotor.");
    match e {
        PipelineError::Modulating(m) => format!("{m} (--window)"),
        PipelineError::KnownValueMissing { missing } => format!(
            "--unknowns leaves {missing} known, but the scenario {scenario} does not state \
             rotor.{}: give the known values in the scenario or add them to --unknowns",
            rotor_keys(&missing)
        ),
        PipelineError::NoStart { why, missing } => format!(
            "refine has no starting point: {why}; the scenario {scenario} does not state \
             rotor.{} to start from. The record may not excite the rotor at all; give \
             nominal values in the scenario to let the fit say what the record can determine",
            rotor_keys(&missing)
        ),
        e => e.to_string(),
    }
}

/// The estimates CSV row of one algebraic estimate: the values only where their
/// direction is well conditioned.
#[inline]
fn row_of(e: &SampleEstimate) -> EstimateRow {
    let v = e.values();
    let half = v.len() / 2;
    let mut values = [None; 10];
    for (i, (out, &x)) in values.iter_mut().zip(v).enumerate() {
        *out = (e.well_conditioned[i / half] && x.is_finite()).then_some(x);
    }
    EstimateRow {
        t: e.t,
        model: e.model,
        values,
        rcond_x: e.rcond[0],
        rcond_z: e.rcond[1],
        window: Some(e.window),
    }
}
