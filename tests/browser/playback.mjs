// Playback and the timeline of the dance editor in headless Chromium (tests/editor/browser.rs
// runs it): node playback.mjs URL SCREENSHOT_DIR MODE
//
// MODE "actions" (a short dance): Play from the selected bar; Set, Undo, Redo, Unpin and
// Generate while playing, without a page error and with the song time still running; a click on
// a bar while playing seeks there; a loop keeps the song time inside its bar; after Pause the
// playhead stands still and the candidates still move; a Set marks the other fills stale until
// Generate; the bars whose segment is danced twice are marked; a drag scrubs; a candidate plays
// in context; Save and Export through the buttons; the song arrives bar by bar.
// MODE "long" (a song of 200 bars, device scale factor 2): the timeline's bar numbers do not
// overlap; Play from bar 150 sounds within 200 ms of the click; the wheel zooms (the numbers
// thin less, a click picks the bar under the pointer) and shift+wheel scrolls.
// MODE "actions" also plays a candidate in context (between its bar's neighbours, its seams
// scored).
// Prints one JSON line of what it measured; exits non-zero on any failed check.
import { launch } from './launch.mjs';
import { join } from 'node:path';

const [url, shots, mode] = process.argv.slice(2);
const fail = (msg) => { console.error('FAIL: ' + msg); process.exit(1); };

