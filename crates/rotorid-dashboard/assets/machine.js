// rotorid dashboard, machine page: every parameter's trend with its 95 % band and the
// baseline band, alerts marked; the newest orbit and x(t), z(t); the 1X trend and polar
// plot; the newest identification's details. Updated by the event stream.
'use strict';

const ID = decodeURIComponent(location.pathname.split('/')[2] || '');
const Z95 = 1.959963984540054;
const S = {
  tile: null,
  detail: null,
  windows: new Map(), // window -> trend point
  oneX: new Map(), // window -> 1X point
  parameters: [],
  baseline: [],
  alerts: [],
  history: 3600,
  orbit: null,
};
let busy = false;
let again = false;

document.title = ID + ' \u00b7 rotorid';
document.getElementById('mid').textContent = ID;
const base = '/api/machines/' + encodeURIComponent(ID);
document.getElementById('csv').setAttribute('href', base + '/trend.csv');
document.getElementById('json').setAttribute('href', base + '/summary');

function merge(t) {
  S.parameters = t.parameters;
  S.baseline = t.baseline;
  S.alerts = t.alerts;
  S.history = t.history;
  for (const p of t.windows) S.windows.set(p.window, p);
  for (const p of t.one_x) S.oneX.set(p.window, p);
  const trim = (m) => {
    if (m.size <= S.history) return;
    const keys = Array.from(m.keys()).sort((a, b) => a - b);
    for (const k of keys.slice(0, m.size - S.history)) m.delete(k);
  };
  trim(S.windows);
  trim(S.oneX);
}

function sorted(m) {
  return Array.from(m.values()).sort((a, b) => a.window - b.window);
}

function headerRender() {
  const t = S.tile;
  if (!t) return;
  const st = document.getElementById('state');
  st.className = 'badge ' + t.state;
  st.textContent = t.state + (t.stale && t.state !== 'stale' ? ' \u00b7 stale' : '');
  const parts = [];
  if (t.window !== null) parts.push('window ' + t.window, 't0 ' + R.plain(t.t0_s) + ' s', 'stored ' + R.ago(t.arrived_ms));
  else parts.push('no result yet');
  if (t.method) parts.push(t.method);
  if (t.window_s) parts.push(Number(t.window_s.toPrecision(3)) + ' s windows');
  document.getElementById('meta').textContent = parts.join(' \u00b7 ');
}

function trendsRender() {
  const box = document.getElementById('trends');
  const pts = sorted(S.windows);
  const xs = pts.map((p) => p.window);
  const frag = document.createDocumentFragment();
  const n = S.parameters.length;
  const h = n > 6 ? 118 : n > 4 ? 132 : 170;
  S.parameters.forEach((c, i) => {
    const y = pts.map((p) => (p.values[i] === undefined ? null : p.values[i]));
    const se = pts.map((p) => (p.std_errors[i] === undefined ? null : p.std_errors[i]));
    const lo = y.map((v, k) => (v !== null && se[k] !== null ? v - Z95 * se[k] : null));
    const hi = y.map((v, k) => (v !== null && se[k] !== null ? v + Z95 * se[k] : null));
    const b = S.baseline.find((q) => q.name === c.name);
    const hband = b && b.value !== null && b.std_error !== null ? { lo: b.value - Z95 * b.std_error, hi: b.value + Z95 * b.std_error } : null;
    const vmarks = S.alerts.filter((a) => a.parameter === c.name).map((a) => ({
      x: a.window,
      cls: '',
      title: 'alert window ' + a.window + ': ' + a.parameter + ' z = ' + a.z.toFixed(1),
    }));
    const last = y.length ? y[y.length - 1] : null;
    const lastTxt = last === null ? 'withheld' : R.fmt(last, se[se.length - 1]) + ' ' + c.unit;
    const svg = P.chart({
      w: 1000,
      h,
      title: c.name + ' [' + c.unit + ']   newest ' + lastTxt + (b && b.value !== null ? '   baseline ' + R.fmt(b.value, b.std_error) : ''),
      ylabel: c.name + ' [' + c.unit + ']',
      xlabel: 'window number',
      series: [{ x: xs, y, lo, hi }],
      hband,
      vmarks,
      robust: true,
      keep: last === null ? [] : [last],
      empty: 'no value of ' + c.name + ' yet',
    });
    svg.dataset.param = c.name;
    svg.classList.add('trend');
    frag.appendChild(svg);
  });
  if (n === 0) frag.appendChild(R.el('p', 'note', 'no result yet'));
  R.clear(box).appendChild(frag);
}

