// The dance editor's page: the timeline, six live candidates for the selected bar, the whole
// dance, and the actions of the JSON API (see src/editor/api.rs for the routes).
import { StickView } from '/figure.js';
import { Timeline } from '/timeline.js';

const $ = (id) => document.getElementById(id);
const status = (text, error = false) => { const s = $('status'); s.textContent = text; s.classList.toggle('error', error); };

async function api(method, path, body) {
  const r = await fetch(path, {
    method,
    headers: body === undefined ? {} : { 'Content-Type': 'application/json' },
    body: body === undefined ? undefined : JSON.stringify(body),
  });
  const type = r.headers.get('Content-Type') || '';
  const data = type.startsWith('application/json') ? await r.json() : await r.blob();
  if (!r.ok) throw new Error(data.error || `${path}: ${r.status}`);
  return data;
}

// ---- the clock: the audio clock when the song plays, else a silent one of the same shape ----
const audio = { ctx: null, buffer: null, source: null, loading: null };
let clock = { t0: performance.now() / 1000, from: 0, to: 1, loop: true, audible: false };
const now = () => (clock.audible && audio.ctx ? audio.ctx.currentTime : performance.now() / 1000);

async function ensureAudio() {
  if (audio.buffer) return true;
  if (!audio.loading) {
    audio.loading = (async () => {
      try {
        audio.ctx = new AudioContext();
        const bytes = await (await fetch('/api/audio.wav')).arrayBuffer();
        audio.buffer = await audio.ctx.decodeAudioData(bytes);
      } catch (e) {
        status('no audio: ' + e.message, true);
      }
    })();
  }
  await audio.loading;
  return !!audio.buffer;
}

function stopAudio() {
  if (audio.source) { try { audio.source.stop(); } catch (_) { /* already stopped */ } audio.source = null; }
}

// Plays the song from `from` to `to` (s), looping the span when `loop`; the animation follows.
async function playSpan(from, to, loop) {
  stopAudio();
  const ok = await ensureAudio();
  if (ok) {
    if (audio.ctx.state === 'suspended') await audio.ctx.resume();
    const src = audio.ctx.createBufferSource();
    src.buffer = audio.buffer;
    src.loop = loop;
    if (loop) { src.loopStart = from; src.loopEnd = to; }
    src.connect(audio.ctx.destination);
    const t0 = audio.ctx.currentTime + 0.05;
    src.start(t0, from);
    if (!loop) src.stop(t0 + (to - from));
    audio.source = src;
    clock = { t0, from, to, loop, audible: true };
  } else {
    clock = { t0: performance.now() / 1000, from, to, loop, audible: false };
  }
}

function songTime() {
  let t = Math.max(0, now() - clock.t0);
  const len = clock.to - clock.from;
  if (clock.loop) t %= len; else t = Math.min(t, len);
  return clock.from + t;
}

// ---- state ----
let figure = null;
let bars = [];
let selected = null;
let cands = null; // the selected bar's candidates answer
let views = [];
let dance = null; // { fps, start_s, frames }
let danceView = null;
let playing = false;
const timeline = new Timeline($('timeline'), (k) => selectBar(k));

async function refreshBars() {
  const b = await api('GET', '/api/bars');
  bars = b.bars;
  timeline.set(bars, b.beats_s);
}

async function refreshState() {
  const s = await api('GET', '/api/state');
  $('undo').disabled = s.undo === 0;
  $('redo').disabled = s.redo === 0;
  return s;
}

async function refresh() {
  await Promise.all([refreshBars(), refreshState()]);
  if (selected !== null) showCandidates(cands);
}

async function selectBar(k) {
  if (k < 0 || k >= bars.length) return;
  stopDance();
  selected = k;
  timeline.selected = k;
  timeline.draw();
  try {
    let c = await api('GET', `/api/candidates?bar=${k}`);
    if (c.round === 0) c = await api('POST', '/api/search', { bar: k });
    showCandidates(c);
    playSpan(c.start_s, c.end_s, true);
  } catch (e) { status(e.message, true); }
}

