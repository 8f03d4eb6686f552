// rotorid dashboard: helpers shared by the pages. Every text that comes from the bus
// (ids, parameter names, units, messages) goes into the page through textContent or
// setAttribute, never parsed as HTML.
'use strict';

const R = {};

// the server's clock minus ours [ms], from the last response that carried server_ms
R.offset = 0;
R.now = () => Date.now() + R.offset;

R.el = function (tag, cls, text) {
  const e = document.createElement(tag);
  if (cls) e.className = cls;
  if (text !== undefined && text !== null) e.textContent = String(text);
  return e;
};

R.clear = function (e) {
  while (e.firstChild) e.removeChild(e.firstChild);
  return e;
};

R.getJSON = async function (url) {
  const r = await fetch(url, { credentials: 'same-origin', cache: 'no-store' });
  if (!r.ok) {
    const err = new Error(url + ': HTTP ' + r.status + ': ' + (await r.text()).trim());
    err.status = r.status;
    throw err;
  }
  return r.json();
};

// thousands grouped by thin spaces: "1194930.5" -> "1 194 930.5"
R.group = function (s) {
  const m = /^(-?)(\d+)(\.\d+)?$/.exec(s);
  if (!m) return s;
  return m[1] + m[2].replace(/\B(?=(\d{3})+(?!\d))/g, '\u2009') + (m[3] || '');
};

const SUP = { '-': '\u207b', 0: '\u2070', 1: '\u00b9', 2: '\u00b2', 3: '\u00b3', 4: '\u2074', 5: '\u2075', 6: '\u2076', 7: '\u2077', 8: '\u2078', 9: '\u2079' };
R.sup = (n) => String(n).split('').map((c) => SUP[c] || c).join('');

// a number without uncertainty: 6 significant digits
R.plain = function (v, digits) {
  if (v === null || v === undefined || !isFinite(v)) return '\u2013';
  digits = digits || 6;
  const a = Math.abs(v);
  if (a !== 0 && (a >= 1e9 || a < 1e-3)) {
    const x = Math.floor(Math.log10(a));
    return Number((v / Math.pow(10, x)).toPrecision(digits)).toString() + '\u00d710' + R.sup(x);
  }
  return R.group(Number(v.toPrecision(digits)).toString());
};

// value +- standard error, rounded to the error's second significant digit:
// "1 194 930 ± 140", "14.2891 ± 0.0017", "(3.21 ± 0.11)×10⁻⁵"
R.fmt = function (v, se) {
  if (v === null || v === undefined || !isFinite(v)) return null;
  if (se === null || se === undefined || !isFinite(se) || se <= 0) return R.plain(v);
  const e = Math.floor(Math.log10(se)) - 1; // decimal position of the error's second digit
  const big = Math.max(Math.abs(v), se);
  if (e >= -6 && big < 1e9 && big >= 1e-3) {
    if (e >= 0) {
      const q = Math.pow(10, e);
      return R.group((Math.round(v / q) * q).toFixed(0)) + ' \u00b1 ' + R.group((Math.round(se / q) * q).toFixed(0));
    }
    return R.group(v.toFixed(-e)) + ' \u00b1 ' + R.group(se.toFixed(-e));
  }
  const x = Math.floor(Math.log10(big));
  const s = Math.pow(10, x);
  const dec = Math.max(0, x - e);
  return '(' + (v / s).toFixed(dec) + ' \u00b1 ' + (se / s).toFixed(dec) + ')\u00d710' + R.sup(x);
};

R.ago = function (ms) {
  if (ms === null || ms === undefined) return 'never';
  const s = Math.max(0, (R.now() - ms) / 1000);
  if (s < 90) return s.toFixed(s < 10 ? 1 : 0) + ' s ago';
  if (s < 5400) return (s / 60).toFixed(0) + ' min ago';
  if (s < 172800) return (s / 3600).toFixed(1) + ' h ago';
  return (s / 86400).toFixed(1) + ' d ago';
};

R.clock = function () {
  const c = document.getElementById('clock');
  const tick = () => { c.textContent = new Date(R.now()).toLocaleTimeString(); };
  tick();
  setInterval(tick, 1000);
};

// the banner: what is wrong with NATS or with the connection to the dashboard
R.nats = null;
R.serverLost = false;
R.showBanner = function () {
  const b = document.getElementById('banner');
  R.clear(b);
  const lines = [];
  if (R.serverLost) lines.push(['dashboard server unreachable', 'retrying; what you see may be old']);
  const n = R.nats;
  if (n && !R.serverLost) {
    if (!n.connected) lines.push(['NATS ' + n.url + ' unreachable', 'since ' + new Date(n.since_ms).toLocaleTimeString() + ' (' + R.ago(n.since_ms) + '); reconnecting, values may be old']);
    for (const k of Object.keys(n.problems || {})) {
      if (k === 'connection' && !n.connected) continue;
      lines.push([k, n.problems[k]]);
    }
  }
  b.hidden = lines.length === 0;
  for (const [head, text] of lines) {
    const d = R.el('div');
    d.appendChild(R.el('b', null, head + ': '));
    d.appendChild(document.createTextNode(text));
    b.appendChild(d);
  }
};

// the event stream: onMachine(tile), onResync(), onOpen()
R.events = function (h) {
  const es = new EventSource('/api/events');
  es.addEventListener('open', () => {
    const was = R.serverLost;
    R.serverLost = false;
    R.showBanner();
    if (h.onOpen) h.onOpen(was);
  });
  es.addEventListener('error', () => {
    R.serverLost = es.readyState !== EventSource.OPEN;
    R.showBanner();
  });
  es.addEventListener('nats', (e) => { R.nats = JSON.parse(e.data); R.showBanner(); });
  es.addEventListener('machine', (e) => h.onMachine(JSON.parse(e.data)));
  es.addEventListener('resync', () => h.onResync());
  return es;
};

// how late the pages show results: the time from a result's storing to its arrival here
window.rotoridLag = { count: 0, max_ms: 0, sum_ms: 0, last_ms: null };
R.lag = function (tile) {
  if (tile.arrived_ms === null || tile.arrived_ms === undefined) return;
  const l = Math.max(0, R.now() - tile.arrived_ms);
  const s = window.rotoridLag;
  s.count += 1; s.sum_ms += l; s.last_ms = l; s.max_ms = Math.max(s.max_ms, l);
};

R.stateLabel = { alert: 'alert', errors: 'errors', stale: 'stale', ok: 'ok' };
