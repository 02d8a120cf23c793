// The results page: every motion of a scene in 3-D on the shared orbit camera (`OrbitView`),
// one timeline for all, the scene's plots with a cursor on that timeline, the song in sync.
// The data is the JSON in #page-data (written by marionette's render::page): positions are
// int16 millimetres from each motion's origin, base64.

'use strict';

const DATA = JSON.parse(document.getElementById('page-data').textContent);
const SIDE_RGB = { l: [70, 150, 230], r: [230, 110, 40], c: [175, 178, 184] };
const PALETTE = [[70, 150, 230], [230, 110, 40], [60, 170, 100], [190, 80, 170], [200, 170, 40], [120, 120, 220]];
const CONTACT_RGB = [220, 30, 30];
const CONTACT_M = 0.005; // a box whose lowest corner is this close to the floor, or below, touches it
// An end segment (foot, hand) touches the floor while its capsule is within END_CONTACT_M of
// its own lowest height over the motion, when that comes within END_NEAR_M of the floor (joint
// centres of a capture stand above the floor by the foot's thickness; a hand that never comes
// near the floor never touches it).
const END_CONTACT_M = 0.03;
const END_NEAR_M = 0.15;
const $ = (id) => document.getElementById(id);
const el = (tag, attrs = {}, text) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
};
const rgb = (c, k = 1, a = 1) => `rgba(${Math.round(c[0] * k)},${Math.round(c[1] * k)},${Math.round(c[2] * k)},${a})`;
const mix = (a, b, s) => a.map((v, i) => v + (b[i] - v) * s);

// Base64 int16 little-endian → Float32Array of metres.
function decode(b64) {
  const bin = atob(b64);
  const out = new Float32Array(bin.length / 2);
  for (let i = 0; i < out.length; i++) {
    let v = bin.charCodeAt(2 * i) | (bin.charCodeAt(2 * i + 1) << 8);
    if (v >= 32768) v -= 65536;
    out[i] = v / 1000;
  }
  return out;
}

// Radius of a bone's capsule from its length (m); the head's (the bone out of a joint named
// head, or into a head with nothing beyond it) is wider.
function radius(len, head) {
  if (head) return Math.min(0.11, Math.max(0.07, 0.5 * len));
  return Math.min(0.065, Math.max(0.025, 0.16 * len));
}

const motions = DATA.motions.map((m, idx) => {
  // Each frame's points are millimetres from its origin (whole metres, in metres).
  const origins = decode(m.origins).map((v) => v * 1000);
  const n = m.names.length, nb = m.box_names.length;
  const pts = decode(m.points);
  for (let i = 0; i < pts.length; i++) pts[i] += origins[3 * Math.floor(i / (3 * n)) + (i % 3)];
  let boxes = null;
  if (m.boxes) {
    boxes = decode(m.boxes);
    // Each box is [centre, three half-axes]: only the centre is a position.
    for (let i = 0; i < boxes.length; i += 12) {
      const k = Math.floor(i / (12 * nb));
      for (let c = 0; c < 3; c++) boxes[i + c] += origins[3 * k + c];
    }
  }
  const bones = [];
  m.parents.forEach((p, i) => {
    if (p === null) return;
    const dx = pts[3 * i] - pts[3 * p], dy = pts[3 * i + 1] - pts[3 * p + 1], dz = pts[3 * i + 2] - pts[3 * p + 2];
    const leaf = !m.parents.includes(i);
    const head = /head/i.test(m.names[p]) || (leaf && /head/i.test(m.names[i]));
    bones.push({ a: p, b: i, r: radius(Math.hypot(dx, dy, dz), head), side: m.sides[i], end: leaf && !head });
  });
  for (const bone of bones.filter((x) => x.end)) {
    let rest = Infinity;
    for (let k = 0; k < m.frames; k++) {
      rest = Math.min(rest, pts[3 * (k * n + bone.a) + 1], pts[3 * (k * n + bone.b) + 1]);
    }
    bone.rest = rest - bone.r;
  }
  return { ...m, idx, pts, boxes, n, nb, bones, colour: PALETTE[idx % PALETTE.length],
    end: m.start_s + (m.frames - 1) * m.frame_time, shown: true };
});
const song = DATA.song;
const END = Math.max(...motions.map((m) => m.end), 0);
const STEP = Math.min(...motions.map((m) => m.frame_time));

