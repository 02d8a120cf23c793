// Drives a results page (index.html of a scene, or `marionette view`'s page) in headless
// Chromium from its file:// URL (tests/cli/results_page.rs runs it):
// node results.mjs URL SCREENSHOT.png [AT]
// Prints one JSON line of what the page showed; the Rust test asserts on it. Exits non-zero
// only when the page cannot be driven at all.
import { launch } from './launch.mjs';

const [url, shot, at] = process.argv.slice(2);
const browser = await launch();
const errors = [];
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('request', (r) => { if (!r.url().startsWith('data:') && r.url() !== url) errors.push('fetched ' + r.url()); });
  await page.goto(url);
  await page.waitForFunction(() => window.resultsPage !== undefined, null, { timeout: 15000 });
  const listed = await page.$$eval('#motion-list .label', (ls) => ls.map((l) => l.textContent));
  const views = await page.$$eval('#stage canvas', (cs) => cs.length);

  // Play: the frame advances.
  const before = await page.evaluate(() => ({ t: resultsPage.time(), frames: resultsPage.frames() }));
  await page.click('#play');
  await page.waitForTimeout(700);
  await page.click('#play');
  const after = await page.evaluate(() => ({ t: resultsPage.time(), frames: resultsPage.frames(), playing: resultsPage.playing() }));

  // Scrub: the cursor of every plot on the timeline follows the playhead.
  const end = await page.$eval('#scrub', (s) => parseFloat(s.max));
  const cursors = [];
  for (const at of [0.25, 0.75]) {
    await page.$eval('#scrub', (s, t) => { s.value = t; s.dispatchEvent(new Event('input')); }, at * end);
    cursors.push(await page.evaluate(() => ({
      t: resultsPage.time(),
      plots: [...document.querySelectorAll('canvas.plot')].filter((c) => c.dataset.cursorT !== undefined)
        .map((c) => ({ t: parseFloat(c.dataset.cursorT), x: parseFloat(c.dataset.cursorX) })),
    })));
  }

  // Frame step from the middle.
  await page.evaluate((t) => resultsPage.seek(t), end / 2);
  const unstepped = await page.evaluate(() => resultsPage.frames());
  await page.click('#next');
  const stepped = await page.evaluate(() => resultsPage.frames());

  // The first frame from the front: each figure's lowest and highest drawn body point.
  await page.evaluate(() => { resultsPage.seek(0); resultsPage.setView('three'); });
  const stats = await page.evaluate(() => resultsPage.stats());
  const lit = await page.$eval('#stage canvas', (cv) => {
    const d = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data;
    let n = 0;
    // A body pixel: coloured (a left or right limb, a touching box, a ring) or the cool grey of
    // the mid-line; the floor, its grid and the shadows are warm greys (blue below red).
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - d[i + 1]) > 30 || Math.abs(d[i + 1] - d[i + 2]) > 30 || d[i + 2] - d[i] >= 4) n++;
    }
    return n / (cv.width * cv.height);
  });
  await page.screenshot({ path: shot, fullPage: true });
  // A second picture at time AT (s), when given: SHOT with `_at` before its extension.
  if (at !== undefined) {
    await page.evaluate((t) => resultsPage.seek(t), parseFloat(at));
    await page.screenshot({ path: shot.replace(/\.png$/, '_at.png'), fullPage: true });
  }
  const size = (await page.content()).length;
  console.log(JSON.stringify({ errors, listed, views, before, after, end, cursors, unstepped, stepped, stats, lit, size }));
} finally {
  await browser.close();
}
