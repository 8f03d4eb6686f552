// rotorid dashboard, fleet page: one tile per machine, updated in place by the event stream.
'use strict';

const RANK = { alert: 0, errors: 1, stale: 2, ok: 3 };
const tiles = new Map(); // id -> { t: tile JSON, el: element }
const grid = document.getElementById('tiles');
const filterBox = document.getElementById('filter');
const sortBox = document.getElementById('sort');
let orderDirty = true;

function line(cls) {
  return R.el('div', 'line ' + cls);
}

function build(id) {
  const a = R.el('a', 'tile');
  a.setAttribute('href', '/machine/' + encodeURIComponent(id));
  a.dataset.id = id;
  const head = R.el('div', 'tile-head');
  head.appendChild(R.el('span', 'id', id));
  head.appendChild(R.el('span', 'badge'));
  a.appendChild(head);
  a.appendChild(R.el('div', 'meta'));
  a.appendChild(R.el('table', 'params'));
  a.appendChild(line('alert'));
  a.appendChild(line('errors'));
  return a;
}

function alertText(al) {
  if (al.kind === 'model_inadequate') {
    return 'MODEL ALERT windows ' + al.previous_window + ' and ' + al.window +
      ': the model does not explain them, ' + R.ago(al.arrived_ms);
  }
  const pct = (100 * al.relative_change).toFixed(2);
  return 'ALERT ' + al.parameter + ' ' + (al.relative_change >= 0 ? '+' : '') + pct + ' % (z = ' + al.z.toFixed(1) +
    ') at window ' + al.window + ', ' + R.ago(al.arrived_ms);
}

function renderMeta(entry) {
  const t = entry.t;
  const meta = entry.el.querySelector('.meta');
  if (t.window === null) {
    meta.textContent = 'no result yet' + (t.raw_window !== null ? ' (raw window ' + t.raw_window + ' published)' : '');
  } else {
    const parts = ['window ' + t.window, 't0 ' + R.plain(t.t0_s) + ' s', R.ago(t.arrived_ms)];
    if (t.raw_window !== null && t.raw_window > t.window + 1) parts.push((t.raw_window - t.window) + ' windows behind');
    meta.textContent = parts.join(' \u00b7 ');
  }
}

function render(entry) {
  const t = entry.t;
  const a = entry.el;
  a.className = 'tile state-' + t.state + (t.stale ? ' is-stale' : '');
  a.dataset.state = t.state;
  a.dataset.window = t.window === null ? '' : String(t.window);
  const badge = a.querySelector('.badge');
  badge.className = 'badge ' + t.state;
  badge.textContent = R.stateLabel[t.state] + (t.stale && t.state !== 'stale' ? ' \u00b7 stale' : '');
  renderMeta(entry);
  const table = R.clear(a.querySelector('table.params'));
  for (const p of t.parameters) {
    const tr = R.el('tr');
    tr.dataset.param = p.name;
    tr.appendChild(R.el('th', null, p.name));
    const s = R.fmt(p.value, p.std_error);
    const td = R.el('td', s === null ? 'v withheld' : 'v', s === null ? 'withheld' : s);
    if (p.value !== null) td.dataset.value = String(p.value);
    tr.appendChild(td);
    tr.appendChild(R.el('td', 'u', p.unit));
    table.appendChild(tr);
  }
  const al = a.querySelector('.line.alert');
  al.textContent = t.last_alert ? alertText(t.last_alert) : '';
  al.hidden = !t.last_alert;
  const er = a.querySelector('.line.errors');
  er.textContent = t.last_error ? 'window ' + (t.last_error.window === null ? '?' : t.last_error.window) + ' gave no result: ' + t.last_error.error : '';
  er.hidden = !t.last_error || t.state === 'ok';
  if (t.last_error) er.setAttribute('title', t.last_error.error);
  applyFilter(entry);
}

