// The timeline of the song's bars: intensity per bar, bar numbers (from 0, as the scene file and
// its errors number them), beat ticks, pinned bars, fills made for other pins (stale until the
// next Generate), the loop, the selected bar and the playhead. Drawn at the device's pixel
// ratio; labels that would overlap are thinned to every k-th bar (k = 1, 2, 5, 10, 20, 50, …).
// Zoom and scroll as in a sound editor: the wheel zooms around the pointer (down to two bars),
// shift+wheel or a sideways wheel scrolls; `view` is the song span shown (null: the whole song).

const STEPS = [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000];

export class Timeline {
  // `onPick(k, event)`: a bar was clicked; `onScrub(t, phase)`: the pointer was dragged along
  // the timeline to song time t (phase 'start', 'move' or 'end').
  constructor(canvas, onPick, onScrub = () => {}) {
    this.canvas = canvas;
    this.bars = [];
    this.beats = [];
    this.selected = null;
    this.loop = null; // { a, b }: bars a..=b
    this.playhead = null; // song time (s)
    this.labels = []; // the bar numbers drawn: { text, x0, x1 } in CSS pixels (for tests)
    this.repeated = []; // the bars whose segment is danced in another bar too
    this.view = null; // [a, b]: the song span shown (s); null: all of it
    const px = (e) => e.offsetX * (canvas.width / canvas.clientWidth);
    canvas.addEventListener('wheel', (e) => {
      if (!this.bars.length) return;
      e.preventDefault();
      // Shift turns a wheel sideways (some browsers swap the deltas themselves).
      const d = Math.abs(e.deltaX) > Math.abs(e.deltaY) ? e.deltaX : e.deltaY;
      if (e.shiftKey || Math.abs(e.deltaX) > Math.abs(e.deltaY)) this.scroll(d / (canvas.clientWidth || 1));
      else this.zoom(Math.exp(e.deltaY * 0.002), this.timeAt(px(e)));
    }, { passive: false });
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.offsetX, moved: false };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag || !this.bars.length) return;
      if (!drag.moved && Math.abs(e.offsetX - drag.x) < 4) return;
      if (!drag.moved) { drag.moved = true; onScrub(this.timeAt(px(e)), 'start'); }
      onScrub(this.timeAt(px(e)), 'move');
    });
    canvas.addEventListener('pointerup', (e) => {
      if (drag && drag.moved) onScrub(this.timeAt(px(e)), 'end');
      drag = drag && drag.moved ? { after: true } : null;
    });
    canvas.addEventListener('click', (e) => {
      // A drag ends in a click too: it was a scrub, not a pick.
      if (drag && drag.after) { drag = null; return; }
      drag = null;
      const k = this.barAt(px(e));
      if (k !== null) onPick(k, e);
    });
  }

  // The song time at canvas pixel `px`, within the span shown.
  timeAt(px) {
    const [a, b] = this.visible();
    const m = 8 * this.dpr();
    const u = Math.min(1, Math.max(0, (px - m) / (this.canvas.width - 2 * m)));
    return Math.min(a + u * (b - a), b - 1e-6);
  }

  set(bars, beats) { this.bars = bars; this.beats = beats; this.draw(); }

  span() {
    const n = this.bars.length;
    return n ? [this.bars[0].start_s, this.bars[n - 1].end_s] : [0, 1];
  }

  // The song span shown, [a, b] in s.
  visible() {
    return this.view ?? this.span();
  }

  // Shows `[a, b]` (s), kept within the song and at least two bars long; the whole song is
  // shown as null.
  show(a, b) {
    const [s0, s1] = this.span();
    const n = this.bars.length;
    const least = Math.min(s1 - s0, n ? 2 * (s1 - s0) / n : s1 - s0);
    let w = Math.max(least, Math.min(s1 - s0, b - a));
    a = Math.min(Math.max(s0, a), s1 - w);
    this.view = w >= (s1 - s0) - 1e-9 ? null : [a, a + w];
    this.draw();
  }

  // Zooms by `factor` (< 1: in) around song time `at`, which stays under the pointer.
  zoom(factor, at) {
    const [a, b] = this.visible();
    this.show(at - (at - a) * factor, at + (b - at) * factor);
  }

  // Scrolls by `fraction` of the span shown (positive: later).
  scroll(fraction) {
    const [a, b] = this.visible();
    const d = fraction * (b - a);
    this.show(a + d, b + d);
  }

  // Scrolls so that song time `t` is shown (a quarter in from the left when it was off).
  reveal(t) {
    const [a, b] = this.visible();
    if (this.view && (t < a || t > b)) this.show(t - (b - a) / 4, t + 3 * (b - a) / 4);
  }

  x(t) {
    const [a, b] = this.visible();
    const m = 8 * this.dpr();
    return m + (this.canvas.width - 2 * m) * (t - a) / (b - a);
  }

  dpr() { return window.devicePixelRatio || 1; }

  barAt(px) {
    const k = this.bars.findIndex((b) => px >= this.x(b.start_s) && px < this.x(b.end_s));
    return k < 0 ? null : k;
  }

  // The smallest step of STEPS at which labels `width` px wide, one every `step` bars of
  // `perBar` px, leave a gap of at least `gap` px.
  static step(width, perBar, gap) {
    return STEPS.find((s) => s * perBar >= width + gap) ?? STEPS[STEPS.length - 1];
  }

  draw() {
    const c = this.canvas, r = this.dpr();
    const w = Math.round(c.clientWidth * r) || c.width, h = Math.round(c.clientHeight * r) || c.height;
    if (c.width !== w) c.width = w;
    if (c.height !== h) c.height = h;
    const g = c.getContext('2d');
    g.clearRect(0, 0, w, h);
    const top = 20 * r, bottom = h - 22 * r, n = this.bars.length;
    if (!n) return;
    // The span shown, and a bar's mean width in pixels at this zoom.
    const [va, vb] = this.visible();
    const [s0, s1] = this.span();
    const perBar = (w - 16 * r) / (vb - va) * ((s1 - s0) / n);
    g.font = `${12 * r}px system-ui, sans-serif`;
    g.textAlign = 'center';
    const numW = g.measureText(String(n - 1)).width;
    const step = Timeline.step(numW, perBar, 6 * r);
    const maxSeg = this.bars.reduce((m, b) => Math.max(m, b.pin ?? b.filled ?? 0), 0);
    const fillW = g.measureText(`#${maxSeg}?`).width;
    const fillStep = Timeline.step(fillW, perBar, 6 * r);
    const pinW = g.measureText('PIN').width + 6 * r;
    this.labels = [];
    // A segment danced in more than one bar: a red mark under each of those bars.
    const uses = new Map();
    for (const b of this.bars) {
      const seg = b.pin ?? b.filled;
      if (seg !== null) uses.set(seg, (uses.get(seg) || 0) + 1);
    }
    this.repeated = [];
    if (this.loop) {
      const x0 = this.x(this.bars[this.loop.a].start_s), x1 = this.x(this.bars[this.loop.b].end_s);
      g.fillStyle = 'rgba(129, 199, 132, 0.25)';
      g.fillRect(x0, 0, x1 - x0, h);
      g.fillStyle = '#81c784';
      g.fillRect(x0, 0, x1 - x0, 3 * r);
    }
    this.bars.forEach((b, k) => {
      if (b.end_s <= va || b.start_s >= vb) return;
      const x0 = this.x(b.start_s), x1 = this.x(b.end_s), mid = (x0 + x1) / 2;
      const gap = Math.min(1 * r, (x1 - x0) / 8);
      const v = 0.15 + 0.85 * b.intensity;
      const pinned = b.pin !== null;
      g.fillStyle = pinned ? '#2b6f8f' : (b.filled !== null ? '#3d4350' : '#2c3039');
      g.fillRect(x0 + gap, top, x1 - x0 - 2 * gap, bottom - top);
      g.fillStyle = pinned ? '#4fc3f7' : (b.stale ? '#8a6a3a' : '#f0a030');
      const bh = (bottom - top) * v;
      g.fillRect(x0 + 3 * gap, bottom - bh, x1 - x0 - 6 * gap, bh);
      if (b.stale) {
        // Diagonal hatching: this bar's fill was made for other pins.
        g.save();
        g.beginPath();
        g.rect(x0 + gap, top, x1 - x0 - 2 * gap, bottom - top);
        g.clip();
        g.strokeStyle = 'rgba(22, 24, 29, 0.7)';
        g.lineWidth = 2 * r;
        for (let s = x0 - (bottom - top); s < x1; s += 8 * r) {
          g.beginPath();
          g.moveTo(s, bottom);
          g.lineTo(s + (bottom - top), top);
          g.stroke();
        }
        g.restore();
      }
      if (k === this.selected) {
        g.strokeStyle = '#ffffff';
        g.lineWidth = 2 * r;
        g.strokeRect(x0 + gap, top - r, x1 - x0 - 2 * gap, bottom - top + 2 * r);
      }
      if (k % step === 0) {
        g.fillStyle = '#e6e6e6';
        g.fillText(String(k), mid, top - 6 * r);
        const tw = g.measureText(String(k)).width;
        this.labels.push({ text: String(k), x0: (mid - tw / 2) / r, x1: (mid + tw / 2) / r });
      }
      if (pinned) {
        if (x1 - x0 >= pinW) {
          // A dark badge, readable over the pinned colour whatever the bar's loudness.
          g.fillStyle = '#0e1014';
          g.fillRect(mid - pinW / 2, top + 3 * r, pinW, 16 * r);
          g.fillStyle = '#4fc3f7';
          g.fillText('PIN', mid, top + 15 * r);
        } else {
          g.fillStyle = '#0e1014';
          g.fillRect(x0 + gap, top, x1 - x0 - 2 * gap, 4 * r);
        }
      }
      if ((uses.get(b.pin ?? b.filled) || 0) > 1) {
        this.repeated.push(k);
        g.fillStyle = '#ef5b7b';
        g.fillRect(x0 + 3 * gap, bottom + 5 * r, x1 - x0 - 6 * gap, 2 * r);
      }
      if ((b.filled !== null || pinned) && k % fillStep === 0) {
        g.fillStyle = b.stale ? '#8a6a3a' : '#9aa0a6';
        g.fillText('#' + (b.pin ?? b.filled) + (b.stale ? '?' : ''), mid, h - 5 * r);
      }
    });
    g.strokeStyle = '#9aa0a6';
    g.lineWidth = r;
    for (const t of this.beats) {
      const x = this.x(t);
      if (x < 0 || x > w) continue;
      g.beginPath();
      g.moveTo(x, bottom);
      g.lineTo(x, bottom + 4 * r);
      g.stroke();
    }
    if (this.playhead !== null) {
      const x = this.x(this.playhead);
      g.strokeStyle = '#ef5b7b';
      g.lineWidth = 2 * r;
      g.beginPath();
      g.moveTo(x, 0);
      g.lineTo(x, h);
      g.stroke();
    }
  }
}
