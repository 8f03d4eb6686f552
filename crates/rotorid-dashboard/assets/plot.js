// rotorid dashboard: SVG charts drawn by hand (no library): trends with bands, the orbit
// with equal axes, the polar plot. Sizes are in SVG units; the SVG scales to its box.
'use strict';

const P = {};
const NS = 'http://www.w3.org/2000/svg';

P.svg = function (tag, attrs, text) {
  const e = document.createElementNS(NS, tag);
  for (const k in attrs) e.setAttribute(k, attrs[k]);
  if (text !== undefined) e.textContent = String(text);
  return e;
};

// about n "nice" ticks (1, 2, 5 x 10^k) over [lo, hi]
P.ticks = function (lo, hi, n) {
  const raw = (hi - lo) / Math.max(1, n);
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const f = raw / mag;
  const step = (f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10) * mag;
  const out = [];
  for (let k = Math.ceil(lo / step - 1e-9); k * step <= hi + step * 1e-9; k++) out.push(k * step);
  return { ticks: out, step };
};

P.tickLabel = function (v, step) {
  if (Math.abs(v) < step * 1e-6) return '0';
  const a = Math.max(Math.abs(v), step);
  if (a >= 1e7 || step < 1e-4) {
    const x = Math.floor(Math.log10(a));
    const dec = Math.max(0, x - Math.floor(Math.log10(step)));
    return (v / Math.pow(10, x)).toFixed(Math.min(dec, 8)) + 'e' + x;
  }
  const dec = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  return R.group(v.toFixed(dec));
};

// a domain [lo, hi] of the finite numbers given, padded by 5 %; [v - 1, v + 1] for one value
P.extent = function (values, pad) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const v of values) if (v !== null && isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
  if (lo === Infinity) return null;
  if (hi === lo) { const d = Math.abs(lo) * 1e-3 || 1; return [lo - d, hi + d]; }
  const p = (hi - lo) * (pad === undefined ? 0.05 : pad);
  return [lo - p, hi + p];
};

// the "M x y L x y ..." path of the finite points, broken at gaps
function linePath(xs, ys, sx, sy, yd) {
  let d = '';
  let pen = false;
  for (let i = 0; i < xs.length; i++) {
    let y = ys[i];
    if (yd && y !== null && isFinite(y)) y = Math.min(yd[1], Math.max(yd[0], y));
    if (y === null || !isFinite(y)) { pen = false; continue; }
    d += (pen ? 'L' : 'M') + sx(xs[i]).toFixed(1) + ' ' + sy(y).toFixed(1);
    pen = true;
  }
  return d;
}

// one dot per finite point: "M x y h0" with a round line cap; values outside the y domain
// are drawn on its edge (and listed, to be marked as off scale)
function dotPath(xs, ys, sx, sy, yd) {
  let d = '';
  let n = 0;
  let off = '';
  for (let i = 0; i < xs.length; i++) {
    let y = ys[i];
    if (y === null || !isFinite(y)) continue;
    const out = yd && (y < yd[0] || y > yd[1]);
    if (out) {
      const top = y > yd[1];
      y = top ? yd[1] : yd[0];
      const px = sx(xs[i]);
      const py = sy(y);
      // a chevron pointing off the scale
      off += 'M' + (px - 4).toFixed(1) + ' ' + (py + (top ? 7 : -7)).toFixed(1) + 'L' + px.toFixed(1) + ' ' + (py + (top ? 2 : -2)).toFixed(1) +
        'L' + (px + 4).toFixed(1) + ' ' + (py + (top ? 7 : -7)).toFixed(1);
    }
    d += 'M' + sx(xs[i]).toFixed(1) + ' ' + sy(y).toFixed(1) + 'h0';
    n++;
  }
  return { d, n, off };
}

// a y domain that the typical values fill: from the 5th to the 95th percentile of the
// values, with the bands of `keep` (the baseline, the newest value), unless every value is
// within twice that span anyway (then all of them)
P.robust = function (values, keep) {
  const v = values.filter((x) => x !== null && isFinite(x)).sort((a, b) => a - b);
  if (v.length === 0) return P.extent(keep, 0.1);
  const q = (p) => v[Math.min(v.length - 1, Math.max(0, Math.round(p * (v.length - 1))))];
  let lo = q(0.05);
  let hi = q(0.95);
  for (const k of keep) if (k !== null && isFinite(k)) { lo = Math.min(lo, k); hi = Math.max(hi, k); }
  const span = hi - lo || Math.abs(hi) * 1e-3 || 1;
  if (v[0] >= lo - 2 * span && v[v.length - 1] <= hi + 2 * span) {
    return P.extent(v.concat(keep), 0.08);
  }
  return [lo - 0.25 * span, hi + 0.25 * span];
};

