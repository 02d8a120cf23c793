// A stick figure on a 2D canvas with an orbit camera: drag to orbit, wheel to zoom.
// Points are metres, y up; `parents[i]` joins point i to its parent (null for the pelvis).
// The camera ({ yaw, pitch, dist }) may be shared: views given the same object orbit and zoom
// together, and a view rebuilt with it keeps the orbit and zoom the user chose.

const COLOURS = { l: '#4fc3f7', r: '#f0a030', c: '#e6e6e6' };

export class StickView {
  constructor(canvas, figure, cam = { yaw: 0.5, pitch: 0.2, dist: 3.6 }) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.figure = figure; // { parents, sides, head }
    this.cam = cam;
    this.target = [0, 0.9, 0];
    let drag = null;
    canvas.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY };
      canvas.setPointerCapture(e.pointerId);
    });
    canvas.addEventListener('pointermove', (e) => {
      if (!drag) return;
      this.yaw += (e.clientX - drag.x) * 0.01;
      this.pitch = Math.max(-1.4, Math.min(1.4, this.pitch + (e.clientY - drag.y) * 0.01));
      drag = { x: e.clientX, y: e.clientY };
    });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.dist = Math.max(1.0, Math.min(20, this.dist * Math.exp(e.deltaY * 0.001)));
    }, { passive: false });
  }

  get yaw() { return this.cam.yaw; }
  set yaw(v) { this.cam.yaw = v; }
  get pitch() { return this.cam.pitch; }
  set pitch(v) { this.cam.pitch = v; }
  get dist() { return this.cam.dist; }
  set dist(v) { this.cam.dist = v; }

  // World point → [x, y, depth] on the canvas, or null behind the camera.
  project(p, w, h) {
    let x = p[0] - this.target[0], y = p[1] - this.target[1], z = p[2] - this.target[2];
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    [x, z] = [cy * x - sy * z, sy * x + cy * z];
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    [y, z] = [cp * y - sp * z, sp * y + cp * z];
    const d = this.dist - z;
    if (d < 0.05) return null;
    const f = 1.6 * h / d;
    return [w / 2 + x * f, h / 2 - y * f, d];
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
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
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

  // A floor grid of 0.5 m squares around the target.
  grid(w, h) {
    const g = this.ctx;
    g.strokeStyle = '#34383f';
    g.lineWidth = 1;
    const cx = Math.round(this.target[0] * 2) / 2, cz = Math.round(this.target[2] * 2) / 2;
    for (let k = -4; k <= 4; k++) {
      for (const [a, b] of [[[cx + k / 2, 0, cz - 2], [cx + k / 2, 0, cz + 2]], [[cx - 2, 0, cz + k / 2], [cx + 2, 0, cz + k / 2]]]) {
        const p = this.project(a, w, h), q = this.project(b, w, h);
        if (!p || !q) continue;
        g.beginPath();
        g.moveTo(p[0], p[1]);
        g.lineTo(q[0], q[1]);
        g.stroke();
      }
    }
  }
}
