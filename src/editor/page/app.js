// The dance editor's page: the timeline, six live candidates for the selected bar, the whole
// dance, and the actions of the JSON API (see src/editor/api.rs for the routes).
//
// Playback: one transport over song time. Playing, the song time runs on the audio context's
// clock (or, without audio, on performance.now) from the playhead, looping the loop's bars when
// a loop is on; the song is fetched bar by bar (`/api/audio.wav?bar=K`, 22.05 kHz mono) a few
// bars ahead and scheduled bar after bar on that same clock, and the dance, the playhead and
// the candidates all read the song time. Paused, the playhead stays where it stopped and the
// candidates keep looping the selected bar silently. Any action may come during play: the pins
// change, the dance is fetched again and swapped in at the same song time, and the song goes on.
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

// ---- state ----
let figure = null;
let bars = [];
let stale = false; // the unpinned bars' fills were made for other pins
let selected = null;
let cands = null; // the selected bar's candidates answer
let views = [];
let dance = null; // { fps, start_s, frames, figures }: the last dance fetched
let danceView = null;
// Every candidate card shares one camera: orbit or zoom one and all follow, kept across rounds.
const cardCam = { yaw: 0.5, pitch: 0.2, dist: 4.2 };
const timeline = new Timeline($('timeline'), (k, e) => pickBar(k, e), (t, phase) => scrub(t, phase));

// ---- the transport ----
// playing: song time = from + (clock() − t0), wrapped into the loop; stopped: song time = pos.
const transport = { playing: false, pos: 0, from: 0, t0: 0, audible: false, loop: null, gen: 0 };
const audio = { ctx: null, failed: false, bars: new Map(), ready: new Map(), sources: new Set(), next: null, bytes: 0 };
const clock = () => (transport.audible ? audio.ctx.currentTime : performance.now() / 1000);
const danceEnd = () => (bars.length ? bars[bars.length - 1].end_s : 0);
const loopSpan = () => (transport.loop ? [bars[transport.loop.a].start_s, bars[transport.loop.b].end_s] : null);

// What tests/browser/playback.mjs reads: the song time, the transport and the timeline's labels.
window.editor = { songTime: () => songTime(), transport, timeline };

function songTime() {
  if (!transport.playing) return transport.pos;
  let t = transport.from + Math.max(0, clock() - transport.t0);
  const l = loopSpan();
  if (l && t >= l[1]) t = l[0] + ((t - l[0]) % (l[1] - l[0]));
  return t;
}

// The bar that song time `t` falls in (the last bar at or after the end).
function barOf(t) {
  const k = bars.findIndex((b) => t < b.end_s);
  return k < 0 ? bars.length - 1 : k;
}

// The audio context, made on the first Play (a user's gesture); false when the page has none.
async function ensureAudio() {
  if (audio.ctx) {
    if (audio.ctx.state === 'suspended') await audio.ctx.resume();
    return audio.ctx.state === 'running';
  }
  if (audio.failed) return false;
  try {
    audio.ctx = new AudioContext();
    if (audio.ctx.state === 'suspended') await audio.ctx.resume();
    return audio.ctx.state === 'running';
  } catch (e) {
    audio.failed = true;
    status('no audio: ' + e.message, true);
    return false;
  }
}

// Bar k's piece of the song as an AudioBuffer (fetched once; null when it failed).
function barBuffer(k) {
  if (!audio.bars.has(k)) {
    audio.bars.set(k, (async () => {
      try {
        const r = await fetch(`/api/audio.wav?bar=${k}`);
        if (!r.ok) throw new Error(`bar ${k}'s audio: ${r.status}`);
        const bytes = await r.arrayBuffer();
        audio.bytes += bytes.byteLength;
        document.body.dataset.audioBytes = String(audio.bytes);
        const buf = await audio.ctx.decodeAudioData(bytes);
        audio.ready.set(k, buf);
        return buf;
      } catch (e) {
        status(e.message, true);
        return null;
      }
    })());
  }
  return audio.bars.get(k);
}

function stopSources() {
  for (const s of audio.sources) { try { s.stop(); } catch (_) { /* already stopped */ } }
  audio.sources.clear();
  audio.next = null;
}