// the band between lo[i] and hi[i], one closed polygon per run of finite points
function bandPath(xs, lo, hi, sx, sy) {
  let d = '';
  let run = [];
  const flush = () => {
    if (run.length > 0) {
      const up = run.map((i) => sx(xs[i]).toFixed(1) + ' ' + sy(hi[i]).toFixed(1));
      const down = run.slice().reverse().map((i) => sx(xs[i]).toFixed(1) + ' ' + sy(lo[i]).toFixed(1));
      if (run.length === 1) {
        const x = sx(xs[run[0]]);
        d += 'M' + (x - 2).toFixed(1) + ' ' + sy(hi[run[0]]).toFixed(1) + 'H' + (x + 2).toFixed(1) + 'V' + sy(lo[run[0]]).toFixed(1) + 'H' + (x - 2).toFixed(1) + 'Z';
      } else {
        d += 'M' + up.join('L') + 'L' + down.join('L') + 'Z';
      }
    }
    run = [];
  };
  for (let i = 0; i < xs.length; i++) {
    if (lo[i] !== null && hi[i] !== null && isFinite(lo[i]) && isFinite(hi[i])) run.push(i);
    else flush();
  }
  flush();
  return d;
}

// A chart: opts = { w, h, xlabel, ylabel, title, series: [{ x, y, lo, hi, cls, dots }],
// hband: { lo, hi } | null, vmarks: [{ x, cls, title }], xdomain, ydomain, empty }
P.chart = function (opts) {
  const w = opts.w || 800;
  const h = opts.h || 180;
  const m = { l: 84, r: 12, t: opts.title ? 22 : 8, b: 36 };
  const svg = P.svg('svg', { viewBox: '0 0 ' + w + ' ' + h, role: 'img' });
  if (opts.title) svg.appendChild(P.svg('text', { x: m.l, y: 15, class: 'title' }, opts.title));
  let xs = [];
  let ys = [];
  for (const s of opts.series) {
    xs = xs.concat(s.x);
    ys = ys.concat(s.y, s.lo || [], s.hi || []);
  }
  if (opts.hband) ys.push(opts.hband.lo, opts.hband.hi);
  const xd = opts.xdomain || P.extent(xs, 0.02);
  let yd = opts.ydomain || P.extent(ys, 0.08);
  if (opts.robust && !opts.ydomain) {
    let values = [];
    for (const s of opts.series) values = values.concat(s.y);
    yd = P.robust(values, (opts.keep || []).concat(opts.hband ? [opts.hband.lo, opts.hband.hi] : []));
  }
  if (!xd || !yd) {
    svg.appendChild(P.svg('text', { x: w / 2, y: h / 2, 'text-anchor': 'middle', class: 'empty-msg' }, opts.empty || 'no data yet'));
    return svg;
  }
  const sx = (v) => m.l + ((v - xd[0]) / (xd[1] - xd[0])) * (w - m.l - m.r);
  const sy = (v) => h - m.b - ((v - yd[0]) / (yd[1] - yd[0])) * (h - m.t - m.b);
  const gx = P.ticks(xd[0], xd[1], Math.max(2, Math.floor((w - m.l) / 110)));
  const gy = P.ticks(yd[0], yd[1], Math.max(3, Math.floor((h - m.t - m.b) / 30)));
  for (const v of gy.ticks) {
    if (v < yd[0] || v > yd[1]) continue;
    svg.appendChild(P.svg('line', { x1: m.l, x2: w - m.r, y1: sy(v), y2: sy(v), class: 'grid' }));
    svg.appendChild(P.svg('text', { x: m.l - 6, y: sy(v) + 4, 'text-anchor': 'end' }, P.tickLabel(v, gy.step)));
  }
  for (const v of gx.ticks) {
    if (v < xd[0] || v > xd[1]) continue;
    svg.appendChild(P.svg('line', { x1: sx(v), x2: sx(v), y1: m.t, y2: h - m.b, class: 'grid' }));
    svg.appendChild(P.svg('text', { x: sx(v), y: h - m.b + 15, 'text-anchor': 'middle' }, P.tickLabel(v, gx.step)));
  }
  svg.appendChild(P.svg('rect', { x: m.l, y: m.t, width: w - m.l - m.r, height: h - m.t - m.b, fill: 'none', class: 'axis' }));
  if (opts.xlabel) svg.appendChild(P.svg('text', { x: w - m.r, y: h - 4, 'text-anchor': 'end' }, opts.xlabel));
  if (opts.ylabel) {
    svg.appendChild(P.svg('text', { x: 12, y: (m.t + h - m.b) / 2, 'text-anchor': 'middle', transform: 'rotate(-90 12 ' + (m.t + h - m.b) / 2 + ')' }, opts.ylabel));
  }
  const clipId = 'c' + Math.random().toString(36).slice(2);
  const clip = P.svg('clipPath', { id: clipId });
  clip.appendChild(P.svg('rect', { x: m.l, y: m.t, width: w - m.l - m.r, height: h - m.t - m.b }));
  svg.appendChild(clip);
  const g = P.svg('g', { 'clip-path': 'url(#' + clipId + ')' });
  svg.appendChild(g);
  if (opts.hband && isFinite(opts.hband.lo) && isFinite(opts.hband.hi)) {
    const y1 = sy(opts.hband.hi);
    g.appendChild(P.svg('rect', { x: m.l, y: y1, width: w - m.l - m.r, height: Math.max(1, sy(opts.hband.lo) - y1), class: 'baseline' }));
  }
  for (const s of opts.series) {
    if (s.lo && s.hi) g.appendChild(P.svg('path', { d: bandPath(s.x, s.lo, s.hi, sx, sy), class: 'band ' + (s.cls || '') }));
  }
  for (const vm of opts.vmarks || []) {
    if (vm.x < xd[0] || vm.x > xd[1]) continue;
    const l = P.svg('line', { x1: sx(vm.x), x2: sx(vm.x), y1: m.t, y2: h - m.b, class: 'alertmark ' + (vm.cls || '') });
    if (vm.title) l.appendChild(P.svg('title', {}, vm.title));
    g.appendChild(l);
  }
  for (const s of opts.series) {
    g.appendChild(P.svg('path', { d: linePath(s.x, s.y, sx, sy, yd), class: 'series ' + (s.cls || '') }));
    if (s.dots !== false) {
      const dp = dotPath(s.x, s.y, sx, sy, yd);
      g.appendChild(P.svg('path', { d: dp.d, class: 'dots ' + (s.cls || ''), 'data-points': dp.n }));
      if (dp.off) {
        const o = P.svg('path', { d: dp.off, class: 'offscale' });
        o.appendChild(P.svg('title', {}, 'off the scale'));
        g.appendChild(o);
      }
    }
  }
  return svg;
};