function orbitRender() {
  const o = S.orbit;
  const title = document.getElementById('orbit-title');
  const note = document.getElementById('orbit-note');
  if (!o) {
    title.textContent = 'Orbit: no raw window read yet';
    R.clear(document.getElementById('orbit'));
    R.clear(document.getElementById('xt'));
    R.clear(document.getElementById('zt'));
    return;
  }
  title.textContent = 'Orbit, window ' + o.window + ' (t0 ' + R.plain(o.t0_s) + ' s' + (o.speed_rpm !== null ? ', ' + R.plain(o.speed_rpm, 5) + ' rpm' : '') + ', ' + o.keyphasor.length + ' keyphasor marks)';
  note.hidden = !o.note;
  note.textContent = o.note || '';
  const t = o.x_um.map((_, i) => o.t0_s + i * o.stride * o.dt_s);
  R.clear(document.getElementById('orbit')).appendChild(P.orbit(o.x_um, o.z_um, o.keyphasor, 400));
  const kpMarks = o.keyphasor.map((k) => ({ x: k.t_s, cls: 'kp-t' }));
  for (const [id, ys, cls, name] of [['xt', o.x_um, '', 'x'], ['zt', o.z_um, 'z', 'z']]) {
    const svg = P.chart({
      w: 560,
      h: 150,
      ylabel: name + ' [\u00b5m]',
      xlabel: 't [s]',
      series: [{ x: t, y: ys, cls, dots: false }],
      vmarks: [],
    });
    // keyphasor instants as thin lines
    R.clear(document.getElementById(id)).appendChild(svg);
    void kpMarks;
  }
}

function oneXRender() {
  const pts = sorted(S.oneX);
  const xs = pts.map((p) => p.window);
  const series = (key, what) => ['x', 'z'].map((d) => {
    const v = pts.map((p) => (p[d] ? p[d][key] : null));
    const se = pts.map((p) => (p[d] ? p[d][what] : null));
    return {
      x: xs,
      y: v,
      lo: v.map((a, i) => (a !== null && se[i] !== null ? a - Z95 * se[i] : null)),
      hi: v.map((a, i) => (a !== null && se[i] !== null ? a + Z95 * se[i] : null)),
      cls: d === 'z' ? 'z' : '',
    };
  });
  const amp = P.chart({ w: 620, h: 150, ylabel: 'amplitude [\u00b5m pk]', xlabel: 'window number', series: series('amplitude_um', 'amplitude_se_um'), robust: true, empty: 'no 1X vector yet (needs the phi channel)' });
  amp.dataset.kind = 'amplitude';
  const ph = P.chart({ w: 620, h: 150, ylabel: 'phase lag [deg]', xlabel: 'window number', series: series('phase_deg', 'phase_se_deg'), empty: 'no 1X vector yet (needs the phi channel)' });
  ph.dataset.kind = 'phase';
  R.clear(document.getElementById('amp')).appendChild(amp);
  R.clear(document.getElementById('phase')).appendChild(ph);
  const polar = [];
  pts.forEach((p, i) => {
    for (const d of ['x', 'z']) polar.push({ v: p[d], cls: d, latest: i === pts.length - 1 });
  });
  R.clear(document.getElementById('polar')).appendChild(P.polar(polar, 360));
}

