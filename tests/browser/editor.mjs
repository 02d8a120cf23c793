// Drives the dance editor's page in headless Chromium (tests/editor/browser.rs runs it):
// node editor.mjs URL SCREENSHOT_DIR
// Prints one JSON line of what the page showed; exits non-zero on any failed check.
import { launch } from './launch.mjs';
import { join } from 'node:path';

const [url, shots] = process.argv.slice(2);
const fail = (msg) => { console.error('FAIL: ' + msg); process.exit(1); };

const browser = await launch();
const errors = [];
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 860 } });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text() + ' ' + (m.location().url || '')); });
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 15000 });
  const loadMs = Date.now() - t0;

  // The segments shown, and how many of each candidate canvas's pixels are drawn (not blank).
  const cards = () => page.$$eval('#candidates .cand', (cs) => cs.map((c) => {
    const cv = c.querySelector('canvas');
    const d = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data;
    let lit = 0;
    for (let i = 3; i < d.length; i += 4) if (d[i] > 0) lit++;
    return { segment: Number(c.dataset.segment), lit, pixels: cv.width * cv.height };
  }));
  // Snapshots of the first canvas every 200 ms for up to 3 s: an animated figure changes (a
  // renderer starved by a loaded machine may skip a few frames, a still figure never changes).
  const animated = () => page.$eval('#candidates .cand canvas', async (cv) => {
    const grab = () => cv.toDataURL();
    const a = grab();
    for (let k = 0; k < 15; k++) {
      await new Promise((r) => setTimeout(r, 200));
      if (a !== grab()) return true;
    }
    return false;
  });

  // Click bar 3 on the timeline (bars are equal in width).
  const box = await page.$eval('#timeline', (c) => { const r = c.getBoundingClientRect(); return { x: r.x, y: r.y, w: r.width, h: r.height }; });
  const state0 = await (await page.request.get(url + 'api/state')).json();
  const bars = state0.bars;
  await page.mouse.click(box.x + 8 + (box.w - 16) * (2.5 / bars), box.y + box.h / 2);
  await page.waitForFunction(() => document.querySelectorAll('#candidates .cand').length === 6, null, { timeout: 10000 });
  await page.waitForTimeout(300);
  const first = await cards();
  if (first.length !== 6) fail(`${first.length} candidates`);
  for (const c of first) if (c.lit < c.pixels * 0.002) fail(`candidate #${c.segment} is blank (${c.lit} of ${c.pixels} pixels)`);
  if (!(await animated())) fail('the first candidate does not move');
  const title = await page.textContent('#bar-title');
  if (title !== 'Bar 2') fail(`selected ${title}`);
  await page.screenshot({ path: join(shots, 'editor_candidates.png') });

  // Like two, Search: six new ones, none shown before.
  const likes = await page.$$('#candidates .cand button.like');
  await likes[0].click();
  await page.waitForSelector('#candidates .cand:nth-child(1) button.like.on');
  await (await page.$$('#candidates .cand button.like'))[2].click();
  await page.waitForSelector('#candidates .cand:nth-child(3) button.like.on');
  const liked = [first[0].segment, first[2].segment];
  await page.click('#search');
  await page.waitForFunction((old) => {
    const s = [...document.querySelectorAll('#candidates .cand')].map((c) => Number(c.dataset.segment));
    return s.length === 6 && s.every((x) => !old.includes(x));
  }, first.map((c) => c.segment), { timeout: 10000 });
  await page.waitForTimeout(300);
  const second = await cards();
  for (const c of second) if (c.lit < c.pixels * 0.002) fail(`new candidate #${c.segment} is blank`);

  // The two liked stay reachable: a "Liked" row of two live cards, each with Set.
  const likedRow = await page.$$eval('#liked .cand', (cs) => cs.map((c) => ({
    segment: Number(c.dataset.segment), set: !!c.querySelector('button.set'), on: !!c.querySelector('button.like.on'),
  })));
  if (likedRow.map((c) => c.segment).join() !== liked.join()) fail(`liked row ${JSON.stringify(likedRow)}, liked ${liked}`);
  if (!likedRow.every((c) => c.set && c.on)) fail(`liked cards without Set or ♥: ${JSON.stringify(likedRow)}`);
  if (await page.isHidden('#liked-head')) fail('the Liked heading is hidden');

  // The explore ↔ follow slider: halfway sets τ₀ = 0.5 for the next rounds.
  await page.$eval('#tau0', (r) => { r.value = '0.5'; r.dispatchEvent(new Event('input')); r.dispatchEvent(new Event('change')); });
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('τ₀ 0.50'), null, { timeout: 10000 });
  const tauShown = await page.textContent('#tau0-value');
  if (tauShown !== 'τ₀ 0.50') fail(`slider label ${tauShown}`);
  const barInfo = await page.textContent('#bar-info');
  if (!barInfo.includes('τ 0.451')) fail(`τ of round 2 at τ₀ 0.5 not shown: ${barInfo}`);
  await page.screenshot({ path: join(shots, 'editor_liked.png'), fullPage: true });

  // Set the second new candidate, then Generate.
  const pinned = second[1].segment;
  await (await page.$$('#candidates .cand button.set'))[1].click();
  await page.waitForSelector('#candidates .cand.pinned');
  // Start over: round 0 again, six candidates none of them liked, the liked row still there.
  await page.click('#start-over');
  await page.waitForFunction(() => document.getElementById('status').textContent.includes('started over'), null, { timeout: 10000 });
  const restarted = await page.textContent('#bar-info');
  if (!restarted.includes('round 1 ·') || !restarted.includes(' 8 shown')) fail(`after Start over: ${restarted}`);
  const third = await cards();
  if (third.length !== 6) fail(`${third.length} candidates after Start over`);
  if (third.some((c) => liked.includes(c.segment))) fail(`a liked segment among the new candidates: ${third.map((c) => c.segment)}`);
  if ((await page.$$('#liked .cand')).length !== 2) fail('the liked row is gone after Start over');
  await page.screenshot({ path: join(shots, 'editor_start_over.png'), fullPage: true });

  await page.click('#generate');
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('generated'), null, { timeout: 10000 });

  // Play (space) for a moment: the dance view draws and the playhead moves.
  await page.keyboard.press('Space');
  await page.waitForFunction(() => document.getElementById('play').textContent.includes('Pause'), null, { timeout: 15000 });
  await page.waitForTimeout(1200);
  const danceLit = await page.$eval('#dance', (cv) => {
    const d = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data;
    let lit = 0;
    for (let i = 3; i < d.length; i += 4) if (d[i] > 0) lit++;
    return lit;
  });
  if (danceLit < 500) fail(`the dance view is blank (${danceLit} pixels)`);
  await page.screenshot({ path: join(shots, 'editor_playing.png') });
  await page.keyboard.press('Space');

  // → selects the next bar.
  await page.keyboard.press('ArrowRight');
  await page.waitForFunction(() => document.getElementById('bar-title').textContent === 'Bar 3', null, { timeout: 10000 });

  // Save and export through the page's buttons.
  await page.click('#save');
  await page.waitForFunction(() => document.getElementById('status').textContent.startsWith('saved'), null, { timeout: 10000 });
  const download = page.waitForEvent('download', { timeout: 15000 });
  await page.click('#export');
  const bvhPath = join(shots, 'editor_dance.bvh');
  await (await download).saveAs(bvhPath);

  if (errors.length) fail('page errors: ' + errors.join(' | '));
  console.log(JSON.stringify({
    load_ms: loadMs, first: first.map((c) => c.segment), liked, second: second.map((c) => c.segment),
    after_start_over: third.map((c) => c.segment),
    pinned_bar: 2, pinned, lit: first.map((c) => c.lit), dance_lit: danceLit, bvh: bvhPath,
  }));
} finally {
  await browser.close();
}