// The bar after k in playing order: the loop wraps; the dance ends after its last bar.
function nextBar(k) {
  if (transport.loop && k >= transport.loop.b) return transport.loop.a;
  return k + 1 < bars.length ? k + 1 : null;
}

// Schedules the song's bars on the audio clock up to half a second ahead, fetching three ahead.
function schedule() {
  const s = audio.next;
  if (!transport.playing || !transport.audible || !s) return;
  for (let i = 0, k = s.k; i < 3 && k !== null; i++, k = nextBar(k)) barBuffer(k);
  const ctx = audio.ctx;
  while (s.k !== null && s.at < ctx.currentTime + 0.5) {
    const buf = audio.ready.get(s.k);
    if (!buf) {
      if (!audio.bars.has(s.k)) break;
      if (s.at > ctx.currentTime) break; // still loading, in time: try again next frame
    }
    const b = bars[s.k];
    const late = Math.max(0, ctx.currentTime + 0.005 - s.at);
    const offset = s.offset + late;
    if (buf && offset < buf.duration) {
      const src = ctx.createBufferSource();
      src.buffer = buf;
      src.connect(ctx.destination);
      src.start(s.at + late, offset);
      src.onended = () => audio.sources.delete(src);
      audio.sources.add(src);
      if (audio.firstSound && audio.firstSound.gen === transport.gen) {
        // From the click to the moment the first sample reaches the output.
        const lead = s.at + late - ctx.currentTime + (ctx.baseLatency || 0) + (ctx.outputLatency || 0);
        document.body.dataset.firstSoundMs = (performance.now() - audio.firstSound.t + 1000 * lead).toFixed(1);
        audio.firstSound = null;
      }
    }
    if (!buf && s.at + (b.end_s - b.start_s - s.offset) > ctx.currentTime) break;
    s.at += b.end_s - b.start_s - s.offset;
    s.offset = 0;
    s.k = nextBar(s.k);
  }
}

// Starts (or restarts) playing from song time `from`, after any action: every older start gives way.
async function startAt(from) {
  const gen = ++transport.gen;
  stopSources();
  const l = loopSpan();
  if (l && (from < l[0] || from >= l[1])) from = l[0];
  if (from >= danceEnd() - 1e-3) from = bars[0].start_s;
  from = Math.max(from, bars[0].start_s);
  const k = barOf(from);
  // The clock keeps running on performance.now while the first bar arrives.
  transport.pos = from;
  const audible = await ensureAudio();
  if (gen !== transport.gen) return;
  if (audible) await barBuffer(k);
  if (gen !== transport.gen) return;
  transport.audible = audible;
  transport.from = from;
  transport.t0 = clock() + (audible ? 0.02 : 0);
  transport.playing = true;
  if (audible) audio.next = { k, at: transport.t0, offset: from - bars[k].start_s };
  schedule();
  $('play').textContent = '❚❚ Pause';
  showPlaying();
}

async function play() {
  audio.firstSound = { t: performance.now(), gen: transport.gen + 1 };
  await startAt(transport.pos);
  // A dance made for other pins (a Set, Unpin, Undo or Redo since) is made again.
  if (!dance || stale) loadDance();
}

function pause() {
  transport.pos = songTime();
  transport.playing = false;
  transport.gen++;
  stopSources();
  $('play').textContent = '▶ Play';
  status(`paused at ${transport.pos.toFixed(2)} s (bar ${barOf(transport.pos)}) · the candidates keep looping bar ${selected ?? '–'} silently`);
}

// Metres as centimetres to one decimal, without a negative zero ("−0.0" reads as a depth).
function cm(m) {
  const v = Math.round(1000 * m) / 10;
  return (v === 0 ? 0 : v).toFixed(1);
}

function showPlaying() {
  const loop = transport.loop ? ` · looping bars ${transport.loop.a}–${transport.loop.b}` : '';
  const sound = transport.audible ? '' : ' (no sound)';
  status(`playing from bar ${barOf(transport.from)}${loop}${sound}` + (dance ? ' · ' + figuresText(dance.figures) : ''));
}