function detailsRender() {
  const t = S.tile;
  const table = R.clear(document.getElementById('params'));
  if (t) {
    const head = R.el('tr');
    for (const h of ['parameter', 'value \u00b1 standard error', 'unit', 'relative']) head.appendChild(R.el('th', null, h));
    table.appendChild(head);
    for (const p of t.parameters) {
      const tr = R.el('tr');
      tr.dataset.param = p.name;
      tr.appendChild(R.el('th', null, p.name));
      const s = R.fmt(p.value, p.std_error);
      tr.appendChild(R.el('td', s === null ? 'v withheld' : 'v', s === null ? 'withheld' : s));
      tr.appendChild(R.el('td', 'u', p.unit));
      const rel = p.value !== null && p.std_error !== null && p.value !== 0 ? R.plain((100 * p.std_error) / Math.abs(p.value), 2) + ' %' : '';
      tr.appendChild(R.el('td', 'rel', rel));
      table.appendChild(tr);
    }
  }
  const ident = S.detail && S.detail.identification;
  const diag = R.clear(document.getElementById('diagnostics'));
  const dl = R.clear(document.getElementById('details'));
  if (!ident) return;
  const ds = Array.isArray(ident.diagnostics) ? ident.diagnostics : [];
  if (ds.length === 0) diag.appendChild(R.el('li', 'none', 'no diagnostic: nothing to read before trusting these numbers'));
  for (const d of ds) diag.appendChild(R.el('li', String(d.severity || ''), String(d.severity || '') + ': ' + String(d.message || d.kind || '')));
  const add = (k, v) => {
    if (v === null || v === undefined || typeof v === 'object') return;
    dl.appendChild(R.el('dt', null, k));
    dl.appendChild(R.el('dd', null, typeof v === 'number' ? R.plain(v) : String(v)));
  };
  add('method', ident.method);
  if (ident.model !== undefined) add('model', typeof ident.model === 'object' && ident.model !== null ? JSON.stringify(ident.model) : ident.model);
  if (ident.noise) {
    if (ident.noise.sigma_x_m !== undefined) add('noise sigma x [\u00b5m]', ident.noise.sigma_x_m * 1e6);
    if (ident.noise.sigma_z_m !== undefined) add('noise sigma z [\u00b5m]', ident.noise.sigma_z_m * 1e6);
    add('noise source', ident.noise.source);
  }
  if (ident.record) {
    add('samples', ident.record.samples);
    add('dt_s', ident.record.dt_s);
    add('speed from', ident.record.speed);
  }
  // the method's own figures (conditioning, convergence, adequacy), whatever they are
  const skip = new Set(['schema', 'method', 'input', 'scenario', 'record', 'noise', 'diagnostics', 'rotor', 'model']);
  for (const k of Object.keys(ident)) {
    const v = ident[k];
    if (skip.has(k) || v === null) continue;
    if (typeof v !== 'object' || Array.isArray(v)) { add(k, Array.isArray(v) ? v.join(', ') : v); continue; }
    for (const f of Object.keys(v)) {
      const x = v[f];
      if (x !== null && typeof x === 'object' && !Array.isArray(x)) {
        for (const g of Object.keys(x)) add(k + '.' + f + '.' + g, x[g]);
      } else {
        add(k + '.' + f, Array.isArray(x) ? x.map((e) => (typeof e === 'object' ? JSON.stringify(e) : e)).join(', ') : x);
      }
    }
  }
}