const state = { t: 0, playing: false, loop: true, speed: 1, layout: motions.length > 1 ? 'side' : 'overlay', follow: true, last: null };
const cam = { yaw: 0.6, pitch: 0.25, dist: 4.2 };

function frameOf(m, t) {
  return Math.max(0, Math.min(m.frames - 1, Math.round((t - m.start_s) / m.frame_time)));
}
function point(m, k, i) {
  const j = 3 * (k * m.n + i);
  return [m.pts[j], m.pts[j + 1], m.pts[j + 2]];
}

// ---------- page layout ----------
function build() {
  const head = el('header');
  head.append(el('h1', {}, DATA.title));
  if (DATA.headline.length) {
    const ul = el('ul', { id: 'headline' });
    DATA.headline.forEach((h) => ul.append(el('li', {}, h)));
    head.append(ul);
  }
  if (DATA.notes.length) {
    const ul = el('ul', { id: 'notes' });
    DATA.notes.forEach((h) => ul.append(el('li', {}, h)));
    head.append(ul);
  }
  document.body.append(head);

  const bar = el('section', { id: 'controls' });
  bar.innerHTML = `
    <button id="play" title="play / pause (space)">▶ Play</button>
    <button id="prev" title="one frame back (←)">◀︎ frame</button>
    <button id="next" title="one frame on (→)">frame ▶︎</button>
    <input id="scrub" type="range" min="0" step="any" aria-label="time">
    <span id="time"></span>
    <label><input id="loop" type="checkbox" checked> loop</label>
    <label>speed <select id="speed"><option>0.1</option><option>0.25</option><option>0.5</option><option selected>1</option><option>2</option></select></label>
    <label>layout <select id="layout"><option value="side">side by side</option><option value="overlay">overlaid</option></select></label>
    <span class="views">view <button data-view="front">front</button><button data-view="side">side</button><button data-view="top">top</button><button data-view="three">¾</button></span>
    <label><input id="follow" type="checkbox" checked> follow the root</label>
    ${song ? '<label><input id="song-on" type="checkbox" checked> song</label>' : ''}`;
  document.body.append(bar);
  const marks = el('div', { id: 'event-marks' });
  document.body.append(marks);

  const list = el('ul', { id: 'motion-list' });
  motions.forEach((m) => {
    const li = el('li', { class: 'motion' });
    const cb = el('input', { type: 'checkbox', checked: '' });
    cb.addEventListener('change', () => { m.shown = cb.checked; layout(); });
    const sw = el('span', { class: 'swatch' });
    sw.style.background = rgb(m.colour);
    const dur = (m.frames - 1) * m.frame_time;
    li.append(cb, sw, el('span', { class: 'label' }, m.label),
      el('span', { class: 'info' }, ` ${m.frames} frames, ${dur.toFixed(2)} s${m.boxes ? ', contact boxes' : ''}`));
    if (m.events.length) {
      const ev = el('ul', { class: 'events' });
      m.events.forEach((e) => {
        const b = el('li', {}, `${(m.start_s + e.t).toFixed(2)} s: ${e.label}`);
        b.addEventListener('click', () => seek(m.start_s + e.t));
        ev.append(b);
        const mk = el('span', { class: 'mark', title: `${m.label}: ${e.label}` });
        mk.style.left = `${100 * (m.start_s + e.t) / Math.max(END, 1e-9)}%`;
        mk.style.background = rgb(m.colour);
        marks.append(mk);
      });
      li.append(ev);
    }
    list.append(li);
  });
  document.body.append(list);
  document.body.append(el('section', { id: 'stage' }));
  document.body.append(el('p', { class: 'hint' },
    'drag: orbit · wheel: zoom · space: play/pause · ←/→: frame · ' +
    (motions.some((m) => m.boxes) ? 'links drawn as their contact boxes; red: touching the floor (a corner within 5 mm of it or below) · ' : 'bones drawn as capsules sized from their lengths; red: an end segment (foot, hand) on the floor, within 3 cm of its lowest height · ') +
    'blue: left, orange: right · rings: events of the list'));
  const plots = el('section', { id: 'plots' });
  DATA.plots.forEach((p, i) => {
    const c = el('canvas', { class: 'plot', id: `plot-${i}`, width: 560, height: 300, 'aria-label': p.title });
    plots.append(c);
  });
  document.body.append(plots);
  if (song) {
    const a = el('audio', { id: 'song', preload: 'auto' });
    a.src = `data:audio/wav;base64,${song.wav}`;
    document.body.append(a);
  }

  const scrub = $('scrub');
  scrub.max = END;
  scrub.addEventListener('input', () => seek(parseFloat(scrub.value)));
  $('play').addEventListener('click', () => (state.playing ? pause() : play()));
  $('prev').addEventListener('click', () => stepFrame(-1));
  $('next').addEventListener('click', () => stepFrame(1));
  $('loop').addEventListener('change', (e) => { state.loop = e.target.checked; });
  $('speed').addEventListener('change', (e) => {
    state.speed = parseFloat(e.target.value);
    if (song) $('song').playbackRate = state.speed;
  });
  $('layout').value = state.layout;
  $('layout').addEventListener('change', (e) => { state.layout = e.target.value; layout(); });
  $('follow').addEventListener('change', (e) => { state.follow = e.target.checked; draw(); });
  bar.querySelectorAll('[data-view]').forEach((b) => b.addEventListener('click', () => setView(b.dataset.view)));
  if (song) $('song-on').addEventListener('change', () => { if (state.playing) play(); });
  document.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' && e.target.type !== 'checkbox') return;
    if (e.key === ' ') { e.preventDefault(); state.playing ? pause() : play(); }
    if (e.key === 'ArrowLeft') stepFrame(-1);
    if (e.key === 'ArrowRight') stepFrame(1);
  });
  window.addEventListener('resize', draw);
}