function figuresText(f) {
  const m = f.metrics, pen = m.foot_penetration;
  return `feet under −1 cm in ${(100 * pen.frames_below_fraction).toFixed(1)} % of frames` +
    ` (deepest ${cm(pen.deepest_m)} cm) · skating ${m.foot_skating_m_s.toFixed(2)} m/s` +
    ` (its segments ${f.sources.foot_skating_m_s.toFixed(2)}) · beat alignment ${m.beat_alignment_score.toFixed(2)}` +
    ` (its segments ${f.sources.beat_alignment_score.toFixed(2)}) · intensity ρ ${f.intensity_spearman.toFixed(2)}` +
    ` · seam jerk ${Math.round(m.seam_jerk.mean_rad_s3)} rad/s³ (inside ${Math.round(m.inside_jerk.mean_rad_s3)})`;
}

// Fetches the dance of the current pins (the server fills first) and swaps it in; the song
// and the playhead go on. Older fetches that arrive late are dropped.
let danceAsked = 0;
async function loadDance() {
  const ask = ++danceAsked;
  try {
    const d = await api('GET', '/api/dance');
    if (ask !== danceAsked) return;
    dance = d;
    await refreshBars();
    if (transport.playing) showPlaying();
  } catch (e) { status(e.message, true); }
}

function setLoop(loop) {
  transport.loop = loop;
  timeline.loop = loop;
  $('loop').classList.toggle('on', !!loop);
  $('loop').textContent = loop ? `⟲ Loop ${loop.a}${loop.b !== loop.a ? '–' + loop.b : ''}` : '⟲ Loop';
  if (transport.playing) startAt(songTime());
  timeline.draw();
}

// A click on the timeline: seek there while playing, else move the playhead; select the bar.
// Shift+click loops the bars from the selected one to the clicked one.
function pickBar(k, e) {
  if (e && e.shiftKey && selected !== null) {
    setLoop({ a: Math.min(selected, k), b: Math.max(selected, k) });
    return;
  }
  selectBar(k);
}

// A drag along the timeline moves the playhead (the dance view follows); playback, paused for
// the drag, goes on from where it ends.
let scrubResume = false;
function scrub(t, phase) {
  if (phase === 'start') {
    scrubResume = transport.playing;
    if (transport.playing) pause();
  }
  transport.pos = t;
  if (phase === 'end') {
    if (scrubResume) startAt(t);
    else status(`playhead at ${t.toFixed(2)} s (bar ${barOf(t)})`);
  }
}

async function selectBar(k) {
  if (k < 0 || k >= bars.length) return;
  selected = k;
  timeline.selected = k;
  if (transport.playing) startAt(bars[k].start_s);
  else transport.pos = bars[k].start_s;
  // The bar's sound, ready for Play (88 kB a 2 s bar).
  if (audio.ctx) barBuffer(k);
  timeline.reveal(bars[k].start_s);
  timeline.draw();
  try {
    let c = await api('GET', `/api/candidates?bar=${k}`);
    if (c.round === 0) c = await api('POST', '/api/search', { bar: k });
    if (selected === k) showCandidates(c);
  } catch (e) { status(e.message, true); }
}

async function refreshBars() {
  const b = await api('GET', '/api/bars');
  bars = b.bars;
  stale = b.stale;
  timeline.set(bars, b.beats_s);
  $('timeline-note').textContent = stale
    ? 'Hatched bars: their fill was made before the last pin change — Generate (or Play) fills them again.'
    : '';
}

async function refreshState() {
  const s = await api('GET', '/api/state');
  $('undo').disabled = s.undo === 0;
  $('redo').disabled = s.redo === 0;
  return s;
}

// After a change of pins: the bars, the buttons, the cards; while playing, the dance again.
async function refresh() {
  await Promise.all([refreshBars(), refreshState()]);
  if (selected !== null) showCandidates(cands);
  if (transport.playing) await loadDance();
}

// The fit of segment `m` to the bar, in words: where the bar's loudness ranks in the song
// against where the segment's W ranks in the database.
function fitWords(c, m) {
  const d = m.intensity_rank - c.loudness_rank;
  const how = Math.abs(d) < 0.15 ? 'matches the bar' : (d < 0 ? 'calmer than the bar' : 'livelier than the bar');
  return { short: `fit ${m.relevance.toFixed(2)}: ${how}`, long:
    `The bar is louder than ${Math.round(100 * c.loudness_rank)} % of the song's bars; this segment moves more ` +
    `than ${Math.round(100 * m.intensity_rank)} % of the database's segments. Fit (relevance) = 1 − |difference| = ` +
    `${m.relevance.toFixed(2)}: 1 when the segment is as intense among the segments as the bar is loud among the bars.` };
}