const browser = await launch();
const errors = [];
try {
  const page = await browser.newPage({
    viewport: { width: 1280, height: 860 },
    deviceScaleFactor: mode === 'long' ? 2 : 1,
  });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text() + ' ' + (m.location().url || '')); });
  const audio = []; // bytes of every song piece received
  page.on('response', (r) => {
    // A piece still arriving when the browser closes is not counted (nor an error).
    if (r.url().includes('/api/audio.wav')) r.body().then((b) => audio.push(b.length), () => {});
  });
  const checkErrors = (when) => { if (errors.length) fail(`page errors ${when}: ` + errors.join(' | ')); };
  await page.goto(url);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 60000 });
  const barsAnswer = await (await page.request.get(url + 'api/bars')).json();
  const bars = barsAnswer.bars;
  const box = await page.$eval('#timeline', (c) => { const r = c.getBoundingClientRect(); return { x: r.x, y: r.y, w: r.width, h: r.height }; });
  const clickBar = (k, opts = {}) => page.mouse.click(box.x + 8 + (box.w - 16) * ((k + 0.5) / bars.length), box.y + box.h / 2, opts);
  const songTime = () => page.evaluate(() => window.editor.songTime());
  const playing = () => page.evaluate(() => window.editor.transport.playing);
  const statusText = () => page.textContent('#status');
  const waitStatus = (prefix) => page.waitForFunction((p) => document.getElementById('status').textContent.startsWith(p), prefix, { timeout: 20000 })
    .catch(async () => fail(`status never started with "${prefix}": "${await statusText()}"`));
  const candidateShot = () => page.$eval('#candidates .cand canvas', (cv) => cv.toDataURL());

  if (mode === 'long') {
    // Bar numbers at 200 bars, device scale 2: none overlap, and they count from 0.
    const labels = await page.evaluate(() => window.editor.timeline.labels);
    if (labels.length < 10) fail(`only ${labels.length} bar numbers on the timeline`);
    if (labels[0].text !== '0') fail(`the first bar is numbered ${labels[0].text}`);
    for (let i = 1; i < labels.length; i++) {
      if (labels[i].x0 < labels[i - 1].x1 + 2) fail(`bar numbers ${labels[i - 1].text} and ${labels[i].text} overlap: ${JSON.stringify(labels.slice(i - 1, i + 1))}`);
    }
    await clickBar(150);
    await page.waitForFunction(() => document.getElementById('bar-title').textContent === 'Bar 150', null, { timeout: 20000 });
    await page.waitForSelector('#candidates .cand');
    await page.screenshot({ path: join(shots, 'editor_timeline_200_bars.png'), clip: { x: 0, y: 0, width: 1280, height: 240 } });
    await page.click('#play');
    await page.waitForSelector('body[data-first-sound-ms]', { timeout: 10000 }).catch(() => fail('no sound scheduled'));
    const firstSoundMs = Number(await page.getAttribute('body', 'data-first-sound-ms'));
    await page.waitForTimeout(500);
    const t = await songTime();
    if (!(t >= bars[150].start_s && t < bars[152].end_s)) fail(`playing from bar 150 (${bars[150].start_s} s) is at ${t} s`);
    // Zoom: the wheel over the timeline narrows the span shown around the pointer; the bar
    // numbers thin less and still do not overlap; a click picks the bar under the pointer;
    // shift+wheel scrolls later.
    await page.click('#play'); // pause
    const cx = box.x + box.w / 2, cy = box.y + box.h / 2;
    await page.mouse.move(cx, cy);
    const whole = bars[bars.length - 1].end_s - bars[0].start_s;
    const shown = async () => { const [a, b] = await page.evaluate(() => window.editor.timeline.visible()); return b - a; };
    for (let i = 0; i < 20 && (await shown()) > 0.08 * whole; i++) { await page.mouse.wheel(0, -200); await page.waitForTimeout(50); }
    const [z0, z1] = await page.evaluate(() => window.editor.timeline.visible());
    if (!(z1 - z0 < 0.2 * whole)) fail(`zoomed in, the timeline still shows ${z0}–${z1} s of ${whole} s`);
    const zl = await page.evaluate(() => window.editor.timeline.labels);
    if (zl.length < 2) fail(`zoomed in, ${zl.length} bar numbers`);
    const zStep = Number(zl[1].text) - Number(zl[0].text);
    const wholeStep = Number(labels[1].text) - Number(labels[0].text);
    if (!(zStep < wholeStep)) fail(`zoomed in, bar numbers every ${zStep} bars, as at the whole song (${wholeStep})`);
    for (let i = 1; i < zl.length; i++) {
      if (zl[i].x0 < zl[i - 1].x1 + 2) fail(`zoomed, bar numbers ${zl[i - 1].text} and ${zl[i].text} overlap`);
    }
    const under = await page.evaluate(([x]) => {
      const tl = window.editor.timeline, c = tl.canvas;
      return tl.barAt((x - c.getBoundingClientRect().x) * (c.width / c.clientWidth));
    }, [cx]);
    await page.mouse.click(cx, cy);
    await page.waitForFunction((k) => document.getElementById('bar-title').textContent === `Bar ${k}`, under, { timeout: 20000 })
      .catch(async () => fail(`zoomed, a click on bar ${under} showed "${await page.textContent('#bar-title')}"`));
    const ub = bars[under];
    if (!(ub.end_s > z0 && ub.start_s < z1)) fail(`the bar clicked (${under}) is outside the span shown`);
    await page.screenshot({ path: join(shots, 'editor_timeline_zoomed.png'), clip: { x: 0, y: 0, width: 1280, height: 240 } });
    await page.keyboard.down('Shift');
    await page.mouse.wheel(0, 400);
    await page.keyboard.up('Shift');
    await page.waitForTimeout(100);
    const [s0, s1] = await page.evaluate(() => window.editor.timeline.visible());
    if (!(s0 > z0 && Math.abs((s1 - s0) - (z1 - z0)) < 1e-6)) fail(`shift+wheel moved the span ${z0}–${z1} s to ${s0}–${s1} s`);
    checkErrors('on the long song');
    const songS = bars[bars.length - 1].end_s;
    console.log(JSON.stringify({ labels: labels.length, zoomed_label_step: zStep, whole_label_step: wholeStep, first_label_gap_px: labels[1].x0 - labels[0].x1, first_sound_ms: firstSoundMs, audio_bytes: audio.reduce((a, b) => a + b, 0), song_s: songS }));
    process.exit(0);
  }

  // Select bar 2, then Play: it plays from bar 2.
  await clickBar(2);
  await page.waitForFunction(() => document.querySelectorAll('#candidates .cand').length === 6, null, { timeout: 10000 });
  await page.click('#play');
  await waitStatus('playing from bar 2');
  await page.waitForSelector('body[data-first-sound-ms]', { timeout: 10000 }).catch(() => fail('no sound scheduled'));
  const firstSoundMs = Number(await page.getAttribute('body', 'data-first-sound-ms'));
  const t0 = await songTime();
  if (!(t0 >= bars[2].start_s && t0 < bars[3].end_s)) fail(`Play from bar 2 (${bars[2].start_s} s) is at ${t0} s`);

  // Every action during play: no page error, still playing, the song time goes on.
  const segs = await page.$$eval('#candidates .cand', (cs) => cs.map((c) => Number(c.dataset.segment)));
  await (await page.$$('#candidates .cand button.set'))[0].click();
  await waitStatus(`bar 2 pinned to #${segs[0]}`);
  await page.keyboard.press('Control+z');
  await waitStatus('undo: bar 2');
  await page.keyboard.press('Control+Shift+z');
  await waitStatus('redo: bar 2');
  await page.click('#unpin');
  await waitStatus('bar 2 unpinned');
  await page.click('#generate');
  await waitStatus('generated');
  await page.waitForTimeout(300);
  checkErrors('after actions during Play');
  if (!(await playing())) fail('playback stopped after the actions');
  const t1 = await songTime();
  if (!(t1 > t0)) fail(`the song time stood still during the actions (${t0} → ${t1})`);
  const danceShown = await page.evaluate(() => document.getElementById('status').textContent);

  // A click on bar 9 while playing seeks there and keeps playing.
  await clickBar(9);
  await page.waitForFunction(() => document.getElementById('bar-title').textContent === 'Bar 9', null, { timeout: 10000 });
  await page.waitForTimeout(300);
  if (!(await playing())) fail('clicking a bar while playing stopped playback');
  const t2 = await songTime();
  if (!(t2 >= bars[9].start_s && t2 < bars[9].end_s)) fail(`after clicking bar 9 (${bars[9].start_s}–${bars[9].end_s} s) the song is at ${t2} s`);
  await page.waitForSelector('#candidates .cand');
  await page.screenshot({ path: join(shots, 'editor_playing_bar_9.png') });

  // L loops bar 9: over two and a half bars the song time stays inside it and wraps.
  await page.keyboard.press('l');
  await waitStatus('playing from bar 9 · looping bars 9–9');
  const len9 = bars[9].end_s - bars[9].start_s;
  const samples = [];
  const tEnd = Date.now() + 2500 * len9;
  while (Date.now() < tEnd) { samples.push(await songTime()); await page.waitForTimeout(100); }
  const outside = samples.filter((t) => t < bars[9].start_s - 1e-6 || t >= bars[9].end_s + 1e-6);
  if (outside.length) fail(`the loop of bar 9 (${bars[9].start_s}–${bars[9].end_s} s) played ${outside[0]} s`);
  const wraps = samples.filter((t, i) => i > 0 && t < samples[i - 1]).length;
  if (wraps < 2) fail(`the loop wrapped ${wraps} times in ${samples.length} samples over 2.5 bars`);
  await page.screenshot({ path: join(shots, 'editor_loop.png'), clip: { x: 0, y: 0, width: 1280, height: 240 } });
  await page.keyboard.press('l'); // loop off

  // Pause: the status says so, the playhead stands, the candidates keep moving.
  await page.keyboard.press('Space');
  await waitStatus('paused at');
  const p0 = await songTime();
  const a = await candidateShot();
  await page.waitForTimeout(400);
  const b = await candidateShot();
  const p1 = await songTime();
  if (a === b) fail('the candidates stopped moving after Pause');
  if (p0 !== p1) fail(`the playhead moved after Pause (${p0} → ${p1})`);

  // A Set while paused: the other bars' fills are marked stale until Generate.
  const seg9 = Number(await page.$eval('#candidates .cand', (c) => c.dataset.segment));
  await (await page.$$('#candidates .cand button.set'))[0].click();
  await waitStatus(`bar 9 pinned to #${seg9}`);
  const note = await page.textContent('#timeline-note');
  if (!note.includes('Generate')) fail(`no word of stale fills after Set: "${note}"`);
  await page.screenshot({ path: join(shots, 'editor_stale.png'), clip: { x: 0, y: 0, width: 1280, height: 240 } });
  await page.click('#generate');
  await waitStatus('generated');
  if ((await page.textContent('#timeline-note')) !== '') fail('stale note kept after Generate');

  // The bars whose segment is danced more than once are the ones marked.
  const after = (await (await page.request.get(url + 'api/bars')).json()).bars;
  const count = new Map();
  for (const x of after) count.set(x.pin ?? x.filled, (count.get(x.pin ?? x.filled) || 0) + 1);
  const want = after.map((x, k) => (count.get(x.pin ?? x.filled) > 1 ? k : null)).filter((k) => k !== null);
  const marked = await page.evaluate(() => window.editor.timeline.repeated);
  if (marked.join() !== want.join()) fail(`repeated segments marked on bars ${marked}, danced twice or more on bars ${want}`);

  // A drag from bar 4 to bar 6 while paused scrubs: the playhead passes bar 5 and stops in bar
  // 6; nothing plays and the selected bar stays.
  const xOf = (k) => box.x + 8 + (box.w - 16) * ((k + 0.5) / bars.length);
  await page.mouse.move(xOf(4), box.y + box.h / 2);
  await page.mouse.down();
  const passed = [];
  for (let i = 1; i <= 10; i++) {
    await page.mouse.move(xOf(4) + (xOf(6) - xOf(4)) * i / 10, box.y + box.h / 2);
    passed.push(await songTime());
  }
  await page.mouse.up();
  await page.waitForTimeout(200);
  const scrubbed = await songTime();
  if (!passed.some((t) => t >= bars[5].start_s && t < bars[5].end_s)) fail(`the scrub never passed bar 5: ${passed}`);
  if (!(scrubbed >= bars[6].start_s && scrubbed < bars[6].end_s)) fail(`the scrub ended at ${scrubbed} s, not in bar 6`);
  if (await playing()) fail('a scrub while paused started playback');
  if ((await page.textContent('#bar-title')) !== 'Bar 9') fail('a scrub picked a bar');

  // A candidate of bar 1 in context: it plays from bar 0 through bar 2, both seams scored.
  await clickBar(1);
  await page.waitForFunction(() => document.getElementById('bar-title').textContent === 'Bar 1', null, { timeout: 10000 });
  await page.waitForSelector('#candidates .cand button.context');
  const still = await candidateShot();
  await (await page.$$('#candidates .cand button.context'))[0].click();
  await page.waitForSelector('#candidates .cand[data-context="1"]', { timeout: 20000 }).catch(() => fail('no candidate in context'));
  const seamText = await page.$eval('#candidates .cand[data-context="1"] .seams', (e) => e.textContent);
  if (!/^from bar 0 S -?[0-9.]+ · into bar 2 S -?[0-9.]+ · C [0-9.]+$/.test(seamText)) fail(`the seams in context read "${seamText}"`);
  const c0 = await candidateShot();
  await page.waitForTimeout(400);
  const c1 = await candidateShot();
  if (c0 === c1 || c0 === still) fail('the candidate in context does not move');
  // Over its loop the card says which bar it is dancing: 0, 1 (this segment), 2.
  const seen = new Set();
  const until = Date.now() + 3000 * (bars[2].end_s - bars[0].start_s);
  while (seen.size < 3 && Date.now() < until) {
    seen.add(await page.$eval('#candidates .cand[data-context="1"] .where', (e) => e.textContent));
    await page.waitForTimeout(120);
  }
  const wantSeen = ['▶ bar 0 (neighbour)', '▶ bar 1 (this segment)', '▶ bar 2 (neighbour)'];
  if (!wantSeen.every((w) => seen.has(w))) fail(`in context the card showed ${[...seen]}`);
  await page.screenshot({ path: join(shots, 'editor_in_context.png'), clip: { x: 0, y: 200, width: 1280, height: 560 } });
  await (await page.$$('#candidates .cand button.context'))[0].click();
  await page.waitForFunction(() => !document.querySelector('#candidates .cand[data-context]'), null, { timeout: 5000 }).catch(() => fail('In context did not turn off'));

  await clickBar(0);
  await page.waitForFunction(() => document.getElementById('bar-title').textContent === 'Bar 0', null, { timeout: 10000 });

  // Save and Export through the page's buttons: the whole edit, from loading to Export.
  await page.click('#save');
  await waitStatus('saved');
  const download = page.waitForEvent('download', { timeout: 30000 });
  await page.click('#export');
  const bvh = join(shots, 'playback_dance.bvh');
  await (await download).saveAs(bvh);
  checkErrors('at the end');
  await page.waitForTimeout(300); // the last pieces asked for arrive
  const bytes = audio.reduce((x, y) => x + y, 0);
  console.log(JSON.stringify({ repeated: marked, first_sound_ms: firstSoundMs, audio_pieces: audio.length, audio_bytes: bytes, loop_samples: samples.length, loop_wraps: wraps, status_while_playing: danceShown, bvh }));
} finally {
  await browser.close();
}