// ---------- the 3-D views ----------
let views = [];
function layout() {
  const stage = $('stage');
  stage.innerHTML = '';
  const shown = motions.filter((m) => m.shown);
  const groups = state.layout === 'side' ? shown.map((m) => [m]) : [shown];
  views = groups.map((g) => {
    const box = el('figure', { class: 'view' });
    const c = el('canvas', { class: 'figure' });
    box.append(c, el('figcaption', {}, g.length === 1 ? g[0].label : 'overlaid'));
    stage.append(box);
    const v = new OrbitView(c, cam);
    v.onchange = draw;
    v.motions = g;
    return v;
  });
  stage.dataset.views = views.length;
  draw();
}

function setView(name) {
  const v = { front: [0, 0.05], side: [Math.PI / 2, 0.05], top: [0, 1.55], three: [0.6, 0.25] }[name];
  [cam.yaw, cam.pitch] = v;
  draw();
}

// The volumes of motion m at frame k as drawable pieces: capsules or box faces.
function pieces(m, k, tint) {
  const out = [], touching = [];
  let lowest = Infinity, highest = -Infinity;
  if (m.boxes) {
    for (let b = 0; b < m.nb; b++) {
      const j = 12 * (k * m.nb + b);
      const c = [m.boxes[j], m.boxes[j + 1], m.boxes[j + 2]];
      const ax = [0, 1, 2].map((a) => [m.boxes[j + 3 + 3 * a], m.boxes[j + 4 + 3 * a], m.boxes[j + 5 + 3 * a]]);
      const corner = (s) => [0, 1, 2].map((d) => c[d] + s[0] * ax[0][d] + s[1] * ax[1][d] + s[2] * ax[2][d]);
      let low = Infinity;
      for (let s = 0; s < 8; s++) low = Math.min(low, corner([s & 1 ? 1 : -1, s & 2 ? 1 : -1, s & 4 ? 1 : -1])[1]);
      lowest = Math.min(lowest, low);
      highest = Math.max(highest, c[1] + Math.abs(ax[0][1]) + Math.abs(ax[1][1]) + Math.abs(ax[2][1]));
      const side = sideOf(m.box_names[b]);
      let col = tint ? tint : SIDE_RGB[side];
      if (low <= CONTACT_M) {
        col = mix(col, CONTACT_RGB, Math.min(1, 0.55 + (CONTACT_M - low) / 0.03));
        touching.push(m.box_names[b]);
      }
      for (let a = 0; a < 3; a++) {
        for (const sg of [-1, 1]) {
          const [u, w] = [0, 1, 2].filter((x) => x !== a);
          const quad = [[-1, -1], [1, -1], [1, 1], [-1, 1]].map(([p, q]) => {
            const s = [0, 0, 0];
            s[a] = sg; s[u] = p; s[w] = q;
            return corner(s);
          });
          const len = Math.hypot(...ax[a]) || 1;
          const normal = ax[a].map((x) => sg * x / len);
          out.push({ kind: 'face', quad, normal, col, name: m.box_names[b] });
        }
      }
    }
  } else {
    for (const bone of m.bones) {
      const a = point(m, k, bone.a), b = point(m, k, bone.b);
      const low = Math.min(a[1], b[1]) - bone.r;
      lowest = Math.min(lowest, low);
      highest = Math.max(highest, a[1] + bone.r, b[1] + bone.r);
      let col = tint ? mix(tint, SIDE_RGB[bone.side], 0.25) : SIDE_RGB[bone.side];
      if (bone.end && bone.rest <= END_NEAR_M && low <= Math.max(bone.rest, 0) + END_CONTACT_M) {
        col = mix(col, CONTACT_RGB, 0.75);
        touching.push(m.names[bone.b]);
      }
      out.push({ kind: 'capsule', a, b, r: bone.r, col });
    }
  }
  return { out, lowest, highest, touching };
}