// The orbit: z against x with equal axes [um], keyphasor dots.
P.orbit = function (x, z, kp, size) {
  const s = size || 420;
  const m = { l: 56, r: 12, t: 10, b: 40 };
  const svg = P.svg('svg', { viewBox: '0 0 ' + s + ' ' + s, role: 'img', class: 'orbit-svg' });
  const ex = P.extent(x, 0);
  const ez = P.extent(z, 0);
  if (!ex || !ez) {
    svg.appendChild(P.svg('text', { x: s / 2, y: s / 2, 'text-anchor': 'middle', class: 'empty-msg' }, 'no samples yet'));
    return svg;
  }
  const cx = (ex[0] + ex[1]) / 2;
  const cz = (ez[0] + ez[1]) / 2;
  const half = Math.max(ex[1] - ex[0], ez[1] - ez[0]) * 0.55 || 1;
  const side = s - Math.max(m.l + m.r, m.t + m.b);
  const k = side / (2 * half); // px per um, the same on both axes
  const ox = m.l + side / 2;
  const oz = m.t + side / 2;
  const sx = (v) => ox + (v - cx) * k;
  const sy = (v) => oz - (v - cz) * k;
  const tx = P.ticks(cx - half, cx + half, 5);
  const tz = P.ticks(cz - half, cz + half, 5);
  for (const v of tx.ticks) {
    svg.appendChild(P.svg('line', { x1: sx(v), x2: sx(v), y1: sy(cz + half), y2: sy(cz - half), class: 'grid' }));
    svg.appendChild(P.svg('text', { x: sx(v), y: sy(cz - half) + 15, 'text-anchor': 'middle' }, P.tickLabel(v, tx.step)));
  }
  for (const v of tz.ticks) {
    svg.appendChild(P.svg('line', { x1: sx(cx - half), x2: sx(cx + half), y1: sy(v), y2: sy(v), class: 'grid' }));
    svg.appendChild(P.svg('text', { x: sx(cx - half) - 5, y: sy(v) + 4, 'text-anchor': 'end' }, P.tickLabel(v, tz.step)));
  }
  svg.appendChild(P.svg('rect', { x: sx(cx - half), y: sy(cz + half), width: 2 * half * k, height: 2 * half * k, fill: 'none', class: 'axis' }));
  svg.appendChild(P.svg('text', { x: sx(cx + half), y: sy(cz - half) + 30, 'text-anchor': 'end' }, 'x [\u00b5m]'));
  svg.appendChild(P.svg('text', { x: 12, y: oz, 'text-anchor': 'middle', transform: 'rotate(-90 12 ' + oz + ')' }, 'z [\u00b5m]'));
  svg.appendChild(P.svg('path', { d: linePath(x, z, sx, sy), class: 'orbitpath' }));
  const g = P.svg('g', { class: 'keyphasors', 'data-points': kp.length });
  for (const p of kp) g.appendChild(P.svg('circle', { cx: sx(p.x_um).toFixed(1), cy: sy(p.z_um).toFixed(1), r: 4, class: 'kp' }));
  svg.appendChild(g);
  return svg;
};