// The seams of a segment in context (`GET /api/in-context`), in words.
function seamWords(x) {
  const one = (seam, which) => (seam ? `${which} S ${seam.s.toFixed(2)}` : null);
  const parts = [one(x.before, `from bar ${x.bar - 1}`), one(x.after, `into bar ${x.bar + 1}`)].filter(Boolean);
  const cost = [x.before, x.after].filter(Boolean).reduce((a, seam) => a + seam.cost, 0);
  return {
    short: parts.length ? `${parts.join(' · ')} · C ${cost.toFixed(2)}` : 'no neighbouring bar',
    long: 'S: how well two bars join, the posture and movement similarity of the seam (eq. 8; higher joins ' +
      'better). C = 1/S is the transition cost the fill minimises; C here is the sum over the seams shown. ' +
      'Compare a candidate\'s C with the others\' to see which one this bar\'s neighbours take best.',
  };
}

function showCandidates(c) {
  cands = c;
  const pin = bars[c.bar] ? bars[c.bar].pin : c.pin;
  $('bar-title').textContent = `Bar ${c.bar}`;
  $('bar-info').textContent = `${c.start_s.toFixed(2)}–${c.end_s.toFixed(2)} s · louder than ${Math.round(100 * c.loudness_rank)} % of the bars` +
    ` · round ${c.round} · τ ${c.tau.toFixed(3)} · ${c.shown} shown · ${c.left} left · ${c.liked.length} liked` +
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
    const name = document.createElement('div');
    name.className = 'name';
    name.textContent = `${m.name ?? 'clip ?'} · bar ${m.source_bar}`;
    name.title = `${m.source ?? 'unknown clip'}, its bar ${m.source_bar} (from 0) · segment #${m.segment}`;
    const fit = fitWords(c, m);
    const info = document.createElement('div');
    info.className = 'info';
    info.textContent = `#${m.segment} · W ${m.intensity.toFixed(1)} ${c.intensity_unit} · ${fit.short}`;
    info.title = `W: the segment's motion intensity, the mean over the bar of Σ α_i·|velocity of point i| ` +
      `(${c.intensity_unit}).\n${fit.long}`;
    const row = document.createElement('div');
    row.className = 'row';
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
      await refresh();
      status(`bar ${c.bar} pinned to #${m.segment}`);
    });
    const seams = document.createElement('div');
    seams.className = 'info seams';
    const where = document.createElement('div');
    where.className = 'info where';
    const context = document.createElement('button');
    context.className = 'context';
    context.textContent = 'In context';
    context.title = 'Play this segment between the bars before and after it as they are now (their pins, ' +
      'else the last fill), joined as the dance would join them; the seams\' connection scores are shown';
    row.append(like, context, set);
    card.append(canvas, name, info, seams, where, row);
    box.append(card);
    const v = new StickView(canvas, figure, cardCam);
    v.frames = m.frames;
    v.context = null;
    v.whereEl = where;
    context.onclick = () => act(async () => {
      if (v.context) {
        v.context = null;
        context.classList.remove('on');
        seams.textContent = '';
        where.textContent = '';
        delete card.dataset.context;
        return;
      }
      const x = await api('GET', `/api/in-context?bar=${c.bar}&segment=${m.segment}`);
      v.context = x;
      context.classList.add('on');
      card.dataset.context = '1';
      const words = seamWords(x);
      seams.textContent = words.short;
      seams.title = words.long;
    });
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

const togglePlay = () => act(async () => (transport.playing ? pause() : play()));