function sideOf(name) {
  const n = name.toLowerCase();
  if (/^(left|l_|l[A-Z]|l\.)/.test(name) || n.startsWith('left')) return 'l';
  if (/^(right|r_|r[A-Z]|r\.)/.test(name) || n.startsWith('right')) return 'r';
  return 'c';
}

const LIGHT = (() => { const l = [0.4, 0.8, 0.45]; const n = Math.hypot(...l); return l.map((x) => x / n); })();

function drawView(v, t) {
  const [w, h] = v.fit();
  const g = v.ctx;
  g.fillStyle = '#f4f3ef';
  g.fillRect(0, 0, w, h);
  const frames = v.motions.map((m) => frameOf(m, t));
  if (state.follow && v.motions.length) {
    let x = 0, z = 0;
    v.motions.forEach((m, i) => { const p = point(m, frames[i], 0); x += p[0]; z += p[2]; });
    v.target = [x / v.motions.length, 0.8, z / v.motions.length];
  }
  v.grid(w, h, '#c9c7bf', 3);
  const overlay = v.motions.length > 1;
  const all = [];
  v.stats = [];
  v.motions.forEach((m, i) => {
    const { out, lowest, highest, touching } = pieces(m, frames[i], overlay ? m.colour : null);
    v.stats.push({ motion: m.label, frame: frames[i], lowest, highest, touching });
    all.push(...out);
    // Shadow: the bones flattened onto the floor.
    g.strokeStyle = 'rgba(60,60,50,0.18)';
    g.lineCap = 'round';
    m.bones.forEach((bone) => {
      const a = point(m, frames[i], bone.a), b = point(m, frames[i], bone.b);
      const p = v.project([a[0], 0, a[2]], w, h), q = v.project([b[0], 0, b[2]], w, h);
      if (!p || !q) return;
      g.lineWidth = Math.max(1, 2 * bone.r * 1.6 * h / ((p[2] + q[2]) / 2));
      g.beginPath(); g.moveTo(p[0], p[1]); g.lineTo(q[0], q[1]); g.stroke();
    });
  });
  // Painter's order: far pieces first.
  const camDir = [Math.sin(v.yaw) * Math.cos(v.pitch), Math.sin(v.pitch), Math.cos(v.yaw) * Math.cos(v.pitch)];
  const drawn = [];
  for (const pc of all) {
    if (pc.kind === 'face') {
      const s = pc.quad.map((p) => v.project(p, w, h));
      if (s.some((p) => !p)) continue;
      // Faces turned away from the camera are hidden by the box's own front faces.
      const mid = [0, 1, 2].map((d) => pc.quad.reduce((a, q) => a + q[d], 0) / 4);
      const eye = [0, 1, 2].map((d) => v.target[d] + v.dist * camDir[d] - mid[d]);
      const facing = pc.normal[0] * eye[0] + pc.normal[1] * eye[1] + pc.normal[2] * eye[2];
      if (facing < 0) continue;
      drawn.push({ depth: s.reduce((a, p) => a + p[2], 0) / 4, pc, s });
    } else {
      const p = v.project(pc.a, w, h), q = v.project(pc.b, w, h);
      if (!p || !q) continue;
      drawn.push({ depth: (p[2] + q[2]) / 2, pc, s: [p, q] });
    }
  }
  drawn.sort((a, b) => b.depth - a.depth);
  let minY = -Infinity;
  for (const { pc, s, depth } of drawn) {
    if (pc.kind === 'face') {
      const lit = 0.55 + 0.45 * Math.max(0, pc.normal[0] * LIGHT[0] + pc.normal[1] * LIGHT[1] + pc.normal[2] * LIGHT[2]);
      g.fillStyle = rgb(pc.col, lit);
      g.strokeStyle = rgb(pc.col, lit * 0.7);
      g.lineWidth = 1;
      g.beginPath();
      s.forEach((p, i) => (i ? g.lineTo(p[0], p[1]) : g.moveTo(p[0], p[1])));
      g.closePath(); g.fill(); g.stroke();
      s.forEach((p) => { minY = Math.max(minY, p[1]); });
    } else {
      const [p, q] = s;
      const px = pc.r * 1.6 * h / depth;
      g.lineCap = 'round';
      g.strokeStyle = rgb(pc.col, 0.72);
      g.lineWidth = 2 * px;
      g.beginPath(); g.moveTo(p[0], p[1]); g.lineTo(q[0], q[1]); g.stroke();
      g.strokeStyle = rgb(pc.col, 1.0);
      g.lineWidth = 1.1 * px;
      g.beginPath(); g.moveTo(p[0] - 0.3 * px, p[1] - 0.3 * px); g.lineTo(q[0] - 0.3 * px, q[1] - 0.3 * px); g.stroke();
      minY = Math.max(minY, p[1] + px, q[1] + px);
    }
  }
  // Events near now: a ring at their point and their words.
  v.motions.forEach((m, i) => {
    const local = t - m.start_s;
    const near = m.events.filter((e) => e.point !== null && Math.abs(local - e.t) <= 0.3)
      .sort((a, b) => Math.abs(local - a.t) - Math.abs(local - b.t));
    near.forEach((e, k) => {
      const p = v.project(point(m, frames[i], e.point), w, h);
      if (!p) return;
      g.strokeStyle = '#d01010'; g.lineWidth = 2.5;
      g.beginPath(); g.arc(p[0], p[1], 0.12 * 1.6 * h / p[2], 0, 2 * Math.PI); g.stroke();
      if (k >= 3) return;
      g.fillStyle = '#8a0000'; g.font = `${Math.max(11, Math.round(h / 40))}px sans-serif`;
      g.fillText(e.tag, 8, h - 10 - k * Math.max(13, h / 34));
      g.beginPath(); g.moveTo(p[0], p[1]); g.lineTo(8 + g.measureText(e.tag).width + 4, h - 14 - k * Math.max(13, h / 34));
      g.lineWidth = 0.8; g.stroke();
    });
  });
  v.canvas.dataset.lowestScreenY = minY.toFixed(1);
}

