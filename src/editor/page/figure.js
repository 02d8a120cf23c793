// A stick figure on the shared orbit camera (`OrbitView`, the results page's, served before
// this file as one module): drag to orbit, wheel to zoom.
// `parents[i]` joins point i to its parent (null for the pelvis).

const COLOURS = { l: '#4fc3f7', r: '#f0a030', c: '#e6e6e6' };

export class StickView extends OrbitView {
  constructor(canvas, figure, cam = { yaw: 0.5, pitch: 0.2, dist: 3.6 }) {
    super(canvas, cam);
    this.figure = figure; // { parents, sides, head }
  }

  // Draws one frame (a list of points); `follow` centres the camera on the pelvis. A call that
  // would draw the picture already on the canvas (the same frame, camera and size) does nothing,
  // so a view whose motion has fewer frames than the display refreshes costs nothing between them.
  draw(points, follow = false) {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = Math.round(c.clientWidth * dpr) || c.width, h = Math.round(c.clientHeight * dpr) || c.height;
    const key = [points, follow, this.target[0], this.target[2], this.yaw, this.pitch, this.dist, w, h];
    if (this.drawn && key.every((v, i) => v === this.drawn[i])) return;
    this.drawn = key;
    this.fit();
    const g = this.ctx;
    g.clearRect(0, 0, w, h);
    if (follow && points) this.target = [points[0][0], 0.9, points[0][2]];
    this.grid(w, h);
    if (!points) return;
    const s = points.map((p) => this.project(p, w, h));
    const { parents, sides, head } = this.figure;
    g.lineCap = 'round';
    g.lineWidth = Math.max(2, h / 90);
    parents.forEach((par, i) => {
      if (par === null || !s[i] || !s[par]) return;
      g.strokeStyle = COLOURS[sides[i]] || COLOURS.c;
      g.beginPath();
      g.moveTo(s[par][0], s[par][1]);
      g.lineTo(s[i][0], s[i][1]);
      g.stroke();
    });
    if (head && s[head[0]] && s[head[1]]) {
      const [a, b] = [s[head[0]], s[head[1]]];
      const r = Math.hypot(a[0] - b[0], a[1] - b[1]) * 0.3;
      g.fillStyle = '#e6e6e6';
      g.beginPath();
      g.arc(a[0] + 0.65 * (b[0] - a[0]), a[1] + 0.65 * (b[1] - a[1]), Math.max(3, r), 0, 2 * Math.PI);
      g.fill();
    }
  }
}