function showCandidates(c) {
  cands = c;
  const pin = bars[c.bar] ? bars[c.bar].pin : c.pin;
  $('bar-title').textContent = `Bar ${c.bar + 1}`;
  $('bar-info').textContent = `round ${c.round} · τ ${c.tau.toFixed(3)} · ${c.shown} shown · ${c.left} left · ${c.liked.length} liked` +
    (pin !== null && pin !== undefined ? ` · pinned #${pin}` : '');
  // A bar that ran dry: say so, and offer Start over instead of a Search that cannot answer.
  const dry = c.left === 0;
  $('search').disabled = dry;
  $('start-over').disabled = c.shown === 0;
  $('start-over').classList.toggle('offer', dry);
  $('dry').hidden = !dry;
  $('dry').textContent = dry ? `All ${c.shown} segments have been shown for this bar. Start over to see them again — your likes stay in their row.` : '';
  $('unpin').disabled = pin === null || pin === undefined;
  views = [
    ...fillCards($('candidates'), c, c.candidates, pin),
    ...fillCards($('liked'), c, c.liked_segments, pin),
  ];
  $('liked-head').hidden = c.liked_segments.length === 0;
  $('liked-head').textContent = `Liked (${c.liked_segments.length}) — kept across rounds and Start over`;
}

// One card per segment of `list` into `box` (a live stick figure, Like/Unlike, Set); their views.
function fillCards(box, c, list, pin) {
  box.replaceChildren();
  return list.map((m) => {
    const card = document.createElement('div');
    card.className = 'cand' + (pin === m.segment ? ' pinned' : '');
    card.dataset.segment = m.segment;
    const canvas = document.createElement('canvas');
    const row = document.createElement('div');
    row.className = 'row';
    const label = document.createElement('span');
    label.className = 'label';
    label.textContent = `#${m.segment} · ${m.source ?? ''} bar ${m.source_bar + 1} · W ${m.intensity.toFixed(1)}`;
    label.title = label.textContent;
    const like = document.createElement('button');
    like.className = 'like' + (m.liked ? ' on' : '');
    like.textContent = m.liked ? '♥ Liked' : '♡ Like';
    like.title = m.liked ? 'Take this segment out of your likes' : 'Like: the next Search leans toward segments like this one';
    like.onclick = () => act(async () => {
      await api('POST', m.liked ? '/api/unlike' : '/api/like', { bar: c.bar, segment: m.segment });
      showCandidates(await api('GET', `/api/candidates?bar=${c.bar}`));
    });
    const set = document.createElement('button');
    set.className = 'set';
    set.textContent = 'Set';
    set.title = 'Pin this segment to the bar';
    set.onclick = () => act(async () => {
      await api('POST', '/api/set', { bar: c.bar, segment: m.segment });
      dance = null;
      await refresh();
      status(`bar ${c.bar + 1} pinned to #${m.segment}`);
    });
    row.append(label, like, set);
    card.append(canvas, row);
    box.append(card);
    const v = new StickView(canvas, figure);
    v.frames = m.frames;
    return v;
  });
}

// The "explore ↔ follow my likes" slider: its position is 1 − τ_0.
function showTau(p) {
  $('tau0').value = (1 - p.tau0).toFixed(2);
  $('tau0-value').textContent = `τ₀ ${p.tau0.toFixed(2)}`;
  $('tau-decay').textContent = String(p.tau_decay);
}

async function act(f) {
  try { await f(); } catch (e) { status(e.message, true); }
}

// ---- the whole dance ----
async function startDance() {
  status('assembling the dance…');
  dance = await api('GET', '/api/dance');
  await refreshBars();
  const end = dance.start_s + dance.frames.length / dance.fps;
  await playSpan(dance.start_s, end, false);
  playing = true;
  $('play').textContent = '❚❚ Pause';
  const f = dance.figures, m = f.metrics, pen = m.foot_penetration;
  status(`playing ${bars.length} bars · feet under −1 cm in ${(100 * pen.frames_below_fraction).toFixed(1)} % of frames` +
    ` (deepest ${(100 * pen.deepest_m).toFixed(1)} cm) · skating ${m.foot_skating_m_s.toFixed(2)} m/s` +
    ` (its segments ${f.sources.foot_skating_m_s.toFixed(2)}) · beat alignment ${m.beat_alignment_score.toFixed(2)}` +
    ` (its segments ${f.sources.beat_alignment_score.toFixed(2)}) · intensity ρ ${f.intensity_spearman.toFixed(2)}` +
    ` · seam jerk ${Math.round(m.seam_jerk.mean_rad_s3)} rad/s³ (inside ${Math.round(m.inside_jerk.mean_rad_s3)})`);
}