// ---------- plots ----------
function nice(lo, hi, n = 5) {
  const span = hi - lo || 1;
  const step = Math.pow(10, Math.floor(Math.log10(span / n)));
  const m = [1, 2, 5, 10].find((k) => span / (k * step) <= n) * step;
  const ticks = [];
  for (let x = Math.ceil(lo / m) * m; x <= hi + 1e-9 * span; x += m) ticks.push(x);
  return ticks;
}

function drawPlot(i, t) {
  const p = DATA.plots[i];
  const c = $(`plot-${i}`);
  const dpr = window.devicePixelRatio || 1;
  const w = Math.round((c.clientWidth || 560) * dpr), h = Math.round((c.clientHeight || 300) * dpr);
  if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
  const g = c.getContext('2d');
  g.setTransform(dpr, 0, 0, dpr, 0, 0);
  const W = w / dpr, H = h / dpr;
  g.fillStyle = '#fff'; g.fillRect(0, 0, W, H);
  const xs = p.series.flatMap((s) => s.points.map((q) => q[0])).concat(p.markers.map((q) => q[0]));
  const ys = p.series.flatMap((s) => s.points.map((q) => q[1]));
  if (p.time_axis) xs.push(0, END);
  let [x0, x1] = [Math.min(...xs), Math.max(...xs)];
  let [y0, y1] = [Math.min(...ys), Math.max(...ys)];
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) { y0 -= 0.5; y1 += 0.5; }
  const pad = 0.05 * (y1 - y0); y0 -= pad; y1 += pad;
  const L = 58, R = W - 12, T = 26 + 14 * Math.ceil(p.series.length / 2), B = H - 40;
  const X = (x) => L + (x - x0) / (x1 - x0) * (R - L), Y = (y) => B - (y - y0) / (y1 - y0) * (B - T);
  g.font = '12px sans-serif'; g.fillStyle = '#222';
  g.fillText(p.title, L, 16);
  g.strokeStyle = '#ddd'; g.lineWidth = 1;
  g.textAlign = 'center';
  for (const x of nice(x0, x1)) { g.beginPath(); g.moveTo(X(x), T); g.lineTo(X(x), B); g.stroke(); g.fillText(+x.toPrecision(4), X(x), B + 14); }
  g.textAlign = 'right';
  for (const y of nice(y0, y1)) { g.beginPath(); g.moveTo(L, Y(y)); g.lineTo(R, Y(y)); g.stroke(); g.fillText(+y.toPrecision(4), L - 4, Y(y) + 4); }
  g.textAlign = 'center'; g.fillText(p.x_label, (L + R) / 2, H - 8);
  g.save(); g.translate(12, (T + B) / 2); g.rotate(-Math.PI / 2); g.fillText(p.y_label, 0, 0); g.restore();
  g.textAlign = 'left';
  g.strokeStyle = '#888'; g.strokeRect(L, T, R - L, B - T);
  p.markers.forEach(([x, label]) => {
    g.strokeStyle = '#999'; g.setLineDash([4, 3]);
    g.beginPath(); g.moveTo(X(x), T); g.lineTo(X(x), B); g.stroke(); g.setLineDash([]);
    g.fillStyle = '#666'; g.fillText(label, X(x) + 3, T + 12);
  });
  p.series.forEach((s, k) => {
    const col = PALETTE[k % PALETTE.length];
    g.strokeStyle = rgb(col); g.lineWidth = 1.6;
    g.beginPath();
    s.points.forEach(([x, y], j) => (j ? g.lineTo(X(x), Y(y)) : g.moveTo(X(x), Y(y))));
    g.stroke();
    g.fillStyle = rgb(col);
    g.fillText(`— ${s.name}`, L + (k % 2) * (R - L) / 2, 30 + 14 * Math.floor(k / 2));
  });
  if (p.time_axis) {
    const cx = X(Math.max(x0, Math.min(x1, t)));
    g.strokeStyle = '#d01010'; g.lineWidth = 1.5;
    g.beginPath(); g.moveTo(cx, T); g.lineTo(cx, B); g.stroke();
    c.dataset.cursorT = t.toFixed(4);
    c.dataset.cursorX = cx.toFixed(1);
  }
}