function update(t) {
  let e = tiles.get(t.id);
  if (!e) {
    e = { t, el: build(t.id) };
    tiles.set(t.id, e);
    grid.appendChild(e.el);
    orderDirty = true;
  } else if (e.t.state !== t.state || e.t.window !== t.window) {
    orderDirty = true;
  }
  e.t = t;
  render(e);
}

function matches(t, q) {
  if (!q) return true;
  const hay = [t.id, t.state, t.method || ''].concat(t.parameters.map((p) => p.name)).join(' ').toLowerCase();
  return q.split(/\s+/).every((w) => hay.includes(w));
}

function applyFilter(e) {
  e.el.hidden = !matches(e.t, filterBox.value.trim().toLowerCase());
}

function reorder() {
  const mode = sortBox.value;
  const all = Array.from(tiles.values());
  all.sort((a, b) => {
    if (mode === 'recent') return (b.t.arrived_ms || 0) - (a.t.arrived_ms || 0) || a.t.id.localeCompare(b.t.id);
    if (mode === 'worst') {
      const r = RANK[a.t.state] - RANK[b.t.state];
      if (r) return r;
    }
    return a.t.id < b.t.id ? -1 : a.t.id > b.t.id ? 1 : 0;
  });
  all.forEach((e, i) => {
    if (grid.children[i] !== e.el) grid.insertBefore(e.el, grid.children[i] || null);
  });
  orderDirty = false;
}

function counts() {
  const c = { alert: 0, errors: 0, stale: 0, ok: 0 };
  for (const e of tiles.values()) c[e.t.state] += 1;
  const box = R.clear(document.getElementById('counts'));
  for (const k of ['alert', 'errors', 'stale', 'ok']) {
    const s = R.el('span', 'count ' + k);
    s.appendChild(R.el('b', null, c[k]));
    s.appendChild(document.createTextNode(' ' + k));
    box.appendChild(s);
  }
  document.getElementById('empty').hidden = tiles.size > 0;
  document.title = (c.alert ? c.alert + ' alert \u00b7 ' : '') + 'rotorid fleet';
}

let loading = null;
async function load() {
  if (loading) return loading;
  loading = (async () => {
    try {
      const r = await R.getJSON('/api/machines');
      R.offset = r.server_ms - Date.now();
      R.nats = r.nats;
      R.showBanner();
      const seen = new Set();
      for (const t of r.machines) { update(t); seen.add(t.id); }
      for (const [id, e] of tiles) if (!seen.has(id)) { e.el.remove(); tiles.delete(id); }
      orderDirty = true;
      footer(r);
    } catch (err) {
      R.serverLost = true;
      R.showBanner();
    } finally {
      loading = null;
    }
  })();
  return loading;
}

function footer(r) {
  const f = document.getElementById('footer');
  const s = window.rotoridLag;
  const lag = s.count ? 'results shown ' + (s.last_ms / 1000).toFixed(2) + ' s after they were stored (max ' + (s.max_ms / 1000).toFixed(2) + ' s over ' + s.count + ')' : 'waiting for results';
  const parts = [lag];
  if (r) parts.push('stale after ' + r.stale_windows + ' window lengths without a result', 'the last ' + r.history + ' windows per machine kept');
  f.dataset.base = parts.slice(1).join(' \u00b7 ');
  f.textContent = [lag].concat(f.dataset.base ? [f.dataset.base] : []).join(' \u00b7 ');
}

filterBox.addEventListener('input', () => { for (const e of tiles.values()) applyFilter(e); });
sortBox.addEventListener('change', () => { orderDirty = true; reorder(); });

R.clock();
R.events({
  onMachine: (t) => {
    const before = tiles.get(t.id);
    if (!before || before.t.window !== t.window) R.lag(t);
    update(t);
  },
  onResync: load,
  onOpen: () => load(),
});
load();
// once a second: the order (worst first) and the counts, the "ago" texts
setInterval(() => {
  if (orderDirty) reorder();
  counts();
  for (const e of tiles.values()) renderMeta(e);
  footer(null);
}, 1000);
