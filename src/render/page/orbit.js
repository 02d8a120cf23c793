// An orbit camera over a 2D canvas: drag to orbit, wheel to zoom, a floor grid. Shared by the
// results page (index.html of every scene) and the dance editor's figure views.
// Points are metres, y up. The camera ({ yaw, pitch, dist }) may be shared: views given the
// same object orbit and zoom together, and a view rebuilt with it keeps the orbit and zoom the
// user chose.

class OrbitView {
  constructor(canvas, cam = { yaw: 0.5, pitch: 0.2, dist: 3.6 }) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
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
      this.pitch = Math.max(-1.4, Math.min(1.55, this.pitch + (e.clientY - drag.y) * 0.01));
      drag = { x: e.clientX, y: e.clientY };
      if (this.onchange) this.onchange();
    });
    canvas.addEventListener('pointerup', () => { drag = null; });
    canvas.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.dist = Math.max(1.0, Math.min(40, this.dist * Math.exp(e.deltaY * 0.001)));
      if (this.onchange) this.onchange();
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

  // Sizes the canvas to its displayed size; returns [w, h] in canvas pixels.
  fit() {
    const c = this.canvas;
    const dpr = window.devicePixelRatio || 1;
    const w = Math.round(c.clientWidth * dpr) || c.width, h = Math.round(c.clientHeight * dpr) || c.height;
    if (c.width !== w || c.height !== h) { c.width = w; c.height = h; }
    return [w, h];
  }

  // A floor grid of 0.5 m squares around the target, `half` metres each way.
  grid(w, h, colour = '#34383f', half = 2) {
    const g = this.ctx;
    g.strokeStyle = colour;
    g.lineWidth = 1;
    const cx = Math.round(this.target[0] * 2) / 2, cz = Math.round(this.target[2] * 2) / 2;
    const n = Math.round(half * 2);
    for (let k = -n; k <= n; k++) {
      for (const [a, b] of [[[cx + k / 2, 0, cz - half], [cx + k / 2, 0, cz + half]], [[cx - half, 0, cz + k / 2], [cx + half, 0, cz + k / 2]]]) {
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