// ---------- the clock ----------
function draw() {
  views.forEach((v) => drawView(v, state.t));
  DATA.plots.forEach((_, i) => drawPlot(i, state.t));
  const scrub = $('scrub');
  if (document.activeElement !== scrub) scrub.value = state.t;
  const fr = motions.map((m) => `${frameOf(m, state.t) + 1}/${m.frames}`);
  $('time').textContent = `${state.t.toFixed(3)} s · frame ${fr.join(', ')}`;
}

function songOn() { return song && $('song-on').checked; }

function syncSong() {
  if (!song) return;
  const a = $('song');
  if (!state.playing || !songOn() || state.t < song.start_s) { a.pause(); return; }
  a.currentTime = state.t - song.start_s;
  a.playbackRate = state.speed;
  a.play().catch(() => {});
}

function seek(t) {
  state.t = Math.max(0, Math.min(END, t));
  syncSong();
  draw();
}

// One frame back or on: to the neighbouring frame of the finest motion (the shortest frame
// time), from the frame shown now; outside that motion's span, by its frame time.
function stepFrame(dir) {
  pause();
  const m = motions.reduce((a, b) => (b.frame_time < a.frame_time ? b : a));
  const local = (state.t - m.start_s) / m.frame_time;
  if (local < 0 || local > m.frames - 1) { seek(state.t + dir * STEP); return; }
  seek(m.start_s + (frameOf(m, state.t) + dir) * m.frame_time);
}