// The polar plot of 1X vectors: radius = amplitude [um], angle = phase lag [deg], 0 deg at
// the top, lag increasing clockwise; the newest point ringed.
P.polar = function (pts, size) {
  const s = size || 360;
  const svg = P.svg('svg', { viewBox: '0 0 ' + s + ' ' + (s + 20), role: 'img' });
  const c = s / 2;
  const rmax = c - 30;
  let amax = 0;
  for (const p of pts) if (p.v) amax = Math.max(amax, p.v.amplitude_um);
  if (!(amax > 0)) {
    svg.appendChild(P.svg('text', { x: c, y: c, 'text-anchor': 'middle', class: 'empty-msg' }, 'no 1X vector yet'));
    return svg;
  }
  const t = P.ticks(0, amax * 1.05, 3);
  const top = t.ticks[t.ticks.length - 1] >= amax ? t.ticks[t.ticks.length - 1] : amax * 1.05;
  const r = (a) => (a / top) * rmax;
  for (const a of t.ticks) {
    if (a <= 0 || a > top) continue;
    svg.appendChild(P.svg('circle', { cx: c, cy: c, r: r(a), class: 'polar-ring' }));
    svg.appendChild(P.svg('text', { x: c + 3, y: c - r(a) - 3 }, P.tickLabel(a, t.step)));
  }
  for (let d = 0; d < 360; d += 30) {
    const a = (d * Math.PI) / 180;
    svg.appendChild(P.svg('line', { x1: c, y1: c, x2: c + rmax * Math.sin(a), y2: c - rmax * Math.cos(a), class: 'grid' }));
    svg.appendChild(P.svg('text', { x: c + (rmax + 14) * Math.sin(a), y: c - (rmax + 14) * Math.cos(a) + 4, 'text-anchor': 'middle' }, d + '\u00b0'));
  }
  const n = pts.length;
  pts.forEach((p, i) => {
    if (!p.v) return;
    const a = (p.v.phase_deg * Math.PI) / 180;
    const op = n > 1 ? 0.25 + 0.75 * (i / (n - 1)) : 1;
    svg.appendChild(P.svg('circle', { cx: c + r(p.v.amplitude_um) * Math.sin(a), cy: c - r(p.v.amplitude_um) * Math.cos(a), r: p.latest ? 6 : 3, class: 'polar-pt ' + p.cls + (p.latest ? ' latest' : ''), 'fill-opacity': op.toFixed(2) }));
  });
  svg.appendChild(P.svg('text', { x: c, y: s + 14, 'text-anchor': 'middle' }, 'r: amplitude [\u00b5m pk], angle: phase lag [deg]'));
  return svg;
};