function eventsRender() {
  const table = R.clear(document.getElementById('alerts'));
  if (S.alerts.length === 0) {
    const tr = R.el('tr');
    tr.appendChild(R.el('td', 'muted', 'none'));
    table.appendChild(tr);
  } else {
    const head = R.el('tr');
    for (const h of ['window', 't0 [s]', 'parameter', 'baseline', 'value', 'change', 'z', 'stored']) head.appendChild(R.el('th', null, h));
    table.appendChild(head);
    const newest = S.tile && S.tile.window !== null ? S.tile.window : 0;
    for (const a of S.alerts.slice().reverse().slice(0, 12)) {
      const tr = R.el('tr', a.window + 10 > newest ? 'recent' : '');
      if (a.kind === 'model_inadequate') {
        // two consecutive windows the model does not explain: no parameter, a message
        tr.appendChild(R.el('td', null, a.window));
        tr.appendChild(R.el('td', null, R.plain(a.t0_s)));
        tr.appendChild(R.el('td', null, 'model'));
        const msg = R.el('td', null, 'windows ' + a.previous_window + ' and ' + a.window + ' not explained by the model: ' + a.message);
        msg.colSpan = 4;
        tr.appendChild(msg);
        tr.appendChild(R.el('td', null, R.ago(a.arrived_ms)));
      } else {
        for (const v of [a.window, R.plain(a.t0_s), a.parameter + ' [' + a.unit + ']', R.fmt(a.baseline, a.baseline_std_error), R.fmt(a.value, a.std_error),
          (a.relative_change >= 0 ? '+' : '') + (100 * a.relative_change).toFixed(2) + ' %', a.z.toFixed(1), R.ago(a.arrived_ms)]) {
          tr.appendChild(R.el('td', null, v));
        }
      }
      table.appendChild(tr);
    }
  }
  const ul = R.clear(document.getElementById('errors'));
  const errs = S.detail ? S.detail.errors : [];
  if (errs.length === 0) ul.appendChild(R.el('li', 'none', 'none'));
  for (const e of errs.slice().reverse().slice(0, 8)) {
    ul.appendChild(R.el('li', null, 'window ' + (e.window === null ? '?' : e.window) + ' (' + R.ago(e.arrived_ms) + '): ' + e.error));
  }
}

function renderAll() {
  headerRender();
  trendsRender();
  orbitRender();
  oneXRender();
  detailsRender();
  eventsRender();
  document.body.dataset.windows = String(S.windows.size);
  document.body.dataset.newest = S.tile && S.tile.window !== null ? String(S.tile.window) : '';
}

async function refresh(full) {
  if (busy) { again = true; return; }
  busy = true;
  try {
    // results arrive out of order (workers run in parallel) and behind the raw windows:
    // ask again for the 32 windows before the older of the newest result and 1X point
    const newest = Math.min(Math.max(-1, ...S.windows.keys()), Math.max(-1, ...S.oneX.keys()));
    const after = full || newest < 0 ? '' : '?after=' + Math.max(0, newest - 32);
    if (full) { S.windows.clear(); S.oneX.clear(); }
    const [detail, trend] = await Promise.all([R.getJSON(base), R.getJSON(base + '/trend' + after)]);
    S.detail = detail;
    S.tile = detail.tile;
    R.offset = detail.server_ms - Date.now();
    merge(trend);
    if (!S.orbit || S.tile.raw_window !== S.orbit.window) {
      try { S.orbit = await R.getJSON(base + '/orbit'); } catch (e) { if (e.status !== 404) throw e; }
    }
    R.serverLost = false;
    renderAll();
  } catch (err) {
    if (err.status === 404) {
      document.getElementById('meta').textContent = 'no window of ' + ID + ' has been read (yet)';
    } else {
      R.serverLost = true;
    }
    R.showBanner();
  } finally {
    busy = false;
    if (again) { again = false; setTimeout(() => refresh(false), 0); }
  }
}

R.clock();
R.events({
  onMachine: (t) => {
    if (t.id !== ID) return;
    if (!S.tile || S.tile.window !== t.window) R.lag(t);
    refresh(false);
  },
  onResync: () => refresh(true),
  onOpen: (wasLost) => { if (wasLost) refresh(true); },
});
refresh(true);
setInterval(headerRender, 1000);
// and the whole trend once a minute, for a result that came later than that
setInterval(() => refresh(true), 60000);