function play() {
  if (state.t >= END) state.t = 0;
  state.playing = true;
  state.last = null;
  state.audioSeen = performance.now();
  $('play').textContent = '❚❚ Pause';
  syncSong();
  requestAnimationFrame(tick);
}

function pause() {
  state.playing = false;
  $('play').textContent = '▶ Play';
  syncSong();
}

function tick(now) {
  if (!state.playing) return;
  const dt = state.last === null ? 0 : (now - state.last) / 1000;
  state.last = now;
  const a = song ? $('song') : null;
  const at = a ? a.currentTime : 0;
  if (a && at !== state.audioT) { state.audioT = at; state.audioSeen = now; }
  // The song is the clock while it plays (a song that does not advance, e.g. with no sound
  // device, leaves the clock to the display's time after 0.3 s).
  if (a && songOn() && !a.paused && state.t >= song.start_s && now - (state.audioSeen || now) < 300) {
    state.t = song.start_s + at;
  } else {
    const before = state.t;
    state.t += dt * state.speed;
    if (a && songOn() && a.paused && before < song.start_s && state.t >= song.start_s) syncSong();
  }
  if (state.t > END) {
    if (state.loop) { state.t = 0; syncSong(); } else { state.t = END; pause(); }
  }
  draw();
  requestAnimationFrame(tick);
}

// For tests and for anyone scripting the page: the playhead, each motion's frame, and of each
// drawn body its lowest and highest point (m above the floor) and the parts marked touching it.
window.resultsPage = {
  motions: () => motions.map((m) => m.label),
  time: () => state.t,
  frames: () => motions.map((m) => frameOf(m, state.t)),
  playing: () => state.playing,
  seek, play, pause, setView,
  stats: () => views.flatMap((v) => v.stats),
};

build();
layout();