// ---- the animation: every view follows the one song time ----
function drawFrame() {
  const t = songTime();
  if (cands && views.length) {
    // Playing: the candidates move in step with the bar being played; paused: they loop the
    // selected bar on the page's own clock.
    let u;
    if (transport.playing && bars.length) {
      const b = bars[barOf(t)];
      u = (t - b.start_s) / (b.end_s - b.start_s);
    } else {
      const len = cands.end_s - cands.start_s;
      u = ((performance.now() / 1000) % len) / len;
    }
    u = Math.min(1, Math.max(0, u));
    for (const v of views) {
      if (v.context) {
        // In context: the bars before, this one and after, looped on the page's clock.
        const x = v.context, len = x.end_s - x.start_s, n = x.frames.length;
        const at = (performance.now() / 1000) % len;
        const t = x.start_s + at;
        const k = t < x.bar_start_s ? x.bar - 1 : (t < x.bar_end_s ? x.bar : x.bar + 1);
        const where = k === x.bar ? `▶ bar ${k} (this segment)` : `▶ bar ${k} (neighbour)`;
        if (v.whereEl && v.whereEl.textContent !== where) v.whereEl.textContent = where;
        v.draw(x.frames[Math.min(n - 1, Math.floor(at * x.fps))], true);
        continue;
      }
      const n = v.frames.length;
      v.draw(v.frames[Math.min(n - 1, Math.floor(u * n))], true);
    }
  }
  if (danceView) {
    const f = dance ? Math.floor((t - dance.start_s) * dance.fps) : 0;
    danceView.draw(dance ? dance.frames[Math.min(dance.frames.length - 1, Math.max(0, f))] : null, true);
  }
  if (transport.playing) {
    schedule();
    if (!transport.loop && t >= danceEnd()) {
      pause();
      transport.pos = bars[0].start_s;
      status('played to the end');
    }
  }
  if (bars.length && timeline.playhead !== t) {
    timeline.playhead = t;
    if (transport.playing) timeline.reveal(t);
    timeline.draw();
  }
}

function frame() {
  try { drawFrame(); } catch (e) { console.error(e); status('drawing: ' + e.message, true); }
  requestAnimationFrame(frame);
}

// ---- buttons and keys ----
$('play').onclick = togglePlay;
$('loop').onclick = () => {
  if (transport.loop) setLoop(null);
  else if (selected !== null) setLoop({ a: selected, b: selected });
  else status('select a bar to loop (shift+click another for a range)');
};
$('search').onclick = () => act(async () => {
  const c = await api('POST', '/api/search', { bar: selected });
  showCandidates(c);
  await refreshBars();
  status(`bar ${selected}: round ${c.round}`);
});
$('start-over').onclick = () => act(async () => {
  await api('POST', '/api/start-over', { bar: selected });
  const c = await api('POST', '/api/search', { bar: selected });
  showCandidates(c);
  await refreshBars();
  status(`bar ${selected}: started over (${c.liked.length} liked kept)`);
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
  await refresh();
  status(`bar ${selected} unpinned`);
});
$('generate').onclick = () => act(async () => {
  const s = await api('POST', '/api/generate', {});
  await refresh();
  if (!transport.playing) await loadDance();
  status(`generated: total transition cost ${s.fill.total_cost.toFixed(3)}`);
});
for (const which of ['undo', 'redo']) {
  $(which).onclick = () => act(async () => {
    const s = await api('POST', `/api/${which}`, {});
    await refresh();
    status(`${which}: bar ${s.change.bar}`);
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
  else if (e.key.toLowerCase() === 'l' && !e.ctrlKey && !e.metaKey) { e.preventDefault(); $('loop').click(); }
  else if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === 'z') { e.preventDefault(); $(e.shiftKey ? 'redo' : 'undo').click(); }
});
window.addEventListener('resize', () => timeline.draw());
// The audio context needs a user's gesture: the first click or key makes it, so that Play
// itself waits only for its bar's sound.
for (const ev of ['pointerdown', 'keydown']) {
  document.addEventListener(ev, () => { if (!audio.ctx && !audio.failed) ensureAudio(); }, { once: true, capture: true });
}

(async () => {
  const s = await refreshState();
  figure = { parents: s.parents, sides: s.sides, head: s.head };
  danceView = new StickView($('dance'), figure, { yaw: 0.5, pitch: 0.2, dist: 4.6 });
  showTau(s.search);
  await refreshBars();
  transport.pos = bars.length ? bars[0].start_s : 0;
  status(`${s.bars} bars (numbered from 0, as in the scene file) · ${s.segments} segments · ${s.tempo_bpm.toFixed(1)} BPM`);
  // The first load (navigation start to a usable page), for tests/browser/latency.mjs.
  document.body.dataset.readyMs = performance.now().toFixed(1);
  document.body.dataset.ready = '1';
  requestAnimationFrame(frame);
  loadDance();
})().catch((e) => status(e.message, true));