function stopDance() {
  if (!playing) return;
  playing = false;
  stopAudio();
  $('play').textContent = '▶ Play';
  timeline.playhead = null;
  timeline.draw();
}

const togglePlay = () => act(async () => (playing ? stopDance() : startDance()));

// ---- the animation: every view follows the one clock ----
function frame() {
  const t = songTime();
  if (cands && views.length) {
    const barLen = cands.end_s - cands.start_s;
    const u = playing ? ((t - dance.start_s) % barLen) / barLen : (t - cands.start_s) / barLen;
    for (const v of views) {
      const n = v.frames.length;
      v.draw(v.frames[Math.min(n - 1, Math.max(0, Math.floor(u * n)))]);
    }
  }
  if (playing && dance) {
    const f = Math.floor((t - dance.start_s) * dance.fps);
    danceView.draw(dance.frames[Math.min(dance.frames.length - 1, Math.max(0, f))], true);
    timeline.playhead = t;
    timeline.draw();
    if (f >= dance.frames.length) stopDance();
  } else if (danceView) {
    danceView.draw(dance ? dance.frames[0] : null, true);
  }
  requestAnimationFrame(frame);
}

// ---- buttons and keys ----
$('play').onclick = togglePlay;
$('search').onclick = () => act(async () => {
  const c = await api('POST', '/api/search', { bar: selected });
  showCandidates(c);
  await refreshBars();
  status(`bar ${selected + 1}: round ${c.round}`);
});
$('start-over').onclick = () => act(async () => {
  await api('POST', '/api/start-over', { bar: selected });
  const c = await api('POST', '/api/search', { bar: selected });
  showCandidates(c);
  await refreshBars();
  status(`bar ${selected + 1}: started over (${c.liked.length} liked kept)`);
});
$('tau0').oninput = () => { $('tau0-value').textContent = `τ₀ ${(1 - Number($('tau0').value)).toFixed(2)}`; };
$('tau0').onchange = () => act(async () => {
  const p = await api('POST', '/api/search-params', { tau0: Number((1 - Number($('tau0').value)).toFixed(2)) });
  showTau(p);
  if (selected !== null) showCandidates(await api('GET', `/api/candidates?bar=${selected}`));
  status(`τ₀ ${p.tau0.toFixed(2)} for the next rounds of every bar`);
});
$('unpin').onclick = () => act(async () => {
  await api('POST', '/api/unpin', { bar: selected });
  dance = null;
  await refresh();
});
$('generate').onclick = () => act(async () => {
  const s = await api('POST', '/api/generate', {});
  dance = null;
  await refresh();
  status(`generated: total transition cost ${s.fill.total_cost.toFixed(3)}`);
});
for (const which of ['undo', 'redo']) {
  $(which).onclick = () => act(async () => {
    const s = await api('POST', `/api/${which}`, {});
    dance = null;
    await refresh();
    status(`${which}: bar ${s.change.bar + 1}`);
  });
}
$('save').onclick = () => act(async () => status(`saved ${(await api('POST', '/api/save', {})).saved}`));
$('export').onclick = () => act(async () => {
  const blob = await api('POST', '/api/export-bvh', {});
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = 'dance.bvh';
  a.click();
  URL.revokeObjectURL(a.href);
  status(`exported dance.bvh (${blob.size} bytes)`);
});
document.addEventListener('keydown', (e) => {
  if (e.key === ' ') { e.preventDefault(); togglePlay(); }
  else if (e.key === 'ArrowLeft') { e.preventDefault(); selectBar(selected === null ? 0 : selected - 1); }
  else if (e.key === 'ArrowRight') { e.preventDefault(); selectBar(selected === null ? 0 : selected + 1); }
  else if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'z') { e.preventDefault(); $(e.shiftKey ? 'redo' : 'undo').click(); }
});
window.addEventListener('resize', () => timeline.draw());

(async () => {
  const s = await refreshState();
  figure = { parents: s.parents, sides: s.sides, head: s.head };
  danceView = new StickView($('dance'), figure);
  danceView.dist = 4.6;
  showTau(s.search);
  await refreshBars();
  status(`${s.bars} bars · ${s.segments} segments · ${s.tempo_bpm.toFixed(1)} BPM`);
  // The first load (navigation start to a usable page), for tests/browser/latency.mjs.
  document.body.dataset.readyMs = performance.now().toFixed(1);
  document.body.dataset.ready = '1';
  requestAnimationFrame(frame);
})().catch((e) => status(e.message, true));
