// Latency of the dance editor as its page sees it (tests/editor/browser.rs runs it):
// node latency.mjs URL
// In headless Chromium, with performance.now() in the page: the first load (navigation start
// to a usable page), Search rounds (the POST answered and its JSON read; and the Search
// button to six new candidates drawn), and Generate (every unpinned bar filled); for the POSTs
// also the server's own time from its Server-Timing header. Prints one
// JSON line of every measurement; these are measurements, not checks: only correctness
// (six candidates, every bar filled) fails the script.
import { launch } from './launch.mjs';

const [url] = process.argv.slice(2);
const fail = (msg) => { console.error('FAIL: ' + msg); process.exit(1); };

const browser = await launch();
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 860 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(url);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 30000 });
  const loadMs = Number(await page.getAttribute('body', 'data-ready-ms'));
  // The server's own milliseconds of an answer (its Server-Timing header), for both timed loops.
  await page.evaluate(() => {
    window.serverMs = (r) => Number((r.headers.get('Server-Timing') || '').match(/dur=([0-9.]+)/)?.[1]);
  });

  // Search rounds straight through the API, as the page's fetch sees them: bars 0..9, two
  // rounds each.
  const search = await page.evaluate(async () => {
    const out = [];
    for (let round = 0; round < 2; round++) {
      for (let bar = 0; bar < 10; bar++) {
        const t0 = performance.now();
        const r = await fetch('/api/search', {
          method: 'POST', headers: { 'Content-Type': 'application/json' },
          body: JSON.stringify({ bar }),
        });
        const j = await r.json();
        const ms = performance.now() - t0;
        const server = window.serverMs(r);
        out.push({ ms, server, candidates: j.candidates.length, bytes: JSON.stringify(j).length });
      }
    }
    return out;
  });
  for (const s of search) if (s.candidates !== 6) fail(`a search round gave ${s.candidates} candidates`);

  // The Search button of the page: from the click to six new candidates drawn.
  const box = await page.$eval('#timeline', (c) => { const r = c.getBoundingClientRect(); return { x: r.x, y: r.y, w: r.width, h: r.height }; });
  const bars = (await (await page.request.get(url + 'api/state')).json()).bars;
  await page.mouse.click(box.x + 8 + (box.w - 16) * (12.5 / bars), box.y + box.h / 2);
  await page.waitForFunction(() => document.querySelectorAll('#candidates .cand').length === 6, null, { timeout: 10000 });
  const clicks = [];
  for (let k = 0; k < 5; k++) {
    clicks.push(await page.evaluate(async () => {
      const ids = () => [...document.querySelectorAll('#candidates .cand')].map((c) => c.dataset.segment).join();
      const before = ids();
      const t0 = performance.now();
      document.getElementById('search').click();
      while (ids() === before || document.querySelectorAll('#candidates .cand').length !== 6) {
        await new Promise((r) => requestAnimationFrame(r));
      }
      return performance.now() - t0;
    }));
  }

  // Generate with four bars pinned (as benches/choreo_fill.rs pins them).
  const generate = await page.evaluate(async (n) => {
    const post = (path, body) => fetch(path, {
      method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body),
    }).then((r) => r.json());
    for (const [bar, segment] of [[5, 17 % n], [21, 901 % n], [40, 1402 % n], [58, 3 % n]]) {
      await post('/api/set', { bar, segment });
    }
    const out = [];
    for (let k = 0; k < 5; k++) {
      const t0 = performance.now();
      const r = await fetch('/api/generate', {
        method: 'POST', headers: { 'Content-Type': 'application/json' }, body: '{}',
      });
      const j = await r.json();
      const ms = performance.now() - t0;
      const server = window.serverMs(r);
      out.push({ ms, server, bars: j.fill.segments.length });
    }
    return out;
  }, (await (await page.request.get(url + 'api/state')).json()).segments);
  for (const g of generate) if (g.bars !== bars) fail(`generate filled ${g.bars} of ${bars} bars`);
  if (errors.length) fail('page errors: ' + errors.join(' | '));
  console.log(JSON.stringify({
    load_ms: loadMs, bars,
    search_ms: search.map((s) => s.ms), search_server_ms: search.map((s) => s.server),
    search_bytes: search[0].bytes,
    search_click_to_drawn_ms: clicks,
    generate_ms: generate.map((g) => g.ms), generate_server_ms: generate.map((g) => g.server),
  }));
} finally {
  await browser.close();
}
