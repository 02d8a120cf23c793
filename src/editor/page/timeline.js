// The timeline of the song's bars: intensity per bar, bar numbers, beat ticks, pinned bars,
// the selected bar and the playhead.

export class Timeline {
  constructor(canvas, onPick) {
    this.canvas = canvas;
    this.bars = [];
    this.beats = [];
    this.selected = null;
    this.playhead = null; // song time (s)
    canvas.addEventListener('click', (e) => {
      const k = this.barAt(e.offsetX * (canvas.width / canvas.clientWidth));
      if (k !== null) onPick(k);
    });
  }

  set(bars, beats) { this.bars = bars; this.beats = beats; this.draw(); }

  span() {
    const n = this.bars.length;
    return n ? [this.bars[0].start_s, this.bars[n - 1].end_s] : [0, 1];
  }

  x(t) {
    const [a, b] = this.span();
    return 8 + (this.canvas.width - 16) * (t - a) / (b - a);
  }

  barAt(px) {
    const k = this.bars.findIndex((b) => px >= this.x(b.start_s) && px < this.x(b.end_s));
    return k < 0 ? null : k;
  }

  draw() {
    const c = this.canvas;
    const w = Math.round(c.clientWidth * (window.devicePixelRatio || 1)) || c.width;
    if (c.width !== w) c.width = w;
    const h = c.height, g = c.getContext('2d');
    g.clearRect(0, 0, w, h);
    const top = 18, bottom = h - 22;
    this.bars.forEach((b, k) => {
      const x0 = this.x(b.start_s), x1 = this.x(b.end_s);
      const v = 0.15 + 0.85 * b.intensity;
      g.fillStyle = b.pin !== null ? '#2b6f8f' : (b.filled !== null ? '#3d4350' : '#2c3039');
      g.fillRect(x0 + 1, top, x1 - x0 - 2, bottom - top);
      g.fillStyle = b.pin !== null ? '#4fc3f7' : '#f0a030';
      const bh = (bottom - top) * v;
      g.fillRect(x0 + 3, bottom - bh, x1 - x0 - 6, bh);
      if (k === this.selected) {
        g.strokeStyle = '#ffffff';
        g.lineWidth = 2;
        g.strokeRect(x0 + 1, top - 1, x1 - x0 - 2, bottom - top + 2);
      }
      g.fillStyle = '#e6e6e6';
      g.font = '11px system-ui';
      g.textAlign = 'center';
      g.fillText(String(k + 1), (x0 + x1) / 2, top - 5);
      if (b.pin !== null) {
        g.fillStyle = '#4fc3f7';
        g.fillText('PIN', (x0 + x1) / 2, top + 12);
      }
      if (b.filled !== null || b.pin !== null) {
        g.fillStyle = '#9aa0a6';
        g.fillText('#' + (b.pin ?? b.filled), (x0 + x1) / 2, h - 4);
      }
    });
    g.strokeStyle = '#9aa0a6';
    g.lineWidth = 1;
    for (const t of this.beats) {
      const x = this.x(t);
      if (x < 0 || x > w) continue;
      g.beginPath();
      g.moveTo(x, bottom);
      g.lineTo(x, bottom + 5);
      g.stroke();
    }
    if (this.playhead !== null) {
      const x = this.x(this.playhead);
      g.strokeStyle = '#ef5b7b';
      g.lineWidth = 2;
      g.beginPath();
      g.moveTo(x, 0);
      g.lineTo(x, h);
      g.stroke();
    }
  }
}
